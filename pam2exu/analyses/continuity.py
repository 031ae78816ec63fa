"""Whether a computed motion is continuous: the whole turns an angle jumped between steps,
the turns to take from a configuration to bring it to a reference, and the velocity jumps
(the continuity defect) that show a switch of assembly branch (``branch.py`` reads them)."""
from __future__ import annotations

import numpy as np

from ..kinematics import ANGLES
from .native import RESIDUAL_CHUNK, residuals


def turns_jumped(t, q, qd, solids: int) -> np.ndarray:
    """n (steps, solids): whole turns by which each angle jumped at each step.

    fi_k − fi_j − (t_k − t_j)(ω_k + ω_j)/2 ≈ 2π n, j the previous step with finite rates
    (a step without rates is predicted from ω_j alone). Newton's iteration at a singular
    position can land on the same configuration with an angle off by whole turns.
    """
    fi, w = q[:, ANGLES][:, :solids], qd[:, ANGLES][:, :solids]
    valid = np.isfinite(w).all(axis=1)
    valid[0] = True
    if valid.all():                  # j = k − 1 at every step: slices, not gathers
        j, k = slice(None, -1), slice(1, None)
        wk = w[k]
    else:
        last = np.maximum.accumulate(np.where(valid, np.arange(len(t)), 0))
        j, k = last[:-1], np.arange(1, len(t))
        wk = np.where(valid[k, None], w[k], w[j])
    n = np.zeros(fi.shape)
    with np.errstate(invalid="ignore"):
        n[1:] = np.rint((fi[k] - fi[j] - (t[k] - t[j])[:, None] * (wk + w[j]) / 2)
                        / (2 * np.pi))
    n[~np.isfinite(n)] = 0.0
    return n


def whole_turns(mech, t: float, q: np.ndarray, target: np.ndarray) -> np.ndarray:
    """n (solids,): whole turns to take from each angle of q (a configuration at time t) to
    bring it nearest the angle of ``target``, where the constraints still hold after it.

    Joints are 2π-periodic in the angles, actuators and transmissions are not: a solid whose
    angle an actuator sets keeps its turn. Each solid is tried alone, then all together
    (gears coupled by a transmission turn together).
    """
    wanted = np.rint((q[ANGLES] - target[ANGLES]) / (2 * np.pi))
    wanted[~np.isfinite(wanted)] = 0.0
    if not wanted.any() or mech.n_equations == 0:
        return wanted
    tol = 10 * max(float(np.max(np.abs(residuals(mech, [t], q)))), 1e-12 * mech.scale())

    def holds(turns):
        moved = q.copy()
        moved[ANGLES] -= 2 * np.pi * turns
        return float(np.max(np.abs(residuals(mech, [t], moved)))) <= tol

    if holds(wanted):
        return wanted
    accepted = np.zeros_like(wanted)
    for i in np.nonzero(wanted)[0]:
        trial = accepted.copy()
        trial[i] = wanted[i]
        if holds(trial):
            accepted = trial
    return accepted


def continuity_defect(t, qd, qdd, scale, breakpoints=()) -> np.ndarray:
    """d_k = max |qd_k − qd_{k−1} − dt (qdd_k + qdd_{k−1})/2| / scale (k ≥ 1; d_0 = 0).

    On a smooth motion d_k = O(dt³); a jump of the velocities, as when Newton's iteration
    switches to another branch of the mechanism, makes it O(1). Steps whose interval holds
    a law breakpoint (where velocities may jump) get 0.
    """
    dt = np.diff(t)[:, None]
    d = np.zeros(len(t))
    for a in range(1, len(t), RESIDUAL_CHUNK):      # in blocks that stay in the cache
        k = slice(a, min(len(t), a + RESIDUAL_CHUNK))
        j = slice(a - 1, k.stop - 1)
        jump = qd[k] - qd[j] - dt[j] * (qdd[k] + qdd[j]) / 2
        with np.errstate(invalid="ignore"):
            d[k] = np.max(np.abs(jump) / scale, axis=1)
    d[np.isnan(d)] = np.inf
    for b in breakpoints:
        d[1:][(t[:-1] < b) & (b <= t[1:])] = 0.0
    return d

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
    valid = finite_rows(w)
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
    # in blocks that stay in the cache, the same operations into two buffers (no new
    # arrays per block: a block's temporaries cost more than their arithmetic)
    size = max(1, min(len(t) - 1, RESIDUAL_CHUNK))
    jump, mean = np.empty((size, qd.shape[1])), np.empty((size, qd.shape[1]))
    for a in range(1, len(t), RESIDUAL_CHUNK):
        k = slice(a, min(len(t), a + RESIDUAL_CHUNK))
        j = slice(a - 1, k.stop - 1)
        J, M = jump[:k.stop - a], mean[:k.stop - a]
        # qd_k − qd_j − dt (qdd_k + qdd_j) / 2, in that order
        np.subtract(qd[k], qd[j], out=J)
        np.add(qdd[k], qdd[j], out=M)
        np.multiply(dt[j], M, out=M)
        np.divide(M, 2, out=M)
        np.subtract(J, M, out=J)
        with np.errstate(invalid="ignore"):
            np.divide(np.abs(J, out=J), scale, out=J)
            d[k] = row_max(J)
    d[np.isnan(d)] = np.inf
    for b in breakpoints:
        d[1:][(t[:-1] < b) & (b <= t[1:])] = 0.0
    return d


def finite_rows(*arrays) -> np.ndarray:
    """Per row (step), whether every value of every array there is finite (the whole arrays
    checked first: one pass each when they are, the usual case)."""
    if all(np.isfinite(a).all() for a in arrays):
        return np.ones(len(arrays[0]), dtype=bool)
    out = np.isfinite(arrays[0]).all(axis=1)
    for a in arrays[1:]:
        out &= np.isfinite(a).all(axis=1)
    return out


def row_max(X: np.ndarray) -> np.ndarray:
    """np.max(X, axis=1), NaN where a row has one: column by column when there are few (a
    maximum is exact in any order; numpy's reduction over short rows is slow)."""
    if X.shape[1] == 0 or X.shape[1] > 32:
        return np.max(X, axis=1)
    out = X[:, 0].copy()
    for c in range(1, X.shape[1]):
        np.maximum(out, X[:, c], out=out)
    return out

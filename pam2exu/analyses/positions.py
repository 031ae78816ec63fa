"""Positions from the backend (the assembly first, then the run) and the rates of the
native pass, with their self-check."""
from __future__ import annotations

import time as _time

import numpy as np

from ..backend import Positions
from ..elements import ACCELERATION, VELOCITY
from ..kinematics import ANGLES
from . import native
from .checks import check_residual
from .failure import position_failure, singular_error
from .job import Job, warn_redundant


def positions(job: Job, redundant: bool, anchor_stiffness: float = 0.0,
              check: bool = True, partial: bool = False):
    """Positions at every time from the backend; raises SolverError on failure.

    ``check=False`` leaves the residual check to ``velocities`` (which has the residual).
    ``partial``: a failure after the first step is not raised; returns (q, Positions) with
    the rows from ``Positions.solved`` on NaN (``branch.motion`` may still repair it).
    When the analysis needs velocities and the backend ``gives_rates``, it is asked for
    them too (``Positions.qd``, ``qdd``; ``rates`` uses them).
    """
    mech = job.mech
    clock = _time.perf_counter()
    job.stage = f"solving the positions with {job.backend.solver_name}"
    start = assemble(job, redundant, anchor_stiffness)
    if len(job.times) == 1:                      # the assembly itself
        found = Positions(start[None], 1, None, start)
    else:
        found = job.backend.solve_positions(mech, job.times, start, job.solver,
                                            redundant=redundant,
                                            rates=VELOCITY in job.levels)
        if found.solved:         # step 0 is the assembly (Newton moved it by round-off)
            found.q[0] = start
    job.info["exudyn_seconds"] = _time.perf_counter() - clock

    if found.solved < len(job.times) and not (partial and found.solved > 0):
        raise position_failure(job, found)
    if check:
        check_residual(mech, job.times, found.q, job)
    if redundant:
        warn_redundant(job, found.q[0])
    return (found.q, found) if partial else found.q


def assemble(job: Job, redundant: bool, anchor_stiffness: float = 0.0) -> np.ndarray:
    """x, y, fi of every solid at the first time, solved by the backend from the model's guess.

    What the assembly analysis returns, and where every other analysis starts: each angle
    keeps the whole turn nearest its guess where the constraints allow (Newton's iteration
    may land a whole turn away, and the guess says which numbering the user means).
    ``anchor_stiffness``: see ``Backend.solve_positions`` (free degrees of freedom).
    """
    mech = job.mech
    guess = mech.initial_q()
    found = job.backend.solve_positions(mech, job.times[:1], guess, job.solver,
                                        redundant=redundant, anchor_stiffness=anchor_stiffness)
    if not found.solved:
        raise position_failure(job, found)
    q0 = found.q[0].copy()
    q0[ANGLES] -= 2 * np.pi * native.whole_turns(mech, float(job.times[0]), q0, guess)
    return q0


def rates(job: Job, t, q, redundant: bool, found: Positions | None = None,
          accelerations: bool = True):
    """(qd, qdd, C(q, t)) at the steps t: the backend's own (``found.qd``, ``qdd``) when it
    gave them for these rows, else the native pass's (``native.rates``); rows at a singular
    position are NaN either way."""
    if found is not None and found.qd is not None:
        n = len(t)
        with np.errstate(all="ignore"):
            residual = native.residuals(job.mech, t, q)
        return found.qd[:n], (found.qdd[:n] if accelerations else None), residual
    with np.errstate(all="ignore"):
        return native.rates(job.mech, t, q, accelerations, redundant)


def velocities(job: Job, q: np.ndarray, redundant: bool):
    """(qd, qdd) from the native pass, after the residual check of the backend's positions;
    SolverError at a singular position (``branch.motion`` follows the branch instead)."""
    mech, t = job.mech, job.times
    accelerations = ACCELERATION in job.levels
    job.stage = "computing velocities and accelerations"
    qd, qdd, residual = rates(job, t, q, redundant, accelerations=accelerations)
    check_residual(mech, t, q, job, residual)
    bad = ~np.isfinite(qd).all(axis=1)
    if qdd is not None:
        bad |= ~np.isfinite(qdd).all(axis=1)
    if bad.any():
        raise singular_error(job, min(int(np.argmax(bad)), native.first_singular(mech, t, q)))
    return qd, qdd

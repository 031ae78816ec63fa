"""Positions from the backend (the assembly first, then the run) and the rates of the
native pass, with their self-check."""
from __future__ import annotations

import time as _time

import numpy as np

from ..backend import Positions
from ..elements import VELOCITY
from ..kinematics import ANGLES, State
from ..progress import Progress
from . import continuity, native
from .checks import check_residual
from .failure import position_failure
from .job import Job, warn_redundant

#: steps solved by one call of the backend: a longer run is solved in parts, one tick of its
#: progress bar each (a part takes a few seconds: 5 s for the four-bar on a slow machine;
#: each part costs the Exudyn backend a new system, about 5 ms, and its predictor's probe)
PART_STEPS = 50_000

#: stiffness tying each coordinate to its guess when degrees of freedom are free, so that
#: ``assemble`` finds the assembly nearest to the guess [N/m]
GUESS_STIFFNESS = 1.0


def positions(job: Job, redundant: bool, anchor_stiffness: float = 0.0,
              check: bool = True, partial: bool = False, with_rates: bool | None = None):
    """Positions at every time from the backend; raises SolverError on failure.

    ``check=False`` leaves the residual check to ``velocities`` (which has the residual).
    ``partial``: a failure after the first step is not raised; returns (q, Positions) with
    the rows from ``Positions.solved`` on NaN (``branch.motion`` may still repair it).
    When the analysis needs velocities (``with_rates``, default: when it outputs some) and
    the backend ``gives_rates``, it is asked for them too (``Positions.qd``, ``qdd``;
    ``rates`` uses them).
    """
    mech = job.mech
    clock = _time.perf_counter()
    job.stage = f"solving the positions with {job.backend.solver_name}"
    start = assemble(job, redundant, anchor_stiffness)
    if len(job.times) == 1:                      # the assembly itself
        found = Positions(start[None], 1, None, start)
    else:
        if with_rates is None:
            with_rates = VELOCITY in job.levels
        found = solve_in_parts(job, start, redundant, with_rates and job.backend.gives_rates)
        if found.solved:         # step 0 is the assembly (Newton moved it by round-off)
            found.q[0] = start
    job.info["backend_seconds"] = _time.perf_counter() - clock

    if found.solved < len(job.times) and not (partial and found.solved > 0):
        raise position_failure(job, found)
    if check:
        check_residual(mech, job.times, found.q, job)
    if redundant:
        warn_redundant(job, found.q[0])
    return (found.q, found) if partial else found.q


def solve_in_parts(job: Job, start: np.ndarray, redundant: bool, rates: bool) -> Positions:
    """The backend's Positions at every time of the run from ``start``, solved in parts of
    ``PART_STEPS`` steps, each from where the last ended, with a progress bar on a terminal
    (``pam2exu.progress``) when there are several: a long run shows how far it is."""
    mech, times = job.mech, job.times
    n = len(times)
    if n <= PART_STEPS + 1:
        return job.backend.solve_positions(mech, times, start, job.solver,
                                           redundant=redundant, rates=rates)
    firsts = range(0, n - 1, PART_STEPS)
    # the rows no part gives are made NaN (not every row NaN first: a pass less over each);
    # a column per coordinate, contiguous (order F): the analysis reads q column by column
    # (the solids' angles and points, the table's columns), a step's row seldom
    q = np.empty((n, mech.nq), order="F")
    rates_of: dict[str, np.ndarray] = {}          # the backend's qd, qdd if it gives them
    written: dict[str, int] = {}                  # ... and the rows given so far
    solved, error, last, iterations = 0, None, start, 0
    with Progress(len(firsts), "solving the positions") as bar:
        for done, a in enumerate(firsts, start=1):
            b = min(a + PART_STEPS, n - 1)
            part = job.backend.solve_positions(mech, times[a:b + 1], q[a] if a else start,
                                               job.solver, redundant=redundant, rates=rates)
            iterations += part.iterations
            keep = slice(a + (1 if a else 0), a + part.solved)   # row a: the last part's
            q[keep] = part.q[keep.start - a:part.solved]
            for mine, theirs in (("qd", part.qd), ("qdd", part.qdd)):
                if theirs is not None:
                    rows = rates_of.setdefault(mine, np.empty_like(q))
                    rows[written.get(mine, 0):a] = np.nan    # after parts without them
                    rows[a:a + part.solved] = theirs[:part.solved]
                    written[mine] = max(written.get(mine, 0), a + part.solved)
            solved = a + max(part.solved, 1 if a else 0)
            bar.update(done)
            if part.solved < b - a + 1:
                error, last = part.error, part.last
                break
    q[solved:] = np.nan
    for mine, rows in rates_of.items():
        rows[written[mine]:] = np.nan
    return Positions(q, solved, error, last, None, iterations, rates_of.get("qd"),
                     rates_of.get("qdd"))


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
    q0[ANGLES] -= 2 * np.pi * continuity.whole_turns(mech, float(job.times[0]), q0, guess)
    return q0


def rates(job: Job, t, q, redundant: bool, found: Positions | None = None,
          accelerations: bool = True, with_jacobian: bool = False):
    """(qd, qdd, C(q, t)) at the steps t: the backend's own (``found.qd``, ``qdd``) when it
    gave them for these rows, else the native pass's (``native.rates``); rows at a singular
    position are NaN either way. ``with_jacobian``: (qd, qdd, C, Cq), Cq (n, m, nq) from the
    same evaluation of the equations (None where the native pass does not keep it)."""
    if found is not None and found.qd is not None:
        n = len(t)
        with np.errstate(all="ignore"):
            if with_jacobian:            # C and Cq from one evaluation (the same C)
                eq = native.equations(job.mech, State(t, q))
                residual, jacobian = eq.residual, eq.jacobian
            else:
                residual, jacobian = native.residuals(job.mech, t, q), None
        out = found.qd[:n], (found.qdd[:n] if accelerations else None), residual
        return (*out, jacobian) if with_jacobian else out
    with np.errstate(all="ignore"):
        return native.rates(job.mech, t, q, accelerations, redundant, with_jacobian)



"""Following one branch of the motion through singular and nearly singular positions.

The backend's solver starts each step's Newton iteration from the previous step's
configuration. Near a change point (a parallelogram whose links become collinear, a
four-bar passing close to one) that start can be nearer to another assembly branch, and
Newton converges there: the positions still close, but the mechanism has switched branch.
The velocities tell: on a smooth motion they change by O(dt³) more than the accelerations
predict between two steps (``continuity.continuity_defect``); a branch switch makes them jump.

Where they jump, the step is solved again by the backend, its Newton iteration now started from
the Taylor predictor q + h q̇ + h²/2 q̈ of the last good step, which lies on the branch
followed. If the backend lands on the same configuration as before, there was no switch (a
coarse grid); otherwise the rest of the run is replaced by the re-solved one.

At a step that lies exactly on a singular position, Cq q̇ = −C_t does not fix the rates.
Kinematic runs give there the limits interpolated from the neighbouring steps, and warn;
force analyses stop (the reactions are not defined there).
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..errors import ConditionWarning, SolverError
from ..kinematics import ANGLES
from . import continuity, native, rank
from .checks import check_residual
from .failure import motion_per_step, position_failure, singular_error
from .job import Job, warn
from .positions import positions, rates

#: a velocity jump between two steps above this fraction of the velocities' scale is
#: taken as a possible branch switch (smooth motion: O((ω dt)³) of it)
JUMP = 0.05
#: ... or above SPIKE times the defects around it (and above SPIKE_FLOOR)
SPIKE, SPIKE_FLOOR = 10.0, 1e-4
#: sub-steps per step when the predictor alone does not find the branch
SUBSTEPS = 16
#: the most re-solves of a run before giving up
MAX_RESOLVES = 64
#: ... and the most position solves they may take: this many times the run, plus a floor
RESOLVE_WORK, RESOLVE_FLOOR = 8, 20_000
#: the condition number of the constraint Jacobian (rows and columns equilibrated) above
#: which a run warns; ordinary mechanisms: 3 to 10, a four-bar 0.2° from a change point: 190
CONDITION_WARNING = 100.0
#: condition numbers are computed at most at this many steps (equally spaced) per run
CONDITION_SAMPLES = 400
#: a step next to a velocity jump whose condition number is above this is taken as lying
#: on the singular position itself: Newton converges there only to ~√(tolerance), so the
#: condition number of the backend's configuration is ~1e6, not 1e16
SINGULAR = 1e4


def _scales(mech, qd) -> np.ndarray:
    """Per-coordinate scale of the velocities: the largest speed, angles × the length scale
    (of the finite velocities)."""
    L = mech.scale()
    weights = np.tile([1.0, 1.0, L], len(mech.solids))
    # max_k |q̇_k w| = w max_k |q̇_k| for w > 0 (rounding is monotone): each column's
    # largest first, one pass over the run when every velocity is finite
    largest = np.max(np.abs(qd), axis=0, initial=0.0)
    if not np.isfinite(largest).all():
        largest = np.max(np.abs(qd), axis=0, initial=0.0, where=np.isfinite(qd))
    speed = max(float(np.max(largest * weights, initial=0.0)), 1e-12 * L)
    return speed / weights


def _breakpoints(mech) -> list[float]:
    return [b for el in mech.drivers
            for b in el.time_law().breakpoints()]


def _resolve(job: Job, k: int, start: np.ndarray, redundant: bool):
    """The backend's Positions at steps k… from ``start`` at step k (with its rates if it
    gives them)."""
    return job.backend.solve_positions(job.mech, job.times[k:], start, job.solver,
                                       redundant=redundant, rates=job.backend.gives_rates)


def motion(job: Job, redundant: bool, accelerations: bool = True, singular_ok: bool = True):
    """(q, qd, qdd) on the branch the mechanism starts on (see the module's doc).

    Positions come from the backend, rates from it too if it gives them (else from the
    native pass); steps where the velocities jump are solved again.
    singular_ok: steps exactly at a singular position get interpolated rates (with a
    warning); False: they raise a SolverError (force analyses).
    """
    mech, t = job.mech, job.times
    # the rates are wanted here whatever the outputs (the branch is followed on them): the
    # backend's, as for the parts solved again (``_resolve``), not a native pass besides
    q, found = positions(job, redundant, check=False, partial=True, with_rates=True)
    solved = found.solved
    own = found if found.qd is not None else None       # the backend's rates, if any
    breakpoints = _breakpoints(mech)
    verified: set[int] = set()
    resolves = spent = 0              # re-solves, and the position solves they took
    # Cq at every step is kept from the rates' evaluation when the condition numbers are
    # wanted at every step (a short run): evaluated once, not again for them
    keep = len(t) <= condition_samples(mech)
    while True:
        job.stage = "computing velocities and following the branch"
        tk, qk = t[:solved], q[:solved]
        qd, qdd, residual, *kept = rates(job, tk, qk, redundant, own, with_jacobian=keep)
        jacobian = kept[0] if kept else None
        check_residual(mech, tk, qk, job, residual)
        singular = ~continuity.finite_rows(qd, qdd)
        unwrapped = _unwrap(mech, tk, q, qd, solved)
        if unwrapped is not q:       # whole turns taken out: Cq at qk is not Cq at q
            q, jacobian = unwrapped, None
        if singular[0] or (singular.any() and not singular_ok):
            raise singular_error(job, int(np.argmax(singular)))
        scale = _scales(mech, qd)
        defect = continuity.continuity_defect(tk, qd, qdd, scale, breakpoints)
        k = _first_jump(defect, singular, verified)
        while k is not None:         # numerically singular steps: their rates are round-off
            near = [i for i in (k - 1, k) if i > 0 and not singular[i]]
            at = [i for i, c in zip(near, rank.condition_numbers(
                mech, tk[near], qk[near], None if jacobian is None else jacobian[near]))
                  if c > SINGULAR]
            if not at:
                break
            singular[at] = True
            qd[at] = qdd[at] = np.nan
            k = _first_jump(defect, singular, verified)
        if k is None:
            if solved < len(t):
                raise position_failure(job, replace(found, q=q, solved=solved))
            break
        j = k - 1
        while singular[j]:
            j -= 1
        spent += len(t) - k
        if resolves == MAX_RESOLVES or spent > RESOLVE_WORK * len(t) + RESOLVE_FLOOR:
            raise _keeps_switching(job, k, resolves, spent)
        h = t[k] - t[j]
        start = q[j] + h * qd[j] + 0.5 * h * h * qdd[j]
        part_found = _resolve(job, k, start, redundant)
        part, part_solved = part_found.q, part_found.solved
        if part_solved:
            part = _unturn(mech, t[k:k + part_solved], part, part_solved, start)
        resolves += 1
        verified.add(k)
        verdict = _compare(job, q, qd, qdd, j, k, part[0], scale, redundant) if part_solved \
            else "worse"
        j0, k1 = max(0, j - 2), min(k + 2, solved - 1)
        if verdict != "better" and not singular[j0:k1 + 1].any():
            # the predictor found no other branch: track the branch closely instead (not
            # through a singular step, where small steps cannot choose the branch)
            spent += (k1 - j0) * SUBSTEPS
            tracked = _track(job, j0, k1, q[j0], redundant)
            if tracked is not None:
                differs = np.nonzero(np.max(np.abs(tracked - q[j0:j0 + len(tracked)]),
                                            axis=1) > 1e-8 * mech.scale())[0]
                if differs.size:     # the switch happened at step f: go on from there
                    k = j0 + int(differs[0])
                    spent += len(t) - k
                    part_found = _resolve(job, k, tracked[differs[0]], redundant)
                    part, part_solved = part_found.q, part_found.solved
                    verdict = "better" if part_solved else "worse"
        if verdict == "worse" or (verdict == "same" and k + part_solved <= solved):
            continue                 # no switch (a coarse grid), or no better branch found
        q = q.copy()
        q[k:] = part
        if own is not None:
            own = _joined(own, k, part_found, len(t))
        solved, found = k + part_solved, part_found
    job.info["branch_resolves"] = resolves
    if singular.any() and not singular_ok:     # numerically singular steps, found above
        raise singular_error(job, int(np.argmax(singular)))
    if singular.any():
        qd, qdd = _interpolate_singular(t, qd, qdd, singular)
        times = ", ".join(f"{t[i]:.6g}" for i in np.nonzero(singular)[0][:5])
        warn(job, f"at t = {times} s the mechanism is exactly at a singular position (a "
                  "change point, where the constraints do not fix the velocities): it goes "
                  "on along the branch it was on, and the velocities and accelerations "
                  "there are interpolated from the neighbouring steps (error of order "
                  "(ω dt)⁴).", ConditionWarning)
    near = np.nonzero(_spikes(defect) | _with_neighbours(singular))[0]
    _warn_ill_conditioned(job, q, singular, near, jacobian)
    return q, qd, (qdd if accelerations else None)


def _joined(own, k: int, part, n: int):
    """The backend's rates of steps before k, then those of ``part`` (from step k on); None
    when the part has none."""
    if part.qd is None:
        return None
    joined = replace(own, qd=own.qd.copy(), qdd=own.qdd.copy())
    joined.qd[k:], joined.qdd[k:] = part.qd[:n - k], part.qdd[:n - k]
    return joined


def _keeps_switching(job: Job, k: int, resolves: int, spent: int) -> SolverError:
    """The error when following the branch takes more re-solves, or more position solves,
    than a run allows (the work of a run stays bounded)."""
    t = job.times
    if resolves == MAX_RESOLVES:
        much = f"{resolves} steps solved again already"
    else:
        much = (f"solving it again would take {spent:,} position solves, more than "
                f"{RESOLVE_WORK} times the run")
    motion = f" {motion_per_step(job)}." if job.motion else ""
    return SolverError(
        f"at t = {t[k]:.6g} s the mechanism keeps switching branch near singular positions "
        f"({much}).{motion} Use more steps, so the actuators move less per step, or end the "
        "interval before this time.", time=float(t[k]), step=k // job.every)


def _unwrap(mech, t, q, qd, solved):
    """q with angles that jumped by whole turns at a step (Newton at a singular position)
    brought back, when the constraints still hold after it (they are 2π-periodic in the
    angles of joints, not in those of actuators or transmissions)."""
    turns = continuity.turns_jumped(t, q[:solved], qd, len(mech.solids))
    if not turns.any():
        return q
    out = q.copy()
    out[:solved, ANGLES] -= 2 * np.pi * np.cumsum(turns, axis=0)
    before = np.max(np.abs(native.residuals(mech, t, q[:solved])))
    after = np.max(np.abs(native.residuals(mech, t, out[:solved])))
    return out if after <= max(before, 1e-12 * mech.scale()) * 10 else q


def _track(job: Job, j0: int, k1: int, start, redundant: bool, count: int = SUBSTEPS):
    """Configurations at steps j0…k1 reached from step j0 in ``count`` backend steps per
    step (Newton then follows the branch closely), or None if the backend fails."""
    times = np.linspace(job.times[j0], job.times[k1], (k1 - j0) * count + 1)
    fine = job.backend.solve_positions(job.mech, times, start, job.solver, redundant=redundant)
    return fine.q[::count] if fine.solved == len(times) else None


def _unturn(mech, t, part, solved, start):
    """``part`` with whole turns removed from its angles so that it starts nearest
    ``start`` (where the constraints still hold after it)."""
    turns = continuity.whole_turns(mech, float(t[0]), part[0], start)
    if not turns.any():
        return part
    out = part.copy()
    out[:, ANGLES] -= 2 * np.pi * turns
    return out



def _compare(job, q, qd, qdd, j, k, candidate, scale, redundant) -> str:
    """'same' (q[k] again), 'better' or 'worse': how ``candidate`` at step k continues the
    motion of step j, against q[k]."""
    mech, t = job.mech, job.times
    if np.max(np.abs(candidate - q[k])) <= 1e-8 * mech.scale():
        return "same"
    with np.errstate(all="ignore"):
        new_qd, new_qdd, _ = native.rates(mech, t[[k]], candidate[None], True, redundant)
    old = _jump(t, qd, qdd, j, k, scale) if k < len(qd) else np.inf
    new = _jump(t, np.r_[qd[:k], new_qd], np.r_[qdd[:k], new_qdd], j, k, scale)
    return "better" if new <= min(JUMP, 0.1 * old) else "worse"


def _spikes(defect) -> np.ndarray:
    """Steps whose defect stands out: above JUMP, or SPIKE times the median of the 17
    steps around it (a smooth motion changes its defect gradually, a switch does not)."""
    out = defect > JUMP
    candidates = np.nonzero((defect > SPIKE_FLOOR) & ~out)[0]
    if candidates.size:
        finite = np.where(np.isfinite(defect), defect, 0.0)
        windows = np.lib.stride_tricks.sliding_window_view(np.pad(finite, 8, mode="edge"), 17)
        background = np.median(windows[candidates], axis=1)
        out[candidates] = defect[candidates] > SPIKE * background
    return out


def _with_neighbours(mask: np.ndarray) -> np.ndarray:
    """m_k | m_{k−1} | m_{k+1}: the steps marked and those next to them (any length)."""
    out = mask.copy()
    out[1:] |= mask[:-1]
    out[:-1] |= mask[1:]
    return out


def _first_jump(defect, singular, verified) -> int | None:
    """The first step whose velocities jump (or that follows a singular step)."""
    for k in np.nonzero(_spikes(defect) | np.r_[False, singular[:-1]])[0]:
        k = int(k)
        if k not in verified and not singular[k]:
            return k
    return None


def _jump(t, qd, qdd, j, k, scale) -> float:
    """Velocity jump from step j to k beyond the trapezoid rule on the accelerations (scaled)."""
    h = t[k] - t[j]
    jump = qd[k] - qd[j] - h * (qdd[k] + qdd[j]) / 2
    value = float(np.max(np.abs(jump) / scale))
    return value if np.isfinite(value) else np.inf


def _interpolate_singular(t, qd, qdd, singular):
    """Rates at singular steps from the regular steps around them (cubic through 4 steps)."""
    qd, qdd = qd.copy(), qdd.copy()
    good = np.nonzero(~singular)[0]
    for k in np.nonzero(singular)[0]:
        near = good[np.argsort(np.abs(good - k))[:4]]
        near.sort()
        for values in (qd, qdd):
            coefficients = np.polyfit(t[near] - t[k], values[near], len(near) - 1)
            values[k] = coefficients[-1]
    return qd, qdd


def condition_samples(mech) -> int:
    """Steps of a run whose condition numbers are computed (equally spaced; an SVD costs
    ~nq³: fewer for large mechanisms)."""
    return int(min(max(2e7 / max(1, mech.nq) ** 3, 1), CONDITION_SAMPLES))


def _warn_ill_conditioned(job: Job, q, singular, near=(), jacobian=None) -> None:
    """Warn when the constraint Jacobian is ill-conditioned somewhere: at sampled steps,
    and at the steps ``near`` singular positions or velocity jumps. ``jacobian``: Cq at
    every step of q when already evaluated (else evaluated at the steps sampled)."""
    mech, t = job.mech, job.times
    tolerance = job.solver.tolerance
    if mech.n_equations == 0:
        return
    samples = condition_samples(mech)
    if len(t) <= samples and not singular.any():     # every step: no copies of them
        i, worst = rank.largest_condition(mech, t, q, jacobian)
        steps = np.arange(len(t))
    else:
        steps = np.unique(np.r_[np.linspace(0, len(t) - 1, min(len(t), samples)).astype(int),
                                np.asarray(near, dtype=int)[:samples]])
        steps = steps[~singular[steps]]
        i, worst = rank.largest_condition(mech, t[steps], q[steps],
                                          None if jacobian is None else jacobian[steps])
    job.info["max_condition_number"] = worst
    # well-conditioned large mechanisms (long chains) still have condition numbers that
    # grow with their size: the threshold grows as √(coordinates / 12)
    if worst > CONDITION_WARNING * max(1.0, mech.nq / 12) ** 0.5:
        warn(job, f"the constraint Jacobian is ill-conditioned near t = {t[steps[i]]:.6g} s "
                  f"(condition number {worst:.2g}): the mechanism passes close to a singular "
                  f"position, and velocities, accelerations and forces there may carry "
                  f"relative errors of order {worst * worst * tolerance:.0e} (condition "
                  f"number² × the position tolerance {tolerance:g}).", ConditionWarning)

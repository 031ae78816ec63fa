"""Why a position solve failed, said in the mechanism's terms: the loop that cannot close,
the constraints that contradict each other, the dead point, or Newton's divergence."""
from __future__ import annotations

from ..backend import Positions
from ..errors import SolverError
from . import closest, loops, native, rank
from .job import Job


def position_failure(job: Job, found: Positions) -> SolverError:
    """The error for the backend's solver stopping at step ``found.solved``, with a diagnosis.

    A least-squares solve at the failing time (native, for the message only) tells whether
    the constraints can hold there. If they cannot, after the previous step did: the
    motion went through a limit position, where the Jacobian is singular (dead point).
    """
    mech, times, q, solved = job.mech, job.times, found.q, found.solved
    t = float(times[solved])
    start = q[solved - 1] if solved > 0 else found.last
    said = f"{job.backend.label} said: {found.error}"
    left, _, _ = closest.closest_violation(mech, t, start)
    # Newton aims at tolerance × L: what the closest configuration leaves above 1000 times
    # that cannot be closed
    can_hold = 1e3 * job.solver.tolerance * mech.scale()
    worst = [w for w in native.worst_elements(mech, left, len(mech.constraints))
             if w[1] > can_hold]
    # actuators and fixed links can always hold on their own: name the joints, if any
    setters = {f"'{e.name}' ({e.type})" for e in mech.constraints
               if e.drives or e.grounds}
    if any(name not in setters for name, _ in worst):
        worst = [w for w in worst if w[0] not in setters]
    violated = ", ".join(f"{name} by {r:.3g}" for name, r in worst)
    drivers = ", ".join(f"'{e.name}'" for e in mech.drivers)
    elements = tuple(n for n, _ in worst)
    disagreement, among = rank.contradiction(mech, t, start)
    step = _step_text(job, solved)
    if worst and disagreement > can_hold:
        since = (f"at t = {t:.6g} s" if solved == 0 else
                 f"from t = {float(times[solved - 1]):.6g} s to t = {t:.6g} s")
        names = ", ".join(f"'{n}'" for n in among)
        concerned = [e for e in mech.constraints if e.name in among]
        extra = rank.culprit(mech, t, start, among, disagreement)
        bar = loops.bar_of(mech, extra) if extra is not None else None
        if bar is not None:           # the extra bar: the last one the file adds
            solid, concerned = bar
            which = (f" Without '{extra.name}' the others agree: "
                     f"{mech.solids[solid].name}, held by "
                     f"{' and '.join(repr(e.name) for e in concerned)}, is an extra bar that "
                     f"does not fit: remove it, or give it the length that fits.")
        else:
            which = (f" Without '{extra.name}' the others agree." if extra is not None
                     else "") + (" Remove the extra constraint, or make the laws or the "
                                 "geometry agree.")
        return SolverError(
            f"the constraints of {names} contradict each other {since} ({step}): they are "
            f"redundant (between them they fix a coordinate more than once) and their targets "
            f"disagree by {disagreement:.3g} (m or rad), so no configuration satisfies them "
            f"all.{which} {said}",
            time=t, step=solved // job.every,
            elements=tuple(f"'{e.name}' ({e.type})" for e in concerned))
    if worst and solved == 0:
        by_name = {f"'{el.name}' ({el.type})": el for el in mech.constraints}
        loop = (loops.first_open(mech, t, start, can_hold,
                                 {by_name[name].name: r for name, r in worst})
                or loops.diagnose(mech, [by_name[name] for name in elements], t))
        ours = [w for w in worst if loop is not None and by_name[w[0]].name in loop.elements]
        if ours:                      # the joints of that loop only
            worst = ours
            violated = ", ".join(f"{name} by {r:.3g}" for name, r in worst)
            elements = tuple(n for n, _ in worst)
        return SolverError(
            f"the mechanism cannot be assembled at t = {t:.6g} s: "
            + (f"{loop.text}. " if loop else "")
            + f"The constraints cannot all hold: still violated at the closest configuration: "
              f"{violated}. {said}", time=t, step=0, elements=elements)
    if worst:
        t0 = float(times[solved - 1])
        return SolverError(
            f"between t = {t0:.6g} s and t = {t:.6g} s ({step}) "
            f"the mechanism reached a singular (dead-point) position: the actuator(s) "
            f"{drivers or '(none)'} drive it to a limit position it cannot pass. After it "
            f"the constraints cannot all hold (still violated at the closest "
            f"configuration: {violated}). Drive the mechanism by another member, change the "
            f"law so it stays within the limit, or end the interval before t = {t0:.6g} s. "
            f"{said}", time=t0, step=solved // job.every,
            elements=elements)
    if solved == 0:
        return SolverError(
            f"{job.backend.solver_name} did not converge at t = {t:.6g} s (the assembly): the "
            "constraints can all hold there, but the Newton iteration diverged from the "
            "initial guess. Give the solids x, y, fi closer to an assembled position (angles "
            f"in radians). {said}", time=t, step=0, elements=elements)
    motion = f" ({motion_per_step(job)})" if job.motion else ""
    return SolverError(
        f"{job.backend.solver_name} did not converge at t = {t:.6g} s ({step}){motion}: the "
        "constraints can all hold there, so the Newton iteration diverged near a singular "
        "position. Try more steps, so that the actuators move less per step, or check "
        "whether the mechanism reaches a singular (dead-point) position there. "
        f"{said}", time=t, step=solved // job.every, elements=elements)


def _step_text(job: Job, k: int) -> str:
    """Where step k of the solve grid is, in the user's steps."""
    steps = (len(job.times) - 1) // job.every
    if job.analysis_type.at_start:
        return "the assembly"
    if job.every == 1:
        return f"step {k} of {steps}"
    return f"between steps {k // job.every} and {k // job.every + 1} of {steps}"


def singular_error(job: Job, k: int) -> SolverError:
    """The error for a singular (dead-point) position at step k, where rates are undefined."""
    t = job.times
    drivers = [f"'{e.name}'" for e in job.mech.drivers]
    return SolverError(
        f"at t = {t[k]:.6g} s (step {k}) the mechanism is at a singular (dead-point) "
        f"position: the constraint Jacobian loses rank, so the actuator(s) "
        f"{', '.join(drivers) or '(none)'} cannot drive it through this position and "
        f"velocities{' and reactions' if job.analysis_type.gives_forces else ''} are not "
        "defined. Drive the mechanism by another member, or stop the interval before this "
        "time.", time=float(t[k]), step=k)


def motion_per_step(job: Job) -> str:
    """"'motor' moves 1.8 rad per step, solved in 8 sub-steps": the fastest actuator's
    motion per user step, where the plan solved each step in sub-steps (``job.motion``)."""
    name, moved, unit = job.motion
    return f"'{name}' moves {moved:.3g} {unit} per step, solved in {job.every} sub-steps"

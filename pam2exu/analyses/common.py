"""What all analyses share: settings, output columns, Exudyn positions, self-checks."""
from __future__ import annotations

import os
import sys
import time as _time
import warnings
from dataclasses import dataclass, field, replace

import numpy as np

from ..elements import ACCELERATION, FORCE, POSITION, VELOCITY, Var
from .. import registry
from ..errors import ModelError, Problem, RedundancyWarning, SolverError, TranslationError
from ..kinematics import ANGLES, State, column
from ..backend import Backend, Positions
from ..model import Model, load
from ..model.solid import SOLID_OUTPUTS
from ..results import Results, select_columns
from ..results.info import RunInfo
from . import grid, loops, native

#: constraint residual above this (× the length scale) means a wrong translation
RESIDUAL_TOLERANCE = 1e-8


@dataclass
class Job:
    """One analysis of one mechanism, with everything decided before the numerics.

    ``times`` is the grid positions are solved on; the results keep every ``every``-th row
    of it (the user's times, ``grid.Plan``).
    """

    mech: object
    analysis: str
    times: np.ndarray
    columns: list[str]
    units: dict[str, str]
    levels: set[str]
    #: what solves the positions, and its settings (``backend.Settings``)
    backend: Backend
    solver: object
    warnings: list[str] = field(default_factory=list)
    info: RunInfo = field(default_factory=RunInfo)
    every: int = 1
    #: (actuator, its largest motion per user step, unit), for messages
    motion: tuple | None = None
    #: what the analysis is doing, for the message of an unexpected failure
    stage: str = "checking the analysis settings"


def available_columns(mech, analysis: str) -> dict[str, Var]:
    """Every column the analysis can produce, in order: solids, then elements."""
    kind = registry.ANALYSES[analysis]
    out = {}
    for s in mech.solids:
        for var in SOLID_OUTPUTS:
            if var.level in kind.levels:
                out[f"{s.name}.{var.name}"] = var
    if kind.at_start:
        return out
    for el in mech.elements:
        for var in el.outputs:
            if var.level in kind.levels:
                out[f"{el.name}.{var.name}"] = var
    return out


def prepare(model, analysis=None, t_end=None, steps=None, outputs=None, solver=None,
            backend=None) -> Job:
    """Load and validate the model, apply the overrides, choose the columns and the backend
    (``solver``: the backend's settings, default ``backend.Settings()``)."""
    if not isinstance(model, Model):
        model = load(model)
    settings = replace(model.analysis, **{k: v for k, v in
                                          dict(type=analysis, t_end=t_end, steps=steps,
                                               outputs=outputs, backend=backend).items()
                                          if v is not None})
    problems = [Problem("[analysis]", m) for m in settings.problems()]
    if problems:
        raise ModelError(problems, model.source)
    mech = model.mechanism()
    kind = registry.ANALYSES[settings.type]
    available = available_columns(mech, kind.name)
    try:
        columns = select_columns(list(available), settings.outputs)
    except ModelError as exc:
        raise ModelError(exc.problems, model.source) from None
    if kind.at_start:
        plan = grid.Plan(np.zeros(1), 1, None)
        grid.check_laws(mech, plan.times)        # the actuators' values at t = 0
    else:
        plan = grid.plan(mech, settings.t_end, settings.steps, len(columns))
    levels = {available[c].level for c in columns} | {POSITION}
    if FORCE in levels and ACCELERATION in kind.levels:
        levels.add(ACCELERATION)                 # the inertia forces need qdd
    if ACCELERATION in levels:
        levels.add(VELOCITY)
    engine = registry.BACKENDS[settings.backend].create()
    job = Job(mech, kind.name, plan.times, columns, {c: available[c].unit for c in columns},
              levels, engine, solver if solver is not None else engine.Settings(),
              every=plan.every, motion=plan.motion)
    if plan.every > 1:
        job.info["substeps"] = plan.every
    return job



def check_mobility(job: Job, q0: np.ndarray, need_driven: bool | None = None) -> native.Mobility:
    """Rank test at the initial guess, before the backend is called (``warn_redundant``
    follows once positions are solved); ``need_driven`` (default: what the analysis
    declares, ``AnalysisType.driven``) raises MobilityError for a DOF not driven."""
    if need_driven is None:
        need_driven = registry.ANALYSES[job.analysis].driven
    native.require_defined(job.mech, float(job.times[0]), q0)
    mob = native.mobility(job.mech, float(job.times[0]), q0)
    job.info.update(dof=mob.dof, redundant_equations=mob.redundant,
                    condition_number=mob.condition)
    if need_driven:
        native.require_driven(job.mech, mob, job.analysis)
    return mob


def warn_redundant(job: Job, q: np.ndarray) -> None:
    """Warn once about redundant constraints, naming the elements of the self-stress found
    at the first solved configuration (where the rank test is exact)."""
    mob = native.mobility(job.mech, float(job.times[0]), q)
    if not mob.redundant or mob.dof:
        return
    names = ", ".join(f"'{n}'" for n in mob.redundant_elements)
    text = (f"{mob.redundant} redundant constraint equation(s) among {names}: positions, "
            f"velocities and accelerations are unique, the reactions of these elements "
            f"are not (they are given as the minimum-norm solution)")
    warn(job, text, RedundancyWarning)


def warn(job: Job, text: str, category) -> None:
    """Keep a warning with the results and issue it at the caller's line outside pam2exu."""
    job.warnings.append(text)
    package = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    frame, level = sys._getframe(1), 2
    while frame is not None and frame.f_code.co_filename.startswith(package):
        frame, level = frame.f_back, level + 1
    warnings.warn(text, category, stacklevel=level)


def positions(job: Job, redundant: bool, anchor_stiffness: float = 0.0,
              check: bool = True, partial: bool = False):
    """Positions at every time from the backend; raises SolverError on failure.

    ``check=False`` leaves the residual check to ``velocities`` (which has the residual).
    ``partial``: a failure after the first step is not raised; returns (q, Positions) with
    the rows from ``Positions.solved`` on NaN (``branch.motion`` may still repair it).
    """
    mech = job.mech
    clock = _time.perf_counter()
    job.stage = f"solving the positions with {job.backend.solver_name}"
    start = assemble(job, redundant, anchor_stiffness)
    if len(job.times) == 1:                      # the assembly itself
        found = Positions(start[None], 1, None, start)
    else:
        found = job.backend.solve_positions(mech, job.times, start, job.solver,
                                            redundant=redundant)
        if found.solved:         # step 0 is the assembly (Newton moved it by round-off)
            found.q[0] = start
    job.info["exudyn_seconds"] = _time.perf_counter() - clock

    if found.solved < len(job.times) and not (partial and found.solved > 0):
        raise _position_failure(job, found)
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
        raise _position_failure(job, found)
    q0 = found.q[0].copy()
    q0[ANGLES] -= 2 * np.pi * native.whole_turns(mech, float(job.times[0]), q0, guess)
    return q0


def _position_failure(job: Job, found: Positions) -> SolverError:
    """The error for the backend's solver stopping at step ``found.solved``, with a diagnosis.

    A least-squares solve at the failing time (native, for the message only) tells whether
    the constraints can hold there. If they cannot, after the previous step did: the
    motion went through a limit position, where the Jacobian is singular (dead point).
    """
    mech, times, q, solved = job.mech, job.times, found.q, found.solved
    t = float(times[solved])
    start = q[solved - 1] if solved > 0 else found.last
    said = f"{job.backend.label} said: {found.error}"
    left, _ = native.closest_violation(mech, t, start)
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
    disagreement, among = native.contradiction(mech, t, start)
    step = _step_text(job, solved)
    if worst and disagreement > can_hold:
        since = (f"at t = {t:.6g} s" if solved == 0 else
                 f"from t = {float(times[solved - 1]):.6g} s to t = {t:.6g} s")
        names = ", ".join(f"'{n}'" for n in among)
        concerned = [e for e in mech.constraints if e.name in among]
        extra = native.culprit(mech, t, start, among, disagreement)
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
        loop = loops.diagnose(mech, [by_name[name] for name in elements], t)
        if loop is not None:          # the joints of that loop only
            worst = [w for w in worst if by_name[w[0]].name in loop.elements]
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
    motion = ""
    if job.motion:
        name, moved, unit = job.motion
        motion = (f" ('{name}' moves {moved:.3g} {unit} per step, solved in {job.every} "
                  "sub-steps)")
    return SolverError(
        f"{job.backend.solver_name} did not converge at t = {t:.6g} s ({step}){motion}: the "
        "constraints can all hold there, so the Newton iteration diverged near a singular "
        "position. Try more steps, so that the actuators move less per step, or check "
        "whether the mechanism reaches a singular (dead-point) position there. "
        f"{said}", time=t, step=solved // job.every, elements=elements)


def _step_text(job: Job, k: int) -> str:
    """Where step k of the solve grid is, in the user's steps."""
    steps = (len(job.times) - 1) // job.every
    if registry.ANALYSES[job.analysis].at_start:
        return "the assembly"
    if job.every == 1:
        return f"step {k} of {steps}"
    return f"between steps {k // job.every} and {k // job.every + 1} of {steps}"


def check_residual(mech, t, q, job: Job | None = None, res: np.ndarray | None = None) -> None:
    """Self-check: pam2exu's own constraint equations hold at Exudyn's configuration.

    res: the residual C(q, t) when already computed.
    """
    if mech.n_equations == 0:
        return
    if res is None:
        res = native.residuals(mech, t, q)
    worst = float(np.max(np.abs(res)))
    if job is not None:
        job.info["max_residual"] = worst
    # a looser Newton tolerance leaves a larger residual: not a translation error
    tolerance = job.solver.tolerance if job is not None else 0.0
    tol = max(RESIDUAL_TOLERANCE, 100 * tolerance) * mech.scale()
    if worst > tol:
        over = np.max(np.abs(res), axis=1) > tol
        first = int(np.argmax(over))
        if job is not None and first > 0:
            # redundant constraints whose targets part: the solver (told to ignore the
            # singular Jacobian) can stop on a configuration that violates them
            disagreement, _ = native.contradiction(mech, float(t[first]), q[first - 1])
            if disagreement > tol:
                raise _position_failure(job, Positions(
                    q, first, "no error (it stopped on a configuration that violates the "
                              "constraints)", q[first - 1]))
        k = int(np.argmax(np.max(np.abs(res), axis=1)))
        name, value = native.worst_elements(mech, res[k], 1)[0]
        raise TranslationError(
            f"internal error: at t = {t[k]:.6g} s Exudyn's configuration violates pam2exu's "
            f"equations of element {name} by {value:.3g} (tolerance {tol:.1g}): the Exudyn "
            "translation of this element is wrong. Please report it with the model file.")


def singular_error(job: Job, k: int) -> SolverError:
    """The error for a singular (dead-point) position at step k, where rates are undefined."""
    t = job.times
    drivers = [f"'{e.name}'" for e in job.mech.drivers]
    return SolverError(
        f"at t = {t[k]:.6g} s (step {k}) the mechanism is at a singular (dead-point) "
        f"position: the constraint Jacobian loses rank, so the actuator(s) "
        f"{', '.join(drivers) or '(none)'} cannot drive it through this position and "
        f"velocities{'' if job.analysis == 'kinematic' else ' and reactions'} are not "
        "defined. Drive the mechanism by another member, or stop the interval before this "
        "time.", time=float(t[k]), step=k)


def velocities(job: Job, q: np.ndarray, redundant: bool):
    """(qd, qdd) from the native pass, after the residual check of Exudyn's positions;
    SolverError at a singular position (``branch.motion`` follows the branch instead)."""
    mech, t = job.mech, job.times
    accelerations = ACCELERATION in job.levels
    job.stage = "computing velocities and accelerations"
    with np.errstate(all="ignore"):
        qd, qdd, residual = native.rates(mech, t, q, accelerations, redundant)
    check_residual(mech, t, q, job, residual)
    bad = ~np.isfinite(qd).all(axis=1)
    if qdd is not None:
        bad |= ~np.isfinite(qdd).all(axis=1)
    if bad.any():
        raise singular_error(job, min(int(np.argmax(bad)), native.first_singular(mech, t, q)))
    return qd, qdd


def collect(job: Job, q, qd=None, qdd=None, extra: dict | None = None) -> Results:
    """The Results table of the chosen columns, on the user's times (rows of the solve grid).

    The last guard of every analysis: a value that is not finite is a SolverError naming
    the columns and the first time, never a result.
    """
    job.stage = "collecting the result columns"
    mech, rows = job.mech, slice(None, None, job.every)
    t = job.times[rows]
    q, qd, qdd = (None if a is None else a[rows] for a in (q, qd, qdd))
    extra = {k: v[rows] for k, v in (extra or {}).items()}
    wanted = set(job.columns)
    values: dict[str, np.ndarray] = {}
    for i, s in enumerate(mech.solids):
        for k, var in enumerate(SOLID_OUTPUTS):
            name = f"{s.name}.{var.name}"
            if name in wanted:
                source = (q, qd, qdd)[k // 3]
                values[name] = source[:, column(i, k % 3)]
    st = State(t, q, qd if VELOCITY in job.levels else None)
    for el in mech.elements:
        names = {v.name for v in el.outputs if f"{el.name}.{v.name}" in wanted}
        if names:
            for var, v in el.compute(st, names).items():
                if var in names:
                    values[f"{el.name}.{var}"] = v
    values.update(extra)
    values = {k: v + 0.0 for k, v in values.items()}    # no negative zeros in tables
    check_finite(job, t, values)
    return Results(t, {c: values[c] for c in job.columns}, job.units, job.analysis,
                   mech.name, job.warnings, job.info)


def check_finite(job: Job, t: np.ndarray, values: dict[str, np.ndarray]) -> None:
    """SolverError when a column has a value that is not finite (NaN, ±inf)."""
    bad = {name: np.nonzero(~np.isfinite(v))[0] for name, v in values.items()}
    bad = {name: rows for name, rows in bad.items() if rows.size}
    if not bad:
        return
    k = min(int(rows[0]) for rows in bad.values())
    names = [name for name, rows in bad.items() if rows[0] == k]
    shown = ", ".join(names[:8]) + (f" and {len(names) - 8} more" if len(names) > 8 else "")
    raise SolverError(
        f"the {job.analysis} analysis gave values that are not numbers (NaN or infinite) "
        f"first at t = {t[k]:.6g} s (row {k}), in {shown}"
        + (f"; {len(bad)} columns in all" if len(bad) > len(names) else "")
        + ". The mechanism is at or near a position where these are not defined (a "
          "singular position, two points of an element that coincide): end the interval "
          "before this time, or change the model so it avoids that position.",
        time=float(t[k]), step=k)


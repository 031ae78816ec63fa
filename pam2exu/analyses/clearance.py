"""The clearance analysis (shared/spec/clearance.md, docs/clearance.md): ``clearance``.

It follows the clearance of least norm of an over-constrained mechanism whose
``[[variation]]`` dimensions and command vary, with its conditions of applicability
(``require_applicable``, ``require_strict_minimum``) and the recommended warning against
the first-order estimate (``first_order``). ``Closures`` evaluates the closure
F(u(t), j, q, r(t)) = C(q, t) + F_j j of a mechanism at one time: every constraint element's
rows (``Element.constraint``, or ``Element.clearance_constraint`` where the element has
``clearance = true``), with the points and lines of the ``[[variation]]`` entries at u(t),
and F_j from the clearance elements' ``clearance_terms``. The mathematics of the least-norm
clearance it feeds is ``least_norm``.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..errors import MobilityError, ModelError, SolverError
from ..kinematics import PER_SOLID, State
from .closures import Closures
from .job import Job, check_mobility, collect
from .least_norm import (RANK, Applicability, Closure, Followed, Stop, applicability,
                         follow, lagrange_jacobian, lagrange_jacobian_rows, newton_rows, split,
                         step_by_step, strict_minimum_rows)
from . import native
from .positions import GUESS_STIFFNESS, assemble, positions


def clearance(job: Job):
    """x, y, fi of every solid and the parameters of every clearance joint over the
    interval (shared/spec/clearance.md): the clearance of least norm as the dimensions of
    the ``[[variation]]`` entries and the command vary.

    From the nominal assembly (j = 0, λ = 0, by the backend), the fixed deviations of the
    ``[[variation]]`` entries reached along the straight path of dimensions (``as_made``),
    then the slides' ODE through the times of the grid, each one corrected by Newton on the Lagrange conditions
    (``least_norm.follow``). The conditions of applicability are checked at the start
    (``require_applicable``), the strict minimum at every output row
    (``require_strict_minimum``).
    """
    mech = job.mech
    mob = check_mobility(job, mech.initial_q(), need_driven=False)
    job.warnings.extend(str(p) for p in mech.model.warnings())
    # an undriven degree of freedom: the assembly nearest the guess (the guess springs of
    # ``assembly``), so that condition (ii) below names the free solids
    q0 = assemble(job, redundant=mob.redundant > 0,
                  anchor_stiffness=GUESS_STIFFNESS if mob.dof else 0.0)
    closures = Closures(mech, q0)
    p, nq, m = closures.p, closures.nq, closures.m
    t0 = float(job.times[0])
    # at the nominal dimensions (the fixed deviations not yet reached: ``as_made``)
    require_applicable(closures, closures.evaluate(t0, q0, np.zeros(m), reached=0.0), t0)
    if not p and not closures.varied:
        return kinematic_closure(job, closures)
    job.info["clearance_method"] = FOLLOWED
    job.stage = "following the clearance of least norm (the slides' ODE)"
    y0 = np.r_[np.zeros(p), q0, np.zeros(m)]
    if closures.has_fixed:
        job.stage = "following the clearance of least norm to the dimensions as made (t = 0)"
        y0 = as_made(closures, t0, y0)
    if job.options["method"] == NEWTON:
        job.info["clearance_method"] = BY_NEWTON
        y, ok, stop = step_by_step_rows(closures, job.times, y0)
    else:
        y, ok, stop = follow(closures.evaluate, None, job.times, y0, p, nq,
                             rate=closures.evaluate_rate, correct=corrector(closures))
    job.stage = "checking the clearance is a strict minimum at every row"
    rows = range(0, len(job.times), job.every)
    checked = np.array([k for k in rows if ok[k]], dtype=int)
    lost = _first_lost(closures, job.times[checked], y[checked])
    if lost is not None:
        k = int(checked[lost])
        q, lam = y[k, p:p + nq], y[k, p + nq:]
        t = float(job.times[k])
        try:
            require_strict_minimum(closures.evaluate(t, q, lam), t, source(closures),
                                   closures)
        except SolverError as error:
            raise _with_rows(error, job, closures, y, k) from None
    if stop is not None:
        raise _with_rows(not_followed(closures, job, stop), job, closures, y,
                         int(np.argmin(ok)))
    if p:
        _warn_far_from_first_order(job, closures, y[:, :p], list(rows), mob.redundant > 0)
    return collect(job, y[:, p:p + nq], extra=closures.columns(y[:, :p]))


#: ``RunInfo.clearance_method`` of a run that follows the least-norm clearance
FOLLOWED = "the slides' ODE, Newton on the Lagrange conditions at every row"
#: the ``method`` option's value (``registry.OPTIONS``) of Newton at every row
NEWTON = "newton"
#: ``RunInfo.clearance_method`` of a run with ``method = "newton"``
BY_NEWTON = "Newton on the Lagrange conditions at every row, from the previous row's solution"
#: ``RunInfo.clearance_method`` of a run with no clearance joint and no varied anchor
KINEMATIC = ("no clearance joint and no varied anchor: no clearance (no column), the "
             "positions those of the kinematic analysis (the backend's, refined by Newton on "
             "the closure)")


def kinematic_closure(job: Job, closures: "Closures"):
    """The clearance analysis of a mechanism with no clearance joint (p = 0) whose
    ``[[variation]]`` entries move no anchor: the least-norm clearance is empty, λ = 0, and
    the closure C(q, t) = 0 (square and regular, ``require_applicable``) fixes the
    positions: the kinematic ones (the backend's, ``positions``), each row refined by
    Newton on C = 0 as ``least_norm.newton`` refines the ODE's; the condition (i) at every
    row (σ_min/σ_max of F_q, vectorised) as ``require_strict_minimum`` checks it."""
    job.info["clearance_method"] = KINEMATIC
    q = positions(job, redundant=False)
    q[1:] = refine(closures.mech, job.times[1:], q[1:])   # row 0: the assembly, as follow's
    job.stage = "checking the clearance is a strict minimum at every row"
    rows = np.arange(0, len(job.times), job.every)
    jacobian = native.equations(closures.mech, State(job.times[rows], q[rows])).jacobian
    s = np.linalg.svd(jacobian, compute_uv=False)
    lost = np.nonzero(s[:, -1] <= RANK * s[:, 0])[0]
    if lost.size:
        k = int(rows[lost[0]])
        t = float(job.times[k])
        try:
            require_strict_minimum(closures.evaluate(t, q[k], np.zeros(closures.m)), t,
                                   source(closures), closures)
        except SolverError as error:
            raise _with_rows(error, job, closures, np.asarray(q), k) from None
    return collect(job, q, extra={})


def step_by_step_rows(closures: Closures, times: np.ndarray, y0: np.ndarray) -> Followed:
    """``least_norm.step_by_step`` (``method = "newton"``) as ``follow`` reports it: the
    rows up to the first where Newton does not converge (``Stop.NEWTON`` there, NaN
    after)."""
    y, ok = step_by_step(closures.evaluate, times, y0, closures.p, closures.nq)
    failed = np.nonzero(~ok)[0]
    if not failed.size:
        return Followed(y, ok, None)
    row = int(failed[0])
    stop = Stop(float(times[row]), Stop.NEWTON, y[row - 1])
    y[row:], ok[row:] = np.nan, False
    return Followed(y, ok, stop)


def refine(mech, times: np.ndarray, q: np.ndarray, tolerance: float = 1e-13,
           iterations: int = 30) -> np.ndarray:
    """q with every row refined by Newton on C(q, t) = 0, C square (all rows at once), until
    each row's step is below ``tolerance`` (relative to 1 + |q|), as ``least_norm.newton``."""
    q = np.array(q, dtype=float)
    active = np.arange(len(times))
    for _ in range(iterations):
        eq = native.equations(mech, State(times[active], q[active]))
        step = np.linalg.solve(eq.jacobian, -eq.residual[..., None])[..., 0]
        q[active] += step
        done = (np.max(np.abs(step), axis=1)
                <= tolerance * (1.0 + np.max(np.abs(q[active]), axis=1)))
        active = active[~done]
        if not active.size:
            break
    return q


def corrector(closures: Closures, t0: float | None = None):
    """``follow``'s ``correct``: Newton on h = 0 at every row reached at once
    (``least_norm.newton_rows``), along the time, or with ``t0`` along the straight path
    u0 + s δ at t0 (the rows' "times" are then s)."""
    def rows(times, q, lam):
        if t0 is None:
            return closures.evaluate_rows(times, q, lam)
        return _path_rows(closures, t0, times, q, lam)

    def correct(times, ys):
        return newton_rows(rows, closures.Fj, times, ys, closures.p, closures.nq)
    return correct


def _path_rows(closures: Closures, t0: float, reached: np.ndarray, q, lam):
    """``evaluate_rows`` on the straight path u0 + s δ at t0, one row per s."""
    out = [closures.evaluate_rows(np.array([t0]), q[k:k + 1], lam[k:k + 1], reached=s)
           for k, s in enumerate(reached)]
    return tuple(np.concatenate([o[i] for o in out]) for i in range(3))


#: a row whose conditions ``strict_minimum_rows`` finds within this factor of the limit
#: (RANK) is decided by ``applicability`` itself, one row at a time
MARGIN = 10.0


def _first_lost(closures: Closures, times: np.ndarray, y: np.ndarray) -> int | None:
    """The index of the first row of (times, y) where (i) or the reduced Hessian's condition
    may fail (``require_strict_minimum`` decides), None where every row holds clearly."""
    if not len(times):
        return None
    p, nq = closures.p, closures.nq
    _, Fq, W = closures.evaluate_rows(times, y[:, p:p + nq], y[:, p + nq:])
    ratio, hessian = strict_minimum_rows(closures.Fj, Fq, W)
    near = np.nonzero((ratio <= MARGIN * RANK) | (hessian <= MARGIN * RANK))[0]
    for k in near:
        found = applicability(Closure(np.zeros(closures.m), Fq[k], closures.Fj, W[k]))
        if found.ratio_i <= RANK or found.hessian <= RANK:
            return int(k)
    return None


#: the rows of the straight path u0 + s δ at t = 0 where Newton corrects the clearance
#: followed (s = 0, 1/4, …, 1); the integrator steps as it needs between them
PATH_ROWS = 4
#: an integration step along that path below this fraction of it: a fold (the steps of a
#: smooth path are 10⁻³ to 10⁻¹ of it; towards a fold they halve at every step, down to
#: round-off), where ``as_made`` stops
FOLD_STEP = 1e-7


def as_made(closures: "Closures", t0: float, y0: np.ndarray) -> np.ndarray:
    """y = (j, q, λ) at t0 with the fixed deviations δ of the ``[[variation]]`` entries:
    the slides' ODE along the straight path of dimensions u0 + s δ, s from 0 (the nominal
    assembly y0) to 1, corrected by Newton at ``PATH_ROWS`` + 1 values of s, the clearance a
    strict minimum at each; SolverError (``t=<t0>:``) where the deviations cannot be
    absorbed so."""
    def along(s, q, lam):
        return closures.evaluate(t0, q, lam, reached=s)

    p, nq = closures.p, closures.nq
    path = np.linspace(0.0, 1.0, PATH_ROWS + 1)
    y, ok, stop = follow(along, None, path, y0, p, nq,
                         rate=lambda s, q, lam: closures.evaluate_rate(t0, q, lam, reached=s,
                                                                       along="s"),
                         correct=corrector(closures, t0), min_step=FOLD_STEP)
    for k, s in enumerate(path):
        at, there = (float(s), y[k]) if ok[k] else (stop.time, stop.y)
        found = applicability(along(at, *split(there, p, nq)[1:]))
        if not ok[k] or found.ratio_i <= RANK or found.hessian <= RANK:
            raise SolverError(
                f"t={t0:g}: the clearance of least norm of {source(closures)} cannot absorb "
                f"the fixed deviations of its [[variation]] entries (fixed_dx, fixed_dy, "
                f"fixed_dangle): followed from the nominal assembly along the straight path "
                f"of dimensions u0 + s δ, it stops at s = {at:.4g} (of 0 … 1). There "
                f"{_nearest_failure(found, closures)}. Try clearance = true on another joint "
                f"of the loop, or smaller fixed deviations; no row is kept", time=t0, step=0)
    return y[-1]


def source(closures: "Closures") -> str:
    """The model file, for messages ("the model" when it was built in Python)."""
    return closures.mech.model.source or "the model"


def _with_rows(error: SolverError, job: Job, closures: "Closures", y: np.ndarray,
               end: int) -> SolverError:
    """``error`` with ``partial``: the Results of the rows before index ``end`` of the grid
    (None when there are none)."""
    kept = range(0, end, job.every)
    if len(kept):
        last = kept[-1] + 1
        part = replace(job, times=job.times[:last], warnings=list(job.warnings))
        error.partial = collect(part, y[:last, closures.p:closures.p + closures.nq],
                                extra=closures.columns(y[:last, :closures.p]))
    return error


def not_followed(closures: "Closures", job: Job, stop: Stop) -> SolverError:
    """The SolverError for ``follow`` stopping before the end: where it stopped, how, the
    condition nearest to failing there, and what to try."""
    t, t_end = stop.time, float(job.times[-1])
    j, q, lam = split(stop.y, closures.p, closures.nq)
    found = applicability(closures.evaluate(t, q, lam))
    how = {Stop.SINGULAR: "the integration cannot step past it (the equations of the least "
                          "clearance are singular there: h_y)",
           Stop.WORK: f"the integration took {stop.steps} steps in one output step without "
                      f"reaching the next row, its steps shrinking as the path nears a "
                      f"singular position (the work limit, least_norm.MAX_STEPS)",
           Stop.NEWTON: "the least clearance found by the integration cannot be refined "
                        "there (Newton's method on the Lagrange conditions does not "
                        "converge)"}[stop.cause]
    return SolverError(
        f"t={t:.6g}: the clearance of least norm of {source(closures)} could not be followed "
        f"beyond t = {t:.6g} s (of 0 … {t_end:g} s): {how}. There "
        f"{_nearest_failure(found, closures)}. {TRY} (t_end below {t:.6g} s); {_kept(t)}.",
        time=t,
        step=int(np.ceil(np.searchsorted(job.times, t) / job.every)))


def _nearest_failure(found: Applicability, closures: "Closures | None" = None) -> str:
    """Which condition of the method is nearest to failing, in the designer's words, with
    its number: the smallest of σ_min/σ_max of [F_j F_q] (i), of F_q (ii), and of the
    reduced Hessian's eigenvalue (the contract's item 3)."""
    worst = min((found.ratio_i, "i"), (found.ratio_ii, "ii"), (found.hessian, "3"))[1]
    if worst == "i":
        names = (", ".join(f"'{n}'" for n in loaded_elements(closures, found.self_stress))
                 if closures is not None else "")
        return (f"the joints lock into a new self-stress that the clearances barely take up"
                f"{f' (through {names})' if names else ''}: a singular position of the "
                f"mechanism (condition (i): σ_min/σ_max of [F_j F_q] = {found.ratio_i:.3g})")
    if worst == "ii":
        names = (", ".join(f"'{n}'" for n in free_solids(closures.mech, found.free))
                 if closures is not None else "")
        return (f"the joints and the command nearly stop fixing the positions"
                f"{f' of {names}' if names else ''}: a singular position such as a dead "
                f"centre, where cranks line up with a rod (condition (ii): σ_min/σ_max of "
                f"F_q = {found.ratio_ii:.3g})")
    return (f"the least clearance is close to branching: the minimum followed turns into a "
            f"saddle, usually near a singular position such as a dead centre (smallest "
            f"eigenvalue of the reduced Hessian = {found.hessian:.3g}, condition 3 of a "
            f"strict minimum)")


def first_order(closures: "Closures", t: float, q_nominal: np.ndarray) -> np.ndarray:
    """δj: the least-norm solution of F_j δj + F_q δq = −F(u(t), 0, q_nom(t)) at the
    nominal positions (the contract's first-order estimate of the clearance): h_y at λ = 0
    applied to (0, 0, −F)."""
    c = closures.evaluate(t, q_nominal, np.zeros(closures.m))
    rhs = np.r_[np.zeros(closures.p + closures.nq), -c.F]
    return np.linalg.solve(lagrange_jacobian(c), rhs)[:closures.p]


def first_order_rows(closures: Closures, times: np.ndarray,
                     q_nominal: np.ndarray) -> np.ndarray:
    """``first_order`` at every row (times (n,), q_nominal (n, nq)) at once: (n, p)."""
    C, Fq, W = closures.evaluate_rows(times, q_nominal, np.zeros((len(times), closures.m)))
    rhs = np.concatenate([np.zeros((len(times), closures.p + closures.nq)), -C], axis=1)
    H = lagrange_jacobian_rows(closures.Fj, Fq, W)
    return np.linalg.solve(H, rhs[..., None])[:, :closures.p, 0]


def _warn_far_from_first_order(job, closures, j, rows, redundant):
    """The contract's recommended warning: a clearance column that departs from its
    first-order estimate (``first_order``, at the nominal positions by the backend) by more
    than half its largest magnitude, named with the first time it does."""
    job.stage = "estimating the clearance to first order, at the nominal positions"
    found = job.backend.solve_positions(job.mech, job.times, closures.start.q[0], job.solver,
                                        redundant=redundant)
    if found.solved < len(job.times):
        job.warnings.append(
            "no first-order estimate of the clearance to compare with: the nominal mechanism "
            f"has no position at t = {job.times[found.solved]:.6g} s ({found.error})")
        return
    estimate = first_order_rows(closures, job.times[rows], found.q[rows])
    gap = np.abs(j[rows] - estimate)
    far = gap > 0.5 * np.max(np.abs(j[rows]), axis=0)
    for col in np.nonzero(far.any(axis=0))[0]:
        k = rows[int(np.argmax(far[:, col]))]
        job.warnings.append(
            f"{closures.names[col]} departs from its first-order estimate by "
            f"{gap[rows.index(k), col]:.3g} (more than half its largest magnitude) from "
            f"t = {job.times[k]:.6g} s: the variations are too large for the linear picture, "
            "or a singular position of the nominal mechanism is near (docs/clearance.md, "
            "'When the method applies')")


# ---- when the method applies (shared/spec/clearance.md, "When the method applies") -------

def loaded_elements(closures: Closures, stresses: np.ndarray) -> list[str]:
    """The constraint elements whose rows a self-stress loads (stresses: (m, k), a basis of
    the λ with [F_j F_q]ᵀλ = 0), in element order."""
    size = np.max(np.abs(stresses), axis=1) if stresses.size else np.zeros(closures.m)
    largest = float(np.max(size, initial=0.0))
    return [el.name for el, rows in zip(closures.mech.constraints, closures.mech.rows)
            if largest > 0 and np.max(size[rows]) > RANK * largest]


def free_solids(mech, motions: np.ndarray) -> list[str]:
    """The solids a free motion moves (motions: (nq, k), a basis of the δq with
    F_q δq = 0), in solid order."""
    size = np.max(np.abs(motions), axis=1) if motions.size else np.zeros(mech.nq)
    largest = float(np.max(size, initial=0.0))
    return [s.name for i, s in enumerate(mech.solids)
            if largest > 0 and np.max(size[PER_SOLID * i:PER_SOLID * (i + 1)]) > RANK * largest]


def require_applicable(closures: Closures, c: Closure, t: float) -> None:
    """Raise the contract's error where the method does not apply at the start (λ = 0):
    (i) a self-stress that loads no clearance parameter: ModelError naming the elements;
    (ii) positions the closure and the command leave free: MobilityError naming the
    solids. Both messages begin with ``t=<time>:`` and name the model file."""
    found = applicability(c)
    if found.self_stress.shape[1]:
        names = ", ".join(f"'{n}'" for n in loaded_elements(closures, found.self_stress))
        raise ModelError(
            f"t={t:g}: the clearance analysis of {source(closures)} cannot start: the "
            f"elements {names} close an over-constrained loop with no clearance in it, so "
            f"no clearance can absorb the variations that strain it (condition (i): a "
            f"self-stress that loads no clearance parameter, σ_min/σ_max of [F_j F_q] = "
            f"{found.ratio_i:.3g}): declare clearance = true on one of them (a revolute, "
            f"pin_slot or prismatic)")
    if found.free.shape[1] or found.hessian <= RANK:
        names = ", ".join(f"'{n}'" for n in free_solids(closures.mech, found.free))
        raise MobilityError(
            f"t={t:g}: the clearance analysis of {source(closures)} cannot start: the joints "
            f"and the actuators leave the solids {names} free to move (condition (ii): "
            f"σ_min/σ_max of F_q = {found.ratio_ii:.3g}): drive the free degree of freedom "
            f"with an actuator, or, at a singular position such as a dead centre, start "
            f"elsewhere (the actuator's law at t = 0, or the solids' fi)")


def require_strict_minimum(c: Closure, t: float, source: str = "the model",
                           closures: Closures | None = None) -> None:
    """Raise SolverError where, at a later time, (i) or the reduced Hessian's condition
    fails: the clearance followed is no longer a strict minimum (``closures``, when given,
    names the elements or solids concerned)."""
    found = applicability(c)
    if found.ratio_i <= RANK or found.hessian <= RANK:
        raise SolverError(
            f"t={t:g}: the clearance followed is no longer a strict minimum in {source}: "
            f"{_nearest_failure(found, closures)}. The least-norm clearance may leave for "
            f"another branch here. {TRY} (t_end below {t:g} s); {_kept(t)}", time=t)


#: what a designer can change when the least-norm clearance cannot be followed
TRY = ("Try clearance = true on another joint of the loop, smaller variations (dx, dy, "
       "dangle), or a shorter interval")


def _kept(t: float) -> str:
    """What is kept of a run stopped at t > 0."""
    return (f"the rows before t = {t:.6g} s are kept (SolverError.partial; pam2exu run "
            f"--partial -o FILE.csv writes them)" if t > 0 else "no row is kept")

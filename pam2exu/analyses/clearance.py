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

import copy
from dataclasses import replace

import numpy as np

from ..errors import MobilityError, ModelError, SolverError
from ..kinematics import PER_SOLID, State
from ..model.solid import LineRef
from .job import Job, check_mobility, collect
from .least_norm import (RANK, Applicability, Closure, Stop, applicability, follow,
                         lagrange_jacobian, split, time_rate)
from .native import target_values
from .positions import GUESS_STIFFNESS, assemble


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
    job.stage = "following the clearance of least norm (the slides' ODE)"
    y0 = np.r_[np.zeros(p), q0, np.zeros(m)]
    if closures.has_fixed:
        job.stage = "following the clearance of least norm to the dimensions as made (t = 0)"
        y0 = as_made(closures, t0, y0)
    y, ok, stop = follow(closures.evaluate, time_rate(closures.evaluate, p, start=t0),
                         job.times, y0, p, nq)
    job.stage = "checking the clearance is a strict minimum at every row"
    rows = range(0, len(job.times), job.every)
    for k in rows:
        if not ok[k]:
            break
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


#: the rows of the straight path u0 + s δ at t = 0 where Newton corrects the clearance
#: followed (s = 0, 1/4, …, 1); the integrator steps as it needs between them
PATH_ROWS = 4
#: the step in s of the central differences of h_s on that path: h is linear in a point's
#: δ and smooth in a line's, so a large step loses nothing, while 1e-6 (the time's, whose
#: rates are O(1)) leaves round-off of O(1e-10) in rates of O(δ) that the integrator's
#: error control chases (the locomotive, 3e-4 m deviations: 5.5 s at 1e-6, 1.0 s at 1e-3,
#: the clearances equal to 2e-16)
PATH_RATE_STEP = 1e-3


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
    y, ok, stop = follow(along, time_rate(along, p, step=PATH_RATE_STEP), path, y0, p, nq)
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
    q_nominal = found.q
    estimate = np.array([first_order(closures, float(job.times[k]), q_nominal[k])
                         for k in rows])
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


class Closures:
    """The closure of ``mech`` at any time, with its clearance parameters laid out.

    Parameters
    ----------
    mech : Mechanism
        The validated mechanism (its ``variations`` bound).
    start : numpy.ndarray
        q at the nominal assembly (what a prismatic's sense is read from).
    """

    def __init__(self, mech, start: np.ndarray):
        self.mech = mech
        self.start = State([0.0], np.asarray(start, dtype=float)[None])
        #: the clearance elements, in element order, and the names of their parameters
        self.elements = [el for el in mech.constraints if el.clearance]
        self.names = [f"{el.name}.{var.name}" for el in self.elements
                      for var in el.clearance_parameters]
        self.p, self.nq, self.m = len(self.names), mech.nq, mech.n_equations
        self.Fj = np.zeros((self.m, self.p))
        k = 0
        for el, rows in zip(mech.constraints, mech.rows):
            if el in self.elements:
                width = len(el.clearance_parameters)
                self.Fj[rows, k:k + width] = np.asarray(el.clearance_terms, dtype=float)
                k += width

    def columns(self, j: np.ndarray) -> dict[str, np.ndarray]:
        """The result columns of the clearance parameters j (n, p), and those derived from
        them (a revolute's jr), as ``<element>.<name>``."""
        out, k = {}, 0
        for el in self.elements:
            values = {}
            for var in el.clearance_parameters:
                values[var.name] = j[:, k]
                k += 1
            values.update(el.clearance_derived_values(values))
            out.update({f"{el.name}.{name}": v for name, v in values.items()})
        return out

    @property
    def has_fixed(self) -> bool:
        """Some ``[[variation]]`` has a fixed deviation (``fixed_dx`` …) to reach at t = 0
        (``as_made``)."""
        return any(v.has_fixed for v in self.mech.variations)

    def at(self, t: float, reached: float = 1.0) -> list:
        """The constraint elements with their varied points and lines at time t (copies;
        the elements whose anchors do not vary are the mechanism's own), the fixed
        deviations ``reached`` of the way (``Variation.offsets``)."""
        out = []
        for el in self.mech.constraints:
            refs = list(el.refs)
            for k, ref in enumerate(refs):
                variation = self.mech.variation(el, k)
                if variation is not None:
                    refs[k] = _moved(ref, variation.offsets(np.array([t]), reached)[0][0])
            if refs != list(el.refs):
                el = copy.copy(el)
                el.refs = tuple(refs)
                el.ref1, el.ref2 = refs[0], refs[1] if len(refs) > 1 else None
            out.append(el)
        return out

    def evaluate(self, t: float, q: np.ndarray, lam: np.ndarray,
                 reached: float = 1.0) -> Closure:
        """C (without F_j j), F_q, F_j and W = Σ λ_i ∂²F_i/∂q² at (t, q), the fixed
        deviations ``reached`` of the way."""
        st = State([t], np.asarray(q, dtype=float)[None], hessians=True)
        C = np.zeros(self.m)
        Fq = np.zeros((1, self.m, self.nq))
        W = np.zeros((1, self.nq, self.nq))
        for el, rows in zip(self.at(t, reached), self.mech.rows):
            if el.clearance:
                v, target = el.clearance_constraint(st, self.start)
            else:
                v, target = el.constraint(st)
            f = target_values(target, st.t, el.equations)[0]
            C[rows] = (v.value - f)[0]
            v.rows(Fq, rows.start)
            v.weighted_hessian(np.asarray(lam, dtype=float)[None, rows], W)
        return Closure(C, Fq[0], self.Fj, W[0])


def _moved(ref, offset: np.ndarray):
    """A point or line reference moved by u − u0 = (dx, dy, dangle) in its solid's frame."""
    if isinstance(ref, LineRef):
        return replace(ref, point=(ref.point[0] + offset[0], ref.point[1] + offset[1]),
                       angle=ref.angle + offset[2])
    return replace(ref, local=(ref.local[0] + offset[0], ref.local[1] + offset[1]))


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

"""Forward dynamics (shared/spec/dynamics.md, ``dynamic``): let go of the mechanism.

The degrees of freedom no actuator drives move under gravity, the torsors, the springs and
dampers and the inertia of every solid; the driven ones follow their laws. A backend
with a fixed-step integrator (``Backend.integrate``; the Exudyn backend's: ``SolveDynamic``
on the translated model, ``backend.exudyn.integrate``) integrates with a given step: its
generalized-α rule is of order 2, so two runs at h and h/2 extrapolate (Richardson) to
order 3 at least (measured 3.3 on the pendulum of the tests), and three runs give two such
values whose difference bounds the error of the better one (Romberg). The step is halved
until that estimate meets ``tolerance`` · (1 + |value|) on every coordinate and rate.

The native pass then does what the integrator does not: the extrapolated state is projected back
onto the constraints (positions and velocities, a correction of the integration error's
size), the accelerations and multipliers come from the equations of motion

    [M  C_qᵀ] [q̈]   [Q(q, q̇, t) − b(q, q̇)]
    [C_q  0 ] [μ] = [γ(q, q̇, t)          ],

and the reactions from the same formulas as ``kinetostatic`` (``force_pass.over_time``),
so every row satisfies every solid's Newton–Euler equations.

A backend with its own adaptive integrator (``Integrator.ADAPTIVE``, ``Backend.motion``:
the natural backend's, in natural coordinates) replaces the Romberg sequence; the rest is
the same.
"""
from __future__ import annotations

import math

import numpy as np

from ..backend import Integrator
from ..errors import InputWarning, ModelError, SolverError
from ..kinematics import State, pose
from ..registry import backends_that
from . import force_pass, free, native
from .job import Job, check_mobility, collect, warn
from .kinetostatic import kinetostatic
from .positions import GUESS_STIFFNESS, assemble, check_residual

#: the coarsest run takes at least this many steps over the interval
FIRST_STEPS = 64
#: the finest run may take at most this many steps over the interval; beyond, the results
#: are those of the finest run, with a warning giving the estimate reached
MOST_STEPS = 2 ** 21
#: the refinement stops when the estimate failed to halve this many halvings in a row:
#: the round-off floor of the integrator (~1e-9 per unit on the free four-bar's rates)
STALLS = 2
#: Gauss–Newton iterations of the projection onto the position constraints
PROJECTIONS = 3


class AccuracyWarning(UserWarning):
    """The dynamic analysis could not meet its tolerance: the integrator's accuracy floor,
    or more than ``MOST_STEPS`` steps (the message gives the estimate reached)."""


def dynamic(job: Job):
    """Every output of ``kinetostatic``, the free degrees of freedom integrated in time
    from the assembly and the nearest consistent velocities (shared/spec/dynamics.md).

    A fully driven model gives the kinetostatic results. ``res.info``: the error estimate
    reached (``integration_error``), the steps of the finest run (``integration_steps``).
    """
    mech, t = job.mech, job.times
    mob = check_mobility(job, mech.initial_q(), need_driven=False)
    if mob.dof == 0:
        return kinetostatic(job)
    if job.backend.integrator is Integrator.NONE:
        able = backends_that(lambda b: b.integrator is not Integrator.NONE)
        raise ModelError(
            f"the {job.backend.name} backend cannot integrate the motion of free solids "
            f"({', '.join(repr(n) for n in mob.free_solids)}): run the dynamic analysis on "
            f"the {' or '.join(able)} backend (backend = \"{able[0]}\", --backend {able[0]})")
    redundant = mob.redundant > 0
    q0 = assemble(job, redundant, GUESS_STIFFNESS)
    require_inertia(mech, float(t[0]), q0)
    qd0 = nearest_velocities(mech, float(t[0]), q0, mech.initial_qd())
    warn_rates(job, mech.initial_qd(), qd0)
    job.stage = f"integrating the equations of motion ({job.backend.label})"
    q, qd = motion(job, q0, qd0)
    job.stage = "projecting the integrated states onto the constraints"
    q, qd = project(mech, t, q, qd)
    check_residual(mech, t, q, job)
    job.stage = "computing accelerations and multipliers (equations of motion)"
    qdd = accelerations(mech, t, q, qd)
    job.stage = "computing the reactions (the kinetostatic formulas)"
    # C_q is not square with free degrees of freedom: the multipliers by least squares,
    # exact here since the accelerations make the equations consistent
    out, _ = force_pass.over_time(mech, t, q, True, qd, qdd)
    return collect(job, q, qd, qdd, extra=out)


# ---- the motion, by the backend, to the tolerance ---------------------------------------------

def motion(job: Job, q0: np.ndarray, qd0: np.ndarray, pieces: list | None = None):
    """(q, q̇) at every time of the job, segment by segment between the laws' breakpoints
    (where the velocities jump: ``impulse``), each one to the tolerance (``romberg``).
    ``pieces``: a list that receives every run's (times, rows it fills, steps of its finest
    run, whether it ends at a breakpoint), in order (``export_dynamic`` repeats them)."""
    mech, t, tolerance = job.mech, job.times, job.options["tolerance"]
    dt = float(t[1] - t[0])
    # a breakpoint within round-off of a row is that row's time
    breaks = sorted({float(t[np.argmin(np.abs(t - b))])
                     if np.min(np.abs(t - b)) <= 1e-9 * dt else float(b)
                     for el in mech.drivers for b in el.time_law().breakpoints()})
    breaks = [b for b in breaks if t[0] < b < t[-1]]
    q, qd = np.full((len(t), mech.nq), np.nan), np.full((len(t), mech.nq), np.nan)
    q[0], qd[0] = q0, qd0
    worst, steps = 0.0, 0
    start, state = float(t[0]), (q0, qd0)
    for end in [*breaks, float(t[-1])]:
        inside = np.nonzero((t > start) & (t <= end))[0]
        for times, rows in _pieces(t, inside, start, end):
            at_break = end < float(t[-1]) and times[-1] == end
            found, estimate, n = romberg(job, times, *state, at_break=at_break)
            if pieces is not None:
                pieces.append((times, list(rows), n, at_break))
            q[rows], qd[rows] = found[0][1:len(rows) + 1], found[1][1:len(rows) + 1]
            worst, steps = max(worst, estimate), max(steps, n)
            state = (found[0][-1], found[1][-1])
        if end < float(t[-1]):
            state = (state[0], impulse(mech, end, *state))
            at = np.nonzero(np.abs(t - end) <= 1e-12 * max(1.0, abs(end)))[0]
            if at.size:                      # a row at the breakpoint: the values after
                q[at], qd[at] = state
        start = end
    job.info["integration_error"] = worst
    job.info["integration_steps"] = steps
    if worst > tolerance:
        warn(job, f"the time integration reached an error estimate of {worst:.2g} per unit "
                  f"of value, not the tolerance {tolerance:g}: "
                  + (f"{job.backend.label} cannot integrate more accurately here. Ask for "
                     "a looser tolerance, or a shorter interval"
                     if job.backend.integrator is Integrator.ADAPTIVE
                     else _finer_steps_advice(job)),
             AccuracyWarning)
    return q, qd


def _finer_steps_advice(job: Job) -> str:
    """Why a fixed-step integrator stopped short of the tolerance, and what to do."""
    adaptive = backends_that(lambda b: b.integrator is Integrator.ADAPTIVE)
    return (f"{job.backend.integrator_name} stops improving here, or would need more than "
            f"{MOST_STEPS:,} steps. Ask for a looser tolerance"
            + (f", or run on the {' or '.join(adaptive)} backend (backend = "
               f"\"{adaptive[0]}\": an adaptive high-order integrator, docs/analyses.md)"
               if adaptive else ""))


def _pieces(t: np.ndarray, inside: np.ndarray, start: float, end: float):
    """The runs that cover (start, end]: equally spaced times from ``start`` through the
    output rows ``inside``, and the rows they fill (a run from ``start`` to the first row
    when ``start`` is a breakpoint between rows, and one from the last row to ``end``)."""
    out = []
    rows = list(inside)
    if rows and not math.isclose(t[rows[0]] - start, t[1] - t[0], rel_tol=1e-9) \
            and t[rows[0]] - start < t[1] - t[0]:
        out.append((np.array([start, t[rows[0]]]), rows[:1]))
        start, rows = float(t[rows[0]]), rows[1:]
    if rows:
        out.append((np.r_[start, t[rows]], rows))
        start = float(t[rows[-1]])
    if end > start + 1e-9 * (t[1] - t[0]):
        out.append((np.array([start, end]), []))
    return out


def romberg(job: Job, times: np.ndarray, q0: np.ndarray, qd0: np.ndarray,
            at_break: bool = False):
    """((q, q̇) at ``times``, error estimate, steps of the finest run): runs with s, 2s, 4s …
    steps per interval, each pair extrapolated (R = y_h/2 + (y_h/2 − y_h)/3), until two
    successive R differ by at most tolerance · (1 + |R|). Their difference is the error of
    the earlier one to first order, so it bounds the error of the later one, which is
    kept, as long as the extrapolations converge (the error falls as h³ or faster: by
    8 or more per halving; measured 10 on the pendulum). Dividing it by 7, as the order
    would allow, let the pendulum's error exceed the estimate by 1.3 ×. A run the
    integrator cannot finish (a step too long for its Newton iteration) starts the
    sequence again from twice its steps. A backend with its own adaptive integrator
    (``Integrator.ADAPTIVE``: ``Backend.motion``) meets the tolerance itself.
    ``at_break``: the last time is a law breakpoint, where the velocity equations change:
    that row is left as integrated (the state before the jump)."""
    tolerance = job.options["tolerance"]
    if job.backend.integrator is Integrator.ADAPTIVE:
        q, qd, estimate, steps = job.backend.motion(job.mech, times, q0, qd0, tolerance,
                                                    verbose=job.solver.verbose)
        return (q, qd), estimate, steps
    n = len(times) - 1
    s = max(1, math.ceil(FIRST_STEPS / n))
    runs, best, stalled, last = [], None, 0, np.inf
    while True:
        found = _run(job, times, q0, qd0, s, last=s * n * 2 > MOST_STEPS)
        if found is None:                     # too long a step: start again, finer
            runs, best = [], None
            s *= 2
            continue
        runs.append(found)
        if len(runs) >= 2:
            coarse, fine = runs[-2], runs[-1]
            # projected onto the constraints before they are compared: the index-3
            # velocities carry a noise normal to them that grows as the step shrinks
            # (measured on the free four-bar: from 2e-10 to 1.2e-9 between 2,048 and
            # 16,384 steps per row; 1e-10 once projected), which the result never shows
            R = tuple(b + (b - a) / 3.0 for a, b in zip(coarse, fine))
            rows = slice(None, -1) if at_break else slice(None)
            R[0][rows], R[1][rows] = project(job.mech, times[rows], R[0][rows], R[1][rows])
            if best is not None:
                estimate = max(float(np.max(np.abs(r - p) / (1.0 + np.abs(r))))
                               for r, p in zip(R, best))
                # a floor: twice in a row the estimate did not halve when the step did
                stalled = stalled + 1 if estimate > 0.5 * last else 0
                last = min(last, estimate)
                if estimate <= tolerance or s * n * 2 > MOST_STEPS or stalled >= STALLS:
                    return R, estimate, s * n
            best = R
        s *= 2


def _run(job: Job, times, q0, qd0, substeps: int, last: bool):
    """(q, q̇) of one run of the backend's fixed-step integrator, None if it failed; on
    the ``last`` run allowed, a SolverError naming the time where it stopped."""
    found = job.backend.integrate(job.mech, times, q0, qd0, substeps,
                                  verbose=job.solver.verbose)
    if found.error is None:
        return found.q, found.qd
    if not last:
        return None
    rows = ~np.isfinite(found.q).all(axis=1)
    at = float(times[int(np.argmax(rows))]) if rows.any() else float(times[-1])
    raise SolverError(
        f"t={at:g}: {job.backend.label}'s dynamic solver failed ({found.error}) even with "
        f"{substeps} steps per interval of {times[1] - times[0]:g} s. The motion may reach "
        "a singular position where the mechanism locks or branches: check the model "
        "there (pam2exu draw MODEL --t T), or end the interval before it", time=at)


# ---- the native pass: consistent states, accelerations, impulses -----------------------

def mass_matrix(mech, st: State) -> np.ndarray:
    """M (n, nq, nq): Σ m J_Gᵀ J_G + J_G e_fi e_fiᵀ per solid (J_G: ∂r_G/∂(x, y, fi))."""
    M = np.zeros((st.n, mech.nq, mech.nq))
    for i, s in enumerate(mech.solids):
        m, J = float(s.mass), float(s.inertia)
        if m == 0 and J == 0:
            continue
        block = st.point(i, [float(c) for c in s.cog]).jac[i]
        cols = pose(i)
        M[:, cols, cols] += m * np.einsum("ndk,ndl->nkl", block, block)
        M[:, cols.stop - 1, cols.stop - 1] += J
    return M


def accelerations(mech, t, q, qd) -> np.ndarray:
    """q̈ (n, nq) from [[M, C_qᵀ], [C_q, 0]] [q̈; μ] = [Q − b; γ], b the inertia terms at
    q̈ = 0 (least squares where redundant constraints make it singular); exactly 0 for the
    solids held by fixed links."""
    st = State(t, q, qd)
    M = mass_matrix(mech, st)
    b, _ = force_pass.inertia_forces(mech, st, np.zeros_like(q))
    Q = force_pass.applied_forces(mech, st, damping=True).force
    eq = native.equations(mech, st)
    A = _saddle(M, eq.jacobian)
    rhs = np.concatenate([Q - b, eq.gamma], axis=1)
    qdd = _solve(A, rhs)[:, :mech.nq]
    qdd[:, ~moving_columns(mech)] = 0.0
    return qdd


def impulse(mech, t: float, q: np.ndarray, qd_before: np.ndarray) -> np.ndarray:
    """q̇⁺ after a breakpoint at t: min (q̇⁺ − q̇⁻)ᵀ M (q̇⁺ − q̇⁻) subject to the velocity
    equations after it, [[M, C_qᵀ], [C_q, 0]] [q̇⁺; μ] = [M q̇⁻; −C_t⁺]."""
    st = State([t], q[None])
    M = mass_matrix(mech, st)
    eq = native.equations(mech, st)
    rhs = np.concatenate([M[0] @ qd_before, -eq.c_t[0]])[None]
    return _solve(_saddle(M, eq.jacobian), rhs)[0, :mech.nq]


def nearest_velocities(mech, t: float, q: np.ndarray, guess: np.ndarray) -> np.ndarray:
    """q̇ = q̇_g − C_q⁺ (C_q q̇_g + C_t): the velocities that satisfy the velocity equations
    nearest to the guess in the Euclidean norm (SI units); the solids held by fixed links
    at rest, exactly."""
    free = moving_columns(mech)
    eq = native.equations(mech, State([t], q[None]))
    J = eq.jacobian[0][:, free]
    qd = np.zeros(mech.nq)
    qd[free] = guess[free] - np.linalg.pinv(J, rcond=1e-12) @ (J @ guess[free] + eq.c_t[0])
    return qd


def warn_rates(job: Job, given: np.ndarray, used: np.ndarray) -> None:
    """InputWarning naming each solid given a rate (Dx, Dy or Dfi ≠ 0) whose rates the run
    changed by more than round-off (1e-9 (1 + max |given|)), with the given and used values
    in the model's units."""
    model = job.mech.model
    degrees = model.angles == "deg"
    roundoff = 1e-9 * (1.0 + float(np.max(np.abs(given), initial=0.0)))
    used = np.where(np.abs(used) <= roundoff, 0.0, used)        # no -2.2e-16 in the text
    for i, solid in enumerate(model.solids):
        rows = slice(3 * i, 3 * i + 3)
        if not np.any(given[rows]) or np.all(np.abs(used[rows] - given[rows]) <= roundoff):
            continue
        changes = [f"{key} = {float(getattr(solid, key)):.6g} {unit} given, "
                   f"{math.degrees(u) if degrees and key == 'Dfi' else u:.6g} {unit} used"
                   for key, u, g, unit in
                   zip(("Dx", "Dy", "Dfi"), used[rows], given[rows],
                       ("m/s", "m/s", "deg/s" if degrees else "rad/s"))
                   if abs(u - g) > roundoff]
        warn(job, f"{model.source + ': ' if model.source else ''}{solid.where}: the constraints "
                  "do not allow the initial rates given, the run starts from the nearest that "
                  f"they do: {'; '.join(changes)}", InputWarning)


def project(mech, t, q, qd):
    """(q, q̇) moved by least norm onto C(q, t) = 0 (Gauss–Newton) and then onto
    C_q q̇ + C_t = 0: corrections of the size of the integration error. The solids held by
    fixed links are put exactly where the links hold them, at rest (the least-norm
    corrections would leave round-off there, 1e-31)."""
    free = moving_columns(mech)
    q, qd = q.copy(), qd.copy()
    q[:, ~free], qd[:, ~free] = mech.initial_q()[~free], 0.0     # the fixed links' poses
    for _ in range(PROJECTIONS):
        eq = native.equations(mech, State(t, q))
        q[:, free] -= np.einsum("nqm,nm->nq", np.linalg.pinv(eq.jacobian[:, :, free],
                                                             rcond=1e-12), eq.residual)
    eq = native.equations(mech, State(t, q))
    defect = np.einsum("nmq,nq->nm", eq.jacobian, qd) + eq.c_t
    qd[:, free] -= np.einsum("nqm,nm->nq", np.linalg.pinv(eq.jacobian[:, :, free],
                                                          rcond=1e-12), defect)
    return q, qd


def moving_columns(mech) -> np.ndarray:
    """Mask (nq,) of the coordinates of the solids not held by a fixed link."""
    free = np.ones(mech.nq, dtype=bool)
    for el in mech.constraints:
        if el.grounds:
            free[pose(el.ref1.solid)] = False
    return free



def require_inertia(mech, t: float, q: np.ndarray) -> None:
    """ModelError naming the solids of a free motion that moves no mass and no inertia
    (Zᵀ M Z singular, Z a basis of the motions the constraints allow)."""
    Z = free.free_motions(mech, t, q)              # angles scaled by the length scale
    if Z.shape[1] == 0:
        return
    scale = np.tile([1.0, 1.0, mech.scale()], len(mech.solids))
    M = mass_matrix(mech, State([t], q[None]))[0] / np.outer(scale, scale)
    values, vectors = np.linalg.eigh(Z.T @ M @ Z)
    size = max(float(np.max(np.abs(M))), np.finfo(float).tiny)
    if values[0] > 1e-12 * size:
        return
    moved = free.moving_solids(mech, Z @ vectors[:, :1])
    raise ModelError(
        f"a free motion of the solids {', '.join(repr(n) for n in moved)} moves no mass and "
        "no inertia, so its acceleration is not defined: give those solids a mass or an "
        "inertia, or drive the motion with an actuator")


def _saddle(M: np.ndarray, J: np.ndarray) -> np.ndarray:
    """[[M, Jᵀ], [J, 0]] per step."""
    n, m, nq = J.shape
    A = np.zeros((n, nq + m, nq + m))
    A[:, :nq, :nq] = M
    A[:, :nq, nq:] = np.swapaxes(J, 1, 2)
    A[:, nq:, :nq] = J
    return A


def _solve(A: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """x with A x = rhs per step; least squares (min norm) where A is singular."""
    try:
        return np.linalg.solve(A, rhs[..., None])[..., 0]
    except np.linalg.LinAlgError:
        return np.einsum("nij,nj->ni", np.linalg.pinv(A, rcond=1e-12), rhs)

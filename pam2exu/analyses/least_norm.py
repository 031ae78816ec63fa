"""The clearance of least norm: Rameau's Lagrange conditions and how to follow them.

With clearance parameters j the closure equations F(u(t), j, q, r(t)) = 0 of an
over-constrained mechanism hold again for perturbed dimensions u(t); the clearance analysis
(shared/spec/clearance.md) follows

    (j, q)(t) = argmin ½‖j‖²  subject to  F(u(t), j, q, r(t)) = 0,

whose Lagrange conditions, with y = (j, q, λ), are

    h(t, y) = (j + F_jᵀλ, F_qᵀλ, F) = 0.

The clearance terms are linear in j (F_j constant), so

    h_y = [[I, 0, F_jᵀ], [0, W, F_qᵀ], [F_j, F_q, 0]],   W = Σ_i λ_i ∂²F_i/∂q².

This module is the mathematics only, on a ``Closure`` (F, F_q, F_j and W at one time, which
the caller evaluates): the residual h, its Jacobian, Newton's iteration on h = 0, the
slides' ODE y' = −h_y⁻¹ h_t with a Newton corrector at each output time, and the
conditions under which the method applies. Reference: J.-F. Rameau, "Équation
différentielle pour modéliser les mécanismes sur-contraints avec jeu" (2014), pp. 8–10.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, NamedTuple

import numpy as np

#: a singular value below this fraction of the largest counts as zero (the contract's 1e-9)
RANK = 1e-9


@dataclass
class Closure:
    """The closure equations F = C(q, t) + F_j j at one time: C (m,) (``F``, without the
    clearance terms), F_q (m, nq), F_j (m, p), and W = Σ λ_i ∂²F_i/∂q² (nq, nq) for the λ
    they were evaluated with."""

    F: np.ndarray
    Fq: np.ndarray
    Fj: np.ndarray
    W: np.ndarray


#: evaluate(t, q, λ) -> Closure
Evaluate = Callable[[float, np.ndarray, np.ndarray], Closure]


def split(y: np.ndarray, p: int, nq: int):
    """(j, q, λ) of y = (j, q, λ)."""
    return y[:p], y[p:p + nq], y[p + nq:]


def lagrange(j: np.ndarray, lam: np.ndarray, c: Closure) -> np.ndarray:
    """h = (j + F_jᵀλ, F_qᵀλ, C + F_j j)."""
    return np.concatenate([j + c.Fj.T @ lam, c.Fq.T @ lam, c.F + c.Fj @ j])


def lagrange_jacobian(c: Closure) -> np.ndarray:
    """h_y = [[I, 0, F_jᵀ], [0, W, F_qᵀ], [F_j, F_q, 0]] (F_j constant)."""
    return lagrange_jacobian_rows(c.Fj, c.Fq[None], c.W[None])[0]


def newton(evaluate: Evaluate, t: float, y: np.ndarray, p: int, nq: int,
           tolerance: float = 1e-13, iterations: int = 30) -> tuple[np.ndarray, bool]:
    """(y, converged): Newton's iteration on h(t, y) = 0 from y, until the step is below
    ``tolerance`` (relative to 1 + |y|) or h is at round-off."""
    for _ in range(iterations):
        j, q, lam = split(y, p, nq)
        c = evaluate(t, q, lam)
        h = lagrange(j, lam, c)
        try:
            step = np.linalg.solve(lagrange_jacobian(c), -h)
        except np.linalg.LinAlgError:
            return y, False
        y = y + step
        if np.max(np.abs(step)) <= tolerance * (1.0 + np.max(np.abs(y))):
            return y, True
    return y, False


#: evaluate_rows(times (n,), q (n, nq), λ (n, m)) -> (C (n, m), F_q (n, m, nq), W (n, nq, nq))
EvaluateRows = Callable[[np.ndarray, np.ndarray, np.ndarray], tuple]


def lagrange_rows(y: np.ndarray, Fj: np.ndarray, C: np.ndarray, Fq: np.ndarray, p: int,
                  nq: int) -> np.ndarray:
    """h of every row (n, p + nq + m): ``lagrange`` at each."""
    j, lam = y[:, :p], y[:, p + nq:]
    return np.concatenate([j + lam @ Fj, np.einsum("nmq,nm->nq", Fq, lam), C + j @ Fj.T],
                          axis=1)


def lagrange_jacobian_rows(Fj: np.ndarray, Fq: np.ndarray, W: np.ndarray) -> np.ndarray:
    """h_y of every row (n, N, N): ``lagrange_jacobian`` at each."""
    n, m, nq = Fq.shape
    p = Fj.shape[1]
    H = np.zeros((n, p + nq + m, p + nq + m))
    H[:, :p, :p] = np.eye(p)
    H[:, :p, p + nq:] = Fj.T
    H[:, p:p + nq, p:p + nq] = W
    H[:, p:p + nq, p + nq:] = np.transpose(Fq, (0, 2, 1))
    H[:, p + nq:, :p] = Fj
    H[:, p + nq:, p:p + nq] = Fq
    return H


def newton_rows(evaluate_rows: EvaluateRows, Fj: np.ndarray, times: np.ndarray,
                y: np.ndarray, p: int, nq: int, tolerance: float = 1e-13,
                iterations: int = 30) -> tuple[np.ndarray, np.ndarray]:
    """(y, converged) of every row: ``newton`` at each row from its own y, all rows at
    once (the rows are independent: the corrections of ``follow``)."""
    y = np.array(y, dtype=float)
    ok = np.zeros(len(times), dtype=bool)
    active = np.arange(len(times))
    for _ in range(iterations):
        if not active.size:
            break
        at = y[active]
        C, Fq, W = evaluate_rows(times[active], at[:, p:p + nq], at[:, p + nq:])
        h = lagrange_rows(at, Fj, C, Fq, p, nq)
        H = lagrange_jacobian_rows(Fj, Fq, W)
        try:
            step = np.linalg.solve(H, -h[..., None])[..., 0]
        except np.linalg.LinAlgError:            # some row singular: it stops there
            step = np.full_like(h, np.nan)
            for r in range(len(active)):
                try:
                    step[r] = np.linalg.solve(H[r], -h[r])
                except np.linalg.LinAlgError:
                    pass
        singular = ~np.isfinite(step).all(axis=1) & np.isfinite(h).all(axis=1)
        y[active[~singular]] = at[~singular] + step[~singular]
        done = (np.max(np.abs(step), axis=1)
                <= tolerance * (1.0 + np.max(np.abs(y[active]), axis=1)))
        ok[active[done]] = True
        active = active[~done & ~singular]
    return y, ok


def strict_minimum_rows(Fj: np.ndarray, Fq: np.ndarray, W: np.ndarray):
    """(σ_min/σ_max of [F_j F_q], the smallest eigenvalue of the reduced Hessian) of every
    row: ``applicability``'s ``ratio_i`` and ``hessian`` at each, in batches, to round-off
    (the kernel's basis is another, ``kernel_rows``; the reduced Hessian's eigenvalues do not
    depend on it): the screen of ``clearance._first_lost``, whose rows near a limit
    ``applicability`` decides."""
    n, m, nq = Fq.shape
    p = Fj.shape[1]
    A = np.concatenate([np.broadcast_to(Fj, (n, m, p)), Fq], axis=2)
    s = np.linalg.svd(A, compute_uv=False)
    top = s[:, 0]
    smallest = np.zeros(n) if m > min(m, p + nq) else s[:, -1]
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(top > 0, smallest / top, np.inf)
    rank = np.sum(s > RANK * top[:, None], axis=1)
    hessian = np.full(n, np.inf)
    full = np.zeros((n, p + nq, p + nq))
    full[:, :p, :p] = np.eye(p)
    full[:, p:, p:] = W
    for r in np.unique(rank):
        rows = np.nonzero(rank == r)[0]
        Z = kernel_rows(A[rows], int(r))
        if Z.shape[2]:
            reduced = np.transpose(Z, (0, 2, 1)) @ full[rows] @ Z
            hessian[rows] = np.linalg.eigvalsh(reduced)[:, 0]
    return ratio, hessian


def kernel_rows(A: np.ndarray, rank: int) -> np.ndarray:
    """An orthonormal basis of ker A_k (k, columns − rank) of every matrix of the stack A (n,
    rows, columns) of that rank: of full row rank, the last columns of the complete QR of
    A_kᵀ (its range is A_k's row space; a third of the full SVD's work), else the last
    right singular vectors."""
    n, rows, columns = A.shape
    if rank == rows < columns:
        return np.linalg.qr(np.transpose(A, (0, 2, 1)), mode="complete").Q[:, :, rank:]
    return np.transpose(np.linalg.svd(A)[2][:, rank:], (0, 2, 1))


@dataclass
class Applicability:
    """The conditions of the slides (p. 10) at a configuration: (i) [F_j F_q] has full row
    rank, (ii) F_q has full column rank and the reduced Hessian is positive definite."""

    ratio_i: float              # σ_min / σ_max of [F_j F_q]
    ratio_ii: float             # σ_min / σ_max of F_q
    hessian: float              # the smallest eigenvalue of Zᵀ W_full Z (``_reduced_hessian``)
    self_stress: np.ndarray     # (m, k): a basis of the λ with [F_j F_q]ᵀ λ ≈ 0 ((i) fails if k)
    free: np.ndarray            # (nq, k): a basis of the δq with F_q δq ≈ 0 ((ii) fails if k)

    @property
    def holds(self) -> bool:
        return self.ratio_i > RANK and self.ratio_ii > RANK and self.hessian > RANK


def _ratio_and_null(shape: tuple, svd, side: str):
    """(σ_min/σ_max, a basis of the null space on ``side``: 'left' (columns λ with Aᵀλ ≈ 0)
    or 'right' (columns δ with A δ ≈ 0)) of a matrix A of ``shape`` from its full SVD,
    singular values ≤ RANK σ_max counting as 0; a ratio of +inf where that null space is
    {0} and A has no singular value (no equations, or nothing they constrain)."""
    U, s, Vt = svd
    size = min(shape)
    top = s[0] if s.size else 0.0
    lost = np.r_[s <= RANK * top, np.ones(max(shape) - size, dtype=bool)]
    n = shape[0] if side == "left" else shape[1]
    null = U[:, lost[:n]] if side == "left" else Vt[lost[:n]].T
    smallest = 0.0 if n > size else (s[-1] if s.size else top)
    if top > 0:
        return smallest / top, null
    return (np.inf if null.shape[1] == 0 else 0.0), null


def _reduced_hessian(c: Closure, svd) -> float:
    """The smallest eigenvalue of Zᵀ diag(I, W) Z, Z an orthonormal basis of ker [F_j F_q]
    (``svd``: its full SVD), the second-order condition of a strict minimum; +inf where the
    kernel is {0}."""
    _, s, Vt = svd
    rank = int(np.sum(s > RANK * s[0])) if s.size else 0
    Z = Vt[rank:].T
    if Z.shape[1] == 0:
        return np.inf
    p = c.Fj.shape[1]
    full = np.zeros((Vt.shape[0], Vt.shape[0]))
    full[:p, :p] = np.eye(p)
    full[p:, p:] = c.W
    return float(np.min(np.linalg.eigvalsh(Z.T @ full @ Z)))


def applicability(c: Closure) -> Applicability:
    """The conditions at a configuration (``Applicability``): one SVD of [F_j F_q] for (i)
    and the reduced Hessian, one of F_q for (ii)."""
    A = np.hstack([c.Fj, c.Fq])
    whole = np.linalg.svd(A)
    ratio_i, stress = _ratio_and_null(A.shape, whole, "left")
    ratio_ii, free = _ratio_and_null(c.Fq.shape, np.linalg.svd(c.Fq), "right")
    return Applicability(ratio_i, ratio_ii, _reduced_hessian(c, whole), stress, free)


def kkt_residual(j: np.ndarray, c: Closure) -> float:
    """min over λ of ‖(F_jᵀλ + j, F_qᵀλ)‖∞ (least squares for λ): 0 where j is minus the
    clearance part of a self-stress (the first-order condition of least norm)."""
    A = np.vstack([c.Fj.T, c.Fq.T])
    b = -np.concatenate([j, np.zeros(c.Fq.shape[1])])
    lam = np.linalg.lstsq(A, b, rcond=None)[0]
    return float(np.max(np.abs(A @ lam - b), initial=0.0))


def time_rate(evaluate: Evaluate, p: int, step: float = 1e-6, start: float = 0.0) -> Callable:
    """h_t(t, q, λ) at fixed y by central differences in t (error O(step²)), forward ones
    (−3h(t) + 4h(t + s) − h(t + 2s))/(2s) where t − step is before ``start`` (the
    variations are not defined there): the ODE only tracks the branch, the corrector of
    ``follow`` makes every output meet h = 0."""
    def h_t(t, q, lam):
        j = np.zeros(p)
        at = [lagrange(j, lam, evaluate(t + s, q, lam))
              for s in ((step, -step) if t - step >= start else (0.0, step, 2 * step))]
        if len(at) == 2:
            return (at[0] - at[1]) / (2 * step)
        return (-3 * at[0] + 4 * at[1] - at[2]) / (2 * step)
    return h_t


#: the integrator's steps allowed in one interval of the output grid before ``follow`` stops
#: (``Stop.WORK``): the shipped examples take at most 4, a variation at the grid's limit
#: (ω Δt = π, ``model.variation.PHASE_PER_STEP``) about 30; a path that crawls (steps
#: shrinking near a singular position) ends instead of running for hours
MAX_STEPS = 100


@dataclass
class Stop:
    """Where and why ``follow`` stopped before the last output time."""

    #: the integration could not go on: h_y singular, or the step size fell to round-off
    SINGULAR = "singular"
    #: more than ``MAX_STEPS`` steps in one output interval
    WORK = "work"
    #: Newton on h = 0 did not converge at an output time
    NEWTON = "newton"

    time: float            # the last time reached [s]
    cause: str             # SINGULAR, WORK or NEWTON
    y: np.ndarray          # y = (j, q, λ) there
    steps: int = 0         # the steps taken in the output interval where it stopped


class Followed(NamedTuple):
    """What ``follow`` found: every row up to ``stop`` (NaN after it, ``converged`` False)."""

    y: np.ndarray            # (len(times), p + nq + m)
    converged: np.ndarray    # (len(times),) bool
    stop: Stop | None        # None: it reached the last output time


def follow(evaluate: Evaluate, h_t: Callable | None, times: np.ndarray, y0: np.ndarray,
           p: int, nq: int, rtol: float = 1e-10, atol: float = 1e-12,
           max_steps: int | None = None, rate: Callable | None = None,
           correct: Callable | None = None, min_step: float | None = None) -> Followed:
    """The slides' ODE y' = −h_y⁻¹ h_t from y0 at times[0], integrated by scipy's DOP853
    step by step through every output time (its dense output there, as ``solve_ivp`` with
    ``t_eval``), then Newton on h = 0 at each output time from the integrated value.
    h_t is ``h_t(t, q, λ)`` (e.g. ``time_rate``), or, with ``rate(t, q, λ)`` -> (Closure,
    h_t) given instead (``Closures.evaluate_rate``), from the same evaluation as h_y.
    ``correct(times, ys)`` -> (ys, converged) corrects the rows reached all at once
    (``newton_rows``); None: ``newton`` at each.

    It stops at the first of: h_y singular or the step size fallen to round-off, or
    below ``min_step`` times the interval (``Stop.SINGULAR``: the steps of a fold shrink
    geometrically towards it), more than ``max_steps`` steps in one output interval
    (``Stop.WORK``; None: ``MAX_STEPS``), Newton not converging at an output time
    (``Stop.NEWTON``); the rows before are kept.
    """
    from scipy.integrate import DOP853

    max_steps = MAX_STEPS if max_steps is None else max_steps
    floor = 0.0 if min_step is None else min_step * float(times[-1] - times[0])

    jacobian = []                   # h_y's constant blocks (I, F_j, F_jᵀ), laid out once

    def rhs(t, y):
        j, q, lam = split(y, p, nq)
        c, rate_t = rate(t, q, lam) if rate is not None else (evaluate(t, q, lam),
                                                              h_t(t, q, lam))
        if not jacobian:
            jacobian.append(lagrange_jacobian(c))
        H = jacobian[0].copy()
        H[p:p + nq, p:p + nq] = c.W
        H[p:p + nq, p + nq:] = c.Fq.T
        H[p + nq:, p:p + nq] = c.Fq
        return -solve(H, rate_t)

    times = np.asarray(times, dtype=float)
    out = np.full((len(times), len(y0)), np.nan)
    ok = np.zeros(len(times), dtype=bool)
    out[0], ok[0] = y0, True
    if len(times) == 1:
        return Followed(out, ok, None)
    predicted = np.full_like(out, np.nan)
    taken = np.zeros(len(times), dtype=int)       # the steps to reach each row
    k, steps, stop = 1, 0, None
    try:
        solver = DOP853(rhs, times[0], y0, times[-1], rtol=rtol, atol=atol)
    except np.linalg.LinAlgError:
        return Followed(out, ok, Stop(float(times[0]), Stop.SINGULAR, y0))
    while k < len(times):
        t, y = float(solver.t), solver.y
        try:
            solver.step()
        except np.linalg.LinAlgError:
            stop = Stop(t, Stop.SINGULAR, y, steps)
            break
        if solver.status == "failed" or not np.isfinite(solver.y).all():
            stop = Stop(t, Stop.SINGULAR, y, steps)
            break
        steps += 1
        if floor and solver.step_size < floor and solver.t < times[-1]:
            stop = Stop(float(solver.t), Stop.SINGULAR, solver.y, steps)
            break
        if times[k] <= solver.t:
            passed = np.searchsorted(times, solver.t, side="right")
            predicted[k:passed] = solver.dense_output()(times[k:passed]).T
            taken[k:passed] = steps
            k, steps = passed, 0
        elif steps >= max_steps:
            stop = Stop(float(solver.t), Stop.WORK, solver.y, steps)
            break
    # Newton at every row reached (independent of each other: the integration goes on
    # from its own state); the first that fails ends the rows, as if met on the way
    if correct is None:
        def correct(at, ys):
            pairs = [newton(evaluate, float(t), y, p, nq) for t, y in zip(at, ys)]
            return (np.array([y for y, _ in pairs]).reshape(ys.shape),
                    np.array([c for _, c in pairs], dtype=bool))
    out[1:k], ok[1:k] = correct(times[1:k], predicted[1:k])
    failed = np.nonzero(~ok[1:k])[0]
    if failed.size:
        row = 1 + int(failed[0])
        out[row:], ok[row:] = np.nan, False
        return Followed(out, ok, Stop(float(times[row]), Stop.NEWTON, predicted[row],
                                      int(taken[row])))
    return Followed(out, ok, stop)


def solve(H: np.ndarray, b: np.ndarray) -> np.ndarray:
    """x with H x = b (H (N, N), b (N,)): LAPACK's gesv as ``numpy.linalg.solve`` calls it,
    without its wrapping (a third of a right-hand side's time); LinAlgError where H is
    singular."""
    from scipy.linalg.lapack import dgesv

    _, _, x, info = dgesv(H, b)
    if info > 0:
        raise np.linalg.LinAlgError("Singular matrix")
    return x


def step_by_step(evaluate: Evaluate, times: np.ndarray, y0: np.ndarray, p: int, nq: int):
    """(y, converged) as ``follow``, by Newton on h = 0 at each time from the previous
    solution (the reference the ODE is checked against)."""
    out = np.empty((len(times), len(y0)))
    ok = np.zeros(len(times), dtype=bool)
    out[0], ok[0] = y0, True
    for k in range(1, len(times)):
        out[k], ok[k] = newton(evaluate, float(times[k]), out[k - 1], p, nq)
    return out, ok

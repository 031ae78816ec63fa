"""Rank tests of the constraint Jacobian Cq: its conditioning, the degrees of freedom the
constraints leave and the equations they repeat (``Mobility``), whether redundant equations
contradict each other and which element added last makes them, the first singular step."""
from __future__ import annotations

from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass

import numpy as np

from ..errors import MobilityError, ModelError, Problem
from ..kinematics import State
from .native import equations, residuals


def condition_numbers(mech, t, q, jacobian: np.ndarray | None = None) -> np.ndarray:
    """κ(Cq) at each step: largest over smallest singular value of the constraint Jacobian,
    its rows and columns equilibrated first (each scaled to unit length, three passes), so
    that units and the choice of length scale drop out; ∞ at a singular position.

    The one condition number of pam2exu (``pam2exu check``, ``Results.info``, the
    ConditionWarning). The shipped examples: 1.5 to 8.6 over their motion; a four-bar
    0.2° from a change point: about 190. ``jacobian``: Cq (n, m, nq) at these steps when
    already evaluated (``native.equations``).
    """
    J = equations(mech, State(t, q)).jacobian if jacobian is None else jacobian
    if J.shape[1] == 0:
        return np.full(len(J), np.inf)
    return _kappa(_equilibrated(J), min(J.shape[1], mech.nq))


def largest_condition(mech, t, q, jacobian: np.ndarray | None = None) -> tuple[int, float]:
    """(k, κ_k): the step of the largest ``condition_numbers`` (the first of equal ones) and
    its value, the same bits, with the SVD only at the steps that can be it.

    The eigenvalues of the Gram matrix of each equilibrated Cq (σ², cheaper than its SVD)
    bound every κ to within their error (``_candidates``); the steps whose upper bound
    reaches the largest lower bound get their SVD, the others are below them for certain.
    """
    J = equations(mech, State(t, q)).jacobian if jacobian is None else jacobian
    if J.shape[1] == 0:
        return 0, np.inf
    A, rank = _equilibrated(J), min(J.shape[1], mech.nq)
    steps = _candidates(A)
    kappa = _kappa(A if steps is None else A[steps], rank)
    i = int(np.argmax(kappa))
    return (i if steps is None else int(steps[i])), float(kappa[i])


#: relative error allowed the Gram matrices' eigenvalues (of ‖A‖_F²; LAPACK's is ~n ε) and
#: the SVD's condition numbers (~n ε κ) in ``_candidates``, with margins of 10⁴ and more
GRAM_ERROR, SVD_ERROR = 1e-10, 1e-8
#: ``_candidates`` bounds condition numbers up to about this; beyond, every step's SVD
BOUNDED = 1e3
#: ``_candidates`` takes the eigenvalues of every PROBE-th step (and the last) first
PROBE = 4


def _candidates(A: np.ndarray) -> np.ndarray | None:
    """The steps whose κ(A) can be the largest (None: every step), from the eigenvalues λ
    of A Aᵀ or Aᵀ A (the smaller: λ = σ², λ_min = σ_r²) within ±GRAM_ERROR ‖A‖_F²; a step
    whose κ may exceed about BOUNDED is one of them (its bounds are not tight).

    The eigenvalues are taken at every PROBE-th step first; a step between them whose κ
    is below their largest lower bound for certain, from its nearest probed step's σ and
    Weyl's |σ_i(A_k) − σ_i(A_j)| ≤ ‖A_k − A_j‖_F (``_ruled_out``), needs none. Within
    ``references``, the first stack of a shape gets them at every step and becomes its
    reference; a later one gets them only at the steps its reference's bounds leave
    (``_referred``), or, when those are more than half, as without one."""
    n = len(A)
    if n == 0 or np.iscomplexobj(A):
        return None
    size = np.einsum("nij,nij->n", A, A)             # ‖A‖_F² ≥ λ_max
    if not np.isfinite(size).all():                  # (A has a NaN or an ∞: so has it)
        return None
    error, low, high = GRAM_ERROR * size, np.zeros(n), np.zeros(n)
    references_ = _REFERENCES.get()
    referred = None if references_ is None else _referred(A, references_, low, high, size,
                                                          error)
    if referred is not None:
        known, bounded = referred
    elif (references_ is not None and A.shape not in references_
          and len(references_) < KEPT_REFERENCES and A.nbytes <= REFERENCE_BYTES):
        known = np.ones(n, dtype=bool)                     # this shape's reference
        bounded = _bound(A, known, low, high, size)
        references_[A.shape] = _reference(A, low, high, error, bounded)
    else:
        known = np.zeros(n, dtype=bool)
        known[::PROBE] = known[-1] = True
        bounded = _bound(A, known, low, high, size)
        rest = ~known
        if rest.any() and bounded[known].all():
            rest[rest] = ~_ruled_out(A, known, rest, low, high, error)
        if rest.any():
            bounded = _bound(A, rest, low, high, size)
            known |= rest
    if not bounded.any():
        return None
    with np.errstate(divide="ignore", invalid="ignore"):     # (steps not bounded)
        upper = np.sqrt((high + error) / (low - error))
        lower = np.sqrt(np.maximum(high - error, 0.0) / (low + error))
    reach = np.max(lower[bounded]) * (1 - SVD_ERROR)
    return np.nonzero(known & (~bounded | (upper * (1 + SVD_ERROR) >= reach)))[0]


def _bound(A, steps, low, high, size) -> np.ndarray:
    """λ_min, λ_max of the Gram matrices of A (A Aᵀ or Aᵀ A, the smaller) at ``steps`` (a
    mask) into ``low``, ``high``; the steps whose bounds are tight: λ_min > ‖A‖_F² /
    BOUNDED² (then λ_min − error > 0)."""
    B = A[steps]
    G = B @ B.transpose(0, 2, 1) if B.shape[1] < B.shape[2] else B.transpose(0, 2, 1) @ B
    lam = np.linalg.eigvalsh(G)
    low[steps], high[steps] = lam[:, 0], lam[:, -1]
    return low > size / BOUNDED ** 2


def _ruled_out(A, known, rest, low, high, error) -> np.ndarray:
    """Of the steps ``rest`` (a mask), those whose κ is below the largest lower bound of
    the ``known`` steps' for certain: σ_1(A_k) ≤ σ_1(A_j) + d, σ_r(A_k) ≥ σ_r(A_j) − d
    (Weyl) for d ≥ ‖A_k − A_j‖_2, j a probed step next to k (its bounds all tight); d is
    the sum of the steps' ‖A_{i+1} − A_i‖_F from j to k (one difference of the stack)."""
    steps = np.flatnonzero(rest)
    j = np.minimum((steps + PROBE // 2) // PROBE * PROBE, len(A) - 1)
    D = A[1:] - A[:-1]
    walked = np.zeros(len(A))
    np.cumsum(np.sqrt(np.einsum("nij,nij->n", D, D)), out=walked[1:])
    # (the sums' round-off: below 1e-12 of the whole walk)
    d = np.abs(walked[steps] - walked[j]) * (1 + SVD_ERROR) + 1e-12 * walked[-1]
    smallest, largest = np.sqrt(low[j] - error[j]) - d, np.sqrt(high[j] + error[j]) + d
    lower = np.sqrt(np.maximum(high[known] - error[known], 0.0) / (low[known] + error[known]))
    return largest * (1 + 2 * SVD_ERROR) < np.max(lower) * (1 - SVD_ERROR) * smallest


#: ``references``' stacks: shape → (R, σ_1 ≥, σ_1 ≤, σ_r ≥, σ_r ≤ of every step), or None
#: outside it (a context variable: each thread its own)
_REFERENCES: ContextVar[dict | None] = ContextVar("references", default=None)
#: at most this many shapes kept by ``references``, each of at most this many bytes
KEPT_REFERENCES, REFERENCE_BYTES = 4, 1 << 23


@contextmanager
def references():
    """Within it, ``largest_condition`` keeps the first equilibrated Cq stack of each shape
    with its Gram eigenvalues at every step (a reference) and bounds a later stack's κ from
    it (``_referred``): a study's variants, whose Cq differ little, then need the
    eigenvalues at a few steps, not at every PROBE-th. What it returns is the same: the
    references decide only which steps get their SVD, and every step that can be the
    largest does. Left: the references go."""
    token = _REFERENCES.set({} if _REFERENCES.get() is None else _REFERENCES.get())
    try:
        yield
    finally:
        _REFERENCES.reset(token)


def _reference(R, low, high, error, bounded) -> tuple:
    """(R, σ_1 ≥, σ_1 ≤, σ_r ≥, σ_r ≤) at every step of R from its Gram eigenvalues (within
    ±``error``; σ_r ≥ 0 where they are not tight)."""
    floor = np.where(bounded, np.sqrt(np.maximum(low - error, 0.0)), 0.0)
    return (R.copy(), np.sqrt(np.maximum(high - error, 0.0)), np.sqrt(high + error),
            floor, np.sqrt(low + error))


def _referred(A, references_: dict, low, high, size, error) -> tuple | None:
    """(the steps (a mask) whose κ(A) can be the largest by the reference of A's shape
    among ``references_`` (``references``), their Gram eigenvalues put into ``low``,
    ``high``; the steps whose bounds are tight, ``_bound``'s); None without a reference, or
    when it leaves more than half of the steps.

    Weyl: |σ_i(A_k) − σ_i(R_k)| ≤ ‖A_k − R_k‖_2 ≤ d_k = ‖A_k − R_k‖_F (1 + SVD_ERROR) (its
    round-off: ~n ε of it), so κ_k ≤ (σ_1(R_k)≤ + d_k) / (σ_r(R_k)≥ − d_k) where that
    denominator is positive, and κ_k ≥ (σ_1(R_k)≥ − d_k) / (σ_r(R_k)≤ + d_k): a step whose
    upper bound × (1 + 2 SVD_ERROR) is below the largest lower bound × (1 − SVD_ERROR) is
    below the largest κ, with the margins of ``_ruled_out``; the step of the largest κ is
    never one of those."""
    ref = references_.get(A.shape)
    if ref is None:
        return None
    R, top_low, top_high, bottom_low, bottom_high = ref
    D = A - R
    d = np.sqrt(np.einsum("nij,nij->n", D, D)) * (1 + SVD_ERROR)
    floor = bottom_low - d
    with np.errstate(divide="ignore", invalid="ignore"):
        upper = np.where(floor > 0.0, (top_high + d) / floor, np.inf)
        lower = (top_low - d) / (bottom_high + d)
    near = upper * (1 + 2 * SVD_ERROR) >= np.max(lower) * (1 - SVD_ERROR)
    if np.count_nonzero(near) > len(A) // 2:
        return None
    return near, _bound(A, near, low, high, size)


def _equilibrated(J: np.ndarray) -> np.ndarray:
    """J with its rows and columns scaled to unit length, three passes (a copy)."""
    if np.iscomplexobj(J):
        for _ in range(3):
            J = J / np.maximum(np.linalg.norm(J, axis=2, keepdims=True), 1e-300)
            J = J / np.maximum(np.linalg.norm(J, axis=1, keepdims=True), 1e-300)
        return J
    if len(J) >= STACKED and J.dtype == np.float64 and J.flags.c_contiguous \
            and 1 <= J.shape[2] <= PAIRWISE:
        return _equilibrated_stack(J)
    # the same operations as np.linalg.norm's (√ of the sums of squares, in its order), in
    # place: a third fewer passes over the arrays
    squares, A = J * J, None
    for axis in (2, 1, 2, 1, 2, 1):
        if A is not None:
            np.multiply(A, A, out=squares)
        norm = np.sqrt(np.add.reduce(squares, axis=axis, keepdims=True))
        np.maximum(norm, 1e-300, out=norm)
        A = J / norm if A is None else np.divide(A, norm, out=A)
    return A


#: from this many matrices on, ``_equilibrated`` lays the stack out entry by entry
#: (``_equilibrated_stack``)
STACKED = 20
#: numpy's reduce sums up to this many numbers in one pairwise block (8 partial sums)
PAIRWISE = 128


def _equilibrated_stack(J: np.ndarray) -> np.ndarray:
    """``_equilibrated`` of a stack of real matrices (n, m, nq), the same bits in fewer,
    longer numpy loops: laid out T[j, i] = J[:, i, j] (each entry a row of the n matrices),
    the rows' sums of squares taken in the order numpy's reduce takes a row's
    (``_pairwise``), the columns' in order (numpy's reduce over an outer axis)."""
    T = np.ascontiguousarray(J.transpose(2, 1, 0))          # (nq, m, n)
    squares, A = T * T, None
    for _ in range(3):
        if A is not None:
            np.multiply(A, A, out=squares)
        norm = np.sqrt(_pairwise(squares))                  # the rows' (m, n)
        np.maximum(norm, 1e-300, out=norm)
        A = T / norm if A is None else np.divide(A, norm, out=A)
        np.multiply(A, A, out=squares)
        norm = np.sqrt(np.add.reduce(squares, axis=1, keepdims=True))   # the columns'
        np.maximum(norm, 1e-300, out=norm)
        np.divide(A, norm, out=A)
    return np.ascontiguousarray(A.transpose(2, 1, 0))


def _pairwise(S: np.ndarray) -> np.ndarray:
    """Σ_j S[j] (k ≤ PAIRWISE terms) in numpy's pairwise order for a contiguous row: in
    order below 8 terms; else 8 partial sums r of every 8th term, added as
    ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7)), then the terms left over in order."""
    k = len(S)
    if k < 8:
        total = S[0].copy()
        for j in range(1, k):
            total += S[j]
        return total
    end = k - k % 8
    partial = S[:8] if end == 8 else S[:8] + S[8:16]
    for j in range(16, end, 8):
        partial += S[j:j + 8]
    pairs = partial[0::2] + partial[1::2]               # r0 + r1, r2 + r3, …
    quads = pairs[0::2] + pairs[1::2]
    total = quads[0] + quads[1]
    for j in range(end, k):
        total += S[j]
    return total


def _kappa(A: np.ndarray, rank: int) -> np.ndarray:
    """σ_1 / σ_rank of each matrix A (the SVD's; ∞ or NaN where σ_rank = 0)."""
    s = np.linalg.svd(A, compute_uv=False)
    with np.errstate(divide="ignore", invalid="ignore"):
        return s[:, 0] / s[:, rank - 1]


@dataclass
class Mobility:
    """Degrees of freedom and redundancy of the constraints at one configuration."""

    dof: int
    redundant: int
    free_solids: list[str]
    redundant_elements: list[str]
    condition: float

    def describe(self) -> str:
        text = f"{self.dof} degree(s) of freedom left free by the actuators"
        if self.redundant:
            text += f", {self.redundant} redundant constraint equation(s)"
        return text


def _rank(mech, t: float, q: np.ndarray, rtol: float, rows=None, jacobian=None):
    """(U, s, Vt, rank) of the SVD of Cq at (q, t), with the angle columns scaled by the
    length scale so that all columns have units of length (only the equations ``rows``,
    when given); None without equations. ``jacobian``: Cq (m, nq) at (q, t) when already
    evaluated."""
    J = equations(mech, State([t], q[None, :])).jacobian[0] if jacobian is None else jacobian
    if rows is not None:
        J = J[rows]
    J = _scaled(mech, J)
    if J.shape[0] == 0:
        return None
    U, s, Vt = np.linalg.svd(J)
    return U, s, Vt, int(np.sum(s > rtol * max(1.0, s[0] if s.size else 1.0)))


def _scaled(mech, J: np.ndarray) -> np.ndarray:
    """Cq with its angle columns (x, y, fi of each solid) times 1 / the length scale
    (``_rank``'s coordinates; a copy)."""
    out = J.copy()
    out[..., 2::3] *= 1.0 / mech.scale()
    return out


def _regular_condition(mech, J: np.ndarray, rtol: float) -> tuple[bool, float | None]:
    """(regular, ``_condition``) of a square Cq (m, nq) of one configuration, the same bits
    from one SVD call on the two matrices: regular when it is of full rank by ``_rank``'s
    test with a margin, its smallest singular value over twice the threshold (then
    ``mobility`` needs no singular vectors: the values alone, from another LAPACK path,
    differ from theirs by round-off, ~1e-15 of the largest, far below the margin); (False,
    None) for another Cq."""
    m, nq = J.shape
    if m != nq or m == 0:
        return False, None
    s = np.linalg.svd(np.stack([_scaled(mech, J), _equilibrated(J[None])[0]]),
                      compute_uv=False)
    with np.errstate(divide="ignore", invalid="ignore"):
        condition = s[1, 0] / s[1, m - 1]
    return bool(s[0, -1] > 2 * rtol * max(1.0, s[0, 0])), float(condition)


def at_guess(mech, t: float, q: np.ndarray):
    """The constraint equations (``native.Equations``) at one configuration q (the initial
    guess), evaluated once for ``require_defined`` and ``mobility`` (NaN where undefined,
    without numpy's warnings)."""
    with np.errstate(all="ignore"):
        return equations(mech, State([t], q[None, :]))


def require_defined(mech, t: float, q: np.ndarray, eq=None) -> None:
    """ModelError when some constraint equation is not defined at the initial guess q
    (a linear actuator whose two points coincide there has no direction); ``eq``: the
    equations there when already evaluated (``at_guess``)."""
    if eq is None:
        eq = at_guess(mech, t, q)
    if np.isfinite(eq.residual).all() and np.isfinite(eq.jacobian).all():
        return                                   # (the elements' rows one by one: not)
    bad = [el for el, rows in zip(mech.constraints, mech.rows)
           if not (np.isfinite(eq.residual[0, rows]).all()
                   and np.isfinite(eq.jacobian[0, rows]).all())]
    if bad:
        raise ModelError([Problem(el.where, (
            "its equation is not defined at the initial guess: its two points coincide "
            "there, so the distance between them has no direction. Give the solids x, y, fi "
            "that put the points apart (near the assembled position)")) for el in bad],
            mech.model.source)


def mobility(mech, t: float, q: np.ndarray, rtol: float = 1e-9, rows=None,
             jacobian: np.ndarray | None = None) -> Mobility:
    """Rank test of Cq at (q, t): free degrees of freedom and redundant equations (of the
    equations ``rows`` only, a mask of C's rows, when given: ``classify`` leaves out the
    actuators'); ``jacobian``: Cq (m, nq) there when already evaluated (one evaluation for
    the rank and the condition number)."""
    if jacobian is None:
        jacobian = equations(mech, State([t], q[None, :])).jacobian[0]
    condition = None
    if rows is None:
        regular, condition = _regular_condition(mech, jacobian, rtol)
        if regular:                                  # no DOF left, none repeated
            return Mobility(0, 0, [], [], condition)
    keep = np.ones(mech.n_equations, dtype=bool) if rows is None else np.asarray(rows)
    svd = _rank(mech, t, q, rtol, None if rows is None else keep, jacobian=jacobian)
    if svd is None:
        return Mobility(mech.nq, 0, [s.name for s in mech.solids], [], np.inf)
    U, s, Vt, rank = svd
    dof, redundant = mech.nq - rank, U.shape[0] - rank
    free = []
    if dof:
        null = Vt[rank:].T                           # (nq, dof)
        weight = np.linalg.norm(null.reshape(len(mech.solids), 3, dof), axis=(1, 2))
        free = [sv.name for sv, w in zip(mech.solids, weight) if w > 1e-6]
    dependent = []
    if redundant:
        weight = np.zeros(mech.n_equations)
        weight[keep] = np.linalg.norm(U[:, rank:], axis=1)    # (m, redundant) → (m,)
        for el, own in zip(mech.constraints, mech.rows):
            if np.max(weight[own]) > 1e-6:
                dependent.append(el.name)
    return Mobility(dof, redundant, free, dependent,
                    _condition(mech, t, q, jacobian) if condition is None else condition)


def _condition(mech, t: float, q: np.ndarray, jacobian: np.ndarray) -> float:
    """``condition_numbers`` at one configuration, Cq (m, nq) there given."""
    return float(condition_numbers(mech, [t], q[None, :], jacobian[None])[0])


def contradiction(mech, t: float, q: np.ndarray, rtol: float = 1e-9,
                  without=None) -> tuple[float, list[str]]:
    """How far redundant constraints contradict each other at time t, near configuration q.

    With N the left null space of Cq(q) (the combinations of equations that no change of q
    can alter, to first order), |Nᵀ C(q, t)| is a violation no configuration near q can
    remove: the constraints' targets disagree. Returns that size (in the equations' units,
    m or rad) and the elements whose equations make it up. Zero when Cq has full row rank.
    ``without``: an element whose equations are left out.
    """
    keep = np.ones(mech.n_equations, dtype=bool)
    if without is not None:
        keep[mech.rows[mech.constraints.index(without)]] = False
    svd = _rank(mech, t, q, rtol, keep)
    if svd is None or svd[3] == svd[0].shape[0]:
        return 0.0, []
    left = np.zeros((mech.n_equations, svd[0].shape[0] - svd[3]))
    left[keep] = svd[0][:, svd[3]:]                        # (m, redundant)
    disagreement = left.T @ residuals(mech, np.array([t]), q[None, :])[0]
    share = np.abs(left @ disagreement)                    # each equation's part in it
    names = [el.name for el, rows in zip(mech.constraints, mech.rows)
             if np.max(share[rows]) > 1e-6 * max(float(np.max(share)), 1e-300)]
    return float(np.linalg.norm(disagreement)), names


def culprit(mech, t: float, q: np.ndarray, among: list[str], size: float):
    """The last element of ``among`` (in the file's order; joints before actuators and
    fixed links) without whose equations the others no longer contradict each other (the
    extra constraint a user added last), or None. ``size``: the contradiction with it, the
    scale of "no longer"."""
    concerned = [e for e in mech.constraints if e.name in among]
    setters = [e for e in concerned if e.drives or e.grounds]
    joints = [e for e in concerned if e not in setters]
    for el in [*reversed(joints), *reversed(setters)]:
        if contradiction(mech, t, q, without=el)[0] <= 1e-3 * size:
            return el
    return None


def require_driven(mech, mob: Mobility, analysis: str) -> None:
    """Raise MobilityError when some degree of freedom is not driven."""
    if mob.dof <= 0:
        return
    solids = ", ".join(f"'{s}'" for s in mob.free_solids)
    raise MobilityError(Problem(
        f"{analysis} analysis",
        f"the mechanism has {mob.dof} free degree(s) of freedom that no actuator drives: "
        f"solid(s) {solids} can still move. Add an angular_actuator or linear_actuator "
        f"(or a fixed link) for each free degree of freedom, or run an analysis that "
        f"lets them go: assembly (the pose nearest the guess), equilibrium (at rest under "
        f"the loads) or dynamic (in motion)."), mech.model.source)

"""The native pass: constraint equations, Jacobian, velocities and accelerations.

Everything here is NumPy on all time steps at once (in chunks that bound memory):

    C(q, t) = 0                 positions (solved by the backend, checked here)
    Cq qd = −C_t                velocities
    Cq qdd = γ                  accelerations, γ = f'' − conv (see kinematics)
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import MobilityError, ModelError, Problem
from ..kinematics import ANGLES, PER_SOLID, State, column
from ..laws import Law
from ..progress import Progress

#: bytes of Jacobian kept in memory at once (steps are processed in chunks)
CHUNK_BYTES = 64 * 2**20
#: from this many constraint equations on, a chunk of steps is solved as one sparse,
#: block-diagonal system (one LU for velocities and accelerations, cost linear in the
#: mechanism's size) instead of dense batched solves (cost cubic in it)
SPARSE_FROM = 40
#: unknowns per sparse chunk
SPARSE_CHUNK = 200_000
#: steps per chunk of the residuals and the continuity defect: their arrays then stay in
#: the cache
RESIDUAL_CHUNK = 8192


@dataclass
class Equations:
    """C (n, m), Cq (n, m, nq), C_t (n, m), γ (n, m; None without velocities) and the
    constraint quantity v of each element (``mech.constraints`` order; the reactions read
    their dv/dq blocks)."""

    residual: np.ndarray
    jacobian: np.ndarray
    c_t: np.ndarray
    gamma: np.ndarray | None
    parts: list


def target_values(target, t, m):
    """(f, f', f'') of a constraint's right-hand side, each (n, m) or broadcastable."""
    if isinstance(target, Law):
        f, df, ddf = target(t)
        return f[:, None], df[:, None], ddf[:, None]
    return np.broadcast_to(np.asarray(target, dtype=float), (m,)), 0.0, 0.0


def equations(mech, st: State, jacobian: bool = True) -> Equations:
    """All constraint equations of a mechanism at the states ``st`` (without ``jacobian``,
    Cq is not assembled: ``Equations.jacobian`` is None)."""
    n, m = st.n, mech.n_equations
    residual, c_t = np.zeros((n, m)), np.zeros((n, m))
    jac = np.zeros((n, m, mech.nq)) if jacobian else None
    gamma = np.zeros((n, m)) if st.qd is not None else None
    parts = []
    for el, rows in zip(mech.constraints, mech.rows):
        v, target = el.constraint(st)
        parts.append(v)
        f, df, ddf = target_values(target, st.t, el.equations)
        residual[:, rows] = v.value - f
        c_t[:, rows] = -np.broadcast_to(df, (n, el.equations))
        if jac is not None:
            v.rows(jac, rows.start)
        if gamma is not None:
            gamma[:, rows] = ddf - v.conv
    return Equations(residual, jac, c_t, gamma, parts)


def chunks(mech, n: int, sparse: bool = False, most: int | None = None):
    """Slices of the n steps, each small enough that its Jacobian fits in CHUNK_BYTES
    (sparse: SPARSE_CHUNK unknowns), and of at most ``most`` steps."""
    if sparse:
        size = max(1, SPARSE_CHUNK // max(1, mech.nq))
    else:
        size = max(1, CHUNK_BYTES // (8 * max(1, mech.n_equations) * mech.nq))
    size = min(size, most or size)
    return (slice(a, min(n, a + size)) for a in range(0, n, size))


def sparse_jacobian(mech, st: State):
    """Cq of every state as one block-diagonal sparse matrix, (n·m, n·nq), CSR."""
    from scipy.sparse import coo_matrix
    n, m, nq = st.n, mech.n_equations, mech.nq
    step = np.arange(n)[:, None, None]
    rows, cols, data = [], [], []
    for el, rr in zip(mech.constraints, mech.rows):
        v, _ = el.constraint(st)
        for solid, block in v.jac.items():                      # (n, d, 3)
            r = step * m + rr.start + np.arange(block.shape[1])[None, :, None]
            c = step * nq + column(solid, np.arange(PER_SOLID))[None, None, :]
            rows.append(np.broadcast_to(r, block.shape).ravel())
            cols.append(np.broadcast_to(c, block.shape).ravel())
            data.append(block.ravel())
    return coo_matrix((np.concatenate(data), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(n * m, n * nq)).tocsr()


def sparse_lu(J, rows, cols, n: int, m: int, nq: int):
    """LU of the block-diagonal system restricted to ``rows`` and ``cols`` of every step;
    None where it is singular."""
    from scipy.sparse.linalg import splu
    R = (np.arange(n)[:, None] * m + rows[None]).ravel()
    C = (np.arange(n)[:, None] * nq + cols[None]).ravel()
    try:
        return splu(J[R][:, C].tocsc())
    except RuntimeError:                           # exactly singular somewhere
        return None


def residuals(mech, t, q) -> np.ndarray:
    """Constraint residual C(q, t), (n, m)."""
    t, q = np.atleast_1d(np.asarray(t, dtype=float)), np.atleast_2d(q)
    out = np.empty((len(t), mech.n_equations))
    for s in chunks(mech, len(t), most=RESIDUAL_CHUNK):
        out[s] = equations(mech, State(t[s], q[s], jacobians=False), jacobian=False).residual
    return out


def worst_elements(mech, residual_row: np.ndarray, count: int = 3) -> list[tuple[str, float]]:
    """The elements whose equations are violated most in one residual row."""
    scores = [(el, float(np.max(np.abs(residual_row[rows]))))
              for el, rows in zip(mech.constraints, mech.rows)]
    scores.sort(key=lambda s: -s[1])
    return [(f"'{el.name}' ({el.type})", r) for el, r in scores[:count] if r > 0]


def _solve(J, b, redundant, rtol=1e-12):
    """x with J x = b per step: LU when square; x = V Σ⁻¹ Uᵀ b (exact when consistent) if
    redundant or where LU fails. Rows where J has lost rank (a singular position) are NaN.
    """
    if J.shape[2] == 0:                     # nothing moves (every solid is held)
        return np.zeros(J.shape[:1] + J.shape[2:])
    if not redundant:
        try:
            return np.linalg.solve(J, b[..., None])[..., 0]
        except np.linalg.LinAlgError:       # an exactly singular step: solve this chunk by SVD
            pass

    U, s, Vt = np.linalg.svd(J, full_matrices=False)
    with np.errstate(divide="ignore", invalid="ignore"):
        x = np.einsum("nkq,nk->nq", Vt, np.einsum("nmk,nm->nk", U, b) / s)
    x[s[:, -1] <= rtol * s[:, 0]] = np.nan
    return x


def turns_jumped(t, q, qd, solids: int) -> np.ndarray:
    """n (steps, solids): whole turns by which each angle jumped at each step.

    fi_k − fi_j − (t_k − t_j)(ω_k + ω_j)/2 ≈ 2π n, j the previous step with finite rates
    (a step without rates is predicted from ω_j alone). Newton's iteration at a singular
    position can land on the same configuration with an angle off by whole turns.
    """
    fi, w = q[:, ANGLES][:, :solids], qd[:, ANGLES][:, :solids]
    valid = np.isfinite(w).all(axis=1)
    valid[0] = True
    if valid.all():                  # j = k − 1 at every step: slices, not gathers
        j, k = slice(None, -1), slice(1, None)
        wk = w[k]
    else:
        last = np.maximum.accumulate(np.where(valid, np.arange(len(t)), 0))
        j, k = last[:-1], np.arange(1, len(t))
        wk = np.where(valid[k, None], w[k], w[j])
    n = np.zeros(fi.shape)
    with np.errstate(invalid="ignore"):
        n[1:] = np.rint((fi[k] - fi[j] - (t[k] - t[j])[:, None] * (wk + w[j]) / 2)
                        / (2 * np.pi))
    n[~np.isfinite(n)] = 0.0
    return n


def whole_turns(mech, t: float, q: np.ndarray, target: np.ndarray) -> np.ndarray:
    """n (solids,): whole turns to take from each angle of q (a configuration at time t) to
    bring it nearest the angle of ``target``, where the constraints still hold after it.

    Joints are 2π-periodic in the angles, actuators and transmissions are not: a solid whose
    angle an actuator sets keeps its turn. Each solid is tried alone, then all together
    (gears coupled by a transmission turn together).
    """
    wanted = np.rint((q[ANGLES] - target[ANGLES]) / (2 * np.pi))
    wanted[~np.isfinite(wanted)] = 0.0
    if not wanted.any() or mech.n_equations == 0:
        return wanted
    tol = 10 * max(float(np.max(np.abs(residuals(mech, [t], q)))), 1e-12 * mech.scale())

    def holds(turns):
        moved = q.copy()
        moved[ANGLES] -= 2 * np.pi * turns
        return float(np.max(np.abs(residuals(mech, [t], moved)))) <= tol

    if holds(wanted):
        return wanted
    accepted = np.zeros_like(wanted)
    for i in np.nonzero(wanted)[0]:
        trial = accepted.copy()
        trial[i] = wanted[i]
        if holds(trial):
            accepted = trial
    return accepted


def continuity_defect(t, qd, qdd, scale, breakpoints=()) -> np.ndarray:
    """d_k = max |qd_k − qd_{k−1} − dt (qdd_k + qdd_{k−1})/2| / scale (k ≥ 1; d_0 = 0).

    On a smooth motion d_k = O(dt³); a jump of the velocities, as when Newton's iteration
    switches to another branch of the mechanism, makes it O(1). Steps whose interval holds
    a law breakpoint (where velocities may jump) get 0.
    """
    dt = np.diff(t)[:, None]
    d = np.zeros(len(t))
    for a in range(1, len(t), RESIDUAL_CHUNK):      # in blocks that stay in the cache
        k = slice(a, min(len(t), a + RESIDUAL_CHUNK))
        j = slice(a - 1, k.stop - 1)
        jump = qd[k] - qd[j] - dt[j] * (qdd[k] + qdd[j]) / 2
        with np.errstate(invalid="ignore"):
            d[k] = np.max(np.abs(jump) / scale, axis=1)
    d[np.isnan(d)] = np.inf
    for b in breakpoints:
        d[1:][(t[:-1] < b) & (b <= t[1:])] = 0.0
    return d


def rates(mech, t, q, accelerations: bool, redundant: bool):
    """(qd, qdd, C) at every step; qdd is None when not asked for; C = C(q, t) (n, m)
    comes from the same evaluation of the equations, for the residual check."""
    n = len(t)
    qd = np.zeros_like(q)
    qdd = np.zeros_like(q) if accelerations else None
    residual = np.empty((n, mech.n_equations))
    rows, cols = moving(mech)
    sparse = not redundant and mech.n_equations >= SPARSE_FROM
    parts = list(chunks(mech, n, sparse=sparse))
    # a bar on a terminal when the pass takes several chunks (one chunk: over in a blink)
    with Progress(len(parts), "velocities and accelerations") as bar:
        for done, s in enumerate(parts, start=1):
            if not (sparse and _sparse_rates(mech, t[s], q[s], qd[s],
                                             qdd[s] if accelerations else None,
                                             residual[s], rows, cols)):
                _dense_rates(mech, t[s], q[s], qd[s], qdd[s] if accelerations else None,
                             residual[s], rows, cols, redundant)
            bar.update(done)
    return qd, qdd, residual


def _sparse_rates(mech, t, q, qd, qdd, residual, rows, cols) -> bool:
    """Fill qd, qdd (views) of a chunk by one sparse LU; False if it is singular."""
    st = State(t, q)
    eq = equations(mech, st, jacobian=False)
    residual[:] = eq.residual
    n = st.n
    lu = sparse_lu(sparse_jacobian(mech, st), rows, cols, n, mech.n_equations, mech.nq)
    if lu is None:
        return False
    qd[:, cols] = lu.solve(np.ascontiguousarray(-eq.c_t[:, rows]).ravel()).reshape(n, -1)
    if qdd is not None:
        gamma = equations(mech, State(t, q, qd, jacobians=False), jacobian=False).gamma
        qdd[:, cols] = lu.solve(np.ascontiguousarray(gamma[:, rows]).ravel()).reshape(n, -1)
    return True


def _dense_rates(mech, t, q, qd, qdd, residual, rows, cols, redundant) -> None:
    """Fill qd, qdd (views) of a chunk by batched dense solves."""
    eq = equations(mech, State(t, q))
    residual[:] = eq.residual
    J = eq.jacobian[:, rows[:, None], cols]
    qd[:, cols] = _solve(J, -eq.c_t[:, rows], redundant)
    if qdd is not None:
        gamma = equations(mech, State(t, q, qd, jacobians=False), jacobian=False).gamma
        qdd[:, cols] = _solve(J, gamma[:, rows], redundant)


def moving(mech):
    """(rows, columns) of Cq left once fixed links and the solids they hold are removed:
    those solids do not move (q̇ = q̈ = 0), so the rate solves are smaller."""
    held = {el.ref1.solid for el in mech.constraints if el.grounds}
    rows = [r for el, rr in zip(mech.constraints, mech.rows) if not el.grounds
            for r in range(rr.start, rr.stop)]
    cols = [column(i, k) for i in range(len(mech.solids)) if i not in held
            for k in range(PER_SOLID)]
    return np.array(rows, dtype=int), np.array(cols, dtype=int)


def condition_numbers(mech, t, q) -> np.ndarray:
    """κ(Cq) at each step: largest over smallest singular value of the constraint Jacobian,
    its rows and columns equilibrated first (each scaled to unit length, three passes), so
    that units and the choice of length scale drop out; ∞ at a singular position.

    The one condition number of pam2exu (``pam2exu check``, ``Results.info``, the
    ConditionWarning). The shipped examples: 1.5 to 8.6 over their motion; a four-bar
    0.2° from a change point: about 190.
    """
    J = equations(mech, State(t, q)).jacobian
    if J.shape[1] == 0:
        return np.full(len(J), np.inf)
    for _ in range(3):
        J = J / np.maximum(np.linalg.norm(J, axis=2, keepdims=True), 1e-300)
        J = J / np.maximum(np.linalg.norm(J, axis=1, keepdims=True), 1e-300)
    s = np.linalg.svd(J, compute_uv=False)
    with np.errstate(divide="ignore", invalid="ignore"):
        return s[:, 0] / s[:, min(J.shape[1], mech.nq) - 1]


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


def _rank(mech, t: float, q: np.ndarray, rtol: float, rows=None):
    """(U, s, Vt, rank) of the SVD of Cq at (q, t), with the angle columns scaled by the
    length scale so that all columns have units of length (only the equations ``rows``,
    when given); None without equations."""
    J = equations(mech, State([t], q[None, :])).jacobian[0]
    if rows is not None:
        J = J[rows]
    J = J * np.tile([1.0, 1.0, 1.0 / mech.scale()], len(mech.solids))
    if J.shape[0] == 0:
        return None
    U, s, Vt = np.linalg.svd(J)
    return U, s, Vt, int(np.sum(s > rtol * max(1.0, s[0] if s.size else 1.0)))


def require_defined(mech, t: float, q: np.ndarray) -> None:
    """ModelError when some constraint equation is not defined at the initial guess q
    (a linear actuator whose two points coincide there has no direction)."""
    with np.errstate(all="ignore"):
        eq = equations(mech, State([t], q[None, :]))
    bad = [el for el, rows in zip(mech.constraints, mech.rows)
           if not (np.isfinite(eq.residual[0, rows]).all()
                   and np.isfinite(eq.jacobian[0, rows]).all())]
    if bad:
        raise ModelError([Problem(el.where, (
            "its equation is not defined at the initial guess: its two points coincide "
            "there, so the distance between them has no direction. Give the solids x, y, fi "
            "that put the points apart (near the assembled position)")) for el in bad],
            mech.model.source)


def mobility(mech, t: float, q: np.ndarray, rtol: float = 1e-9) -> Mobility:
    """Rank test of Cq at (q, t): free degrees of freedom and redundant equations."""
    svd = _rank(mech, t, q, rtol)
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
        left = U[:, rank:]                           # (m, redundant)
        weight = np.linalg.norm(left, axis=1)
        for el, rows in zip(mech.constraints, mech.rows):
            if np.max(weight[rows]) > 1e-6:
                dependent.append(el.name)
    condition = float(condition_numbers(mech, [t], q[None, :])[0])
    return Mobility(dof, redundant, free, dependent, condition)


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


def first_singular(mech, t, q, rtol: float = 1e-10) -> int:
    """Index of the first step where Cq is (numerically) rank-deficient, else the last step."""
    n = len(t)
    for s in chunks(mech, n):
        J = equations(mech, State(t[s], q[s])).jacobian
        sv = np.linalg.svd(J, compute_uv=False)
        rank = np.sum(sv > rtol * sv[:, :1], axis=1)
        bad = np.nonzero(rank < mech.nq)[0]
        if bad.size:
            return s.start + int(bad[0])
    return n - 1

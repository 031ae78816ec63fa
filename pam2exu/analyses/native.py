"""The native pass: constraint equations, Jacobian, velocities and accelerations (the rank
tests of the Jacobian are in ``rank.py``, the continuity checks of a motion in
``continuity.py``).

Everything here is NumPy on all time steps at once (in chunks that bound memory):

    C(q, t) = 0                 positions (solved by the backend, checked here)
    Cq qd = −C_t                velocities
    Cq qdd = γ                  accelerations, γ = f'' − conv (see kinematics)
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..complex_step import as_array
from ..kinematics import PER_SOLID, PointSet, State, column
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
#: the key under which a mechanism keeps the points and directions its constraints ask
#: for (``kinematics.PointSet``, from its first evaluation): ``equations`` builds them at
#: once afterwards (``State.prepare``)
POINTS = "_constraint_points"


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
    """(f, f', f'') of a constraint's right-hand side, each (n, m) or broadcastable to it
    (a constant: a read-only view of it, not ``np.broadcast_to``'s, 5 µs a constraint; a
    float: itself)."""
    if type(target) is float:                   # (a joint's 0.0: no array to make)
        return target, 0.0, 0.0
    if isinstance(target, Law):
        f, df, ddf = target(t)
        return f[:, None], df[:, None], ddf[:, None]
    target = as_array(target)                  # (m,), or (n, m) where it varies by row
    if target.ndim == 0 or target.shape == (m,):    # read-only, broadcast where used
        view = target.view()
        view.flags.writeable = False
        return view, 0.0, 0.0
    return np.broadcast_to(target, np.broadcast_shapes(target.shape, (m,))), 0.0, 0.0


def equations(mech, st: State, jacobian: bool = True) -> Equations:
    """All constraint equations of a mechanism at the states ``st`` (without ``jacobian``,
    Cq is not assembled: ``Equations.jacobian`` is None)."""
    n, m, dtype = st.n, mech.n_equations, st.q.dtype    # complex in the complex step
    # C_t = −f' of each row: −0.0 where the target is constant (f' = 0.0, not written)
    residual, c_t = np.zeros((n, m), dtype), np.full((n, m), -0.0, dtype)
    jac = np.zeros((n, m, mech.nq), dtype) if jacobian else None
    gamma = np.zeros((n, m), dtype) if st.qd is not None else None
    points = mech.__dict__.get(POINTS) if st.jacobians else None
    if points is not None:
        st.prepare(points)              # the elements' points at once, the same values
    parts = []
    for el, rows in zip(mech.constraints, mech.rows):
        v, target = el.constraint(st)
        parts.append(v)
        f, df, ddf = target_values(target, st.t, el.equations)
        residual[:, rows] = v.value - f
        if isinstance(target, Law):             # (a constant's f' = 0.0: −0.0 there)
            c_t[:, rows] = np.negative(df)      # broadcast over the steps
        if jac is not None:
            v.rows(jac, rows.start)
        if gamma is not None:
            gamma[:, rows] = ddf - v.conv
    if points is None and st.jacobians and st.qd is None:
        mech.__dict__[POINTS] = PointSet.of(st.asked)
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
    """Constraint residual C(q, t), (n, m): ``equations``' residual, each element's rows
    written straight into it (without C_t, Cq and the Equations around them)."""
    t, q = np.atleast_1d(np.asarray(t, dtype=float)), np.atleast_2d(q)
    out = np.zeros((len(t), mech.n_equations))
    for s in chunks(mech, len(t), most=RESIDUAL_CHUNK):
        st, rows_of = State(t[s], q[s], jacobians=False), out[s]
        for el, rows in zip(mech.constraints, mech.rows):
            v, target = el.constraint(st)
            rows_of[:, rows] = v.value - target_values(target, st.t, el.equations)[0]
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


def rates(mech, t, q, accelerations: bool, redundant: bool, with_jacobian: bool = False):
    """(qd, qdd, C) at every step; qdd is None when not asked for; C = C(q, t) (n, m)
    comes from the same evaluation of the equations, for the residual check.
    ``with_jacobian``: (qd, qdd, C, Cq), Cq (n, m, nq) from that evaluation too when the
    steps are solved dense in one chunk (else None: it is not kept)."""
    n = len(t)
    qd = np.zeros_like(q)
    qdd = np.zeros_like(q) if accelerations else None
    residual = np.empty((n, mech.n_equations))
    rows, cols = moving(mech)
    sparse = not redundant and mech.n_equations >= SPARSE_FROM
    parts = list(chunks(mech, n, sparse=sparse))
    jacobian = None
    # a bar on a terminal when the pass takes several chunks (one chunk: over in a blink)
    with Progress(len(parts), "velocities and accelerations") as bar:
        for done, s in enumerate(parts, start=1):
            if not (sparse and _sparse_rates(mech, t[s], q[s], qd[s],
                                             qdd[s] if accelerations else None,
                                             residual[s], rows, cols)):
                J = _dense_rates(mech, t[s], q[s], qd[s], qdd[s] if accelerations else None,
                                 residual[s], rows, cols, redundant)
                if len(parts) == 1:
                    jacobian = J
            bar.update(done)
    return (qd, qdd, residual, jacobian) if with_jacobian else (qd, qdd, residual)


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


def _dense_rates(mech, t, q, qd, qdd, residual, rows, cols, redundant) -> np.ndarray:
    """Fill qd, qdd (views) of a chunk by batched dense solves; returns the chunk's Cq."""
    eq = equations(mech, State(t, q))
    residual[:] = eq.residual
    J = eq.jacobian[:, rows[:, None], cols]
    qd[:, cols] = _solve(J, -eq.c_t[:, rows], redundant)
    if qdd is not None:
        gamma = equations(mech, State(t, q, qd, jacobians=False), jacobian=False).gamma
        qdd[:, cols] = _solve(J, gamma[:, rows], redundant)
    return eq.jacobian


def moving(mech):
    """(rows, columns) of Cq left once fixed links and the solids they hold are removed:
    those solids do not move (q̇ = q̈ = 0), so the rate solves are smaller."""
    rows = [r for el, rr in zip(mech.constraints, mech.rows) if not el.grounds
            for r in range(rr.start, rr.stop)]
    cols = [column(i, k) for i in range(len(mech.solids)) if i not in mech.held
            for k in range(PER_SOLID)]
    return np.array(rows, dtype=int), np.array(cols, dtype=int)

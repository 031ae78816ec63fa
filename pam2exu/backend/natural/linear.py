"""The linear solves of the natural-coordinate Newton solver (``solver.Solver``): Φ_z x = b
for one step or many (dense per step, batched over steps, sparse block-diagonal, or least
squares), the pivot orders that keep the batched solves from exchanging rows, the rates
Φ_z ż = g', Φ_z z̈ = γ, and Newton on a block of steps from good guesses (``_bulk``,
``_bulk_sparse``), whose last factors also give the rates.
"""
from __future__ import annotations

import numpy as np

from ...batched import lu_factor, lu_solve

try:
    # numpy.linalg.solve's own kernel (LAPACK's gesv) for one system, without the wrapper:
    # the same bits; its checks and error-state switches cost more than the solve of a small
    # system (four-bar 100 steps, ~75 solves: 13.3 -> 12.4 ms a run, paired)
    from numpy.linalg._umath_linalg import solve1 as _gesv
except ImportError:                                   # another numpy: its public solve
    _gesv = None

#: from this many coordinates on, a chunk of steps is solved as one sparse block-diagonal
#: system (cost linear in the mechanism's size) instead of dense batched solves
SPARSE_FROM = 40
#: a few steps of a larger system are still solved dense (LAPACK per step) while
#: steps × coordinates² is at most this: a sparse LU's set-up costs more (measured: one
#: step of 129 coordinates, 0.2 ms dense against 0.3 ms sparse)
DENSE_WORK = 20_000
#: below this many steps, the dense solves are numpy's (LAPACK per step) rather than ``batched``
BATCHED_FROM = 64
#: rows are exchanged in the batched solves where a pivot is below this fraction of the
#: largest in its column (``batched.lu_factor``)
PIVOT_THRESHOLD = 0.5
#: bytes of Jacobians kept at once (the steps are solved in chunks)
CHUNK_BYTES = 64 * 2**20
#: a ``_bulk`` block of this many steps or more iterates only its steps still moving once
#: most have stopped (a smaller one as a whole: gathering its few steps costs more than
#: their iteration)
NARROW_FROM = 512


class LinearSolves:
    """The linear algebra of ``Solver`` (a base class: it uses the solver's ``terms``,
    ``w``, ``settings``, ``least_squares``, ``order``, ``fill_rates`` and counts
    ``iterations``)."""

    def rows_per_chunk(self) -> int:
        """Steps solved at once: the Jacobians, their terms and the solves' copies of a
        chunk take about CHUNK_BYTES."""
        t = self.terms
        per_step = 8 * (3 * t.m * t.nz + 3 * len(t.rows) + 3 * (len(t.pr) + len(t.sr)) + 8 * t.nz)
        return max(1, CHUNK_BYTES // per_step)

    # ---- linear algebra -------------------------------------------------------------------
    def solve(self, data: np.ndarray, b: np.ndarray) -> np.ndarray:
        """x with Φ_z x = b per step (data: ``Terms.jacobian``); minimum-norm least squares
        when the system is not square or is singular; NaN where it has lost rank."""
        terms = self.terms
        n = data.shape[0]
        if terms.nz == 0:
            return np.zeros((n, 0))
        if not self.least_squares and n < BATCHED_FROM and (
                terms.nz < SPARSE_FROM or n * terms.nz ** 2 <= DENSE_WORK):
            try:                               # a diverged step gives NaN here too
                return np.linalg.solve(terms.dense(data), b[..., None])[..., 0]
            except np.linalg.LinAlgError:
                pass
        finite = np.isfinite(data).all(axis=1) & np.isfinite(b).all(axis=1)
        if not finite.all():                   # a diverged step: NaN, the others solved
            x = np.full((n, terms.nz), np.nan)
            if finite.any():
                x[finite] = self.solve(data[finite], b[finite])
            return x
        if not self.least_squares:
            if terms.nz >= SPARSE_FROM:
                x = self._sparse(data, b)
                if x is not None:
                    return x
            elif n >= BATCHED_FROM:
                A = terms.dense_cols(data.T, self.order)
                swaps, regular = lu_factor(A, PIVOT_THRESHOLD)
                x = lu_solve(A, swaps, b.T[self.order]).T
                if not regular.all():              # singular: NaN (``_least_squares``)
                    x[~regular] = self._least_squares(data[~regular], b[~regular])
                return x
        return self._least_squares(data, b)

    def solve_one(self, J: np.ndarray, b: np.ndarray) -> np.ndarray:
        """``solve`` at one step (J (m, nz) dense, b (m,) -> x (nz,)): the same LAPACK solve of
        the same matrix where ``solve`` takes numpy's dense one, with fewer calls around it.
        Called under ``numpy.errstate(all="ignore")``: a singular J gives NaN (as ``solve``)."""
        terms = self.terms
        if not self.least_squares and terms.nz and (
                terms.nz < SPARSE_FROM or terms.nz ** 2 <= DENSE_WORK):
            if _gesv is not None:
                return _gesv(J, b, signature="dd->d")
            try:
                return np.linalg.solve(J, b)
            except np.linalg.LinAlgError:
                pass
        return self.solve(J[terms.rows, terms.cols][None], b[None])[0]

    def _least_squares(self, data, b):
        """The minimum-norm least-squares x of Φ_z x = b per step (SVD); NaN where a square
        system is singular."""
        U, s, Vt = np.linalg.svd(self.terms.dense(data), full_matrices=False)
        keep = s > 1e-12 * s[:, :1]
        with np.errstate(divide="ignore", invalid="ignore"):
            coef = np.where(keep, np.einsum("nmk,nm->nk", U, b) / s, 0.0)
        x = np.einsum("nkq,nk->nq", Vt, coef)
        if not self.least_squares:           # square but singular: no unique answer
            x[~keep.all(axis=1)] = np.nan
        return x

    def _sparse(self, data, b):
        lu = self._sparse_lu(data)
        return None if lu is None else lu.solve(np.ascontiguousarray(b).ravel()).reshape(b.shape)

    def _sparse_lu(self, data):
        """The sparse LU of the block-diagonal Φ_z of the steps (data (n, nnz)); None where
        it is singular."""
        from scipy.sparse import csc_matrix
        from scipy.sparse.linalg import splu
        t = self.terms
        n, m, nz = data.shape[0], t.m, t.nz
        step = np.arange(n)[:, None]
        A = csc_matrix((data.ravel(), ((step * m + t.rows).ravel(), (step * nz + t.cols).ravel())),
                       shape=(n * m, n * nz))
        try:
            return splu(A)
        except RuntimeError:
            return None

    def pivot_orders(self, z: np.ndarray) -> np.ndarray:
        """The equations' order (N, m) that partial pivoting gives at each configuration z
        (N, nz), so that the batched solves near it (``batched.lu_factor`` with
        PIVOT_THRESHOLD) rarely exchange rows (which is what costs); ``self.order`` where
        Φ_z is singular."""
        key = z.tobytes()
        if key == self._ordered[0]:              # the run's start, asked again
            return self._ordered[1]
        m, N = self.terms.m, len(z)
        if N == 1:
            order = _pivot_order(self.terms.jacobian_one(z[0]))
            order = (self.order if order is None else order)[None]
            self._ordered = (key, order)
            return order
        A = self.terms.dense_cols(self.terms.jacobian_cols(z.T))
        swaps, regular = lu_factor(A)
        order = np.tile(np.arange(m)[:, None], (1, N))
        each = np.arange(N)
        for k in range(m):                       # the exchanges, in turn
            p = swaps[k]
            order[k], order[p, each] = order[p, each], order[k].copy()
        order[:, ~regular] = self.order[:, None]
        self._ordered = (key, order.T)
        return order.T

    def run_rates(self, t, z):
        """(ż, z̈) at the steps of the last ``run`` (z its answer, solved rows only): those
        found with the positions, the others solved now (written into the run's own rows:
        views of them, not copies; the next ``run`` makes new ones)."""
        n = len(t)
        zd, zdd = self.zd[:n], self.zdd[:n]
        missing = np.nonzero(~self.own_rates[:n])[0]
        if missing.size:
            zd[missing], zdd[missing] = self.rates(t[missing], z[missing])
        return zd, zdd

    def rates(self, t, z):
        """(ż, z̈) at the steps (z solved): Φ_z ż = g', Φ_z z̈ = γ; in chunks that bound
        the memory of the Jacobians."""
        terms = self.terms
        if len(t) == 1 and terms.nz:              # one step (the coarse pass's)
            with np.errstate(all="ignore"):       # a singular Φ_z: NaN
                return tuple(x[None] for x in self.rates_one(t, z[0]))
        zd, zdd = np.empty_like(z), np.empty_like(z)
        rows = self.rows_per_chunk()
        for a in range(0, len(t), rows):
            s = slice(a, a + rows)
            data = terms.jacobian(z[s])
            zd[s] = self.solve(data, terms.velocity_rhs(t[s]))
            zdd[s] = self.solve(data, terms.gamma(t[s], z[s], zd[s]))
        return zd, zdd

    def rates_one(self, t, z):
        """(ż, z̈) (nz,) at one step (t (1,), z (nz,) solved, nz > 0): ``rates``' arithmetic
        on 1-D arrays (under ``numpy.errstate(all="ignore")``: a singular Φ_z gives NaN)."""
        terms = self.terms
        J = terms.jacobian_one(z)
        b = np.zeros(terms.m)
        if terms.laws:
            b[terms.law_rows] = terms.targets(t, 1)[:, 0]
        g2 = terms.targets(t, 2)[:, 0] if terms.laws else None
        zd = self.solve_one(J, b)
        return zd, self.solve_one(J, terms.gamma_one(z, zd, g2))

    def _bulk(self, t, z, order, iterations: int = 4):
        """(z, ż, z̈, ok) for a block of steps of a small square system from good guesses
        (z (nz, n), one column per step, as the answers): each Newton solve also solves
        Φ_z ż = g' (two right-hand sides, one factorisation), and a step's last one (its
        Jacobian at z within the tolerance) gives its z̈; ż, z̈ None without
        ``fill_rates`` (one right-hand side); None where a Jacobian is singular. In a block
        of NARROW_FROM steps or more, once at least half of the steps have a Newton step
        below the tolerance they stop there and the next iterations solve only the steps
        still moving (each step's arithmetic is its own, whichever others share the solve);
        a smaller block, or one where most steps still move, iterates as a whole (fewer,
        larger numpy calls: gathering the few or the many costs more than it saves)."""
        terms, tol, rates = self.terms, self.settings.tolerance, self.fill_rates
        z = np.array(z, dtype=float)
        n, w = len(t), self.w[:, None]
        g = terms.targets(t, 0)
        velocity = terms.velocity_rhs_cols(t)[order] if rates else None
        zd = zdd = None
        step = np.full(n, np.inf)
        active = np.arange(n)                 # the steps still iterating
        whole = True                          # ... all of them, as views
        with np.errstate(all="ignore"):
            for left in range(iterations - 1, -1, -1):
                ta, za, ga = (t, z, g) if whole else (t[active], z[:, active], g[:, active])
                phi, data = terms.residual_jacobian_cols(ta, za, ga)
                A = terms.dense_cols(data, order)
                rhs = np.empty((terms.m, 2 if rates else 1, len(ta)))
                rhs[:, 0] = -phi[order]
                if rates:
                    rhs[:, 1] = velocity if whole else velocity[:, active]
                swaps, regular = lu_factor(A, PIVOT_THRESHOLD)
                if not regular.all():
                    return None
                x = lu_solve(A, swaps, rhs)
                self.iterations += len(ta)
                za += x[:, 0]
                moved = np.max(np.abs(x[:, 0]) * w, axis=0, initial=0.0)
                if whole:
                    step = moved
                else:
                    z[:, active], step[active] = za, moved
                done = moved <= tol
                if done.all():
                    break
                if left and n >= NARROW_FROM and 2 * np.count_nonzero(done) >= len(done):
                    # most have stopped: the others go on without them (x, A are then
                    # the last solve's of the steps still active whenever the loop ends)
                    if rates:                 # the stopped steps' (whole: every step's,
                        part = slice(None) if whole else done   # the others' replaced)
                        zd, zdd = self._bulk_rates(t, z, order, x[:, :, part],
                                                   A[:, :, part], swaps[:, part],
                                                   None if whole else (zd, zdd, active[done]))
                    active, whole = active[~done], False
            if not rates:
                return z, None, None, step <= tol
            # the last solve's steps (converged, or the iterations spent)
            zd, zdd = self._bulk_rates(t, z, order, x, A, swaps,
                                       None if whole else (zd, zdd, active))
        return z, zd, zdd, step <= tol

    def _bulk_rates(self, t, z, order, x, A, swaps, into=None):
        """(ż, z̈) from one of ``_bulk``'s solves: ż its second right-hand side x[:, 1], z̈
        from its factors A, swaps. ``into`` None: the solve is of every step of the block
        (ż a view of x); else (zd, zdd, steps): of those steps, written into zd, zdd."""
        if into is None:
            zd = x[:, 1]
            return zd, lu_solve(A, swaps, self.terms.gamma_cols(t, z, zd)[order])
        zd, zdd, steps = into
        zd[:, steps] = x[:, 1]
        gamma = self.terms.gamma_cols(t[steps], z[:, steps], zd[:, steps])[order]
        zdd[:, steps] = lu_solve(A, swaps, gamma)
        return zd, zdd

    def _bulk_sparse(self, t, z, iterations: int = 4):
        """``_bulk`` for a large system: each Newton iteration one sparse LU of the steps'
        block-diagonal Φ_z, the last one's factors also giving ż and z̈ (with
        ``fill_rates``; z (nz, n), one column per step); None where a Jacobian is singular."""
        terms, tol = self.terms, self.settings.tolerance
        z = np.array(z, dtype=float)
        n, w = len(t), self.w[:, None]
        g = terms.targets(t, 0)

        def solve(lu, b):                       # b (m, n) -> x (nz, n)
            return lu.solve(np.ascontiguousarray(b.T).ravel()).reshape(n, terms.nz).T

        with np.errstate(all="ignore"):
            for _ in range(iterations):
                phi, data = terms.residual_jacobian_cols(t, z, g)
                if not (np.isfinite(phi).all() and np.isfinite(data).all()):
                    return None
                lu = self._sparse_lu(data.T)
                if lu is None:
                    return None
                dz = solve(lu, -phi)
                self.iterations += n
                z += dz
                step = np.max(np.abs(dz) * w, axis=0, initial=0.0)
                if np.all(step <= tol):
                    break
            if not self.fill_rates:
                return z, None, None, step <= tol
            zd = solve(lu, terms.velocity_rhs_cols(t))
            zdd = solve(lu, terms.gamma_cols(t, z, zd))
        if not (np.isfinite(zd).all() and np.isfinite(zdd).all()):
            return None
        return z, zd, zdd, step <= tol


def _pivot_order(A: np.ndarray) -> np.ndarray | None:
    """The rows' order (m,) that partial pivoting gives for one square A (m, m): the
    arithmetic and choices of ``batched.lu_factor`` (threshold 1) on that one system, in
    2-D; None where A is singular or not finite (``pivot_orders`` then keeps its order)."""
    if not np.isfinite(A).all():
        return None
    A = A.copy()
    m = len(A)
    order = np.arange(m)
    for k in range(m):
        size = np.abs(A[k:, k]).tolist()
        best, largest = 0, size[0]
        for r in range(1, len(size)):          # the first largest, as lu_factor
            if size[r] > largest:
                best, largest = r, size[r]
        if size[0] < largest:                  # exchange rows k and k + best
            p = k + best
            A[[k, p]] = A[[p, k]]
            order[k], order[p] = order[p], order[k]
        pivot = A[k, k]
        if not np.isfinite(pivot) or pivot == 0.0:
            return None
        if k + 1 < m:
            L = A[k + 1:, k] / pivot
            A[k + 1:, k] = L
            A[k + 1:, k + 1:] -= L[:, None] * A[k, k + 1:][None]
    return order

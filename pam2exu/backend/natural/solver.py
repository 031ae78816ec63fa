"""Newton's method on the natural-coordinate equations, for all time steps at once.

A run is solved in two passes (vectorised over steps, sequential only where it must be):

1. a coarse sequential pass: every ``stride``-th step from the previous one, Newton started
   from the Taylor predictor z + h ż + h²/2 z̈ (velocities and accelerations there are two
   linear solves); an interval whose predictor misses by more than ``COARSE_MISS`` (a fast
   or nearly singular motion) is solved step by step instead;
2. every step in between at once: Newton started from the cubic Hermite interpolation of
   z and ż at the ends of its interval (error O(h⁴)), Jacobians and solves batched over the
   steps. A step that does not converge, or converges far from its guess (another branch),
   has its interval solved step by step.

A step that Newton cannot solve from the previous one is cut into 2, 4, … 64 sub-steps
before the run stops there.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import SolverError
from ...batched import lu_factor, lu_solve

#: from this many coordinates on, a chunk of steps is solved as one sparse block-diagonal
#: system (cost linear in the mechanism's size) instead of dense batched solves
SPARSE_FROM = 40
#: intervals of the coarse pass (fewer when the run is short)
COARSE = 100
#: the coarse predictor may miss by this much (relative: lengths / L, angles in rad)
#: before its interval is solved step by step
COARSE_MISS = 2e-2
#: bytes of Jacobians kept at once (the steps are solved in chunks)
CHUNK_BYTES = 64 * 2**20
#: a row's magnitude (what its residual is measured against) is at least this fraction of
#: its terms with the coordinates at their scales: a coordinate whose answer is 0 otherwise
#: leaves a round-off residual as large as the row's terms, and no residual is ever small
MAGNITUDE_FLOOR = 1e-6
#: steps solved together by ``_bulk``: small enough for their arrays to stay in the cache
BLOCK = 8192
#: below this many steps, the dense solves are numpy's (LAPACK per step) rather than ``batched``
BATCHED_FROM = 64
#: rows are exchanged in the batched solves where a pivot is below this fraction of the
#: largest in its column (``batched.lu_factor``)
PIVOT_THRESHOLD = 0.5
#: a step that failed is cut into at most this many sub-steps
MAX_SUBSTEPS = 64
#: the extrapolation of a step looks back this many times 8 steps for solved ones
COARSE_GAP = 64


@dataclass
class NaturalSettings:
    """Settings of the natural-coordinate Newton solver.

    Parameters
    ----------
    tolerance : float
        Newton stops when its step is below this, relative to the mechanism's length (angles
        and unit vectors: the step itself), or when the residual is at round-off.
    max_iterations : int
        Newton iterations per step before the step is cut into sub-steps.
    verbose : int
        Unused (the solver prints nothing); kept so that settings read alike.
    """

    tolerance: float = 1e-13
    max_iterations: int = 25
    verbose: int = 0


class Solver:
    """Newton's method for one ``Formulation`` (``terms``), with step weights ``w``."""

    def __init__(self, terms, weights: np.ndarray, settings: NaturalSettings,
                 least_squares: bool):
        self.terms, self.w, self.settings = terms, weights, settings
        self.least_squares = least_squares or terms.m != terms.nz
        self.iterations = 0
        self.floor = MAGNITUDE_FLOOR * terms.magnitude_at(1.0 / weights)[:, None]
        #: the equations in the order of the pivots at the run's start (``pivot_order``)
        self.order = np.arange(terms.m)

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
                A = terms.dense_cols(data.T)[self.order]
                swaps, regular = lu_factor(A, PIVOT_THRESHOLD)
                x = lu_solve(A, swaps, b.T[self.order]).T
                if not regular.all():              # singular: NaN (``_least_squares``)
                    x[~regular] = self._least_squares(data[~regular], b[~regular])
                return x
            else:
                try:
                    return np.linalg.solve(terms.dense(data), b[..., None])[..., 0]
                except np.linalg.LinAlgError:
                    pass
        return self._least_squares(data, b)

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
        from scipy.sparse import csc_matrix
        from scipy.sparse.linalg import splu
        t = self.terms
        n, m, nz = data.shape[0], t.m, t.nz
        step = np.arange(n)[:, None]
        A = csc_matrix((data.ravel(), ((step * m + t.rows).ravel(), (step * nz + t.cols).ravel())),
                       shape=(n * m, n * nz))
        try:
            return splu(A).solve(np.ascontiguousarray(b).ravel()).reshape(n, nz)
        except RuntimeError:
            return None

    def pivot_order(self, t0: float, z0: np.ndarray):
        """Order the equations as partial pivoting would at (t0, z0), so that the batched
        solves (``batched.lu_factor`` with PIVOT_THRESHOLD) rarely exchange rows; the order
        depends on the run's start only (not on how the steps are chunked)."""
        if self.least_squares or not self.terms.m:
            return
        A = self.terms.dense_cols(self.terms.jacobian_cols(z0[:, None]))
        swaps, regular = lu_factor(A)
        if regular.all():
            order = np.arange(self.terms.m)
            for k, p in enumerate(swaps[:, 0]):
                order[[k, p]] = order[[p, k]]
            self.order = order

    def run_rates(self, t, z):
        """(ż, z̈) at the steps of the last ``run`` (z its answer, solved rows only): those
        found with the positions, the others solved now."""
        n = len(t)
        zd, zdd = self.zd[:n].copy(), self.zdd[:n].copy()
        missing = np.nonzero(~self.own_rates[:n])[0]
        if missing.size:
            zd[missing], zdd[missing] = self.rates(t[missing], z[missing])
        return zd, zdd

    def rates(self, t, z):
        """(ż, z̈) at the steps (z solved): Φ_z ż = g', Φ_z z̈ = γ; in chunks that bound
        the memory of the Jacobians."""
        terms = self.terms
        zd, zdd = np.empty_like(z), np.empty_like(z)
        rows = self.rows_per_chunk()
        for a in range(0, len(t), rows):
            s = slice(a, a + rows)
            data = terms.jacobian(z[s])
            zd[s] = self.solve(data, terms.velocity_rhs(t[s]))
            zdd[s] = self.solve(data, terms.gamma(t[s], z[s], zd[s]))
        return zd, zdd

    # ---- Newton -------------------------------------------------------------------------------
    def newton(self, t: np.ndarray, z: np.ndarray):
        """(z, ok) after Newton's iteration from z at every step at once."""
        terms, tol = self.terms, self.settings.tolerance
        z = np.array(z, dtype=float)
        ok = np.zeros(len(t), dtype=bool)
        active = np.arange(len(t))
        eps = np.finfo(float).eps
        last = np.full(len(t), np.inf)        # the previous step's size
        for _ in range(self.settings.max_iterations):
            if not active.size:
                break
            ta, za = t[active], z[active]
            with np.errstate(all="ignore"):
                phi = terms.residual(ta, za)
                dz = self.solve(terms.jacobian(za), -phi)
                step = np.max(np.abs(dz) * self.w, axis=1, initial=0.0)
                small = step <= tol
                # |Φ| relative to its terms: wanted where the step alone does not decide
                ask = ~small | self.least_squares
                size = np.zeros_like(phi)
                if ask.any():
                    magnitude = np.maximum(terms.magnitude(ta[ask], za[ask]), self.floor.T)
                    size[ask] = np.divide(np.abs(phi[ask]), magnitude,
                                          out=np.abs(phi[ask]) * np.inf, where=magnitude > 0)
                    size[phi == 0] = 0.0
            self.iterations += len(active)
            finite = np.isfinite(step)
            if self.least_squares:        # a least-squares step also stops where Φ ≠ 0
                small &= np.all(size <= max(64 * eps, 100 * tol), axis=1)
            # at round-off, steps stop shrinking (at a singular position Φ is quadratic in
            # the error, and a step that still halves is still worth taking); such a step
            # is round-off amplified by a nearly singular Φ_z, and is not taken
            floor = np.all(size <= 64 * eps, axis=1)
            stalled = floor & (step > 0.7 * last[active])
            take = finite & ~stalled
            z[active[take]] = za[take] + dz[take]
            last[active] = step
            done = finite & (small | stalled)
            ok[active[done]] = True
            active = active[finite & ~done]
        return z, ok

    def damped(self, t: float, z: np.ndarray, iterations: int = 200):
        """(z, ok): Newton's iteration at one time from a poor guess, each step shortened
        until it lowers |Φ| (backtracking), then full steps near the solution."""
        terms = self.terms
        t = np.array([t])

        def size(x):
            with np.errstate(all="ignore"):
                phi = terms.residual(t, x[None])[0]
                return float(np.sqrt(np.sum((phi / (1.0 + terms.magnitude(t, x[None])[0])) ** 2)))

        now = size(z)
        for _ in range(iterations):
            with np.errstate(all="ignore"):
                dz = self.solve(terms.jacobian(z[None]), -terms.residual(t, z[None]))[0]
            if not np.isfinite(dz).all():
                return z, False
            alpha = 1.0
            while alpha > 1e-6 and not size(z + alpha * dz) <= (1 - 1e-4 * alpha) * now:
                alpha *= 0.5
            z = z + alpha * dz
            now = size(z)
            if alpha == 1.0:
                done, ok = self.newton(t, z[None])
                if ok[0]:
                    return done[0], True
        return z, False

    def step(self, t0: float, z0: np.ndarray, t1: float, guess: np.ndarray | None = None):
        """z at t1 from z0 at t0 (None if Newton fails even in MAX_SUBSTEPS sub-steps)."""
        z, ok = self.newton(np.array([t1]), (z0 if guess is None else guess)[None])
        if ok[0]:
            return z[0]
        parts = 2
        while parts <= MAX_SUBSTEPS:
            zk = z0
            for tk in np.linspace(t0, t1, parts + 1)[1:]:
                z, ok = self.newton(np.array([tk]), zk[None])
                if not ok[0]:
                    break
                zk = z[0]
            else:
                return zk
            parts *= 2
        return None

    def run(self, t: np.ndarray, z0: np.ndarray):
        """(z (n, nz), solved): the steps of ``t`` from the solved z0 at t[0] (module doc)."""
        n = len(t)
        z = np.full((n, self.terms.nz), np.nan)
        z[0] = z0
        #: rates found with the positions (``_bulk``) at the steps marked in own_rates
        self.zd, self.zdd = np.empty_like(z), np.empty_like(z)
        self.own_rates = np.zeros(n, dtype=bool)
        self.pivot_order(t[0], z0)
        stride = max(1, n // COARSE)
        if stride < 4:
            return self._sequential(t, z, 0, n)
        base, intervals = stride, []      # (k, j, ż_k, ż_j, miss) to fill in the second pass
        end = n                                # the steps solved (all, unless one fails)
        k, zd, zdd = 0, *(r[0] for r in self.rates(t[:1], z[:1]))
        while k < n - 1:
            j = min(n - 1, k + stride)
            if j - k < 4:                      # too fast or too near a singular position
                z, solved = self._sequential(t, z, k, j + 1)
                if solved <= j:
                    end = solved
                    break
                k, stride = j, min(base, 4 * stride)
                zd, zdd = (r[0] for r in self.rates(t[j:j + 1], z[j:j + 1]))
                continue
            h = t[j] - t[k]
            guess = z[k] + h * zd + 0.5 * h * h * zdd
            zj, ok = self.newton(t[j:j + 1], guess[None])
            miss = float(np.max(np.abs(zj[0] - guess) * self.w)) if ok[0] else np.inf
            if miss > COARSE_MISS:             # a shorter interval
                stride = max(1, stride // 4)
                continue
            if miss < COARSE_MISS / 64:
                stride = min(base, 2 * stride)
            z[j] = zj[0]
            zdj, zddj = (r[0] for r in self.rates(t[j:j + 1], z[j:j + 1]))
            intervals.append((k, j, zd, zdj, miss))
            k, zd, zdd = j, zdj, zddj
        bad = self._fill(t, z, intervals)
        for number in bad:                     # another branch, or no convergence
            k, j = intervals[number][:2]
            self.own_rates[k:j + 1] = False
            z, solved = self._sequential(t, z, k, j + 1)
            if solved <= j:
                return z, solved
        return z, end

    def _fill(self, t, z, intervals) -> list[int]:
        """Solve the steps inside every interval at once from cubic Hermite guesses; the
        numbers of the intervals where some step failed or left its guess far behind."""
        if not intervals:
            return []
        k, j = (np.array([iv[i] for iv in intervals]) for i in (0, 1))
        zdk, zdj = (np.array([iv[i] for iv in intervals]) for i in (2, 3))
        allowed = np.maximum(10 * np.array([iv[4] for iv in intervals]), 1e-6)
        counts = j - k - 1
        owner = np.repeat(np.arange(len(intervals)), counts)
        steps = np.concatenate([np.arange(a + 1, b) for a, b in zip(k, j)])
        rows = self.rows_per_chunk()
        failed = np.zeros(len(intervals), dtype=bool)
        for a in range(0, len(steps), rows):    # chunks: memory bounded, whatever the run
            part, at = steps[a:a + rows], owner[a:a + rows]
            h = (t[j] - t[k])[at][:, None]
            u = (t[part][:, None] - t[k][at][:, None]) / h
            guess = ((2 * u**3 - 3 * u**2 + 1) * z[k][at] + (u**3 - 2 * u**2 + u) * h * zdk[at]
                     + (-2 * u**3 + 3 * u**2) * z[j][at] + (u**3 - u**2) * h * zdj[at])
            found = self._bulk(t[part], guess)
            if found is None:
                zi, ok = self.newton(t[part], guess)
            else:
                zi, ok, zd, zdd = found
                self.own_rates[part] = True
                self.zd[part], self.zdd[part] = zd, zdd
            far = np.max(np.abs(zi - guess) * self.w, axis=1) > allowed[at]
            z[part] = zi
            failed[at[~ok | far]] = True
        return list(np.nonzero(failed)[0])

    def _bulk(self, t, z, iterations: int = 4):
        """(z, ok, ż, z̈) for many steps of a small square system from good guesses: each
        Newton solve also solves Φ_z ż = g' (two right-hand sides, one factorisation), and
        the last one's Jacobian (at z within the tolerance) gives z̈; None where that does
        not apply (large, redundant or singular systems). In blocks of BLOCK steps, one
        column per step (``batched``)."""
        if self.least_squares or self.terms.nz >= SPARSE_FROM or not len(t):
            return None
        out = np.empty((3, self.terms.nz, len(t)))
        ok = np.empty(len(t), dtype=bool)
        for a in range(0, len(t), BLOCK):
            s = slice(a, a + BLOCK)
            found = self._bulk_block(t[s], z[s].T, iterations)
            if found is None:
                return None
            out[:, :, s], ok[s] = found
        return out[0].T, ok, out[1].T, out[2].T

    def _bulk_block(self, t, z, iterations):
        """((z, ż, z̈) (3, nz, n), ok) of ``_bulk`` for one block, z (nz, n)."""
        terms, tol = self.terms, self.settings.tolerance
        z = np.array(z, dtype=float)
        rhs = np.empty((terms.m, 2, len(t)))
        rhs[:, 1] = terms.velocity_rhs_cols(t)[self.order]
        w = self.w[:, None]
        order = self.order
        with np.errstate(all="ignore"):
            for _ in range(iterations):
                A = terms.dense_cols(terms.jacobian_cols(z))[order]
                rhs[:, 0] = -terms.residual_cols(t, z)[order]
                swaps, regular = lu_factor(A, PIVOT_THRESHOLD)
                if not regular.all():
                    return None
                x = lu_solve(A, swaps, rhs)
                self.iterations += len(t)
                z += x[:, 0]
                step = np.max(np.abs(x[:, 0]) * w, axis=0, initial=0.0)
                if np.all(step <= tol):
                    break
            zd = x[:, 1]
            zdd = lu_solve(A, swaps, terms.gamma_cols(t, z, zd)[order])
        return np.stack([z, zd, zdd]), step <= tol

    def _sequential(self, t, z, k: int, end: int):
        """(z, solved): steps k+1 … end−1 one after the other from the solved step k,
        each from the parabola through the last three solved steps (``_extrapolate``)."""
        for i in range(k + 1, end):
            guess = self._extrapolate(t, z, i)
            zi = self.step(t[i - 1], z[i - 1], t[i], guess)
            if zi is None:
                return z, i
            z[i] = zi
        return z, end

    def _extrapolate(self, t, z, i: int):
        """z at t_i on the parabola through the last (up to) three solved steps before i
        (None if there is only one): through a singular position, where the solution
        itself is a poor start for Newton and its rates are not defined."""
        known = [j for j in range(i - 1, max(-1, i - 1 - 8 * COARSE_GAP), -1)
                 if np.isfinite(z[j, 0])][:3]
        if len(known) < 2:
            return None
        ts, zs = t[known], z[known]
        out = np.zeros_like(zs[0])
        for a in range(len(known)):          # Lagrange's form
            weight = np.prod([(t[i] - ts[b]) / (ts[a] - ts[b])
                              for b in range(len(known)) if b != a])
            out += weight * zs[a]
        return out


def anchored(terms, t0: float, z: np.ndarray, K: np.ndarray, target: np.ndarray,
             weight: np.ndarray, settings: NaturalSettings, w: np.ndarray) -> np.ndarray:
    """z minimising ½ Σ weight (K [z; 1] − target)² subject to Φ(z, t0) = 0: Newton on the
    optimality conditions, H Δz + Φ_zᵀ μ = −∇E, Φ_z Δz = −Φ (H: the Lagrangian's Hessian).

    The free degrees of freedom settle nearest the guess (an assembly with free solids).
    Raises SolverError when it does not converge.
    """
    nz, m = terms.nz, terms.m
    A = K[:, :nz]
    mu = np.zeros(m)
    t = np.array([t0])
    for _ in range(4 * settings.max_iterations):
        phi = terms.residual(t, z[None])[0]
        J = terms.dense(terms.jacobian(z[None]))[0]
        gap = K @ np.r_[z, 1.0] - target
        H = A.T @ (weight[:, None] * A) + terms.hessian(z, mu)
        kkt = np.block([[H, J.T], [J, np.zeros((m, m))]])
        rhs = -np.r_[A.T @ (weight * gap), phi]
        sol = np.linalg.lstsq(kkt, rhs, rcond=1e-13)[0]
        dz, mu = sol[:nz], sol[nz:]
        z = z + dz
        if np.max(np.abs(dz) * w, initial=0.0) <= settings.tolerance:
            return z
    raise SolverError("the natural-coordinate assembly with free degrees of freedom did not "
                      "converge")

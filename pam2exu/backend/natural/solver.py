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

#: from this many coordinates on, a chunk of steps is solved as one sparse block-diagonal
#: system (cost linear in the mechanism's size) instead of dense batched solves
SPARSE_FROM = 40
#: intervals of the coarse pass (fewer when the run is short)
COARSE = 200
#: the coarse predictor may miss by this much (relative: lengths / L, angles in rad)
#: before its interval is solved step by step
COARSE_MISS = 2e-2
#: bytes of Jacobians kept at once (the steps are solved in chunks)
CHUNK_BYTES = 64 * 2**20
#: a step that failed is cut into at most this many sub-steps
MAX_SUBSTEPS = 64


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
            else:
                try:
                    return np.linalg.solve(terms.dense(data), b[..., None])[..., 0]
                except np.linalg.LinAlgError:
                    pass
        U, s, Vt = np.linalg.svd(terms.dense(data), full_matrices=False)
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

    def rates(self, t, z, data=None):
        """(ż, z̈) at the steps (z solved): Φ_z ż = g', Φ_z z̈ = γ."""
        terms = self.terms
        data = terms.jacobian(z) if data is None else data
        zd = self.solve(data, terms.velocity_rhs(t))
        zdd = self.solve(data, terms.gamma(t, z, zd))
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
                magnitude = terms.magnitude(ta, za)
                size = np.divide(np.abs(phi), magnitude, out=np.abs(phi) * np.inf,
                                 where=magnitude > 0)
                size[phi == 0] = 0.0
                floor = np.all(size <= 64 * eps, axis=1)
                dz = self.solve(terms.jacobian(za), -phi)
                step = np.max(np.abs(dz) * self.w, axis=1, initial=0.0)
            self.iterations += len(active)
            finite = np.isfinite(step)
            z[active[finite]] = za[finite] + dz[finite]
            small = step <= tol
            if self.least_squares:        # a least-squares step also stops where Φ ≠ 0
                small &= np.all(size <= max(64 * eps, 100 * tol), axis=1)
            # at round-off, steps stop shrinking (at a singular position Φ is quadratic in
            # the error, and a step that still halves is still worth taking)
            stalled = floor & (step > 0.7 * last[active])
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
        """(z (n, nz), solved, t_failed): the steps of ``t`` from the solved z0 at t[0]."""
        n = len(t)
        z = np.full((n, self.terms.nz), np.nan)
        z[0] = z0
        stride = max(1, n // COARSE)
        if stride < 4:
            return self._sequential(t, z, 0, n)
        rows_per_chunk = max(1, CHUNK_BYTES // (8 * max(1, self.terms.m) * self.terms.nz))
        base = stride
        k, zd, zdd = 0, *(r[0] for r in self.rates(t[:1], z[:1]))
        while k < n - 1:
            j = min(n - 1, k + stride)
            if j - k < 4:                      # too fast or too near a singular position
                z, solved = self._sequential(t, z, k, j + 1)
                if solved <= j:
                    return z, solved
                k, stride = j, min(base, 4 * stride)
                zd, zdd = (r[0] for r in self.rates(t[j:j + 1], z[j:j + 1]))
                continue
            h = t[j] - t[k]
            guess = z[k] + h * zd + 0.5 * h * h * zdd
            zj, ok = self.newton(t[j:j + 1], guess[None])
            zj = zj[0]
            miss = float(np.max(np.abs(zj - guess) * self.w)) if ok[0] else np.inf
            if miss > COARSE_MISS:             # a shorter interval
                stride = max(1, stride // 4)
                continue
            if miss < COARSE_MISS / 64:
                stride = min(base, 2 * stride)
            z[j] = zj
            zdj, zddj = (r[0] for r in self.rates(t[j:j + 1], z[j:j + 1]))
            inner = np.arange(k + 1, j)
            u = ((t[inner] - t[k]) / h)[:, None]
            guess = ((2 * u**3 - 3 * u**2 + 1) * z[k] + (u**3 - 2 * u**2 + u) * h * zd
                     + (-2 * u**3 + 3 * u**2) * zj + (u**3 - u**2) * h * zdj)
            good = True
            for a in range(0, len(inner), rows_per_chunk):
                part = inner[a:a + rows_per_chunk]
                zi, ok = self.newton(t[part], guess[a:a + rows_per_chunk])
                far = np.max(np.abs(zi - guess[a:a + rows_per_chunk]) * self.w, axis=1) > \
                    max(10 * miss, 1e-6)
                if not ok.all() or far.any():
                    good = False
                    break
                z[part] = zi
            if not good:                       # another branch, or no convergence
                z, solved = self._sequential(t, z, k, j + 1)
                if solved <= j:
                    return z, solved
            k, zd, zdd = j, zdj, zddj
        return z, n

    def _sequential(self, t, z, k: int, end: int):
        """(z, solved): steps k+1 … end−1 one after the other from the solved step k,
        each from the quadratic extrapolation of the last three."""
        for i in range(k + 1, end):
            if i - k >= 3:
                guess = 3.0 * (z[i - 1] - z[i - 2]) + z[i - 3]
            elif i - k == 2:
                guess = 2.0 * z[i - 1] - z[i - 2]
            else:
                guess = None
            zi = self.step(t[i - 1], z[i - 1], t[i], guess)
            if zi is None:
                return z, i
            z[i] = zi
        return z, end


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

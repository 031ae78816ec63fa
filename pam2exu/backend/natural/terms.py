"""The natural-coordinate equations as tables of terms, evaluated for all steps at once.

Each equation row r is Σ c z_a z_b + Σ c z_a sin(z_b + α) − g(t), with z_ONE = 1 and
g(t) = f(t) or f(t)² for an actuator's law f (``forms``). Then, for every step,

    Φ        the terms' values summed per row, minus g
    Φ_z      ∂(c z_a z_b)/∂z_a = c z_b, …: a fixed sparsity pattern, values per step
    Φ_z ż = g'                                  velocities
    Φ_z z̈ = g'' − Σ 2 c ż_a ż_b − Σ c (2 ż_a ż_b cos + z_a ż_b² (−sin))   accelerations

(the exact quadratic velocity term of a quadratic constraint: −ż ᵀ ∂²Φ/∂z² ż).
"""
from __future__ import annotations

import numpy as np
from scipy import sparse

from ...laws import Law
from .forms import ONE

def _summer(index: np.ndarray, size: int) -> sparse.csr_matrix:
    """S (size, len(index)) with S[index[k], k] = 1: S @ values (k, n) sums the values per
    index, term after term (sparse: the same sum in the same order whatever n, so that a
    run's results do not depend on how its steps are chunked)."""
    return sparse.csr_matrix((np.ones(len(index)), (index, np.arange(len(index)))),
                             shape=(size, len(index)))


class Terms:
    """The equations of a ``Formulation``, compiled.

    Parameters
    ----------
    nz : int
        Number of coordinates.
    rows : list of (Expr, target, power)
        One per equation: the expression, its target (a number or a ``Law``) and whether
        the target enters as f (1) or f² (2).
    """

    def __init__(self, nz: int, rows):
        self.nz, self.m = nz, len(rows)
        one = lambda i: nz if i == ONE else i              # noqa: E731
        prod, sine, self.laws = [], [], []
        for r, (expr, target, power) in enumerate(rows):
            for (a, b), c in expr.products.items():
                prod.append((r, one(a), one(b), c))
            for (a, b, alpha), c in expr.sines.items():
                sine.append((r, one(a), b, alpha, c))
            if isinstance(target, Law):
                self.laws.append((r, target, power))
            elif target:
                prod.append((r, nz, nz, -float(target) ** power))
        p = np.array(prod, dtype=float).reshape(-1, 4)
        s = np.array(sine, dtype=float).reshape(-1, 5)
        self.pr, self.pa, self.pb = (p[:, k].astype(int) for k in range(3))
        self.pc = p[:, 3]
        self.sr, self.sa, self.sb = (s[:, k].astype(int) for k in range(3))
        self.salpha, self.sc = s[:, 3], s[:, 4]
        self.row_sum = _summer(np.r_[self.pr, self.sr], self.m)

        # Jacobian entries: (row, column) of each term's derivative, ONE columns left out
        entries = [(self.pr, self.pa, "p_b"), (self.pr, self.pb, "p_a"),
                   (self.sr, self.sa, "s_sin"), (self.sr, self.sb, "s_cos")]
        self._entry_kinds = []
        rr, cc = [], []
        for rows_, cols, kind in entries:
            keep = cols != nz
            self._entry_kinds.append((kind, keep))
            rr.append(rows_[keep])
            cc.append(cols[keep])
        rr, cc = np.concatenate(rr), np.concatenate(cc)
        flat = rr * max(nz, 1) + cc
        pattern, where = np.unique(flat, return_inverse=True)
        #: the Jacobian's nonzero pattern: Φ_z[:, rows[k], cols[k]] = data[:, k]
        self.rows, self.cols = pattern // max(nz, 1), pattern % max(nz, 1)
        self.entry_sum = _summer(where, len(pattern))

    # ---- evaluation: one column per step --------------------------------------------------
    # The ``*_cols`` methods take z as (nz, n) and return (m, n) or (nnz, n): one column per
    # step, so that every term is a contiguous row and the sums over terms are one product
    # with a small matrix. The methods without the suffix take and return one row per step.
    def _ext(self, z: np.ndarray) -> np.ndarray:
        """[z; 1] (nz + 1, n)."""
        out = np.empty((self.nz + 1, z.shape[1]))
        out[:self.nz] = z
        out[self.nz] = 1.0
        return out

    @staticmethod
    def _sum(values: np.ndarray, S) -> np.ndarray:
        """S values: the terms' values (k, n) summed per row or entry (``_summer``)."""
        return np.asarray(S @ values)

    def _targets(self, t: np.ndarray, order: int) -> list:
        """[(row, g^(order)(t))] of the rows with a law: g = f or f²."""
        out = []
        for r, law, power in self.laws:
            f, df, ddf = law(t)
            if power == 1:
                g = (f, df, ddf)[order]
            else:
                g = (f * f, 2 * f * df, 2 * (df * df + f * ddf))[order]
            out.append((r, g))
        return out

    def residual_cols(self, t: np.ndarray, z: np.ndarray) -> np.ndarray:
        """Φ(z, t) (m, n)."""
        x = self._ext(z)
        values = np.concatenate([self.pc[:, None] * x[self.pa] * x[self.pb],
                                 self.sc[:, None] * x[self.sa]
                                 * np.sin(x[self.sb] + self.salpha[:, None])])
        out = self._sum(values, self.row_sum)
        for r, g in self._targets(t, 0):
            out[r] -= g
        return out

    def magnitude_cols(self, t: np.ndarray, z: np.ndarray) -> np.ndarray:
        """Σ |terms| per row (m, n): the size round-off errors of Φ scale with."""
        x = np.abs(self._ext(z))
        values = np.concatenate([np.abs(self.pc)[:, None] * x[self.pa] * x[self.pb],
                                 np.abs(self.sc)[:, None] * x[self.sa]])
        out = self._sum(values, self.row_sum)
        for r, g in self._targets(t, 0):
            out[r] += np.abs(g)
        return out

    def magnitude_at(self, scales: np.ndarray) -> np.ndarray:
        """Σ |terms| per row (m,) with every coordinate at its scale (nz,)."""
        x = np.r_[scales, 1.0][:, None]
        values = np.concatenate([np.abs(self.pc)[:, None] * x[self.pa] * x[self.pb],
                                 np.abs(self.sc)[:, None] * x[self.sa]])
        return self._sum(values, self.row_sum)[:, 0]

    def jacobian_cols(self, z: np.ndarray) -> np.ndarray:
        """Φ_z as data (nnz, n) on the pattern (``rows``, ``cols``)."""
        x = self._ext(z)
        arg = x[self.sb] + self.salpha[:, None]
        pc, sc = self.pc[:, None], self.sc[:, None]
        parts = {"p_b": pc * x[self.pb], "p_a": pc * x[self.pa],
                 "s_sin": sc * np.sin(arg), "s_cos": sc * x[self.sa] * np.cos(arg)}
        values = np.concatenate([parts[kind][keep] for kind, keep in self._entry_kinds])
        return self._sum(values, self.entry_sum)

    def dense_cols(self, data: np.ndarray) -> np.ndarray:
        """Φ_z (m, nz, n) from its data (nnz, n)."""
        J = np.zeros((self.m, self.nz, data.shape[1]))
        J[self.rows, self.cols] = data
        return J

    def velocity_rhs_cols(self, t: np.ndarray) -> np.ndarray:
        """g'(t) (m, n): Φ_z ż = g' (−Φ_t)."""
        out = np.zeros((self.m, len(t)))
        for r, g in self._targets(t, 1):
            out[r] = g
        return out

    def gamma_cols(self, t: np.ndarray, z: np.ndarray, zd: np.ndarray) -> np.ndarray:
        """γ (m, n): Φ_z z̈ = γ = g'' − (d/dt Φ_z) ż."""
        x, v = self._ext(z), np.zeros((self.nz + 1, z.shape[1]))
        v[:self.nz] = zd
        arg = x[self.sb] + self.salpha[:, None]
        wb = v[self.sb]
        values = np.concatenate([
            2.0 * self.pc[:, None] * v[self.pa] * v[self.pb],
            self.sc[:, None] * wb * (2.0 * v[self.sa] * np.cos(arg) - x[self.sa] * wb * np.sin(arg))])
        out = -self._sum(values, self.row_sum)
        for r, g in self._targets(t, 2):
            out[r] += g
        return out

    # ---- evaluation: one row per step -------------------------------------------------------
    def residual(self, t: np.ndarray, z: np.ndarray) -> np.ndarray:
        """Φ(z, t) (n, m)."""
        return self.residual_cols(t, z.T).T

    def magnitude(self, t: np.ndarray, z: np.ndarray) -> np.ndarray:
        """Σ |terms| per row (n, m)."""
        return self.magnitude_cols(t, z.T).T

    def jacobian(self, z: np.ndarray) -> np.ndarray:
        """Φ_z as data (n, nnz) on the pattern (``rows``, ``cols``)."""
        return self.jacobian_cols(z.T).T

    def dense(self, data: np.ndarray) -> np.ndarray:
        """Φ_z (n, m, nz) from its data (n, nnz)."""
        J = np.zeros((data.shape[0], self.m, self.nz))
        J[:, self.rows, self.cols] = data
        return J

    def velocity_rhs(self, t: np.ndarray) -> np.ndarray:
        """g'(t) (n, m)."""
        return self.velocity_rhs_cols(t).T

    def gamma(self, t: np.ndarray, z: np.ndarray, zd: np.ndarray) -> np.ndarray:
        """γ (n, m): Φ_z z̈ = γ."""
        return self.gamma_cols(t, z.T, zd.T).T

    def hessian(self, z: np.ndarray, mu: np.ndarray) -> np.ndarray:
        """Σ_r μ_r ∂²Φ_r/∂z² (nz, nz) at one configuration z (nz,)."""
        H = np.zeros((self.nz + 1, self.nz + 1))
        x = np.r_[z, 1.0]
        w = mu[self.pr] * self.pc
        np.add.at(H, (self.pa, self.pb), w)
        np.add.at(H, (self.pb, self.pa), w)
        arg = x[self.sb] + self.salpha
        w = mu[self.sr] * self.sc
        np.add.at(H, (self.sa, self.sb), w * np.cos(arg))
        np.add.at(H, (self.sb, self.sa), w * np.cos(arg))
        np.add.at(H, (self.sb, self.sb), -w * x[self.sa] * np.sin(arg))
        return H[:self.nz, :self.nz]

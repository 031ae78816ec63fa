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

#: sums over terms use a dense matrix up to this many (terms × rows) entries
DENSE_SUM = 20_000


def _summer(index: np.ndarray, size: int):
    """S (len(index), size) with S[k, index[k]] = 1: values @ S sums values per index."""
    if len(index) * size <= DENSE_SUM:
        S = np.zeros((len(index), size))
        np.add.at(S, (np.arange(len(index)), index), 1.0)
        return S
    return sparse.csr_matrix((np.ones(len(index)), (np.arange(len(index)), index)),
                             shape=(len(index), size))


def _sum(values: np.ndarray, S) -> np.ndarray:
    """values (n, k) @ S (k, size), S dense or sparse."""
    if isinstance(S, np.ndarray):
        return values @ S
    return np.asarray((S.T @ values.T).T)


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

    # ---- evaluation -----------------------------------------------------------------------
    def _ext(self, z: np.ndarray) -> np.ndarray:
        """[z, 1] (n, nz + 1)."""
        out = np.empty((z.shape[0], self.nz + 1))
        out[:, :self.nz] = z
        out[:, self.nz] = 1.0
        return out

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

    def residual(self, t: np.ndarray, z: np.ndarray) -> np.ndarray:
        """Φ(z, t) (n, m)."""
        x = self._ext(z)
        values = np.concatenate([self.pc * x[:, self.pa] * x[:, self.pb],
                                 self.sc * x[:, self.sa] * np.sin(x[:, self.sb] + self.salpha)],
                                axis=1)
        out = _sum(values, self.row_sum)
        for r, g in self._targets(t, 0):
            out[:, r] -= g
        return out

    def magnitude(self, t: np.ndarray, z: np.ndarray) -> np.ndarray:
        """Σ |terms| per row (n, m): the size round-off errors of Φ scale with."""
        x = np.abs(self._ext(z))
        values = np.concatenate([np.abs(self.pc) * x[:, self.pa] * x[:, self.pb],
                                 np.abs(self.sc) * x[:, self.sa]], axis=1)
        out = _sum(values, self.row_sum)
        for r, g in self._targets(t, 0):
            out[:, r] += np.abs(g)
        return out

    def jacobian(self, z: np.ndarray) -> np.ndarray:
        """Φ_z as data (n, nnz) on the pattern (``rows``, ``cols``)."""
        x = self._ext(z)
        arg = x[:, self.sb] + self.salpha
        parts = {"p_b": self.pc * x[:, self.pb], "p_a": self.pc * x[:, self.pa],
                 "s_sin": self.sc * np.sin(arg), "s_cos": self.sc * x[:, self.sa] * np.cos(arg)}
        values = np.concatenate([parts[kind][:, keep] for kind, keep in self._entry_kinds],
                                axis=1)
        return _sum(values, self.entry_sum)

    def dense(self, data: np.ndarray) -> np.ndarray:
        """Φ_z (n, m, nz) from its data."""
        J = np.zeros((data.shape[0], self.m, self.nz))
        J[:, self.rows, self.cols] = data
        return J

    def velocity_rhs(self, t: np.ndarray) -> np.ndarray:
        """g'(t) (n, m): Φ_z ż = g' (−Φ_t)."""
        out = np.zeros((len(t), self.m))
        for r, g in self._targets(t, 1):
            out[:, r] = g
        return out

    def gamma(self, t: np.ndarray, z: np.ndarray, zd: np.ndarray) -> np.ndarray:
        """γ (n, m): Φ_z z̈ = γ = g'' − (d/dt Φ_z) ż."""
        x, v = self._ext(z), np.zeros((z.shape[0], self.nz + 1))
        v[:, :self.nz] = zd
        arg = x[:, self.sb] + self.salpha
        wb = v[:, self.sb]
        values = np.concatenate([
            2.0 * self.pc * v[:, self.pa] * v[:, self.pb],
            self.sc * wb * (2.0 * v[:, self.sa] * np.cos(arg) - x[:, self.sa] * wb * np.sin(arg))],
            axis=1)
        out = -_sum(values, self.row_sum)
        for r, g in self._targets(t, 2):
            out[:, r] += g
        return out

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

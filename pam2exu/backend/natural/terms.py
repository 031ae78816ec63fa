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

#: up to this many steps, terms are summed by ``numpy.bincount`` (one call, no sparse-matrix
#: overhead); above, by the sparse summing matrix (``_summer``): both add each row's terms
#: one after the other in the terms' order, so the two give the same bits. A short run's
#: fill (86 steps of a 100-step run) stays below it and never builds the summing matrices
#: (~0.1-0.3 ms each); the two sums cost alike at ~200 steps (four-bar, measured)
BINCOUNT_STEPS = 256


def _summer(index: np.ndarray, size: int) -> sparse.csr_matrix:
    """S (size, len(index)) with S[index[k], k] = 1: S @ values (k, n) sums the values per
    index, term after term (sparse: the same sum in the same order whatever n, so that a
    run's results do not depend on how its steps are chunked)."""
    return sparse.csr_matrix((np.ones(len(index)), (index, np.arange(len(index)))),
                             shape=(size, len(index)))


def extended(z: np.ndarray, last: float = 1.0) -> np.ndarray:
    """[z; last] along the first axis: (nz + 1, n) of one column per step, or (nz + 1,) of
    one configuration (last = 1: the ``ONE`` coordinate; 0: its rate)."""
    out = np.empty((z.shape[0] + 1,) + z.shape[1:])
    out[:-1] = z
    out[-1] = last
    return out


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
        self.__dict__.update(_indices(nz, self.m, p, s))
        self.pc = p[:, 3]
        self.salpha, self.sc = s[:, 3], s[:, 4]
        self.law_rows = np.array([r for r, _, _ in self.laws], dtype=int)
        self._last_times, self._last_laws = None, []
        self._table = None                   # ``tabulate``
        # the terms' constants as columns, kept (evaluations broadcast them over the steps)
        self._pc, self._sc, self._alpha = self.pc[:, None], self.sc[:, None], self.salpha[:, None]
        self._apc, self._asc = np.abs(self._pc), np.abs(self._sc)
        # the Jacobian's constants in the order of ``_indices``' entries: products c z_other
        # (both derivatives in one gather), then c sin(z_b + α) and c z_a cos(z_b + α)
        kb, ka, ks, kc = self._keeps
        self._jp_c = np.concatenate([self.pc[kb], self.pc[ka]])[:, None]
        self._js_c, self._js_alpha = self._sc[ks], self._alpha[ks]
        self._jc_c, self._jc_alpha = self._sc[kc], self._alpha[kc]
        # the same constants 1-D, for the evaluations at one step (``*_one``)
        self._jp_c1, self._js_c1, self._js_alpha1, self._jc_c1, self._jc_alpha1 = (
            a[:, 0] for a in (self._jp_c, self._js_c, self._js_alpha, self._jc_c,
                              self._jc_alpha))
        self._pc2 = np.concatenate([self.pc, self.pc])

    # ---- evaluation: one column per step --------------------------------------------------
    # The ``*_cols`` methods take z as (nz, n) and return (m, n) or (nnz, n): one column per
    # step, so that every term is a contiguous row and the sums over terms are one product
    # with a small matrix. The methods without the suffix take and return one row per step.
    def _sum(self, values: np.ndarray, per: str) -> np.ndarray:
        """The terms' values (k, n) summed per row (``per`` 'row') or per Jacobian entry
        ('entry'): out[index[k]] += values[k], term after term (``numpy.bincount`` for a
        few steps, else the sparse summing matrix of ``_summer``, made on first use)."""
        index, size = {"row": (self.row_index, self.m),
                       "entry": (self.entry_index, len(self.rows)),
                       "both": (self._both_index, self.m + len(self.rows))}[per]
        n = values.shape[1]
        if n > BINCOUNT_STEPS:
            summers = self._summers              # shared by the structure's ``Terms``
            if per not in summers:
                summers[per] = _summer(index, size)
            return np.asarray(summers[per] @ values)
        flat = index if n == 1 else (index[:, None] * n + np.arange(n)).ravel()
        return np.bincount(flat, weights=values.ravel(), minlength=size * n).reshape(size, n)

    def tabulate(self, t: np.ndarray) -> None:
        """Evaluate the laws once at all the times t of a run (ascending): a later ask at one
        of them (``_law_values``, a step of the coarse pass) reads its row, the same values (a
        law's value at a time does not depend on the times evaluated beside it)."""
        self._table = (t, [law(t) for _, law, _ in self.laws]) \
            if self.laws and len(t) > 1 else None

    def _law_values(self, t: np.ndarray) -> list:
        """[(f, f', f'')] of every law at the times t; for a few steps, the values at the
        times last asked are kept (a step's Newton iteration, velocities and accelerations
        ask for the same times), and times ``tabulate`` was given are read from its table."""
        if len(t) > BINCOUNT_STEPS:
            return [law(t) for _, law, _ in self.laws]
        key = np.asarray(t, dtype=float).tobytes()
        if self._last_times != key:
            self._last_times, self._last_laws = key, self._tabulated(t) or \
                [law(t) for _, law, _ in self.laws]
        return self._last_laws

    def _tabulated(self, t: np.ndarray) -> list | None:
        """``_law_values`` at times t from the table of ``tabulate`` (None where it has not
        all of them)."""
        if self._table is None:
            return None
        times, values = self._table
        if len(t) == 1:                          # a slice: no index array
            i = int(np.searchsorted(times, t[0]))
            if i < len(times) and times[i] == t[0]:
                return [(f[i:i + 1], df[i:i + 1], ddf[i:i + 1]) for f, df, ddf in values]
            return None
        i = np.minimum(np.searchsorted(times, t), len(times) - 1)
        if np.array_equal(times[i], t):
            return [(f[i], df[i], ddf[i]) for f, df, ddf in values]
        return None

    def targets(self, t: np.ndarray, order: int) -> np.ndarray:
        """g^(order)(t) (laws, n) of the rows with a law (``law_rows``): g = f or f²."""
        out = np.empty((len(self.laws), len(t)))
        for k, ((r, law, power), (f, df, ddf)) in enumerate(zip(self.laws, self._law_values(t))):
            if power == 1:
                out[k] = (f, df, ddf)[order]
            else:
                out[k] = (f * f, 2 * f * df, 2 * (df * df + f * ddf))[order]
        return out

    def residual_cols(self, t: np.ndarray, z: np.ndarray, g: np.ndarray | None = None
                      ) -> np.ndarray:
        """Φ(z, t) (m, n); g: ``targets(t, 0)`` when already known."""
        x = extended(z)
        values = np.concatenate([self._pc * x[self.pa] * x[self.pb],
                                 self._sc * x[self.sa] * np.sin(x[self.sb] + self._alpha)])
        out = self._sum(values, "row")
        if self.laws:
            out[self.law_rows] -= self.targets(t, 0) if g is None else g
        return out

    def magnitude_cols(self, t: np.ndarray, z: np.ndarray, g: np.ndarray | None = None
                       ) -> np.ndarray:
        """Σ |terms| per row (m, n): the size round-off errors of Φ scale with; g:
        ``targets(t, 0)`` when already known."""
        x = np.abs(extended(z))
        values = np.concatenate([self._apc * x[self.pa] * x[self.pb], self._asc * x[self.sa]])
        out = self._sum(values, "row")
        if self.laws:
            out[self.law_rows] += np.abs(self.targets(t, 0) if g is None else g)
        return out

    def magnitude_at(self, scales: np.ndarray) -> np.ndarray:
        """Σ |terms| per row (m,) with every coordinate at its scale (nz,); the last answer is
        kept (a run's assembly and its steps ask with the same scales; not to be modified)."""
        key = scales.tobytes()
        kept = self.__dict__.get("_magnitude_at")
        if kept is None or kept[0] != key:
            x = np.r_[scales, 1.0][:, None]
            values = np.concatenate([self._apc * x[self.pa] * x[self.pb],
                                     self._asc * x[self.sa]])
            kept = self._magnitude_at = (key, self._sum(values, "row")[:, 0])
        return kept[1]

    def jacobian_cols(self, z: np.ndarray) -> np.ndarray:
        """Φ_z as data (nnz, n) on the pattern (``rows``, ``cols``)."""
        x = extended(z)
        values = np.concatenate([
            self._jp_c * x[self._jp_i],
            self._js_c * np.sin(x[self._js_b] + self._js_alpha),
            self._jc_c * x[self._jc_a] * np.cos(x[self._jc_b] + self._jc_alpha)])
        return self._sum(values, "entry")

    def residual_jacobian_cols(self, t: np.ndarray, z: np.ndarray, g: np.ndarray | None = None
                               ) -> tuple[np.ndarray, np.ndarray]:
        """(Φ (m, n), Φ_z data (nnz, n)): the same values as ``residual_cols`` and
        ``jacobian_cols``. For a few steps (Newton step by step), from one gather of the
        terms' coordinates, each product c z_a computed once (for Φ and ∂/∂z_b) and one
        bincount for both sums (disjoint bins: the same additions in the same order)."""
        if z.shape[1] > BINCOUNT_STEPS:
            return self._residual_jacobian_many(t, z, g)
        x = extended(z)
        gathered = x[self._gather]
        xa, xb, arg, xs = (gathered[part] for part in self._parts)
        arg += self._alpha
        sin = np.sin(arg)
        ca, cs = self._pc * xa, self._sc * xs
        kb, ka, ks, kc = self._keeps
        entries = np.concatenate([np.concatenate([self._pc * xb, ca])[self._jp_keep],
                                  self._js_c * sin[ks], cs[kc] * np.cos(arg[kc])])
        n, size = x.shape[1], self.m + len(self.rows)
        index = self._both_index
        flat = index if n == 1 else (index[:, None] * n + np.arange(n)).ravel()
        both = np.bincount(flat, weights=np.concatenate([ca * xb, cs * sin, entries]).ravel(),
                           minlength=size * n).reshape(size, n)
        out, data = both[:self.m], both[self.m:]
        if self.laws:
            out[self.law_rows] -= self.targets(t, 0) if g is None else g
        return out, data

    # ---- evaluation at one step: 1-D arrays (Newton and the rates step by step) ---------------
    # The same arithmetic as the ``*_cols`` methods' column of that step (the same products
    # in the same order, the same bincount): the same bits, with fewer numpy calls.
    def residual_jacobian_one(self, z: np.ndarray, g: np.ndarray | None = None
                              ) -> tuple[np.ndarray, np.ndarray]:
        """(Φ (m,), Φ_z (m, nz) dense) at one configuration z (nz,): ``residual_jacobian_cols``'
        column, Φ_z's data on its pattern; g: ``targets(t, 0)[:, 0]`` of the step (its laws'
        rows). Every product is made once over all terms and the summed ones picked by one
        index (``_one_pick``)."""
        P, S = len(self.pa), len(self.sa)
        x = extended(z)
        gathered = x[self._gather]                   # z_a, z_b of the products; z_b, z_a of sines
        ab = self._pc2 * gathered[:2 * P]            # c z_a, c z_b
        arg = gathered[2 * P:2 * P + S] + self.salpha
        sin, cs = np.sin(arg), self.sc * gathered[2 * P + S:]
        values = np.concatenate([ab[:P] * gathered[P:2 * P], cs * sin, ab, self.sc * sin,
                                 cs * np.cos(arg)])
        both = np.bincount(self._both_dense, weights=values[self._one_pick],
                           minlength=self.m * (1 + self.nz))
        out = both[:self.m]
        if self.laws:
            out[self.law_rows] -= g
        return out, both[self.m:].reshape(self.m, self.nz)

    def jacobian_one(self, z: np.ndarray) -> np.ndarray:
        """Φ_z (m, nz) dense at one configuration z (nz,): ``jacobian_cols``' column, on its
        pattern."""
        x = extended(z)
        values = np.concatenate([
            self._jp_c1 * x[self._jp_i],
            self._js_c1 * np.sin(x[self._js_b] + self._js_alpha1),
            self._jc_c1 * x[self._jc_a] * np.cos(x[self._jc_b] + self._jc_alpha1)])
        return np.bincount(self._dense_index, weights=values,
                           minlength=self.m * self.nz).reshape(self.m, self.nz)

    def gamma_one(self, z: np.ndarray, zd: np.ndarray, g2: np.ndarray | None) -> np.ndarray:
        """γ (m,) at one step: ``gamma_cols``' column; g2: ``targets(t, 2)[:, 0]``."""
        pc, sc, alpha = self.pc, self.sc, self.salpha
        x = extended(z)
        v = extended(zd, 0.0)                        # ONE's rate: 0
        arg = x[self.sb] + alpha
        wb = v[self.sb]
        values = np.concatenate([
            2.0 * pc * v[self.pa] * v[self.pb],
            sc * wb * (2.0 * v[self.sa] * np.cos(arg) - x[self.sa] * wb * np.sin(arg))])
        out = -np.bincount(self.row_index, weights=values, minlength=self.m)
        if self.laws:
            out[self.law_rows] += g2
        return out

    def _residual_jacobian_many(self, t, z, g=None):
        """``residual_jacobian_cols`` for many steps: Φ's and Φ_z's terms written into one
        array, each product c z_a made once (for Φ and ∂/∂z_b), and summed by one sparse
        summing matrix of both (``_both_index``: disjoint rows, each the same terms in the
        same order as its own matrix)."""
        x = extended(z)
        P, S, n = len(self.pa), len(self.sa), x.shape[1]
        kb, ka, ks, kc = self._keeps
        B, A = self._jp_counts
        values = np.empty((len(self._both_index), n))
        ca = self._pc * x[self.pa]
        arg = x[self.sb]
        arg += self._alpha
        sin = np.sin(arg)
        cs = np.multiply(self._sc, x[self.sa], out=values[P:P + S])
        e = P + S                                  # Φ_z's terms: c z_b, c z_a, c sin, c z_a cos
        np.multiply(self._jp_c[:B], x[self._jp_i[:B]], out=values[e:e + B])
        values[e + B:e + B + A] = ca[ka]
        e += B + A
        np.multiply(self._js_c, sin[ks], out=values[e:e + len(self._js_c)])
        e += len(self._js_c)
        np.multiply(cs[kc], np.cos(arg[kc]), out=values[e:])
        np.multiply(ca, x[self.pb], out=values[:P])
        cs *= sin
        both = self._sum(values, "both")
        out, data = both[:self.m], both[self.m:]
        if self.laws:
            out[self.law_rows] -= self.targets(t, 0) if g is None else g
        return out, data

    def dense_cols(self, data: np.ndarray, order: np.ndarray | None = None) -> np.ndarray:
        """Φ_z (m, nz, n) from its data (nnz, n); with ``order`` (m,), its rows in that
        order (Φ_z[order], made in place)."""
        J = np.zeros((self.m, self.nz, data.shape[1]))
        rows = self.rows
        if order is not None:
            where = np.empty(self.m, dtype=int)
            where[order] = np.arange(self.m)
            rows = where[rows]
        J[rows, self.cols] = data
        return J

    def velocity_rhs_cols(self, t: np.ndarray) -> np.ndarray:
        """g'(t) (m, n): Φ_z ż = g' (−Φ_t)."""
        out = np.zeros((self.m, len(t)))
        if self.laws:
            out[self.law_rows] = self.targets(t, 1)
        return out

    def gamma_cols(self, t: np.ndarray, z: np.ndarray, zd: np.ndarray) -> np.ndarray:
        """γ (m, n): Φ_z z̈ = γ = g'' − (d/dt Φ_z) ż."""
        x, v = extended(z), extended(zd, 0.0)     # ONE's rate: 0
        arg = x[self.sb]
        arg += self._alpha
        wb = v[self.sb]
        P = len(self.pa)
        values = np.empty((P + len(self.sa), z.shape[1]))     # the terms, written in place
        np.multiply(2.0 * self._pc, v[self.pa], out=values[:P])
        values[:P] *= v[self.pb]
        cos = np.cos(arg)
        cos *= 2.0 * v[self.sa]
        sin = np.sin(arg)
        sin *= x[self.sa] * wb
        np.subtract(cos, sin, out=cos)
        np.multiply(self._sc * wb, cos, out=values[P:])
        out = self._sum(values, "row")
        np.negative(out, out=out)
        if self.laws:
            out[self.law_rows] += self.targets(t, 2)
        return out

    # ---- evaluation: one row per step -------------------------------------------------------
    def residual(self, t: np.ndarray, z: np.ndarray, g: np.ndarray | None = None
                 ) -> np.ndarray:
        """Φ(z, t) (n, m); g: ``targets(t, 0)`` when already known."""
        return self.residual_cols(t, z.T, g).T

    def magnitude(self, t: np.ndarray, z: np.ndarray, g: np.ndarray | None = None
                  ) -> np.ndarray:
        """Σ |terms| per row (n, m); g: ``targets(t, 0)`` when already known."""
        return self.magnitude_cols(t, z.T, g).T

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


#: ``_indices`` of the structures met last (at most ``KEPT_STRUCTURES``): a study's variants
#: share one structure, and a ``Terms``' index arrays depend on nothing else
_STRUCTURES: dict = {}
KEPT_STRUCTURES = 32


def _indices(nz: int, m: int, p: np.ndarray, s: np.ndarray) -> dict:
    """The index arrays of the terms p (row, a, b, c) and s (row, a, b, α, c): made once per
    structure (the key is all of their rows and columns and the sizes), read-only, shared
    by the ``Terms`` of that structure."""
    key = (nz, m, p.shape, s.shape, p[:, :3].tobytes(), s[:, :3].tobytes())
    if key not in _STRUCTURES:
        if len(_STRUCTURES) >= KEPT_STRUCTURES:
            _STRUCTURES.pop(next(iter(_STRUCTURES)))
        made = _make_indices(nz, m, p, s)
        for value in made.values():
            for a in value if isinstance(value, (tuple, list)) else (value,):
                if isinstance(a, np.ndarray):
                    a.setflags(write=False)
        _STRUCTURES[key] = made
    return _STRUCTURES[key]


def _make_indices(nz: int, m: int, p: np.ndarray, s: np.ndarray) -> dict:
    """``_indices``, made: the terms' rows and coordinates, the Jacobian's pattern and where
    each term's derivative goes in it."""
    pr, pa, pb = (p[:, k].astype(int) for k in range(3))
    sr, sa, sb = (s[:, k].astype(int) for k in range(3))
    row_index = np.concatenate([pr, sr])
    # Jacobian entries: (row, column) of each term's derivative, ONE columns left out
    entries = [(pr, pa), (pr, pb), (sr, sa), (sr, sb)]
    rr, cc = [], []
    for rows_, cols in entries:
        keep = cols != nz
        rr.append(rows_[keep])
        cc.append(cols[keep])
    rr, cc = np.concatenate(rr), np.concatenate(cc)
    flat = rr * max(nz, 1) + cc
    pattern, where = np.unique(flat, return_inverse=True)
    #: the Jacobian's nonzero pattern: Φ_z[:, rows[k], cols[k]] = data[:, k]
    rows, cols = pattern // max(nz, 1), pattern % max(nz, 1)
    # the Jacobian's terms in the order of ``entries``: products c z_other (both
    # derivatives in one gather), then c sin(z_b + α) and c z_a cos(z_b + α)
    kb, ka = pa != nz, pb != nz
    ks, kc = sa != nz, sb != nz
    jp_keep = np.concatenate([kb, ka])
    # ``residual_jacobian_one``: its values are [c z_a z_b, c z_a sin, c z_a, c z_b,
    # c sin, c z_a cos] (products over all terms); the sums' weights pick, in the order of
    # ``residual_jacobian_cols``, Φ's terms, then Φ_z's: c z_b, c z_a (kept), c sin (ks),
    # c z_a cos (kc)
    P, S = len(pa), len(sa)
    jp = np.concatenate([P + S + P + np.arange(P), P + S + np.arange(P)])[jp_keep]
    # ``residual_jacobian_cols``: the coordinates of every term in one gather, and the
    # rows' and the entries' sums in one ``numpy.bincount`` (disjoint bins: each sum
    # adds the same terms in the same order as two calls)
    edges = np.cumsum([0, len(pa), len(pb), len(sb), len(sa)])
    # the same sums straight into a dense Φ_z (m, nz), row by row (``*_one``): each
    # position gets its entry's terms in the same order
    dense_index = (rows * nz + cols)[where]
    return {"pr": pr, "pa": pa, "pb": pb, "sr": sr, "sa": sa, "sb": sb,
            "row_index": row_index, "rows": rows, "cols": cols, "entry_index": where,
            "_jp_i": np.concatenate([pb[kb], pa[ka]]), "_js_b": sb[ks], "_jc_a": sa[kc],
            "_jc_b": sb[kc], "_keeps": (kb, ka, ks, kc), "_jp_keep": jp_keep,
            "_one_pick": np.concatenate([np.arange(P + S), jp, 3 * P + S + np.nonzero(ks)[0],
                                         3 * P + 2 * S + np.nonzero(kc)[0]]),
            "_gather": np.concatenate([pa, pb, sb, sa]),
            "_parts": tuple(slice(a, b) for a, b in zip(edges[:-1], edges[1:])),
            "_both_index": np.concatenate([row_index, m + where]),
            "_dense_index": dense_index, "_jp_counts": (int(kb.sum()), int(ka.sum())),
            # the sparse summing matrices (``_sum``), made on first use: one structure's
            # ``Terms`` share them
            "_summers": {},
            "_both_dense": np.concatenate([row_index, m + dense_index])}

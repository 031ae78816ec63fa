"""Inverse dynamics in natural coordinates: the constraint forces that make a given motion.

Each solid's base point p and base vector v (``Frame``) are linear in z: ζ_b = (p, v) =
A_b z + c_b (``Formulation.affine``). Its kinetic energy is a constant quadratic form in ζ̇_b,

    T_b = ½ ζ̇_bᵀ M_b ζ̇_b,   M_b = [[m I, m G], [m Gᵀ, J_p / |d|² I]],   G = a_G I + b_G Ω,

(``Formulation.mass_matrix`` is Σ A_bᵀ M_b A_b), so the solid's equilibrium, the forces
its joints apply to it on (p, v), is

    W_b = M_b ζ̈_b − Q_b                      (inertia minus applied: no velocity term)

with Q_b the loads of gravity, the torsors and the spring-dampers (``loads.Loads``). On
x, y, fi (``Loads.on_pose``) W is Q_inertia − Q_applied of the reference-point pass. Summed
on z, the constraints' forces are the natural multipliers':

    M z̈ + Φ_zᵀ μ = Q   ⇔   Φ_zᵀ μ = −Σ A_bᵀ W_b     (least norm where Φ_z is rank deficient)

Every quantity is an array over the steps; the solids' constants (masses, a_G, b_G, J_p,
|d|²) are arrays over the solids (``Bodies``), so that they can gain an axis over variants.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse

from ...batched import lu_factor, lu_solve
from .linear import PIVOT_THRESHOLD
from .loads import Loads

#: rank tolerance of the least-norm multipliers, relative to the largest singular value
RCOND = 1e-10


@dataclass
class Bodies:
    """The solids of a formulation as arrays: ζ = A z + c and the constant mass matrices.

    A : (ns, 4, nz)   c : (ns, 4)   mass : (ns, 4, 4)   (ground solids: A = 0, mass = 0)
    """

    A: np.ndarray
    c: np.ndarray
    mass: np.ndarray

    def __post_init__(self):
        ns, _, nz = self.A.shape
        self.flat = shared_csr(self.A.reshape(4 * ns, nz))              # ζ = flat z + c
        self.flat_t = shared_csr(self.A.reshape(4 * ns, nz).T)

    @property
    def block(self) -> np.ndarray:
        """The mass matrices as one block-diagonal (4 ns, 4 ns) (one product for all solids)."""
        ns = len(self.mass)
        out = np.zeros((ns, 4, ns, 4))
        out[np.arange(ns), :, np.arange(ns), :] = self.mass
        return out.reshape(4 * ns, 4 * ns)


def times(x: np.ndarray, A) -> np.ndarray:
    """x Aᵀ over x's last axis, A a constant scipy sparse matrix (``sparse_of``): one pass
    over A's nonzeros, single-threaded, the same sums whatever the number of rows. Not a
    BLAS product, whose threads make a small one a hundred times slower on a loaded machine
    (measured: (4096, 16) × (16, 16): 18 ms threaded at a load of 7 on 2 cores, 0.6 ms by
    ``numpy.einsum``, 0.17 ms sparse)."""
    flat = x.reshape(-1, x.shape[-1])
    return (A @ flat.T).T.reshape(x.shape[:-1] + (A.shape[0],))


#: a CSR matrix of each nonzero pattern met last (at most ``KEPT_PATTERNS``): a study's
#: variants share their constant matrices' patterns (the rates, the mass matrices), not their
#: numbers
_PATTERNS: dict = {}
KEPT_PATTERNS = 64


def csr(dense: np.ndarray) -> sparse.csr_matrix:
    """A 2-D array's nonzeros as a CSR matrix (row-major, columns ascending: the matrix
    ``scipy.sparse.csr_matrix(dense)`` makes): a copy of the first matrix of the same pattern
    with the array's own numbers, sharing its read-only index arrays (the key is the shape
    and the nonzeros' rows and columns); scipy's constructor runs once per pattern."""
    rows, cols = np.nonzero(dense)
    key = (dense.shape, rows.tobytes(), cols.tobytes())
    like = _PATTERNS.get(key)
    if like is None:
        if len(_PATTERNS) >= KEPT_PATTERNS:
            _PATTERNS.pop(next(iter(_PATTERNS)))
        starts = np.searchsorted(rows, np.arange(dense.shape[0] + 1))
        like = sparse.csr_matrix((dense[rows, cols], cols.astype(np.int32),
                                  starts.astype(np.int32)), shape=dense.shape)
        like.indices.setflags(write=False)
        like.indptr.setflags(write=False)
        _PATTERNS[key] = like
    out = like.__class__.__new__(like.__class__)          # a shallow copy
    out.__dict__.update(like.__dict__)
    out.data = dense[rows, cols]
    return out


#: ``shared_csr`` of the matrices met last (at most ``KEPT_MATRICES``): a study's variants
#: share their solids' A (which coordinates each base point and base vector are: entries ±1)
_SHARED: dict = {}
KEPT_MATRICES = 32


def shared_csr(dense: np.ndarray) -> sparse.csr_matrix:
    """``csr(dense)``, made once per matrix (the key is its shape and entries) and shared:
    never to be changed."""
    key = (dense.shape, dense.tobytes())
    if key not in _SHARED:
        if len(_SHARED) >= KEPT_MATRICES:
            _SHARED.pop(next(iter(_SHARED)))
        _SHARED[key] = csr(dense)
    return _SHARED[key]


def sparse_of(form, name: str, make):
    """The constant matrix ``make()`` of a formulation as a CSR matrix, made once."""
    kept = form.__dict__.setdefault("_kept", {})
    if name not in kept:
        kept[name] = csr(make())
    return kept[name]


#: I and Ω (read-only)
_EYE, _OMEGA = np.eye(2), np.array([[0.0, -1.0], [1.0, 0.0]])
_EYE.setflags(write=False)
_OMEGA.setflags(write=False)


def body_mass_matrices(m, jp, a, b, d2) -> np.ndarray:
    """M_b (…, 4, 4) = [[m I, m G], [m Gᵀ, J_p / |d|² I]], G = a I + b Ω (arrays over solids)."""
    m, jp, a, b, d2 = (np.asarray(x, dtype=float) for x in (m, jp, a, b, d2))
    if not m.shape == jp.shape == a.shape == b.shape == d2.shape:
        m, jp, a, b, d2 = np.broadcast_arrays(m, jp, a, b, d2)
    G = (m * a)[..., None, None] * _EYE + (m * b)[..., None, None] * _OMEGA
    out = np.empty(m.shape + (4, 4))
    out[..., :2, :2] = m[..., None, None] * _EYE
    out[..., :2, 2:] = G
    out[..., 2:, :2] = np.swapaxes(G, -1, -2)
    out[..., 2:, 2:] = (jp / d2)[..., None, None] * _EYE
    return out


def bodies(form) -> Bodies:
    """The formulation's solids as arrays (made once per formulation)."""
    kept = form.__dict__.setdefault("_kept", {})
    if "bodies" not in kept:
        ns, mech = len(form.frames), form.mech
        parts = [form.affine(i, None, kind) for i in range(ns) for kind in ("p", "v")]
        A = np.concatenate([p[0] for p in parts]).reshape(ns, 4, form.nz)
        c = np.concatenate([p[1] for p in parts]).reshape(ns, 4)
        m, jp, a, b, d2 = ([0.0] * ns for _ in range(5))       # numbers, made arrays below
        d2[:] = [1.0] * ns
        for i, f in enumerate(form.frames):
            if i in form.grounds:
                continue
            s = mech.solids[i]
            g = (float(s.cog[0]) - f.sp[0], float(s.cog[1]) - f.sp[1])
            m[i] = float(s.mass)
            a[i], b[i] = f._ab(g)
            jp[i] = float(s.inertia) + m[i] * (g[0] ** 2 + g[1] ** 2)
            d2[i] = f.d[0] ** 2 + f.d[1] ** 2
        kept["bodies"] = Bodies(A, c, body_mass_matrices(*map(np.array, (m, jp, a, b, d2))))
    return kept["bodies"]


def body_coordinates(bd: Bodies, z: np.ndarray, constant: bool = True) -> np.ndarray:
    """ζ (n, ns, 4) = A z + c per solid (``constant`` False: A ż, the rates)."""
    ns, _, nz = bd.A.shape
    out = times(z, bd.flat).reshape(len(z), ns, 4)
    return out + bd.c if constant else out


def on_coordinates(bd: Bodies, W: np.ndarray) -> np.ndarray:
    """Σ_b A_bᵀ W_b (n, nz): forces on the solids' (p, v) as forces on z."""
    return times(W.reshape(len(W), -1), bd.flat_t)


def applied(form, t, z, q, zd) -> np.ndarray:
    """Q_b (n, ns, 4) on (p, v): gravity, the torsors and the spring-dampers (rates ż)."""
    loads = Loads(form, z, q, zd, t=t)
    loads.gravity(form.mech.gravity)
    for el in form.mech.elements:
        el.natural_loads(loads)
    return loads.Q


def constraint_forces(form, t, z, zd, zdd, q) -> np.ndarray:
    """W (n, ns, 4) = M_b ζ̈_b − Q_b: what the joints apply to each solid's (p, v)."""
    bd = bodies(form)
    block = sparse_of(form, "mass_block", lambda: bd.block)
    inertia = times(body_coordinates(bd, zdd, constant=False).reshape(len(z), -1), block)
    return inertia.reshape(len(z), -1, 4) - applied(form, t, z, q, zd)


def kinetic_energy(form, zd) -> np.ndarray:
    """T (n,) = Σ_b ½ ζ̇_bᵀ M_b ζ̇_b = ½ żᵀ M ż, M = Σ A_bᵀ M_b A_b."""
    bd = bodies(form)
    M = sparse_of(form, "mass_z", lambda: np.einsum("bkz,bkl,blw->zw", bd.A, bd.mass, bd.A))
    return 0.5 * np.sum(zd * times(zd, M), axis=1)


def on_pose(form, z, q, W) -> np.ndarray:
    """W on x, y, fi (n, nq): Q_xy = W_p, Q_fi = W_p·Ω(p − R) + W_v·Ω v (``Loads.on_pose``)."""
    loads = Loads(form, z, q)
    loads.Qp[:], loads.Qv[:] = W[:, :, :2], W[:, :, 2:]
    return loads.on_pose()


def multipliers(form, z, W, redundant: bool, jacobian: np.ndarray | None = None) -> np.ndarray:
    """μ (n, m) with Φ_zᵀ μ = −Σ A_bᵀ W_b (= Q − M z̈), least norm where ``redundant``
    (``jacobian``: Φ_z (n, m, nz) when already evaluated)."""
    rhs = -on_coordinates(bodies(form), W)
    J = form.terms.dense(form.terms.jacobian(z)) if jacobian is None else jacobian
    if not redundant and J.shape[1] == J.shape[2]:
        return transposed_solve(J, rhs)
    return np.einsum("nmz,nz->nm", np.linalg.pinv(np.swapaxes(J, 1, 2), rcond=RCOND), rhs)


def transposed_solve(J: np.ndarray, b: np.ndarray) -> np.ndarray:
    """x (n, m) with J_kᵀ x_k = b_k at every step, J (n, m, m): one batched LU over all
    steps with the backend's threshold pivoting (``batched``, ``linear.PIVOT_THRESHOLD``:
    LAPACK's per-matrix call costs more than the elimination for small systems); NaN where
    J_k is singular (``numpy.linalg.solve`` raises there: these multipliers do not exist)."""
    At = np.ascontiguousarray(J.transpose(2, 1, 0))         # Jᵀ with the steps last
    swaps, ok = lu_factor(At, PIVOT_THRESHOLD)
    x = lu_solve(At, swaps, b.T).T
    if not ok.all():
        x[~ok] = np.nan
    return x


__all__ = ["Bodies", "applied", "bodies", "body_coordinates", "body_mass_matrices",
           "constraint_forces", "csr", "kinetic_energy", "multipliers", "on_coordinates",
           "on_pose", "shared_csr", "sparse_of", "times"]

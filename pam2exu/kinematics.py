"""Planar rigid-body kinematics, vectorised over all time steps at once.

The generalized coordinates of solid i are q[pose(i)] = q[3i:3i+3] = (x, y, fi): the
origin of its local frame and the angle of its x axis (the layout is written down once,
below: ``pose``, ``column``, ``ANGLES``). A point fixed at s in the local frame is at
r = R + A(fi) s. A *quantity* is anything built from points, directions and angles
(differences, dot products, lengths) together with what the velocity and acceleration
analyses need of it:

    value   v(q)                        shape (n, d)
    jac     dv/dq, per solid            {solid: (n, d, 3)}
    rate    dv/dt = jac · qd            (n, d)      (only with velocities)
    conv    d²v/dt² − jac · qdd         (n, d)      (only with velocities)
    hess    ∂²v/∂q_a∂q_b, per pair of solids (a, b), both orders
                                        {(a, b): (n, d, 3, 3)}  (only with hessians)

so that a constraint v(q) − f(t) = 0 has C_t = −f', and Cq qdd = γ with γ = f'' − conv.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .complex_step import as_array, number_type


# ---- the layout of q: (x, y, fi) of each solid in order -----------------------------------

#: coordinates per solid: x, y, fi
PER_SOLID = 3
#: the angles fi of every solid, in q or in a row of it (``q[..., ANGLES]``)
ANGLES = slice(2, None, PER_SOLID)


#: d(x, y)/d(x, y) of a point of a solid
_IDENTITY = np.eye(2)


def pose(solid: int) -> slice:
    """q[pose(i)] = (x, y, fi) of solid i."""
    return slice(PER_SOLID * solid, PER_SOLID * solid + PER_SOLID)


def column(solid: int, k: int) -> int:
    """The column of x (k = 0), y (1) or fi (2) of solid i in q."""
    return PER_SOLID * solid + k


def rotate(fi, v):
    """A(fi) v = (vx cos fi − vy sin fi, vx sin fi + vy cos fi), for arrays fi (n,) and v (2,)."""
    return _rotate(np.cos(fi), np.sin(fi), v)


def _rotate(c, s, v):
    """A v with A = [[c, −s], [s, c]]: ``rotate`` with cos fi and sin fi given."""
    vx, vy = v[0], v[1]
    x = c * vx
    out = np.empty(x.shape + (2,), x.dtype)     # np.stack's values, without its checks
    np.subtract(x, s * vy, out=out[..., 0])
    np.add(s * vx, c * vy, out=out[..., 1])
    return out


def perp(w):
    """Ω w = (−wy, wx): w turned 90° counter-clockwise (dA/dfi · s = Ω A s)."""
    out = np.empty(w.shape[:-1] + (2,), w.dtype)
    np.negative(w[..., 1], out=out[..., 0])
    out[..., 1] = w[..., 0]
    return out


def dot(a, b):
    """a · b over the last axis, keeping it: (n, d) · (n, d) -> (n, 1)."""
    return np.sum(a * b, axis=-1, keepdims=True)


@dataclass
class Quantity:
    """A vector-valued function of the coordinates with its derivatives (see module doc)."""

    value: np.ndarray
    jac: dict[int, np.ndarray] = field(default_factory=dict)
    rate: np.ndarray | None = None
    conv: np.ndarray | None = None
    hess: dict[tuple[int, int], np.ndarray] | None = None

    def __sub__(self, other: "Quantity") -> "Quantity":
        """v = a − b."""
        return Quantity(self.value - other.value, _combine(self.jac, other.jac, subtract=True),
                        _sub(self.rate, other.rate), _sub(self.conv, other.conv),
                        _combine(self.hess, other.hess, subtract=True))

    def __add__(self, other: "Quantity") -> "Quantity":
        """v = a + b."""
        return Quantity(self.value + other.value, _combine(self.jac, other.jac, subtract=False),
                        _add(self.rate, other.rate), _add(self.conv, other.conv),
                        _combine(self.hess, other.hess, subtract=False))

    def __mul__(self, k: float) -> "Quantity":
        """v = k a for a constant k."""
        return Quantity(self.value * k, {s: b * k for s, b in self.jac.items()},
                        None if self.rate is None else self.rate * k,
                        None if self.conv is None else self.conv * k,
                        None if self.hess is None else {p: b * k for p, b in self.hess.items()})

    def dot(self, other: "Quantity") -> "Quantity":
        """v = a · b; v'' = a''·b + a·b'' + 2 a'·b'."""
        a, b = self, other
        jac = {}
        for x, y in ((a, b), (b, a)):
            for solid, block in x.jac.items():
                term = np.einsum("nd,ndk->nk", y.value, block)[:, None, :]
                jac[solid] = jac[solid] + term if solid in jac else term
        rate = conv = None
        if a.rate is not None:
            rate = dot(a.rate, b.value) + dot(a.value, b.rate)
            conv = dot(a.conv, b.value) + dot(a.value, b.conv) + 2.0 * dot(a.rate, b.rate)
        hess = None
        if a.hess is not None and b.hess is not None:
            # ∂²(a·b) = b·∂²a + a·∂²b + ∂aᵀ∂b + ∂bᵀ∂a
            hess = {}
            for x, y in ((a, b), (b, a)):
                for pair, block in x.hess.items():
                    _accumulate(hess, pair, np.einsum("nd,ndkl->nkl", y.value, block))
                for s1, j1 in x.jac.items():
                    for s2, j2 in y.jac.items():
                        _accumulate(hess, (s1, s2), np.einsum("ndk,ndl->nkl", j1, j2))
            hess = {p: h[:, None] for p, h in hess.items()}
        return Quantity(dot(a.value, b.value), jac, rate, conv, hess)

    def norm(self) -> "Quantity":
        """v = |a|; v' = e·a', v'' = e·a'' + (|a'|² − (e·a')²)/|a| with e = a/|a|."""
        length = np.sqrt(dot(self.value, self.value))
        e = self.value / length
        jac = {s: np.einsum("nd,ndk->nk", e, b)[:, None, :] for s, b in self.jac.items()}
        rate = conv = None
        if self.rate is not None:
            rate = dot(e, self.rate)
            conv = dot(e, self.conv) + (dot(self.rate, self.rate) - rate * rate) / length
        hess = None
        if self.hess is not None:
            # ∂²|a| = e·∂²a + (∂aᵀ∂a − (eᵀ∂a)ᵀ(eᵀ∂a)) / |a|
            hess = {}
            for pair, block in self.hess.items():
                _accumulate(hess, pair, np.einsum("nd,ndkl->nkl", e, block))
            for s1, j1 in self.jac.items():
                for s2, j2 in self.jac.items():
                    g1, g2 = jac[s1][:, 0], jac[s2][:, 0]
                    term = (np.einsum("ndk,ndl->nkl", j1, j2)
                            - g1[:, :, None] * g2[:, None, :]) / length[:, :, None]
                    _accumulate(hess, (s1, s2), term)
            hess = {p: h[:, None] for p, h in hess.items()}
        return Quantity(length, jac, rate, conv, hess)

    def weighted_hessian(self, weights: np.ndarray, out: np.ndarray) -> None:
        """out (n, nq, nq) += Σ_d w_d ∂²v_d/∂q², weights (n, d) (λ of the rows of v)."""
        for (a, b), block in self.hess.items():
            out[:, pose(a), pose(b)] += np.einsum("nd,ndkl->nkl", weights, block)

    def rows(self, jacobian: np.ndarray, row: int) -> None:
        """Write dv/dq into rows row… of a full Jacobian (n, m, 3·solids), zero there before."""
        d = self.value.shape[1]
        for solid, block in self.jac.items():
            jacobian[:, row:row + d, pose(solid)] = block


def _add(a, b):
    return None if a is None else a + b


def _combine(a: dict | None, b: dict | None, subtract: bool) -> dict | None:
    """The blocks of a + b or a − b, per key (None if either is None)."""
    if a is None or b is None:
        return None
    out = dict(a)
    for key, block in b.items():
        if key in out:
            out[key] = out[key] - block if subtract else out[key] + block
        else:
            out[key] = -block if subtract else block
    return out


def _accumulate(blocks: dict, key, block: np.ndarray) -> None:
    """blocks[key] += block (a new entry if there is none)."""
    blocks[key] = blocks[key] + block if key in blocks else block


def _sub(a, b):
    return None if a is None else a - b


def stack(*quantities: Quantity) -> Quantity:
    """The rows of several quantities, one after the other."""
    n = quantities[0].value.shape[0]
    dims = [q.value.shape[1] for q in quantities]
    dtype = np.result_type(*(q.value for q in quantities))   # complex in the complex step
    jac: dict[int, np.ndarray] = {}
    offset = 0
    for q, d in zip(quantities, dims):
        for solid, block in q.jac.items():
            if solid not in jac:
                jac[solid] = np.zeros((n, sum(dims), 3), dtype)
            jac[solid][:, offset:offset + d] += block
        offset += d
    hess = None
    if all(q.hess is not None for q in quantities):
        hess = {}
        offset = 0
        for q, d in zip(quantities, dims):
            for pair, block in q.hess.items():
                if pair not in hess:
                    hess[pair] = np.zeros((n, sum(dims), 3, 3), dtype)
                hess[pair][:, offset:offset + d] += block
            offset += d
    cat = lambda xs: None if xs[0] is None else np.concatenate(xs, axis=1)  # noqa: E731
    return Quantity(cat([q.value for q in quantities]), jac,
                    cat([q.rate for q in quantities]), cat([q.conv for q in quantities]),
                    hess)


@dataclass
class PointSet:
    """Points and directions of solids to build at once (``State.prepare``), from
    [(solid, local (2,), translate)] as ``State.asked`` lists them."""

    solids: np.ndarray          # (K,) int
    local: np.ndarray           # (K, 2)
    translate: np.ndarray       # (K,) bool: a point (True) or a direction
    keys: list                  # the State's keys of them

    def __post_init__(self):
        #: the columns of q of each one's solid: fi (K,) and x, y (K, 2)
        self.angles = PER_SOLID * self.solids + 2
        self.origins = PER_SOLID * self.solids[:, None] + np.arange(2)
        #: dv/d(x, y) of each (K, 2, 3): the identity for a point, zero for a direction
        self.frame = np.zeros((len(self.solids), 2, 3))
        self.frame[:, 0, 0] = self.frame[:, 1, 1] = self.translate
        self.points_only = bool(self.translate.all())

    @classmethod
    def of(cls, asked: list[tuple]) -> "PointSet":
        locals_ = [as_array(a[1]) for a in asked]      # complex at p + ih (complex step)
        return cls(np.array([a[0] for a in asked], dtype=int),
                   np.array(locals_, dtype=number_type(*locals_)).reshape(-1, 2),
                   np.array([a[2] for a in asked], dtype=bool),
                   [(a[0], local.tobytes(), a[2]) for a, local in zip(asked, locals_)])


def _rows(a: np.ndarray, ndim: int) -> np.ndarray:
    """``np.atleast_1d`` (ndim 1) or ``np.atleast_2d`` (ndim 2) of an array."""
    if a.ndim >= ndim:
        return a
    return np.atleast_1d(a) if ndim == 1 else np.atleast_2d(a)


class State:
    """Coordinates q (n, 3·solids) at times t (n,), and optionally velocities qd.

    ``jacobians=False``: the quantities built from it carry no dv/dq (``Quantity.jac`` is
    empty), for passes that need only values, rates and conv (residuals, γ).
    ``hessians=True``: they also carry ∂²v/∂q² (``Quantity.hess``; the clearance analysis).
    """

    def __init__(self, t, q, qd=None, jacobians: bool = True, hessians: bool = False):
        self.t = _rows(np.asarray(t, dtype=float), 1)
        self.q = _rows(as_array(q), 2)
        self.qd = None if qd is None else _rows(as_array(qd), 2)
        self.n = self.q.shape[0]
        self.jacobians = jacobians or hessians
        self.hessians = hessians
        # what is evaluated once per State: (cos fi, sin fi) per solid, points and directions
        self._trig: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        self._rotated_memo: dict[tuple, Quantity] = {}
        #: the points and directions built one by one, as ``prepare`` takes them
        self.asked: list[tuple] = []

    def coordinate(self, solid: int, k: int) -> Quantity:
        """v = q[column(solid, k)]: x (k=0), y (k=1) or fi (k=2) of a solid."""
        col = column(solid, k)
        jac = {}
        if self.jacobians:
            jac[solid] = np.zeros((self.n, 1, 3))
            jac[solid][:, 0, k] = 1.0
        rate = conv = None
        if self.qd is not None:
            rate, conv = self.qd[:, col:col + 1], np.zeros((self.n, 1))
        return Quantity(self.q[:, col:col + 1], jac, rate, conv, {} if self.hessians else None)

    def angle(self, solid: int) -> Quantity:
        """v = fi of a solid."""
        return self.coordinate(solid, 2)

    def trig(self, solid: int) -> tuple[np.ndarray, np.ndarray]:
        """(cos fi, sin fi) of a solid at every state, evaluated once per State."""
        if solid not in self._trig:
            fi = self.q[:, column(solid, 2)]
            self._trig[solid] = np.cos(fi), np.sin(fi)
        return self._trig[solid]

    def _rotated(self, solid: int, local, translate: bool) -> Quantity:
        """A point (``translate``) or a direction of a solid, built once per State (the
        Quantity is shared: never changed in place)."""
        local = as_array(local)
        key = (solid, local.tobytes(), translate)
        if key not in self._rotated_memo:
            self._rotated_memo[key] = self._build_rotated(solid, local, translate)
            self.asked.append((solid, local, translate))
        return self._rotated_memo[key]

    def _build_rotated(self, solid: int, local: np.ndarray, translate: bool) -> Quantity:
        x = PER_SOLID * solid
        c, s = self.trig(solid)
        if (self.n == 1 and self.qd is None and not self.hessians and c.dtype == np.float64
                and local.dtype == np.float64):
            return self._one_rotated(x, c.item(), s.item(), local, translate)
        As = _rotate(c, s, local)
        jac = {}
        turned = None
        if self.jacobians:
            block = jac[solid] = np.empty((self.n, 2, 3), dtype=As.dtype)
            block[:, :, :2] = _IDENTITY if translate else 0.0
            turned = block[:, :, 2]
            np.negative(As[:, 1], out=turned[:, 0])          # perp(As), written in place
            turned[:, 1] = As[:, 0]
        value = As + self.q[:, x:x + 2] if translate else As
        rate = conv = None
        if self.qd is not None:
            w = self.qd[:, x + 2:x + 3]
            rate = w * (perp(As) if turned is None else turned)
            if translate:
                rate += self.qd[:, x:x + 2]
            conv = -(w * w) * As
        hess = None
        if self.hessians:                      # ∂²(A s)/∂fi² = −A s, the rest 0
            hess = {(solid, solid): np.zeros((self.n, 2, 3, 3), dtype=As.dtype)}
            hess[solid, solid][:, :, 2, 2] = -As
        return Quantity(value, jac, rate, conv, hess)

    def _one_rotated(self, x: int, c: float, s: float, local: np.ndarray,
                     translate: bool) -> Quantity:
        """``_build_rotated`` at one real state without velocities: the same products and
        sums in floats, each array made at once (a rank test's point)."""
        vx, vy = local.tolist()
        ax, ay = c * vx - s * vy, s * vx + c * vy
        value = ([[ax + self.q[0, x].item(), ay + self.q[0, x + 1].item()]] if translate
                 else [[ax, ay]])
        jac = {}
        if self.jacobians:
            e = 1.0 if translate else 0.0
            jac[x // PER_SOLID] = np.array([[[e, 0.0, -ay], [0.0, e, ax]]])
        return Quantity(np.array(value), jac)

    def values_only(self) -> "State":
        """The same states for values alone: the points and directions built from it carry
        no velocities and no dv/dq (``jacobians=False``); (cos fi, sin fi) are shared."""
        light = State(self.t, self.q, jacobians=False)
        light._trig = self._trig              # the same q: the same cos fi, sin fi
        return light

    def prepare(self, points: "PointSet") -> None:
        """Build the points and directions of ``points`` at once, in one vectorised pass,
        with the values ``point`` and ``direction`` give one by one (real coordinates, no
        velocities: otherwise they are left to those)."""
        if self.qd is not None or np.iscomplexobj(self.q):
            return
        local, translate, K = points.local, points.translate, len(points.solids)
        fi = self.q[:, points.angles]                                 # (n, K)
        c, s = np.cos(fi), np.sin(fi)
        x = c * local[:, 0]
        As = np.empty(x.shape + (2,), x.dtype)                        # (n, K, 2)
        np.subtract(x, s * local[:, 1], out=As[..., 0])
        np.add(s * local[:, 0], c * local[:, 1], out=As[..., 1])
        origin = self.q[:, points.origins]                            # (n, K, 2)
        value = (As + origin if points.points_only
                 else np.where(translate[None, :, None], As + origin, As))
        jac = np.empty((self.n, K, 2, 3))
        jac[...] = points.frame
        jac[..., 2] = perp(As)
        hess = None
        if self.hessians:                      # ∂²(A s)/∂fi² = −A s, the rest 0
            hess = np.zeros((self.n, K, 2, 3, 3))
            hess[..., 2, 2] = -As
        for k, key in enumerate(points.keys):
            solid = key[0]
            self._rotated_memo[key] = Quantity(
                value[:, k], {solid: jac[:, k]}, None, None,
                None if hess is None else {(solid, solid): hess[:, k]})

    def point(self, solid: int, local) -> Quantity:
        """v = R + A(fi) s: global position of the point s of a solid."""
        return self._rotated(solid, local, translate=True)

    def direction(self, solid: int, local) -> Quantity:
        """v = A(fi) u: a vector u fixed to a solid, in the global basis."""
        return self._rotated(solid, local, translate=False)


def cross(a, b):
    """a × b = ax by − ay bx (the z component), over the last axis: (n, 2) × (n, 2) -> (n,)."""
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def generalized_force(point: Quantity, force) -> dict[int, np.ndarray]:
    """Q = Jᵀ F: a force F (n, 2) applied at a point (a Quantity of value (n, 2)), per solid.

    For a point of solid i, Q_i = (Fx, Fy, (A s) × F): the force and its moment about the
    origin of the solid's frame.
    """
    return {s: np.einsum("nd,ndk->nk", force, block) for s, block in point.jac.items()}


def torque(solid: int, moment) -> dict[int, np.ndarray]:
    """Q = (0, 0, M): a pure moment M (n,) on a solid."""
    moment = as_array(moment)
    out = np.zeros((moment.shape[0], 3), moment.dtype)
    out[:, 2] = moment
    return {solid: out}


def move_wrench(wrench, origin, point):
    """(F, M_p) with M_p = M_O − (p − O) × F: a wrench (..., 3) about O moved to the point p."""
    out = np.array(wrench, dtype=np.result_type(float, wrench, origin, point), copy=True)
    out[..., 2] -= cross(point - origin, wrench[..., :2])
    return out


def moved_to_basis(wrench, origin, point, direction):
    """``to_basis(move_wrench(wrench, origin, point), direction)``, the same products and
    sums, with one array made (the moved wrench is not copied first)."""
    ex, ey = direction[..., 0], direction[..., 1]
    fx, fy = wrench[..., 0], wrench[..., 1]
    out = np.empty(wrench.shape, np.result_type(float, wrench, origin, point, direction))
    np.add(ex * fx, ey * fy, out=out[..., 0])
    np.add(-ey * fx, ex * fy, out=out[..., 1])
    np.subtract(wrench[..., 2], cross(point - origin, wrench[..., :2]), out=out[..., 2])
    return out


def to_basis(wrench, direction):
    """The wrench (..., 3) with its force in the basis whose x axis is the unit vector
    ``direction`` (..., 2)."""
    ex, ey = direction[..., 0], direction[..., 1]
    fx, fy = wrench[..., 0], wrench[..., 1]
    out = np.empty_like(wrench, dtype=np.result_type(wrench, direction))
    np.add(ex * fx, ey * fy, out=out[..., 0])
    np.add(-ey * fx, ex * fy, out=out[..., 1])
    out[..., 2] = wrench[..., 2]
    return out

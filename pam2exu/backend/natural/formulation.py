"""A mechanism in natural coordinates (Unda & García de Jalón): which coordinates, which
equations, and how x, y, fi follow from them.

The coordinates z are

* basic points: the points that revolute joints join, one shared pair (x, y) for all the
  solids a joint pins together (a revolute is a shared point and no equation);
* unit vectors (x, y) fixed to a solid that has fewer than two basic points (its x axis),
  and its origin as a basic point if it has none;
* angles: the absolute angle of a solid whose angle an element uses (angular actuators,
  transmissions), tied to the solid's vector by one equation ("mixed coordinates").

A solid held by a fixed link is ground: its points are constants. Every point and
direction of a solid is linear in z (``Frame``): with a base point p (local s_p) and a base
vector v = A d (two basic points, v = P₂ − P₁, or a unit vector, d = (1, 0)),

    r(s) = p + a v + b Ω v,    (a, b) = (d·w, d×w) / |d|²,  w = s − s_p,

so the rigid-solid equations are |v|² = |d|² (quadratic) and, for each further basic point,
P_k − r(s_k) = 0 (linear); no solid can mirror. The elements declare their own equations
(``Element.natural``) from these points, directions and angles.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...kinematics import pose
from .forms import ONE, Expr, Vec
from .terms import Terms


@dataclass
class Frame:
    """A solid's points as linear forms in z: r(s) = p + a v + b Ω v (module doc)."""

    solid: int
    p: Vec
    v: Vec
    sp: tuple[float, float]
    d: tuple[float, float]
    #: the index of its angle coordinate, or None
    angle: int | None = None
    #: its constant angle if it is ground
    fixed_angle: float | None = None

    def _ab(self, w) -> tuple[float, float]:
        dx, dy = self.d
        n2 = dx * dx + dy * dy
        return (dx * w[0] + dy * w[1]) / n2, (dx * w[1] - dy * w[0]) / n2

    def point(self, local) -> Vec:
        """r(s) = p + a v + b Ω v: the point s (local) of the solid."""
        a, b = self._ab((local[0] - self.sp[0], local[1] - self.sp[1]))
        return self._plus(self.p, a, b)

    def direction(self, local) -> Vec:
        """A u = a v + b Ω v: the local vector u of the solid in the global basis."""
        a, b = self._ab(local)
        return self._plus(None, a, b)

    def _plus(self, out: Vec | None, a: float, b: float) -> Vec:
        """out + a v + b Ω v (out None: 0), a term whose coefficient is 0 left out, a
        coefficient 1 not multiplied, and 0 + e taken as e (the same sums: such a term adds
        nothing, c · 1 is c, 0 + c is c; expressions are never changed once made, so the
        result may share the frame's)."""
        if a:
            term = self.v if a == 1.0 else self.v * a
            out = term if out is None else out + term
        if b:
            perp = self.v.perp()
            term = perp if b == 1.0 else perp * b
            out = term if out is None else out + term
        return Vec(Expr(), Expr()) if out is None else out

    def cos_sin(self) -> tuple[Expr, Expr]:
        """(cos fi, sin fi) = (d·v, d×v) / |d|²: linear in z."""
        c = self.direction((1.0, 0.0))
        return c.x, c.y

    def origin(self) -> Vec:
        """The solid's frame origin (x, y) = r(0)."""
        return self.point((0.0, 0.0))


class _Recorder:
    """The first reading of the elements' declarations: which solids are ground, which
    points revolutes join, which solids need an angle coordinate."""

    def __init__(self):
        self.grounds: dict[int, tuple] = {}
        self.joined: list[tuple] = []
        self.angles: set[int] = set()

    def ground(self, solid, pose_):
        self.grounds.setdefault(solid, tuple(float(v) for v in pose_))

    def coincide(self, ref1, ref2, element=None):
        self.joined.append(((ref1.solid, tuple(ref1.local)), (ref2.solid, tuple(ref2.local))))

    def point(self, solid, local):
        return Vec(Expr(), Expr())

    def direction(self, solid, local):
        return Vec(Expr(), Expr())

    def angle(self, solid):
        self.angles.add(solid)
        return Expr()

    def equation(self, element, expressions, target=0.0, power=1):
        pass


@dataclass
class Coordinate:
    """One natural coordinate: its name (for tables) and kind ('point', 'vector', 'angle')."""

    name: str
    kind: str


class Formulation:
    """The natural coordinates, equations and mass matrix of a mechanism.

    Parameters
    ----------
    mech : Mechanism
    all_angles : bool
        Give every moving solid an angle coordinate (the assembly's distance to the guess
        is then quadratic in z).

    Attributes
    ----------
    coordinates : list of Coordinate
    frames : list of Frame
        One per solid, in order.
    terms : Terms
        The equations, compiled (values, Jacobians, velocity terms for all steps at once).
    labels : list of str
        What each equation is ("rigid 'coupler'", "'motor' (angular_actuator)").
    """

    def __init__(self, mech, all_angles: bool = False):
        self.mech = mech
        self.coordinates: list[Coordinate] = []
        rec = _Recorder()
        for el in mech.elements:
            el.natural(rec)
        self.grounds = rec.grounds
        wanted = set(rec.angles) | (set(range(len(mech.solids))) if all_angles else set())
        self._basic_points(rec.joined)
        self.frames = [self._frame(i) for i in range(len(mech.solids))]
        for i, f in enumerate(self.frames):
            if i in wanted and i not in self.grounds:
                f.angle = self._new(f"{mech.solids[i].name}.fi", "angle")
        self.nz = len(self.coordinates)
        self._rows: list = []          # (label, Expr, target, power)
        self._rigid_equations()
        for el in mech.elements:
            el.natural(self)
        self.labels = [r[0] for r in self._rows]
        self.terms = Terms(self.nz, [r[1:] for r in self._rows])
        self.m = len(self._rows)

    # ---- coordinates ----------------------------------------------------------------------
    def _new(self, name: str, kind: str) -> int:
        self.coordinates.append(Coordinate(name, kind))
        return len(self.coordinates) - 1

    def _new_point(self, name: str, kind: str = "point") -> Vec:
        i = self._new(f"{name}.x", kind)
        j = self._new(f"{name}.y", kind)
        return Vec(Expr.coordinate(i), Expr.coordinate(j))

    def _ground_point(self, solid: int, local) -> np.ndarray:
        x, y, fi = self.grounds[solid]
        c, s = math.cos(fi), math.sin(fi)
        return np.array([x + c * local[0] - s * local[1], y + s * local[0] + c * local[1]])

    def _basic_points(self, joined) -> None:
        """Union of the points revolutes join; one basic point per group (a constant if a
        ground solid is in it); a solid with two different points in one group, or a second
        ground point in it, keeps its own point and the revolute becomes two equations."""
        parent: dict = {}

        def find(k):
            while parent.setdefault(k, k) != k:
                parent[k] = parent[parent[k]]
                k = parent[k]
            return k

        for a, b in joined:
            parent[find(a)] = find(b)
        groups: dict = {}
        for a, b in joined:
            for key in (a, b):
                members = groups.setdefault(find(key), [])
                if key not in members:
                    members.append(key)
        self.basic: dict = {}                  # (solid, local) -> Vec
        self.own: dict[int, list] = {}         # solid -> [(local, Vec)] of its basic points
        names = self.mech.solids
        for members in groups.values():
            grounded = [k for k in members if k[0] in self.grounds]
            if grounded:
                shared = Vec.constant(self._ground_point(*grounded[0]))
            else:
                s, loc = members[0]
                shared = self._new_point(f"{names[s].name}({loc[0]:g},{loc[1]:g})")
            used: dict[int, tuple] = {}
            for key in members:
                solid, loc = key
                if solid in self.grounds and key != (grounded[0] if grounded else None):
                    vec = Vec.constant(self._ground_point(solid, loc))
                elif solid in used and used[solid] != loc:
                    vec = self._new_point(f"{names[solid].name}({loc[0]:g},{loc[1]:g})")
                else:
                    vec = shared
                used.setdefault(solid, loc)
                self.basic[key] = vec
                if solid not in self.grounds and all(l != loc for l, _ in
                                                     self.own.get(solid, [])):
                    self.own.setdefault(solid, []).append((loc, vec))

    def _frame(self, i: int) -> Frame:
        """The solid's base point and base vector (module doc)."""
        name = self.mech.solids[i].name
        if i in self.grounds:
            x, y, fi = self.grounds[i]
            return Frame(i, Vec.constant((x, y)), Vec.constant((math.cos(fi), math.sin(fi))),
                         (0.0, 0.0), (1.0, 0.0), fixed_angle=fi)
        own = self.own.get(i, [])
        if len(own) >= 2:
            (s1, p1) = own[0]
            far = max(own[1:], key=lambda o: math.hypot(o[0][0] - s1[0], o[0][1] - s1[1]))
            size = max(1.0, *(abs(c) for loc, _ in own for c in loc))
            # two basic points closer than round-off do not give the solid a direction
            # (|d|² would underflow, fuzz seed 107791): its unit vector then
            if math.hypot(far[0][0] - s1[0], far[0][1] - s1[1]) > 1e-9 * size:
                d = (far[0][0] - s1[0], far[0][1] - s1[1])
                return Frame(i, p1, far[1] - p1, s1, d)
        if own:
            s1, p1 = own[0]
        else:
            s1, p1 = (0.0, 0.0), self._new_point(f"{name}.origin")
        return Frame(i, p1, self._new_point(f"{name}.u", "vector"), s1, (1.0, 0.0))

    def _rigid_equations(self) -> None:
        """|v|² = |d|² for each moving solid, P_k = r(s_k) for its further basic points;
        ``rigid_owners``: the solid of each of these rows, in order."""
        self.rigid_owners: list[int] = []
        for i, f in enumerate(self.frames):
            if i in self.grounds:
                continue
            before = len(self._rows)
            label = f"rigid '{self.mech.solids[i].name}'"
            if not f.v.x.is_constant or not f.v.y.is_constant:   # else held by two ground pins
                self._rows.append((label, f.v.dot(f.v), f.d[0] ** 2 + f.d[1] ** 2, 1))
            base = {f.sp, (f.sp[0] + f.d[0], f.sp[1] + f.d[1])}
            for loc, vec in self.own.get(i, []):
                if loc not in base:
                    gap = vec - f.point(loc)
                    self._rows += [(label, gap.x, 0.0, 1), (label, gap.y, 0.0, 1)]
            if f.angle is not None:
                alpha = math.atan2(f.d[1], f.d[0])
                size = math.hypot(*f.d)
                self._rows.append((f"angle of '{self.mech.solids[i].name}'",
                                   f.v.aligned(f.angle, alpha) * (1.0 / size), 0.0, 1))
            self.rigid_owners += [i] * (len(self._rows) - before)

    # ---- what the elements' ``natural`` declarations call -----------------------------------
    def ground(self, solid, pose_) -> None:
        """A fixed link: the solid is ground (no coordinates, no equation)."""

    def coincide(self, ref1, ref2, element=None) -> None:
        """A revolute: its two points are one basic point (or, where they could not be
        shared, two equal ones: two linear equations)."""
        a, b = (self.basic[(r.solid, tuple(r.local))] for r in (ref1, ref2))
        if a != b:
            self.equation(element, [(b - a).x, (b - a).y])

    def point(self, solid: int, local) -> Vec:
        """The point ``local`` of a solid, linear in z."""
        return self.frames[solid].point(local)

    def direction(self, solid: int, local) -> Vec:
        """The local vector ``local`` of a solid in the global basis, linear in z."""
        return self.frames[solid].direction(local)

    def angle(self, solid: int) -> Expr:
        """The solid's absolute angle fi: its angle coordinate (a constant for ground)."""
        f = self.frames[solid]
        return Expr.constant(f.fixed_angle) if f.angle is None else Expr.coordinate(f.angle)

    def equation(self, element, expressions, target=0.0, power: int = 1) -> None:
        """expression − target = 0 for each expression; target: a number or a Law, which
        enters as f(t) (power 1) or f(t)² (power 2)."""
        label = f"'{element.name}' ({element.type})" if element is not None else "revolute"
        for e in expressions:
            if not e.is_constant:
                self._rows.append((label, e, target, power))
            # else: between ground solids only: nothing to solve (the native residual check
            # still reports the model if they disagree)

    # ---- x, y, fi ---------------------------------------------------------------------------
    def pose_forms(self) -> np.ndarray:
        """K (4·solids, nz + 1): (x, y, cos fi, sin fi) of every solid = K [z; 1] (a copy of
        the one made on the first call: it depends only on the formulation)."""
        if "_pose_forms" not in self.__dict__:
            self._pose_forms = self._make_pose_forms()
        return self._pose_forms.copy()

    def _make_pose_forms(self) -> np.ndarray:
        rows = []
        for f in self.frames:
            c, s = f.cos_sin()
            o = f.origin()
            rows += [o.x, o.y, c, s]
        K = np.zeros((len(rows), self.nz + 1))
        for r, e in enumerate(rows):
            for i, c in e.linear().items():
                K[r, self.nz if i == ONE else i] += c
        return K

    def from_q(self, q: np.ndarray) -> np.ndarray:
        """z (n, nz) of configurations q (n, nq): each coordinate from the first solid that
        has it (exact where q satisfies the constraints)."""
        q = np.atleast_2d(q)
        z = np.zeros((q.shape[0], self.nz))
        if "_placing" not in self.__dict__:
            self._placing = self._make_placing()
        for i, placed, angle in self._placing:
            x, y, fi = (q[:, k] for k in range(pose(i).start, pose(i).stop))
            c, s = np.cos(fi), np.sin(fi)
            for k, what, loc in placed:
                if what == "x":                     # a basic point's x, y
                    z[:, k] = x + c * loc[0] - s * loc[1]
                elif what == "y":
                    z[:, k] = y + s * loc[0] + c * loc[1]
                else:                               # the origin, a unit vector
                    z[:, k] = {"ox": x, "oy": y, "c": c, "s": s}[what]
            if angle is not None:
                z[:, angle] = fi
        return z

    def _make_placing(self) -> list:
        """What ``from_q`` writes, per moving solid: [(solid, [(coordinate, what, local)],
        angle coordinate)], each coordinate from the first solid whose basic point, origin
        or unit vector it is alone (coefficient 1)."""
        placed = np.zeros(self.nz, dtype=bool)
        out = []
        for i, f in enumerate(self.frames):
            if i in self.grounds:
                continue
            writes = []

            def place(vec: Vec, what, loc):
                for e, name in zip((vec.x, vec.y), what):
                    lin = e.linear()
                    if len(lin) == 1 and next(iter(lin.values())) == 1.0:
                        k = next(iter(lin))
                        if k != ONE and not placed[k]:     # (ONE: a ground point's 1.0)
                            writes.append((k, name, loc))
                            placed[k] = True

            for loc, vec in self.own.get(i, []):
                place(vec, ("x", "y"), loc)
            if not self.own.get(i):
                place(f.p, ("ox", "oy"), None)
            place(f.v, ("c", "s"), None)       # a unit vector (does nothing for P₂ − P₁)
            out.append((i, writes, f.angle))
        return out

    # ---- the constant mass matrix -----------------------------------------------------------
    def mass_matrix(self, solids=None) -> np.ndarray:
        """M (nz, nz), constant: T = ½ żᵀ M ż; per solid, with ṗ = P ż and v̇ = V ż,
        T = ½ [m |ṗ|² + 2 m ṗ·(a_G v̇ + b_G Ω v̇) + J_p |v̇|² / |d|²], J_p = I_G + m |s_G − s_p|².
        ``solids``: only these solids' share (indices; default all)."""
        M = np.zeros((self.nz, self.nz))
        omega = np.array([[0.0, -1.0], [1.0, 0.0]])
        for i, f in enumerate(self.frames):
            if solids is not None and i not in solids:
                continue
            solid = self.mech.solids[i]
            m, inertia = float(solid.mass), float(solid.inertia)
            if i in self.grounds or (m == 0 and inertia == 0):
                continue
            P, V = self.matrix(f.p), self.matrix(f.v)
            g = (float(solid.cog[0]), float(solid.cog[1]))
            a, b = f._ab((g[0] - f.sp[0], g[1] - f.sp[1]))
            jp = inertia + m * ((g[0] - f.sp[0]) ** 2 + (g[1] - f.sp[1]) ** 2)
            G = a * V + b * omega @ V
            M += m * P.T @ P + m * (P.T @ G + G.T @ P) + jp / (f.d[0] ** 2 + f.d[1] ** 2) * V.T @ V
        return M

    def affine(self, solid: int, local, kind: str = "point") -> tuple:
        """(A (2, nz), c (2,)): a solid's point ``local`` (kind ``point``), local vector
        (``direction``), base point (``p``) or base vector (``v``) is A z + c (kept: the
        dynamic analysis asks for the same ones at every state)."""
        cache = self.__dict__.setdefault("_affine", {})
        key = (solid, None if local is None else (float(local[0]), float(local[1])), kind)
        if key not in cache:
            f = self.frames[solid]
            vec = {"point": f.point, "direction": f.direction}[kind](local) \
                if kind in ("point", "direction") else getattr(f, kind)
            cache[key] = (self.matrix(vec), self.constants(vec))
        return cache[key]

    def matrix(self, vec: Vec) -> np.ndarray:
        """(2, nz): the coefficients of a linear Vec (its constant left out)."""
        out = np.zeros((2, self.nz))
        for r, e in enumerate((vec.x, vec.y)):
            for i, c in e.linear().items():
                if i != ONE:
                    out[r, i] += c
        return out

    def constants(self, vec: Vec) -> np.ndarray:
        """(2,): the constant parts of a linear Vec."""
        return np.array([e.linear().get(ONE, 0.0) for e in (vec.x, vec.y)])

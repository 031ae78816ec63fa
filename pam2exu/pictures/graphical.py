"""The graphical methods of a mechanism course, as data drawn from the computed values.

At one instant t (a kinematic run from 0 to t with the model's step length, as ``draw``):

- ``polygon(model, t, 'v' | 'a')``: the velocity or acceleration polygon. From its pole,
  the absolute vector of every declared point of the moving solids; for every two points P,
  Q of one solid, the relative vector v_QP = ω Ω (Q − P), or a_QP = a^n + a^t with the
  normal component a^n = −ω² (Q − P) and the tangential one a^t = α Ω (Q − P).
- ``all_centres(model, t)``: the instantaneous centre I_ij of every two bodies, relative ones
  included (the ground, all solids held by a fixed link, is body 1; the moving solids
  follow in the model's order): n (n − 1) / 2 of them, and the Kennedy line through the
  three centres of every three bodies.
- ``centrodes(model, solid, t)``: the fixed centrode (the solid's instantaneous centre over
  the model's run, in the ground's frame), the moving centrode (the same points in the
  solid's own frame, drawn where the solid is at t) and the inflection circle at t.

Each is a frozen dataclass with named fields (numbers, not pixels): ``graphical_draw.py``
draws them. The mathematics is ``pam2exu.points``' (``point_motion``,
``instantaneous_centre``, ``velocity_field``, ``relative_centre``, ``collinearity``,
``inflection_circle``, ``in_frame``).
"""
from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

import numpy as np

from ..kinematics import perp, rotate
from ..points import (collinearity, in_frame, inflection_circle, instantaneous_centre,
                      motion_size, off_line, point_motion, relative_centre,
                      relative_field, velocity_field)
from ..results.plot import PictureError
from .poses import _model
from .vectors import _row

#: the polygons: analysis run, unit, what they are called
POLYGONS = {"v": ("m/s", "velocity polygon"), "a": ("m/s²", "acceleration polygon")}


@dataclass(frozen=True)
class Motion:
    """One solid at one instant: origin r [m], its velocity v, acceleration a (None when not
    computed), angle fi [rad], angular velocity dfi, angular acceleration ddfi."""

    index: int
    name: str
    r: np.ndarray
    v: np.ndarray
    a: np.ndarray | None
    fi: float
    dfi: float
    ddfi: float | None

    def point(self, local) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        """(x_P, v_P, a_P) of the local point p (``points.point_motion``)."""
        x, v, a = point_motion(self.r[None], self.v[None],
                               None if self.a is None else self.a[None], [self.fi],
                               [self.dfi], None if self.ddfi is None else [self.ddfi], local)
        return x[0], v[0], None if a is None else a[0]


def motions(model, t: float, accelerations: bool = False):
    """(mechanism, q, [Motion of every solid]) at time t, from a kinematic run to t."""
    model = _model(model)
    mech = model.mechanism()
    rates = ("Dx", "Dy", "Dfi") + (("DDx", "DDy", "DDfi") if accelerations else ())
    res, k = _row(model, t, "kinematic", mech.coordinate_columns()
                  + [f"{s.name}.{r}" for s in mech.solids for r in rates])
    out = []
    for i, s in enumerate(mech.solids):
        get = lambda *rs: np.array([float(res[f"{s.name}.{r}"][k]) for r in rs])  # noqa: E731
        out.append(Motion(i, s.name, get("x", "y"), get("Dx", "Dy"),
                          get("DDx", "DDy") if accelerations else None, float(get("fi")[0]),
                          float(get("Dfi")[0]),
                          float(get("DDfi")[0]) if accelerations else None))
    return mech, mech.coordinates(res)[k], out


def _points(solid) -> dict[str, tuple[float, float]]:
    """A solid's declared points (its origin, named '', when it has none)."""
    return {n: tuple(float(c) for c in p) for n, p in solid.points.items()} or {"": (0.0, 0.0)}


# ---- polygons -----------------------------------------------------------------------------
@dataclass(frozen=True)
class Vector:
    """The absolute velocity or acceleration ``value`` of point ``point`` of ``solid``, which is
    at ``at`` [m]; ``name`` is PAM's (``coupler.P``; a solid's origin: the solid's name)."""

    name: str
    solid: str
    point: str
    at: np.ndarray
    value: np.ndarray


@dataclass(frozen=True)
class Relative:
    """The relative vector of point ``end`` to point ``start`` of ``solid``: v_QP = ω Ω (Q − P),
    or a_QP = ``normal`` + ``tangential`` (a^n = −ω² (Q − P), a^t = α Ω (Q − P); None for
    velocities)."""

    solid: str
    start: str
    end: str
    value: np.ndarray
    normal: np.ndarray | None = None
    tangential: np.ndarray | None = None

    @property
    def name(self) -> str:
        return f"{self.solid}.{self.end}/{self.start}"


@dataclass(frozen=True)
class Polygon:
    """The velocity (``kind`` 'v') or acceleration ('a') polygon at time ``t`` [s]: the pole
    is the zero vector; ``absolute`` from it, ``relative`` between the images of two points
    of one solid (image of P = pole + its absolute vector)."""

    kind: str
    t: float
    unit: str
    absolute: tuple[Vector, ...]
    relative: tuple[Relative, ...]

    def image(self, name: str) -> np.ndarray:
        """The image of the point ``name`` (``coupler.P``): the tip of its absolute vector."""
        for v in self.absolute:
            if v.name == name:
                return v.value
        raise KeyError(f"no point {name!r} in the polygon; it has "
                       f"{', '.join(v.name for v in self.absolute)}")


def relative_velocity(dfi: float, d) -> np.ndarray:
    """v_QP = ω Ω (Q − P), d = Q − P."""
    return dfi * perp(np.asarray(d, dtype=float))


def acceleration_components(dfi: float, ddfi: float, d) -> tuple[np.ndarray, np.ndarray]:
    """(a^n, a^t) = (−ω² (Q − P), α Ω (Q − P)), d = Q − P: a_QP = a^n + a^t."""
    d = np.asarray(d, dtype=float)
    return -dfi * dfi * d, ddfi * perp(d)


def polygon(model, t: float, kind: str) -> Polygon:
    """The velocity (``kind='v'``) or acceleration (``'a'``) polygon at time t [s].

    Every declared point of every moving solid (a solid without points: its origin) has
    its absolute vector (``points.point_motion`` of the run's x … DDfi, the values of its
    ``<solid>.<point>.Dx`` … columns); every two points of one solid, in the order declared,
    their relative vector from the solid's ω (and α).

    Raises
    ------
    PictureError
        ``kind`` is not 'v' or 'a'.
    """
    if kind not in POLYGONS:
        raise PictureError(f"--polygon is v (velocities) or a (accelerations), not {kind!r}")
    mech, _, moving = motions(model, t, accelerations=kind == "a")
    absolute, relative = [], []
    for m in moving:
        if m.index in mech.held:
            continue
        local = _points(mech.solids[m.index])
        where = {}
        for name, p in local.items():
            x, v, a = m.point(p)
            where[name] = x
            absolute.append(Vector(f"{m.name}.{name}" if name else m.name, m.name, name, x,
                                   v if kind == "v" else a))
        for start, end in combinations(local, 2):
            d = where[end] - where[start]
            if kind == "v":
                relative.append(Relative(m.name, start, end, relative_velocity(m.dfi, d)))
            else:
                n, tg = acceleration_components(m.dfi, m.ddfi, d)
                relative.append(Relative(m.name, start, end, n + tg, n, tg))
    return Polygon(kind, float(t), POLYGONS[kind][0], tuple(absolute), tuple(relative))


# ---- instantaneous centres ----------------------------------------------------------------
@dataclass(frozen=True)
class Centre:
    """The instantaneous centre I_ij of bodies ``bodies`` = (i, j), numbered from 1 (the
    ground) and named ``names``: ``point`` [m], NaN where it is at infinity (the two translate
    relative to each other), then ``direction`` (unit) points to it; both NaN and None where
    the two move together (``defined``); ``homogeneous`` is h_i − h_j
    (``points.velocity_field``)."""

    bodies: tuple[int, int]
    names: tuple[str, str]
    point: np.ndarray
    direction: np.ndarray | None
    homogeneous: np.ndarray

    @property
    def label(self) -> str:
        """I12, I23, …; I1,12 when a number has two digits."""
        i, j = self.bodies
        return f"I{i}{j}" if max(i, j) < 10 else f"I{i},{j}"

    @property
    def finite(self) -> bool:
        return bool(np.all(np.isfinite(self.point)))

    @property
    def defined(self) -> bool:
        """False where the two bodies move together (the same ω and velocities): every point
        of the plane is then a centre of theirs."""
        return self.finite or self.direction is not None


@dataclass(frozen=True)
class KennedyLine:
    """The line through I_ij, I_jk, I_ik of three bodies ``bodies`` = (i, j, k) (Kennedy's
    theorem); ``residual`` [m] is how far they are from one line (``points.collinearity``,
    or ``points.off_line`` when one is at infinity); None when two are at infinity (the
    three bodies translate relative to each other: the line at infinity)."""

    bodies: tuple[int, int, int]
    centres: tuple[Centre, Centre, Centre]
    residual: float | None


@dataclass(frozen=True)
class Centres:
    """Every instantaneous centre at time ``t`` [s]: ``bodies`` the names of bodies 1 … n
    (1: the ground, named after its first solid), ``centres`` the n (n − 1) / 2 centres
    I_ij, i < j, ``lines`` the Kennedy line of every three bodies."""

    t: float
    bodies: tuple[str, ...]
    centres: tuple[Centre, ...]
    lines: tuple[KennedyLine, ...]

    def centre(self, i: int, j: int) -> Centre:
        """I_ij (= I_ji)."""
        key = (min(i, j), max(i, j))
        return next(c for c in self.centres if c.bodies == key)


def kennedy_residual(a: Centre, b: Centre, c: Centre) -> float | None:
    """How far three centres are from one line [m]: the triangle's height over its longest
    side, or the distance of one finite centre from the line through the other along the
    direction of the one at infinity; None with two at infinity. Where two of the bodies
    move together (a centre not ``defined``), the other two centres are one point: their
    distance (0 when both are at infinity)."""
    undefined = [x for x in (a, b, c) if not x.defined]
    if undefined:
        others = [x for x in (a, b, c) if x.defined]
        if len(others) == 2 and all(x.finite for x in others):
            return float(np.hypot(*(others[0].point - others[1].point)))
        return 0.0
    finite = [x for x in (a, b, c) if x.finite]
    if len(finite) == 3:
        return collinearity(a.point, b.point, c.point)
    if len(finite) == 2:
        (far,) = [x for x in (a, b, c) if not x.finite]
        return off_line(finite[0].point, finite[1].point, far.direction)
    return None


def all_centres(model, t: float) -> Centres:
    """The n (n − 1) / 2 instantaneous centres of the mechanism's n bodies at time t [s] and
    the Kennedy lines of every three bodies (``kennedy``)."""
    mech, _, moving = motions(model, t)
    held = sorted(mech.held)
    ground = [] if not held else [(mech.solids[held[0]].name, np.zeros(3))]
    bodies = ground + [(m.name, velocity_field(m.r, m.v, m.dfi)) for m in moving
                       if m.index not in mech.held]
    return kennedy(bodies, t, mech.scale())


def kennedy(bodies, t: float, length: float) -> Centres:
    """The centres and Kennedy lines of ``bodies``, [(name, h)] with h their
    ``points.velocity_field``s (the ground first): the centre of each two
    (``points.relative_centre``; none for two moving together to roundoff:
    ``points.relative_field``), the line of each three."""
    fastest = max(motion_size(h, length) for _, h in bodies)
    found = []
    for (i, (ni, hi)), (j, (nj, hj)) in combinations(enumerate(bodies, start=1), 2):
        h = relative_field(hi, hj, fastest, length)
        point = relative_centre(h, np.zeros(3), length)
        direction = None
        if not np.all(np.isfinite(point)):
            size = float(np.hypot(h[0], h[1]))
            direction = h[:2] / size if size > 0 else None
        found.append(Centre((i, j), (ni, nj), point, direction, h))
    index = {c.bodies: c for c in found}
    lines = []
    for i, j, k in combinations(range(1, len(bodies) + 1), 3):
        three = (index[i, j], index[j, k], index[i, k])
        lines.append(KennedyLine((i, j, k), three, kennedy_residual(*three)))
    return Centres(float(t), tuple(n for n, _ in bodies), tuple(found), tuple(lines))


# ---- centrodes ----------------------------------------------------------------------------
@dataclass(frozen=True)
class Centrodes:
    """The centrodes of ``solid`` over the run ``times`` (n,) [s]: ``fixed`` (n, 2) the
    instantaneous centre in the ground's frame (NaN where the solid translates), ``moving``
    (n, 2) the same points in the solid's own frame, ``moving_at`` (n, 2) those placed where
    the solid is at ``t``; at ``t``: the ``pole`` I, the acceleration ``pole_acceleration``
    of the solid's point at I, and the inflection circle (``inflection_centre``,
    ``inflection_radius``) [m]."""

    solid: str
    times: np.ndarray
    fixed: np.ndarray
    moving: np.ndarray
    moving_at: np.ndarray
    t: float
    pole: np.ndarray
    pole_acceleration: np.ndarray
    inflection_centre: np.ndarray
    inflection_radius: float


def centrodes(model, solid: str, t: float) -> Centrodes:
    """The fixed and moving centrodes of ``solid`` over the model's kinematic run (its t_end
    and steps) and its inflection circle at time t [s] (``points.inflection_circle``).

    Raises
    ------
    PictureError
        ``solid`` is not a moving solid of the model, or it translates at t (no pole).
    """
    from ..analyses import run
    model = _model(model)
    mech = model.mechanism()
    names = [s.name for i, s in enumerate(mech.solids) if i not in mech.held]
    if solid not in names:
        raise PictureError(f"--centrodes names a moving solid of '{mech.name}' "
                           f"({', '.join(names)}), not {solid!r}")
    columns = [f"{solid}.{v}" for v in ("x", "y", "fi", "Dx", "Dy", "Dfi")]
    res = run(model, analysis="kinematic", outputs=columns, angles="rad")
    get = lambda v: np.asarray(res[f"{solid}.{v}"], dtype=float)  # noqa: E731
    r, v = np.column_stack([get("x"), get("y")]), np.column_stack([get("Dx"), get("Dy")])
    fixed = instantaneous_centre(r, v, get("Dfi"), mech.scale())
    moving = in_frame(r, get("fi"), fixed)
    _, _, at = motions(model, t, accelerations=True)
    (m,) = [x for x in at if x.name == solid]
    pole = instantaneous_centre(m.r[None], m.v[None], [m.dfi], mech.scale())[0]
    if not np.all(np.isfinite(pole)):
        raise PictureError(f"'{solid}' translates at t = {t:g} s (Dfi = {m.dfi:g} rad/s): it "
                           f"has no pole and no inflection circle there; choose another --t")
    _, _, a_pole = m.point(in_frame(m.r[None], [m.fi], pole[None])[0])
    centre, radius = inflection_circle(pole, a_pole, m.dfi)
    moving_at = m.r + rotate(m.fi, moving.T)
    return Centrodes(solid, np.asarray(res.t, dtype=float), fixed, moving, moving_at, float(t),
                     pole, a_pole, centre, radius)

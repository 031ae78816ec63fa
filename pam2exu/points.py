"""What a teacher reads off a moving mechanism besides the solids' x, y, fi: the motion of
any declared point, each solid's instantaneous centre of rotation, and the transmission
angle of a coupler (issue 14).

These columns are *opt-in* (``OPT_IN``): ``--outputs`` / ``outputs`` patterns must ask for
them (docs/model-format.md, "Output variables"), so default tables do not change.

- ``<solid>.<point>.<variable>``: x, y [m], Dx, Dy [m/s], v = |(Dx, Dy)|, DDx, DDy [m/s²],
  a = |(DDx, DDy)| of the point declared in the solid's ``points`` (``point_motion``:
  exact, from the solid's own x … DDfi of the same pass, no differencing).
- ``<solid>.ICx``, ``<solid>.ICy`` [m]: the instantaneous centre of every solid not held
  by a ``fixed`` link (``instantaneous_centre``); NaN where it translates (Dfi = 0) or is
  at rest to round-off (``motion_sizes`` ≤ ``STILL`` · the fastest solid's).
- ``<coupler>.transmission_angle`` [rad]: of a solid joined by two revolutes to a driven
  input and to a rocker or a slider (``couplers``, ``transmission_angle``).

And for the graphical methods (``pictures/graphical.py``): the relative centre of two solids
from their velocity fields (``velocity_field``, ``relative_centre``), how far three points
are from a line (``collinearity``, ``off_line``: Kennedy's theorem), the inflection circle
(``inflection_circle``) and global points in a solid's frame (``in_frame``: the moving
centrode).

The functions are pure and vectorised over time steps (arrays of shape (n,) or (n, 2)),
so a drawing can call them on one configuration as well.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .complex_step import absolute, as_array, atan2, hypot, number_type
from .elements.base import ACCELERATION, POSITION, VELOCITY, Var
from .kinematics import State, perp, pose, rotate

#: the outputs of every declared point: columns ``<solid>.<point>.<variable>``
POINT_OUTPUTS = (
    Var("x", "m", POSITION, "x of the point, global frame: x_P = x + R(fi) p"),
    Var("y", "m", POSITION, "y of the point, global frame"),
    Var("Dx", "m/s", VELOCITY, "dx_P/dt: v_P = v + Dfi Ω R(fi) p"),
    Var("Dy", "m/s", VELOCITY, "dy_P/dt"),
    Var("v", "m/s", VELOCITY, "speed of the point, |v_P| = √(Dx² + Dy²)"),
    Var("DDx", "m/s²", ACCELERATION, "d²x_P/dt²: a_P = a + DDfi Ω R(fi) p − Dfi² R(fi) p"),
    Var("DDy", "m/s²", ACCELERATION, "d²y_P/dt²"),
    Var("a", "m/s²", ACCELERATION, "magnitude of the point's acceleration, |a_P|"),
)
#: the instantaneous centre of a moving solid: columns ``<solid>.ICx``, ``<solid>.ICy``
CENTRE_OUTPUTS = (
    Var("ICx", "m", VELOCITY, "x of the instantaneous centre of rotation, x − Dy/Dfi "
                              "(NaN where the solid translates, Dfi = 0)"),
    Var("ICy", "m", VELOCITY, "y of the instantaneous centre of rotation, y + Dx/Dfi"),
)
#: the transmission angle of a coupler: column ``<coupler>.transmission_angle``
COUPLER_OUTPUTS = (
    Var("transmission_angle", "rad", POSITION,
        "acute angle between the coupler line (input pin → output pin) and the normal to "
        "the output pin's path: the rocker line for a rocker, the guide's normal for a "
        "slider; π/2 is ideal (the coupler pushes along the pin's path), 0 a toggle "
        "position"),
)
#: the point columns of its position, velocity and acceleration: (x, y, magnitude)
_POINT_PARTS = (("x", "y", "distance"), ("Dx", "Dy", "v"), ("DDx", "DDy", "a"))
#: the variables a pattern must name to select them (besides every point column)
OPT_IN = frozenset(v.name for v in CENTRE_OUTPUTS + COUPLER_OUTPUTS)
#: an instantaneous centre farther than this many mechanism lengths is at infinity
#: (the solid translates): |v| / |Dfi| > FAR · L gives NaN
FAR = 1e9
#: a relative motion smaller than this fraction of the mechanism's fastest motion is the
#: roundoff of two solids moving together (``relative_field``)
STILL = 1e-12


def is_opt_in(column: str) -> bool:
    """A column the default outputs leave out: a point's (two dots) or an ``OPT_IN`` variable.

    Examples
    --------
    >>> is_opt_in("coupler.P.x"), is_opt_in("crank.ICx"), is_opt_in("crank.x")
    (True, True, False)
    """
    owner, _, variable = column.rpartition(".")
    return "." in owner or variable in OPT_IN


def point_motion(r, v, a, fi, dfi, ddfi, p):
    """(x_P, v_P, a_P) of the local point p: x + R p, v + Dfi Ω R p, a + DDfi Ω R p − Dfi² R p.

    Parameters
    ----------
    r, v, a : array_like (n, 2)
        The solid's origin, its velocity and acceleration (None for v, a: not computed).
    fi, dfi, ddfi : array_like (n,)
        Its angle and angular rates (None when not computed).
    p : (float, float)
        The point in the solid's local frame [m].

    Returns
    -------
    tuple of numpy.ndarray (n, 2) or None
        Position, velocity and acceleration of the point (None where the input was None).

    Examples
    --------
    >>> x, v, a = point_motion([[1.0, 0.0]], [[0.0, 0.0]], [[0.0, 0.0]], [np.pi / 2],
    ...                        [2.0], [0.0], (0.5, 0.0))
    >>> [(np.round(u, 12) + 0.0).tolist() for u in (x, v, a)]
    [[[1.0, 0.5]], [[-1.0, 0.0]], [[0.0, -2.0]]]
    """
    Rp = rotate(as_array(fi), as_array(p))
    x = as_array(r) + Rp
    vel = acc = None
    if v is not None:
        dfi = as_array(dfi)[:, None]
        vel = as_array(v) + dfi * perp(Rp)
        if a is not None:
            ddfi = as_array(ddfi)[:, None]
            acc = as_array(a) + ddfi * perp(Rp) - dfi * dfi * Rp
    return x, vel, acc


def instantaneous_centre(r, v, dfi, length: float = 1.0, fastest=None) -> np.ndarray:
    """I = r + Ω v / Dfi: the point of the solid's plane at rest, v_I = v + Dfi Ω (I − r) = 0.

    Ω v = (−vy, vx), so I = (x − Dy/Dfi, y + Dx/Dfi). Where the solid translates (Dfi = 0,
    or I farther than ``FAR`` · ``length`` from r: |v| > FAR · length · |Dfi|) there is no
    centre: NaN. With ``fastest``, also where the solid is at rest but for round-off: its
    ``motion_sizes`` at most ``STILL`` · fastest (its centre would be anywhere).

    Parameters
    ----------
    r, v : array_like (n, 2)
        Any point of the solid (its frame's origin) and that point's velocity.
    dfi : array_like (n,)
        The solid's angular velocity [rad/s].
    length : float
        The mechanism's length scale [m] (``Mechanism.scale()``), for "at infinity".
    fastest : array_like (n,), optional
        The largest ``motion_sizes`` of the mechanism's solids at each row [m/s].

    Returns
    -------
    numpy.ndarray (n, 2)
        The instantaneous centre [m], NaN rows where it is undefined.

    Examples
    --------
    >>> instantaneous_centre([[1.0, 0.0], [0.0, 0.0]], [[0.0, 2.0], [1.0, 0.0]], [2.0, 0.0])
    array([[ 0.,  0.],
           [nan, nan]])
    """
    r, v, dfi = as_array(r), as_array(v), as_array(dfi)
    speed = hypot(v[:, 0], v[:, 1])
    # (decided on the real parts: complex in the complex step)
    defined = (np.real(dfi) != 0.0) & (np.real(speed) <= FAR * length * np.abs(np.real(dfi)))
    if fastest is not None:
        defined &= motion_sizes(r, v, dfi, length) > STILL * np.asarray(fastest)
    out = np.full(r.shape, np.nan, dtype=number_type(r, v, dfi))
    out[defined] = r[defined] + perp(v[defined]) / dfi[defined, None]
    return out


def velocity_field(r, v, dfi) -> np.ndarray:
    """h = (Ω u, ω), u = v − ω Ω r: a solid's velocity field v(P) = u + ω Ω P, homogeneous.

    The relative centre of two solids is h_i − h_j in homogeneous coordinates
    (``relative_centre``), so h_ij + h_jk = h_ik: the three centres of any three solids are
    collinear (Kennedy's theorem).

    Parameters
    ----------
    r, v : array_like (2,) or (n, 2)
        Any point of the solid (its frame's origin) [m] and that point's velocity [m/s].
    dfi : float or array_like (n,)
        The solid's angular velocity [rad/s]; rows give a field (n, 3) per row.

    Examples
    --------
    >>> velocity_field([1.0, 0.0], [0.0, 2.0], 2.0) + 0.0  # turning about the origin
    array([0., 0., 2.])
    """
    r, v, dfi = (np.asarray(a, dtype=float) for a in (r, v, dfi))
    u = v - dfi[..., None] * perp(r)
    return np.stack([-u[..., 1], u[..., 0], dfi], axis=-1)


def motion_size(h, length: float = 1.0):
    """|Ω u| + |ω| L [m/s] of a ``velocity_field`` h = (Ω u, ω), L the length scale [m]: a
    float, or one per row of fields (n, 3).

    Examples
    --------
    >>> motion_size(velocity_field([[1.0, 0.0]], [[0.0, 2.0]], [2.0]), length=0.5)
    array([1.])
    """
    h = np.asarray(h, dtype=float)
    size = np.hypot(h[..., 0], h[..., 1]) + np.abs(h[..., 2]) * length
    return float(size) if size.ndim == 0 else size


def motion_sizes(r, v, dfi, length: float = 1.0) -> np.ndarray:
    """``motion_size`` of a solid's ``velocity_field`` at every row (r, v (n, 2), dfi (n,)),
    from their real parts (complex in the complex step)."""
    return motion_size(velocity_field(*(np.real(a) for a in (r, v, dfi))), length)


def relative_field(h_i, h_j, fastest: float, length: float = 1.0) -> np.ndarray:
    """h_i − h_j, exactly 0 where ``motion_size`` ≤ ``STILL`` · fastest (moving together).

    ``fastest`` [m/s] is the largest ``motion_size`` of the mechanism's solids: two solids at
    rest in a mechanism that moves differ by roundoff (1e-17 m/s), and that roundoff must not
    give them a centre (its point would be anywhere).

    Examples
    --------
    >>> relative_field([2e-17, 0.0, 4e-17], [0.0, 0.0, 0.0], fastest=0.2) + 0.0
    array([0., 0., 0.])
    """
    h = np.asarray(h_i, dtype=float) - np.asarray(h_j, dtype=float)
    if motion_size(h, length) <= STILL * fastest:
        return np.zeros(3)
    return h


def relative_centre(h_i, h_j, length: float = 1.0) -> np.ndarray:
    """I_ij = Ω (u_i − u_j) / (ω_i − ω_j): the point where v_i(P) = v_j(P) (NaN at infinity).

    h_i, h_j are ``velocity_field``s. Where ω_i = ω_j (the solids translate relative to
    each other) or I_ij lies farther than ``FAR`` · ``length`` from the origin, the centre is
    at infinity, in the direction ``h_i − h_j``'s first two components: NaN.

    Examples
    --------
    >>> relative_centre([0.0, 0.0, 2.0], [0.0, 0.0, 0.0])
    array([0., 0.])
    """
    h = np.asarray(h_i, dtype=float) - np.asarray(h_j, dtype=float)
    if h[2] == 0.0 or np.hypot(h[0], h[1]) > FAR * length * abs(h[2]):
        return np.full(2, np.nan)
    return h[:2] / h[2]


def collinearity(a, b, c) -> float:
    """|(b − a) × (c − a)| / (longest side): the height of the triangle abc, 0 when collinear [m].

    Examples
    --------
    >>> collinearity([0.0, 0.0], [2.0, 0.0], [1.0, 0.5])
    0.5
    """
    a, b, c = (np.asarray(x, dtype=float) for x in (a, b, c))
    u, w = b - a, c - a
    side = max(np.hypot(*u), np.hypot(*w), np.hypot(*(c - b)))
    return float(abs(u[0] * w[1] - u[1] * w[0]) / side) if side > 0 else 0.0


def off_line(a, b, direction) -> float:
    """|(b − a) × d| / |d|: how far b is from the line through a along d [m]."""
    u, d = np.asarray(b, dtype=float) - np.asarray(a, dtype=float), np.asarray(direction,
                                                                                 dtype=float)
    return float(abs(u[0] * d[1] - u[1] * d[0]) / np.hypot(*d))


def inflection_circle(pole, a_pole, dfi: float) -> tuple[np.ndarray, float]:
    """Centre I + a_I / (2 ω²), radius |a_I| / (2 ω²): the points P of zero normal
    acceleration, a_P · (P − I) = 0, with a_P = a_I + α Ω (P − I) − ω² (P − I).

    Parameters
    ----------
    pole : array_like (2,)
        The solid's instantaneous centre I [m].
    a_pole : array_like (2,)
        The acceleration of the solid's point at I [m/s²] (not the pole's own rate of
        travel along the centrodes: a_I = ω Ω u for the pole velocity u).
    dfi : float
        The solid's angular velocity ω ≠ 0 [rad/s].

    Returns
    -------
    (numpy.ndarray (2,), float)
        The circle's centre [m] and radius [m]; the diameter through I is the pole normal
        and |a_I| / ω² the inflection circle's diameter.

    Examples
    --------
    >>> c, r = inflection_circle([0.0, 0.0], [0.0, 4.0], 2.0)   # a wheel of radius 1 rolling
    >>> c.tolist(), r
    ([0.0, 0.5], 0.5)
    """
    a = np.asarray(a_pole, dtype=float)
    return np.asarray(pole, dtype=float) + a / (2.0 * dfi * dfi), float(np.hypot(*a)) / (
        2.0 * dfi * dfi)


def in_frame(r, fi, p) -> np.ndarray:
    """R(fi)ᵀ (p − r): global points p (n, 2) in the frame of a solid at r (n, 2), fi (n,).

    Examples
    --------
    >>> in_frame([[1.0, 0.0]], [np.pi / 2], [[1.0, 2.0]]).round(12) + 0.0
    array([[2., 0.]])
    """
    d = np.asarray(p, dtype=float) - np.asarray(r, dtype=float)
    return rotate(-np.asarray(fi, dtype=float), d.T)


def transmission_angle(a, b, normal) -> np.ndarray:
    """μ = atan2(|c × n|, |c · n|), c = b − a: the acute angle between the coupler line (pin a
    to pin b) and the normal n to the output pin's path at b, in [0, π/2].

    For a rocker pinned at O, n = b − O (μ: the acute angle between coupler and rocker); for
    a slider on a guide of direction d, n = Ω d. Equivalently μ = π/2 − α, α the pressure
    angle between the coupler (the force of a two-force member) and b's velocity.

    Examples
    --------
    >>> transmission_angle([[0.0, 0.0]], [[1.0, 1.0]], [[0.0, 1.0]]) * 4 / np.pi
    array([1.])
    """
    c = as_array(b) - as_array(a)
    n = as_array(normal)
    return atan2(absolute(c[:, 0] * n[:, 1] - c[:, 1] * n[:, 0]),
                 absolute(c[:, 0] * n[:, 0] + c[:, 1] * n[:, 1]))


@dataclass(frozen=True)
class Coupler:
    """A coupler of a four-bar or slider-crank: solid ``solid`` joined by revolutes to an
    input driven from a fixed solid (at its point ``input_pin``) and to an output (at
    ``output_pin``) that is a rocker pinned to a fixed solid at ``pivot`` or a slider on a
    fixed solid's line ``guide`` (PointRef / LineRef; the other one None)."""

    solid: int
    input_pin: object
    output_pin: object
    pivot: object = None
    guide: object = None

    def angle(self, st) -> np.ndarray:
        """Its transmission angle [rad] at the configurations of a ``kinematics.State``."""
        a, b = (st.point(p.solid, p.local).value for p in (self.input_pin, self.output_pin))
        if self.pivot is not None:
            normal = b - st.point(self.pivot.solid, self.pivot.local).value
        else:
            normal = perp(st.direction(self.guide.solid, self.guide.direction).value)
        return transmission_angle(a, b, normal)


def couplers(mech) -> list[Coupler]:
    """The couplers whose transmission angle is defined, in the order of the solids.

    A coupler is a solid not fixed whose only constraint elements are two revolutes, to two
    other solids that are not fixed. One of those, the input, is driven by an actuator
    from a fixed solid; the other, the output, is a rocker (a revolute to a fixed solid) or
    a slider (a prismatic on a fixed solid). Any other arrangement has no column.
    """
    ground = mech.held
    around: dict[int, list] = {}
    for el in mech.constraints:
        for s in set(el.solids):
            around.setdefault(s, []).append(el)

    def driven(x: int) -> bool:
        return any(el.drives and set(el.solids) - {x} <= ground and x in el.solids
                   and len(set(el.solids)) == 2 for el in around.get(x, ()))

    def held(x: int, joint):
        """The fixed solid's reference of an element between x and a fixed solid for which
        ``joint(element)`` holds (a pin: ``Element.pins``, a slider: ``Element.slides``)."""
        for el in around.get(x, ()):
            others = [r for r in el.refs if r.solid != x]
            if joint(el) and len(others) == 1 and others[0].solid in ground:
                return others[0]
        return None

    out = []
    for s in range(len(mech.solids)):
        joints = around.get(s, [])
        if s in ground or len(joints) != 2 or not all(el.pins for el in joints):
            continue
        ends = []
        for el in joints:
            own, other = (el.ref1, el.ref2) if el.ref1.solid == s else (el.ref2, el.ref1)
            ends.append((own, other.solid))
        if len({x for _, x in ends}) != 2 or any(x in ground or x == s for _, x in ends):
            continue
        inputs = [k for k, (_, x) in enumerate(ends) if driven(x)]
        if len(inputs) != 1:
            continue
        (pin_in, _), (pin_out, x_out) = ends[inputs[0]], ends[1 - inputs[0]]
        pivot = held(x_out, lambda el: el.pins)
        guide = held(x_out, lambda el: el.slides)
        if pivot is not None or guide is not None:
            out.append(Coupler(s, pin_in, pin_out, pivot, None if pivot is not None else guide))
    return out


def columns(mech, t, q, qd, qdd, wanted) -> tuple[dict[str, np.ndarray], list[str]]:
    """The opt-in columns among ``wanted``, from x … DDfi of every solid at the times t.

    Parameters
    ----------
    mech : Mechanism
    t : numpy.ndarray (n,)
    q, qd, qdd : numpy.ndarray (n, nq) or None
        The solids' coordinates and rates (``kinematics.pose``), None where not computed.
    wanted : set of str
        The column names asked for.

    Returns
    -------
    (dict, list of str)
        Column → values (n,), and one note per solid whose centre is NaN somewhere (why,
        where first), for the results' info.
    """
    out, notes = {}, []
    length = mech.scale()
    st = None
    angles = {v.name for v in COUPLER_OUTPUTS}
    asked = any(c.rpartition(".")[2] in angles for c in wanted)   # else no coupler is sought
    for c in couplers(mech) if asked else ():
        name = f"{mech.solids[c.solid].name}.transmission_angle"
        if name in wanted:
            if st is None:
                st = State(t, q, jacobians=False)
            out[name] = c.angle(st)
    fastest = None
    centres = {v.name for v in CENTRE_OUTPUTS}
    if qd is not None and any(c.rpartition(".")[2] in centres for c in wanted):
        fastest = np.max([motion_sizes(q[:, pose(i)][:, :2], qd[:, pose(i)][:, :2],
                                       qd[:, pose(i)][:, 2], length)
                          for i in range(len(mech.solids))], axis=0)
    for i, s in enumerate(mech.solids):
        x, dx, ddx = (None if a is None else a[:, pose(i)] for a in (q, qd, qdd))
        if f"{s.name}.ICx" in wanted or f"{s.name}.ICy" in wanted:
            centre = instantaneous_centre(x[:, :2], dx[:, :2], dx[:, 2], length, fastest)
            out[f"{s.name}.ICx"], out[f"{s.name}.ICy"] = centre[:, 0], centre[:, 1]
            nan = np.flatnonzero(np.isnan(centre[:, 0]))
            if nan.size:
                notes.append(f"{s.name}.ICx, {s.name}.ICy are NaN at {nan.size} of {len(t)} "
                             f"rows, first t = {t[nan[0]]:.6g} s: there the solid translates or "
                             f"is at rest (Dfi = 0, or its motion below {STILL:g} of the "
                             f"fastest solid's: round-off) and has no instantaneous centre")
        for p, local in s.points.items():
            prefix = f"{s.name}.{p}."
            names = {v.name for v in POINT_OUTPUTS if prefix + v.name in wanted}
            if not names:
                continue
            motion = point_motion(x[:, :2], None if dx is None else dx[:, :2],
                                  None if ddx is None else ddx[:, :2], x[:, 2],
                                  None if dx is None else dx[:, 2],
                                  None if ddx is None else ddx[:, 2], local)
            found = {}
            for (along_x, along_y, size), vector in zip(_POINT_PARTS, motion):
                if vector is not None:
                    found[along_x], found[along_y] = vector[:, 0], vector[:, 1]
                    found[size] = hypot(vector[:, 0], vector[:, 1])
            out.update({prefix + name: found[name] for name in names})
    return out, notes

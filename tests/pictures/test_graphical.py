"""The graphical methods of issue 26 item 2 as numbers (``pam2exu.pictures.graphical``): the
velocity and acceleration polygons against the run's point columns, every instantaneous
centre against Kennedy's theorem, the zero relative velocity and the four-bar's geometry,
the centrodes against the run's ``ICx``, ``ICy`` columns, and the inflection circle against
the Euler–Savary equation; then the drawing and the command, once.

The four-bar is examples/four_bar.toml (O2 = (0, 0), O4 = (0.4, 0), crank 0.1 m turning at
2π rad/s, coupler A B = 0.35 m, rocker 0.3 m); the slider-crank examples/slider_crank.toml.
"""
import math

import numpy as np
import pytest
from matplotlib.patches import Circle, FancyArrowPatch

import pam2exu
from pam2exu.cli import _parser, main
from pam2exu.pictures import Pen, draw
from pam2exu.pictures.constructions import draw_centres, draw_polygon
from pam2exu.pictures.graphical import all_centres, centrodes, kennedy, polygon
from pam2exu.results.plot import PictureError, figure

T = 0.1                  # [s]: crank at 36°
O2, O4 = np.array([0.0, 0.0]), np.array([0.4, 0.0])
SOLIDS = ("crank", "coupler", "rocker")
POINTS = {"crank": ("O", "A"), "coupler": ("A", "B", "P"), "rocker": ("O", "B")}


def _run(path, t, outputs):
    """The kinematic run from 0 to t with the model's step length (as ``draw`` at t)."""
    model = pam2exu.load(path)
    steps = math.ceil(model.analysis.steps * t / model.analysis.t_end - 1e-9)
    return pam2exu.run(model, analysis="kinematic", t_end=t, steps=steps, outputs=outputs,
                       angles="rad")


@pytest.fixture(scope="module")
def four_bar():
    """The four-bar's run to T: every solid's x … DDfi and every point's Dx … DDy."""
    from pathlib import Path
    path = Path(__file__).resolve().parents[2] / "examples" / "four_bar.toml"
    outputs = [f"{s}.{v}" for s in SOLIDS for v in ("x", "y", "fi", "Dx", "Dy", "Dfi", "DDx",
                                                      "DDy", "DDfi")]
    outputs += [f"{s}.{p}.{v}" for s in SOLIDS for p in POINTS[s]
                for v in ("x", "y", "Dx", "Dy", "DDx", "DDy")]
    return path, _run(path, T, outputs)


def _at(res, name):
    return np.array([float(res[name][-1])])[0]


def _xy(res, prefix, x="x", y="y"):
    return np.array([_at(res, f"{prefix}.{x}"), _at(res, f"{prefix}.{y}")])


@pytest.mark.parametrize("kind", ["v", "a"])
def test_polygon_vectors_are_the_point_velocities_and_accelerations(four_bar, kind):
    """Each absolute vector is the run's ``<solid>.<point>.Dx, Dy`` (``DDx, DDy``), 1e-12;
    each relative vector is the difference of its two points' images (the polygon closes,
    v_B = v_A + v_BA), its normal component −ω² (Q − P) and tangential α Ω (Q − P) add up
    to it; the crank's A against the closed form v_A = ω r (−sin θ, cos θ),
    a_A = −ω² r (cos θ, sin θ) (θ = ω T, r = 0.1 m, ω = 2π rad/s)."""
    path, res = four_bar
    poly = polygon(path, T, kind)
    x, y = ("Dx", "Dy") if kind == "v" else ("DDx", "DDy")
    names = [f"{s}.{p}" for s in SOLIDS for p in POINTS[s]]
    assert [v.name for v in poly.absolute] == names
    scale = max(np.hypot(*v.value) for v in poly.absolute)
    for v in poly.absolute:
        np.testing.assert_allclose(v.value, _xy(res, v.name, x, y), rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(v.at, _xy(res, v.name), rtol=0, atol=1e-12)
    w, theta = 2 * math.pi, 2 * math.pi * T
    closed = (w * 0.1 * np.array([-math.sin(theta), math.cos(theta)]) if kind == "v"
              else -w * w * 0.1 * np.array([math.cos(theta), math.sin(theta)]))
    np.testing.assert_allclose(poly.image("crank.A"), closed, rtol=0, atol=1e-9 * scale)
    # every two points of a solid, once: crank O-A, coupler A-B, A-P, B-P, rocker O-B
    assert [r.name for r in poly.relative] == ["crank.A/O", "coupler.B/A", "coupler.P/A",
                                               "coupler.P/B", "rocker.B/O"]
    for r in poly.relative:
        start, end = poly.image(f"{r.solid}.{r.start}"), poly.image(f"{r.solid}.{r.end}")
        np.testing.assert_allclose(start + r.value, end, rtol=0, atol=1e-12 * scale)
        d = _xy(res, f"{r.solid}.{r.end}") - _xy(res, f"{r.solid}.{r.start}")
        if kind == "v":
            assert r.normal is None and r.tangential is None
            assert abs(np.dot(r.value, d)) <= 1e-12 * scale      # v_QP ⟂ Q − P
            continue
        dfi, ddfi = _at(res, f"{r.solid}.Dfi"), _at(res, f"{r.solid}.DDfi")
        np.testing.assert_allclose(r.normal + r.tangential, r.value, rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(r.normal, -dfi ** 2 * d, rtol=1e-12, atol=1e-15)
        np.testing.assert_allclose(r.tangential, ddfi * np.array([-d[1], d[0]]), rtol=1e-12,
                                   atol=1e-15)
    # the loop closes: B reached through the crank and the coupler is the rocker's B
    np.testing.assert_allclose(poly.image("crank.A") + poly.relative[1].value,
                               poly.image("rocker.B"), rtol=0, atol=1e-9 * scale)


def test_polygon_refuses_another_kind(four_bar):
    with pytest.raises(PictureError, match="v .velocities. or a .accelerations., not 'F'"):
        polygon(four_bar[0], T, "F")


def _line_meet(p, d, q, e):
    """The point p + s d on the line q + u e."""
    s, _ = np.linalg.solve(np.column_stack([d, -e]), q - p)
    return p + s * d


def _velocity(res, solid, point):
    """v of the point of ``solid`` at ``point`` from the run's columns: v + Dfi Ω (P − r)."""
    if solid == "ground":
        return np.zeros(2)
    d = point - _xy(res, solid)
    return _xy(res, solid, "Dx", "Dy") + _at(res, f"{solid}.Dfi") * np.array([-d[1], d[0]])


def test_every_centre_of_the_four_bar(four_bar):
    """The 4 · 3 / 2 = 6 centres: each the point of zero relative velocity (from the run's
    columns, 1e-12 of the speeds); each three bodies' centres collinear (Kennedy, the
    triangle's height over its longest side ≤ 1e-9 of the length scale); and the
    geometry: I12 = O2, I14 = O4, I23 = A, I34 = B, I13 = O2A ∩ O4B, I24 = AB ∩ O2O4."""
    path, res = four_bar
    found = all_centres(path, T)
    assert found.bodies == ("ground", "crank", "coupler", "rocker")
    assert [c.label for c in found.centres] == ["I12", "I13", "I14", "I23", "I24", "I34"]
    length = pam2exu.load(path).mechanism().scale()
    speed = max(np.hypot(*_xy(res, f"{s}.{p}", "Dx", "Dy")) for s in SOLIDS for p in POINTS[s])
    for c in found.centres:
        assert c.finite
        vi, vj = (_velocity(res, n, c.point) for n in c.names)
        assert np.hypot(*(vi - vj)) <= 1e-12 * speed, (c.label, vi, vj)
    assert len(found.lines) == 4
    for line in found.lines:
        a, b, c = (x.point for x in line.centres)
        u, w = b - a, c - a
        height = abs(u[0] * w[1] - u[1] * w[0]) / max(np.hypot(*u), np.hypot(*w),
                                                       np.hypot(*(c - b)))
        assert height <= 1e-9 * length and line.residual <= 1e-9 * length
    A, B = _xy(res, "crank.A"), _xy(res, "rocker.B")
    expected = {"I12": O2, "I14": O4, "I23": A, "I34": B,
                "I13": _line_meet(O2, A - O2, O4, B - O4), "I24": _line_meet(A, B - A, O2, O4)}
    for c in found.centres:
        np.testing.assert_allclose(c.point, expected[c.label], rtol=0, atol=1e-9 * length)
    assert found.centre(3, 1) is found.centre(1, 3)


def test_centres_of_the_slider_crank_with_one_at_infinity(examples):
    """The slider translates: I14 is at infinity, perpendicular to the (horizontal) guide;
    the Kennedy lines through it are parallel to that direction (I13 above I34, I12 above
    I24 on a vertical line), and I24 is where the rod's line meets the vertical through the
    crank's pivot (the slider's velocity is the crank's point's there)."""
    path = examples / "slider_crank.toml"
    res = _run(path, 0.1, ["*.x", "*.y", "*.fi", "*.Dx", "*.Dy", "*.Dfi"])
    found = all_centres(path, 0.1)
    assert found.bodies == ("ground", "crank", "rod", "slider")
    i14 = found.centre(1, 4)
    assert not i14.finite and abs(i14.direction[0]) <= 1e-12
    assert abs(abs(i14.direction[1]) - 1.0) <= 1e-12
    length = pam2exu.load(path).mechanism().scale()
    for line in found.lines:
        assert line.residual is not None and line.residual <= 1e-9 * length
    for c in found.centres:
        if c.finite:
            vi, vj = (_velocity(res, n, c.point) for n in c.names)
            assert np.hypot(*(vi - vj)) <= 1e-12 * max(1.0, np.hypot(*vi))
    assert abs(found.centre(1, 3).point[0] - found.centre(3, 4).point[0]) <= 1e-9 * length


def test_every_centre_of_twelve_bodies(examples):
    """examples/all_elements.toml, 12 bodies (four sub-mechanisms on one ground, gears, a
    slot, a cylinder) at t = 0.05 s: 66 centres and 220 Kennedy lines, each within 1e-9 of
    the length scale of one line; each finite centre at zero relative velocity. The sun's
    ramp and the cylinder's Bézier law start at t = 0.2 s: until then the sun (5), the
    rocker (10), the barrel (11) and the piston (12) are at rest with the ground (1), so
    these five move together (10 centres undefined) and the slider (4) translates relative
    to each of them (5 centres at infinity, perpendicular to its horizontal rail). The
    planet (r = 0.04 m) rolls on the sun (r = 0.06 m): their centre is the pitch point,
    0.06 / 0.1 of the way from the sun's centre to the planet's."""
    path, t = examples / "all_elements.toml", 0.05
    res = _run(path, t, ["*.x", "*.y", "*.fi", "*.Dx", "*.Dy", "*.Dfi"])
    found = all_centres(path, t)
    assert len(found.bodies) == 12 and len(found.centres) == 66 and len(found.lines) == 220
    length = pam2exu.load(path).mechanism().scale()
    assert max(line.residual for line in found.lines) <= 1e-9 * length
    together = {1, 5, 10, 11, 12}
    assert {c.bodies for c in found.centres if not c.defined} == {
        (i, j) for i in together for j in together if i < j}
    at_infinity = [c for c in found.centres if c.defined and not c.finite]
    assert {c.bodies for c in at_infinity} == {tuple(sorted((4, k))) for k in together}
    for c in at_infinity:
        assert abs(c.direction[0]) <= 1e-12
    speed = max(np.hypot(_at(res, f"{n}.Dx"), _at(res, f"{n}.Dy")) for n in found.bodies[1:])
    for c in found.centres:
        if c.finite:
            vi, vj = (_velocity(res, n, c.point) for n in c.names)
            assert np.hypot(*(vi - vj)) <= 1e-12 * speed, c.label
    sun, planet = _xy(res, "sun"), _xy(res, "planet")
    gears = found.centre(found.bodies.index("sun") + 1, found.bodies.index("planet") + 1)
    np.testing.assert_allclose(gears.point, sun + 0.6 * (planet - sun), rtol=0, atol=1e-9)


def test_solids_at_rest_to_roundoff_move_together():
    """The fields of examples/all_elements.toml at t = 0.05 s that a run gave once (CI of
    stop 37, this test's reason): the sun at rest with the ground but for roundoff
    (2.2e-17, 0, 3.7e-17), the slider translating at 0.164 m/s. Taken at face value the
    sun's roundoff gives it a centre with the ground at (0.6, 0) and the line of the ground,
    slider and sun two centres at infinity (no residual); below 1e-12 of the fastest motion
    the sun and the ground move together (``points.relative_field``), as the sun and a
    solid held still exactly. A real relative motion of 1e-6 of the fastest is kept."""
    ground, slider = np.zeros(3), np.array([0.0, 0.16435874, 0.0])
    for sun, together in ((np.array([2.22044605e-17, 0.0, 3.70074342e-17]), True),
                          (np.zeros(3), True),
                          (np.array([0.0, 0.0, 1.64e-7]), False)):
        found = kennedy([("ground", ground), ("slider", slider), ("sun", sun)], 0.05, 1.0)
        assert found.centre(1, 3).defined is not together
        (line,) = found.lines
        assert line.residual == 0.0 if together else line.residual <= 1e-9
    np.testing.assert_array_equal(found.centre(1, 3).point, [0.0, 0.0])


def _circle_through(p, q, r):
    """Centre and radius of the circle through three points."""
    m = 2 * np.array([q - p, r - p])
    c = np.linalg.solve(m, [q @ q - p @ p, r @ r - p @ p])
    return c, float(np.hypot(*(c - p)))


@pytest.mark.parametrize("t", [T, 0.6])
def test_inflection_circle_of_the_coupler_by_euler_savary(examples, t):
    """The coupler's inflection circle from the geometry alone, by the Euler–Savary
    equation (Hartenberg & Denavit, *Kinematic Synthesis of Linkages*, 1964, §7; Uicker,
    Pennock & Shigley, *Theory of Machines and Mechanisms*, ch. "Euler–Savary equation"):
    for a point A of the moving plane with centre of curvature A0 on the ray from the pole
    I, distances signed along that ray, 1/IA − 1/IA0 = 1/IA_I, A_I the ray's point on the
    inflection circle. The four-bar's coupler points A and B move on circles about O2 and
    O4, so A_I and B_I follow, and the circle through I, A_I, B_I is the inflection circle
    (Bobillier's construction gives the same). pam2exu's circle comes from the
    accelerations instead: centre I + a_I / (2 ω²), radius |a_I| / (2 ω²)."""
    path = examples / "four_bar.toml"
    found = centrodes(path, "coupler", t)
    res = _run(path, t, ["crank.A.x", "crank.A.y", "rocker.B.x", "rocker.B.y"])
    A, B = _xy(res, "crank.A"), _xy(res, "rocker.B")
    pole = _line_meet(O2, A - O2, O4, B - O4)
    np.testing.assert_allclose(found.pole, pole, rtol=0, atol=1e-10)
    inflection = []
    for point, centre in ((A, O2), (B, O4)):
        u = (point - pole) / np.hypot(*(point - pole))
        r, r0 = np.hypot(*(point - pole)), (centre - pole) @ u
        inflection.append(pole + u / (1.0 / r - 1.0 / r0))
    c, radius = _circle_through(pole, *inflection)
    assert found.inflection_radius == pytest.approx(radius, rel=1e-12)       # 3e-16 measured
    np.testing.assert_allclose(found.inflection_centre, c, rtol=0, atol=1e-12 * radius)


def test_centrodes_are_the_centres_over_the_run(examples):
    """The fixed centrode is the run's ``coupler.ICx, ICy`` at every step (1e-12); the moving
    one, put back where the coupler is at each step, is the same points; placed where the
    coupler is at T, it touches the fixed one at the pole (the centrodes roll on each
    other there)."""
    path = examples / "four_bar.toml"
    found = centrodes(path, "coupler", T)
    res = pam2exu.run(path, analysis="kinematic",
                      outputs=["coupler.ICx", "coupler.ICy", "coupler.x", "coupler.y",
                               "coupler.fi"], angles="rad")
    np.testing.assert_allclose(found.times, res.t, rtol=0, atol=0)
    fixed = np.column_stack([res["coupler.ICx"], res["coupler.ICy"]])
    np.testing.assert_allclose(found.fixed, fixed, rtol=0, atol=1e-12)
    fi = np.asarray(res["coupler.fi"])
    back = np.column_stack([res["coupler.x"], res["coupler.y"]]) + np.column_stack(
        [np.cos(fi) * found.moving[:, 0] - np.sin(fi) * found.moving[:, 1],
         np.sin(fi) * found.moving[:, 0] + np.cos(fi) * found.moving[:, 1]])
    np.testing.assert_allclose(back, fixed, rtol=0, atol=1e-12)
    k = int(np.argmin(np.abs(found.times - T)))
    np.testing.assert_allclose(found.fixed[k], found.pole, rtol=0, atol=1e-9)
    np.testing.assert_allclose(found.moving_at[k], found.pole, rtol=0, atol=1e-9)
    with pytest.raises(PictureError, match="a moving solid of 'four-bar' .crank, coupler, "
                                           "rocker., not 'ground'"):
        centrodes(path, "ground", T)


def test_the_constructions_draw_the_numbers(examples):
    """The polygon's arrows run from the pole to the absolute vectors' tips and between the
    images of a link's points; each centre is marked where it is and each Kennedy line
    drawn (on bare axes: no layout, no rendering)."""
    path = examples / "four_bar.toml"
    poly = polygon(path, T, "a")
    fig = figure(6.0, 6.0)
    draw_polygon(fig.add_subplot(), poly, {})
    arrows = {a.get_gid(): a._posA_posB for a in fig.axes[0].patches
              if isinstance(a, FancyArrowPatch)}
    scale = max(np.hypot(*v.value) for v in poly.absolute)
    np.testing.assert_allclose(arrows["polygon:absolute:coupler.P"],
                               [(0.0, 0.0), poly.image("coupler.P")], atol=1e-12 * scale)
    start = poly.image("coupler.A")
    r = poly.relative[1]
    np.testing.assert_allclose(arrows["polygon:relative:coupler.B/A"],
                               [start, poly.image("coupler.B")], atol=1e-12 * scale)
    np.testing.assert_allclose(arrows["polygon:normal:coupler.B/A"],
                               [start, start + r.normal], atol=1e-12 * scale)
    assert "polygon:relative:crank.A/O" not in arrows      # from the pole: the absolute one
    found = all_centres(path, T)
    fig = figure(6.0, 6.0)
    ax = fig.add_subplot()
    pen = Pen(ax, 0.5)
    draw_centres(pen, found, {c.label for c in found.centres})
    marks = {a.get_gid(): np.array(a.center) for a in ax.get_children()
             if isinstance(a, Circle)}
    for c in found.centres:
        np.testing.assert_allclose(marks[f"centre:{c.label}"], c.point, atol=1e-12)
    assert {a.get_gid() for a in ax.get_children() if (a.get_gid() or "").startswith(
        "kennedy:")} == {"kennedy:1-2-3", "kennedy:1-2-4", "kennedy:1-3-4", "kennedy:2-3-4"}


def test_ic_alone_and_ic_all():
    """--ic alone still marks each solid's centre (True); --ic all every centre."""
    parse = _parser().parse_args
    assert parse(["draw", "m.toml", "--ic", "-o", "x.png"]).ic is True
    assert parse(["draw", "m.toml", "--ic", "all"]).ic == "all"
    assert parse(["draw", "m.toml"]).ic is False
    assert parse(["draw", "m.toml", "--polygon", "a", "--centrodes", "coupler"]).polygon == "a"
    with pytest.raises(PictureError, match="initial guess"):
        draw("examples/four_bar.toml", guess=True, polygon="v")
    with pytest.raises(PictureError, match="--ic alone"):
        draw("examples/four_bar.toml", ic="some")


@pytest.mark.long
def test_draw_with_polygon_centres_and_centrodes(examples, tmp_path):
    """One drawing with all three (two panels), and the command writing it."""
    path = examples / "four_bar.toml"
    fig = draw(path, t=T, polygon="v", ic="all", centrodes="coupler")
    mech_ax, poly_ax = fig.axes
    gids = {a.get_gid() for a in mech_ax.get_children()}
    assert {"centre:I13", "kennedy:1-2-3", "centrode:fixed", "centrode:moving",
            "inflection"} <= gids
    assert "polygon:absolute:coupler.P" in {a.get_gid() for a in poly_ax.patches}
    out = tmp_path / "fb.png"
    assert main(["draw", str(path), "--t", "0.1", "--polygon", "a", "-o", str(out)]) == 0
    assert out.read_bytes()[:4] == b"\x89PNG"

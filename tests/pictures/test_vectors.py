"""draw --vectors (issue 14, item 7): the arrows are the velocities, accelerations or reaction
forces at that instant, to scale, checked against closed forms (the four-bar's crank
f(t) = 2π t, r = 0.1 m; a driven crank with its centre of mass off the pivot) and against
central differences of the run's positions; and draw --guess."""
import math

import numpy as np
import pytest
from matplotlib.patches import Circle
from matplotlib.quiver import Quiver

import pam2exu
from pam2exu.cli import main
from pam2exu.kinematics import rotate
from pam2exu.pictures import draw
from pam2exu.pictures.mechanism import extent
from pam2exu.pictures.vectors import KEY, LONGEST, round_length

W = 2 * math.pi                 # the four-bar's crank speed [rad/s]


def _quiver(fig, kind):
    (q,) = [a for a in fig.axes[0].get_children() if isinstance(a, Quiver)
            and a.get_gid() == f"vectors:{kind}"]
    xy = np.column_stack([q.X, q.Y])
    uv = np.column_stack([np.asarray(q.U), np.asarray(q.V)])
    return xy, uv, 1.0 / q.scale            # drawing length per unit (scale_units "xy")


def _drawn(fig, kind):
    """Lengths [m] of the arrows as rendered: each path's farthest vertex from its tail."""
    ax = fig.axes[0]
    (q,) = [a for a in ax.get_children() if isinstance(a, Quiver)
            and a.get_gid() == f"vectors:{kind}"]
    fig.canvas.draw()
    px_per_m = ax.transData.transform([1.0, 0.0])[0] - ax.transData.transform([0.0, 0.0])[0]
    return np.array([np.max(np.hypot(*q.get_transform().transform(p.vertices).T))
                     for p in q.get_paths()]) / px_per_m


def _at(xy, uv, p):
    k = int(np.argmin(np.hypot(*(xy - p).T)))
    assert np.hypot(*(xy[k] - p)) < 1e-9
    return uv[k]


def _size(model, q):
    lo, hi = extent(model.mechanism(), q)
    return float(max(hi - lo))


def _positions(examples, t, h):
    """x, y, fi of every solid of the four-bar at t − h, t, t + h (a kinematic run)."""
    steps = round((t + h) / h)
    res = pam2exu.run(examples / "four_bar.toml", analysis="kinematic", t_end=t + h,
                      steps=steps, outputs=["*.x", "*.y", "*.fi"])
    return res, [-3, -2, -1]


def _point(res, rows, solid, local):
    fi = np.asarray(res[f"{solid}.fi"])[rows]
    return (np.column_stack([np.asarray(res[f"{solid}.x"])[rows],
                             np.asarray(res[f"{solid}.y"])[rows]])
            + rotate(fi, np.asarray(local, dtype=float)))


@pytest.mark.parametrize("kind", ["v", "a"])
def test_point_vectors_of_the_four_bar(examples, kind):
    """At t = 0.25 s the crank's A is at (0, 0.1): v_A = (−ω r, 0), a_A = (0, −ω² r); the
    coupler's P against central differences of P(t) (h = 1e-4 s); the longest arrow is
    LONGEST of the mechanism's size."""
    t, h = 0.25, 1e-4
    fig = draw(examples / "four_bar.toml", t=t, vectors=kind)
    xy, uv, scale = _quiver(fig, kind)
    expected = (-W * 0.1, 0.0) if kind == "v" else (0.0, -W ** 2 * 0.1)
    np.testing.assert_allclose(_at(xy, uv, (0.0, 0.1)), expected, atol=1e-9)

    res, rows = _positions(examples, t, h)
    P = _point(res, rows, "coupler", (0.2, 0.1))
    if kind == "v":
        fd = (P[2] - P[0]) / (2 * h)
    else:
        fd = (P[2] - 2 * P[1] + P[0]) / h ** 2
    arrow = _at(xy, uv, P[1])
    np.testing.assert_allclose(arrow, fd, rtol=0, atol=2e-6 * np.hypot(*fd))

    q = np.array([np.asarray(res[f"{s}.{k}"])[rows[1]] for s in ("ground", "crank", "coupler",
                                                                  "rocker")
                  for k in ("x", "y", "fi")])
    size = _size(pam2exu.load(examples / "four_bar.toml"), q)
    lengths = np.hypot(*uv.T) * scale
    assert lengths.max() == pytest.approx(LONGEST * size, rel=1e-12)
    np.testing.assert_allclose(_drawn(fig, kind), lengths, rtol=1e-9)   # as rendered
    # crank A; coupler A, B, P; rocker B (the pivots' zero arrows and the ground: none)
    assert len(xy) == 5
    # the legend's round length and what it stands for
    legend = [t.get_text() for t in fig.axes[0].texts if t.get_gid() == f"vectors:{kind}"]
    length = round_length(KEY * size)
    unit = "m/s" if kind == "v" else "m/s²"
    assert legend == [f"{kind}: {'velocity' if kind == 'v' else 'acceleration'} of each point; "
                      f"arrow of {length:g} m = {length / scale:.3g} {unit}"]


def test_round_length():
    assert round_length(0.037) == 0.02 and round_length(0.05) == 0.05
    assert round_length(9.9) == 5.0


def _crank(omega=3.0, mass=2.0, g=9.81):
    m = pam2exu.Model("crank", gravity=g)
    m.add_solid("ground", points={"O": [0, 0]})
    m.add("fixed", name="base", anc1="ground")
    m.add_solid("crank", mass=mass, inertia=0.01, cog=[0.05, 0.0],
                points={"O": [0, 0], "A": [0.1, 0]})
    m.add("revolute", name="O", anc1="ground.O", anc2="crank.O")
    m.add("angular_actuator", name="motor", anc1="ground", anc2="crank", law="polynomial",
          C=[0.0, omega, 0.0, 0.0])
    m.analysis.t_end, m.analysis.steps = 1.0, 100
    return m


def test_reaction_forces_of_a_driven_crank():
    """Crank at ω = 3 rad/s, m = 2 kg, G at 0.05 m: the pin O gives the crank
    F = m a_G − m g = m (−ω² r_G (cos ωt, sin ωt)) + (0, m g); the fixed link's arrow is the
    force it gives the ground, +F, which holds it against the pin's −F (the motor's reaction
    is a pure torque)."""
    omega, mass, g, t = 3.0, 2.0, 9.81, 0.4
    fig = draw(_crank(omega, mass, g), t=t, vectors="F")
    xy, uv, scale = _quiver(fig, "F")
    fi = omega * t
    F = mass * (-omega ** 2 * 0.05 * np.array([math.cos(fi), math.sin(fi)])) + [0.0, mass * g]
    assert len(xy) == 2                                   # the motor has no force arrow
    np.testing.assert_allclose(uv[1], F, rtol=1e-9)       # O, at the pivot
    np.testing.assert_allclose(uv[0], F, rtol=1e-9)       # base, at the ground's origin
    np.testing.assert_allclose(xy, np.zeros((2, 2)), atol=1e-12)
    res = pam2exu.run(_crank(omega, mass, g), analysis="kinetostatic", t_end=t, steps=40,
                      outputs=["O.Fx", "O.Fy"])
    np.testing.assert_allclose(uv[1], [res["O.Fx"][-1], res["O.Fy"][-1]], rtol=1e-12)


def test_prismatic_and_pin_forces_are_normal_to_their_guides(examples):
    """Slider-crank at t = 0.1 s: the guide's arrow is Fnormal along the normal of the
    slider's line (the guide is horizontal: (0, Fnormal)) at B; the pins' arrows are Fx, Fy."""
    t = 0.1
    fig = draw(examples / "slider_crank.toml", t=t, vectors="F")
    xy, uv, _ = _quiver(fig, "F")
    model = pam2exu.load(examples / "slider_crank.toml")
    a = model.analysis
    steps = max(1, math.ceil(a.steps * t / a.t_end - 1e-9))
    res = pam2exu.run(model, analysis="kinetostatic", t_end=t, steps=steps,
                      outputs=["guide.Fnormal", "A.Fx", "A.Fy", "slider.x", "slider.y",
                               "crank.fi"])
    assert np.any(np.all(np.abs(uv - [0.0, res["guide.Fnormal"][-1]]) < 1e-9, axis=1))
    A = 0.1 * np.array([math.cos(res["crank.fi"][-1]), math.sin(res["crank.fi"][-1])])
    np.testing.assert_allclose(_at(xy, uv, A), [res["A.Fx"][-1], res["A.Fy"][-1]],
                               rtol=1e-12)


def _short_coupler(examples):
    """The four-bar with a coupler of 0.01 m and a rocker of 0.1 m: it cannot close."""
    model = pam2exu.load(examples / "four_bar.toml")
    model.solids[2].points["B"] = [0.01, 0.0]
    model.solids[3].points["B"] = [0.1, 0.0]
    return model


def test_guess_draws_the_files_poses(examples, tmp_path):
    """A four-bar that does not assemble: draw fails, draw --guess draws each solid at its
    x, y, fi of the file (the joint circles at solid 2's points there) and marks the
    constraints not met (A, B and the motor: the crank's fi = 0.02 is not f(0) = 0; O4 holds,
    the rocker's guess being at the ground's O4)."""
    model = _short_coupler(examples)
    with pytest.raises(pam2exu.SolverError, match="cannot close"):
        draw(model)
    fig = draw(model, guess=True)
    circles = {a.get_gid(): a.center for a in fig.axes[0].patches
               if isinstance(a, Circle) and a.get_gid().startswith("revolute:")
               and a.get_facecolor()[:3] == (1.0, 1.0, 1.0)}
    solid = {s.name: s for s in model.solids}

    def at(name, local):
        s = solid[name]
        return np.array([s.x, s.y]) + rotate(np.array([s.fi]), np.asarray(local, float))[0]

    np.testing.assert_allclose(circles["revolute:A"], at("coupler", (0, 0)), atol=1e-15)
    np.testing.assert_allclose(circles["revolute:B"], at("rocker", (0.1, 0)), atol=1e-15)
    np.testing.assert_allclose(circles["revolute:O4"], at("rocker", (0, 0)), atol=1e-15)
    title = fig.axes[0].get_title()
    assert "initial guess" in title and "3 constraints not met" in title
    red = {t.get_text() for t in fig.axes[0].texts if t.get_color() == "#e6194b"}
    assert red == {"A", "B", "motor"}
    assert main(["draw", str(examples / "four_bar.toml"), "--guess",
                 "-o", str(tmp_path / "g.png")]) == 0
    assert main(["draw", str(examples / "four_bar.toml"), "--guess", "--t", "1",
                 "-o", str(tmp_path / "g.png")]) == 2


def test_cli_draw_vectors(examples, tmp_path, capsys):
    out = tmp_path / "v.png"
    assert main(["draw", str(examples / "four_bar.toml"), "--t", "0.25", "--vectors", "v",
                 "-o", str(out)]) == 0
    assert out.read_bytes()[:4] == b"\x89PNG"
    with pytest.raises(SystemExit):
        main(["draw", str(examples / "four_bar.toml"), "--vectors", "w"])
    assert "invalid choice: 'w'" in capsys.readouterr().err


def test_instantaneous_centres_of_the_four_bar(examples):
    """draw(ic=True) at t = 0.1 s: the coupler's centre is where the crank's line O2A meets
    the rocker's line O4B (closed form from the run's positions), the crank's and rocker's
    at their pivots O2 = (0, 0) and O4 = (0.4, 0)."""
    t = 0.1
    fig = draw(examples / "four_bar.toml", t=t, ic=True)
    marks = {}
    for a in fig.axes[0].get_children():
        if isinstance(a, Circle) and (a.get_gid() or "").startswith("centre:"):
            marks[a.get_gid()[7:]] = np.array(a.center)
    model = pam2exu.load(examples / "four_bar.toml")
    steps = math.ceil(model.analysis.steps * t / model.analysis.t_end - 1e-9)
    res = pam2exu.run(model, analysis="kinematic", t_end=t, steps=steps,
                      outputs=["crank.fi", "rocker.fi"])
    e1 = np.array([math.cos(res["crank.fi"][-1]), math.sin(res["crank.fi"][-1])])
    e2 = np.array([math.cos(res["rocker.fi"][-1]), math.sin(res["rocker.fi"][-1])])
    # s e1 = (0.4, 0) + u e2
    s, _ = np.linalg.solve(np.column_stack([e1, -e2]), [0.4, 0.0])
    np.testing.assert_allclose(marks["coupler"], s * e1, atol=1e-9)
    np.testing.assert_allclose(marks["crank"], (0.0, 0.0), atol=1e-12)
    np.testing.assert_allclose(marks["rocker"], (0.4, 0.0), atol=1e-12)
    assert {"I crank", "I coupler", "I rocker"} <= {x.get_text() for x in fig.axes[0].texts}

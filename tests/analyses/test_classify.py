"""``pam2exu classify`` (issue 26 item 1): Grashof classes and input ranges against their
formulas, dead points against closed forms (1e-9 in time), assembly modes, the six-bar's
transmission angles against a hand computation, and the command."""
import json

import numpy as np
import pytest

from pam2exu import RedundancyWarning, loads, run
from pam2exu.analyses.classify import classify
from pam2exu.analyses.job import prepare
from pam2exu.cli import main

GROUND = """
[[solid]]
name = "ground"
points = {{ {points} }}
{lines}
[[element]]
type = "fixed"
name = "base"
anc1 = "ground"
"""


def solid(name, x, y, fi, points, lines=""):
    pts = ", ".join(f"{k} = [{float(u)!r}, {float(v)!r}]" for k, (u, v) in points.items())
    return (f'\n[[solid]]\nname = "{name}"\nx = {float(x)!r}\ny = {float(y)!r}\nfi = {float(fi)!r}\n'
            f"points = {{ {pts} }}\n{lines}")


def element(kind, name, anc1, anc2, extra=""):
    return f'\n[[element]]\ntype = "{kind}"\nname = "{name}"\nanc1 = "{anc1}"\nanc2 = "{anc2}"\n{extra}'


def analysis(t_end, steps):
    return f'\n[analysis]\ntype = "kinematic"\nt_end = {t_end!r}\nsteps = {steps}\n'


def meet(a, p, l1, l2, side=1.0):
    """B with |B − a| = l1, |B − p| = l2, on the side sign((p − a) × (B − a)) = side."""
    a, p = np.asarray(a, float), np.asarray(p, float)
    d = np.linalg.norm(p - a)
    u = (p - a) / d
    along = (l1 * l1 - l2 * l2 + d * d) / (2 * d)
    h = np.sqrt(l1 * l1 - along * along)
    return a + along * u + side * h * np.array([-u[1], u[0]])


def angle(u):
    return float(np.arctan2(u[1], u[0]))


def four_bar(d, a, b, c, theta0=1.0, speed=0.5, t_end=0.2, steps=4, rocker_driven=False,
             psi0=None):
    """A four-bar: pivots O2 = (0, 0), O4 = (d, 0); crank a, coupler b, rocker c; the crank
    driven from theta0 (or the rocker from psi0), both at ``speed`` rad/s."""
    o4 = np.array([d, 0.0])
    if rocker_driven:
        B = o4 + c * np.array([np.cos(psi0), np.sin(psi0)])
        A = meet(B, [0.0, 0.0], b, a, -1.0)
    else:
        A = a * np.array([np.cos(theta0), np.sin(theta0)])
        B = meet(A, o4, b, c, 1.0)
    text = '[model]\nname = "four-bar"\n' + GROUND.format(points=f"O2 = [0.0, 0.0], O4 = [{d!r}, 0.0]", lines="")
    text += solid("crank", 0.0, 0.0, angle(A), {"O": (0, 0), "A": (a, 0)})
    text += solid("coupler", *A, angle(B - A), {"A": (0, 0), "B": (b, 0)})
    text += solid("rocker", d, 0.0, angle(B - o4), {"O": (0, 0), "B": (c, 0)})
    for name, p, q in (("O2", "ground.O2", "crank.O"), ("A", "crank.A", "coupler.A"),
                       ("B", "coupler.B", "rocker.B"), ("O4", "ground.O4", "rocker.O")):
        text += element("revolute", name, p, q)
    start = psi0 if rocker_driven else theta0
    text += element("angular_actuator", "motor", "ground",
                    "rocker" if rocker_driven else "crank",
                    f'law = "polynomial"\nC = [{float(start)!r}, {speed!r}, 0.0, 0.0]\n')
    return loads(text + analysis(t_end, steps))


def slider_crank(r, L, e, theta0=np.pi / 2, t_end=0.2, steps=4, slider_x0=None, speed=0.5):
    """A slider-crank: crank pivot O = (0, 0), the slider pin on the line y = e; the crank
    driven from theta0, or (``slider_x0``) the slider by a linear actuator from (−1, e)."""
    if slider_x0 is None:
        A = r * np.array([np.cos(theta0), np.sin(theta0)])
        B = np.array([A[0] + np.sqrt(L * L - (e - A[1]) ** 2), e])
    else:
        B = np.array([slider_x0, e])
        A = meet(B, [0.0, 0.0], L, r, -1.0)
    text = '[model]\nname = "slider-crank"\n' + GROUND.format(
        points=f"O = [0.0, 0.0], P = [-1.0, {e!r}]",
        lines=f"lines = {{ rail = {{ point = [0.0, {e!r}], angle = 0.0 }} }}")
    text += solid("crank", 0.0, 0.0, angle(A), {"O": (0, 0), "A": (r, 0)})
    text += solid("rod", *A, angle(B - A), {"A": (0, 0), "B": (L, 0)})
    text += solid("slider", *B, 0.0, {"B": (0, 0)},
                  "lines = { axis = { point = [0.0, 0.0], angle = 0.0 } }\n")
    for name, p, q in (("O", "ground.O", "crank.O"), ("A", "crank.A", "rod.A"),
                       ("B", "rod.B", "slider.B")):
        text += element("revolute", name, p, q)
    text += element("prismatic", "guide", "ground.rail", "slider.axis")
    if slider_x0 is None:
        text += element("angular_actuator", "motor", "ground", "crank",
                        f'law = "polynomial"\nC = [{theta0!r}, {speed!r}, 0.0, 0.0]\n')
    else:
        text += element("linear_actuator", "piston", "ground.P", "slider.B",
                        f'law = "polynomial"\nC = [{slider_x0 + 1.0!r}, {speed!r}, 0.0, 0.0]\n')
    return loads(text + analysis(t_end, steps))


def grashof_by_formula(d, a, b, c):
    s, *pq, l = sorted((d, a, b, c))
    if np.isclose(s + l, sum(pq), rtol=1e-12):
        return "change-point"
    if s + l > sum(pq):
        return "non-grashof"
    return {d: "double-crank", b: "double-rocker"}.get(s, "crank-rocker")


@pytest.mark.parametrize("lengths", [(0.4, 0.1, 0.35, 0.3), (0.1, 0.3, 0.35, 0.4),
                                     (0.4, 0.3, 0.1, 0.35), (0.4, 0.2, 0.4, 0.2),
                                     (0.4, 0.3, 0.3, 0.35)])
def test_four_bar_grashof_classes_and_input_range(lengths):
    d, a, b, c = lengths
    atlas = classify(four_bar(*lengths))
    (loop,) = atlas.loops
    assert loop.kind == "four-bar" and loop.input == "crank"
    assert loop.solids == ["ground", "crank", "coupler", "rocker"]
    assert loop.joints == ["O2", "A", "B", "O4"]
    assert loop.grashof.kind == grashof_by_formula(*lengths)
    s, *pq, l = sorted(lengths)
    assert loop.grashof.left == pytest.approx(s + l, abs=1e-12)
    assert loop.grashof.right == pytest.approx(sum(pq), abs=1e-12)
    # the crank reaches the dyad where |b − c| ≤ |A − O4| ≤ b + c
    theta = np.radians(np.linspace(-180, 180, 3601))
    reach = np.sqrt(a * a + d * d - 2 * a * d * np.cos(theta))
    closes = (reach >= abs(b - c) - 1e-12) & (reach <= b + c + 1e-12)
    inside = np.zeros_like(closes)
    for lo, hi in loop.input_range:
        deg = np.degrees(theta)
        inside |= ((deg >= lo - 1e-9) & (deg <= hi + 1e-9)) | \
                   ((deg + 360 >= lo - 1e-9) & (deg + 360 <= hi + 1e-9))
    assert np.array_equal(closes, inside)
    assert (atlas.gruebler, atlas.mobility, atlas.free, atlas.redundant) == (1, 1, 0, 0)
    assert atlas.assembly_modes == 2 and loop.modes == ["open", "crossed"]
    assert loop.selected == "open"


@pytest.mark.parametrize("offset", [0.0, 0.15, -0.15, 0.2, 0.25])
def test_slider_crank_grashof_with_offset(offset):
    r, L = 0.1, 0.3
    atlas = classify(slider_crank(r, L, offset))
    (loop,) = atlas.loops
    assert loop.kind == "slider-crank" and loop.input == "crank"
    expected = ("change-point" if np.isclose(r + abs(offset), L, rtol=1e-12) else
                "crank-rocker" if r + abs(offset) < L else "non-grashof")
    assert loop.grashof.kind == expected
    assert loop.grashof.left == pytest.approx(r + abs(offset), abs=1e-12)
    if expected == "non-grashof":              # r sin θ ≥ e − L: the crank rocks
        (lo, hi), = loop.input_range
        assert np.sin(np.radians(lo)) == pytest.approx((offset - L) / r, abs=1e-12)
        assert np.sin(np.radians(hi)) == pytest.approx((offset - L) / r, abs=1e-12)
    else:
        assert loop.input_range == [[-180.0, 180.0]]
    assert atlas.assembly_modes == 2 and loop.selected == "open"


def _folded_rocker(d, a, b, c):
    """ψ of the rocker-driven crank-rocker's dead point: the crank and coupler in line,
    |O2 B| = b − a with B = O4 + c (cos ψ, sin ψ)."""
    return np.arccos(((b - a) ** 2 - d * d - c * c) / (2 * d * c))


def test_dead_points_of_a_rocker_driven_crank_rocker():
    d, a, b, c = 0.4, 0.1, 0.35, 0.3
    atlas = classify(four_bar(d, a, b, c, rocker_driven=True, psi0=2.0, speed=1.0,
                              t_end=1.0, steps=10))
    psi = _folded_rocker(d, a, b, c)
    (point,) = atlas.dead_points
    assert point["kind"] == "dead point" and point["joint"] == "A" and point["loop"] == 1
    assert point["t"] == pytest.approx(psi - 2.0, abs=1e-9)
    loop = atlas.loops[0]
    assert loop.input == "rocker" and loop.grashof.kind == "crank-rocker"
    assert loop.transmission["min"] == pytest.approx(0.0, abs=1e-5)
    assert loop.transmission["t_min"] == point["t"]
    # the rocker's range: between its two dead points, measured from the line O4 → O2
    extended = np.arccos(((b + a) ** 2 - d * d - c * c) / (2 * d * c))
    now = np.degrees(2.0 - np.pi)          # the rocker's angle from the line O4 → O2
    (lo, hi), = [(lo, hi) for lo, hi in loop.input_range if lo <= now <= hi]
    assert sorted(np.radians([abs(lo), abs(hi)])) == pytest.approx(
        sorted([np.pi - psi, np.pi - extended]), abs=1e-12)


def test_dead_point_of_a_slider_driven_slider_crank():
    r, L, e = 0.1, 0.3, 0.05
    atlas = classify(slider_crank(r, L, e, slider_x0=0.3, speed=0.2, t_end=1.0, steps=10))
    (point,) = atlas.dead_points
    assert point["kind"] == "dead point" and point["joint"] == "A"
    assert point["t"] == pytest.approx((np.sqrt((L + r) ** 2 - e * e) - 0.3) / 0.2, abs=1e-9)
    loop = atlas.loops[0]
    assert loop.input == "slider" and loop.range_unit == "m"
    assert loop.input_range[-1][1] == pytest.approx(np.sqrt((L + r) ** 2 - e * e), abs=1e-12)


def six_bar(steps=20, c2=0.35):
    """A Watt II six-bar: the four-bar O2-A-B-O4, and on the rocker's point C a second dyad
    C-D-O6 (link 0.4, output c2). Returns the model, the hand-computed poses and the acute
    angle of two vectors."""
    a, b, c, o4, o6 = 0.1, 0.35, 0.3, np.array([0.4, 0.0]), np.array([0.9, 0.0])
    c_local, b2 = np.array([0.15, 0.1]), 0.4
    omega, t_end = 2 * np.pi, 1.0

    def pose(theta):
        A = a * np.array([np.cos(theta), np.sin(theta)])
        B = meet(A, o4, b, c, 1.0)
        psi = angle(B - o4)
        rot = np.array([[np.cos(psi), -np.sin(psi)], [np.sin(psi), np.cos(psi)]])
        C = o4 + rot @ c_local
        D = meet(C, o6, b2, c2, 1.0)
        return A, B, psi, C, D

    A, B, psi, C, D = pose(0.3)
    text = '[model]\nname = "six-bar"\n' + GROUND.format(
        points="O2 = [0.0, 0.0], O4 = [0.4, 0.0], O6 = [0.9, 0.0]", lines="")
    text += solid("crank", 0.0, 0.0, 0.3, {"O": (0, 0), "A": (a, 0)})
    text += solid("coupler", *A, angle(B - A), {"A": (0, 0), "B": (b, 0)})
    text += solid("rocker", *o4, psi, {"O": (0, 0), "B": (c, 0), "C": tuple(c_local)})
    text += solid("link", *C, angle(D - C), {"C": (0, 0), "D": (b2, 0)})
    text += solid("output", *o6, angle(D - o6), {"O": (0, 0), "D": (float(c2), 0)})
    for name, p, q in (("O2", "ground.O2", "crank.O"), ("A", "crank.A", "coupler.A"),
                       ("B", "coupler.B", "rocker.B"), ("O4", "ground.O4", "rocker.O"),
                       ("C", "rocker.C", "link.C"), ("D", "link.D", "output.D"),
                       ("O6", "ground.O6", "output.O")):
        text += element("revolute", name, p, q)
    text += element("angular_actuator", "motor", "ground", "crank",
                    f'law = "polynomial"\nC = [0.3, {omega!r}, 0.0, 0.0]\n')
    model = loads(text + analysis(t_end, steps))

    def acute(u, w):
        return np.degrees(np.arctan2(abs(u[0] * w[1] - u[1] * w[0]), abs(u @ w)))

    return model, pose, acute


def test_six_bar_transmission_angles_against_a_hand_computation():
    model, pose, acute = six_bar()
    atlas = classify(model)
    assert [lp.kind for lp in atlas.loops] == ["four-bar", "four-bar"]
    assert (atlas.gruebler, atlas.mobility, atlas.assembly_modes) == (1, 1, 4)
    first, second = atlas.loops
    assert first.solids == ["ground", "crank", "coupler", "rocker"]
    assert second.solids == ["ground", "rocker", "link", "output"]
    assert second.joints == ["O4", "C", "D", "O6"] and second.input == "rocker"
    assert (second.dyad.coupler, second.dyad.output) == (4, 5)
    t = prepare(model, analysis="kinematic").times         # the run's grid (sub-steps)
    mu1, mu2 = [], []
    for theta in 0.3 + 2 * np.pi * t:
        A, B, psi, C, D = pose(theta)
        mu1.append(acute(B - A, B - np.array([0.4, 0.0])))
        mu2.append(acute(D - C, D - np.array([0.9, 0.0])))
    for loop, mu in ((first, np.array(mu1)), (second, np.array(mu2))):
        assert loop.transmission["min"] == pytest.approx(mu.min(), abs=1e-7)
        assert loop.transmission["max"] == pytest.approx(mu.max(), abs=1e-7)
        assert loop.transmission["t_min"] == t[np.argmin(mu)]
        assert loop.transmission["t_max"] == t[np.argmax(mu)]
    assert atlas.dead_points == []


def test_command_prints_the_atlas_and_its_json(examples, capsys):
    assert main(["classify", str(examples / "four_bar.toml"), "--json", "--steps", "40"]) == 0
    found = json.loads(capsys.readouterr().out)
    assert {"dof", "loops", "assembly_modes", "dead_points"} <= set(found)
    assert found["dof"] == 1 and found["mobility"]["gruebler"] == 1
    (loop,) = found["loops"]
    assert {"solids", "joints", "kind", "grashof", "transmission_angle"} <= set(loop)
    assert loop["grashof"]["class"] == "crank-rocker"
    assert set(loop["transmission_angle"]) == {"min", "max", "t_min", "t_max"}
    # the acute angle of the coupler's transmission_angle column, in degrees
    res = run(examples / "four_bar.toml", steps=40, outputs=["coupler.transmission_angle"])
    mu = np.degrees(res["coupler.transmission_angle"])
    assert loop["transmission_angle"]["min"] == pytest.approx(mu.min(), abs=1e-9)
    assert loop["transmission_angle"]["max"] == pytest.approx(mu.max(), abs=1e-9)
    assert main(["classify", str(examples / "four_bar.toml"), "--steps", "4"]) == 0
    assert "Grashof: crank-rocker" in capsys.readouterr().out


def test_change_point_of_a_change_point_four_bar():
    # d = b, a = c: every link in line when the crank reaches θ = π, at t = (π − 1)/2
    atlas = classify(four_bar(0.4, 0.2, 0.4, 0.2, theta0=1.0, speed=2.0, t_end=1.5, steps=30))
    (point,) = atlas.dead_points
    assert point["kind"] == "change point" and point["loop"] == 1
    assert point["t"] == pytest.approx((np.pi - 1) / 2, abs=1e-9)
    assert atlas.loops[0].grashof.kind == "change-point"


def test_mobility_of_an_over_constrained_parallelogram_names_the_elements():
    from pathlib import Path
    with pytest.warns(RedundancyWarning):               # the run's own warning
        atlas = classify(Path(__file__).parents[1] / "data" / "parallelogram5.toml", steps=4)
    assert (atlas.gruebler, atlas.mobility, atlas.redundant, atlas.free) == (0, 1, 1, 0)
    assert set(atlas.redundant_elements) == {"O1", "O2", "O3", "A1", "A2", "A3"}
    assert "'A3'" in atlas.meaning and "repeat" in atlas.meaning
    assert [lp.kind for lp in atlas.loops] == ["four-bar", "four-bar"]


def test_a_free_degree_of_freedom_takes_the_first_free_solid_as_input(examples):
    atlas = classify(examples / "equilibrium" / "spring_four_bar.toml")
    assert (atlas.actuated, atlas.free) == (0, 1)
    assert atlas.assembly_modes == 2 and atlas.loops[0].input == "crank"
    assert "not driven" in atlas.note and atlas.dead_points == []


def test_a_model_error_names_the_file_and_the_element(examples, tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text((examples / "four_bar.toml").read_text().replace(
        'anc2 = "coupler.A"', 'anc2 = "coupler.Q"'))
    assert main(["classify", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "bad.toml" in err and "'A'" in err and "coupler.Q" in err


def test_dead_point_of_a_six_bars_second_loop():
    # a shorter output: C leaves the reach of the second dyad, |C − O6| = 0.4 + c2
    c2 = 0.265
    model, pose, _ = six_bar(c2=c2)
    atlas = classify(model)
    (point,) = atlas.dead_points
    assert point["kind"] == "dead point" and point["loop"] == 2 and point["joint"] == "D"
    from scipy.optimize import brentq
    def gap(t):                        # C only (D does not exist past the dead point)
        with np.errstate(invalid="ignore"):
            return np.linalg.norm(pose(0.3 + 2 * np.pi * t)[3] - [0.9, 0.0]) - 0.4 - c2
    t = prepare(model, analysis="kinematic").times
    k = int(np.argmax([gap(x) > 0 for x in t]))
    assert point["t"] == pytest.approx(brentq(gap, t[k - 1], t[k], xtol=1e-15), abs=1e-9)
    assert atlas.loops[1].transmission["min"] == pytest.approx(0.0, abs=1e-5)


def test_a_dead_point_far_past_the_last_solved_step_is_still_found():
    # 2 steps: the run stops at t = 0.25 s, 0.22 s before the dead point; Newton on the
    # extended system from there does not converge, from a bisected step it does
    d, a, b, c = 0.4, 0.1, 0.35, 0.3
    atlas = classify(four_bar(d, a, b, c, rocker_driven=True, psi0=2.0, speed=1.0,
                              t_end=1.0, steps=2))
    psi = _folded_rocker(d, a, b, c)
    (point,) = atlas.dead_points
    assert point["t"] == pytest.approx(psi - 2.0, abs=1e-9) and atlas.note == ""


def test_a_floating_loop_is_measured_from_its_solid_placed_first():
    """Watt I: the second loop coupler-E-link-G-out-F-rocker touches no frame."""
    a, b, c, o4 = 0.1, 0.35, 0.3, np.array([0.4, 0.0])

    def rot(f):
        return np.array([[np.cos(f), -np.sin(f)], [np.sin(f), np.cos(f)]])

    def pose(theta):
        A = a * np.array([np.cos(theta), np.sin(theta)])
        B = meet(A, o4, b, c, 1.0)
        E = A + rot(angle(B - A)) @ [0.2, 0.15]
        F = o4 + rot(angle(B - o4)) @ [0.15, 0.1]
        return A, B, E, F, meet(E, F, 0.3, 0.25, 1.0)

    A, B, E, F, G = pose(0.3)
    text = '[model]\nname = "watt-1"\n' + GROUND.format(
        points="O2 = [0.0, 0.0], O4 = [0.4, 0.0]", lines="")
    text += solid("crank", 0, 0, 0.3, {"O": (0, 0), "A": (a, 0)})
    text += solid("coupler", *A, angle(B - A), {"A": (0, 0), "B": (b, 0), "E": (0.2, 0.15)})
    text += solid("rocker", *o4, angle(B - o4), {"O": (0, 0), "B": (c, 0), "F": (0.15, 0.1)})
    text += solid("link", *E, angle(G - E), {"E": (0, 0), "G": (0.3, 0)})
    text += solid("out", *F, angle(G - F), {"F": (0, 0), "G": (0.25, 0)})
    for name, p, q in (("O2", "ground.O2", "crank.O"), ("A", "crank.A", "coupler.A"),
                       ("B", "coupler.B", "rocker.B"), ("O4", "ground.O4", "rocker.O"),
                       ("E", "coupler.E", "link.E"), ("G", "link.G", "out.G"),
                       ("F", "rocker.F", "out.F")):
        text += element("revolute", name, p, q)
    text += element("angular_actuator", "motor", "ground", "crank",
                    f'law = "polynomial"\nC = [0.3, {2 * np.pi!r}, 0.0, 0.0]\n')
    model = loads(text + analysis(1.0, 20))
    atlas = classify(model)
    loop = atlas.loops[1]
    assert loop.solids == ["coupler", "link", "out", "rocker"] and loop.reference == "coupler"
    assert loop.input == "rocker" and atlas.assembly_modes == 4
    lengths = (np.hypot(0.2 - 0.35, 0.15), 0.3, 0.25, np.hypot(0.3 - 0.15, 0.1))
    s, *pq, l = sorted(lengths)
    assert s + l > sum(pq) and loop.grashof.kind == "non-grashof"
    assert loop.grashof.left == pytest.approx(s + l, abs=1e-12)
    t = prepare(model, analysis="kinematic").times
    mu = []
    for theta in 0.3 + 2 * np.pi * t:               # the coupler 'out' F → G, 'link' E → G
        A, B, E, F, G = pose(theta)
        u, w = G - F, G - E
        mu.append(np.degrees(np.arctan2(abs(u[0] * w[1] - u[1] * w[0]), abs(u @ w))))
    assert loop.transmission["min"] == pytest.approx(min(mu), abs=1e-7)
    assert loop.transmission["max"] == pytest.approx(max(mu), abs=1e-7)

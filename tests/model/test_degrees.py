"""Models in degrees (``[model] angles = "deg"``, issue 14 item 1) and results in degrees.

A degrees model is the radians model with every angle the user gives multiplied by 180/π; the
lists of which values those are (``DEGREE_VALUES``, ``_in_degrees``) are written here by hand,
from the element tables of docs/model-format.md, not read from the declarations they test.
"""
from __future__ import annotations

import copy
import math
from pathlib import Path

import numpy as np
import pytest

import pam2exu
from pam2exu import ModelError, loads
from pam2exu.analyses import force_pass, native
from pam2exu.cli import main
from pam2exu.kinematics import State
from pam2exu.model.angles import angle_warnings

ROOT = Path(__file__).resolve().parents[2]
FOUR_BAR = ROOT / "examples" / "four_bar.toml"
TO_DEG = 180.0 / math.pi
ANGULAR = {"rad": "deg", "rad/s": "deg/s", "rad/s²": "deg/s²"}

#: per element type, which constants are angles or angular rates, by law where there is one
DEGREE_VALUES = {
    ("angular_actuator", "polynomial"): (0, 1, 2, 3),
    ("angular_actuator", "harmonic"): (0, 1),          # C3 [rad/s], C4 [rad]: the cosine's
    ("angular_actuator", "ramp"): (2, 3),              # C1, C2: times
    ("angular_actuator", "bezier_c1"): (2, 3),
    ("angular_actuator", "bezier_c2"): (2, 3),
    ("torsional_spring", None): (2,),                  # C2 N·m/rad and C4 stay SI
    ("transmission", None): (0,),
}


def _in_degrees(model: pam2exu.Model) -> pam2exu.Model:
    """A copy of a radians model written in degrees: fi, line angles, DEGREE_VALUES and
    the variations' dangle × 180/π."""
    out = copy.deepcopy(model)
    out.angles = "deg"
    for s in out.solids:
        s.fi = float(s.fi) * TO_DEG
        s.lines = {k: {**v, "angle": float(v.get("angle", 0.0)) * TO_DEG}
                   for k, v in s.lines.items()}
    for el in out.elements:
        which = DEGREE_VALUES.get((el.type, getattr(el, "law", None)),
                                  DEGREE_VALUES.get((el.type, None), ()))
        if not which:
            continue
        if el.type == "transmission":
            el.C = float(el.C) * TO_DEG
        else:
            C = [float(c) for c in el.C] + [0.0] * (4 - len(el.C))
            el.C = [c * TO_DEG if k in which else c for k, c in enumerate(C)]
    for v in out.variations:
        v.dangle = float(v.dangle) * TO_DEG
    return out


def _assert_degrees_of(deg: pam2exu.Results, rad: pam2exu.Results, rtol=1e-12):
    """deg's angular columns are rad's × 180/π, the others equal, to rtol of each column's
    largest magnitude; the units say deg."""
    assert deg.columns == rad.columns
    for c in rad.columns:
        factor = TO_DEG if rad.units[c] in ANGULAR else 1.0
        assert deg.units[c] == ANGULAR.get(rad.units[c], rad.units[c]), c
        expected = rad[c] * factor
        scale = max(float(np.max(np.abs(expected))), 1e-300)
        assert float(np.max(np.abs(deg[c] - expected))) <= rtol * scale, c


@pytest.fixture(scope="module")
def four_bar_runs():
    """The four-bar's kinetostatic run in radians, written in degrees, and converted."""
    rad_model = pam2exu.load(FOUR_BAR)
    deg_model = _in_degrees(rad_model)
    assert deg_model["motor"].C[1] == 360.0 and rad_model["motor"].C[1] == 2 * math.pi
    kw = dict(analysis="kinetostatic", steps=40)
    return (pam2exu.run(rad_model, **kw), pam2exu.run(deg_model, **kw),
            pam2exu.run(rad_model, angles="deg", **kw), pam2exu.run(deg_model, angles="rad",
                                                                   **kw))


def test_four_bar_in_degrees_gives_the_radian_results_times_180_over_pi(four_bar_runs):
    rad, deg, _, _ = four_bar_runs
    assert {rad.units[c] for c in rad.columns} >= {"rad", "rad/s", "rad/s²", "N", "N·m"}
    _assert_degrees_of(deg, rad)
    assert deg.units["crank.fi"] == "deg" and deg.units["coupler.DDfi"] == "deg/s²"
    assert deg.units["motor.Df(t)"] == "deg/s" and deg.units["motor.Mz"] == "N·m"
    assert deg["crank.fi"][-1] == pytest.approx(360.0, rel=1e-14)


def test_angles_argument_converts_either_way(four_bar_runs):
    rad, deg, rad_as_deg, deg_as_rad = four_bar_runs
    _assert_degrees_of(rad_as_deg, rad)
    _assert_degrees_of(deg, deg_as_rad)          # the degrees model asked for radians
    for c in rad.columns:
        assert deg_as_rad.units[c] == rad.units[c]
        scale = max(float(np.max(np.abs(rad[c]))), 1e-300)
        assert float(np.max(np.abs(deg_as_rad[c] - rad[c]))) <= 1e-12 * scale, c


def test_every_declared_angle_is_converted(data):
    """every_element.toml (all types, line angles, a harmonic motor, a ramp cylinder, a
    transmission, a torsional spring with C3 ≠ 0) written in degrees: the mechanism's
    constraint residuals and applied forces (dampers included) equal the radians model's."""
    rad_model = pam2exu.load(data / "every_element.toml")
    rad_model["twist"].C = [0.1, 2.0, 0.4, 0.01]          # C3 ≠ 0, C2 and C4 must stay
    deg_model = _in_degrees(rad_model)
    assert deg_model["motor"].C[2:] == [2.0, 0.3] and deg_model["cylinder"].C == [
        0.0, 1.0, 0.45, 0.5]
    rad, deg = rad_model.mechanism(), deg_model.mechanism()
    np.testing.assert_allclose(deg.initial_q(), rad.initial_q(), rtol=1e-15, atol=0)
    rng = np.random.default_rng(14)
    t = np.array([0.0, 0.3, 0.7, 1.4])
    q = rad.initial_q() + 0.1 * rng.standard_normal((len(t), rad.nq))
    qd = rng.standard_normal((len(t), rad.nq))
    np.testing.assert_allclose(native.residuals(deg, t, q), native.residuals(rad, t, q),
                               rtol=0, atol=1e-14)
    f_rad = force_pass.applied_forces(rad, State(t, q, qd), damping=True).force
    f_deg = force_pass.applied_forces(deg, State(t, q, qd), damping=True).force
    np.testing.assert_allclose(f_deg, f_rad, rtol=1e-13, atol=1e-13)
    assert float(np.max(np.abs(f_rad))) > 0.1


@pytest.mark.parametrize("law, C, expected", [
    ("polynomial", [90.0, 180.0, 45.0, 9.0], [math.pi / 2, math.pi, math.pi / 4, math.pi / 20]),
    ("harmonic", [90.0, 180.0, 2.0, 0.5], [math.pi / 2, math.pi, 2.0, 0.5]),
    ("ramp", [0.5, 1.5, 90.0, 180.0], [0.5, 1.5, math.pi / 2, math.pi]),
    ("bezier_c2", [0.5, 1.5, 90.0, 180.0], [0.5, 1.5, math.pi / 2, math.pi]),
])
def test_law_constants(law, C, expected):
    """An angular actuator's constants in the unit of f are degrees; a linear actuator's and
    the other constants (times, the cosine's ω and phase) are as written."""
    m = pam2exu.Model("laws", angles="deg")
    m.add_solid("ground", points={"O": [0, 0]})
    m.add_solid("arm", points={"O": [0, 0], "P": [0.5, 0]})
    m.add("fixed", anc1="ground")
    m.add("revolute", anc1="ground.O", anc2="arm.O")
    m.add("angular_actuator", name="motor", anc1="ground", anc2="arm", law=law, C=C)
    m.add("linear_actuator", name="cyl", anc1="ground.O", anc2="arm.P", law=law, C=C)
    mech = m.mechanism()
    np.testing.assert_allclose(mech.elements[2].C, expected, rtol=1e-15)
    assert list(mech.elements[3].C) == C
    assert m["motor"].C == C                     # the model keeps what the user wrote


def test_variation_dangle_in_degrees_and_its_frequency_in_rad_per_s(guides):
    m = guides()
    m.angles = "deg"
    m["ground"].lines["rail"]["angle"] = 0.3 * TO_DEG
    m["slider"].lines["axis"]["angle"] = 0.2 * TO_DEG
    m.add_variation("ground.rail", dy=1e-3, dangle=0.5, wangle=2.0, fixed_dangle=-0.25)
    mech = m.mechanism()
    v = mech.variations[0]
    assert (v.dangle, v.wangle, v.dy) == (pytest.approx(0.5 / TO_DEG, rel=1e-15), 2.0, 1e-3)
    assert v.fixed_dangle == pytest.approx(-0.25 / TO_DEG, rel=1e-15)
    assert mech.solids[0].lines["rail"]["angle"] == pytest.approx(0.3, rel=1e-15)
    assert m.variations[0].dangle == 0.5


def test_toml_key_and_bad_values():
    text = FOUR_BAR.read_text().replace('name = "four-bar"', 'name = "four-bar"\nangles = "deg"')
    assert loads(text).angles == "deg" and pam2exu.load(FOUR_BAR).angles == "rad"
    with pytest.raises(ModelError, match=r"\[model\]: angles must be \"rad\" \(the default\) "
                                         r"or \"deg\", got 'degrees'"):
        loads(text.replace('angles = "deg"', 'angles = "degrees"'))
    with pytest.raises(ModelError, match="angles must be 'rad' or 'deg'"):
        pam2exu.run(FOUR_BAR, steps=2, angles="grad")


def test_check_warns_on_a_fi_in_degrees(tmp_path, capsys):
    text = FOUR_BAR.read_text().replace("fi = 0.02", "fi = 47")
    (tmp_path / "m.toml").write_text(text)
    assert main(["check", str(tmp_path / "m.toml")]) == 0
    err = capsys.readouterr().err                # the CLI's warnings: one line each, stderr
    warnings = [line for line in err.splitlines() if "warning:" in line]
    assert warnings == [
        "pam2exu: warning: [[solid]] #2 'crank': fi = 47 rad is more than a full turn (2π = "
        "6.28 rad): "
        "did you give degrees? Write fi in radians (47° = 0.8203 rad), or set angles = \"deg\" "
        "in [model] to give every angle of the model in degrees"]
    assert not angle_warnings(loads(text.replace("fi = 47", "fi = -6.28")))
    assert not angle_warnings(loads(text.replace('name = "four-bar"',
                                                 'name = "four-bar"\nangles = "deg"')))
    assert main(["check", str(FOUR_BAR)]) == 0
    assert "warning" not in str(capsys.readouterr())


def test_run_cli_angles_deg(tmp_path, capsys):
    assert main(["run", str(FOUR_BAR), "--steps", "4", "--angles", "deg",
                 "--outputs", "crank.fi", "motor.Df(t)", "rocker.x"]) == 0
    out = capsys.readouterr().out
    rows = {line.split()[0]: line.split()[1:] for line in out.splitlines()[3:6]}
    assert rows["crank.fi"][:3] == ["deg", "0", "360"]
    assert rows["motor.Df(t)"][:3] == ["deg/s", "360", "360"]
    assert rows["rocker.x"][:3] == ["m", "0.4", "0.4"]


def test_verify_compares_a_degrees_model_in_radians():
    """verify's tolerances are per SI unit: both runs are made in radians."""
    text = FOUR_BAR.read_text()
    deg = _in_degrees(loads(text))
    found = pam2exu.verify(deg, steps=10)
    assert found.ok
    assert found.comparison["crank.fi"].unit == "rad"
    assert found.reference["motor.f(t)"][-1] == pytest.approx(2 * math.pi, rel=1e-14)


def test_pictures_of_a_degrees_model_are_those_of_the_radians_model(tmp_path):
    """draw's configurations come from runs in radians whatever the model's angles."""
    from pam2exu.pictures.mechanism import pose
    from pam2exu.pictures.vectors import at_instant
    rad_model = pam2exu.load(FOUR_BAR)
    deg_model = _in_degrees(rad_model)
    for t in (0.0, 0.3):
        (_, q_rad), (_, q_deg) = pose(rad_model, t), pose(deg_model, t)
        np.testing.assert_allclose(q_deg, q_rad, rtol=0, atol=1e-12)
    _, q_rad, arrows_rad = at_instant(rad_model, 0.3, "v")
    _, q_deg, arrows_deg = at_instant(deg_model, 0.3, "v")
    np.testing.assert_allclose(q_deg, q_rad, rtol=0, atol=1e-12)
    np.testing.assert_allclose(arrows_deg.values, arrows_rad.values, rtol=0, atol=1e-12)
    np.testing.assert_allclose(arrows_deg.points, arrows_rad.points,
                               rtol=0, atol=1e-12)


def test_range_messages_of_a_degrees_model_are_in_degrees():
    """A solid's fi, Dfi and line angles are checked in the model's unit: the limit of
    1e7 rad is 5.73e8 deg, and the message says deg (a radian model keeps rad)."""
    text = ('[model]\nangles = "{a}"\n[[solid]]\nname = "a"\nfi = 1e9\nDfi = 1e13\n'
            'lines = {{ l = {{ point = [0, 0], angle = 1e10 }} }}\n')
    with pytest.raises(pam2exu.ModelError) as error:
        pam2exu.loads(text.format(a="deg"))
    message = str(error.value)
    assert "fi = 1e+09 deg is out of range: its magnitude must be at most 5.72958e+08 deg" \
        in message
    assert "Dfi = 1e+13 deg/s is out of range: its magnitude must be at most 1e+12 deg/s" \
        in message
    assert "line 'l' angle = 1e+10 deg is out of range" in message
    assert "rad" not in message
    # 5e8 deg is inside the degrees range (8.7e6 rad), 1e7 rad is the radian one
    pam2exu.loads(text.format(a="deg").replace("1e9", "5e8").replace("1e13", "1")
                  .replace("1e10", "0"))
    with pytest.raises(pam2exu.ModelError, match="fi = 1e\\+09 rad is out of range"):
        pam2exu.loads(text.format(a="rad"))


def test_radians_model_inputs_are_shallow_copies_of_every_element_and_variation():
    """``si_inputs`` of a radians model: new objects of the same class with the same
    attribute values (``copy.copy``'s), the model's own left alone."""
    import copy
    from pathlib import Path
    import pam2exu
    from pam2exu.model.angles import si_inputs
    root = Path(__file__).parents[2] / "examples"
    for name in ("all_elements.toml", "clearance/locomotive.toml"):
        model = pam2exu.load(root / name)
        solids, elements, variations = si_inputs(model)
        assert solids == model.solids
        for mine, theirs in zip(elements + variations, model.elements + model.variations):
            assert mine is not theirs and type(mine) is type(theirs)
            assert vars(mine) == vars(copy.copy(theirs))
            assert all(vars(mine)[k] is v for k, v in vars(theirs).items())
        assert len(elements) == len(model.elements) > 5
    assert len(variations) == 2                     # (the locomotive's)

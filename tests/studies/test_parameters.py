"""What a study can vary (pam2exu/studies/parameters.py): the names, nominal values and
units read from the model, and a variant written into the model's text equal to a model
file with those values written in by hand."""
from pathlib import Path

import numpy as np
import pytest

import pam2exu
from pam2exu.studies import loads_study, targets, varied

ROOT = Path(__file__).resolve().parents[2]
FOUR_BAR = ROOT / "examples" / "four_bar.toml"


def test_targets_name_nominal_and_unit_from_the_model():
    # reference: examples/four_bar.toml's values and the contract's units
    found = targets(pam2exu.load(FOUR_BAR))
    expected = {"coupler.B.x": (0.35, "m"), "coupler.P.y": (0.1, "m"),
                "crank.mass": (0.3, "kg"), "coupler.inertia": (8.2e-3, "kg·m²"),
                "rocker.cog.x": (0.15, "m"), "motor.C2": (6.283185307179586, "rad/s"),
                "motor.C4": (0.0, "rad/s³"), "model.gravity": (9.81, "m/s²")}
    assert {k: (found[k].nominal, found[k].unit) for k in expected} == expected


def test_targets_of_lines_transmission_springs_and_a_transition_law():
    # reference: tests/data/every_element.toml; units from the declarations
    found = targets(pam2exu.load(ROOT / "tests" / "data" / "every_element.toml"))
    assert (found["ground.rail.y"].nominal, found["ground.rail.angle"].unit) == (-0.2, "rad")
    assert (found["gears.T"].nominal, found["gears.T"].unit) == (-2.0, "–")
    assert (found["gears.C"].nominal, found["gears.C"].unit) == (0.3, "rad")
    assert [found[f"spring.C{k}"].unit for k in (1, 2, 3, 4)] == ["N", "N/m", "m", "N·s/m"]
    assert [found[f"cylinder.C{k}"].unit for k in (1, 2, 3, 4)] == ["s", "s", "m", "m"]


def test_a_degrees_model_gives_its_angles_in_degrees():
    text = FOUR_BAR.read_text().replace('gravity = 9.81', 'gravity = 9.81\nangles = "deg"')
    text = text.replace("C = [0.0, 6.283185307179586, 0.0, 0.0]", "C = [0.0, 360.0, 0.0, 0.0]")
    text = text.replace("fi = 1.85", "fi = 106.0").replace("fi = 0.9", "fi = 51.6")
    found = targets(pam2exu.loads(text))
    assert (found["motor.C2"].nominal, found["motor.C2"].unit) == (360.0, "deg/s")


def test_a_variant_from_the_text_equals_the_file_written_by_hand():
    # the acceptance of the contract: a varied model runs as a model file with those values
    # written in by hand, bit for bit (kinetostatic four-bar, 4 steps)
    study = loads_study(f'''
[study]
model = "{FOUR_BAR.name}"
samples = 3
seed = 7
[[parameter]]
name = "coupler.B.x"
distribution = "normal"
tol = 1e-3
[[parameter]]
name = "crank.A.x"
distribution = "uniform"
tol = 1e-3
[[parameter]]
name = "coupler.mass"
distribution = "triangular"
tol = 0.1
[[parameter]]
name = "motor.C2"
distribution = "normal"
std = 0.01
[[parameter]]
name = "model.gravity"
distribution = "values"
values = [1.62, 3.71]
''', folder=FOUR_BAR.parent)
    row = [float(v) for v in study.variants(2, 3)[0]]
    values = dict(zip(study.names, row))
    text = study.model_text
    model = varied(text, values, source=str(FOUR_BAR))
    by_hand = (text.replace("B = [0.35, 0.0]", f"B = [{row[0]!r}, 0.0]")
               .replace("A = [0.1, 0.0]", f"A = [{row[1]!r}, 0.0]")
               .replace("mass = 0.8", f"mass = {row[2]!r}")
               .replace("C = [0.0, 6.283185307179586, 0.0, 0.0]",
                        f"C = [0.0, {row[3]!r}, 0.0, 0.0]")
               .replace("gravity = 9.81", f"gravity = {row[4]!r}"))
    assert by_hand.count(repr(row[0])) == 1 and row[4] in (1.62, 3.71)
    ours = pam2exu.run(model, analysis="kinetostatic", steps=4)
    theirs = pam2exu.run(pam2exu.loads(by_hand), analysis="kinetostatic", steps=4)
    assert ours.columns == theirs.columns
    for column in theirs.columns:
        assert np.array_equal(ours[column], theirs[column]), column
    assert study.model["coupler"].points["B"] == [0.35, 0.0]      # the nominal is untouched
    nominal = pam2exu.run(study.model, analysis="kinetostatic", steps=4)
    assert not np.array_equal(nominal["motor.Mz"], ours["motor.Mz"])     # it did vary


def test_a_variant_that_makes_the_model_invalid_is_a_model_error():
    with pytest.raises(pam2exu.ModelError, match="mass is negative"):
        varied(FOUR_BAR.read_text(), {"crank.mass": -0.1})


def test_a_clearance_variant_writes_its_points_and_lines_as_fixed_deviations():
    """as_made: a point's or line's value becomes value − nominal in the fixed deviation of
    its [[variation]] (the model's own entry when it has one, a new one otherwise); the
    nominal dimensions stay; other parameters are written as usual."""
    text = (ROOT / "examples" / "clearance" / "locomotive.toml").read_text(encoding="utf-8")
    model = varied(text, {"frame.O2.x": 1.5 + 2e-4, "frame.O2.y": -1e-4,
                          "wheel2.A.x": 0.25 - 3e-4, "rod.mass": 7.0}, as_made=True)
    assert model["frame"].points["O2"] == [1.5, 0.0] and model["wheel2"].points["A"] == [0.25, 0.0]
    assert model["rod"].mass == 7.0
    own = model.variations[0]                                        # frame.O2, the file's
    assert (own.anchor, own.dx, own.fixed_dx, own.fixed_dy) == ("frame.O2", 3.7e-4,
                                                                (1.5 + 2e-4) - 1.5, -1e-4)
    new = model.variations[-1]
    assert (new.anchor, new.fixed_dx, new.fixed_dy, new.position) == \
        ("wheel2.A", (0.25 - 3e-4) - 0.25, 0.0, 3)
    plain = varied(text, {"frame.O2.x": 1.5 + 2e-4})                 # the other analyses
    assert plain["frame"].points["O2"][0] == 1.5 + 2e-4 and not plain.variations[0].has_fixed


def test_a_line_angle_is_a_fixed_deviation_of_its_angle():
    model = pam2exu.load(ROOT / "tests" / "data" / "every_element.toml")
    nominal = targets(model)["ground.rail.angle"].nominal
    text = (ROOT / "tests" / "data" / "every_element.toml").read_text(encoding="utf-8")
    varied_model = varied(text, {"ground.rail.angle": nominal + 0.5}, as_made=True)
    (v,) = [v for v in varied_model.variations if v.anchor == "ground.rail"]
    assert v.fixed_dangle == (nominal + 0.5) - nominal and v.fixed_dx == 0.0

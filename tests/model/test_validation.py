"""Model validation: every rule has an error-path test, plus the loader's positive paths.

Reference: shared/spec/model-format.md (the model format contract). A ModelError lists every
problem found, each as ``<where>: <message>``, where is e.g. ``[[element]] #2 'A' (revolute)``.
"""
from __future__ import annotations

import re
import shutil
from pathlib import Path

import sys

import pytest

import pam2exu
from pam2exu import ELEMENTS, Model, ModelError, Solid, loads
from pam2exu.elements import ALIASES
from pam2exu import registry

ROOT = Path(__file__).resolve().parents[2]

#: two solids with points and lines, referenced by the snippets below
SOLIDS = """
[[solid]]
name = "ground"
points = { O = [0.0, 0.0], P = [0.5, 0.0] }
lines = { rail = { point = [0.0, 0.0], angle = 0.0 } }

[[solid]]
name = "crank"
x = 0.1
points = { O = [0.0, 0.0], A = [0.1, 0.0] }
lines = { axis = { point = [0.0, 0.0], angle = 0.0 } }
"""


def element(body: str) -> str:
    """A model: SOLIDS followed by one [[element]] table with ``body``."""
    return SOLIDS + "\n[[element]]\n" + body.strip() + "\n"


def problems(text: str) -> list[str]:
    """The problems of a model that must fail, as strings."""
    with pytest.raises(ModelError) as info:
        loads(text)
    return [str(p) for p in info.value.problems]


def only_problem(text: str) -> str:
    found = problems(text)
    assert len(found) == 1, found
    return found[0]


def test_sound_snippet_loads():
    """The base of the snippets below is itself valid (so each test's error is its own)."""
    model = loads(element('type = "revolute"\nname = "O"\nanc1 = "ground.O"\nanc2 = "crank.O"'))
    assert [s.name for s in model.solids] == ["ground", "crank"]
    assert model.problems() == []


# ---- element types -----------------------------------------------------------------------

def test_unknown_element_type_suggests_closest():
    text = element('type = "revolut"\nanc1 = "ground.O"\nanc2 = "crank.O"')
    with pytest.raises(ModelError, match=r"unknown element type 'revolut' "
                                         r"\(did you mean 'revolute'\?\)"):
        loads(text)
    message = only_problem(text)
    assert message.startswith("[[element]] #1: ")
    assert "known types: fixed, revolute, prismatic" in message


def test_unknown_catalan_type_suggests_closest_alias():
    with pytest.raises(ModelError, match=r"unknown element type 'articulacion' "
                                         r"\(did you mean 'articulacio'\?\)"):
        loads(element('type = "articulacion"\nanc1 = "ground.O"\nanc2 = "crank.O"'))


def test_unknown_element_type_in_python_api():
    with pytest.raises(ModelError, match=r"unknown element type 'revolut' "
                                         r"\(did you mean 'revolute'\?\)"):
        Model().add("revolut", anc1="ground.O", anc2="crank.O")


def test_missing_element_type():
    with pytest.raises(ModelError, match=r"\[\[element\]\] #1 'O': 'type' is missing; one of fixed"):
        loads(element('name = "O"\nanc1 = "ground.O"\nanc2 = "crank.O"'))


def test_element_type_that_is_not_a_string():
    """The value is quoted as written, without quotes around its quotes (issue 22)."""
    with pytest.raises(ModelError, match=r"\[\[element\]\] #1: unknown element type \['revolute'\] "):
        loads(element('type = ["revolute"]\nanc1 = "ground.O"\nanc2 = "crank.O"'))


# ---- unknown keys and tables -------------------------------------------------------------

def test_unknown_key_in_model_table():
    with pytest.raises(ModelError, match=r"\[model\]: unknown key 'gravty' "
                                         r"\(did you mean 'gravity'\?\)"):
        loads('[model]\ngravty = 9.81\n' + SOLIDS)


def test_unknown_key_in_solid():
    with pytest.raises(ModelError, match=r"\[\[solid\]\] #2 'crank': unknown key 'mas' "
                                         r"\(did you mean 'mass'\?\); allowed keys: name, x, y"):
        loads(SOLIDS.replace('x = 0.1', 'mas = 1.0'))


def test_unknown_key_in_element():
    with pytest.raises(ModelError, match=r"\[\[element\]\] #1 'O' \(revolute\): unknown key "
                                         r"'anc_2' \(did you mean 'anc2'\?\)"):
        loads(element('type = "revolute"\nname = "O"\nanc1 = "ground.O"\nanc_2 = "crank.O"\n'
                      'anc2 = "crank.O"'))


def test_unknown_key_in_element_keys_of_its_type():
    """A key valid for another type (law on a spring) is unknown for this one."""
    with pytest.raises(ModelError, match=r"\(spring\): unknown key 'law'; allowed keys: "
                                         r"type, name, anc1, anc2, C"):
        loads(element('type = "spring"\nanc1 = "ground.P"\nanc2 = "crank.A"\nlaw = "ramp"'))


def test_unknown_key_in_analysis():
    with pytest.raises(ModelError, match=r"\[analysis\]: unknown key 't_edn' "
                                         r"\(did you mean 't_end'\?\)"):
        loads(SOLIDS + '\n[analysis]\nt_edn = 1.0\n')


def test_unknown_top_level_table():
    with pytest.raises(ModelError, match=r"\[modle\]: unknown table \(did you mean 'model'\?\); "
                                         r"a model has model, solid, element, variation, analysis"):
        loads('[modle]\nname = "x"\n' + SOLIDS)


def test_unknown_key_of_a_line():
    with pytest.raises(ModelError, match=r"line 'rail' has an unknown key 'angel' "
                                         r"\(did you mean 'angle'\?\)"):
        loads(SOLIDS.replace("angle = 0.0 } }\n\n[[solid]]", "angel = 0.0 } }\n\n[[solid]]"))


@pytest.mark.parametrize("text,match", [
    ("model = 3\n" + SOLIDS, r"\[model\]: must be a table \[model\], not a value"),
    ("solid = 3\n", r"\[\[solid\]\]: must be an array of tables \[\[solid\]\]"),
    ("element = [1, 2]\n" + SOLIDS,
     r"\[\[element\]\]: must be an array of tables"),
    ("analysis = 'kinematic'\n" + SOLIDS, r"\[analysis\]: must be a table \[analysis\]"),
])
def test_tables_of_the_wrong_kind(text, match):
    with pytest.raises(ModelError, match=match):
        loads(text)


def test_model_without_solids():
    with pytest.raises(ModelError, match=r"there are no solids: add at least one \[\[solid\]\]"):
        loads('[model]\nname = "empty"\n')


def test_solid_without_name():
    with pytest.raises(ModelError, match=r"\[\[solid\]\] #3: 'name' is missing"):
        loads(SOLIDS + '\n[[solid]]\nx = 1.0\n')


# ---- names -------------------------------------------------------------------------------

def test_duplicate_solid_names():
    text = SOLIDS + '\n[[solid]]\nname = "crank"\n'
    with pytest.raises(ModelError, match=r"\[\[solid\]\] #3 'crank': name 'crank' is already used "
                                         r"by \[\[solid\]\] #2 'crank'"):
        loads(text)


def test_element_named_like_a_solid():
    text = element('type = "fixed"\nname = "ground"\nanc1 = "ground"')
    with pytest.raises(ModelError, match=r"\[\[element\]\] #1 'ground' \(fixed\): name 'ground' is "
                                         r"already used by \[\[solid\]\] #1 'ground': solids and "
                                         r"elements share one namespace"):
        loads(text)


def test_duplicate_element_names():
    text = element('type = "fixed"\nname = "base"\nanc1 = "ground"') + (
        '\n[[element]]\ntype = "revolute"\nname = "base"\nanc1 = "ground.O"\nanc2 = "crank.O"\n')
    with pytest.raises(ModelError, match=r"\[\[element\]\] #2 'base' \(revolute\): name 'base' is "
                                         r"already used by \[\[element\]\] #1 'base' \(fixed\)"):
        loads(text)


def test_name_with_a_dot():
    with pytest.raises(ModelError, match=r"name 'crank.2' contains '\.'"):
        loads(SOLIDS.replace('name = "crank"', 'name = "crank.2"'))


@pytest.mark.parametrize("value", ['""', "3"])
def test_name_that_is_not_a_nonempty_string(value):
    with pytest.raises(ModelError, match=r"\[\[element\]\] #1 .*name must be a non-empty string"):
        loads(element(f'type = "fixed"\nname = {value}\nanc1 = "ground"'))


# ---- references --------------------------------------------------------------------------

def test_reference_to_missing_solid():
    with pytest.raises(ModelError, match=r"\[\[element\]\] #1 'O' \(revolute\): anc1 = 'grund\.O': "
                                         r"no solid 'grund' \(did you mean 'ground'\?\)"):
        loads(element('type = "revolute"\nname = "O"\nanc1 = "grund.O"\nanc2 = "crank.O"'))


def test_reference_to_missing_solid_where_a_solid_is_expected():
    with pytest.raises(ModelError, match=r"anc1 = 'crnk': no solid 'crnk' "
                                         r"\(did you mean 'crank'\?\)"):
        loads(element('type = "fixed"\nanc1 = "crnk"'))


def test_point_of_a_solid_where_a_solid_is_expected():
    """A fixed link, an actuator or a transmission anchors a whole solid, not one of its points."""
    with pytest.raises(ModelError, match=r"anc2 = 'crank\.A': no solid 'crank\.A'"):
        loads(element('type = "angular_actuator"\nanc1 = "ground"\nanc2 = "crank.A"'))


def test_reference_to_missing_point():
    with pytest.raises(ModelError, match=r"anc2 = 'crank\.AA': solid 'crank' has no point 'AA' "
                                         r"\(did you mean 'A'\?\); its points are: O, A"):
        loads(element('type = "revolute"\nanc1 = "ground.P"\nanc2 = "crank.AA"'))


def test_reference_to_missing_point_of_a_solid_without_points():
    text = SOLIDS + '\n[[solid]]\nname = "slider"\n' + (
        '\n[[element]]\ntype = "revolute"\nanc1 = "ground.P"\nanc2 = "slider.B"\n')
    with pytest.raises(ModelError, match=r"solid 'slider' has no point 'B'; its points are: none"):
        loads(text)


def test_reference_to_missing_line():
    with pytest.raises(ModelError, match=r"anc1 = 'ground\.rial': solid 'ground' has no line "
                                         r"'rial' \(did you mean 'rail'\?\); its lines are: rail"):
        loads(element('type = "prismatic"\nanc1 = "ground.rial"\nanc2 = "crank.axis"'))


def test_point_where_a_line_is_expected():
    with pytest.raises(ModelError, match=r"anc1 = 'ground\.P': solid 'ground' has no line 'P' "
                                         r"\(that is a point; a line is expected here\)"):
        loads(element('type = "pin_slot"\nanc1 = "ground.P"\nanc2 = "crank.A"'))


def test_line_where_a_point_is_expected():
    with pytest.raises(ModelError, match=r"anc2 = 'crank\.axis': solid 'crank' has no point 'axis' "
                                         r"\(that is a line; a point is expected here\)"):
        loads(element('type = "pin_slot"\nanc1 = "ground.rail"\nanc2 = "crank.axis"'))


@pytest.mark.parametrize("points", ['{ P = "x" }', '{ P = [1.0, 2.0, 3.0] }',
                                    '{ P = ["a", 1.0] }', '3', '[1.0, 2.0]'])
def test_reference_to_a_malformed_point_is_a_model_error(points):
    """A malformed point table is reported (not a TypeError/ValueError from the resolution)."""
    text = element('type = "revolute"\nanc1 = "ground.P"\nanc2 = "crank.A"').replace(
        "points = { O = [0.0, 0.0], P = [0.5, 0.0] }", f"points = {points}")
    found = problems(text)
    assert any(p.startswith("[[solid]] #1 'ground': ") and "point" in p for p in found), found
    assert any(p.startswith("[[element]] #1 'revolute1' (revolute): anc1 = 'ground.P'")
               for p in found), found


@pytest.mark.parametrize("lines", ['{ rail = 3 }', '{ rail = { point = [1.0, 2.0, 3.0] } }',
                                   '{ rail = { angle = "a" } }', '"rail"'])
def test_reference_to_a_malformed_line_is_a_model_error(lines):
    text = element('type = "prismatic"\nanc1 = "ground.rail"\nanc2 = "crank.axis"').replace(
        "lines = { rail = { point = [0.0, 0.0], angle = 0.0 } }", f"lines = {lines}")
    found = problems(text)
    assert any(p.startswith("[[solid]] #1 'ground': ") and "line" in p for p in found), found
    assert any(p.startswith("[[element]] #1 'prismatic1' (prismatic): anc1 = 'ground.rail'")
               for p in found), found


# ---- anchors -----------------------------------------------------------------------------

@pytest.mark.parametrize("kind,missing,body", [
    ("revolute", "anc1", 'anc2 = "crank.O"'),
    ("revolute", "anc2", 'anc1 = "ground.O"'),
    ("fixed", "anc1", ""),
    ("prismatic", "anc2", 'anc1 = "ground.rail"'),
    ("torsor", "anc1", "C = [1.0, 0.0, 0.0]"),
])
def test_missing_anchor(kind, missing, body):
    what = {"revolute": "point", "fixed": "solid", "prismatic": "line", "torsor": "point"}[kind]
    with pytest.raises(ModelError, match=rf"\[\[element\]\] #1 '{kind}1' \({kind}\): '{missing}' "
                                         rf"is missing: it must name a {what}"):
        loads(element(f'type = "{kind}"\n{body}'))


def test_both_anchors_missing_are_both_reported():
    assert problems(element('type = "spring"')) == [
        "[[element]] #1 'spring1' (spring): 'anc1' is missing: it must name a point",
        "[[element]] #1 'spring1' (spring): 'anc2' is missing: it must name a point"]


def test_extra_anc2_on_fixed_link_in_file():
    with pytest.raises(ModelError, match=r"\[\[element\]\] #1 'fixed1' \(fixed\): unknown key "
                                         r"'anc2' \(did you mean 'anc1'\?\)"):
        loads(element('type = "fixed"\nanc1 = "ground"\nanc2 = "crank"'))


def test_extra_anc2_on_fixed_link_in_python_api():
    model = Model()
    model.add_solid("ground")
    model.add_solid("crank")
    model.add("fixed", anc1="ground", anc2="crank")
    with pytest.raises(ModelError, match=r"\[\[element\]\] #1 'fixed1' \(fixed\): a fixed takes "
                                         r"no 'anc2' \(remove it\)"):
        model.validate()


@pytest.mark.parametrize("body", [
    'type = "revolute"\nanc1 = "crank.O"\nanc2 = "crank.A"',
    'type = "prismatic"\nanc1 = "ground.rail"\nanc2 = "ground"',
    'type = "angular_actuator"\nanc1 = "crank"\nanc2 = "crank"',
    'type = "transmission"\nanc1 = "ground"\nanc2 = "ground"\nT = 2.0\narm = "crank"',
])
def test_anchors_on_the_same_solid(body):
    with pytest.raises(ModelError, match=r"anc1 and anc2 are on the same solid '(crank|ground)': "
                                         r"an element must join two different solids"):
        loads(element(body))


# ---- constants and numbers ---------------------------------------------------------------

@pytest.mark.parametrize("kind,anchors", [
    ("spring", 'anc1 = "ground.P"\nanc2 = "crank.A"'),
    ("torsional_spring", 'anc1 = "ground"\nanc2 = "crank"'),
    ("angular_actuator", 'anc1 = "ground"\nanc2 = "crank"'),
    ("linear_actuator", 'anc1 = "ground.P"\nanc2 = "crank.A"'),
])
def test_five_constants(kind, anchors):
    with pytest.raises(ModelError, match=rf"\({kind}\): 'C' has 5 constants, at most 4 are "
                                         r"allowed"):
        loads(element(f'type = "{kind}"\n{anchors}\nC = [1.0, 2.0, 3.0, 4.0, 5.0]'))


def test_torsor_with_four_constants():
    with pytest.raises(ModelError, match=r"\(torsor\): 'C' has 4 constants, at most 3 are allowed "
                                         r"\(\[Fx, Fy, M\]"):
        loads(element('type = "torsor"\nanc1 = "crank.A"\nC = [1.0, 2.0, 3.0, 4.0]'))


@pytest.mark.parametrize("value,shown", [('["a"]', "'a'"), ('[1.0, "b", true]', "'b', True"),
                                         ("[nan]", "nan"), ("[inf]", "inf")])
def test_non_numeric_constants(value, shown):
    with pytest.raises(ModelError, match=rf"\(spring\): 'C' must hold numbers, got "
                                         rf"{re.escape(shown)}$"):
        loads(element(f'type = "spring"\nanc1 = "ground.P"\nanc2 = "crank.A"\nC = {value}'))


@pytest.mark.parametrize("key,value", [("x", '"a"'), ("y", "[0.0]"), ("fi", "true"),
                                       ("mass", '"heavy"'), ("inertia", "nan")])
def test_non_numeric_solid_values(key, value):
    text = SOLIDS.replace("x = 0.1", f"{key} = {value}")
    with pytest.raises(ModelError, match=rf"\[\[solid\]\] #2 'crank': {key} must be a number, "
                                         r"got "):
        loads(text)


@pytest.mark.parametrize("key", ["mass", "inertia"])
def test_negative_mass_or_inertia(key):
    with pytest.raises(ModelError, match=rf"\[\[solid\]\] #2 'crank': {key} is negative \(-0\.5\): "
                                         r"it must be ≥ 0"):
        loads(SOLIDS.replace("x = 0.1", f"{key} = -0.5"))


@pytest.mark.parametrize("cog", ["[1.0]", '["a", 0.0]', "3.0", "[0.0, 0.0, 0.0]"])
def test_bad_centre_of_gravity(cog):
    with pytest.raises(ModelError, match=r"\[\[solid\]\] #2 'crank': cog must be \[x, y\] in the "
                                         r"local frame"):
        loads(SOLIDS.replace("x = 0.1", f"cog = {cog}"))


def test_bad_point_and_line_values():
    text = SOLIDS.replace("A = [0.1, 0.0]", 'A = [0.1]').replace(
        "axis = { point = [0.0, 0.0], angle = 0.0 }", 'axis = { point = [0.0], angle = "up" }')
    assert problems(text) == [
        "[[solid]] #2 'crank': point 'A' must be [x, y], got [0.1]",
        "[[solid]] #2 'crank': line 'axis': point must be [x, y], got [0.0]",
        "[[solid]] #2 'crank': line 'axis': angle must be a number [rad], got 'up'"]


@pytest.mark.parametrize("value", ["-1.0", '"a"', "true"])
def test_bad_gravity(value):
    with pytest.raises(ModelError, match=r"\[model\]: gravity is the magnitude along −y, "
                                         r"a number ≥ 0"):
        loads(f"[model]\ngravity = {value}\n" + SOLIDS)


# ---- laws --------------------------------------------------------------------------------

@pytest.mark.parametrize("law,suggestion", [("rmap", "ramp"), ("polinomial", "polynomial"),
                                            ("bezier_c3", "bezier_c[12]"), ("harmonics", "harmonic")])
def test_unknown_law_suggests_closest(law, suggestion):
    with pytest.raises(ModelError, match=rf"\(angular_actuator\): unknown law '{law}' "
                                         rf"\(did you mean '{suggestion}'\?\); known laws: "
                                         r"polynomial, harmonic, ramp, bezier_c1, bezier_c2, "
                                         r"polinomica, harmonica, rampa"):
        loads(element(f'type = "angular_actuator"\nanc1 = "ground"\nanc2 = "crank"\n'
                      f'law = "{law}"'))


@pytest.mark.parametrize("value,shown", [('"a"', "'a'"), ("{ a = 1 }", "{'a': 1}")])
def test_constants_that_are_not_a_list(value, shown):
    with pytest.raises(ModelError, match=rf"\(spring\): 'C' must be a list of numbers, "
                                         rf"C = \[C1, C2, C3, C4\] \(.*\), got "
                                         rf"{re.escape(shown)}$"):
        loads(element(f'type = "spring"\nanc1 = "ground.P"\nanc2 = "crank.A"\nC = {value}'))


def test_law_that_is_not_a_string():
    with pytest.raises(ModelError, match=r"\(linear_actuator\): unknown law \['ramp'\] "):
        loads(element('type = "linear_actuator"\nanc1 = "ground.P"\nanc2 = "crank.A"\n'
                      'law = ["ramp"]'))


@pytest.mark.parametrize("law", ["ramp", "rampa", "bezier_c1", "bezier_c2"])
@pytest.mark.parametrize("C", ["[1.0, 1.0, 0.0, 1.0]", "[2.0, 1.0, 0.0, 1.0]", "[]"])
def test_transition_law_needs_c1_before_c2(law, C):
    """u = (t − C1)/(C2 − C1) on C1 ≤ t < C2 (contract) has no meaning unless C1 < C2."""
    with pytest.raises(ModelError, match=rf"\(angular_actuator\): law '{law}' needs C1 < C2"):
        loads(element(f'type = "angular_actuator"\nanc1 = "ground"\nanc2 = "crank"\n'
                      f'law = "{law}"\nC = {C}'))


@pytest.mark.parametrize("law", ["polynomial", "harmonic", "polinomica", "harmonica"])
def test_smooth_laws_take_any_constants(law):
    model = loads(element(f'type = "angular_actuator"\nanc1 = "ground"\nanc2 = "crank"\n'
                          f'law = "{law}"\nC = [2.0, 1.0]'))
    assert model.elements[0].time_law().C == (2.0, 1.0, 0.0, 0.0)


# ---- transmission ------------------------------------------------------------------------

GEARS = """
[[solid]]
name = "ground"
points = { O1 = [0.0, 0.0], O2 = [0.3, 0.0] }

[[solid]]
name = "gear1"

[[solid]]
name = "gear2"
x = 0.3
"""


def test_transmission_arm_found():
    model = loads(GEARS + """
[[element]]
type = "revolute"
anc1 = "ground.O1"
anc2 = "gear1"

[[element]]
type = "revolute"
anc1 = "ground.O2"
anc2 = "gear2"

[[element]]
type = "transmission"
anc1 = "gear1"
anc2 = "gear2"
T = -2.0
""")
    mech = model.mechanism()
    assert mech.solids[mech.elements[2].arm_solid].name == "ground"


def test_transmission_without_arm():
    text = GEARS + """
[[element]]
type = "revolute"
anc1 = "ground.O1"
anc2 = "gear1"

[[element]]
type = "transmission"
name = "pair"
anc1 = "gear1"
anc2 = "gear2"
T = -2.0
"""
    with pytest.raises(ModelError, match=r"\[\[element\]\] #2 'pair' \(transmission\): no arm "
                                         r"found: no solid is hinged by revolute joints to both "
                                         r"'gear1' and 'gear2'; add the joints or name the arm"):
        loads(text)


def test_transmission_with_ambiguous_arm():
    text = GEARS + """
[[solid]]
name = "carrier"
points = { O1 = [0.0, 0.0], O2 = [0.3, 0.0] }

[[element]]
type = "revolute"
anc1 = "ground.O1"
anc2 = "gear1"

[[element]]
type = "revolute"
anc1 = "ground.O2"
anc2 = "gear2"

[[element]]
type = "revolute"
anc1 = "carrier.O1"
anc2 = "gear1"

[[element]]
type = "revolute"
anc1 = "carrier.O2"
anc2 = "gear2"

[[element]]
type = "transmission"
name = "pair"
anc1 = "gear1"
anc2 = "gear2"
T = -2.0
"""
    with pytest.raises(ModelError, match=r"\[\[element\]\] #5 'pair' \(transmission\): the arm is "
                                         r"ambiguous: 'ground', 'carrier' are each hinged to both "
                                         r"'gear1' and 'gear2'; name it with arm = "):
        loads(text)
    # naming the arm resolves it
    model = loads(text.replace("T = -2.0", 'T = -2.0\narm = "carrier"'))
    mech = model.mechanism()
    assert mech.solids[mech.elements[4].arm_solid].name == "carrier"


def test_transmission_arm_naming_a_missing_solid():
    text = GEARS + '\n[[element]]\ntype = "transmission"\nanc1 = "gear1"\nanc2 = "gear2"\n' \
                   'T = 2.0\narm = "grond"\n'
    with pytest.raises(ModelError, match=r"\(transmission\): arm = 'grond': no solid 'grond' "
                                         r"\(did you mean 'ground'\?\)"):
        loads(text)


def test_transmission_arm_that_is_not_a_name():
    text = GEARS + '\n[[element]]\ntype = "transmission"\nanc1 = "gear1"\nanc2 = "gear2"\n' \
                   'T = 2.0\narm = 3\n'
    with pytest.raises(ModelError, match=r"'arm' must be a solid name, got 3"):
        loads(text)


@pytest.mark.parametrize("extra,match", [
    ("", r"'T' is required \(transmission ratio\)"),
    ('T = "two"', r"'T' must be a number \(transmission ratio\), got 'two'"),
    ("T = [1.0, 2.0]", r"'T' must be a number \(transmission ratio\), got \[1\.0, 2\.0\]"),
    ('T = 2.0\nC = "a"', r"'C' must be a number \(initial angle \[rad\]\), got 'a'"),
])
def test_transmission_ratio_and_offset(extra, match):
    text = GEARS + '\n[[element]]\ntype = "transmission"\nanc1 = "gear1"\nanc2 = "gear2"\n' \
                   f'arm = "ground"\n{extra}\n'
    with pytest.raises(ModelError, match=match):
        loads(text)


def test_torsor_axes():
    with pytest.raises(ModelError, match=r"\(torsor\): 'axes' must be one of 'global', 'solid', "
                                         r"got 'globl' \(did you mean 'global'\?\)"):
        loads(element('type = "torsor"\nanc1 = "crank.A"\naxes = "globl"'))


# ---- analysis ----------------------------------------------------------------------------

@pytest.mark.parametrize("body,match", [
    ('type = "kinematics"', r"\[analysis\]: unknown analysis type 'kinematics' \(did you mean "
                            r"'kinematic'\?\); known types: assembly, quasi_static, kinematic, "
                            r"kinetostatic"),
    ('type = "dynamics"', r"\[analysis\]: unknown analysis type 'dynamics' \(did you mean "
                          r"'dynamic'\?\)"),
    ("t_end = 0.0", r"\[analysis\]: t_end must be a positive number of seconds, got 0\.0"),
    ("t_end = -1.0", r"t_end must be a positive number of seconds, got -1\.0"),
    ('t_end = "1"', r"t_end must be a positive number of seconds, got '1'"),
    ("t_end = inf", r"t_end must be a positive number of seconds, got inf"),
    ("steps = 0", r"\[analysis\]: steps must be a positive whole number, got 0"),
    ("steps = 2.5", r"steps must be a positive whole number, got 2\.5"),
    ('steps = "10"', r"steps must be a positive whole number, got '10'"),
    ("steps = true", r"steps must be a positive whole number, got True"),
    ('outputs = "crank.*"', r"\[analysis\]: outputs must be a list of names or patterns"),
    ('backend = "exudin"', r"\[analysis\]: unknown backend 'exudin' \(did you mean 'exudyn'\?\); "
                           r"known backends: exudyn"),
    ("backend = 1", r"\[analysis\]: unknown backend 1; known backends: exudyn"),
    ("outputs = [1, 2]", r"outputs must be a list of names or patterns"),
    ("tolerance = 0.0", r"\[analysis\]: tolerance must be a number in \(0, 0.01\], the error "
                        r"allowed per unit of a coordinate or rate, got 0.0"),
    ('tolerance = "fine"', r"tolerance must be a number in \(0, 0.01\]"),
])
def test_bad_analysis(body, match):
    with pytest.raises(ModelError, match=match):
        loads(SOLIDS + f"\n[analysis]\n{body}\n")


#: the analysis options' defaults (``registry.OPTIONS``): every [analysis] table has them
OPTION_DEFAULTS = {o.name: o.default for o in registry.OPTIONS.values()}


def test_analysis_defaults_and_values():
    assert vars(loads(SOLIDS).analysis) == {"type": "kinematic", "t_end": 1.0, "steps": 100,
                                            "outputs": None, "backend": "exudyn",
                                            **OPTION_DEFAULTS}
    assert OPTION_DEFAULTS["tolerance"] == 1e-8
    model = loads(SOLIDS + '\n[analysis]\ntype = "assembly"\nt_end = 2\nsteps = 7\n'
                           'outputs = ["crank.*", "Fx"]\nbackend = "exudyn"\n')
    assert vars(model.analysis) == {"type": "assembly", "t_end": 2, "steps": 7,
                                    "outputs": ["crank.*", "Fx"], "backend": "exudyn",
                                    **OPTION_DEFAULTS}


# ---- files and sources -------------------------------------------------------------------

def test_invalid_toml_names_the_source():
    with pytest.raises(ModelError, match=r"^broken\.toml: not valid TOML: ") as info:
        loads('[[solid]]\nname = "ground\n', source="broken.toml")
    assert info.value.source == "broken.toml"
    with pytest.raises(ModelError, match=r"^<string>: not valid TOML: "):
        loads("[[solid]\n")


def test_invalid_toml_file_names_the_file(tmp_path):
    path = tmp_path / "broken.toml"
    path.write_text('[[solid]]\nname = "ground"\nx = \n', encoding="utf-8")
    with pytest.raises(ModelError, match=rf"^{re.escape(str(path))}: not valid TOML: "
                                         r".*line 3"):
        pam2exu.load(path)


def test_missing_file(tmp_path):
    path = tmp_path / "nowhere.toml"
    with pytest.raises(ModelError, match=rf"^{re.escape(str(path))}: cannot read the "
                                         r"model file: No such file or directory"):
        pam2exu.load(path)
    with pytest.raises(ModelError, match=r"cannot read the model file"):
        pam2exu.load(str(path))


def test_directory_instead_of_file(tmp_path):
    with pytest.raises(ModelError, match=r"cannot read the model file"):
        pam2exu.load(tmp_path)


def test_errors_from_a_file_start_with_its_name(tmp_path):
    path = tmp_path / "mech.toml"
    path.write_text(element('type = "revolute"\nanc1 = "ground.X"\nanc2 = "crank.O"'),
                    encoding="utf-8")
    with pytest.raises(ModelError) as info:
        pam2exu.load(path)
    assert str(info.value).startswith(f"{path}: [[element]] #1 'revolute1' (revolute): "
                                      "anc1 = 'ground.X': solid 'ground' has no point 'X'")
    assert info.value.source == str(path)


def test_every_problem_is_reported_at_once(tmp_path):
    """Three different mistakes: three problems, each naming its table, position and name."""
    text = SOLIDS.replace("x = 0.1", "x = 0.1\nmas = 2.0") + """
[[element]]
type = "fixed"
name = "base"
anc1 = "ground"

[[element]]
type = "revolut"
name = "hinge"
anc1 = "ground.O"
anc2 = "crank.O"

[[element]]
type = "angular_actuator"
name = "motor"
anc1 = "ground"
anc2 = "crank"
law = "rmap"
"""
    path = tmp_path / "three.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(ModelError) as info:
        pam2exu.load(path)
    error = info.value
    assert len(error.problems) == 3
    assert [p.where for p in error.problems] == [
        "[[solid]] #2 'crank'", "[[element]] #2 'hinge'", "[[element]] #3 'motor' (angular_actuator)"]
    message = str(error)
    assert message.splitlines()[0] == f"{path}: 3 problems in the model:"
    assert "  - [[solid]] #2 'crank': unknown key 'mas' (did you mean 'mass'?)" in message
    assert ("  - [[element]] #2 'hinge': unknown element type 'revolut' "
            "(did you mean 'revolute'?)") in message
    assert ("  - [[element]] #3 'motor' (angular_actuator): unknown law 'rmap' "
            "(did you mean 'ramp'?)") in message


def test_python_api_reports_every_problem():
    model = Model("api")
    model.add_solid("ground", points={"O": [0.0, 0.0]})
    model.add_solid("crank", mass=-1.0, points={"O": [0.0, 0.0], "P": [1.0, 0.0]})
    model.add("revolute", name="O", anc1="ground.O", anc2="crank.OO")
    model.add("spring", anc1="ground.O", anc2="crank.O", C=[1, 2, 3, 4, 5])
    model.analysis.steps = 0
    found = [str(p) for p in model.problems()]
    assert found == [
        "[[solid]] #2 'crank': mass is negative (-1.0): it must be ≥ 0",
        "[[element]] #1 'O' (revolute): anc2 = 'crank.OO': solid 'crank' has no point 'OO' "
        "(did you mean 'O'?); its points are: O, P",
        "[[element]] #2 'spring1' (spring): 'C' has 5 constants, at most 4 are allowed "
        "(C1 [N], C2 [N/m], C3 [m], C4 [N·s/m])",
        "[analysis]: steps must be a positive whole number, got 0"]
    with pytest.raises(ModelError, match=r"^4 problems in the model:\n  - \[\[solid\]\] #2"):
        model.validate()
    with pytest.raises(ModelError, match=r"4 problems in the model"):
        model.mechanism()


def test_model_error_with_one_problem_has_one_line():
    model = Model(source="m.toml")
    model.add_solid("ground")
    model.add("fixed", anc1="grond")
    with pytest.raises(ModelError) as info:
        model.validate()
    assert str(info.value) == ("m.toml: [[element]] #1 'fixed1' (fixed): anc1 = 'grond': "
                               "no solid 'grond' (did you mean 'ground'?)")


# ---- positive paths ----------------------------------------------------------------------

def test_shipped_example_loads():
    model = pam2exu.load(ROOT / "examples" / "slider_crank.toml")
    assert model.name == "slider-crank"
    assert model.gravity == 9.81
    assert [s.name for s in model.solids] == ["ground", "crank", "rod", "slider"]
    assert [(e.name, e.type) for e in model.elements] == [
        ("base", "fixed"), ("O", "revolute"), ("A", "revolute"), ("B", "revolute"),
        ("guide", "prismatic"), ("motor", "angular_actuator")]
    assert model["rod"].fi == -0.2 and model["rod"].cog == [0.15, 0.0]
    assert model["motor"].time_law() == pam2exu.Law("polynomial", (0.0, 10.0, 0.0, 0.0))
    assert vars(model.analysis) == {"type": "kinetostatic", "t_end": 0.6283185307179586,
                                    "steps": 200, "outputs": None, "backend": "exudyn",
                                    **OPTION_DEFAULTS}
    assert model.problems() == []
    assert model.source == str(ROOT / "examples" / "slider_crank.toml")


def test_copied_example_loads_from_any_path(tmp_path):
    path = tmp_path / "copy.toml"
    shutil.copy(ROOT / "examples" / "slider_crank.toml", path)
    assert pam2exu.load(str(path)).name == "slider-crank"


def test_model_name_defaults_to_the_file_stem(tmp_path):
    path = tmp_path / "four_bar.toml"
    path.write_text(SOLIDS, encoding="utf-8")
    assert pam2exu.load(path).name == "four_bar"
    assert loads(SOLIDS).gravity == 9.81
    assert loads("[model]\ngravity = 0\n" + SOLIDS).gravity == 0


ALIAS_SNIPPETS = {
    "fixed": 'anc1 = "ground"',
    "revolute": 'anc1 = "ground.O"\nanc2 = "crank.O"',
    "prismatic": 'anc1 = "ground.rail"\nanc2 = "crank.axis"',
    "pin_slot": 'anc1 = "ground.rail"\nanc2 = "crank.A"',
    "transmission": 'anc1 = "ground"\nanc2 = "crank"\nT = 2.0\narm = "ground"',
    "torsor": 'anc1 = "crank.A"\nC = [1.0, 0.0, 0.5]\naxes = "solid"',
    "spring": 'anc1 = "ground.P"\nanc2 = "crank.A"\nC = [0.0, 100.0, 0.4]',
    "torsional_spring": 'anc1 = "ground"\nanc2 = "crank"\nC = [0.0, 1.0]',
    "angular_actuator": 'anc1 = "ground"\nanc2 = "crank"\nlaw = "harmonica"\nC = [0.0, 1.0, 2.0]',
    "linear_actuator": 'anc1 = "ground.P"\nanc2 = "crank.A"\nlaw = "rampa"\nC = [0.0, 1.0, 0.4, 0.5]',
}

CONTRACT_ALIASES = {"fixed": "enllac_fix", "revolute": "articulacio", "prismatic": "prismatic",
                    "pin_slot": "piu_guia", "transmission": "transmissio", "torsor": "torsor",
                    "spring": "molla_amortidor_lineal",
                    "torsional_spring": "molla_amortidor_torsional",
                    "angular_actuator": "actuador_angular", "linear_actuator": "actuador_lineal"}


def test_registry_matches_the_contract_table():
    """The contract's ten types, in its order, with their Catalan aliases; a type beyond
    them says which extension of the format adds it (``Element.extension``)."""
    assert [k for k, cls in ELEMENTS.items() if not cls.extension] == list(CONTRACT_ALIASES)
    assert {a: k for a, k in ALIASES.items() if k in CONTRACT_ALIASES} == {
        alias: kind for kind, alias in CONTRACT_ALIASES.items()}


@pytest.mark.parametrize("kind", list(CONTRACT_ALIASES))
def test_catalan_alias_loads_to_the_same_class(kind):
    english = loads(element(f'type = "{kind}"\n{ALIAS_SNIPPETS[kind]}'))
    catalan = loads(element(f'type = "{CONTRACT_ALIASES[kind]}"\n{ALIAS_SNIPPETS[kind]}'))
    a, b = english.elements[0], catalan.elements[0]
    assert type(a) is type(b) is ELEMENTS[kind]
    assert b.type == kind
    assert b.name == a.name == f"{kind}1"            # default name uses the English type name
    assert (b.anc1, b.anc2) == (a.anc1, a.anc2)
    assert {k: getattr(b, k) for k in type(b).params} == {k: getattr(a, k) for k in type(a).params}


@pytest.mark.parametrize("kind", list(CONTRACT_ALIASES))
def test_catalan_alias_in_python_api(kind):
    model = Model()
    model.add_solid("ground")
    element = model.add(CONTRACT_ALIASES[kind])
    assert type(element) is ELEMENTS[kind]
    assert element.name == f"{kind}1"


def test_default_names_count_per_type():
    text = SOLIDS + """
[[element]]
type = "fixed"
anc1 = "ground"

[[element]]
type = "revolute"
anc1 = "ground.O"
anc2 = "crank.O"

[[element]]
type = "spring"
name = "k"
anc1 = "ground.P"
anc2 = "crank.A"

[[element]]
type = "molla_amortidor_lineal"
anc1 = "ground.P"
anc2 = "crank.A"

[[element]]
type = "articulacio"
anc1 = "ground.P"
anc2 = "crank.A"

[[element]]
type = "spring"
anc1 = "ground.O"
anc2 = "crank.A"
"""
    model = loads(text)
    assert [e.name for e in model.elements] == ["fixed1", "revolute1", "k", "spring2",
                                                "revolute2", "spring3"]
    assert [e.position for e in model.elements] == [1, 2, 3, 4, 5, 6]


def test_default_names_in_python_api():
    model = Model()
    model.add_solid("ground")
    assert model.add("fixed", anc1="ground").name == "fixed1"
    assert model.add("torsor", anc1="ground").name == "torsor1"
    assert model.add("enllac_fix", anc1="ground").name == "fixed2"
    assert model.add("torsor", name="F").name == "F"
    assert model.add("torsor").name == "torsor3"
    assert [e.position for e in model.elements] == [1, 2, 3, 4, 5]


def _content(model: Model):
    """What a model says, independent of how it was built."""
    solids = [(s.name, float(s.x), float(s.y), float(s.fi), float(s.mass), float(s.inertia),
               tuple(map(float, s.cog)), {k: tuple(map(float, v)) for k, v in s.points.items()},
               {k: (tuple(map(float, v.get("point", (0, 0)))), float(v.get("angle", 0)))
                for k, v in s.lines.items()}) for s in model.solids]
    elements = [(type(e), e.name, e.anc1, e.anc2,
                 {k: getattr(e, k) for k in type(e).params}) for e in model.elements]
    return model.name, model.gravity, solids, elements, vars(model.analysis)


def test_python_api_builds_the_same_model_as_the_file():
    loaded = pam2exu.load(ROOT / "examples" / "slider_crank.toml")
    built = Model("slider-crank", gravity=9.81)
    built.add_solid("ground", points={"O": [0.0, 0.0]},
                    lines={"rail": {"point": [0.0, 0.0], "angle": 0.0}})
    built.add_solid("crank", mass=1.0, inertia=0.001, cog=[0.05, 0.0],
                    points={"O": [0.0, 0.0], "A": [0.1, 0.0]})
    built.add_solid(Solid("rod", x=0.1, fi=-0.2, mass=2.0, inertia=0.015, cog=[0.15, 0.0],
                          points={"A": [0.0, 0.0], "B": [0.3, 0.0]}))
    built.add_solid("slider", x=0.4, mass=0.5, points={"B": [0.0, 0.0]},
                    lines={"axis": {"point": [0.0, 0.0], "angle": 0.0}})
    built.add("enllac_fix", name="base", anc1="ground")
    built.add("revolute", name="O", anc1="ground.O", anc2="crank.O")
    built.add(pam2exu.Revolute(name="A", anc1="crank.A", anc2="rod.A"))
    built.add_element("articulacio", name="B", anc1="rod.B", anc2="slider.B")
    built.add("prismatic", name="guide", anc1="ground.rail", anc2="slider.axis")
    built.add("angular_actuator", name="motor", anc1="ground", anc2="crank", law="polynomial",
              C=[0.0, 10.0, 0.0, 0.0])
    built.analysis.type = "kinetostatic"
    built.analysis.t_end = 0.6283185307179586
    built.analysis.steps = 200
    built.validate()
    assert _content(built) == _content(loaded)
    assert [s.position for s in built.solids] == [s.position for s in loaded.solids]
    assert [e.position for e in built.elements] == [e.position for e in loaded.elements]
    # and both resolve to the same mechanism
    a, b = built.mechanism(), loaded.mechanism()
    assert a.nq == b.nq == 12 and a.n_equations == b.n_equations == 12
    assert [e.refs for e in a.elements] == [e.refs for e in b.elements]
    assert a.initial_q().tolist() == b.initial_q().tolist()


def test_python_api_unknown_keywords_are_model_errors():
    m = pam2exu.Model("api")
    with pytest.raises(ModelError, match="a solid has no key 'mas' \\(did you mean 'mass'\\?\\)"):
        m.add_solid("g", mas=1.0)
    with pytest.raises(ModelError, match="a revolute has no key 'anc3' \\(did you mean 'anc2'\\?\\)"):
        m.add("revolute", anc1="a.O", anc3="b.O")


def test_keys_with_an_object_are_refused_not_ignored():
    m = Model()
    with pytest.raises(TypeError, match="keys 'x' given with a Solid object"):
        m.add_solid(Solid("crank"), x=1.0)
    with pytest.raises(TypeError, match="keys 'name' given with an element object"):
        m.add(pam2exu.Revolute(anc1="ground", anc2="crank"), name="O")
    assert m.solids == [] and m.elements == []


@pytest.mark.parametrize("catalan,kind", [("ensamblatge", "assembly"),
                                          ("quasi_estatica", "quasi_static"),
                                          ("cinematica", "kinematic"),
                                          ("cinetostatica", "kinetostatic")])
def test_catalan_analysis_names_are_read_as_the_contracts(catalan, kind):
    """Extension (docs/model-format.md, "Analysis"): PAM's names of the four analyses."""
    model = loads(SOLIDS + f'\n[analysis]\ntype = "{catalan}"\n')
    assert model.analysis.type == kind and model.problems() == []
    model.analysis.type = catalan                    # set later, from Python
    assert model.problems() == [] and model.analysis.type == kind


def test_unknown_analysis_name_lists_both_spellings():
    with pytest.raises(ModelError, match=r"'cinematic' \(did you mean 'cinematica'\?\).*"
                                         r"\(Catalan: ensamblatge, quasi_estatica"):
        loads(SOLIDS + '\n[analysis]\ntype = "cinematic"\n')


# ---- values of a wrong type or out of range, names, encodings (issue 10, faults 3, 9) ------

def test_a_solid_name_that_is_not_a_string_is_a_model_error():
    """Before: "unexpected error (TypeError: unhashable type: 'list')" from model/solid.py."""
    message = only_problem(SOLIDS.replace('name = "crank"', "name = []"))
    assert message.startswith("[[solid]] #2 '[]': name must be a non-empty string, got []")


@pytest.mark.parametrize("entry, value", [
    ("x = 0.1", "x = 1e300"), ("x = 0.1", "fi = -2e7"), ("x = 0.1", "mass = 1e13"),
    ("x = 0.1", "cog = [0.0, 2e6]"), ("A = [0.1, 0.0]", "A = [1e200, 0.0]"),
    ("angle = 0.0 } }\n\n[[solid]]\nname = \"crank\"",
     "angle = 1e8 } }\n\n[[solid]]\nname = \"crank\""),
])
def test_numbers_out_of_range_are_model_errors(entry, value):
    """A length beyond 1e6 m, an angle beyond 1e7 rad or another number beyond 1e12 is a
    unit error, reported with the entry and the key (before: OverflowError, or Exudyn's
    "inertia may not be negative, but received -nan" for a cog far away)."""
    message = only_problem(SOLIDS.replace(entry, value, 1))
    assert "out of range" in message and "are the units right?" in message
    assert message.startswith("[[solid]] #")


def test_law_constants_out_of_range_are_model_errors():
    """C = 1e308 (before: "Residuals are not finite" from scipy)."""
    message = only_problem(element('type = "angular_actuator"\nanc1 = "ground"\n'
                                   'anc2 = "crank"\nC = [0.0, 1e308]'))
    assert "'C' is out of range: C2 = 1e+308" in message


def test_a_transmission_of_ratio_zero_is_a_model_error():
    """T = 0 (before: "Singular matrix" from the multipliers' solve)."""
    text = element('type = "transmission"\nanc1 = "ground"\nanc2 = "crank"\nT = 0.0\n'
                   'arm = "ground"')
    assert "T = 0 is not a gear ratio" in only_problem(text)


def test_a_spring_between_a_point_and_itself_is_a_model_error():
    """Length 0, no direction (before: NaN forces in a successful result)."""
    text = element('type = "spring"\nname = "k"\nanc1 = "crank.A"\nanc2 = "crank.A"\n'
                   'C = [1.0, 10.0]')
    assert only_problem(text) == ("[[element]] #1 'k' (spring): anc1 and anc2 are the same "
                                  "point 'crank.A': a spring of length 0 has no direction for "
                                  "its force; attach it between two different points")


@pytest.mark.parametrize("name, phrase", [
    ("x" * 101, "name is 101 characters long: at most 100 are allowed"),
    ("a\nb", "contains a control character"),
    (" crank", "starts or ends with blanks"),
    ("", "name must be a non-empty string"),
])
def test_names_must_be_usable_in_every_output(name, phrase):
    """Names reach CSV headers, messages and pictures: short, printable, trimmed."""
    m = Model("demo")
    m.add_solid(name)
    assert any(phrase in str(p) for p in m.problems())


def test_a_long_name_is_shortened_in_messages():
    m = Model("demo")
    m.add_solid("y" * 1_000_000)
    (problem,) = m.problems()
    assert len(str(problem)) < 200 and "1000000 characters long" in str(problem)


def test_a_model_name_of_a_million_characters_is_a_model_error():
    """Fuzz seed 6295: a model name of 1,000,002 characters was accepted and `draw` spent
    97 s writing it as the picture's title; the model's name has a length limit too."""
    m = Model("x" * 1_000_002)
    m.add_solid("ground")
    (problem,) = m.problems()
    assert str(problem) == ("[model]: name is 1000002 characters long: at most 200 are "
                            "allowed")
    assert not Model("x" * 200).problems() or all("name" not in str(p)
                                                    for p in Model("x" * 200).problems())


def test_outputs_that_are_not_a_list_are_a_model_error():
    """outputs = 5 (before: TypeError 'int' object is not iterable)."""
    with pytest.raises(ModelError, match=r"outputs must be a list of names or patterns"):
        loads(SOLIDS + "\n[analysis]\noutputs = 5\n")


def test_an_integer_too_large_for_a_float_is_not_a_number():
    m = Model("demo")
    m.add_solid("s", x=10**400)
    assert any("x must be a number" in str(p) for p in m.problems())


def test_a_windows_1252_file_is_read(tmp_path):
    """PAM's exports and Windows editors save Windows-1252 (before: UnicodeDecodeError)."""
    text = SOLIDS.replace('name = "crank"', 'name = "maneta_ç"') + "\n# Força\n"
    path = tmp_path / "cp1252.toml"
    path.write_bytes(text.encode("cp1252"))
    model = pam2exu.load(path)
    assert [s.name for s in model.solids] == ["ground", "maneta_ç"]
    assert model.encoding == "cp1252"
    assert pam2exu.load(ROOT / "examples" / "four_bar.toml").encoding == "utf-8"


def test_bytes_that_are_no_text_say_to_save_as_utf8(tmp_path):
    path = tmp_path / "binary.toml"
    path.write_bytes(b"[model]\nname = \"\x81\x8d\"\n")
    with pytest.raises(ModelError, match=r"not text in UTF-8 or Windows-1252 \(byte 0x81 at "
                                         r"position 16\): save it as UTF-8 text"):
        pam2exu.load(path)


def test_arrays_nested_too_deeply_are_a_model_error():
    """More levels than Python's recursion limit (before: RecursionError from tomllib).
    The depth follows the limit: a kernel run earlier in the session (test_notebook) raises
    it, and 600 levels then parse."""
    depth = sys.getrecursionlimit() + 10
    with pytest.raises(ModelError, match=r"nested too deeply"):
        loads("x = " + "[" * depth + "]" * depth)


def test_a_point_of_an_integer_too_large_for_a_float_is_reported_not_raised():
    """An anchor on a point [0, 10**400] (fuzz seed 1871: before, OverflowError from
    Scope.point while checking the element)."""
    m = Model("demo")
    m.add_solid("ground", points={"O": [0, 10**400]})
    m.add_solid("crank", points={"O": [0, 0]})
    m.add("revolute", name="O", anc1="ground.O", anc2="crank.O")
    found = [str(p) for p in m.problems()]
    assert "[[solid]] #1 'ground': point 'O' must be [x, y], got [0, " in found[0]
    assert any("point 'O' of solid 'ground' is not [x, y]" in p for p in found)


def test_solid_problems_each_value_once_in_order():
    """Numbers in range (floats, ints) say nothing, the others their problem, in the order
    of the keys, negative mass and inertia after them, then cog, points, lines."""
    from pam2exu.model.solid import solid_problems
    s = Solid("a", x=3, y=True, fi=float("nan"), mass=-1.0, inertia=-2, Dx=1e30, Dy=-5e9,
              cog=[1e9, True], points={"A": [0, 2e7], "B": (1.0, 2.0, 3.0), "C": [-1, 2]},
              lines={"l": {"point": [1e9, 0], "angle": 1e9}})
    limit = "its magnitude must be at most"
    assert solid_problems(s) == [
        "y must be a number, got True", "fi must be a number, got nan",
        f"Dx = 1e+30 m/s is out of range: {limit} 1e+12 m/s (are the units right?)",
        "mass is negative (-1.0): it must be ≥ 0", "inertia is negative (-2): it must be ≥ 0",
        "cog must be [x, y] in the local frame, got [1000000000.0, True]",
        f"point 'A' y = 2e+07 m is out of range: {limit} 1e+06 m (are the units right?)",
        "point 'B' must be [x, y], got (1.0, 2.0, 3.0)",
        f"line 'l' point x = 1e+09 m is out of range: {limit} 1e+06 m (are the units right?)",
        f"line 'l' angle = 1e+09 rad is out of range: {limit} 1e+07 rad (are the units "
        "right?)"]
    assert solid_problems(Solid("c", x=10**400, mass=-3, cog=[1, 2]), degrees=True)[1:] == [
        "mass is negative (-3): it must be ≥ 0"]

"""The clearance analysis's model input: ``clearance = true`` on joints and ``[[variation]]``.

Reference: shared/spec/clearance.md, sections "Clearance joints" and "Dimension variations"
(it extends shared/spec/model-format.md). The parameter names, units and defaults below are
copied from its tables; the law u(t) = u0 + (1 − e^(−t/τ)) (Δ/2) cos(ω t) is checked against
its closed form and a finite difference. The other analyses ignore both keys (the contract's
opening section): a kinematic run is checked to be bit-identical with and without them.
"""
from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

import pam2exu
from pam2exu import ELEMENTS, Model, ModelError, VariationWarning, loads
from pam2exu.elements import CLEARANCE_TYPES
from pam2exu.model import Variation, ramped_cosine

ROOT = Path(__file__).resolve().parents[2]
#: over-constrained (a parallelogram with a third crank): the contract's kind of mechanism
PARALLELOGRAM = (ROOT / "tests" / "data" / "parallelogram5.toml").read_text(encoding="utf-8")

#: solids with points and lines, and a revolute, a pin_slot and a prismatic using them
BASE = """
[[solid]]
name = "ground"
points = { O = [0.0, 0.0], P = [0.5, 0.0] }
lines = { rail = { point = [0.0, 0.0], angle = 0.0 } }

[[solid]]
name = "crank"
points = { O = [0.0, 0.0], A = [0.1, 0.0] }
lines = { axis = { point = [0.0, 0.0], angle = 0.0 } }

[[solid]]
name = "slider"
points = { B = [0.0, 0.0] }
lines = { axis = { point = [0.0, 0.0], angle = 0.0 } }

[[element]]
type = "revolute"
name = "O"
anc1 = "ground.O"
anc2 = "crank.O"

[[element]]
type = "pin_slot"
name = "slot"
anc1 = "ground.rail"
anc2 = "crank.A"

[[element]]
type = "prismatic"
name = "guide"
anc1 = "ground.rail"
anc2 = "slider.axis"
"""


def with_variation(*bodies: str, base: str = BASE) -> str:
    """``base`` followed by one [[variation]] table per body."""
    return base + "".join("\n[[variation]]\n" + b.strip() + "\n" for b in bodies)


def problems(text: str) -> list[str]:
    """The problems of a model that must fail, as strings (each '<where>: <message>')."""
    with pytest.raises(ModelError) as info:
        loads(text, source="m.toml")
    assert str(info.value).startswith("m.toml: ")          # the file is named
    return [str(p) for p in info.value.problems]


def only_problem(text: str) -> str:
    found = problems(text)
    assert len(found) == 1, found
    return found[0]


# ---- clearance = true ------------------------------------------------------------------

def test_clearance_parameters_are_declared_by_the_three_joint_classes():
    """The contract's table: revolute jx, jy [m]; pin_slot jn [m]; prismatic jn [m], jfi [rad]."""
    declared = {kind: [(v.name, v.unit) for v in cls.clearance_parameters]
                for kind, cls in ELEMENTS.items() if cls.clearance_parameters}
    assert declared == {"revolute": [("jx", "m"), ("jy", "m")],
                        "prismatic": [("jn", "m"), ("jfi", "rad")],
                        "pin_slot": [("jn", "m")]}
    assert set(CLEARANCE_TYPES) == set(declared)
    meanings = {kind: " ".join(v.meaning for v in ELEMENTS[kind].clearance_parameters)
                for kind in declared}
    assert "P2 − P1" in meanings["revolute"] and "global basis" in meanings["revolute"]
    assert "n1·(P2 − p1)" in meanings["pin_slot"]
    assert "n1·(p2 − p1)" in meanings["prismatic"] and "kπ" in meanings["prismatic"]


def test_clearance_defaults_to_false_and_is_read_from_toml_and_python():
    text = BASE.replace('anc2 = "crank.O"', 'anc2 = "crank.O"\nclearance = true')
    text = text.replace('anc2 = "slider.axis"', 'anc2 = "slider.axis"\nclearance = false')
    model = loads(text)
    assert [(e.name, e.clearance) for e in model.elements] == [
        ("O", True), ("slot", False), ("guide", False)]
    m = Model("python")
    assert m.add("articulacio", anc1="a.O", anc2="b.O", clearance=True).clearance is True
    assert m.add("piu_guia", anc1="a", anc2="b.O").clearance is False
    assert pam2exu.Prismatic(anc1="a", anc2="b", clearance=True).clearance is True


@pytest.mark.parametrize("kind", [k for k, cls in ELEMENTS.items()
                                  if k not in CLEARANCE_TYPES and not cls.extension])
def test_clearance_on_another_type_is_an_error_naming_the_types_that_take_it(kind):
    """Every other type of the contract: the entry is named, the three types are listed, the
    fix is said (the message is ``misplaced_clearance``'s, the same for any type)."""
    entry = {"fixed": 'anc1 = "ground"', "transmission": 'anc1 = "ground"\nanc2 = "crank"\nT = 2.0',
             "torsor": 'anc1 = "crank.A"', "spring": 'anc1 = "ground.P"\nanc2 = "crank.A"',
             "torsional_spring": 'anc1 = "ground"\nanc2 = "crank"',
             "angular_actuator": 'anc1 = "ground"\nanc2 = "crank"',
             "linear_actuator": 'anc1 = "ground.P"\nanc2 = "crank.A"\nC = [0.4]'}[kind]
    text = BASE + f'\n[[element]]\ntype = "{kind}"\nname = "e"\n{entry}\nclearance = true\n'
    if kind == "transmission":                      # its arm: ground, through revolute O
        text = text.replace('anc2 = "crank"\nT', 'anc2 = "crank"\narm = "ground"\nT')
    message = only_problem(text)
    assert message.startswith(f"[[element]] #4 'e' ({kind}): a {kind} takes no 'clearance'")
    assert "only revolute, prismatic and pin_slot joints" in message
    assert message.endswith("remove the key")
    with pytest.raises(ModelError, match=rf"a {kind} takes no 'clearance': only revolute"):
        Model().add(kind, clearance=True)


@pytest.mark.parametrize("value", ["1", '"yes"', "[true]"])
def test_clearance_must_be_a_boolean(value):
    message = only_problem(BASE.replace('anc2 = "crank.O"',
                                        f'anc2 = "crank.O"\nclearance = {value}'))
    assert message.startswith("[[element]] #1 'O' (revolute): 'clearance' must be true or false")
    m = Model()
    m.add_solid("ground", points={"O": [0, 0]})
    m.add_solid("crank", points={"O": [0, 0]})
    m.add("revolute", anc1="ground.O", anc2="crank.O", clearance="yes")
    assert [p.message for p in m.problems()] == [
        "'clearance' must be true or false (true: the joint has clearance parameters, which the "
        "clearance analysis follows; the other analyses treat the joint as ideal), got 'yes'"]


# ---- [[variation]]: reading --------------------------------------------------------------

def test_variation_defaults_are_the_contracts():
    """dx = dy = dangle = 0, w = 1 rad/s, wx = wy = wangle = w, tau = 1 s."""
    (v,) = loads(with_variation('anchor = "ground.O"')).variations
    assert (v.anchor, v.dx, v.dy, v.dangle, v.w, v.tau) == ("ground.O", 0.0, 0.0, 0.0, 1.0, 1.0)
    assert (v.wx, v.wy, v.wangle) == (None, None, None)
    assert [v.omega(c) for c in ("x", "y", "angle")] == [1.0, 1.0, 1.0]
    assert v.position == 1 and v.where == "[[variation]] #1 (anchor 'ground.O')"
    assert (v.fixed_dx, v.fixed_dy, v.fixed_dangle, v.has_fixed) == (0.0, 0.0, 0.0, False)


def test_fixed_deviations_add_to_the_ramped_cosine_reached_on_the_straight_path():
    """u(t) − u0 = s δ + (1 − e^(−t/τ)) (Δ/2) cos(ω t), s = 1 unless given (extension:
    docs/clearance.md, 'Parts as made')."""
    (v,) = loads(with_variation('anchor = "ground.rail"\nfixed_dx = 3e-4\nfixed_dangle = -0.02'
                                '\ndy = 4e-3\nw = 2.0\ntau = 0.5')).variations
    t = np.array([0.0, 0.7])
    u, du = v.offsets(t)
    ramp = -np.expm1(-t / 0.5) * 2e-3 * np.cos(2.0 * t)
    np.testing.assert_allclose(u, np.column_stack([[3e-4] * 2, ramp, [-0.02] * 2]),
                               rtol=1e-15, atol=0)
    assert u[0].tolist() == [3e-4, 0.0, -0.02] and v.has_fixed
    half, _ = v.offsets(t, reached=0.5)
    np.testing.assert_allclose(half[0], [1.5e-4, 0.0, -0.01], rtol=1e-15, atol=0)
    assert du[:, 0].tolist() == [0.0, 0.0]            # a fixed deviation does not move


def test_variation_keys_from_toml_and_from_python_agree():
    body = ('anchor = "ground.rail"\ndx = 3.7e-4\ndy = -2.9e-4\ndangle = 0.01\nw = 2.0\n'
            'wx = 1.91\nwy = 0.57\ntau = 0.5')
    (read,) = loads(with_variation('anchor = "ground.O"\ndx = 1e-3', body)).variations[1:]
    m = Model("python")
    first = m.add_variation(anchor="ground.O", dx=1e-3)
    built = m.add_variation("ground.rail", dx=3.7e-4, dy=-2.9e-4, dangle=0.01, w=2.0, wx=1.91,
                            wy=0.57, tau=0.5)
    assert (first.position, built.position, read.position) == (1, 2, 2)
    assert repr(built) == repr(read)
    assert [read.omega(c) for c in ("x", "y", "angle")] == [1.91, 0.57, 2.0]
    assert m.variations == [first, built]
    given = Variation("ground.P", dy=1e-3)
    assert m.add_variation(given) is given and given.position == 3


def test_add_variation_rejects_an_unknown_key_at_once_suggesting_the_nearest():
    with pytest.raises(ModelError, match=r"a variation has no key 'tua' \(did you mean 'tau'\?\); "
                                         r"its keys are: anchor, dx, dy, dangle, w, wx, wy, "
                                         r"wangle, tau"):
        Model().add_variation("ground.O", tua=1.0)
    with pytest.raises(TypeError, match="keys given with a Variation"):
        Model().add_variation(Variation("ground.O"), dx=1.0)


def test_mechanism_binds_each_variation_to_its_point_or_line():
    """kind, ref, nominal u0, and the lookup by element anchor the analysis uses."""
    text = with_variation('anchor = "crank.A"\ndy = 2e-3', 'anchor = "ground.rail"\ndangle = 0.1')
    text = text.replace('A = [0.1, 0.0]', 'A = [0.1, 0.02]')
    mech = loads(text).mechanism()
    point, line = mech.variations
    assert (point.kind, point.nominal, line.kind, line.nominal) == (
        "point", (0.1, 0.02, 0.0), "line", (0.0, 0.0, 0.0))
    revolute, slot, guide = mech.elements
    assert mech.variation(slot, 1) is point and mech.variation(slot, 0) is line
    assert mech.variation(guide, 0) is line and mech.variation(guide, 1) is None
    assert mech.variation(revolute, 0) is None
    assert loads(text).variations[0] is not point               # the model's stay unbound


# ---- the law ----------------------------------------------------------------------------

@pytest.mark.parametrize("delta, omega, tau", [(3.7e-4, 1.91, 1.0), (-2.9e-4, 0.57, 0.3),
                                               (0.02, 0.0, 2.5), (1.0, -4.0, 1e-3)])
def test_law_against_its_closed_form(delta, omega, tau):
    """u − u0 = (1 − e^(−t/τ)) (Δ/2) cos(ω t); u' by the product rule, written out here."""
    t = np.linspace(0.0, 10.0, 101)
    u, du = ramped_cosine(t, delta, omega, tau)
    for k, tk in enumerate(t):
        ramp, decay = 1 - math.exp(-tk / tau), math.exp(-tk / tau)
        assert u[k] == pytest.approx(ramp * delta / 2 * math.cos(omega * tk), rel=1e-13, abs=1e-18)
        assert du[k] == pytest.approx(delta / 2 * (decay / tau * math.cos(omega * tk)
                                                   - ramp * omega * math.sin(omega * tk)),
                                      rel=1e-12, abs=1e-15 * abs(delta) / tau)
    assert u[0] == 0.0 and du[0] == pytest.approx(delta / (2 * tau))     # u(0) = u0


def test_law_derivative_against_a_central_difference():
    """(u(t + h) − u(t − h)) / 2h = u'(t) + O(h²): with h = 1e-5 s, to ~1e-9 of Δ."""
    delta, omega, tau, h = 3.7e-4, 1.91, 0.7, 1e-5
    t = np.linspace(h, 9.66643893412244, 400)
    ahead, behind = (ramped_cosine(t + s, delta, omega, tau)[0] for s in (h, -h))
    fd = (ahead - behind) / (2 * h)
    assert np.max(np.abs(fd - ramped_cosine(t, delta, omega, tau)[1])) < 1e-9 * delta


def test_variation_offsets_per_component():
    """Columns x, y, angle, each with its own Δ and ω; a scalar t gives one row."""
    v = Variation("ground.rail", dx=2e-3, dangle=-0.05, w=3.0, wx=0.5, tau=0.8)
    t = np.array([0.0, 0.4, 2.0])
    u, du = v.offsets(t)
    assert u.shape == du.shape == (3, 3)
    for col, (delta, omega) in enumerate([(2e-3, 0.5), (0.0, 3.0), (-0.05, 3.0)]):
        expected = ramped_cosine(t, delta, omega, 0.8)
        np.testing.assert_array_equal(u[:, col], expected[0])
        np.testing.assert_array_equal(du[:, col], expected[1])
    assert v.offsets(0.4)[0].shape == (1, 3)


# ---- [[variation]]: errors ---------------------------------------------------------------

def test_unknown_key_suggests_the_closest():
    message = only_problem(with_variation('anchor = "ground.O"\ntua = 1.0'))
    assert message.startswith("[[variation]] #1 (anchor 'ground.O'): unknown key 'tua' "
                              "(did you mean 'tau'?); allowed keys: anchor, dx, dy, dangle, w, ")


def test_a_point_varied_twice_names_the_first_entry():
    message = only_problem(with_variation('anchor = "ground.O"\ndx = 1e-3',
                                          'anchor = "crank.A"', 'anchor = "ground.O"\ndy = 1e-3'))
    assert message == ("[[variation]] #3 (anchor 'ground.O'): point 'ground.O' is already "
                       "varied by [[variation]] #1 (anchor 'ground.O'): put both changes in "
                       "one entry")


def test_a_line_varied_twice():
    message = only_problem(with_variation('anchor = "ground.rail"', 'anchor = "ground.rail"'))
    assert "line 'ground.rail' is already varied by [[variation]] #1" in message


@pytest.mark.parametrize("key", ["dangle", "wangle", "fixed_dangle"])
def test_an_angle_on_a_point(key):
    message = only_problem(with_variation(f'anchor = "crank.A"\n{key} = 0.1'))
    assert message == (f"[[variation]] #1 (anchor 'crank.A'): '{key}' varies a line's angle, "
                       f"and 'crank.A' is a point: remove '{key}', or vary a line")


@pytest.mark.parametrize("tau", ["0.0", "-1.0"])
def test_tau_must_be_positive(tau):
    message = only_problem(with_variation(f'anchor = "ground.O"\ntau = {tau}'))
    assert message.startswith("[[variation]] #1 (anchor 'ground.O'): 'tau' = ")
    assert "the time constant of the ramp must be > 0" in message


def test_a_bare_solid_is_an_error_listing_its_points_and_lines():
    message = only_problem(with_variation('anchor = "crank"'))
    assert message == ("[[variation]] #1 (anchor 'crank'): anchor 'crank' is a bare solid: a "
                       "variation changes a declared point or line, name it as \"solid.point\" "
                       "or \"solid.line\" (the points and lines of 'crank': 'crank.O', "
                       "'crank.A', 'crank.axis')")


@pytest.mark.parametrize("anchor, words", [
    ("crank.AA", "solid 'crank' has no point or line 'AA' (did you mean 'A'?); its points and "
                 "lines: 'crank.O', 'crank.A', 'crank.axis'"),
    ("crnk.A", "no solid 'crnk' (did you mean 'crank'?)")])
def test_an_anchor_that_does_not_exist(anchor, words):
    assert only_problem(with_variation(f'anchor = "{anchor}"')) == (
        f"[[variation]] #1 (anchor '{anchor}'): anchor '{anchor}': {words}")


def test_a_missing_or_non_text_anchor():
    assert only_problem(with_variation("dx = 1e-3")) == (
        "[[variation]] #1: 'anchor' is missing: name the point or line to vary, "
        "\"solid.point\" or \"solid.line\"")
    assert "'anchor' must be \"solid.point\" or \"solid.line\", got 3" in only_problem(
        with_variation("anchor = 3"))


def test_a_point_and_a_line_of_one_name_are_ambiguous():
    text = with_variation('anchor = "crank.A"').replace("axis = {", "A = {", 1)
    assert "solid 'crank' has a point and a line named 'A': rename one" in only_problem(text)


def test_non_numbers_are_errors_each_named():
    found = problems(with_variation('anchor = "ground.O"\ndx = "1e-3"\nw = true\nwy = [1.0]'))
    where = "[[variation]] #1 (anchor 'ground.O'): "
    assert found == [where + "'dx' must be a number [m], got '1e-3'",
                     where + "'w' must be a number [rad/s], got True",
                     where + "'wy' must be a number [rad/s], got [1.0]"]
    assert "'tau' must be a number of seconds, got 'x'" in only_problem(
        with_variation('anchor = "ground.O"\ntau = "x"'))


@pytest.mark.parametrize("entry, words", [
    ("dx = 2e6", "'dx' = 2e+06 m is out of range: its magnitude must be at most 1e+06 m"),
    ("dangle = 1e8", "'dangle' = 1e+08 rad is out of range"),
    ("fixed_dy = -2e6", "'fixed_dy' = -2e+06 m is out of range: its magnitude must be at most"),
    ("fixed_dangle = 1e8", "'fixed_dangle' = 1e+08 rad is out of range"),
    ("w = -1e13", "'w' = -1e+13 rad/s is out of range"),
    ("tau = 1e10", "'tau' = 1e+10 s is out of range: it must lie between 1e-09 s and 1e+09 s")])
def test_numbers_out_of_the_ranges_of_limits(entry, words):
    anchor = "ground.rail" if "angle" in entry else "ground.O"
    assert words in only_problem(with_variation(f'anchor = "{anchor}"\n{entry}'))


def test_every_problem_is_reported_at_once_and_python_models_too():
    """Nothing is half-written: the loader collects the variation problems with the rest."""
    text = with_variation('anchor = "crank"', 'anchor = "ground.O"\ntau = 0')
    text = text.replace('type = "pin_slot"', 'type = "pin_slot"\nclearance = 2')
    found = problems(text)
    assert [p.split(":")[0] for p in found] == [
        "[[element]] #2 'slot' (pin_slot)", "[[variation]] #1 (anchor 'crank')",
        "[[variation]] #2 (anchor 'ground.O')"]
    m = Model("python")
    m.add_solid("ground", points={"O": [0, 0]})
    m.add_variation("ground.O", dangle=0.1)
    with pytest.raises(ModelError, match=r"\[\[variation\]\] #1 \(anchor 'ground.O'\): 'dangle' "
                                         r"varies a line's angle"):
        m.mechanism()


# ---- [[variation]]: the unused-anchor warning --------------------------------------------

def test_an_unused_point_is_allowed_with_a_warning_issued_once():
    """ground.P is anchored by no element: no effect, a VariationWarning (not an error)."""
    text = with_variation('anchor = "ground.O"', 'anchor = "ground.P"\ndy = 1e-3')
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        model = loads(text, source="m.toml")
        model.mechanism()                    # validated again: not issued a second time
    assert [(w.category, str(w.message)) for w in caught] == [(
        VariationWarning, "m.toml: [[variation]] #2 (anchor 'ground.P'): no constraint element "
                          "anchors the point 'ground.P': the variation has no effect")]
    assert caught[0].filename == __file__                # at the caller's line
    assert [str(p) for p in model.warnings()] == [str(caught[0].message).removeprefix("m.toml: ")]


def test_a_point_only_a_force_element_uses_is_unused():
    """A spring is no constraint: its point is not in the closure equations."""
    text = with_variation('anchor = "ground.P"') + (
        '\n[[element]]\ntype = "spring"\nanc1 = "ground.P"\nanc2 = "crank.A"\n')
    with pytest.warns(VariationWarning, match="'ground.P': the variation has no effect"):
        loads(text)


def test_python_models_warn_when_validated():
    m = Model("python")
    m.add_solid("ground", points={"O": [0, 0], "Q": [1, 0]})
    m.add_variation("ground.Q", dx=1e-3)
    with pytest.warns(VariationWarning, match=r"^\[\[variation\]\] #1 \(anchor 'ground.Q'\)"):
        m.validate()


# ---- the other analyses ignore both keys -------------------------------------------------

def test_clearance_is_an_analysis_type():
    """[analysis] type = "clearance" (shared/spec/clearance.md) is read like the others."""
    model = loads(PARALLELOGRAM.replace('type = "kinematic"', 'type = "clearance"'))
    assert model.analysis.type == "clearance"


def test_kinematic_run_is_unchanged_by_clearance_and_variations():
    """The over-constrained parallelogram, with two clearance pins and two varied anchors,
    gives a kinematic run bit-identical to the file without them (same columns, warnings)."""
    varied = PARALLELOGRAM.replace('anc2 = "coupler.A2"', 'anc2 = "coupler.A2"\nclearance = true')
    varied = varied.replace('anc2 = "coupler.A3"', 'anc2 = "coupler.A3"\nclearance = true')
    varied = varied.replace("[analysis]", '[[variation]]\nanchor = "ground.O2"\ndx = 3.7e-4\n'
                            'dy = -2.9e-4\nwx = 1.91\nwy = 0.57\n\n[[variation]]\n'
                            'anchor = "crank3.A"\ndx = 1e-3\ntau = 0.2\n\n[analysis]')
    plain, model = loads(PARALLELOGRAM), loads(varied)
    assert len(model.variations) == 2 and sum(e.clearance for e in model.elements) == 2
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        a = pam2exu.run(plain, steps=40)
        b = pam2exu.run(model, steps=40)
    assert a.columns == b.columns and a.warnings == b.warnings
    np.testing.assert_array_equal(a.to_numpy(), b.to_numpy())

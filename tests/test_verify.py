"""``pam2exu verify`` and ``pam2exu.verify``: one analysis on two backends, compared within the
tolerance of ``pam2exu.verify.Rule``.

References: the rule's formula (docs/verify.md); a mistranslation whose size is known (an
angular actuator's angle shifted by DELTA in the Exudyn model only), which moves the crank by
exactly DELTA and every point of it by DELTA times its distance from the pivot.
"""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import pam2exu
from pam2exu.cli import main
from pam2exu.elements.actuators import AngularActuator
from pam2exu.registry import ANALYSES, BACKENDS
from pam2exu.results import Results
from pam2exu.verify import FLOOR, SAFETY, Rule, agreement, verify

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = sorted((ROOT / "examples").glob("*.toml")) + [ROOT / "tests/data/parallelogram5.toml"]
#: the second backend verified against exudyn (exudyn itself until another is registered)
OTHER = next((b for b in BACKENDS if b != "exudyn"), "exudyn")
#: the mistranslation: a shift of the actuator's angle below the residual self-check's
#: tolerance (1e-8 × L = 4e-9 for the four-bar), so that every self-check passes
DELTA = 1e-9


#: the clearance analysis's refusal of a self-stress without clearance (condition (i))
CONDITION_I = (r"^t=0: the clearance analysis of .* cannot start: the elements .* "
               r"\(condition \(i\): a self-stress")


def quiet_verify(*args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")        # parallelogram5: redundant constraints
        return verify(*args, **kwargs)


# ---- the rule ----------------------------------------------------------------------------

def test_rule_formula():
    """rtol_p = max(FLOOR, SAFETY · max tol · κ^p), S_u = family scale · L^k."""
    rule = Rule({"a": 1e-13, "b": 1e-11}, condition=10.0, length=0.5,
                scales={"position": 1.0, "velocity": 4.0, "force": 30.0})
    assert rule.rtol("position") == pytest.approx(SAFETY * 1e-11 * 10)            # 1e-8
    assert rule.rtol("velocity") == rule.rtol("force") == pytest.approx(SAFETY * 1e-11 * 100)
    assert (rule.scale("m"), rule.scale("rad")) == (0.5, 1.0)
    assert (rule.scale("m/s"), rule.scale("rad/s")) == (2.0, 4.0)
    assert (rule.scale("N"), rule.scale("N·m")) == (30.0, 15.0)
    assert rule.allowed("m/s", 123.0) == pytest.approx(1e-7 * 2.0)
    assert rule.allowed("", 3.0) == pytest.approx(1e-7 * 3.0)      # unknown unit: own scale
    tight = Rule({"a": 1e-13}, condition=2.0, length=0.5, scales={"position": 1.0})
    assert tight.rtol("position") == tight.rtol("force") == FLOOR


def test_rule_numbers_of_the_four_bar():
    """κ = 3.28 over the motion (the run's own ConditionWarning figure), L = 0.4 m: positions
    at the floor, the others 100 · 1e-13 · κ²; S of rad/s is the crank's 2π rad/s, of m/s
    that times L, of rad/s² ω² = (2π)² (above the rocker's largest 20.5 rad/s²)."""
    v = quiet_verify(ROOT / "examples/four_bar.toml", backends=("exudyn", OTHER))
    rule = v.rule
    assert rule.length == 0.4 and rule.condition == pytest.approx(3.2804, abs=1e-3)
    assert rule.rtol("position") == 1e-10
    assert rule.rtol("velocity") == pytest.approx(1e-11 * 3.2804 ** 2, rel=1e-3)
    assert rule.scale("rad/s") == pytest.approx(2 * np.pi)
    assert rule.scale("m/s") == pytest.approx(0.4 * 2 * np.pi)
    assert rule.scale("rad/s²") == pytest.approx((2 * np.pi) ** 2)
    assert v.comparison["rocker.DDfi"].scale == pytest.approx(20.5, rel=1e-2)
    assert v.comparison["crank.fi"].tolerance == 1e-10
    assert v.comparison["coupler.x"].tolerance == pytest.approx(4e-11)
    text = str(v)
    assert "rtol = max(1e-10, 100 · 1e-13 · κ^p)" in text
    assert "worst condition number κ = 3.28" in text


def _perturbed(res: Results, name: str, amount: float) -> Results:
    columns = {c: res[c].copy() for c in res.columns}
    columns[name][len(res) // 2] += amount
    return Results(res.t, columns, res.units, res.analysis, res.model)


@pytest.mark.parametrize("model, analysis", [("four_bar.toml", "kinematic"),
                                             ("slider_crank.toml", "kinetostatic"),
                                             ("all_elements.toml", "kinetostatic")])
def test_a_relative_error_of_1e_6_is_caught(model, analysis):
    """Every variable whose scale is at least 1e-3 of its unit's: an error of 1e-6 of its
    scale at one row fails it, and it alone (the rule's rtol is at most 7.4e-10 here)."""
    v = quiet_verify(ROOT / "examples" / model, analysis=analysis, backends=("exudyn", OTHER))
    assert max(v.rule.rtol(f) for f in ("position", "velocity", "force")) < 1e-9
    checked = 0
    for row in v.comparison.rows:
        if row.scale < 1e-3 * v.rule.scale(row.unit):
            continue
        bad = agreement(_perturbed(v.result, row.name, 1e-6 * row.scale), v.reference,
                        v.rule, v.backends)
        assert bad.failed == [row.name]
        assert bad[row.name].max_abs_error == pytest.approx(1e-6 * row.scale, rel=1e-3)
        checked += 1
    assert checked >= 15


# ---- shipped examples agree -----------------------------------------------------------

@pytest.mark.parametrize("analysis", list(ANALYSES))
@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: p.name)
def test_every_shipped_example_agrees(path, analysis, request):
    """The clearance runs over their whole second take 5 to 35 s each on two cores: their
    first 0.1 s here (tests/backend/test_natural.py holds the two backends' whole clearance
    runs of four_bar, slider_crank and scotch_yoke against each other at 1e-9), the whole
    runs with --long."""
    if analysis == "clearance" and path.stem == "parallelogram5":
        # over-constrained without a clearance joint: refused (condition (i)), not compared
        with pytest.raises(pam2exu.ModelError, match=CONDITION_I):
            quiet_verify(path, analysis=analysis, backends=("exudyn", OTHER))
        return
    settings = {}
    if analysis == "clearance" and not request.config.getoption("--long"):
        settings = {"t_end": 0.1, "steps": 10}
    v = quiet_verify(path, analysis=analysis, backends=("exudyn", OTHER), **settings)
    assert v.ok, str(v)
    assert v.differing == [] and v.verdict().startswith("AGREE")
    assert len(v.comparison.rows) == len(v.reference.columns) > 0
    worst = max(r.max_abs_error / r.tolerance for r in v.comparison.rows if r.tolerance)
    assert worst < 0.01                 # the examples agree with a margin of 100 at least
    assert all(r.tolerance > 0 or r.max_abs_error == 0 for r in v.comparison.rows)


#: a free crank held by a spring: the equilibrium analysis (docs/analyses.md)
EQUILIBRIUM = ROOT / "examples/equilibrium/spring_four_bar.toml"


def test_the_equilibrium_example_agrees_with_the_static_rule():
    """Both backends descend to the same equilibrium (Exudyn's static solver, Newton on the
    natural coordinates' equilibrium), held to the rule of the static analyses (no
    integration term). Measured: crank.fi 7.3e-13 rad, B.Fx 1.7e-11 N, worst 0.0073 of
    the tolerance."""
    v = quiet_verify(EQUILIBRIUM, backends=("exudyn", OTHER))
    assert v.reference.analysis == v.result.analysis == "equilibrium"
    assert v.rule.integration == 0.0
    assert v.ok, str(v)
    assert {"crank.fi", "spring.Força", "O2.Fx"} <= {r.name for r in v.comparison.rows}
    worst = max(r.max_abs_error / r.tolerance for r in v.comparison.rows if r.tolerance)
    assert worst < 0.05


def test_cli_verify_equilibrium_exits_0(capsys):
    assert main(["verify", str(EQUILIBRIUM)]) == 0
    out = capsys.readouterr().out
    assert "the equilibrium analysis of 'four-bar held by a spring'" in out
    assert out.rstrip().splitlines()[-1] == (f"AGREE: {OTHER} and exudyn agree on all 25 "
                                             "variables within the tolerance")


def test_the_same_backend_twice_gives_no_difference():
    v = quiet_verify(ROOT / "examples/slider_crank.toml", steps=20, backends=("exudyn",) * 2)
    assert v.ok and {r.max_abs_error for r in v.comparison.rows} == {0.0}


def test_a_model_that_does_not_assemble_names_the_backend():
    with pytest.raises(pam2exu.SolverError, match=r"^exudyn backend: the constraints of"):
        verify(ROOT / "tests/data/every_element.toml", backends=("exudyn", OTHER))


def test_unknown_backend_is_a_model_error():
    with pytest.raises(pam2exu.ModelError, match="did you mean 'exudyn'"):
        verify(ROOT / "examples/four_bar.toml", backends=("exudyn", "exudin"))


# ---- a mistranslated model -------------------------------------------------------------

@pytest.fixture
def mistranslated(monkeypatch):
    """The Exudyn translation of the angular actuator 'motor' off by DELTA rad (its angle
    offset), the natural backend's untouched: a wrong translation that every self-check of
    the Exudyn run lets through (its constraint residual, DELTA, is below 1e-8 · L)."""
    build = AngularActuator.build

    def shifted(self, ex):
        if self.name != "motor":
            return build(self, ex)
        real = ex.coordinate_shift
        ex.coordinate_shift = lambda solid, k: real(solid, k) + (
            DELTA if solid == self.ref1.solid and k == 2 else 0.0)
        try:
            build(self, ex)
        finally:
            del ex.coordinate_shift

    monkeypatch.setattr(AngularActuator, "build", shifted)
    if OTHER == "exudyn":               # no second backend yet: a patched copy of Exudyn
        pytest.skip("needs a second backend that does not use the Exudyn translation")
    return ROOT / "examples/four_bar.toml"


def test_mistranslation_passes_the_self_checks(mistranslated):
    """No error, no warning: the residual is DELTA (< 1e-8 · 0.4 m), Exudyn's multipliers
    meet the native equilibrium, the power balance holds."""
    runs = {}
    for analysis in ("quasi_static", "kinetostatic"):
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            runs[analysis] = pam2exu.run(mistranslated, analysis=analysis, backend="exudyn")
        assert runs[analysis].warnings == []
        assert runs[analysis].info["max_residual"] == pytest.approx(DELTA, rel=1e-3)
    assert runs["quasi_static"].info["equilibrium_error"] < 1e-9
    info = runs["kinetostatic"].info
    assert info["power_balance_error"] <= info["power_balance_tolerance"]


def test_verify_finds_the_mistranslation(mistranslated):
    """The crank turns DELTA too far: crank.fi is off by DELTA, the coupler's origin (the
    crank's point A, 0.1 m from the pivot) by 0.1 · DELTA, 2.5 and 1 times its tolerance;
    the ground and the law f(t) itself are not off."""
    v = verify(mistranslated, backends=("exudyn", OTHER))
    assert not v.ok and v.verdict().startswith("DISAGREE")
    c = v.comparison
    assert c["crank.fi"].max_abs_error == pytest.approx(DELTA, rel=1e-3)
    assert c["crank.fi"].tolerance == 1e-10
    assert np.hypot(c["coupler.x"].max_abs_error, c["coupler.y"].max_abs_error) \
        == pytest.approx(0.1 * DELTA, rel=0.5)
    for name in ("crank.fi", "coupler.fi", "rocker.fi", "rocker.Dfi", "coupler.DDfi"):
        assert name in v.differing
    for name in ("ground.x", "ground.fi", "motor.f(t)", "motor.Df(t)"):
        assert c[name].passed and c[name].max_abs_error < 1e-12
    assert "rocker.Dfi" in v.verdict() and "crank.fi" in v.verdict()


def test_verify_finds_the_mistranslation_in_the_forces(mistranslated):
    """quasi_static: the static reactions at the shifted positions differ too."""
    v = verify(mistranslated, analysis="quasi_static", backends=("exudyn", OTHER))
    assert {"crank.fi", "motor.Mz"} <= set(v.differing)
    assert v.comparison["motor.Mz"].max_abs_error > v.comparison["motor.Mz"].tolerance


# ---- the command line ---------------------------------------------------------------------

def test_cli_prints_the_table_and_exits_0(capsys):
    code = main(["verify", str(ROOT / "examples/slider_crank.toml"), "--steps", "20",
                 "--against", OTHER])
    out = capsys.readouterr().out
    assert code == 0
    assert f"{OTHER} (result) against exudyn (reference)" in out
    assert "| variable | unit | max abs error | max rel error | at t [s] | scale | tolerance" \
        in out
    assert "| motor.Mz | N·m |" in out
    assert out.rstrip().splitlines()[-1] == (f"AGREE: {OTHER} and exudyn agree on all 50 "
                                             f"variables within the tolerance")


def test_cli_mistranslation_exits_1_and_names_the_variables(mistranslated, capsys):
    assert main(["verify", str(mistranslated), "-a", "kinematic", "--steps", "40"]) == 1
    out = capsys.readouterr().out
    last = out.rstrip().splitlines()[-1]
    assert last.startswith(f"DISAGREE: {OTHER} and exudyn differ on ")
    assert "crank.fi" in last and "rocker.fi" in last
    row = next(line for line in out.splitlines() if line.startswith("| crank.fi |"))
    assert row.split("|")[3].strip() == "1e-09" and row.rstrip().endswith("| FAIL |")


def test_cli_bad_input_exits_2(capsys, tmp_path):
    assert main(["verify", str(ROOT / "examples/four_bar.toml"), "--against", "exudin"]) == 2
    assert "did you mean 'exudyn'" in capsys.readouterr().err
    assert main(["verify", str(tmp_path / "missing.toml")]) == 2
    assert main(["verify", str(ROOT / "examples/four_bar.toml"), "--steps", "0"]) == 2


def test_cli_solver_failure_exits_1(capsys):
    assert main(["verify", str(ROOT / "tests/data/every_element.toml")]) == 1
    assert "solver failure: exudyn backend: " in capsys.readouterr().err


# ---- a mistranslation on the natural side: its own velocity terms ------------------------

#: the natural translation of the motor's law with f' off by this (relative): positions
#: and every position check are untouched, the rates the natural backend computes are not
SKEW = 1e-6


class SkewedLaw(pam2exu.Law):
    """The law with its first derivative scaled by 1 + SKEW (f and f'' exact)."""

    def __call__(self, t, xp=np):
        f, df, ddf = super().__call__(t, xp)
        return f, df * (1 + SKEW), ddf


@pytest.fixture
def natural_rates_off(monkeypatch):
    """AngularActuator.natural declares its law as SkewedLaw: the natural backend's Φ_z ż = g'
    sees ḟ·(1 + SKEW); its positions (f exact) and pam2exu's residual check still hold."""
    def skewed(self, nc):
        law = self.time_law()
        nc.equation(self, [nc.angle(self.ref2.solid) - nc.angle(self.ref1.solid)],
                    SkewedLaw(law.name, law.C))
    monkeypatch.setattr(AngularActuator, "natural", skewed)
    return ROOT / "examples" / "four_bar.toml"


@pytest.mark.skipif("natural" not in BACKENDS, reason="needs the natural backend")
def test_verify_finds_a_natural_side_mistranslation_in_the_rates(natural_rates_off, capsys):
    """The crank's Dfi is 2π·SKEW off (the motor turns at 2π rad/s), the other solids' rates
    in proportion; positions agree. verify exits 1 and names the rate columns, not x, y, fi."""
    found = quiet_verify(natural_rates_off, analysis="kinematic", steps=40)
    assert not found.ok
    assert "crank.Dfi" in found.differing
    assert not any(name.split(".")[1] in ("x", "y", "fi") for name in found.differing)
    assert main(["verify", str(natural_rates_off), "-a", "kinematic", "--steps", "40"]) == 1
    last = capsys.readouterr().out.rstrip().splitlines()[-1]
    assert last.startswith("DISAGREE") and "crank.Dfi" in last

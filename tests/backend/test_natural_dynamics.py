"""The dynamic analysis on the natural backend (backend/natural/dynamics.py): the equations
of motion M z̈ + Φ_zᵀ μ = Q, Φ = 0 in natural coordinates, integrated by DOP853 with
projections to the tolerance.

References, each computed here without pam2exu's code: scipy's DOP853 (rtol 1e-13) on the
one-DOF equations of a free compound pendulum (I_O θ̈ = −m g d cos θ), of the same with a
torsional spring-damper at its pivot (− k (θ − θ0) − c θ̇), and of a pendulum hanging from a
slider driven by bezier_c2 (I_O θ̈ = m d sin θ ẍ_s − m g d cos θ); the energy T + V of the
free four-bar from the result columns; and the Exudyn backend's integration of the same
models (``pam2exu.verify``: two integrations within the verify rule, docs/verify.md).
"""
import math
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import pam2exu
from pam2exu.cli import main
from pam2exu.laws import Law

from references.pendulum import D, G, IO, M, pendulum_toml, reference, slider_toml
from tests.conftest import Terminal

ROOT = Path(__file__).resolve().parents[2]
FOUR_BAR = ROOT / "examples/equilibrium/spring_four_bar.toml"


def pendulum(fi, dfi=0.0, dx=0.0):
    return pam2exu.loads(pendulum_toml(fi, dfi, dx))


def _run(model, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return pam2exu.run(model, backend="natural", **kw)


def _within(value, ref, tolerance):
    """Largest |value − ref| / (tolerance (1 + |ref|)): at most 1 passes."""
    return float(np.max(np.abs(value - ref) / (tolerance * (1 + np.abs(ref)))))


@pytest.mark.parametrize("tolerance", [1e-6, 1e-8, 1e-10])
def test_free_pendulum_against_its_one_dof_equation(tolerance):
    """Every row within tolerance (1 + |value|) of DOP853 on θ̈ = −m g d cos θ / I_O
    (measured at 1e-8: θ 6.9e-11, θ̇ 1.2e-10 relative), the estimate below the tolerance,
    θ̈ from the equation and the pivot on the ground."""
    res = _run(pendulum(0.3), t_end=2.0, steps=50, tolerance=tolerance)
    ref = solve_ivp(lambda t, y: [y[1], -M * G * D * math.cos(y[0]) / IO], (0, 2.0),
                    [0.3, 0.0], method="DOP853", rtol=1e-13, atol=1e-14, t_eval=res.t)
    assert res.info["integration_error"] <= tolerance
    assert _within(res["lever.fi"], ref.y[0], tolerance) <= 1
    assert _within(res["lever.Dfi"], ref.y[1], tolerance) <= 1
    th = res["lever.fi"]
    np.testing.assert_allclose(res["lever.DDfi"], -M * G * D * np.cos(th) / IO, atol=1e-12)
    np.testing.assert_allclose(res["lever.x"], 0.0, atol=1e-12)
    assert np.ptp(th) > 3                                          # it swung


def test_torsional_spring_damper_at_the_pivot():
    """C4 of a torsional spring-damper (ground, lever) brakes the natural integration as
    I_O θ̈ = −m g d cos θ − k (θ − θ0) − c θ̇ says (the dampers see the rates)."""
    k, theta0, c = 3.0, -1.0, 0.4
    text = pendulum_toml(0.3, elements=f"""
[[element]]
type = "torsional_spring"
name = "hinge_spring"
anc1 = "ground"
anc2 = "lever"
C = [0.0, {k}, {theta0}, {c}]
""")
    tolerance = 1e-8
    res = _run(pam2exu.loads(text), t_end=1.5, steps=30, tolerance=tolerance)

    def rhs(t, y):
        return [y[1], (-M * G * D * math.cos(y[0]) - k * (y[0] - theta0) - c * y[1]) / IO]

    ref = solve_ivp(rhs, (0, 1.5), [0.3, 0.0], method="DOP853", rtol=1e-13, atol=1e-14,
                    t_eval=res.t)
    assert _within(res["lever.fi"], ref.y[0], tolerance) <= 1
    assert _within(res["lever.Dfi"], ref.y[1], tolerance) <= 1


def test_pendulum_on_a_driven_slider_against_its_one_dof_equation():
    """The actuator's law drives the distance equation (f, f', f'' from the law): the slider
    follows it exactly, the lever its one-DOF equation within the tolerance."""
    law = Law("bezier_c2", [0.2, 0.7, 0.5, 0.9])
    tolerance = 1e-8
    res = _run(pam2exu.loads(slider_toml()), tolerance=tolerance)
    ref = reference(res.t, (-1.2, 0.0), lambda t: law(np.array([t]))[2][0])
    np.testing.assert_allclose(res["slider.x"], law(res.t)[0], atol=1e-12)
    np.testing.assert_allclose(res["slider.Dx"], law(res.t)[1], atol=1e-12)
    assert _within(res["lever.fi"], ref[0], tolerance) <= 1
    assert _within(res["lever.Dfi"], ref[1], tolerance) <= 1


def test_radau_when_dop853_takes_too_many_steps(monkeypatch):
    """A run of DOP853 beyond STIFF_STEPS steps (a stiff model) goes on with Radau, to the
    same tolerance (forced here on the pendulum)."""
    import pam2exu.backend.natural.dynamics as nd
    monkeypatch.setattr(nd, "STIFF_STEPS", 5)
    res = _run(pendulum(0.3), t_end=1.0, steps=20, tolerance=1e-6)
    ref = solve_ivp(lambda t, y: [y[1], -M * G * D * math.cos(y[0]) / IO], (0, 1.0),
                    [0.3, 0.0], method="DOP853", rtol=1e-13, atol=1e-14, t_eval=res.t)
    assert _within(res["lever.fi"], ref.y[0], 1e-6) <= 1
    assert _within(res["lever.Dfi"], ref.y[1], 1e-6) <= 1


def test_an_interval_far_longer_than_the_motion_stops_at_its_pace():
    """A pendulum of 1 s swings asked over 1e9 s: at the pace of its first PACE_STEPS steps
    the run would need some 1e11 steps, so it stops there with the time reached and what to
    change, instead of integrating up to MOST_STEPS steps (Andrews' mechanism over 1e7 s,
    fuzz seed 77251: over 120 s; 6 s now)."""
    import pam2exu.backend.natural.dynamics as nd
    with pytest.raises(pam2exu.SolverError) as caught:
        _run(pendulum(0.3), t_end=1e9, steps=4, tolerance=1e-8)
    text = str(caught.value)
    assert f"took {nd.PACE_STEPS:,} steps to reach t = " in text
    assert "of the interval's 1e+09 s: at that pace it would need about" in text
    assert "end it earlier ([analysis] t_end), check that it is in seconds" in text
    t = caught.value.time
    assert 0 < t < 1e9 * nd.PACE_STEPS / (nd.PACE_FACTOR * nd.MOST_STEPS)


@pytest.mark.parametrize("tolerance", [5e-324, 1e-300])
def test_a_tolerance_below_the_integrators_floor_stops_at_the_floor(monkeypatch, tolerance):
    """A valid tolerance no integrator meets (a subnormal 5e-324: 0.1 · tol underflowed to
    rtol = atol = 0, and the run never ended; 1e-300: atol 1e-301, and DOP853 stopped on a
    step below the spacing of floats) is integrated as far as DOP853 goes: the runs start
    at rtol = atol = SMALLEST (fuzz seed 5e-324 on examples/equilibrium/spring_four_bar.toml
    let go: over 5 minutes before), and the AccuracyWarning gives the estimate reached."""
    import pam2exu.backend.natural.dynamics as nd
    from pam2exu.analyses.dynamic import AccuracyWarning
    seen = []
    run = nd.Dynamics.run

    def spy(self, times, y0, r):
        seen.append(r)
        assert r > 0 and len(seen) <= 4, seen        # r = 0: a run that never ends
        return run(self, times, y0, r)
    monkeypatch.setattr(nd.Dynamics, "run", spy)
    with pytest.warns(AccuracyWarning):
        res = pam2exu.run(pendulum(0.3), backend="natural", t_end=0.2, steps=4,
                          tolerance=tolerance)
    assert seen[0] == nd.SMALLEST
    assert 0 < res.info["integration_error"] < 1e-10
    assert np.isfinite(res.to_numpy()).all()


@pytest.mark.parametrize("case", ["four_bar", "slider", "damped_four_bar"])
def test_natural_and_exudyn_agree_within_the_verify_rule(case):
    """Two independent integrations (Exudyn's generalized-α refined by Romberg, natural
    coordinates by DOP853) agree within 10 T (1 + S) (docs/verify.md); measured on the
    free four-bar at T = 1e-8: at most 0.6 % of the allowed difference."""
    if case == "slider":
        model = pam2exu.loads(slider_toml())
        v = pam2exu.verify(model, analysis="dynamic", steps=25)
    else:
        model = pam2exu.load(FOUR_BAR)
        if case == "damped_four_bar":        # a damper on the spring (C4 = 2 N·s/m)
            spring = next(e for e in model.elements if e.name == "spring")
            spring.C = [0.0, 400.0, 0.1, 2.0]
        v = pam2exu.verify(model, analysis="dynamic", steps=15, t_end=0.3)
    assert v.ok, v.verdict()
    assert v.rule.integration == 1e-8
    row = v.comparison["crank.fi" if case != "slider" else "lever.fi"]
    assert 0 < row.max_abs_error <= row.tolerance


def test_verify_catches_a_wrong_damper():
    """The rule is not loose: C4 = 2 on one backend's spring and 2.002 on the other's is a
    disagreement (a 0.1 % change of one force)."""
    model = pam2exu.load(FOUR_BAR)
    spring = next(e for e in model.elements if e.name == "spring")
    spring.C = [0.0, 400.0, 0.1, 2.0]
    ref = pam2exu.run(model, analysis="dynamic", steps=15, t_end=0.3)
    spring.C = [0.0, 400.0, 0.1, 2.002]
    other = pam2exu.run(model, analysis="dynamic", steps=15, t_end=0.3, backend="natural")
    from pam2exu.verify import Rule, agreement, _scales
    good = pam2exu.verify(model, analysis="dynamic", steps=15, t_end=0.3)
    rule = Rule(good.rule.tolerances, good.rule.condition, good.rule.length,
                _scales([ref, other], good.rule.length), good.rule.integration)
    table = agreement(other, ref, rule, ("exudyn", "natural"))
    assert not table.passed and "crank.fi" in table.failed


def test_cli_verify_dynamic_exits_0(capsys):
    code = main(["verify", str(FOUR_BAR), "-a", "dynamic", "--steps", "20", "--t-end", "0.3"])
    out = capsys.readouterr().out
    assert code == 0, out
    assert "two time integrations, each within T = 1e-08" in out
    assert "AGREE: natural and exudyn agree" in out


def test_the_error_estimate_bounds_the_error_of_the_rows():
    """The estimate (the largest |coarser − finer| / (1 + |finer|) of the last two runs,
    the finer returned) bounds the returned rows' error against DOP853 at rtol 1e-13 on the
    one-DOF equation, in the same measure (measured: 7.2e-7 ≤ 2.9e-5 ≤ 1e-4). Scaled by
    1 + 10³ |value| instead, it was 1.1e-7: below the error it claims to bound."""
    tolerance = 1e-4
    res = _run(pendulum(0.3), t_end=1.0, steps=10, tolerance=tolerance)
    ref = reference(res.t, (0.3, 0.0))
    error = max(float(np.max(np.abs(res[c] - r) / (1 + np.abs(r))))
                for c, r in (("lever.fi", ref[0]), ("lever.Dfi", ref[1])))
    assert 0 < error <= res.info["integration_error"] <= tolerance



def test_a_long_integration_shows_its_progress_on_a_terminal(monkeypatch):
    """Each of the integrator's runs draws a bar on a terminal (``progress.Progress``: its
    label names the method and the run's tolerance), erased when the run ends; the rows are
    those of the same run off a terminal, bit for bit."""
    monkeypatch.delenv("PAM2EXU_PROGRESS", raising=False)
    quiet = _run(pendulum(0.3), t_end=0.4, steps=8)
    tty = Terminal()
    monkeypatch.setattr(sys, "stderr", tty)
    shown = _run(pendulum(0.3), t_end=0.4, steps=8)
    bars = tty.getvalue()
    assert "integrating the motion (DOP853, tolerance 1e-" in bars and "] 100%" in bars
    assert bars.endswith("\r")                              # erased at the end
    np.testing.assert_array_equal(shown.to_numpy(), quiet.to_numpy())

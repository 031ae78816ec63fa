"""Redundant but consistent constraints still move (contract: "Degrees of freedom").

Reference: a parallelogram with a fifth parallel bar, driven by crank1 with
θ(t) = π/2 + 1.2 cos(2π t): all three cranks turn with θ and the coupler translates
(fi = 0) on a circle of radius 0.3, so its origin is (0.3 cos θ, 0.3 sin θ).
"""
import numpy as np
import pytest

import pam2exu
from pam2exu.analyses import RedundancyWarning

#: each test runs on each backend (``every_backend`` in conftest.py)
pytestmark = pytest.mark.usefixtures("every_backend")


@pytest.fixture(scope="module")
def res(request):
    with pytest.warns(RedundancyWarning, match="redundant constraint"):
        return pam2exu.run(request.config.rootpath / "tests/data/parallelogram5.toml")


def test_positions_velocities_accelerations_are_exact(res):
    w = 2 * np.pi
    th = np.pi / 2 + 1.2 * np.cos(w * res.t)
    thd = -1.2 * w * np.sin(w * res.t)
    thdd = -1.2 * w * w * np.cos(w * res.t)
    for crank in ("crank1", "crank2", "crank3"):
        np.testing.assert_allclose(res[f"{crank}.fi"], th, rtol=0, atol=1e-12)
        np.testing.assert_allclose(res[f"{crank}.Dfi"], thd, rtol=0, atol=1e-12 * w)
        np.testing.assert_allclose(res[f"{crank}.DDfi"], thdd, rtol=0, atol=1e-11 * w * w)
    np.testing.assert_allclose(res["coupler.fi"], 0.0, atol=1e-13)
    np.testing.assert_allclose(res["coupler.x"], 0.3 * np.cos(th), atol=1e-13)
    np.testing.assert_allclose(res["coupler.y"], 0.3 * np.sin(th), atol=1e-13)
    np.testing.assert_allclose(res["coupler.DDx"], 0.3 * (-np.cos(th) * thd**2 - np.sin(th) * thdd),
                               atol=1e-11 * 0.3 * w * w)


def test_run_reports_the_redundancy(res):
    assert res.info["redundant_equations"] == 1
    assert res.info["dof"] == 0
    assert any("'O3'" in w and "not" in w for w in res.warnings)


def test_redundant_mechanism_passes_its_change_points_on_its_branch(request, every_backend):
    """Driven through θ = π and 2π (steps 100 and 300 of 400), all bars are collinear and Cq
    loses rank: a change point. The mechanism goes on as a parallelogram (every crank at θ,
    the coupler translating), and the rates at those two steps, not fixed by the
    constraints, are the limits interpolated from the neighbours, with a warning.

    Reference: θ = π/2 + 2π t, θ' = 2π, θ'' = 0 for all three cranks; coupler fi = 0.
    At the change point two branches cross: the equations hold to second order along both,
    so Newton's error there halves per iteration and stops at ~√ε (1e-8) once the residual
    is at round-off. Exudyn's iterates stay exact parallelograms and reach 1e-12; the
    natural backend's (least-squares steps) do not: between 4e-9 and 1.5e-8 (√ε) at those
    two steps as round-off falls (measured), 5e-8 allowed.
    """
    from pam2exu.analyses import ConditionWarning
    model = pam2exu.load(request.config.rootpath / "tests/data/parallelogram5.toml")
    model["motor"].law, model["motor"].C = "polynomial", [np.pi / 2, 2 * np.pi]
    with pytest.warns(RedundancyWarning):
        with pytest.warns(ConditionWarning, match=r"t = 0\.25, 0\.75 s .*exactly at a singular"):
            res = pam2exu.run(model, steps=400)
    th, w = np.pi / 2 + 2 * np.pi * res.t, 2 * np.pi
    at_crossing = np.full(len(th), 1e-12)
    if every_backend == "natural":
        at_crossing[[100, 300]] = 5e-8
    for crank in ("crank1", "crank2", "crank3"):
        assert np.all(np.abs(res[f"{crank}.fi"] - th) <= at_crossing), crank
        np.testing.assert_allclose(res[f"{crank}.Dfi"], w, rtol=0, atol=1e-9 * w)
        np.testing.assert_allclose(res[f"{crank}.DDfi"], 0.0, rtol=0, atol=1e-9 * w * w)
    assert np.all(np.abs(res["coupler.fi"]) <= np.maximum(at_crossing, 1e-9))
    for var, scale in (("Dfi", w), ("DDfi", w * w)):
        np.testing.assert_allclose(res[f"coupler.{var}"], 0.0, rtol=0, atol=1e-9 * scale)


def test_quasi_static_through_a_singular_position_is_an_error(request, every_backend):
    """At the change point the reactions are undefined (Cq loses rank): quasi_static must
    stop there, as kinematic does, even though Exudyn's solver, told to ignore the
    singular Jacobian, passes it. The natural backend solves this change point only to
    ~1e-8 (the test above), where a rank test of Cq does not see it: quasi_static follows
    the branch as kinematic does, which finds it (its velocities jump there), and stops.
    Over the first half second alone (only this change point), the same."""
    model = pam2exu.load(request.config.rootpath / "tests/data/parallelogram5.toml")
    model["motor"].law, model["motor"].C = "polynomial", [np.pi / 2, 2 * np.pi]
    model.gravity = 9.81
    model["coupler"].mass = 1.0
    for settings in ({"steps": 400}, {"steps": 200, "t_end": 0.5}):
        with pytest.warns(RedundancyWarning):
            with pytest.raises(pam2exu.SolverError, match=r"t = 0\.25 s .*singular"):
                pam2exu.run(model, analysis="quasi_static", **settings)


def _two_motors(c2):
    """A crank driven by two angular actuators: m1 at fi = t, m2 at fi = c2[0] + c2[1] t."""
    m = pam2exu.Model("two motors", gravity=0.0)
    m.add_solid("ground")
    m.add_solid("crank", points={"O": [0, 0], "A": [0.1, 0]})
    m.add("fixed", anc1="ground")
    m.add("revolute", name="O", anc1="ground", anc2="crank.O")
    m.add("angular_actuator", name="m1", anc1="ground", anc2="crank", C=[0.0, 1.0])
    m.add("angular_actuator", name="m2", anc1="ground", anc2="crank", C=c2)
    return m


@pytest.mark.parametrize("c2,since", [([0.0, 2.0], r"from t = 0 s to t = 0\.01 s"),
                                      ([0.5, 1.0], r"at t = 0 s")])
def test_contradicting_constraints_are_named_not_taken_for_a_dead_point(c2, since):
    """Contract ("Degrees of freedom"): constraints that contradict each other get a clear
    error that says so and names the elements. The two drives agree at t = 0 and part
    at once (first case), or disagree from the start by 0.5 rad (second case)."""
    with pytest.warns(RedundancyWarning) if c2[0] == 0 else _no_warning():
        with pytest.raises(pam2exu.SolverError, match=rf"'m1', 'm2' contradict each other "
                                                      rf"{since}") as info:
            pam2exu.run(_two_motors(c2), analysis="kinematic", t_end=1.0, steps=100)
    assert "dead-point" not in str(info.value)
    assert info.value.elements == ("'m1' (angular_actuator)", "'m2' (angular_actuator)")


def test_agreeing_redundant_drives_run():
    with pytest.warns(RedundancyWarning, match="m1"):
        res = pam2exu.run(_two_motors([0.0, 1.0]), analysis="kinematic", t_end=1.0, steps=10)
    np.testing.assert_allclose(res["crank.fi"], res.t, rtol=0, atol=1e-14)


def _no_warning():
    import contextlib
    return contextlib.nullcontext()

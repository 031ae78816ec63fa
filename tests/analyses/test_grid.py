"""The plan of a run (analyses/grid.py): laws over the grid, sub-steps, bounded work.

Issue 10, faults 1, 5 and 9: a crank turning millions of radians per step ran for minutes;
a motor at 360 rad/s (degrees given as radians) switched branch; ``--steps 1`` failed on
every example; t_end = 5e-324, steps = 1e30 and law constants of 1e308 gave foreign
exceptions. References: the four-bar's closed form (circle intersection,
references/closed_form.py ``four_bar``), and the motion per step computed here by hand.
"""
from __future__ import annotations

import math
import signal
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest

import pam2exu
from pam2exu.analyses import grid
from references.closed_form import FOUR_BAR, four_bar

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@contextmanager
def deadline(seconds: int):
    """Fail (instead of hanging the suite) when the block runs longer than ``seconds``."""
    def stop(*_):
        raise TimeoutError(f"still running after {seconds} s")
    previous = signal.signal(signal.SIGALRM, stop)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


def fast_four_bar(speed: float):
    """examples/four_bar.toml with the crank at ``speed`` rad/s."""
    model = pam2exu.load(EXAMPLES / "four_bar.toml")
    model["motor"].C = [0.0, speed, 0.0, 0.0]
    return model


def test_motion_per_step_of_a_law():
    """θ = 2π t on 0 … 1 s in 4 steps: Δθ = π/2 per step (= θ' Δt)."""
    law = pam2exu.Law("polynomial", [0.0, 2 * math.pi])
    assert grid.motion_per_step(law, np.linspace(0.0, 1.0, 5)) == pytest.approx(math.pi / 2)


def test_a_crank_at_360_rad_per_second_is_solved_in_sub_steps_and_is_exact():
    """360 rad/s over 1 s in 200 steps: 1.8 rad per step, so ⌈1.8 / 0.25⌉ = 8 sub-steps per
    step; the results are reported on the 201 user times and match the closed form (before:
    "the mechanism keeps switching branch near singular positions")."""
    res = pam2exu.run(fast_four_bar(360.0), analysis="kinematic")
    assert len(res) == 201 and res.info["substeps"] == 8
    assert res.t[1] == pytest.approx(1.0 / 200)
    th = 360.0 * res.t
    (phi, dphi, _), (psi, dpsi, _) = four_bar(**FOUR_BAR, th=th, dth=360.0 + 0 * th,
                                             ddth=0 * th)
    assert np.max(np.abs(res["coupler.fi"] - phi)) < 1e-9
    assert np.max(np.abs(res["rocker.fi"] - psi)) < 1e-9
    assert np.max(np.abs(res["rocker.Dfi"] - dpsi)) < 1e-9 * 360.0
    assert np.max(np.abs(res["coupler.Dfi"] - dphi)) < 1e-9 * 360.0


def test_failure_messages_state_the_motion_per_step_of_a_sub_stepped_run():
    """The phrase both failure messages (Newton's divergence, endless branch switching)
    use: 360 rad/s in 200 steps is 1.8 rad per step, solved in 8 sub-steps."""
    from pam2exu.analyses.failure import motion_per_step
    from pam2exu.analyses.job import prepare
    job = prepare(fast_four_bar(360.0), "kinematic")
    assert motion_per_step(job) == "'motor' moves 1.8 rad per step, solved in 8 sub-steps"


def test_the_default_grid_has_no_sub_steps():
    """2π/200 = 0.031 rad per step: the user's grid is solved as it is."""
    res = pam2exu.run(EXAMPLES / "four_bar.toml", analysis="kinematic")
    assert "substeps" not in res.info


def test_a_run_that_would_take_too_long_is_refused_at_once_with_the_motion_per_step():
    """t_end = 1e7 s in 40 steps at 2π rad/s: 2π·1e7/40 = 1.57e6 rad per step; in steps
    of 0.25 rad that is 40·⌈1.57e6/0.25⌉ = 2.5e8 solves (before: minutes without end)."""
    model = pam2exu.load(EXAMPLES / "four_bar.toml")
    with deadline(20), pytest.raises(pam2exu.ModelError) as info:
        pam2exu.run(model, t_end=1e7, steps=40)
    text = str(info.value)
    assert "'motor' turns 1.6e+06 rad per step" in text
    assert "2.5e+08 position solves" in text and "2,000,000" in text
    assert "degrees" in text


@pytest.mark.parametrize("steps", [1, 2])
@pytest.mark.parametrize("path", sorted(EXAMPLES.glob("*.toml")), ids=lambda p: p.stem)
def test_one_or_two_steps_give_the_fine_run_at_those_times(path, steps):
    """``--steps 1`` and ``--steps 2`` work on every example (issue 10, fault 9): the rows
    equal those of the model's own grid at the same times (the same branch)."""
    model = pam2exu.load(path)
    fine = pam2exu.run(model, analysis="kinematic")
    coarse = pam2exu.run(model, analysis="kinematic", steps=steps)
    assert len(coarse) == steps + 1
    stride = model.analysis.steps // steps
    assert model.analysis.steps % steps == 0
    for name in coarse.columns:
        scale = max(1.0, float(np.max(np.abs(fine[name]))))
        assert np.max(np.abs(coarse[name] - fine[name][::stride])) < 1e-8 * scale, name


@pytest.mark.parametrize("path", sorted(EXAMPLES.glob("*.toml")), ids=lambda p: p.stem)
def test_one_step_runs_every_analysis(path):
    for analysis in ("quasi_static", "kinetostatic"):
        res = pam2exu.run(path, analysis=analysis, steps=1)
        assert len(res) == 2 and np.isfinite(res.to_numpy()).all()


def test_a_linear_actuator_whose_distance_reaches_zero_is_a_model_error():
    """examples/all_elements.toml's linear actuator with f(t) = 0.3 − 0.6 t: f(0.5) = 0,
    a distance without direction."""
    model = pam2exu.load(EXAMPLES / "all_elements.toml")
    actuator = next(el for el in model.elements if el.type == "linear_actuator")
    actuator.law, actuator.C = "polynomial", [0.3, -0.6]
    with pytest.raises(pam2exu.ModelError, match=r"the distance PQ must stay positive.*"
                                                 r"f\(t\) = 0 m at t = 0.5 s"):
        pam2exu.run(model, analysis="kinematic", t_end=1.0, steps=10)


def test_a_law_whose_rate_is_not_finite_is_a_model_error():
    """A ramp over 5e-324 s has f' = rise / 5e-324 = ∞ (before: a hang of minutes)."""
    model = pam2exu.load(EXAMPLES / "four_bar.toml")
    model["motor"].law, model["motor"].C = "ramp", [0.0, 5e-324, 0.0, 1.0]
    with deadline(20), pytest.raises(pam2exu.ModelError, match=r"f'\(t\) is not finite"):
        pam2exu.run(model)


def test_a_law_beyond_its_range_is_a_model_error():
    """θ = 2e7 rad (a constant): more than the 1e7 rad an angle may reach."""
    model = pam2exu.load(EXAMPLES / "four_bar.toml")
    model["motor"].C = [2e7, 0.0, 0.0, 0.0]
    with pytest.raises(pam2exu.ModelError, match=r"f\(t\) is .* \(at most 1e\+07 rad\)"):
        pam2exu.run(model)


@pytest.mark.parametrize("t_end, steps, message", [
    (5e-324, 10, r"t_end = 4.94066e-324 s is out of range"),
    (1e300, 10, r"t_end = 1e\+300 s is out of range"),
    (1.0, 10**30, r"steps = 10{30} is more than pam2exu runs"),
])
def test_absurd_intervals_are_model_errors(t_end, steps, message):
    """Before: "cannot convert float NaN to integer", "Maximum allowed size exceeded"."""
    with pytest.raises(pam2exu.ModelError, match=message):
        pam2exu.run(EXAMPLES / "four_bar.toml", t_end=t_end, steps=steps)


def test_a_run_that_would_not_fit_in_memory_is_refused():
    """all_elements, 2e6 steps (the most a run takes): 2e6 rows × (4 × 36 coordinates +
    equations + columns) × 8 bytes is over 4 GiB."""
    with pytest.raises(pam2exu.ModelError, match=r"GiB of coordinates and results"):
        pam2exu.run(EXAMPLES / "all_elements.toml", analysis="kinematic", steps=2_000_000)


def test_the_assembly_checks_the_actuators_values_at_t0():
    """A linear actuator of length 0 at t = 0, assembly analysis (fuzz seed 264: before,
    Exudyn's "ObjectConnectorDistance.distance must be given")."""
    model = pam2exu.load(EXAMPLES / "all_elements.toml")
    actuator = next(el for el in model.elements if el.type == "linear_actuator")
    actuator.law, actuator.C = "polynomial", [0.0]
    with pytest.raises(pam2exu.ModelError, match=r"'cylinder' \(linear_actuator\): the "
                                                 r"distance PQ must stay positive"):
        pam2exu.run(model, analysis="assembly")


@pytest.mark.parametrize("angular", [True, False])
def test_the_quick_law_check_passes_exactly_what_the_detailed_one_passes(angular, monkeypatch):
    """``check_laws`` tests (f, f', f'') at once (``_fine``) before naming what fails: on
    values at and just past each limit (NaN, ±∞ in each order, |f| = the range and one ulp
    more, f = 0 and −0 for a distance), it passes exactly what the detailed check passes."""
    from types import SimpleNamespace
    from pam2exu import limits
    limit = limits.ANGLE if angular else limits.LENGTH
    el = SimpleNamespace(angular=angular, where="'a' (actuator)", name="a")
    mech = SimpleNamespace(drivers=[el], model=SimpleNamespace(source="m.toml"))
    law = pam2exu.Law("polynomial", [0.0])
    times = np.linspace(0.0, 1.0, 5)
    base = np.array([0.5, 1.0, 2.0, 1.0, 0.5])
    cases = [(base, base, base)]
    for order in range(3):
        for bad in (np.nan, np.inf, -np.inf):
            values = [base.copy() for _ in range(3)]
            values[order][2] = bad
            cases.append(tuple(values))
    for f0 in (limit, np.nextafter(limit, np.inf), -limit, -np.nextafter(limit, np.inf),
               0.0, -0.0, -1e-300, 1e-300):
        f = base.copy()
        f[3] = f0
        cases.append((f, base, base))

    def verdict(values, ranges):
        try:
            grid.check_laws(mech, times, ranges=ranges, evaluated=[(law, values)])
            return "passes"
        except pam2exu.ModelError as exc:
            return str(exc)

    quick = [verdict(v, r) for v in cases for r in (True, False)]
    monkeypatch.setattr(grid, "_fine", lambda *_: False)
    detailed = [verdict(v, r) for v in cases for r in (True, False)]
    assert quick == detailed
    assert quick.count("passes") == (16 if angular else 12)


def test_a_plan_of_the_same_laws_and_interval_is_made_once(monkeypatch):
    """``plan`` of the same laws, interval and steps is the plan made before (its grid a
    writable copy, equal to a plan made afresh); another law, number of steps or limit
    makes its own, failures are not kept, and at most KEPT_PLANS plans are."""
    monkeypatch.setattr(grid, "_PLANS", {})
    made = []
    planned = grid._planned
    monkeypatch.setattr(grid, "_planned", lambda *a: made.append(a[1:]) or planned(*a))
    slow, fast = (fast_four_bar(s).mechanism() for s in (2.0, 360.0))
    first, again = grid.plan(slow, 1.0, 50, 10), grid.plan(slow, 1.0, 50, 3)
    assert made == [(1.0, 50)] and again.times is not first.times
    again.times[0] = 1.0                               # (a copy: the kept one unchanged)
    assert grid.plan(slow, 1.0, 50, 10).times[0] == 0.0
    sub = grid.plan(fast, 1.0, 200, 10)
    assert (sub.every, sub.motion) == (8, ("motor", pytest.approx(1.8), "rad"))
    assert (grid.plan(fast, 1.0, 200, 10).every, len(made)) == (8, 2)
    grid.plan(slow, 1.0, 51, 10)
    monkeypatch.setattr(grid, "MAX_ANGLE_STEP", 0.125)
    assert grid.plan(fast, 1.0, 200, 10).every == 15 and len(made) == 4
    monkeypatch.setattr(grid.limits, "SOLVE_STEPS", 1000)
    for _ in range(2):
        with pytest.raises(pam2exu.ModelError, match="more than pam2exu runs"):
            grid.plan(fast, 1.0, 200, 10)
    monkeypatch.setattr(grid.limits, "MEMORY", 1000)
    with pytest.raises(pam2exu.ModelError, match="GiB"):
        grid.plan(slow, 1.0, 50, 10)                    # (the memory bound: every time)
    assert len(made) == 7 and len(grid._PLANS) == 5         # (a limit is in the key)
    monkeypatch.setattr(grid.limits, "MEMORY", 2**30)
    for steps in range(1, 2 * grid.KEPT_PLANS):
        grid.plan(slow, 1.0, steps, 10)
    assert len(grid._PLANS) == grid.KEPT_PLANS

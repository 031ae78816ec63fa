"""Exudyn's position solve: the predictor, the compiled drivers, the quasi-static check steps.

References: exact polynomials (the predictor's extrapolation), Exudyn's own Newton counters
(``mbs.sys['staticSolver'].it``), and the four-bar's positions solved without the
predictor (the same configurations to the solver's tolerance).
"""
import logging

import numpy as np
import pytest

import pam2exu
from pam2exu.analyses.quasi_static import checked_steps
from pam2exu.analyses.job import prepare
from pam2exu.backend import ExudynSystem, SolveSettings
from pam2exu.backend.exudyn import system


@pytest.fixture(scope="module")
def four_bar(request):
    return prepare(request.config.rootpath / "examples" / "four_bar.toml",
                   analysis="kinematic", steps=1000)


def test_extrapolation_is_exact_for_a_parabola():
    """3 q(−1) − 3 q(−2) + q(−3) = q(0) for every polynomial of degree ≤ 2, not for t³."""
    t = np.array([-1.0, -2.0, -3.0])
    for p in (lambda t: 2.0 + 0 * t, lambda t: 1.5 - 4 * t, lambda t: 0.3 + t - 7 * t**2):
        assert system.extrapolate(*p(t)) == pytest.approx(p(0.0), abs=1e-14)
    assert system.extrapolate(*t**3) == pytest.approx(-6.0)      # not 0: −3 + 24 − 27


class _Data:
    """Stands for Exudyn's systemData: coordinates that the solver 'solves' to k²."""

    def __init__(self):
        self.q, self.set_to = np.zeros(1), []

    def GetODE2Coordinates(self):
        return self.q.copy()

    def SetODE2Coordinates(self, q):
        self.set_to.append(float(q[0]))


def test_predictor_uses_only_unbroken_runs_of_grid_steps():
    """Steps 0…5 on the grid, then a step cut by Exudyn (None), then 6…9: a prediction
    from the fourth grid step of each unbroken run on, each exact for q = k²."""
    data = _Data()
    predict = system.Predictor(data)
    predicted = []
    for k in [0, 1, 2, 3, 4, 5, None, 6, 7, 8, 9]:
        data.set_to.clear()
        predict(k)
        predicted.append(data.set_to[0] if data.set_to else None)
        if k is not None:
            data.q = np.array([float(k * k)])          # step k solved
    # at the call for step k the coordinates are step k − 1's solution
    assert predicted == [None, None, None, 9.0, 16.0, 25.0, None, None, None, None, 81.0]


def test_predictor_brings_newton_to_one_iteration_per_step(four_bar):
    """Exudyn's own counter: about 1 iteration per step with the predictor, 3 without (at
    1,000 steps and the default tolerance), and the same configurations."""
    runs = {}
    for predictor in (True, False):
        ex = ExudynSystem(four_bar.mech)
        q, solved = ex.solve_positions(four_bar.times, SolveSettings(predictor=predictor))
        assert solved == len(four_bar.times)
        runs[predictor] = q, ex.newton_iterations / solved
    assert runs[True][1] < 1.05 and runs[False][1] >= 2.0, runs
    np.testing.assert_allclose(runs[True][0], runs[False][0], rtol=0, atol=1e-12)


def test_angular_actuator_law_is_compiled(four_bar):
    """The motor's law is an Exudyn symbolic function, not a Python pre-step function."""
    ex = ExudynSystem(four_bar.mech)
    ex.solve_positions(four_bar.times[:5])
    assert len(ex._symbolic) == 1 and ex.stepped == []


def test_a_law_that_cannot_be_compiled_is_logged_and_stepped(four_bar, monkeypatch, caplog):
    """If Exudyn cannot build the symbolic function, the law is set step by step from
    Python (same positions) and a warning on the 'pam2exu' logger says so."""
    reference, _ = ExudynSystem(four_bar.mech).solve_positions(four_bar.times)

    def broken(*args):
        raise RuntimeError("no symbolic functions here")
    monkeypatch.setattr(system, "offset_function", broken)
    ex = ExudynSystem(four_bar.mech)
    with caplog.at_level(logging.WARNING, logger="pam2exu"):
        q, solved = ex.solve_positions(four_bar.times)
    assert solved == len(four_bar.times) and len(ex.stepped) == 1 and not ex._symbolic
    assert "could not be compiled" in caplog.text and "no symbolic functions here" in caplog.text
    np.testing.assert_allclose(q, reference, rtol=0, atol=1e-12)


@pytest.mark.parametrize("n, rows", [(1, [0]), (2, [0, 1]), (3, [0, 1, 2]), (201, [0, 100, 200]),
                                     (10, [0, 4, 9])])
def test_quasi_static_checks_exudyns_multipliers_at_first_middle_last(n, rows):
    """(the wrong-translation check itself: tests/analyses/test_forces.py, flipped spring)"""
    assert checked_steps(n) == rows


def test_long_runs_stay_on_the_grid(request):
    """Exudyn adds up its load-step times: after ~240,000 steps their round-off passed the
    1e-6 of a step the grid matching allowed, and a 300,000-step run stopped there ("the
    static solver stopped early", found by the benchmark's million-step run). Reference:
    the crank's law, fi = C1 + C2 t exactly, at every one of the 300,001 times."""
    path = request.config.rootpath / "examples/pam_crank.toml"
    model = pam2exu.load(path)
    res = pam2exu.run(model, analysis="kinematic", steps=300_000, outputs=["Solid1.fi"])
    assert len(res.t) == 300_001 and np.isfinite(res["Solid1.fi"]).all()
    driver = next(e for e in model.elements if e.type == "angular_actuator")
    expected = driver.time_law()(res.t)[0]
    assert np.max(np.abs(res["Solid1.fi"] - expected)) < 1e-12 * max(1.0, np.max(np.abs(expected)))
    assert system.ON_GRID * 64 < 1.0     # a cut step (≥ 1/64 of a step off the grid) never is

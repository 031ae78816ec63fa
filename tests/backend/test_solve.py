"""Exudyn's position solve: the predictor, the compiled drivers, the quasi-static check steps.

References: exact polynomials (the predictor's extrapolation), Exudyn's own Newton counters
(``mbs.sys['staticSolver'].it``), and the four-bar's positions solved without the
predictor (the same configurations to the solver's tolerance).
"""
import logging

import exudyn as exu
import numpy as np
import pytest

import pam2exu
from pam2exu.analyses.quasi_static import checked_steps
from pam2exu.analyses.job import prepare
from pam2exu.backend import ExudynSystem, SolveSettings
from pam2exu.backend.exudyn import predictor, system
from pam2exu.kinematics import column
from references.closed_form import four_bar_angles


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


def test_a_run_takes_one_jacobian_per_step(four_bar):
    """Exudyn's own counters: by default a run's steps are solved by modified Newton, one
    Jacobian each (full Newton: one per iteration, 3 per step at 1,000 steps without the
    predictor), at the same configurations to the tolerance (1e-13 × 0.4 m; 1e-12 checked)
    and the crank at its law 2π t."""
    runs = {}
    for modified in (True, False):
        ex = ExudynSystem(four_bar.mech)
        q, solved = ex.solve_positions(four_bar.times, SolveSettings(
            predictor=False, modified_newton=modified))
        assert solved == len(four_bar.times)
        runs[modified] = q, ex.mbs.sys["staticSolver"].it.newtonJacobiCount / solved
    assert runs[True][1] <= 1.01 and runs[False][1] >= 2.9, runs
    assert SolveSettings().modified_newton
    np.testing.assert_allclose(runs[True][0], runs[False][0], rtol=0, atol=1e-12)
    crank = [s.name for s in four_bar.mech.solids].index("crank")
    np.testing.assert_allclose(runs[True][0][:, column(crank, 2)], 2 * np.pi * four_bar.times,
                               rtol=0, atol=1e-13)


def test_one_time_alone_redundant_constraints_and_many_turns_keep_full_newton(four_bar):
    """An assembly (one time, from a guess: full Newton's path decides the branch), a
    redundant mechanism (a singular Jacobian) and a run whose round-off floor is above the
    tolerance (100 turns: 16 ulps of 200π = 2.2e-12 > 1e-13 × 0.4 m; modified Newton would
    stop at the floor) are solved by full Newton; a run by modified Newton unless asked
    otherwise (the exported script writes the run's settings)."""
    key = "staticSolver.newton.useModifiedNewton"
    mech, on, off = four_bar.mech, SolveSettings(), SolveSettings(modified_newton=False)
    assert system.solver_options(mech, on, False)[key] is True
    assert key not in system.solver_options(mech, on, False, run=False)
    assert key not in system.solver_options(mech, on, True)
    assert key not in system.solver_options(mech, off, False)
    assert key not in system.solver_options(mech, on, False, roundoff=4.1e-14)
    for times, modified in ((four_bar.times[:1], False), (four_bar.times, True),
                            (np.linspace(0.0, 100.0, 2001), False)):
        ex = ExudynSystem(mech)
        q, solved = ex.solve_positions(times)
        assert solved == len(times) and ex.modified is modified
        assert ex.mbs.sys["staticSolver"].newton.useModifiedNewton is modified


def parallelogram(th0):
    """A parallelogram four-bar (cranks r = 0.3 m, coupler and ground L = 1 m), the crank
    from θ0 at 6π rad/s: its links are collinear (a change point) at θ = π."""
    r, L = 0.3, 1.0
    m = pam2exu.Model("parallelogram", gravity=0.0)
    m.add_solid("ground", points={"O1": [0.0, 0.0], "O2": [L, 0.0]})
    m.add_solid("crank", fi=th0, points={"O": [0.0, 0.0], "A": [r, 0.0]})
    m.add_solid("coupler", x=r * np.cos(th0), y=r * np.sin(th0),
                points={"A": [0.0, 0.0], "B": [L, 0.0]})
    m.add_solid("rocker", x=L, fi=th0, points={"O": [0.0, 0.0], "B": [r, 0.0]})
    m.add("fixed", anc1="ground")
    m.add("revolute", anc1="ground.O1", anc2="crank.O")
    m.add("revolute", anc1="crank.A", anc2="coupler.A")
    m.add("revolute", anc1="coupler.B", anc2="rocker.B")
    m.add("revolute", anc1="ground.O2", anc2="rocker.O")
    m.add("angular_actuator", anc1="ground", anc2="crank", C=[th0, 6 * np.pi])
    return m


def test_a_run_modified_newton_leaves_unsolved_is_solved_by_full_newton():
    """Past the parallelogram's change point θ = π (from θ0 = 0.9π, 0.24 rad per step),
    modified Newton's second iteration diverges and Exudyn stops early (step 28 of 80);
    the run is then solved again by full Newton: every step, the same positions as full
    Newton's bit for bit, and the crank at its law."""
    job = prepare(parallelogram(0.9 * np.pi), analysis="kinematic", steps=20)
    n = len(job.times)
    modified = ExudynSystem(job.mech)
    assert modified._solve_positions(job.times, SolveSettings(), False, False)[1] < n
    ex = ExudynSystem(job.mech)
    q, solved = ex.solve_positions(job.times)
    full, _ = ExudynSystem(job.mech).solve_positions(job.times,
                                                     SolveSettings(modified_newton=False))
    assert solved == n and ex.error is None
    np.testing.assert_array_equal(q, full)
    np.testing.assert_allclose(q[:, column(1, 2)], 0.9 * np.pi + 6 * np.pi * job.times,
                               rtol=0, atol=1e-12)


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


# ---- the predictor decided by measurement (predictor = "auto") -------------------------------

def test_predictor_pays_when_its_own_steps_are_clearly_shorter():
    """The lower quartile, not the mean nor the median: steps slowed by the machine's other
    work do not decide, even when they are most of one way's; and shorter by more than
    MARGIN (the pre-step call only the predictor's way pays after the probe)."""
    slowed = [1.0] * 4 + [9.0] * 5             # five of nine steps slowed by the machine
    assert predictor.predictor_pays(slowed, [1.2] * 4 + [8.0] * 5)
    assert not predictor.predictor_pays([1.2] * 4 + [8.0] * 5, slowed)
    assert predictor.predictor_pays([1.0, 1.0, 1.0], [2.0, 2.0, 2.0])
    assert not predictor.predictor_pays([1.0, 3.0, 3.0], [2.0, 2.0, 2.0])
    assert predictor.predictor_pays([1.0, 1.0, 50.0], [2.0, 2.0, 2.0])
    assert not predictor.predictor_pays([], [2.0])
    just = 1.0 - predictor.MARGIN
    assert predictor.predictor_pays([0.99 * just], [1.0])
    assert not predictor.predictor_pays([1.01 * just], [1.0])


def test_probe_alternates_blocks_and_ends_predicting():
    """Warm-up predicted and not timed; blocks of BLOCK steps, off, on, off, …, the last on;
    a predicted block's first HISTORY steps (no three-step history yet) not timed."""
    P = predictor.Probe
    modes = [P.predicting(i) for i in range(predictor.PROBE_STEPS)]
    assert all(modes[:predictor.WARM_UP]) and modes[-1]
    blocks = [modes[predictor.WARM_UP + b * predictor.BLOCK:
                    predictor.WARM_UP + (b + 1) * predictor.BLOCK]
              for b in range(predictor.BLOCKS)]
    assert [set(b) for b in blocks] == [{b % 2 == 1} for b in range(predictor.BLOCKS)]
    timed = [P.timed(i) for i in range(predictor.PROBE_STEPS)]
    on = predictor.WARM_UP + predictor.BLOCK          # the first predicted block
    assert not any(timed[:predictor.WARM_UP]) and all(timed[predictor.WARM_UP:on])
    assert timed[on:on + predictor.BLOCK] == [False] * predictor.HISTORY + [True] * (
        predictor.BLOCK - predictor.HISTORY)


def fake_clock(cost_on, cost_off):
    """A clock for ``Probe`` in which probe step i takes cost_on with the predictor and
    cost_off without: its j-th reading is the sum of the costs of steps 0 … j − 1."""
    state = {"calls": 0, "now": 0.0}

    def clock():
        j = state["calls"]
        if j:
            state["now"] += cost_on if predictor.Probe.predicting(j - 1) else cost_off
        state["calls"] += 1
        return state["now"]
    return clock


@pytest.fixture(scope="module")
def long_four_bar(request):
    return prepare(request.config.rootpath / "examples" / "four_bar.toml",
                   analysis="kinematic", steps=predictor.PROBE_FROM)


@pytest.mark.parametrize("cost_on, cost_off, predicted", [(1.0, 2.0, True), (3.0, 2.0, False)])
def test_auto_keeps_the_faster_way_and_the_positions(long_four_bar, cost_on, cost_off,
                                                     predicted):
    """Timings injected: the run goes on with the predictor (Newton: 1 iteration per step)
    when its probe steps were the shorter, without it (2 per step) otherwise; every row solved
    across the probe's end, the crank's angle 2π t and the rocker's the closed form's (to the
    solver's tolerance) either way, and the initial configuration left as it was."""
    job = long_four_bar
    ex = ExudynSystem(job.mech)
    ex.clock = fake_clock(cost_on, cost_off)
    initial = ex.mbs.systemData.GetODE2Coordinates(configuration=exu.ConfigurationType.Initial)
    q, solved = ex.solve_positions(job.times)      # the default: predictor = "auto"
    assert solved == len(job.times) and ex.error is None and ex.predicted is predicted
    per_step = ex.newton_iterations / len(job.times)         # the probe's 200 steps too
    assert per_step < 1.1 if predicted else per_step > 1.9, per_step
    names = [s.name for s in job.mech.solids]
    crank, rocker = names.index("crank"), names.index("rocker")
    theta = 2 * np.pi * job.times
    _, psi = np.array([four_bar_angles(0.1, 0.35, 0.3, 0.4, th) for th in theta]).T
    np.testing.assert_allclose(q[:, column(crank, 2)], theta, rtol=0, atol=1e-13)
    np.testing.assert_allclose(q[:, column(rocker, 2)], psi, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(
        ex.mbs.systemData.GetODE2Coordinates(configuration=exu.ConfigurationType.Initial),
        initial)


def test_auto_keeps_the_multipliers_across_the_probe(long_four_bar):
    """With the forces (the static multipliers of a kinetostatic run) and the predictor
    found slower: every step's multipliers kept, the same as a run without the predictor."""
    job = long_four_bar
    runs = {}
    for setting in ("auto", False):
        ex = ExudynSystem(job.mech, forces=True, velocity_forces=False)
        ex.clock = fake_clock(3.0, 2.0)
        q, solved = ex.solve_positions(job.times, SolveSettings(predictor=setting),
                                       multipliers=True)
        assert solved == len(job.times) and np.isfinite(ex.multipliers).all()
        runs[setting] = q, ex.multipliers
    np.testing.assert_allclose(runs["auto"][0], runs[False][0], rtol=0, atol=1e-12)
    scale = np.max(np.abs(runs[False][1]))
    np.testing.assert_allclose(runs["auto"][1], runs[False][1], rtol=0, atol=1e-10 * scale)


def test_the_angle_gain_is_computed_once_per_mechanism_and_run(monkeypatch):
    """An analysis solves its assembly, then its run, each on a new Exudyn system: the
    round-off floor's angle coefficient (a native evaluation of every constraint) is the
    mechanism's, evaluated once. Reference: examples/all_elements.toml's transmission
    'mesh', fi_planet − fi_arm = T (fi_sun − fi_arm), T = −1.5, puts 1 − T = 2.5 on the
    arm's angle, above every lever arm (< 1 m)."""
    from pam2exu.backend import exudyn as backend
    calls = []

    def counted(mech):
        calls.append(mech)
        return system.angle_gain(mech)
    monkeypatch.setattr(backend, "angle_gain", counted)
    pam2exu.run(pam2exu.load("examples/four_bar.toml"), "kinematic", steps=10)
    assert len(calls) == 1
    assert system.angle_gain(pam2exu.load("examples/four_bar.toml").mechanism()) == 1.0
    assert system.angle_gain(pam2exu.load("examples/all_elements.toml").mechanism()) == 2.5

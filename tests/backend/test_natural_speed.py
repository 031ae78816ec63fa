"""What keeps the natural backend's short runs and large mechanisms fast (issue 25), checked
by what it computes, never by time: the laws evaluated once per step, a step of a larger
system solved dense, the coarse pass sized by the run's motion, the few-step sums giving
the same bits as the many-step ones. References: the four-bar's closed form
(references/closed_form.py) and numpy's dense solve."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import pam2exu
from benchmarks.cases import chain_model
from pam2exu.backend.natural import Natural
from pam2exu.backend.natural import terms as terms_module
from pam2exu.backend.natural.formulation import Formulation
from pam2exu.backend.natural.linear import SPARSE_FROM
from pam2exu.backend.natural.solver import (NaturalSettings, Solver, cubic_hermite,
                                            quintic_hermite)
from pam2exu.backend.natural.terms import BINCOUNT_STEPS
from references.closed_form import FOUR_BAR, four_bar

ROOT = Path(__file__).resolve().parents[2]


def solver_of(mech, rates: bool = True):
    backend = Natural()
    form = backend.formulation(mech)
    return form, Solver(form.terms, backend.weights(form, mech), NaturalSettings(), False,
                        rates=rates)


@pytest.fixture(scope="module")
def four_bar_mech():
    return pam2exu.load(ROOT / "examples" / "four_bar.toml").mechanism()


class CountedLaw:
    """A law that counts its calls."""

    def __init__(self, law):
        self.law, self.calls = law, 0

    def __call__(self, t):
        self.calls += 1
        return self.law(t)


def test_a_step_evaluates_its_law_once(four_bar_mech):
    """Newton's iterations at one time, then its velocities and accelerations, ask the
    actuator's law once (before: twice per iteration and once per rate)."""
    form, solver = solver_of(four_bar_mech)
    terms = form.terms
    r, law, power = terms.laws[0]
    counted = CountedLaw(law)
    terms.laws[0] = (r, counted, power)
    z0 = form.from_q(four_bar_mech.initial_q()[None])
    t = np.array([0.03])
    z, ok = solver.newton(t, z0)
    solver.rates(t, z)
    assert ok[0] and solver.iterations >= 3
    assert counted.calls == 1


def test_the_coarse_pass_follows_the_motion(four_bar_mech):
    """A 100-step turn of the four-bar: the coarse pass's intervals grow from 4 steps to 8
    where the predictor misses little (before: 25 intervals of 4 steps), and the run still
    meets the closed form to 1e-12 of the link lengths."""
    form, solver = solver_of(four_bar_mech)
    n = 101
    t = np.linspace(0.0, 1.0, n)
    z0, ok = solver.newton(t[:1], form.from_q(four_bar_mech.initial_q()[None]))
    z, solved = solver.run(t, z0[0])
    assert solved == n
    lengths = [j - k for k, j, _ in solver.intervals]
    assert sum(lengths) == n - 1 and max(lengths) == 8 and len(lengths) < 16
    q = Natural().to_q(form, four_bar_mech, z, four_bar_mech.initial_q())
    a, b, c, d = (FOUR_BAR[key] for key in "abcd")
    theta = 2 * np.pi * t
    (phi, _, _), (psi, _, _) = four_bar(a, b, c, d, theta, 2 * np.pi + 0 * t, 0 * t)
    names = [s.name for s in four_bar_mech.solids]
    fi = lambda name: q[:, 3 * names.index(name) + 2]          # noqa: E731
    turn = lambda x: (x + np.pi) % (2 * np.pi) - np.pi          # noqa: E731
    assert np.max(np.abs(turn(fi("coupler") - phi))) < 1e-12
    assert np.max(np.abs(turn(fi("rocker") - psi))) < 1e-12


def test_the_fill_guesses_are_the_hermite_interpolants():
    """``quintic_hermite``'s weights give any polynomial of degree 5 exactly from its value,
    first and second derivative at both ends, ``cubic_hermite``'s any cubic from its value
    and first derivative (each interpolant is unique), and both keep a constant."""
    rng = np.random.default_rng(5)
    t0, h = 0.3, 0.7
    u = np.linspace(0.0, 1.0, 11)
    for weights, degree, orders in ((quintic_hermite(u, h), 5, (0, 1, 2)),
                                    (cubic_hermite(u, h), 3, (0, 1))):
        c = rng.normal(size=degree + 1)                    # p(x) = Σ c_k x^k
        p = np.polynomial.Polynomial(c)
        ends = [p.deriv(k)(x) for x in (t0, t0 + h) for k in orders]
        got = sum(w * e for w, e in zip(weights, ends))
        assert np.max(np.abs(got - p(t0 + u * h))) < 1e-14 * np.max(np.abs(c))
        assert np.max(np.abs(weights[0] + weights[len(orders)] - 1.0)) < 1e-15


def test_the_fill_converges_in_two_newton_iterations(four_bar_mech):
    """1,000 steps of the four-bar's turn: the coarse intervals miss by more than
    QUINTIC_MISS, so every step between the coarse ones is solved in two Newton iterations
    from the quintic guess (from the cubic one: three), and the run meets the closed form to
    1e-12 of the link lengths."""
    form, solver = solver_of(four_bar_mech)
    n = 1001
    t = np.linspace(0.0, 1.0, n)
    z0, ok = solver.newton(t[:1], form.from_q(four_bar_mech.initial_q()[None]))
    solver.iterations = 0
    z, solved = solver.run(t, z0[0])
    coarse = len(solver.intervals)
    assert solved == n
    # the coarse steps take 2 or 3 iterations each; every other step exactly 2
    assert 2 * (n - 1) <= solver.iterations <= 2 * (n - 1) + coarse
    q = Natural().to_q(form, four_bar_mech, z, four_bar_mech.initial_q())
    a, b, c, d = (FOUR_BAR[key] for key in "abcd")
    (phi, _, _), (psi, _, _) = four_bar(a, b, c, d, 2 * np.pi * t, 2 * np.pi + 0 * t, 0 * t)
    names = [s.name for s in four_bar_mech.solids]
    fi = lambda name: q[:, 3 * names.index(name) + 2]          # noqa: E731
    turn = lambda x: (x + np.pi) % (2 * np.pi) - np.pi          # noqa: E731
    assert np.max(np.abs(turn(fi("coupler") - phi))) < 1e-12
    assert np.max(np.abs(turn(fi("rocker") - psi))) < 1e-12


def test_the_quintic_guess_where_the_coarse_intervals_are_long_or_short(four_bar_mech,
                                                                        monkeypatch):
    """The fill takes the quintic guess at 1,000 steps of the four-bar's turn (coarse misses
    ~8e-5 > QUINTIC_MISS: from the cubic, three Newton iterations a step), the cubic at
    10,000 (~1e-5: two iterations a step either way, and the cubic has two terms fewer), and
    the quintic again at 50,000 steps over half the turn (intervals of 0.005 s, misses
    ~1.3e-6: the quintic is within the tolerance and most steps take one iteration, 1.34 a
    step against 2.00 from the cubic)."""
    import pam2exu.backend.natural.solver as solver_module
    asked = []
    quintic = solver_module.quintic_hermite
    monkeypatch.setattr(solver_module, "quintic_hermite",
                        lambda u, h: asked.append(len(u)) or quintic(u, h))
    per_step = {}
    for n, span, expected in ((1001, 1.0, True), (10001, 1.0, False), (50001, 0.5, True)):
        asked.clear()
        form, solver = solver_of(four_bar_mech)
        t = np.linspace(0.0, span, n)
        z0, _ = solver.newton(t[:1], form.from_q(four_bar_mech.initial_q()[None]))
        solver.iterations = 0
        z, solved = solver.run(t, z0[0])
        misses = [miss for _, _, miss in solver.intervals]
        assert solved == n and bool(asked) == expected
        assert (max(misses) > solver_module.QUINTIC_MISS) == (n == 1001)
        per_step[n] = solver.iterations / (n - 1)
    assert per_step[10001] >= 2.0 and per_step[50001] < 1.5


def test_the_fill_iterates_only_the_steps_still_moving():
    """examples/all_elements.toml over its interval in 1,000 steps: a few of the fill's
    steps (next to the laws' breakpoints, where the guess is poorer) need a third or fourth
    Newton iteration. Only they take them: 2.11 iterations a step, where the block that
    iterated as a whole took 3.95; every step's answer holds its equations (|Φ| ≤ 1e-12 of
    the equations' magnitude) and equals a fresh Newton from it (to the tolerance)."""
    model = pam2exu.load(ROOT / "examples" / "all_elements.toml")
    mech = model.mechanism()
    form, solver = solver_of(mech)
    n = 1001
    t = np.linspace(0.0, model.analysis.t_end, n)
    z0, ok = solver.newton(t[:1], form.from_q(mech.initial_q()[None]))
    solver.iterations = 0
    z, solved = solver.run(t, z0[0])
    assert solved == n
    assert solver.iterations / (n - 1) < 2.3
    terms = form.terms
    phi = terms.residual(t, z)
    magnitude = np.maximum(terms.magnitude(t, z), 1.0)
    assert np.max(np.abs(phi) / magnitude) <= 1e-12
    again, ok = solver.newton(t, z)
    assert ok.all()
    assert np.max(np.abs(again - z) * solver.w) <= NaturalSettings().tolerance


@pytest.mark.parametrize("iterations", [2, 3])
def test_a_fill_block_out_of_iterations_leaves_its_last_steps_to_the_step_by_step_pass(
        iterations, monkeypatch):
    """all_elements at 1,000 steps with the fill's blocks allowed 2 or 3 Newton iterations
    (4 by default): after the steps that stopped early, those still moving when the
    iterations run out (a few next to the laws' breakpoints) take their rates from the
    last solve and their intervals are solved again step by step; the run equals the
    default one to 1e-12 of each column's largest value."""
    from pam2exu.backend.natural import linear
    model = pam2exu.load(ROOT / "examples" / "all_elements.toml")
    reference = pam2exu.run(model, analysis="kinematic", steps=1000, backend="natural")
    bulk = linear.LinearSolves._bulk
    monkeypatch.setattr(linear.LinearSolves, "_bulk",
                        lambda self, t, z, order, iterations_=4: bulk(self, t, z, order,
                                                                      iterations))
    res = pam2exu.run(model, analysis="kinematic", steps=1000, backend="natural")
    for column in reference.columns:
        a, b = np.asarray(res[column]), np.asarray(reference[column])
        scale = max(1.0, np.nanmax(np.abs(b), initial=0.0))
        assert np.array_equal(np.isnan(a), np.isnan(b)), column
        assert np.nanmax(np.abs(a - b), initial=0.0) <= 1e-12 * scale, column


def test_a_step_of_a_larger_system_is_solved_dense():
    """One step of the chain of 12 loops (49 coordinates, at least SPARSE_FROM) is solved by
    a dense factorisation, not a sparse LU (before: ``_sparse``), to numpy's answer."""
    form, solver = solver_of(chain_model(12).mechanism())
    assert form.nz >= SPARSE_FROM

    def refuse(*args):
        raise AssertionError("sparse LU for one step")

    solver._sparse = refuse
    z = form.from_q(form.mech.initial_q()[None])
    data = form.terms.jacobian(z)
    b = np.linspace(-1.0, 1.0, form.terms.m)[None]
    x = solver.solve(data, b)
    expected = np.linalg.solve(form.terms.dense(data)[0], b[0])
    assert np.max(np.abs(x[0] - expected)) <= 1e-12 * np.max(np.abs(expected))


def test_few_steps_sum_to_the_same_bits_as_many(four_bar_mech):
    """Φ, Φ_z and γ of one step (summed by bincount) equal, bit for bit, that step's column
    of an evaluation of more than BINCOUNT_STEPS steps (summed by the sparse matrix): a
    run's results do not depend on how its steps are grouped."""
    form, _ = solver_of(four_bar_mech)
    terms = form.terms
    n = BINCOUNT_STEPS + 8
    rng = np.random.default_rng(7)
    z = form.from_q(four_bar_mech.initial_q()[None]).T + 0.1 * rng.standard_normal((form.nz, n))
    zd = rng.standard_normal((form.nz, n))
    t = np.linspace(0.0, 0.5, n)
    many = (terms.residual_cols(t, z), terms.jacobian_cols(z), terms.gamma_cols(t, z, zd))
    for k in (0, 17, n - 1):
        s = slice(k, k + 1)
        few = (terms.residual_cols(t[s], z[:, s]), terms.jacobian_cols(z[:, s]),
               terms.gamma_cols(t[s], z[:, s], zd[:, s]))
        for a, b in zip(many, few):
            assert a[:, s].tobytes() == b.tobytes()


def test_a_large_system_gets_its_rates_with_its_positions():
    """The chain of 12 loops (49 coordinates, sparse block solves): every step's ż and z̈
    come with its positions, from the last Newton iteration's factors (before: solved
    again afterwards for the filled steps), and equal fresh solves at the answers."""
    mech = chain_model(12).mechanism()
    form, solver = solver_of(mech)
    t = np.linspace(0.0, 0.5, 81)
    z0, ok = solver.newton(t[:1], form.from_q(mech.initial_q()[None]))
    z, solved = solver.run(t, z0[0])
    assert solved == len(t) and solver.own_rates.all()
    zd, zdd = solver.rates(t, z)
    for mine, fresh in ((solver.zd, zd), (solver.zdd, zdd)):
        assert np.max(np.abs(mine - fresh)) <= 1e-10 * np.max(np.abs(fresh))


@pytest.mark.parametrize("mech_of", [
    lambda: pam2exu.load(ROOT / "examples" / "four_bar.toml").mechanism(),
    lambda: chain_model(12).mechanism()], ids=["four-bar, dense", "chain of 12, sparse"])
def test_a_run_without_rates_solves_none_in_its_fill(mech_of):
    """A run asked for positions only (``Solver(rates=False)``: a kinematic run whose
    outputs are x, y, fi) solves ż, z̈ at the coarse steps alone, which its predictor needs,
    not at the filled ones; its positions are the same bits as with the rates."""
    mech = mech_of()
    t = np.linspace(0.0, 0.5, 1001)
    runs = {}
    for rates in (True, False):
        form, solver = solver_of(mech, rates)
        z0, ok = solver.newton(t[:1], form.from_q(mech.initial_q()[None]))
        z, solved = solver.run(t, z0[0])
        assert solved == len(t)
        runs[rates] = z, solver
    (z, with_rates), (z_only, without) = runs[True], runs[False]
    assert z.tobytes() == z_only.tobytes()
    coarse = {0} | {j for _, j, _ in without.intervals}
    assert with_rates.own_rates.all()
    assert set(np.nonzero(without.own_rates)[0]) == coarse
    assert len(coarse) < len(t) // 4


def test_newton_stops_where_quadratic_convergence_says_the_next_step_is_below(
        four_bar_mech, monkeypatch):
    """Newton at one time stops after the step whose successor, step³ / last², would be 1000
    times below the tolerance (the iteration that would only confirm it is not taken): a
    coarse step of the four-bar takes 3 iterations instead of 4, and lands within round-off
    of the 4-iteration answer."""
    from pam2exu.backend.natural import solver as solver_module
    form, solver = solver_of(four_bar_mech)
    z0 = form.from_q(four_bar_mech.initial_q()[None])
    t = np.array([0.0, 0.04])
    start, _ = solver.newton(t[:1], z0)
    zd, zdd = solver.rates(t[:1], start)
    h = t[1] - t[0]
    guess = start + h * zd + 0.5 * h * h * zdd            # the coarse pass's predictor
    answers = {}
    for converged in (solver_module.CONVERGED, 0.0):     # 0: every step must be below tol
        monkeypatch.setattr(solver_module, "CONVERGED", converged)
        solver.iterations = 0
        z, ok = solver.newton(t[1:], guess)
        assert ok[0]
        answers[converged] = (z[0], solver.iterations)
    (fast, n_fast), (slow, n_slow) = answers.values()
    assert (n_fast, n_slow) == (3, 4)
    assert np.max(np.abs(fast - slow) * solver.w) <= 1e-15


def test_the_run_starts_from_the_assembly_it_solved(monkeypatch):
    """The run after the assembly starts from the assembly's natural coordinates (its angle
    coordinates those of the start, whole turns added) instead of solving t0 again: Newton
    at t0 once a run (before: twice)."""
    at = []
    iterate = Solver._iterate_one

    def counted(self, t, z):
        at.append(float(t[0]))
        return iterate(self, t, z)

    monkeypatch.setattr(Solver, "_iterate_one", counted)
    model = pam2exu.load(ROOT / "examples" / "four_bar.toml")
    res = pam2exu.run(model, analysis="kinematic", steps=100, backend="natural")
    assert at.count(0.0) == 1 and len(res.t) == 101


def test_a_run_asks_its_law_once(four_bar_mech):
    """A 101-step run evaluates the actuator's law once, at all its times (``tabulate``): its
    coarse steps and its fill read their rows (before: once per coarse step and once for
    the fill), the same values as an evaluation at those times alone."""
    form, solver = solver_of(four_bar_mech)
    terms = form.terms
    r, law, power = terms.laws[0]
    counted = CountedLaw(law)
    terms.laws[0] = (r, counted, power)
    t = np.linspace(0.0, 1.0, 101)
    z0, _ = solver.newton(t[:1], form.from_q(four_bar_mech.initial_q()[None]))
    counted.calls = 0
    z, solved = solver.run(t, z0[0])
    assert solved == len(t) and counted.calls == 1
    for rows in ([37], [3, 50, 99]):
        for order in range(3):
            assert terms.targets(t[rows], order).tobytes() == \
                np.array([law(t[rows])[order]]).tobytes()


def test_variants_of_one_structure_share_their_terms_indices(four_bar_mech):
    """Equations scaled by 1.1 (other coefficients) have the same terms' rows and columns: their
    ``Terms`` share the index arrays (made once, read-only), keep their own coefficients, and
    evaluate exactly as a ``Terms`` made with no structure kept (the answer of a variant does
    not depend on the variants made before it)."""
    a = Formulation(four_bar_mech).terms
    rows = [r[1:] for r in Formulation(four_bar_mech)._rows]
    b = terms_module.Terms(a.nz, [(e * 1.1, g, p) for e, g, p in rows])
    assert b.pa is a.pa and b.entry_index is a.entry_index and not a.pa.flags.writeable
    assert not np.array_equal(b.pc, a.pc)
    z = np.random.default_rng(3).standard_normal((2, a.nz))
    t = np.array([0.1, 0.2])
    kept = dict(terms_module._STRUCTURES)
    terms_module._STRUCTURES.clear()
    try:
        fresh = terms_module.Terms(b.nz, [(e * 1.1, g, p) for e, g, p in rows])
        assert fresh.pa is not b.pa
    finally:
        terms_module._STRUCTURES.clear()
        terms_module._STRUCTURES.update(kept)
    for got, want in ((b.residual(t, z), fresh.residual(t, z)),
                      (b.jacobian(z), fresh.jacobian(z))):
        assert got.tobytes() == want.tobytes()


def test_the_damped_iteration_gives_up_where_its_line_searches_find_no_descent(monkeypatch):
    """A four-bar whose coupler (0.7 m) cannot close the loop at t = 0 (the crank 0.3 m from
    the rocker's axle, the rocker 0.3 m long): |Φ| has a minimum that is
    not 0. From the model's guess the damped iteration reaches it, its line searches then
    find no descent, and it stops after STALLED_SEARCHES of them, not after its 200
    iterations (a redundant parallelogram driven 1e5 s a step spent 20 s in 51 such
    solves): the same answer, not solved, for a fraction of the residuals."""
    from pam2exu.backend.natural import solver as solver_module
    text = (ROOT / "examples" / "four_bar.toml").read_text(encoding="utf-8")
    mech = pam2exu.loads(text.replace("B = [0.35, 0.0]", "B = [0.7, 0.0]")).mechanism()
    form, solver = solver_of(mech)
    z0 = form.from_q(mech.initial_q())[0]
    counted = []
    residual = form.terms.residual
    monkeypatch.setattr(form.terms, "residual", lambda *a: counted.append(1) or residual(*a))
    monkeypatch.setattr(solver_module, "STALLED_SEARCHES", 10 ** 9)        # as before
    z_all, ok_all = solver.damped(0.0, z0)
    before = len(counted)
    counted.clear()
    monkeypatch.setattr(solver_module, "STALLED_SEARCHES", 3)
    z_now, ok_now = solver.damped(0.0, z0)
    assert not ok_all and not ok_now
    assert before > 1000 and len(counted) < before / 10
    # where it stopped, |Φ| is as low as 200 iterations took it, to the line search's 1e-4
    size = lambda z: np.linalg.norm(residual(np.array([0.0]), z[None])[0])      # noqa: E731
    assert size(z_now) <= size(z_all) * (1 + 1e-3)

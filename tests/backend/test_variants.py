"""Many variants in one pass on the natural backend (pam2exu/backend/natural/variants.py,
``Natural.solved_variants``).

Reference: each variant solved alone by the same backend (``Natural.solve_positions``,
the run's own path: coarse pass, fill, sub-steps), its x, y, fi and rates compared
column by column relative to the column's largest value. The pass steps differently
(every variant at once, its own coarse pass and fill), so the two agree to Newton's
tolerance, not bit for bit.
"""

import numpy as np
import pytest

from benchmarks.cases import chain_model
from pam2exu.backend.natural import Natural, NaturalSettings
from pam2exu.backend.natural.variants import structure
from pam2exu.model import load
from tests.conftest import varied_mechanisms
from pam2exu.studies.parameters import targets

from pathlib import Path

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


_variants = varied_mechanisms



def _alone(mech, times):
    settings = NaturalSettings()
    return Natural().solve_positions(mech, times, mech.initial_q(), settings, rates=True)


def _relative(a, b):
    scale = np.maximum(np.max(np.abs(b), axis=0), 1e-300)
    return float(np.max(np.abs(a - b) / scale))


def _check_against_alone(mechs, times, tolerance=1e-12):
    found = Natural().solved_variants(mechs, times, NaturalSettings())
    for mech, backend in zip(mechs, found):
        ref = _alone(mech, times)
        if backend is None:                       # left out of the pass: its run solves it
            continue
        got = backend.solve_positions(mech, times, mech.initial_q(), NaturalSettings(),
                                      rates=True)
        assert ref.solved == got.solved == len(times)
        for a, b in ((got.q, ref.q), (got.qd, ref.qd), (got.qdd, ref.qdd)):
            assert _relative(a, b) < tolerance
    return found


def test_four_bar_variants_equal_their_own_runs():
    rng = np.random.default_rng(5)
    mechs = _variants(load(EXAMPLES / "four_bar.toml"), {
        "coupler.B.x": list(0.35 + 2e-3 * rng.standard_normal(12)),
        "crank.A.x": list(0.10 + 2e-3 * rng.standard_normal(12))})
    found = _check_against_alone(mechs, np.linspace(0.0, 1.0, 81))
    assert all(b is not None for b in found)


def test_the_fill_starts_from_the_quintic_guess():
    """Four four-bars × 100 steps of a turn in one pass: the steps between the coarse ones
    start from the quintic through z, ż and z̈ (``solver.quintic_hermite``) and take 2.54
    Newton iterations per variant-step in all (3.16 from the cubic through z and ż), and
    each variant's answers meet its own run's to 1e-12."""
    from pam2exu.backend.natural import variants
    mechs = _variants(load(EXAMPLES / "four_bar.toml"),
                      {"crank.A.x": [0.1, 0.1001, 0.0999, 0.10005]})
    times = np.linspace(0.0, 1.0, 101)
    backend = Natural()
    forms = [backend.formulation(m) for m in mechs]
    stack = variants.Stack([f.terms for f in forms],
                           [backend.weights(f, m) for f, m in zip(forms, mechs)], times)
    z0 = np.stack([f.from_q(m.initial_q())[0] for f, m in zip(forms, mechs)], axis=1)
    answers = variants.solve(stack, z0, NaturalSettings().tolerance, 25)
    assert list(answers.solved) == [101] * 4
    assert answers.iterations / (4 * 101) < 2.8
    _check_against_alone(mechs, times)


def test_slider_crank_variants_equal_their_own_runs():
    rng = np.random.default_rng(6)
    mechs = _variants(load(EXAMPLES / "slider_crank.toml"), {
        "rod.B.x": list(0.30 + 3e-3 * rng.standard_normal(6)),
        "crank.A.x": list(0.10 + 3e-3 * rng.standard_normal(6))})
    found = _check_against_alone(mechs, np.linspace(0.0, 0.5, 41))
    assert all(b is not None for b in found)


def test_chain_of_four_loops_variants_equal_their_own_runs():
    model = chain_model(4)
    rng = np.random.default_rng(7)
    found = targets(model)
    names = [n for n in ("K2.B.x", "L3.B.x") if n in found]
    assert names
    mechs = _variants(model, {n: list(found[n].nominal * (1 + 1e-3 * rng.standard_normal(5)))
                              for n in names})
    out = _check_against_alone(mechs, np.linspace(0.0, 0.2, 33))
    assert all(b is not None for b in out)


def test_failing_variants_are_left_out_and_the_others_kept():
    # a coupler of 0.1 m or a rocker of 0.12 m make the loop non-Grashof: the crank cannot
    # turn through, their runs fail part-way
    mechs = _variants(load(EXAMPLES / "four_bar.toml"), {
        "coupler.B.x": [0.35, 0.10, 0.35, 0.351],
        "rocker.B.x": [0.30, 0.30, 0.12, 0.301]})
    times = np.linspace(0.0, 1.0, 41)
    found = _check_against_alone(mechs, times)
    assert [b is None for b in found] == [False, True, True, False]
    assert all(0 < _alone(m, times).solved < len(times) for m in mechs[1:3])  # alone too


def test_a_variant_does_not_depend_on_its_chunk():
    rng = np.random.default_rng(8)
    mechs = _variants(load(EXAMPLES / "four_bar.toml"), {
        "coupler.B.x": list(0.35 + 2e-3 * rng.standard_normal(6)),
        "rocker.B.x": list(0.30 + 2e-3 * rng.standard_normal(6))})
    times = np.linspace(0.0, 1.0, 61)
    whole = Natural().solved_variants(mechs, times, NaturalSettings())
    part = Natural().solved_variants(mechs[3:], times, NaturalSettings())
    for a, b in zip(whole[3:], part):
        for x, y in ((a.answered.z, b.answered.z), (a.answered.zdd, b.answered.zdd)):
            assert np.array_equal(x, y)            # bit for bit


def test_another_structure_is_solved_in_its_own_group():
    # a ground pivot at x = 0 has no term for x: the variants moved off it have one more
    model = load(EXAMPLES / "four_bar.toml")
    mechs = _variants(model, {"ground.O2.x": [0.0, 0.013, 0.0, 0.012]})
    backend = Natural()
    assert len({structure(backend.formulation(m).terms) for m in mechs}) == 2
    found = _check_against_alone(mechs, np.linspace(0.0, 0.5, 21))
    assert all(b is not None for b in found)


def test_the_answers_are_read_only_for_the_run_they_answer():
    mech = _variants(load(EXAMPLES / "four_bar.toml"), {"coupler.B.x": [0.352]})[0]
    times = np.linspace(0.0, 1.0, 41)
    backend = Natural().solved_variants([mech], times, NaturalSettings())[0]
    # another start (a re-solve from a predictor) or other times: solved as usual
    other = backend.solve_positions(mech, times[5:], backend.answered.guess,
                                    NaturalSettings(), rates=True)
    ref = Natural().solve_positions(mech, times[5:], backend.answered.guess, NaturalSettings(),
                                    rates=True)
    assert np.array_equal(other.q, ref.q)

"""A chunk's variants after the one pass, all at once (pam2exu/backend/natural/population.py).

References: each variant's own conversion of the pass's z, ż, z̈ (``Natural._converted``,
what its run would do): x, y, fi and their rates bit for bit; its own natural inverse
dynamics (``reactions.constraint_wrenches`` on those x, y, fi: z taken back by least
squares), every wrench and the kinetic energy to 1e-12 of the largest value of its kind.
"""

import numpy as np
import pytest

from benchmarks.cases import chain_model
from pam2exu.backend.natural import Natural, NaturalSettings
from pam2exu.backend.natural.reactions import constraint_wrenches
from pam2exu.errors import ModelError
from pam2exu.model import load
from tests.conftest import varied_mechanisms
from pam2exu.studies.parameters import targets

from pathlib import Path

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


_variants = varied_mechanisms



def _own(backend, mech):
    """The variant's x, y, fi, rates and reactions as its own run computes them."""
    a = backend.answered
    form = Natural().formulation(mech)
    q, qd, qdd = Natural()._converted(form, mech, a.z, a.guess, a.zd, a.zdd)
    return (q, qd, qdd), constraint_wrenches(form, a.times, q, qd, qdd)


def _check(mechs, times):
    found = Natural().solved_variants(mechs, times, NaturalSettings())
    checked = 0
    for mech, backend in zip(mechs, found):
        if backend is None:
            continue
        a = backend.answered
        (q, qd, qdd), ref = _own(backend, mech)
        for x, y in ((a.q, q), (a.qd, qd), (a.qdd, qdd)):
            assert np.array_equal(x, y)                       # bit for bit
        got = a.reactions(a.times, a.q, a.qd, a.qdd)
        assert got is not None
        scale = np.max(np.abs(ref.wrenches[:, :, :2]))
        assert np.max(np.abs(got.wrenches[:, :, :2] - ref.wrenches[:, :, :2])) <= 1e-12 * scale
        moments = np.max(np.abs(ref.wrenches[:, :, 2]), initial=scale * 1e-3)
        assert np.max(np.abs(got.wrenches[:, :, 2] - ref.wrenches[:, :, 2])) <= 1e-12 * moments
        assert np.max(np.abs(got.kinetic - ref.kinetic)) <= 1e-12 * np.max(np.abs(ref.kinetic))
        checked += 1
    return found, checked


def test_four_bar_variants_equal_their_own_conversion_and_reactions():
    rng = np.random.default_rng(11)
    mechs = _variants(load(EXAMPLES / "four_bar.toml"), {
        "coupler.B.x": list(0.35 + 2e-3 * rng.standard_normal(7)),
        "crank.A.x": list(0.10 + 2e-3 * rng.standard_normal(7))})
    _, checked = _check(mechs, np.linspace(0.0, 1.0, 61))
    assert checked == 7


def test_slider_crank_and_a_chain_of_four_loops():
    rng = np.random.default_rng(12)
    mechs = _variants(load(EXAMPLES / "slider_crank.toml"), {
        "rod.B.x": list(0.30 + 3e-3 * rng.standard_normal(5))})
    assert _check(mechs, np.linspace(0.0, 0.5, 41))[1] == 5
    model = chain_model(4)             # drag links: every link turns, its atan2 wraps
    nominal = targets(model)["K2.B.x"].nominal
    mechs = _variants(model, {"K2.B.x": list(nominal * (1 + 1e-3 * rng.standard_normal(4)))})
    found, checked = _check(mechs, np.linspace(0.0, 1.0, 81))
    assert checked == 4
    a = found[0].answered                          # the free solids' angles: unwrapped
    assert np.max(np.ptp(a.q[:, a.free_fi], axis=0)) > 2 * np.pi - 0.1


def test_every_element_kind_with_loads():
    # prismatic, pin-in-slot, transmission, actuators' rows in the solids' frames; gravity,
    # a spring, a torsional spring and torsors as loads
    model = load(EXAMPLES / "all_elements.toml")
    name = next(n for n in targets(model) if n.endswith(".x") and "." in n[:-2])
    nominal = targets(model)[name].nominal
    mechs = _variants(model, {name: [nominal, nominal * (1 + 1e-3), nominal * (1 - 2e-3)]})
    found, checked = _check(mechs, np.linspace(0.0, 0.5, 26))
    assert checked == sum(b is not None for b in found) == 3


def test_reactions_do_not_depend_on_the_chunk():
    rng = np.random.default_rng(13)
    mechs = _variants(load(EXAMPLES / "four_bar.toml"), {
        "rocker.B.x": list(0.30 + 2e-3 * rng.standard_normal(5))})
    times = np.linspace(0.0, 1.0, 41)
    whole = Natural().solved_variants(mechs, times, NaturalSettings())
    part = Natural().solved_variants(mechs[2:], times, NaturalSettings())
    for a, b in zip(whole[2:], part):
        x, y = a.answered, b.answered
        assert np.array_equal(x.q, y.q)
        rx, ry = x.reactions(x.times, x.q, x.qd, x.qdd), y.reactions(y.times, y.q, y.qd, y.qdd)
        assert np.array_equal(rx.wrenches, ry.wrenches)       # bit for bit
        assert np.array_equal(rx.kinetic, ry.kinetic)


def test_another_motion_is_not_answered():
    mechs = _variants(load(EXAMPLES / "four_bar.toml"), {"coupler.B.x": [0.35, 0.351]})
    times = np.linspace(0.0, 1.0, 21)
    backend = Natural().solved_variants(mechs, times, NaturalSettings())[0]
    a = backend.answered
    moved = a.q.copy()
    moved[5, 2] += 1e-9                     # a step solved again, say: its own reactions
    assert a.reactions(times, moved, a.qd, a.qdd) is None
    assert a.reactions(times[:-1], a.q[:-1], a.qd[:-1], a.qdd[:-1]) is None
    near = a.guess + 1e-3                   # (the run starts from its assembly, say)
    own = Natural()._converted(Natural().formulation(mechs[0]), mechs[0], a.z, near, a.zd,
                               a.zdd)
    assert all(np.array_equal(x, y) for x, y in zip(a.converted(len(times), near), own))
    turned = a.guess.copy()
    turned[a.free_fi[0]] += 2 * np.pi       # a whole turn on: converted as usual
    assert a.free_fi.size and a.converted(len(times), turned) is None
    got = backend.reactions(mechs[0], times, moved, a.qd, a.qdd)
    ref = constraint_wrenches(Natural().formulation(mechs[0]), times, moved, a.qd, a.qdd)
    assert np.array_equal(got.wrenches, ref.wrenches)


def test_a_variant_whose_loads_fail_is_left_to_its_run(monkeypatch):
    from pam2exu.backend.natural import inverse
    mechs = _variants(load(EXAMPLES / "four_bar.toml"), {"coupler.B.x": [0.35, 0.351, 0.349]})
    times = np.linspace(0.0, 1.0, 21)
    found = Natural().solved_variants(mechs, times, NaturalSettings())
    original = inverse.applied

    def applied(form, t, z, q, zd):
        if form.mech is mechs[1]:
            raise ModelError("a spring's two points meet")
        return original(form, t, z, q, zd)

    monkeypatch.setattr(inverse, "applied", applied)
    given = [b.answered.reactions(b.answered.times, b.answered.q, b.answered.qd,
                                  b.answered.qdd) for b in found]
    assert [g is None for g in given] == [False, True, False]


@pytest.mark.parametrize("columns", [1, 3])
def test_blocks_of_rows_give_the_same_bits(monkeypatch, columns):
    from pam2exu.backend.natural import population
    mechs = _variants(load(EXAMPLES / "four_bar.toml"), {"coupler.B.x": [0.35, 0.351, 0.349]})
    times = np.linspace(0.0, 1.0, 31)
    whole = Natural().solved_variants(mechs, times, NaturalSettings())
    monkeypatch.setattr(population, "BLOCK_ROWS", columns)
    blocks = Natural().solved_variants(mechs, times, NaturalSettings())
    for a, b in zip(whole, blocks):
        x, y = a.answered, b.answered
        rx, ry = x.reactions(x.times, x.q, x.qd, x.qdd), y.reactions(y.times, y.q, y.qd, y.qdd)
        assert np.array_equal(rx.wrenches, ry.wrenches)


def test_a_pass_too_large_to_convert_leaves_each_run_its_own(monkeypatch):
    from pam2exu.backend.natural import population
    mechs = _variants(load(EXAMPLES / "four_bar.toml"), {"coupler.B.x": [0.35, 0.351]})
    times = np.linspace(0.0, 1.0, 21)
    monkeypatch.setattr(population, "MOST_BYTES", 3 * 8 * 2 * 21 * mechs[0].nq - 1)
    found = Natural().solved_variants(mechs, times, NaturalSettings())
    assert all(b.answered.q is None and b.answered.group is None for b in found)
    a = found[0].answered                      # its run converts, and makes its reactions
    got = found[0].solve_positions(mechs[0], times, a.guess, NaturalSettings(), rates=True)
    own = Natural()._converted(Natural().formulation(mechs[0]), mechs[0], a.z, a.guess,
                               a.zd, a.zdd)
    assert np.array_equal(got.q, own[0]) and np.array_equal(got.qdd, own[2])
    assert a.reactions(times, got.q, got.qd, got.qdd) is None

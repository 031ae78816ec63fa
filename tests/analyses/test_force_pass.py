"""force_pass.power_balance: the residual of Σ P_actuators = dE/dt + dissipation − P_torsors
and its tolerance, against closed forms; the reported reactions of every constraint in one
pass against each element's own, the energies without the generalized forces against those
with them, and the columns a run gives itself not computed again (bit for bit).

Reference: E(t) = sin(ωt) sampled every dt, with the exact power P = ω cos(ωt). The
fourth-order central difference's error is −(dt⁴/30) E⁽⁵⁾ + O(dt⁶) (Taylor expansion of
the stencil), so the residual is (dt⁴/30) ω⁵ at its largest, and its Richardson estimate
(D(2dt) − D(dt))/15 the same: the tolerance is 10 × that, + 1e-9 × the largest power
+ round-off (1e3 ε max|E| / dt).
"""
from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from pam2exu.analyses.force_pass import power_balance

OMEGA, DT = 2 * math.pi, 0.01
T = np.arange(101) * DT
ENERGY = np.sin(OMEGA * T)
POWER = OMEGA * np.cos(OMEGA * T)
ZERO = np.zeros_like(T)
NO_LAWS = SimpleNamespace(drivers=[])          # no breakpoints: every step k = 4 … n−5
TRUNCATION = DT**4 / 30 * OMEGA**5             # 3.26e-6 W


def test_the_power_balance_tolerance_is_ten_times_the_difference_error():
    found = power_balance(NO_LAWS, T, POWER, ENERGY, ZERO, ZERO)
    assert found.checked == len(T) - 8
    assert found.error == pytest.approx(TRUNCATION, rel=2e-3)
    roundoff = 1e3 * np.finfo(float).eps / DT
    assert found.tolerance == pytest.approx(10 * TRUNCATION + 1e-9 * OMEGA + roundoff,
                                            rel=1e-2)
    assert found.ok


def test_a_power_missing_from_the_balance_fails_it():
    """100 × the difference's error (10 × the tolerance) missing from the actuators'
    power: not ok (with the tolerance × 1000 it would pass)."""
    missing = 100 * TRUNCATION
    found = power_balance(NO_LAWS, T, POWER + missing, ENERGY, ZERO, ZERO)
    assert found.error == pytest.approx(missing, rel=2e-2)
    assert not found.ok


def test_steps_whose_stencil_crosses_a_breakpoint_are_not_checked():
    """A law breakpoint at 0.505 s (between rows 50 and 51): the steps k with
    t[k−4] < 0.505 ≤ t[k+4], k = 47 … 54, are left out, and a power error there is not
    seen; breakpoints covering every step leave none checked."""
    law = SimpleNamespace(breakpoints=lambda: (0.505,))
    mech = SimpleNamespace(drivers=[SimpleNamespace(time_law=lambda: law)])
    spike = np.where(np.arange(len(T)) == 50, 1.0, 0.0)
    found = power_balance(mech, T, POWER + spike, ENERGY, ZERO, ZERO)
    assert found.checked == len(T) - 8 - 8
    assert found.error <= TRUNCATION * 1.002 and found.ok
    everywhere = SimpleNamespace(breakpoints=lambda: tuple(T[4:-4] + DT / 2))
    mech = SimpleNamespace(drivers=[SimpleNamespace(time_law=lambda: everywhere)])
    found = power_balance(mech, T, POWER, ENERGY, ZERO, ZERO)
    assert (found.error, found.tolerance, found.checked) == (0.0, 0.0, 0)


# ---- the reported reactions of every constraint at once ----------------------------------

@pytest.fixture(scope="module")
def all_elements():
    """Every element type's mechanism at 7 random states (positions, rates), and random
    wrenches on the receivers about their origins."""
    from pam2exu.model import load
    mech = load("examples/all_elements.toml").mechanism()
    rng = np.random.default_rng(7)
    q, qd = rng.uniform(-2, 2, (2, 7, mech.nq))
    return mech, q, qd, rng.normal(size=(7, len(mech.constraints), 3))


def test_the_stacked_report_is_each_elements_own(all_elements):
    """reported_wrenches (one pass over every constraint, frames from a values-only State)
    gives, bit for bit, each element's reported_wrench (moved to its reporting point,
    turned into its basis from a full State)."""
    from pam2exu.analyses.force_pass import reported_wrench, reported_wrenches
    from pam2exu.kinematics import State
    mech, q, qd, wrenches = all_elements
    found = reported_wrenches(mech, State(np.zeros(7), q, qd), wrenches)
    for k, el in enumerate(mech.constraints):
        own = reported_wrench(el, State(np.zeros(7), q, qd), wrenches[:, k])
        assert found[:, k].tobytes() == own.tobytes(), el.name


def test_a_moment_at_a_revolute_is_an_internal_error(all_elements):
    """checked_reactions returns the reported components by column name and refuses a
    component that must be zero (a revolute's moment) above 1e-9 of the element's scale."""
    from pam2exu.analyses.force_pass import checked_reactions
    from pam2exu.errors import TranslationError
    mech = all_elements[0]
    wrenches = np.zeros((3, len(mech.constraints), 3))
    for k, el in enumerate(mech.constraints):           # the reported components only
        wrenches[:, k, [j for j, name in enumerate(el.wrench) if name is not None]] = 10.0
    k = next(k for k, el in enumerate(mech.constraints) if el.type == "revolute")
    name = mech.constraints[k].name
    found = checked_reactions(mech, wrenches)
    assert found[f"{name}.Fx"].tolist() == [10.0] * 3 and f"{name}.Mz" not in found
    wrenches[1, k, 2] = 1e-3 * mech.scale() * 10.0          # 1e-3 of the scale
    with pytest.raises(TranslationError, match=f"'{name}' \\(revolute\\) has a moment"):
        checked_reactions(mech, wrenches)


def test_the_energies_without_the_generalized_forces_are_the_same(all_elements):
    """applied_forces(forces=False) (what a backend's reactions leave to compute) gives
    the same potential, dissipation, torsor forces and outputs, bit for bit."""
    from pam2exu.analyses.force_pass import applied_forces
    from pam2exu.kinematics import State
    mech, q, qd, _ = all_elements
    full = applied_forces(mech, State(np.zeros(7), q, qd), damping=True)
    light = applied_forces(mech, State(np.zeros(7), q, qd), damping=True, forces=False)
    assert light.force is None
    for a, b in [(full.potential, light.potential), (full.dissipation, light.dissipation),
                 (full.external, light.external)]:
        assert a.tobytes() == b.tobytes()
    assert full.outputs.keys() == light.outputs.keys()
    assert all(np.array_equal(full.outputs[k], light.outputs[k]) for k in full.outputs)


def test_columns_the_analysis_gives_are_not_computed_again(monkeypatch):
    """A kinetostatic run asked for the motor's torque (its own column) and the rocker's
    angle does not evaluate the motor's outputs (``compute``: its law), and its columns are
    the full run's, bit for bit."""
    import pam2exu
    mech = pam2exu.load("examples/four_bar.toml").mechanism()
    full = pam2exu.run(mech, "kinetostatic", steps=16, backend="natural")
    motor = next(el for el in mech.elements if el.name == "motor")
    asked = []
    own = type(motor).compute
    monkeypatch.setattr(type(motor), "compute",
                        lambda el, st, names: asked.append(names) or own(el, st, names))
    part = pam2exu.run(mech, "kinetostatic", steps=16, backend="natural",
                       outputs=["motor.Mz", "rocker.fi"])
    assert asked == []
    for name in part.columns:
        assert part[name].tobytes() == full[name].tobytes()
    pam2exu.run(mech, "kinetostatic", steps=16, backend="natural", outputs=["motor.Df(t)"])
    assert asked == [{"Df(t)"}]

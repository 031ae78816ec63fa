"""force_pass.power_balance: the residual of Σ P_actuators = dE/dt + dissipation − P_torsors
and its tolerance, against closed forms.

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

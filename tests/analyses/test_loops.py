"""loops.py: a loop that cannot close because the free chain is too long for the gap, not
too short (the 'gap < shortest' half of the reach test).

Reference: the example four-bar (ground d = 0.4 m, crank a = 0.1 m) with its coupler b and
rocker c changed, at θ = f(0) = 0: the chain coupler–rocker from crank.A = (a, 0) to
ground.O4 = (d, 0) must span the gap δ = d − a = 0.3 m, and spans |b − c| … b + c
(triangle inequality).
"""
from __future__ import annotations

from pathlib import Path

import pytest

import pam2exu

FOUR_BAR = Path(__file__).resolve().parents[2] / "examples" / "four_bar.toml"


def test_a_chain_too_long_for_its_gap_is_named_with_its_span():
    """b = 0.35 m, c = 0.02 m: the polygon test passes (longest 0.4 ≤ 0.47), but the gap
    0.3 m is below |b − c| = 0.33 m: the error names the gap and the span 0.33 … 0.37 m
    (without that half of the test: 'its lengths would close it, but not in the position
    its actuators set')."""
    m = pam2exu.load(FOUR_BAR)
    m["rocker"].points["B"] = [0.02, 0.0]
    m["rocker"].fi = 3.0
    with pytest.raises(pam2exu.SolverError) as info:
        pam2exu.run(m, analysis="assembly")
    message = str(info.value)
    assert "ground.O4 and crank.A are 0.3 m apart" in message, message
    assert "spans only 0.33 … 0.37 m" in message, message
    assert "would close it" not in message


ALL_ELEMENTS = FOUR_BAR.parent / "all_elements.toml"


def test_a_loop_whose_actuator_length_is_0_is_named_without_a_fault():
    """examples/all_elements.toml with the cylinder's pin-to-pin length at t = 0 a subnormal
    5e-324 m (bezier_c2 C3; fuzz seed 60675): the diagnosis of the assembly met a Jacobian
    with NaN (its two points coincide, so the distance has no direction), and the SVD in
    ``rigid`` raised. Now the error names the loop that cannot close, with no warning of
    NumPy's."""
    import warnings
    text = ALL_ELEMENTS.read_text(encoding="utf-8")
    assert text.count("C = [0.2, 0.8, 0.28, 0.38]") == 1
    model = pam2exu.loads(text.replace("C = [0.2, 0.8, 0.28, 0.38]",
                                       "C = [0.2, 0.8, 5e-324, 0.38]"))
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        with pytest.raises(pam2exu.SolverError) as info:
            pam2exu.run(model, analysis="kinematic", backend="natural", steps=4)
    message = str(info.value)
    assert "fault of pam2exu" not in message, message
    assert "the loop piston –piston_pin– rocker" in message and "cannot close" in message


def test_rigid_is_false_where_the_columns_are_not_finite():
    """``loops.rigid`` on a Jacobian with a NaN: the rank cannot be told, so False (the SVD
    raised LinAlgError before)."""
    import numpy as np
    from pam2exu.analyses.loops import rigid
    mech = pam2exu.load(FOUR_BAR).mechanism()
    jac = np.eye(mech.n_equations, mech.nq)         # solid 1's columns: of full rank
    assert rigid(mech, jac, mech.constraints, {1})
    jac[0, 3] = np.nan
    assert not rigid(mech, jac, mech.constraints, {1})

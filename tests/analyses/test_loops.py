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

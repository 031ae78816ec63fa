"""Every shipped example loads and runs (kinematic over its interval, and assembly)."""
from pathlib import Path

import numpy as np
import pytest

import pam2exu

EXAMPLES = sorted((Path(__file__).resolve().parents[1] / "examples").glob("*.toml"))


def test_examples_exist():
    assert {p.name for p in EXAMPLES} >= {"slider_crank.toml", "four_bar.toml",
                                          "all_elements.toml"}


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_example_runs(path):
    res = pam2exu.run(path, analysis="kinematic")
    model = pam2exu.load(path)
    assert len(res) == model.analysis.steps + 1
    assert np.isfinite(res.to_numpy()).all()
    assert res.info["dof"] == 0 and res.info["max_residual"] < 1e-12
    assembled = pam2exu.run(path, analysis="assembly")
    assert len(assembled) == 1
    for s in model.solids:
        assert assembled[f"{s.name}.fi"][0] == pytest.approx(res[f"{s.name}.fi"][0], abs=1e-12)


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
@pytest.mark.parametrize("analysis", ["quasi_static", "kinetostatic"])
def test_example_force_analyses_pass_their_checks(path, analysis):
    """Every example runs the force analyses with every check met and no warning."""
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = pam2exu.run(path, analysis=analysis, steps=100)
    assert np.isfinite(res.to_numpy()).all()
    assert not res.warnings
    if analysis == "quasi_static":
        assert res.info["equilibrium_error"] < 1e-12
    else:
        assert res.info["power_balance_error"] <= res.info["power_balance_tolerance"]


def test_examples_own_analysis_runs():
    """Each example runs as declared (the contract's slider-crank is kinetostatic)."""
    for path in EXAMPLES:
        res = pam2exu.run(path)
        assert res.analysis == pam2exu.load(path).analysis.type

"""First-order sensitivities ∂y/∂p (pam2exu/analyses/sensitivity.py, complex_step.py).

References: the slider-crank's slider position in closed form, x = r cos θ + √(L² − r² sin² θ)
(crank r, rod L, no offset), with ∂x/∂r = cos θ − r sin² θ / √(L² − r² sin² θ) and
∂x/∂L = L / √(L² − r² sin² θ), at the crank angles θ of the run; central differences of
whole runs (independent: two runs of the model with p ± ε written in, no complex number
anywhere), whose own error (ε² y''' / 6 plus round-off / ε) bounds the agreement.
"""
import copy
import warnings
from pathlib import Path

import numpy as np
import pytest

import pam2exu
from pam2exu.analyses.job import check_mobility, prepare
from pam2exu.analyses.sensitivity import STEP, derivatives, nominal
from pam2exu.errors import ModelError, SolverError
from pam2exu.model import load
from pam2exu.studies.parameters import targets, write

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"


def _sensitivity(model, analysis, name, steps):
    """(∂y/∂p of every column, the nominal run, the job) by ``derivatives``."""
    mech = model.mechanism()
    job = prepare(model, analysis, steps=steps)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = pam2exu.run(model, analysis, steps=steps,
                          outputs=list(dict.fromkeys(job.columns
                                                     + mech.coordinate_columns(""))))
    redundant = check_mobility(job, mech.initial_q()).redundant > 0
    target = targets(model)[name]
    shifted = copy.deepcopy(model)
    write(shifted, target, complex(target.nominal, STEP))
    return derivatives(job, nominal(job, res.t, mech.coordinates(res), redundant), shifted,
                       parameter=name), res, job


def _central(model, analysis, name, steps, eps):
    """(y(p + ε) − y(p − ε)) / 2ε of every column, from two whole runs."""
    target = targets(model)[name]
    runs = []
    for sign in (1, -1):
        varied = copy.deepcopy(model)
        write(varied, target, target.nominal + sign * eps)
        varied.validate()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            runs.append(pam2exu.run(varied, analysis, steps=steps))
    return {c: (runs[0][c] - runs[1][c]) / (2 * eps) for c in runs[0].columns}


def test_the_slider_position_is_differentiated_exactly():
    model = load(EXAMPLES / "slider_crank.toml")
    r, L = 0.1, 0.3
    for name in ("crank.A.x", "rod.B.x"):
        d, res, _ = _sensitivity(model, "kinematic", name, steps=16)
        theta = res["crank.fi"]
        root = np.sqrt(L * L - (r * np.sin(theta)) ** 2)
        assert np.allclose(res["slider.x"], r * np.cos(theta) + root, rtol=0, atol=1e-13)
        exact = (np.cos(theta) - r * np.sin(theta) ** 2 / root if name == "crank.A.x"
                 else L / root)
        assert np.max(np.abs(d["slider.x"] - exact)) <= 1e-12 * np.max(np.abs(exact))


# every kind of parameter: a point, a line's angle, a mass, an inertia, a centre of mass,
# a law constant, gravity
SLIDER_PARAMETERS = ("crank.A.x", "rod.B.x", "ground.rail.angle", "rod.mass", "rod.inertia",
                     "rod.cog.y", "motor.C2", "model.gravity")
FOUR_BAR_PARAMETERS = ("coupler.B.x", "rocker.B.y", "ground.O4.x", "coupler.P.y",
                       "coupler.cog.x", "crank.mass", "motor.C2")


def _agree(d, fd, res, eps, tolerance=1e-6, rows=slice(None)):
    """|∂y/∂p − central difference| ≤ tolerance · max |difference| of the column, plus the
    difference's own round-off, 100 u S / ε (u: the unit round-off; S: the largest |y| of
    the columns in the same unit, the scale of a solver's error in y: the runs are solved
    to 1e-13 or so, not to u), per column."""
    scale = {}
    for c in fd:
        scale[res.units[c]] = max(scale.get(res.units[c], 0.0), np.max(np.abs(res[c])))
    worst = 0.0
    for c in fd:
        bound = (tolerance * np.max(np.abs(fd[c]))
                 + 100 * 2.2e-16 * scale[res.units[c]] / eps + 1e-300)
        worst = max(worst, np.max(np.abs(d[c] - fd[c])[rows]) / bound)
    assert worst <= 1.0, worst


@pytest.mark.parametrize("name", SLIDER_PARAMETERS)
def test_the_slider_crank_agrees_with_central_differences_of_whole_runs(name):
    model = load(EXAMPLES / "slider_crank.toml")
    d, res, job = _sensitivity(model, "kinetostatic", name, steps=7)
    fd = _central(model, "kinetostatic", name, steps=7, eps=1e-6)
    _agree(d, fd, res, 1e-6)


@pytest.mark.parametrize("name", FOUR_BAR_PARAMETERS)
def test_the_four_bar_agrees_with_central_differences_of_whole_runs(name):
    model = load(EXAMPLES / "four_bar.toml")
    d, res, job = _sensitivity(model, "kinetostatic", name, steps=7)
    fd = _central(model, "kinetostatic", name, steps=7, eps=1e-6)
    _agree(d, fd, res, 1e-6)


@pytest.mark.long
@pytest.mark.parametrize("path", ["slider_crank.toml", "four_bar.toml", "all_elements.toml"])
def test_every_parameter_agrees_with_central_differences(path):
    """All of them, every column, kinetostatic (all_elements: every element type; 13 steps
    so that no row falls on a law's breakpoint, where a law's time has no derivative)."""
    model = load(EXAMPLES / path)
    checked = 0
    for name, target in targets(model).items():
        eps = 1e-6 * max(1.0, abs(target.nominal))
        try:
            fd = _central(model, "kinetostatic", name, steps=13, eps=eps)
        except ModelError:                 # p − ε not allowed (a mass or gravity of 0)
            continue
        d, res, job = _sensitivity(model, "kinetostatic", name, steps=13)
        # a law's start or end time at an output row (t = 0, t_end): the law has no
        # derivative there with respect to that time (one-sided), the difference straddles it
        breaks = [b for el in job.mech.drivers for b in el.time_law().breakpoints()]
        rows = ~np.isin(np.round(res.t, 12), np.round(breaks, 12))
        try:
            _agree(d, fd, res, eps, rows=rows)
        except AssertionError as exc:
            raise AssertionError(f"{path} {name}: {exc}") from None
        checked += 1
    assert checked >= 20


def test_a_redundant_mechanism_follows_a_parameter_its_constraints_allow():
    """The parallelogram with a third crank (one redundant loop): the motor's law moves
    it consistently, so the normal-equation solve gives the derivative."""
    model = load(ROOT / "tests" / "data" / "parallelogram5.toml")
    d, res, job = _sensitivity(model, "kinematic", "motor.C2", steps=6)
    fd = _central(model, "kinematic", "motor.C2", steps=6, eps=1e-6)
    _agree(d, fd, res, 1e-6)


def test_a_redundant_mechanism_refuses_a_dimension_that_breaks_its_assembly():
    model = load(ROOT / "tests" / "data" / "parallelogram5.toml")
    with pytest.raises(SolverError, match="crank3.A.x cannot vary in this over-constrained"):
        _sensitivity(model, "kinematic", "crank3.A.x", steps=4)


def test_real_runs_are_unchanged_by_the_complex_paths():
    """The helpers that keep a complex number complex give a float run bit for bit what
    numpy's real functions give (they pass reals to the same functions)."""
    from pam2exu import complex_step as cs
    rng = np.random.default_rng(3)
    x, y = rng.normal(size=50), rng.normal(size=50)
    assert np.array_equal(cs.hypot(x, y), np.hypot(x, y))
    assert np.array_equal(cs.atan2(y, x), np.arctan2(y, x))
    assert np.array_equal(cs.absolute(x), np.abs(x))
    d = rng.normal(size=(7, 2))
    assert np.array_equal(cs.row_norm(d), np.linalg.norm(d, axis=1, keepdims=True))
    assert cs.scalar(0.1) == 0.1 and type(cs.scalar(1)) is float
    h = 1e-30
    for f, df in ((cs.hypot, lambda: (x * 1 + y * 0) / np.hypot(x, y)),):
        assert np.allclose(np.imag(f(x + 1j * h, y)) / h, df(), rtol=1e-14)
    assert np.allclose(np.imag(cs.atan2(y, x + 1j * h)) / h, -y / (x * x + y * y), rtol=1e-14)
    assert np.array_equal(np.imag(cs.absolute(x + 1j * h)) / h, np.sign(x))

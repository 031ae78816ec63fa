"""Minimal reproducers of what fuzz campaigns found (issue 22: the campaign extended to the
natural backend, verify, export and plot), each failing before its fix; the seed of the
campaign (``python -m tests.fuzz.runner --case SEED``) in each docstring."""
import warnings
from pathlib import Path

import pytest

import pam2exu

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"

BACKENDS = ("exudyn", "natural")


def crank(extra_fix=False) -> pam2exu.Model:
    """A crank turned at 2 rad/s (tests/data/compare/crank.toml without its spring); with
    ``extra_fix`` a fixed link on the crank as well, which the motor contradicts from t > 0."""
    m = pam2exu.Model("crank", gravity=0.0)
    m.add_solid("ground", points={"O": [0.0, 0.0]})
    m.add_solid("crank", mass=1.0, inertia=1e-3, cog=[0.05, 0.0],
                points={"O": [0.0, 0.0], "A": [0.1, 0.0]})
    m.add("fixed", name="base", anc1="ground")
    m.add("revolute", name="O", anc1="ground.O", anc2="crank.O")
    m.add("angular_actuator", name="motor", anc1="ground", anc2="crank", C=[0.0, 2.0])
    if extra_fix:
        m.add("fixed", name="extra_fix", anc1="crank")
    return m


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.filterwarnings("ignore::pam2exu.RedundancyWarning")
def test_every_solid_held_and_a_motor_that_contradicts_them(backend):
    """Seed 401: every solid held by a fixed link leaves the natural backend no coordinate;
    it raised ZeroDivisionError (and IndexError, seed 408). Both backends now name the
    contradiction."""
    with pytest.raises(pam2exu.SolverError, match=r"'base', 'motor', 'extra_fix' contradict "
                                                  r"each other.*Without 'extra_fix'"):
        pam2exu.run(crank(extra_fix=True), analysis="kinematic", backend=backend,
                    t_end=0.1, steps=10)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.filterwarnings("ignore::pam2exu.RedundancyWarning")
def test_every_solid_held_and_consistent_runs(backend):
    """Held solids whose constraints agree: nothing to solve, the fixed pose at every row."""
    m = crank(extra_fix=True)
    m.elements[:] = [el for el in m.elements if el.name != "motor"]
    res = pam2exu.run(m, analysis="kinetostatic", backend=backend, t_end=0.1, steps=4)
    assert list(res["crank.fi"]) == [0.0] * 5 and list(res["crank.x"]) == [0.0] * 5


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.filterwarnings("ignore::pam2exu.RedundancyWarning")
def test_two_held_solids_pinned_apart_are_a_contradiction_at_t0(backend):
    """Seed 408: two solids held by fixed links and pinned by a revolute at points 0.01 m
    apart: at t = 0 already. Was 'internal error … the translation is wrong'."""
    m = crank()
    m.solids[1].x = 0.01
    m.add("fixed", name="extra_fix", anc1="crank")
    m.elements[:] = [el for el in m.elements if el.name != "motor"]
    with pytest.raises(pam2exu.SolverError, match=r"'base', 'O', 'extra_fix' contradict each "
                                                  r"other at t = 0 s.*Without 'O'") as err:
        pam2exu.run(m, analysis="kinematic", backend=backend, t_end=0.1, steps=4)
    assert "internal error" not in str(err.value)


@pytest.mark.parametrize("backend", BACKENDS)
def test_clearance_of_a_model_without_elements(backend):
    """Seed 195: no element at all, so no closure equation: the clearance analysis's SVD of
    an empty matrix raised IndexError; now condition (ii) names the free solids."""
    m = pam2exu.Model("bare", gravity=0.0)
    m.add_solid("ground", points={"O": [0.0, 0.0]})
    m.add_solid("crank", points={"A": [0.1, 0.0]})
    with pytest.raises(pam2exu.ModelError, match=r"'ground', 'crank'"):
        pam2exu.run(m, analysis="clearance", backend=backend, t_end=0.05, steps=4)


def test_a_spring_between_pinned_points_ends_the_natural_dynamics():
    """Seed 95: a spring of free length 0.1 m between the two points a revolute pins
    together has no direction: the natural backend's integration crawled on NaN forces for
    minutes (until the fuzz runner's guard); now a SolverError names the spring at t = 0."""
    m = crank()
    m.elements[:] = [el for el in m.elements if el.name != "motor"]
    m.add_solid("arm", mass=1.0, inertia=1e-3, cog=[0.05, 0.0],
                points={"A": [0.1, 0.0], "B": [0.2, 0.0]}, x=0.0)
    m.add("revolute", name="A", anc1="crank.A", anc2="arm.A")
    m.add("spring", name="k0", anc1="crank.A", anc2="arm.A", C=[0.0, 100.0, 0.1, 0.5])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(pam2exu.SolverError, match=r"points of spring 'k0' coincide"):
            pam2exu.run(m, analysis="dynamic", backend="natural", t_end=0.01, steps=2,
                        tolerance=1e-5)


def test_two_points_of_a_solid_closer_than_round_off():
    """Seed 107791: a point of a solid moved to within 5e-324 m of another: the natural
    formulation took them as the solid's two base points and divided by |d|² = 0
    (ZeroDivisionError); now it gives the solid a unit vector. The four-bar whose coupler's
    B is moved onto A (the rocker then pinned to the crank's pin) assembles alike on both
    backends."""
    found = {}
    for backend in BACKENDS:
        model = pam2exu.load(EXAMPLES / "four_bar.toml")
        model["coupler"].points["B"] = [0.0, 5e-324]        # A is at (0, 0)
        res = pam2exu.run(model, analysis="assembly", backend=backend)
        found[backend] = [float(res[f"{s}.fi"][0]) for s in ("crank", "coupler", "rocker")]
    assert found["natural"] == pytest.approx(found["exudyn"], abs=1e-12)


def test_verify_follows_one_branch_when_the_guess_lies_between_two():
    """Seed 106649: the four-bar's coupler and rocker guesses moved far: Exudyn and the
    natural backend assembled different branches and verify said DISAGREE on 6 angles,
    which says nothing of the formulations. The second backend now starts from the first's
    assembly, verify agrees and warns of the guess."""
    model = pam2exu.load(EXAMPLES / "four_bar.toml")
    for name, (x, y, fi) in {"coupler": (0.6934892387694876, -0.39594182695492774,
                                         -0.05109058322711135),
                             "rocker": (0.08348167902716186, -0.9589284421881887,
                                        1.1727823118376355)}.items():
        model[name].x, model[name].y, model[name].fi = x, y, fi
    found = pam2exu.verify(model, analysis="kinematic", steps=20)
    assert found.ok, found.verdict()
    assert any("assembled different branches" in w for w in found.result.warnings)
    # the reference is Exudyn's own run from the guess: its branch is the one followed
    assert found.comparison["rocker.fi"].max_abs_error < 1e-9

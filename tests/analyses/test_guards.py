"""The guards of every analysis: no non-finite value in a result, no foreign exception.

Issue 10, faults 2 and 9: a spring whose anchors coincide returned NaN forces in a
"successful" result (its only sign a power balance "by up to nan W"); a linear actuator
whose points coincide at the guess gave "SVD did not converge"; a solid fixed and jointed
gave an IndexError; any other fault of pam2exu escaped as a bare NumPy exception.
"""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import pam2exu
from pam2exu.analyses import checks, closest, native
from pam2exu.analyses import job as job_module

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def four_bar_with(extra):
    model = pam2exu.load(EXAMPLES / "four_bar.toml")
    extra(model)
    return model


@pytest.mark.parametrize("analysis", ["kinematic", "kinetostatic"])
def test_a_spring_whose_points_coincide_is_a_solver_error_naming_it_and_the_time(analysis):
    """ground.O2 and crank.O are joined by the revolute O2: the spring between them has
    ro = 0 at every time, so its direction (and Dro, and its force) is undefined."""
    model = four_bar_with(lambda m: m.add("spring", name="k0", anc1="ground.O2",
                                          anc2="crank.O", C=[1.0, 10.0]))
    with pytest.raises(pam2exu.SolverError, match=r"at t = 0 s the points of spring 'k0' "
                                                  r"coincide \(ro = 0 m\)") as info:
        pam2exu.run(model, analysis=analysis)
    assert info.value.time == 0.0 and info.value.elements == ("'k0' (spring)",)


def test_a_non_finite_value_is_never_a_result(monkeypatch):
    """The last guard (job.check_finite): whatever produced it, a NaN in a column is a
    SolverError naming the column and the first time, not a result."""
    from pam2exu.elements import Spring

    def nan_after(self, st, names):
        values = real(self, st, names)
        values["ro"] = np.where(st.t >= 0.5, np.nan, values["ro"])
        return values

    real = Spring.compute
    monkeypatch.setattr(Spring, "compute", nan_after)
    model = four_bar_with(lambda m: m.add("spring", name="k", anc1="ground.O4",
                                          anc2="coupler.P", C=[0.0, 10.0]))
    with pytest.raises(pam2exu.SolverError, match=r"not numbers \(NaN or infinite\) first at "
                                                  r"t = 0.5 s \(row 100\), in k.ro") as info:
        pam2exu.run(model, analysis="kinematic")
    assert info.value.time == 0.5 and info.value.step == 100


def test_check_finite_names_every_column_of_the_first_bad_row():
    job = job_module.prepare(EXAMPLES / "four_bar.toml", "kinematic", steps=4)
    t = np.linspace(0.0, 1.0, 5)
    values = {"a.x": np.array([0, 1, np.inf, 3, 4.0]), "b.y": np.array([0, 1, np.nan, 3, 4.0]),
              "c.z": np.array([0, 1, 2, np.nan, 4.0]), "d.w": np.arange(5.0)}
    with pytest.raises(pam2exu.SolverError, match=r"first at t = 0.5 s \(row 2\), in a.x, b.y; "
                                                  r"3 columns in all"):
        job_module.check_finite(job, t, values)
    job_module.check_finite(job, t, {"d.w": np.arange(5.0)})        # nothing to say


def test_a_foreign_exception_becomes_a_solver_error_saying_what_was_done(monkeypatch):
    """Any exception that is not pam2exu's own, raised inside an analysis, reaches the
    user as a SolverError naming the stage, with the exception as its cause."""
    def broken(*args, **kwargs):
        raise IndexError("index 3 is out of bounds")

    monkeypatch.setattr(native, "rates", broken)
    with pytest.raises(pam2exu.SolverError, match=r"the kinematic analysis of .*four_bar.toml "
                                                  r"failed unexpectedly \(IndexError: index 3 is "
                                                  r"out of bounds\) while computing velocities "
                                                  r"and following the branch") as info:
        pam2exu.run(EXAMPLES / "four_bar.toml", analysis="kinematic")
    assert isinstance(info.value.__cause__, IndexError)
    assert "please report it" in str(info.value)


def test_a_linear_actuator_whose_points_coincide_at_the_guess_is_a_model_error(tmp_path):
    """The slider's point B starts on the ground's O: |PQ| = 0 has no direction there
    (before: "SVD did not converge")."""
    text = """
[[solid]]
name = "ground"
points = { O = [0.0, 0.0] }
lines = { rail = { point = [0.0, 0.0], angle = 0.0 } }
[[solid]]
name = "slider"
points = { B = [0.0, 0.0] }
lines = { axis = { point = [0.0, 0.0], angle = 0.0 } }
[[element]]
type = "fixed"
anc1 = "ground"
[[element]]
type = "prismatic"
anc1 = "ground.rail"
anc2 = "slider.axis"
[[element]]
type = "linear_actuator"
name = "act"
anc1 = "ground.O"
anc2 = "slider.B"
C = [0.1, 0.1]
"""
    with pytest.raises(pam2exu.ModelError, match=r"#3 'act' \(linear_actuator\): its equation "
                                                 r"is not defined at the initial guess"):
        pam2exu.run(pam2exu.loads(text), analysis="kinematic", steps=4)
    moved = pam2exu.loads(text.replace('name = "slider"\n', 'name = "slider"\nx = 0.1\n'))
    res = pam2exu.run(moved, analysis="kinematic", steps=4)
    assert res["slider.x"][-1] == pytest.approx(0.2, abs=1e-14)      # f(1) = 0.1 + 0.1


def test_a_solid_fixed_and_jointed_runs_with_minimum_norm_reactions():
    """The crank held by a fixed link and hinged to the held ground: nothing moves, the
    revolute is redundant (before: IndexError in native._solve)."""
    m = pam2exu.Model("held", gravity=9.81)
    m.add_solid("ground", points={"O": [0, 0]})
    m.add_solid("crank", mass=2.0, points={"O": [0, 0]})
    m.add("fixed", name="f0", anc1="ground")
    m.add("fixed", name="f1", anc1="crank")
    m.add("revolute", name="O", anc1="ground.O", anc2="crank.O")
    with pytest.warns(pam2exu.RedundancyWarning):
        res = pam2exu.run(m, analysis="kinetostatic", steps=4)
    assert np.all(res["crank.Dfi"] == 0.0)
    # the weight m g = 2 · 9.81 N is carried by f1 (a) and the pin O (b), a + b = m g; the
    # pin's force on the ground, b, is carried by f0 (f0.Fy = b). Least squares of the
    # reported components a² + b² + b²: a = 2 b, so a = 2 m g / 3, b = m g / 3
    weight = 2.0 * 9.81
    assert res["f1.Fy"] == pytest.approx(np.full(5, 2 * weight / 3), rel=1e-12)
    assert res["O.Fy"] == pytest.approx(np.full(5, weight / 3), rel=1e-12)
    assert res["f0.Fy"] == pytest.approx(np.full(5, weight / 3), rel=1e-12)


def test_the_diagnosis_of_a_failure_stops_when_its_work_is_done(monkeypatch):
    """The least-squares search behind "cannot be assembled" crawled for 24 s along the
    flat valley of a mechanism that cannot close (fuzz seeds 740, 944). Its work is
    bounded (``closest.DIAGNOSIS_WORK`` equations evaluated, not seconds, so that it says
    the same on a busy machine): with none left it stops at once and still gives its best
    configuration, and the diagnosis says the same thing."""
    model = pam2exu.load(EXAMPLES / "four_bar.toml")
    model["coupler"].points["B"] = [0.1, 0.0]
    model["rocker"].points["B"] = [0.1, 0.0]          # 0.1 + 0.1 + 0.1 < 0.4
    calls = []
    real = native.equations

    def counted(*args, **kwargs):
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(closest, "DIAGNOSIS_WORK", 0)
    monkeypatch.setattr(native, "equations", counted)
    with pytest.raises(pam2exu.SolverError, match=r"cannot be assembled .* the longest, "
                                                  r"ground.O4–ground.O2 0.4 m, is longer"):
        pam2exu.run(model, analysis="assembly")
    assert len(calls) < 50                       # the search's first call ended it


@pytest.mark.parametrize("points", [{"coupler": [0.1, 0.0], "rocker": [0.1, 0.0]},
                                    {"coupler": [0.2, 0.05]}])
def test_the_diagnosis_search_evaluates_each_point_once(monkeypatch, points):
    """Least squares asks the Jacobian at the point whose residual it has just asked: one
    evaluation of the equations gives both (fuzz seed 50320, a loop that cannot close:
    2,784 evaluations before, 1,412 after, the same diagnosis). Reference: the search with
    its residual and its Jacobian evaluated apart, as before, written here; the budget
    counts what is asked, so the search stops where it did."""
    from scipy.optimize import least_squares
    from pam2exu.kinematics import State
    from pam2exu.model import Mechanism

    model = pam2exu.load(EXAMPLES / "four_bar.toml")
    for solid, point in points.items():
        model[solid].points["B"] = point
    mech = Mechanism(model)
    q0, t = mech.initial_q(), 0.0
    weight = np.ones(mech.n_equations)
    for el, rows in zip(mech.constraints, mech.rows):
        weight[rows] *= 1e3 if el.drives or el.grounds else 1.0

    def fun(q):
        st = State([t], q[None], jacobians=False)
        return weight * native.equations(mech, st, jacobian=False).residual[0]

    def jac(q):
        return weight[:, None] * native.equations(mech, State([t], q[None])).jacobian[0]

    with np.errstate(all="ignore"):
        apart = least_squares(fun, q0, jac=jac, method="lm", max_nfev=200 * mech.nq,
                              xtol=1e-15, ftol=1e-15, gtol=1e-15)
    calls = []
    real = native.equations

    def counted(*args, **kwargs):
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(native, "equations", counted)
    left, found, converged = closest.closest_violation(mech, t, q0)
    assert np.array_equal(found, apart.x) and converged == (apart.status > 0)
    # one evaluation per point whose residual is asked (least_squares' own first one
    # included): no Jacobian evaluated apart (before: one per njev besides)
    assert apart.njev > 0 and len(calls) <= apart.nfev + 1
    assert np.array_equal(left, native.residuals(mech, np.array([t]), found[None])[0])


def test_a_driven_solid_also_fixed_is_a_contradiction_not_an_internal_error(tmp_path):
    """Fuzz seed 6295: a crank held by a fixed link and turned by a motor. Exudyn, told to
    ignore the singular Jacobian of the redundant constraints, stops on a configuration
    that violates the motor's law; that was reported as an internal error of the
    translation. It is the contradiction of the two constraints, from the first step."""
    path = tmp_path / "fixed_and_driven.toml"
    path.write_text("""
[[solid]]
name = "ground"
points = { O = [0.0, 0.0] }
[[solid]]
name = "crank"
points = { O = [0.0, 0.0], A = [0.1, 0.0] }
[[element]]
type = "fixed"
name = "base"
anc1 = "ground"
[[element]]
type = "revolute"
name = "O"
anc1 = "ground.O"
anc2 = "crank.O"
[[element]]
type = "angular_actuator"
name = "motor"
anc1 = "ground"
anc2 = "crank"
C = [0.0, 2.0]
[[element]]
type = "fixed"
name = "extra_fix"
anc1 = "crank"
[analysis]
t_end = 1.0
steps = 100
""", encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pam2exu.RedundancyWarning)
        with pytest.raises(pam2exu.SolverError, match=r"the constraints of .*'motor'.*'extra_fix' "
                           r"contradict each other from t = 0 s to t = 0\.01 s .*Without "
                           r"'extra_fix' the others agree") as info:
            pam2exu.run(path)
    assert not isinstance(info.value, pam2exu.TranslationError)
    assert info.value.time == pytest.approx(0.01)


@pytest.mark.parametrize("analysis, undefined", [
    ("kinematic", "velocities are not defined"),
    ("kinetostatic", "velocities and reactions are not defined"),
    ("quasi_static", "velocities and reactions are not defined")])
def test_a_singular_position_names_what_the_analysis_would_give(analysis, undefined):
    """The singular-position message says reactions are undefined too when the analysis
    gives forces (``AnalysisType.gives_forces``), not by its name."""
    from types import SimpleNamespace

    from pam2exu.analyses.failure import singular_error
    from pam2exu.registry import ANALYSES
    job = SimpleNamespace(times=np.array([0.0, 0.5]), mech=SimpleNamespace(drivers=[]),
                          analysis_type=ANALYSES[analysis])
    assert undefined in str(singular_error(job, 1))


def test_a_run_of_a_mechanism_is_the_run_of_its_model():
    """``run`` takes a model's ``Mechanism`` (validated already, as a study's one-pass
    variants give it): the same table, bit for bit, and the same warnings."""
    model = pam2exu.load(Path(__file__).resolve().parents[2] / "examples" / "slider_crank.toml")
    with warnings.catch_warnings(record=True) as a:
        warnings.simplefilter("always")
        by_model = pam2exu.run(model, "kinetostatic", steps=12)
    with warnings.catch_warnings(record=True) as b:
        warnings.simplefilter("always")
        by_mech = pam2exu.run(model.mechanism(), "kinetostatic", steps=12)
    assert by_model.columns == by_mech.columns
    assert np.array_equal(by_model.to_numpy(), by_mech.to_numpy())
    assert [str(w.message) for w in a] == [str(w.message) for w in b]

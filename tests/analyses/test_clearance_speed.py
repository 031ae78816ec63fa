"""The clearance analysis at speed (issue 25): h_t exact from one evaluation, the rows
evaluated at once, and a mechanism with no clearance joint run as the kinematic analysis.

References: central differences of the closure in t and in s (``Closures.evaluate``,
an independent path: real arithmetic, one time at a time); ``evaluate``, ``least_norm.newton``
and ``applicability`` one row at a time; the kinematic analysis and Newton step by step on
the Lagrange conditions.
"""
import warnings

import numpy as np
import pytest

import pam2exu
from pam2exu.analyses import least_norm as ln
from pam2exu.analyses.clearance import KINEMATIC, Closures
from tests.conftest import guides_model


def _varied_guides():
    """The pin in a slot and the slider in a prismatic guide (tests/conftest.py), both with
    clearance, the rail's point and angle varied in time and the slider's line as made:
    every kind of varied anchor under both clearance forms (a line's angle in a
    prismatic's own target)."""
    model = guides_model()
    model.add("angular_actuator", name="turn", anc1="ground", anc2="crank", law="harmonic",
              C=[0.2, 0.3, 1.7, 0.0])
    model.add_variation(anchor="ground.rail", dy=3e-3, dangle=4e-3, wy=0.8, wangle=1.7,
                        tau=0.3)
    model.add_variation(anchor="slider.axis", dx=2e-3, dangle=-3e-3, w=2.1,
                        fixed_dangle=1e-3, fixed_dy=-2e-3)
    mech = model.mechanism()
    q = np.array([0.0, 0.0, 0.0, 0.3, -0.1, 0.7, 0.5, 0.2, np.pi + 0.15])
    return Closures(mech, q), q


def _h(closures, t, q, lam, reached=1.0):
    return ln.lagrange(np.zeros(closures.p), lam, closures.evaluate(t, q, lam, reached))


def test_h_t_is_the_rate_of_h_along_the_time_and_the_straight_path():
    """h_t = (0, F_qtᵀλ, F_u u′ − f′) from one complex-step evaluation equals the
    central difference of h in t (and in s along u0 + s δ), to the difference's own error;
    its Closure is ``evaluate``'s, to rounding (the fixed solid's and the actuator's rows by
    the products of ``closures.Linear``, found linear: the others are not)."""
    closures, q = _varied_guides()
    lam = np.linspace(-0.7, 0.9, closures.m)
    for t, reached in ((0.37, 1.0), (1.3, 1.0)):
        c, h_t = closures.evaluate_rate(t, q, lam, reached)
        d = 1e-5
        reference = (_h(closures, t + d, q, lam) - _h(closures, t - d, q, lam)) / (2 * d)
        np.testing.assert_allclose(h_t, reference, rtol=0, atol=1e-8 * np.max(np.abs(h_t)))
        assert np.max(np.abs(h_t)) > 1e-3                      # the laws and the variations
        plain = closures.evaluate(t, q, lam, reached)
        for name in ("F", "Fq", "W"):
            np.testing.assert_allclose(getattr(c, name), getattr(plain, name), rtol=0,
                                       atol=1e-14)
    mech = closures.mech
    assert [mech.constraints[k].name for k in sorted(closures._fitted.elements)] == [
        mech.constraints[0].name, "turn"]
    c, h_s = closures.evaluate_rate(0.0, q, lam, reached=0.4, along="s")
    d = 1e-4                                                    # h is smooth in s
    reference = (_h(closures, 0.0, q, lam, 0.4 + d) - _h(closures, 0.0, q, lam, 0.4 - d)) / (2 * d)
    np.testing.assert_allclose(h_s, reference, rtol=0, atol=1e-8 * np.max(np.abs(h_s)))
    assert np.max(np.abs(h_s)) > 1e-4


def test_rows_at_once_equal_one_row_at_a_time():
    """``evaluate_rows`` (the varied lines as arrays, one value per row), ``newton_rows`` and
    ``strict_minimum_rows`` equal ``evaluate``, ``newton`` and ``applicability`` row by
    row."""
    closures, q = _varied_guides()
    p, nq, m = closures.p, closures.nq, closures.m
    times = np.array([0.0, 0.4, 1.1, 2.5])
    rng = np.random.default_rng(3)
    Q = q + 0.01 * rng.standard_normal((len(times), nq))
    Q[:, :3] = 0.0                                                # the ground, fixed
    lam = 0.1 * rng.standard_normal((len(times), m))
    C, Fq, W = closures.evaluate_rows(times, Q, lam)
    for k, t in enumerate(times):
        one = closures.evaluate(t, Q[k], lam[k])
        np.testing.assert_allclose(C[k], one.F, rtol=0, atol=1e-15)
        np.testing.assert_allclose(Fq[k], one.Fq, rtol=0, atol=1e-15)
        np.testing.assert_allclose(W[k], one.W, rtol=0, atol=1e-15)
    ratio, hessian = ln.strict_minimum_rows(closures.Fj, Fq, W)
    for k in range(len(times)):
        found = ln.applicability(ln.Closure(C[k], Fq[k], closures.Fj, W[k]))
        assert ratio[k] == pytest.approx(found.ratio_i, rel=1e-12)
        assert hessian[k] == pytest.approx(found.hessian, rel=1e-9, abs=1e-14)
    y = np.hstack([np.zeros((len(times), p)), Q, np.zeros((len(times), m))])
    together, ok = ln.newton_rows(closures.evaluate_rows, closures.Fj, times, y, p, nq)
    for k, t in enumerate(times):
        alone, converged = ln.newton(closures.evaluate, float(t), y[k], p, nq)
        assert converged == ok[k]
        np.testing.assert_allclose(together[k], alone, rtol=0, atol=1e-13)


def _quiet(*args, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return pam2exu.run(*args, **kw)


def test_without_a_clearance_joint_the_positions_are_the_kinematic_ones(request):
    """The slider-crank has no clearance joint and no variation: the run says so
    (``clearance_method``), has no clearance column, and its positions are the kinematic
    analysis's (1e-12) and Newton's step by step on the Lagrange conditions (the
    contract's method, 1e-12), each row closing to 1e-13."""
    path = request.config.rootpath / "examples/slider_crank.toml"
    res = _quiet(path, analysis="clearance", steps=12)
    kinematic = _quiet(path, analysis="kinematic", steps=12)
    assert res.info["clearance_method"] == KINEMATIC
    mech = pam2exu.load(path).mechanism()
    solids = [f"{s.name}.{k}" for s in mech.solids for k in ("x", "y", "fi")]
    assert res.columns == solids
    q = np.column_stack([res[c] for c in solids])
    np.testing.assert_allclose(q, np.column_stack([kinematic[c] for c in solids]), atol=1e-12)
    closures = Closures(mech, q[0])
    assert closures.p == 0
    y, ok = ln.step_by_step(closures.evaluate, res.t, np.r_[q[0], np.zeros(closures.m)], 0,
                            closures.nq)
    assert ok.all()
    np.testing.assert_allclose(q, y[:, :closures.nq], rtol=0, atol=1e-12)
    for t, row in zip(res.t, q):
        assert np.max(np.abs(closures.evaluate(t, row, np.zeros(closures.m)).F)) <= 1e-13


def test_varied_points_of_linear_elements_move_by_their_rate(request):
    """The locomotive: every element is linear in its points (``closures.Linear``), two of
    them with a varied point (axle 2's frame.O2, pin 3's wheel3.A), moved by ∂v/∂P A(fi) δ
    in the right-hand sides: h_t against the central difference of h in t (to its own
    error, F_qtᵀλ included), the Closure against ``evaluate``'s to rounding."""
    model = pam2exu.load(request.config.rootpath / "examples/clearance/locomotive.toml")
    res = _quiet(model, analysis="assembly")
    mech = model.mechanism()
    q = np.array([res[f"{s.name}.{k}"][0] for s in mech.solids for k in ("x", "y", "fi")])
    q = q + 0.01                                          # off the assembly: F ≠ 0
    closures = Closures(mech, q)
    lam = np.linspace(-1.0, 1.0, closures.m)
    for t in (0.7, 3.1):
        c, h_t = closures.evaluate_rate(t, q, lam)
        assert len(closures._fitted.elements) == len(mech.constraints)
        assert len(closures._fitted.moves) == 2
        d = 1e-5
        reference = (_h(closures, t + d, q, lam) - _h(closures, t - d, q, lam)) / (2 * d)
        np.testing.assert_allclose(h_t, reference, rtol=0, atol=1e-9)
        rows = slice(closures.p, closures.p + closures.nq)               # F_qtᵀλ
        np.testing.assert_allclose(h_t[rows], reference[rows], rtol=0, atol=1e-10)
        assert np.max(np.abs(h_t[rows])) > 1e-5
        plain = closures.evaluate(t, q, lam)
        for name in ("F", "Fq", "W"):
            np.testing.assert_allclose(getattr(c, name), getattr(plain, name), rtol=0,
                                       atol=1e-14)


def test_a_fold_on_the_path_to_the_dimensions_as_made_is_met_in_few_steps(monkeypatch):
    """The locomotive with axle 3 0.3 m across the frame: the least-norm clearance folds at
    s = 0.3565 of the straight path of dimensions (the steps halve towards it); the run
    stops there with the message of deviations that cannot be absorbed once a step falls
    below ``FOLD_STEP`` of the path, after about 1050 right-hand sides (1745 when it crawled
    to round-off)."""
    from pathlib import Path
    from pam2exu.analyses import closures as closures_module
    text = (Path(__file__).parents[2] / "examples/clearance/locomotive.toml").read_text(
        encoding="utf-8").replace("steps = 400", "steps = 2").replace(
        "t_end = 9.66643893412244", "t_end = 0.2")
    head, _, tail = text.partition("[analysis]")
    model = pam2exu.loads(f'{head}[[variation]]\nanchor = "frame.O3"\nfixed_dy = 0.3\n\n'
                          f'[analysis]{tail}')
    counted = []
    rate = closures_module.Closures.evaluate_rate
    monkeypatch.setattr(closures_module.Closures, "evaluate_rate",
                        lambda self, *a, **k: counted.append(1) or rate(self, *a, **k))
    with pytest.raises(pam2exu.SolverError) as error:
        pam2exu.run(model)
    assert ("cannot absorb the fixed deviations of its [[variation]] entries (fixed_dx, "
            "fixed_dy, fixed_dangle): followed from the nominal assembly along the straight "
            "path of dimensions u0 + s δ, it stops at s = 0.3565 (of 0 … 1)") in str(error.value)
    assert "close to branching" in str(error.value) and error.value.partial is None
    assert len(counted) < 1200


@pytest.mark.parametrize("path, steps", [("examples/clearance/locomotive.toml", 20),
                                         ("examples/clearance/slider_guided_twice.toml", 10)])
def test_newton_at_every_row_agrees_with_the_ode_to_1e_9(path, steps):
    """``method = "newton"`` (Newton on the Lagrange conditions at every row from the
    previous row) against the default ODE on both clearance examples: every column to 1e-9
    (6.6e-15 measured at 400 steps), and the run says which method it followed."""
    from pathlib import Path
    from pam2exu.analyses.clearance import BY_NEWTON, FOLLOWED
    model = pam2exu.load(Path(__file__).parents[2] / path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ode = pam2exu.run(model, "clearance", steps=steps)
        newton = pam2exu.run(model, "clearance", steps=steps, method="newton")
    assert ode.info["clearance_method"] == FOLLOWED
    assert newton.info["clearance_method"] == BY_NEWTON
    assert list(newton.columns) == list(ode.columns)
    np.testing.assert_allclose(newton.to_numpy(), ode.to_numpy(), rtol=0, atol=1e-9)


def test_the_method_is_one_of_its_choices():
    """An unknown ``method`` is the model's problem, named with the allowed values."""
    with pytest.raises(pam2exu.ModelError, match="method must be one of 'ode', 'newton', "
                                                  "how the clearance of least norm is "
                                                  "followed, got 'euler'"):
        pam2exu.run(guides_model(), "clearance", method="euler")

"""The closure of a mechanism with clearance joints (analyses/clearance.py) on the
over-constrained parallelogram of tests/data/parallelogram5.toml (three cranks, one
coupler: one self-stress), with clearance in pins A2 and A3.

References: with no variation the least-norm clearance is 0 and the positions are the
kinematic analysis's (shared/spec/clearance.md, item 4); with variations, SLSQP's minimum of
½‖j‖² under the closure equations (scipy.optimize.minimize), and the contract's conditions
1–3 computed from the rows alone.
"""
import warnings

import numpy as np
import pytest
from scipy.optimize import minimize

import pam2exu
from pam2exu.analyses import least_norm as ln
from pam2exu.analyses.clearance import Closures


def _model(request, variations=()):
    model = pam2exu.load(request.config.rootpath / "tests/data/parallelogram5.toml")
    model["A2"].clearance = True
    model["A3"].clearance = True
    for v in variations:
        model.add_variation(**v)
    return model


def _start(model, times):
    """q of the kinematic analysis at ``times`` (nominal dimensions), and the closure."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = pam2exu.run(model, analysis="kinematic", t_end=float(times[-1]),
                          steps=len(times) - 1)
    mech = model.mechanism()
    q = np.column_stack([res[f"{s.name}.{k}"] for s in mech.solids for k in ("x", "y", "fi")])
    return mech, q


VARIED = ({"anchor": "ground.O2", "dx": 3.7e-3, "dy": -2.9e-3, "wx": 1.91, "wy": 0.57},
          {"anchor": "crank3.A", "dx": 2e-3, "tau": 0.2})


def test_without_variations_the_clearance_is_zero_and_the_positions_kinematic(request):
    times = np.linspace(0.0, 1.0, 21)
    mech, q = _start(_model(request), times)
    closures = Closures(mech, q[0])
    assert closures.names == ["A2.jx", "A2.jy", "A3.jx", "A3.jy"]
    y0 = np.r_[np.zeros(closures.p), q[0], np.zeros(closures.m)]
    y, ok = ln.step_by_step(closures.evaluate, times, y0, closures.p, closures.nq)
    assert ok.all()
    assert np.max(np.abs(y[:, :closures.p])) < 1e-14
    np.testing.assert_allclose(y[:, closures.p:closures.p + closures.nq], q, atol=1e-12)


@pytest.fixture(scope="module")
def varied(request):
    """The clearance over 2 s with O2 and crank3.A varied (``VARIED``): by the slides' ODE
    and by Newton step by step, from the nominal assembly."""
    times = np.linspace(0.0, 2.0, 41)
    _, q = _start(_model(request), np.array([0.0, 1e-3]))
    closures = Closures(_model(request, VARIED).mechanism(), q[0])
    y0 = np.r_[np.zeros(closures.p), q[0], np.zeros(closures.m)]
    ode = ln.follow(closures.evaluate, ln.time_rate(closures.evaluate, closures.p), times, y0,
                    closures.p, closures.nq)[:2]
    newton = ln.step_by_step(closures.evaluate, times, y0, closures.p, closures.nq)
    return times, closures, ode, newton


def test_ode_and_newton_step_by_step_agree(varied):
    times, closures, (ode, ok_ode), (newton, ok_newton) = varied
    assert ok_ode.all() and ok_newton.all()
    np.testing.assert_allclose(ode[:, :closures.p + closures.nq],
                               newton[:, :closures.p + closures.nq], atol=1e-9)
    assert np.max(np.abs(ode[:, :closures.p])) > 1e-4       # the variations need clearance


def test_every_row_meets_the_contracts_conditions(varied):
    times, closures, (ode, _), _ = varied
    p, nq = closures.p, closures.nq
    largest = np.max(np.abs(ode[:, :p]))
    for t, y in zip(times, ode):
        j, q, lam = ln.split(y, p, nq)
        c = closures.evaluate(t, q, lam)
        assert np.max(np.abs(c.F + c.Fj @ j)) <= 1e-10                     # 1. closure
        assert ln.kkt_residual(j, c) <= 1e-8 * largest                       # 2. KKT
        assert ln.applicability(c).hessian > 1e-9                            # 3. second order


def test_the_clearance_is_the_least_norm_one(varied):
    times, closures, (ode, _), _ = varied
    p, nq = closures.p, closures.nq
    for k in (10, 40):
        t = times[k]

        def closure(x):
            c = closures.evaluate(t, x[p:], np.zeros(closures.m))
            return c.F + c.Fj @ x[:p]

        def jacobian(x):
            c = closures.evaluate(t, x[p:], np.zeros(closures.m))
            return np.hstack([c.Fj, c.Fq])

        start = ode[k, :p + nq] + 1e-5
        found = minimize(lambda x: 0.5 * x[:p] @ x[:p], start,
                         jac=lambda x: np.r_[x[:p], np.zeros(nq)],
                         constraints=[{"type": "eq", "fun": closure, "jac": jacobian}],
                         method="SLSQP", options={"ftol": 1e-14, "maxiter": 1000})
        assert found.success, found.message
        np.testing.assert_allclose(ode[k, :p], found.x[:p], atol=1e-8)


def test_a_revolutes_clearance_is_the_vector_between_its_points(varied):
    """The contract's jx, jy = P2 − P1: from solid 1's point (anc1, crank2.A / crank3.A,
    the latter varied) to solid 2's point (coupler.A2 / coupler.A3), global basis."""
    from pam2exu.kinematics import State
    times, closures, (ode, _), _ = varied
    mech = closures.mech
    index = {s.name: i for i, s in enumerate(mech.solids)}
    for k in (5, 25, 40):
        t, y = times[k], ode[k]
        st = State([t], y[closures.p:closures.p + closures.nq][None])
        # u = u0 + (1 − e^(−t/τ)) (Δ/2) cos(ω t), Δ = 2e-3, τ = 0.2, ω = 1
        crank3_a = np.array([0.3 + (1 - np.exp(-t / 0.2)) * 1e-3 * np.cos(t), 0.0])
        for name, crank, local, joint in (("A2", "crank2", [0.3, 0.0], 0),
                                          ("A3", "crank3", crank3_a, 2)):
            P1 = st.point(index[crank], local).value[0]
            P2 = st.point(index["coupler"], [1.0 if name == "A2" else 0.5, 0.0]).value[0]
            np.testing.assert_allclose(y[joint:joint + 2], P2 - P1, atol=1e-14, err_msg=name)


def test_pin_slot_and_prismatic_rows_vanish_at_the_contracts_clearances(guides):
    """shared/spec/clearance.md: pin_slot jn = n1·(P2 − p1); prismatic jn = n1·(p2 − p1) and
    jfi = (fi2 + α2) − (fi1 + α1) − kπ (n1: line 1's direction turned +90°, all in the
    current configuration). At an arbitrary configuration, C + F_j j = 0 with exactly
    those j, computed here from the geometry by hand."""
    mech = guides().mechanism()
    q = np.array([0.0, 0.0, 0.0, 0.3, -0.1, 0.7, 0.5, 0.2, np.pi + 0.15])
    closures = Closures(mech, q)                       # sense k = 1 (opposite) here
    c = closures.evaluate(0.0, q, np.zeros(closures.m))

    def rot(a, v):
        return np.array([np.cos(a) * v[0] - np.sin(a) * v[1], np.sin(a) * v[0] + np.cos(a) * v[1]])

    p1 = rot(0.0, [0.1, -0.2])                          # ground at the origin, fi = 0
    n1 = rot(0.3, [0.0, 1.0])
    P2 = q[3:5] + rot(q[5], [0.25, 0.05])
    p2 = q[6:8] + rot(q[8], [0.02, 0.03])
    jn_slot = n1 @ (P2 - p1)
    jn_guide = n1 @ (p2 - p1)
    jfi = (q[8] + 0.2) - (0.0 + 0.3) - np.pi
    j = np.array([jn_slot, jn_guide, jfi])
    assert closures.names == ["slot.jn", "guide.jn", "guide.jfi"]
    rows = np.r_[mech.rows[1], mech.rows[2]]
    np.testing.assert_allclose((c.F + c.Fj @ j)[rows], 0.0, atol=1e-15)
    assert abs(jfi - 0.05) < 1e-15 and abs(jn_slot) > 0.1     # a real gap, a real angle


def _assembled(request, model):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = pam2exu.run(model, analysis="assembly")
    mech = model.mechanism()
    q0 = np.array([res[f"{s.name}.{k}"][0] for s in mech.solids for k in ("x", "y", "fi")])
    closures = Closures(mech, q0)
    return closures, closures.evaluate(0.0, q0, np.zeros(closures.m))


def test_a_self_stress_without_clearance_fails_condition_i_naming_its_elements(request):
    """The parallelogram's one self-stress runs through its six pins (the fixed link and
    the motor carry none of it): with no clearance anywhere, (i) fails and names them."""
    from pam2exu.analyses.clearance import require_applicable
    model = pam2exu.load(request.config.rootpath / "tests/data/parallelogram5.toml")
    closures, c = _assembled(request, model)
    with pytest.raises(pam2exu.ModelError) as error:
        require_applicable(closures, c, 0.0)
    text = str(error.value)
    assert text.startswith("t=0: the clearance analysis of ")
    assert "parallelogram5.toml cannot start" in text and "(condition (i)" in text
    assert "'O1', 'O2', 'O3', 'A1', 'A2', 'A3'" in text and "motor" not in text
    assert "declare clearance = true on one of them" in text
    model["A2"].clearance = True                         # one pin with clearance suffices
    closures, c = _assembled(request, model)
    require_applicable(closures, c, 0.0)


def test_an_undriven_mechanism_fails_condition_ii_naming_its_solids(request):
    from pam2exu.analyses.clearance import require_applicable
    model = _model(request)
    closures, _ = _assembled(request, model)
    q0 = closures.start.q[0]
    model.elements.remove(model["motor"])
    closures = Closures(model.mechanism(), q0)
    with pytest.raises(pam2exu.MobilityError) as error:
        require_applicable(closures, closures.evaluate(0.0, q0, np.zeros(closures.m)), 0.0)
    text = str(error.value)
    assert text.startswith("t=0: the clearance analysis of ") and "cannot start" in text
    assert "(condition (ii)" in text
    assert "the solids 'crank1', 'crank2', 'crank3', 'coupler' free to move" in text
    assert "'ground'" not in text


def test_a_clearance_run_of_an_undriven_model_names_its_free_solids():
    """Through pam2exu.run (found by the fuzz suite): the assembly nearest the guess, then
    condition (ii) naming the free solids (before, the static solver's failure to assemble
    an undriven model stopped it, naming none)."""
    path = pam2exu.__file__.replace("pam2exu/__init__.py",
                                    "examples/equilibrium/spring_four_bar.toml")
    with pytest.raises(pam2exu.MobilityError,
                       match=r"^t=0: the clearance analysis of .*spring_four_bar.toml "
                             r"cannot start: .*the solids 'crank', 'coupler', 'rocker' free "
                             r"to move \(condition \(ii\)"):
        pam2exu.run(path, analysis="clearance", steps=4)


def test_a_lost_strict_minimum_stops_the_run_at_its_time():
    """Item 3 of the contract: a reduced Hessian with a non-positive eigenvalue (here W =
    −5 I on a closure with a one-dimensional kernel where the δq part dominates) is a
    SolverError at that time; the same closure with W = 0 passes."""
    from pam2exu.analyses.clearance import require_strict_minimum
    Fj = np.array([[1.0], [0.0]])
    Fq = np.array([[0.1, 1.0], [1.0, 0.0]])
    good = ln.Closure(np.zeros(2), Fq, Fj, np.zeros((2, 2)))
    require_strict_minimum(good, 0.5)
    bad = ln.Closure(np.zeros(2), Fq, Fj, -5.0 * np.eye(2))
    assert ln.applicability(bad).hessian < 0
    with pytest.raises(pam2exu.SolverError, match=r"^t=0\.5: the clearance followed is no "
                                                  r"longer a strict minimum") as error:
        require_strict_minimum(bad, 0.5)
    assert error.value.time == 0.5


def test_the_clearance_analysis_runs_end_to_end(request, varied):
    """pam2exu.run(..., analysis="clearance"): the contract's columns, the solids' x, y, fi
    then the clearance columns (jr = √(jx² + jy²)) and nothing else, equal to the
    ``Closures`` path above."""
    times, closures, (ode, _), _ = varied
    model = _model(request, VARIED)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = pam2exu.run(model, analysis="clearance", t_end=2.0, steps=40)
    np.testing.assert_array_equal(res.t, times)
    solids = [f"{s.name}.{k}" for s in closures.mech.solids for k in ("x", "y", "fi")]
    assert res.columns == solids + ["A2.jx", "A2.jy", "A2.jr", "A3.jx", "A3.jy", "A3.jr"]
    for k, name in enumerate(closures.names):
        np.testing.assert_allclose(res[name], ode[:, k], atol=1e-12, err_msg=name)
    np.testing.assert_allclose(res["A2.jr"], np.hypot(res["A2.jx"], res["A2.jy"]), rtol=1e-15)
    mech = closures.mech
    for i, s in enumerate(mech.solids):
        for c, key in enumerate(("x", "y", "fi")):
            np.testing.assert_allclose(res[f"{s.name}.{key}"], ode[:, closures.p + 3 * i + c],
                                       atol=1e-12)
    with pytest.raises(pam2exu.ModelError, match=r"^t=0: .*parallelogram5.toml cannot start: "
                                                 r"the elements .*\(condition \(i\)"):
        pam2exu.run(request.config.rootpath / "tests/data/parallelogram5.toml",
                    analysis="clearance", steps=4)


def test_for_small_variations_the_clearance_is_its_first_order_estimate(request):
    """Issue 13's acceptance: for Δ of 1e-7 of the dimensions the clearance equals the
    least-norm solution of the linearised closure at the nominal positions
    (``first_order``) to second order in Δ: the gap scales as Δ² (×4 when Δ doubles)."""
    from pam2exu.analyses.clearance import first_order
    times = np.linspace(0.0, 1.0, 11)
    _, q_nominal = _start(_model(request), times)
    gaps = []
    for scale in (1e-7, 2e-7):
        varied = ({"anchor": "ground.O2", "dx": scale, "dy": -0.8 * scale, "wx": 1.91},
                  {"anchor": "crank3.A", "dx": 0.6 * scale, "tau": 0.2})
        closures = Closures(_model(request, varied).mechanism(), q_nominal[0])
        y0 = np.r_[np.zeros(closures.p), q_nominal[0], np.zeros(closures.m)]
        y, ok = ln.step_by_step(closures.evaluate, times, y0, closures.p, closures.nq)
        assert ok.all()
        j = y[:, :closures.p]
        estimate = np.array([first_order(closures, t, q) for t, q in zip(times, q_nominal)])
        assert np.max(np.abs(j)) > 0.05 * scale                 # first order in Δ
        gaps.append(np.max(np.abs(j - estimate)))
        assert gaps[-1] <= 1e-6 * np.max(np.abs(j))
    assert 3.0 < gaps[1] / gaps[0] < 5.0                         # second order in Δ


@pytest.mark.long          # 7 s idle on 2 cores
def test_a_clearance_far_from_its_first_order_estimate_is_warned(request):
    """The contract's recommended warning: O2 moved by 20 % of the cranks' spacing, the
    clearance of A2 departs from its first-order estimate by more than half its maximum
    (and by less with 3.7 %: no warning)."""
    big = _model(request, ({"anchor": "ground.O2", "dx": 0.2, "dy": -0.2, "wx": 1.91,
                            "wy": 0.57},))
    small = _model(request, ({"anchor": "ground.O2", "dx": 0.037, "dy": -0.037,
                              "wx": 1.91, "wy": 0.57},))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = pam2exu.run(big, analysis="clearance", t_end=2.0, steps=40)
        quiet = pam2exu.run(small, analysis="clearance", t_end=2.0, steps=40)
    text = [w for w in res.warnings if "first-order estimate" in w]
    assert text and text[0].startswith("A2.jx departs from its first-order estimate")
    assert "from t = 1.5 s" in text[0]
    assert not [w for w in quiet.warnings if "first-order" in w]

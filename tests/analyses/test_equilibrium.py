"""The equilibrium analysis (shared/spec/dynamics.md, ``equilibrium``).

References, each computed here without pam2exu's code:
- a lever with a torsional spring under gravity: the hand moment balance about the pivot,
  k·fi + m g d cos(fi) = 0, solved by brentq; the pivot carries the weight;
- a four-bar whose crank is free, held by a linear spring from the ground to the coupler
  (examples/equilibrium/spring_four_bar.toml):
  the minimum of its potential energy V(θ) = Σ m g y_G + ½ k (ro − L0)², with the
  positions from the circle intersection of the four-bar, found by scipy's
  minimize_scalar;
- a redundant parallelogram (tests/data/parallelogram5.toml without its motor) with a
  torsional spring under gravity: k θ + 0.3 m g cos θ = 0, solved by brentq;
- a pendulum exactly at its top warns (unstable), a torque larger than m g d is an error
  naming the lever, and a fully driven model gives the first row of quasi_static.

Each test runs on each backend (``every_backend`` in conftest.py): Exudyn's static solver
and Newton on the natural coordinates' equilibrium, with the same tolerances.
"""
import math
import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq, minimize_scalar

import pam2exu
from pam2exu.analyses import force_pass, native
from pam2exu.analyses.equilibrium import StabilityWarning, reduced_stiffness
from pam2exu.kinematics import State
from references.pendulum import D, G, M, pendulum_toml

#: each test runs on each backend (``every_backend`` in conftest.py)
pytestmark = pytest.mark.usefixtures("every_backend")

K = 20.0                           # the torsional spring's stiffness [N·m/rad]


def lever(fi=0.3, stiffness=K, torque=None):
    """references.pendulum's pendulum held by a torsional spring (C2 = stiffness, C3 = 0),
    with a torsor of moment ``torque`` when given, for the equilibrium analysis."""
    torsor = ("" if torque is None else
              f'\n[[element]]\ntype = "torsor"\nname = "torque"\nanc1 = "lever"\n'
              f"C = [0.0, 0.0, {torque}]\n")
    spring = (f'\n[[element]]\ntype = "torsional_spring"\nname = "spring"\nanc1 = "ground"\n'
              f'anc2 = "lever"\nC = [0.0, {stiffness!r}, 0.0, 0.0]\n')
    return pam2exu.loads(pendulum_toml(fi, elements=spring + torsor,
                                       analysis='type = "equilibrium"'))


def _run(model, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("error")          # no warning unless a test expects it
        return pam2exu.run(model, **kw)


@pytest.mark.parametrize("guess", [0.3, -1.2, 2.0])
def test_lever_against_the_hand_moment_balance(guess):
    """Moments about the pivot: spring −k·fi, weight −m g d cos(fi): one root near 0."""
    fi = brentq(lambda f: K * f + M * G * D * math.cos(f), -1.5, 1.5)
    res = _run(lever(guess))
    assert len(res) == 1 and res.t[0] == 0.0
    assert res["lever.fi"][0] == pytest.approx(fi, abs=1e-12)
    assert res["spring.fi_rel"][0] == pytest.approx(fi, abs=1e-12)
    assert res["spring.Parell"][0] == pytest.approx(K * fi, abs=1e-10)
    assert res["pivot.Fx"][0] == pytest.approx(0.0, abs=1e-10)
    assert res["pivot.Fy"][0] == pytest.approx(M * G, abs=1e-10)     # carries the weight
    # stable: V'' = k − m g d sin(fi) > 0, in the analysis's scaled units (angles × L)
    L = lever().mechanism().scale()
    assert res.info["stiffness_eigenvalue"] == pytest.approx(
        (K - M * G * D * math.sin(fi)) / L ** 2, rel=1e-6)


EXAMPLE = Path(__file__).resolve().parents[2] / "examples/equilibrium/spring_four_bar.toml"


def _four_bar():
    """The shipped example: examples/four_bar.toml without its motor, held by a spring
    (k = 400 N/m, free length 0.1 m) from ground.S = (0.25, −0.15) to coupler.P."""
    return pam2exu.load(EXAMPLE)


def _four_bar_pose(th, a=0.10, b=0.35, c=0.30, d=0.40):
    """Crank angle θ → (A, B, coupler angle, rocker angle): B on the circles |B − A| = b
    and |B − O4| = c, the branch above the line A–O4 (the example's assembly mode)."""
    A = a * np.array([math.cos(th), math.sin(th)])
    O4 = np.array([d, 0.0])
    u = O4 - A
    L = np.hypot(*u)
    along = (b * b - c * c + L * L) / (2 * L)
    h = math.sqrt(b * b - along * along)
    B = A + along * u / L + h * np.array([-u[1], u[0]]) / L
    return A, B, math.atan2(*(B - A)[::-1]), math.atan2(*(B - O4)[::-1])


def _four_bar_energy(th, k, L0):
    """V(θ) = Σ m g y_G + ½ k (ro − L0)² (the example's masses and G)."""
    A, B, fc, fr = _four_bar_pose(th)
    rot = lambda f, p: np.array([math.cos(f) * p[0] - math.sin(f) * p[1],
                                 math.sin(f) * p[0] + math.cos(f) * p[1]])
    yG = [0.3 * rot(th, (0.05, 0.0))[1], 0.8 * (A + rot(fc, (0.175, 0.03)))[1],
          0.6 * rot(fr, (0.15, 0.0))[1]]
    P = A + rot(fc, (0.2, 0.1))
    ro = np.hypot(*(P - np.array([0.25, -0.15])))
    return G * sum(yG) + 0.5 * k * (ro - L0) ** 2


def test_four_bar_with_a_spring_at_the_minimum_of_its_potential_energy():
    """scipy's minimize_scalar finds the minimum of V(θ) near the crank angle found (to
    ~√ε: a minimum is flat), then brentq the root of dV/dθ (central differences, step
    1e-6) there to ~1e-10 (measured: θ 2.6e-10, coupler 2e-11, rocker 7e-11 rad)."""
    k, L0 = 400.0, 0.1
    res = _run(_four_bar())
    th = res["crank.fi"][0]
    V = lambda x: _four_bar_energy(x, k, L0)
    best = minimize_scalar(V, bracket=(th - 0.3, th + 0.3), tol=1e-12)
    assert th == pytest.approx(best.x, abs=1e-7)
    slope = lambda x: (V(x + 1e-6) - V(x - 1e-6)) / 2e-6
    root = brentq(slope, best.x - 0.05, best.x + 0.05, xtol=1e-15)
    A, B, fc, fr = _four_bar_pose(root)
    assert th == pytest.approx(root, abs=1e-9)
    assert res["coupler.fi"][0] == pytest.approx(fc, abs=1e-9)
    assert res["rocker.fi"][0] == pytest.approx(fr, abs=1e-9)
    assert V(th) == pytest.approx(best.fun, abs=1e-12)
    assert V(th) < V(_four_bar().solids[1].fi)          # lower than where it started
    assert res.info["stiffness_eigenvalue"] > 0


def test_a_redundant_parallelogram_against_its_moment_balance():
    """tests/data/parallelogram5.toml (three cranks 0.3 long, a coupler over them: one
    redundant revolute) without its motor, assembled, under gravity with a torsional spring
    k = 5 on crank 1 and 1 kg on every moving solid (each centre of mass at its frame
    origin): the coupler translates, V(θ) = m g 0.3 sin θ + ½ k θ², so k θ + 0.3 m g cos θ = 0
    (brentq); the redundant reactions are of least norm, the crank angles equal."""
    model = pam2exu.load(Path(__file__).resolve().parents[1] / "data/parallelogram5.toml")
    model.elements.remove(model["motor"])
    model.add("torsional_spring", name="tspring", anc1="ground", anc2="crank1",
              C=[0.0, 5.0, 0.0, 0.0])
    model.gravity = G
    for solid in model.solids[1:]:
        solid.mass, solid.inertia = 1.0, 0.01
        solid.fi = 1.6
    model["crank2"].x = 1.0
    model["coupler"].x, model["coupler"].y = 0.3 * math.cos(1.6), 0.3 * math.sin(1.6)
    model["coupler"].fi = 0.0
    res = _run(model, analysis="equilibrium")
    theta = brentq(lambda f: 5.0 * f + 0.3 * G * math.cos(f), -1.5, 1.5, xtol=1e-15)
    for crank in ("crank1", "crank2", "crank3"):
        assert res[f"{crank}.fi"][0] == pytest.approx(theta, abs=1e-12)
    assert res["coupler.fi"][0] == pytest.approx(0.0, abs=1e-12)
    assert res["tspring.Parell"][0] == pytest.approx(5.0 * theta, abs=1e-10)
    assert res.info["stiffness_eigenvalue"] > 0


def test_the_reactions_balance_every_solid():
    """Cqᵀλ + Q_applied = 0 with λ from the reported reactions (the quasi-static check)."""
    model = _four_bar()
    res = _run(model)
    mech = model.mechanism()
    q = np.array([[res[f"{s.name}.{c}"][0] for s in mech.solids for c in ("x", "y", "fi")]])
    st = State([0.0], q)
    applied = force_pass.applied_forces(mech, st, damping=False).force
    eq = native.equations(mech, st)
    lam = force_pass.multipliers(mech, st, -applied, redundant=True, eq=eq)
    reactions = force_pass.reactions(mech, st, lam, eq.parts)
    for name, value in reactions.items():
        assert res[name][0] == pytest.approx(value[0], abs=1e-9), name
    residual = force_pass.equilibrium_residual(mech, st, lam, -applied, eq.jacobian)
    assert np.max(np.abs(residual)) < 1e-10


def test_the_descent_leaves_the_top_of_a_pendulum_for_its_bottom():
    """From 17° off the top, Newton alone lands on the top (measured: Exudyn's static
    solver from 1.27 rad gives π/2); the descent reaches the hanging position."""
    res = _run(lever(math.pi / 2 - 0.3, stiffness=0.0))
    assert res["lever.fi"][0] == pytest.approx(-math.pi / 2, abs=1e-10)
    assert res.info["stiffness_eigenvalue"] > 0


def test_an_unstable_equilibrium_is_reported_with_a_warning():
    with pytest.warns(StabilityWarning, match="the equilibrium found is unstable.*'lever'"):
        res = pam2exu.run(lever(math.pi / 2, stiffness=0.0))
    assert res["lever.fi"][0] == pytest.approx(math.pi / 2, abs=1e-12)
    assert res.info["stiffness_eigenvalue"] < 0
    assert any("unstable" in w for w in res.warnings)


def test_the_reduced_stiffness_of_a_pendulum():
    """V = m g d sin(fi): V'' = −m g d sin(fi), −m g d at the top, + m g d at the bottom
    (angles scaled by the length scale L)."""
    mech = lever(stiffness=0.0).mechanism()
    L = mech.scale()
    for fi, sign in ((math.pi / 2, -1.0), (-math.pi / 2, 1.0)):
        q = np.zeros(mech.nq)
        q[5] = fi
        lam = force_pass.multipliers(
            mech, State([0.0], q[None]),
            -force_pass.applied_forces(mech, State([0.0], q[None]), False).force,
            redundant=True)[0]
        found = reduced_stiffness(mech, 0.0, q, lam)
        assert found.eigenvalues == pytest.approx([sign * M * G * D / L ** 2], rel=1e-8)


def test_a_load_nothing_balances_is_an_error_naming_the_free_solids():
    with pytest.raises(pam2exu.ModelError, match=r"no static equilibrium found for the free "
                                                 r"solids 'lever'"):
        _run(lever(0.0, stiffness=0.0, torque=2 * M * G * D))


def test_a_fully_driven_model_gives_the_first_row_of_quasi_static():
    path = pam2exu.__file__.replace("pam2exu/__init__.py", "examples/four_bar.toml")
    res = _run(path, analysis="equilibrium")
    first = _run(path, analysis="quasi_static", steps=4)
    assert res.columns == first.columns and len(res) == 1
    np.testing.assert_array_equal(res.to_numpy()[0], first.to_numpy()[0])


def test_a_backend_without_a_static_equilibrium_refuses_free_solids_naming_them(monkeypatch):
    """A backend that does not declare ``moves_free_solids`` is refused by name, and the
    message names one that can (both shipped backends can: the flag is switched off)."""
    from pam2exu.backend.natural import Natural
    monkeypatch.setattr(Natural, "moves_free_solids", False)
    with pytest.raises(pam2exu.ModelError, match="natural backend cannot solve a static "
                                                 "equilibrium.*'lever'.*on the exudyn backend"):
        pam2exu.run(lever(), backend="natural")

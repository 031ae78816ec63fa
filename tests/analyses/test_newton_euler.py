"""Reactions and actuator torques against a hand-written Newton–Euler solution.

The reference is written by hand in ``references/slider_crank.py`` (shared with
benchmarks/speed_vs_error.py) and takes nothing from pam2exu: each model is built from the
plain Python parameters of ``slider_crank_params`` (as TOML text, ``model_toml``, read with
``pam2exu.loads``), and the same parameters feed the reference. Only the result columns are
compared. The closed-form kinematics of the offset slider-crank and the 12 Newton–Euler
equations (ground, crank, rod, slider; the reactions ``REACTIONS`` and the motor torque) are
derived in that module's docstring.

The reference is checked by itself (no pam2exu): its kinematics against finite
differences, the power balance  motor power = d/dt (kinetic + potential energy) − torsor
power  (analytic and by finite differences of the energies), the whole system's momentum
balance (which holds only when every action/reaction pair has been put on both bodies with
opposite signs), and the quasi-static virtual power.

Error measure (``errors``), as in test_kinematic_closed_form.py: per column,
max |pam2exu − reference| divided by the largest |reference| of that column (a column whose
reference is ~0 uses the largest |reference| of all reaction columns).
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import pam2exu
from references.slider_crank import (cross, dot, errors, kinematic_ref, kinematics,
                                     law_polynomial, model_toml, n, newton_euler, rot,
                                     slider_crank_params, torsor_load)

#: each test runs on each backend (``every_backend`` in conftest.py)
pytestmark = pytest.mark.usefixtures("every_backend")

RTOL = 1e-9
TWO_PI = 2.0 * math.pi


# ---- comparison ------------------------------------------------------------------------------

def assert_matches(res, ref, rtol=RTOL):
    err = errors(res, ref)
    bad = {c: f"{v:.3g}" for c, v in err.items() if not v <= rtol}
    worst = max(err, key=err.get)
    assert not bad, f"relative errors above {rtol:g}: {bad} (worst {worst}: {err[worst]:.3g})"
    return err


def run_and_compare(p, analysis):
    model = pam2exu.loads(model_toml(p, analysis))
    res = pam2exu.run(model, analysis=analysis, t_end=p["t_end"], steps=p["steps"])
    t = p["t_end"] * np.arange(p["steps"] + 1) / p["steps"]
    np.testing.assert_allclose(res.t, t, rtol=0, atol=1e-14)
    # the configuration first (else the reactions cannot agree); L = 0.4 m, ω ~ 10 rad/s
    kin = kinematic_ref(p, t, with_rates=(analysis == "kinetostatic"))
    natural = {"x": 0.4, "y": 0.4, "fi": 1.0, "Dx": 4.0, "Dy": 4.0, "Dfi": 10.0,
               "DDx": 40.0, "DDy": 40.0, "DDfi": 100.0}
    kin_err = {c: float(np.max(np.abs(res[c] - v))) / natural[c.split(".")[1]]
               for c, v in kin.items()}
    assert max(kin_err.values()) < 1e-9, f"configuration differs: {kin_err}"
    ref = newton_euler(p, t, static=(analysis == "quasi_static"))
    return assert_matches(res, ref)


VARIANTS = {
    # ground at the global origin, slider's line along the rail, torsor in global axes
    "global_torsor": slider_crank_params(),
    # the same, torsor components constant in the rod's frame
    "solid_torsor": slider_crank_params(torsor={"axes": "solid"}),
    # ground moved and turned, pivot and rail off its origin, rail inclined, the slider's
    # line pointing against the rail (Fnormal, Mz in the slider line's own basis)
    "moved_ground_reversed_line": slider_crank_params(
        ground={"pose": (0.05, -0.02, 0.25), "O": (0.02, -0.01), "rail_point": (0.01, 0.03),
                "rail_angle": 0.1},
        slider={"axis_angle": math.pi, "sense": -1},
        torsor={"C": (-10.0, 20.0, -2.0), "axes": "solid"}),
}


# ---- the reference checked by itself ---------------------------------------------------------

def fd(y, h):
    """4th-order central difference of samples y (…, k) at spacing h, interior points."""
    return (y[..., :-4] - 8 * y[..., 1:-3] + 8 * y[..., 3:-1] - y[..., 4:]) / (12 * h)


def energies(p, t):
    bodies, pts, (_th, dth, _) = kinematics(p, t)
    Tk = sum(0.5 * p[b]["mass"] * dot(bodies[b]["G"][1], bodies[b]["G"][1])
             + 0.5 * p[b]["inertia"] * bodies[b]["fi"][1] ** 2 for b in bodies)
    V = sum(p[b]["mass"] * p["gravity"] * bodies[b]["G"][0][1] for b in bodies)
    dTk = sum(p[b]["mass"] * dot(bodies[b]["G"][1], bodies[b]["G"][2])
              + p[b]["inertia"] * bodies[b]["fi"][1] * bodies[b]["fi"][2] for b in bodies)
    dV = sum(p[b]["mass"] * p["gravity"] * bodies[b]["G"][1][1] for b in bodies)
    Ft, Mt = torsor_load(p, bodies, len(t))
    P_load = dot(Ft, pts["T"][1]) + Mt * bodies["rod"]["fi"][1]
    return Tk, V, dTk, dV, P_load, dth


@pytest.mark.parametrize("variant", VARIANTS)
def test_reference_kinematics_closes(variant):
    """No pam2exu. The closed form satisfies the constraints (B of the rod = B of the
    slider, P on the rail), and velocities and accelerations are the time derivatives of
    the positions (finite differences, 4th order, h = 1e-4 s)."""
    p = VARIANTS[variant]
    h = 1e-4
    t = np.arange(0.0, 1.0 + h / 2, h)
    bodies, pts, _ = kinematics(p, t)
    assert np.max(np.abs(pts["B"] - pts["B_slider"])) < 1e-14
    gx, gy, gam = p["ground"]["pose"]
    K = np.array([gx, gy]) + rot(gam, p["ground"]["rail_point"])
    nu = n(gam + p["ground"]["rail_angle"])
    assert np.max(np.abs(dot(pts["P"] - K[:, None], nu))) < 1e-14
    # slider's line along ±rail
    assert abs(abs(dot(pts["nu_s"][:, 0], nu)) - 1.0) < 1e-14
    for b in bodies.values():
        for x, dx, ddx in (b["G"], b["q"], b["fi"]):
            np.testing.assert_allclose(fd(x, h), dx[..., 2:-2], rtol=0, atol=1e-8)
            np.testing.assert_allclose(fd(dx, h), ddx[..., 2:-2], rtol=0, atol=1e-6)


@pytest.mark.parametrize("variant", VARIANTS)
def test_reference_power_balance(variant):
    """No pam2exu. Ideal joints and a fixed ground do no work, so the motor's power
    Mz θ' = d/dt (kinetic energy) + d/dt (potential energy) − torsor power, both with
    the analytic rates and with finite differences of the energies."""
    p = VARIANTS[variant]
    h = 1e-4
    t = np.arange(0.0, 1.0 + h / 2, h)
    ref = newton_euler(p, t)
    Tk, V, dTk, dV, P_load, dth = energies(p, t)
    P_motor = ref["motor.Mz"] * dth
    scale = np.max(np.abs(P_motor))
    assert np.max(np.abs(P_motor - (dTk + dV - P_load))) < 1e-12 * scale
    assert np.max(np.abs(P_motor[2:-2] - (fd(Tk + V, h) - P_load[2:-2]))) < 1e-8 * scale


@pytest.mark.parametrize("variant", VARIANTS)
def test_reference_momentum_balance(variant):
    """No pam2exu. The whole mechanism's external loads (the fixed link's wrench, the
    weights, the torsor) equal the rate of its momentum and of its angular momentum
    about the global origin: the internal pairs cancel only if each was put on both
    solids with opposite signs. Also the quasi-static virtual power: Mz θ' + Σ m g·v_G +
    torsor power = 0."""
    p = VARIANTS[variant]
    t = np.linspace(0.0, 1.0, 101)
    k = len(t)
    bodies, pts, (_, dth, _) = kinematics(p, t)
    grav = np.array([0.0, -p["gravity"]])[:, None]
    Ft, Mt = torsor_load(p, bodies, k)
    for static in (False, True):
        ref = newton_euler(p, t, static=static)
        F = np.stack([ref["base.Fx"], ref["base.Fy"]]) + Ft
        M = ref["base.Mz"] + cross(pts["g0"], np.stack([ref["base.Fx"], ref["base.Fy"]])) \
            + cross(pts["T"][0], Ft) + Mt
        dP = np.zeros((2, k))
        dL = np.zeros(k)
        for name, b in bodies.items():
            m, J = p[name]["mass"], p[name]["inertia"]
            F = F + m * grav
            M = M + cross(b["G"][0], m * grav)
            if not static:
                dP += m * b["G"][2]
                dL += cross(b["G"][0], m * b["G"][2]) + J * b["fi"][2]
        assert np.max(np.abs(F - dP)) < 1e-11
        assert np.max(np.abs(M - dL)) < 1e-11
    ref = newton_euler(p, t, static=True)
    P = ref["motor.Mz"] * dth + dot(Ft, pts["T"][1]) + Mt * bodies["rod"]["fi"][1]
    for name, b in bodies.items():
        P = P + p[name]["mass"] * dot(grav, b["G"][1])
    assert np.max(np.abs(P)) < 1e-11


# ---- pam2exu against the reference ---------------------------------------------------------

@pytest.mark.parametrize("variant", VARIANTS)
def test_kinetostatic_slider_crank(variant):
    """Inverse dynamics of the slider-crank (θ = 0.3 + 6 t + 2 t², 1 s, 200 steps; more
    than a turn, with angular acceleration) against the Newton–Euler solution: motor.Mz,
    the three revolutes' Fx, Fy, guide.Fnormal and Mz, base.Fx, Fy, Mz, every column
    within RTOL of its scale; the solids' coordinates and rates first.

    Sign of the motor torque (free body of the crank alone, about O): with the crank
    horizontal (θ_g = 0), at rest, and only its weight acting, the weight m g at G
    (x_G = 0.04 m to the right of O) turns it clockwise with −m g x_G; the pin force at
    O has no moment about O and A carries nothing, so the motor must give the crank
    +m g x_G: Mz > 0 is counter-clockwise on the crank (solid 2), −Mz goes to the
    ground. The same signs are checked with literal numbers in
    ``test_crank_weight_signs``. Likewise O.Fy > 0 there (ground pushes the crank up),
    and base.Fy = (m_ground + m_crank) g > 0 (the fixed link carries both weights).
    """
    run_and_compare(VARIANTS[variant], "kinetostatic")


@pytest.mark.parametrize("analysis", ["quasi_static", "kinetostatic"])
@pytest.mark.parametrize("law, C", [("ramp", (0.2, 0.8, 0.3, 4.0)),
                                    ("bezier_c1", (0.1, 0.7, -0.5, 3.0)),
                                    ("bezier_c2", (0.25, 0.9, 0.3, 6.0))])
def test_force_analyses_with_transition_laws(law, C, analysis):
    """The slider-crank (moved ground, reversed slider line, torsor in the rod's axes) whose
    motor follows a transition law: at rest at C3 until C1, to C4 by C2, at rest after
    (issue 10: these laws were covered only by pam2exu's own power balance). Every reaction
    and the motor torque against the Newton–Euler solution, the law evaluated by the
    independent implementation of test_kinematic_closed_form; the breakpoints lie on the
    grid (200 steps over 1 s), where both sides take the right-hand limit (the ramp's θ'
    jumps there, so its θ'' is zero on both sides and the torque jumps with the
    centripetal terms)."""
    p = dict(VARIANTS["moved_ground_reversed_line"])
    p["motor"] = {"law": law, "C": C}
    run_and_compare(p, analysis)


@pytest.mark.parametrize("variant", VARIANTS)
def test_quasi_static_slider_crank(variant):
    """Quasi-static: the same slider-crank, positions from the constraints and, at each
    configuration, static equilibrium (the Newton–Euler equations with a_G = 0, α = 0):
    weights, the torsor, the reactions and the motor torque balance. Same sign argument
    for the motor as in ``test_kinetostatic_slider_crank``: it holds the weights up,
    counter-clockwise torque on the crank being positive."""
    run_and_compare(VARIANTS[variant], "quasi_static")


@pytest.mark.parametrize("analysis", ["quasi_static", "kinetostatic"])
def test_crank_weight_signs(analysis):
    """Literal hand values. A crank (m = 2 kg, G at (0.05, 0) local) hinged at the ground's
    origin, held horizontal (θ = 0 for all t) by the motor; ground (m0 = 3 kg, G0 at
    (0.1, 0.2)) fixed at its initial pose, the global origin.

    Crank free body (moments about O): weight −m g at x = 0.05 turns it clockwise by
    −0.05 m g; the motor's torque on the crank balances it: Mz = +0.05 m g. Forces:
    O.Fy − m g = 0 → O.Fy = +m g (ground pushes the crank up), O.Fx = 0.
    Ground free body: −O.F at O = (0, 0), −Mz, its weight −m0 g at G0, and the fixed
    link's wrench at the origin: base.Fy = (m + m0) g, base.Fx = 0, and about the origin
    base.Mz − Mz − 0.1 m0 g = 0 → base.Mz = 0.05 m g + 0.1 m0 g.
    """
    g, m, m0 = 9.81, 2.0, 3.0
    text = f"""
[model]
name = "held crank"
gravity = {g}

[[solid]]
name = "ground"
mass = {m0}
inertia = 0.5
cog = [0.1, 0.2]
points = {{ O = [0.0, 0.0] }}

[[solid]]
name = "crank"
mass = {m}
inertia = 0.01
cog = [0.05, 0.0]

[[element]]
type = "fixed"
name = "base"
anc1 = "ground"

[[element]]
type = "revolute"
name = "O"
anc1 = "ground.O"
anc2 = "crank"

[[element]]
type = "angular_actuator"
name = "motor"
anc1 = "ground"
anc2 = "crank"
C = [0.0, 0.0, 0.0, 0.0]
"""
    res = pam2exu.run(pam2exu.loads(text), analysis=analysis, t_end=1.0, steps=4)
    expect = {"motor.Mz": 0.05 * m * g, "O.Fx": 0.0, "O.Fy": m * g, "base.Fx": 0.0,
              "base.Fy": (m + m0) * g, "base.Mz": 0.05 * m * g + 0.1 * m0 * g}
    for column, value in expect.items():
        np.testing.assert_allclose(res[column], value, rtol=0, atol=RTOL * (m + m0) * g,
                                   err_msg=column)


# ---- virtual work ---------------------------------------------------------------------------

def virtual_work_model(P, h, r, l, C, analysis):
    return f"""
[model]
name = "massless slider-crank"
gravity = 0.0

[[solid]]
name = "ground"
points = {{ O = [0.0, 0.0] }}
lines = {{ rail = {{ point = [0.0, {h!r}], angle = 0.0 }} }}

[[solid]]
name = "crank"
fi = {C[0]!r}
points = {{ O = [0.0, 0.0], A = [{r!r}, 0.0] }}

[[solid]]
name = "rod"
x = {r * math.cos(C[0])!r}
y = {r * math.sin(C[0])!r}
points = {{ A = [0.0, 0.0], B = [{l!r}, 0.0] }}

[[solid]]
name = "slider"
x = {r + l!r}
y = {h!r}
points = {{ B = [0.0, 0.0] }}
lines = {{ axis = {{ point = [0.0, 0.0], angle = 0.0 }} }}

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
type = "revolute"
name = "A"
anc1 = "crank.A"
anc2 = "rod.A"

[[element]]
type = "revolute"
name = "B"
anc1 = "rod.B"
anc2 = "slider.B"

[[element]]
type = "prismatic"
name = "guide"
anc1 = "ground.rail"
anc2 = "slider.axis"

[[element]]
type = "angular_actuator"
name = "motor"
anc1 = "ground"
anc2 = "crank"
law = "polynomial"
C = {list(C)!r}

[[element]]
type = "torsor"
name = "push"
anc1 = "slider.B"
C = [{P!r}, 0.0, 0.0]

[analysis]
type = "{analysis}"
"""


@pytest.mark.parametrize("analysis", ["quasi_static", "kinetostatic"])
def test_crank_torque_virtual_work(analysis):
    """Massless slider-crank (gravity 0), crank r = 0.1 about the origin, rod l = 0.3,
    slider pin on the rail y = h = 0.02, a constant global force P = 40 N along +x on the
    slider; θ = 0.2 + 5 t + 1 t², 1.2 s (a whole turn and more), 240 steps.

    Virtual work: the joints are ideal and the ground is fixed, so for any virtual motion
    δθ of the crank the motor's torque (Mz on the crank, −Mz on the ground, whose
    rotation is zero) and the force P do zero work in total: Mz δθ + P δx = 0, x the
    slider's position, hence
        Mz = −P dx/dθ.
    From the loop r sinθ + l sinφ = h, r cosθ + l cosφ = x:  dφ/dθ = −r cosθ/(l cosφ),
        dx/dθ = −r sinθ − l sinφ dφ/dθ = −r sin(θ − φ)/cosφ,
    so Mz = P r sin(θ − φ)/cosφ. Sign check: crank straight up (θ = π/2, φ ≈ 0) and the
    slider pushed to the right (P > 0): the rod pulls A to the right, a clockwise moment
    −r P about O, so the motor holds with +r P: Mz = P r cosφ/cosφ = P r > 0. ✓
    Massless, the result does not depend on the speed: kinetostatic gives the same.
    """
    P, h, r, l = 40.0, 0.02, 0.1, 0.3
    C = [0.2, 5.0, 1.0, 0.0]
    res = pam2exu.run(pam2exu.loads(virtual_work_model(P, h, r, l, C, analysis)),
                      analysis=analysis, t_end=1.2, steps=240)
    t = 1.2 * np.arange(241) / 240
    np.testing.assert_allclose(res.t, t, rtol=0, atol=1e-14)
    th, _, _ = law_polynomial(t, C)
    phi = np.arcsin((h - r * np.sin(th)) / l)
    dx_dth = -r * np.sin(th) - l * np.sin(phi) * (-r * np.cos(th) / (l * np.cos(phi)))
    np.testing.assert_allclose(dx_dth, -r * np.sin(th - phi) / np.cos(phi), rtol=0, atol=1e-15)
    ref = {"motor.Mz": -P * dx_dth}
    assert_matches(res, ref)

"""Kinematic analysis against closed-form solutions derived here, by hand.

Every reference below is an analytic expression of time: the actuator's law, then the
loop-closure equations of the mechanism solved for its position, differentiated once for
the velocities and twice for the accelerations. The derivation is in each docstring.
Nothing is taken from pam2exu except the results under test. The time laws
(``references/laws.py``), the column helpers, the error measure ``errors`` and the
four-bar's ``four_bar`` (``references/closed_form.py``) are shared with
benchmarks/speed_vs_error.py and live in the top-level ``references`` package.

Notation: e(a) = (cos a, sin a), n(a) = e(a + π/2) = (−sin a, cos a), so that
d/dt e(a) = a' n(a), d/dt n(a) = −a' e(a), and e(a)·e(b) = cos(a − b),
n(a)·e(b) = sin(b − a).

Error measure: for each column, max |pam2exu − reference| / scale, with scale the
largest |reference| of that column, or, when the reference is identically ~0 (a fixed
coordinate), the mechanism's natural scale of that variable (length L, L·ω, L·ω² for
x-like columns; 1 rad, ω, ω² for angles; ω a typical driver speed).
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import pam2exu
from references.closed_form import FOUR_BAR, e, errors, four_bar, n, solid, still
from references.laws import LAWS, actuator_law

#: each test runs on each backend (``every_backend`` in conftest.py)
pytestmark = pytest.mark.usefixtures("every_backend")

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
RTOL = 1e-9
TWO_PI = 2.0 * math.pi


# ---- comparison ------------------------------------------------------------------------

def assert_matches(res, ref, L, w, rtol=RTOL):
    err = errors(res, ref, L, w)
    bad = {k: v for k, v in err.items() if not v <= rtol}
    worst = max(err, key=err.get)
    assert not bad, f"relative errors above {rtol:g}: {bad} (worst {worst}: {err[worst]:.3g})"
    return err


# ---- closed forms ------------------------------------------------------------------------

def slider_crank(r, l, h, th, dth, ddth):
    """Offset slider-crank: crank r from the origin, rod l, pin B on the line y = h.

    Loop: r e(θ) + l e(φ) = (x_B, h).
    y:   r sinθ + l sinφ = h  →  φ = asin((h − r sinθ)/l)  (the branch with B to the
         right of A, cos φ > 0, as in the examples).
    d/dt:  r cosθ θ' + l cosφ φ' = 0  →  φ' = −r cosθ θ' / (l cosφ).
    d²/dt²: −r sinθ θ'² + r cosθ θ'' − l sinφ φ'² + l cosφ φ'' = 0
           →  φ'' = (r sinθ θ'² − r cosθ θ'' + l sinφ φ'²) / (l cosφ).
    x:   x_B = r cosθ + l cosφ,  x_B' = −r sinθ θ' − l sinφ φ',
         x_B'' = −r cosθ θ'² − r sinθ θ'' − l cosφ φ'² − l sinφ φ''.
    The rod's origin is A = r e(θ): A' = r θ' n(θ), A'' = r θ'' n(θ) − r θ'² e(θ).
    """
    phi = np.arcsin((h - r * np.sin(th)) / l)
    dphi = -r * np.cos(th) * dth / (l * np.cos(phi))
    ddphi = (r * np.sin(th) * dth**2 - r * np.cos(th) * ddth
             + l * np.sin(phi) * dphi**2) / (l * np.cos(phi))
    A, dA, ddA = r * e(th), r * dth * n(th), r * ddth * n(th) - r * dth**2 * e(th)
    xB = r * np.cos(th) + l * np.cos(phi)
    dxB = -r * np.sin(th) * dth - l * np.sin(phi) * dphi
    ddxB = (-r * np.cos(th) * dth**2 - r * np.sin(th) * ddth
            - l * np.cos(phi) * dphi**2 - l * np.sin(phi) * ddphi)
    return (A, dA, ddA), (phi, dphi, ddphi), (xB, dxB, ddxB)


def polar(Q, dQ, ddQ):
    """Angle β and length ρ of a moving vector Q = ρ e(β), with their rates.

    Q' = ρ' e(β) + ρ β' n(β)  →  ρ' = Q'·e(β), β' = Q'·n(β)/ρ;
    Q'' = (ρ'' − ρ β'²) e(β) + (2 ρ' β' + ρ β'') n(β)
       →  β'' = (Q''·n(β) − 2 ρ' β')/ρ,  ρ'' = Q''·e(β) + ρ β'².
    """
    beta = np.unwrap(np.arctan2(Q[1], Q[0]))
    rho = np.hypot(Q[0], Q[1])
    eb, nb = e(beta), n(beta)
    drho = np.sum(dQ * eb, axis=0)
    dbeta = np.sum(dQ * nb, axis=0) / rho
    ddbeta = (np.sum(ddQ * nb, axis=0) - 2 * drho * dbeta) / rho
    ddrho = np.sum(ddQ * eb, axis=0) + rho * dbeta**2
    return (beta, dbeta, ddbeta), (rho, drho, ddrho)


def rocker_by_cylinder(c, d, L, dL, ddL):
    """Rocker of length c hinged at the origin, cylinder from P = (d, 0) to the rocker's
    end Q = c e(ψ), length |Q − P| = L(t).

    Law of cosines: L² = c² + d² − 2 c d cosψ  →  ψ = acos((c² + d² − L²)/(2 c d))
    (the branch with the rocker above the ground line, 0 < ψ < π).
    d/dt:   2 c d sinψ ψ' = 2 L L'  →  ψ' = L L' / (c d sinψ).
    d²/dt²: c d (cosψ ψ'² + sinψ ψ'') = L'² + L L''
            →  ψ'' = (L'² + L L'' − c d cosψ ψ'²) / (c d sinψ).
    """
    psi = np.arccos((c * c + d * d - L * L) / (2 * c * d))
    dpsi = L * dL / (c * d * np.sin(psi))
    ddpsi = (dL**2 + L * ddL - c * d * np.cos(psi) * dpsi**2) / (c * d * np.sin(psi))
    return psi, dpsi, ddpsi


def rigid_point(r, dr, ddr, fi, dfi, ddfi, s):
    """Point s (local) of a solid with origin r and angle fi: p = r + R(fi) s.

    p' = r' + fi' Ω R s, p'' = r'' + fi'' Ω R s − fi'² R s (Ω: turn by +90°).
    """
    Rs = np.stack([np.cos(fi) * s[0] - np.sin(fi) * s[1], np.sin(fi) * s[0] + np.cos(fi) * s[1]])
    ORs = np.stack([-Rs[1], Rs[0]])
    return r + Rs, dr + dfi * ORs, ddr + ddfi * ORs - dfi**2 * Rs


# ---- slider-crank (examples/slider_crank.toml) -------------------------------------------

@pytest.fixture(scope="module")
def slider_crank_run():
    model = pam2exu.load(EXAMPLES / "slider_crank.toml")
    omega = 10.0                                  # C2 of the motor's polynomial law
    res = pam2exu.run(model, analysis="kinematic", t_end=2 * TWO_PI / omega, steps=2000)
    return model, res


def test_slider_crank_all_bodies(slider_crank_run):
    """Crank r = 0.1, rod l = 0.3, slider on y = 0, θ = 10 t (examples/slider_crank.toml),
    two full turns in 2000 steps. Closed form: ``slider_crank`` (loop closure r e(θ) +
    l e(φ) = (x_B, 0), differentiated twice). The crank's origin is fixed at O; the rod's
    origin is A; the slider's origin is B, its angle stays 0.
    """
    model, res = slider_crank_run
    t = res.t
    th, dth, ddth = actuator_law(model, "motor", t)
    (A, dA, ddA), (phi, dphi, ddphi), (xB, dxB, ddxB) = slider_crank(0.1, 0.3, 0.0, th, dth, ddth)
    z = np.zeros_like(t)
    ref = {**still("ground", 0.0, 0.0, 0.0, len(t)),
           **solid("crank", (z, z), th, (z, z), dth, (z, z), ddth),
           **solid("rod", A, phi, dA, dphi, ddA, ddphi),
           **solid("slider", (xB, z), z, (dxB, z), z, (ddxB, z), z),
           "motor.f(t)": th, "motor.Df(t)": dth}
    assert_matches(res, ref, L=0.4, w=10.0)


def test_slider_crank_angles_not_wrapped(slider_crank_run):
    """Two turns at 10 rad/s: crank.fi runs continuously from 0 to 4π (never wrapped);
    motor.f(t) = 10 t and motor.Df(t) = 10 (polynomial law C = [0, 10, 0, 0])."""
    _, res = slider_crank_run
    assert res["crank.fi"][-1] == pytest.approx(4 * math.pi, rel=1e-12)
    assert np.all(np.diff(res["crank.fi"]) > 0)
    np.testing.assert_allclose(res["motor.f(t)"], 10.0 * res.t, rtol=0, atol=1e-12)
    np.testing.assert_allclose(res["motor.Df(t)"], 10.0, rtol=0, atol=1e-12)


# ---- four-bar (examples/four_bar.toml) ---------------------------------------------------

COUPLER_P = np.array([0.2, 0.1])
SPRING_ANCHOR = np.array([0.25, -0.15])


def four_bar_model(law=None, C=None):
    """examples/four_bar.toml, with a spring ground.S – coupler.P and a torsional spring
    crank – rocker added for their outputs; optionally another law for the motor."""
    model = pam2exu.load(EXAMPLES / "four_bar.toml")
    if law is not None:
        model["motor"].law, model["motor"].C = law, C
    model["ground"].points["S"] = list(SPRING_ANCHOR)
    model.add("spring", name="spring", anc1="ground.S", anc2="coupler.P", C=[0, 100.0, 0.2, 1.0])
    model.add("torsional_spring", name="twist", anc1="crank", anc2="rocker", C=[0, 2.0, 0, 0.1])
    return model


@pytest.mark.parametrize("law, C", [
    (None, None),                                      # the example: θ = 2π t
    ("polynomial", [0.3, 4.0, 3.0, -1.0]),             # accelerating crank, θ'' ≠ 0
], ids=["constant_speed", "accelerating"])
def test_four_bar_all_bodies(law, C):
    """Crank-rocker a = 0.1, b = 0.35, c = 0.3, d = 0.4 (examples/four_bar.toml), 2 s in
    2000 steps. Closed form: ``four_bar`` (circle intersection for φ, ψ, then the loop
    closure differentiated once and twice). Crank origin O2 fixed, coupler origin A =
    a e(θ), rocker origin O4 = (d, 0) fixed.

    Also the force elements' kinematic outputs: spring from S to the coupler point P,
    P = A + R(φ) p (``rigid_point``), ro = |P − S|, Dro = (P − S)·P'/ro; torsional spring
    crank → rocker, fi_rel = ψ − θ, Dfi_rel = ψ' − θ'.
    """
    model = four_bar_model(law, C)
    res = pam2exu.run(model, analysis="kinematic", t_end=2.0, steps=2000)
    t = res.t
    th, dth, ddth = actuator_law(model, "motor", t)
    (phi, dphi, ddphi), (psi, dpsi, ddpsi) = four_bar(**FOUR_BAR, th=th, dth=dth, ddth=ddth)
    a, d = FOUR_BAR["a"], FOUR_BAR["d"]
    z = np.zeros_like(t)
    A, dA, ddA = a * e(th), a * dth * n(th), a * ddth * n(th) - a * dth**2 * e(th)
    P, dP, _ = rigid_point(A, dA, ddA, phi, dphi, ddphi, COUPLER_P)
    SP = P - SPRING_ANCHOR[:, None]
    ro = np.hypot(SP[0], SP[1])
    ref = {**still("ground", 0.0, 0.0, 0.0, len(t)),
           **solid("crank", (z, z), th, (z, z), dth, (z, z), ddth),
           **solid("coupler", A, phi, dA, dphi, ddA, ddphi),
           **solid("rocker", (z + d, z), psi, (z, z), dpsi, (z, z), ddpsi),
           "motor.f(t)": th, "motor.Df(t)": dth,
           "spring.ro": ro, "spring.Dro": np.sum(SP * dP, axis=0) / ro,
           "twist.fi_rel": psi - th, "twist.Dfi_rel": dpsi - dth}
    w = float(np.max(np.abs(dth)))
    assert_matches(res, ref, L=0.4, w=w)


# ---- transmissions -----------------------------------------------------------------------

def planetary_model(sun_driven):
    """Sun r_s = 0.06 at the origin, arm hinged to the sun's centre, planet r_p = 0.04
    hinged to the arm at R = r_s + r_p. Sun held (fixed at fi = 0.2) or driven."""
    m = pam2exu.Model("planetary", gravity=0)
    m.add_solid("ground", points={"O": [0.0, 0.0]})
    m.add_solid("sun", fi=0.2, points={"O": [0.0, 0.0]})
    m.add_solid("arm", fi=0.55, points={"O": [0.0, 0.0], "P": [0.1, 0.0]})
    m.add_solid("planet", x=0.08, y=0.06, fi=2.0, points={"O": [0.0, 0.0]})
    m.add("fixed", name="base", anc1="ground")
    if sun_driven:
        m.add("revolute", name="sun_bearing", anc1="ground.O", anc2="sun.O")
        m.add("angular_actuator", name="sun_drive", anc1="ground", anc2="sun",
              law="polynomial", C=[0.2, -1.5, 0.8, 0.0])
    else:
        m.add("fixed", name="sun_held", anc1="sun")
    m.add("revolute", name="arm_bearing", anc1="sun.O", anc2="arm.O")
    m.add("revolute", name="planet_bearing", anc1="arm.P", anc2="planet.O")
    m.add("angular_actuator", name="arm_drive", anc1="ground", anc2="arm", law="harmonic",
          C=[1.0, 0.5, 3.0, 0.4])
    m.add("transmission", name="mesh", anc1="sun", anc2="planet", T=-0.06 / 0.04, C=0.25)
    return m


@pytest.mark.parametrize("sun_driven", [False, True], ids=["sun_held", "sun_driven"])
def test_planetary_gear_train(sun_driven):
    """Epicyclic train. Relative to the arm the sun and the planet mesh as a fixed-axis
    external pair, so (Willis) ω_p − ω_a = −(r_s/r_p)(ω_s − ω_a): the contract's
    (fi_p − fi_a) − T (fi_s − fi_a) − C = 0 with T = −r_s/r_p = −1.5, C = 0.25 gives
        fi_p = (1 − T) fi_a + T fi_s + C,
    and with the sun held (ω_s = 0) ω_p/ω_a = 1 − T = 1 + r_s/r_p = 2.5.
    The planet's centre is on the arm at R = 0.1: R e(fi_a), R fi_a' n(fi_a),
    R fi_a'' n(fi_a) − R fi_a'² e(fi_a). The arm turns about the origin with
    fi_a = 1 + 0.5 cos(3t + 0.4) (harmonic law); the sun is fixed at 0.2 or follows
    0.2 − 1.5 t + 0.8 t² (polynomial law).
    """
    model = planetary_model(sun_driven)
    res = pam2exu.run(model, analysis="kinematic", t_end=3.0, steps=600)
    t = res.t
    fa, dfa, ddfa = actuator_law(model, "arm_drive", t)
    if sun_driven:
        fs, dfs, ddfs = actuator_law(model, "sun_drive", t)
    else:
        fs, dfs, ddfs = 0.2 + 0 * t, 0 * t, 0 * t
    T, C, R = -1.5, 0.25, 0.1
    z = np.zeros_like(t)
    ref = {**still("ground", 0.0, 0.0, 0.0, len(t)),
           **solid("sun", (z, z), fs, (z, z), dfs, (z, z), ddfs),
           **solid("arm", (z, z), fa, (z, z), dfa, (z, z), ddfa),
           **solid("planet", R * e(fa), (1 - T) * fa + T * fs + C, R * dfa * n(fa),
                   (1 - T) * dfa + T * dfs, R * ddfa * n(fa) - R * dfa**2 * e(fa),
                   (1 - T) * ddfa + T * ddfs)}
    assert_matches(res, ref, L=0.1, w=float(np.max(np.abs(dfa))))
    if not sun_driven:
        np.testing.assert_allclose(res["planet.Dfi"], 2.5 * res["arm.Dfi"], rtol=0,
                                   atol=1e-9 * float(np.max(np.abs(res["planet.Dfi"]))))


def test_fixed_axis_gears_with_ground_as_arm():
    """Gear pair and a ring gear on a ground turned by fi_g = 0.3 and moved to (0.05, −0.02),
    so the arm term matters. Gear 1 (r1 = 0.05) hinged at G1 = (0, 0) of the ground,
    gear 2 (r2 = 0.03) at G2 = (0.08, 0) (external mesh, T12 = −r1/r2), ring 3
    (internal, R3 = 0.07) at G3 = (0.08 − 0.04, 0) around gear 2 (internal mesh, same
    sense, T23 = +r2/R3). The arm of both transmissions is the ground (the only solid
    hinged to both gears): fi_2 − fi_g = T12 (fi_1 − fi_g) + C12, fi_3 − fi_g =
    T23 (fi_2 − fi_g) + C23. Gear 1 follows fi_1 − fi_g = f(t), bezier_c1 from 0 to
    3 rad over [0.1, 0.9] s, so every rate is a multiple of f', f''. Centres are at rest
    at (0.05, −0.02) + R(0.3) G.
    """
    g, r0 = 0.3, np.array([0.05, -0.02])
    m = pam2exu.Model("gears", gravity=0)
    G = {"G1": [0.0, 0.0], "G2": [0.08, 0.0], "G3": [0.04, 0.0]}
    m.add_solid("ground", x=r0[0], y=r0[1], fi=g, points=G)
    centre = {k: r0 + np.array([math.cos(g) * p[0] - math.sin(g) * p[1],
                                math.sin(g) * p[0] + math.cos(g) * p[1]]) for k, p in G.items()}
    for k, (name, fi) in enumerate((("gear1", 0.3), ("gear2", 0.5), ("ring", 0.4)), start=1):
        x, y = centre[f"G{k}"] + 0.003
        m.add_solid(name, x=float(x), y=float(y), fi=fi, points={"O": [0.0, 0.0]})
        m.add("revolute", name=f"bearing{k}", anc1=f"ground.G{k}", anc2=f"{name}.O")
    m.add("fixed", name="base", anc1="ground")
    m.add("angular_actuator", name="drive", anc1="ground", anc2="gear1", law="bezier_c1",
          C=[0.1, 0.9, 0.0, 3.0])
    T12, C12, T23, C23 = -0.05 / 0.03, 0.2, 0.03 / 0.07, -0.1
    m.add("transmission", name="pair", anc1="gear1", anc2="gear2", T=T12, C=C12)
    m.add("transmission", name="internal", anc1="gear2", anc2="ring", T=T23, C=C23)
    res = pam2exu.run(m, analysis="kinematic", t_end=1.0, steps=400)
    t = res.t
    f, df, ddf = actuator_law(m, "drive", t)
    rel = {"gear1": (f, df, ddf)}
    rel["gear2"] = tuple(T12 * v + (C12 if k == 0 else 0.0) for k, v in enumerate(rel["gear1"]))
    rel["ring"] = tuple(T23 * v + (C23 if k == 0 else 0.0) for k, v in enumerate(rel["gear2"]))
    z = np.zeros_like(t)
    ref = dict(still("ground", r0[0], r0[1], g, len(t)))
    for k, name in enumerate(("gear1", "gear2", "ring"), start=1):
        c = centre[f"G{k}"]
        v, dv, ddv = rel[name]
        ref.update(solid(name, (z + c[0], z + c[1]), g + v, (z, z), dv, (z, z), ddv))
    assert_matches(res, ref, L=0.1, w=float(np.max(np.abs(df))) * abs(T12))


#: 60 turns take 11 s on the natural backend (2 cores): --long (one turn stays in CI)
SIXTY_TURNS = pytest.mark.long(backends=("natural",))


@pytest.mark.parametrize("size, turns", [pytest.param(1.0, 60, marks=SIXTY_TURNS), (0.01, 1),
                                         pytest.param(0.01, 60, marks=SIXTY_TURNS)],
                         ids=["60_turns", "centimetre_gears", "centimetre_gears_60_turns"])
def test_gear_pair_many_turns(size, turns):
    """Angles are never wrapped, so after many turns the angle equations add up terms of
    hundreds of radians; the positions must still be solved (and to the same accuracy), at
    any size of the mechanism. Pinion (r1 = 0.05·size) hinged at the ground's origin
    turned ``turns`` times at constant speed, wheel (r2 = 0.03·size) at (0.08·size, 0):
    fi_2 = T fi_1 + C with T = −r1/r2 (external mesh, arm = ground at fi = 0),
    Dfi_2 = T Dfi_1, DDfi_2 = 0.
    """
    T, C, w = -0.05 / 0.03, 0.2, TWO_PI * turns
    m = pam2exu.Model("gear-pair", gravity=0)
    m.add_solid("ground", points={"G1": [0.0, 0.0], "G2": [0.08 * size, 0.0]})
    m.add_solid("pinion", points={"O": [0.0, 0.0]})
    m.add_solid("wheel", x=0.08 * size, fi=C, points={"O": [0.0, 0.0]})
    m.add("fixed", name="base", anc1="ground")
    m.add("revolute", name="bearing1", anc1="ground.G1", anc2="pinion.O")
    m.add("revolute", name="bearing2", anc1="ground.G2", anc2="wheel.O")
    m.add("angular_actuator", name="drive", anc1="ground", anc2="pinion", C=[0.0, w])
    m.add("transmission", name="pair", anc1="pinion", anc2="wheel", T=T, C=C)
    res = pam2exu.run(m, analysis="kinematic", t_end=1.0, steps=2000)
    t, z = res.t, np.zeros_like(res.t)
    ref = {**solid("pinion", (z, z), w * t, (z, z), w + z, (z, z), z),
           **solid("wheel", (z + 0.08 * size, z), T * w * t + C, (z, z), T * w + z, (z, z), z)}
    assert_matches(res, ref, L=0.08 * size, w=w * abs(T))


# ---- linear actuator ---------------------------------------------------------------------

def cylinder_model(law, C):
    """Rocker c = 0.2 hinged at O = (0, 0); hydraulic cylinder from P = (0.3, 0): barrel
    hinged at P, piston hinged to the rocker's end Q, prismatic barrel-piston, linear
    actuator from the barrel's pin P to the piston's pin Q."""
    m = pam2exu.Model("cylinder", gravity=0)
    m.add_solid("ground", points={"O": [0.0, 0.0], "P": [0.3, 0.0]})
    m.add_solid("rocker", fi=1.2, points={"O": [0.0, 0.0], "Q": [0.2, 0.0]})
    m.add_solid("barrel", x=0.3, fi=2.3, points={"O": [0.0, 0.0]},
                lines={"axis": {"point": [0.0, 0.0], "angle": 0.0}})
    m.add_solid("piston", x=0.08, y=0.18, fi=2.3, points={"O": [0.0, 0.0]},
                lines={"axis": {"point": [0.0, 0.0], "angle": 0.0}})
    m.add("fixed", name="base", anc1="ground")
    m.add("revolute", name="pivot", anc1="ground.O", anc2="rocker.O")
    m.add("revolute", name="barrel_pin", anc1="ground.P", anc2="barrel.O")
    m.add("revolute", name="piston_pin", anc1="piston.O", anc2="rocker.Q")
    m.add("prismatic", name="bore", anc1="barrel.axis", anc2="piston.axis")
    m.add("linear_actuator", name="cylinder", anc1="barrel.O", anc2="piston.O", law=law, C=C)
    return m


@pytest.mark.parametrize("law, C", [
    ("bezier_c2", [0.1, 0.9, 0.26, 0.40]),
    ("harmonic", [0.33, 0.06, 7.0, 0.5]),
])
def test_linear_actuator_rocker(law, C):
    """Rocker angle from the triangle O-P-Q (``rocker_by_cylinder``: law of cosines,
    L² = c² + d² − 2 c d cosψ, differentiated twice), c = 0.2, d = 0.3, L(t) the law.
    The rocker end Q = c e(ψ), Q' = c ψ' n(ψ), Q'' = c ψ'' n(ψ) − c ψ'² e(ψ); the barrel
    and the piston point from P to Q: their angle β and rates from ``polar`` applied to
    Q − P (and |Q − P| = L is checked on the way). Barrel origin at P, at rest;
    piston origin at Q.
    """
    c, d = 0.2, 0.3
    model = cylinder_model(law, C)
    res = pam2exu.run(model, analysis="kinematic", t_end=1.0, steps=500)
    t = res.t
    L, dL, ddL = actuator_law(model, "cylinder", t)
    psi, dpsi, ddpsi = rocker_by_cylinder(c, d, L, dL, ddL)
    Q, dQ, ddQ = c * e(psi), c * dpsi * n(psi), c * ddpsi * n(psi) - c * dpsi**2 * e(psi)
    (beta, dbeta, ddbeta), (rho, drho, ddrho) = polar(Q - np.array([[d], [0.0]]), dQ, ddQ)
    np.testing.assert_allclose(np.stack([rho, drho, ddrho]), np.stack([L, dL, ddL]),
                               rtol=0, atol=1e-12)           # the reference closes
    z = np.zeros_like(t)
    ref = {**still("ground", 0.0, 0.0, 0.0, len(t)),
           **solid("rocker", (z, z), psi, (z, z), dpsi, (z, z), ddpsi),
           **solid("barrel", (z + d, z), beta, (z, z), dbeta, (z, z), ddbeta),
           **solid("piston", Q, beta, dQ, dbeta, ddQ, ddbeta),
           "cylinder.f(t)": L, "cylinder.Df(t)": dL}
    assert_matches(res, ref, L=0.3, w=float(np.max(np.abs(dpsi))))


# ---- pin in slot ---------------------------------------------------------------------------

def test_pin_slot_quick_return():
    """Crank-and-slotted-lever quick return. Lever hinged at O4 = (0, 0), its slot along
    its local x axis; crank hinged at O2 = (0, h), h = 0.15, pin at r = 0.06 on it, so the
    pin is Q = (r cosθ, h + r sinθ), Q' = r θ' n(θ), Q'' = r θ'' n(θ) − r θ'² e(θ).
    The pin stays on the slot, so the lever's angle is the polar angle of Q: β and its
    rates from ``polar`` (Q = ρ e(β) differentiated twice). Since h > r the lever
    oscillates and never passes a dead point. Crank: θ = 0.1 + 5 t + 2 t², 2 s.
    """
    r, h = 0.06, 0.15
    m = pam2exu.Model("quick-return", gravity=0)
    m.add_solid("ground", points={"O4": [0.0, 0.0], "O2": [0.0, h]})
    m.add_solid("crank", y=h, fi=0.12, points={"O": [0.0, 0.0], "pin": [r, 0.0]})
    m.add_solid("lever", fi=1.2, points={"O": [0.0, 0.0]},
                lines={"slot": {"point": [0.0, 0.0], "angle": 0.0}})
    m.add("fixed", name="base", anc1="ground")
    m.add("revolute", name="O2", anc1="ground.O2", anc2="crank.O")
    m.add("revolute", name="O4", anc1="ground.O4", anc2="lever.O")
    m.add("pin_slot", name="slot", anc1="lever.slot", anc2="crank.pin")
    m.add("angular_actuator", name="motor", anc1="ground", anc2="crank", C=[0.1, 5.0, 2.0])
    res = pam2exu.run(m, analysis="kinematic", t_end=2.0, steps=1000)
    t = res.t
    th, dth, ddth = actuator_law(m, "motor", t)
    Q = np.stack([r * np.cos(th), h + r * np.sin(th)])
    dQ, ddQ = r * dth * n(th), r * ddth * n(th) - r * dth**2 * e(th)
    (beta, dbeta, ddbeta), _ = polar(Q, dQ, ddQ)
    z = np.zeros_like(t)
    ref = {**solid("crank", (z, z + h), th, (z, z), dth, (z, z), ddth),
           **solid("lever", (z, z), beta, (z, z), dbeta, (z, z), ddbeta)}
    assert_matches(res, ref, L=h, w=float(np.max(dth)))


def test_pin_slot_scotch_yoke():
    """Scotch yoke: crank r = 0.05 hinged at the origin, its pin in a vertical slot of a
    yoke that slides along the ground's x axis (prismatic). The slot is the yoke's line
    through its origin at 90°, so the yoke's origin is at x = r cosθ, y = 0, fi = 0:
    x' = −r sinθ θ', x'' = −r cosθ θ'² − r sinθ θ''. θ harmonic: 1 + 2 cos(4 t).
    """
    r = 0.05
    m = pam2exu.Model("scotch-yoke", gravity=0)
    m.add_solid("ground", points={"O": [0.0, 0.0]},
                lines={"rail": {"point": [0.0, 0.0], "angle": 0.0}})
    m.add_solid("crank", fi=2.9, points={"O": [0.0, 0.0], "pin": [r, 0.0]})
    m.add_solid("yoke", x=-0.04, y=0.002, fi=0.01,
                lines={"axis": {"point": [0.0, 0.0], "angle": 0.0},
                       "slot": {"point": [0.0, 0.0], "angle": math.pi / 2}})
    m.add("fixed", name="base", anc1="ground")
    m.add("revolute", name="O", anc1="ground.O", anc2="crank.O")
    m.add("prismatic", name="guide", anc1="ground.rail", anc2="yoke.axis")
    m.add("pin_slot", name="slot", anc1="yoke.slot", anc2="crank.pin")
    m.add("angular_actuator", name="motor", anc1="ground", anc2="crank", law="harmonic",
          C=[1.0, 2.0, 4.0, 0.0])
    res = pam2exu.run(m, analysis="kinematic", t_end=2.0, steps=800)
    t = res.t
    th, dth, ddth = actuator_law(m, "motor", t)
    z = np.zeros_like(t)
    ref = {**solid("crank", (z, z), th, (z, z), dth, (z, z), ddth),
           **solid("yoke", (r * np.cos(th), z), z, (-r * np.sin(th) * dth, z), z,
                   (-r * np.cos(th) * dth**2 - r * np.sin(th) * ddth, z), z)}
    assert_matches(res, ref, L=r, w=8.0)


# ---- every element and every law (examples/all_elements.toml) ----------------------------------

def test_all_elements_example():
    """examples/all_elements.toml runs as it is: fully driven (0 free degrees of freedom),
    no redundant constraint, no warning, every column finite. Each sub-mechanism against
    its closed form, with the geometry read from the model file:
    offset slider-crank (``slider_crank``, rail at y = h), planetary train
    (fi_p = (1 − T) fi_a + T fi_s + C, planet centre on the arm), quick return
    (``polar`` of the pin seen from the lever's pivot), rocker and cylinder
    (``rocker_by_cylinder`` and ``polar``), and each actuator's f(t), Df(t), with
    the five laws written independently above. Spring: ro = |B − K|, Dro = (B − K)·B'/ro;
    torsional spring ground → rocker: fi_rel = ψ, Dfi_rel = ψ'.
    """
    model = pam2exu.load(EXAMPLES / "all_elements.toml")
    assert {el.type for el in model.elements} == {k for k, cls in pam2exu.ELEMENTS.items()
                                                  if not cls.extension}     # the contract's
    assert {el.law for el in model.elements if hasattr(el, "law")} == set(LAWS)
    res = pam2exu.run(model)
    assert res.analysis == "kinematic"
    assert res.info["dof"] == 0 and res.info["redundant_equations"] == 0
    assert res.warnings == []
    assert all(np.isfinite(res[c]).all() for c in res.columns)
    t = res.t
    z = np.zeros_like(t)
    ground = model["ground"].points
    pt = lambda solid_name, p: np.array(model[solid_name].points[p], dtype=float)  # noqa: E731
    ref = {}
    laws = {name: actuator_law(model, name, t)
            for name in ("motor", "sun_drive", "arm_drive", "wheel_drive", "cylinder")}
    for name, (f, df, _) in laws.items():
        ref[f"{name}.f(t)"], ref[f"{name}.Df(t)"] = f, df

    # 1. slider-crank, crank pivot at the ground's origin, rail y = h
    r, l = pt("crank", "A")[0], pt("rod", "B")[0]
    h = model["ground"].lines["rail"]["point"][1]
    th, dth, ddth = laws["motor"]
    (A, dA, ddA), (phi, dphi, ddphi), (xB, dxB, ddxB) = slider_crank(r, l, h, th, dth, ddth)
    ref.update(solid("crank", (z, z), th, (z, z), dth, (z, z), ddth))
    ref.update(solid("rod", A, phi, dA, dphi, ddA, ddphi))
    ref.update(solid("slider", (xB, z + h), z, (dxB, z), z, (ddxB, z), z))
    K = np.array(ground["K"])
    BK = np.stack([xB - K[0], h - K[1] + z])
    ro = np.hypot(*BK)
    ref["return_spring.ro"], ref["return_spring.Dro"] = ro, BK[0] * dxB / ro

    # 2. planetary train about S
    S = np.array(ground["S"])[:, None]
    T, C = float(model["mesh"].T), float(model["mesh"].C)
    R = pt("arm", "P")[0]
    fs, dfs, ddfs = laws["sun_drive"]
    fa, dfa, ddfa = laws["arm_drive"]
    ref.update(solid("sun", S + 0 * z, fs, (z, z), dfs, (z, z), ddfs))
    ref.update(solid("arm", S + 0 * z, fa, (z, z), dfa, (z, z), ddfa))
    ref.update(solid("planet", S + R * e(fa), (1 - T) * fa + T * fs + C, R * dfa * n(fa),
                     (1 - T) * dfa + T * dfs, R * ddfa * n(fa) - R * dfa**2 * e(fa),
                     (1 - T) * ddfa + T * ddfs))

    # 3. quick return: wheel centre W, lever pivot L
    W, Lp = np.array(ground["W"])[:, None], np.array(ground["L"])[:, None]
    rw = pt("wheel", "pin")[0]
    tw, dtw, ddtw = laws["wheel_drive"]
    (beta, dbeta, ddbeta), _ = polar(W - Lp + rw * e(tw), rw * dtw * n(tw),
                                     rw * ddtw * n(tw) - rw * dtw**2 * e(tw))
    ref.update(solid("wheel", W + 0 * z, tw, (z, z), dtw, (z, z), ddtw))
    ref.update(solid("lever", Lp + 0 * z, beta, (z, z), dbeta, (z, z), ddbeta))

    # 4. rocker about Rp raised by the cylinder from P (P on the rocker's x axis)
    Rp, P = np.array(ground["R"])[:, None], np.array(ground["P"])[:, None]
    c, d = pt("rocker", "Q")[0], float(P[0, 0] - Rp[0, 0])
    assert P[1, 0] == Rp[1, 0]
    psi, dpsi, ddpsi = rocker_by_cylinder(c, d, *laws["cylinder"])
    Q, dQ, ddQ = c * e(psi), c * dpsi * n(psi), c * ddpsi * n(psi) - c * dpsi**2 * e(psi)
    (gam, dgam, ddgam), _ = polar(Q - np.array([[d], [0.0]]), dQ, ddQ)
    ref.update(solid("rocker", Rp + 0 * z, psi, (z, z), dpsi, (z, z), ddpsi))
    ref.update(solid("barrel", P + 0 * z, gam, (z, z), dgam, (z, z), ddgam))
    ref.update(solid("piston", Rp + Q, gam, dQ, dgam, ddQ, ddgam))
    ref["rocker_spring.fi_rel"], ref["rocker_spring.Dfi_rel"] = psi, dpsi

    ref.update(still("ground", 0.0, 0.0, 0.0, len(t)))
    assert set(ref) == set(res.columns)
    assert_matches(res, ref, L=0.9, w=TWO_PI)

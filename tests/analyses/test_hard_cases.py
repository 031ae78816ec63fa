"""Hard cases (issue 4): dead centres, dead points, branches, poor guesses, long runs,
(near-)redundancy, stiff springs — each against a reference derived here, by hand.

Nothing is taken from pam2exu except the results under test. The references:

* Slider-crank (crank r, rod l, slider pin on the rail y = h): loop closure
  r e(θ) + l e(φ) = (x_B, h) solved for φ and x_B and differentiated twice
  (``slider_crank``); forces by Newton–Euler on the free-body diagram of each solid,
  solved in closed form one solid after the other (``slider_crank_forces``); the motor
  torque a second time by the power balance Mz θ' = d/dt (kinetic + potential energy).
* Four-bars: every loop is a *dyad* — two links l1, l2 in series between a point P and a
  point Q(t) whose motion is known — solved in closed form (``dyad``: law of cosines for
  the position, the loop equation dotted with the links' directions for the rates).
  Crank-driven: the dyad coupler–rocker from the crank pin A to the pivot O4.
  Rocker-driven: the dyad crank–coupler from the pivot O2 to the rocker pin B. The
  rocker's dead points (limit angles, where crank and coupler are collinear) follow from
  the law of cosines: |B − O2| = a + b (extended) or b − a (folded).
* Parallelogram (crank = rocker, coupler = ground) on its parallelogram branch: rocker
  angle = crank angle, the coupler translates (fi = 0), its origin at r e(θ).
* Redundant parallelogram (tests/data/parallelogram5.toml): the same, three cranks.
* Stiff springs: static equilibrium of one solid (a pendulum, a slider) by hand.

Notation: e(a) = (cos a, sin a), n(a) = e(a + π/2) = (−sin a, cos a), so that
d/dt e(a) = a' n(a), d/dt n(a) = −a' e(a), n(a)·e(b) = sin(b − a); R(a) the rotation by
a; a × b = a_x b_y − a_y b_x; gravity g along −y.

Error measure, as in test_kinematic_closed_form.py: for each column,
max |pam2exu − reference| / scale, with scale the largest |reference| of that column, or,
when the reference is identically ~0, the mechanism's natural scale of that variable
(a length L, L·ω, L·ω², 1 rad, ω, ω², a force F, a moment F·L).
"""
from __future__ import annotations

import math
import re
import resource
import tracemalloc
import warnings
from pathlib import Path

import numpy as np
import pytest

import pam2exu
from pam2exu.analyses import RedundancyWarning
from references.closed_form import errors

#: the ill-conditioning warnings these cases raise on purpose are checked in res.warnings
pytestmark = [pytest.mark.filterwarnings("ignore::pam2exu.ConditionWarning"),
              pytest.mark.usefixtures("every_backend")]   # each test on each backend

DATA = Path(__file__).resolve().parents[1] / "data"
RTOL = 1e-9
TWO_PI = 2.0 * math.pi
GRAV = 9.81


# ---- helpers (independent of pam2exu) -----------------------------------------------------

def e(a):
    return np.stack([np.cos(a), np.sin(a)])


def n(a):
    return np.stack([-np.sin(a), np.cos(a)])


def dot(u, v):
    return u[0] * v[0] + u[1] * v[1]


def cross(u, v):
    return u[0] * v[1] - u[1] * v[0]


def rot(a, s):
    """R(a) s for a fixed local vector s; a scalar or an array of angles."""
    return np.stack([np.cos(a) * s[0] - np.sin(a) * s[1], np.sin(a) * s[0] + np.cos(a) * s[1]])


def rigid_point(r, dr, ddr, fi, dfi, ddfi, s):
    """Point s (local) of a solid with origin r and angle fi: p = r + R(fi) s,
    p' = r' + fi' Ω R s, p'' = r'' + fi'' Ω R s − fi'² R s (Ω: turn by +90°)."""
    Rs = rot(fi, s)
    ORs = np.stack([-Rs[1], Rs[0]])
    return r + Rs, dr + dfi * ORs, ddr + ddfi * ORs - dfi**2 * Rs


def law_polynomial(t, C):
    """f = C1 + C2 t + C3 t² + C4 t³, f' = C2 + 2 C3 t + 3 C4 t², f'' = 2 C3 + 6 C4 t."""
    c1, c2, c3, c4 = (tuple(C) + (0.0,) * 4)[:4]
    return (c1 + c2 * t + c3 * t**2 + c4 * t**3, c2 + 2 * c3 * t + 3 * c4 * t**2,
            2 * c3 + 6 * c4 * t + 0 * t)


def solid(name, r, fi, dr, dfi, ddr, ddfi):
    """The nine columns of a solid from its origin r (2, k), its angle and their rates."""
    z = np.zeros_like(np.asarray(fi, dtype=float))
    return {f"{name}.{v}": value + z for v, value in
            zip(("x", "y", "fi", "Dx", "Dy", "Dfi", "DDx", "DDy", "DDfi"),
                (*r, fi, *dr, dfi, *ddr, ddfi))}


def still(name, x, y, fi, k):
    z = np.zeros(k)
    return solid(name, (x + z, y + z), fi + z, (z, z), z, (z, z), z)


def positions_only(ref):
    return {k: v for k, v in ref.items() if k.rsplit(".", 1)[1] in ("x", "y", "fi")}


def rates_only(ref):
    return {k: v for k, v in ref.items() if k.rsplit(".", 1)[1] not in ("x", "y", "fi")}


def assert_matches(res, ref, L, w, F=1.0, rtol=RTOL):
    err = errors(res, ref, L, w, F)
    bad = {k: float(f"{v:.3g}") for k, v in err.items() if not v <= rtol}
    worst = max(err, key=err.get)
    assert not bad, f"relative errors above {rtol:g}: {bad} (worst {worst}: {err[worst]:.3g})"
    return err


def nearest_turn(angle, guess):
    """The angle series shifted by whole turns so that it starts nearest to ``guess``
    (pam2exu never wraps angles: they stay on the turn of the initial guess)."""
    return angle + TWO_PI * round((guess - float(angle[0])) / TWO_PI)


def dyad(D, dD, ddD, l1, l2, mode):
    """Two links in series, l1 e(θ1) + l2 e(θ2) = D(t), with D, D', D'' known (2, k).

    Position (law of cosines in the triangle of sides l1, l2, δ = |D|):
        θ1 = atan2(D) + mode · acos((l1² + δ² − l2²)/(2 l1 δ)),  mode = ±1 (assembly mode),
        θ2 = atan2(D − l1 e(θ1)).
    Velocity: l1 θ1' n(θ1) + l2 θ2' n(θ2) = D'. Dotted with e(θ2) and with e(θ1)
    (n(θ1)·e(θ2) = sin(θ2 − θ1) =: s, n(θ2)·e(θ1) = −s, n(θ)·e(θ) = 0):
        θ1' = D'·e(θ2)/(l1 s),  θ2' = −D'·e(θ1)/(l2 s).
    Acceleration: l1 θ1'' n(θ1) + l2 θ2'' n(θ2) = W := D'' + l1 θ1'² e(θ1) + l2 θ2'² e(θ2),
        θ1'' = W·e(θ2)/(l1 s),  θ2'' = −W·e(θ1)/(l2 s).
    s = 0 where the links are collinear: the dyad's dead point.
    """
    delta = np.hypot(D[0], D[1])
    th1 = np.unwrap(np.arctan2(D[1], D[0])
                    + mode * np.arccos((l1 * l1 + delta**2 - l2 * l2) / (2 * l1 * delta)))
    R = D - l1 * e(th1)
    th2 = np.unwrap(np.arctan2(R[1], R[0]))
    s = np.sin(th2 - th1)
    d1, d2 = dot(dD, e(th2)) / (l1 * s), -dot(dD, e(th1)) / (l2 * s)
    W = ddD + l1 * d1**2 * e(th1) + l2 * d2**2 * e(th2)
    return (th1, d1, dot(W, e(th2)) / (l1 * s)), (th2, d2, -dot(W, e(th1)) / (l2 * s))


# ---- 1. dead centres: slider-crank, centred and offset -------------------------------------

SC = {"r": 0.1, "l": 0.3,
      "crank": {"mass": 1.2, "inertia": 0.004, "cog": (0.04, 0.01)},
      "rod": {"mass": 2.0, "inertia": 0.02, "cog": (0.12, -0.02)},
      "slider": {"mass": 0.8, "inertia": 0.001, "cog": (0.02, 0.01)}}
#: centred: θ = 10 t, three turns in 600 steps, so θ_k = kπ/100 puts a grid point on
#: every dead centre (θ = 0, π, …, 6π); offset (h = 0.05): starts on the outer dead
#: centre θ_e = asin(h/(r + l)) and accelerates, θ = θ_e + 8 t + 2 t², about 3 turns
SC_CASES = {
    "centred": {"h": 0.0, "C": [0.0, 10.0], "t_end": 0.6 * math.pi, "steps": 600},
    "offset": {"h": 0.05, "C": [math.asin(0.05 / 0.4), 8.0, 2.0], "t_end": 1.7, "steps": 1700},
}


def slider_crank_model(h, C):
    """Crank O-A hinged at the ground's origin, rod A-B, slider pin B on the rail y = h
    (the ground's line 'rail'); the slider's origin is its pin B, its line through B at 0.
    Revolutes: O (ground → crank), A (crank → rod), B (rod → slider); prismatic 'guide'
    (ground rail → slider axis); motor ground → crank."""
    r, l = SC["r"], SC["l"]
    th0 = C[0]
    phi0 = math.asin((h - r * math.sin(th0)) / l)
    m = pam2exu.Model("slider-crank", gravity=GRAV)
    m.add_solid("ground", points={"O": [0.0, 0.0]},
                lines={"rail": {"point": [0.0, h], "angle": 0.0}})
    def inertia(name):
        return {"mass": SC[name]["mass"], "inertia": SC[name]["inertia"],
                "cog": list(SC[name]["cog"])}

    m.add_solid("crank", fi=th0 + 0.05, points={"O": [0.0, 0.0], "A": [r, 0.0]},
                **inertia("crank"))
    m.add_solid("rod", x=r * math.cos(th0) + 0.01, y=r * math.sin(th0) - 0.01, fi=phi0 + 0.05,
                points={"A": [0.0, 0.0], "B": [l, 0.0]}, **inertia("rod"))
    m.add_solid("slider", x=r * math.cos(th0) + l * math.cos(phi0) + 0.02, y=h, fi=0.02,
                points={"B": [0.0, 0.0]}, lines={"axis": {"point": [0.0, 0.0], "angle": 0.0}},
                **inertia("slider"))
    m.add("fixed", name="base", anc1="ground")
    m.add("revolute", name="O", anc1="ground.O", anc2="crank.O")
    m.add("revolute", name="A", anc1="crank.A", anc2="rod.A")
    m.add("revolute", name="B", anc1="rod.B", anc2="slider.B")
    m.add("prismatic", name="guide", anc1="ground.rail", anc2="slider.axis")
    m.add("angular_actuator", name="motor", anc1="ground", anc2="crank", C=list(C))
    return m


def slider_crank(h, t, C):
    """Closed-form motion of every solid.

    Loop r e(θ) + l e(φ) = (x_B, h). Its y component: sin φ = (h − r sin θ)/l, the branch
    cos φ > 0 (B to the right of A; l > r + |h|, so cos φ never vanishes and the crank
    passes both dead centres). Differentiated:
        r cos θ θ' + l cos φ φ' = 0  →  φ' = −r cos θ θ'/(l cos φ),
        φ'' = (r sin θ θ'² − r cos θ θ'' + l sin φ φ'²)/(l cos φ);
    x component: x_B = r cos θ + l cos φ, x_B' = −r sin θ θ' − l sin φ φ',
        x_B'' = −r cos θ θ'² − r sin θ θ'' − l cos φ φ'² − l sin φ φ''.
    Crank origin O = 0; rod origin A = r e(θ); slider origin (x_B, h), fi = 0.
    """
    r, l = SC["r"], SC["l"]
    th, dth, ddth = law_polynomial(t, C)
    phi = np.arcsin((h - r * np.sin(th)) / l)
    dphi = -r * np.cos(th) * dth / (l * np.cos(phi))
    ddphi = (r * np.sin(th) * dth**2 - r * np.cos(th) * ddth
             + l * np.sin(phi) * dphi**2) / (l * np.cos(phi))
    xB = r * np.cos(th) + l * np.cos(phi)
    dxB = -r * np.sin(th) * dth - l * np.sin(phi) * dphi
    ddxB = (-r * np.cos(th) * dth**2 - r * np.sin(th) * ddth
            - l * np.cos(phi) * dphi**2 - l * np.sin(phi) * ddphi)
    z = np.zeros_like(t)
    A = (r * e(th), r * dth * n(th), r * ddth * n(th) - r * dth**2 * e(th))
    return {"crank": ((np.stack([z, z]),) * 3, (th, dth, ddth)),
            "rod": (A, (phi, dphi, ddphi)),
            "slider": ((np.stack([xB, z + h]), np.stack([dxB, z]), np.stack([ddxB, z])),
                       (z, z, z))}


def slider_crank_ref(h, t, C):
    bodies = slider_crank(h, t, C)
    ref = dict(still("ground", 0.0, 0.0, 0.0, len(t)))
    for name, ((r0, dr, ddr), (fi, dfi, ddfi)) in bodies.items():
        ref.update(solid(name, r0, fi, dr, dfi, ddr, ddfi))
    f, df, _ = law_polynomial(t, C)
    ref["motor.f(t)"], ref["motor.Df(t)"] = f, df
    return ref


def slider_crank_forces(h, t, C, static=False):
    """Every reaction and the motor torque, by Newton–Euler, one solid after the other.

    G, a_G of each solid from ``rigid_point``; ``static``: every a_G and α set to 0
    (quasi_static). Unknowns, with the signs of docs/model-format.md: F_B = (B.Fx, B.Fy)
    rod → slider at B; F_A = (A.Fx, A.Fy) crank → rod at A; F_O = (O.Fx, O.Fy) ground →
    crank at O; guide: ground → slider, Fnormal along ν = (0, 1) (the slider's line at
    angle 0 turned +90°) at the line's point P = B plus a couple Mz; motor.Mz on the crank.
    Slider (no rotation, forces F_B and (0, Fn) at P, weight at G):
        x: B.Fx = m_s a_Gx;  y: B.Fy + Fn − m_s g = m_s a_Gy;
        about G: (P − G) × (F_B + (0, Fn)) + Mz = 0  →  Mz = (G − P) × (F_B + (0, Fn)).
    Rod (F_A at A, −F_B at B, weight): F_A = m_r a_G + F_B + (0, m_r g); about G:
        (A − G) × F_A − (B − G) × F_B = J_r φ''. With F_A substituted, (A − B) × F_B =
        J_r φ'' − (A − G) × (m_r a_G + (0, m_r g)) =: M, A − B = −l e(φ), so
        e(φ) × F_B = −M/l, i.e. cos φ B.Fy − sin φ B.Fx = −M/l → B.Fy (cos φ > 0).
    Crank (F_O at O, −F_A at A, Mz, weight): F_O = m_c a_G + F_A + (0, m_c g); about G:
        (O − G) × F_O − (A − G) × F_A + Mz = J_c θ''.
    Ground (massless, fixed): it receives −F_O at O, −(0, Fn) at P, −guide.Mz, −motor.Mz,
    and the fixed link's wrench at its origin, so base = (F_O + (0, Fn),
    O × F_O + P × (0, Fn) + guide.Mz + motor.Mz).
    """
    l = SC["l"]
    bodies = slider_crank(h, t, C)
    G = {}
    for name, (q, fi) in bodies.items():
        p, dp, ddp = rigid_point(*q, *fi, SC[name]["cog"])
        G[name] = (p, dp, 0 * ddp if static else ddp)
    alpha = {name: 0 * fi[2] if static else fi[2] for name, (_, fi) in bodies.items()}
    m = {name: SC[name]["mass"] for name in bodies}
    J = {name: SC[name]["inertia"] for name in bodies}
    up = np.array([[0.0], [1.0]])
    P = bodies["slider"][0][0]                                  # = B
    A = bodies["rod"][0][0]
    O = bodies["crank"][0][0]
    phi = bodies["rod"][1][0]
    # slider
    BFx = m["slider"] * G["slider"][2][0]
    # rod
    M = J["rod"] * alpha["rod"] - cross(A - G["rod"][0], m["rod"] * G["rod"][2]
                                        + m["rod"] * GRAV * up)
    BFy = (-M / l + np.sin(phi) * BFx) / np.cos(phi)
    FB = np.stack([BFx, BFy])
    Fn = m["slider"] * G["slider"][2][1] + m["slider"] * GRAV - BFy
    guide_Mz = cross(G["slider"][0] - P, FB + Fn * up)
    FA = m["rod"] * G["rod"][2] + FB + m["rod"] * GRAV * up
    # crank
    FO = m["crank"] * G["crank"][2] + FA + m["crank"] * GRAV * up
    Mz = (J["crank"] * alpha["crank"] - cross(O - G["crank"][0], FO)
          + cross(A - G["crank"][0], FA))
    base = FO + Fn * up
    base_Mz = cross(O, FO) + cross(P, Fn * up) + guide_Mz + Mz
    return {"motor.Mz": Mz, "O.Fx": FO[0], "O.Fy": FO[1], "A.Fx": FA[0], "A.Fy": FA[1],
            "B.Fx": FB[0], "B.Fy": FB[1], "guide.Fnormal": Fn, "guide.Mz": guide_Mz,
            "base.Fx": base[0], "base.Fy": base[1], "base.Mz": base_Mz}


def motor_torque_by_power(h, t, C, static=False):
    """Mz from the power balance alone (no reaction enters it): the only actuator's
    power equals the rate of kinetic plus potential energy,
        Mz θ' = Σ (m v_G·a_G + J ω α) + Σ m g v_Gy,
    every term in closed form (T = Σ ½ m |v_G|² + ½ J ω², V = Σ m g y_G); ``static``:
    virtual power, the inertia terms dropped. θ' > 0 throughout both cases."""
    bodies = slider_crank(h, t, C)
    power = 0.0
    for name, (q, (fi, dfi, ddfi)) in bodies.items():
        _, dp, ddp = rigid_point(*q, fi, dfi, ddfi, SC[name]["cog"])
        power = power + SC[name]["mass"] * GRAV * dp[1]
        if not static:
            power = power + SC[name]["mass"] * dot(dp, ddp) + SC[name]["inertia"] * dfi * ddfi
    return power / bodies["crank"][1][1]


@pytest.fixture(scope="module", params=list(SC_CASES))
def slider_crank_case(request):
    return request.param, SC_CASES[request.param]


def test_slider_crank_dead_centres_kinematic(slider_crank_case):
    """Kinematic analysis through both dead centres, several turns: every column against
    ``slider_crank`` (rel 1e-9). Centred: grid points fall on every dead centre
    (θ = kπ, where x_B = r + l and l − r, x_B' = 0); offset h = 0.05: it starts on the
    outer dead centre θ_e = asin(h/(r + l)) (crank and rod collinear, x_B = √((r + l)² − h²))
    and crosses the inner one θ_i = π + asin(h/(l − r)) three times between grid points."""
    name, case = slider_crank_case
    r, l, h = SC["r"], SC["l"], case["h"]
    res = pam2exu.run(slider_crank_model(h, case["C"]), analysis="kinematic",
                      t_end=case["t_end"], steps=case["steps"])
    t = res.t
    ref = slider_crank_ref(h, t, case["C"])
    assert_matches(res, ref, L=r + l, w=20.0)
    th = ref["crank.fi"]
    if name == "centred":
        for k in range(0, len(t), 100):                     # θ_k = kπ/100
            outer = (k // 100) % 2 == 0
            assert res["slider.x"][k] == pytest.approx(l + r if outer else l - r, abs=1e-12)
            assert abs(res["slider.Dx"][k]) <= 1e-10
    else:
        assert th[0] == pytest.approx(math.asin(h / (r + l)), abs=1e-15)
        assert res["slider.x"][0] == pytest.approx(math.sqrt((r + l)**2 - h * h), abs=1e-12)
        assert th[-1] > math.pi + math.asin(h / (l - r)) + 2 * TWO_PI    # 3 inner dead centres
    assert res["crank.fi"][-1] == pytest.approx(th[-1], rel=1e-12)    # never wrapped


@pytest.mark.parametrize("analysis", ["kinetostatic", "quasi_static"])
def test_slider_crank_dead_centres_forces(slider_crank_case, analysis):
    """Every reaction and the motor torque through the dead centres against Newton–Euler
    (``slider_crank_forces``), rel 1e-9; the reference's motor torque is first checked
    against the power balance (``motor_torque_by_power``), which uses no reaction.
    quasi_static: the same equations without inertia."""
    _, case = slider_crank_case
    h = case["h"]
    static = analysis == "quasi_static"
    res = pam2exu.run(slider_crank_model(h, case["C"]), analysis=analysis,
                      t_end=case["t_end"], steps=case["steps"])
    t = res.t
    ref = slider_crank_forces(h, t, case["C"], static)
    scale = float(np.max(np.abs(ref["motor.Mz"])))
    np.testing.assert_allclose(ref["motor.Mz"], motor_torque_by_power(h, t, case["C"], static),
                               rtol=0, atol=1e-12 * scale)          # the reference closes
    F = max(float(np.max(np.abs(v))) for k, v in ref.items() if not k.endswith("Mz"))
    assert_matches(res, ref, L=SC["r"] + SC["l"], w=20.0, F=F)
    assert res.warnings == []


# ---- 2. toggle: a crank-rocker driven by its rocker, through its dead point ----------------

FB4 = {"a": 0.1, "b": 0.35, "c": 0.3, "d": 0.4}         # crank, coupler, rocker, ground


def four_bar_model(d, guess, drive, C, name="four-bar"):
    """Four-bar O2 = (0, 0), O4 = (d, 0); crank O2-A (a), coupler A-B (b), rocker O4-B (c).
    ``guess``: {solid: (x, y, fi)}; ``drive``: 'crank' (motor ground → crank) or 'rocker'
    (rocker_drive ground → rocker), polynomial law C."""
    a, b, c = FB4["a"], FB4["b"], FB4["c"]
    m = pam2exu.Model(name, gravity=0.0)
    m.add_solid("ground", points={"O2": [0.0, 0.0], "O4": [d, 0.0]})
    for s, pts in (("crank", {"O": [0.0, 0.0], "A": [a, 0.0]}),
                   ("coupler", {"A": [0.0, 0.0], "B": [b, 0.0]}),
                   ("rocker", {"O": [0.0, 0.0], "B": [c, 0.0]})):
        x, y, fi = (float(v) for v in guess[s])
        m.add_solid(s, x=x, y=y, fi=fi, points=pts)
    m.add("fixed", name="base", anc1="ground")
    m.add("revolute", name="O2", anc1="ground.O2", anc2="crank.O")
    m.add("revolute", name="A", anc1="crank.A", anc2="coupler.A")
    m.add("revolute", name="B", anc1="coupler.B", anc2="rocker.B")
    m.add("revolute", name="O4", anc1="ground.O4", anc2="rocker.O")
    actuator = "motor" if drive == "crank" else "rocker_drive"
    m.add("angular_actuator", name=actuator, anc1="ground", anc2=drive, C=list(C))
    return m


def crank_driven(d, t, C, mode, guess):
    """Columns of a crank-driven four-bar: θ = f(t); the dyad coupler (φ) – rocker from
    A = a e(θ) to O4, D = O4 − A, D' = −A', D'' = −A''; the second link of the dyad points
    from B to O4, so the rocker angle is ψ = θ2 ± π (the turn nearest the guess)."""
    a, b, c = FB4["a"], FB4["b"], FB4["c"]
    th, dth, ddth = law_polynomial(t, C)
    A = (a * e(th), a * dth * n(th), a * ddth * n(th) - a * dth**2 * e(th))
    (phi, dphi, ddphi), (chi, dchi, ddchi) = dyad(np.array([[d], [0.0]]) - A[0], -A[1], -A[2],
                                                  b, c, mode)
    phi = nearest_turn(phi, guess["coupler"][2])
    psi = nearest_turn(chi + math.pi, guess["rocker"][2])
    z = np.zeros_like(t)
    return {**still("ground", 0.0, 0.0, 0.0, len(t)),
            **solid("crank", (z, z), th, (z, z), dth, (z, z), ddth),
            **solid("coupler", A[0], phi, A[1], dphi, A[2], ddphi),
            **solid("rocker", (z + d, z), psi, (z, z), dchi, (z, z), ddchi)}


def rocker_driven(t, C, mode, guess):
    """Columns of the rocker-driven four-bar: ψ = f(t), B = O4 + c e(ψ),
    B' = c ψ' n(ψ), B'' = c ψ'' n(ψ) − c ψ'² e(ψ); the dyad crank (θ) – coupler (φ) from
    O2 = 0 to B."""
    a, b, c, d = FB4["a"], FB4["b"], FB4["c"], FB4["d"]
    psi, dpsi, ddpsi = law_polynomial(t, C)
    B = (np.array([[d], [0.0]]) + c * e(psi), c * dpsi * n(psi),
         c * ddpsi * n(psi) - c * dpsi**2 * e(psi))
    (th, dth, ddth), (phi, dphi, ddphi) = dyad(*B, a, b, mode)
    th = nearest_turn(th, guess["crank"][2])
    phi = nearest_turn(phi, guess["coupler"][2])
    z = np.zeros_like(t)
    A = rigid_point(np.stack([z, z]), np.stack([z, z]), np.stack([z, z]), th, dth, ddth, (a, 0.0))
    return {**still("ground", 0.0, 0.0, 0.0, len(t)),
            **solid("crank", (z, z), th, (z, z), dth, (z, z), ddth),
            **solid("coupler", A[0], phi, A[1], dphi, A[2], ddphi),
            **solid("rocker", (z + d, z), psi, (z, z), dpsi, (z, z), ddpsi)}


def rocker_limits():
    """The rocker's dead points: crank and coupler collinear, |B − O2| = a + b (outer)
    or b − a (inner); |B − O2|² = d² + c² + 2 d c cos ψ (B = O4 + c e(ψ)), so
    ψ = acos((|B − O2|² − d² − c²)/(2 d c)) on the upper side (0 < ψ < π)."""
    a, b, c, d = FB4["a"], FB4["b"], FB4["c"], FB4["d"]
    return tuple(math.acos((rho**2 - d * d - c * c) / (2 * d * c)) for rho in (a + b, b - a))


#: the rocker turned at 1 rad/s from ψ = 2.0 towards its inner dead point ψ_i ≈ 2.4675,
#: reached at t* = ψ_i − 2.0 ≈ 0.4675 s; 1 ms steps
TOGGLE_C, TOGGLE_DT = [2.0, 1.0], 1e-3


def toggle_guess():
    """The exact pose at t = 0 (mode +1), slightly disturbed."""
    ref = rocker_driven(np.zeros(1), TOGGLE_C, +1, {"crank": (0, 0, 0.0), "coupler": (0, 0, 0.0)})
    return {s: (ref[f"{s}.x"][0] + 0.003, ref[f"{s}.y"][0] - 0.002, ref[f"{s}.fi"][0] + 0.02)
            for s in ("crank", "coupler", "rocker")}


@pytest.mark.parametrize("analysis", ["kinematic", "kinetostatic", "quasi_static"])
def test_rocker_driven_four_bar_stops_at_its_dead_point(analysis):
    """Driven by its rocker, the crank-rocker cannot pass the rocker's inner limit angle
    ψ_i (``rocker_limits``): there crank and coupler are collinear (a singular, dead-point
    position), and past it the loop cannot close. Required: a SolverError whose message
    says that the mechanism reached a singular (dead-point) position, names the driving
    element ('rocker_drive') and the time, with .time within two steps of the closed-form
    t* = ψ_i − ψ(0); no results (so no garbage rows after t*)."""
    inner = rocker_limits()[1]
    t_star = inner - TOGGLE_C[0]
    assert 0.46 < t_star < 0.47
    model = four_bar_model(FB4["d"], toggle_guess(), "rocker", TOGGLE_C)
    with pytest.raises(pam2exu.SolverError) as info:
        pam2exu.run(model, analysis=analysis, t_end=1.0, steps=1000)
    err = info.value
    message = str(err)
    assert err.time is not None and abs(err.time - t_star) <= 2 * TOGGLE_DT, (err.time, t_star)
    assert err.step is not None and abs(err.step * TOGGLE_DT - t_star) <= 2 * TOGGLE_DT
    assert f"{err.time:.6g}" in message
    assert "'rocker_drive'" in message
    assert re.search(r"\b(reached|is at)\b[^.]*\bsingular\b[^.]*\bdead-point\b", message), (
        f"the message must say that the mechanism reached a singular (dead-point) "
        f"position; it says: {message}")


def test_rocker_driven_four_bar_is_exact_up_to_its_dead_point():
    """The same mechanism run to the last 1 ms step before t* (t = 0.467 s, ψ_i − ψ =
    4.6e-4 rad, where the crank already turns at 67 rad/s for a rocker at 1 rad/s):
    every column against ``rocker_driven`` (rel 1e-9)."""
    t_end = math.floor((rocker_limits()[1] - TOGGLE_C[0]) / TOGGLE_DT) * TOGGLE_DT
    steps = round(t_end / TOGGLE_DT)
    guess = toggle_guess()
    res = pam2exu.run(four_bar_model(FB4["d"], guess, "rocker", TOGGLE_C),
                      analysis="kinematic", t_end=t_end, steps=steps)
    ref = rocker_driven(res.t, TOGGLE_C, +1, guess)
    ref["rocker_drive.f(t)"], ref["rocker_drive.Df(t)"] = law_polynomial(res.t, TOGGLE_C)[:2]
    assert float(np.max(np.abs(ref["crank.Dfi"]))) > 60.0           # it is close to t*
    assert_matches(res, ref, L=0.4, w=1.0)


# ---- 3. branch stability -------------------------------------------------------------------

PAR = {"r": 0.3, "L": 1.0}
#: θ = θ0 + 6π t, 600 steps: Δθ = π/100. θ0 = π/4 puts grid points exactly on the six
#: change points θ = kπ (steps 75, 175, …, 575); θ0 = 0.3 passes them between grid points
PAR_CASES = {"grid_on_change_points": math.pi / 4, "grid_between_change_points": 0.3}


def parallelogram_model(th0):
    """Crank O1-A (r) and rocker O2-B (r), O1 = (0, 0), O2 = (L, 0), coupler A-B (L):
    a parallelogram four-bar (no fifth bar, no redundancy), motor ground → crank. The guess
    is near the parallelogram branch (coupler level, rocker parallel to the crank)."""
    r, L = PAR["r"], PAR["L"]
    m = pam2exu.Model("parallelogram", gravity=0.0)
    m.add_solid("ground", points={"O1": [0.0, 0.0], "O2": [L, 0.0]})
    m.add_solid("crank", fi=th0, points={"O": [0.0, 0.0], "A": [r, 0.0]})
    m.add_solid("coupler", x=r * math.cos(th0) + 0.01, y=r * math.sin(th0) - 0.01, fi=0.02,
                points={"A": [0.0, 0.0], "B": [L, 0.0]})
    m.add_solid("rocker", x=L, fi=th0 + 0.03, points={"O": [0.0, 0.0], "B": [r, 0.0]})
    m.add("fixed", name="base", anc1="ground")
    m.add("revolute", name="O1", anc1="ground.O1", anc2="crank.O")
    m.add("revolute", name="A", anc1="crank.A", anc2="coupler.A")
    m.add("revolute", name="B", anc1="coupler.B", anc2="rocker.B")
    m.add("revolute", name="O2", anc1="ground.O2", anc2="rocker.O")
    m.add("angular_actuator", name="motor", anc1="ground", anc2="crank", C=[th0, 3 * TWO_PI])
    return m


@pytest.fixture(scope="module", params=list(PAR_CASES))
def parallelogram_run(request):
    """(θ0, the Results or the SolverError raised) of three turns in 600 steps."""
    th0 = PAR_CASES[request.param]
    try:
        res = pam2exu.run(parallelogram_model(th0), analysis="kinematic", t_end=1.0, steps=600)
    except pam2exu.SolverError as exc:
        return th0, exc
    return th0, res


def parallelogram_ref(t, th0):
    """The parallelogram branch: θ = θ0 + ω t (ω = 6π, θ'' = 0); crank and rocker turn
    with θ, the coupler translates: origin A = r e(θ), A' = r ω n(θ), A'' = −r ω² e(θ)."""
    r, L, w = PAR["r"], PAR["L"], 3 * TWO_PI
    th = th0 + w * t
    z = np.zeros_like(t)
    return {**solid("crank", (z, z), th, (z, z), w + z, (z, z), z),
            **solid("coupler", r * e(th), z, r * w * n(th), z, -r * w * w * e(th), z),
            **solid("rocker", (z + L, z), th, (z, z), w + z, (z, z), z)}


def _change_point_steps(res, th0):
    """Steps within one step of a change point θ = kπ (on the grid when θ0 = π/4)."""
    th = th0 + 3 * TWO_PI * res.t
    near = np.abs((th + math.pi / 2) % math.pi - math.pi / 2) < 1.5 * 3 * TWO_PI * res.t[1]
    return near


def test_parallelogram_stays_on_its_branch(parallelogram_run):
    """Three turns through the six change points θ = kπ, where all four links are
    collinear and the parallelogram could turn into an antiparallelogram: it must stay on
    the branch it started on — coupler angle constant (0), rocker angle = crank angle,
    coupler origin at r e(θ) — at every step (``parallelogram_ref``, rel 1e-9).

    When a grid point lies exactly on a change point, Newton's iteration there converges
    only to ~√(tolerance) (the constraints are tangent at a bifurcation): at those steps
    the angles are within 1e-6 rad of the branch, and the run says so in a warning."""
    th0, res = parallelogram_run
    assert not isinstance(res, Exception), f"the run stopped: {res}"
    ref = parallelogram_ref(res.t, th0)
    on = _change_point_steps(res, th0) if th0 == PAR_CASES["grid_on_change_points"] \
        else np.zeros(len(res.t), dtype=bool)
    np.testing.assert_allclose(res["coupler.fi"][~on], 0.0, rtol=0, atol=1e-9)
    np.testing.assert_allclose(res["rocker.fi"][~on], res["crank.fi"][~on], rtol=0, atol=1e-9)
    np.testing.assert_allclose(res["coupler.fi"][on], 0.0, rtol=0, atol=1e-6)
    np.testing.assert_allclose(res["rocker.fi"][on], res["crank.fi"][on], rtol=0, atol=1e-6)
    sel = {k: v[~on] for k, v in positions_only(ref).items()}
    err = {k: float(np.max(np.abs(res[k][~on] - v)) / max(np.max(np.abs(v)), 1e-300))
           for k, v in sel.items() if np.max(np.abs(v)) > 0}
    assert max(err.values()) <= 1e-9, err
    if on.any():
        assert any("exactly at a singular position" in w for w in res.warnings), res.warnings


def test_parallelogram_rates_through_change_points(parallelogram_run):
    """On its branch the parallelogram's motion is smooth through the change points, so
    its velocities and accelerations are defined there too (the limits from either side):
    every rate at every step against ``parallelogram_ref`` (rel 1e-9). At a grid point
    exactly on a change point the constraints do not fix the rates: pam2exu interpolates
    them from the neighbouring steps (error O((ω dt)⁴) ≈ 1e-6 here) and warns; there, and
    one step either side (positions only to ~√tolerance next to it), rel 1e-5."""
    th0, res = parallelogram_run
    assert not isinstance(res, Exception), f"the run stopped: {res}"
    ref = rates_only(parallelogram_ref(res.t, th0))
    near = _change_point_steps(res, th0) if th0 == PAR_CASES["grid_on_change_points"] \
        else np.zeros(len(res.t), dtype=bool)
    scale = {"fi": 1.0, "x": PAR["r"], "y": PAR["r"]}
    w = 3 * TWO_PI
    for name, value in ref.items():
        var = name.split(".")[1]
        order = var.count("D")
        s = max(np.max(np.abs(value)), scale[var.lstrip("D")] * w**order)
        err = np.abs(res[name] - value) / s
        assert np.max(err[~near]) <= 1e-9, (name, np.max(err[~near]))
        assert np.max(err[near], initial=0.0) <= 1e-5, (name, np.max(err[near]))


@pytest.mark.parametrize("mode", [+1, -1], ids=["mode_plus", "mode_minus"])
def test_four_bar_started_near_its_dead_point_keeps_the_guessed_branch(mode):
    """The rocker-driven crank-rocker started 1e-5 rad inside its inner dead point,
    ψ(0) = ψ_i − 1e-5, the rocker moving away from it (ψ' = −1 rad/s, 0.6 s, not reaching
    the outer one). The two assembly modes (θ = atan2(B) ± acos(…), ``dyad``) are only
    0.018 rad apart; the guess is 60 % of the way from the chosen mode to the dead point
    (the midpoint), so still nearer the chosen one. Required: assembly on the guessed
    branch, then the whole run exact against ``rocker_driven`` in that mode (rel 1e-9)."""
    C = [rocker_limits()[1] - 1e-5, -1.0]
    t0 = np.zeros(1)
    zero = {"crank": (0, 0, 0.0), "coupler": (0, 0, 0.0)}
    this, other = rocker_driven(t0, C, mode, zero), rocker_driven(t0, C, -mode, zero)
    gap = {k: (other[f"{k}.fi"][0] - this[f"{k}.fi"][0] + math.pi) % TWO_PI - math.pi
           for k in ("crank", "coupler")}
    assert 0.01 < abs(gap["crank"]) < 0.03
    fi = {k: this[f"{k}.fi"][0] + 0.3 * gap[k] for k in gap}
    guess = {"crank": (0.0, 0.0, fi["crank"]),
             "coupler": (FB4["a"] * math.cos(fi["crank"]), FB4["a"] * math.sin(fi["crank"]),
                         fi["coupler"]),
             "rocker": (FB4["d"], 0.0, C[0])}
    res = pam2exu.run(four_bar_model(FB4["d"], guess, "rocker", C), analysis="kinematic",
                      t_end=0.6, steps=600)
    ref = rocker_driven(res.t, C, mode, guess)
    assert_matches(res, ref, L=0.4, w=1.0)


# ---- 4. poor initial guesses ---------------------------------------------------------------

def four_bar_pose(th, mode, d=FB4["d"]):
    """Closed-form pose at crank angle θ (the ``dyad`` A → O4 at t = 0):
    {solid: (x, y, fi)}; mode +1: coupler above the line A-O4 (open), −1: crossed."""
    t = np.zeros(1)
    ref = crank_driven(d, t, [th], mode, {"coupler": (0, 0, 0.0), "rocker": (0, 0, 0.0)})
    return {s: tuple(float(ref[f"{s}.{v}"][0]) for v in ("x", "y", "fi"))
            for s in ("crank", "coupler", "rocker")}


GUESS_TH0 = 1.0
LENGTH = {"crank": FB4["a"], "coupler": FB4["b"], "rocker": FB4["c"]}


@pytest.mark.parametrize("offset", [0.3, 0.5], ids=["0.3rad", "0.5rad"])
@pytest.mark.parametrize("signs", [(1, 1, 1), (1, -1, -1), (-1, 1, -1), (-1, -1, 1)],
                         ids=["+++", "+--", "-+-", "--+"])
@pytest.mark.parametrize("mode", [+1, -1], ids=["open", "crossed"])
def test_assembly_from_a_poor_guess_finds_the_nearest_mode(mode, signs, offset):
    """The crank-rocker at θ = 1 rad (motor), guess = the closed-form pose of one
    assembly mode (``four_bar_pose``) with every x, y moved by ±20 % of its solid's link
    length and every angle by ±0.3 or ±0.5 rad. The guess is checked (here) to be much
    nearer that mode than the other (distance in x, y and length × angle); the assembly
    must be that mode, to 1e-10 m and rad, on the guess's turn (no 2π jump)."""
    poses = {m: four_bar_pose(GUESS_TH0, m) for m in (+1, -1)}
    sx, sy, sf = signs
    guess = {s: (x + sx * 0.2 * LENGTH[s], y + sy * 0.2 * LENGTH[s], fi + sf * offset)
             for s, (x, y, fi) in poses[mode].items()}

    def distance(pose):
        return math.sqrt(sum((guess[s][0] - x)**2 + (guess[s][1] - y)**2
                             + (LENGTH[s] * ((guess[s][2] - fi + math.pi) % TWO_PI - math.pi))**2
                             for s, (x, y, fi) in pose.items()))

    assert distance(poses[mode]) < 0.3 * distance(poses[-mode])
    m = four_bar_model(FB4["d"], guess, "crank", [GUESS_TH0, TWO_PI])
    res = pam2exu.run(m, analysis="assembly")
    for s, pose in poses[mode].items():
        for v, value in zip(("x", "y", "fi"), pose):
            assert res[f"{s}.{v}"][0] == pytest.approx(value, abs=1e-10), f"{s}.{v}"


def test_four_bar_that_cannot_close_names_the_loop():
    """Ground d = 0.9 > a + b + c = 0.75: the loop cannot close at any crank angle. The
    assembly raises a SolverError at t = 0 whose message (and .elements) names the four
    revolutes of the loop, which cannot close — and neither the fixed link nor the motor,
    which can always hold (the crank can be put at any angle)."""
    guess = {"crank": (0.0, 0.0, GUESS_TH0), "coupler": (0.05, 0.08, 0.3),
             "rocker": (0.9, 0.0, 2.0)}
    with pytest.raises(pam2exu.SolverError) as info:
        pam2exu.run(four_bar_model(0.9, guess, "crank", [GUESS_TH0, TWO_PI]),
                    analysis="assembly")
    message = str(info.value)
    assert info.value.time == 0.0
    for joint in ("O2", "A", "B", "O4"):
        assert f"'{joint}'" in message
    named = {re.match(r"'([^']*)'", el).group(1) for el in info.value.elements}
    assert named == {"O2", "A", "B", "O4"}, info.value.elements
    assert "'motor'" not in message and "'base'" not in message, message


# ---- 5. long runs --------------------------------------------------------------------------

#: tracemalloc peak allowed for 100 turns in 100,000 steps: the result table is
#: 100,001 × 38 columns × 8 B = 30 MB, q, q', q'' another 3 × 9.6 MB, Exudyn's sensor
#: data 13 MB; the native pass adds one chunk (CHUNK_BYTES = 64 MB of Jacobian and the
#: solver's copy). Measured 210 MB (88 MB with 8 MB chunks). An unchunked pass — the
#: Jacobian of all steps at once, 100,001 × 13 × 12 × 8 B = 125 MB, and its copies —
#: would exceed it.
LONG_RUN_PEAK = 256 * 2**20
#: growth of the process's peak resident size (also counts Exudyn's C++ memory)
LONG_RUN_RSS = 512 * 2**20


@pytest.mark.long      # 24 s on natural, 8 s on Exudyn (2 cores)
def test_hundred_turns_in_100000_steps():
    """The example crank-rocker (a, b, c, d = 0.1, 0.35, 0.3, 0.4) turned 100 times at
    constant speed (θ = 200π t, 1 s) in 100,000 steps, kinematic. Required: crank.fi
    ends at 200π (never wrapped); the closed-loop constraints do not drift (max residual
    ≤ 1e-12 m; every column against ``crank_driven`` at every step, the last one
    included, rel 1e-9); memory bounded (``LONG_RUN_PEAK``, ``LONG_RUN_RSS``)."""
    guess = {"crank": (0.0, 0.0, 0.02), "coupler": (0.11, 0.01, 0.9),
             "rocker": (0.4, 0.0, 1.85)}
    C = [0.0, 100 * TWO_PI]
    model = four_bar_model(FB4["d"], guess, "crank", C)
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    tracemalloc.start()
    try:
        res = pam2exu.run(model, analysis="kinematic", t_end=1.0, steps=100_000)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    rss_growth = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024 - rss
    assert len(res) == 100_001
    assert res["crank.fi"][-1] == pytest.approx(200 * math.pi, rel=1e-14)
    assert res.info["max_residual"] <= 1e-12
    ref = crank_driven(FB4["d"], res.t, C, +1, guess)
    ref["motor.f(t)"], ref["motor.Df(t)"] = law_polynomial(res.t, C)[:2]
    assert_matches(res, ref, L=0.4, w=100 * TWO_PI)
    assert peak < LONG_RUN_PEAK, f"tracemalloc peak {peak / 2**20:.0f} MB"
    assert rss_growth < LONG_RUN_RSS, f"max RSS grew by {rss_growth / 2**20:.0f} MB"


# ---- 6. redundant and nearly redundant -----------------------------------------------------

def test_redundant_parallelogram_is_exact_and_warns():
    """tests/data/parallelogram5.toml (three parallel cranks r = 0.3, θ = π/2 + 1.2 cos 2πt):
    positions, velocities and accelerations exact (rel 1e-9), and one RedundancyWarning."""
    with pytest.warns(RedundancyWarning, match="redundant"):
        res = pam2exu.run(DATA / "parallelogram5.toml")
    t, w = res.t, TWO_PI
    th, dth, ddth = (np.pi / 2 + 1.2 * np.cos(w * t), -1.2 * w * np.sin(w * t),
                     -1.2 * w * w * np.cos(w * t))
    z = np.zeros_like(t)
    ref = {}
    for crank, x in (("crank1", 0.0), ("crank2", 1.0), ("crank3", 0.5)):
        ref.update(solid(crank, (z + x, z), th, (z, z), dth, (z, z), ddth))
    ref.update(solid("coupler", 0.3 * e(th), z, 0.3 * dth * n(th), z,
                     0.3 * ddth * n(th) - 0.3 * dth**2 * e(th), z))
    assert_matches(res, ref, L=1.0, w=1.2 * w)
    assert res.info["redundant_equations"] == 1 and len(res.warnings) == 1


def ill_conditioning_warning(res):
    """The warning text that says the results are ill-conditioned and reports a
    condition number, and that number; (None, None) when there is none."""
    for text in res.warnings:
        found = re.search(r"condition number\D{0,20}?(\d+(?:\.\d*)?(?:e[+-]?\d+)?)", text)
        if "ill-conditioned" in text and found:
            return text, float(found.group(1))
    return None, None


@pytest.mark.parametrize("offset", [1e-7, 1e-9, 1e-3], ids=["1e-7", "1e-9", "1e-3"])
def test_nearly_redundant_five_bar(offset):
    """parallelogram5 with crank3's ground pivot moved by ``offset`` along x: its fifth
    bar is no longer parallel, so, strictly, the bars cannot all close (a locked structure,
    off by ~offset) and the motor cannot turn it. Specified: a SolverError at t = 0 that
    says the constraints contradict each other, by how much (the self-stress component of
    the residual, of the order of the offset), and names the fifth bar, crank3, and its joints 'O3' and 'A3' as the ones that do not fit
    (the bar the file adds last; without it the parallelogram moves), in ``elements`` and
    in the message, and no other joint as such (issue 10: before, every joint was named)."""
    model = pam2exu.load(DATA / "parallelogram5.toml")
    model["ground"].points["O3"] = [0.5 + offset, 0.0]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(pam2exu.SolverError, match=r"contradict each other at t = 0 s"
                                                      ) as info:
            pam2exu.run(model)
    message = str(info.value)
    assert info.value.elements == ("'O3' (revolute)", "'A3' (revolute)")
    assert ("Without 'A3' the others agree: crank3, held by 'O3' and 'A3', is an extra bar "
            "that does not fit") in message
    if offset < 1e-6:          # first order in the offset: of its size
        size = float(re.search(r"disagree by ([0-9.e+-]+)", message).group(1))
        assert offset / 10 < size < 10 * offset
    assert info.value.time == 0.0


#: the crank-rocker with d = 0.55 − 1e-6: a + d = b + c − 1e-6, a hair from a change-point
#: (all four links collinear at θ = π); the smallest transmission angle is 3.5e-3 rad
NEAR_CP_D = 0.55 - 1e-6


@pytest.mark.parametrize("steps", [400, 401], ids=["grid_on_pi", "grid_off_pi"])
def test_four_bar_near_its_change_point(steps):
    """Crank-driven crank-rocker a = 0.1, b = 0.35, c = 0.3, d = 0.55 − 1e-6, one turn
    θ = 2π t from the open mode. At θ = π coupler and rocker are within 3.5e-3 rad of
    collinear (the constraint Jacobian is nearly singular) and the crossed mode is only
    3.2e-3 rad (coupler angle) away. Required: it stays on its branch (coupler and rocker
    angles within 1e-6 rad of ``crank_driven``, mode +1, at every step) and then either
    every column is exact (rel 1e-9) or the run warns that the results are ill-conditioned
    and reports the condition number (> 100). 400 steps put a grid point on θ = π, 401 do
    not."""
    C = [0.0, TWO_PI]
    guess = four_bar_pose(0.0, +1, NEAR_CP_D)
    guess = {s: (x, y, fi + 0.01) for s, (x, y, fi) in guess.items()}
    res = pam2exu.run(four_bar_model(NEAR_CP_D, guess, "crank", C), analysis="kinematic",
                      t_end=1.0, steps=steps)
    ref = crank_driven(NEAR_CP_D, res.t, C, +1, guess)
    at_pi = crank_driven(NEAR_CP_D, np.array([0.5]), C, +1, guess)
    mu = abs(math.sin(at_pi["coupler.fi"][0] - at_pi["rocker.fi"][0]))
    assert 3e-3 < mu < 4e-3                                          # nearly collinear
    for s in ("coupler", "rocker"):
        jump = float(np.max(np.abs(res[f"{s}.fi"] - ref[f"{s}.fi"])))
        assert jump <= 1e-6, f"{s}.fi left its branch by {jump:.3g} rad"
    err = errors(res, ref, L=0.55, w=TWO_PI)
    worst = max(err, key=err.get)
    if err[worst] > RTOL:
        text, number = ill_conditioning_warning(res)
        assert text is not None, (
            f"inexact ({worst}: {err[worst]:.3g}) and no warning that the results are "
            f"ill-conditioned with their condition number: {res.warnings}")
        assert number > 100


# ---- 7. stiff and soft springs (quasi_static) ----------------------------------------------

def stiff_pendulum(ratio):
    """A crank (m = 1.5, cog at L/2 = 0.1 on its x axis) hinged at the ground's origin,
    motor θ = 0.2 + 2 t, torsional spring ground → crank, C2 = k = ratio × m g L/2,
    C3 = −0.5 (so it is always wound). Statics of the crank (moments about O):
    Mz − Parell − m g (L/2) cos θ = 0 (the spring turns the crank clockwise by Parell =
    k (θ + 0.5)), forces: O = (0, m g); the massless ground: base = (0, m g),
    base.Mz = Mz − Parell = m g (L/2) cos θ (the weight's moment only, a 1e-6 part of Mz
    when ratio = 1e6)."""
    m_, L = 1.5, 0.2
    k = ratio * m_ * GRAV * L / 2
    model = pam2exu.Model("stiff-pendulum", gravity=GRAV)
    model.add_solid("ground", points={"O": [0.0, 0.0]})
    model.add_solid("crank", fi=0.25, mass=m_, inertia=0.01, cog=[L / 2, 0.0],
                    points={"O": [0.0, 0.0]})
    model.add("fixed", name="base", anc1="ground")
    model.add("revolute", name="O", anc1="ground.O", anc2="crank.O")
    model.add("angular_actuator", name="motor", anc1="ground", anc2="crank", C=[0.2, 2.0])
    model.add("torsional_spring", name="spring", anc1="ground", anc2="crank",
              C=[0.0, k, -0.5, 0.0])

    def reference(t):
        th = 0.2 + 2.0 * t
        parell = k * (th + 0.5)
        gravity = m_ * GRAV * L / 2 * np.cos(th)
        z = np.zeros_like(t)
        return {"spring.Parell": parell, "motor.Mz": parell + gravity, "O.Fx": z,
                "O.Fy": m_ * GRAV + z, "base.Fx": z, "base.Fy": m_ * GRAV + z,
                "base.Mz": gravity}
    return model, reference, L


def stiff_slider(ratio):
    """A slider (m = 0.8, cog (0.01, 0.02) off its line) on a rail through the ground's
    origin P at α = 0.5 rad, pushed by a linear actuator P → Q (Q the slider's origin, on
    the rail), s = |PQ| = 0.2 + 0.1 t, and pulled back by a spring P-Q, k = ratio × m g/L
    (L = 0.1), free length 0.1. Statics of the slider in the rail's basis (u along it,
    ν = u turned +90°): along u, Força − F − m g sin α = 0 (F = k (s − 0.1) attraction,
    Força repulsion); along ν, Fnormal = m g cos α; moments about Q (the actuator and the
    spring act along PQ, through Q): guide.Mz = m g (G − Q)_x, (G − Q) = R(α) cog; the
    massless ground: base = (0, m g), base.Mz = m g x_G."""
    m_, L, al = 0.8, 0.1, 0.5
    cog = np.array([0.01, 0.02])
    k = ratio * m_ * GRAV / L
    model = pam2exu.Model("stiff-slider", gravity=GRAV)
    model.add_solid("ground", points={"P": [0.0, 0.0]},
                    lines={"rail": {"point": [0.0, 0.0], "angle": al}})
    model.add_solid("slider", x=0.21 * math.cos(al), y=0.2 * math.sin(al), fi=al + 0.01,
                    mass=m_, inertia=1e-3, cog=list(cog), points={"Q": [0.0, 0.0]},
                    lines={"axis": {"point": [0.0, 0.0], "angle": 0.0}})
    model.add("fixed", name="base", anc1="ground")
    model.add("prismatic", name="guide", anc1="ground.rail", anc2="slider.axis")
    model.add("linear_actuator", name="cylinder", anc1="ground.P", anc2="slider.Q",
              C=[0.2, 0.1])
    model.add("spring", name="spring", anc1="ground.P", anc2="slider.Q", C=[0.0, k, 0.1, 0.0])
    GQ = rot(al, cog)

    def reference(t):
        s = 0.2 + 0.1 * t
        F = k * (s - 0.1)
        z = np.zeros_like(t)
        return {"spring.Força": F, "cylinder.Força": F + m_ * GRAV * math.sin(al),
                "guide.Fnormal": m_ * GRAV * math.cos(al) + z, "guide.Mz": m_ * GRAV * GQ[0] + z,
                "base.Fx": z, "base.Fy": m_ * GRAV + z,
                "base.Mz": m_ * GRAV * (s * math.cos(al) + GQ[0])}
    return model, reference, L


@pytest.mark.parametrize("ratio", [1e6, 1e-6], ids=["stiff", "soft"])
@pytest.mark.parametrize("build", [stiff_pendulum, stiff_slider], ids=["pendulum", "slider"])
def test_stiff_and_soft_springs_quasi_static(build, ratio):
    """Quasi-static equilibrium with a spring ``ratio`` times the gravity load (k L against
    m g): it converges, no warning, and every reaction, actuator force and spring force
    matches the statics by hand (``stiff_pendulum``, ``stiff_slider``). Tolerance per
    column: 1e-9 × its own scale, plus 8 ulps of the largest force (or moment) in the
    model — a weight that is 1e-6 of the spring force can only be resolved to round-off
    of the spring force."""
    model, reference, L = build(ratio)
    res = pam2exu.run(model, analysis="quasi_static", t_end=1.0, steps=100)
    assert res.warnings == []
    ref = reference(res.t)
    largest = {}
    for name, v in ref.items():
        kind = "moment" if name.endswith(("Mz", "Parell")) else "force"
        largest[kind] = max(largest.get(kind, 0.0), float(np.max(np.abs(v))))
    bad = {}
    for name, v in ref.items():
        kind = "moment" if name.endswith(("Mz", "Parell")) else "force"
        natural = GRAV * (L if kind == "moment" else 1.0)
        scale = max(float(np.max(np.abs(v))), natural)
        tol = RTOL * scale + 8 * np.finfo(float).eps * largest[kind]
        error = float(np.max(np.abs(res[name] - v)))
        if not error <= tol:
            bad[name] = f"{error:.3g} > {tol:.3g}"
    assert not bad, bad

"""Reactions, spring forces and actuator forces (quasi_static and kinetostatic) against
closed forms derived here, by hand.

Each mechanism is small enough that its statics (quasi_static) or inverse dynamics
(kinetostatic) is solved on paper: the positions, velocities and accelerations come from
the actuator's law (written again below, independently of pam2exu), then Newton-Euler on
each solid's free-body diagram gives every force. The derivation and the free-body
argument for the sign of each output are in each docstring. Nothing is taken from pam2exu
except the results under test. Sign conventions: docs/model-format.md, "Output variables":

- fixed: Fx, Fy, Mz = wrench the solid receives from the fixed link, at the solid's local
  origin, global basis (a fixed solid's weight goes into it);
- revolute: Fx, Fy = force solid 1 exerts on solid 2, global basis;
- prismatic: Fnormal, Mz = wrench solid 1 exerts on solid 2, at the defining point of
  solid 2's line, basis with x along solid 2's line in its own sense (Fnormal = the
  component along that direction turned by +90°);
- pin_slot: Fnormal = force the guide (solid 1) exerts on the pin (solid 2), basis with x
  along the guide (Fnormal = the component along the guide's direction turned by +90°);
- transmission: Parell = torque solid 2 receives; solid 1 receives −T·Parell and the arm
  (T − 1)·Parell, all pure torques;
- spring: Força = C1 + C2 (ro − C3) + C4 Dro, positive = attraction;
- torsional_spring: Parell = C1 + C2 (fi_rel − C3) + C4 Dfi_rel, fi_rel = fi2 − fi1,
  counter-clockwise on solid 1, clockwise on solid 2;
- angular_actuator: Mz = torque it exerts on solid 2 (−Mz on solid 1);
- linear_actuator: Força = force along PQ, positive = repulsion between P and Q.
quasi_static: equilibrium at each configuration, no inertia and no C4 (damper) terms;
kinetostatic: inertia (mass at G, inertia I_G about G) and the C4 terms included.

Notation: e(a) = (cos a, sin a), n(a) = e(a + π/2) = (−sin a, cos a), R(a) the rotation
by a, a × b = a_x b_y − a_y b_x (the z component), Ω d = d turned by +90°. For a
solid turning about a fixed point J with d = G − J: a_G = θ'' Ω d − θ'² d, and
Σ M_J = I_J θ'' with I_J = I_G + m |d|². For a translating solid (no rotation):
Σ M_D = (G − D) × m a_G about any point D. Gravity g along −y.

Every fixed-link wrench is derived twice, from the fixed solid's own free-body diagram
and from the whole mechanism (external wrench = rate of momentum and of angular momentum
about the fixed solid's origin); the test checks that the two references agree before
comparing with pam2exu.

Error measure: for each column, max |pam2exu − reference| / scale, with scale the
largest |reference| of that column, or, when the reference is identically ~0, the
mechanism's natural scale of that variable (a force F, a moment F·L, a length L, 1 rad).
"""
from __future__ import annotations

import math
import textwrap

import numpy as np
import pytest

import pam2exu

RTOL = 1e-9
GRAV = 9.81
ANALYSES = ["quasi_static", "kinetostatic"]


# ---- helpers (independent of pam2exu) -----------------------------------------------------

def law_polynomial(t, C):
    """f = C1 + C2 t + C3 t² + C4 t³, f' = C2 + 2 C3 t + 3 C4 t², f'' = 2 C3 + 6 C4 t."""
    c1, c2, c3, c4 = C
    return (c1 + c2 * t + c3 * t**2 + c4 * t**3, c2 + 2 * c3 * t + 3 * c4 * t**2,
            2 * c3 + 6 * c4 * t)


def e(a):
    return np.stack([np.cos(a), np.sin(a)])


def n(a):
    return np.stack([-np.sin(a), np.cos(a)])


def rot(a, v):
    """R(a) v for a local vector v = (vx, vy); a scalar or an array of angles."""
    return np.stack([np.cos(a) * v[0] - np.sin(a) * v[1], np.sin(a) * v[0] + np.cos(a) * v[1]])


def cross(a, b):
    """z component of a × b for planar vectors (first axis x, y)."""
    return a[0] * b[1] - a[1] * b[0]


def col(v):
    """A constant planar vector as a (2, 1) column, to broadcast against (2, k)."""
    return np.asarray(v, dtype=float).reshape(2, 1)


def toml(text):
    return pam2exu.loads(textwrap.dedent(text))


def errors(res, ref, F, L):
    """{column: max |res − ref| / scale} (see the module docstring for the scale)."""
    natural = {"Fx": F, "Fy": F, "Fnormal": F, "Força": F, "Mz": F * L, "Parell": F * L,
               "x": L, "y": L, "ro": L, "fi": 1.0, "fi_rel": 1.0}
    out = {}
    for name, value in ref.items():
        value = np.broadcast_to(np.asarray(value, dtype=float), res.t.shape)
        scale = float(np.max(np.abs(value)))
        fallback = natural.get(name.split(".", 1)[1], 1.0)
        if scale < 1e-9 * fallback:
            scale = fallback
        out[name] = float(np.max(np.abs(res[name] - value))) / scale
    return out


def assert_matches(res, ref, F, L, rtol=RTOL):
    err = errors(res, ref, F, L)
    bad = {k: v for k, v in err.items() if not v <= rtol}
    worst = max(err, key=err.get)
    assert not bad, f"relative errors above {rtol:g}: {bad} (worst {worst}: {err[worst]:.3g})"
    return err


def assert_closes(a, b, scale):
    """The two derivations of the same reference agree (a check of the test itself)."""
    np.testing.assert_allclose(a, b, rtol=0, atol=1e-12 * scale)


# ---- 1. pendulum: fixed, revolute, angular_actuator, torsional_spring (solid 2 = ground) ---

PEND = {"r0": (0.2, -0.1), "fi0": 0.4, "m0": 3.0, "c0": (0.15, -0.05), "J": (-0.1, 0.25),
        "m": 1.2, "IG": 0.004, "cg": (0.08, 0.03),
        "motor": (0.1, 0.5, 0.4, -0.3), "twist": (0.2, 1.5, -0.3, 0.05)}


def pendulum_model():
    p = PEND
    Jg = col(p["r0"]) + rot(p["fi0"], p["J"]).reshape(2, 1)
    return toml(f"""
        [model]
        name = "pendulum"
        gravity = {GRAV!r}

        [[solid]]
        name = "ground"
        x = {p['r0'][0]!r}
        y = {p['r0'][1]!r}
        fi = {p['fi0']!r}
        mass = {p['m0']!r}
        inertia = 0.5
        cog = {list(p['c0'])!r}
        points = {{ J = {list(p['J'])!r} }}

        [[solid]]
        name = "crank"
        x = {float(Jg[0, 0]) + 0.01!r}
        y = {float(Jg[1, 0]) - 0.01!r}
        fi = {p['fi0'] + p['motor'][0] + 0.05!r}
        mass = {p['m']!r}
        inertia = {p['IG']!r}
        cog = {list(p['cg'])!r}
        points = {{ O = [0.0, 0.0] }}

        [[element]]
        type = "fixed"
        name = "base"
        anc1 = "ground"

        [[element]]
        type = "revolute"
        name = "pivot"
        anc1 = "ground.J"
        anc2 = "crank.O"

        [[element]]
        type = "angular_actuator"
        name = "motor"
        anc1 = "ground"
        anc2 = "crank"
        law = "polynomial"
        C = {list(p['motor'])!r}

        [[element]]
        type = "torsional_spring"
        name = "twist"
        anc1 = "crank"
        anc2 = "ground"
        C = {list(p['twist'])!r}
        """)


@pytest.mark.parametrize("analysis", ANALYSES)
def test_pendulum_fixed_revolute_motor_torsional_spring(analysis):
    """Crank (m = 1.2, I_G = 0.004, G at cg = (0.08, 0.03) in its frame) hinged by its
    origin to the point J = (−0.1, 0.25) of a ground posed at r0 = (0.2, −0.1),
    fi0 = 0.4 (fixed link "base"), ground mass m0 = 3 at c0 = (0.15, −0.05). The motor
    ground → crank sets θ = fi0 + f(t), f = 0.1 + 0.5 t + 0.4 t² − 0.3 t³
    (θ from 0.5 to 1.1 rad). A torsional
    spring-damper crank → ground (solid 1 = the crank, so the reversed sense is checked):
    fi_rel = fi0 − θ = −f, Dfi_rel = −f', Parell_s = C1 + C2 (fi_rel − C3) + C4 Dfi_rel
    (no C4 term in quasi_static), counter-clockwise on the crank (solid 1), clockwise
    on the ground (solid 2).

    Crank (turns about the fixed point J, d = G − J = R(θ) cg):
        F (revolute: the ground on the crank, at J) + (0, −m g) = m a_G
            →  F = m a_G + (0, m g);
        about J: Mz + Parell_s + d × (0, −m g) = I_J θ''
            →  Mz = I_J θ'' + m g d_x − Parell_s.
    Signs: quasi-statically F = (0, m g) points up (the pivot holds the crank's
    weight); G is to the right of J (d_x > 0 over the interval), so the weight turns
    the crank clockwise and motor + spring must supply the counter-clockwise torque
    m g d_x.
    Ground (at rest; receives −F at J, −Mz from the motor, −Parell_s from the spring,
    its weight at G0 = r0 + R(fi0) c0, and the fixed-link wrench (Fb, Mb) at r0):
        Fb = F + (0, m0 g),  Mb = (J − r0) × F + Mz + Parell_s + m0 g (G0 − r0)_x.
    Whole mechanism (external: Fb, Mb and the two weights; the actuator's and the
    spring's torques are internal): Fb = m a_G + (0, (m + m0) g),
        Mb = I_G θ'' + (G − r0) × m a_G + m g (G − r0)_x + m0 g (G0 − r0)_x.
    So Fb_y > 0 (the base holds both weights up), and Mb ≠ 0 since the weights act away
    from the ground's origin.
    """
    p = PEND
    dyn = analysis == "kinetostatic"
    model = pendulum_model()
    res = pam2exu.run(model, analysis=analysis, t_end=1.0, steps=50)
    t = res.t
    f, df, ddf = law_polynomial(t, p["motor"])
    if not dyn:
        df, ddf = 0 * t, 0 * t                  # quasi_static: no rates, no inertia
    th, dth, ddth = p["fi0"] + f, df, ddf
    m, m0, g = p["m"], p["m0"], GRAV
    r0 = col(p["r0"])
    J = r0 + rot(p["fi0"], p["J"]).reshape(2, 1)
    G0 = r0 + rot(p["fi0"], p["c0"]).reshape(2, 1)
    d = rot(th, p["cg"])
    G = J + d
    aG = ddth * np.stack([-d[1], d[0]]) - dth**2 * d
    IJ = p["IG"] + m * (p["cg"][0] ** 2 + p["cg"][1] ** 2)
    c1, c2, c3, c4 = p["twist"]
    fi_rel, dfi_rel = p["fi0"] - th, -dth
    parell = c1 + c2 * (fi_rel - c3) + c4 * dfi_rel
    weight, weight0 = np.array([[0.0], [m * g]]), np.array([[0.0], [m0 * g]])

    F = m * aG + weight
    Mz = IJ * ddth + m * g * d[0] - parell
    Fb = F + weight0
    Mb = cross(J - r0, F) + Mz + parell + m0 * g * (G0 - r0)[0]
    # the whole mechanism gives the same base wrench
    assert_closes(Fb, m * aG + weight + weight0, (m + m0) * g)
    assert_closes(Mb, p["IG"] * ddth + cross(G - r0, m * aG) + m * g * (G - r0)[0]
                  + m0 * g * (G0 - r0)[0], (m + m0) * g * 0.3)
    assert np.all(d[0] > 0)                     # the sign argument above holds

    ref = {"crank.x": J[0] + 0 * t, "crank.y": J[1] + 0 * t, "crank.fi": th,
           "motor.f(t)": f, "twist.fi_rel": fi_rel,
           "pivot.Fx": F[0], "pivot.Fy": F[1], "motor.Mz": Mz, "twist.Parell": parell,
           "base.Fx": Fb[0], "base.Fy": Fb[1], "base.Mz": Mb}
    if dyn:
        ref.update({"crank.Dfi": dth, "crank.DDfi": ddth, "motor.Df(t)": df,
                    "twist.Dfi_rel": dfi_rel})
    assert_matches(res, ref, F=(m + m0) * g, L=0.3)


# ---- 2. slider on an inclined prismatic guide, pushed by a linear actuator -----------------

SLIDE = {"alpha": 0.5, "p1": (0.1, 0.05), "m": 2.0, "IG": 0.01, "cg": (0.01, 0.04),
         "D": (0.02, 0.0), "law": (0.2, 0.3, -0.4, 0.1)}


def slider_model():
    p = SLIDE
    S0 = np.array(p["p1"]) + p["law"][0] * np.array([math.cos(p["alpha"]),
                                                      math.sin(p["alpha"])])
    return toml(f"""
        [model]
        name = "inclined-slider"
        gravity = {GRAV!r}

        [[solid]]
        name = "ground"
        points = {{ P = {list(p['p1'])!r} }}
        lines = {{ rail = {{ point = {list(p['p1'])!r}, angle = {p['alpha']!r} }} }}

        [[solid]]
        name = "slider"
        x = {float(S0[0]) + 0.01!r}
        y = {float(S0[1]) - 0.005!r}
        fi = {p['alpha'] + 0.03!r}
        mass = {p['m']!r}
        inertia = {p['IG']!r}
        cog = {list(p['cg'])!r}
        points = {{ Q = [0.0, 0.0] }}
        lines = {{ axis = {{ point = {list(p['D'])!r}, angle = {math.pi!r} }} }}

        [[element]]
        type = "fixed"
        name = "base"
        anc1 = "ground"

        [[element]]
        type = "prismatic"
        name = "guide"
        anc1 = "ground.rail"
        anc2 = "slider.axis"

        [[element]]
        type = "linear_actuator"
        name = "jack"
        anc1 = "ground.P"
        anc2 = "slider.Q"
        law = "polynomial"
        C = {list(p['law'])!r}
        """)


@pytest.mark.parametrize("analysis", ANALYSES)
def test_inclined_slider_prismatic_linear_actuator(analysis):
    """Ground at the origin (fixed, massless), rail through p1 = (0.1, 0.05) at
    α = 0.5 rad. Slider (m = 2, I_G = 0.01, G at cg = (0.01, 0.04), off the line) with
    its line "axis" through its local D = (0.02, 0) at local angle π: the slider keeps
    fi = α (its x axis along the rail, the line pointing the other way, −e(α), which the
    prismatic keeps since the initial guess is near it). The linear actuator from P = p1
    (on the rail) to the slider's origin Q (on its line) sets s = |PQ| = f(t),
    f = 0.2 + 0.3 t − 0.4 t² + 0.1 t³ > 0, so Q = p1 + s e(α), D = Q + 0.02 e(α),
    G = Q + R(α) cg, a_G = s'' e(α) (none in quasi_static).

    Slider: the actuator pushes Q with Força e(α) (Q − P = s e(α), repulsion positive);
    the guide acts with N n(α) at D (no component along the line: frictionless) and a
    moment Mz; gravity (0, −m g) at G.
        along e(α):  Força − m g sin α = m s''  →  Força = m (s'' + g sin α) > 0 in
                     quasi_static: P is below Q on the rising rail, so the actuator must
                     push the slider up, away from P: repulsion.
        along n(α):  N − m g cos α = 0  →  N = m g cos α > 0: the guide holds the slider
                     up, along n(α). In the output basis (x along the slider's line,
                     −e(α), so y = −n(α)), Fnormal = −N = −m g cos α < 0.
        about D (translating solid; Força acts along the line through D, no moment):
                     Mz + w × (0, −m g) = w × m a_G, w = G − D
                     →  Mz = m g w_x + m s'' (w × e(α)).
    Fixed link (ground massless, origin O): from the ground's free-body diagram (it
    receives −N n(α) at D, −Mz, −Força e(α) at P) Fb = N n(α) + Força e(α),
    Mb = D × N n(α) + Mz + P × Força e(α); from the whole mechanism
    Fb = m a_G + (0, m g), Mb = m g G_x + G × m a_G.
    """
    p = SLIDE
    dyn = analysis == "kinetostatic"
    res = pam2exu.run(slider_model(), analysis=analysis, t_end=1.0, steps=50)
    t = res.t
    s, ds, dds = law_polynomial(t, p["law"])
    if not dyn:
        ds, dds = 0 * t, 0 * t
    a, m, g = p["alpha"], p["m"], GRAV
    ea, na = col(e(a)), col(n(a))
    P = col(p["p1"])
    Q = P + s * ea
    D = Q + p["D"][0] * ea
    G = Q + col(rot(a, p["cg"]))
    aG = dds * ea
    w = G - D

    jack = m * (dds + g * math.sin(a))
    N = m * g * math.cos(a) + 0 * t
    fnormal = -N                                # basis of the slider's line: y = −n(α)
    Mz = m * g * w[0] + m * dds * cross(w, ea)
    Fb = N * na + jack * ea
    Mb = cross(D, N * na) + Mz + cross(P, jack * ea)
    assert_closes(Fb, m * aG + np.array([[0.0], [m * g]]), m * g)
    assert_closes(Mb, m * g * G[0] + cross(G, m * aG), m * g * 0.3)
    assert np.all(s > 0)

    ref = {"slider.x": Q[0], "slider.y": Q[1], "slider.fi": a + 0 * t, "jack.f(t)": s,
           "jack.Força": jack, "guide.Fnormal": fnormal, "guide.Mz": Mz,
           "base.Fx": Fb[0], "base.Fy": Fb[1], "base.Mz": Mb}
    if dyn:
        ref.update({"slider.Dx": ds * ea[0], "slider.Dy": ds * ea[1], "slider.DDx": aG[0],
                    "slider.DDy": aG[1], "jack.Df(t)": ds})
    assert_matches(res, ref, F=m * g, L=0.3)


# ---- 3. Scotch yoke: pin_slot, prismatic, revolute, spring-damper ------------------------

YOKE = {"r": 0.05, "K": (-0.25, 0.0), "mc": 0.5, "Ic": 2.0e-4, "cgc": (0.02, 0.01),
        "my": 0.8, "Iy": 3.0e-3, "cgy": (0.03, 0.06), "motor": (0.2, 3.0, 1.0, 0.0),
        "spring": (3.0, 200.0, 0.2, 4.0)}


def yoke_model():
    p = YOKE
    th0 = p["motor"][0]
    return toml(f"""
        [model]
        name = "scotch-yoke"
        gravity = {GRAV!r}

        [[solid]]
        name = "ground"
        points = {{ O = [0.0, 0.0], K = {list(p['K'])!r} }}
        lines = {{ rail = {{ point = [0.0, 0.0], angle = 0.0 }} }}

        [[solid]]
        name = "crank"
        fi = {th0 + 0.02!r}
        mass = {p['mc']!r}
        inertia = {p['Ic']!r}
        cog = {list(p['cgc'])!r}
        points = {{ O = [0.0, 0.0], pin = [{p['r']!r}, 0.0] }}

        [[solid]]
        name = "yoke"
        x = {p['r'] * math.cos(th0) - 0.003!r}
        y = 0.002
        fi = 0.01
        mass = {p['my']!r}
        inertia = {p['Iy']!r}
        cog = {list(p['cgy'])!r}
        points = {{ Y = [0.0, 0.0] }}
        lines.axis = {{ point = [0.0, 0.0], angle = 0.0 }}
        lines.slot = {{ point = [0.0, 0.0], angle = {math.pi / 2!r} }}

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
        type = "prismatic"
        name = "guide"
        anc1 = "ground.rail"
        anc2 = "yoke.axis"

        [[element]]
        type = "pin_slot"
        name = "slot"
        anc1 = "yoke.slot"
        anc2 = "crank.pin"

        [[element]]
        type = "angular_actuator"
        name = "motor"
        anc1 = "ground"
        anc2 = "crank"
        law = "polynomial"
        C = {list(p['motor'])!r}

        [[element]]
        type = "spring"
        name = "spring"
        anc1 = "ground.K"
        anc2 = "yoke.Y"
        C = {list(p['spring'])!r}
        """)


@pytest.mark.parametrize("analysis", ANALYSES)
def test_scotch_yoke_pin_slot_spring(analysis):
    """Crank (m_c = 0.5, I_c = 2e-4, G_c at (0.02, 0.01)) hinged at the origin O of a
    fixed massless ground, pin Q = r e(θ), r = 0.05, θ = f(t) = 0.2 + 3 t + t² (past
    θ = π/2). The yoke (m_y = 0.8, I_y = 3e-3, G_y at (0.03, 0.06)) slides on the
    ground's x axis (prismatic, its line "axis" = its local x axis through its origin
    Y, fi = 0) and its vertical slot (line through Y at π/2) holds the pin (pin_slot,
    guide = the yoke). So Y = (x_Y, 0), x_Y = r cos θ, x_Y'' = −r cos θ θ'² −
    r sin θ θ''. A spring-damper from K = (−0.25, 0) to Y: ro = x_Y + 0.25,
    Dro = −r sin θ θ', Força = C1 + C2 (ro − C3) + C4 Dro (C4 term only in
    kinetostatic), attraction: on the yoke −Força e_x at Y.

    Pin force (the yoke on the pin) P = (P_x, 0), normal to the vertical slot.
    Yoke, along x:  −Força − P_x = m_y x_Y''  →  P_x = −Força − m_y x_Y''.
        The guide's direction is e(π/2) = (0, 1), its +90° normal (−1, 0), so
        slot.Fnormal = −P_x = Força + m_y x_Y''. Sign (quasi_static, Força > 0): the
        spring pulls the yoke to the left and the slot's wall drags the pin to the
        left, along the normal (−1, 0): Fnormal > 0.
    Yoke, along y:  N − m_y g = 0, N the rail's force on the yoke (the pin force and the
        spring are horizontal); the yoke's line is +x, so guide.Fnormal = N = m_y g > 0
        (the rail holds the yoke up).
    Yoke, about Y (translating; the spring acts along the line through Y; −P acts at
        the pin, Q − Y = (0, r sin θ)):
        Mz + (Q − Y) × (−P) + w × (0, −m_y g) = w × m_y a_Y, w = G_y − Y = (0.03, 0.06),
        →  guide.Mz = −r sin θ P_x + m_y g w_x − m_y w_y x_Y''.
    Crank, about O:  Mz + Q × P + G_c × (0, −m_c g) = I_O θ'', I_O = I_c + m_c |cg_c|²,
        Q × P = −r sin θ P_x  →  motor.Mz = I_O θ'' + r sin θ P_x + m_c g G_c,x.
    Crank, forces:   F_O + P + (0, −m_c g) = m_c a_Gc  →  O.F = m_c a_Gc − P + (0, m_c g).
    Fixed link: ground's free-body diagram (it receives −F_O at O, −N e_y at Y, −guide.Mz,
    +Força e_x at K, −motor.Mz): Fb = F_O + N e_y − Força e_x,
    Mb = x_Y N + guide.Mz + motor.Mz − K × Força e_x (K on the x axis: 0); whole
    mechanism: Fb = m_c a_Gc + m_y a_Y + (0, (m_c + m_y) g),
    Mb = I_c θ'' + G_c × m_c a_Gc + G_y × m_y a_Y + g (m_c G_c,x + m_y G_y,x).
    """
    p = YOKE
    dyn = analysis == "kinetostatic"
    res = pam2exu.run(yoke_model(), analysis=analysis, t_end=1.0, steps=50)
    t = res.t
    th, dth, ddth = law_polynomial(t, p["motor"])
    if not dyn:
        dth, ddth = 0 * t, 0 * t
    r, g, mc, my = p["r"], GRAV, p["mc"], p["my"]
    z = 0 * t
    xY = r * np.cos(th)
    dxY = -r * np.sin(th) * dth
    ddxY = -r * np.cos(th) * dth**2 - r * np.sin(th) * ddth
    Y = np.stack([xY, z])
    aY = np.stack([ddxY, z])
    Gy = Y + col(p["cgy"])
    dc = rot(th, p["cgc"])                      # G_c (O is the origin)
    aGc = ddth * np.stack([-dc[1], dc[0]]) - dth**2 * dc
    IO = p["Ic"] + mc * (p["cgc"][0] ** 2 + p["cgc"][1] ** 2)
    c1, c2, c3, c4 = p["spring"]
    ro, dro = xY - p["K"][0], dxY
    forca = c1 + c2 * (ro - c3) + c4 * dro

    Px = -forca - my * ddxY
    P = np.stack([Px, z])
    N = my * g + z
    wx, wy = p["cgy"]
    guide_Mz = -r * np.sin(th) * Px + my * g * wx - my * wy * ddxY
    motor_Mz = IO * ddth + r * np.sin(th) * Px + mc * g * dc[0]
    FO = mc * aGc - P + np.array([[0.0], [mc * g]])
    Fb = FO + np.stack([-forca, N])
    Mb = xY * N + guide_Mz + motor_Mz
    assert_closes(Fb, mc * aGc + my * aY + np.array([[0.0], [(mc + my) * g]]), (mc + my) * g)
    assert_closes(Mb, p["Ic"] * ddth + cross(dc, mc * aGc) + cross(Gy, my * aY)
                  + g * (mc * dc[0] + my * Gy[0]), (mc + my) * g * 0.1)
    assert np.all(forca > 0) and np.all(ro > 0)

    ref = {"crank.fi": th, "yoke.x": xY, "yoke.y": z, "yoke.fi": z, "motor.f(t)": th,
           "spring.ro": ro, "spring.Força": forca, "slot.Fnormal": -Px,
           "guide.Fnormal": N, "guide.Mz": guide_Mz, "motor.Mz": motor_Mz,
           "O.Fx": FO[0], "O.Fy": FO[1], "base.Fx": Fb[0], "base.Fy": Fb[1], "base.Mz": Mb}
    if dyn:
        ref.update({"yoke.Dx": dxY, "yoke.DDx": ddxY, "crank.DDfi": ddth, "spring.Dro": dro})
    assert_matches(res, ref, F=float(np.max(np.abs(forca))), L=0.1)


# ---- 4. gear pair on the ground: transmission, torsional spring, torsor ------------------

GEARS = {"G1": (0.1, 0.05), "G2": (0.2, 0.05), "m1": 0.6, "I1": 1.1e-3, "m2": 0.3,
         "I2": 2.4e-4, "T": -1.5, "C": 0.1, "M": 0.7, "motor": (0.0, 2.0, 3.0, -1.0),
         "twist": (0.1, 0.8, 0.2, 0.03)}


def gears_model():
    p = GEARS
    return toml(f"""
        [model]
        name = "gear-pair"
        gravity = {GRAV!r}

        [[solid]]
        name = "ground"
        points = {{ G1 = {list(p['G1'])!r}, G2 = {list(p['G2'])!r} }}

        [[solid]]
        name = "gear1"
        x = {p['G1'][0] + 0.002!r}
        y = {p['G1'][1]!r}
        fi = 0.02
        mass = {p['m1']!r}
        inertia = {p['I1']!r}
        points = {{ O = [0.0, 0.0] }}

        [[solid]]
        name = "gear2"
        x = {p['G2'][0]!r}
        y = {p['G2'][1] - 0.002!r}
        fi = {p['C'] - 0.03!r}
        mass = {p['m2']!r}
        inertia = {p['I2']!r}
        points = {{ O = [0.0, 0.0] }}

        [[element]]
        type = "fixed"
        name = "base"
        anc1 = "ground"

        [[element]]
        type = "revolute"
        name = "bearing1"
        anc1 = "ground.G1"
        anc2 = "gear1.O"

        [[element]]
        type = "revolute"
        name = "bearing2"
        anc1 = "ground.G2"
        anc2 = "gear2.O"

        [[element]]
        type = "transmission"
        name = "mesh"
        anc1 = "gear1"
        anc2 = "gear2"
        T = {p['T']!r}
        C = {p['C']!r}

        [[element]]
        type = "angular_actuator"
        name = "motor"
        anc1 = "ground"
        anc2 = "gear1"
        law = "polynomial"
        C = {list(p['motor'])!r}

        [[element]]
        type = "torsor"
        name = "load"
        anc1 = "gear2.O"
        C = [0.0, 0.0, {p['M']!r}]

        [[element]]
        type = "torsional_spring"
        name = "twist"
        anc1 = "ground"
        anc2 = "gear2"
        C = {list(p['twist'])!r}
        """)


@pytest.mark.parametrize("analysis", ANALYSES)
def test_gear_pair_transmission_torsional_spring(analysis):
    """Gear 1 (m1 = 0.6, I1 = 1.1e-3) and gear 2 (m2 = 0.3, I2 = 2.4e-4), G at their
    centres, hinged at G1 = (0.1, 0.05) and G2 = (0.2, 0.05) of a fixed massless ground at
    the origin, fi = 0, which is the arm of the transmission gear1 → gear2, T = −1.5,
    C = 0.1: θ2 = T θ1 + C. The motor ground → gear1 sets θ1 = f = 2 t + 3 t² − t³. On
    gear 2: a torsor M = 0.7 (counter-clockwise), and a torsional spring-damper
    ground → gear2: fi_rel = θ2, Parell_s = C1 + C2 (θ2 − C3) + C4 θ2' (C4 term only in
    kinetostatic), clockwise on gear 2 (solid 2), counter-clockwise on the ground.
    τ = mesh.Parell, on gear 2; −T τ on gear 1; (T − 1) τ on the ground (the arm).

    Gear 2, about its fixed centre:  τ + M − Parell_s = I2 θ2''
        →  τ = I2 θ2'' − M + Parell_s. Sign (quasi_static, spring unloaded): the load
        turns gear 2 counter-clockwise, so the mesh must hold it clockwise: τ = −M < 0.
    Gear 1:  Mz − T τ = I1 θ1''  →  motor.Mz = I1 θ1'' + T τ. With T < 0 and τ < 0 the
        motor drives counter-clockwise (Mz > 0): the mesh reverses the sense, so gear 1
        must be held counter-clockwise to hold gear 2 clockwise; power check:
        Mz θ1' = I1 θ1'' θ1' + τ θ2' (τ θ2' = (I2 θ2'' − M + Parell_s) θ2').
    Bearings (ground on gear, centres at rest, pure torques only in the mesh):
        bearing_i.F = (0, m_i g).
    Fixed link: ground's free-body diagram: Fb = (0, (m1 + m2) g),
        Mb = G1 × F1 + G2 × F2 + Mz − (T − 1) τ − Parell_s; whole mechanism (the
        internal torques cancel: Mz − Mz, τ − T τ + (T − 1) τ, Parell_s − Parell_s):
        Mb = I1 θ1'' + I2 θ2'' − M + g (m1 G1_x + m2 G2_x).
    """
    p = GEARS
    dyn = analysis == "kinetostatic"
    res = pam2exu.run(gears_model(), analysis=analysis, t_end=1.0, steps=50)
    t = res.t
    th1, dth1, ddth1 = law_polynomial(t, p["motor"])
    if not dyn:
        dth1, ddth1 = 0 * t, 0 * t
    T, C, M, g = p["T"], p["C"], p["M"], GRAV
    th2, dth2, ddth2 = T * th1 + C, T * dth1, T * ddth1
    c1, c2, c3, c4 = p["twist"]
    parell = c1 + c2 * (th2 - c3) + c4 * dth2
    tau = p["I2"] * ddth2 - M + parell
    Mz = p["I1"] * ddth1 + T * tau
    G1, G2 = col(p["G1"]), col(p["G2"])
    F1 = np.array([[0.0], [p["m1"] * g]]) + 0 * t
    F2 = np.array([[0.0], [p["m2"] * g]]) + 0 * t
    Fb = F1 + F2
    Mb = cross(G1, F1) + cross(G2, F2) + Mz - (T - 1) * tau - parell
    assert_closes(Mb, p["I1"] * ddth1 + p["I2"] * ddth2 - M
                  + g * (p["m1"] * G1[0, 0] + p["m2"] * G2[0, 0]), 1.0)

    ref = {"gear1.fi": th1, "gear2.fi": th2, "motor.f(t)": th1, "twist.fi_rel": th2,
           "twist.Parell": parell, "mesh.Parell": tau, "motor.Mz": Mz,
           "bearing1.Fx": F1[0], "bearing1.Fy": F1[1], "bearing2.Fx": F2[0],
           "bearing2.Fy": F2[1], "base.Fx": Fb[0], "base.Fy": Fb[1], "base.Mz": Mb}
    if dyn:
        ref.update({"gear2.Dfi": dth2, "gear2.DDfi": ddth2, "twist.Dfi_rel": dth2})
    assert_matches(res, ref, F=(p["m1"] + p["m2"]) * g, L=0.2)


def test_gear_pair_quasi_static_signs():
    """The signs argued in ``test_gear_pair_transmission_torsional_spring``, without the
    spring (C = 0) and at rest: the mesh holds gear 2 clockwise against the load,
    mesh.Parell = −M = −0.7; the motor holds gear 1 counter-clockwise,
    motor.Mz = T·Parell = (−1.5)(−0.7) = +1.05; the ground receives (T − 1)·Parell =
    +1.75 from the mesh and −Mz = −1.05 from the motor, so the base holds
    Mb = −0.7 + g (m1 G1_x + m2 G2_x) (= −M plus the weights' moments).
    """
    model = gears_model()
    model["twist"].C = [0.0, 0.0, 0.0, 0.0]
    res = pam2exu.run(model, analysis="quasi_static", t_end=1.0, steps=4)
    p = GEARS
    tol = 1e-9
    np.testing.assert_allclose(res["mesh.Parell"], -0.7, rtol=tol)
    np.testing.assert_allclose(res["motor.Mz"], 1.05, rtol=tol)
    np.testing.assert_allclose(res["base.Mz"], -0.7 + GRAV * (p["m1"] * p["G1"][0]
                                                            + p["m2"] * p["G2"][0]), rtol=tol)
    np.testing.assert_allclose(res["twist.Parell"], 0.0, atol=tol)


# ---- transmission with a moving arm (planetary train) ------------------------------------

def _planetary(R=0.09, T=-2.0, m=0.4, J=2e-4):
    """Sun and planet gears (T = −r_sun/r_planet) on an arm that turns about the sun's axis."""
    model = pam2exu.Model("planetary", gravity=0.0)
    model.add_solid("ground", points={"O": [0.0, 0.0]})
    model.add_solid("sun", points={"O": [0.0, 0.0]})
    model.add_solid("arm", points={"O": [0.0, 0.0], "P": [R, 0.0]})
    model.add_solid("planet", x=R, mass=m, inertia=J, points={"C": [0.0, 0.0]})
    model.add("fixed", name="base", anc1="ground")
    model.add("revolute", name="arm_bearing", anc1="ground.O", anc2="arm.O")
    model.add("revolute", name="sun_bearing", anc1="arm.O", anc2="sun.O")
    model.add("revolute", name="planet_bearing", anc1="arm.P", anc2="planet.C")
    model.add("transmission", name="mesh", anc1="sun", anc2="planet", T=T)
    model.add("angular_actuator", name="sun_drive", anc1="ground", anc2="sun",
              law="harmonic", C=[0.2, 0.8, 5.0, 0.3])
    model.add("angular_actuator", name="arm_drive", anc1="ground", anc2="arm",
              law="polynomial", C=[0.1, 1.5, 2.0, -0.7])
    model.add("torsor", name="load", anc1="planet.C", C=[0.0, 0.0, 0.35])
    return model


@pytest.mark.parametrize("analysis", ["quasi_static", "kinetostatic"])
def test_transmission_on_a_moving_arm(analysis):
    """Planetary train: the arm turns, so the mesh's reaction (T − 1)·Parell loads it.

    Free bodies (gravity off; sun and arm massless; planet mass m at its centre, inertia J;
    torsor moment M on the planet; θs, θa the laws, θp = θa + T (θs − θa)):
    - planet, moments about its centre (its bearing force passes through it):
      J θp'' = Parell + M, so Parell = J θp'' − M (quasi-static: −M);
    - planet, forces: m a_P = F, F = planet_bearing.(Fx, Fy) the force the arm exerts on
      it, a_P = R (θa'' n(θa) − θa'² e(θa));
    - sun, moments about O: sun_drive.Mz − T·Parell = 0 (its bearing passes no moment), so
      sun_drive.Mz = T·Parell: with M > 0 at rest, Parell = −M and the sun's motor pushes
      with −T·M = +2M, counter-clockwise, against the mesh;
    - arm, moments about O: arm_drive.Mz + (T − 1)·Parell − R e(θa) × F = 0 (the planet
      pushes back with −F at P).
    """
    R, T, m, J, M = 0.09, -2.0, 0.4, 2e-4, 0.35
    res = pam2exu.run(_planetary(R, T, m, J), analysis=analysis, t_end=1.0, steps=60)
    t = res.t
    ths = 0.2 + 0.8 * np.cos(5.0 * t + 0.3)
    dds = -0.8 * 25.0 * np.cos(5.0 * t + 0.3)
    tha = 0.1 + 1.5 * t + 2.0 * t**2 - 0.7 * t**3
    da, dda = 1.5 + 4.0 * t - 2.1 * t**2, 4.0 - 4.2 * t
    np.testing.assert_allclose(res["planet.fi"], tha + T * (ths - tha), atol=1e-12)
    dyn = analysis == "kinetostatic"
    ddp = dda + T * (dds - dda) if dyn else 0.0 * t
    e = np.column_stack([np.cos(tha), np.sin(tha)])
    n = np.column_stack([-np.sin(tha), np.cos(tha)])
    a_P = R * (dda[:, None] * n - (da**2)[:, None] * e) if dyn else 0.0 * e
    parell = J * ddp - M
    F = m * a_P
    expected = {
        "mesh.Parell": parell,
        "sun_drive.Mz": T * parell,
        "planet_bearing.Fx": F[:, 0], "planet_bearing.Fy": F[:, 1],
        "arm_drive.Mz": -(T - 1.0) * parell + R * (e[:, 0] * F[:, 1] - e[:, 1] * F[:, 0]),
        "sun_bearing.Fx": 0.0 * t, "sun_bearing.Fy": 0.0 * t,
    }
    for name, ref in expected.items():
        scale = max(np.max(np.abs(ref)), M)
        np.testing.assert_allclose(res[name], ref, rtol=0, atol=1e-9 * scale, err_msg=name)
    if not dyn:
        assert res["sun_drive.Mz"][0] == pytest.approx(2 * M, rel=1e-12)

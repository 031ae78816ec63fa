"""Reactions and actuator torques against a hand-written Newton–Euler solution.

The reference is written here, by hand, and takes nothing from pam2exu: each model is
built from the plain Python parameters below (as TOML text, read with ``pam2exu.loads``),
and the same parameters feed the reference. Only the result columns are compared.

Kinematics (closed form). An offset slider-crank on a fixed ground (possibly moved and
turned: pose g, γ), crank r, rod l, slider on a rail. Notation e(a) = (cos a, sin a),
n(a) = e(a + π/2), R(a) the rotation by a, a × b = a_x b_y − a_y b_x.

* crank: origin at the pivot O = g + R(γ) o, angle θ_g = γ + f(t) (motor: fi2 − fi1 = f).
* rod: origin A = O + r e(θ_g), angle φ; B = A + l e(φ).
* rail: through K = g + R(γ) k at angle β = γ + α_r, u = e(β), ν = n(β).
* slider: angle fi_s = β − α_s (+ π when its line is to point against the rail), its
  line's defining point P = K + s u, its origin P − R(fi_s) p, its pin
  B = P + R(fi_s)(b − p) = Q0 + s u with Q0 = K + R(fi_s)(b − p) (constant).
* loop O + r e(θ_g) + l e(φ) = Q0 + s u. With ψ = φ − β, τ = θ_g − β and
  c0 = (O − Q0)·ν: the ν component gives sin ψ = −(c0 + r sin τ)/l (branch cos ψ > 0),
  the u component s = (O − Q0)·u + r cos τ + l cos ψ. Differentiated (τ' = θ', ψ' = φ'):
      φ'  = −r cos τ θ' / (l cos ψ),
      φ'' = (r sin τ θ'² − r cos τ θ'' + l sin ψ φ'²) / (l cos ψ),
      s'  = −r sin τ θ' − l sin ψ φ',
      s'' = −r cos τ θ'² − r sin τ θ'' − l cos ψ φ'² − l sin ψ φ''.
* a point c (local) of a solid with origin q and angle a: p = q + R(a) c,
  p' = q' + a' n-turn(R c), p'' = q'' + a'' n-turn(R c) − a'² R c, which gives the centres
  of mass G and their velocities and accelerations.

Dynamics (Newton–Euler, 3 equations per body, moments about each body's own G):
    Σ F = m a_G,   Σ (P − G) × F + Σ M = J_G α,
for ground (a = 0), crank, rod, slider; 12 equations, linear in the 12 unknowns
    base.Fx, base.Fy, base.Mz   wrench the fixed link applies to the ground, at the
                                ground's origin g
    O.Fx, O.Fy                  force ground → crank at O (the ground gets the opposite)
    A.Fx, A.Fy                  force crank → rod at A
    B.Fx, B.Fy                  force rod → slider at B
    guide.Fnormal, guide.Mz     ground → slider: force Fnormal ν_s at P plus a couple Mz,
                                ν_s = slider's line direction turned by +90° (so
                                Fnormal is the y component in the basis with x along the
                                slider's line, Mz the moment about P); an ideal prismatic
                                transmits no force along the line
    motor.Mz                    torque on the crank (the ground gets −Mz)
with gravity m (0, −g) at each G (the ground's weight too) and the torsor on the rod
(F at its point T, couple M; F = (C1, C2) in global axes or R(φ)(C1, C2) in the rod's
axes). Assembled with numpy as a (steps + 1, 12, 12) system and solved at every step.
quasi_static: the same equations with every a_G and α set to zero.

The reference is checked by itself (no pam2exu): its kinematics against finite
differences, the power balance  motor power = d/dt (kinetic + potential energy) − torsor
power  (analytic and by finite differences of the energies), the whole system's momentum
balance (which holds only when every action/reaction pair has been put on both bodies with
opposite signs), and the quasi-static virtual power.

Error measure, as in test_kinematic_closed_form.py: per column, max |pam2exu − reference|
divided by the largest |reference| of that column (a column whose reference is ~0 uses
the largest |reference| of all reaction columns).
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import pam2exu
import test_kinematic_closed_form as kcf

RTOL = 1e-9
TWO_PI = 2.0 * math.pi
REACTIONS = ("motor.Mz", "O.Fx", "O.Fy", "A.Fx", "A.Fy", "B.Fx", "B.Fy",
             "guide.Fnormal", "guide.Mz", "base.Fx", "base.Fy", "base.Mz")


# ---- plane vector helpers ----------------------------------------------------------------

def e(a):
    return np.stack([np.cos(a), np.sin(a)])


def n(a):
    return np.stack([-np.sin(a), np.cos(a)])


def rot(a, s):
    """R(a) s, s a fixed local vector, a scalar or an array of angles → (2,) or (2, k)."""
    s = np.asarray(s, dtype=float)
    c, si = np.cos(a), np.sin(a)
    return np.stack([c * s[0] - si * s[1], si * s[0] + c * s[1]])


def turn(v):
    """v turned by +90°."""
    return np.stack([-v[1], v[0]])


def cross(a, b):
    return a[0] * b[1] - a[1] * b[0]


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1]


def col(v, k):
    """A constant vector (2,) as (2, k)."""
    return np.asarray(v, dtype=float)[:, None] + np.zeros(k)


def rigid_point(q, dq, ddq, a, da, dda, c):
    """Point c (local) of a solid with origin q and angle a, with its two time derivatives."""
    Rc = rot(a, c)
    return q + Rc, dq + da * turn(Rc), ddq + dda * turn(Rc) - da**2 * Rc


def law_polynomial(t, C):
    """f = C1 + C2 t + C3 t² + C4 t³, f' = C2 + 2 C3 t + 3 C4 t², f'' = 2 C3 + 6 C4 t."""
    c1, c2, c3, c4 = (tuple(C) + (0.0,) * 4)[:4]
    return (c1 + c2 * t + c3 * t**2 + c4 * t**3, c2 + 2 * c3 * t + 3 * c4 * t**2,
            2 * c3 + 6 * c4 * t + 0 * t)


#: the motor's laws: polynomial above, the transition laws written independently in
#: test_kinematic_closed_form.py (nothing from pam2exu)
MOTOR_LAWS = {"polynomial": law_polynomial, "ramp": kcf.law_ramp,
              "bezier_c1": kcf.law_bezier_c1, "bezier_c2": kcf.law_bezier_c2}


# ---- the mechanism -------------------------------------------------------------------------

def slider_crank_params(**over):
    """The slider-crank of the tests. Centres of mass off the origins and off the x axes,
    nonzero inertias, a heavy ground, a torsor on the rod, a motor that accelerates."""
    p = {
        "gravity": 9.81,
        "ground": {"pose": (0.0, 0.0, 0.0), "mass": 5.0, "inertia": 0.2, "cog": (0.15, -0.1),
                   "O": (0.0, 0.0), "rail_point": (0.0, 0.03), "rail_angle": 0.0},
        "crank": {"mass": 1.2, "inertia": 0.004, "cog": (0.04, 0.01), "r": 0.1},
        "rod": {"mass": 2.0, "inertia": 0.02, "cog": (0.12, -0.02), "l": 0.3, "T": (0.2, 0.03)},
        "slider": {"mass": 0.8, "inertia": 0.001, "cog": (0.01, 0.02), "B": (0.015, 0.01),
                   "axis_point": (-0.02, -0.005), "axis_angle": 0.0, "sense": +1},
        "torsor": {"C": (15.0, -25.0, 3.0), "axes": "global"},
        "motor": {"C": (0.3, 6.0, 2.0, 0.0)},
        "t_end": 1.0, "steps": 200,
    }
    for key, value in over.items():
        if isinstance(value, dict):
            p[key] = {**p[key], **value}
        else:
            p[key] = value
    return p


def kinematics(p, t):
    """Closed-form positions, velocities, accelerations (module docstring)."""
    k = len(t)
    gx, gy, gam = p["ground"]["pose"]
    g0 = np.array([gx, gy])
    r, l = p["crank"]["r"], p["rod"]["l"]
    sl = p["slider"]
    law = MOTOR_LAWS[p["motor"].get("law", "polynomial")]
    th, dth, ddth = law(t, (tuple(p["motor"]["C"]) + (0.0,) * 4)[:4])
    thg = gam + th
    O = g0 + rot(gam, p["ground"]["O"])
    K = g0 + rot(gam, p["ground"]["rail_point"])
    beta = gam + p["ground"]["rail_angle"]
    u, nu = e(beta), n(beta)
    fi_s = beta - sl["axis_angle"] + (0.0 if sl["sense"] > 0 else math.pi)
    Q0 = K + rot(fi_s, np.subtract(sl["B"], sl["axis_point"]))
    c0 = dot(O - Q0, nu)
    tau = thg - beta
    psi = np.arcsin(-(c0 + r * np.sin(tau)) / l)
    phi = beta + psi
    dphi = -r * np.cos(tau) * dth / (l * np.cos(psi))
    ddphi = (r * np.sin(tau) * dth**2 - r * np.cos(tau) * ddth
             + l * np.sin(psi) * dphi**2) / (l * np.cos(psi))
    s = dot(O - Q0, u) + r * np.cos(tau) + l * np.cos(psi)
    ds = -r * np.sin(tau) * dth - l * np.sin(psi) * dphi
    dds = (-r * np.cos(tau) * dth**2 - r * np.sin(tau) * ddth
           - l * np.cos(psi) * dphi**2 - l * np.sin(psi) * ddphi)
    z = np.zeros(k)
    Z = np.zeros((2, k))
    Ok = col(O, k)
    A = rigid_point(Ok, Z, Z, thg, dth, ddth, (r, 0.0))
    P = (col(K, k) + s * u[:, None], ds * u[:, None], dds * u[:, None])
    slider_origin = (P[0] - col(rot(fi_s, sl["axis_point"]), k), P[1], P[2])
    bodies = {
        "ground": {"q": (col(g0, k), Z, Z), "fi": (gam + z, z, z)},
        "crank": {"q": (Ok, Z, Z), "fi": (thg, dth, ddth)},
        "rod": {"q": A, "fi": (phi, dphi, ddphi)},
        "slider": {"q": slider_origin, "fi": (fi_s + z, z, z)},
    }
    for name, b in bodies.items():
        b["G"] = rigid_point(*b["q"], *b["fi"], p[name]["cog"])
    pts = {"O": Ok, "A": A[0], "B": rigid_point(*A, phi, dphi, ddphi, (l, 0.0))[0], "P": P[0],
               "T": rigid_point(*A, phi, dphi, ddphi, p["rod"]["T"]),
               "nu_s": col(n(fi_s + sl["axis_angle"]), k), "g0": col(g0, k),
               "B_slider": rigid_point(*slider_origin, fi_s + z, z, z, sl["B"])[0]}
    return bodies, pts, (th, dth, ddth)


def torsor_load(p, bodies, k):
    """Torsor on the rod: global force (2, k) and couple (k,)."""
    C = np.array(p["torsor"]["C"], dtype=float)
    if p["torsor"]["axes"] == "solid":
        F = rot(bodies["rod"]["fi"][0], C[:2])
    else:
        F = col(C[:2], k)
    return F, C[2] + np.zeros(k)


def newton_euler(p, t, static=False):
    """Solve the 12 Newton–Euler equations at every time; {column: reference}."""
    k = len(t)
    bodies, pts, _ = kinematics(p, t)
    order = ("ground", "crank", "rod", "slider")
    row = {name: 3 * i for i, name in enumerate(order)}
    unknowns = list(REACTIONS)
    M = np.zeros((k, 12, 12))
    rhs = np.zeros((k, 12))
    G = {name: bodies[name]["G"][0] for name in order}

    def force(j, body, F, at):
        """Unit unknown j puts force F (2, k) at point `at` (2, k) on body."""
        i = row[body]
        M[:, i, j] += F[0]
        M[:, i + 1, j] += F[1]
        M[:, i + 2, j] += cross(at - G[body], F)

    def couple(j, body, value):
        M[:, row[body] + 2, j] += value

    ex, ey = col((1.0, 0.0), k), col((0.0, 1.0), k)
    j = unknowns.index
    # fixed link → ground, at the ground's origin
    force(j("base.Fx"), "ground", ex, pts["g0"])
    force(j("base.Fy"), "ground", ey, pts["g0"])
    couple(j("base.Mz"), "ground", 1.0)
    # revolute joints: + on solid 2, − on solid 1, at the joint
    for name, s1, s2, at in (("O", "ground", "crank", pts["O"]), ("A", "crank", "rod", pts["A"]),
                             ("B", "rod", "slider", pts["B"])):
        for comp, unit in (("Fx", ex), ("Fy", ey)):
            force(j(f"{name}.{comp}"), s2, unit, at)
            force(j(f"{name}.{comp}"), s1, -unit, at)
    # prismatic: ground → slider, normal force at P and couple
    force(j("guide.Fnormal"), "slider", pts["nu_s"], pts["P"])
    force(j("guide.Fnormal"), "ground", -pts["nu_s"], pts["P"])
    couple(j("guide.Mz"), "slider", 1.0)
    couple(j("guide.Mz"), "ground", -1.0)
    # motor: + on the crank, − on the ground
    couple(j("motor.Mz"), "crank", 1.0)
    couple(j("motor.Mz"), "ground", -1.0)

    # right-hand side: m a_G − known forces, J α − known moments about G
    grav = np.array([0.0, -p["gravity"]])
    Ft, Mt = torsor_load(p, bodies, k)
    for name in order:
        i, m, J = row[name], p[name]["mass"], p[name]["inertia"]
        aG = np.zeros((2, k)) if static else bodies[name]["G"][2]
        alpha = np.zeros(k) if static else bodies[name]["fi"][2]
        rhs[:, i] = m * aG[0] - m * grav[0]
        rhs[:, i + 1] = m * aG[1] - m * grav[1]
        rhs[:, i + 2] = J * alpha
    i = row["rod"]
    rhs[:, i] -= Ft[0]
    rhs[:, i + 1] -= Ft[1]
    rhs[:, i + 2] -= cross(pts["T"][0] - G["rod"], Ft) + Mt
    assert np.max(np.linalg.cond(M)) < 1e8
    x = np.linalg.solve(M, rhs[..., None])[..., 0]
    return {name: x[:, i] for i, name in enumerate(unknowns)}


# ---- the model as TOML, from the same parameters ------------------------------------------

def fmt(v):
    if isinstance(v, (tuple, list, np.ndarray)):
        return "[" + ", ".join(fmt(x) for x in v) + "]"
    return repr(float(v))


def model_toml(p, analysis):
    """The TOML model; initial guesses are the exact configuration at t = 0."""
    bodies, _, _ = kinematics(p, np.array([0.0]))
    gr, cr, rd, sl = p["ground"], p["crank"], p["rod"], p["slider"]

    def pose(name):
        q, fi = bodies[name]["q"][0][:, 0], bodies[name]["fi"][0][0]
        return f"x = {fmt(q[0])}\ny = {fmt(q[1])}\nfi = {fmt(fi)}"

    def inertial(name):
        b = p[name]
        return f"mass = {fmt(b['mass'])}\ninertia = {fmt(b['inertia'])}\ncog = {fmt(b['cog'])}"

    return f"""
[model]
name = "newton-euler slider-crank"
gravity = {fmt(p['gravity'])}

[[solid]]
name = "ground"
{pose('ground')}
{inertial('ground')}
points = {{ O = {fmt(gr['O'])} }}
lines = {{ rail = {{ point = {fmt(gr['rail_point'])}, angle = {fmt(gr['rail_angle'])} }} }}

[[solid]]
name = "crank"
{pose('crank')}
{inertial('crank')}
points = {{ O = [0.0, 0.0], A = {fmt((cr['r'], 0.0))} }}

[[solid]]
name = "rod"
{pose('rod')}
{inertial('rod')}
points = {{ A = [0.0, 0.0], B = {fmt((rd['l'], 0.0))}, T = {fmt(rd['T'])} }}

[[solid]]
name = "slider"
{pose('slider')}
{inertial('slider')}
points = {{ B = {fmt(sl['B'])} }}
lines = {{ axis = {{ point = {fmt(sl['axis_point'])}, angle = {fmt(sl['axis_angle'])} }} }}

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
law = "{p['motor'].get('law', 'polynomial')}"
C = {fmt(p['motor']['C'])}

[[element]]
type = "torsor"
name = "load"
anc1 = "rod.T"
C = {fmt(p['torsor']['C'])}
axes = "{p['torsor']['axes']}"

[analysis]
type = "{analysis}"
t_end = {fmt(p['t_end'])}
steps = {int(p['steps'])}
"""


# ---- comparison ------------------------------------------------------------------------------

def errors(res, ref):
    """{column: max |res − ref| / scale} (scale: module docstring)."""
    floor = max(float(np.max(np.abs(ref[c]))) for c in ref)
    out = {}
    for name, value in ref.items():
        value = np.broadcast_to(np.asarray(value, dtype=float), res.t.shape)
        scale = float(np.max(np.abs(value)))
        if scale < 1e-9 * floor:
            scale = floor
        out[name] = float(np.max(np.abs(res[name] - value))) / scale
    return out


def assert_matches(res, ref, rtol=RTOL):
    err = errors(res, ref)
    bad = {c: f"{v:.3g}" for c, v in err.items() if not v <= rtol}
    worst = max(err, key=err.get)
    assert not bad, f"relative errors above {rtol:g}: {bad} (worst {worst}: {err[worst]:.3g})"
    return err


def kinematic_ref(p, t, with_rates):
    """Solid columns from the closed form (positions only when not with_rates)."""
    bodies, _, _ = kinematics(p, t)
    out = {}
    for name, b in bodies.items():
        (q, dq, ddq), (fi, dfi, ddfi) = b["q"], b["fi"]
        out.update({f"{name}.x": q[0], f"{name}.y": q[1], f"{name}.fi": fi})
        if with_rates:
            out.update({f"{name}.Dx": dq[0], f"{name}.Dy": dq[1], f"{name}.Dfi": dfi,
                        f"{name}.DDx": ddq[0], f"{name}.DDy": ddq[1], f"{name}.DDfi": ddfi})
    return out


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

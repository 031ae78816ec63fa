"""The offset slider-crank of the Newton–Euler tests: closed-form kinematics and a hand-written
Newton–Euler solution of its reactions and motor torque, from plain Python parameters.

``slider_crank_params`` gives the parameters (override any group: ``ground={"pose": …}``);
``model_toml`` writes the same mechanism as a pam2exu model (TOML text, for
``pam2exu.loads``); ``kinematics`` and ``kinematic_ref`` give the closed-form motion,
``newton_euler`` the reactions. Nothing is taken from pam2exu.

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

Error measure (``errors``): per column, max |pam2exu − reference| divided by the largest
|reference| of that column (a column whose reference is ~0 uses the largest |reference| of
all reaction columns).
"""
from __future__ import annotations

import math

import numpy as np

from .closed_form import e, n
from .laws import law_bezier_c1, law_bezier_c2, law_ramp

REACTIONS = ("motor.Mz", "O.Fx", "O.Fy", "A.Fx", "A.Fy", "B.Fx", "B.Fy",
             "guide.Fnormal", "guide.Mz", "base.Fx", "base.Fy", "base.Mz")


# ---- plane vector helpers (e, n: references.closed_form) ---------------------------------

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


#: the motor's laws: polynomial above, the transition laws of references.laws (nothing from
#: pam2exu)
MOTOR_LAWS = {"polynomial": law_polynomial, "ramp": law_ramp,
              "bezier_c1": law_bezier_c1, "bezier_c2": law_bezier_c2}


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

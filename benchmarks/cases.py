"""The benchmark's mechanisms, each with its references (nothing from pam2exu).

Each ``*_case`` returns a pam2exu model, a function ``reference(t)`` giving
({kinematic column: array}, {reaction column: array} or None) at the times t (the
four-bar's also ``reference(t, forces=False)``: the kinematics alone), and the
natural scales L [m] and w [rad/s] of the error measure (``references.closed_form.errors``).

- ``four_bar_case``: examples/four_bar.toml; kinematics ``four_bar``, reactions
  ``revolute_newton_euler`` (references/).
- ``slider_crank_case``: the Newton–Euler slider-crank of references/slider_crank.py.
- ``parallelogram_case``: tests/data/parallelogram5.toml (redundant), kinematics only.
- ``chain_model``, ``chain_reference``: a chain of N four-bar loops driven by one motor,
  its closed form loop by loop and its reactions.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

import pam2exu
from references import slider_crank
from references.closed_form import FOUR_BAR, e, four_bar, n, solid, still
from references.laws import actuator_law
from references.revolute import body, revolute_newton_euler

ROOT = Path(__file__).resolve().parents[1]
TWO_PI = 2.0 * math.pi


def still_body(x, y, k):
    z = np.zeros(k)
    return ((np.stack([x + z, y + z]), np.zeros((2, k)), np.zeros((2, k))), (z, z, z))


def solid_columns(name, origin, fi):
    return solid(name, origin[0], fi[0], origin[1], fi[1], origin[2], fi[2])


def four_bar_case(t_end=1.0, C=None):
    """examples/four_bar.toml (optionally another polynomial law) and its references."""
    model = pam2exu.load(ROOT / "examples" / "four_bar.toml")
    if C is not None:
        model["motor"].C = list(C)

    def reference(t, forces=True):
        a, b, c, d = (FOUR_BAR[key] for key in "abcd")
        th, dth, ddth = actuator_law(model, "motor", t)
        (phi, dphi, ddphi), (psi, dpsi, ddpsi) = four_bar(a, b, c, d, th, dth, ddth)
        k = len(t)
        z = np.zeros(k)
        Z = np.zeros((2, k))
        origin = {"ground": (Z, Z, Z), "crank": (Z, Z, Z),
                  "coupler": (a * e(th), a * dth * n(th),
                              a * ddth * n(th) - a * dth**2 * e(th)),
                  "rocker": (np.stack([d + z, z]), Z, Z)}
        angle = {"ground": (z, z, z), "crank": (th, dth, ddth), "coupler": (phi, dphi, ddphi),
                 "rocker": (psi, dpsi, ddpsi)}
        kin = {}
        bodies = {}
        for name, r in origin.items():
            kin.update(solid_columns(name, r, angle[name]))
            if not forces:
                continue
            s = model[name]
            bodies[name] = body(float(s.mass), float(s.inertia), [float(v) for v in s.cog],
                                r, angle[name])
        if not forces:
            return kin, None
        A = origin["coupler"][0]
        B = A + b * e(phi)
        links = [("fixed", "base", "ground"),
                 ("revolute", "O2", "ground", "crank", Z),
                 ("revolute", "A", "crank", "coupler", A),
                 ("revolute", "B", "coupler", "rocker", B),
                 ("revolute", "O4", "ground", "rocker", origin["rocker"][0]),
                 ("motor", "motor", "ground", "crank")]
        forces = revolute_newton_euler(bodies, links, float(model.gravity))
        return kin, forces
    w = float(np.max(np.abs(actuator_law(model, "motor", np.linspace(0, t_end, 101))[1])))
    return model, reference, 0.4, w


def slider_crank_case(**over):
    """The Newton–Euler slider-crank of test_newton_euler (offset pin, centres of mass off
    the axes, gravity, a torsor on the rod, an accelerating motor) and its references."""
    p = slider_crank.slider_crank_params(**over)
    model = pam2exu.loads(slider_crank.model_toml(p, "kinematic"))

    def reference(t):
        return slider_crank.kinematic_ref(p, t, with_rates=True), slider_crank.newton_euler(p, t)
    th = slider_crank.law_polynomial(np.linspace(0, p["t_end"], 101), p["motor"]["C"])
    return model, reference, 0.4, float(np.max(np.abs(th[1]))), p


def parallelogram_case():
    """tests/data/parallelogram5.toml: three parallel cranks 0.3 at x = 0, 0.5, 1 turned by
    θ = π/2 + 1.2 cos 2πt; the coupler translates, its origin A1 = 0.3 e(θ), fi = 0."""
    model = pam2exu.load(ROOT / "tests" / "data" / "parallelogram5.toml")

    def reference(t):
        th, dth, ddth = actuator_law(model, "motor", t)
        k = len(t)
        z = np.zeros(k)
        Z = np.zeros((2, k))
        r = 0.3
        kin = {**still("ground", 0.0, 0.0, 0.0, k),
               **solid_columns("coupler", (r * e(th), r * dth * n(th),
                                           r * ddth * n(th) - r * dth**2 * e(th)),
                               (z, z, z))}
        for name, x in (("crank1", 0.0), ("crank2", 1.0), ("crank3", 0.5)):
            kin.update(solid_columns(name, (np.stack([x + z, z]), Z, Z), (th, dth, ddth)))
        return kin, None
    return model, reference, 1.0, 1.2 * TWO_PI


# ---- the chain of four-bar loops ---------------------------------------------------------------

#: each loop: input link a, coupler b, output link c, ground d (the shortest: a drag link,
#: Grashof, both links turn fully); the shared link carries the next loop's input point at
#: −a (opposite its output point), which keeps the speed ratio of the whole chain bounded
CHAIN = {"a": 0.3, "b": 0.32, "c": 0.3, "d": 0.1}
LINK = {"mass": 0.4, "inertia": 0.012, "cog": (0.01, 0.005)}
COUPLER = {"mass": 0.3, "inertia": 0.0026, "cog": (0.16, 0.01)}
CHAIN_LAW = (0.3, TWO_PI)                        # θ = 0.3 + 2π t


def chain_kinematics(N, t):
    """Closed form of the chain, loop by loop (``four_bar`` of the tests, shifted by j·d):
    link i pivots at P_i = (i d, 0); loop j turns link j−1 (input point at angle
    fi_{j−1} + α, α = 0 for the crank, π after) and link j (output point at angle fi_j).
    Returns ({solid: (origin, angle)}, {joint: point}) with rates."""
    a, b, c, d = (CHAIN[key] for key in "abcd")
    k = len(t)
    z = np.zeros(k)
    Z = np.zeros((2, k))
    th = (CHAIN_LAW[0] + CHAIN_LAW[1] * t, CHAIN_LAW[1] + z, z)
    solids = {"L0": ((Z, Z, Z), th)}
    joints = {"O0": Z}
    for j in range(1, N + 1):
        alpha = 0.0 if j == 1 else math.pi
        fi_in, dfi_in, ddfi_in = solids[f"L{j - 1}"][1]
        ti = fi_in + alpha
        (phi, dphi, ddphi), (psi, dpsi, ddpsi) = four_bar(a, b, c, d, ti, dfi_in, ddfi_in)
        P = np.stack([(j - 1) * d + z, z])
        A = (P + a * e(ti), a * dfi_in * n(ti),
             a * ddfi_in * n(ti) - a * dfi_in**2 * e(ti))
        solids[f"K{j}"] = (A, (phi, dphi, ddphi))
        solids[f"L{j}"] = ((np.stack([j * d + z, z]), Z, Z), (psi, dpsi, ddpsi))
        joints[f"A{j}"] = A[0]
        joints[f"B{j}"] = A[0] + b * e(phi)
        joints[f"O{j}"] = np.stack([j * d + z, z])
    return solids, joints


def chain_model(N):
    """N loops, assembled exactly at t = 0 from ``chain_kinematics`` (initial guesses)."""
    a, b, c, d = (CHAIN[key] for key in "abcd")
    solids, _ = chain_kinematics(N, np.zeros(1))
    m = pam2exu.Model(f"chain of {N} four-bar loops", gravity=9.81)
    m.add_solid("ground", points={f"P{i}": [i * d, 0.0] for i in range(N + 1)})
    m.add("fixed", name="base", anc1="ground")
    for i in range(N + 1):
        (r, _, _), (fi, _, _) = solids[f"L{i}"]
        points = {"O": [0.0, 0.0]}
        if i < N:
            points["A"] = [a, 0.0] if i == 0 else [-a, 0.0]
        if i > 0:
            points["B"] = [c, 0.0]
        m.add_solid(f"L{i}", x=float(r[0, 0]), y=float(r[1, 0]), fi=float(fi[0]),
                    points=points, **LINK)
        m.add("revolute", name=f"O{i}", anc1=f"ground.P{i}", anc2=f"L{i}.O")
    for j in range(1, N + 1):
        (r, _, _), (fi, _, _) = solids[f"K{j}"]
        m.add_solid(f"K{j}", x=float(r[0, 0]), y=float(r[1, 0]), fi=float(fi[0]),
                    points={"A": [0.0, 0.0], "B": [b, 0.0]}, **COUPLER)
        m.add("revolute", name=f"A{j}", anc1=f"L{j - 1}.A", anc2=f"K{j}.A")
        m.add("revolute", name=f"B{j}", anc1=f"K{j}.B", anc2=f"L{j}.B")
    m.add("angular_actuator", name="motor", anc1="ground", anc2="L0", law="polynomial",
          C=[CHAIN_LAW[0], CHAIN_LAW[1], 0.0, 0.0])
    return m


def chain_reference(N, t):
    solids, joints = chain_kinematics(N, t)
    k = len(t)
    kin = dict(still("ground", 0.0, 0.0, 0.0, k))
    bodies = {"ground": body(0.0, 0.0, (0.0, 0.0), *still_body(0.0, 0.0, k))}
    for name, (origin, angle) in solids.items():
        kin.update(solid_columns(name, origin, angle))
        inertial = LINK if name.startswith("L") else COUPLER
        bodies[name] = body(inertial["mass"], inertial["inertia"], inertial["cog"], origin, angle)
    links = [("fixed", "base", "ground")]
    for i in range(N + 1):
        links.append(("revolute", f"O{i}", "ground", f"L{i}", joints[f"O{i}"]))
    for j in range(1, N + 1):
        links.append(("revolute", f"A{j}", f"L{j - 1}", f"K{j}", joints[f"A{j}"]))
        links.append(("revolute", f"B{j}", f"K{j}", f"L{j}", joints[f"B{j}"]))
    links.append(("motor", "motor", "ground", "L0"))
    return kin, revolute_newton_euler(bodies, links, 9.81)

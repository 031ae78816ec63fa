"""Newton–Euler for planar mechanisms of revolute joints driven by angular motors.

The reactions of the four-bar and of the chain of four-bar loops in
benchmarks/speed_vs_error.py: per body Σ F = m a_G and Σ M_G = J α, solved at every step for
the joint forces, the fixed link's wrench and the motor torques (``revolute_newton_euler``);
the bodies' motion comes from the closed forms (``references.closed_form``). The solution
checks itself by the power balance (``check_power``) before it is returned. Nothing is taken
from pam2exu.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .slider_crank import rigid_point


@dataclass
class Body:
    """Mass m at G, inertia J about G; G (2, k) with its two rates, angle rates w, alpha (k,)."""

    m: float
    J: float
    G: np.ndarray
    vG: np.ndarray
    aG: np.ndarray
    w: np.ndarray
    alpha: np.ndarray


def body(m, J, cog, origin, fi):
    """Body from its origin (r, r', r'') and angle (fi, fi', fi'') and G's local position."""
    G, vG, aG = rigid_point(*origin, *fi, cog)
    return Body(m, J, G, vG, aG, fi[1], fi[2])


def revolute_newton_euler(bodies, links, gravity, chunk=32):
    """Reactions of a planar mechanism whose first body is fixed, joined by revolutes and
    driven by angular actuators; {column: (k,) array}, as pam2exu names them.

    ``links``: ("fixed", name, body) — wrench the body receives at its origin (Fx, Fy, Mz,
    the body's origin being (0, 0) here); ("revolute", name, body1, body2, P) — force body1
    exerts on body2 at P (2, k) (Fx, Fy; body1 receives the opposite); ("motor", name,
    body1, body2) — torque Mz on body2, −Mz on body1.
    Equations, 3 per body: Σ F = m a_G, Σ (P − G) × F + Σ M = J α, with the weight
    m (0, −g) at G; solved at every step (dense, ``chunk`` steps at a time).
    """
    names = list(bodies)
    row = {b: 3 * i for i, b in enumerate(names)}
    cols, entries = [], []                # entries: (column, body, kind, sign, direction, P)
    for link in links:
        kind, name = link[0], link[1]
        if kind == "fixed":
            for comp, u in (("Fx", (1.0, 0.0)), ("Fy", (0.0, 1.0))):
                entries.append((len(cols), link[2], "force", 1.0, u, None))
                cols.append(f"{name}.{comp}")
            entries.append((len(cols), link[2], "couple", 1.0, None, None))
            cols.append(f"{name}.Mz")
        elif kind == "revolute":
            _, _, b1, b2, P = link
            for comp, u in (("Fx", (1.0, 0.0)), ("Fy", (0.0, 1.0))):
                entries.append((len(cols), b2, "force", 1.0, u, P))
                entries.append((len(cols), b1, "force", -1.0, u, P))
                cols.append(f"{name}.{comp}")
        elif kind == "motor":
            _, _, b1, b2 = link
            entries.append((len(cols), b2, "couple", 1.0, None, None))
            entries.append((len(cols), b1, "couple", -1.0, None, None))
            cols.append(f"{name}.Mz")
    n = 3 * len(names)
    assert len(cols) == n, (len(cols), n)
    k = next(iter(bodies.values())).G.shape[1]
    x = np.empty((k, n))
    for a in range(0, k, chunk):
        s = slice(a, min(k, a + chunk))
        A = np.zeros((s.stop - s.start, n, n))
        rhs = np.zeros((s.stop - s.start, n))
        for j, b, kind, sign, u, P in entries:
            i = row[b]
            if kind == "couple":
                A[:, i + 2, j] += sign
                continue
            A[:, i, j] += sign * u[0]
            A[:, i + 1, j] += sign * u[1]
            arm = (np.zeros((2, s.stop - s.start)) if P is None else P[:, s]) - bodies[b].G[:, s]
            A[:, i + 2, j] += sign * (arm[0] * u[1] - arm[1] * u[0])
        for b in names:
            i, B = row[b], bodies[b]
            rhs[:, i] = B.m * B.aG[0, s]
            rhs[:, i + 1] = B.m * (B.aG[1, s] + gravity)
            rhs[:, i + 2] = B.J * B.alpha[s]
        x[s] = np.linalg.solve(A, rhs[..., None])[..., 0]
    out = {c: x[:, j] for j, c in enumerate(cols)}
    check_power(bodies, links, out, gravity)
    return out


def check_power(bodies, links, out, gravity):
    """Self-check of the reference: ideal joints and a fixed first body do no work, so
    Σ motor power = Σ (m a_G·v_G + J α ω + m g v_Gy) (the rate of kinetic + potential energy)."""
    motor = sum(out[f"{name}.Mz"] * (bodies[b2].w - bodies[b1].w)
                for kind, name, *rest in links if kind == "motor" for b1, b2 in [rest])
    energy = sum(B.m * np.sum(B.aG * B.vG, axis=0) + B.J * B.alpha * B.w
                 + B.m * gravity * B.vG[1] for B in bodies.values())
    scale = max(float(np.max(np.abs(motor))), 1e-300)
    err = float(np.max(np.abs(motor - energy))) / scale
    assert err < 1e-9, f"Newton–Euler reference fails its power balance: {err:.3g}"

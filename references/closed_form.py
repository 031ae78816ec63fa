"""Closed-form kinematics: column helpers, the error measure, and the four-bar.

Every reference is an analytic expression of time: the actuator's law (``references.laws``),
then the loop-closure equations of the mechanism solved for its position, differentiated
once for the velocities and twice for the accelerations. The derivation is in each
docstring. Nothing is taken from pam2exu.

Notation: e(a) = (cos a, sin a), n(a) = e(a + π/2) = (−sin a, cos a), so that
d/dt e(a) = a' n(a), d/dt n(a) = −a' e(a), and e(a)·e(b) = cos(a − b),
n(a)·e(b) = sin(b − a).

Error measure (``errors``): for each column, max |pam2exu − reference| / scale, with scale
the largest |reference| of that column, or, when the reference is identically ~0 (a fixed
coordinate), the mechanism's natural scale of that variable (length L, L·ω, L·ω² for
x-like columns; 1 rad, ω, ω² for angles; ω a typical driver speed).
"""
from __future__ import annotations

import math

import numpy as np

#: examples/four_bar.toml: crank a, coupler b, rocker c, ground d [m]
FOUR_BAR = dict(a=0.1, b=0.35, c=0.3, d=0.4)


def e(a):
    return np.stack([np.cos(a), np.sin(a)])


def n(a):
    return np.stack([-np.sin(a), np.cos(a)])


def solid(name, r, fi, dr, dfi, ddr, ddfi):
    """The nine columns of a solid from its origin r (2, k), its angle and their rates."""
    z = np.zeros_like(np.asarray(fi, dtype=float))
    out = {}
    for suffix, value in zip(("x", "y", "fi", "Dx", "Dy", "Dfi", "DDx", "DDy", "DDfi"),
                              (*r, fi, *dr, dfi, *ddr, ddfi)):
        out[f"{name}.{suffix}"] = value + z
    return out


def still(name, x, y, fi, k):
    """A solid at rest at (x, y, fi)."""
    z = np.zeros(k)
    return solid(name, (x + z, y + z), fi + z, (z, z), z, (z, z), z)


def natural_scales(L, w, F=1.0):
    """Scale of each variable when its reference is identically ~0 (length L [m], angular
    velocity w [rad/s], force F [N])."""
    return {"x": L, "y": L, "fi": 1.0, "Dx": L * w, "Dy": L * w, "Dfi": w,
            "DDx": L * w * w, "DDy": L * w * w, "DDfi": w * w,
            "f(t)": 1.0, "Df(t)": w, "ro": L, "Dro": L * w, "fi_rel": 1.0, "Dfi_rel": w,
            "Fx": F, "Fy": F, "Fnormal": F, "Força": F, "Mz": F * L, "Parell": F * L}


def errors(res, ref, L, w, F=1.0):
    """{column: max |res − ref| / scale}: the scale is the largest |ref|, or the natural
    scale (``natural_scales``) where the reference is identically ~0."""
    fallback = natural_scales(L, w, F)
    out = {}
    for name, value in ref.items():
        value = np.broadcast_to(np.asarray(value, dtype=float), res.t.shape)
        natural = fallback[name.split(".", 1)[1]]
        scale = float(np.max(np.abs(value)))
        if scale < 1e-9 * natural:
            scale = natural
        out[name] = float(np.max(np.abs(res[name] - value))) / scale
    return out


def four_bar(a, b, c, d, th, dth, ddth):
    """Four-bar O2 = (0, 0), O4 = (d, 0): crank a at θ, coupler b at φ, rocker c at ψ.

    Loop closure: a e(θ) + b e(φ) − c e(ψ) − d e(0) = 0.
    Position (circle intersection): with A = a e(θ), D = O4 − A, δ = |D|, the joint B
    is at distance b from A and c from O4, so the angle at A between D and AB is
    γ = acos((b² + δ² − c²)/(2 b δ)) (law of cosines); the assembly mode with the
    coupler above the line A-O4 is φ = atan2(D) + γ, and ψ = atan2(B − O4).
    Velocity: a θ' n(θ) + b φ' n(φ) − c ψ' n(ψ) = 0. Dot with e(ψ) (n(ψ)·e(ψ) = 0):
        a θ' sin(ψ − θ) + b φ' sin(ψ − φ) = 0  →  φ' = −a θ' sin(ψ − θ)/(b sin(ψ − φ));
    dot with e(φ):
        a θ' sin(φ − θ) − c ψ' sin(φ − ψ) = 0  →  ψ' = a θ' sin(φ − θ)/(c sin(φ − ψ)).
    Acceleration: a θ'' n(θ) − a θ'² e(θ) + b φ'' n(φ) − b φ'² e(φ) − c ψ'' n(ψ)
    + c ψ'² e(ψ) = 0. Dot with e(ψ):
        φ'' = (a θ'² cos(θ − ψ) − a θ'' sin(ψ − θ) + b φ'² cos(φ − ψ) − c ψ'²)
              / (b sin(ψ − φ));
    dot with e(φ):
        ψ'' = (a θ'' sin(φ − θ) − a θ'² cos(θ − φ) − b φ'² + c ψ'² cos(ψ − φ))
              / (c sin(φ − ψ)).
    (Equivalent to Freudenstein's equation K1 cosψ − K2 cosθ + K3 = cos(θ − ψ) for ψ.)
    """
    A = a * e(th)
    D = np.array([d, 0.0])[:, None] - A
    delta = np.hypot(D[0], D[1])
    gamma = np.arccos((b * b + delta**2 - c * c) / (2 * b * delta))
    phi = np.unwrap(np.arctan2(D[1], D[0]) + gamma)
    B = A + b * e(phi)
    psi = np.unwrap(np.arctan2(B[1], B[0] - d))
    dphi = -a * dth * np.sin(psi - th) / (b * np.sin(psi - phi))
    dpsi = a * dth * np.sin(phi - th) / (c * np.sin(phi - psi))
    ddphi = (a * dth**2 * np.cos(th - psi) - a * ddth * np.sin(psi - th)
             + b * dphi**2 * np.cos(phi - psi) - c * dpsi**2) / (b * np.sin(psi - phi))
    ddpsi = (a * ddth * np.sin(phi - th) - a * dth**2 * np.cos(th - phi) - b * dphi**2
             + c * dpsi**2 * np.cos(psi - phi)) / (c * np.sin(phi - psi))
    return (phi, dphi, ddphi), (psi, dpsi, ddpsi)


def four_bar_angles(a, b, c, d, theta, mode=1):
    """(φ, ψ) of the coupler and the rocker of ``four_bar``'s linkage at one crank angle θ:
    φ = atan2(O4 − A) + mode·γ, γ by the law of cosines in the triangle A B O4, ψ =
    atan2(B − O4); mode 1: the coupler above the line A-O4, −1: the other assembly mode."""
    A = a * np.array([math.cos(theta), math.sin(theta)])
    D = np.array([d, 0.0]) - A
    delta = math.hypot(*D)
    phi = math.atan2(D[1], D[0]) + mode * math.acos((b * b + delta**2 - c * c)
                                                    / (2 * b * delta))
    B = A + b * np.array([math.cos(phi), math.sin(phi)])
    return phi, math.atan2(B[1], B[0] - d)


def rigid_point(r, dr, ddr, fi, dfi, ddfi, s):
    """Point s (local) of a solid with origin r and angle fi: p = r + R(fi) s.

    p' = r' + fi' Ω R s, p'' = r'' + fi'' Ω R s − fi'² R s (Ω: turn by +90°).
    """
    Rs = np.stack([np.cos(fi) * s[0] - np.sin(fi) * s[1], np.sin(fi) * s[0] + np.cos(fi) * s[1]])
    ORs = np.stack([-Rs[1], Rs[0]])
    return r + Rs, dr + dfi * ORs, ddr + ddfi * ORs - dfi**2 * Rs

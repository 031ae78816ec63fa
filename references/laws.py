"""The actuators' time laws, written independently of pam2exu (docs/model-format.md, "Time laws").

Each law gives (f, f', f'') at the times ``t`` from the coefficients C; its formula is in its
docstring. ``actuator_law`` reads an actuator's law name and coefficients from a model and
evaluates them with these laws, so none of pam2exu's own law code is used.
"""
from __future__ import annotations

import numpy as np


def law_polynomial(t, C):
    """f = C1 + C2 t + C3 t² + C4 t³, f' = C2 + 2 C3 t + 3 C4 t², f'' = 2 C3 + 6 C4 t."""
    c1, c2, c3, c4 = C
    return (c1 + c2 * t + c3 * t**2 + c4 * t**3, c2 + 2 * c3 * t + 3 * c4 * t**2,
            2 * c3 + 6 * c4 * t)


def law_harmonic(t, C):
    """f = C1 + C2 cos(C3 t + C4), f' = −C2 C3 sin(·), f'' = −C2 C3² cos(·)."""
    c1, c2, c3, c4 = C
    p = c3 * t + c4
    return c1 + c2 * np.cos(p), -c2 * c3 * np.sin(p), -c2 * c3**2 * np.cos(p)


def _blend(shape):
    """f = C3 + (C4 − C3) s(u), u = (t − C1)/(C2 − C1) on [C1, C2); C3 before, C4 after.

    f' = (C4 − C3) s'(u)/(C2 − C1), f'' = (C4 − C3) s''(u)/(C2 − C1)²; outside the
    interval both are 0 (at C1 the right-hand limit, inside; at C2 after, so 0).
    """
    def law(t, C):
        c1, c2, c3, c4 = C
        h = c2 - c1
        u = (t - c1) / h
        s, ds, dds = shape(u)
        inside = (t >= c1) & (t < c2)
        f = np.where(t < c1, c3, np.where(inside, c3 + (c4 - c3) * s, c4))
        return (f, np.where(inside, (c4 - c3) * ds / h, 0.0),
                np.where(inside, (c4 - c3) * dds / h**2, 0.0))
    return law


law_ramp = _blend(lambda u: (u, np.ones_like(u), np.zeros_like(u)))
law_bezier_c1 = _blend(lambda u: (3 * u**2 - 2 * u**3, 6 * u - 6 * u**2, 6 - 12 * u))
law_bezier_c2 = _blend(lambda u: (6 * u**5 - 15 * u**4 + 10 * u**3,
                                  30 * u**4 - 60 * u**3 + 30 * u**2,
                                  120 * u**3 - 180 * u**2 + 60 * u))

LAWS = {"polynomial": law_polynomial, "harmonic": law_harmonic, "ramp": law_ramp,
        "bezier_c1": law_bezier_c1, "bezier_c2": law_bezier_c2}


def actuator_law(model, name, t):
    """(f, f', f'') of a model's actuator, by the independent laws above."""
    el = model[name]
    C = tuple(float(c) for c in el.C) + (0.0,) * (4 - len(el.C))
    return LAWS[el.law](np.asarray(t, dtype=float), C)

"""The time laws as a standalone script writes them: plain Python functions of t and
C1 ... C4 (the formulas of ``pam2exu.laws``, as a reader would write them), shared by the
exported scripts (``export``: positions, ``export_dynamic``: forward dynamics).
"""
from __future__ import annotations

__all__ = ["LAW_CODE", "RATE_CODE"]


def _transition(name: str, shape: str, doc: str) -> str:
    return f'''def {name}(t, C1, C2, C3, C4):
    """f = C3 + (C4 - C3) s(u), s(u) = {doc}, u = (t - C1)/(C2 - C1)
    on C1 <= t < C2; C3 before C1, C4 from C2 on."""
    if t < C1:
        return C3
    if t >= C2:
        return C4
    u = (t - C1) / (C2 - C1)
    return C3 + (C4 - C3) * {shape}
'''


#: law name -> its definition in the script, a function of t and C1 ... C4 (the formulas of
#: pam2exu.laws, as a reader would write them)
LAW_CODE = {
    "polynomial": '''def polynomial(t, C1, C2, C3, C4):
    """f = C1 + C2 t + C3 t^2 + C4 t^3."""
    return C1 + t * (C2 + t * (C3 + t * C4))
''',
    "harmonic": '''def harmonic(t, C1, C2, C3, C4):
    """f = C1 + C2 cos(C3 t + C4)."""
    return C1 + C2 * np.cos(C3 * t + C4)
''',
    "ramp": _transition("ramp", "u", "u"),
    "bezier_c1": _transition("bezier_c1", "(u * u * (3.0 - 2.0 * u))", "3u^2 - 2u^3"),
    "bezier_c2": _transition("bezier_c2", "(u * u * u * (10.0 + u * (-15.0 + 6.0 * u)))",
                             "6u^5 - 15u^4 + 10u^3"),
}


def _transition_rate(name: str, shape: str, doc: str) -> str:
    return f'''def {name}_rate(t, C1, C2, C3, C4):
    """f'(t) of {name}: (C4 - C3) s'(u) / (C2 - C1), s'(u) = {doc}, on C1 <= t < C2; 0
    elsewhere (the right-hand limit at C1 and C2, where it jumps)."""
    if t < C1 or t >= C2:
        return 0.0
    u = (t - C1) / (C2 - C1)
    return (C4 - C3) * {shape} / (C2 - C1)
'''


#: law name -> the definition of its first derivative f'(t) in the script (``<law>_rate``,
#: the right-hand limit where it jumps, as ``pam2exu.laws``): the exported dynamic script's
#: velocity equations after a breakpoint
RATE_CODE = {
    "polynomial": '''def polynomial_rate(t, C1, C2, C3, C4):
    """f'(t) of polynomial: C2 + 2 C3 t + 3 C4 t^2."""
    return C2 + t * (2.0 * C3 + 3.0 * C4 * t)
''',
    "harmonic": '''def harmonic_rate(t, C1, C2, C3, C4):
    """f'(t) of harmonic: -C2 C3 sin(C3 t + C4)."""
    return -C2 * C3 * np.sin(C3 * t + C4)
''',
    "ramp": '''def ramp_rate(t, C1, C2, C3, C4):
    """f'(t) of ramp: (C4 - C3) / (C2 - C1) on C1 <= t < C2; 0 elsewhere (the right-hand
    limit at C1 and C2, where it jumps)."""
    if t < C1 or t >= C2:
        return 0.0
    return (C4 - C3) / (C2 - C1)
''',
    "bezier_c1": _transition_rate("bezier_c1", "(6.0 * u * (1.0 - u))", "6u - 6u^2"),
    "bezier_c2": _transition_rate("bezier_c2", "(30.0 * u * u * (1.0 - u) ** 2)",
                                  "30u^2 (1 - u)^2"),
}

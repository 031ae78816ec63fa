"""The time laws as a standalone script writes them: plain Python functions of t and
C1 ... C4 (the formulas of ``pam2exu.laws``, as a reader would write them), shared by the
exported scripts (``export``: positions, ``export_dynamic``: forward dynamics).
"""
from __future__ import annotations

__all__ = ["LAW_CODE"]


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

"""The time laws as a standalone script writes them: plain Python functions of t and
C1 ... C4, made from each law's declaration (``laws.LawForm``: its formula in words, and
``code``, ``rate_code``), shared by the exported scripts (``export``: positions,
``export_dynamic``: forward dynamics).
"""
from __future__ import annotations

from .laws import LAWS, LawForm

__all__ = ["LAW_CODE", "RATE_CODE", "law_code", "rate_code"]

#: the characters a script's docstrings spell in ASCII
_ASCII = str.maketrans({"²": "^2", "³": "^3", "⁴": "^4", "⁵": "^5", "−": "-"})


def _grouped(code: str) -> str:
    """``code`` in parentheses, unless it is a bare name (``u``)."""
    return code if code.isidentifier() else f"({code})"


def law_code(name: str, form: LawForm) -> str:
    """The definition of the law ``name`` in the script: a function of t and C1 ... C4."""
    words = form.words.translate(_ASCII)
    if not form.interval:
        return f'''def {name}(t, C1, C2, C3, C4):
    """f = {words}."""
    return {form.code}
'''
    return f'''def {name}(t, C1, C2, C3, C4):
    """f = C3 + (C4 - C3) s(u), s(u) = {words}, u = (t - C1)/(C2 - C1)
    on C1 <= t < C2; C3 before C1, C4 from C2 on."""
    if t < C1:
        return C3
    if t >= C2:
        return C4
    u = (t - C1) / (C2 - C1)
    return C3 + (C4 - C3) * {_grouped(form.code)}
'''


def rate_code(name: str, form: LawForm) -> str:
    """The definition of its first derivative f'(t) in the script (``<law>_rate``, the
    right-hand limit where it jumps, as ``pam2exu.laws``)."""
    if not form.interval:
        return f'''def {name}_rate(t, C1, C2, C3, C4):
    """f'(t) of {name}: {form.rate_words}."""
    return {form.rate_code}
'''
    if form.rate_code is None:
        return f'''def {name}_rate(t, C1, C2, C3, C4):
    """f'(t) of {name}: (C4 - C3) / (C2 - C1) on C1 <= t < C2; 0 elsewhere (the right-hand
    limit at C1 and C2, where it jumps)."""
    if t < C1 or t >= C2:
        return 0.0
    return (C4 - C3) / (C2 - C1)
'''
    return f'''def {name}_rate(t, C1, C2, C3, C4):
    """f'(t) of {name}: (C4 - C3) s'(u) / (C2 - C1), s'(u) = {form.rate_words}, on C1 <= t < C2; 0
    elsewhere (the right-hand limit at C1 and C2, where it jumps)."""
    if t < C1 or t >= C2:
        return 0.0
    u = (t - C1) / (C2 - C1)
    return (C4 - C3) * {_grouped(form.rate_code)} / (C2 - C1)
'''


#: law name -> its definition in the script, a function of t and C1 ... C4
LAW_CODE = {name: law_code(name, form) for name, form in LAWS.items()}

#: law name -> the definition of its first derivative f'(t) in the script: the exported
#: dynamic script's velocity equations after a breakpoint
RATE_CODE = {name: rate_code(name, form) for name, form in LAWS.items()}

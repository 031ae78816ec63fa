"""The complex step: how the first-order method of a study (``studies/linear.py``) takes
exact derivatives of the native equations.

A function f analytic in a real parameter p has f(p + ih) = f(p) + ih f'(p) + O(h²), so
f'(p) = Im f(p + ih) / h with no difference taken: exact to rounding for h = 1e-30. The
study writes p + ih into a copy of the model; its numbers then flow as complex numbers
through the anchors, the laws, the constraint equations, the velocity, acceleration and
force passes and the outputs. The helpers below are where those paths keep a complex
number complex; a real number passes through them exactly as before (the same float, the
same ``math`` function), so nothing changes for a run.
"""
from __future__ import annotations

import cmath
import math

import numpy as np


def scalar(x):
    """x as a float, or as a complex when it is one (a parameter at p + ih)."""
    return complex(x) if isinstance(x, complex) else float(x)


def cos(a):
    """cos a of a float (``math.cos``) or of a complex (``cmath.cos``)."""
    return cmath.cos(a) if isinstance(a, complex) else math.cos(a)


def sin(a):
    """sin a of a float (``math.sin``) or of a complex (``cmath.sin``)."""
    return cmath.sin(a) if isinstance(a, complex) else math.sin(a)


def number_type(*values) -> np.dtype:
    """float64, or complex128 when any of ``values`` (numbers or arrays) is complex."""
    return np.dtype(complex if any(np.iscomplexobj(v) for v in values) else float)


def as_array(x) -> np.ndarray:
    """``np.asarray(x, dtype=float)``, keeping a complex array complex (one conversion: it
    is on the path of every point of every run)."""
    a = np.asarray(x)
    return a if a.dtype == np.float64 or a.dtype == np.complex128 else a.astype(
        complex if a.dtype.kind == "c" else float)


def hypot(x, y):
    """√(x² + y²): ``numpy.hypot`` of real arrays; of complex ones √(x·x + y·y) (analytic)."""
    if np.iscomplexobj(x) or np.iscomplexobj(y):
        return np.sqrt(x * x + y * y)
    return np.hypot(x, y)


def atan2(y, x):
    """The angle of (x, y): ``numpy.arctan2`` of real arrays; of complex ones its value at
    the real parts plus i times its first-order change, (x Im y − y Im x)/(x² + y²)."""
    if not (np.iscomplexobj(x) or np.iscomplexobj(y)):
        return np.arctan2(y, x)
    xr, yr = np.real(x), np.real(y)
    return np.arctan2(yr, xr) + 1j * (xr * np.imag(y) - yr * np.imag(x)) / (xr * xr + yr * yr)


def absolute(x):
    """|x|: ``numpy.abs`` of a real array; of a complex one x·sign(Re x) (analytic where
    Re x ≠ 0, where |x| is differentiable)."""
    if np.iscomplexobj(x):
        return x * np.sign(np.real(x))
    return np.abs(x)


def row_norm(d):
    """|d| of each row of d (n, k), kept as (n, 1): ``numpy.linalg.norm`` of a real array;
    √(Σ d·d) of a complex one (analytic: the norm conjugates)."""
    if np.iscomplexobj(d):
        return np.sqrt(np.sum(d * d, axis=1, keepdims=True))
    return np.linalg.norm(d, axis=1, keepdims=True)

"""Values of a table between its rows: the cubic spline ``pam2exu compare`` interpolates a
result onto a reference's times with, and ``Results.at`` a result at any time."""
from __future__ import annotations

import numpy as np


def interpolate(t: np.ndarray, values: np.ndarray, t_new: np.ndarray,
                method: str = "cubic") -> np.ndarray:
    """values(t_new) for each row of values (one variable per row): not-a-knot cubic spline,
    or piecewise linear; rows with non-finite values always piecewise linear."""
    values = np.atleast_2d(values)
    if len(t) == 1:
        return np.repeat(values[:, :1], len(t_new), axis=1)
    out = np.empty((values.shape[0], len(t_new)))
    finite = np.all(np.isfinite(values), axis=1)
    if method == "cubic" and finite.any():
        from scipy.interpolate import CubicSpline
        out[finite] = CubicSpline(t, values[finite], axis=1)(t_new)
    linear = np.flatnonzero(~finite) if method == "cubic" else range(values.shape[0])
    for i in linear:
        out[i] = np.interp(t_new, t, values[i])
    return out


def interpolation_error(t: np.ndarray, values: np.ndarray, t_new: np.ndarray,
                        method: str = "cubic") -> np.ndarray:
    """Estimated max interpolation error per row: max |I_h − I_2h| / (2^p − 1), I_2h built on
    every other point, p = 4 (cubic) or 2 (linear); nan with fewer than 7 points."""
    values = np.atleast_2d(values)
    if len(t) < 7 or len(t_new) == 0:
        return np.full(values.shape[0], np.nan)
    every_other = np.unique(np.r_[np.arange(0, len(t), 2), len(t) - 1])
    fine = interpolate(t, values, t_new, method)
    coarse = interpolate(t[every_other], values[:, every_other], t_new, method)
    order = 4 if method == "cubic" else 2
    with np.errstate(invalid="ignore"):
        diff = np.abs(fine - coarse)
    diff[np.isnan(diff)] = 0.0
    return diff.max(axis=1) / (2 ** order - 1)

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


#: the bounds' margin over the terms of the interpolation error they add up: covers the
#: change of the derivative over the rows used (measured below ``error_bound``)
SAFETY = 2.0
#: the spline's slope error at a row, in units of h³ max|f⁗| / 24: 1 inside (the complete
#: spline's bound), and at the rows 0, 1, 2 from each end those of the cubic through the
#: four end rows, |ω'(t_k)| / h³ = 6, 2, 2 (the not-a-knot spline's end piece)
END_SLOPES = (6.0, 2.0, 2.0)
#: max|f⁽ᵏ⁾| is taken over the windows of k + 1 rows that reach this many rows beyond the
#: interval on each side (the spline's error at t depends on the rows around it)
REACH = 2


def interpolation_error(t: np.ndarray, values: np.ndarray, t_new: np.ndarray,
                        method: str = "cubic") -> np.ndarray:
    """Estimated largest interpolation error per row over the times t_new (``pam2exu
    compare``'s column): the largest leading term of ``error_bound`` (``leading``); nan with
    too few points (cubic 5, linear 3) or no t_new. Measured against the true largest error:
    1.0 … 5.6 times it (the four-bar's angles in 25 … 400 steps, sin(2πt) on 41 rows)."""
    values = np.atleast_2d(values)
    if len(t_new) == 0:
        return np.full(values.shape[0], np.nan)
    return error_bound(t, values, t_new, method, leading=True).max(axis=1)


def error_bound(t: np.ndarray, values: np.ndarray, t_new: np.ndarray,
                method: str = "cubic", leading: bool = False) -> np.ndarray:
    """|f − I f|(t_new) ≤ SAFETY · max|f⁽ᵏ⁾| / k! · w(t_new), each row (rows, len(t_new)).

    k = 4 (cubic) or 2 (linear); max|f⁽ᵏ⁾| is k! times the largest |divided difference| of
    order k over the windows of k + 1 rows within ``REACH`` rows of the interval [a, b] of
    t (h = b − a, θ = (t − a)/h). The kernel w: linear (t − a)(b − t); cubic
    h⁴ [θ²(1−θ)² + c_a θ(1−θ)² + c_b θ²(1−θ)], the Hermite cubic's error plus the spline's
    slope errors at a and b (c = ``END_SLOPES`` near the ends, else 1), and in the two
    intervals at each end, where the not-a-knot spline is the cubic through the four end
    rows t0 … t3, at least |Π (t − t_k)| over those rows. Zero at the rows; nan with too
    few rows (5 cubic, 3 linear) or for a row with a value that is not finite.

    ``leading``: the leading term only, an estimate (no slope terms, which matter next to
    the rows, and only the windows that hold the interval).

    Measured (true error / bound, at 2000 times over the run): the example four-bar's
    angles in 25 … 400 steps, and sin(ωt + φ) + cos(0.7 ωt)/2 for ω = 1 … 30 on 21 … 401
    rows: at most 0.61 (linear, the sines: 0.70).
    """
    t = np.asarray(t, dtype=float)
    values = np.atleast_2d(np.asarray(values, dtype=float))
    t_new = np.asarray(t_new, dtype=float)
    k = 4 if method == "cubic" else 2
    n = len(t)
    if n < k + 1:
        return np.full((values.shape[0], len(t_new)), np.nan)
    dd = values
    for order in range(1, k + 1):                  # divided differences f[t_s … t_s+k]
        dd = (dd[:, 1:] - dd[:, :-1]) / (t[order:] - t[:-order])
    size = np.abs(np.nan_to_num(dd, posinf=0.0, neginf=0.0))
    j = np.clip(np.searchsorted(t, t_new, side="right"), 1, n - 1)     # t_new in [t[j-1], t[j]]
    largest = np.zeros((values.shape[0], len(t_new)))
    reach = 0 if leading else REACH
    for shift in range(-k - reach, reach):         # windows s … s + k near t[j-1], t[j]
        s = j + shift
        ok = (s >= 0) & (s <= n - 1 - k)
        largest[:, ok] = np.maximum(largest[:, ok], size[:, s[ok]])
    a, b = t[j - 1], t[j]
    if k == 2:
        kernel = np.abs((t_new - a) * (t_new - b))
    else:
        h = b - a
        theta = (t_new - a) / h
        kernel = (theta * (1 - theta)) ** 2
        if not leading:
            kernel = kernel + theta * (1 - theta) * ((1 - theta) * _slope(j - 1, n)
                                                     + theta * _slope(j, n))
        kernel = kernel * h ** 4
        for ends, near in ((t[:4], j <= 2), (t[-4:], j >= n - 2)):
            poly = np.abs(np.prod(t_new[:, None] - ends[None, :], axis=1))
            kernel = np.where(near, np.maximum(kernel, poly), kernel)
    finite = np.all(np.isfinite(values), axis=1)
    with np.errstate(invalid="ignore"):
        return np.where(finite[:, None], SAFETY * largest * kernel, np.nan)


def _slope(i: np.ndarray, n: int) -> np.ndarray:
    """The slope error factor (``END_SLOPES``) at rows i of n."""
    from_end = np.minimum(i, n - 1 - i)
    factors = np.ones(len(from_end))
    for k, c in enumerate(END_SLOPES):
        factors[from_end == k] = c
    return factors

"""Gaussian elimination for many small dense systems at once, the systems along the last axis.

``numpy.linalg.solve`` calls LAPACK once per matrix: for 100,000 systems of 5 equations its
per-matrix overhead is most of the cost (36 ms, against 3 ms here). Here every elimination
step is one numpy operation over all systems: A is (m, m, n), a right-hand side (m, n) or
(m, r, n), and each system has its own partial pivoting (PA = LU, as LAPACK's getrf).
"""
from __future__ import annotations

import numpy as np


def lu_factor(A: np.ndarray, threshold: float = 1.0):
    """(swaps, ok): A (m, m, n) overwritten by L (unit diagonal, below) and U (on and above)
    of PA = LU for every system; swaps[k] the row exchanged with row k at step k; ok False
    where a pivot is zero or not finite (a singular system: its answer is meaningless).

    Threshold pivoting: rows are exchanged where |A[k, k]| < threshold · max |A[k:, k]| (1:
    partial pivoting, as LAPACK; 0.1 keeps |L| ≤ 10 and exchanges far fewer rows when the
    rows come in a good order, and exchanges are what costs)."""
    m, n = A.shape[0], A.shape[2]
    swaps = np.empty((m, n), dtype=np.intp)
    ok = np.ones(n, dtype=bool)
    for k in range(m):
        best = np.full(n, k)                          # argmax |A[k:, k]| (np.argmax along
        largest = np.abs(A[k, k])                     # the first axis is slow)
        for r in range(k + 1, m):
            size = np.abs(A[r, k])
            larger = size > largest
            best += larger * (r - best)               # (faster than best[larger] = r)
            np.maximum(largest, size, out=largest)
        swaps[k] = k
        moved = np.nonzero(np.abs(A[k, k]) < threshold * largest)[0]
        if moved.size:
            p = swaps[k][moved] = best[moved]
            row = A[k][:, moved]                      # a copy: (m, moved)
            A[k][:, moved] = A[p, :, moved].T
            A[p, :, moved] = row.T
        pivot = A[k, k]
        bad = ~np.isfinite(pivot) | (pivot == 0.0)
        if bad.any():
            ok &= ~bad
            pivot = np.where(bad, 1.0, pivot)
        if k + 1 < m:
            L = A[k + 1:, k] / pivot
            A[k + 1:, k] = L
            A[k + 1:, k + 1:] -= L[:, None, :] * A[k, k + 1:][None]
    return swaps, ok


def lu_solve(A: np.ndarray, swaps: np.ndarray, b: np.ndarray) -> np.ndarray:
    """x with A x = b per system, A and swaps from ``lu_factor``; b (m, n) or (m, r, n)."""
    m, n = A.shape[0], A.shape[2]
    x = np.array(b, dtype=float)
    extra = (1,) * (x.ndim - 2)
    for k in range(m):                                # P b
        moved = np.nonzero(swaps[k] != k)[0]
        if moved.size:
            p = swaps[k][moved]
            row = x[k][..., moved]
            x[k][..., moved] = x[p, ..., moved].T if x.ndim == 3 else x[p, moved]
            if x.ndim == 3:
                x[p, ..., moved] = row.T
            else:
                x[p, moved] = row
    for k in range(m - 1):                            # L y = P b
        x[k + 1:] -= A[k + 1:, k].reshape((m - k - 1,) + extra + (n,)) * x[k][None]
    with np.errstate(divide="ignore", invalid="ignore"):   # singular systems: NaN, inf
        for k in range(m - 1, -1, -1):                # U x = y
            x[k] /= A[k, k].reshape(extra + (n,))
            if k:
                x[:k] -= A[:k, k].reshape((k,) + extra + (n,)) * x[k][None]
    return x

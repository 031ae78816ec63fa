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
        size = np.abs(A[k:, k])                       # (m - k, n)
        largest = size.max(axis=0)                    # exact: NaN where any is NaN
        swaps[k] = k
        moved = np.nonzero(size[0] < threshold * largest)[0]
        if moved.size:
            few = 4 * moved.size < n                  # else all columns (no copy)
            best = _first_largest(size[:, moved] if few else size)
            p = swaps[k][moved] = k + (best if few else best[moved])
            rows = [] if few else np.nonzero(np.bincount(p, minlength=m))[0]
            if few or len(rows) * n > 2 * moved.size:
                row = A[k][:, moved]                  # a copy: (m, moved)
                A[k][:, moved] = A[p, :, moved].T
                A[p, :, moved] = row.T
            else:                                     # most systems exchange rows k and r:
                for r in rows:                        # whole rows (no gathers)
                    there = swaps[k] == r
                    row = np.where(there, A[r], A[k])
                    A[r] = np.where(there, A[k], A[r])
                    A[k] = row
        pivot = A[k, k]
        if not (np.isfinite(pivot).all() and pivot.all()):
            bad = ~np.isfinite(pivot) | (pivot == 0.0)
            ok &= ~bad
            pivot = np.where(bad, 1.0, pivot)
        if k + 1 < m:
            L = np.divide(A[k + 1:, k], pivot, out=A[k + 1:, k])
            A[k + 1:, k + 1:] -= L[:, None, :] * A[k, k + 1:][None]
    return swaps, ok


def _first_largest(size: np.ndarray) -> np.ndarray:
    """The row of the first largest of each column of size (r, n) (``numpy.argmax`` along
    the first axis, which is slow): NaN is never larger."""
    best = np.zeros(size.shape[1], dtype=np.intp)
    largest = size[0].copy()
    for r in range(1, len(size)):
        larger = size[r] > largest
        best += larger * (r - best)                   # (faster than best[larger] = r)
        np.maximum(largest, size[r], out=largest)
    return best


def lu_solve(A: np.ndarray, swaps: np.ndarray, b: np.ndarray) -> np.ndarray:
    """x with A x = b per system, A and swaps from ``lu_factor``; b (m, n) or (m, r, n)."""
    m, n = A.shape[0], A.shape[2]
    x = np.array(b, dtype=float)
    extra = (1,) * (x.ndim - 2)
    exchanged = swaps != np.arange(m)[:, None]
    for k in np.nonzero(exchanged.any(axis=1))[0]:    # P b, the steps that exchanged rows
        moved = np.nonzero(exchanged[k])[0]
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

"""batched.lu_factor / lu_solve: Gaussian elimination for many small systems at once.

Reference: numpy.linalg.solve (LAPACK getrf/getrs, one system at a time) on the same
systems; the backward error |A x − b| / (|A| |x|) of both is at round-off.
"""
import numpy as np
import pytest

from pam2exu.batched import lu_factor, lu_solve


def _systems(m, n, seed=0):
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, m, m))
    A[:, 0, 0] = 0.0                          # every system needs a row exchange
    return A, rng.standard_normal((n, m, 2))


def _backward_error(A, x, b):
    return np.max(np.abs(A @ x - b).max(axis=(1, 2))
                  / (np.abs(A).max(axis=(1, 2)) * np.abs(x).max(axis=(1, 2))))


@pytest.mark.parametrize("m,n", [(2, 50), (5, 3000), (12, 400), (30, 60)])
@pytest.mark.parametrize("threshold", [1.0, 0.5])
def test_solves_like_lapack(m, n, threshold):
    A, b = _systems(m, n)
    LU = np.ascontiguousarray(A.transpose(1, 2, 0))
    swaps, ok = lu_factor(LU, threshold)
    assert ok.all()
    x = lu_solve(LU, swaps, b.transpose(1, 2, 0)).transpose(2, 0, 1)
    reference = np.linalg.solve(A, b)
    assert _backward_error(A, x, b) <= 8 * max(_backward_error(A, reference, b), 1e-16) * m
    # one right-hand side at a time gives the same numbers, bit for bit
    x0 = lu_solve(LU, swaps, b[:, :, 0].T).T
    np.testing.assert_array_equal(x0, x[:, :, 0])


def test_partial_pivoting_chooses_the_largest_pivot():
    """threshold 1: the row of the largest |entry| becomes the pivot row (as getrf)."""
    A = np.array([[1.0, 2.0], [3.0, 4.0]])[:, :, None].copy()
    swaps, ok = lu_factor(A, 1.0)
    assert swaps[:, 0].tolist() == [1, 1] and ok.all()
    np.testing.assert_allclose(A[:, :, 0], [[3.0, 4.0], [1 / 3, 2 - 4 / 3]], rtol=1e-15)
    # threshold 0.25: 1 ≥ 0.25 · 3, the rows stay
    B = np.array([[1.0, 2.0], [3.0, 4.0]])[:, :, None].copy()
    swaps, _ = lu_factor(B, 0.25)
    assert swaps[:, 0].tolist() == [0, 1]


def test_singular_and_non_finite_systems_are_flagged_alone():
    A = np.repeat(np.eye(3)[:, :, None], 4, axis=2)
    A[2, 2, 1] = 0.0                                  # singular
    A[1, 1, 2] = np.nan                               # not finite
    swaps, ok = lu_factor(A)
    assert ok.tolist() == [True, False, False, True]
    x = lu_solve(A, swaps, np.ones((3, 4)))
    np.testing.assert_array_equal(x[:, [0, 3]], 1.0)


@pytest.mark.parametrize("exchanging", [3, 40])
def test_tied_pivots_take_the_first_row_as_getrf(exchanging):
    """Rows exchanged in a few systems of a batch or in all: each takes the first of its
    largest |entries| (LAPACK getrf's idamax), the same rows either way (a check of the
    search's two paths, both already right before they were split)."""
    from scipy.linalg import lu_factor as getrf
    rng = np.random.default_rng(3)
    A = rng.integers(-3, 4, size=(40, 4, 4)).astype(float)   # ties among the integers
    A[:, 0, 0] = 0.5
    A[exchanging:, 0, 0] = 9.0                    # these keep their rows at the first step
    A[:, [1, 3], 0] = -4.0                        # two largest: rows 1 and 3
    swaps, ok = lu_factor(np.ascontiguousarray(A.transpose(1, 2, 0)), 1.0)
    for k in range(40):                           # the first step's pivot (exact data)
        assert swaps[0, k] == getrf(A[k])[1][0]
    assert (swaps[0, :exchanging] == 1).all() and (swaps[0, exchanging:] == 0).all()

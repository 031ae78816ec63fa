"""The variants' values (pam2exu/studies/sampling.py): moments of the distributions, the
methods' designs, and rows that depend only on their index (any chunking, bit for bit)."""
import itertools
import math
import warnings

import numpy as np
import pytest
from scipy import stats

from pam2exu.studies import METHODS, Parameter, design
from pam2exu.studies.sampling import grid_size

#: one parameter of each distribution (nominal, and the keys a study file gives)
PARAMETERS = [Parameter("a.x", "normal", 1.0, tol=0.3),
              Parameter("b.x", "uniform", 0.0, low=2.0, high=4.0),
              Parameter("c.x", "triangular", 5.0, tol=0.5),
              Parameter("d.x", "values", 0.0, values=[1.0, 2.0, 5.0])]


def test_sigma_p_of_each_distribution():
    # closed forms: normal 3σ = tol; uniform (high − low)/√12; a symmetric triangular of
    # half-width tol: tol/√6; equally likely values: their population standard deviation
    expected = [0.1, 2.0 / math.sqrt(12.0), 0.5 / math.sqrt(6.0), np.std([1.0, 2.0, 5.0])]
    assert [p.sigma for p in PARAMETERS] == pytest.approx(expected, rel=1e-14)


def test_monte_carlo_moments_within_four_standard_errors():
    n = 20_000
    drawn = design("monte_carlo", PARAMETERS, n, 11, 0, n)
    # the distributions' mean, σ and kurtosis (values: of the list, equally likely)
    values = np.array([1.0, 2.0, 5.0])
    moments = [(1.0, 0.1, 3.0), (3.0, 2.0 / math.sqrt(12.0), 1.8),
               (5.0, 0.5 / math.sqrt(6.0), 2.4),
               (values.mean(), values.std(), stats.kurtosis(values, fisher=False))]
    for column, (mean, sigma, kurtosis) in zip(drawn.T, moments):
        # standard errors: of the mean σ/√n, of the standard deviation σ √((κ − 1)/(4n))
        assert abs(column.mean() - mean) < 4 * sigma / math.sqrt(n)
        assert abs(column.std(ddof=1) - sigma) < 4 * sigma * math.sqrt((kurtosis - 1) / (4 * n))
    assert set(drawn[:, 3]) == {1.0, 2.0, 5.0}
    low, high = drawn[:, 2].min(), drawn[:, 2].max()
    assert 4.5 <= low and high <= 5.5              # the triangular stays within nominal ± tol


def test_latin_hypercube_has_one_point_per_stratum_per_parameter():
    n = 64
    drawn = design("latin_hypercube", PARAMETERS[:3], n, 5, 0, n)
    for p, column in zip(PARAMETERS[:3], drawn.T):
        strata = np.floor(p.distribution_object().cdf(column) * n).astype(int)
        assert sorted(strata) == list(range(n)), p.name


def test_grid_is_the_row_major_product_of_the_values_lists():
    parameters = [Parameter("a.x", "values", 0.0, values=[1.0, 2.0]),
                  Parameter("b.x", "values", 0.0, values=[10.0, 20.0, 30.0]),
                  Parameter("c.x", "values", 0.0, values=[-1.0, -2.0])]
    n = grid_size(parameters)
    assert n == 12
    expected = list(itertools.product([1.0, 2.0], [10.0, 20.0, 30.0], [-1.0, -2.0]))
    assert design("grid", parameters, n, 0, 0, n).tolist() == [list(r) for r in expected]


def test_linear_is_the_nominal_variant():
    assert design("linear", PARAMETERS, 1, 0, 0, 1).tolist() == [[1.0, 0.0, 5.0, 0.0]]


@pytest.mark.parametrize("method", [m for m in METHODS if m not in ("grid", "linear")])
def test_any_chunking_gives_the_rows_of_the_whole_design_bit_for_bit(method):
    n, seed = 100, 3
    with warnings.catch_warnings():
        warnings.simplefilter("error")            # no scipy warning from a chunk
        whole = design(method, PARAMETERS, n, seed, 0, n)
        for size in (1, 7, 32, 99):
            chunks = [design(method, PARAMETERS, n, seed, a, min(a + size, n))
                      for a in range(0, n, size)]
            assert np.array_equal(np.vstack(chunks), whole), size
    assert not np.array_equal(design(method, PARAMETERS, n, seed + 1, 0, n), whole)
    assert np.array_equal(design(method, PARAMETERS, n, seed, 0, n), whole)


def test_rows_outside_the_study_are_refused():
    with pytest.raises(ValueError, match=r"rows \[5, 12\)"):
        design("monte_carlo", PARAMETERS, 10, 0, 5, 12)

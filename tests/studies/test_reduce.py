"""What a study makes of its variants' runs (pam2exu/studies/reduce.py): the seven
reductions, the outputs' patterns, clearance components as absolute values, the status by
the requirements and the per-variant table.

References: each reduction computed by hand in plain Python (``math.fsum``, ``min``,
``max``) over the rows; the patterns against the columns ``run(..., outputs=)`` gives;
the contract's rules (shared/spec/studies.md, "Per variant", "Results").
"""
import doctest
import math
import warnings

import numpy as np
import pytest

import pam2exu
from pam2exu.errors import ModelError
from pam2exu.results import Results
from pam2exu.studies import reduce
from pam2exu.studies.reduce import (REDUCTIONS, Variant, reduce_run, reduced_names, status,
                                    variant_table)


def _by_hand(y: list[float]) -> dict[str, float]:
    """The seven reductions of the rows ``y`` in plain Python, each row weighted equally."""
    n = len(y)
    return {"min": min(y), "max": max(y), "absmax": max(abs(v) for v in y),
            "mean": math.fsum(y) / n, "rms": math.sqrt(math.fsum(v * v for v in y) / n),
            "final": y[-1], "range": max(y) - min(y)}


def test_the_seven_reductions_are_the_contracts_in_its_order():
    assert list(REDUCTIONS) == ["min", "max", "absmax", "mean", "rms", "final", "range"]
    # each reduction's function and its first-order derivative: one-line equations
    assert all(f.__doc__ and "\n" not in f.__doc__.strip()
               for reduction in REDUCTIONS.values() for f in reduction)


def test_several_series_at_once_are_each_reduced_as_alone():
    """A reduction of a 2-D array (``Reduction.value``, what ``reduce_run`` takes for all
    of a run's outputs at once) gives each row's reduction bit for bit (numpy sums a
    contiguous row in the same order alone or as a row of a table), at lengths across
    the pairwise summation's block edges, with NaN rows and scales from 1e-5 to 1e5."""
    rng = np.random.default_rng(7)
    for n in (1, 2, 7, 8, 9, 101, 127, 128, 129, 1000):
        y = rng.normal(size=(5, n)) * 10.0 ** rng.integers(-5, 6, size=(5, 1))
        y[3, n // 2] = np.nan
        for name, reduction in REDUCTIONS.items():
            with np.errstate(invalid="ignore"):
                rows = reduction.value(y)
            alone = [reduction(row) for row in y]
            assert rows.shape == (5,)
            assert np.array_equal(rows, alone, equal_nan=True), (name, n)


def test_each_reduction_equals_the_computation_by_hand():
    rng = np.random.default_rng(24)
    t = np.linspace(0.0, 1.0, 11)
    columns = {"crank.fi": rng.uniform(-4.0, 3.0, 11), "motor.Mz": rng.normal(2.0, 5.0, 11),
               "B.Fx": np.r_[rng.uniform(1.0, 2.0, 10), -7.5]}      # |final| the largest
    res = Results(t, columns, analysis="kinetostatic")
    reduced = reduce_run(res)
    assert list(reduced) == [f"{c}.{r}" for c in columns for r in REDUCTIONS]
    for c, y in columns.items():
        expected = _by_hand(y.tolist())
        got = {r: reduced[f"{c}.{r}"] for r in REDUCTIONS}
        assert all(isinstance(v, float) for v in got.values())
        np.testing.assert_allclose([got[r] for r in REDUCTIONS],
                                   [expected[r] for r in REDUCTIONS], rtol=1e-15, atol=1e-15)
    assert reduced["B.Fx.absmax"] == 7.5 and reduced["B.Fx.final"] == -7.5


def test_reductions_of_dyadic_rows_are_exact():
    """Eight rows of multiples of 1/8: every sum is exact, so every reduction is too."""
    y = [0.5, -1.25, 3.0, 0.125, -2.0, 1.75, 0.0, -0.375]
    reduced = reduce_run(Results(np.arange(8.0), {"A.Fx": y}), "A.Fx")
    assert reduced == {f"A.Fx.{r}": v for r, v in _by_hand(y).items()}
    assert reduced["A.Fx.mean"] == 1.75 / 8 and reduced["A.Fx.range"] == 5.0


def test_a_nan_row_makes_every_reduction_nan():
    """Documented choice: a NaN is never dropped (a run that succeeds has none)."""
    reduced = reduce_run(Results([0.0, 1.0, 2.0], {"A.Fx": [1.0, np.nan, 2.0]}))
    assert all(math.isnan(v) for v in reduced.values())


@pytest.fixture(scope="module")
def four_bar(request):
    """The four-bar's kinetostatic result over 4 steps, every column."""
    return pam2exu.run(request.config.rootpath / "examples/four_bar.toml",
                       analysis="kinetostatic", steps=4)


PATTERNS = ["motor.Mz", "B.F*", "Fy", "motor.f"]       # "motor.f": PAM's spelling of f(t)


def test_patterns_choose_the_columns_run_outputs_chooses_in_the_patterns_order(
        four_bar, request):
    chosen = pam2exu.run(request.config.rootpath / "examples/four_bar.toml",
                         analysis="kinetostatic", steps=4, outputs=PATTERNS)
    reduced = reduce_run(four_bar, PATTERNS, ["absmax", "final"])
    columns = list(dict.fromkeys(k.rpartition(".")[0] for k in reduced))
    assert sorted(columns) == sorted(chosen.columns)
    assert columns == ["motor.Mz", "B.Fx", "B.Fy", "base.Fy", "O2.Fy", "A.Fy", "O4.Fy",
                       "motor.f(t)"]
    assert list(reduced) == [f"{c}.{r}" for c in columns for r in ("absmax", "final")]
    assert reduced_names(four_bar.columns, PATTERNS, ["absmax", "final"]) == list(reduced)
    for c in columns:                 # the same numbers as the run that chose them
        assert reduced[f"{c}.absmax"] == np.max(np.abs(chosen[c]))
        assert reduced[f"{c}.final"] == chosen[c][-1]


def test_a_pattern_matching_nothing_and_an_unknown_reduction_are_model_errors(four_bar):
    with pytest.raises(ModelError, match=r"'motor\.Mx' matches no variable.*motor\.Mz"):
        reduce_run(four_bar, ["motor.Mx", "B.Fx"])
    with pytest.raises(ModelError, match=r"unknown reduction 'absmx'.*did you mean 'absmax'"):
        reduce_run(four_bar, "B.Fx", ["absmx"])


def _clearance_table(analysis: str) -> Results:
    """A table with the columns and units a clearance run of a model with one clearance
    pin A and one clearance slot G leaves (``A.jx``, ``A.jy``, ``A.jr`` [m], ``G.jn`` [m],
    ``G.jfi`` [rad]) beside a solid's angle; made by ``analysis``."""
    t = np.linspace(0.0, 1.0, 5)
    columns = {"crank.fi": [-0.5, -0.25, 0.0, 0.25, 0.5],
               "A.jx": [0.0, -3e-5, 2e-5, -1e-5, 1e-5], "A.jy": [0.0, 1e-5, -4e-5, 2e-5, -3e-5],
               "G.jn": [-2e-4, -1e-4, 0.0, 5e-5, -6e-5], "G.jfi": [1e-3, -2e-3, 0.0, 0.0, -1e-3]}
    columns["A.jr"] = np.hypot(columns["A.jx"], columns["A.jy"])
    units = {"crank.fi": "rad", "A.jx": "m", "A.jy": "m", "A.jr": "m", "G.jn": "m",
             "G.jfi": "rad"}
    return Results(t, columns, units, analysis)


def test_clearance_components_are_reduced_as_their_absolute_values():
    res = _clearance_table("clearance")
    reduced = reduce_run(res)
    for c in ("A.jx", "A.jy", "A.jr", "G.jn", "G.jfi"):
        expected = _by_hand([abs(v) for v in res[c]])
        np.testing.assert_allclose([reduced[f"{c}.{r}"] for r in REDUCTIONS],
                                   [expected[r] for r in REDUCTIONS], rtol=1e-15, err_msg=c)
    assert reduced["A.jx.max"] == 3e-5 and reduced["G.jn.final"] == 6e-5
    assert reduced["crank.fi.min"] == -0.5          # a solid's angle keeps its sign
    # the columns are clearance components because the clearance analysis made them
    assert reduce_run(_clearance_table("kinematic"), "A.jx")["A.jx.min"] == -3e-5


@pytest.mark.long
def test_a_real_clearance_run_is_reduced_as_absolute_values(request):
    """The over-constrained parallelogram with two clearance pins and a varied ground pin
    (tests/analyses/test_clearance.py): about 3 s."""
    model = pam2exu.load(request.config.rootpath / "tests/data/parallelogram5.toml")
    model["A2"].clearance = True
    model["A3"].clearance = True
    model.add_variation(anchor="ground.O2", dx=3.7e-3, dy=-2.9e-3, wx=1.91, wy=0.57)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = pam2exu.run(model, analysis="clearance", t_end=1.0, steps=4)
    reduced = reduce_run(res, ["A2.*", "A3.jr"], ["min", "max", "final"])
    assert list(reduced)[:3] == ["A2.jx.min", "A2.jx.max", "A2.jx.final"]
    assert any(v < 0 for v in res["A2.jx"])          # the sign that the reduction drops
    for c in ("A2.jx", "A2.jy", "A2.jr", "A3.jr"):
        y = np.abs(res[c])
        assert reduced[f"{c}.min"] == y.min() and reduced[f"{c}.max"] == y.max()
        assert reduced[f"{c}.final"] == y[-1]


# ---- status ------------------------------------------------------------------------------

def test_status_by_the_requirements_a_value_at_a_bound_meets_it():
    """Both bounds are inclusive, as a tolerance's limits are: a part exactly at its limit
    is in tolerance, and max = 12 reads as 'at most 12'."""
    reduced = {"motor.Mz.absmax": 12.0, "B.Fx.min": -3.0}
    assert status(reduced) == "ok"                                     # no requirement
    assert status(reduced, [("motor.Mz.absmax", None, 12.0)]) == "ok"   # at max
    assert status(reduced, [("motor.Mz.absmax", 12.0, None)]) == "ok"   # at min
    assert status(reduced, [("motor.Mz.absmax", 12.0, 12.0)]) == "ok"   # both
    assert status(reduced, [("motor.Mz.absmax", None, np.nextafter(12.0, 0))]) == "rejected"
    assert status(reduced, [("motor.Mz.absmax", np.nextafter(12.0, 13), None)]) == "rejected"
    assert status(reduced, [("motor.Mz.absmax", None, 13.0), ("B.Fx.min", -2.0, None)]) \
        == "rejected"                                                  # one of two fails
    assert status(reduced, [("motor.Mz.absmax", 11.0, 13.0), ("B.Fx.min", -4.0, -3.0)]) \
        == "ok"
    assert status({"B.Fx.min": np.nan}, [("B.Fx.min", None, 1.0)]) == "rejected"


def test_a_requirement_on_an_output_not_reduced_is_a_model_error():
    with pytest.raises(ModelError, match=r"'motor\.Mz\.absmx' is not a reduced output.*"
                                         r"did you mean 'motor\.Mz\.absmax'"):
        status({"motor.Mz.absmax": 1.0}, [("motor.Mz.absmx", None, 2.0)])


def test_the_variant_table_has_the_contracts_columns():
    table = variant_table(["crank.A.x", "coupler.mass"], ["motor.Mz.absmax", "motor.Mz.rms"], [
        Variant(0, "ok", "", (0.1, 2.0), {"motor.Mz.absmax": 3.0, "motor.Mz.rms": 1.5}),
        Variant(1, "error", "AssemblyError: the loop does not close", (0.3, 2.1), None),
        (2, "rejected", "", (0.2, 1.9), {"motor.Mz.rms": 2.5, "motor.Mz.absmax": 4.0})])
    assert list(table) == ["sample", "status", "error", "crank.A.x", "coupler.mass",
                           "motor.Mz.absmax", "motor.Mz.rms"]
    assert table["sample"].dtype == np.int64 and table["sample"].tolist() == [0, 1, 2]
    assert table["status"].tolist() == ["ok", "error", "rejected"]
    assert table["error"].tolist() == ["", "AssemblyError: the loop does not close", ""]
    assert table["coupler.mass"].tolist() == [2.0, 2.1, 1.9]
    np.testing.assert_array_equal(table["motor.Mz.absmax"], [3.0, np.nan, 4.0])
    np.testing.assert_array_equal(table["motor.Mz.rms"], [1.5, np.nan, 2.5])
    empty = variant_table(["p"], ["y.max"], [])
    assert all(len(v) == 0 for v in empty.values()) and list(empty)[-2:] == ["p", "y.max"]


def test_the_examples_in_the_docstrings_run():
    assert doctest.testmod(reduce, optionflags=doctest.ELLIPSIS).failed == 0

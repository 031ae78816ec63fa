"""The statistics of a study over its variants and its yield (pam2exu/studies/summary.py).

References: the Wilson score interval's closed form (Wilson 1927), with z from Python's
``statistics.NormalDist``, not scipy; the sample standard deviation and mean computed by
hand (``math.fsum``); the quantiles by ``numpy.percentile``; the contract's summary file
(shared/spec/studies.md, "Results").
"""
import csv
import doctest
import math
from statistics import NormalDist

import numpy as np
import pytest

from pam2exu.studies import summary as summary_module
from pam2exu.studies.summary import (SUMMARY_COLUMNS, error_groups, summary, summary_lines,
                                     wilson_interval, write_summary)


def _wilson(k: int, n: int, confidence: float = 0.95) -> tuple[float, float]:
    """(p̂ + z²/2n ± z sqrt(p̂(1−p̂)/n + z²/4n²)) / (1 + z²/n)."""
    z = NormalDist().inv_cdf(0.5 + confidence / 2)
    p = k / n
    centre, half = p + z * z / (2 * n), z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
    return (centre - half) / (1 + z * z / n), (centre + half) / (1 + z * z / n)


@pytest.mark.parametrize("k, n", [(0, 1), (1, 1), (0, 20), (20, 20), (7, 10), (993, 1000),
                                  (5000, 10000), (1, 3)])
def test_the_wilson_interval_is_its_closed_form(k, n):
    np.testing.assert_allclose(wilson_interval(k, n), _wilson(k, n), rtol=1e-12, atol=1e-12)


def test_the_yield_of_no_variant_is_unknown():
    assert all(math.isnan(v) for v in wilson_interval(0, 0))
    row = summary({}, [])[-1]
    assert row.output == "yield" and row.count == 0 and math.isnan(row.mean)


@pytest.fixture(scope="module")
def study():
    """Forty variants: 31 ok, 5 rejected, 4 in error (NaN outputs)."""
    rng = np.random.default_rng(2024)
    statuses = np.array(["ok"] * 31 + ["rejected"] * 5 + ["error"] * 4)
    rng.shuffle(statuses)
    columns = {"motor.Mz.absmax": rng.normal(10.0, 0.7, 40),
               "B.Fx.final": rng.normal(-3.0, 2.0, 40), "B.Fx.mean": rng.uniform(-1.0, 1.0, 40)}
    for y in columns.values():
        y[statuses == "error"] = np.nan
    linear = {"B.Fx.final": 1.9375, "B.Fx.mean": 0.5}
    return columns, statuses, linear, summary(columns, statuses, linear)


def test_the_statistics_are_over_the_variants_that_ran(study):
    columns, statuses, linear, rows = study
    assert [r.output for r in rows] == [*columns, "yield"]
    ran = statuses != "error"
    for row in rows[:-1]:
        y = columns[row.output][ran]
        n = len(y)
        mean = math.fsum(y) / n
        std = math.sqrt(math.fsum((v - mean) ** 2 for v in y) / (n - 1))     # ddof = 1
        assert row.count == 36 and row.min == y.min() and row.max == y.max()
        np.testing.assert_allclose([row.mean, row.std], [mean, std], rtol=1e-14)
        np.testing.assert_array_equal([row.q01, row.q05, row.q50, row.q95, row.q99],
                                      np.percentile(y, [1, 5, 50, 95, 99]))
    assert rows[0].q01 < rows[0].q05 < rows[0].q50 < rows[0].q95 < rows[0].q99
    assert math.isnan(rows[0].linear_std)              # absmax: no first-order σ
    assert (rows[1].linear_std, rows[2].linear_std) == (1.9375, 0.5)


def test_the_yield_row_is_the_share_ok_of_every_variant(study):
    *_, rows = study
    row = rows[-1]
    assert (row.output, row.count, row.mean) == ("yield", 40, 31 / 40)
    np.testing.assert_allclose((row.min, row.max), _wilson(31, 40), rtol=1e-12)
    assert all(math.isnan(getattr(row, c)) for c in SUMMARY_COLUMNS[3:] if c not in ("min", "max"))


def test_one_value_has_no_std_and_no_value_no_statistics():
    rows = summary({"y.max": np.array([2.5, np.nan])}, ["ok", "error"])
    assert (rows[0].count, rows[0].mean, rows[0].q99) == (1, 2.5, 2.5)
    assert math.isnan(rows[0].std)
    rows = summary({"y.max": np.array([np.nan])}, ["error"])
    assert rows[0].count == 0 and math.isnan(rows[0].mean) and rows[1].mean == 0.0


def test_the_file_reads_back_bit_for_bit(study, tmp_path):
    *_, rows = study
    extra = summary({"odd,name.max": np.array([0.1 + 0.2, -0.0, 5e-324])}, ["ok"] * 3)
    rows = rows[:-1] + extra
    path = write_summary(rows, tmp_path / "OUT.summary.csv")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["OUT.summary.csv"]
    with open(path, newline="", encoding="utf-8") as fh:
        header, *lines = list(csv.reader(fh))
    assert header == list(SUMMARY_COLUMNS)
    assert [line[0] for line in lines] == [r.output for r in rows]
    for row, line in zip(rows, lines):
        for name, text in zip(SUMMARY_COLUMNS[1:], line[1:]):
            value = float(getattr(row, name))
            if math.isnan(value):
                assert text == "", (row.output, name)       # no value: an empty field
            else:
                back = float(text)
                assert back == value and math.copysign(1, back) == math.copysign(1, value)
    assert lines[-2][0] == "odd,name.max"                     # quoted in the file
    assert (lines[-2][1], lines[-2][4], lines[-2][5]) == ("3", "-0", "3.0000000000000004e-1")
    assert all(line[1].isdigit() for line in lines)           # a count is written as one
    many = summary_lines(summary({"y.max": np.arange(16.0)}, ["ok"] * 16))
    assert many[1].split(",")[1] == "16"                      # not the shortest float 1.6e1


def test_a_failed_write_leaves_no_file(tmp_path, monkeypatch):
    def broken(rows):
        raise OSError("disk full")
    monkeypatch.setattr(summary_module, "summary_lines", broken)
    with pytest.raises(OSError, match="disk full"):
        write_summary(summary({}, ["ok"]), tmp_path / "OUT.summary.csv")
    assert list(tmp_path.iterdir()) == []


def test_the_examples_in_the_docstrings_run():
    assert doctest.testmod(summary_module, optionflags=doctest.ELLIPSIS).failed == 0
    assert summary_lines([]) == [",".join(SUMMARY_COLUMNS)]


def test_the_variants_in_error_are_grouped_by_their_error():
    statuses = ["error", "ok", "error", "rejected", "error", "error", "error"]
    errors = ["AssemblyError: x", "", "SingularPosition: y at 0.5 s", "",
              "SingularPosition: y at 0.25 s", "AssemblyError: x", "ClearanceError: z"]
    found = error_groups(statuses, errors, range(10, 17))
    assert [(g.kind, g.head, g.samples, g.example) for g in found] == [
        ("AssemblyError: x", "AssemblyError: x", (10, 15), "AssemblyError: x"),
        ("SingularPosition: y at … s", "SingularPosition: y at [0.25 … 0.5] s", (12, 14),
         "SingularPosition: y at 0.5 s"),
        ("ClearanceError: z", "ClearanceError: z", (16,), "ClearanceError: z")]
    assert error_groups(["ok"], [""], [0]) == []

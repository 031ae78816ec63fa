"""The statistics of a study over its variants and its yield: ``OUT.summary.csv``.

One row per reduced output over the variants that ran (status ok or rejected; a variant in
error has no values): ``count``, ``mean``, ``std`` (the sample standard deviation, ddof =
1), ``min``, ``max``, the quantiles ``q01`` … ``q99`` (numpy's default, the linear method:
the order statistics interpolated at (n − 1) p) and ``linear_std`` (the first-order σ the
study gives for a ``final`` or a ``mean`` reduction; empty for the others). Then the row
``yield``: ``count`` = every variant, ``mean`` = the share with status ok, ``min`` and
``max`` = its 95 % Wilson score interval (scipy's ``binomtest(...).proportion_ci``).

What a clearance study answers, the clearance a yield needs (``needed_for_yield``): for a
joint's ``jr.max`` the value q such that the share of every variant (those in error
included: no clearance lets them assemble) needing at most q is the yield asked; at 99 %,
the column's q99 when no variant is in error.

A value that does not exist (a std of fewer than two values, the statistics of no value,
the yield row's other fields, ``linear_std`` of another reduction) is NaN in Python and an
empty field in the file.
"""
from __future__ import annotations

from dataclasses import astuple, dataclass, fields
from pathlib import Path

import numpy as np

from ..results.table_csv import csv_cells, csv_field
from ..results.writers import write_whole
from .messages import Group, group
from .reduce import ERROR, OK

#: the quantiles' columns and their probabilities
QUANTILES = {"q01": 0.01, "q05": 0.05, "q50": 0.50, "q95": 0.95, "q99": 0.99}
#: the confidence level of the yield's interval
CONFIDENCE = 0.95
YIELD = "yield"


@dataclass(frozen=True)
class SummaryRow:
    """One row of the summary (NaN: no value; the file leaves it empty)."""

    output: str
    count: int
    mean: float = np.nan
    std: float = np.nan
    min: float = np.nan
    max: float = np.nan
    q01: float = np.nan
    q05: float = np.nan
    q50: float = np.nan
    q95: float = np.nan
    q99: float = np.nan
    linear_std: float = np.nan


#: the summary's header, in the file's order
SUMMARY_COLUMNS = tuple(f.name for f in fields(SummaryRow))


def statistics(output: str, y: np.ndarray, linear_std: float = np.nan) -> SummaryRow:
    """The summary row of one reduced output's values ``y`` over the variants that ran:
    std with ddof = 1 (NaN for fewer than two values), quantiles by ``numpy.quantile``'s
    default linear method, every statistic NaN for no value."""
    y = np.asarray(y, dtype=float)
    if y.size == 0:
        return SummaryRow(output, 0, linear_std=linear_std)
    std = float(np.std(y, ddof=1)) if y.size > 1 else np.nan
    q = np.quantile(y, list(QUANTILES.values()))
    return SummaryRow(output, int(y.size), float(np.mean(y)), std, float(np.min(y)),
                      float(np.max(y)), *map(float, q), linear_std=linear_std)


def wilson_interval(k: int, n: int, confidence: float = CONFIDENCE) -> tuple[float, float]:
    """The Wilson score interval of a share k/n at ``confidence`` (scipy's
    ``binomtest(k, n).proportion_ci(method="wilson")``); (NaN, NaN) for n = 0."""
    if n == 0:
        return np.nan, np.nan
    from scipy.stats import binomtest
    ci = binomtest(k, n).proportion_ci(confidence_level=confidence, method="wilson")
    return float(ci.low), float(ci.high)


#: the yield a clearance study's report gives each joint's radial clearance for
CLEARANCE_YIELD = 0.99


def needed_for_yield(y, statuses, share: float = CLEARANCE_YIELD) -> float:
    """The least value a bound ``max`` must allow for the share ``share`` of every variant:
    the quantile of y at ``share`` (numpy's linear method, as the summary's q99) over all
    the variants, one in error counted as +inf (no bound lets it pass); +inf when those in
    error reach into the quantile, NaN for no variant.

    Examples
    --------
    >>> needed_for_yield([1.0, 2.0, np.nan], ["ok", "ok", "error"], 0.5)
    2.0
    >>> needed_for_yield([1.0, 2.0, np.nan], ["ok", "ok", "error"], 0.99)
    inf
    """
    statuses = np.asarray(statuses, dtype=str)
    y = np.asarray(y, dtype=float)
    if y.size == 0:
        return np.nan
    failed = statuses == ERROR
    ordered = np.sort(np.where(failed, np.inf, y))
    if not np.isfinite(ordered[int(np.ceil((y.size - 1) * share))]):
        return np.inf
    # the quantile reads only the order statistics either side of (n − 1) share, both
    # finite: those in error, above them, may stand at any larger value
    return float(np.quantile(np.where(failed, np.max(y[~failed]), y), share))


def yield_row(statuses) -> SummaryRow:
    """The row ``yield``: count = the variants, mean = the share with status ok, min, max =
    its 95 % Wilson interval (``wilson_interval``)."""
    statuses = np.asarray(statuses, dtype=str)
    n, k = statuses.size, int(np.count_nonzero(statuses == OK))
    low, high = wilson_interval(k, n)
    return SummaryRow(YIELD, n, k / n if n else np.nan, min=low, max=high)


def summary(columns: dict[str, np.ndarray], statuses, linear_std=None) -> list[SummaryRow]:
    """The summary of a study: one row per reduced output, then the yield.

    Parameters
    ----------
    columns : dict
        Reduced output name (``motor.Mz.absmax``) → its values over every variant, in
        variant order (NaN for a variant in error: ``reduce.variant_table``'s columns).
    statuses : sequence of str
        Every variant's status ('ok', 'rejected' or 'error'), in the same order.
    linear_std : dict, optional
        Reduced output name → its first-order σ (for the ``final`` and ``mean``
        reductions); the others' ``linear_std`` is NaN.

    Returns
    -------
    list of SummaryRow
        The outputs' rows over the variants with status ok or rejected, in the order of
        ``columns``, then the row ``yield``.

    Examples
    --------
    >>> rows = summary({"B.Fx.max": np.array([1.0, 3.0, np.nan])}, ["ok", "rejected", "error"])
    >>> rows[0].count, rows[0].mean, rows[0].q50, rows[1].output, rows[1].count, rows[1].mean
    (2, 2.0, 2.0, 'yield', 3, 0.3333333333333333)
    """
    statuses = np.asarray(statuses, dtype=str)
    ran = statuses != ERROR
    linear_std = linear_std or {}
    rows = [statistics(name, np.asarray(y, dtype=float)[ran], linear_std.get(name, np.nan))
            for name, y in columns.items()]
    return rows + [yield_row(statuses)]


def summary_lines(rows: list[SummaryRow]) -> list[str]:
    """The summary's CSV lines (no line ends): the header, then one line per row, each
    number in the shortest digits that read back bit for bit (``table_csv.csv_block``), a
    NaN as an empty field, the count as a whole number."""
    lines = [",".join(SUMMARY_COLUMNS)]
    if not rows:
        return lines
    numbers = np.array([astuple(r)[1:] for r in rows], dtype=float)
    for row, cells in zip(rows, csv_cells(numbers)):
        cells[0] = str(int(row.count))                   # a count, written as one
        lines.append(",".join([csv_field(row.output), *cells]))
    return lines


def write_summary(rows: list[SummaryRow], path: str | Path) -> Path:
    """Write the summary as CSV at ``path`` (``summary_lines``), under a temporary name
    then renamed: a failure leaves neither half a file nor the temporary one."""
    return write_whole(Path(path), lambda tmp: tmp.write_text(
        "\n".join(summary_lines(rows)) + "\n", encoding="utf-8"))


def error_groups(statuses, errors, samples) -> list[Group]:
    """The variants in error grouped by the kind of their error (``messages.group``: the
    head of the message, its numbers masked), the most frequent kind first (ties: the one
    met first), samples in variant order.

    Examples
    --------
    >>> found = error_groups(["ok", "error", "error", "error"],
    ...                      ["", "E: b", "E: a at 0.1 s", "E: a at 0.3 s"], [0, 1, 2, 3])
    >>> [(g.head, g.samples) for g in found]
    [('E: a at [0.1 … 0.3] s', (2, 3)), ('E: b', (1,))]
    """
    return group((i, str(e)) for s, e, i in zip(statuses, errors, samples) if s == ERROR)

"""A study's result: the per-variant table, the summary and the yield, the series table
of a study that keeps it (``series.py``), their files (``OUT.parquet`` or ``OUT.csv``,
``OUT.summary.csv`` and ``OUT.series.parquet`` or ``OUT.series.csv`` beside it), the
printed report and the pictures (``plots.py``).

The per-variant table has one row per variant in variant order: ``sample`` (int64),
``status`` (ok, rejected, error), ``error`` (the error's class and message, '' unless in
error), each parameter's value, each reduced output (float64; NaN for a variant in error).
Its files read back bit for bit: Parquet's float64 columns as they are, CSV's numbers in
the shortest digits that read back exactly (``results.table_csv.csv_block``), a NaN as an
empty field. Each file is written under a temporary name then renamed.
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import NamedTuple

import numpy as np

from ..errors import OutputError, PictureError
from ..results.table_csv import csv_cells, csv_field
from ..results.writers import optional, write_whole
from . import plots
from .reduce import ERROR, OK, REJECTED, radial_clearances
from .messages import WARNINGS, Group, report_lines, warning_groups
from .series import series_path, write_csv
from .summary import CLEARANCE_YIELD, error_groups, needed_for_yield, summary, write_summary

#: the per-variant table's file formats, by suffix
STUDY_FORMATS = {".parquet": "Parquet", ".csv": "CSV"}
#: the summary's columns the printed report shows
SHOWN = ("count", "mean", "std", "min", "q05", "q50", "q95", "max")
#: the variants of a grid study the printed report lists (a sweep's result is its rows)
GRID_SHOWN = 50


class Yield(NamedTuple):
    """The share of the variants with status ok and its 95 % Wilson interval."""

    share: float
    low: float
    high: float
    ok: int
    count: int


def summary_path(out: str | Path) -> Path:
    """``OUT.summary.csv`` beside ``OUT.parquet`` (or ``OUT.csv``)."""
    out = Path(out)
    return out.with_name(out.stem + ".summary.csv")


def check_out(out: str | Path) -> Path:
    """The per-variant table's path, checked before anything runs: a known suffix, its
    library installed (``OutputError`` otherwise)."""
    out = Path(out)
    suffix = out.suffix.lower()
    if suffix not in STUDY_FORMATS:
        raise OutputError(f"{out}: a study writes its table as "
                          f"{' or '.join(STUDY_FORMATS)} (the format from the suffix), not "
                          f"'{out.suffix or 'no suffix'}'")
    if suffix == ".parquet":
        optional("pyarrow.parquet", "a Parquet file")
    if not out.parent.is_dir():
        raise OutputError(f"{out}: the folder '{out.parent}' does not exist")
    return out


class StudyResult:
    """The result of ``pam2exu.study``.

    Parameters
    ----------
    study : Study
        The study as it ran.
    table : dict of str to numpy.ndarray
        The per-variant columns (``runner.run_variants``, merged in variant order).
    outputs : list of str
        The reduced outputs' names, in the table's order.
    units : dict of str to str
        Each reduced output's unit (and each series output's, with ``series``).
    series : dict of str to numpy.ndarray, optional
        The series table in long format (``series.long_table``), for ``series = true``.
    sensitivities : linear.Sensitivities, optional
        ∂y/∂p at the nominal variant: the summary's ``linear_std`` of the ``final`` and
        ``mean`` reductions, and the tornado plots.
    note : str
        Why the linear σ is not given, when it is not ('' otherwise), for the report.

    Attributes
    ----------
    study : Study
        The study as it ran.
    table : dict of str to numpy.ndarray
        The per-variant columns: ``sample``, ``status``, ``error``, each parameter, each
        reduced output, in variant order.
    parameters, outputs : list of str
        The parameters' and the reduced outputs' column names.
    units : dict of str to str
        Each parameter's, reduced output's and series output's unit (SI; a parameter's in
        the model's).
    summary : list of SummaryRow
        One row per reduced output over the variants that ran, then the row ``yield``.
    warnings : numpy.ndarray of str
        Each variant's warnings, in variant order: one line each, '<class>: <first line of
        the message>', one per kind (``messages.kind``); '' for none. Not a column of the
        table or its files (a chunk's ``messages.WARNINGS`` column, taken out here).
    series : dict of str to numpy.ndarray or None
        With ``series = true``: every variant's time series in long format, ``sample``,
        ``t``, each output (``motor.Mz``), the rows of the variants that ran (status ok or
        rejected) in variant order; a variant in error has no rows. None otherwise.
    """

    #: what a row of the table is, for messages
    ROWS = "variants"

    def __init__(self, study, table: dict, outputs: list[str], units: dict[str, str],
                 series: dict | None = None, sensitivities=None, note: str = ""):
        self.study, self.note, self.sensitivities = study, note, sensitivities
        self.warnings = table.pop(WARNINGS, None)
        self.table = table
        if self.warnings is None:
            self.warnings = np.full(len(table["sample"]), "")
        self.parameters = list(study.names)
        self.outputs = list(outputs)
        self.units = {**{p.name: p.unit for p in study.parameters}, **units}
        if series is not None:
            self.units["t"] = "s"
        self.series = series
        self.summary = summary({n: table[n] for n in self.outputs}, table["status"],
                               sensitivities and sensitivities.linear_std(self.outputs))

    def __len__(self) -> int:
        return len(self.table["sample"])

    def __repr__(self) -> str:
        return (f"<StudyResult {self.study.analysis} of '{self.study.model_path}': "
                f"{len(self)} variants, yield {self.yield_.share:.4g}>")

    @property
    def yield_(self) -> Yield:
        """The share of the variants with status ok, with its 95 % Wilson interval."""
        row = self.summary[-1]
        ok = int(np.count_nonzero(self.table["status"] == OK))
        return Yield(row.mean, row.min, row.max, ok, row.count)

    def clearance_needed(self, share: float = CLEARANCE_YIELD) -> dict[str, float]:
        """The radial clearance each joint needs for the yield ``share`` (a clearance study).

        Parameters
        ----------
        share : float
            The yield [–], 0 … 1.

        Returns
        -------
        dict of str to float
            ``<joint>.jr.max`` → its quantile at ``share`` over every variant, one in error
            counted as needing more than any (``summary.needed_for_yield``; +inf when those
            in error reach into it) [m]; empty for a study without radial clearances.
        """
        t = self.table
        return {name: needed_for_yield(t[name], t["status"], share)
                for name in radial_clearances(self.outputs)}

    def errors(self) -> list[Group]:
        """The variants in error grouped by the kind of their error
        (``summary.error_groups``)."""
        t = self.table
        return error_groups(t["status"], t["error"], t["sample"])

    def warning_groups(self) -> list[Group]:
        """The variants that warned grouped by the kind of their warning
        (``messages.warning_groups``); a variant may be in several groups."""
        return warning_groups(self.warnings, self.table["sample"])

    def to_pandas(self, series: bool = False):
        """The per-variant table (or the series table) as a pandas DataFrame (copies, bit
        for bit); ``attrs`` holds ``units``. Needs pandas (``pip install "pam2exu[pandas]"``).

        Parameters
        ----------
        series : bool
            The series table (``series = true``) instead of the per-variant table.
        """
        pd = optional("pandas", "a DataFrame")
        columns = self._series("to_pandas(series=True)") if series else self.table
        df = pd.DataFrame({n: np.array(c, copy=True) for n, c in columns.items()})
        df.attrs["units"] = {n: self.units.get(n, "") for n in columns if n in self.units}
        return df

    def _series(self, asked: str) -> dict:
        """The series table, or PictureError naming what asked for it."""
        if self.series is None:
            raise PictureError(f"{asked} needs the series table: set series = true in "
                               f"the [study] table of {self.study.source}")
        return self.series

    def hist(self, output: str, ax=None):
        """The histogram of a reduced output over the variants that ran, with its
        requirements' limits (``plots.hist``); returns the matplotlib Axes.

        Parameters
        ----------
        output : str
            A reduced output (``motor.Mz.absmax``).
        ax : matplotlib.axes.Axes, optional
            Where to draw; default a new figure on the Agg canvas.
        """
        return plots.hist(self, output, ax)

    def band(self, output: str, ax=None):
        """The 1, 5, 50, 95 and 99 % percentiles of an output's series over t
        (``plots.band``; needs ``series = true``); returns the matplotlib Axes.

        Parameters
        ----------
        output : str
            An output whose series the study keeps (``motor.Mz``).
        ax : matplotlib.axes.Axes, optional
            Where to draw; default a new figure on the Agg canvas.
        """
        return plots.band(self, output, ax)

    def scatter(self, output: str, parameter: str, ax=None):
        """A reduced output against a parameter, a point per variant that ran
        (``plots.scatter``); returns the matplotlib Axes.

        Parameters
        ----------
        output : str
            A reduced output (``motor.Mz.absmax``).
        parameter : str
            A parameter of the study (``crank.A.x``).
        ax : matplotlib.axes.Axes, optional
            Where to draw; default a new figure on the Agg canvas.
        """
        return plots.scatter(self, output, parameter, ax)

    def tornado(self, output: str, ax=None):
        """The tornado of a reduced output (``motor.Mz.final``): each parameter's
        first-order contribution ∂y_r/∂p · σ_p at the nominal variant, the largest on top
        (``plots.sensitivity_tornado``); returns the matplotlib Axes. PictureError when the
        study has no sensitivities (``pam2exu.study(..., first_order=True)`` computes them).

        Parameters
        ----------
        output : str
            A reduced output (``motor.Mz.absmax``).
        ax : matplotlib.axes.Axes, optional
            Where to draw; default a new figure on the Agg canvas.
        """
        if self.sensitivities is None:
            raise PictureError(f"tornado '{output}': the study has no sensitivities ("
                               f"{self.note or 'none were asked for'}); ask for them with "
                               "--tornado or pam2exu.study(..., first_order=True)")
        return plots.sensitivity_tornado(self.sensitivities, output, ax)

    def to_parquet(self, path: str | Path) -> Path:
        """Write the per-variant table as Parquet (float64 columns bit for bit, each
        column's unit in its field's metadata), under a temporary name then renamed.
        Needs pyarrow (``pip install "pam2exu[parquet]"``).

        Parameters
        ----------
        path : str or Path
            The file to write (replaced if it exists).
        """
        return write_parquet(self.table, self.units, path)

    def to_csv(self, path: str | Path) -> Path:
        """Write the per-variant table as CSV: a header of the column names, then one line
        per variant; numbers in the shortest digits that read back exactly, NaN empty, an
        error quoted when it holds a separator, a quote or a line break; under a temporary
        name then renamed.

        Parameters
        ----------
        path : str or Path
            The file to write (replaced if it exists).
        """
        path = Path(path)
        names = list(self.table)
        numbers = np.column_stack([self.table[n] for n in names[3:]]).astype(float)
        lines = [",".join(csv_field(n) for n in names)]
        t = self.table
        for k, cells in enumerate(csv_cells(numbers)):
            lines.append(",".join([str(int(t["sample"][k])), str(t["status"][k]),
                                   csv_field(str(t["error"][k])), *cells]))
        body = ("\n".join(lines) + "\n").encode("utf-8")
        return write_whole(path, lambda tmp: tmp.write_bytes(body))

    def series_to_parquet(self, path: str | Path) -> Path:
        """Write the series table as Parquet (as ``to_parquet``; needs ``series = true``).

        Parameters
        ----------
        path : str or Path
            The file to write (replaced if it exists).
        """
        return write_parquet(self._series("series_to_parquet"), self.units, path)

    def series_to_csv(self, path: str | Path) -> Path:
        """Write the series table as CSV (``series.write_csv``; needs ``series = true``).

        Parameters
        ----------
        path : str or Path
            The file to write (replaced if it exists).
        """
        return write_csv(self._series("series_to_csv"), path)

    def write(self, out: str | Path) -> tuple[Path, ...]:
        """Write ``OUT.parquet`` or ``OUT.csv`` (by suffix), ``OUT.summary.csv`` and, with
        the series table, ``OUT.series.parquet`` or ``OUT.series.csv``.

        Parameters
        ----------
        out : str or Path
            The per-variant table's file (``check_out``).

        Returns
        -------
        tuple of Path
            The files written: the table, the summary (then the series).
        """
        out = check_out(out)
        parquet = out.suffix.lower() == ".parquet"
        written = (self.to_parquet(out) if parquet else self.to_csv(out),
                   write_summary(self.summary, summary_path(out)))
        if self.series is not None:
            path = series_path(out)
            written += (self.series_to_parquet(path) if parquet else self.series_to_csv(path),)
        return written

    def report(self) -> str:
        """The printed form: the summary table, the yield, the variants in error and those
        that warned, grouped by the kind of their message (``messages.report_lines``); for a
        grid study, then its variants (``grid_lines``)."""
        s = self.study
        lines = [f"study of {os.path.normpath(s.model_path)}: {s.analysis}, {len(self)} variants "
                 f"({s.method}{f', seed {s.seed}' if s.method != 'grid' else ''}), "
                 f"{s.steps} steps to t = {s.t_end:.6g} s"]
        width = max([len("output"), *(len(r.output) for r in self.summary[:-1])])
        shown = SHOWN + (("linear_std",) if any(not np.isnan(r.linear_std)
                                                for r in self.summary[:-1]) else ())
        lines.append("  ".join([f"{'output':<{width}}", *(f"{c:>11}" for c in shown)]))
        for row in self.summary[:-1]:
            cells = [f"{row.count:>11d}", *(_number(getattr(row, c)) for c in shown[1:])]
            lines.append("  ".join([f"{row.output:<{width}}", *cells]).rstrip())
        if self.note:
            lines.append(self.note)
        y = self.yield_
        lines.append(f"yield: {y.share:.4g} ({y.ok} of {y.count} variants ok), 95 % Wilson "
                     f"interval {y.low:.4g} … {y.high:.4g}")
        rejected = int(np.count_nonzero(self.table["status"] == REJECTED))
        failed = int(np.count_nonzero(self.table["status"] == ERROR))
        lines.append(f"rejected by the requirements: {rejected}; in error: {failed}")
        lines += _clearance_lines(self.clearance_needed(), len(self), failed)
        lines += report_lines(self.errors(), "errors")
        warned = int(np.count_nonzero(self.warnings != ""))
        if warned:
            lines.append(f"variants that warned: {warned} of {len(self)}")
            lines += report_lines(self.warning_groups(), "warnings")
        if s.method == "grid":
            lines += grid_lines(self.table, self.parameters + self.outputs)
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.report()


def write_parquet(columns: dict, units: dict, path: str | Path) -> Path:
    """Write NumPy columns as Parquet: ``sample`` int64, strings as strings, the others
    float64 bit for bit, each column's unit in its field's metadata; under a temporary name
    then renamed. Needs pyarrow (``pip install "pam2exu[parquet]"``)."""
    pa = optional("pyarrow", "a Parquet file")
    parquet = optional("pyarrow.parquet", "a Parquet file")
    arrays, fields = [], []
    for name, column in columns.items():
        kind = {"sample": pa.int64()}.get(name, pa.string() if column.dtype.kind == "U"
                                           else pa.float64())
        arrays.append(pa.array(column.tolist() if column.dtype.kind == "U" else column,
                               type=kind))
        fields.append(pa.field(name, kind, metadata={"unit": units.get(name, "")}))
    table = pa.Table.from_arrays(arrays, schema=pa.schema(fields))
    return write_whole(Path(path), lambda tmp: parquet.write_table(table, tmp))


def _clearance_lines(needed: dict[str, float], count: int, failed: int) -> list[str]:
    """The report's lines of a clearance study: the radial clearance each joint needs for a
    99 % yield (``StudyResult.clearance_needed``)."""
    head = f"radial clearance for a {CLEARANCE_YIELD * 100:.0f} % yield:"
    over = (f"its q{CLEARANCE_YIELD * 100:.0f} over the {count} variants" if not failed else
            f"over all {count} variants, the {failed} in error counted as needing more")
    out = []
    for name, value in needed.items():
        joint = name.rsplit(".", 2)[0]
        out.append(f"{head} {joint} needs {value:.4g} m ({name}, {over})"
                   if np.isfinite(value) else
                   f"{head} none is enough for {joint}: {failed} of {count} variants are in "
                   f"error, and the q{CLEARANCE_YIELD * 100:.0f} over all of them falls among "
                   f"those")
    return out


def grid_lines(table: dict, columns: list[str], shown: int = GRID_SHOWN) -> list[str]:
    """A grid study's variants, one line each (the first ``shown``): sample, status, the
    parameters' values and the reduced outputs (empty for a variant in error)."""
    widths = [max(11, len(c)) for c in columns]
    lines = ["  ".join(["sample", f"{'status':<8}", *(f"{c:>{w}}" for c, w in zip(columns,
                                                                                 widths))])]
    n = len(table["sample"])
    for i in range(min(n, shown)):
        cells = [_number(float(table[c][i])).rjust(w) for c, w in zip(columns, widths)]
        lines.append("  ".join([f"{table['sample'][i]:>6d}", f"{table['status'][i]:<8}",
                                *cells]).rstrip())
    if n > shown:
        lines.append(f"… and the other {n - shown} of the {n} variants (-o OUT writes them all)")
    return lines


def _number(x: float) -> str:
    """A statistic in 11 characters (an empty field for NaN)."""
    return f"{'':>11}" if np.isnan(x) else f"{x:>11.5g}"


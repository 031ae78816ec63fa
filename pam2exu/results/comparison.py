"""The comparison table ``compare`` returns: one row per variable, its text and CSV forms.

``Comparison.to_markdown()`` is what ``pam2exu compare`` prints; ``Comparison.to_csv()`` the
same rows at full precision. The rule and the reading of the tables are in ``compare``; the
user guide is docs/compare.md.
"""
from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import closest
from .names import listing


@dataclass(frozen=True)
class VariableComparison:
    """One variable found in both tables, over the reference rows compared.

    A row of ``Comparison.rows`` (``comparison["crank.fi"]``). Errors, scale and tolerance
    are in the variable's SI unit [unit].

    Attributes
    ----------
    name : str
        The variable (pam2exu's spelling).
    max_abs_error : float
        max_k |result(t_k) − reference(t_k)| [unit]; inf when one table only has a
        non-finite value at some t_k. For an angle compared modulo 2π, the difference is
        first reduced to (−π, π].
    max_rel_error : float
        max_abs_error / scale [–]; nan when scale ≤ atol (a reference zero to within
        atol: a column of zeros and round-off).
    t_at_max : float
        First reference time of the maximum [s]; nan when there is no error.
    scale : float
        max_k |reference(t_k)| over its finite values [unit]; π for an angle compared
        modulo 2π (the largest difference on the circle).
    tolerance : float
        atol + rtol · scale [unit].
    passed : bool
        max_abs_error ≤ tolerance.
    interpolation_error : float
        Estimate of the interpolation's own error [unit]; nan when the times are the same
        or the result has fewer than 7 rows.
    unit : str
        The SI unit, from the Results tables ('' when both are CSV files).
    """

    name: str
    max_abs_error: float        # max_k |result(t_k) - reference(t_k)|
    max_rel_error: float        # max_abs_error / scale; nan when scale <= atol
    t_at_max: float             # first reference time of the maximum [s]; nan when no error
    scale: float                # max_k |reference(t_k)|
    tolerance: float            # atol + rtol * scale
    passed: bool                # max_abs_error <= tolerance
    interpolation_error: float  # bound of the interpolation's own error; nan if none
    unit: str = ""


@dataclass
class Comparison:
    """The comparison table: one row per common variable, and the variables of one table only.

    What ``compare`` returns. ``passed`` is True when every common variable is within its
    tolerance (variables found in one table only do not count). ``str(comparison)`` is
    ``to_markdown()``; ``comparison["crank.fi"]`` is the row of one variable (KeyError when
    it was not compared).

    Attributes
    ----------
    rows : list of VariableComparison
        One per variable in both tables, in the result's column order.
    only_in_result, only_in_reference : list of str
        Variables found in one table only (not compared).
    result, reference : str
        How each table was given: its path, or a description of a Results table.
    rtol : float
        Relative tolerance [–].
    atol : float
        Absolute tolerance [SI unit of each variable].
    result_rows, reference_rows : int
        Number of rows of each table.
    rows_compared : int
        Reference rows inside the result's time interval (all when the times are equal).
    method : str or None
        ``'cubic'`` or ``'linear'``: how the result was interpolated onto the reference
        times; None when the times are equal (compared row by row).
    overlap : (float, float)
        The time interval compared [s].
    notes : list of str
        What was done to read the tables: renamed columns, separators, encodings, unused
        names-map entries, angles not wrapped.
    time_digits : str
        When the rows were matched to the precision a file's times carry (not to float
        round-off): what they carry, e.g. ``'6 significant digits the reference carries'``;
        else ''.
    time_difference : float
        max |t_result − t_reference| over the rows matched [s]; 0 when interpolated.
    wrapped : list of str
        The angles [rad] compared modulo 2π (``wrap_angles=True``).
    rule : str
        The pass rule's line of the header when the tolerances are not one rtol and atol
        (``pam2exu verify``: one per variable, in the rows' ``tolerance``); '' for the rule
        atol + rtol · scale.

    Examples
    --------
    >>> from pam2exu.results import Results, compare
    >>> a = Results([0.0, 1.0], {"crank.fi": [0.0, 6.0], "B.Fx": [1.0, 2.0]})
    >>> b = Results([0.0, 1.0], {"crank.fi": [0.0, 6.0 + 1e-7]})
    >>> c = compare(a, b, rtol=1e-6)
    >>> c.passed, c.only_in_result, c["crank.fi"].max_abs_error < 2e-7
    (True, ['B.Fx'], True)
    >>> print(c.verdict())
    PASS: all 1 common variables within the tolerance
    """

    rows: list[VariableComparison]
    only_in_result: list[str]
    only_in_reference: list[str]
    result: str                         # how the result was given (path or description)
    reference: str
    rtol: float
    atol: float
    result_rows: int
    reference_rows: int
    rows_compared: int                  # reference rows inside the overlap
    method: str | None                  # interpolation method, None when the times are equal
    overlap: tuple[float, float]        # [s]
    notes: list[str] = field(default_factory=list)
    time_digits: str = ""               # what the times carry when matched to it
    time_difference: float = 0.0        # max |t_result - t_reference| of the rows matched [s]
    wrapped: list[str] = field(default_factory=list)    # angles compared modulo 2π
    rule: str = ""                      # the rule's line when not atol + rtol·scale

    @property
    def passed(self) -> bool:
        """Every common variable within atol + rtol·scale."""
        return all(r.passed for r in self.rows)

    @property
    def failed(self) -> list[str]:
        """Names of the variables outside the tolerance."""
        return [r.name for r in self.rows if not r.passed]

    @property
    def rows_outside(self) -> int:
        """Reference rows outside the result's time interval (not compared)."""
        return self.reference_rows - self.rows_compared

    def __getitem__(self, name: str) -> VariableComparison:
        """The row of variable ``name``; KeyError (suggesting the nearest) if not compared."""
        for r in self.rows:
            if r.name == name:
                return r
        raise KeyError(f"'{name}' is not compared{closest(name, [r.name for r in self.rows])}")

    def header(self) -> list[str]:
        """The lines above the table: the two tables, how times were matched, the rule, notes.

        Returns
        -------
        list of str
            One line each: the result, the reference, how the times were matched, the
            pass rule with rtol and atol (or ``rule``), the angles compared modulo 2π, then the ``notes``.
        """
        lo, hi = self.overlap
        if self.method is None and self.time_digits:
            times = (f"times matched row by row to the {self.time_digits}: the same "
                     f"{self.reference_rows} times to within half a unit of the last digit "
                     f"(largest difference {self.time_difference:.3g} s; "
                     f"t = {lo:g} … {hi:g} s)")
        elif self.method is None:
            times = (f"times: the same {self.reference_rows} times in both, "
                     f"compared row by row (t = {lo:g} … {hi:g} s)")
        else:
            kind = "not-a-knot cubic spline" if self.method == "cubic" else "linear"
            times = (f"times differ: the result is interpolated onto the reference times "
                     f"({kind}) within t = {lo:g} … {hi:g} s; {self.rows_compared} of "
                     f"{self.reference_rows} reference rows compared, {self.rows_outside} "
                     f"outside that interval (not compared); 'interp. error' bounds the "
                     f"interpolation's own error")
        return [f"result: {self.result} ({self.result_rows} rows)",
                f"reference: {self.reference} ({self.reference_rows} rows)",
                times,
                self.rule or
                (f"rule: a variable passes when max |result − reference| ≤ atol + rtol·scale, "
                 f"scale = max |reference| (rtol = {self.rtol:g}, atol = {self.atol:g})"),
                *([f"angles compared modulo 2π (the difference reduced to (−π, π], scale π): "
                   f"{listing(self.wrapped)}"] if self.wrapped else []),
                *self.notes]

    def verdict(self) -> str:
        """One line: PASS or FAIL, with the failing variables.

        Returns
        -------
        str
            ``PASS: all n common variables within the tolerance`` or ``FAIL: k of n common
            variables outside the tolerance: …`` (at most 20 names).
        """
        n = len(self.rows)
        if self.passed:
            return f"PASS: all {n} common variables within the tolerance"
        bad = self.failed
        return f"FAIL: {len(bad)} of {n} common variables outside the tolerance: " \
               + listing(bad, 20)

    def to_markdown(self) -> str:
        """Header as a bullet list, the table, the variables of one table only, the verdict.

        What ``pam2exu compare`` prints. Numbers have 3 significant digits (t 6), '–' where
        a number does not apply; a unit column when some variable has a unit, an
        ``interp. error`` column when the result was interpolated.

        Returns
        -------
        str
            Markdown text.
        """
        cols = ["variable", "max abs error", "max rel error", "at t [s]", "scale", "tolerance"]
        cols += ["interp. error"] if self.method else []
        units = any(r.unit for r in self.rows)
        cols = cols[:1] + (["unit"] if units else []) + cols[1:] + ["verdict"]
        lines = [f"- {h}" for h in self.header()] + [""]
        lines += ["| " + " | ".join(cols) + " |",
                  "|" + "|".join(["---"] + ["---"] * units + ["---:"] * (len(cols) - 2 - units)
                                 + ["---"]) + "|"]
        for r in self.rows:
            cells = [r.name] + ([r.unit] if units else [])
            cells += [_fmt(r.max_abs_error), _fmt(r.max_rel_error), _fmt(r.t_at_max, ".6g"),
                      _fmt(r.scale), _fmt(r.tolerance)]
            cells += [_fmt(r.interpolation_error)] if self.method else []
            lines.append("| " + " | ".join(cells + ["pass" if r.passed else "FAIL"]) + " |")
        lines.append("")
        for where, names in (("result", self.only_in_result),
                             ("reference", self.only_in_reference)):
            if names:
                lines += [f"only in the {where} ({len(names)}, not compared): "
                          + ", ".join(names), ""]
        lines.append(self.verdict())
        return "\n".join(lines)

    def to_csv(self, path: str | Path | None = None) -> str | Path:
        """CSV text, one line per variable, full precision; written to ``path`` when given.

        Header ``variable,unit,verdict,max_abs_error,max_rel_error,t_at_max,scale,tolerance,
        interpolation_error``; verdict is pass, fail, only in result or only in reference;
        a number that does not apply is empty. Errors, scale and tolerance are in the
        variable's SI unit, t_at_max in s.

        Parameters
        ----------
        path : str or Path, optional
            The CSV file to write (UTF-8); None returns the text instead.

        Returns
        -------
        str or Path
            The CSV text when ``path`` is None, else ``path``.

        Raises
        ------
        OSError
            The file cannot be written.
        """
        out = io.StringIO()
        w = csv.writer(out, lineterminator="\n")
        w.writerow(["variable", "unit", "verdict", "max_abs_error", "max_rel_error",
                    "t_at_max", "scale", "tolerance", "interpolation_error"])
        for r in self.rows:
            w.writerow([r.name, r.unit, "pass" if r.passed else "fail"]
                       + [_num(v) for v in (r.max_abs_error, r.max_rel_error, r.t_at_max,
                                            r.scale, r.tolerance, r.interpolation_error)])
        for where, names in (("result", self.only_in_result),
                             ("reference", self.only_in_reference)):
            for name in names:
                w.writerow([name, "", f"only in {where}"] + [""] * 6)
        if path is None:
            return out.getvalue()
        path = Path(path)
        path.write_text(out.getvalue(), encoding="utf-8")
        return path

    def __str__(self) -> str:
        return self.to_markdown()


def _fmt(x: float, spec: str = ".3g") -> str:
    """A number for the table; '–' for nan (does not apply)."""
    return "–" if math.isnan(x) else format(x, spec)


def _num(x: float) -> str:
    """A number for CSV at full precision; empty for nan."""
    return "" if math.isnan(x) else repr(float(x))

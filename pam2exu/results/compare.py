"""Compare a result table with a reference, variable by variable (``pam2exu compare``).

For every variable in both tables, over the reference rows compared:

    error(t_k) = |result(t_k) - reference(t_k)|
    scale      = max_k |reference(t_k)|
    passes when  max_k error(t_k) <= atol + rtol * scale

Rows are matched by ``t``, to the precision each file's time column carries (a time written
0.00277778 matches 1/360). When the two tables have different times, the result is
interpolated onto the reference times (cubic spline by default) inside the result's time
interval; reference rows outside it are counted and left out. With ``wrap_angles``, angles
[rad] are compared modulo 2π (exports that wrap them at ±π). Column names are brought to
pam2exu's spelling first: the reference's by a names map (PAM name -> pam2exu name), then
both tables' by ``SPELLINGS``.
The user guide is docs/compare.md.
"""
from __future__ import annotations

import csv
import io
import math
import re
import unicodedata
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import CompareInputError, ModelError, closest
from .table import Results, select_columns

RTOL = 1e-9
ATOL = 1e-12
METHODS = ("cubic", "linear")
# PAM spellings of variable names -> pam2exu's (applied to the part after the last dot)
SPELLINGS = {"Forca": "Força", "f": "f(t)", "Df": "Df(t)"}
MAP_HEADER = ("pam_name", "pam2exu_name")
_SHOWN = 8                  # names listed in a note before "… and n more"


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
        max_abs_error / scale [–]; nan when scale == 0.
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
    max_rel_error: float        # max_abs_error / scale; nan when scale == 0
    t_at_max: float             # first reference time of the maximum [s]; nan when no error
    scale: float                # max_k |reference(t_k)|
    tolerance: float            # atol + rtol * scale
    passed: bool                # max_abs_error <= tolerance
    interpolation_error: float  # estimate of the interpolation's own error; nan if none
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
            pass rule with rtol and atol, the angles compared modulo 2π, then the ``notes``.
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
                     f"outside that interval (not compared); 'interp. error' estimates the "
                     f"interpolation's own error")
        return [f"result: {self.result} ({self.result_rows} rows)",
                f"reference: {self.reference} ({self.reference_rows} rows)",
                times,
                (f"rule: a variable passes when max |result − reference| ≤ atol + rtol·scale, "
                 f"scale = max |reference| (rtol = {self.rtol:g}, atol = {self.atol:g})"),
                *([f"angles compared modulo 2π (the difference reduced to (−π, π], scale π): "
                   f"{_listing(self.wrapped)}"] if self.wrapped else []),
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
               + _listing(bad, 20)

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


def _listing(names, n: int = _SHOWN) -> str:
    """'a, b, c' with at most n names, then '… and k more'."""
    names = list(names)
    more = f", … and {len(names) - n} more" if len(names) > n else ""
    return ", ".join(names[:n]) + more


# --- the pure parts: names, errors, interpolation ------------------------------------------

def tolerance(scale: float, rtol: float = RTOL, atol: float = ATOL) -> float:
    """Allowed maximum error of a variable: atol + rtol · scale."""
    return atol + rtol * scale


def abs_error(result: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """|result − reference| per row; 0 where both are equal or both nan, inf where one only is
    not finite."""
    with np.errstate(invalid="ignore"):
        err = np.abs(result - reference)
    err[(result == reference) | (np.isnan(result) & np.isnan(reference))] = 0.0
    err[np.isnan(err)] = np.inf
    return err


def scale_of(reference: np.ndarray) -> float:
    """max |reference| over its finite values (0 when it has none)."""
    finite = np.abs(reference[np.isfinite(reference)])
    return float(finite.max()) if finite.size else 0.0


def canonical_name(column: str, names: dict[str, str] | None = None) -> str:
    """pam2exu's name of a column: the names map (whole column, else the part before the dot),
    then ``SPELLINGS`` on the part after the dot (Forca → Força, f → f(t), Df → Df(t))."""
    return _canonical(column, names or {})[0]


def _canonical(column: str, names: dict[str, str]) -> tuple[str, tuple[str, ...]]:
    """``canonical_name`` and the map keys it used."""
    col = _clean(column)
    if col in names:
        return names[col], (col,)
    owner, dot, variable = col.rpartition(".")
    if not dot:
        return col, ()
    used = (owner,) if owner in names else ()
    full = f"{names.get(owner, owner)}.{SPELLINGS.get(variable, variable)}"
    if full in names:
        return names[full], used + (full,)
    return full, used


def _clean(name: str) -> str:
    """Strip blanks and use one Unicode form (NFC), so 'Força' typed either way matches."""
    return unicodedata.normalize("NFC", name.strip())


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


def interpolation_error(t: np.ndarray, values: np.ndarray, t_new: np.ndarray,
                        method: str = "cubic") -> np.ndarray:
    """Estimated max interpolation error per row: max |I_h − I_2h| / (2^p − 1), I_2h built on
    every other point, p = 4 (cubic) or 2 (linear); nan with fewer than 7 points."""
    values = np.atleast_2d(values)
    if len(t) < 7 or len(t_new) == 0:
        return np.full(values.shape[0], np.nan)
    every_other = np.unique(np.r_[np.arange(0, len(t), 2), len(t) - 1])
    fine = interpolate(t, values, t_new, method)
    coarse = interpolate(t[every_other], values[:, every_other], t_new, method)
    order = 4 if method == "cubic" else 2
    with np.errstate(invalid="ignore"):
        diff = np.abs(fine - coarse)
    diff[np.isnan(diff)] = 0.0
    return diff.max(axis=1) / (2 ** order - 1)


_NUMBER = re.compile(r"[+-]?(\d*)(?:\.(\d*))?(?:[eE]([+-]?\d+))?")


def written_precision(cells) -> tuple[np.ndarray, str]:
    """Half a unit of the last digit each time of a column carries, from its text.

    A writer that drops trailing zeros (``%g``, PAM's 6 significant digits) writes 0.01 for
    0.0100000: every time then carries the most significant digits any time of the column
    shows, d, and its precision is half a unit of its d-th significant digit (0 for a time
    written 0). A writer that keeps them (every time with the same number of decimals, some
    ending in 0: ``%.4f``) gives each time half a unit of its own last digit.

    Parameters
    ----------
    cells : list of str
        The time column as written ('.' as decimal mark), one cell per row.

    Returns
    -------
    precision : numpy.ndarray
        Half a unit of the last digit each time carries [s]; 0 for a cell that is not a
        plain number (``nan``, empty).
    digits : str
        What the column carries: ``'6 significant digits'`` or ``'4 decimals'``; '' when no
        cell is a number.

    Examples
    --------
    >>> p, digits = written_precision(["0", "0.00277778", "0.5", "1", "100"])
    >>> digits, [float(f"{x:.3g}") for x in p]
    ('6 significant digits', [0.0, 5e-09, 5e-07, 5e-06, 0.0005])
    >>> written_precision(["0.000", "0.250", "1.125"])[1]
    '3 decimals'
    """
    parsed = []                    # (digits after the point, place of the first and last digit)
    for cell in cells:
        m = _NUMBER.fullmatch(cell.strip())
        whole, frac = (m.group(1), m.group(2) or "") if m else ("", "")
        if not whole + frac:
            parsed.append(None)
            continue
        exponent, digits = int(m.group(3) or 0), whole + frac
        lead = len(digits) - len(digits.lstrip("0"))           # leading zeros
        first = exponent + len(whole) - 1 - lead if lead < len(digits) else None  # None: 0
        parsed.append((frac, first, exponent - len(frac)))
    numbers = [q for q in parsed if q is not None]
    if not numbers:
        return np.zeros(len(parsed)), ""
    decimals = {len(frac) for frac, _, _ in numbers}
    zeros_kept = len(decimals) == 1 and decimals != {0} \
        and any(frac.endswith("0") for frac, _, _ in numbers)
    if zeros_kept:                                   # each time its own last digit
        places = [q[2] if q else None for q in parsed]
        n = decimals.pop()
        digits = f"{n + 1} significant digits" if any("e" in c.lower() for c in cells) \
            else f"{n} decimal{'s' * (n > 1)}"
    else:                                            # every time d significant digits
        d = max((first - last + 1 for _, first, last in numbers if first is not None),
                default=1)
        places = [q[1] - d + 1 if q and q[1] is not None else None for q in parsed]
        digits = f"{d} significant digit{'s' * (d > 1)}"
    precision = np.array([0.0 if k is None else 0.5 * 10.0 ** k for k in places])
    return precision, digits


def times_match(t: np.ndarray, precision: np.ndarray, t_ref: np.ndarray,
                precision_ref: np.ndarray) -> bool:
    """Whether two time grids are the same to the precision each carries (rows matched 1:1).

    Row k matches when |t_k − t_ref,k| ≤ precision_k + precision_ref,k + 4 ε max |t_ref|
    (the two intervals the written times stand for overlap, ε the float's epsilon), and the
    pairing is unambiguous: the intervals of neighbouring rows do not overlap.

    Parameters
    ----------
    t, t_ref : numpy.ndarray
        The times of the result and of the reference [s].
    precision, precision_ref : numpy.ndarray
        Half a unit of the last digit each time carries [s] (``written_precision``); 0 for
        times held as floats.

    Returns
    -------
    bool
        True when the grids have the same number of rows and every row matches.

    Examples
    --------
    >>> t = np.arange(4) / 360                    # 0, 0.00277778, 0.00555556, 0.00833333
    >>> six = np.array([float(f"{x:.6g}") for x in t])
    >>> p = written_precision([f"{x:.6g}" for x in t])[0]
    >>> times_match(t, 0 * t, six, p), times_match(t, 0 * t, six, 0 * p)
    (True, False)
    """
    if t.shape != t_ref.shape:
        return False
    floor = 4 * np.finfo(float).eps * max(float(np.max(np.abs(t_ref), initial=0.0)), 1e-300)
    tol = precision + precision_ref + floor
    if not np.all(np.abs(t - t_ref) <= tol):
        return False
    reach = tol[:-1] + tol[1:]                   # neighbouring intervals must stay apart
    return bool(np.all(reach < np.abs(np.diff(t))) and np.all(reach < np.abs(np.diff(t_ref))))


def angle_error(result: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """|result − reference| of angles modulo 2π: the difference reduced to (−π, π], then its
    magnitude [rad], in [0, π]; non-finite values as in ``abs_error``."""
    err = abs_error(result, reference)
    finite = np.isfinite(err) & (err > 0)
    with np.errstate(invalid="ignore"):
        diff = result[finite] - reference[finite]
    err[finite] = np.abs(np.pi - np.mod(np.pi - diff, 2 * np.pi))
    return err


# --- reading -------------------------------------------------------------------------------

@dataclass
class _Table:
    """One side of the comparison, with pam2exu's column names."""

    label: str
    t: np.ndarray
    names: list[str]
    values: np.ndarray                  # (len(names), len(t))
    units: dict[str, str]
    notes: list[str]
    used_keys: set[str]
    t_text: tuple[str, list[str], int] | None = None   # (separator, lines, column of t)


def _time_precision(table: _Table) -> tuple[np.ndarray, str]:
    """Half a unit of the last digit each time carries [s], and what the times carry, from
    the text of the time column (``written_precision``); zeros for a Results table."""
    if table.t_text is None:
        return np.zeros(len(table.t)), ""
    delimiter, lines, j = table.t_text
    return written_precision(_cells((delimiter, lines), j))


def read_names(path: str | Path) -> dict[str, str]:
    """A names map file: two-column CSV ``pam_name,pam2exu_name`` (',' or ';'), one pair a line.

    A name with a dot renames one column (``Solid1.fi,crank.fi``); without, a solid or element
    in every column (``Solid1,crank``). Blank lines, lines starting with '#' and a
    ``pam_name,pam2exu_name`` header line are skipped.

    Parameters
    ----------
    path : str or Path
        The names map file (UTF-8, else read as Windows-1252).

    Returns
    -------
    dict
        PAM name → pam2exu name, for ``compare(..., names=...)``.

    Raises
    ------
    CompareInputError
        The file is missing, a line does not have two names, or a name is mapped twice to
        different names.

    Examples
    --------
    >>> read_names("tests/data/compare/crank_names.csv")      # doctest: +SKIP
    {'Solid1': 'crank', ...}
    """
    lines = _lines(_text(Path(path), "names map")[0])
    out: dict[str, str] = {}
    for number, line in lines:
        delimiter = ";" if ";" in line else ","
        fields = [_clean(f) for f in next(csv.reader([line], delimiter=delimiter))]
        if tuple(fields) == MAP_HEADER:
            continue
        if len(fields) != 2 or not all(fields):
            raise CompareInputError(
                f"{path}, line {number}: expected two names 'pam_name,pam2exu_name', "
                f"found {line.strip()!r}; write one pair a line, e.g. 'Solid1,crank'")
        if out.get(fields[0], fields[1]) != fields[1]:
            raise CompareInputError(f"{path}, line {number}: '{fields[0]}' is mapped twice "
                                    f"('{out[fields[0]]}' and '{fields[1]}'); keep one line")
        out[fields[0]] = fields[1]
    return out


def _names_map(names) -> dict[str, str]:
    """The names map from None, a dict or a file."""
    if names is None:
        return {}
    if isinstance(names, dict):
        return {_clean(str(k)): _clean(str(v)) for k, v in names.items()}
    return read_names(names)


def _text(path: Path, role: str) -> tuple[str, list[str]]:
    """File text, UTF-8 (with or without BOM), else Windows-1252 with a note saying so."""
    if not path.is_file():
        what = "is a directory" if path.is_dir() else "not found"
        wanted = ("a two-column CSV 'pam_name,pam2exu_name'" if role == "names map" else
                  "a CSV file (written by `pam2exu run MODEL -o FILE.csv`, or exported from PAM)")
        raise CompareInputError(f"{role} file '{path}' {what}; give the path of {wanted}")
    raw = path.read_bytes()
    try:
        return raw.decode("utf-8-sig"), []
    except UnicodeDecodeError:
        return raw.decode("cp1252", errors="replace"), \
            [f"{role} '{path}' is not UTF-8: read as Windows-1252"]


def _lines(text: str) -> list[tuple[int, str]]:
    """(line number, line) of the non-blank lines that do not start with '#'."""
    return [(k, line) for k, line in enumerate(text.splitlines(), start=1)
            if line.strip() and not line.lstrip().startswith("#")]


def _read_csv(path: Path, role: str) -> tuple[list[str], np.ndarray, list[str],
                                              tuple[str, list[str]]]:
    """Column names, values (columns × rows), notes, and (separator, lines of values) of a
    result CSV file, the lines for ``_cells``.

    Separator ';' or tab when the header line has one outside quoted names, else ','; with
    ';' or tab a ',' inside a number is a decimal comma. Empty cells are nan.
    """
    text, notes = _text(path, role)
    lines = _lines(text)
    if len(lines) < 2:
        raise CompareInputError(f"{role} file '{path}' has no rows of values; it needs a "
                                f"header line 't,<name>.<variable>,…' and one line per time")
    header_line = lines[0][1]
    unquoted = header_line.replace('""', "").split('"')[::2]   # outside quoted names
    delimiter = (";" if any(";" in u for u in unquoted) else
                 "\t" if any("\t" in u for u in unquoted) else ",")
    if delimiter != ",":
        notes.append(f"{role} read with {'tab' if delimiter == chr(9) else repr(delimiter)} "
                     f"as separator and ',' as decimal mark")
    header = [_clean(h) for h in next(csv.reader([header_line], delimiter=delimiter))]
    while header and header[-1] == "":
        header.pop()                       # a trailing separator
    if "" in header:
        raise CompareInputError(f"{path}: column {header.index('') + 1} has no name in the "
                                f"header line; name it or delete the column")
    body = "\n".join(line for _, line in lines[1:])
    try:                                   # fast path: a clean table
        values = np.loadtxt(io.StringIO(body if delimiter == "," else body.replace(",", ".")),
                            delimiter=delimiter, ndmin=2, dtype=float, comments=None)
        if values.shape[1] == len(header):
            return header, values.T, notes, (delimiter, [line for _, line in lines[1:]])
    except ValueError:
        pass
    rows = list(csv.reader([line for _, line in lines[1:]], delimiter=delimiter))
    cells = []
    for row, (number, _) in zip(rows, lines[1:]):
        if all(f.strip() == "" for f in row[len(header):]):
            row = row[:len(header)]        # trailing separators
        if len(row) != len(header):
            hint = " (a file with decimal commas must use ';' as separator)" \
                if delimiter == "," else ""
            raise CompareInputError(f"{path}, line {number}: {len(row)} values, the header has "
                                    f"{len(header)} names{hint}; every line needs one value "
                                    f"per column")
        cells.append([f.strip().replace(",", ".") if delimiter != "," else f.strip()
                      for f in row])
    try:
        values = np.array(cells, dtype=float).reshape(len(cells), len(header))
    except ValueError:                     # empty cells, or a bad one to point at
        values = np.empty((len(cells), len(header)))
        for k, (row, (number, _)) in enumerate(zip(cells, lines[1:])):
            for j, cell in enumerate(row):
                try:
                    values[k, j] = float(cell) if cell else np.nan
                except ValueError:
                    raise CompareInputError(
                        f"{path}, line {number}, column '{header[j]}': '{rows[k][j].strip()}'"
                        f" is not a number; fix the value (an empty cell is read as missing)"
                    ) from None
    return header, values.T, notes, (delimiter, [line for _, line in lines[1:]])


def _cells(body: tuple[str, list[str]], j: int) -> list[str]:
    """The text of column j on each line of values ('.' as decimal mark)."""
    delimiter, lines = body
    cells = [row[j].strip() if j < len(row) else "" for row in csv.reader(lines,
                                                                         delimiter=delimiter)]
    return cells if delimiter == "," else [c.replace(",", ".") for c in cells]


def _load(source, role: str, names: dict[str, str]) -> _Table:
    """A path or a Results table, with its columns renamed to pam2exu's spelling."""
    if isinstance(source, Results):
        label = f"'{source.model}' {source.analysis} results" if source.model \
            else "Results table"
        raw = ["t", *source.columns]
        data, units, notes, body = source.to_numpy().T, dict(source.units), [], None
    elif isinstance(source, (str, Path)):
        label = str(source)
        raw, data, notes, body = _read_csv(Path(source), role)
        units = {}
    else:
        raise CompareInputError(f"the {role} must be a CSV file path or a Results table, "
                                f"not {type(source).__name__}")
    renamed, used, origin = [], set(), {}
    new_names = []
    for name in raw:
        new, keys = _canonical(name, names)
        used.update(keys)
        if new in origin:
            raise CompareInputError(
                f"{label}: columns '{origin[new]}' and '{name}' both become '{new}' (names map "
                f"or built-in spelling {_spellings()}); delete one of them from the file or "
                f"map one to another name with --names (names= from Python)")
        origin[new] = name
        if new != _clean(name):
            renamed.append(f"{_clean(name)} → {new}")
        new_names.append(new)
        if name in units:
            units[new] = units.pop(name)
    if "t" not in new_names:
        raise CompareInputError(
            f"{label}: no column 't' (the columns are {_listing(new_names)}); the time column "
            f"must be named t: rename it in the file, or map it with --names (names= from "
            f"Python), e.g. a line 'Temps,t'")
    it = new_names.index("t")
    keep = [j for j in range(len(new_names)) if j != it]
    if renamed:
        notes.append(f"{role}: {len(renamed)} columns renamed: {_listing(renamed)}")
    return _Table(label, np.asarray(data[it], dtype=float), [new_names[j] for j in keep],
                  data[keep], units, notes, used, None if body is None else (*body, it))


def _spellings() -> str:
    """'Forca → Força, f → f(t), Df → Df(t)'."""
    return ", ".join(f"{k} → {v}" for k, v in SPELLINGS.items())


# --- the comparison ------------------------------------------------------------------------

def _check_times(table: _Table, need_increasing: bool) -> None:
    """t finite, and strictly increasing where the table is interpolated."""
    bad = np.flatnonzero(~np.isfinite(table.t))
    if bad.size:
        raise CompareInputError(f"{table.label}: t is not a number on row {bad[0] + 1}; every "
                                f"row needs its time")
    if need_increasing:
        back = np.flatnonzero(np.diff(table.t) <= 0)
        if back.size:
            k = back[0]
            raise CompareInputError(
                f"{table.label}: t is not strictly increasing at rows {k + 1}–{k + 2} "
                f"(t = {table.t[k]:.17g}, {table.t[k + 1]:.17g}); sort the rows by t and "
                f"remove repeated times")


def _same_times(a: np.ndarray, b: np.ndarray) -> bool:
    """Equal time grids, to within a few rounding errors of the largest |t|."""
    if a.shape != b.shape:
        return False
    tol = 4 * np.finfo(float).eps * max(float(np.max(np.abs(b), initial=0.0)), 1e-300)
    return bool(np.all(np.abs(a - b) <= tol))


def _angles(names: list[str], res: _Table, ref: _Table) -> tuple[list[str], list[str]]:
    """The columns among ``names`` that are angles [rad], and those that may be one but whose
    unit neither table tells (``f(t)`` of an actuator of unknown type, in two CSV files)."""
    from .units import declared_units, unit_of
    columns = res.names + ref.names
    angles, unknown = [], []
    for name in names:
        unit = (res.units.get(name) or ref.units.get(name) or unit_of(name)
                or _unit_among(name, columns))
        if unit == "rad":
            angles.append(name)
        elif not unit and "rad" in declared_units().get(name.rpartition(".")[2], ()):
            unknown.append(name)
    return angles, unknown


def _unit_among(column: str, columns: list[str]) -> str:
    """The unit of ``column`` declared by every element type whose outputs include all the
    variables its owner has in ``columns`` ('' when none or several): ``motor.f(t)`` next to
    ``motor.Mz`` is an angular actuator's, in rad."""
    from ..elements import ELEMENTS
    owner, _, variable = column.rpartition(".")
    present = {c.rpartition(".")[2] for c in columns if c.rpartition(".")[0] == owner}
    units = {v.unit for cls in ELEMENTS.values()
             if present <= {o.name for o in cls.outputs}
             for v in cls.outputs if v.name == variable}
    return units.pop() if len(units) == 1 else ""


def _carried(res: tuple[np.ndarray, str], ref: tuple[np.ndarray, str], floor: float) -> str:
    """'6 significant digits the reference carries': what the times coarser than ``floor``
    [s] carry, from the (precision, digits) of each table, for the header."""
    sides = [f"{digits} the {role} carries" for role, (precision, digits) in
             (("result", res), ("reference", ref)) if digits and np.any(precision > floor)]
    return " and the ".join(sides) or "digits the files carry"


def _choose(res: _Table, ref: _Table, columns) -> tuple[list[str], list[str], list[str]]:
    """Common columns (result order), and those of one table only, restricted to ``columns``."""
    union = res.names + [c for c in ref.names if c not in set(res.names)]
    if columns is not None:
        columns = [columns] if isinstance(columns, str) else list(columns)
        chosen, unmatched = set(), []
        for p in columns:
            try:
                chosen.update(select_columns(union, [p]))
            except ModelError:
                unmatched.append(f"'{p}'{closest(p, union)}")
        if unmatched:
            raise CompareInputError(f"--columns (columns=): {', '.join(unmatched)} match no "
                                    f"variable of {res.label} or {ref.label}; use full names "
                                    f"(crank.fi), 'crank.*', '*.Fx' or a bare variable (Fx)")
        union = [c for c in union if c in chosen]
    in_res, in_ref = set(res.names), set(ref.names)
    common = [c for c in union if c in in_res and c in in_ref]
    if not common:
        raise CompareInputError(
            f"no variable in common between the result {res.label} ({_listing(res.names, 5)}) "
            f"and the reference {ref.label} ({_listing(ref.names, 5)})"
            + (" among the chosen --columns" if columns is not None else "")
            + "; map the reference's names to pam2exu's with --names MAP (names= from "
              "Python), a two-column CSV 'pam_name,pam2exu_name' (see docs/compare.md)")
    return (common, [c for c in union if c not in in_ref],
            [c for c in union if c not in in_res])


def compare(result, reference, rtol: float = RTOL, atol: float = ATOL, columns=None,
            names=None, method: str = "cubic", wrap_angles: bool = False) -> Comparison:
    """Compare ``result`` with ``reference`` variable by variable.

    Rows are matched by ``t``, to the precision each file's times carry: a time written with
    d significant digits matches one within half a unit of its last digit
    (``written_precision``, ``times_match``). When the times differ, the result is
    interpolated onto the reference times inside the result's interval (reference rows
    outside it are not compared) and the interpolation's own error is estimated.
    ``pam2exu compare`` calls this function; the user guide is docs/compare.md.

    Parameters
    ----------
    result, reference : str, Path or Results
        CSV files (header ``t,<name>.<variable>,…``; ',' or ';' separated, decimal comma
        with ';') or Results tables.
    rtol : float
        Relative tolerance [–], ≥ 0, times the scale max |reference| of each variable.
    atol : float
        Absolute tolerance [SI unit of each variable], ≥ 0. A variable passes when
        max |result − reference| ≤ atol + rtol · max |reference|.
    columns : list of str, optional
        Patterns of the variables to compare: full names, ``crank.*``, ``*.Fx``, bare ``Fx``.
    names : dict, str or Path, optional
        Names map PAM name → pam2exu name, or a two-column CSV file of it (``read_names``);
        applied to the reference's columns, before the built-in ``SPELLINGS`` (which apply
        to both tables).
    method : str
        ``cubic`` (not-a-knot spline) or ``linear``: how the result is interpolated onto the
        reference times when the times differ.
    wrap_angles : bool
        Compare angles (unit rad: ``fi``, ``fi_rel``, an angular actuator's ``f(t)``)
        modulo 2π, for exports that wrap them at ±π: the difference is reduced to (−π, π]
        before its magnitude is taken, and the scale is π. An interpolated result is
        unwrapped first.

    Returns
    -------
    Comparison
        ``.rows`` (one VariableComparison per common variable), ``.passed``,
        ``.to_markdown()``, ``.to_csv()``.

    Raises
    ------
    CompareInputError
        A file is missing or unreadable, has no ``t``, the tables have nothing in common or
        their times do not overlap, a ``columns`` pattern matches nothing, ``rtol`` or
        ``atol`` is not a number ≥ 0, ``method`` is unknown, or ``wrap_angles`` is not a
        bool.

    Examples
    --------
    >>> import pam2exu
    >>> model = pam2exu.load("examples/four_bar.toml")                  # doctest: +SKIP
    >>> fine = pam2exu.run(model, analysis="kinematic", steps=400)        # doctest: +SKIP
    >>> coarse = pam2exu.run(model, analysis="kinematic", steps=200)      # doctest: +SKIP
    >>> table = pam2exu.compare(coarse, fine, rtol=1e-5)                  # doctest: +SKIP
    >>> table.passed                                                       # doctest: +SKIP
    True
    >>> print(table)                                                       # doctest: +SKIP
    - result: 'four-bar' kinematic results (201 rows)
    ...
    """
    for label, value in (("rtol", rtol), ("atol", atol)):
        if not (isinstance(value, (int, float)) and not isinstance(value, bool)
                and math.isfinite(value) and value >= 0):
            raise CompareInputError(f"`{label}` must be a number ≥ 0, not {value!r}")
    if method not in METHODS:
        raise CompareInputError(f"`method` must be one of {', '.join(METHODS)}, not "
                                f"{method!r}{closest(method, METHODS)}")
    if not isinstance(wrap_angles, bool):
        raise CompareInputError(f"`wrap_angles` must be True or False, not {wrap_angles!r}")
    names_map = _names_map(names)
    res = _load(result, "result", {})              # the map is for the reference's names
    ref = _load(reference, "reference", names_map)
    common, only_res, only_ref = _choose(res, ref, columns)
    ir = [res.names.index(c) for c in common]
    jr = [ref.names.index(c) for c in common]
    notes = res.notes + ref.notes
    unused = sorted(set(names_map) - ref.used_keys)
    if unused:
        notes.append(f"names map: no column matched {_listing(unused)}")
    wrapped, unknown = _angles(common, res, ref) if wrap_angles else ([], [])
    if unknown:
        notes.append(f"not compared modulo 2π (angle or length: neither file tells which "
                     f"actuator it is): {_listing(unknown)}")
    angle = np.array([name in wrapped for name in common], dtype=bool)

    same = _same_times(res.t, ref.t)
    written = None if same else (_time_precision(res), _time_precision(ref))
    matched = same or times_match(res.t, written[0][0], ref.t, written[1][0])
    _check_times(ref, need_increasing=False)
    _check_times(res, need_increasing=not matched)
    digits, dt = "", 0.0
    if matched:
        inside = np.ones(len(ref.t), dtype=bool)
        values = res.values[ir]
        interp_err = np.full(len(common), np.nan)
        overlap = (float(ref.t.min(initial=0)), float(ref.t.max(initial=0)))
        if not same:
            floor = 4 * np.finfo(float).eps * float(np.max(np.abs(ref.t), initial=0.0))
            digits = _carried(*written, floor)
            dt = float(np.max(np.abs(res.t - ref.t)))
    else:
        lo, hi = float(res.t[0]), float(res.t[-1])
        slack = 1e-9 * max(hi - lo, abs(lo), abs(hi))
        inside = (ref.t >= lo - slack) & (ref.t <= hi + slack)
        if not inside.any():
            raise CompareInputError(
                f"the times do not overlap: result {res.label} has t = {lo:g} … {hi:g} s, "
                f"reference {ref.label} t = {ref.t.min():g} … {ref.t.max():g} s; compare "
                f"files of the same interval (pam2exu run --t-end)")
        source = res.values[ir]
        smooth = angle & np.all(np.isfinite(source), axis=1)
        if smooth.any():                   # an angle that wraps at ±π is not smooth
            source = source.copy()
            source[smooth] = np.unwrap(source[smooth], axis=1)
        values = interpolate(res.t, source, ref.t[inside], method)
        interp_err = interpolation_error(res.t, source, ref.t[inside], method)
        overlap = (lo, hi)
    t_ref = ref.t[inside]
    rows = []
    for k, (name, j) in enumerate(zip(common, jr)):
        target = ref.values[j][inside]
        err = (angle_error if angle[k] else abs_error)(values[k], target)
        at = int(np.argmax(err))
        worst, scale = float(err[at]), math.pi if angle[k] else scale_of(target)
        tol = tolerance(scale, rtol, atol)
        rows.append(VariableComparison(
            name=name, max_abs_error=worst,
            max_rel_error=worst / scale if scale > 0 else math.nan,
            t_at_max=float(t_ref[at]) if worst > 0 else math.nan, scale=scale,
            tolerance=tol, passed=bool(worst <= tol),
            interpolation_error=float(interp_err[k]),
            unit=res.units.get(name) or ref.units.get(name) or ""))
    return Comparison(rows, only_res, only_ref, res.label, ref.label, float(rtol), float(atol),
                      len(res.t), len(ref.t), int(inside.sum()), None if matched else method,
                      overlap, notes, digits, dt, wrapped)

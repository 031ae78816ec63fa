"""Reading result tables and names maps: the one reader of ``compare``, ``read_csv`` and ``plot``.

A result CSV file has a header line ``t,<name>.<variable>,…`` and one line per time: ','
separated (``Results.to_csv``), or ';' or tab separated with a decimal comma (PAM-style
exports). It is read as UTF-8, else as Windows-1252 (with a note); blank lines and lines
starting with '#' are skipped, empty cells are nan. Column names are brought to pam2exu's
spelling (``names``: a names map, then ``SPELLINGS``). ``load_table`` gives the ``Table``
one side of a comparison is; ``read_csv`` gives a ``Results`` table with units;
``read_names`` reads a names map file; ``written_precision`` says what the text of the time
column carries (``compare`` matches rows to it). The user guide is docs/compare.md.
"""
from __future__ import annotations

import csv
import io
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import CompareInputError
from ..model import Model, load
from .names import canonical, clean, listing, spellings
from .table import Results
from .table_csv import own_values
from .units import UNITS_LINE, unit_of

MAP_HEADER = ("pam_name", "pam2exu_name")
_NUMBER = re.compile(r"[+-]?(\d*)(?:\.(\d*))?(?:[eE]([+-]?\d+))?")


# --- names maps ----------------------------------------------------------------------------

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
        fields = [clean(f) for f in next(csv.reader([line], delimiter=delimiter))]
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


def names_map(names) -> dict[str, str]:
    """The names map from None, a dict or a file."""
    if names is None:
        return {}
    if isinstance(names, dict):
        return {clean(str(k)): clean(str(v)) for k, v in names.items()}
    return read_names(names)


# --- CSV files -----------------------------------------------------------------------------

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


def _parse_csv(path: Path, role: str) -> tuple[list[str], np.ndarray, list[str],
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
    header = [clean(h) for h in next(csv.reader([header_line], delimiter=delimiter))]
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


# --- tables --------------------------------------------------------------------------------

@dataclass
class Table:
    """A result table as read, with pam2exu's column names: one side of a comparison, or what
    ``read_csv`` makes a Results table of."""

    label: str
    t: np.ndarray
    names: list[str]
    values: np.ndarray                  # (len(names), len(t))
    units: dict[str, str]
    notes: list[str]
    used_keys: set[str]
    t_text: tuple[str, list[str], int] | None = None   # (separator, lines, column of t)


def time_precision(table: Table) -> tuple[np.ndarray, str]:
    """Half a unit of the last digit each time carries [s], and what the times carry, from
    the text of the time column (``written_precision``); zeros for a Results table."""
    if table.t_text is None:
        return np.zeros(len(table.t)), ""
    delimiter, lines, j = table.t_text
    return written_precision(_cells((delimiter, lines), j))


def written_units(path: Path, names: list[str]) -> dict[str, str]:
    """The units the file's units line gives (``units.units_line``: the line right after the
    header, ``# units: s,m,deg,…``, which ``Results.to_csv`` writes for a table in
    degrees), by column name; {} without one, or when it does not have one unit per name."""
    try:
        with open(path, encoding="utf-8-sig", errors="replace") as fh:
            fh.readline()
            line = fh.readline().rstrip("\r\n")
    except OSError:
        return {}
    if not line.startswith(UNITS_LINE):
        return {}
    text = line[len(UNITS_LINE):]
    sep = ";" if ";" in text else "\t" if "\t" in text else ","
    units = [u.strip() for u in text.split(sep)]
    return dict(zip(names, units)) if len(units) == len(names) else {}


def load_table(source, role: str, names: dict[str, str]) -> Table:
    """A path or a Results table, with its columns renamed to pam2exu's spelling."""
    if isinstance(source, Results):
        label = f"'{source.model}' {source.analysis} results" if source.model \
            else "Results table"
        raw = ["t", *source.columns]
        data, units, notes, body = source.to_numpy().T, dict(source.units), [], None
    elif isinstance(source, (str, Path)):
        label = str(source)
        raw, data, notes, body = _parse_csv(Path(source), role)
        units = written_units(Path(source), raw)          # a file in degrees says so
    else:
        raise CompareInputError(f"the {role} must be a CSV file path or a Results table, "
                                f"not {type(source).__name__}")
    renamed, used, origin = [], set(), {}
    new_names = []
    for name in raw:
        new, keys = canonical(name, names)
        used.update(keys)
        if new in origin:
            raise CompareInputError(
                f"{label}: columns '{origin[new]}' and '{name}' both become '{new}' (names map "
                f"or built-in spelling {spellings()}); delete one of them from the file or "
                f"map one to another name with --names (names= from Python)")
        origin[new] = name
        if new != clean(name):
            renamed.append(f"{clean(name)} → {new}")
        new_names.append(new)
        if name in units:
            units[new] = units.pop(name)
    if "t" not in new_names:
        raise CompareInputError(
            f"{label}: no column 't' (the columns are {listing(new_names)}); the time column "
            f"must be named t: rename it in the file, or map it with --names (names= from "
            f"Python), e.g. a line 'Temps,t'")
    it = new_names.index("t")
    keep = [j for j in range(len(new_names)) if j != it]
    if renamed:
        notes.append(f"{role}: {len(renamed)} columns renamed: {listing(renamed)}")
    return Table(label, np.asarray(data[it], dtype=float), [new_names[j] for j in keep],
                 data[keep], units, notes, used, None if body is None else (*body, it))


def read_csv(path: str | Path, model=None) -> Results:
    """A result CSV file as a Results table, with units from the output declarations.

    Reads what ``pam2exu compare`` reads: ``Results.to_csv`` files and PAM-style exports
    (',' or ';' separated, decimal comma with ';', PAM spellings such as ``Forca``, which
    become pam2exu's: ``Força``). ``model`` (a Model or a model file) gives the units of
    ``f(t)`` and ``Df(t)``, which depend on the actuator type (see ``units.unit_of``).
    A file exactly as ``to_csv`` writes it is read by scipy's Matrix Market reader (C++),
    its values taken only when they write back as the file's bytes; any other file as
    ``compare`` reads it.

    Parameters
    ----------
    path : str or Path
        The CSV file: a header line ``t,<name>.<variable>,…``, then one line per time.
    model : Model, str or Path, optional
        The model the file was computed from, for the units of ``f(t)`` and ``Df(t)``
        (rad or m); also gives the table's ``model`` name (else the file's stem).

    Returns
    -------
    Results
        The columns of the file (``t`` first), ``analysis`` ''.

    Raises
    ------
    CompareInputError
        The file is missing or unreadable: no ``t`` column, a line with the wrong number of
        values, a value that is not a number, two columns with one name.
    ModelError
        ``model`` is a model file with problems.

    Examples
    --------
    >>> res = read_csv("slider.csv", model="examples/slider_crank.toml")  # doctest: +SKIP
    >>> res.units["motor.f(t)"]                                          # doctest: +SKIP
    'rad'
    """
    if model is not None and not isinstance(model, Model):
        model = load(model)
    own = _read_own(Path(path))
    try:
        table = load_table(path if own is None else own, "results", {})
    except CompareInputError:
        if own is None:
            raise
        table = load_table(path, "results", {})          # the message names the file
    units = {name: table.units.get(name) or unit_of(name, model) for name in table.names}
    return Results(table.t, dict(zip(table.names, table.values)), units,
                   model=Path(path).stem if model is None else model.name)


def _read_own(path: Path) -> Results | None:
    """A file exactly as ``Results.to_csv`` writes it, read fast (``table_csv.own_values``);
    None for any other file."""
    own = own_values(path)
    if own is None:
        return None
    names, values = own
    return Results(values[0], dict(zip(names[1:], values[1:])))

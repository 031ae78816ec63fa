"""The result of an analysis: one table of named columns, PAM's variable names.

``Results`` and its CSV writer (``Results.to_csv``), with the fast reader of exactly what the
writer writes (``_read_own``); any result CSV file is read by ``reading.read_csv``.
"""
from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np

from ..errors import ModelError, Problem, closest
from ..limits import one_form
from .info import RunInfo
from .instant import Instants
from .names import selects, spelled
from .units import units_line
from .writers import BOM, Exports, csv_translation


class Results(Exports, Instants):
    """Columns ``<name>.<variable>`` over time, stored as one array.

    What ``pam2exu.run`` returns (and ``read_csv`` reads). ``res["crank.fi"]`` is a NumPy
    view of a column (writing to it changes the table; KeyError, suggesting the nearest
    name, for a column that does not exist), ``res.t`` the times [s], ``res.columns`` the
    column names (without ``t``), ``res.units`` their SI units, ``res.to_numpy()`` the
    (steps + 1, 1 + columns) array with ``t`` first (a view, no copy) and
    ``res.to_csv(path)`` the CSV file of the contract (``to_excel``, ``to_parquet`` and
    ``to_pandas``: the other forms, ``results.writers``). ``"crank.fi" in res`` tests for a
    column, ``len(res)`` is the number of rows (times).

    Column names are ``<solid>.<variable>`` (``x``, ``y`` [m], ``fi`` [rad], ``Dx``, ``Dy``
    [m/s], ``Dfi`` [rad/s], ``DDx``, ``DDy`` [m/s²], ``DDfi`` [rad/s²]) and
    ``<element>.<variable>`` (``Fx``, ``Fy``, ``Fnormal``, ``Força`` [N], ``Mz``,
    ``Parell`` [N·m], ``f(t)``, ``Df(t)``, ``ro``, ``fi_rel``, …), in the order of the
    model: solids, then elements.

    Parameters
    ----------
    t : array_like
        Times [s], shape (rows,).
    columns : dict
        Column name → values (rows,), in the order of the table; copied into the table.
    units : dict, optional
        Column name → SI unit (``"rad"``, ``"N·m"``, …); ``t`` is always ``"s"``.
    analysis : str
        The analysis that made the table (``'kinematic'``, …; '' when unknown).
    model : str
        The model's name ('' when unknown).
    warnings : list of str, optional
        Warnings issued during the run.
    info : RunInfo or dict, optional
        Facts about the run (see Attributes).
    backend : str, optional
        The backend that ran, as messages name it (``Backend.label``; '' when unknown).

    Attributes
    ----------
    units : dict
        Column name → SI unit, ``t`` included (``"s"``); a column read from a CSV file
        without a known unit has ''.
    analysis : str
        The analysis type.
    model : str
        The model's name.
    backend : str
        The backend that ran (``'Exudyn'``, ``'the natural-coordinate backend'``).
    warnings : list of str
        Warnings raised during the run (redundant constraints, singular positions, the
        power balance), also issued as Python warnings.
    info : RunInfo
        Run facts, read as a dictionary of those the run set: ``dof`` and
        ``redundant_equations`` (rank test at the initial guess), ``condition_number`` of
        the constraint Jacobian at the initial guess, ``max_residual`` (largest constraint
        residual at the backend's positions [m or rad]), ``backend_seconds`` (time in the
        backend's position solves [s]; ``exudyn_seconds``, its old name, still reads it,
        deprecated), and per analysis ``max_condition_number``, ``branch_resolves``,
        ``equilibrium_error`` (relative), ``reactions_from``, ``power_balance_error`` and
        ``power_balance_tolerance`` [W] (``RunInfo``).

    Examples
    --------
    >>> res = Results([0.0, 0.5, 1.0], {"crank.fi": [0.0, 3.0, 6.0], "motor.Mz": [1.0, 2.0, 1.5]},
    ...               {"crank.fi": "rad", "motor.Mz": "N·m"}, "kinetostatic", "demo")
    >>> res
    <Results kinetostatic 'demo': 3 rows × 2 columns>
    >>> res["crank.fi"].tolist(), res.units["motor.Mz"], len(res), "motor.Mz" in res
    ([0.0, 3.0, 6.0], 'N·m', 3, True)
    >>> res["crank.Fi"]
    Traceback (most recent call last):
    ...
    KeyError: "no column 'crank.Fi' (did you mean 'crank.fi'?)"
    """

    def __init__(self, t, columns: dict[str, np.ndarray], units: dict[str, str] | None = None,
                 analysis: str = "", model: str = "", warnings=None, info=None,
                 backend: str = ""):
        t = np.asarray(t, dtype=float)
        self._names = ["t", *map(one_form, columns)]      # names in one Unicode form
        self._data = np.empty((len(self._names), len(t)))
        self._data[0] = t
        for i, values in enumerate(columns.values(), start=1):
            self._data[i] = values
        self._index = {name: i for i, name in enumerate(self._names)}
        self.units = {"t": "s", **{one_form(k): v for k, v in (units or {}).items()}}
        self.analysis, self.model, self.backend = analysis, model, backend
        self.warnings = list(warnings or [])
        self.info = RunInfo(**dict(info or {}))

    @property
    def t(self) -> np.ndarray:
        """Times [s]: a view of the table's ``t`` column, shape (rows,)."""
        return self._data[0]

    @property
    def columns(self) -> list[str]:
        """Column names, without ``t``, in the order of the table (a new list)."""
        return self._names[1:]

    def __getitem__(self, name: str) -> np.ndarray:
        """The column ``name`` (``t`` included), a view; KeyError naming the nearest."""
        if (name := one_form(name)) not in self._index:
            raise KeyError(f"no column '{name}'{closest(name, self._names)}")
        return self._data[self._index[name]]

    def __contains__(self, name: str) -> bool:
        return one_form(name) in self._index

    def __len__(self) -> int:
        return self._data.shape[1]

    def to_numpy(self) -> np.ndarray:
        """(rows, 1 + columns) array, ``t`` first: a transposed view of the storage.

        Returns
        -------
        numpy.ndarray
            Column 0 is ``t`` [s], column j the values of ``columns[j - 1]`` (SI units of
            ``units``). A view: copy it before changing it.

        Examples
        --------
        >>> res = Results([0.0, 1.0], {"crank.fi": [0.0, 6.0]})
        >>> res.to_numpy().tolist()
        [[0.0, 0.0], [1.0, 6.0]]
        """
        return self._data.T

    def to_csv(self, path: str | Path, sep: str = ",", decimal: str = ".",
               bom: bool = False) -> Path:
        """Write UTF-8 CSV: header ``t,<name>.<variable>,…``, every value read back exactly.

        One line per time, ',' separated, each value in the fewest digits that read back as
        the same float, bit for bit (``0.1`` is ``1e-1``, ``0.1 + 0.2`` is
        ``3.0000000000000004e-1``, ``-0.0`` is ``-0``; non-finite values are ``nan``,
        ``infinity``, ``-infinity``), formatted by scipy's Matrix Market writer (C++). A
        name holding ',', ';' or '"' is quoted (``"a,b.x"``, a '"' doubled). The file is
        written under a temporary name and then renamed, so a failure never leaves half a
        file (nor the temporary one). ``read_csv`` and ``pam2exu compare`` read it; units
        are not written. ``sep=';', decimal=','`` writes the same digits with a decimal comma
        (the CSV Excel opens in Catalan or Spanish), ``bom=True`` a UTF-8 byte-order mark first.

        Parameters
        ----------
        path : str or Path
            The CSV file to write (replaced if it exists).
        sep : str
            Separator: ',' (default), ';' or a tab.
        decimal : str
            Decimal mark: '.' (default) or ',' (with ``sep`` ';' or a tab).
        bom : bool
            Start the file with a UTF-8 byte-order mark (Excel then reads it as UTF-8).

        Returns
        -------
        Path
            ``path``.

        Raises
        ------
        OSError
            The file cannot be written.
        OutputError
            An unknown separator or decimal mark, or both ','.

        Examples
        --------
        >>> res = Results([0.0, 1.0], {"crank.fi": [0.0, 6.0]})
        >>> res.to_csv("crank.csv")                     # doctest: +SKIP
        PosixPath('crank.csv')
        """
        path, translate = Path(path), csv_translation(sep, decimal)
        tmp = path.with_name(path.name + ".part")
        try:
            with open(tmp, "wb") as fh:
                fh.write((BOM if bom else b"") + (_csv_header(self._names, sep) + "\n").encode())
                fh.write(units_line(self._names, self.units, sep).encode())   # degrees only
                for lines in _csv_lines(self._data.T):
                    fh.write(lines if translate is None else translate[lines])
            tmp.replace(path)
        except BaseException:
            tmp.unlink(missing_ok=True)
            raise
        return path

    def select(self, patterns) -> "Results":
        """A new table with the columns that match ``patterns`` (see ``select_columns``).

        Parameters
        ----------
        patterns : str or list of str
            Full names (``crank.fi``), ``crank.*``, ``*.Fx`` or a bare ``Fx``; None keeps
            every column.

        Returns
        -------
        Results
            The matching columns in the order of this table (copied), with the same ``t``,
            units, analysis, model, warnings and info.

        Raises
        ------
        ModelError
            A pattern matches no column.

        Examples
        --------
        >>> res = Results([0.0], {"crank.fi": [0.1], "B.Fx": [2.0], "B.Fy": [3.0]})
        >>> res.select(["Fy", "crank.*"]).columns
        ['crank.fi', 'B.Fy']
        """
        names = select_columns(self.columns, patterns)
        return Results(self.t, {n: self[n] for n in names}, self.units, self.analysis,
                       self.model, self.warnings, self.info, self.backend)

    def summary(self, max_rows: int = 60, warnings: bool = True) -> str:
        """A short text table: unit, first and last value, minimum and maximum of each column.

        What ``pam2exu run`` prints: a head line (analysis, model, rows, interval), one line
        per column, the self-checks (``checks``) and the warnings.

        Parameters
        ----------
        max_rows : int
            Most columns listed; a last line says how many more there are.
        warnings : bool
            End with the warnings (``pam2exu run`` prints them on stderr instead).

        Returns
        -------
        str
            Lines separated by newlines, no final newline.

        Examples
        --------
        >>> res = Results([0.0, 1.0], {"crank.fi": [0.0, 6.0]}, {"crank.fi": "rad"},
        ...               "kinematic", "demo")
        >>> print(res.summary())
        kinematic analysis of 'demo': 2 rows, t = 0 … 1 s, 1 columns
        <BLANKLINE>
        variable  unit            first          last           min           max
        crank.fi  rad                 0             6             0             6
        """
        head = f"{self.analysis} analysis of '{self.model}': {len(self)} rows, " \
               f"t = {self.t[0]:g} … {self.t[-1]:g} s, {len(self.columns)} columns"
        width = max([len(c) for c in self.columns] + [8])
        lines = [head, "",
                 f"{'variable':<{width}}  {'unit':<7} {'first':>13} {'last':>13} "
                 f"{'min':>13} {'max':>13}"]
        for name in self.columns[:max_rows]:
            v = self[name]
            lines.append(f"{name:<{width}}  {self.units.get(name, ''):<7} {v[0]:>13.6g} "
                         f"{v[-1]:>13.6g} {np.min(v):>13.6g} {np.max(v):>13.6g}")
        if len(self.columns) > max_rows:
            lines.append(f"… and {len(self.columns) - max_rows} more columns (write them all "
                         f"with -o results.csv)")
        lines += ["", "checks: " + "; ".join(self.checks())] if self.checks() else []
        lines += [f"warning: {w}" for w in self.warnings] if warnings else []
        return "\n".join(lines)

    def checks(self) -> list[str]:
        """The consistency checks the analysis ran, one phrase each: ``RunInfo.checks`` of
        ``info``, naming the backend that ran (``backend``).

        Examples
        --------
        >>> Results([0.0], {}, info={"max_residual": 3e-15}).checks()
        ['constraint residual 3.0e-15 m']
        """
        return self.info.checks(self.backend)

    def __repr__(self) -> str:
        return (f"<Results {self.analysis} '{self.model}': {len(self)} rows × "
                f"{len(self.columns)} columns>")


#: values the CSV writer formats at once: ~20 bytes each, so its memory stays bounded
_BLOCK = 1 << 20
_COMMA, _NEWLINE, _MINUS, _ZERO = b",\n-0"
#: the bytes of the lines of numbers that ``_csv_block`` writes (only such text reaches
#: scipy's C++ reader: scipy 1.17's crashes on some other, e.g. a last line '…,7e')
_WRITTEN = b"0123456789.-e,\nnaifty"


def _csv_header(names, sep: str = ",") -> str:
    """The header line (no line end): names ``sep`` separated, quoted when CSV needs it.

    A name holding ',', ';', '"' or a line break is written in quotes, '"' doubled.

    Examples
    --------
    >>> _csv_header(["t", "a,b.x", 'q"uo.y', "Força.Fx"])
    't,"a,b.x","q""uo.y",Força.Fx'
    """
    return sep.join(csv_field(n) for n in names)


def csv_field(name: str) -> str:
    """A name as a CSV field: in quotes, '"' doubled, when it holds ',', ';', '"' or a
    line break (``_csv_header``, the extremes' file)."""
    return '"' + name.replace('"', '""') + '"' if any(c in name for c in ',;"\r\n') else name


def _csv_block(values: np.ndarray) -> np.ndarray:
    """CSV lines of a (rows, columns) float block: the shortest digits that read back exactly.

    scipy's Matrix Market writer (fast_matrix_market: shortest round-trip digits, C++,
    several threads) writes the numbers one a line, row after row; every line end but each
    row's last becomes ',', and letters become lower case (``1e-5``, ``nan``, ``infinity``).

    Parameters
    ----------
    values : numpy.ndarray
        float64, shape (rows, columns), rows ≥ 1.

    Returns
    -------
    numpy.ndarray
        The ASCII text as uint8 (writable to a binary file as it is): one line per row, each
        ended by '\\n'.

    Examples
    --------
    >>> _csv_block(np.array([[0.1 + 0.2, -0.0, 1e300], [5e-324, 2.0, -np.inf]])).tobytes()
    b'3.0000000000000004e-1,-0,1e300\\n5e-324,2,-infinity\\n'
    """
    import scipy.io
    out = io.BytesIO()
    scipy.io.mmwrite(out, values.T, field="real", symmetry="general")
    head, start = out.getbuffer()[:1024].tobytes(), 0
    while head.startswith(b"%", start):       # the banner and comment lines
        start = head.index(b"\n", start) + 1
    start = head.index(b"\n", start) + 1       # the size line
    text = np.frombuffer(out.getbuffer(), np.uint8, offset=start)
    ends = np.flatnonzero(text == _NEWLINE)
    if ends.size != values.size:
        raise RuntimeError(f"scipy.io.mmwrite wrote {ends.size} lines for {values.size} numbers")
    text |= 0x20                  # 'E' → 'e', 'NaN' → 'nan'; digits, '.', '-' have the bit
    text[ends] = _COMMA
    text[ends[values.shape[1] - 1::values.shape[1]]] = _NEWLINE
    return text


def _csv_lines(values: np.ndarray):
    """``_csv_block`` of a (rows, columns) array, ``_BLOCK`` values at a time (uint8 text)."""
    step = max(1, _BLOCK // max(values.shape[1], 1))
    for start in range(0, values.shape[0], step):
        yield _csv_block(values[start:start + step])


def _pattern(p: str) -> str:
    """A bare variable name ``Fx`` means every ``*.Fx``."""
    return p if "." in p or p == "t" else f"*.{p}"


def select_columns(columns: list[str], patterns) -> list[str]:
    """Columns matching any pattern: full names, ``solid.*``, ``*.Fx`` or a bare ``Fx``.

    Patterns are shell-style (``fnmatch``, case-sensitive); one without a dot means that
    variable of every solid and element (``Fx`` is ``*.Fx``). ``t`` matches nothing and is
    no error (it is always in a table). PAM's spellings are read as pam2exu's
    (``names.spelled``: ``Forca`` is ``Força``, ``motor.f`` is ``motor.f(t)``).

    Parameters
    ----------
    columns : list of str
        The column names to choose from.
    patterns : str or list of str
        The patterns; None chooses every column.

    Returns
    -------
    list of str
        The columns matching any pattern, in the order of ``columns``.

    Raises
    ------
    ModelError
        A pattern matches no column (one problem per pattern, with the nearest name).

    Examples
    --------
    >>> select_columns(["crank.fi", "crank.Dfi", "B.Fx", "C.Fx"], ["Fx", "crank.fi"])
    ['crank.fi', 'B.Fx', 'C.Fx']
    >>> select_columns(["crank.fi"], "crank.fy")
    Traceback (most recent call last):
    ...
    pam2exu.errors.ModelError: outputs: 'crank.fy' matches no variable...(did you mean 'crank.fi'?)
    """
    if patterns is None:
        return list(columns)
    if isinstance(patterns, str):
        patterns = [patterns]
    chosen, problems = set(), []
    for p in map(spelled, patterns):
        hits = [c for c in columns if selects(_pattern(p), c)]
        if not hits and p != "t":
            problems.append(Problem("outputs", f"'{p}' matches no variable of this analysis"
                                               f"{closest(p, columns)}"))
        chosen.update(hits)
    if problems:
        raise ModelError(problems)
    return [c for c in columns if c in chosen]


def _read_own(path: Path) -> Results | None:
    """A file exactly as ``to_csv`` writes it, read fast; None for any other file.

    scipy's Matrix Market reader (fast_matrix_market: fast_float, correctly rounded, C++)
    reads the numbers; they are taken only when ``_csv_lines`` writes them back as the
    file's own bytes, so they are what the general reader (``reading.load_table``, which
    ``compare`` uses) reads, bit for bit, whatever the file holds. Anything else (another
    writer's digits, comments, ';', a byte-order mark, CRLF) is None, and ``read_csv`` reads
    it the general way.

    Parameters
    ----------
    path : Path
        The CSV file.

    Returns
    -------
    Results or None
        The file's columns under its header's names, ``t`` first; None when the file is
        not exactly ``to_csv``'s (or cannot be read: the general reader says why).
    """
    import scipy.io
    try:
        raw = path.read_bytes()
        end = raw.index(b"\n")
        header = raw[:end].decode("utf-8")
        names = next(csv.reader([header]), [])
    except (OSError, ValueError, csv.Error):   # UnicodeDecodeError is a ValueError
        return None
    body = raw[end + 1:]
    rows = body.count(b"\n")
    if rows == 0 or not body.endswith(b"\n") or body.translate(None, _WRITTEN) \
            or names[:1] != ["t"] or len(set(names)) < len(names) or _csv_header(names) != header:
        return None
    banner = f"%%MatrixMarket matrix array real general\n{len(names)} {rows}\n".encode()
    try:
        values = scipy.io.mmread(io.BytesIO(banner + body.replace(b",", b"\n")))
    except ValueError:
        return None
    text = np.frombuffer(raw, np.uint8)
    if b"-0," in body or b"-0\n" in body:      # the reader makes "-0" +0.0
        ends = end + 1 + np.flatnonzero((text[end + 1:] == _COMMA) | (text[end + 1:] == _NEWLINE))
        if ends.size != values.size:
            return None
        starts = np.r_[end + 1, ends[:-1] + 1]
        k = np.flatnonzero((ends - starts == 2) & (text[starts] == _MINUS)
                           & (text[starts + 1] == _ZERO))
        values[k % len(names), k // len(names)] = -0.0
    at = end + 1
    for block in _csv_lines(values.T):
        if not np.array_equal(text[at:at + block.size], block):
            return None
        at += block.size
    if at != text.size:
        return None
    return Results(values[0], dict(zip(names[1:], values[1:])))

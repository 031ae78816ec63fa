"""The result of an analysis: one table of named columns, PAM's variable names.

``Results``: the columns over time, what made them (the analysis, the model), the run's
warnings and facts, and the table's views (a column, a selection, the summary, the
checks). Its files are written elsewhere: CSV by ``table_csv`` (``Results.to_csv``), the
other forms by ``writers``; any result CSV file is read by ``reading.read_csv``.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import closest
from ..limits import one_form
from ..registry import AnalysisType, analysis_type
from .info import RunInfo
from .instant import Instants
from .names import select_columns
from .table_csv import write_csv
from .writers import Exports


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
    analysis : str or AnalysisType
        The analysis that made the table: its declaration (``registry.AnalysisType``) or
        its name (``'kinematic'``, …; '' when unknown).
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
        The analysis's name (``'kinematic'``, …; '' when unknown): what summaries and
        files say.
    analysis_type : AnalysisType or None
        The analysis's declaration (``registry.ANALYSES``), found by its name (None for
        a name the registry does not know, or '', as for a table read from a CSV file):
        what it gives (``levels``, one row ``at_start``, …).
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
        data = np.empty((1 + len(columns), len(t)))
        data[0] = t
        for i, values in enumerate(columns.values(), start=1):
            data[i] = values
        self._own(list(columns), data, units, analysis, model, warnings, info, backend)

    @classmethod
    def _on(cls, names: list[str], data: np.ndarray, units: dict[str, str] | None = None,
            analysis: str = "", model: str = "", warnings=None, info=None,
            backend: str = "") -> "Results":
        """The table of the columns ``names`` whose storage is ``data`` itself (1 + columns,
        rows; t first), not copied: for the analyses, which write their table in place."""
        res = cls.__new__(cls)
        res._own(names, data, units, analysis, model, warnings, info, backend)
        return res

    def _own(self, names, data, units, analysis, model, warnings, info, backend) -> None:
        """Set the table on its storage ``data`` (``__init__``, ``_on``)."""
        self._names = ["t", *map(one_form, names)]        # names in one Unicode form
        self._data = data
        self._index = {name: i for i, name in enumerate(self._names)}
        self.units = {"t": "s", **{one_form(k): v for k, v in (units or {}).items()}}
        self.analysis, self.model = analysis, model     # the name (``analysis``'s setter)
        self.backend = backend
        self.warnings = list(warnings or [])
        self.info = RunInfo(**dict(info or {}))

    @property
    def analysis(self) -> str:
        """The analysis's name ('' when unknown); set from a name or an ``AnalysisType``."""
        return self._analysis

    @analysis.setter
    def analysis(self, value) -> None:
        self._analysis = value.name if isinstance(value, AnalysisType) else value

    @property
    def analysis_type(self):
        """The analysis's declaration (``registry.AnalysisType``), looked up by its name
        (Catalan names too); None when the registry knows no analysis of that name."""
        return analysis_type(self._analysis)

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
        return write_csv(Path(path), self._names, self._data.T, self.units, sep, decimal, bom)

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

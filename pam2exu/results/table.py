"""The result of an analysis: one table of named columns, PAM's variable names."""
from __future__ import annotations

import fnmatch
from pathlib import Path

import numpy as np

from ..errors import ModelError, Problem, closest


class Results:
    """Columns ``<name>.<variable>`` over time, stored as one array.

    ``res["crank.fi"]`` is a NumPy view of a column, ``res.t`` the times [s],
    ``res.columns`` the column names (without ``t``), ``res.units`` their SI units,
    ``res.to_numpy()`` the (steps + 1, 1 + columns) array with ``t`` first (a view, no copy)
    and ``res.to_csv(path)`` the CSV file of the contract.

    Attributes
    ----------
    analysis : str
    model : str
        The model's name.
    warnings : list[str]
        Warnings raised during the run (redundant constraints, …).
    info : dict
        Run facts: degrees of freedom, redundancy, maximum constraint residual, timings.
    """

    def __init__(self, t, columns: dict[str, np.ndarray], units: dict[str, str] | None = None,
                 analysis: str = "", model: str = "", warnings=None, info=None):
        t = np.asarray(t, dtype=float)
        self._names = ["t", *columns]
        self._data = np.empty((len(self._names), len(t)))
        self._data[0] = t
        for i, values in enumerate(columns.values(), start=1):
            self._data[i] = values
        self._index = {name: i for i, name in enumerate(self._names)}
        self.units = {"t": "s", **(units or {})}
        self.analysis, self.model = analysis, model
        self.warnings = list(warnings or [])
        self.info = dict(info or {})

    @property
    def t(self) -> np.ndarray:
        """Times [s]."""
        return self._data[0]

    @property
    def columns(self) -> list[str]:
        """Column names, without ``t``."""
        return self._names[1:]

    def __getitem__(self, name: str) -> np.ndarray:
        if name not in self._index:
            raise KeyError(f"no column '{name}'{closest(name, self._names)}")
        return self._data[self._index[name]]

    def __contains__(self, name: str) -> bool:
        return name in self._index

    def __len__(self) -> int:
        return self._data.shape[1]

    def to_numpy(self) -> np.ndarray:
        """(rows, 1 + columns) array, ``t`` first: a transposed view of the storage."""
        return self._data.T

    def to_csv(self, path: str | Path) -> Path:
        """Write UTF-8 CSV: header ``t,<name>.<variable>,…``, full float precision."""
        path = Path(path)
        tmp = path.with_name(path.name + ".part")
        with open(tmp, "w", encoding="utf-8", newline="\n") as fh:
            fh.write(",".join(self._names) + "\n")
            np.savetxt(fh, self._data.T, delimiter=",", fmt="%.17g")
        tmp.replace(path)
        return path

    def select(self, patterns) -> "Results":
        """A new table with the columns that match ``patterns`` (see ``select_columns``)."""
        names = select_columns(self.columns, patterns)
        return Results(self.t, {n: self[n] for n in names}, self.units, self.analysis,
                       self.model, self.warnings, self.info)

    def summary(self, max_rows: int = 60) -> str:
        """A short text table: unit, first and last value, minimum and maximum of each column."""
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
        checks = self.checks()
        if checks:
            lines += ["", "checks: " + "; ".join(checks)]
        for w in self.warnings:
            lines.append(f"warning: {w}")
        return "\n".join(lines)

    def checks(self) -> list[str]:
        """The consistency checks the analysis ran, one phrase each (from ``info``)."""
        info, out = self.info, []
        if "max_residual" in info:
            out.append(f"constraint residual {info['max_residual']:.1e} m")
        if "equilibrium_error" in info:
            out.append(f"Exudyn's multipliers vs native equilibrium {info['equilibrium_error']:.1e}"
                       " (relative)")
        if "power_balance_error" in info:
            out.append(f"power balance {info['power_balance_error']:.2g} W "
                       f"(finite-difference tolerance {info['power_balance_tolerance']:.2g} W)")
        return out

    def __repr__(self) -> str:
        return (f"<Results {self.analysis} '{self.model}': {len(self)} rows × "
                f"{len(self.columns)} columns>")


def _pattern(p: str) -> str:
    """A bare variable name ``Fx`` means every ``*.Fx``."""
    return p if "." in p or p == "t" else f"*.{p}"


def select_columns(columns: list[str], patterns) -> list[str]:
    """Columns matching any pattern: full names, ``solid.*``, ``*.Fx`` or a bare ``Fx``.

    Raises ModelError for a pattern that matches no column of this analysis.
    """
    if patterns is None:
        return list(columns)
    if isinstance(patterns, str):
        patterns = [patterns]
    chosen, problems = set(), []
    for p in patterns:
        hits = [c for c in columns if fnmatch.fnmatchcase(c, _pattern(p))]
        if not hits and p != "t":
            problems.append(Problem("outputs", f"'{p}' matches no variable of this analysis"
                                               f"{closest(p, columns)}"))
        chosen.update(hits)
    if problems:
        raise ModelError(problems)
    return [c for c in columns if c in chosen]


def read_csv(path: str | Path, model=None) -> Results:
    """A result CSV file as a Results table, with units from the output declarations.

    Reads what ``pam2exu compare`` reads: ``Results.to_csv`` files and PAM-style exports
    (',' or ';' separated, decimal comma with ';', PAM spellings such as ``Forca``).
    ``model`` (a Model or a model file) gives the units of ``f(t)`` and ``Df(t)``, which
    depend on the actuator type (see ``units.unit_of``). Raises CompareInputError for a
    missing or unreadable file.
    """
    from ..model import Model, load
    from .compare import _load
    from .units import unit_of
    if model is not None and not isinstance(model, Model):
        model = load(model)
    table = _load(path, "results", {})
    units = {name: unit_of(name, model) for name in table.names}
    return Results(table.t, dict(zip(table.names, table.values)), units,
                   model=Path(path).stem if model is None else model.name)

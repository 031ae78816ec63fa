"""The values of a result at one instant, grouped by solid and element as a teacher reads a
free-body diagram (``Results.at``, ``pam2exu run MODEL --at T``).

At a time of the table's grid the values are that row's; between rows they are
interpolated by the not-a-knot cubic spline ``pam2exu compare`` uses
(``interpolation.interpolate``), and the text says so, with a bound of each value's
interpolation error (``interpolation.error_bound``).
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from ..errors import closest
from .interpolation import error_bound, interpolate

#: a time within this fraction of a step of a row is that row's time (no interpolation)
GRID_TOLERANCE = 1e-9


@dataclass
class Instant(Mapping):
    """Every column of a result at one time: column → value, read as a dict.

    ``inst["crank.fi"]`` is a float; ``inst.group("B")`` the columns of one solid or
    element; ``str(inst)`` / ``repr(inst)`` one block per solid and element with values
    and units (a joint's reactions in its own block).

    Attributes
    ----------
    t : float
        The time [s].
    by_column : dict
        Column → value, in the table's order (also ``dict(inst)``).
    units : dict
        Column → SI unit ('' when unknown).
    row : int or None
        The table's row at ``t`` when it is a grid time; None when interpolated.
    between : (int, int) or None
        The rows ``t`` lies between when interpolated.
    errors : dict
        Column → bound of the interpolation error (empty at a grid time; NaN with fewer
        than 5 rows).
    kinds : dict
        Owner → what it is (``"solid"``, ``"revolute"``, …), for the block titles; empty
        when unknown (``kinds_of(model)``).
    title : str
        The first line of the text (model, analysis).
    """

    t: float
    by_column: dict
    units: dict
    row: int | None = None
    between: tuple[int, int] | None = None
    errors: dict = field(default_factory=dict)
    kinds: dict = field(default_factory=dict)
    title: str = ""

    def __getitem__(self, column: str) -> float:
        if column not in self.by_column:
            raise KeyError(f"no column '{column}'{closest(column, list(self.by_column))}")
        return self.by_column[column]

    def __iter__(self):
        return iter(self.by_column)

    def __len__(self) -> int:
        return len(self.by_column)

    @property
    def interpolated(self) -> bool:
        """Whether the values come from the spline (t is not a grid time)."""
        return self.row is None

    def owners(self) -> dict[str, list[str]]:
        """Solid or element name → its columns (the part before the first dot), in order."""
        out: dict[str, list[str]] = {}
        for column in self.by_column:
            out.setdefault(column.partition(".")[0], []).append(column)
        return out

    def group(self, owner: str) -> dict[str, float]:
        """The values of one solid or element: variable (``x``, ``P.Dx``, ``Fx``) → value."""
        columns = self.owners().get(owner)
        if columns is None:
            raise KeyError(f"no solid or element '{owner}'{closest(owner, self.owners())}")
        return {c.partition(".")[2]: self.by_column[c] for c in columns}

    def text(self) -> str:
        """The values as blocks, one per solid and element: variable, value, unit."""
        if self.interpolated:
            i, j = self.between
            how = (f"interpolated by the cubic spline of pam2exu compare between rows {i} and "
                   f"{j}; the last column bounds its error")
        else:
            how = f"row {self.row} of the table"
        lines = [f"{self.title}values at t = {self.t:.6g} s ({how})"]
        width = max([len(c.partition('.')[2]) for c in self.by_column] + [8])
        for owner, columns in self.owners().items():
            kind = self.kinds.get(owner)
            lines += ["", f"{owner} ({kind})" if kind else owner]
            for c in columns:
                var, value = c.partition(".")[2], self.by_column[c]
                line = f"  {var:<{width}} {value:>14.7g}  {self.units.get(c, ''):<7}"
                if self.interpolated:
                    line += f" ±{rounded_up(self.errors.get(c, math.nan))}"
                lines.append(line.rstrip())
        return "\n".join(lines)

    __str__ = text

    def __repr__(self) -> str:
        return self.text()


def rounded_up(bound: float, digits: int = 2) -> str:
    """A bound printed with ``digits`` significant digits, rounded up (so that it still
    bounds): 1.401e-9 → '1.5e-09'; 'nan' when unknown."""
    if not math.isfinite(bound) or bound <= 0:
        return f"{bound:.{digits}g}"
    scale = 10.0 ** (math.floor(math.log10(bound)) - digits + 1)
    return f"{math.ceil(bound / scale * (1 - 1e-12)) * scale:.{digits}g}"


def at(res, t: float, kinds: dict | None = None) -> Instant:
    """Every column of ``res`` at time t: the row at a grid time, else the cubic spline.

    Parameters
    ----------
    res : Results
        A result table.
    t : float
        The time [s], within the table's interval.
    kinds : dict, optional
        Owner → kind for the block titles (``kinds_of(model)``).

    Returns
    -------
    Instant

    Raises
    ------
    ValueError
        t is not a number or outside the table's times.

    Examples
    --------
    >>> from pam2exu.results import Results
    >>> res = Results([0.0, 0.5, 1.0], {"crank.fi": [0.0, 1.0, 4.0]}, {"crank.fi": "rad"})
    >>> at(res, 0.5)["crank.fi"], at(res, 0.5).row, at(res, 0.25).interpolated
    (1.0, 1, True)
    """
    times = res.t
    t = float(t)
    step = float(np.max(np.diff(times))) if len(times) > 1 else 0.0
    tol = GRID_TOLERANCE * step
    if not math.isfinite(t) or not times[0] - tol <= t <= times[-1] + tol:
        raise ValueError(f"t = {t:g} s is outside the result's times, t = {times[0]:g} … "
                         f"{times[-1]:g} s")
    k = int(np.argmin(np.abs(times - t)))
    units = {c: res.units.get(c, "") for c in res.columns}
    title = f"{res.model}, {res.analysis} analysis: " if res.model else ""
    common = dict(kinds=dict(kinds or {}), title=title)
    if abs(times[k] - t) <= tol:
        return Instant(float(times[k]), {c: float(res[c][k]) for c in res.columns}, units,
                       row=k, **common)
    data = res.to_numpy()[:, 1:].T
    value = interpolate(times, data, np.array([t]))[:, 0]
    error = error_bound(times, data, np.array([t]))[:, 0]
    j = int(np.searchsorted(times, t))
    return Instant(t, dict(zip(res.columns, map(float, value))), units, between=(j - 1, j),
                   errors=dict(zip(res.columns, map(float, error))), **common)


class Instants:
    """``Results``' values at one time (``at``); uses ``t``, ``columns``, ``units`` and the
    table's rows."""

    def at(self, t: float, kinds: dict | None = None) -> Instant:
        """Every column at time t, grouped by solid and element: the row at a grid time,
        else the cubic spline of ``pam2exu compare`` (and the text says so).

        Parameters
        ----------
        t : float
            The time [s], within the table's times.
        kinds : dict, optional
            Solid or element name → what it is, for the titles of the blocks
            (``instant.kinds_of(model)``).

        Returns
        -------
        Instant
            Column → value (a dict-like), with ``row`` (the row at a grid time, else None),
            ``between`` (the two rows it is interpolated between), ``errors`` (each value's
            interpolation error's bound), ``owners()``, ``group(name)``; printed, one
            block per solid and element with values and units.

        Raises
        ------
        ValueError
            t is not a number or outside the table's times.

        Examples
        --------
        >>> from pam2exu.results import Results
        >>> res = Results([0.0, 0.5, 1.0], {"crank.fi": [0.0, 1.0, 4.0], "B.Fx": [1.0, 2.0, 3.0]},
        ...               {"crank.fi": "rad", "B.Fx": "N"}, "kinematic", "demo")
        >>> res.at(0.5)["crank.fi"], res.at(0.5).group("B")
        (1.0, {'Fx': 2.0})
        >>> print(res.at(0.5))
        demo, kinematic analysis: values at t = 0.5 s (row 1 of the table)
        <BLANKLINE>
        crank
          fi                    1  rad
        <BLANKLINE>
        B
          Fx                    2  N
        """
        return at(self, t, kinds)


def kinds_of(model) -> dict[str, str]:
    """Name → ``"solid"`` or the element's type, for the titles of ``Instant`` blocks."""
    return {**{s.name: "solid" for s in model.solids},
            **{e.name: e.type for e in model.elements}}


def report(res, times, kinds: dict | None = None, warnings: bool = True) -> str:
    """``pam2exu run --at``: the ``Instant`` text at each time, then the run's checks, its
    notes and (``warnings``) its warnings, as ``Results.summary`` ends."""
    blocks = [at(res, t, kinds).text() for t in times]
    tail = []
    if res.checks():
        tail.append("checks: " + "; ".join(res.checks()))
    if "undefined" in res.info:
        tail.append(f"note: {res.info['undefined']}")
    tail += [f"warning: {w}" for w in res.warnings] if warnings else []
    return "\n\n".join(blocks) + ("\n\n" + "\n".join(tail) if tail else "")

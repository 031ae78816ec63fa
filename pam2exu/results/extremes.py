"""The extremes of a clearance run (shared/spec/clearance.md, "Extremes").

Per clearance column of a result, its smallest and largest value over the rows (at the
sample times, not between them) and the first time each is reached; written beside the
result CSV (``run.csv`` gives ``run.extremes.csv``) with the header
``column,min,t_min,max,t_max``, one row per clearance column in the result's order, every
value at full precision (the shortest text that reads back as the same float).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..elements import CLEARANCE, ELEMENTS
from .table_csv import csv_field
from .writers import write_whole

#: the variables of the joints' clearance parameters and of what derives from them
CLEARANCE_VARIABLES = frozenset(v.name for cls in ELEMENTS.values()
                                for v in cls.clearance_parameters + cls.clearance_derived)


@dataclass(frozen=True)
class Extreme:
    """One clearance column's extremes: min at t_min, max at t_max (first rows reaching them)."""

    column: str
    min: float
    t_min: float
    max: float
    t_max: float


def clearance_columns(res) -> list[str]:
    """The result's clearance columns (``<joint>.<parameter>``), in its order; none unless
    it comes from an analysis that gives clearance parameters (``CLEARANCE`` among its
    levels: the clearance analysis)."""
    kind = res.analysis_type
    if kind is None or CLEARANCE not in kind.levels:
        return []
    return [c for c in res.columns if c.rpartition(".")[2] in CLEARANCE_VARIABLES]


def extremes(res) -> list[Extreme]:
    """The extremes of every clearance column of ``res`` (``Extreme``)."""
    out = []
    for c in clearance_columns(res):
        values = np.asarray(res[c], dtype=float)
        low, high = int(np.argmin(values)), int(np.argmax(values))
        out.append(Extreme(c, float(values[low]), float(res.t[low]),
                           float(values[high]), float(res.t[high])))
    return out


def extremes_path(path: str | Path) -> Path:
    """Where the extremes of the result file ``path`` go, as CSV: ``run.csv`` ->
    ``run.extremes.csv`` (``run.xlsx`` and ``run.parquet`` too: before, a CSV was written
    under the name ``run.extremes.xlsx``, fuzz seed 100072)."""
    path = Path(path)
    return path.with_name(f"{path.stem}.extremes.csv")


def write_extremes(res, path: str | Path) -> Path:
    """Write the extremes of ``res`` as CSV at ``path`` (under a temporary name, then
    renamed: a failure leaves no half file); the path written."""
    path = Path(path)
    lines = ["column,min,t_min,max,t_max"]
    for e in extremes(res):
        lines.append(",".join([csv_field(e.column),
                               *(repr(v) for v in (e.min, e.t_min, e.max, e.t_max))]))
    return write_whole(path, lambda tmp: tmp.write_text("\n".join(lines) + "\n",
                                                       encoding="utf-8"))


def extremes_table(res) -> str:
    """The extremes as a printed table (not part of the contract)."""
    rows = extremes(res)
    if not rows:
        return ""
    width = max(len(e.column) for e in rows)
    lines = [f"{'column':<{width}}  {'min':>13} {'t_min':>10}  {'max':>13} {'t_max':>10}"]
    lines += [f"{e.column:<{width}}  {e.min:>13.6g} {e.t_min:>10.6g}  {e.max:>13.6g} "
              f"{e.t_max:>10.6g}" for e in rows]
    return "\n".join(lines)

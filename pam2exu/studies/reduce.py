"""What a study makes of one variant's run: its reduced outputs, its status and its row.

A variant's result is reduced over its rows (t = 0 … t_end, each row weighted equally) to
one value per output column and reduction, named ``<output>.<reduction>``
(``motor.Mz.absmax``): ``REDUCTIONS`` holds the seven, one small function each with its
first-order derivative (the linear method). A clearance component (``A.jx``, ``A.jr``,
``G.jn``: the clearance analysis's clearance parameters,
``results.extremes.clearance_columns``) is reduced as its absolute value, so
``A.jx.max`` is the largest |jx| the variant needs over the motion.

A value that is not a number (NaN) makes every reduction of its column NaN: it is never
dropped silently. The result of a run that succeeds has none (the analyses' last guard
refuses values that are not finite), so a NaN reduction marks a table that is not a run's.

``status`` tells "ok" from "rejected" by the requirements; ``variant_table`` lays the
variants out as the per-variant table's NumPy columns: ``sample``, ``status``, ``error``,
each parameter, each reduced output (a variant in error: NaN outputs).
"""
from __future__ import annotations

from typing import Callable, NamedTuple

import numpy as np

from ..elements import ELEMENTS
from ..errors import ModelError, Problem, closest
from ..results.extremes import clearance_columns
from ..results.names import select_columns


def minimum(y: np.ndarray) -> np.ndarray:
    """min_i y_i (over the last axis: one value per row of a 2-D y)."""
    return np.min(y, axis=-1)


def maximum(y: np.ndarray) -> np.ndarray:
    """max_i y_i."""
    return np.max(y, axis=-1)


def absmax(y: np.ndarray) -> np.ndarray:
    """max_i |y_i|."""
    return np.max(np.abs(y), axis=-1)


def mean(y: np.ndarray) -> np.ndarray:
    """(1/n) Σ_i y_i."""
    return np.mean(y, axis=-1)


def rms(y: np.ndarray) -> np.ndarray:
    """sqrt((1/n) Σ_i y_i²)."""
    return np.sqrt(np.mean(np.square(y), axis=-1))


def final(y: np.ndarray) -> np.ndarray:
    """y_n: the last row (t = t_end)."""
    return y[..., -1]


def spread(y: np.ndarray) -> np.ndarray:
    """max_i y_i − min_i y_i."""
    return np.max(y, axis=-1) - np.min(y, axis=-1)


# ---- first order: ∂(reduction)/∂p from the series' ∂y/∂p (the linear method) -------------
# Each takes y (n,) and dy = ∂y/∂p (n, P) and gives the reduction's derivative (P,). On the
# rows of a run a max is a max over finitely many values: where it is attained at one row
# k its derivative is ∂y_k/∂p exactly (Danskin), as for min, absmax and range.

def d_minimum(y: np.ndarray, dy: np.ndarray) -> np.ndarray:
    """∂ min_i y_i = ∂y_k, k = argmin y."""
    return dy[int(np.argmin(y))]


def d_maximum(y: np.ndarray, dy: np.ndarray) -> np.ndarray:
    """∂ max_i y_i = ∂y_k, k = argmax y."""
    return dy[int(np.argmax(y))]


def d_absmax(y: np.ndarray, dy: np.ndarray) -> np.ndarray:
    """∂ max_i |y_i| = sign(y_k) ∂y_k, k = argmax |y|."""
    k = int(np.argmax(np.abs(y)))
    return np.sign(y[k]) * dy[k]


def d_mean(y: np.ndarray, dy: np.ndarray) -> np.ndarray:
    """∂ (1/n) Σ y_i = (1/n) Σ ∂y_i."""
    return np.mean(dy, axis=0)


def d_rms(y: np.ndarray, dy: np.ndarray) -> np.ndarray:
    """∂ sqrt(mean y²) = mean(y ∂y) / rms."""
    return np.mean(y[:, None] * dy, axis=0) / np.sqrt(np.mean(np.square(y)))


def d_final(y: np.ndarray, dy: np.ndarray) -> np.ndarray:
    """∂ y_n = ∂y_n."""
    return dy[-1]


def d_spread(y: np.ndarray, dy: np.ndarray) -> np.ndarray:
    """∂ (max y − min y) = ∂y_argmax − ∂y_argmin."""
    return dy[int(np.argmax(y))] - dy[int(np.argmin(y))]


class Reduction(NamedTuple):
    """One reduction: its value over a run's rows (the last axis: several outputs' series
    at once, one per row of a 2-D array, each reduced as alone: the same bits), and its
    first-order derivative from the series' ∂y/∂p (the linear method). Called on one
    series, it gives its value as a float."""

    value: Callable[[np.ndarray], np.ndarray]
    derivative: Callable[[np.ndarray, np.ndarray], np.ndarray]

    def __call__(self, y: np.ndarray) -> float:
        """The reduction of the rows y (n,)."""
        return float(self.value(y))


#: the reductions of a variant's output column, by the name a study file gives them, in
#: the contract's order, each with its derivative
REDUCTIONS = {"min": Reduction(minimum, d_minimum), "max": Reduction(maximum, d_maximum),
              "absmax": Reduction(absmax, d_absmax), "mean": Reduction(mean, d_mean),
              "rms": Reduction(rms, d_rms), "final": Reduction(final, d_final),
              "range": Reduction(spread, d_spread)}
#: the reductions whose first-order σ is the summary's ``linear_std`` (the contract's)
LINEAR_STD = ("final", "mean")


#: a joint's radial clearance (a revolute's ``jr``), as the joints declare what derives
#: from their clearance parameters (``Element.clearance_derived``)
RADIAL = frozenset(v.name for cls in ELEMENTS.values() for v in cls.clearance_derived)


def radial_clearances(reduced: list[str]) -> list[str]:
    """The reduced outputs ``<joint>.jr.max`` among ``reduced``: the radial clearance each
    variant needs over the motion, in order.

    Examples
    --------
    >>> radial_clearances(["pin2.jx.max", "pin2.jr.max", "pin2.jr.mean", "pin3.jr.max"])
    ['pin2.jr.max', 'pin3.jr.max']
    """
    out = []
    for name in reduced:
        column, _, reduction = name.rpartition(".")
        if reduction == "max" and column.rpartition(".")[2] in RADIAL:
            out.append(name)
    return out


STATUSES = ("ok", "rejected", "error")
OK, REJECTED, ERROR = STATUSES


def reduced_name(column: str, reduction: str) -> str:
    """'<output>.<reduction>': ``reduced_name("motor.Mz", "absmax")`` is 'motor.Mz.absmax'."""
    return f"{column}.{reduction}"


def output_columns(columns: list[str], outputs=None) -> list[str]:
    """The columns the ``outputs`` patterns choose, in the patterns' order (each column
    once, where its first pattern chooses it; a pattern's columns in the table's order).

    The patterns are those of ``[analysis] outputs`` (``results.names.select_columns``:
    full names, ``B.F*``, ``*.Fx``, a bare ``Fx``, PAM's spellings); None chooses every
    column. A pattern that matches nothing is a ``ModelError`` (one problem per pattern,
    with the nearest name).

    Examples
    --------
    >>> output_columns(["crank.fi", "B.Fx", "B.Fy", "motor.Mz"], ["motor.Mz", "B.F*"])
    ['motor.Mz', 'B.Fx', 'B.Fy']
    """
    if outputs is None:
        return list(columns)
    if isinstance(outputs, str):
        outputs = [outputs]
    select_columns(columns, outputs)                  # every pattern's problem at once
    chosen = {}
    for pattern in outputs:
        chosen.update(dict.fromkeys(select_columns(columns, [pattern])))
    return list(chosen)


def check_reductions(reductions) -> list[str]:
    """The reductions' names as a list; ``ModelError`` naming each unknown one (with the
    closest name and the seven allowed)."""
    reductions = [reductions] if isinstance(reductions, str) else list(reductions)
    problems = [Problem("reduce", f"unknown reduction '{r}'{closest(r, REDUCTIONS)}: one of "
                                  f"{', '.join(REDUCTIONS)}")
                for r in reductions if r not in REDUCTIONS]
    if problems:
        raise ModelError(problems)
    return reductions


def reduced_names(columns: list[str], outputs=None, reductions=tuple(REDUCTIONS)) -> list[str]:
    """The names ``reduce_run`` gives a result with these ``columns``, in its order: the
    per-variant table's output columns, known before any variant has run (from the
    columns the analysis gives).

    Examples
    --------
    >>> reduced_names(["crank.fi", "B.Fx", "B.Fy", "motor.Mz"], ["Mz", "B.F*"], ["absmax", "rms"])
    ['motor.Mz.absmax', 'motor.Mz.rms', 'B.Fx.absmax', 'B.Fx.rms', 'B.Fy.absmax', 'B.Fy.rms']
    """
    reductions = check_reductions(reductions)
    return [reduced_name(c, r) for c in output_columns(columns, outputs) for r in reductions]


def reduce_run(results, outputs=None, reductions=tuple(REDUCTIONS)) -> dict[str, float]:
    """A variant's run reduced: ``<output>.<reduction>`` → value.

    Parameters
    ----------
    results : Results
        The variant's result table (its rows weighted equally).
    outputs : str or list of str, optional
        Output names and patterns as in ``[analysis] outputs`` (``output_columns``); None:
        every column of ``results``.
    reductions : str or sequence of str
        Names from ``REDUCTIONS``; default all seven.

    Returns
    -------
    dict
        ``'<column>.<reduction>'`` → float, in the outputs' order, then the reductions'
        (``motor.Mz.absmax``, ``motor.Mz.rms``, ``B.Fx.absmax``, …). A clearance
        component is reduced as its absolute value; a column with a NaN row has NaN
        for every reduction.

    Raises
    ------
    ModelError
        An output pattern matches no column, or a reduction is unknown.

    Examples
    --------
    >>> from pam2exu.results import Results
    >>> res = Results([0.0, 0.5, 1.0], {"motor.Mz": [1.0, -3.0, 2.0]})
    >>> reduce_run(res, ["Mz"], ["absmax", "final"])
    {'motor.Mz.absmax': 3.0, 'motor.Mz.final': 2.0}
    """
    reductions = check_reductions(reductions)
    columns = output_columns(results.columns, outputs)
    if not columns:
        return {}
    absolute = set(clearance_columns(results))
    y = np.array([results[column] for column in columns], dtype=float)   # one row each
    magnitudes = [i for i, column in enumerate(columns) if column in absolute]
    if magnitudes:
        y[magnitudes] = np.abs(y[magnitudes])
    unknown = np.isnan(y).any(axis=1)              # never dropped: every reduction NaN
    with np.errstate(invalid="ignore"):
        values = {r: REDUCTIONS[r].value(y) for r in reductions}
    out = {}
    for i, column in enumerate(columns):
        for r in reductions:
            out[reduced_name(column, r)] = np.nan if unknown[i] else float(values[r][i])
    return out


class Requirement(NamedTuple):
    """A reduced output's bounds: min ≤ value ≤ max (None: that side is free)."""

    output: str
    min: float | None = None
    max: float | None = None


def meets(value: float, low: float | None, high: float | None) -> bool:
    """low ≤ value ≤ high, a bound of None left out; a NaN value meets no bound.

    A value exactly at a bound meets it: a limit is inclusive, as a tolerance's limits are
    (a part at its upper limit is in tolerance).
    """
    return (low is None or value >= low) and (high is None or value <= high)


def status(reduced: dict[str, float], requirements=()) -> str:
    """'ok' when the reduced outputs meet every requirement (``meets``), else 'rejected'.

    Parameters
    ----------
    reduced : dict
        ``reduce_run``'s values of a variant that ran.
    requirements : iterable of (output, min, max)
        A reduced output's name (``motor.Mz.absmax``) and its bounds, None for an absent one.

    Raises
    ------
    ModelError
        A requirement names an output that is not reduced (with the closest name).

    Examples
    --------
    >>> status({"motor.Mz.absmax": 12.0}, [("motor.Mz.absmax", None, 12.0)])
    'ok'
    >>> status({"motor.Mz.absmax": 12.5}, [("motor.Mz.absmax", None, 12.0)])
    'rejected'
    """
    requirements = [Requirement(*r) for r in requirements]
    missing = [Problem("[[requirement]]", f"'{r.output}' is not a reduced output"
                                          f"{closest(r.output, reduced)}")
               for r in requirements if r.output not in reduced]
    if missing:
        raise ModelError(missing)
    ok = all(meets(reduced[r.output], r.min, r.max) for r in requirements)
    return OK if ok else REJECTED


class Variant(NamedTuple):
    """One variant's row: its index, status, error ('' unless status is 'error': the
    error's class and message), its parameters' values and its reduced outputs (None for
    a variant in error)."""

    sample: int
    status: str
    error: str
    values: tuple[float, ...]
    reduced: dict[str, float] | None


def variant_table(parameters: list[str], outputs: list[str], variants) -> dict[str, np.ndarray]:
    """The per-variant table as NumPy columns: ``sample`` (int64), ``status``, ``error``
    (str), each parameter, each reduced output (float64; NaN for a variant in error).

    Parameters
    ----------
    parameters : list of str
        The parameters' names, in the study's order (the order of ``Variant.values``).
    outputs : list of str
        The reduced outputs' names (``reduce_run``'s keys, in its order).
    variants : iterable of Variant (or tuples in its order)
        The rows, in variant order.

    Examples
    --------
    >>> t = variant_table(["crank.A.x"], ["motor.Mz.absmax"],
    ...                   [(0, "ok", "", (0.1,), {"motor.Mz.absmax": 2.5}),
    ...                    (1, "error", "AssemblyError: no closure", (0.3,), None)])
    >>> list(t)
    ['sample', 'status', 'error', 'crank.A.x', 'motor.Mz.absmax']
    >>> t["motor.Mz.absmax"].tolist(), t["error"].tolist()
    ([2.5, nan], ['', 'AssemblyError: no closure'])
    """
    rows = [Variant(*v) for v in variants]
    table = {"sample": np.array([v.sample for v in rows], dtype=np.int64),
             "status": np.array([v.status for v in rows], dtype=str),
             "error": np.array([v.error for v in rows], dtype=str)}
    values = np.array([v.values for v in rows], dtype=float).reshape(len(rows), len(parameters))
    table.update({name: values[:, j].copy() for j, name in enumerate(parameters)})
    for name in outputs:
        table[name] = np.array([np.nan if v.reduced is None else v.reduced[name]
                                for v in rows], dtype=float)
    return table

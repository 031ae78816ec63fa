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
The tables are read by ``reading`` (``load_table``); the table of errors returned is
``comparison.Comparison``. The user guide is docs/compare.md.
"""
from __future__ import annotations

import math

import numpy as np

from ..elements import ELEMENTS
from ..errors import CompareInputError, ModelError, closest
from .comparison import Comparison, VariableComparison
from .interpolation import interpolate, interpolation_error
from .names import listing
from .reading import Table, load_table, names_map, time_precision
from .names import select_columns
from .units import RADIAN_UNITS, angle_factor, declared_units, unit_of

RTOL = 1e-9
ATOL = 1e-12
METHODS = ("cubic", "linear")


# --- the pure parts: errors, interpolation, matching times ---------------------------------

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


def relative_error(error: float, scale: float, atol: float) -> float:
    """error / scale [–]; nan where it means nothing: a reference zero to within atol
    (scale ≤ atol: a column of zeros and round-off, where error / scale could be 512)."""
    return error / scale if scale > atol and scale > 0 else math.nan


def scale_of(reference: np.ndarray) -> float:
    """max |reference| over its finite values (0 when it has none)."""
    finite = np.abs(reference[np.isfinite(reference)])
    return float(finite.max()) if finite.size else 0.0


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
    >>> from pam2exu.results.reading import written_precision
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


# --- the comparison ------------------------------------------------------------------------

def _check_times(table: Table, need_increasing: bool) -> None:
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


def _angles(names: list[str], res: Table, ref: Table) -> tuple[list[str], list[str]]:
    """The columns among ``names`` that are angles [rad], and those that may be one but whose
    unit neither table tells (``f(t)`` of an actuator of unknown type, in two CSV files)."""
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


def _choose(res: Table, ref: Table, columns) -> tuple[list[str], list[str], list[str]]:
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
            f"no variable in common between the result {res.label} ({listing(res.names, 5)}) "
            f"and the reference {ref.label} ({listing(ref.names, 5)})"
            + (" among the chosen --columns" if columns is not None else "")
            + "; map the reference's names to pam2exu's with --names MAP (names= from "
              "Python), a two-column CSV 'pam_name,pam2exu_name' (see docs/compare.md)")
    return (common, [c for c in union if c not in in_ref],
            [c for c in union if c not in in_res])


def _in_radians(table: Table, note: bool = True) -> Table:
    """The table with the columns its units say are in degrees (a CSV's units line, a
    Results table in degrees) in radians: compare works in SI units; a note says so."""
    done = [n for n in table.names if table.units.get(n) in RADIAN_UNITS]
    if done:
        table.values = table.values.copy()
        for name in done:
            factor, table.units[name] = angle_factor(table.units[name], "rad")
            table.values[table.names.index(name)] *= factor
        if note:
            table.notes.append(f"{table.label}: {listing(done)} given in degrees, compared in "
                               "radians")
    return table


def _in_degrees(res: Table, ref: Table, names: list[str]) -> None:
    """The angular columns among ``names`` (rad, rad/s, rad/s², by either table's unit or
    the declarations) in degrees in both tables (``compare(..., angles="deg")``)."""
    for table in (res, ref):
        table.values = table.values.copy()
    for name in names:
        unit = (res.units.get(name) or ref.units.get(name) or unit_of(name)
                or _unit_among(name, res.names + ref.names))
        factor, new = angle_factor(unit, "deg")
        if factor != 1.0:
            for table in (res, ref):
                table.values[table.names.index(name)] *= factor
                table.units[name] = new


def compare(result, reference, rtol: float = RTOL, atol: float = ATOL, columns=None,
            names=None, method: str = "cubic", wrap_angles: bool = False,
            angles: str | None = None) -> Comparison:
    """Compare ``result`` with ``reference`` variable by variable.

    Rows are matched by ``t``, to the precision each file's times carry: a time written with
    d significant digits matches one within half a unit of its last digit
    (``written_precision``, ``times_match``). When the times differ, the result is
    interpolated onto the reference times inside the result's interval (reference rows
    outside it are not compared) and the interpolation's own error is bounded.
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
    angles : str, optional
        ``"deg"``: the angular variables (rad, rad/s, rad/s²) are compared in degrees
        (their errors, scales and ``atol`` in deg, deg/s, deg/s²). Default (or ``"rad"``):
        in radians. Either way a table in degrees (a CSV whose units line says deg, see
        ``units.units_line``, or a Results table in degrees) is read in radians first, so
        a degrees file compares with a radians one.

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
    if angles not in (None, "rad", "deg"):
        raise CompareInputError(f"`angles` must be 'rad' or 'deg', not {angles!r}")
    if angles == "deg" and wrap_angles:
        raise CompareInputError("angles modulo 2π are compared in radians: leave out "
                                "--angles deg (angles='deg') with --wrap-angles")
    mapping = names_map(names)
    # the map is for the reference's names; tables in degrees are read in radians
    res = _in_radians(load_table(result, "result", {}), note=angles != "deg")
    ref = _in_radians(load_table(reference, "reference", mapping), note=angles != "deg")
    common, only_res, only_ref = _choose(res, ref, columns)
    if angles == "deg":
        _in_degrees(res, ref, common)
    ir = [res.names.index(c) for c in common]
    jr = [ref.names.index(c) for c in common]
    notes = res.notes + ref.notes
    unused = sorted(set(mapping) - ref.used_keys)
    if unused:
        notes.append(f"names map: no column matched {listing(unused)}")
    wrapped, unknown = _angles(common, res, ref) if wrap_angles else ([], [])
    if unknown:
        notes.append(f"not compared modulo 2π (angle or length: neither file tells which "
                     f"actuator it is): {listing(unknown)}")
    angle = np.array([name in wrapped for name in common], dtype=bool)

    same = _same_times(res.t, ref.t)
    written = None if same else (time_precision(res), time_precision(ref))
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
    rows, zeros = [], []
    for k, (name, j) in enumerate(zip(common, jr)):
        target = ref.values[j][inside]
        err = (angle_error if angle[k] else abs_error)(values[k], target)
        at = int(np.argmax(err))
        worst, scale = float(err[at]), math.pi if angle[k] else scale_of(target)
        tol = tolerance(scale, rtol, atol)
        if 0 < scale <= atol:
            zeros.append(name)
        rows.append(VariableComparison(
            name=name, max_abs_error=worst, max_rel_error=relative_error(worst, scale, atol),
            t_at_max=float(t_ref[at]) if worst > 0 else math.nan, scale=scale,
            tolerance=tol, passed=bool(worst <= tol),
            interpolation_error=float(interp_err[k]),
            unit=res.units.get(name) or ref.units.get(name) or ""))
    if zeros:
        notes.append(f"no relative error for {listing(zeros)}: the reference is zero to "
                     f"within atol (scale ≤ {atol:g}), so the error is judged by its size "
                     f"alone, against atol")
    return Comparison(rows, only_res, only_ref, res.label, ref.label, float(rtol), float(atol),
                      len(res.t), len(ref.t), int(inside.sum()), None if matched else method,
                      overlap, notes, digits, dt, wrapped)

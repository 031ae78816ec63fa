"""The SI unit of a result column, from the output declarations (for CSV files, which have none).

A run's ``Results.units`` come from the declarations of the variables it computed. A CSV file
has only names; ``unit_of`` finds a column's unit by the variable's PAM name across every
declaration (``SOLID_OUTPUTS`` and each element class's ``outputs``): ``crank.fi`` → rad,
``B.Fx`` → N, ``motor.Mz`` → N·m. ``f(t)`` and ``Df(t)`` are declared in rad and rad/s by the
angular actuator and in m and m/s by the linear one: their unit needs the model (which says
what kind of element ``motor`` is) and is '' without it.
"""
from __future__ import annotations

import functools
import math

from ..elements import ELEMENTS
from ..model.solid import SOLID_OUTPUTS
from ..points import CENTRE_OUTPUTS, COUPLER_OUTPUTS, POINT_OUTPUTS
from .names import canonical_name


@functools.cache
def declared_units() -> dict[str, tuple[str, ...]]:
    """Variable name → the units it is declared with (one unit: unambiguous).

    Returns
    -------
    dict
        PAM variable name (``fi``, ``Fx``, ``f(t)``, …) → tuple of the SI units it is
        declared with by ``SOLID_OUTPUTS`` and the element classes' ``outputs``.

    Examples
    --------
    >>> declared_units()["Mz"], declared_units()["f(t)"]
    (('N·m',), ('rad', 'm'))
    """
    out: dict[str, list[str]] = {}
    for var in (*SOLID_OUTPUTS, *POINT_OUTPUTS, *CENTRE_OUTPUTS, *COUPLER_OUTPUTS,
                *(v for cls in ELEMENTS.values() for v in cls.outputs)):
        units = out.setdefault(var.name, [])
        if var.unit not in units:
            units.append(var.unit)
    return {name: tuple(units) for name, units in out.items()}


def unit_of(column: str, model=None) -> str:
    """SI unit of a column ``<name>.<variable>`` ('' when unknown or ambiguous).

    Parameters
    ----------
    column : str
        A column name, PAM spellings accepted (``motor.Forca``).
    model : Model, optional
        Resolves the variables whose unit depends on the element type (``f(t)``, ``Df(t)``):
        the unit declared by the class of the solid or element named ``<name>``.

    Returns
    -------
    str
        The SI unit (``"s"`` for ``t``), or '' when the variable is unknown, or declared
        with several units and not resolved by ``model``.

    Examples
    --------
    >>> unit_of("crank.fi"), unit_of("B.Fx"), unit_of("motor.Forca"), unit_of("motor.f(t)")
    ('rad', 'N', 'N', '')
    """
    if column == "t":
        return "s"
    owner, _, variable = canonical_name(column).rpartition(".")
    if model is not None and owner:
        unit = _unit_in_model(model, owner, variable)
        if unit is not None:
            return unit
    units = declared_units().get(variable, ())
    return units[0] if len(units) == 1 else ""


def _unit_in_model(model, owner: str, variable: str) -> str | None:
    """The unit the model's solid or element ``owner`` declares for ``variable``, if any."""
    declared = None
    if any(s.name == owner for s in model.solids):
        declared = SOLID_OUTPUTS
    else:
        for el in model.elements:
            if el.name == owner:
                declared = el.outputs
    for var in declared or ():
        if var.name == variable:
            return var.unit
    return None


#: the angular units of results and their degree counterparts (``[model] angles = "deg"``)
DEGREE_UNITS = {"rad": "deg", "rad/s": "deg/s", "rad/s²": "deg/s²"}
#: and back
RADIAN_UNITS = {deg: rad for rad, deg in DEGREE_UNITS.items()}


def angle_factor(unit: str, angles: str) -> tuple[float, str]:
    """(factor, new unit) that expresses a column in ``unit`` in ``angles`` ("rad" or "deg"):
    v [deg…] = v [rad…] · 180/π and back; (1, unit) for a column that is not angular."""
    if angles == "deg" and unit in DEGREE_UNITS:
        return 180.0 / math.pi, DEGREE_UNITS[unit]
    if angles == "rad" and unit in RADIAN_UNITS:
        return math.pi / 180.0, RADIAN_UNITS[unit]
    return 1.0, unit


def in_angles(res, angles: str | None):
    """The table with its angular columns in ``angles``: "deg" (deg, deg/s, deg/s²) or "rad".

    The one conversion of results between radians and degrees: a column is angular by its
    unit (``res.units``: rad, rad/s, rad/s² or deg, deg/s, deg/s²); the others are copied
    as they are.

    Parameters
    ----------
    res : Results
        A table with units (a run's, or ``read_csv``'s).
    angles : str or None
        ``"deg"``, ``"rad"``, or None (``res`` itself, unchanged).

    Returns
    -------
    Results
        ``res`` when nothing changes, else a new table (same times, analysis, model,
        warnings and info) with the angular columns × 180/π (to degrees) or × π/180 (to
        radians) and their units renamed.

    Raises
    ------
    ValueError
        ``angles`` is not "rad", "deg" or None.

    Examples
    --------
    >>> from pam2exu.results import Results
    >>> res = Results([0.0, 1.0], {"crank.fi": [0.0, 3.141592653589793], "B.Fx": [1.0, 2.0]},
    ...               {"crank.fi": "rad", "B.Fx": "N"})
    >>> deg = in_angles(res, "deg")
    >>> deg["crank.fi"].tolist(), deg.units["crank.fi"], deg["B.Fx"].tolist()
    ([0.0, 180.0], 'deg', [1.0, 2.0])
    >>> in_angles(deg, "rad").units["crank.fi"]
    'rad'
    """
    if angles is None:
        return res
    if angles not in ("rad", "deg"):
        raise ValueError(f"angles must be 'rad' or 'deg', got {angles!r}")
    factors = {c: angle_factor(res.units.get(c, ""), angles) for c in res.columns}
    if all(f == 1.0 for f, _ in factors.values()):
        return res
    return type(res)(res.t, {c: res[c] * f if f != 1.0 else res[c]
                             for c, (f, _) in factors.items()},
                     {c: u for c, (_, u) in factors.items()}, res.analysis, res.model,
                     res.warnings, res.info, res.backend)


#: how a result CSV in degrees starts its second line, its units line (``units_line``)
UNITS_LINE = "# units: "


def units_line(names: list[str], units: dict[str, str], sep: str = ",") -> str:
    """The line under a CSV header that gives each column's unit, for a table in degrees.

    A result CSV in radians (SI) is the contract's: a header and numbers; its units follow
    from the names (``unit_of``). One with columns in degrees says so, on a comment line
    that readers skipping '#' lines ignore and ``reading.load_table`` reads back:
    ``# units: s,m,deg,…`` (one unit per column, '' where unknown).

    Parameters
    ----------
    names : list of str
        The columns, ``t`` first.
    units : dict
        Column → unit.
    sep : str
        The CSV separator.

    Returns
    -------
    str
        The line with its line end, or '' when no column is in degrees.

    Examples
    --------
    >>> units_line(["t", "crank.fi", "B.Fx"], {"t": "s", "crank.fi": "deg", "B.Fx": "N"})
    '# units: s,deg,N\\n'
    >>> units_line(["t", "crank.fi"], {"t": "s", "crank.fi": "rad"})
    ''
    """
    if not any(units.get(n) in RADIAN_UNITS for n in names):
        return ""
    return UNITS_LINE + sep.join(units.get(n, "") for n in names) + "\n"

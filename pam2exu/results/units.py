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

from ..elements import ELEMENTS
from ..model.solid import SOLID_OUTPUTS
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
    for var in (*SOLID_OUTPUTS, *(v for cls in ELEMENTS.values() for v in cls.outputs)):
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

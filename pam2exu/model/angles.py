"""The angle unit of a model's input (``[model] angles = "deg"``, an extension of the format).

A model in degrees gives every angle and angular rate in degrees: the solids' ``fi``, the lines'
``angle``, a transmission's ``C``, a torsional spring's ``C3``, an angular actuator's law
constants in the unit of f (``laws.VALUES_OF_F``) and a variation's ``dangle``. Which values
these are is declared where the keys are (``Param.angles``, ``Element.angle_values``); they
are converted to radians once, when the mechanism is made (``si_inputs``): everything after
the model layer works in SI radians. Frequencies and phases inside a cosine (a harmonic law's
C3 and C4, a variation's ``w``), stiffnesses [N·m/rad] and lengths keep their SI units.
"""
from __future__ import annotations

import copy
import math

import numpy as np

from ..complex_step import scalar
from ..elements import Element
from ..errors import Problem, echo
from ..limits import is_number
from .solid import Solid
from .variation import Variation

#: the angle units a model may be written in ([model] angles)
UNITS = ("rad", "deg")
#: one degree [rad]
DEGREE = math.pi / 180.0


def degrees_to_radians(value: float) -> float:
    """a [rad] = a [deg] · π/180."""
    return scalar(value) * DEGREE


def solid_in_radians(solid: Solid) -> Solid:
    """A copy of a degrees solid with ``fi``, its lines' ``angle`` and ``Dfi`` (deg/s) in
    radians."""
    out = copy.copy(solid)
    out.fi = degrees_to_radians(solid.fi)
    out.Dfi = degrees_to_radians(solid.Dfi)
    out.lines = {name: {**line, **({"angle": degrees_to_radians(line["angle"])}
                                   if "angle" in line else {})}
                 for name, line in solid.lines.items()}
    return out


def element_in_radians(element: Element) -> Element:
    """A copy of a degrees element with the values its keys declare angles in radians."""
    out = copy.copy(element)
    for key in element.params:
        flags, value = element.angle_values(key), getattr(element, key)
        if not any(flags) or value is None:
            continue
        if isinstance(value, (list, tuple, np.ndarray)):
            value = [degrees_to_radians(v) if k < len(flags) and flags[k] else v
                     for k, v in enumerate(value)]
        elif flags[0]:
            value = degrees_to_radians(value)
        setattr(out, key, value)
    return out


def variation_in_radians(variation: Variation) -> Variation:
    """A copy of a degrees variation with ``dangle`` and ``fixed_dangle`` in radians (ω
    stays rad/s)."""
    out = copy.copy(variation)
    if variation.dangle is not None:
        out.dangle = degrees_to_radians(variation.dangle)
    if variation.fixed_dangle is not None:
        out.fixed_dangle = degrees_to_radians(variation.fixed_dangle)
    return out


def si_inputs(model) -> tuple[list[Solid], list[Element], list[Variation]]:
    """The model's solids, and copies of its elements and variations, with angles in radians.

    Parameters
    ----------
    model : Model
        A valid model; ``model.angles`` says how its angles are written.

    Returns
    -------
    solids, elements, variations : list
        For ``angles = "rad"`` the model's solids and copies of its elements and
        variations; for ``"deg"`` copies with every declared angle converted to radians.

    Examples
    --------
    >>> from pam2exu import Model
    >>> m = Model("demo", angles="deg")
    >>> _ = m.add_solid("crank", fi=90.0, lines={"l": {"point": [0, 0], "angle": 180.0}})
    >>> _ = m.add("angular_actuator", anc1="ground", anc2="crank", C=[90.0, 360.0])
    >>> solids, elements, _ = si_inputs(m)
    >>> round(solids[0].fi, 15), round(solids[0].lines["l"]["angle"], 15), elements[0].C
    (1.570796326794897, 3.141592653589793, [1.5707963267948966, 6.283185307179586])
    >>> m["crank"].fi                  # the model keeps what the user wrote
    90.0
    """
    if model.angles != "deg":
        return (list(model.solids), [copy.copy(e) for e in model.elements],
                [copy.copy(v) for v in model.variations])
    return ([solid_in_radians(s) for s in model.solids],
            [element_in_radians(e) for e in model.elements],
            [variation_in_radians(v) for v in model.variations])


def angles_problem(angles) -> str | None:
    """The message for a bad ``[model] angles`` (None when it is "rad" or "deg")."""
    if angles in UNITS:
        return None
    return (f"angles must be \"rad\" (the default) or \"deg\", got {echo(angles)}: the unit of every "
            "angle the model gives (fi, line angles, an angular actuator's law, …)")


def angle_warnings(model) -> list[Problem]:
    """The angles of a radians model that are more than a full turn: degrees, likely.

    ``pam2exu check`` prints them and ``run`` issues them (``AngleWarning``): one text each.

    Parameters
    ----------
    model : Model
        A valid model.

    Returns
    -------
    list of Problem
        One per solid whose ``fi`` guess, and per element whose given angle (an angular
        actuator's law value C1 of a polynomial, C1 and C2 of a harmonic, C3 and C4 of a
        transition; a transmission's C; a torsional spring's C3), has a magnitude above 2π in
        a model with ``angles = "rad"``; each names the solid or element and says what to
        change. None for a degrees model.

    Examples
    --------
    >>> from pam2exu import Model
    >>> m = Model("demo")
    >>> _ = m.add_solid("crank", fi=47.0)
    >>> print(angle_warnings(m)[0])                                   # doctest: +ELLIPSIS
    [[solid]] #1 'crank': fi = 47 rad is more than a full turn (2π = 6.28 rad): did you give degrees? ...
    """
    if model.angles != "rad":
        return []
    found = [(s.where, "fi", s.fi) for s in model.solids if is_number(s.fi)]
    found += [(el.where, label, value) for el in model.elements
              for label, value in el.given_angles()]
    return [Problem(where, _turn_message(label, value))
            for where, label, value in found if abs(value) > 2.0 * math.pi]


def _turn_message(label: str, value: float) -> str:
    """What to say of an angle ``label = value`` [rad] above a full turn."""
    return (f"{label} = {value:g} rad is more than a full turn (2π = 6.28 rad): did you give "
            f"degrees? Write {label.split()[-1]} in radians ({value:g}° = "
            f"{degrees_to_radians(value):.4g} rad), or set angles = \"deg\" in [model] to give "
            "every angle of the model in degrees")

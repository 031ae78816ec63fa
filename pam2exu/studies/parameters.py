"""What a study can vary in a model (shared/spec's table, docs "Studies"), and a variant
written into the model.

A name is ``solid.P.x`` / ``solid.P.y`` (a declared point), ``solid.L.x`` / ``solid.L.y`` /
``solid.L.angle`` (a declared line), ``solid.mass``, ``solid.inertia``, ``solid.cog.x`` /
``solid.cog.y``, ``element.C1`` … ``element.C4`` (an element's or its law's constants,
1-based), ``element.T`` / ``element.C`` (a transmission's numbers) and ``model.gravity``.
The values are in the model's units (a line's angle in degrees in a degrees model): they
are written into the model as its file would give them, and converted as the model is.
For a clearance study a point's or a line's value is instead its part as made: the
deviation from the nominal value is written as the fixed deviation of the point's or line's
``[[variation]]`` (``fixed_dx``, ``fixed_dy``, ``fixed_dangle``; ``write_deviation``),
which the clearance analysis reaches from the nominal assembly.
"""
from __future__ import annotations

import functools
import pickle
import re
from dataclasses import dataclass

from ..laws import LAW_ALIASES, LAWS
from ..model import Model, loads

#: the solid's own numbers that vary, with their units
_SOLID_NUMBERS = (("mass", "kg"), ("inertia", "kg·m²"))


@dataclass(frozen=True)
class Target:
    """One number of a model that a study can vary.

    Parameters
    ----------
    name : str
        The study's name for it (``"coupler.B.x"``).
    nominal : float
        Its value in the model, in the model's units.
    unit : str
        Its unit (``"m"``, ``"deg"`` in a degrees model, ``""`` when no declaration says).
    path : tuple
        Where it is written: (kind, owner, item, component), read by ``write``.
    """

    name: str
    nominal: float
    unit: str
    path: tuple


def targets(model: Model) -> dict[str, Target]:
    """Every number of ``model`` a study can vary, by name, in model order.

    Parameters
    ----------
    model : Model
        A validated model.

    Returns
    -------
    dict of str to Target
        Points' and lines' coordinates, mass properties, element constants, the model's
        gravity.

    Examples
    --------
    >>> import pam2exu
    >>> found = targets(pam2exu.load("examples/four_bar.toml"))
    >>> found["coupler.B.x"].nominal, found["motor.C2"].unit, found["model.gravity"].nominal
    (0.35, 'rad/s', 9.81)
    """
    angle = "deg" if model.angles == "deg" else "rad"
    out: list[Target] = []
    for s in model.solids:
        for p, (x, y) in s.points.items():
            out += [Target(f"{s.name}.{p}.x", float(x), "m", ("point", s.name, p, 0)),
                    Target(f"{s.name}.{p}.y", float(y), "m", ("point", s.name, p, 1))]
        for name, line in s.lines.items():
            px, py = line.get("point", (0.0, 0.0))
            out += [Target(f"{s.name}.{name}.x", float(px), "m", ("line", s.name, name, 0)),
                    Target(f"{s.name}.{name}.y", float(py), "m", ("line", s.name, name, 1)),
                    Target(f"{s.name}.{name}.angle", float(line.get("angle", 0.0)), angle,
                           ("line", s.name, name, "angle"))]
        out += [Target(f"{s.name}.{key}", float(getattr(s, key)), unit,
                       ("solid", s.name, key, None)) for key, unit in _SOLID_NUMBERS]
        out += [Target(f"{s.name}.cog.{c}", float(s.cog[k]), "m", ("cog", s.name, None, k))
                for k, c in enumerate("xy")]
    for el in model.elements:
        for key, param in el.params.items():
            if param.kind == "constants":
                value = list(getattr(el, key) or [])
                for k in range(param.size):
                    unit = _constant_unit(el, key, k, angle)
                    out.append(Target(f"{el.name}.{key}{k + 1}",
                                      float(value[k]) if k < len(value) else 0.0, unit,
                                      ("constant", el.name, key, k)))
            elif param.kind == "number" and getattr(el, key) is not None:
                unit = _unit_in(param.meaning, "") or "–"
                unit = unit.replace("rad", angle) if any(el.angle_values(key)) else unit
                out.append(Target(f"{el.name}.{key}", _number(getattr(el, key)), unit,
                                  ("number", el.name, key, None)))
    out.append(Target("model.gravity", float(model.gravity), "m/s²", ("gravity",) * 4))
    return {t.name: t for t in out}


def _number(value) -> float:
    """A number key's value (a one-element list reads as its element)."""
    return float(value[0] if isinstance(value, (list, tuple)) else value)


def _unit_in(meaning: str, label: str) -> str:
    """The unit a parameter's meaning states after ``label`` (``"C2 [N/m]"``), else ''."""
    found = re.search(rf"{re.escape(label)}\s*\[([^\]]+)\]", meaning)
    return found.group(1) if found else ""


def _constant_unit(element, key: str, k: int, angle: str) -> str:
    """The unit of constant k (0-based) of ``key``: a law constant's from its order under
    f's unit (``laws.LawForm.orders``; '' for a constant in its own unit), else as the
    declaration's meaning states it ('' when it does not); ``angle`` the model's angle
    unit, for the constants the declaration flags as angles (``Element.angle_values``)."""
    if not element.drives or key != "C":
        unit = _unit_in(element.params[key].meaning, f"C{k + 1}")
        flags = element.angle_values(key)
        return unit.replace("rad", angle) if k < len(flags) and flags[k] else unit
    order = LAWS[LAW_ALIASES.get(element.law, element.law)].orders[k]
    if order is None:
        return "s" if LAWS[LAW_ALIASES.get(element.law, element.law)].interval else ""
    f_unit = angle if element.angular else "m"
    return f_unit + ("", "/s", "/s²", "/s³")[order]


def write(model: Model, target: Target, value: float) -> None:
    """Write ``value`` into ``model`` where ``target`` is (new lists; nothing shared)."""
    kind, owner, item, k = target.path
    if kind == "gravity":
        model.gravity = value
        return
    holder = model[owner]
    if kind == "point":
        point = list(holder.points[item])
        point[k] = value
        holder.points = {**holder.points, item: point}
    elif kind == "line":
        line = dict(holder.lines[item])
        if k == "angle":
            line["angle"] = value
        else:
            point = list(line.get("point", (0.0, 0.0)))
            point[k] = value
            line["point"] = point
        holder.lines = {**holder.lines, item: line}
    elif kind == "solid":
        setattr(holder, item, value)
    elif kind == "cog":
        cog = list(holder.cog)
        cog[k] = value
        holder.cog = cog
    elif kind == "constant":
        values = list(getattr(holder, item) or [])
        values += [0.0] * (k + 1 - len(values))
        values[k] = value
        setattr(holder, item, values)
    else:
        setattr(holder, item, value)


#: the fixed deviation's key of a point's or line's component (``Target.path``'s last item)
FIXED_KEYS = {0: "fixed_dx", 1: "fixed_dy", "angle": "fixed_dangle"}


def is_dimension(target: Target) -> bool:
    """The target is a point's or a line's coordinate (what ``[[variation]]`` varies)."""
    return target.path[0] in ("point", "line")


def write_deviation(model: Model, target: Target, value: float) -> None:
    """Add value − nominal to the fixed deviation of the ``[[variation]]`` of ``target``'s
    point or line (a new entry when it has none): the dimension as made is ``value``,
    reached from the nominal one by the clearance analysis."""
    _, owner, item, k = target.path
    anchor = f"{owner}.{item}"
    entry = next((v for v in model.variations if v.anchor == anchor), None)
    if entry is None:
        entry = model.add_variation(anchor)
    key = FIXED_KEYS[k]
    setattr(entry, key, float(getattr(entry, key)) + (float(value) - target.nominal))


@functools.lru_cache(maxsize=4)
def _parsed(text: str, source: str) -> tuple[bytes, dict[str, Target]]:
    """The model of ``text`` parsed once per process, pickled, with its targets (a worker
    runs many variants of one model: each unpickles a fresh copy, as if its text had been
    parsed again; unpickling costs a tenth of a deep copy)."""
    model = loads(text, source=source)
    return pickle.dumps(model, pickle.HIGHEST_PROTOCOL), targets(model)


def varied(text: str, values: dict[str, float], source: str = "<string>",
           as_made: bool = False) -> Model:
    """The model of ``text`` with a variant's ``values`` written in (what a worker builds).

    Parameters
    ----------
    text : str
        The model file's text (TOML).
    values : dict of str to float
        The variant: parameter name (``targets``) to its value, in the model's units.
    source : str
        The model file's name, for messages.
    as_made : bool
        The points' and lines' values are parts as made: written as fixed deviations
        (``write_deviation``, a clearance study), the nominal dimensions kept.

    Returns
    -------
    Model
        A fresh model, as if its file had these values written in; validated.

    Raises
    ------
    KeyError
        A name that is not among the model's ``targets`` (the study file's validation
        reports it first, with the closest names).
    ModelError
        The values make the model invalid (a negative mass, …).
    """
    parsed, found = _parsed(text, source)       # the targets are frozen: shared
    model = pickle.loads(parsed)
    for name, value in values.items():
        target = found[name]
        (write_deviation if as_made and is_dimension(target) else write)(model, target,
                                                                          float(value))
    model.validate()
    return model

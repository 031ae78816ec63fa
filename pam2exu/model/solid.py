"""Solids and the anchors elements attach to (points, lines, solids)."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, ClassVar

from ..elements.base import ACCELERATION, POSITION, VELOCITY, Var
from .. import limits
from ..errors import closest, echo
from ..complex_step import cos, scalar, sin
from ..limits import is_number, shown


@dataclass(eq=False)
class Solid:
    """A rigid solid: pose (x, y, fi) of its local frame, inertia, named points and lines.

    Usually made by ``Model.add_solid`` (or a ``[[solid]]`` table of a model file), which
    takes the same keys. Values are checked by ``Model.problems``, not here.

    Parameters
    ----------
    name : str
        Unique name (one namespace with the elements); no '.'.
    x, y : float
        Origin of the local frame in the global frame [m]; an initial guess, or the pose of
        a solid held by a fixed link.
    fi : float
        Angle of the local x axis from the global x axis, counter-clockwise [rad]; an
        initial guess, like x and y.
    mass : float
        Mass [kg], ≥ 0 (0: a massless solid).
    inertia : float
        Moment of inertia about the centre of mass G [kg·m²], ≥ 0.
    cog : (float, float)
        Centre of mass G in the local frame [m].
    Dx, Dy, Dfi : float
        Initial-velocity guess of the ``dynamic`` analysis: the rates of x, y [m/s] and
        fi [rad/s] at t = 0; the velocities nearest to them that satisfy the velocity
        equations are used. Default 0.
    points : dict
        ``{name: [x, y]}`` in the local frame [m]; anchors ``"<solid>.<point>"``.
    lines : dict
        ``{name: {"point": [x, y], "angle": a}}`` in the local frame: a point of the line
        [m] and the angle of its direction from the local x axis [rad]; anchors
        ``"<solid>.<line>"``.
    position : int, optional
        1-based position in the model file's ``[[solid]]`` array, for messages (set by the
        loader, or by ``Model.add_solid`` to the solid's number in the model).

    Examples
    --------
    >>> crank = Solid("crank", fi=0.3, mass=0.5, inertia=1e-3, cog=[0.05, 0.0],
    ...               points={"O": [0, 0], "A": [0.1, 0]})
    >>> crank.points["A"]
    [0.1, 0]
    """

    name: str
    x: float = 0.0
    y: float = 0.0
    fi: float = 0.0
    mass: float = 0.0
    inertia: float = 0.0
    cog: Any = (0.0, 0.0)
    points: dict = field(default_factory=dict)
    lines: dict = field(default_factory=dict)
    Dx: float = 0.0
    Dy: float = 0.0
    Dfi: float = 0.0

    #: keys beyond the contract's [[solid]] table (forward dynamics; docs/model-format.md)
    EXTENSIONS: ClassVar[tuple[str, ...]] = ("Dx", "Dy", "Dfi")
    #: 1-based position in the file's [[solid]] array (set by the loader or the model)
    position: int | None = field(default=None, repr=False)

    def __post_init__(self):
        """Its name, points' and lines' names in one Unicode form (``limits.one_form``)."""
        self.name = limits.one_form(self.name)
        for key in ("points", "lines"):
            table = getattr(self, key)
            if isinstance(table, dict):
                setattr(self, key, {limits.one_form(k): v for k, v in table.items()})

    @property
    def where(self) -> str:
        """Where the solid is in the model, for messages: ``"[[solid]] #2 'crank'"``."""
        at = f" #{self.position}" if self.position else ""
        return f"[[solid]]{at} '{shown(self.name)}'"


#: the outputs of every solid: columns ``<solid>.<variable>`` (``Results``, ``units.unit_of``)
SOLID_OUTPUTS = (
    Var("x", "m", POSITION, "x of the local frame's origin"),
    Var("y", "m", POSITION, "y of the local frame's origin"),
    Var("fi", "rad", POSITION, "angle of the local x axis, counter-clockwise, never wrapped"),
    Var("Dx", "m/s", VELOCITY, "dx/dt"),
    Var("Dy", "m/s", VELOCITY, "dy/dt"),
    Var("Dfi", "rad/s", VELOCITY, "dfi/dt"),
    Var("DDx", "m/s²", ACCELERATION, "d²x/dt²"),
    Var("DDy", "m/s²", ACCELERATION, "d²y/dt²"),
    Var("DDfi", "rad/s²", ACCELERATION, "d²fi/dt²"),
)


@dataclass(frozen=True)
class SolidRef:
    """A whole solid, by index."""

    solid: int
    label: str

    @property
    def anchor_point(self) -> tuple[float, float]:
        """The point the anchor stands for, local coordinates [m]: the solid's origin."""
        return (0.0, 0.0)


@dataclass(frozen=True)
class PointRef:
    """A point fixed to a solid: local coordinates [m]."""

    solid: int
    local: tuple[float, float]
    label: str

    @property
    def anchor_point(self) -> tuple[float, float]:
        """The point the anchor stands for, local coordinates [m]: the point itself."""
        return self.local


@dataclass(frozen=True)
class LineRef:
    """A line fixed to a solid: defining point [m] and angle of its x direction [rad]."""

    solid: int
    point: tuple[float, float]
    angle: float
    label: str

    @property
    def anchor_point(self) -> tuple[float, float]:
        """The point the anchor stands for, local coordinates [m]: the line's defining point."""
        return self.point

    @property
    def direction(self) -> tuple[float, float]:
        """Unit vector along the line, local frame: (cos a, sin a)."""
        return (cos(self.angle), sin(self.angle))

    @property
    def normal(self) -> tuple[float, float]:
        """Unit normal, the direction turned 90° counter-clockwise: (−sin a, cos a)."""
        return (-sin(self.angle), cos(self.angle))


def _table(value) -> dict:
    """A solid's points or lines as a dict of str keys ({} when malformed: reported elsewhere)."""
    return {str(k): v for k, v in value.items()} if isinstance(value, dict) else {}


class Scope:
    """Resolves anchor strings ("solid", "solid.point", "solid.line") to references."""

    def __init__(self, solids: list[Solid]):
        self.solids = solids
        # a name that is not a string is reported by the validation, never found here
        self.index = {s.name: i for i, s in enumerate(solids) if isinstance(s.name, str)}


    def solid(self, text: str) -> SolidRef:
        name = str(text)
        if name not in self.index:
            raise LookupError(f"no solid '{name}'{closest(name, self.index)}")
        return SolidRef(self.index[name], name)

    def _split(self, text: str) -> tuple[int, Solid, str | None]:
        text = str(text)
        if text in self.index:
            return self.index[text], self.solids[self.index[text]], None
        solid_name, dot, item = text.partition(".")
        if not dot or solid_name not in self.index:
            raise LookupError(f"no solid '{solid_name}'{closest(solid_name, self.index)}")
        i = self.index[solid_name]
        return i, self.solids[i], item

    def _find(self, text: str, kind: str):
        """(index, solid, item name, item value) for "solid.item" of a kind 'point' or 'line';
        the item is None for a bare solid name (its origin or its x axis)."""
        i, solid, item = self._split(text)
        if item is None:
            return i, solid, None, None
        items = solid.points if kind == "point" else solid.lines
        if isinstance(items, dict) and item in items:      # the usual case: found
            return i, solid, item, items[item]
        tables = {"point": _table(solid.points), "line": _table(solid.lines)}
        other = "line" if kind == "point" else "point"
        if item not in tables[kind]:
            hint = closest(item, tables[kind])
            if item in tables[other]:
                hint = f" (that is a {other}; a {kind} is expected here)"
            raise LookupError(f"solid '{solid.name}' has no {kind} '{item}'{hint}; "
                              f"its {kind}s are: {', '.join(tables[kind]) or 'none'}")
        return i, solid, item, tables[kind][item]

    def point(self, text: str) -> PointRef:
        i, solid, item, value = self._find(text, "point")
        if item is None:
            return PointRef(i, (0.0, 0.0), str(text))
        try:
            x, y = value
            return PointRef(i, (scalar(x), scalar(y)), str(text))
        except (TypeError, ValueError, OverflowError):
            raise LookupError(f"point '{item}' of solid '{solid.name}' is not [x, y]") from None

    def line(self, text: str) -> LineRef:
        i, solid, item, value = self._find(text, "line")
        if item is None:
            return LineRef(i, (0.0, 0.0), 0.0, str(text))
        try:
            px, py = value.get("point", (0.0, 0.0))
            return LineRef(i, (scalar(px), scalar(py)), scalar(value.get("angle", 0.0)),
                           str(text))
        except (AttributeError, TypeError, ValueError, OverflowError):
            raise LookupError(f"line '{item}' of solid '{solid.name}' is not "
                              "{ point = [x, y], angle = a }") from None

    def resolve(self, kind: str, text: str):
        """kind is 'solid', 'point' or 'line'."""
        return getattr(self, kind)(text)


#: the keys of a line of a solid's ``lines`` table: its defining point and its angle
LINE_KEYS = ("point", "angle")


def _pair(v) -> bool:
    return isinstance(v, (list, tuple)) and len(v) == 2 and all(is_number(x) for x in v)


#: a solid's numbers: (key, range, unit)
_SOLID_NUMBERS = (("x", limits.LENGTH, "m"), ("y", limits.LENGTH, "m"),
                  ("fi", limits.ANGLE, "rad"), ("mass", limits.VALUE, "kg"),
                  ("inertia", limits.VALUE, "kg·m²"), ("Dx", limits.VALUE, "m/s"),
                  ("Dy", limits.VALUE, "m/s"), ("Dfi", limits.VALUE, "rad/s"))


def range_problems(what: str, value, limit: float, unit: str) -> list[str]:
    """A message when a number's magnitude exceeds its range (a unit error, most likely)."""
    if limits.out_of_range(value, limit):
        return [f"{what} = {value:g} {unit} is out of range: its magnitude must be at most "
                f"{limit:g} {unit} (are the units right?)"]
    return []


def _point_range(what: str, p) -> list[str]:
    """Range messages of the coordinates [x, y] of a point [m]."""
    return [m for c, v in zip("xy", p)
            for m in range_problems(f"{what} {c}", v, limits.LENGTH, "m")]


def _in_degrees(limit: float, unit: str) -> tuple[float, str]:
    """A range and unit given in radians, as a model written in degrees states them."""
    if unit.startswith("rad"):
        return (limit * 180.0 / math.pi if unit == "rad" else limit), "deg" + unit[3:]
    return limit, unit


#: ``_SOLID_NUMBERS`` of a model written in degrees (``_in_degrees``)
_SOLID_NUMBERS_DEG = tuple((key, *_in_degrees(limit, unit))
                           for key, limit, unit in _SOLID_NUMBERS)


def _within(v, limit: float) -> bool:
    """|v| ≤ limit for a plain float or int (not a bool): a number with nothing to report
    (NaN and ±inf are not within; anything else goes through the full checks)."""
    return type(v) in (float, int) and -limit <= v <= limit


def _fine_pair(p) -> bool:
    """[x, y] of two numbers within the range of lengths: nothing to report."""
    return (type(p) in (list, tuple) and len(p) == 2 and _within(p[0], limits.LENGTH)
            and _within(p[1], limits.LENGTH))


def solid_problems(s: Solid, degrees: bool = False) -> list[str]:
    """Every problem with a solid's values (``Model.problems`` puts them under its place);
    ``degrees``: the model's angles are in degrees (``[model] angles``), and so are the
    messages' units and the range of angles."""
    out, negative = [], []
    for key, limit, unit in _SOLID_NUMBERS_DEG if degrees else _SOLID_NUMBERS:
        value = getattr(s, key)
        if not _within(value, limit):          # (within: the usual case, nothing to report)
            if not is_number(value):
                out.append(f"{key} must be a number, got {echo(value)}")
            out += range_problems(key, value, limit, unit)
        if key in ("mass", "inertia") and is_number(value) and value < 0:
            negative.append(f"{key} is negative ({value}): it must be ≥ 0")
    out += negative
    if _fine_pair(s.cog):
        pass
    elif not _pair(s.cog):
        out.append(f"cog must be [x, y] in the local frame, got {echo(s.cog)}")
    else:
        out += _point_range("cog", s.cog)
    if not isinstance(s.points, dict):
        out.append(f"points must be a table {{ A = [x, y] }}, got {echo(s.points)}")
    else:
        for name, p in s.points.items():
            if _fine_pair(p):
                continue
            if not _pair(p):
                out.append(f"point {echo(name)} must be [x, y], got {echo(p)}")
            else:
                out += _point_range(f"point {echo(name)}", p)
    if not isinstance(s.lines, dict):
        out.append(f"lines must be a table {{ l = {{ point = [x, y], angle = a }} }}, got "
                   f"{echo(s.lines)}")
        return out
    for name, line in s.lines.items():
        if not isinstance(line, dict):
            out.append(f"line {echo(name)} must be {{ point = [x, y], angle = a }}, got "
                       f"{echo(line)}")
            continue
        for key in line:
            if key not in LINE_KEYS:
                out.append(f"line {echo(name)} has an unknown key {echo(key)}"
                           f"{closest(key, LINE_KEYS)}")
        if "point" in line and not _pair(line["point"]):
            out.append(f"line {echo(name)}: point must be [x, y], got {echo(line['point'])}")
        elif "point" in line:
            out += _point_range(f"line {echo(name)} point", line["point"])
        angle_range = _in_degrees(limits.ANGLE, "rad") if degrees else (limits.ANGLE, "rad")
        if "angle" in line and not is_number(line["angle"]):
            out.append(f"line {echo(name)}: angle must be a number [{angle_range[1]}], got "
                       f"{echo(line['angle'])}")
        out += range_problems(f"line {echo(name)} angle", line.get("angle"), *angle_range)

    return out

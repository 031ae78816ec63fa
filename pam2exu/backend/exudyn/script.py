"""The Exudyn system of a mechanism written as Python code instead of built.

``ScriptSystem`` is an ``ExudynSystem`` whose ``mbs`` and ``items`` record what they are
asked to do: ``ExudynSystem.__init__`` and every element's ``build`` run unchanged, and each
call becomes a line such as ``o_A = mbs.AddObject(ObjectJointRevolute2D(markerNumbers=[...]))``.
The exported script therefore builds the very system the translation builds, and an element
needs no export code of its own: its ``build`` is its snippet.
"""
from __future__ import annotations

import re
import textwrap

import numpy as np

from exudyn import itemInterface

from ...model.solid import Solid
from .system import ExudynSystem

#: lines longer than this put one keyword argument per line
WIDTH = 99


def identifier(text: str) -> str:
    """``text`` as a Python identifier fragment (letters, digits, underscores)."""
    return re.sub(r"\W", "_", str(text))


def code(value) -> str:
    """A value as Python source: full float precision, script variables by name."""
    if isinstance(value, Variable):
        return value.name
    if isinstance(value, (bool, np.bool_)):
        return repr(bool(value))
    if isinstance(value, (int, np.integer)):
        return repr(int(value))
    if isinstance(value, (float, np.floating)):
        return repr(float(value) + 0.0)         # no negative zeros
    if isinstance(value, (list, tuple, np.ndarray)):
        return "[" + ", ".join(code(v) for v in value) + "]"
    if isinstance(value, str):
        return repr(value)
    if type(value).__module__.startswith("exudyn"):   # an Exudyn enum value
        return f"exu.{type(value).__name__}.{value.name}"
    raise TypeError(f"cannot write {value!r} ({type(value).__name__}) as code")


def call(function: str, kwargs: dict, indent: str = "", prefix: str = "",
         closing: str = "") -> list[str]:
    """``prefix function(k=v, ...)closing`` on one line, or one argument per line if long."""
    args = [f"{k}={code(v)}" for k, v in kwargs.items()]
    line = f"{indent}{prefix}{function}({', '.join(args)}){closing}"
    if len(line) <= WIDTH or not args:
        return [line]
    for k, (key, value) in enumerate(kwargs.items()):
        if len(args[k]) > WIDTH - 8 and isinstance(value, (list, tuple)):   # a matrix: by rows
            rows = [code(row) for row in value]
            args[k] = f"{key}=[" + f",\n{indent}{' ' * (len(key) + 6)}".join(rows) + "]"
    lines = [f"{indent}{prefix}{function}("]
    lines += [f"{indent}    {a}," for a in args[:-1]]
    lines.append(f"{indent}    {args[-1]}){closing}")
    return lines


def wrap(comments: list[str]) -> list[str]:
    """Comment lines wrapped at WIDTH, continued with the indent '#     '."""
    return [line for c in comments
            for line in textwrap.wrap(c, WIDTH, subsequent_indent="#     ",
                                      break_on_hyphens=False)]


class Variable:
    """A variable of the script (an item index); ``stem`` names what it belongs to."""

    def __init__(self, name: str, stem: str):
        self.name, self.stem = name, stem

    def __repr__(self):
        return self.name


class Item:
    """A recorded ``exudyn.itemInterface`` item: its class name and keyword arguments."""

    def __init__(self, kind: str, kwargs: dict):
        self.kind, self.kwargs = kind, kwargs


class RecordingItems:
    """Stands for ``exudyn.itemInterface``: ``items.X(**kw)`` records an Item."""

    def __getattr__(self, kind: str):
        if kind not in vars(itemInterface):
            raise AttributeError(f"exudyn.itemInterface has no {kind}")

        def make(*args, **kwargs):
            if args:
                raise TypeError(f"{kind}: give the item's arguments by keyword")
            return Item(kind, kwargs)
        return make


class RecordingSystem:
    """Stands for an Exudyn MainSystem: each Add* call becomes a line of the script."""

    def __init__(self, script: ScriptSystem):
        self._script = script

    def _add(self, method: str, item: Item) -> Variable:
        return self._script.record(method, item)

    def AddNode(self, item):
        return self._add("AddNode", item)

    def AddObject(self, item):
        return self._add("AddObject", item)

    def AddMarker(self, item):
        return self._add("AddMarker", item)

    def AddLoad(self, item):
        return self._add("AddLoad", item)

    def AddSensor(self, item):
        return self._add("AddSensor", item)

    def Assemble(self):
        self._script.blocks.append((["# --- assemble"], ["mbs.Assemble()"]))


_COORDINATE = ("x", "y", "fi")


class ScriptSystem(ExudynSystem):
    """The construction of ``ExudynSystem(mech, forces, ...)`` as Python source.

    ``blocks``: (comment lines, code lines) per solid, element, gravity, sensors and the
    assembly, in the order the system is built; ``drivers`` and ``driver_owners``: the
    actuators' (variable, parameter, law, shift) and their elements; ``sensors``: solid index
    -> sensor variable; ``kinds``: the item classes used.
    """

    items = RecordingItems()

    def __init__(self, mech, forces: bool = False, **options):
        """``options``: ExudynSystem's others (velocity_forces False unless given; a
        time integration's ``start``, ``start_rates`` and ``ground_fixed``)."""
        self.blocks: list[tuple[list[str], list[str]]] = []
        self.driver_owners: list = []
        self.used: set[str] = set()
        self.kinds: set[str] = set()
        self._owner, self._hint = None, None
        self.integrated = options.get("start_rates") is not None
        super().__init__(mech, forces=forces, **{"velocity_forces": False, **options})

    def new_system(self):
        return RecordingSystem(self)

    # ---- blocks ------------------------------------------------------------------------
    def begin(self, owner) -> None:
        self._owner = owner
        self.blocks.append((self._comment(owner), []))

    def _comment(self, owner) -> list[str]:
        mech = self.mech
        if isinstance(owner, Solid):
            i = mech.index[owner.name]
            lines = [f"# --- solid '{owner.name}'",
                     (f"#     PAM: x = {owner.x}, y = {owner.y}, fi = {owner.fi}, "
                      f"mass = {owner.mass}, inertia = {owner.inertia} (about G), "
                      f"cog = {list(owner.cog)}")]
            if owner.points:
                lines.append("#     points: " + ", ".join(f"{k} = {list(v)}"
                                                         for k, v in owner.points.items()))
            if owner.lines:
                lines.append("#     lines: " + ", ".join(
                    f"{k} = {{point = {list(v.get('point', (0.0, 0.0)))}, "
                    f"angle = {v.get('angle', 0.0)}}}" for k, v in owner.lines.items()))
            if i in self.grounded:
                holder = next(el.name for el in mech.elements if el.holds == i)
                lines.append(f"#     held by the fixed link '{holder}': Exudyn ground at "
                             "this pose")
            elif self.integrated:
                lines.append("#     node coordinates are PAM's x, y, fi (reference 0); initial "
                             "values: the assembly at t = 0 and the nearest consistent "
                             "velocities, computed by pam2exu's dynamic analysis")
            else:
                lines.append("#     node coordinates are PAM's x, y, fi (reference 0, initial "
                             "values the initial guess)")
                lines.append("#     Exudyn's inertia is about the node (the frame origin): "
                             "inertia + mass |cog|^2" if self.forces else
                             "#     constraints only: no mass (positions do not need it)")
            return wrap(lines)
        if owner == "gravity":
            return [f"# --- gravity: {mech.gravity} m/s^2 along -y on every solid with mass"]
        if owner == "sensors":
            return ["# --- sensors: x, y, fi of every moving solid at every load step"]
        el = owner
        keys = [f"anc{k + 1} = {a!r}" for k, a in enumerate(el.given_anchors())]
        keys += [f"{key} = {getattr(el, key)!r}" for key, param in el.params.items()
                 if getattr(el, key) is not None
                 and not (param.extension and not getattr(el, key))]   # clearance = False
        lines = [f"# --- {el.name}: {el.type} (PAM {el.alias}): {el.summary}",
                 f"#     {', '.join(keys)}"]
        if not self.builds(el):
            if el.grounds:
                lines.append(f"#     '{mech.solids[el.holds].name}' is Exudyn ground: "
                             "no item needed")
            else:
                lines.append("#     a force element: not in this constraints-only system "
                             "(export with --forces to include it)")
        return wrap(lines)

    # ---- recording ---------------------------------------------------------------------
    def record(self, method: str, item: Item) -> Variable:
        """Write ``name = mbs.method(Item(...))`` into the current block; returns the name."""
        prefix, stem = self._name(item)
        name = base = identifier(f"{prefix}_{stem}")
        k = 1
        while name in self.used:
            k += 1
            name = f"{base}_{k}"
        self.used.add(name)
        self.kinds.add(item.kind)
        self.blocks[-1][1].extend(call(item.kind, item.kwargs, prefix=f"{name} = mbs.{method}(",
                                       closing=")"))
        return Variable(name, stem)

    def _name(self, item: Item) -> tuple[str, str]:
        """(prefix, stem) of the variable of a new item: n_ nodes, b_ bodies, m_ markers,
        o_ other objects, l_ loads, s_ sensors; the stem names the solid, point or element."""
        kind, kw, owner = item.kind, item.kwargs, self._owner
        if isinstance(owner, Solid) and kind.startswith("Node"):
            return "n", owner.name
        if isinstance(owner, Solid) and kind.startswith("Object"):
            return "b", owner.name
        if kind == "MarkerBodyRigid" and self._hint is not None:
            return "m", self._hint
        if kind == "MarkerNodeCoordinate":
            node = kw["nodeNumber"]
            if node.stem == "ground_point":
                return "m", "ground_coordinate"
            return "m", f"{node.stem}_{_COORDINATE[kw['coordinate']]}"
        if kind == "NodePointGround":
            return "n", "ground_point"
        if kind == "MarkerBodiesRelativeRotationCoordinate":
            reference, solid = kw["bodyNumbers"]
            return "m", f"{solid.stem}_rel_{reference.stem}"
        if kind == "MarkerBodyMass":
            return "m", f"{kw['bodyNumber'].stem}_mass"
        if kind == "LoadMassProportional":
            return "l", kw["markerNumber"].stem.removesuffix("_mass") + "_gravity"
        if kind.startswith("Sensor"):
            return "s", kw["nodeNumber"].stem
        stem = owner if isinstance(owner, str) else owner.name
        if kind.startswith("Load"):
            return "l", stem
        return ("n" if kind.startswith("Node") else "m" if kind.startswith("Marker")
                else "o"), stem

    def point_marker(self, ref):
        self._hint = ref.label
        try:
            return super().point_marker(ref)
        finally:
            self._hint = None

    def drive(self, obj, parameter, law, shift=0.0):
        super().drive(obj, parameter, law, shift)
        self.driver_owners.append(self._owner)

    def lines(self) -> list[str]:
        """Every block: its comment, its code, a blank line."""
        out = []
        for comment, body in self.blocks:
            out += comment + body + [""]
        return out

"""What every element declares: its anchors, its parameters, its outputs.

An element class is the one place where everything about a PAM element lives:
the keys it takes (checked by the model's validation), the constraint equations it
adds (used by the native velocity and acceleration pass), the Exudyn items it becomes
(``build``), the output variables it reports under PAM's names (``outputs``) and its
symbol in a drawing (``draw``).
Nothing here imports Exudyn or matplotlib: ``build`` receives the backend's system
builder, ``draw`` a pen (``pictures.pen.Pen``).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from ..complex_step import scalar
from ..errors import closest, echo
from ..limits import VALUE, is_number, one_form, shown
from ..kinematics import Quantity, State, pose
from ..laws import F_ORDERS, LAW_ALIASES, LAWS, VALUES_OF_F, Law, law_names

#: What an output needs from an analysis, in the order analyses can provide it.
POSITION, VELOCITY, ACCELERATION, FORCE = "position", "velocity", "acceleration", "force"
#: the level of a joint's clearance parameters (``Element.clearance_parameters``): given by
#: the clearance analysis only (shared/spec/clearance.md)
CLEARANCE = "clearance"


#: how an anchor of each kind is written
ANCHOR_FORMS = {"solid": '"solid"', "point": '"solid.point", or "solid" for its origin',
                "line": '"solid.line", or "solid" for its x axis'}


@dataclass(frozen=True)
class Var:
    """An output variable: PAM name, SI unit, what it needs, what it means."""

    name: str
    unit: str
    level: str
    meaning: str


# --- parameter kinds: each returns an error message for a bad value, or None -------------

@dataclass(frozen=True)
class Param:
    """A key an element takes besides name, anc1 and anc2."""

    kind: str            # "constants", "number", "law", "solid", "choice", "boolean"
    meaning: str
    size: int = 4        # for constants: at most this many
    choices: tuple = ()
    required: bool = False
    limit: float = VALUE     # for numbers and constants: the largest magnitude allowed
    #: the specification that adds the key to the model format (e.g. "clearance.md"), for
    #: keys beyond model-format.md's element table; None for the contract's own keys
    extension: str | None = None
    #: which of its values are angles or angular rates [rad, rad/s, …] (one flag per
    #: constant, one for a number): given in degrees in a model with ``angles = "deg"``
    #: (pam2exu/model/angles.py converts them once, to radians)
    angles: tuple[bool, ...] = ()

    def values(self) -> tuple[str, ...]:
        """The strings the key takes, as a model file writes them: a choice's choices, a
        law's names and PAM's Catalan aliases; () for the other kinds."""
        if self.kind == "choice":
            return tuple(self.choices)
        if self.kind == "law":
            return (*LAWS, *LAW_ALIASES)
        return ()

    def problem(self, key: str, value: Any) -> str | None:
        if value is None:
            return f"'{key}' is required ({self.meaning})" if self.required else None
        if self.kind == "constants":
            if not isinstance(value, (list, tuple, np.ndarray)):
                shape = ", ".join(f"C{k + 1}" for k in range(self.size))
                if not is_number(value):
                    return (f"'{key}' must be a list of numbers, {key} = [{shape}] "
                            f"({self.meaning}), got {echo(value)}")
                return (f"'{key}' must be a list, {key} = [{shape}] ({self.meaning}), got the "
                        f"single number {value!r}: write {key} = [{value!r}] if it is C1, and "
                        f"give the other constants")
            values = list(value)
            if len(values) > self.size:
                return (f"'{key}' has {len(values)} constants, at most {self.size} are allowed "
                        f"({self.meaning})")
            if any(isinstance(v, (list, tuple, dict, np.ndarray)) for v in values):
                return (f"'{key}' must be a flat list of numbers, {key} = [C1, C2, …] "
                        f"({self.meaning}), got a nested list {echo(value)}")
            bad = [echo(v) for v in values if not is_number(v)]
            if bad:
                return f"'{key}' must hold numbers, got {', '.join(bad)}"
            large = [f"C{k + 1} = {v:g}" for k, v in enumerate(values) if abs(v) > self.limit]
            if large:
                return (f"'{key}' is out of range: {', '.join(large)}; constants must lie "
                        f"within ±{self.limit:g} ({self.meaning}; are the units right?)")
        elif self.kind == "number":
            if isinstance(value, (list, tuple)) and len(value) == 1:
                value = value[0]
            if not is_number(value):
                return f"'{key}' must be a number ({self.meaning}), got {echo(value)}"
            if abs(value) > self.limit:
                return (f"'{key}' = {value:g} is out of range: it must lie within "
                        f"±{self.limit:g} ({self.meaning}; are the units right?)")

        elif self.kind == "law":
            if not isinstance(value, str) or (value not in LAWS and value not in LAW_ALIASES):
                return (f"unknown law {echo(value)}{closest(value, law_names())}; "
                        f"known laws: {', '.join(law_names())}")
        elif self.kind == "choice":
            if value not in self.choices:
                return (f"'{key}' must be one of {', '.join(map(repr, self.choices))}, "
                        f"got {echo(value)}{closest(value, self.choices)}")
        elif self.kind == "solid" and not isinstance(value, str):
            return f"'{key}' must be a solid name, got {echo(value)}"
        elif self.kind == "boolean" and not isinstance(value, bool):
            return f"'{key}' must be true or false ({self.meaning}), got {echo(value)}"
        return None


_X_AXIS = np.array([1.0, 0.0])
_X_AXIS.flags.writeable = False


def global_x(n: int) -> np.ndarray:
    """The global x axis (1, 0) for each of n states, (n, 2): a read-only view of one row
    (what ``np.broadcast_to([1.0, 0.0], (n, 2))`` gives, made without its checks)."""
    return np.ndarray((n, 2), float, _X_AXIS, 0, (0, _X_AXIS.itemsize))


def constants(value, size: int = 4) -> tuple[float, ...]:
    """C as a tuple of floats, missing entries 0."""
    values = list(value) if isinstance(value, (list, tuple, np.ndarray)) else [value]
    values = [scalar(v) for v in values]
    return tuple(values + [0.0] * (size - len(values)))


def number(value) -> float:
    if isinstance(value, (list, tuple)):
        value = value[0]
    return scalar(value)


@dataclass
class Load:
    """What a force element does at the states ``st`` (every array has a row per state).

    force:       generalized force on each solid it acts on, {solid: (n, 3)}: Fx, Fy and
                 the moment about the solid's frame origin
    outputs:     its force outputs under PAM's names (e.g. ``Força``)
    potential:   V(q) when the force derives from a potential (springs), else None: then
                 its whole power counts as work done from outside (torsors)
    dissipation: power removed by its velocity terms (dampers), ≥ 0 for C4 ≥ 0
    """

    force: dict[int, np.ndarray]
    outputs: dict[str, np.ndarray] = field(default_factory=dict)
    potential: np.ndarray | None = None
    dissipation: np.ndarray | None = None


@dataclass(eq=False)
class Element:
    """Base of all PAM elements. Subclasses set the class variables below."""

    name: str | None = None
    anc1: str | None = None
    anc2: str | None = None

    #: type name in the model file, and PAM's Catalan name
    type: ClassVar[str] = ""
    alias: ClassVar[str] = ""
    #: the specification that adds the type to the format (e.g. ``"clearance.md"``), for a
    #: type beyond the contract's ten (model-format.md's element table); None for those
    extension: ClassVar[str | None] = None
    #: what anc1 and anc2 must name: "solid", "point" or "line" (one entry per anchor)
    anchors: ClassVar[tuple[str, ...]] = ()
    #: what each anchor is, in PAM's words (default "solid 1", "solid 2")
    roles: ClassVar[tuple[str, ...]] = ()
    #: one line: what the element does
    summary: ClassVar[str] = ""
    #: keys besides name/anc1/anc2
    params: ClassVar[dict[str, Param]] = {}
    #: output variables, PAM names
    outputs: ClassVar[tuple[Var, ...]] = ()
    #: the joint's clearance parameters j (name, unit, meaning) when it has
    #: ``clearance = true`` (shared/spec/clearance.md); empty: the type takes no clearance
    clearance_parameters: ClassVar[tuple[Var, ...]] = ()
    #: outputs derived from the clearance parameters (``clearance_derived_values``)
    clearance_derived: ClassVar[tuple[Var, ...]] = ()
    #: F_j of its rows: parameter k enters equation row r of ``clearance_constraint`` as
    #: clearance_terms[r][k] · j_k (the closure F = C(q, t) + F_j j is linear in j)
    clearance_terms: ClassVar[tuple[tuple[float, ...], ...]] = ()
    #: number of constraint equations it adds (0: a force element)
    equations: ClassVar[int] = 0
    #: a constraint element's reaction, as reported: the names of the (force x, force y,
    #: moment) components of the wrench it applies to its receiving solid, in its reporting
    #: frame (``report_frame``); None marks a component that is zero by construction
    wrench: ClassVar[tuple[str | None, str | None, str | None]] = ()
    #: the element holds its (first) solid at its pose: a constraints-only Exudyn system
    #: may model that solid as ground instead
    grounds: ClassVar[bool] = False
    #: the element drives a coordinate by a time law f(t) (an actuator: ``time_law``)
    drives: ClassVar[bool] = False
    #: its equations tie a point of solid 1 to a point of solid 2 (a line's defining point,
    #: for a line anchor): an edge of the graph of the mechanism's loops (``analyses.loops``);
    #: ``tie_length`` says at what distance
    ties: ClassVar[bool] = False
    #: its two points coincide: the two solids can only turn about them (a pin joint): what
    #: hinges gears to their arm (``Transmission``), places a solid whose angle is known
    #: (``analyses.loops``) and makes a coupler's pivot (``points.couplers``)
    pins: ClassVar[bool] = False
    #: solid 2 can only slide along solid 1's line, without turning (a slider: the output
    #: of a slider-crank's coupler, ``points.couplers``)
    slides: ClassVar[bool] = False
    #: ``clearance = true``: the joint has clearance parameters (shared/spec/clearance.md);
    #: a key of the types with ``clearance_parameters`` only, always False for the others
    clearance: ClassVar[bool] = False

    #: 1-based position in the file's [[element]] array (set by the loader or the model)
    position: int | None = field(default=None, repr=False, kw_only=True)

    def __post_init__(self):
        """The names it gives (its own, its anchors, a solid key's) in one Unicode form
        (``limits.one_form``), as the solids' names."""
        for key in ("name", "anc1", "anc2", *(k for k, p in self.params.items()
                                               if p.kind == "solid")):
            setattr(self, key, one_form(getattr(self, key)))

    # ---- declaration -------------------------------------------------------------------
    @classmethod
    def keys(cls) -> list[str]:
        """Every key the element accepts in the model file."""
        return ["type", "name", *(f"anc{k + 1}" for k in range(len(cls.anchors))), *cls.params]

    @property
    def where(self) -> str:
        at = f" #{self.position}" if self.position else ""
        return f"[[element]]{at} '{shown(self.name)}' ({self.type})"


    def problems(self, scope) -> list[str]:
        """Every problem with this element's keys and references (empty when it is sound)."""
        out, refs = [], []
        for k, kind in enumerate(("anc1", "anc2")):
            value = getattr(self, kind)
            if k < len(self.anchors):
                if value is None:
                    out.append(f"'{kind}' is missing: it must name a {self.anchors[k]}")
                    continue
                if not isinstance(value, str):
                    out.append(f"'{kind}' must be a string naming a {self.anchors[k]} "
                               f"({ANCHOR_FORMS[self.anchors[k]]}), got {echo(value)}")
                    continue
                try:
                    refs.append(scope.resolve(self.anchors[k], value))
                except LookupError as exc:
                    out.append(f"{kind} = {echo(value)}: {exc}")
            elif value is not None:
                out.append(f"a {self.type} takes no '{kind}' (remove it)")
        for key, param in self.params.items():
            message = param.problem(key, getattr(self, key))
            if message:
                out.append(message)
            elif param.kind == "solid" and getattr(self, key) is not None:
                try:
                    scope.solid(getattr(self, key))
                except LookupError as exc:
                    out.append(f"{key} = {echo(getattr(self, key))}: {exc}")
        if not out and len(self.anchors) == 2 and self.equations:
            a, b = refs                          # (both anchors found: nothing is wrong)
            if a.solid == b.solid:
                out.append(f"anc1 and anc2 are on the same solid '{scope.solids[a.solid].name}': "
                           "an element must join two different solids")
        out += self.more_problems(scope) if not out else []
        return out

    def more_problems(self, scope) -> list[str]:
        """Checks particular to one element type (after the generic ones passed)."""
        return []

    def mistakes(self) -> list[str]:
        """What its valid keys say that is allowed but most likely a mistake, one message
        each (``model.mistakes.input_warnings``; ``run`` warns of them)."""
        return []

    def bind(self, scope) -> None:
        """Resolve anchors to references (``ref1``, ``ref2``): called once the model is valid."""
        refs = [scope.resolve(kind, getattr(self, f"anc{k + 1}"))
                for k, kind in enumerate(self.anchors)]
        self.refs = tuple(refs)
        self.ref1 = refs[0] if refs else None
        self.ref2 = refs[1] if len(refs) > 1 else None

    def given_anchors(self) -> tuple:
        """Its anchors as the model gives them: (anc1, anc2), one per entry of ``anchors``."""
        return tuple(getattr(self, f"anc{k + 1}") for k in range(len(self.anchors)))

    @property
    def solids(self) -> tuple[int, ...]:
        """Indices of the solids the element acts on."""
        return tuple(r.solid for r in self.refs)

    @property
    def holds(self) -> int | None:
        """The solid it holds at its pose (``grounds``: its first solid), None for the others."""
        return self.ref1.solid if self.grounds else None

    def tie_length(self, t: float) -> float | None:
        """The distance [m] it keeps between the two points it ties (``ties``) at time t:
        0 for a pin, f(t) for a distance actuator, None when the points slide (or it ties
        none)."""
        return None

    def angle_values(self, key: str) -> tuple[bool, ...]:
        """Which values of ``key`` are angles or angular rates (``Param.angles``; an
        actuator's law constants depend on its law and kind)."""
        return self.params[key].angles

    def given_angles(self) -> list[tuple[str, float]]:
        """(label, value) of every angle its keys give, in the model's unit (not a rate):
        ``Param.angles`` flags angles only, an actuator says which law constants are f.
        Read after validation (the values are numbers)."""
        out = []
        for key in self.params:
            flags, value = self.angle_values(key), getattr(self, key)
            if not any(flags) or value is None:
                continue
            if isinstance(value, (list, tuple, np.ndarray)):
                out += [(f"{key}{k + 1}", float(v)) for k, v in enumerate(value)
                        if k < len(flags) and flags[k]]
            else:
                out.append((key, float(value)))
        return out

    # ---- kinematics --------------------------------------------------------------------
    def constraint(self, st: State) -> tuple[Quantity, Any]:
        """(v, target): the equations v(q) − target(t) = 0, target a constant or a Law."""
        raise NotImplementedError(f"{self.type} adds no constraint")

    def clearance_derived_values(self, values: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        """The ``clearance_derived`` outputs from its parameters' values (by name)."""
        return {}

    def clearance_constraint(self, st: State, start: State) -> tuple[Quantity, Any]:
        """(v, target) of its rows C(q, t) when it has clearance (``clearance_terms`` adds
        F_j j): ``constraint`` unless the type says otherwise; ``start`` is the nominal
        assembly, for what it fixes (a prismatic's sense)."""
        return self.constraint(st)

    def compute(self, st: State, names: set[str]) -> dict[str, np.ndarray]:
        """Position- and velocity-level outputs (force outputs come from the force analyses)."""
        return {}

    # ---- forces ------------------------------------------------------------------------
    @property
    def receiver(self) -> int:
        """The solid whose received wrench is reported (solid 2 unless stated otherwise)."""
        return self.ref2.solid

    def report_frame(self, st: State) -> tuple[np.ndarray, np.ndarray]:
        """At the receiving solid's frame origin, global basis.

        Returns (point (n, 2), unit x axis (n, 2)): where, and in which basis, the wrench
        is reported (the first docstring line says it in words, for the reference pages).
        """
        s = self.receiver
        return st.q[:, pose(s)][:, :2], global_x(st.n)

    def loads(self, st: State, damping: bool) -> Load | None:
        """A force element's action at the states ``st`` (None for constraint elements).

        damping: include the velocity-dependent (C4) terms; ``st`` then has velocities.
        """
        return None

    # ---- Exudyn ------------------------------------------------------------------------
    def build(self, ex) -> None:
        """Add this element's Exudyn items to ``ex`` (a backend.exudyn.system.ExudynSystem).

        Talk to Exudyn only through ``ex`` (``ex.items``, ``ex.add``, the marker helpers,
        ``ex.drive``), with keyword arguments: the same method then writes the element's
        block of an exported script (``backend.exudyn.script.ScriptSystem``, ``pam2exu export``).
        """
        raise NotImplementedError

    # ---- natural coordinates -----------------------------------------------------------
    def natural(self, nc) -> None:
        """Declare this element's equations in natural coordinates to ``nc`` (a
        ``backend.natural.Formulation``): from its points, directions and angles
        (``nc.point``, ``nc.direction``, ``nc.angle``), ``nc.equation(self, [expressions],
        target)``; a revolute shares a basic point (``nc.coincide``), a fixed link makes its
        solid ground (``nc.ground``). Force elements declare nothing here."""
        if self.equations:
            raise NotImplementedError(f"{self.type} declares no natural-coordinate equations")

    def natural_loads(self, nl) -> None:
        """Apply this element's forces, computed from natural coordinates, to ``nl`` (a
        ``backend.natural.loads.Loads``: ``nl.point``, ``nl.direction``, ``nl.angle`` give
        where things are, ``nl.point_rate`` and ``nl.angle_rate`` how fast they move (zero
        at rest), ``nl.force`` and ``nl.moment`` apply). Constraint elements: none."""

    # ---- pictures ----------------------------------------------------------------------
    def draw(self, pen, st: State) -> None:
        """Draw the element's symbol with ``pen`` (a ``pictures.pen.Pen``) at the one
        configuration of ``st``: the element says what and where, the pen how it looks
        (as ``build`` says which Exudyn items, and the backend how to add them)."""


class Actuator(Element):
    """An element whose constraint follows a time law f(t)."""

    drives = True
    #: f(t) is an angle (an angular actuator), not a length
    angular: ClassVar[bool] = False

    def angle_values(self, key):
        """An angular actuator's law constants in the unit of f (``laws.VALUES_OF_F``)."""
        if key == "C":
            return VALUES_OF_F[LAW_ALIASES.get(self.law, self.law)] if self.angular else ()
        return super().angle_values(key)

    def given_angles(self):
        """An angular actuator's law constants that are values of f (not its rates)."""
        law = LAW_ALIASES.get(self.law, self.law)
        if not self.angular or law not in F_ORDERS:
            return []
        return [(f"law '{law}' C{k + 1}", c) for k, (c, order)
                in enumerate(zip(constants(self.C), F_ORDERS[law])) if order == 0]

    def more_problems(self, scope):
        law = LAW_ALIASES.get(self.law, self.law)
        c1, c2 = constants(self.C)[:2]
        if LAWS[law].interval and not c1 < c2:
            return [f"law '{self.law}' needs C1 < C2 (start and end of the motion, s), "
                    f"got C1 = {c1:g}, C2 = {c2:g}"]
        return []

    def mistakes(self):
        """A transition law given fewer than its four constants: the missing ones are 0 (the
        format's rule), so C4 = 0 is where it goes (from C3, between C1 and C2)."""
        law = LAW_ALIASES.get(self.law, self.law)
        given = len(self.C) if isinstance(self.C, (list, tuple, np.ndarray)) else 1
        if not LAWS[law].interval or given >= 4:
            return []
        c1, c2, c3, c4 = constants(self.C)
        missing = ", ".join(f"C{k + 1}" for k in range(given, 4))
        return [f"law '{self.law}' is given {given} constants, C = {list(self.C)}: {missing} "
                f"{'is' if given == 3 else 'are'} taken as 0, so f goes from C3 = {c3:g} to "
                f"C4 = {c4:g} between t = {c1:g} s and {c2:g} s; give the four constants "
                "C = [C1, C2, C3, C4] (start [s], end [s], value before, value after)"]

    def time_law(self) -> Law:
        """The law f(t) with this element's constants (subclasses have ``law`` and ``C``)."""
        return Law(self.law, constants(self.C))

    def compute(self, st, names):
        f, df, _ = self.time_law()(st.t)
        return {"f(t)": f, "Df(t)": df}

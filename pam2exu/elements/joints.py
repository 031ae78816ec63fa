"""Joints: fixed link, revolute, prismatic, pin-in-slot and gear transmission."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..kinematics import column, stack
from ..limits import ANGLE
from .base import CLEARANCE, FORCE, Element, Param, Var, global_x, number

#: ``clearance = true``: the joint gets clearance parameters (shared/spec/clearance.md)
_CLEARANCE = Param("boolean", "true: the joint has clearance parameters, which the clearance "
                   "analysis follows; the other analyses treat the joint as ideal",
                   extension="clearance.md")


@dataclass(eq=False)
class Fixed(Element):
    """The solid keeps its initial x, y, fi."""

    type = "fixed"
    alias = "enllac_fix"
    anchors = ("solid",)
    roles = ("the solid held",)
    summary = "the solid keeps its initial x, y, fi"
    outputs = (
        Var("Fx", "N", FORCE, "force the solid receives, at its local origin, global x"),
        Var("Fy", "N", FORCE, "force the solid receives, at its local origin, global y"),
        Var("Mz", "N·m", FORCE, "moment the solid receives, about its local origin, "
            "counter-clockwise"),
    )
    equations = 3
    wrench = ("Fx", "Fy", "Mz")
    grounds = True

    @property
    def receiver(self):
        return self.ref1.solid

    def bind(self, scope):
        super().bind(scope)
        s = scope.solids[self.ref1.solid]
        self.pose = np.array([float(s.x), float(s.y), float(s.fi)])

    def constraint(self, st):
        """q_k − q_k(0) = 0 for x, y, fi of the solid."""
        return stack(*(st.coordinate(self.ref1.solid, k) for k in range(3))), self.pose

    def build(self, ex):
        ground = ex.ground_coordinate()
        for k in range(3):
            ex.add(self, ex.items.ObjectConnectorCoordinate(
                markerNumbers=[ground, ex.coordinate_marker(self.ref1.solid, k)],
                offset=float(self.pose[k])))

    def natural(self, nc):
        """The solid is ground: its points are constants (no coordinates, no equation)."""
        nc.ground(self.ref1.solid, self.pose)

    def draw(self, pen, st):
        """A ground line under the held solid's origin."""
        pen.ground(st.point(self.ref1.solid, (0.0, 0.0)).value[0])


@dataclass(eq=False)
class Revolute(Element):
    """Point anc1 of solid 1 and point anc2 of solid 2 coincide."""

    type = "revolute"
    alias = "articulacio"
    anchors = ("point", "point")
    summary = "the two points coincide"
    outputs = (
        Var("Fx", "N", FORCE, "force solid 1 exerts on solid 2 at the joint, global x"),
        Var("Fy", "N", FORCE, "force solid 1 exerts on solid 2 at the joint, global y"),
    )
    equations = 2
    wrench = ("Fx", "Fy", None)
    ties = pins = True
    clearance: bool = False
    params = {"clearance": _CLEARANCE}
    clearance_parameters = (
        Var("jx", "m", CLEARANCE, "x of P2 − P1, from solid 1's point (anc1) to solid 2's "
            "point (anc2), global basis"),
        Var("jy", "m", CLEARANCE, "y of P2 − P1, from solid 1's point (anc1) to solid 2's "
            "point (anc2), global basis"),
    )
    #: C = P2 − P1 (``constraint``), F = C − j: the contract's P1 − P2 + j = 0
    clearance_terms = ((-1.0, 0.0), (0.0, -1.0))
    clearance_derived = (Var("jr", "m", CLEARANCE, "√(jx² + jy²): the radial clearance"),)

    def tie_length(self, t):
        """0: the two points coincide."""
        return 0.0

    def clearance_derived_values(self, values):
        """jr = √(jx² + jy²)."""
        return {"jr": np.hypot(values["jx"], values["jy"])}

    def report_frame(self, st):
        """At the joint, global basis."""
        return st.point(self.ref2.solid, self.ref2.local).value, global_x(st.n)

    def constraint(self, st):
        """r2 − r1 = 0 (Exudyn's ObjectJointRevolute2D: p(marker1) − p(marker0))."""
        p1, p2 = (st.point(r.solid, r.local) for r in self.refs)
        return p2 - p1, 0.0

    def build(self, ex):
        ex.add(self, ex.items.ObjectJointRevolute2D(
            markerNumbers=[ex.point_marker(self.ref1), ex.point_marker(self.ref2)]))

    def natural(self, nc):
        """One basic point shared by both solids: no equation."""
        nc.coincide(self.ref1, self.ref2, self)

    def draw(self, pen, st):
        """A pin joint at solid 2's point (on a support when it holds a solid to ground),
        ringed when it has clearance."""
        p = st.point(self.ref2.solid, self.ref2.local).value[0]
        pen.joint(p, self.solids)
        if self.clearance:
            pen.clearance(p)


def _on_line(st, guide, pin_solid, pin_local):
    """(p_guide − p_pin) · n_guide: the pin's distance from the guide line, sign reversed."""
    p_guide = st.point(guide.solid, guide.point)
    n_guide = st.direction(guide.solid, guide.normal)
    return (p_guide - st.point(pin_solid, pin_local)).dot(n_guide)


@dataclass(eq=False)
class Prismatic(Element):
    """Line anc2 of solid 2 slides along line anc1 of solid 1."""

    type = "prismatic"
    alias = "prismatic"
    anchors = ("line", "line")
    summary = ("the two lines coincide: solid 2's defining point lies on line 1, and the "
               "line directions stay parallel, in the same or the opposite sense, whichever "
               "the initial guess is nearer to")
    outputs = (
        Var("Fnormal", "N", FORCE, "force solid 1 exerts on solid 2, normal to solid 2's line"),
        Var("Mz", "N·m", FORCE, "moment solid 1 exerts on solid 2, about the defining point "
            "of solid 2's line"),
    )
    equations = 2
    wrench = (None, "Fnormal", "Mz")
    ties = slides = True
    clearance: bool = False
    params = {"clearance": _CLEARANCE}
    clearance_parameters = (
        Var("jn", "m", CLEARANCE, "n1·(p2 − p1): signed distance of line 2's defining point "
            "from line 1 (n1: line 1's direction turned +90°)"),
        Var("jfi", "rad", CLEARANCE, "(fi2 + α2) − (fi1 + α1) − kπ: angle of line 2 relative "
            "to line 1 (k: the sense chosen at assembly)"),
    )
    #: rows C = ((p1 − p2)·n1, fi2 − fi1 − (α1 − α2 + kπ)) (``clearance_constraint``),
    #: F = C + (jn, −jfi): the contract's n1·(p2 − p1) − jn = 0 and its angle equation
    clearance_terms = ((1.0, 0.0), (0.0, -1.0))

    def report_frame(self, st):
        """At the defining point of solid 2's line, x along that line (its own sense)."""
        line2 = self.ref2
        return (st.point(line2.solid, line2.point).value,
                st.direction(line2.solid, line2.direction).value)

    def constraint(self, st):
        """(p1 − p2)·n1 = 0 and (A2 t2)·(A1 n1) = 0 (Exudyn's ObjectJointPrismatic2D, markers [2, 1])."""
        line1, line2 = self.refs
        parallel = st.direction(line2.solid, line2.direction).dot(
            st.direction(line1.solid, line1.normal))
        return stack(_on_line(st, line1, line2.solid, line2.point), parallel), 0.0

    def clearance_constraint(self, st, start):
        """(p1 − p2)·n1 and fi2 − fi1 − (α1 − α2 + kπ), k the sense at the nominal assembly
        ``start`` (the contract's angle equation: linear in the angles, so jfi is an angle)."""
        line1, line2 = self.refs
        relative = st.angle(line2.solid) - st.angle(line1.solid)
        at_start = (start.q[0, column(line2.solid, 2)] + line2.angle
                    - start.q[0, column(line1.solid, 2)] - line1.angle)
        sense = np.round(np.real(at_start) / math.pi)   # (real in a complex step)
        target = line1.angle - line2.angle + sense * math.pi   # (n,) where the lines vary
        return (stack(_on_line(st, line1, line2.solid, line2.point), relative),
                np.stack(np.broadcast_arrays(0.0, target), axis=-1))

    def build(self, ex):
        line1, line2 = self.refs
        ex.add(self, ex.items.ObjectJointPrismatic2D(
            markerNumbers=[ex.point_marker(line2), ex.point_marker(line1)],
            axisMarker0=[*line2.direction, 0.0], normalMarker1=[*line1.normal, 0.0],
            constrainRotation=True))

    def natural(self, nc):
        """(p1 − p2)·n1 = 0 and t2·n1 = 0: quadratic in z (points and directions are linear)."""
        line1, line2 = self.refs
        n1 = nc.direction(line1.solid, line1.normal)
        gap = nc.point(line1.solid, line1.point) - nc.point(line2.solid, line2.point)
        nc.equation(self, [gap.dot(n1), nc.direction(line2.solid, line2.direction).dot(n1)])

    def draw(self, pen, st):
        """Line 1 as a guide, a slider block on solid 2's defining point along line 2,
        ringed when it has clearance."""
        line1, line2 = self.refs
        p2 = st.point(line2.solid, line2.point).value[0]
        pen.guide(st.point(line1.solid, line1.point).value[0],
                  st.direction(line1.solid, line1.direction).value[0], p2, line1.solid)
        pen.block(p2, st.direction(line2.solid, line2.direction).value[0], line2.solid)
        if self.clearance:
            pen.clearance(p2)


@dataclass(eq=False)
class PinSlot(Element):
    """Point anc2 (the pin) of solid 2 stays on line anc1 (the guide) of solid 1."""

    type = "pin_slot"
    alias = "piu_guia"
    anchors = ("line", "point")
    roles = ("guide", "pin")
    summary = "the pin stays on the guide"
    outputs = (Var("Fnormal", "N", FORCE,
                   "force the guide (solid 1) exerts on the pin (solid 2), normal to the guide"),)
    equations = 1
    wrench = (None, "Fnormal", None)
    ties = True
    clearance: bool = False
    params = {"clearance": _CLEARANCE}
    clearance_parameters = (
        Var("jn", "m", CLEARANCE, "n1·(P2 − p1): signed distance of the pin from the guide "
            "(n1: the guide's direction turned +90°)"),
    )
    #: C = (p1 − P2)·n1 (``constraint``), F = C + jn: the contract's n1·(P2 − p1) − jn = 0
    clearance_terms = ((1.0,),)

    def report_frame(self, st):
        """At the pin, x along the guide (its own sense)."""
        guide, pin = self.refs
        return (st.point(pin.solid, pin.local).value,
                st.direction(guide.solid, guide.direction).value)

    def constraint(self, st):
        """(p_guide − p_pin)·n_guide = 0 (ObjectJointPrismatic2D, markers [pin, guide])."""
        guide, pin = self.refs
        return _on_line(st, guide, pin.solid, pin.local), 0.0

    def build(self, ex):
        guide, pin = self.refs
        ex.add(self, ex.items.ObjectJointPrismatic2D(
            markerNumbers=[ex.point_marker(pin), ex.point_marker(guide)],
            axisMarker0=[*guide.direction, 0.0], normalMarker1=[*guide.normal, 0.0],
            constrainRotation=False))

    def natural(self, nc):
        """(p_guide − p_pin)·n_guide = 0: quadratic in z."""
        guide, pin = self.refs
        gap = nc.point(guide.solid, guide.point) - nc.point(pin.solid, pin.local)
        nc.equation(self, [gap.dot(nc.direction(guide.solid, guide.normal))])

    def draw(self, pen, st):
        """The guide line, the pin on it, ringed when it has clearance."""
        guide, pin = self.refs
        p = st.point(pin.solid, pin.local).value[0]
        pen.guide(st.point(guide.solid, guide.point).value[0],
                  st.direction(guide.solid, guide.direction).value[0], p, guide.solid)
        pen.pin(p)
        if self.clearance:
            pen.clearance(p)


@dataclass(eq=False)
class Transmission(Element):
    """Gears: (fi2 − fi_arm) − T (fi1 − fi_arm) − C = 0."""

    T: Any = None
    C: Any = 0.0
    arm: str | None = None

    type = "transmission"
    alias = "transmissio"
    anchors = ("solid", "solid")
    summary = ("(fi2 - fi_arm) - T (fi1 - fi_arm) - C = 0; the arm is the solid that both are "
               "hinged to by revolute joints (ground included); name it with `arm` when that "
               "is ambiguous")
    params = {
        "T": Param("number", "transmission ratio", required=True, limit=1e6),
        "C": Param("number", "initial angle [rad]", limit=ANGLE, angles=(True,)),
        "arm": Param("solid", "the solid both gears are hinged to (found when unambiguous)"),
    }
    outputs = (Var("Parell", "N·m", FORCE, "torque solid 2 receives from the transmission "
                   "(pure torques: Parell on solid 2, −T·Parell on solid 1, (T−1)·Parell on "
                   "the arm; no tooth force enters the bearings)"),)
    equations = 1
    wrench = (None, None, "Parell")

    def more_problems(self, scope):
        if number(self.T) == 0:
            return ["T = 0 is not a gear ratio: it would hold solid 2 to the arm and leave "
                    "solid 1 free; give the ratio of the angular velocities (fi2 − fi_arm)' / "
                    "(fi1 − fi_arm)', e.g. T = -0.5 for a pinion driving a gear twice its size"]
        if self.arm is not None:
            return []

        arms = self.candidate_arms(scope)
        s1, s2 = (scope.solids[scope.solid(a).solid].name for a in (self.anc1, self.anc2))
        if not arms:
            return [f"no arm found: no solid is hinged by revolute joints to both '{s1}' and "
                    f"'{s2}'; add the joints or name the arm with arm = \"...\""]
        if len(arms) > 1:
            names = ", ".join(f"'{scope.solids[a].name}'" for a in arms)
            return [f"the arm is ambiguous: {names} are each hinged to both '{s1}' and '{s2}'; "
                    f"name it with arm = \"...\""]
        return []

    def candidate_arms(self, scope) -> list[int]:
        """Solids hinged by pin joints (``pins``: revolutes) to both solid 1 and solid 2."""
        hinged = {}
        for el in scope.elements:
            if el.pins and el is not self:
                try:
                    a, b = (scope.point(x).solid for x in (el.anc1, el.anc2))
                except (LookupError, TypeError):
                    continue
                hinged.setdefault(a, set()).add(b)
                hinged.setdefault(b, set()).add(a)
        s1, s2 = scope.solid(self.anc1).solid, scope.solid(self.anc2).solid
        return sorted(hinged.get(s1, set()) & hinged.get(s2, set()))

    def bind(self, scope):
        super().bind(scope)
        self.arm_solid = (scope.solid(self.arm).solid if self.arm is not None
                          else self.candidate_arms(scope)[0])
        self.ratio, self.offset = number(self.T), number(self.C)

    @property
    def solids(self):
        return (*super().solids, self.arm_solid)

    def constraint(self, st):
        """T (fi1 − fi_arm) − (fi2 − fi_arm) = −C (Exudyn's factor1·q[m1] − q[m0] = offset)."""
        arm = st.angle(self.arm_solid)
        rel1, rel2 = (st.angle(r.solid) - arm for r in self.refs)
        return rel1 * self.ratio - rel2, -self.offset

    def build(self, ex):
        rel2 = ex.relative_rotation_marker(self.arm_solid, self.ref2.solid)
        rel1 = ex.relative_rotation_marker(self.arm_solid, self.ref1.solid)
        ex.add(self, ex.items.ObjectConnectorCoordinate(
            markerNumbers=[rel2, rel1], factor1=self.ratio, offset=-self.offset))

    def natural(self, nc):
        """T (fi1 − fi_arm) − (fi2 − fi_arm) = −C in the solids' angle coordinates: linear."""
        arm = nc.angle(self.arm_solid)
        rel1, rel2 = (nc.angle(r.solid) - arm for r in self.refs)
        nc.equation(self, [rel1 * self.ratio - rel2], -self.offset)

    def draw(self, pen, st):
        """Pitch circles about the two solids' origins, radii in the ratio |T|."""
        o1, o2 = (st.point(r.solid, (0.0, 0.0)).value[0] for r in self.refs)
        pen.gears(o1, o2, self.ratio, (self.ref1.solid, self.ref2.solid))

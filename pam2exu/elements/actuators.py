"""Actuators: relative angle or distance following a time law f(t)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..complex_step import row_norm
from ..laws import Law
from .base import FORCE, POSITION, VELOCITY, Actuator, Param, Var

_LAW = Param("law", "time law")
_C = Param("constants", "constants C1…C4 of the law")


@dataclass(eq=False)
class AngularActuator(Actuator):
    """fi2 − fi1 = f(t)."""

    law: str = "polynomial"
    C: Any = (0.0, 0.0, 0.0, 0.0)

    type = "angular_actuator"
    alias = "actuador_angular"
    anchors = ("solid", "solid")
    summary = "fi2 - fi1 = f(t)"
    params = {"law": _LAW, "C": _C}
    angular = True
    outputs = (
        Var("Mz", "N·m", FORCE, "torque the actuator exerts on solid 2 (motor torque)"),
        Var("f(t)", "rad", POSITION, "the law: relative angle fi2 − fi1"),
        Var("Df(t)", "rad/s", VELOCITY, "its first derivative"),
    )
    equations = 1
    wrench = (None, None, "Mz")

    def constraint(self, st):
        """fi2 − fi1 − f(t) = 0 (Exudyn's ObjectConnectorCoordinate q[m1] − q[m0] − offset)."""
        return st.angle(self.ref2.solid) - st.angle(self.ref1.solid), self.time_law()

    def build(self, ex):
        # marker values are fi − shift (a grounded solid's marker reads 0, not its fi)
        shift = ex.coordinate_shift(self.ref1.solid, 2) - ex.coordinate_shift(self.ref2.solid, 2)
        obj = ex.add(self, ex.items.ObjectConnectorCoordinate(
            markerNumbers=[ex.coordinate_marker(self.ref1.solid, 2),
                           ex.coordinate_marker(self.ref2.solid, 2)],
            offset=self.time_law().value(0.0) + shift))
        ex.drive(obj, "offset", self.time_law(), shift)

    def natural(self, nc):
        """fi2 − fi1 = f(t) in the solids' angle coordinates: linear."""
        nc.equation(self, [nc.angle(self.ref2.solid) - nc.angle(self.ref1.solid)],
                    self.time_law())

    def draw(self, pen, st):
        """An arc arrow about solid 2's origin."""
        pen.rotation(st.point(self.ref2.solid, (0.0, 0.0)).value[0])


@dataclass(eq=False)
class LinearActuator(Actuator):
    """The distance between point P (anc1) and point Q (anc2) is f(t)."""

    law: str = "polynomial"
    C: Any = (0.0, 0.0, 0.0, 0.0)

    type = "linear_actuator"
    alias = "actuador_lineal"
    anchors = ("point", "point")
    roles = ("P", "Q")
    summary = "distance PQ = f(t)"
    params = {"law": _LAW, "C": _C}
    outputs = (
        Var("Força", "N", FORCE, "force of the actuator, positive = repulsion between P and Q"),
        Var("f(t)", "m", POSITION, "the law: distance PQ"),
        Var("Df(t)", "m/s", VELOCITY, "its first derivative"),
    )
    equations = 1
    wrench = ("Força", None, None)
    ties = True

    def tie_length(self, t):
        """f(t): the distance PQ its law sets."""
        return float(self.time_law()(np.array([t]))[0][0])

    def report_frame(self, st):
        """At Q, x from P to Q (so that a positive force pushes Q away from P)."""
        P, Q = (st.point(r.solid, r.local).value for r in self.refs)
        d = Q - P
        return Q, d / row_norm(d)

    def constraint(self, st):
        """|Q − P| − f(t) = 0 (Exudyn's ObjectConnectorDistance)."""
        P, Q = (st.point(r.solid, r.local) for r in self.refs)
        return (Q - P).norm(), self.time_law()

    def build(self, ex):
        law: Law = self.time_law()
        obj = ex.add(self, ex.items.ObjectConnectorDistance(
            markerNumbers=[ex.point_marker(self.ref1), ex.point_marker(self.ref2)],
            distance=law.value(0.0)))
        ex.drive(obj, "distance", law)

    def natural(self, nc):
        """|Q − P|² = f(t)²: quadratic in z."""
        P, Q = (nc.point(r.solid, r.local) for r in self.refs)
        nc.equation(self, [(Q - P).dot(Q - P)], self.time_law(), power=2)

    def draw(self, pen, st):
        """A thick bar from P to Q."""
        pen.cylinder(*(st.point(r.solid, r.local).value[0] for r in self.refs))

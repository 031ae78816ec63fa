"""Force elements: applied torsor, linear and torsional spring-dampers."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from ..complex_step import hypot
from ..errors import SolverError
from ..kinematics import Quantity, column, generalized_force, rotate, torque
from .base import FORCE, POSITION, VELOCITY, Element, Load, Param, Var, constants


def _add(forces: dict, more: dict) -> dict:
    """Sum of two {solid: generalized force} dictionaries."""
    out = dict(forces)
    for solid, q in more.items():
        out[solid] = out[solid] + q if solid in out else q
    return out


def _from_potential(coordinate, value) -> dict:
    """Q = −F ∂c/∂q: a force F (n,) that tends to decrease the scalar quantity c."""
    return {s: -value[:, None] * block[:, 0, :] for s, block in coordinate.jac.items()}


@dataclass(eq=False)
class Torsor(Element):
    """Applied force (Fx, Fy) at a point and moment M, in global or solid axes."""

    C: Any = (0.0, 0.0, 0.0)
    axes: str = "global"

    type = "torsor"
    alias = "torsor"
    anchors = ("point",)
    roles = ("where the force acts",)
    summary = ("applied force and moment; components constant in the global frame or in the "
               "solid's frame")
    params = {
        "C": Param("constants", "[Fx, Fy, M] in N, N, N·m", size=3),
        "axes": Param("choice", "basis of the components", choices=("global", "solid")),
    }

    def loads(self, st, damping):
        """Q = Jᵀ F + (0, 0, M), with F = A(fi) (Fx, Fy) in solid axes."""
        fx, fy, m = constants(self.C, 3)
        solid, local = self.ref1.solid, self.ref1.local
        if self.axes == "solid":
            force = rotate(st.q[:, column(solid, 2)], np.array([fx, fy]))
        else:
            force = np.broadcast_to([fx, fy], (st.n, 2))
        return Load(_add(generalized_force(st.point(solid, local), force),
                         torque(solid, np.full(st.n, m))))

    def build(self, ex):
        fx, fy, m = constants(self.C, 3)
        marker = ex.point_marker(self.ref1)
        solid_axes = self.axes == "solid"
        if fx or fy:
            ex.add(self, ex.items.LoadForceVector(markerNumber=marker, loadVector=[fx, fy, 0.0],
                                                  bodyFixed=solid_axes), kind="load")
        if m:
            ex.add(self, ex.items.LoadTorqueVector(markerNumber=marker, loadVector=[0.0, 0.0, m],
                                                   bodyFixed=solid_axes), kind="load")

    def natural_loads(self, nl):
        """F = (Fx, Fy), or A(fi) (Fx, Fy) in solid axes, at the point; M on the solid."""
        fx, fy, m = constants(self.C, 3)
        solid, local = self.ref1.solid, self.ref1.local
        force = (nl.direction(solid, (fx, fy)) if self.axes == "solid"
                 else np.broadcast_to([fx, fy], (nl.n, 2)))
        nl.force(solid, local, force)
        nl.moment(solid, np.full(nl.n, m))

    def draw(self, pen, st):
        """An arrow along the force at its point, an arc arrow for the moment."""
        fx, fy, m = constants(self.C, 3)
        solid, local = self.ref1.solid, self.ref1.local
        p = st.point(solid, local).value[0]
        force = np.array([fx, fy])
        if self.axes == "solid":
            force = rotate(st.q[:, column(solid, 2)], force)[0]
        if fx or fy:
            pen.force(p, force)
        if m:
            pen.moment(p, m)


class _SpringDamper(Element):
    """A spring-damper on a scalar measure x (a distance, a relative angle):
    F = C1 + C2 (x − C3) + C4 ẋ, acting to decrease x."""

    #: names of the measure x and of the force output
    variable: ClassVar[str] = ""
    force: ClassVar[str] = ""

    def measure(self, st) -> Quantity:
        """x as a Quantity."""
        raise NotImplementedError

    def compute(self, st, names):
        x = self.measure(st)
        out = {self.variable: x.value[:, 0]}
        if x.rate is not None:
            out[f"D{self.variable}"] = x.rate[:, 0]
        return out

    def loads(self, st, damping):
        """Q = −F ∂x/∂q; V = C1 x + C2 (x − C3)²/2; the damper dissipates C4 ẋ²."""
        c1, c2, c3, c4 = constants(self.C)
        x = self.measure(st)
        value = x.value[:, 0]
        force = c1 + c2 * (value - c3)
        dissipation = None
        if damping:
            force = force + c4 * x.rate[:, 0]
            dissipation = c4 * x.rate[:, 0] ** 2
        return Load(_from_potential(x, force), {self.force: force},
                    c1 * value + 0.5 * c2 * (value - c3) ** 2, dissipation)


@dataclass(eq=False)
class Spring(_SpringDamper):
    """F = C1 + C2 (ro − C3) + C4 Dro between two points, positive = attraction."""

    C: Any = (0.0, 0.0, 0.0, 0.0)

    type = "spring"
    alias = "molla_amortidor_lineal"
    anchors = ("point", "point")
    summary = ("F = C1 + C2 (ro - C3) + C4 Dro, positive = attraction; ro = distance between "
               "the points")
    params = {"C": Param("constants", "C1 [N], C2 [N/m], C3 [m], C4 [N·s/m]")}
    outputs = (
        Var("Força", "N", FORCE, "force of the spring-damper, positive = attraction"),
        Var("ro", "m", POSITION, "distance between the points"),
        Var("Dro", "m/s", VELOCITY, "its rate"),
    )

    variable, force = "ro", "Força"

    def more_problems(self, scope):
        P, Q = (scope.point(a) for a in (self.anc1, self.anc2))
        if P.solid == Q.solid and P.local == Q.local:
            return [f"anc1 and anc2 are the same point '{self.anc1}': a spring of length 0 "
                    "has no direction for its force; attach it between two different points"]
        return []

    def measure(self, st):
        """ro = |Q − P| (F > 0 attracts P and Q); SolverError where the points coincide."""
        P, Q = (st.point(r.solid, r.local) for r in self.refs)
        gap = Q - P
        self.require_apart(st.t, hypot(gap.value[:, 0], gap.value[:, 1]), P.value)
        return gap.norm()

    def require_apart(self, t, length, P) -> None:
        """SolverError at the first time where ro ≤ 1e-12 max(1, |P|): a spring of length 0
        has no direction for its force."""
        length = np.real(length)                       # (complex in the complex step)
        if not len(length) or np.min(length) > 1e-12 * max(1.0, float(np.max(np.abs(P)))):
            return
        k = int(np.argmin(length))
        when = f"at t = {t[k]:.6g} s " if np.isfinite(t[k]) else ""
        raise SolverError(
            f"{when}the points of spring '{self.name}' coincide (ro = "
            f"{length[k]:.3g} m): a spring of length 0 has no direction for its force. "
            f"Attach it between points that stay apart, or end the interval before "
            f"this time.", time=float(t[k]), elements=(f"'{self.name}' (spring)",))


    def build(self, ex):
        c1, c2, c3, c4 = constants(self.C)
        damping = c4 if ex.velocity_forces else 0.0
        markers = [ex.point_marker(self.ref1), ex.point_marker(self.ref2)]
        if c2 >= 0 and c3 >= 0:
            ex.add(self, ex.items.ObjectConnectorSpringDamper(
                markerNumbers=markers, referenceLength=c3, stiffness=c2, damping=damping,
                force=c1))
            return

        # Exudyn refuses a negative stiffness or free length: the same law as a force
        # function of ro = deltaL (referenceLength 0)
        def law(mbs, t, item, ro, rate, stiffness, damping_, force):
            return c1 + c2 * (ro - c3) + damping * rate
        ex.add(self, ex.items.ObjectConnectorSpringDamper(
            markerNumbers=markers, springForceUserFunction=law))

    def natural_loads(self, nl):
        """F = C1 + C2 (ro − C3) + C4 Dro pulls P towards Q and Q towards P (Dro = 0 at
        rest: the static check)."""
        c1, c2, c3, c4 = constants(self.C)
        P, Q = (nl.point(r.solid, r.local) for r in self.refs)
        gap = Q - P
        ro = hypot(gap[:, 0], gap[:, 1])
        self.require_apart(nl.t, ro, P)
        rate = nl.point_rate(self.ref2.solid, self.ref2.local) - \
            nl.point_rate(self.ref1.solid, self.ref1.local)
        dro = np.sum(gap * rate, axis=1) / ro
        pull = ((c1 + c2 * (ro - c3) + c4 * dro) / ro)[:, None] * gap
        nl.force(self.ref1.solid, self.ref1.local, pull)
        nl.force(self.ref2.solid, self.ref2.local, -pull)

    def draw(self, pen, st):
        """A zigzag between the two points."""
        pen.zigzag(*(st.point(r.solid, r.local).value[0] for r in self.refs))


@dataclass(eq=False)
class TorsionalSpring(_SpringDamper):
    """Parell = C1 + C2 (fi_rel − C3) + C4 Dfi_rel, fi_rel = fi2 − fi1."""

    C: Any = (0.0, 0.0, 0.0, 0.0)

    type = "torsional_spring"
    alias = "molla_amortidor_torsional"
    anchors = ("solid", "solid")
    summary = ("Parell = C1 + C2 (fi_rel - C3) + C4 Dfi_rel, fi_rel = fi2 - fi1; positive "
               "counter-clockwise on solid 1, clockwise on solid 2")
    params = {"C": Param("constants", "C1 [N·m], C2 [N·m/rad], C3 [rad], C4 [N·m·s/rad]",
                         angles=(False, False, True, False))}
    outputs = (
        Var("Parell", "N·m", FORCE, "torque, counter-clockwise on solid 1, clockwise on solid 2"),
        Var("fi_rel", "rad", POSITION, "relative angle fi2 − fi1"),
        Var("Dfi_rel", "rad/s", VELOCITY, "its rate"),
    )

    variable, force = "fi_rel", "Parell"

    def measure(self, st):
        """fi_rel = fi2 − fi1 (Parell > 0 turns solid 1 counter-clockwise, solid 2 clockwise)."""
        return st.angle(self.ref2.solid) - st.angle(self.ref1.solid)

    def build(self, ex):
        c1, c2, c3, c4 = constants(self.C)
        fi1, fi2 = (ex.coordinate_marker(r.solid, 2) for r in self.refs)
        ex.add(self, ex.items.ObjectConnectorCoordinateSpringDamper(
            markerNumbers=[fi1, fi2], stiffness=c2, offset=c3,
            damping=c4 if ex.velocity_forces else 0.0))
        if c1:
            for ref, sign in ((self.ref1, 1.0), (self.ref2, -1.0)):
                ex.add(self, ex.items.LoadTorqueVector(
                    markerNumber=ex.point_marker(ref), loadVector=[0.0, 0.0, sign * c1]),
                    kind="load")

    def natural_loads(self, nl):
        """Parell = C1 + C2 (fi2 − fi1 − C3) + C4 (Dfi2 − Dfi1): counter-clockwise on solid 1,
        clockwise on 2 (the rates are zero at rest: the static check)."""
        c1, c2, c3, c4 = constants(self.C)
        s1, s2 = (r.solid for r in self.refs)
        torque_ = c1 + c2 * (nl.angle(s2) - nl.angle(s1) - c3) + \
            c4 * (nl.angle_rate(s2) - nl.angle_rate(s1))
        nl.moment(s1, torque_)
        nl.moment(s2, -torque_)

    def draw(self, pen, st):
        """A spiral about solid 2's origin."""
        pen.spiral(st.point(self.ref2.solid, (0.0, 0.0)).value[0])

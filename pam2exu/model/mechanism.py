"""The mechanism: a validated model with its anchors resolved, what the translation and the
analyses work on (``Model.mechanism()`` makes it)."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

from ..complex_step import scalar
from ..elements import Element
from ..kinematics import PER_SOLID
from .angles import si_inputs
from .solid import Scope, Solid
from .variation import Variation


class ModelLike(Protocol):
    """What a mechanism reads of the model it is made from: a ``Model``, which makes
    mechanisms (``Model.mechanism``), so this module does not import it."""

    name: str
    gravity: float
    source: str | None
    angles: str
    solids: list[Solid]
    elements: list[Element]
    variations: list[Variation]


@dataclass
class Mechanism:
    """A validated model with its anchors resolved: what translation and analyses use.

    The generalized coordinates are q = (x, y, fi) of each solid in order, so solid i
    owns q[3i:3i+3]. Made by ``Model.mechanism()``, which validates the model first.

    Parameters
    ----------
    model : Model
        A model without problems (not checked here: use ``Model.mechanism``).

    Attributes
    ----------
    model : Model
        The model it was made from.
    solids : list of Solid
        The model's solids, in order (copies with fi and line angles in radians when the
        model gives degrees).
    elements : list of Element
        Copies of the model's elements, bound to their anchors (``ref1``, ``ref2``), their
        angles in radians.
    constraints : list of Element
        The elements that add constraint equations, in order.
    drivers : list of Element
        The actuators among them (``Element.drives``), in order.
    held : frozenset of int
        The indices of the solids held at their pose by a fixed link (``Element.grounds``,
        ``Element.holds``): the ground.
    rows : list of slice
        The rows of each constraint element's equations in C(q, t) = 0.
    n_equations : int
        Number of constraint equations.
    index : dict
        Solid name → index i (its coordinates are q[3i:3i+3]).
    variations : list of Variation
        Copies of the model's variations, bound to their point or line (``kind``, ``ref``,
        ``nominal``, ``offsets(t)``); read by the clearance analysis only.
    """

    model: ModelLike
    solids: list[Solid] = field(init=False)
    elements: list[Element] = field(init=False)

    def __post_init__(self):
        # the model's angles in radians (copies where it gives degrees: model/angles.py)
        self.solids, self.elements, self.variations = si_inputs(self.model)
        scope = Scope(self.solids)
        scope.elements = self.model.elements
        for el in self.elements:
            el.bind(scope)
        self.constraints = [e for e in self.elements if e.equations]
        #: the actuators: constraint elements that drive a coordinate by a time law
        self.drivers = [e for e in self.constraints if e.drives]
        #: the solids held at their pose by a fixed link (``Element.holds``): the ground
        self.held = frozenset(e.holds for e in self.constraints if e.grounds)

        rows, start = [], 0
        for el in self.constraints:
            rows.append(slice(start, start + el.equations))
            start += el.equations
        self.rows = rows
        self.n_equations = start
        self.index = scope.index
        for v in self.variations:
            v.bind(scope)
        self._varied = {(v.kind, v.anchor): v for v in self.variations}

    def variation(self, element: Element, k: int) -> Variation | None:
        """The variation of anchor ``k`` (0: anc1, 1: anc2) of ``element``, or None.

        A variation applies wherever its point or line is an anchor: where the element
        names it as ``"solid.point"`` or ``"solid.line"`` (a bare solid name is never
        varied).

        Parameters
        ----------
        element : Element
            One of ``elements``.
        k : int
            The anchor: 0 for anc1, 1 for anc2.

        Returns
        -------
        Variation or None
            The bound variation of that point or line (``offsets(t)``: u(t) − u0 and
            u'(t)), or None when it does not vary.
        """
        return self._varied.get((element.anchors[k], element.given_anchors()[k]))

    @property
    def name(self) -> str:
        """The model's name."""
        return self.model.name

    @property
    def gravity(self) -> float:
        """Magnitude of the gravitational acceleration, along −y [m/s²]."""
        return scalar(self.model.gravity)

    @property
    def nq(self) -> int:
        """Number of generalized coordinates: x, y, fi of each solid (``kinematics.pose``)."""
        return PER_SOLID * len(self.solids)

    def initial_q(self):
        """The initial guess q0 from the solids' x, y, fi.

        Returns
        -------
        numpy.ndarray
            Shape (nq,): x [m], y [m], fi [rad] of each solid in order.
        """
        import numpy as np
        return np.array([float(v) for s in self.solids for v in (s.x, s.y, s.fi)])

    def coordinate_columns(self, rate: str = "") -> list[str]:
        """The result columns of q or of its rates, in the order of q.

        Parameters
        ----------
        rate : str
            "" for x, y, fi; "D" for their first, "DD" for their second time derivatives.

        Returns
        -------
        list of str
            ``<solid>.<rate>x``, ``<solid>.<rate>y``, ``<solid>.<rate>fi`` of each solid.
        """
        return [f"{s.name}.{rate}{k}" for s in self.solids for k in ("x", "y", "fi")]

    def coordinates(self, res, rate: str = "", rows=None):
        """q (or q̇, q̈: ``rate`` "D", "DD") from the columns of a result table, in radians.

        Parameters
        ----------
        res : Results
            A run of this mechanism with the columns ``coordinate_columns(rate)``, angles
            in radians.
        rate : str
            "" for x, y, fi; "D" for their first, "DD" for their second time derivatives.
        rows : array of int, optional
            The rows to take; all of them when None.

        Returns
        -------
        numpy.ndarray
            Shape (rows, nq): the columns side by side, solid by solid (``kinematics.pose``).
        """
        import numpy as np
        rows = slice(None) if rows is None else rows
        return np.column_stack([res[c][rows] for c in self.coordinate_columns(rate)])

    def initial_qd(self):
        """The initial-velocity guess q̇0 from the solids' Dx, Dy, Dfi (``dynamic``).

        Returns
        -------
        numpy.ndarray
            Shape (nq,): Dx [m/s], Dy [m/s], Dfi [rad/s] of each solid in order.
        """
        import numpy as np
        return np.array([float(v) for s in self.solids for v in (s.Dx, s.Dy, s.Dfi)])

    def scale(self) -> float:
        """A length typical of the mechanism [m]: the largest point or pose offset, at least 1e-3.

        Returns
        -------
        float
            max(1e-3, |x|, |y| of every solid, |coordinates| of every point) [m]; the
            scale of the solver tolerances and self-checks.
        """
        # (the real part: a point at p + ih in the complex step has the nominal's scale)
        values = [abs(float(v)) for s in self.solids for v in (s.x, s.y)]
        values += [abs(complex(c).real) for s in self.solids for p in s.points.values()
                   for c in p]
        return max([1e-3, *values])

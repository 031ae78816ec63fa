"""Forces in natural coordinates: what the natural backend's static equilibrium gives the
quasi-static analysis to check (``Positions.multipliers``).

Each force acts on one solid, whose points are r(s) = p + a v + b Ω v (``Frame``): a force
F at s does the virtual work F·(δp + a δv + b Ω δv), so it is (F, a F − b Ω F) on the
solid's (p, v); a moment M does M δfi = M (Ω v)·δv / |v|². On x, y, fi (p = R + A s_p,
v = A d): Q_xy = Q_p, Q_fi = Q_p·Ω(p − R) + Q_v·Ω v. The multipliers then follow from
pam2exu's own Cqᵀ λ = −Q (least squares, minimum norm), in its row order. On z itself
(the dynamic analysis, ``dynamics``): Q_z = Σ Pᵀ Q_p + Vᵀ Q_v, with ṗ = P ż and v̇ = V ż
(``inverse.on_coordinates`` of ``Loads.Q``).

Given the rates ż, the dampers (C4) see the rates of the points and angles
(``point_rate``, ``angle_rate``); without them every rate is zero (static).
"""
from __future__ import annotations

import numpy as np

from ...kinematics import State, column, pose, perp


def _lever(frame, local) -> tuple[float, float]:
    """(a, b) of the point ``local`` of a solid: r = p + a v + b Ω v (``Frame.point``)."""
    return frame._ab((local[0] - frame.sp[0], local[1] - frame.sp[1]))


def _on_v(a: float, b: float, force: np.ndarray) -> np.ndarray:
    """a F − b Ω F: the share on the base vector v of a force F at p + a v + b Ω v."""
    return a * force - b * perp(force)


class Loads:
    """The generalized forces of gravity and of the force elements at configurations z.

    Parameters
    ----------
    form : Formulation
    z : numpy.ndarray
        (n, nz) natural coordinates.
    q : numpy.ndarray
        (n, nq) the same configurations as x, y, fi.
    zd : numpy.ndarray, optional
        (n, nz) their rates ż (the dampers' forces); None: at rest.
    t : numpy.ndarray, optional
        (n,) the times of the configurations, for the messages of elements whose force is
        not defined there; None: not known (NaN).
    """

    def __init__(self, form, z: np.ndarray, q: np.ndarray, zd: np.ndarray | None = None,
                 t: np.ndarray | None = None):
        self.form, self.q, self.n = form, q, q.shape[0]
        self.t = np.full(self.n, np.nan) if t is None else np.broadcast_to(
            np.asarray(t, dtype=float), (self.n,))
        self.z = np.asarray(z, dtype=float)
        self.zd = zd
        ns = len(form.frames)
        #: Q (n, ns, 4) on every solid's (p, v); Qp, Qv its views on p and on v
        self.Q = np.zeros((self.n, ns, 4))
        self.Qp, self.Qv = self.Q[:, :, :2], self.Q[:, :, 2:]

    def _value(self, solid: int, local, kind: str) -> np.ndarray:
        """A point or vector of a solid (``Formulation.affine``) at the configurations, (n, 2)."""
        A, c = self.form.affine(solid, local, kind)
        return self.z @ A.T + c

    def point(self, solid: int, local) -> np.ndarray:
        """Where the point ``local`` of the solid is, (n, 2)."""
        return self._value(solid, local, "point")

    def direction(self, solid: int, local) -> np.ndarray:
        """The solid's local vector ``local`` in the global basis, (n, 2)."""
        return self._value(solid, local, "direction")

    def angle(self, solid: int) -> np.ndarray:
        """The solid's angle fi, (n,)."""
        return self.q[:, column(solid, 2)]

    def point_rate(self, solid: int, local) -> np.ndarray:
        """The velocity of the point ``local`` of the solid, (n, 2) (zero at rest)."""
        if self.zd is None:
            return np.zeros((self.n, 2))
        return self.zd @ self.form.affine(solid, local)[0].T

    def angle_rate(self, solid: int) -> np.ndarray:
        """The solid's angular velocity, v × v̇ / |v|², (n,) (zero at rest)."""
        if self.zd is None:
            return np.zeros(self.n)
        v, vd = self._value(solid, None, "v"), self.zd @ self.form.affine(solid, None, "v")[0].T
        return (v[:, 0] * vd[:, 1] - v[:, 1] * vd[:, 0]) / np.sum(v * v, axis=1)

    def force(self, solid: int, local, force) -> None:
        """A force (n, 2) at the point ``local`` of the solid: (F, a F − b Ω F) on (p, v)."""
        a, b = _lever(self.form.frames[solid], local)
        force = np.asarray(force, dtype=float)
        self.Qp[:, solid] += force
        self.Qv[:, solid] += _on_v(a, b, force)

    def moment(self, solid: int, moment) -> None:
        """A moment (n,) on the solid: M Ω v / |v|² on v."""
        v = self._value(solid, None, "v")
        self.Qv[:, solid] += np.asarray(moment, dtype=float)[:, None] * perp(v) / \
            np.sum(v * v, axis=1, keepdims=True)

    def gravity(self, g: float) -> None:
        """(0, −m g) at every solid's centre of mass: on (p, v) the same (F, a F − b Ω F) at
        every step (``force``'s sums), made for all solids at once and added in one
        operation."""
        solids, levers, weights = [], [], []
        for i, s in enumerate(self.form.mech.solids):
            if float(s.mass) and g:
                solids.append(i)
                levers.append(_lever(self.form.frames[i], (float(s.cog[0]), float(s.cog[1]))))
                weights.append([0.0, -float(s.mass) * g])
        if solids:                 # consecutive solids: a slice (no per-element indexing)
            (a, b), weight = np.array(levers).T[:, :, None], np.array(weights)
            at = slice(solids[0], solids[-1] + 1) if solids[-1] - solids[0] == len(solids) - 1 \
                else solids
            self.Q[:, at] += np.concatenate([weight, _on_v(a, b, weight)], axis=1)  # (p, v)

    def on_pose(self) -> np.ndarray:
        """Q (n, nq) on x, y, fi of every solid."""
        out = np.zeros_like(self.q)
        for i in range(len(self.form.frames)):
            p, v = self._value(i, None, "p"), self._value(i, None, "v")
            arm = p - self.q[:, pose(i)][:, :2]
            out[:, pose(i)][:, :2] = self.Qp[:, i]
            out[:, column(i, 2)] = (np.sum(self.Qp[:, i] * perp(arm), axis=1)
                                    + np.sum(self.Qv[:, i] * perp(v), axis=1))
        return out


def multipliers(form, t: np.ndarray, z: np.ndarray, q: np.ndarray,
                extra: np.ndarray | None = None) -> np.ndarray:
    """λ (n, m) in pam2exu's row order with Cqᵀ λ = −Q: the static equilibrium of gravity and
    the force elements (no dampers), the forces taken from natural coordinates, plus
    ``extra`` (n, nq) on x, y, fi when given (the equilibrium's anchor springs)."""
    mech = form.mech
    loads = Loads(form, z, q)
    loads.gravity(mech.gravity)
    for el in mech.elements:
        el.natural_loads(loads)
    Q = loads.on_pose() if extra is None else loads.on_pose() + extra
    st = State(t, q)
    J = np.zeros((len(t), mech.n_equations, mech.nq))
    for el, rows in zip(mech.constraints, mech.rows):
        el.constraint(st)[0].rows(J, rows.start)
    return np.stack([np.linalg.lstsq(J[k].T, -Q[k], rcond=1e-12)[0] for k in range(len(t))])

"""Static equilibrium in natural coordinates: the ``equilibrium`` analysis on the natural
backend (``Natural.static_equilibrium``).

With Q(z) the generalized forces of gravity, the torsors and the springs (no dampers) on
the natural coordinates (``inverse.on_coordinates`` of ``loads.Loads``), an equilibrium at
time t is

    Q(z) − Φ_zᵀ λ = 0,    Φ(z, t) = 0,

a stationary point of the potential energy V (Q = −∂V/∂z) on the constraints. The
descent's proximal steps add springs that tie x, y and fi of every moving solid to a
configuration q_s (stiffness k on x and y, k L² on fi: the Exudyn backend's anchor
springs). In the formulation that gives every moving solid an angle coordinate, x, y, fi
are A z + c (``Formulation.pose_forms``), so the springs add −k Aᵀ W g, g = A z + c − q_s,
W = diag(1, 1, L²), to Q. Newton's iteration on these conditions, λ solved anew each time:

    [H    Φ_zᵀ] [Δz]   [Q − k Aᵀ W g]
    [Φ_z  0   ] [λ ] = [−Φ          ],    H = −∂Q/∂z + k Aᵀ W A + Σ λ_i ∂²Φ_i/∂z²,

∂Q/∂z by central differences (all the perturbed configurations in one ``Loads``), the
constraints' curvature exact (``Terms.hessian``); least squares where redundant
constraints make the matrix singular (their λ of least norm). The angles the torsional
springs read are atan2 of each solid's vector (not its angle coordinate), so that Q is the
exact gradient of −V everywhere in z and its differences are the Hessian's.
"""
from __future__ import annotations

import numpy as np

from ...kinematics import ANGLES, PER_SOLID, column
from .inverse import bodies, on_coordinates
from .loads import Loads

#: the central differences' step of ∂Q/∂z: points × the length scale, vectors and angles
#: as they are
STEP = 1e-6
#: Newton's step is cut so that no unit vector or angle coordinate moves by more than this
#: [rad] (every moving solid has an angle coordinate here, so any solid's turn shows in
#: them): the equations are nonlinear in the turns, and a longer one throws the iteration
#: far from the answer; a translation is not cut (a free solid falling under its anchor
#: springs is one step)
LONGEST_TURN = 0.5
#: a step at most this (in the weights of ``Natural.weights``) that no longer halves is
#: round-off: the iteration has converged as far as the forces' round-off lets it
ROUNDOFF_STEP = 1e-10
#: an answer must balance to this, relative: |Φ| against the size of its terms, the loads
#: the constraints do not balance (Q − Φ_zᵀ λ, λ of least squares) against the loads
BALANCED = 1e-9


class Statics:
    """The equilibrium conditions of a formulation at one time, and Newton's iteration on them.

    Parameters
    ----------
    form : Formulation
        Made with ``all_angles`` (x, y, fi of every moving solid linear in z).
    mech : Mechanism
    t : float
        The time [s] (the actuators hold their laws' values there).
    start : numpy.ndarray
        (nq,) q_s: where the springs tie the solids, and the turn of the angles.
    stiffness : float
        k [N/m] of the springs (0: none).
    """

    def __init__(self, form, mech, t: float, start: np.ndarray, stiffness: float):
        self.form, self.mech, self.terms = form, mech, form.terms
        self.t = np.array([float(t)])
        self.start, self.k = np.asarray(start, dtype=float), float(stiffness)
        self.K = form.pose_forms()               # (x, y, cos, sin) per solid = K [z; 1]
        self.A, self.target, self.weight = pose_distance(form, mech, self.start)
        # gravity acts at fixed points of the solids (a, b constant): its Q is constant
        weight = Loads(form, np.zeros((1, form.nz)), np.zeros((1, mech.nq)))
        weight.gravity(mech.gravity)
        self.bodies = bodies(form)
        self.weight_forces = on_coordinates(self.bodies, weight.Q)[0]

    def angles(self, z: np.ndarray) -> np.ndarray:
        """fi (n, solids) of configurations z (n, nz): atan2 of each solid's vector, in the
        turn nearest the start's."""
        pose = z @ self.K[:, :-1].T + self.K[:, -1]
        fi = np.arctan2(pose[:, 3::4], pose[:, 2::4])
        ref = self.start[ANGLES]
        return fi + 2 * np.pi * np.rint((ref - fi) / (2 * np.pi))

    def forces(self, z: np.ndarray) -> np.ndarray:
        """Q (n, nz) of gravity, the torsors and the springs (at rest) at configurations z."""
        z = np.atleast_2d(z)
        pose = z @ self.K[:, :-1].T + self.K[:, -1]
        q = np.empty((len(z), self.mech.nq))
        solids = np.arange(len(self.mech.solids))
        q[:, column(solids, 0)], q[:, column(solids, 1)] = pose[:, 0::4], pose[:, 1::4]
        q[:, ANGLES] = self.angles(z)
        loads = Loads(self.form, z, q, t=self.t[0])
        for el in self.mech.elements:
            el.natural_loads(loads)
        return self.weight_forces + on_coordinates(self.bodies, loads.Q)

    def balance(self, z: np.ndarray, h: np.ndarray | None = None):
        """Q − k Aᵀ W g (nz,): the loads and the springs on z; with steps h (nz,), also
        their Jacobian −H_loads = ∂Q/∂z − k Aᵀ W A by central differences (one ``Loads``
        for all the configurations)."""
        zs = z[None] if h is None else np.concatenate([z[None], z + np.diag(h), z - np.diag(h)])
        Q = self.forces(zs)
        out = Q[0]
        if self.k:
            gap = self.A @ np.r_[z, 1.0] - self.target
            out = out - self.k * self.A[:, :-1].T @ (self.weight * gap)
        if h is None:
            return out
        n = len(z)
        dQ = ((Q[1:n + 1] - Q[n + 1:]) / (2 * h[:, None])).T
        return out, dQ - self.k * self.A[:, :-1].T @ (self.weight[:, None] * self.A[:, :-1])

    def solve(self, z: np.ndarray, w: np.ndarray, tolerance: float, iterations: int):
        """(z, λ, iterations, converged): Newton's iteration (module doc) from z, each step
        cut to ``LONGEST_TURN``, until the step (weighted by ``w``) is at most
        ``tolerance``, or at round-off, in at most ``iterations``; a step that is not cut
        and is longer than the last one not cut stops it (diverging). A step within the
        tolerance is not taken: a start that already is an equilibrium is kept as it is."""
        terms, nz, m = self.terms, self.terms.nz, self.terms.m
        h = STEP / w
        turning = np.array([c.kind != "point" for c in self.form.coordinates])
        J = terms.dense(terms.jacobian(z[None]))[0]
        lam = np.linalg.lstsq(J.T, self.balance(z), rcond=1e-12)[0]
        last = np.inf
        for iteration in range(1, iterations + 1):
            J = terms.dense(terms.jacobian(z[None]))[0]
            force, dforce = self.balance(z, h)
            kkt = np.block([[terms.hessian(z, lam) - dforce, J.T], [J, np.zeros((m, m))]])
            rhs = np.r_[force, -terms.residual(self.t, z[None])[0]]
            with np.errstate(all="ignore"):
                x = np.linalg.lstsq(kkt, rhs, rcond=1e-13)[0]
            dz, lam = x[:nz], x[nz:]
            step = float(np.max(np.abs(dz) * w, initial=0.0))
            if not np.isfinite(step):
                return z, lam, iteration, False
            if step <= tolerance:
                return z, lam, iteration, self.balanced(z, J)
            if step <= ROUNDOFF_STEP and step > 0.5 * last:
                return z + dz, lam, iteration, self.balanced(z + dz)
            if step > last:                   # moving away again: diverging
                return z, lam, iteration, False
            turn = float(np.max(np.abs(dz[turning]), initial=0.0))
            z = z + dz * min(1.0, LONGEST_TURN / turn) if turn else z + dz
            if turn <= LONGEST_TURN:
                last = step
        return z, lam, iterations, False


    def balanced(self, z: np.ndarray, J: np.ndarray | None = None) -> bool:
        """Whether z is an answer (``BALANCED``): Newton's step also stops where the
        equations are singular (a unit vector off its length, measured)."""
        terms = self.terms
        if J is None:
            J = terms.dense(terms.jacobian(z[None]))[0]
        phi = np.abs(terms.residual(self.t, z[None])[0])
        size = terms.magnitude(self.t, z[None])[0]
        force = self.balance(z)
        lam = np.linalg.lstsq(J.T, force, rcond=1e-12)[0]
        left = np.max(np.abs(force - J.T @ lam), initial=0.0)
        return bool(np.all(phi <= BALANCED * size)
                    and left <= BALANCED * max(np.max(np.abs(force), initial=0.0),
                                               np.max(np.abs(J.T @ lam), initial=0.0)))


def pose_distance(form, mech, target_q: np.ndarray):
    """(A (r, nz + 1), target (r,), weight (r,)): x, y, fi of every moving solid as A [z; 1]
    in a formulation with every angle (``all_angles``), their values in ``target_q``, and
    the weights 1, 1, L² of ½ Σ weight (A [z; 1] − target)², the distance of x, y [m] and
    fi × L to them."""
    K = form.pose_forms()
    L2 = mech.scale() ** 2
    unit = np.eye(form.nz + 1)
    rows, target, weight = [], [], []
    for i, f in enumerate(form.frames):
        if i in form.grounds:
            continue
        rows += [K[4 * i], K[4 * i + 1], unit[f.angle]]
        target += [target_q[column(i, k)] for k in range(PER_SOLID)]
        weight += [1.0, 1.0, L2]
    return np.array(rows).reshape(-1, form.nz + 1), np.array(target), np.array(weight)

"""Where the driver meets a singular position of the mechanism (``pam2exu classify``): the
square constraint Jacobian Cq (actuators included) loses rank.

Two kinds, told apart by the path of positions through them:

- a *dead point* (a fold: the path turns back in time, no position exists beyond it: the
  driver can go no further, e.g. a rocker-driven crank-rocker with its crank and coupler in
  line). Located by Newton on the extended system of Moore and Spence,
  C(q, t) = 0, Cq(q, t) v = 0, v₀ · v = 1, for (q, t, v): regular at a simple fold, so t is
  found to round-off;
- a *change point* (the path goes on through it, the sign of det Cq changes, e.g. a
  change-point four-bar with its links in line): where the branches cross, [Cq C_t] loses
  rank too; located by Gauss–Newton on C = 0, Cqᵀ w = 0, C_tᵀ w = 0, w₀ · w = 1 for
  (q, t, w), to round-off; failing that, the root of det Cq(q(t), t) along the path by
  Brent's method (the positions there are ill-conditioned: about √ε in time).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..kinematics import State
from .native import equations

#: Newton's iterations in ``fold`` and ``position``
ITERATIONS = 40
#: the time tolerance of the located points [s]
TIME_TOL = 1e-12
#: the finite-difference step of the second derivatives in ``fold`` (times the scale)
STEP = 1e-6


@dataclass(frozen=True)
class Singular:
    """A singular position met at time ``t``: ``kind`` "dead point" or "change point", its
    coordinates ``q`` and the motion ``v`` the constraints allow there (Cq v = 0)."""

    kind: str
    t: float
    q: np.ndarray
    v: np.ndarray


def _jacobian(mech, t: float, q: np.ndarray):
    """(C, Cq, ∂C/∂t) at one configuration."""
    eq = equations(mech, State([t], q[None, :]))
    return eq.residual[0], eq.jacobian[0], eq.c_t[0]


def _stencil(mech, q: np.ndarray, t: float, h: float):
    """The equations at (q, t), then at q ± h eᵢ for every coordinate i, then at t ± h: the
    states ``_central`` differences."""
    nq = len(q)
    ts = np.concatenate([[t], np.full(2 * nq, t), [t + h, t - h]])
    qs = np.repeat(q[None], 2 * nq + 3, axis=0)
    qs[1:nq + 1] += h * np.eye(nq)
    qs[nq + 1:2 * nq + 1] -= h * np.eye(nq)
    return equations(mech, State(ts, qs))


def _central(f: np.ndarray, nq: int, h: float):
    """(∂f/∂q, ∂f/∂t) = ((f(q + h eᵢ) − f(q − h eᵢ)) / 2h, (f(t + h) − f(t − h)) / 2h) from f
    at the states of ``_stencil`` (first axis); ∂f/∂q with q along its last axis."""
    return ((f[1:nq + 1] - f[nq + 1:2 * nq + 1]) / (2 * h)).T, (f[-2] - f[-1]) / (2 * h)


def null_motion(jac: np.ndarray) -> np.ndarray:
    """The unit right singular vector of Cq's smallest singular value: v with Cq v ≈ 0."""
    return np.linalg.svd(jac)[2][-1]


def fold(mech, t0: float, q0: np.ndarray, scale: float) -> Singular | None:
    """The dead point near (t0, q0): Newton on C = 0, Cq v = 0, v₀ · v = 1 (v₀ the motion
    Cq nearly allows at q0); None when it does not converge. ∂(Cq v)/∂(q, t) by central
    differences, step ``STEP`` · ``scale`` (the residuals stay exact, so the point does)."""
    nq = mech.nq
    v0 = null_motion(_jacobian(mech, t0, q0)[1])
    h = STEP * scale

    def system(x):
        q, t, v = x[:nq], x[nq], x[nq + 1:]
        eq = _stencil(mech, q, t, h)
        C, J, Ct = eq.residual[0], eq.jacobian[0], eq.c_t[0]
        d_q, d_t = _central(eq.jacobian @ v, nq, h)            # of Cq v
        m = len(C)
        F = np.concatenate([C, J @ v, [v0 @ v - 1.0]])
        A = np.zeros((2 * m + 1, 2 * nq + 1))
        A[:m, :nq], A[:m, nq] = J, Ct
        A[m:2 * m, :nq], A[m:2 * m, nq], A[m:2 * m, nq + 1:] = d_q, d_t, J
        A[-1, nq + 1:] = v0
        return F, A

    x = _converged(system, np.concatenate([q0, [t0], v0]), nq, scale)
    if x is None:
        return None
    v = x[nq + 1:]
    return Singular("dead point", float(x[nq]), x[:nq], v / np.linalg.norm(v))


def branch_point(mech, t0: float, q0: np.ndarray, scale: float) -> Singular | None:
    """The change point near (t0, q0): Gauss–Newton on C = 0, Cqᵀ w = 0, C_tᵀ w = 0,
    w₀ · w = 1 (w₀ the combination of equations Cq nearly loses at q0: where the branches
    cross, [Cq C_t] loses rank), consistent there and regular at a simple crossing; None
    when it does not converge. Derivatives by central differences, as ``fold``."""
    nq, m = mech.nq, mech.n_equations
    w0 = np.linalg.svd(_jacobian(mech, t0, q0)[1])[0][:, -1]
    h = STEP * scale

    def system(x):
        q, t, w = x[:nq], x[nq], x[nq + 1:]
        eq = _stencil(mech, q, t, h)
        C, J, Ct = eq.residual[0], eq.jacobian[0], eq.c_t[0]
        Jw = np.einsum("nmq,m->nq", eq.jacobian, w)           # Cqᵀ w at each state
        Ctw = eq.c_t @ w
        F = np.concatenate([C, J.T @ w, [Ct @ w, w0 @ w - 1.0]])
        A = np.zeros((m + nq + 2, nq + 1 + m))
        A[:m, :nq], A[:m, nq] = J, Ct
        A[m:m + nq, :nq], A[m:m + nq, nq] = _central(Jw, nq, h)
        A[m:m + nq, nq + 1:] = J.T
        A[m + nq, :nq], A[m + nq, nq] = _central(Ctw, nq, h)
        A[m + nq, nq + 1:] = Ct
        A[-1, nq + 1:] = w0
        return F, A

    x = _converged(system, np.concatenate([q0, [t0], w0]), nq, scale)
    if x is None:
        return None
    q = x[:nq]
    return Singular("change point", float(x[nq]), q,
                    null_motion(_jacobian(mech, float(x[nq]), q)[1]))


def _converged(system, x: np.ndarray, nq: int, scale: float) -> np.ndarray | None:
    """x (q, t, then the extra unknowns) after Gauss–Newton steps A s = −F (least squares,
    (F, A) = ``system(x)``) until the step is below TIME_TOL in t and 1e-12 · scale in q;
    None when x stops being finite or ITERATIONS steps do not get there."""
    for _ in range(ITERATIONS):
        F, A = system(x)
        step = np.linalg.lstsq(A, -F, rcond=None)[0]
        x = x + step
        if not np.all(np.isfinite(x)):
            return None
        if abs(step[nq]) < TIME_TOL and np.max(np.abs(step[:nq])) < 1e-12 * scale:
            return x
    return None


def position(mech, t: float, q: np.ndarray, scale: float) -> np.ndarray | None:
    """q with C(q, t) = 0 by Newton from q (least squares with redundant equations); None
    when it does not converge."""
    q = q.copy()
    for _ in range(ITERATIONS):
        C, J, _ = _jacobian(mech, t, q)
        step = np.linalg.lstsq(J, -C, rcond=None)[0]
        q += step
        if np.max(np.abs(step)) < 1e-13 * scale:
            return q
    return None


def sign_change(mech, t0: float, t1: float, q0: np.ndarray, scale: float) -> Singular | None:
    """The change point between t0 and t1 where det Cq(q(t), t) changes sign (Brent's
    method; q(t) by Newton from q0, the position at t0); None if Newton fails."""
    def det(t):
        q = position(mech, t, q0, scale)
        if q is None:
            raise ArithmeticError
        return float(np.linalg.det(_jacobian(mech, t, q)[1]))
    from scipy.optimize import brentq              # (imported when a dead point is bracketed)
    try:
        t = brentq(det, t0, t1, xtol=TIME_TOL, rtol=4 * np.finfo(float).eps)
    except (ArithmeticError, ValueError):
        return None
    q = position(mech, t, q0, scale)
    if q is None:
        return None
    return Singular("change point", float(t), q, null_motion(_jacobian(mech, t, q)[1]))


def determinants(mech, t: np.ndarray, q: np.ndarray) -> np.ndarray:
    """det Cq at each row (a square Cq: no redundant equations)."""
    return np.linalg.det(equations(mech, State(t, q)).jacobian)


def singular_points(mech, t: np.ndarray, q: np.ndarray, solved: int,
                    scale: float) -> list[Singular]:
    """The change points between the solved rows (det Cq changes sign) and, when the run
    stops before its end (``solved`` < len(t)), the dead point it stops at; in time order.
    A stop that is no fold is left out (the run's own message says why it stops)."""
    found = []
    nq = mech.nq
    if mech.n_equations == nq and solved > 1:
        d = determinants(mech, t[:solved], q[:solved])
        for k in np.nonzero(np.sign(d[:-1]) * np.sign(d[1:]) < 0)[0]:
            point = branch_point(mech, float(t[k]), q[k], scale)
            if point is None or not t[k] <= point.t <= t[k + 1]:
                point = sign_change(mech, float(t[k]), float(t[k + 1]), q[k], scale)
            if point is not None:
                found.append(point)
    if 0 < solved < len(t):
        point = stop(mech, float(t[solved - 1]), float(t[solved]), q[solved - 1], scale)
        if point is not None:
            found.append(point)
    return sorted(found, key=lambda p: p.t)


#: bisections of the last step in ``stop``
BISECTIONS = 20


def stop(mech, t0: float, t1: float, q0: np.ndarray, scale: float) -> Singular | None:
    """The dead point between t0 (solved: q0) and t1 (not solved): ``fold`` from the last
    position solved, which moves closer by bisection (Newton from the one before) until the
    fold converges within [t0, t1]; None when it never does (the stop is no fold)."""
    for _ in range(BISECTIONS):
        point = fold(mech, t0, q0, scale)
        if point is not None and t0 - 1e-9 <= point.t <= t1 + 1e-9:
            return point
        middle = 0.5 * (t0 + t1)
        q = position(mech, middle, q0, scale)
        if q is not None:
            t0, q0 = middle, q
        else:
            t1 = middle
    return None

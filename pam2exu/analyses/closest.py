"""The configuration closest to closing, behind the diagnosis of a failure: q* = argmin
|C(q, t)|² by least squares, its work bounded (not its time), so that a diagnosis says the
same on a busy machine as on an idle one."""
from __future__ import annotations

import numpy as np

from ..kinematics import State
from . import native


#: the work the least-squares search of a failure's diagnosis may do, in residuals and
#: Jacobians asked, each counting the mechanism's equations (a Jacobian at the point whose
#: residual was just asked comes from the same evaluation): a bound on work, not on time,
#: so that a diagnosis says the same on a busy machine as on an idle one (all_elements' 36
#: equations: 555 asked)
DIAGNOSIS_WORK = 20_000


class _Enough(Exception):
    """The diagnosis' search has done its work (``Budget``)."""


class Budget:
    """Evaluations a diagnosis may still make: ``DIAGNOSIS_WORK`` (times ``share``) over the
    mechanism's equations, spent one by one; ``_Enough`` when none is left."""

    def __init__(self, mech, share: float = 1.0):
        self.left = int(share * DIAGNOSIS_WORK) // max(1, mech.n_equations)

    def spend(self) -> None:
        if self.left <= 0:
            raise _Enough
        self.left -= 1


def closest_violation(mech, t: float, q_start: np.ndarray, keep: np.ndarray | None = None,
                      budget: Budget | None = None,
                      tol: float = 1e-15) -> tuple[np.ndarray, np.ndarray, bool]:
    """(C(q*, t), q*, converged) at q* = argmin |C(q, t)|² from q_start (diagnosis only):
    of the equations ``keep`` (a mask; C is of all), to the relative tolerance ``tol``;
    ``converged`` False when the search ran out of evaluations (``budget``, default one
    ``Budget`` of its own).

    The elements still violated at q* are those that cannot close at time t. Where
    C(q*) ≠ 0, Cqᵀ C = 0 there: the constraint Jacobian is singular at q*. The search
    stops when its budget is spent with the best configuration found (a mechanism that
    cannot close leaves a flat valley it would crawl along).
    """
    from scipy.optimize import least_squares

    # actuators and fixed links can always hold (they only set a coordinate): weight them
    # so that what is left shows in the joints that cannot close
    weight = np.ones(mech.n_equations) if keep is None else np.where(keep, 1.0, 0.0)
    for el, rows in zip(mech.constraints, mech.rows):
        weight[rows] *= 1e3 if el.drives or el.grounds else 1.0
    budget = Budget(mech) if budget is None else budget
    best = [np.inf, q_start, None]
    last: list = [None, None]          # the last q evaluated and its C, Cq (``evaluated``)

    def evaluated(q):
        """C and Cq at q, from one evaluation: least squares asks the Jacobian at the
        point whose residual it has just asked (the same bits as evaluating C alone)."""
        if last[0] is None or not np.array_equal(q, last[0]):   # (within np.errstate)
            last[:] = q.copy(), native.equations(mech, State([t], q[None]))
        return last[1]

    def fun(q):
        budget.spend()                 # (the budget counts residuals and Jacobians asked)
        with np.errstate(all="ignore"):
            f = weight * evaluated(q).residual[0]
        size = float(np.dot(f, f))
        if size < best[0]:
            best[:] = size, q.copy(), f
        return f

    def jac(q):
        budget.spend()
        with np.errstate(all="ignore"):
            return weight[:, None] * evaluated(q).jacobian[0]

    try:
        sol = least_squares(fun, q_start, jac=jac, method="lm" if mech.n_equations >= mech.nq
                            else "trf", max_nfev=200 * mech.nq, xtol=tol, ftol=tol, gtol=tol)
        found, converged = sol.x, sol.status > 0
    except (_Enough, ValueError):       # out of work, or a residual that is not finite
        if best[2] is None:
            return np.full(mech.n_equations, np.inf), q_start, False
        found, converged = best[1], False
    with np.errstate(all="ignore"):
        return native.residuals(mech, np.array([t]), found[None])[0], found, converged

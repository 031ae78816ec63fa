"""First-order sensitivities ∂y/∂p of an analysis' output columns to one number p of the
model, from the solved equations themselves (the first-order method of a study,
``studies/linear.py``; docs/studies.md).

At every output row, with the positions q of the nominal run:

- positions: C(q, p, t) = 0 gives Cq ∂q/∂p = −∂C/∂p (the implicit-function theorem);
- velocities, accelerations: Cq q̇ = −C_t and Cq q̈ = γ, differentiated the same way;
- forces: Cqᵀ λ = Q_inertia − Q_applied (or −Q_applied, quasi-static), likewise;
- outputs: y = g(q, q̇, q̈, λ, p).

The derivatives of the right-hand sides with respect to p and to q along ∂q/∂p are taken
by the complex step (``complex_step``): the model with p + ih (a copy made by the caller),
the positions q + ih ∂q/∂p, then the native velocity, acceleration and force passes and
the output columns evaluated in complex arithmetic, each linear solve of them analytic
(LU, or normal equations with plain transposes where the constraints are redundant), so
that Im y / h = ∂y/∂p exactly to rounding, with no difference of runs taken.
"""
from __future__ import annotations

import warnings
from dataclasses import replace
from typing import NamedTuple

import numpy as np

from ..elements import ACCELERATION, FORCE, VELOCITY
from ..errors import SolverError
from ..kinematics import State
from ..model.mechanism import Mechanism
from . import force_pass, native
from .job import Job, column_values

#: the complex step h: p + ih (no difference is taken, so no round-off grows as h → 0)
STEP = 1e-30
#: |Cq ∂q/∂p + ∂C/∂p| / |∂C/∂p| above which a parameter cannot vary in an over-constrained
#: mechanism without breaking its assembly (it then needs clearance, not a tolerance)
CONSISTENT = 1e-8


def analytic_solve(J: np.ndarray, b: np.ndarray, redundant: bool) -> np.ndarray:
    """x with J x = b per step (J (n, m, k), b (n, m)): LU, or x = (JᵀJ)⁻¹ Jᵀ b with plain
    transposes when m > k (redundant, consistent): analytic in complex arithmetic."""
    if J.shape[2] == 0:
        return np.zeros(b.shape[:1] + (0,), dtype=np.result_type(J, b))
    if redundant or J.shape[1] != J.shape[2]:
        Jt = np.swapaxes(J, 1, 2)
        return np.linalg.solve(Jt @ J, np.einsum("nkm,nm->nk", Jt, b)[..., None])[..., 0]
    return np.linalg.solve(J, b[..., None])[..., 0]


class Nominal(NamedTuple):
    """The nominal run at its output rows, and what every parameter's derivative reuses
    there: the moving rows and columns of Cq (``native.moving``) and Cq itself, real."""

    t: np.ndarray
    q: np.ndarray
    redundant: bool
    rows: np.ndarray
    cols: np.ndarray
    jacobian: np.ndarray


def nominal(job: Job, t, q, redundant: bool) -> Nominal:
    """``Nominal`` of the rows (t, q) of a run of ``job`` (Cq evaluated once, for every
    parameter)."""
    rows, cols = native.moving(job.mech)
    J = native.equations(job.mech, State(t, q)).jacobian[:, rows[:, None], cols]
    return Nominal(np.asarray(t), np.asarray(q), redundant, rows, cols, J)


def position_derivative(at: Nominal, mech_p, step: float = STEP,
                        parameter: str = "the parameter") -> np.ndarray:
    """∂q/∂p (n, nq) from Cq ∂q/∂p = −∂C/∂p at the nominal positions; ``mech_p``: the
    mechanism with p + i·step. SolverError naming the parameter when an over-constrained
    mechanism cannot follow it (its assembly would break)."""
    t, q, rows, cols, J = at.t, at.q, at.rows, at.cols, at.jacobian
    dq = np.zeros_like(q)
    if not len(cols):
        return dq
    dC = native.equations(mech_p, State(t, q.astype(complex)), jacobian=False).residual
    dC = dC.imag[:, rows] / step
    dq[:, cols] = -analytic_solve(J, dC, at.redundant)
    if at.redundant:
        left = np.einsum("nmk,nk->nm", J, dq[:, cols]) + dC
        scale = np.max(np.abs(dC), axis=1) + 1e-300
        worst = np.max(np.abs(left), axis=1) / scale
        if np.any(worst > CONSISTENT):
            k = int(np.argmax(worst))
            raise SolverError(
                f"{parameter} cannot vary in this over-constrained mechanism: the "
                f"constraints cannot all follow it (relative residual {worst[k]:.2g} at "
                f"t = {t[k]:.6g} s); its variants would not assemble without clearance. "
                "Study it with analysis = \"clearance\", or vary a dimension the "
                "redundant constraints do not fix.",
                time=float(t[k]))
    return dq


def derivatives(job: Job, at: Nominal, model_p, step: float = STEP,
                parameter: str = "the parameter") -> dict[str, np.ndarray]:
    """∂y/∂p of every column of ``job.columns`` at the output rows of a nominal run of
    ``job``; ``model_p``: a copy of the model with p + i·step written in.

    Parameters
    ----------
    job : Job
        The nominal analysis (its mechanism, columns, levels and type).
    at : Nominal
        The nominal run's rows (``nominal``: times, positions, whether the mechanism has
        redundant constraints, its Jacobian there).
    model_p : Model
        The model with the parameter at p + i·step (not validated: complex numbers).
    step : float
        The complex step h.
    parameter : str
        The parameter's name, for messages.

    Returns
    -------
    dict of str to numpy.ndarray
        Column → ∂y/∂p (n,), in the column's unit per the parameter's unit.
    """
    with warnings.catch_warnings():      # an imaginary part dropped is a fault, never a 0
        warnings.simplefilter("error", np.exceptions.ComplexWarning)
        return _derivatives(job, at, model_p, step, parameter)


def _derivatives(job: Job, at: Nominal, model_p, step: float, parameter: str):
    """``derivatives`` (a complex number cast to a float raises)."""
    mech_p = Mechanism(model_p)
    t, rows, cols, redundant = at.t, at.rows, at.cols, at.redundant
    qc = at.q + 1j * step * position_derivative(at, mech_p, step, parameter)
    qdc = qddc = None
    if VELOCITY in job.levels:
        eq = native.equations(mech_p, State(t, qc))
        J = eq.jacobian[:, rows[:, None], cols]
        qdc = np.zeros_like(qc)
        qdc[:, cols] = analytic_solve(J, -eq.c_t[:, rows], redundant)
        if ACCELERATION in job.levels:
            gamma = native.equations(mech_p, State(t, qc, qdc, jacobians=False),
                                     jacobian=False).gamma
            qddc = np.zeros_like(qc)
            qddc[:, cols] = analytic_solve(J, gamma[:, rows], redundant)
    extra = {}
    if FORCE in job.levels:
        inertia = ACCELERATION in job.analysis_type.levels
        extra, _ = force_pass.over_time(mech_p, t, qc, redundant,
                                        qdc if inertia else None, qddc if inertia else None)
    values, _ = column_values(replace(job, mech=mech_p), t, qc, qdc, qddc, extra)
    return {c: np.imag(values[c]) / step for c in job.columns}

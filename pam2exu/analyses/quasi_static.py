"""Quasi-static analysis: positions by the backend, static equilibrium natively,
cross-checked against the backend's static solver with the forces."""
from __future__ import annotations

import numpy as np

from ..elements import FORCE
from ..errors import TranslationError
from ..kinematics import State
from . import force_pass, native
from .job import Job, check_mobility, collect
from .kinetostatic import reactions
from .branch import motion
from .positions import positions

#: the backend's multipliers must satisfy the native equilibrium to this, relative to the forces
EQUILIBRIUM_TOLERANCE = 1e-9
#: the steps at which the backend's static solver, with the forces, checks the native reactions
CHECKED_STEPS = 3


def quasi_static(job: Job):
    """x, y, fi, f(t), ro, fi_rel, every reaction, spring and actuator force; no rates.

    Contract: every degree of freedom is driven, so the configurations do not depend on the
    forces: they come from the backend's solver on the constraints, the branch followed
    on the rates (``branch.motion``, as kinematic: its rates are not reported), and
    the reactions from the equilibrium Cqᵀ λ = −Q_applied at every step (gravity,
    torsors and springs, no damper terms; ``kinetostatic.reactions`` at rest: the backend's
    inverse dynamics where it gives reactions, else ``force_pass.over_time``). The backend's
    static solver with the masses and force elements in the model checks them at
    ``CHECKED_STEPS`` steps (its multipliers λ, f + Cqᵀ λ = 0, must satisfy the native
    equilibrium). With redundant constraints λ is not unique: the reactions are the
    minimum-norm solution and are not checked against the backend's. A singular
    (dead-point) position, where the reactions are not defined, is an error.
    """
    mob = check_mobility(job, job.mech.initial_q())
    redundant = mob.redundant > 0
    if FORCE not in job.levels:
        return collect(job, positions(job, redundant))
    # the branch followed as kinematic follows it; a singular position (exact, or a change
    # point the backend solved to round-off) is an error: the reactions are undefined there
    q, _, _ = motion(job, redundant, accelerations=False, singular_ok=False)
    job.stage = "computing the reactions (static equilibrium)"
    out, _, source = reactions(job, q, redundant=redundant)
    if redundant:
        job.info["reactions_from"] = ("native minimum-norm solve" if source is None
                                      else f"{source}, minimum norm")
    else:
        rows = checked_steps(len(job.times))
        label = job.backend.label
        job.stage = f"checking the reactions with {job.backend.solver_name}"
        worst = backend_equilibrium_error(job, q, rows)
        job.info["reactions_from"] = (f"{source or 'native solve'}, {label}'s multipliers "
                                      f"agree at {len(rows)} steps")
        job.info["equilibrium_error"] = worst
        if worst > EQUILIBRIUM_TOLERANCE:
            raise TranslationError(
                f"internal error: {label}'s multipliers leave a relative equilibrium error of "
                f"{worst:.2g} against pam2exu's own forces (tolerance "
                f"{EQUILIBRIUM_TOLERANCE:g}): the translation of a force element for {label} "
                "is wrong. Please report it with the model file.")
    return collect(job, q, extra=out)


def checked_steps(n: int) -> list[int]:
    """The steps the backend's multipliers are checked at: the first, the last and evenly
    between."""
    return sorted({int(k) for k in np.linspace(0, n - 1, min(n, CHECKED_STEPS)).round()})


def backend_equilibrium_error(job: Job, q: np.ndarray, rows: list[int]) -> float:
    """Largest ``equilibrium_error`` of the backend's multipliers at the given steps.

    At each step, the backend's static solver with the masses and force elements (no
    dampers) starts from the configuration found and gives its multipliers; pam2exu's own
    forces and Jacobian are then evaluated at all those configurations at once.
    """
    mech = job.mech
    found_q, found_lam = [], []
    for k in rows:
        found = job.backend.solve_positions(mech, job.times[k:k + 1], q[k], job.solver,
                                            forces=True)
        if not found.solved:
            raise TranslationError(
                f"internal error: {job.backend.solver_name} with the forces did not converge "
                f"at t = {job.times[k]:.6g} s from the configuration found without them: the "
                f"translation is wrong. Please report it with the model file. "
                f"{job.backend.label} said: {found.error}")
        found_q.append(found.q[0])
        found_lam.append(found.multipliers[0])
    st = State(job.times[rows], np.array(found_q))
    applied = force_pass.applied_forces(mech, st, damping=False)
    jacobian = native.equations(mech, st).jacobian
    return equilibrium_error(mech, st, np.array(found_lam), applied.force, jacobian)


def equilibrium_error(mech, st, lam, applied, jacobian) -> float:
    """max over the steps of |Cqᵀ λ + Q_applied| relative to the step's largest force
    (moments divided by the length scale; 0 at a step without forces)."""
    per_length = np.tile([1.0, 1.0, 1.0 / mech.scale()], len(mech.solids))
    residual = force_pass.equilibrium_residual(mech, st, lam, -applied, jacobian) * per_length
    size = np.maximum(
        np.max(np.abs(applied * per_length), axis=1, initial=0.0),
        np.max(np.abs(np.einsum("nmq,nm->nq", jacobian, lam) * per_length), axis=1,
               initial=0.0))
    error = np.max(np.abs(residual), axis=1, initial=0.0)
    return float(np.max(np.divide(error, size, out=np.zeros_like(error), where=size > 0),
                        initial=0.0))

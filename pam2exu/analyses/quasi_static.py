"""Quasi-static analysis: positions and static equilibrium, by Exudyn's static solver."""
from __future__ import annotations

import numpy as np

from ..elements import FORCE
from ..errors import TranslationError
from ..kinematics import State
from . import forces, native
from .common import Job, check_mobility, collect, positions, velocities

#: Exudyn's multipliers must satisfy the native equilibrium to this, relative to the forces
EQUILIBRIUM_TOLERANCE = 1e-9


def quasi_static(job: Job):
    """x, y, fi, f(t), ro, fi_rel, every reaction, spring and actuator force; no rates.

    Contract: Exudyn's static solver, with the masses, gravity, torsors and springs (no
    damper terms) in the model, gives at each time the configuration and the Lagrange
    multipliers λ (f + Cqᵀ λ = 0); the reactions are read from λ (``forces.reactions``).
    The native equilibrium Cqᵀ λ = −Q_applied is checked at every step. With redundant
    constraints λ is not unique: the reactions are the native minimum-norm solution. A
    singular (dead-point) position, where the reactions are not defined, is an error.
    """
    mob = check_mobility(job, job.mech.initial_q(), need_driven=True)
    redundant = mob.redundant > 0
    if FORCE not in job.levels:
        return collect(job, positions(job, redundant))
    q, system = positions(job, redundant, forces=True, check=False)
    velocities(job, q, redundant)      # raises at a singular position: reactions undefined
    mech, t = job.mech, job.times
    order = [i for el in mech.constraints for i in system.ae_rows(el)]
    lam_exudyn = system.multipliers[:, order]
    out: dict[str, np.ndarray] = {}
    worst = 0.0
    for s in native.chunks(mech, len(t)):
        st = State(t[s], q[s])
        applied = forces.applied_forces(mech, st, damping=False)
        jacobian = native.equations(mech, st).jacobian
        if redundant:
            lam = forces.multipliers(mech, st, -applied.force, True, jacobian)
        else:
            lam = lam_exudyn[s]
            worst = max(worst, _equilibrium_error(mech, st, lam, applied.force, jacobian))
        for name, v in {**forces.reactions(mech, st, lam), **applied.outputs}.items():
            out.setdefault(name, np.empty(len(t)))[s] = v
    job.info["reactions_from"] = ("native minimum-norm solve" if redundant
                                  else "Exudyn's multipliers")
    if not redundant:
        job.info["equilibrium_error"] = worst
        if worst > EQUILIBRIUM_TOLERANCE:
            raise TranslationError(
                f"internal error: Exudyn's multipliers leave a relative equilibrium error of "
                f"{worst:.2g} against pam2exu's own forces (tolerance "
                f"{EQUILIBRIUM_TOLERANCE:g}): the Exudyn translation of a force element is "
                "wrong. Please report it with the model file.")
    return collect(job, q, extra=out)


def _equilibrium_error(mech, st, lam, applied, jacobian) -> float:
    """max |Cqᵀ λ + Q_applied| relative to the largest force (moments divided by the length scale)."""
    per_length = np.tile([1.0, 1.0, 1.0 / mech.scale()], len(mech.solids))
    residual = forces.equilibrium_residual(mech, st, lam, -applied, jacobian) * per_length
    size = max(np.max(np.abs(applied * per_length), initial=0.0),
               np.max(np.abs(np.einsum("nmq,nm->nq", jacobian, lam) * per_length), initial=0.0))
    return float(np.max(np.abs(residual), initial=0.0) / size) if size > 0 else 0.0

"""Kinetostatic analysis (inverse dynamics): the kinematic analysis, then every force."""
from __future__ import annotations

import numpy as np

from ..elements import FORCE
from ..kinematics import State
from . import force_pass
from .branch import motion
from ..errors import ConsistencyWarning
from .job import Job, check_mobility, collect, warn


def kinetostatic(job: Job):
    """Everything of kinematic, plus every reaction, spring force and actuator force.

    Contract: positions from the backend's solver, qd and qdd natively (as kinematic);
    then at every step Cqᵀ λ = Q_inertia − Q_applied is solved natively (inertia from the
    mass at G and the inertia about G; gravity, torsors, springs and dampers applied), and
    the reactions are read from λ (``force_pass.reactions``); a backend that
    ``gives_reactions`` gives the elements' wrenches itself from its own inverse dynamics
    (``Backend.reactions``), reported the same way. The power balance is checked.
    """
    mob = check_mobility(job, job.mech.initial_q())
    redundant = mob.redundant > 0
    q, qd, qdd = motion(job, redundant, singular_ok=False)
    extra = inverse_dynamics(job, q, qd, qdd, redundant) if FORCE in job.levels else {}
    return collect(job, q, qd, qdd, extra)


def inverse_dynamics(job: Job, q, qd, qdd, redundant: bool) -> dict[str, np.ndarray]:
    """Reactions, spring and actuator forces at every step, then the power balance check."""
    job.stage = "computing the reactions and actuator forces (inverse dynamics)"
    out, e, who = reactions(job, q, qd, qdd, redundant)
    if who is not None:
        job.info["reactions_from"] = who
    power = force_pass.actuator_power(job.mech, State(job.times, q), out)
    check_power_balance(job, power, e.energy, e.dissipation, e.external)
    return out


def reactions(job: Job, q, qd=None, qdd=None, redundant: bool = False):
    """(every reaction, spring and actuator force at every step, the energies or None, who
    computed them) of the motion q, q̇, q̈, or without rates of the configurations at rest
    (the quasi-static equilibrium Cqᵀ λ = −Q_applied is the inverse dynamics at q̇ = q̈ = 0:
    no inertia, no damper force). A backend that ``gives_reactions`` gives them from its
    own inverse dynamics (who: "<label>'s inverse dynamics", "… at rest"); else, or where
    it does not handle the model, ``force_pass.over_time`` (who: None)."""
    mech, t = job.mech, job.times
    if job.backend.gives_reactions:
        rates = (qd, qdd) if qdd is not None else (np.zeros_like(q),) * 2
        given = job.backend.reactions(mech, t, q, *rates, redundant)
        if given is not None:
            out, e = force_pass.over_time_given(mech, t, q, rates[0], given)
            return out, e, (f"{job.backend.label}'s inverse dynamics"
                             + ("" if qdd is not None else " at rest"))
    out, e = force_pass.over_time(mech, t, q, redundant, qd, qdd)
    return out, e, None


def check_power_balance(job: Job, power, energy, dissipation, external) -> None:
    """Σ actuator power = dE/dt + dissipation − torsor power; warns when it does not hold."""
    balance = force_pass.power_balance(job.mech, job.times, power, energy, dissipation, external)
    if balance is None:
        job.info["power_balance"] = "not checked (fewer than 9 rows: steps < 8)"
        return
    job.info.update(power_balance_error=balance.error,
                    power_balance_tolerance=balance.tolerance,
                    power_balance_steps=balance.checked)
    if not balance.ok:
        text = (f"power balance not met: Σ actuator power differs from d(kinetic + potential "
                f"energy)/dt + damper dissipation − torsor power by up to {balance.error:.3g} W "
                f"(tolerance {balance.tolerance:.3g} W from the finite difference's own "
                f"error). The forces may be wrong; please report it with the model file.")
        warn(job, text, ConsistencyWarning)

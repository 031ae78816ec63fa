"""Kinematic analysis: positions by Exudyn, velocities and accelerations natively."""
from __future__ import annotations

from ..elements import VELOCITY
from .common import Job, check_mobility, collect, positions, velocities


def kinematic(job: Job):
    """x … DDfi of every solid, f(t), Df(t), ro, Dro, fi_rel, Dfi_rel over the interval.

    Contract: every degree of freedom driven (else MobilityError); positions from Exudyn's
    static solver at each time; Cq qd = −C_t and Cq qdd = γ solved natively for all steps.
    """
    mob = check_mobility(job, job.mech.initial_q(), need_driven=True)
    redundant = mob.redundant > 0
    q = positions(job, redundant, check=VELOCITY not in job.levels)
    qd = qdd = None
    if VELOCITY in job.levels:
        qd, qdd = velocities(job, q, redundant)
    return collect(job, q, qd, qdd)

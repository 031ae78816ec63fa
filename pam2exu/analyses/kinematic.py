"""Kinematic analysis: positions by the backend, velocities and accelerations natively."""
from __future__ import annotations

from ..elements import ACCELERATION, VELOCITY
from .branch import motion
from .job import Job, check_mobility, collect
from .positions import positions


def kinematic(job: Job):
    """x … DDfi of every solid, f(t), Df(t), ro, Dro, fi_rel, Dfi_rel over the interval.

    Contract: every degree of freedom driven (else MobilityError); positions from the
    backend's solver at each time; Cq qd = −C_t and Cq qdd = γ solved natively for all steps;
    the motion stays on the branch it starts on (``branch.motion``).
    """
    mob = check_mobility(job, job.mech.initial_q())
    redundant = mob.redundant > 0
    if VELOCITY not in job.levels:
        return collect(job, positions(job, redundant))
    q, qd, qdd = motion(job, redundant, ACCELERATION in job.levels)
    return collect(job, q, qd, qdd)

"""Assembly: the constraints solved at t = 0 by the backend; one row of x, y, fi per solid."""
from __future__ import annotations

from .job import Job, check_mobility, collect
from .positions import GUESS_STIFFNESS, positions


def assembly(job: Job):
    """Solve C(q, 0) = 0 from the initial guess.

    With free degrees of freedom, each coordinate is tied to its initial value by a soft
    spring, so the backend finds the assembled configuration nearest to the guess (the spring
    forces only select among solutions; the constraints are met exactly).
    """
    q0 = job.mech.initial_q()
    mob = check_mobility(job, q0)
    stiffness = GUESS_STIFFNESS if mob.dof > 0 else 0.0
    q = positions(job, redundant=mob.redundant > 0, anchor_stiffness=stiffness)
    return collect(job, q)

"""The self-check after the numerics: pam2exu's constraints hold at the backend's positions
(that no result is NaN or infinite is the last guard of the table, ``job.check_finite``)."""
from __future__ import annotations

import numpy as np

from ..backend import Positions
from ..errors import TranslationError
from . import native, rank
from .failure import position_failure
from .job import Job


#: constraint residual above this (× the length scale) means a wrong translation
RESIDUAL_TOLERANCE = 1e-8
#: the smallest length scale a mechanism has (``Mechanism.scale``) [m]
SMALLEST_SCALE = 1e-3


def check_residual(mech, t, q, job: Job | None = None, res: np.ndarray | None = None) -> None:
    """Self-check: pam2exu's own constraint equations hold at the backend's configuration.

    res: the residual C(q, t) when already computed. Redundant constraints that contradict
    each other from some step on are reported as such (``failure.position_failure``).
    """
    if mech.n_equations == 0:
        return
    if res is None:
        res = native.residuals(mech, t, q)
    worst = float(np.max(np.abs(res)))
    if job is not None:
        job.info["max_residual"] = worst
    # a looser Newton tolerance leaves a larger residual: not a translation error
    tolerance = job.solver.tolerance if job is not None else 0.0
    relative = max(RESIDUAL_TOLERANCE, 100 * tolerance)
    if worst <= relative * SMALLEST_SCALE:       # within it at any length scale
        return
    tol = relative * mech.scale()
    if worst > tol:
        per_step = np.max(np.abs(res), axis=1)
        first = int(np.argmax(per_step > tol))
        if job is not None:
            # redundant constraints whose targets part: the solver (told to ignore the
            # singular Jacobian) can stop on a configuration that violates them; from the
            # start when they tie held solids only, which no backend moves
            before = q[max(first - 1, 0)]
            disagreement, _ = rank.contradiction(mech, float(t[first]), before)
            if disagreement > tol:
                raise position_failure(job, Positions(
                    q, first, "no error (it stopped on a configuration that violates the "
                              "constraints)", before))
        k = int(np.argmax(per_step))
        name, value = native.worst_elements(mech, res[k], 1)[0]
        label = job.backend.label if job is not None else "the backend"
        raise TranslationError(
            f"internal error: at t = {t[k]:.6g} s {label}'s configuration violates pam2exu's "
            f"equations of element {name} by {value:.3g} (tolerance {tol:.1g}): the translation "
            f"of this element for {label} is wrong. Please report it with the model file.")


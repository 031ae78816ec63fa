"""The analyses of PAM; ``ANALYSES`` is the registry from type name to function.

``run`` runs one (``pam2exu.run`` is the same); the warning classes are those the checks
after an analysis issue.
"""
from __future__ import annotations

from ..errors import ModelError, Problem
from .assembly import assembly
from .common import ConditionWarning, ConsistencyWarning, RedundancyWarning, prepare
from .kinematic import kinematic
from .kinetostatic import kinetostatic
from .quasi_static import quasi_static

#: analysis type -> function(Job) -> Results
ANALYSES = {"assembly": assembly, "quasi_static": quasi_static, "kinematic": kinematic,
            "kinetostatic": kinetostatic}


def run(model, analysis=None, t_end=None, steps=None, outputs=None, solver=None):
    """Run an analysis and return its Results.

    ``pam2exu.run`` is this function, with ``t_end``, ``steps``, ``outputs`` and ``solver``
    passed as keywords; its documentation has the details and an example. None keeps the
    model's ``[analysis]`` setting.

    Parameters
    ----------
    model : Model or path
        A model, or the path of a model file.
    analysis : str, optional
        'assembly', 'quasi_static', 'kinematic' or 'kinetostatic' (default: the
        model's [analysis] type).
    t_end : float, optional
        End of the interval [s].
    steps : int, optional
        Number of intervals; results have steps + 1 rows.
    outputs : list of str, optional
        Names or patterns of the columns to compute and keep.
    solver : backend.SolveSettings, optional
        Exudyn solver settings.

    Returns
    -------
    Results
        The chosen columns over time; ``Results.t`` are the times [s].

    Raises
    ------
    ModelError
        The model or a setting has problems, or an ``outputs`` pattern matches nothing.
    MobilityError
        A degree of freedom is not driven (all analyses but assembly).
    SolverError
        Exudyn's solver did not converge, a singular position was reached, or redundant
        constraints contradict each other.
    TranslationError
        A self-check failed (a bug of pam2exu).

    Warns
    -----
    RedundancyWarning, ConditionWarning, ConsistencyWarning
        See each class; the texts are kept in ``Results.warnings`` too.

    Examples
    --------
    >>> from pam2exu.analyses import run
    >>> res = run("examples/four_bar.toml", "quasi_static", steps=20)  # doctest: +SKIP
    >>> len(res)                                                       # doctest: +SKIP
    21
    """
    job = prepare(model, analysis, t_end, steps, outputs, solver)
    if job.analysis not in ANALYSES:
        raise ModelError(Problem("[analysis]", f"the {job.analysis} analysis is not available "
                                 f"in this version; available: {', '.join(ANALYSES)}"),
                         job.mech.model.source)
    return ANALYSES[job.analysis](job)


__all__ = ["ANALYSES", "run", "RedundancyWarning", "ConsistencyWarning", "ConditionWarning"]

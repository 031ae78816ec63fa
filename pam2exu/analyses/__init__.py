"""The analyses of PAM; ``ANALYSES`` is the registry from type name to function."""
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
    """
    job = prepare(model, analysis, t_end, steps, outputs, solver)
    if job.analysis not in ANALYSES:
        raise ModelError(Problem("[analysis]", f"the {job.analysis} analysis is not available "
                                 f"in this version; available: {', '.join(ANALYSES)}"),
                         job.mech.model.source)
    return ANALYSES[job.analysis](job)


__all__ = ["ANALYSES", "run", "RedundancyWarning", "ConsistencyWarning", "ConditionWarning"]

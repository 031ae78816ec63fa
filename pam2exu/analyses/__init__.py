"""The analyses of PAM, each declared in ``pam2exu.registry.ANALYSES`` (its names, what it
gives, what it needs, and its function in a module of this package).

``run`` runs one (``pam2exu.run`` is the same); the warning classes are those the checks
after an analysis issue.
"""
from __future__ import annotations

from ..errors import (ConditionWarning, ConsistencyWarning, InputWarning, ModelError, echo,
                      Pam2ExuError, RedundancyWarning, SolverError)
from ..model.angles import UNITS as ANGLE_UNITS
from ..results.units import in_angles
from ..registry import ANALYSES
from .job import prepare, warn_input


def run(model, analysis=None, t_end=None, steps=None, outputs=None, solver=None,
        backend=None, angles=None, **options):
    """Run an analysis and return its Results.

    ``pam2exu.run`` is this function, with ``t_end``, ``steps``, ``outputs`` and ``solver``
    passed as keywords; its documentation has the details and an example. None keeps the
    model's ``[analysis]`` setting.

    Parameters
    ----------
    model : Model, Mechanism or path
        A model, the path of a model file, or a model's ``Mechanism`` (``Model.mechanism()``:
        validated already, not again).
    analysis : str, optional
        'assembly', 'quasi_static', 'kinematic', 'kinetostatic', 'clearance',
        'equilibrium' or 'dynamic' (``registry.ANALYSES``; default: the model's [analysis]
        type).
    t_end : float, optional
        End of the interval [s].
    steps : int, optional
        Number of intervals; results have steps + 1 rows.
    outputs : list of str, optional
        Names or patterns of the columns to compute and keep.
    solver : optional
        The backend's settings (``backend.SolveSettings`` for Exudyn); default: its defaults.
    backend : str or Backend, optional
        What solves the positions (``registry.BACKENDS``: 'exudyn', 'natural'; or a
        ``Backend`` instance, such as the natural backend holding a study's batched
        answers); default: the model's [analysis] backend.
    angles : str, optional
        The unit of the angular columns (fi, Dfi, DDfi, f(t) of an angular actuator,
        fi_rel, …): ``'rad'`` or ``'deg'`` (deg, deg/s, deg/s²); default: the model's
        ``[model] angles``.
    **options
        The analysis options (``registry.OPTIONS``), by name; each defaults to the model's
        [analysis] key of that name. ``tolerance`` (float): the dynamic analysis's
        integration tolerance per unit of value [-]. Another keyword is a TypeError.

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
        The backend's solver did not converge, a singular position was reached, or redundant
        constraints contradict each other.
    TranslationError
        A self-check failed (a bug of pam2exu).

    Warns
    -----
    RedundancyWarning, ConditionWarning, ConsistencyWarning, InputWarning
        See each class; the texts are kept in ``Results.warnings`` too.

    Examples
    --------
    >>> from pam2exu.analyses import run
    >>> res = run("examples/four_bar.toml", "quasi_static", steps=20)  # doctest: +SKIP
    >>> len(res)                                                       # doctest: +SKIP
    21
    """
    job = None
    try:
        job = prepare(model, analysis, t_end, steps, outputs, solver, backend, **options)
        if angles not in (None, *ANGLE_UNITS):
            raise ModelError(f"angles must be 'rad' or 'deg' (the unit of the angular "
                             f"results), got {echo(angles)}", job.mech.model.source)
        warn_input(job)
        return in_angles(job.analysis_type.run(job), angles or job.mech.model.angles)
    except SolverError as exc:       # the rows kept before it, in the run's angle unit
        if exc.partial is not None:
            exc.partial = in_angles(exc.partial, angles or job.mech.model.angles)
        raise
    except Pam2ExuError:
        raise
    except Exception as exc:         # a fault of pam2exu: say what was being done
        raise unexpected(exc, job, model) from exc


def unexpected(exc: Exception, job, model) -> SolverError:
    """The SolverError for an exception that is not pam2exu's own (its cause kept)."""
    source = getattr(model, "source", None) or str(model)
    doing = job.stage if job is not None else "reading and checking the model"
    what = ("ran out of memory" if isinstance(exc, MemoryError)
            else f"failed unexpectedly ({type(exc).__name__}: {exc})")
    analysis = f"the {job.analysis_type.name} analysis" if job is not None else "pam2exu"
    return SolverError(
        f"{analysis} of {source} {what} while {doing}. This is a fault of pam2exu: please "
        "report it with the model file (rerun with --debug for the traceback, or catch "
        "the error's __cause__ in Python).")


__all__ = ["ANALYSES", "run", "RedundancyWarning", "ConsistencyWarning", "ConditionWarning",
           "InputWarning"]

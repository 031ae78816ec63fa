"""The configurations a picture shows, taken from the analyses.

``configurations`` runs the assembly (one row at t = 0, free degrees of freedom allowed) or a
kinematic run over [0, t_end] (Exudyn's static solver, on the branch the mechanism starts on;
a dynamic run for a model whose analysis is dynamic)
and returns the mechanism, the times and x, y, fi of every solid; ``pose`` is one of them at
a time t, with the model's step length so that it follows the same branch as ``run``. Both
ask for radians whatever the model is written in. ``draw`` (``mechanism.py``) and
``animate`` (``animation.py``) start here.
"""
from __future__ import annotations

import math

import numpy as np

from ..results.plot import PictureError

#: coordinates asked of a kinematic run (a velocity makes it follow the branch)
_POSE = ("*.x", "*.y", "*.fi", "*.Dfi")


def _model(model):
    from ..model import Model, load
    return model if isinstance(model, Model) else load(model)


def motion(model) -> str:
    """The run a picture of ``model`` over time shows: the model's [analysis] type when it
    integrates the motion (``AnalysisType.integrates``: its free solids move under the
    loads; a Catalan name read as the contract's), else ``'kinematic'``."""
    from ..registry import analysis_type
    kind = analysis_type(model.analysis.type)
    return kind.name if kind is not None and kind.integrates else "kinematic"


def configurations(model, t_end: float | None = None, steps: int | None = None,
                   analysis: str | None = None) -> tuple[object, np.ndarray, np.ndarray]:
    """(mechanism, t (n,), q (n, 3·solids)) of a run: the assembly (one row at t = 0), or
    the positions of a kinematic run over [0, t_end] in ``steps`` intervals (a dynamic run
    for a model whose analysis is ``dynamic``: its free solids move under the loads).

    Parameters
    ----------
    model : Model, str or Path
        A model, or the path of a model file.
    t_end : float, optional
        End of the interval [s] (default: the model's t_end); not used by an assembly.
    steps : int, optional
        Number of intervals (default: the model's steps); not used by an assembly.
    analysis : str, optional
        ``'kinematic'`` (needs every degree of freedom driven), ``'dynamic'`` (free degrees
        of freedom move) or ``'assembly'`` (t = 0 only; free degrees of freedom allowed).
        Default: ``'dynamic'`` for a model whose [analysis] type is dynamic, else
        ``'kinematic'``.

    Returns
    -------
    mechanism : Mechanism
        ``model.mechanism()``.
    t : numpy.ndarray
        Times [s], shape (n,).
    q : numpy.ndarray
        Shape (n, 3·solids): x [m], y [m], fi [rad] of each solid in order.

    Raises
    ------
    ModelError
        The model has problems (``MobilityError``: a degree of freedom is not driven, for
        a kinematic run).
    SolverError
        Exudyn's solver did not converge.
    """
    from ..analyses import run
    from ..registry import analysis_type
    model = _model(model)
    mech = model.mechanism()
    if analysis is None:
        analysis = motion(model)
    kind = analysis_type(analysis)
    if kind is not None and kind.at_start:       # one row, t = 0: no interval, no rates
        res = run(model, analysis=analysis, outputs=list(_POSE[:3]), angles="rad")
    else:
        res = run(model, analysis=analysis, t_end=t_end, steps=steps, outputs=list(_POSE),
                  angles="rad")
    return mech, np.array(res.t), mech.coordinates(res)


def pose(model, t: float = 0.0):
    """(mechanism, q) at time t: the assembly at t = 0, else a kinematic run (dynamic, for a
    dynamic model) from 0 to t with the model's step length.

    Parameters
    ----------
    model : Model, str or Path
        A model, or the path of a model file.
    t : float
        Time [s], ≥ 0. 0: the assembly (free degrees of freedom allowed); else the last
        row of a kinematic run over [0, t] in ceil(steps · t / t_end) intervals (the
        model's step length, or a little shorter), so it follows the same branch as
        ``run``.

    Returns
    -------
    mechanism : Mechanism
        ``model.mechanism()``.
    q : numpy.ndarray
        Shape (3·solids,): x [m], y [m], fi [rad] of each solid at t.

    Raises
    ------
    PictureError
        ``t`` is negative or not a number.
    ModelError
        The model has problems (``MobilityError`` for t > 0 when a degree of freedom is not
        driven).
    SolverError
        Exudyn's solver did not converge.
    """
    model = _model(model)
    if not t:
        mech, _, q = configurations(model, analysis="assembly")
        return mech, q[0]
    a = model.analysis
    if not (isinstance(t, (int, float)) and math.isfinite(t) and t > 0):
        raise PictureError(f"the time of a drawing must be a number ≥ 0 [s], not {t!r}")
    steps = max(1, math.ceil(a.steps * t / a.t_end - 1e-9))
    mech, _, q = configurations(model, t_end=float(t), steps=steps)
    return mech, q[-1]

"""pam2exu: PAM planar mechanism models, run on the Exudyn multibody library.

Load a model (``load``, ``loads``) or build one (``Model``), run an analysis (``run``), get a
``Results`` table of named columns (``crank.fi``, ``motor.Mz``, …), compare it with a
reference (``compare``), verify it on two backends (``verify``) or export the model as a
standalone Exudyn script (``export``).
The API reference is docs/api.md.

>>> import pam2exu
>>> model = pam2exu.load("examples/slider_crank.toml")      # doctest: +SKIP
>>> res = pam2exu.run(model, analysis="kinematic")          # doctest: +SKIP
>>> res["slider.Dx"]                                        # doctest: +SKIP
"""
from .elements import ELEMENTS
from .errors import (MobilityError, ModelError, OutputError, Pam2ExuError, SolverError,
                     TranslationError)
from .export import export
from .errors import (ConditionWarning, ConsistencyWarning, InputWarning, RedundancyWarning,
                     VariationWarning)
from .model import Law, Model, Solid, load, loads
from .pictures import animate, draw
from . import notebook  # noqa: F401  (registers the drawing of Model._repr_html_)
from .results import CompareInputError, Comparison, Results, plot, read_csv
from .results.compare import compare
from .results.plot import PictureError
from .verify import Verification, verify
from .version import __version__

#: every element class under its own name (``pam2exu.Revolute``), read from ``ELEMENTS``
#: (registering a type in ``pam2exu/elements/__init__.py`` is all it takes)
globals().update({cls.__name__: cls for cls in ELEMENTS.values()})



def run(model, analysis=None, **settings):
    """Run an analysis of a model (a Model or a path); returns a Results table.

    The settings default to the model's ``[analysis]`` table (``Model.analysis``); the
    arguments override them for this run. Columns are ``<name>.<variable>`` under PAM's
    names, in SI units (``Results.units``). The warnings of the run (redundant constraints,
    a singular position nearby, a power balance not met) are issued and also kept in
    ``Results.warnings``. The same as ``pam2exu.analyses.run``.

    Parameters
    ----------
    model : Model, str or Path
        A model, or the path of a model file (read with ``load``).
    analysis : str, optional
        ``'assembly'`` (positions at t = 0, free degrees of freedom allowed),
        ``'quasi_static'`` (positions and static reactions), ``'kinematic'`` (positions,
        velocities, accelerations), ``'kinetostatic'`` (kinematic, plus every reaction
        and actuator force by inverse dynamics), and the extensions ``'clearance'``
        (docs/clearance.md), ``'equilibrium'`` (free degrees of freedom at rest) and
        ``'dynamic'`` (free degrees of freedom in motion; docs/analyses.md). Default: the
        model's analysis type.
    **settings
        Keyword overrides of the model's settings: ``t_end``, ``steps``, ``outputs``,
        ``solver``, ``backend``, ``angles`` and ``tolerance``, described below. None (the
        default of each) keeps the model's.
    t_end : float, optional
        End of the interval [0, t_end] [s].
    steps : int, optional
        Number of intervals: results have steps + 1 rows, t_k = k t_end / steps (an
        assembly has one row, t = 0).
    outputs : list of str, optional
        Names or patterns of the columns to compute and keep: full names (``crank.fi``),
        ``crank.*``, ``*.Fx`` or a bare ``Fx`` (every ``*.Fx``); only what they need is
        computed.
    solver : pam2exu.backend.SolveSettings, optional
        The backend's settings; for Exudyn, its static solver's: ``tolerance`` (Newton's
        absolute tolerance relative to the mechanism's length, default 1e-13),
        ``max_iterations``, ``dense``, ``verbose``, ``predictor``, ``modified_newton``
        (default True: a run's steps by Exudyn's modified Newton, one Jacobian per step;
        docs/analyses.md).
    backend : str, optional
        What solves the positions (``pam2exu.registry.BACKENDS``): ``'exudyn'`` (the
        default); an unknown name is a ModelError listing the known ones.
    tolerance : float, optional
        ``'dynamic'`` only: the error allowed in the time integration, per unit of each
        coordinate and rate (tolerance · (1 + |value|), SI units); default 1e-8. The
        estimate achieved is ``res.info["integration_error"]``.
    method : str, optional
        ``'clearance'`` only: how the least-norm clearance is followed, ``'ode'`` (the
        slides' differential equation, the default) or ``'newton'`` (Newton at every row
        from the previous one); ``res.info["clearance_method"]`` says which.

    Returns
    -------
    Results
        The table of columns over time: ``res["crank.fi"]``, ``res.t`` [s], ``res.units``,
        ``res.warnings``, ``res.info``.

    Raises
    ------
    ModelError
        The model file cannot be read or the model has problems; a setting is out of range
        (e.g. ``t_end`` ≤ 0, ``steps`` < 1, an unknown analysis type); a pattern of
        ``outputs`` matches no column of the analysis.
    MobilityError
        quasi_static, kinematic, kinetostatic: some degree of freedom is not driven by an
        actuator (the message names the solids that can move).
    SolverError
        The backend's solver did not converge, the mechanism reaches a singular (dead-point)
        position it cannot pass, or redundant constraints contradict each other (two
        drives of one coordinate that disagree); ``time`` [s], ``step`` and ``elements``
        say where and which.
    TranslationError
        A self-check failed: a bug of pam2exu, to be reported with the model file.
    TypeError
        A keyword that is not one of the settings above.

    Warns
    -----
    RedundancyWarning
        Redundant (consistent) constraints: the reactions of the elements named are the
        minimum-norm solution.
    ConditionWarning
        The mechanism passes at or near a singular position.
    ConsistencyWarning
        kinetostatic: the power balance does not hold.
    InputWarning
        A value that is most likely a mistake: an angle above a full turn in a radians
        model (degrees?), initial rates the constraints do not allow, a law that jumps
        within a step; naming the solids and elements.

    See Also
    --------
    pam2exu.analyses.run : the same, with the settings as named arguments.

    Examples
    --------
    >>> import pam2exu
    >>> m = pam2exu.Model("crank", gravity=0.0)
    >>> m.add_solid("ground").name
    'ground'
    >>> m.add_solid("crank", points={"O": [0, 0], "A": [0.1, 0]}).name
    'crank'
    >>> m.add("fixed", anc1="ground").name
    'fixed1'
    >>> m.add("revolute", name="O", anc1="ground", anc2="crank.O").name
    'O'
    >>> m.add("angular_actuator", name="motor", anc1="ground", anc2="crank",
    ...       C=[0.0, 6.0]).name                     # fi = 6 t [rad]
    'motor'
    >>> res = pam2exu.run(m, analysis="kinematic", t_end=0.5, steps=10)
    >>> res
    <Results kinematic 'crank': 11 rows × 20 columns>
    >>> round(float(res["crank.fi"][-1]), 12), res.units["crank.Dfi"]
    (3.0, 'rad/s')
    >>> res = pam2exu.run("examples/slider_crank.toml", outputs=["motor.Mz"])  # doctest: +SKIP
    >>> res.columns                                                           # doctest: +SKIP
    ['motor.Mz']
    """
    from .analyses import run as _run
    return _run(model, analysis=analysis, **settings)


def energy(model, analysis=None, **settings):
    """The energy account of a kinetostatic or dynamic run of a model; returns a Results
    table of ``energy.kinetic``, ``energy.potential``, ``energy.actuators``,
    ``energy.torsors``, ``energy.dissipated`` and ``energy.balance`` [J].

    The works and the dissipation are counted from t = 0 (Simpson's rule over the rows);
    ``balance`` = (T + V) − (T0 + V0) − the works + the dissipation is zero up to that
    quadrature. ``pam2exu run MODEL --energy FIG.png`` plots it (docs/analyses.md).

    Parameters
    ----------
    model : Model, str or Path
        A model, or the path of a model file.
    analysis : str, optional
        ``'kinetostatic'`` or ``'dynamic'`` (default: the model's, which must be one).
    **settings
        ``run``'s keyword overrides (``t_end``, ``steps``, ``tolerance``, …).

    Returns
    -------
    Results
        One column per quantity, on the run's times.

    Raises
    ------
    ModelError
        The analysis gives no rates or forces (assembly, quasi_static, kinematic,
        clearance, equilibrium), and ``run``'s errors.

    Examples
    --------
    >>> account = pam2exu.energy("examples/slider_crank.toml")      # doctest: +SKIP
    >>> float(abs(account["energy.balance"]).max()) < 1e-5             # doctest: +SKIP
    True
    """
    from .analyses.energy import energy as _energy
    return _energy(model, analysis, **settings)


def study(study_or_path, executor=None, out=None, resume=False, samples=None, workers=None,
          progress=False):
    """Run a study: one analysis of one model for many variants of its values
    (docs/studies.md); returns a ``StudyResult`` with ``.table``, ``.summary``, ``.yield_``.

    Every check comes before any variant runs; a variant that fails is a row with status
    ``error`` and its message, never a stopped study. The same as
    ``pam2exu.studies.runner.study``.

    Parameters
    ----------
    study_or_path : Study, str or Path
        A study (``pam2exu.studies.load_study``) or the path of a study file.
    executor : concurrent.futures.Executor or dask.distributed.Client, optional
        Runs the chunks of variants (default: this process, or ``workers`` processes); the
        table is the same, bit for bit, whatever runs it.
    out : str or Path, optional
        Write the per-variant table (``.parquet`` or ``.csv``) and ``OUT.summary.csv``
        (with ``series = true`` also ``OUT.series.parquet`` or ``OUT.series.csv``).
    resume : bool
        Run only the chunks missing under ``OUT.parts/`` (those of an interrupted study).
    samples : int, optional
        The number of variants, instead of the study's (sampled methods).
    workers : int, optional
        Local worker processes (default 1); with an ``executor``, the processes it runs at
        once, for the chunks' size (default: a Dask cluster's worker threads, else the
        cores).
    progress : bool
        A progress bar on a terminal (variants done, rate, time left).

    Returns
    -------
    StudyResult
        ``.table`` (NumPy columns ``sample``, ``status``, ``error``, the parameters, the
        reduced outputs), ``.summary`` (rows), ``.yield_`` (share ok, Wilson interval),
        ``.to_pandas()``, ``.to_parquet(path)``, ``.to_csv(path)``, ``.report()``; with
        ``series = true`` ``.series`` (long format ``sample``, ``t``, each output); the
        pictures ``.hist(output)``, ``.band(output)``, ``.scatter(output, parameter)``.

    Raises
    ------
    ModelError
        The study file has problems (every one listed, each naming its entry), asks what a
        study cannot do yet (``method = "linear"``, ``analysis = "clearance"``), or its
        nominal model does not run; nothing is written.
    OutputError
        ``out`` has an unknown suffix or needs a library that is not installed.

    Examples
    --------
    >>> result = pam2exu.study("examples/studies/slider_crank_tolerance.toml",
    ...                        samples=4)                                # doctest: +SKIP
    >>> result.table["status"].tolist()                                  # doctest: +SKIP
    ['ok', 'ok', 'ok', 'ok']
    """
    from .studies.runner import study as _study
    return _study(study_or_path, executor=executor, out=out, resume=resume, samples=samples,
                  workers=workers, progress=progress)


__all__ = ["Model", "Solid", "Law", "load", "loads", "run", "energy", "study", "Results",
           "read_csv",
           "compare", "Comparison", "verify", "Verification", "export", "plot", "draw", "animate",
           "ELEMENTS", *(cls.__name__ for cls in ELEMENTS.values()), "Pam2ExuError",
           "ModelError", "MobilityError", "SolverError", "TranslationError",
           "CompareInputError", "PictureError", "OutputError", "RedundancyWarning",
           "ConsistencyWarning", "ConditionWarning", "VariationWarning", "InputWarning"]

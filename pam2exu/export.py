"""Export a model as a standalone Exudyn script (imports exudyn and numpy only).

The script builds the system of the translation (``backend.exudyn.script.ScriptSystem`` records
``ExudynSystem``'s construction and every element's ``build`` as code: one commented block
per solid and element), writes the actuators' laws as plain Python functions of t, solves
the positions over the analysis interval with Exudyn's static solver, one load step per time
step, as ``pam2exu run`` does, and saves x, y, fi of every solid as CSV.

>>> import pam2exu
>>> pam2exu.export("examples/slider_crank.toml", "slider_crank_exudyn.py")  # doctest: +SKIP
"""
from __future__ import annotations

import textwrap
from pathlib import Path

from . import registry
from .law_code import LAW_CODE

__all__ = ["LAW_CODE", "export", "script"]

#: why the script sets a solver option (a comment after it)
_OPTION_NOTES = {
    "staticSolver.useLoadFactor": "actuators and loads in full at every step, no ramp",
    "staticSolver.newton.absoluteTolerance": "1e-13 x the mechanism's length scale (at least "
                                             "the round-off floor of the equations)",
    "linearSolver.ignoreSingularJacobian": "redundant (consistent) constraints",
}

_HEAD = '''"""{title}

{about}

Run:  python {file} [OUT.csv]      (default: {csv})
"""
import csv
import sys

import numpy as np

import exudyn as exu
{items}

csv_file = sys.argv[1] if len(sys.argv) > 1 else {csv!r}

# time grid: t_k = k t_end / steps, k = 0 ... steps
t_end = {t_end!r}
steps = {steps!r}
times = np.linspace(0.0, t_end, steps + 1)
dt = times[1] - times[0]
'''

_LAWS = '''

# ---- time laws of the actuators (PAM's "lleis temporals"), f(t) with constants C1 ... C4
'''

_SYSTEM = '''

# ---- the Exudyn system: one block per solid and per PAM element ---------------------------
SC = exu.SystemContainer()
mbs = SC.AddSystem()

'''

_PRE_STEP = '''
# ---- actuators: before each load step, set every actuator to its law ----------------------
# The static solver solves load step k (k = 1 ... steps + 1) at its time k dt; the laws are
# taken one step earlier, so load step k gives the configuration at t_(k-1) (load step 1 is
# the assembly at t = 0).
def PreStepUserFunction(mbs, t):
    k = int(round(t / dt)) - 1
    # t_k on the time grid; t - dt where the solver subdivided a step
    tau = times[k] if abs(t - (k + 1) * dt) <= 1e-6 * dt else t - dt
{body}    return True


mbs.SetPreStepUserFunction(PreStepUserFunction)
'''

_SOLVE = '''
# ---- Exudyn's static solver: one load step per time t_0 ... t_steps -----------------------
simulationSettings = exu.SimulationSettings()
{options}
simulationSettings.staticSolver.numberOfLoadSteps = steps + 1
simulationSettings.staticSolver.loadStepStart = 0.0
simulationSettings.staticSolver.loadStepDuration = (steps + 1) * dt
try:
    mbs.SolveStatic(simulationSettings)
except Exception as error:          # the rows solved so far are still written below
    print(f"Exudyn's static solver stopped: {{error}}", file=sys.stderr)
'''

_RESULTS = '''
# ---- results: x, y, fi of every solid at every t_k, as CSV --------------------------------
# A sensor's row 0 is the initial state; load step k is stored at time k dt and holds t_(k-1).
solids = {order}
fixed_poses = {fixed}   # held by fixed links
sensors = {sensors}
rows = {{}}                                           # k -> {{solid: [x, y, fi]}}
for solid, sensor in sensors.items():
    for t, x, y, fi in mbs.GetSensorStoredData(sensor)[1:, :4]:
        k = int(round(t / dt)) - 1
        if 0 <= k <= steps and abs(t - (k + 1) * dt) <= 1e-6 * dt:
            rows.setdefault(k, {{}})[solid] = [x, y, fi]
solved = next((k for k in range(steps + 1) if len(rows.get(k, ())) < len(sensors)), steps + 1)
with open(csv_file, "w", newline="", encoding="utf-8") as f:
    writer = csv.writer(f)
    writer.writerow(["t"] + [f"{{s}}.{{c}}" for s in solids for c in ("x", "y", "fi")])
    for k in range(solved):
        pose = {{**fixed_poses, **rows.get(k, {{}})}}
        writer.writerow([float(times[k])] + [float(c) + 0.0 for s in solids for c in pose[s]])
print(f"wrote {{solved}} of {{steps + 1}} rows to {{csv_file}}")
sys.exit(0 if solved == steps + 1 else 1)
'''


def script(model, t_end: float | None = None, steps: int | None = None,
           forces: bool = False, file: str = "script.py", analysis: str | None = None,
           **options) -> str:
    """The source of the standalone Exudyn script of a model (see ``export``).

    Parameters
    ----------
    model : Model, str or Path
        A model, or the path of a model file.
    t_end : float, optional
        End of the interval [s] (default: the model's [analysis] t_end).
    steps : int, optional
        Number of intervals (default: the model's [analysis] steps).
    forces : bool
        Include masses, gravity, springs and loads (see ``export``).
    file : str
        The script's file name, used in its docstring and for its default CSV file
        (``<stem>.csv``).
    analysis : str, optional
        The analysis whose positions the script gives (default: the model's [analysis]
        type). ``'dynamic'`` (``dinamica``) with a degree of freedom free: the forward
        dynamics script (``export_dynamic``; ``forces`` does not apply, the masses and
        forces are always in); any other, or a fully driven model: the positions by
        Exudyn's static solver.
    **options
        The analysis options (``registry.OPTIONS``) of the integrating analysis's script:
        ``tolerance``, the dynamic analysis's (default: the model's [analysis] tolerance).

    Returns
    -------
    str
        Python source that imports only ``exudyn`` and ``numpy`` (and the standard
        library).

    Raises
    ------
    ModelError
        The model or a setting has problems; ``MobilityError`` when a degree of freedom is
        not driven.

    Examples
    --------
    >>> import pam2exu
    >>> from pam2exu.export import script
    >>> m = pam2exu.Model("crank", gravity=0.0)
    >>> m.add_solid("ground").name, m.add("fixed", anc1="ground").name
    ('ground', 'fixed1')
    >>> m.add_solid("crank", points={"O": [0, 0], "A": [0.1, 0]}).name
    'crank'
    >>> m.add("revolute", anc1="ground", anc2="crank.O").name
    'revolute1'
    >>> m.add("angular_actuator", anc1="ground", anc2="crank", C=[0.0, 6.0]).name
    'angular_actuator1'
    >>> source = script(m, t_end=1.0, steps=10, file="crank.py")
    >>> compile(source, "crank.py", "exec") is not None
    True
    >>> "import exudyn as exu" in source, "def polynomial(t, C1, C2, C3, C4):" in source
    (True, True)
    """
    from .analyses.job import check_mobility, prepare
    from .backend.exudyn.script import ScriptSystem, code
    from .backend.exudyn.system import SolveSettings, solver_options

    registry.refuse_unknown_options(options, "script")
    kind = _analysis(model, analysis)
    if kind.integrates:                   # the script of its time integration
        from .export_dynamic import dynamic_script
        source = dynamic_script(model, kind.name, t_end, steps, file, **options)
        if source is not None:
            return source                 # else fully driven: the kinematic positions
    # the job and the checks of a kinematic run: same interval, same mobility errors
    job = prepare(model, "kinematic", t_end, steps, ["*.x", "*.y", "*.fi"])
    # the user's times (a run solves long steps in sub-steps, the script does not)
    mech, times = job.mech, job.times[::job.every]
    mob = check_mobility(job, mech.initial_q(), need_driven=True)
    system = ScriptSystem(mech, forces=forces)
    options = solver_options(mech, SolveSettings(), mob.redundant > 0, system.roundoff(times))
    return (_header(mech, system, times, forces, file) + _laws(system)
            + _SYSTEM + "\n".join(system.lines()) + _pre_step(system)
            + _SOLVE.format(options="\n".join(
                (f"# {_OPTION_NOTES[path]}\n" if path in _OPTION_NOTES else "")
                + f"simulationSettings.{path} = {code(value)}"
                for path, value in options.items()))
            + _results(mech, system))


def _analysis(model, analysis: str | None):
    """The analysis's declaration (``registry.AnalysisType``; a Catalan name too):
    ``analysis``, else the model's type."""
    from .model import Model, load
    if analysis is None:
        analysis = (model if isinstance(model, Model) else load(model)).analysis.type
    kind = registry.analysis_type(analysis)
    if kind is None:
        from .errors import ModelError
        raise ModelError(f"unknown analysis {analysis!r}: known are "
                         + ", ".join(registry.ANALYSES))
    return kind


def _header(mech, system, times, forces: bool, file: str) -> str:
    """Docstring, imports and the time grid."""
    from .version import __version__
    source = mech.model.source
    kind = ("masses, gravity, springs and loads included" if forces else
            "constraints only, as for kinematic positions")
    about = textwrap.fill(
        f"Exudyn model of the PAM mechanism '{mech.name}'"
        f"{f' ({Path(source).name})' if source else ''}, exported by pam2exu {__version__}. "
        f"It builds the Exudyn system pam2exu builds ({kind}), solves the positions for "
        "t = 0 ... t_end in `steps` steps with Exudyn's static solver (one load step per time, "
        "the actuators set to their laws before each step) and writes x, y, fi of every solid "
        "as CSV.", 92)
    items = textwrap.fill(", ".join(sorted(system.kinds)) + ")", 99,
                          initial_indent="from exudyn.itemInterface import (",
                          subsequent_indent="    ")
    return _HEAD.format(title=f"{mech.name}: positions by Exudyn's static solver",
                        about=about, file=Path(file).name, csv=f"{Path(file).stem}.csv",
                        items=items, t_end=float(times[-1]), steps=len(times) - 1)


def _laws(system) -> str:
    """The definitions of the laws the actuators use, in the order of LAW_CODE."""
    laws = sorted({law.name for _, _, law, _ in system.drivers}, key=list(LAW_CODE).index)
    return _LAWS + "\n\n".join(LAW_CODE[name] for name in laws) if laws else ""


def _pre_step(system) -> str:
    """The pre-step function that sets each actuator's parameter to its law at t_k."""
    from .backend.exudyn.script import code
    if not system.drivers:
        return ""
    body = ""
    for (obj, par, law, shift), el in zip(system.drivers, system.driver_owners):
        anchors = ", ".join(f"anc{k + 1} = {a!r}" for k, a in enumerate(el.given_anchors()))
        value = (f"{law.name}(tau, {', '.join(code(c) for c in law.C)})"
                 + (f" + {code(shift)}" if shift else ""))
        line = f"    mbs.SetObjectParameter({obj}, {par!r}, {value})"
        if len(line) > 99:
            line = f"    mbs.SetObjectParameter({obj}, {par!r},\n{' ' * 27}{value})"
        body += f"    # {el.name}: {el.summary} ({anchors})\n{line}\n"
    return _PRE_STEP.format(body=body)


def _results(mech, system) -> str:
    """Reading the sensors and writing the CSV."""
    from .backend.exudyn.script import code
    solids = mech.solids
    fixed = [f"{solids[i].name!r}: {code([solids[i].x, solids[i].y, solids[i].fi])}"
             for i in sorted(system.grounded)]
    sensors = [f"{solids[i].name!r}: {var}" for i, var in system.sensors.items()]
    return _RESULTS.format(order=_fill("[", [repr(s.name) for s in solids], "]"),
                           fixed=_fill("{", fixed, "}"), sensors=_fill("{", sensors, "}"))


def _fill(opening: str, entries: list[str], closing: str) -> str:
    """A list or dict display of ``entries``, wrapped at 99 columns after the name that
    precedes it in the script (at most 16 characters)."""
    return textwrap.fill(opening + ", ".join(entries) + closing, 99 - 16,
                         subsequent_indent=" " * 4, break_long_words=False,
                         break_on_hyphens=False)


def export(model, path, t_end: float | None = None, steps: int | None = None,
           forces: bool = False, analysis: str | None = None, **options) -> Path:
    """Write a model as a standalone Exudyn script; returns its path.

    The script (imports: ``exudyn``, ``numpy``) builds the Exudyn system pam2exu builds, one
    commented block per solid and element, sets the actuators to their laws (plain Python
    functions) in a pre-step function, solves the positions at every time with Exudyn's
    static solver and writes x, y, fi of every solid as CSV. ``pam2exu export`` calls this
    function; the user guide is docs/export.md.

    Parameters
    ----------
    model : Model or path
        A model, or the path of a model file.
    path : str or Path
        The script to write (``.py``). Run it with ``python path [OUT.csv]``; it writes the
        positions to ``OUT.csv`` (default: the script's name with ``.csv``).
    t_end : float, optional
        End of the interval [s] (default: the model's [analysis] t_end).
    steps : int, optional
        Number of intervals (default: the model's [analysis] steps).
    forces : bool
        Include masses, gravity, springs, dampers' stiffness and loads (the system of the
        quasi-static analysis); positions are the same, the constraints alone decide them.
    analysis : str, optional
        Default: the model's [analysis] type. ``'dynamic'`` with a degree of freedom left
        free writes the forward-dynamics script instead (docs/export.md, "Dynamic models"):
        Exudyn's SolveDynamic with the step count of the analysis, Richardson-extrapolated.
    **options
        The analysis options (``registry.OPTIONS``): ``tolerance``, the dynamic analysis's
        (default: the model's [analysis] tolerance).

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    ModelError
        The model or a setting has problems.
    MobilityError
        A degree of freedom is not driven: the script solves positions, so every degree
        of freedom must be driven, as for ``run(..., analysis="kinematic")``.
    OSError
        The script cannot be written.

    Examples
    --------
    >>> import pam2exu
    >>> pam2exu.export("examples/slider_crank.toml", "slider_crank_exudyn.py")  # doctest: +SKIP
    PosixPath('slider_crank_exudyn.py')

    Then ``python slider_crank_exudyn.py positions.csv`` writes t and x, y, fi of every
    solid; they equal ``pam2exu.run(model, analysis="kinematic")`` to round-off.
    """
    path = Path(path)
    path.write_text(script(model, t_end, steps, forces, file=path.name, analysis=analysis,
                           **options), encoding="utf-8")
    return path

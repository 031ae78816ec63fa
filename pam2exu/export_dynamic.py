"""Export a model whose analysis is ``dynamic`` as a standalone Exudyn script of its motion.

The script (imports exudyn and numpy only) builds the system of the dynamic analysis
(``backend.integrate``: masses, gravity, springs, dampers and loads, fixed solids as ground)
as commented blocks (``backend.script.ScriptSystem``), starts it from the state the analysis
starts from (the assembly at t = 0 and the nearest consistent velocities, written as
numbers), drives the actuators at the integrator's time as the analysis does, integrates
with ``SolveDynamic`` (generalized-α, the analysis's settings) twice, with the step count
the analysis needed and half of it, extrapolates the two (Richardson) and writes x, y, fi
of every solid as CSV. The step count comes from a run of the analysis at export time
(``res.info["integration_steps"]``).

Law breakpoints inside the interval (the C1, C2 of ramp, bezier_c1, bezier_c2) while a
degree of freedom is free are refused (``ModelError`` naming the element and its law): the
analysis restarts its integration there and, for a ramp, applies the contract's plastic
impulse, which needs the mass matrix and the constraint Jacobian; the script does not
reproduce them.
"""
from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np

from .law_code import LAW_CODE

__all__ = ["dynamic_script"]

#: the x, y, fi columns of every solid
POSITIONS = ["*.x", "*.y", "*.fi"]

_HEAD = '''"""{title}

{about}

{accuracy}

Run:  python {file} [OUT.csv]      (default: {csv})
"""
import csv
import sys

import numpy as np

import exudyn as exu
{items}

csv_file = sys.argv[1] if len(sys.argv) > 1 else {csv!r}

# output times: t_k = k t_end / steps, k = 0 ... steps
t_end = {t_end!r}
steps = {steps!r}
times = np.linspace(0.0, t_end, steps + 1)

# integration steps over [0, t_end]: the finest run of pam2exu's dynamic analysis at
# tolerance {tolerance:g} took {fine} steps: the script runs it and the run with half as
# many, and extrapolates the two (Richardson) as the analysis does
fine_steps = {fine!r}
coarse_steps = fine_steps // 2
'''

_LAWS = '''

# ---- time laws of the actuators (PAM's "lleis temporals"), f(t) with constants C1 ... C4
'''

_SYSTEM = '''

# ---- the Exudyn system: one block per solid and per PAM element ---------------------------
# Initial state (the nodes' initialCoordinates and initialVelocities): computed by
# pam2exu's dynamic analysis at export time. Positions: the assembly at t = 0 (the
# configuration nearest to the model's x, y, fi that meets the constraints); velocities:
# those that meet the velocity equations at t = 0 nearest (Euclidean norm, SI units) to the
# solids' Dx, Dy, Dfi (0 where not given).
SC = exu.SystemContainer()
mbs = SC.AddSystem()

'''

_DRIVE = '''
# ---- actuators: each follows its law at the integrator's time -----------------------------
# generalized-alpha enforces the constraints at the end of each step: an offset by a user
# function of t (Exudyn calls it with that time), a distance (ObjectConnectorDistance has no
# user function) by a pre-step function, which Exudyn calls with the step's end time too.
{body}'''

_PRE_STEP = '''
def PreStepUserFunction(mbs, t):
{body}    return True


mbs.SetPreStepUserFunction(PreStepUserFunction)
'''

_SOLVE = '''

# ---- Exudyn's dynamic solver: generalized-alpha, index-3 constraints ----------------------
def simulate(number_of_steps):
    """x, y, fi of every moving solid at the output times, {{solid: array (steps + 1, 3)}},
    from one SolveDynamic run of number_of_steps equal steps (from the initial state)."""
    simulationSettings = exu.SimulationSettings()
{options}
    simulationSettings.timeIntegration.numberOfSteps = number_of_steps
    mbs.SolveDynamic(simulationSettings, solverType=exu.DynamicSolverType.GeneralizedAlpha)
    every = number_of_steps // steps          # a sensor stores a row per step, row 0 at t = 0
    out = {{}}
    for solid, sensor in sensors.items():
        data = np.asarray(mbs.GetSensorStoredData(sensor))[::every]
        if len(data) != steps + 1 or np.max(np.abs(data[:, 0] - times)) > 1e-6 * t_end / steps:
            raise RuntimeError(f"Exudyn stopped early at t = {{data[-1, 0]:g}}")
        out[solid] = data[:, 1:4]
    return out


sensors = {sensors}
try:
    coarse = simulate(coarse_steps)
    fine = simulate(fine_steps)
except Exception as error:
    print(f"Exudyn's dynamic solver stopped: {{error}}", file=sys.stderr)
    sys.exit(1)

# Richardson: generalized-alpha's error is c h^2 + O(h^3), so (4 fine - coarse) / 3 cancels
# its h^2 term; the error left is the one the docstring's estimate bounds.
poses = {{solid: fine[solid] + (fine[solid] - coarse[solid]) / 3.0 for solid in sensors}}
'''

_RESULTS = '''
# ---- results: x, y, fi of every solid at every t_k, as CSV --------------------------------
solids = {order}
fixed_poses = {fixed}   # held by fixed links
with open(csv_file, "w", newline="", encoding="utf-8") as f:
    writer = csv.writer(f)
    writer.writerow(["t"] + [f"{{s}}.{{c}}" for s in solids for c in ("x", "y", "fi")])
    for k in range(steps + 1):
        pose = {{**fixed_poses, **{{s: poses[s][k] for s in poses}}}}
        writer.writerow([float(times[k])] + [float(c) + 0.0 for s in solids for c in pose[s]])
print(f"wrote {{steps + 1}} rows to {{csv_file}}")
'''


def dynamic_script(model, t_end=None, steps=None, file: str = "script.py",
                   tolerance=None) -> str | None:
    """The source of the dynamic script of a model (see the module), or None when every
    degree of freedom is driven (its positions are then the kinematic ones: the caller
    writes the positions script).

    Raises ModelError for a law breakpoint inside the interval while a degree of freedom is
    free, and every error of ``run(model, analysis="dynamic")``.
    """
    from .analyses import run
    from .analyses.assembly import GUESS_STIFFNESS
    from .analyses.dynamic import nearest_velocities, require_inertia
    from .analyses.job import check_mobility, prepare
    from .analyses.positions import assemble
    from .backend.integrate import settings
    from .backend.script import ScriptSystem
    from .errors import ModelError

    job = prepare(model, "dynamic", t_end, steps, POSITIONS, tolerance=tolerance)
    mech, t = job.mech, job.times
    mob = check_mobility(job, mech.initial_q(), need_driven=False)
    if mob.dof == 0:
        return None
    for el in mech.drivers:
        law = el.time_law()
        inside = [b for b in law.breakpoints() if t[0] < b < t[-1]]
        if inside:
            what = ("its rate jumps there, and the analysis applies the plastic impulse of "
                    "the contract" if law.name == "ramp" else
                    "the analysis restarts its integration there")
            raise ModelError(
                f"'{el.name}' ({el.type}) follows the law {law.name} with a breakpoint at "
                f"t = {', '.join(f'{b:g}' for b in inside)} s, inside the interval, while "
                f"{mob.dof} degree(s) of freedom are free: {what}, which the exported "
                "script does not reproduce. Export an interval that ends before it "
                "(--t-end), or use a law without breakpoints there (polynomial, harmonic)",
                mech.model.source)
    q0 = assemble(job, mob.redundant > 0, GUESS_STIFFNESS)
    require_inertia(mech, float(t[0]), q0)
    qd0 = nearest_velocities(mech, float(t[0]), q0, mech.initial_qd())
    res = run(model, "dynamic", t_end, steps, outputs=POSITIONS, tolerance=tolerance)
    fine = int(res.info["integration_steps"])
    system = ScriptSystem(mech, forces=True, velocity_forces=True, start=q0, start_rates=qd0,
                          ground_fixed=True)
    options = settings(mech, 0.0, float(t[-1]), fine)
    return (_header(mech, system, res, job, fine, file) + _laws(system)
            + _SYSTEM + "\n".join(system.lines()) + _drive(system) + _solve(system, options)
            + _results(mech, system, q0))


def _header(mech, system, res, job, fine: int, file: str) -> str:
    from . import __version__
    from .backend.integrate import SPECTRAL_RADIUS
    source = str(mech.model.source or "")
    about = textwrap.fill(
        f"Exudyn model of the PAM mechanism '{mech.name}'"
        f"{f' ({Path(source).name})' if source and not source.startswith('<') else ''}, "
        f"exported\0by\0pam2exu\0{__version__} "
        "from its dynamic analysis. It builds the Exudyn system pam2exu integrates (masses, "
        "gravity, springs, dampers and loads; fixed solids as ground), starts it from the "
        "state the analysis starts from, integrates the motion for t = 0 ... t_end with "
        "Exudyn's SolveDynamic (generalized-alpha, index-3 constraints, spectral radius "
        f"{SPECTRAL_RADIUS:g}) in fine_steps and in fine_steps / 2 steps, extrapolates the two (Richardson) "
        "and writes x, y, fi of every solid at the output times as CSV.", 92).replace("\0", " ")
    estimate = float(res.info["integration_error"])
    accuracy = textwrap.fill(
        f"Accuracy: pam2exu's dynamic analysis asked for tolerance {job.tolerance:g} "
        "(the error of every coordinate and rate at most tolerance (1 + |value|), SI "
        "units). It halved its step until two successive Richardson extrapolations agreed "
        f"(Romberg); its finest run took {fine} steps over the interval, and its error "
        f"estimate there is {estimate:.2g} per unit of value. This script's result is "
        "that extrapolation, before the analysis's projection onto the constraints "
        "(a correction of the size of the error).", 92)
    items = textwrap.fill(", ".join(sorted(system.kinds)) + ")", 99,
                          initial_indent="from exudyn.itemInterface import (",
                          subsequent_indent="    ")
    times = job.times[::job.every]
    return _HEAD.format(title=f"{mech.name}: forward dynamics by Exudyn's SolveDynamic",
                        about=about, accuracy=accuracy, file=Path(file).name,
                        csv=f"{Path(file).stem}.csv", items=items, t_end=float(times[-1]),
                        steps=len(times) - 1, tolerance=job.tolerance, fine=fine)


def _laws(system) -> str:
    laws = sorted({law.name for _, _, law, _ in system.drivers}, key=list(LAW_CODE).index)
    return _LAWS + "\n\n".join(LAW_CODE[name] for name in laws) if laws else ""


def _drive(system) -> str:
    """Offsets by user functions of t, distances by a pre-step function."""
    from .backend.script import code, identifier
    if not system.drivers:
        return ""
    body, stepped = "", ""
    for (obj, par, law, shift), el in zip(system.drivers, system.driver_owners):
        anchors = ", ".join(f"anc{k + 1} = {getattr(el, f'anc{k + 1}')!r}"
                            for k in range(len(el.anchors)))
        value = (f"{law.name}(t, {', '.join(code(c) for c in law.C)})"
                 + (f" + {code(shift)}" if shift else ""))
        comment = f"# {el.name}: {el.summary} ({anchors})"
        if par == "offset":
            name = f"offset_{identifier(el.name)}"
            body += (f"\n{comment}\ndef {name}(mbs, t, itemNumber, lOffset):\n"
                     f"    return {value}\n\n\n"
                     f"mbs.SetObjectParameter({obj}, 'offsetUserFunction', {name})\n")
        else:
            start = value.replace("(t, ", "(0.0, ", 1)
            body += (f"\n{comment}: its value at t = 0, then before every step\n"
                     f"mbs.SetObjectParameter({obj}, {par!r}, {start})\n")
            stepped += f"    mbs.SetObjectParameter({obj}, {par!r}, {value})\n"
    if stepped:
        body += _PRE_STEP.format(body=stepped)
    return _DRIVE.format(body=body) + "mbs.Assemble()\n"



def _solve(system, options: dict) -> str:
    from .backend.script import code
    lines = []
    for path, value in options.items():
        if path == "timeIntegration.numberOfSteps":
            continue
        text = code(value) if path != "timeIntegration.endTime" else "t_end"
        lines.append(f"    simulationSettings.{path} = {text}")
    sensors = [f"{system.mech.solids[i].name!r}: {var}" for i, var in system.sensors.items()]
    return _SOLVE.format(options="\n".join(lines), sensors=_fill("{", sensors, "}"))


def _results(mech, system, q0) -> str:
    from .backend.script import code
    from .kinematics import pose
    solids = mech.solids
    fixed = [f"{solids[i].name!r}: {code(np.asarray(q0)[pose(i)])}"
             for i in sorted(system.grounded)]
    return _RESULTS.format(order=_fill("[", [repr(s.name) for s in solids], "]"),
                           fixed=_fill("{", fixed, "}"))


def _fill(opening: str, entries: list[str], closing: str) -> str:
    return textwrap.fill(opening + ", ".join(entries) + closing, 99 - 16,
                         subsequent_indent=" " * 4, break_long_words=False,
                         break_on_hyphens=False)

"""Export a model whose analysis is ``dynamic`` as a standalone Exudyn script of its motion.

The script (imports exudyn, numpy, csv and sys only) builds the system of the dynamic analysis
(``backend.exudyn.integrate``: masses, gravity, springs, dampers and loads, fixed solids as ground)
as commented blocks (``backend.exudyn.script.ScriptSystem``), starts it from the state the analysis
starts from (the assembly at t = 0 and the nearest consistent velocities, written as
numbers), drives the actuators at the integrator's time as the analysis does, integrates
with ``SolveDynamic`` (generalized-α, the analysis's settings) piece by piece as the
analysis does, each piece twice, with the step count the analysis needed and half of it,
extrapolates the two (Richardson) and writes x, y, fi of every solid as CSV. The pieces and
their step counts come from the analysis's own integration at export time
(``analyses.dynamic.motion``'s ``pieces``): one piece over the interval, or, where an
actuator's law has breakpoints inside it (the C1, C2 of ramp, bezier_c1, bezier_c2),
segments between them, cut where a breakpoint falls between output times.

At a breakpoint the script applies the contract's plastic impulse as the analysis does: the
velocities after it minimise (q̇⁺ − q̇⁻)ᵀ M (q̇⁺ − q̇⁻) under the new velocity equations,
with the mass matrix M and the constraint Jacobian C_q from Exudyn (``MainSolverStatic``'s
``ComputeMassMatrix`` and ``ComputeJacobianAE`` at that state) and the equations' right-hand
side from the laws' derivatives (``law_code.RATE_CODE``), as plain Python.
"""
from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np

from .law_code import LAW_CODE, RATE_CODE

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

# output times: t_k = k t_end / steps, k = 0 ... steps{grid}
t_end = {t_end!r}
steps = {steps!r}
every = {every!r}
times = np.linspace(0.0, t_end, steps * every + 1)

{pieces_comment}
pieces = {pieces}
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
initial = exu.ConfigurationType.Initial


def start_from(t, q, q_t):
    """Make q and q_t (Exudyn's ODE2 coordinates: x, y, fi of every moving solid, node by
    node, and their rates) at time t the initial state of the next SolveDynamic run."""
    mbs.systemData.SetODE2Coordinates(q, configuration=initial)
    mbs.systemData.SetODE2Coordinates_t(q_t, configuration=initial)
    # data coordinates (continued relative angles): on from where the last run ended
    mbs.systemData.SetDataCoordinates(mbs.systemData.GetDataCoordinates(),
                                      configuration=initial)
{start_drive}

def simulate(start, end, number_of_steps, intervals):
    """One SolveDynamic run of number_of_steps equal steps from the initial state at start
    to end: x, y, fi of every moving solid at the intervals + 1 equally spaced times from
    start to end, {{solid: array (intervals + 1, 3)}}, and q, q_t at the end."""
    simulationSettings = exu.SimulationSettings()
{options}
    simulationSettings.timeIntegration.startTime = start
    simulationSettings.timeIntegration.endTime = end
    simulationSettings.timeIntegration.numberOfSteps = number_of_steps
    mbs.SolveDynamic(simulationSettings, solverType=exu.DynamicSolverType.GeneralizedAlpha)
    every_step = number_of_steps // intervals  # a sensor stores a row per step, the first at start
    out = {{}}
    for solid, sensor in sensors.items():
        data = np.asarray(mbs.GetSensorStoredData(sensor))[::every_step]
        late = np.abs(data[:, 0] - np.linspace(start, end, intervals + 1)) if \\
            len(data) == intervals + 1 else np.inf
        if np.max(late) > 1e-6 * (end - start) / intervals:
            raise RuntimeError(f"Exudyn stopped early at t = {{data[-1, 0]:g}}")
        out[solid] = data[:, 1:4]
    return (out, np.array(mbs.systemData.GetODE2Coordinates()),
            np.array(mbs.systemData.GetODE2Coordinates_t()))

{impulse}
sensors = {sensors}
poses = {{solid: np.full((len(times), 3), np.nan) for solid in sensors}}
q = np.array(mbs.systemData.GetODE2Coordinates(configuration=initial))     # the nodes'
q_t = np.array(mbs.systemData.GetODE2Coordinates_t(configuration=initial))  # initial state
for start, end, rows, fine_steps, jump in pieces:
    start_from(start, q, q_t)
    intervals = max(1, len(rows))
    try:
        coarse, q_coarse, q_t_coarse = simulate(start, end, fine_steps // 2, intervals)
        fine, q_fine, q_t_fine = simulate(start, end, fine_steps, intervals)
    except Exception as error:
        print(f"Exudyn's dynamic solver stopped: {{error}}", file=sys.stderr)
        sys.exit(1)
    # Richardson: generalized-alpha's error is c h^2 + O(h^3), so (4 fine - coarse) / 3
    # cancels its h^2 term; the error left is the one the docstring's estimate bounds
    for solid in sensors:
        extrapolated = fine[solid] + (fine[solid] - coarse[solid]) / 3.0
        if start == 0.0:
            poses[solid][0] = extrapolated[0]                 # t = 0: the initial state
        poses[solid][rows] = extrapolated[1:len(rows) + 1]
    q = q_fine + (q_fine - q_coarse) / 3.0                    # the next piece starts here
    q_t = q_t_fine + (q_t_fine - q_t_coarse) / 3.0
    if jump:
        q_t = velocities_after(end, q, q_t)
'''

_IMPULSE = '''
# ---- law breakpoints: the velocities jump -------------------------------------------------
# At a breakpoint t_b of a law f' jumps, and with it the velocity equations C_q q_t + C_t = 0
# (C: the algebraic equations; an actuator's is C = g(q) - f(t), so its C_t = -f'(t), the
# others' 0). The velocities after it are those of an ideal plastic impulse (pam2exu's
# contract): the q_t+ nearest q_t- in the kinetic-energy norm, min (q_t+ - q_t-)^T M
# (q_t+ - q_t-), that meets the new equations, C_q q_t+ = -C_t(t_b+):
#     [ M    C_q^T ] [ q_t+ ]   [ M q_t-    ]
#     [ C_q  0     ] [ mu   ] = [ -C_t(t_b+) ]
# with the mass matrix M and the constraint Jacobian C_q = dC/dq from Exudyn at q.
{rates}
# each actuator's object (its algebraic equation) and the rate f'(t) of its law, the
# right-hand limit at a breakpoint
actuator_rates = {actuator_rates}


def velocities_after(t, q, q_t):
    """q_t+ after the breakpoint t, from q and q_t- there (see above)."""
    start_from(t, q, q_t)                 # Exudyn evaluates M and C_q at the initial state
    settings = exu.SimulationSettings()
    settings.solution.file.write = False
    settings.staticSolver.verboseMode = 0     # it only evaluates, it does not solve
    solver = exu.MainSolverStatic()
    solver.InitializeSolver(mbs, settings)
    n, m = solver.GetODE2size(), solver.GetAEsize()
    solver.ComputeMassMatrix(mbs)
    M = solver.GetSystemMassMatrix()[:n, :n]
    # the system Jacobian [[., C_q^T], [C_q, .]] of the algebraic equations (rows and columns
    # after the n ODE2 ones): ComputeJacobianAE adds to the stored matrix, which
    # InitializeSolver leaves unset (exudyn 1.13.6), so it starts from zeros
    solver.SetSystemJacobian(np.zeros((n + m, n + m)))
    solver.ComputeJacobianAE(mbs, scalarFactor_ODE2=1.0, scalarFactor_ODE2_t=0.0,
                             scalarFactor_ODE1=0.0, velocityLevel=False)
    C_q = solver.GetSystemJacobian()[n:, :n]
    solver.FinalizeSolver(mbs, settings)
    C_t = np.zeros(m)
    for obj, rate in actuator_rates:
        C_t[mbs.systemData.GetObjectLTGAE(obj)] = -rate(t)
    A = np.block([[M, C_q.T], [C_q, np.zeros((m, m))]])
    b = np.concatenate([M @ q_t, -C_t])
    return np.linalg.lstsq(A, b, rcond=None)[0][:n]     # least squares: redundant rows

'''

_RESULTS = '''
# ---- results: x, y, fi of every solid at every t_k, as CSV --------------------------------
solids = {order}
fixed_poses = {fixed}   # held by fixed links
with open(csv_file, "w", newline="", encoding="utf-8") as f:
    writer = csv.writer(f)
    writer.writerow(["t"] + [f"{{s}}.{{c}}" for s in solids for c in ("x", "y", "fi")])
    for k in range(0, len(times), every):
        pose = {{**fixed_poses, **{{s: poses[s][k] for s in poses}}}}
        writer.writerow([float(times[k])] + [float(c) + 0.0 for s in solids for c in pose[s]])
print(f"wrote {{steps + 1}} rows to {{csv_file}}")
'''


def dynamic_script(model, analysis: str, t_end=None, steps=None, file: str = "script.py",
                   **options) -> str | None:
    """The source of the dynamic script of a model (see the module), or None when every
    degree of freedom is driven (its positions are then the kinematic ones: the caller
    writes the positions script); ``analysis``: the name of the analysis integrating the
    motion, ``options`` its options (``registry.OPTIONS``: ``tolerance``).

    Raises every error of ``run(model, analysis="dynamic")``.
    """
    from .analyses.dynamic import motion, nearest_velocities, require_inertia
    from .analyses.job import check_mobility, prepare
    from .analyses.positions import GUESS_STIFFNESS, assemble
    from .backend.exudyn.integrate import settings
    from .backend.exudyn.script import ScriptSystem

    # the script is Exudyn's generalized-alpha: its pieces and steps from the Exudyn backend
    job = prepare(model, analysis, t_end, steps, POSITIONS, backend="exudyn", **options)
    mech, t = job.mech, job.times
    mob = check_mobility(job, mech.initial_q(), need_driven=False)
    if mob.dof == 0:
        return None
    # the analysis's own start and integration (``analyses.dynamic.dynamic``), its pieces kept
    q0 = assemble(job, mob.redundant > 0, GUESS_STIFFNESS)
    require_inertia(mech, float(t[0]), q0)
    qd0 = nearest_velocities(mech, float(t[0]), q0, mech.initial_qd())
    pieces: list = []
    motion(job, q0, qd0, pieces)
    system = ScriptSystem(mech, forces=True, velocity_forces=True, start=q0, start_rates=qd0,
                          ground_fixed=True)
    options = settings(mech, 0.0, float(t[-1]), 0)
    return (_header(mech, system, job, pieces, file) + _laws(system)
            + _SYSTEM + "\n".join(system.lines()) + _drive(system)
            + _solve(system, options, pieces) + _results(mech, system, q0))


def _header(mech, system, job, pieces: list, file: str) -> str:
    from .version import __version__
    from .backend.exudyn.integrate import SPECTRAL_RADIUS
    source = str(mech.model.source or "")
    jumps = sum(1 for *_, at_break in pieces if at_break)
    about = textwrap.fill(
        f"Exudyn model of the PAM mechanism '{mech.name}'"
        f"{f' ({Path(source).name})' if source and not source.startswith('<') else ''}, "
        f"exported\0by\0pam2exu\0{__version__} "
        "from its dynamic analysis. It builds the Exudyn system pam2exu integrates (masses, "
        "gravity, springs, dampers and loads; fixed solids as ground), starts it from the "
        "state the analysis starts from, integrates the motion for t = 0 ... t_end with "
        "Exudyn's SolveDynamic (generalized-alpha, index-3 constraints, spectral radius "
        f"{SPECTRAL_RADIUS:g}) piece by piece as the analysis did, each piece in fine_steps "
        "and in fine_steps / 2 steps, extrapolates the two (Richardson)"
        + (f", applies at the {jumps} law breakpoint{'s' if jumps > 1 else ''} the plastic "
           "impulse of pam2exu's contract (M and C_q from Exudyn)" if jumps else "")
        + " and writes x, y, fi of every solid at the output times as CSV.",
        92).replace("\0", " ")
    estimate, tolerance = float(job.info["integration_error"]), job.options["tolerance"]
    most = max(steps for _, _, steps, _ in pieces)
    accuracy = textwrap.fill(
        f"Accuracy: pam2exu's dynamic analysis asked for tolerance {tolerance:g} "
        "(the error of every coordinate and rate at most tolerance (1 + |value|), SI "
        "units). It halved its step until two successive Richardson extrapolations agreed "
        f"(Romberg), piece by piece (the most steps: {most}), and its error estimate is "
        f"{estimate:.2g} per unit of value. This script's result is that extrapolation, "
        "before the analysis's projection onto the constraints (a correction of the size "
        "of the error).", 92)
    items = textwrap.fill(", ".join(sorted(system.kinds)) + ")", 99,
                          initial_indent="from exudyn.itemInterface import (",
                          subsequent_indent="    ")
    times = job.times[::job.every]
    breaks = sorted({float(ts[-1]) for ts, _, _, at_break in pieces if at_break})
    segments = ("one piece over the interval" if len(pieces) == 1 else
                "segments between the laws' breakpoints at t = "
                + ", ".join(f"{b:g}" for b in breaks) + " s, where the velocities jump, "
                "cut where a breakpoint falls between output times"
                if breaks else "pieces")
    return _HEAD.format(title=f"{mech.name}: forward dynamics by Exudyn's SolveDynamic",
                        about=about, accuracy=accuracy, file=Path(file).name,
                        csv=f"{Path(file).stem}.csv", items=items, t_end=float(times[-1]),
                        steps=len(times) - 1, every=job.every, tolerance=tolerance,
                        grid=("" if job.every == 1 else
                              f"; the analysis integrates through {job.every} times as many "
                              "(times), the CSV keeps every every-th"),
                        pieces_comment=_comment(
                            f"integration pieces, as pam2exu's dynamic analysis integrated "
                            f"them at tolerance {tolerance:g}: {segments}, a piece's times "
                            "equally spaced. Each: start and end [s], the rows of times it "
                            "fills, the steps of the analysis's finest run over it (the "
                            "script runs it and the run with half as many, and extrapolates "
                            "the two, Richardson, as the analysis does), and whether its end "
                            "is a law breakpoint"
                            + (" (the velocities jump there: velocities_after)" if breaks
                               else "")),
                        pieces=_pieces_code(pieces))


def _comment(text: str) -> str:
    return textwrap.fill(text, 92, initial_indent="# ", subsequent_indent="# ",
                         break_on_hyphens=False)


def _pieces_code(pieces: list) -> str:
    """The pieces as a list literal, one per line: (start, end, rows, steps, jump)."""
    from .backend.exudyn.script import code
    lines = []
    for times, rows, steps, at_break in pieces:
        if rows and rows != list(range(rows[0], rows[-1] + 1)):
            raise AssertionError(f"the rows of a piece are not consecutive: {rows}")
        filled = f"range({rows[0]}, {rows[-1] + 1})" if rows else "range(0)"
        lines.append(f"    ({code(times[0])}, {code(times[-1])}, {filled}, {steps}, "
                     f"{at_break}),")
    return "[\n" + "\n".join(lines) + "\n]"


def _laws(system) -> str:
    laws = sorted({law.name for _, _, law, _ in system.drivers}, key=list(LAW_CODE).index)
    return _LAWS + "\n\n".join(LAW_CODE[name] for name in laws) if laws else ""


def _drive(system) -> str:
    """Offsets by user functions of t, distances by a pre-step function."""
    from .backend.exudyn.script import code, identifier
    if not system.drivers:
        return ""
    body, stepped = "", ""
    for (obj, par, law, shift), el in zip(system.drivers, system.driver_owners):
        anchors = ", ".join(f"anc{k + 1} = {a!r}" for k, a in enumerate(el.given_anchors()))
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



def _solve(system, options: dict, pieces: list) -> str:
    from .backend.exudyn.script import code
    lines = []
    for path, value in options.items():
        if path.split(".")[-1] in ("numberOfSteps", "startTime", "endTime"):
            continue
        lines.append(f"    simulationSettings.{path} = {code(value)}")
    sensors = [f"{system.mech.solids[i].name!r}: {var}" for i, var in system.sensors.items()]
    stepped = any(par != "offset" for _, par, _, _ in system.drivers)
    start_drive = ("    PreStepUserFunction(mbs, t)       # the actuators' distances at t\n"
                   if stepped else "")
    return _SOLVE.format(options="\n".join(lines), sensors=_fill("{", sensors, "}"),
                         start_drive=start_drive,
                         impulse=_impulse(system) if any(p[3] for p in pieces) else "")


def _impulse(system) -> str:
    """The rates of the laws and ``velocities_after`` (a model with law breakpoints)."""
    from .backend.exudyn.script import code
    laws = sorted({law.name for _, _, law, _ in system.drivers}, key=list(RATE_CODE).index)
    rates = [f"({obj}, lambda t: {law.name}_rate(t, {', '.join(code(c) for c in law.C)})),"
             for obj, _, law, _ in system.drivers]
    return _IMPULSE.format(rates="\n" + "\n\n".join(RATE_CODE[name] for name in laws),
                           actuator_rates="[\n" + "\n".join(f"    {r}" for r in rates)
                           + "\n]")


def _results(mech, system, q0) -> str:
    from .backend.exudyn.script import code
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

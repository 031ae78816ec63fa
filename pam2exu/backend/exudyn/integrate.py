"""Forward dynamics on Exudyn: the translated model with its masses and forces integrated
in time by ``SolveDynamic`` (the ``dynamic`` analysis, shared/spec/dynamics.md).

The system is the one of the static analyses (``ExudynSystem`` with the forces and the
dampers), its solids held by fixed links modelled as ground, started from given positions
and velocities. The actuators' constraints follow their laws at the integrator's own time:
an offset as a compiled symbolic function of t, a distance (which has no user function) set
by a pre-step function, which Exudyn calls with the time at the end of the step, where the
implicit integrator enforces the constraints (measured: the value at t + h instead made
the pendulum on a driven slider of tests/analyses/test_dynamic.py first-order accurate).
"""
from __future__ import annotations

import numpy as np

import exudyn as exu

from ...kinematics import pose
from ..base import Trajectory
from .symbolic import SymbolicNamespace
from .system import ExudynSystem

#: generalized-α's spectral radius at infinite frequency: 1 (no numerical damping)
#: diverged on a free four-bar with index-3 constraints (exudyn 1.13.6); 0.9 damps only
#: what the step cannot resolve, an error the step refinement of ``dynamic`` controls
SPECTRAL_RADIUS = 0.9


def settings(mech, start: float, end: float, steps: int, verbose: int = 0) -> dict:
    """The SimulationSettings of one run, {dotted path: value} (the exported dynamic
    script writes the same ones, ``export_dynamic``)."""
    return {
        "solution.file.write": False,
        "solution.sensors.writePeriod": 0.0,       # every step: rows picked by index
        "timeIntegration.startTime": start,
        "timeIntegration.endTime": end,
        "timeIntegration.numberOfSteps": steps,
        "timeIntegration.verboseMode": verbose,
        "timeIntegration.newton.relativeTolerance": 1e-12,
        "timeIntegration.newton.absoluteTolerance": 1e-14 * max(1.0, mech.scale()),
        "timeIntegration.newton.useModifiedNewton": False,
        "timeIntegration.adaptiveStep": False,
        "timeIntegration.generalizedAlpha.spectralRadius": SPECTRAL_RADIUS,
        "linearSolver.solverType": exu.LinearSolverType.EigenDense,
    }


def integrate(mech, times: np.ndarray, q0: np.ndarray, qd0: np.ndarray, substeps: int,
              verbose: int = 0) -> Trajectory:
    """x, y, fi and their rates at ``times`` (equally spaced, times[0] the start), by
    Exudyn's ``SolveDynamic`` (generalized-α, index-3 constraints, ``SPECTRAL_RADIUS``)
    with ``substeps`` equal steps per interval, from (q0, q̇0)."""
    times = np.asarray(times, dtype=float)
    n = len(times)
    if n < 2:
        return Trajectory(np.asarray(q0, float)[None], np.asarray(qd0, float)[None], 0)
    system = ExudynSystem(mech, forces=True, velocity_forces=True, start=q0, start_rates=qd0,
                          ground_fixed=True)
    mbs = system.mbs
    keep = _drive(system, float(times[0]))
    sensors = {i: mbs.AddSensor(exu.itemInterface.SensorNode(
        nodeNumber=node, storeInternal=True, writeToFile=False,
        outputVariableType=exu.OutputVariableType.Coordinates_t))
        for i, node in enumerate(system.nodes) if node is not None}
    mbs.Assemble()
    ss = exu.SimulationSettings()
    for path, value in settings(mech, float(times[0]), float(times[-1]),
                                (n - 1) * substeps, verbose).items():
        *parents, leaf = path.split(".")
        target = ss
        for name in parents:
            target = getattr(target, name)
        setattr(target, leaf, value)
    error = None
    exu.config.printToConsole = verbose > 0
    try:
        mbs.SolveDynamic(ss, solverType=exu.DynamicSolverType.GeneralizedAlpha)
    except Exception as exc:          # Exudyn raises a bare RuntimeError/ValueError
        error = str(exc) or type(exc).__name__
    finally:
        exu.config.printToConsole = False
    del keep
    q = np.full((n, mech.nq), np.nan)
    qd = np.full((n, mech.nq), np.nan)
    start = np.asarray(q0, dtype=float)
    for i in system.grounded:
        q[:, pose(i)] = start[pose(i)]
        qd[:, pose(i)] = 0.0
    for i, sensor in system.sensors.items():
        _rows(q, mbs.GetSensorStoredData(sensor), i, times, substeps)
        _rows(qd, mbs.GetSensorStoredData(sensors[i]), i, times, substeps)
    if error is None and not np.isfinite(q).all():
        error = "Exudyn's dynamic solver stopped early"
    return Trajectory(q, qd, (n - 1) * substeps, error)


def _rows(out: np.ndarray, data, solid: int, times: np.ndarray, substeps: int) -> None:
    """Fill a solid's three columns of ``out`` at the output times from a sensor's rows
    (one per step, the first the initial state), where their times match."""
    data = np.asarray(data)
    if data.ndim != 2 or len(data) == 0:
        return
    picked = data[::substeps][:len(times)]
    h = (times[-1] - times[0]) / ((len(times) - 1) * substeps)
    ok = np.abs(picked[:, 0] - times[:len(picked)]) <= 1e-6 * h
    rows = np.nonzero(ok)[0]
    out[rows, pose(solid)] = picked[rows, 1:4]


def _offset(law, shift: float):
    """f(t) + shift as an offset user function (Exudyn checks its four arguments)."""
    def offset(mbs, t, itemNumber, lOffset):
        return law(t, xp=SymbolicNamespace)[0] + shift
    return offset


def _drive(system: ExudynSystem, t0: float) -> list:
    """Make every actuator follow its law at the integrator's time; returns what must be
    kept alive while it runs (the compiled functions)."""
    from exudyn.advancedUtilities import CreateSymbolicUserFunction

    mbs, keep, stepped = system.mbs, [], []
    for obj, parameter, law, shift in system.drivers:
        if parameter != "offset":
            stepped.append((obj, parameter, law, shift))
            continue
        function = CreateSymbolicUserFunction(mbs, _offset(law, shift), "offsetUserFunction",
                                              obj)
        mbs.SetObjectParameter(obj, "offsetUserFunction", function)
        keep.append(function)
    if stepped:
        for obj, parameter, law, shift in stepped:        # the initial value
            mbs.SetObjectParameter(obj, parameter, law.value(t0) + shift)

        def pre_step(mbs, t):
            for obj, parameter, law, shift in stepped:
                mbs.SetObjectParameter(obj, parameter, law.value(t) + shift)
            return True

        mbs.SetPreStepUserFunction(pre_step)
        keep.append(pre_step)
    return keep

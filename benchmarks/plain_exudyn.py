"""The four-bar's position solve written by hand in plain Exudyn, to time pam2exu against.

``plain_exudyn_four_bar`` builds examples/four_bar.toml's three moving links directly with
Exudyn's items (``NodeRigidBody2D``, ``ObjectRigidBody2D``, ``ObjectJointRevolute2D``, the
crank's angle driven by an ``ObjectConnectorCoordinate``) and solves it with the static
solver and the settings pam2exu uses, so that section 2 of docs/performance.md compares like
with like. Nothing of pam2exu is used here.
"""
from __future__ import annotations

import math
import time

import exudyn as exu
import numpy as np
from exudyn import itemInterface as items

TWO_PI = 2.0 * math.pi


def plain_exudyn_four_bar(steps, tolerance, driver, count_iterations=False):
    """The four-bar's position solve (examples/four_bar.toml, θ = 2π t, 1 s) written
    directly in Exudyn, with the settings pam2exu uses: one static load step per time
    t_k = k/steps (k = 0 … steps; load step k + 1 solves t_k), Newton tolerance
    ``tolerance`` × 0.4 m (not below the round-off floor 16 ε · max|θ|), dense solver,
    sensors storing the node coordinates.

    driver: "prestep" (the crank's ConnectorCoordinate offset set by a Python
    PreStepUserFunction) or "symbolic" (an exudyn.symbolic offsetUserFunction).
    Returns (q (steps + 1, 9), seconds to build + solve + read, seconds of the solve,
    (Newton iterations, Jacobians) per step with ``count_iterations``, else None).
    """
    start = time.perf_counter()
    a, b, c, d = 0.1, 0.35, 0.3, 0.4
    omega, dt, n = TWO_PI, 1.0 / steps, steps + 1
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    ground = mbs.AddObject(items.ObjectGround())
    nodes, bodies = [], []
    for q0 in ([0.0, 0.0, 0.02], [0.11, 0.01, 0.9], [0.4, 0.0, 1.85]):   # the example's guesses
        node = mbs.AddNode(items.NodeRigidBody2D(referenceCoordinates=[0.0, 0.0, 0.0],
                                                 initialCoordinates=q0))
        nodes.append(node)
        bodies.append(mbs.AddObject(items.ObjectRigidBody2D(nodeNumber=node, mass=0.0,
                                                            inertia=0.0)))
    crank, coupler, rocker = bodies

    def marker(body_, x, y=0.0):
        return mbs.AddMarker(items.MarkerBodyRigid(bodyNumber=body_, localPosition=[x, y, 0.0]))

    for m1, m2 in ((marker(ground, 0.0), marker(crank, 0.0)),
                   (marker(crank, a), marker(coupler, 0.0)),
                   (marker(coupler, b), marker(rocker, c)),
                   (marker(ground, d), marker(rocker, 0.0))):
        mbs.AddObject(items.ObjectJointRevolute2D(markerNumbers=[m1, m2]))
    ground_node = mbs.AddNode(items.NodePointGround())
    m_ground = mbs.AddMarker(items.MarkerNodeCoordinate(nodeNumber=ground_node, coordinate=0))
    m_fi = mbs.AddMarker(items.MarkerNodeCoordinate(nodeNumber=nodes[0], coordinate=2))
    drive = mbs.AddObject(items.ObjectConnectorCoordinate(markerNumbers=[m_ground, m_fi]))
    sensors = [mbs.AddSensor(items.SensorNode(nodeNumber=node, storeInternal=True,
                                              writeToFile=False,
                                              outputVariableType=exu.OutputVariableType.Coordinates))
               for node in nodes]
    symbolic = None
    if driver == "prestep":
        def pre_step(mbs, t):
            mbs.SetObjectParameter(drive, "offset", omega * (t - dt))
            return True
        mbs.SetPreStepUserFunction(pre_step)
    else:
        from exudyn.advancedUtilities import CreateSymbolicUserFunction

        def offset(mbs, t, itemNumber, lOffset):
            return omega * (t - dt)
        symbolic = CreateSymbolicUserFunction(mbs, offset, "offsetUserFunction", drive)
        mbs.SetObjectParameter(drive, "offsetUserFunction", symbolic)
    mbs.Assemble()
    ss = exu.SimulationSettings()
    ss.solution.file.write = False
    ss.solution.sensors.writePeriod = 0.0
    ss.staticSolver.verboseMode = 0
    ss.staticSolver.useLoadFactor = False
    ss.staticSolver.numberOfLoadSteps = n
    ss.staticSolver.loadStepDuration = n * dt
    ss.staticSolver.newton.absoluteTolerance = max(tolerance * d,
                                                   16 * np.finfo(float).eps * omega)
    ss.staticSolver.newton.relativeTolerance = tolerance
    ss.linearSolver.solverType = exu.LinearSolverType.EigenDense
    exu.config.printToConsole = False
    solve_start = time.perf_counter()
    iterations = None
    if count_iterations:
        solver = exu.MainSolverStatic()
        solver.SolveSystem(mbs, ss)
        iterations = (solver.it.newtonStepsCount / n, solver.it.newtonJacobiCount / n)
    else:
        mbs.SolveStatic(ss)
    solve_seconds = time.perf_counter() - solve_start
    q = np.hstack([np.asarray(mbs.GetSensorStoredData(s))[1:, 1:4] for s in sensors])
    del symbolic
    return q, time.perf_counter() - start, solve_seconds, iterations

"""What Exudyn's static solver is told: pam2exu's settings of the position solve
(``SolveSettings``) and the ``SimulationSettings`` they make (``solver_options``), with the
round-off floor's largest angle coefficient (``angle_gain``)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

import exudyn as exu

from ...kinematics import State

#: Exudyn's dense linear solver up to this many coordinates, the sparse one above (measured:
#: sparse is faster from 27–51 coordinates on, 14× faster at 300; docs/performance.md)
DENSE_UP_TO = 40
#: Exudyn's static solver may cut a load step that fails into smaller ones: not below this
#: fraction of a step (bounds the work of a step that cannot be solved)
MIN_STEP_FRACTION = 1.0 / 64


@dataclass
class SolveSettings:
    """Settings of Exudyn's static (position) solver.

    Parameters
    ----------
    tolerance : float
        Newton's absolute tolerance on the constraint residual, relative to the
        mechanism's length scale (never below the round-off floor, ``ExudynSystem.roundoff``).
    max_iterations : int
        Newton iterations per step before Exudyn subdivides the step.
    dense : bool | None
        Dense linear solver (None: dense up to DENSE_UP_TO coordinates, sparse above).
    verbose : int
        Exudyn's solver output (0: quiet).
    predictor : bool | str
        True: start each step's Newton iteration from the quadratic extrapolation of the
        last three solved steps (``extrapolate``) instead of the previous step's solution:
        one Newton iteration per step instead of two on smooth motions, for a Python call
        per step (docs/performance.md). False: from the previous step's solution. "auto"
        (the default): a run of ``PROBE_FROM`` steps or more first times blocks of steps
        each way (``predictor.Probe``) and goes on with the predictor only if its steps
        were clearly the faster (``predictor.predictor_pays``); shorter runs predict.
        Not used with redundant constraints, which Exudyn solves with a singular Jacobian:
        there one iteration from the prediction can stop on the tolerance with a position
        error of ~5e-12 rad after a change point (the redundant parallelogram), where two
        from the previous step reach round-off.
    modified_newton : bool
        True (the default): a run's steps by Exudyn's modified Newton (one Jacobian per
        step, reused by its further iterations; the same positions to the tolerance); False:
        full Newton (a Jacobian per iteration). One time alone (an assembly, from a guess),
        redundant constraints and a run whose round-off floor is above the tolerance (angles
        of many turns: modified Newton would stop at the floor, full Newton's last iteration
        goes below it) always use full Newton (``modified_newton``).
    """

    tolerance: float = 1e-13
    max_iterations: int = 25
    dense: bool | None = None
    verbose: int = 0
    predictor: bool | str = "auto"
    modified_newton: bool = True


def angle_gain(mech) -> float:
    """max(1, |∂C/∂fi|) over the constraint Jacobian at the model's x, y, fi: the largest
    angle coefficient of the equations (a gear ratio, a lever arm), for ``roundoff``."""
    st = State([0.0], mech.initial_q()[None])
    return max([1.0, *(float(np.max(np.abs(block[..., 2])))
                       for el in mech.constraints
                       for block in el.constraint(st)[0].jac.values())])


def modified_newton(settings: SolveSettings, redundant: bool, run: bool, roundoff: float,
                    scale: float) -> bool:
    """asked ∧ a run (not one time) ∧ not redundant ∧ roundoff ≤ tolerance · scale."""
    return (bool(settings.modified_newton) and run and not redundant
            and roundoff <= settings.tolerance * scale)


def solver_options(mech, settings: SolveSettings, redundant: bool,
                   roundoff: float = 0.0, run: bool = True) -> dict:
    """The SimulationSettings that differ from Exudyn's defaults, {dotted path: value}.

    roundoff: the residual floor of ``ExudynSystem.roundoff`` (a lower bound of the
    absolute tolerance); run: a run of steps (False: one time alone, e.g. an assembly).
    """
    dense = settings.dense if settings.dense is not None else mech.nq <= DENSE_UP_TO
    options = {
        "solution.file.write": False,
        "solution.sensors.writePeriod": 0.0,
        "staticSolver.useLoadFactor": False,       # loads in full at every step, no ramp
        "staticSolver.verboseMode": settings.verbose,
        "staticSolver.newton.absoluteTolerance": max(settings.tolerance * mech.scale(),
                                                     roundoff),
        "staticSolver.newton.relativeTolerance": settings.tolerance,
        "staticSolver.newton.maxIterations": settings.max_iterations,
    }
    if modified_newton(settings, redundant, run, roundoff, mech.scale()):
        options["staticSolver.newton.useModifiedNewton"] = True
        options["staticSolver.newton.modifiedNewtonJacUpdatePerStep"] = True
    if redundant:
        dense = True
        options["linearSolver.ignoreSingularJacobian"] = True
    options["linearSolver.solverType"] = (exu.LinearSolverType.EigenDense if dense
                                          else exu.LinearSolverType.EigenSparse)
    return options

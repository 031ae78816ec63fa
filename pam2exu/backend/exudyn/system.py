"""Translate a mechanism into an Exudyn system and solve its positions over time.

Each solid becomes a ``NodeRigidBody2D`` (reference coordinates 0, initial coordinates
x, y, fi, so node coordinates read PAM's values) with an ``ObjectRigidBody2D``. Each
element adds its own items through ``Element.build(system)``, using the helpers below.
Positions over time come from Exudyn's static solver, one load step per time step;
actuators follow their laws through a pre-step function.

The same construction also writes a standalone script (``backend.exudyn.script.ScriptSystem``):
items are created only through ``self.mbs`` and ``self.items``, and ``begin`` marks where
the items of each solid and element start.
"""
from __future__ import annotations

import logging
import time
from dataclasses import replace

import numpy as np

import exudyn as exu
from exudyn import itemInterface as items

from ...kinematics import column, pose
from .settings import (DENSE_UP_TO, MIN_STEP_FRACTION, SolveSettings,  # noqa: F401
                       angle_gain, modified_newton, solver_options)
from .predictor import PROBE_FROM, PROBE_STEPS, Predictor, Probe, extrapolate  # noqa: F401
from .symbolic import ON_GRID, offset_function

log = logging.getLogger("pam2exu")


class ExudynSystem:
    """The Exudyn system of one mechanism for one analysis.

    Parameters
    ----------
    mech : Mechanism
    forces : bool
        Build masses, gravity and force elements (False: constraints only, for kinematics).
    velocity_forces : bool
        Include dampers' velocity terms (False for quasi-static analysis).
    anchor_stiffness : float
        If > 0, tie every coordinate to its start value (``start``) by a spring of this
        stiffness (per m², and per rad² times the length scale²): the assembled
        configuration is then the one nearest to the start when degrees of freedom are
        left free.
    start : array, optional
        x, y, fi of every solid to start Newton's iteration from (default: the solids'
        x, y, fi in the model); used to restart a run part-way.
    start_rates : array, optional
        Their rates at the start (initial velocities of a time integration; default 0).
    ground_fixed : bool
        Model a solid held by a fixed link as Exudyn ground also with the forces (a time
        integration, whose fixed links' reactions come from the native pass).
    """

    items = items
    #: the predictor's probe's clock (``predictor.Probe``): this thread's CPU time
    clock = staticmethod(time.thread_time)

    def __init__(self, mech, forces: bool = False, velocity_forces: bool = True,
                 anchor_stiffness: float = 0.0, start=None, start_rates=None,
                 ground_fixed: bool = False, angle_gain: float | None = None):
        exu.config.printToConsole = False
        self.mech = mech
        #: the mechanism's ``angle_gain`` when already known (None: computed when needed)
        self.angle_gain = angle_gain
        self.forces, self.velocity_forces = forces, velocity_forces
        self.mbs = mbs = self.new_system()
        items = self.items
        # constraints-only systems model a solid held by a fixed link as Exudyn ground at
        # its pose: fewer coordinates and equations (the fixed link's reaction is not
        # needed from Exudyn then)
        self.grounded = set() if forces and not ground_fixed else set(mech.held)
        self.nodes, self.bodies = [], []
        self.start = mech.initial_q() if start is None else np.asarray(start, dtype=float)
        rates = None if start_rates is None else np.asarray(start_rates, dtype=float)
        for i, s in enumerate(mech.solids):
            self.begin(s)
            x, y, fi = (float(v) for v in self.start[pose(i)])
            if i in self.grounded:
                c, sn = np.cos(fi), np.sin(fi)
                self.nodes.append(None)
                self.bodies.append(mbs.AddObject(items.ObjectGround(
                    referencePosition=[x, y, 0.0],
                    referenceRotation=[[c, -sn, 0.0], [sn, c, 0.0], [0.0, 0.0, 1.0]])))
                continue
            node = mbs.AddNode(items.NodeRigidBody2D(
                referenceCoordinates=[0.0, 0.0, 0.0], initialCoordinates=[x, y, fi],
                **({} if rates is None else
                   {"initialVelocities": [float(v) for v in rates[pose(i)]]})))
            mass, inertia = (float(s.mass), float(s.inertia)) if forces else (0.0, 0.0)
            gx, gy = (float(c) for c in s.cog)
            self.nodes.append(node)
            # Exudyn's inertia is about the node (the frame origin), G is centerOfMass
            self.bodies.append(mbs.AddObject(items.ObjectRigidBody2D(
                nodeNumber=node, mass=mass, inertia=inertia + mass * (gx * gx + gy * gy),
                centerOfMass=[gx, gy] if forces else [0.0, 0.0])))
        self._markers: dict = {}
        self._ground = None
        self.drivers: list = []          # (object, parameter, law, shift)
        self.stepped: list = []          # the drivers set by a Python pre-step function
        self.objects: dict[str, list] = {el.name: [] for el in mech.elements}
        for el in mech.elements:
            self.begin(el)
            if self.builds(el):
                el.build(self)
        if forces and mech.gravity:
            self.begin("gravity")
            for s, body in zip(mech.solids, self.bodies):
                if float(s.mass) > 0:
                    marker = mbs.AddMarker(items.MarkerBodyMass(bodyNumber=body))
                    mbs.AddLoad(items.LoadMassProportional(
                        markerNumber=marker, loadVector=[0.0, -mech.gravity, 0.0]))
        if anchor_stiffness > 0:
            L2 = mech.scale() ** 2
            q0 = self.start
            for i in range(len(mech.solids)):
                for k in range(3 if i not in self.grounded else 0):
                    mbs.AddObject(items.ObjectConnectorCoordinateSpringDamper(
                        markerNumbers=[self.ground_coordinate(), self.coordinate_marker(i, k)],
                        stiffness=anchor_stiffness * (L2 if k == 2 else 1.0),
                        offset=float(q0[column(i, k)])))
        self.begin("sensors")
        self.sensors = {i: mbs.AddSensor(items.SensorNode(
            nodeNumber=n, storeInternal=True, writeToFile=False,
            outputVariableType=exu.OutputVariableType.Coordinates))
            for i, n in enumerate(self.nodes) if n is not None}
        mbs.Assemble()

    def new_system(self):
        """The Exudyn MainSystem the items go into."""
        self.SC = exu.SystemContainer()
        return self.SC.AddSystem()

    def begin(self, owner) -> None:
        """Called before the items of each solid and element (and of "gravity" and the
        "sensors") are added; the script exporter writes a comment there."""

    def builds(self, element) -> bool:
        """Whether the element adds Exudyn items to this system: force elements only to
        force systems, and a fixed link not when its solid is modelled as ground."""
        return bool(element.equations or self.forces) and not (
            element.grounds and element.holds in self.grounded)

    # ---- helpers for Element.build ---------------------------------------------------------
    def add(self, element, item, kind: str = "object"):
        """Add an object (or a load, kind='load') for an element; returns its index."""
        index = self.mbs.AddLoad(item) if kind == "load" else self.mbs.AddObject(item)
        self.objects[element.name].append((kind, index))
        return index

    def point_marker(self, ref):
        """MarkerBodyRigid at a point (PointRef, a LineRef's defining point, a SolidRef's origin)."""
        local = ref.anchor_point
        key = ("point", ref.solid, tuple(local))
        if key not in self._markers:
            self._markers[key] = self.mbs.AddMarker(self.items.MarkerBodyRigid(
                bodyNumber=self.bodies[ref.solid], localPosition=[local[0], local[1], 0.0]))
        return self._markers[key]

    def coordinate_marker(self, solid: int, k: int):
        """MarkerNodeCoordinate on x (0), y (1) or fi (2) of a solid.

        On a grounded solid it reads 0, not the pose: see ``coordinate_shift``.
        """
        if solid in self.grounded:
            return self.ground_coordinate()
        key = ("coordinate", solid, k)
        if key not in self._markers:
            self._markers[key] = self.mbs.AddMarker(self.items.MarkerNodeCoordinate(
                nodeNumber=self.nodes[solid], coordinate=k))
        return self._markers[key]

    def coordinate_shift(self, solid: int, k: int) -> float:
        """Coordinate value minus what its ``coordinate_marker`` reads (the pose if grounded)."""
        if solid in self.grounded:
            s = self.mech.solids[solid]
            return float((s.x, s.y, s.fi)[k])
        return 0.0

    def ground_coordinate(self):
        """A coordinate marker on a ground node (value 0)."""
        if self._ground is None:
            node = self.mbs.AddNode(self.items.NodePointGround())
            self._ground = self.mbs.AddMarker(self.items.MarkerNodeCoordinate(
                nodeNumber=node, coordinate=0))
        return self._ground

    def relative_rotation_marker(self, reference: int, solid: int):
        """fi_solid − fi_reference, continued past ±π by a NodeGenericData."""
        fi0, fi1 = self.start[column(reference, 2)], self.start[column(solid, 2)]
        data = self.mbs.AddNode(self.items.NodeGenericData(
            numberOfDataCoordinates=1, initialCoordinates=[float(fi1 - fi0)]))
        return self.mbs.AddMarker(self.items.MarkerBodiesRelativeRotationCoordinate(
            bodyNumbers=[self.bodies[reference], self.bodies[solid]], nodeNumber=data,
            axis0=[0.0, 0.0, 1.0]))

    def drive(self, obj, parameter: str, law, shift: float = 0.0) -> None:
        """Make an object's parameter follow f(t) + shift during position solves."""
        self.drivers.append((obj, parameter, law, shift))

    def ae_rows(self, element) -> list[int]:
        """Exudyn's AE (multiplier) indices of an element, in the order of its native rows.

        A pin_slot's ObjectJointPrismatic2D without rotation keeps a second, unused
        multiplier (always 0): it is left out.
        """
        rows = [i for kind, obj in self.objects[element.name] if kind == "object"
                for i in self.mbs.systemData.GetObjectLTGAE(obj)]
        return rows[:element.equations]

    # ---- solving ---------------------------------------------------------------------------
    def coordinates(self) -> np.ndarray:
        """Current x, y, fi of every solid (grounded ones at their pose)."""
        q = self.mech.initial_q()
        ode2 = np.asarray(self.mbs.systemData.GetODE2Coordinates())
        k = 0
        for i, node in enumerate(self.nodes):
            if node is not None:
                q[pose(i)] = ode2[k:k + 3]
                k += 3
        return q

    def roundoff(self, times) -> float:
        """The residual below which Newton cannot go: 16 ulps of the largest equation term.

        Angles are never wrapped, so the angle equations (actuators, transmissions) add up
        terms that grow with every turn: about the largest |q0| or law value over the run,
        times the largest angle coefficient of the constraint Jacobian (``angle_gain``).
        """
        q0 = self.mech.initial_q()
        gain = angle_gain(self.mech) if self.angle_gain is None else self.angle_gain
        size = max([1.0, *np.abs(q0), *(float(np.max(np.abs(law(times)[0] + shift)))
                                        for *_, law, shift in self.drivers)])
        return 16.0 * np.finfo(float).eps * size * gain

    def simulation_settings(self, settings: SolveSettings, redundant: bool,
                            roundoff: float = 0.0, run: bool = True):
        """Exudyn's SimulationSettings with ``solver_options`` applied."""
        ss = exu.SimulationSettings()
        for path, value in solver_options(self.mech, settings, redundant, roundoff,
                                          run).items():
            *parents, leaf = path.split(".")
            target = ss
            for name in parents:
                target = getattr(target, name)
            setattr(target, leaf, value)
        return ss

    def solve_positions(self, times: np.ndarray, settings: SolveSettings | None = None,
                        redundant: bool = False,
                        multipliers: bool = False) -> tuple[np.ndarray, int]:
        """Positions at times t_k = k·dt (k = k0…k0+n−1, equally spaced), one static load
        step each, from the start configuration.

        Returns (q, n_solved): q has a row per time; when Exudyn stops early, the rows
        after n_solved are NaN. ``self.newton_iterations``: Newton iterations in all. With
        ``multipliers``, Exudyn's Lagrange multipliers of every step are kept in
        ``self.multipliers`` (n, AE size); in the static solver they satisfy
        f + Cqᵀ λ = 0, f the applied generalized forces.

        Exudyn's load step k ≥ 1 is solved at time k·dt; the laws are evaluated one
        step earlier, so load step k gives time t_{k−1} (``loadStepStart`` cannot be < 0).

        A run that modified Newton leaves unsolved is solved again by full Newton: Exudyn
        does not restart a step whose second iteration diverges (at a change point, where
        full Newton's still converges, linearly).
        """
        settings = settings or SolveSettings()
        q, solved = self._solve_positions(times, settings, redundant, multipliers)
        if solved < len(q) and self.modified:
            spent = self.newton_iterations
            q, solved = self._solve_positions(times, replace(settings, modified_newton=False),
                                              redundant, multipliers)
            self.newton_iterations += spent
        return q, solved

    def _solve_positions(self, times, settings: SolveSettings, redundant: bool,
                         multipliers: bool) -> tuple[np.ndarray, int]:
        """``solve_positions`` with the given settings."""
        times = np.asarray(times, dtype=float)
        n = len(times)
        self.error, self.multipliers, self.newton_iterations = None, None, 0
        self.predicted = self.modified = False
        if not self.sensors:                     # every solid is fixed: nothing to solve
            return np.tile(self.mech.initial_q(), (n, 1)), n
        # one time alone (an assembly, a restart at the last step) is step k0 = 1 of a grid
        # of spacing t (or 1 s at t = 0). The spacing over the whole span: times[1] − times[0]
        # of a grid that starts late (a part of a long run, a restart) is off by an ulp of
        # t, which k·dt multiplies (6.5e-17 s × 1e5 steps: 4e-9 rad at 628 rad/s)
        dt = float(times[-1] - times[0]) / (n - 1) if n > 1 else (float(times[0]) or 1.0)
        k0 = int(round(times[0] / dt))          # global index of the first step
        tables = [(obj, par, law, shift, law(times)[0] + shift)
                  for obj, par, law, shift in self.drivers]
        mbs = self.mbs
        # connector offsets follow their law as compiled symbolic functions; a distance
        # (ObjectConnectorDistance has no user function) by a Python pre-step function, and
        # so does an offset whose symbolic function Exudyn cannot build (logged: slower)
        self._symbolic, self.stepped = [], []
        for table in tables:
            obj, par, law, shift, _ = table
            if par != "offset":
                self.stepped.append(table)
                continue
            try:
                function = offset_function(mbs, obj, law, shift, dt)
            except Exception as exc:       # Exudyn's symbolic module raises several kinds
                log.warning("the law %s of Exudyn object %s could not be compiled as a "
                            "symbolic user function (%s: %s): it is set by a Python "
                            "pre-step function instead, which is slower",
                            law.name, obj, type(exc).__name__, exc)
                self.stepped.append(table)
                continue
            mbs.SetObjectParameter(obj, "offsetUserFunction", function)
            self._symbolic.append(function)
        if self._symbolic:
            mbs.Assemble()

        predict = (Predictor(mbs.systemData) if settings.predictor and n > 3 and not redundant
                   else None)
        probe = None
        if predict is not None and settings.predictor == "auto" and n >= PROBE_FROM:
            probe = Probe(predict, self.clock)
        self.predicted = predict is not None

        def pre_step(mbs, t):
            tau = t - dt
            k = int(round(tau / dt)) - k0
            on_grid = 0 <= k < n and abs(tau - (k + k0) * dt) <= ON_GRID * dt
            for obj, par, law, shift, values in self.stepped:
                mbs.SetObjectParameter(obj, par, float(values[k]) if on_grid
                                       else law.value(tau) + shift)
            if guess is not None:
                guess(k if on_grid else None)
            return True

        if multipliers:
            lam = self.multipliers = np.full((n, mbs.systemData.AEsize()), np.nan)
            get = mbs.systemData.GetAECoordinates

            def post_step(mbs, t):
                k = int(round(t / dt)) - 1 - k0
                if 0 <= k < n:
                    lam[k] = get()
                return True

            mbs.SetPostStepUserFunction(post_step)
        ss = self.simulation_settings(settings, redundant, self.roundoff(times), run=n > 1)
        self.modified = ss.staticSolver.newton.useModifiedNewton
        # where Newton fails, Exudyn retries with smaller steps: at most MIN_STEP_FRACTION
        # of a step (its default, 1e-8 s, lets a long step be cut into ~1e15 pieces)
        ss.staticSolver.minimumStepSize = MIN_STEP_FRACTION * dt
        q = np.full((n, self.mech.nq), np.nan)
        done, error = 0, None
        if probe is not None:
            # the probe's steps first (the predictor in some blocks, not in others, each
            # step timed), then the rest from where it stopped, with the predictor only if
            # its steps were the faster
            guess = probe
            error = self._static_steps(ss, q, 0, PROBE_STEPS, k0, dt, pre_step, settings)
            done = PROBE_STEPS
            self.predicted = probe.pays()
        if error is None and done < n:
            guess = predict if self.predicted else None
            sd, initial = mbs.systemData, None
            if done:                  # go on from the probe's last step
                initial = sd.GetSystemState(exu.ConfigurationType.Initial)
                sd.SetSystemState(sd.GetSystemState(), exu.ConfigurationType.Initial)
            error = self._static_steps(ss, q, done, n - done, k0, dt,
                                       pre_step if self.stepped or guess else None, settings)
            if initial is not None:
                sd.SetSystemState(initial, exu.ConfigurationType.Initial)
        solved = int(np.argmin(np.isfinite(q).all(axis=1))) if not np.isfinite(q).all() else n
        if error is None and solved < n:
            error = RuntimeError("the static solver stopped early")
        self.error = error
        return q, solved

    def _static_steps(self, ss, q, first: int, count: int, k0: int, dt: float, pre_step,
                      settings: SolveSettings):
        """Solve the load steps of rows first … first+count−1 of q (times (k0 + row)·dt) in
        one SolveStatic from the initial configuration, with ``pre_step`` (None: no pre-step
        function), into q's rows; adds to ``self.newton_iterations``; returns Exudyn's
        exception or None."""
        mbs = self.mbs
        mbs.SetPreStepUserFunction(pre_step if pre_step is not None else 0)
        ss.staticSolver.numberOfLoadSteps = count
        ss.staticSolver.loadStepStart = (k0 + first) * dt
        ss.staticSolver.loadStepDuration = count * dt
        error = None
        exu.config.printToConsole = settings.verbose > 0
        try:
            mbs.SolveStatic(ss)
        except Exception as exc:  # Exudyn raises a bare RuntimeError/ValueError on failure
            error = exc
        finally:
            exu.config.printToConsole = False
        solver = mbs.sys.get("staticSolver")      # SolveStatic keeps it (storeSolver=True)
        self.newton_iterations += int(solver.it.newtonStepsCount) if solver else 0
        data = {i: np.asarray(mbs.GetSensorStoredData(s)) for i, s in self.sensors.items()}
        sample = next(iter(data.values()), None)
        if sample is not None and len(sample) > 1:
            t_rows = sample[1:, 0] - dt          # row 0 is the unsolved initial state
            k_rows = np.rint(t_rows / dt).astype(int)
            on_grid = np.abs(t_rows - k_rows * dt) <= ON_GRID * dt
            k_rows -= k0
            on_grid &= (k_rows >= first) & (k_rows < first + count)
            for i, d in data.items():
                q[k_rows[on_grid], pose(i)] = d[1:, 1:4][on_grid]
            for i in self.grounded:
                q[k_rows[on_grid], pose(i)] = self.mech.initial_q()[pose(i)]
        return error

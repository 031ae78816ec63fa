"""The Exudyn backend: each solve translates the mechanism (``ExudynSystem``) and runs
Exudyn's static solver, one load step per time.

The package is the only code that imports exudyn: the translation (``system``), the time
laws compiled to Exudyn symbolic functions (``symbolic``), the standalone script writer
(``script``, ``pam2exu export``) and the time integration of the dynamic analysis
(``integrate``).
"""
from __future__ import annotations

import numpy as np

from ..base import Backend, Integrator, Positions
from .system import ExudynSystem, SolveSettings, angle_gain


class Exudyn(Backend):
    """``Backend`` on Exudyn's static solver (``registry.BACKENDS['exudyn']``)."""

    name = "exudyn"
    label = "Exudyn"
    solver_name = "Exudyn's static solver"
    Settings = SolveSettings
    gives_rates = False
    moves_free_solids = True
    integrator = Integrator.FIXED_STEP
    integrator_name = "Exudyn's generalized-α"

    def solve_positions(self, mech, times, start, settings, *, redundant=False, forces=False,
                        anchor_stiffness=0.0, rates=False) -> Positions:
        """See ``Backend.solve_positions``."""
        system = ExudynSystem(mech, forces=forces, velocity_forces=False,
                              anchor_stiffness=anchor_stiffness, start=start,
                              angle_gain=self.angle_gain(mech))
        q, solved = system.solve_positions(times, settings, redundant=redundant,
                                           multipliers=forces)
        lam = None
        if forces:
            order = [i for el in mech.constraints for i in system.ae_rows(el)]
            lam = system.multipliers[:, order]
        error = None if system.error is None else str(system.error)
        return Positions(q, solved, error, system.coordinates(), lam,
                         system.newton_iterations)

    def angle_gain(self, mech) -> float:
        """The mechanism's ``system.angle_gain``, computed once per mechanism for this
        backend's runs (an analysis solves its assembly, then its run: 0.5 ms each for
        the four-bar, measured)."""
        kept = self.__dict__.setdefault("_gains", {})
        if id(mech) not in kept:
            kept[id(mech)] = (mech, angle_gain(mech))     # mech kept: its id is not reused
        return kept[id(mech)][1]

    def static_equilibrium(self, mech, t, start, settings, *, redundant=False,
                           anchor_stiffness=0.0) -> Positions:
        """See ``Backend.static_equilibrium``: Exudyn's static solver with the masses,
        gravity and force elements (``forces``) and the anchor springs, at t alone."""
        return self.solve_positions(mech, np.array([float(t)]), start, settings,
                                    redundant=redundant, forces=True,
                                    anchor_stiffness=anchor_stiffness)

    def integrate(self, mech, times, q0, qd0, substeps, verbose=0):
        """See ``Backend.integrate``: Exudyn's generalized-α (``SolveDynamic``) from (q0, q̇0)
        through ``times``, ``substeps`` steps per interval (``integrate.integrate``)."""
        from .integrate import integrate
        return integrate(mech, times, q0, qd0, substeps, verbose=verbose)

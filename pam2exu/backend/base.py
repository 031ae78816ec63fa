"""What the analyses ask of a backend: configurations over a time grid.

A backend is one formulation of the mechanism's constraints with a solver for them
(``registry.BACKENDS`` lists them; ``Exudyn`` is the default). The analyses and the branch
following talk to it only through ``Backend.solve_positions``; velocities, accelerations
and forces are pam2exu's native pass on the coordinates it returns, which are always
x, y, fi of every solid (``kinematics.pose``), whatever the backend solves internally.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Protocol

import numpy as np


@dataclass
class Positions:
    """A backend's answer to ``solve_positions``.

    Attributes
    ----------
    q : numpy.ndarray
        (n, nq): x [m], y [m], fi [rad] of every solid at each time; the rows from
        ``solved`` on are NaN.
    solved : int
        How many times, from the first, were solved.
    error : str or None
        The solver's own words when it stopped before the last time (quoted in messages).
    last : numpy.ndarray
        (nq,): where the solver stopped (the failure diagnosis starts from it when the
        first time already failed).
    multipliers : numpy.ndarray or None
        (n, n_equations): with ``forces``, the Lagrange multipliers λ of the static
        equilibrium f + Cqᵀ λ = 0 in pam2exu's row order (``Mechanism.rows``); else None.
    iterations : int
        Newton iterations in all (0 if the backend does not count them).
    qd, qdd : numpy.ndarray or None
        (n, nq): with ``rates`` and a backend that ``gives_rates``, the velocities and
        accelerations of x, y, fi from the backend's own formulation (NaN from ``solved``
        on); else None, and the native pass computes them.
    """

    q: np.ndarray
    solved: int
    error: str | None
    last: np.ndarray
    multipliers: np.ndarray | None = None
    iterations: int = 0
    qd: np.ndarray | None = None
    qdd: np.ndarray | None = None


class Backend(Protocol):
    """A formulation with a position solver.

    Attributes
    ----------
    name : str
        Its name in ``registry.BACKENDS`` (``[analysis] backend``, ``--backend``).
    label : str
        How messages name it ("… Exudyn said: …").
    solver_name : str
        How messages name its position solver ("Exudyn's static solver did not converge").
    Settings : type
        Its settings class; an instance has at least ``tolerance`` (Newton's, relative to
        the mechanism's length) and ``verbose`` (0: quiet).
    gives_rates : bool
        ``solve_positions(..., rates=True)`` returns velocities and accelerations too.
    moves_free_solids : bool
        It has ``static_equilibrium``, which moves the free degrees of freedom to a static
        equilibrium (the ``equilibrium`` analysis needs it, and refuses free degrees of
        freedom on a backend without).
    integrates : bool
        It integrates the equations of motion (``dynamic``), by one of two methods:
        ``integrate(mech, times, q0, qd0, substeps, verbose)`` with a fixed step
        (``substeps`` equal steps per interval of the equally spaced ``times``; a
        ``Trajectory`` of q, q̇; the analysis refines it by Romberg), or, when the backend
        has it, ``motion(mech, times, q0, qd0, tolerance, verbose) -> (q, qd, estimate,
        steps)``: an adaptive integrator that meets ``tolerance`` · (1 + |value|) on every
        x, y, fi and rate itself; q, qd (len(times), nq) at ``times`` (the first row the
        start), ``estimate`` the error estimate reached per unit of value, ``steps`` the
        steps of its finest run.
    """

    name: ClassVar[str]
    label: ClassVar[str]
    solver_name: ClassVar[str]
    Settings: ClassVar[type]
    gives_rates: ClassVar[bool]
    moves_free_solids: ClassVar[bool]
    integrates: ClassVar[bool]

    def solve_positions(self, mech, times: np.ndarray, start: np.ndarray, settings, *,
                        redundant: bool = False, forces: bool = False,
                        anchor_stiffness: float = 0.0, rates: bool = False) -> Positions:
        """Configurations at the equally spaced ``times``, step after step from ``start``.

        Parameters
        ----------
        mech : Mechanism
        times : numpy.ndarray
            t_k = k·dt for k = k0 … k0 + n − 1 [s] (one time alone: a grid of spacing t).
        start : numpy.ndarray
            (nq,) the configuration the first solve starts from.
        settings
            An instance of ``Settings``.
        redundant : bool
            The constraint Jacobian is rank deficient (consistent redundant constraints).
        forces : bool
            Solve the static equilibrium with the masses, gravity and force elements (no
            dampers) and return its multipliers.
        anchor_stiffness : float
            If > 0, tie every coordinate to its value in ``start`` by a spring of this
            stiffness, so that free degrees of freedom stay nearest it (the assembly from
            the guess; the equilibrium's descent steps).
        rates : bool
            Also return ``Positions.qd`` and ``qdd`` (ignored unless ``gives_rates``).
        """
        ...

    def static_equilibrium(self, mech, t: float, start: np.ndarray, settings, *,
                           redundant: bool = False,
                           anchor_stiffness: float = 0.0) -> Positions:
        """A static equilibrium at time t, the free degrees of freedom moved to it from
        ``start`` (only with ``moves_free_solids``): what the ``equilibrium`` analysis's
        descent calls (``analyses.equilibrium.descend``).

        The answer q satisfies the constraints C(q, t) = 0 (the actuators at their laws'
        values at t), and the loads (gravity, the torsors, the springs without their
        dampers) and, if ``anchor_stiffness`` k > 0, springs tying every moving solid's
        x, y, fi to their values in ``start`` (stiffness k on x and y [N/m], k L² on fi
        [N·m/rad], L = ``mech.scale()``) do no virtual work on any motion the constraints
        allow: q is a stationary point of

            V(q) + ½ k Σ_solids [(x − x_s)² + (y − y_s)² + L² (fi − fi_s)²]

        on C(q, t) = 0, V the potential energy of the loads. Newton's iteration (or any
        method that converges to the stationary point nearest ``start``; it need not be a
        minimum) to the backend's tolerance. A ``start`` that already is such a point
        (Newton's first step within the tolerance) is returned unmoved, to round-off: the
        descent takes a step that does not move as the sign that it started on an
        equilibrium (``analyses.equilibrium.STILL``).

        Parameters
        ----------
        mech : Mechanism
        t : float
            The time [s].
        start : numpy.ndarray
            (nq,) x, y, fi of every solid where the iteration starts and the springs tie;
            it satisfies the constraints at t.
        settings
            An instance of ``Settings``.
        redundant : bool
            The constraint Jacobian is rank deficient (consistent redundant constraints).
        anchor_stiffness : float
            k [N/m] (0: no springs, the equilibrium of the loads alone).

        Returns
        -------
        Positions
            One row: ``q`` (1, nq) the equilibrium with fi in the turn nearest ``start``
            (NaN and ``solved`` 0 with the solver's ``error`` when it did not converge,
            ``last`` where it stopped); ``multipliers`` (1, n_equations) λ in pam2exu's row
            order with f + Cqᵀ λ = 0, f the loads and springs on x, y, fi (least norm where
            constraints are redundant); ``iterations``.
        """
        ...

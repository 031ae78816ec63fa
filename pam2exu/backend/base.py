"""What the analyses ask of a backend, and what it declares it can do (``Backend``).

A backend is one formulation of the mechanism's constraints with a solver for them
(``registry.BACKENDS`` lists them; ``Exudyn`` is the default). The analyses, the branch
following and the checks talk to it only through the methods of ``Backend``; velocities,
accelerations and forces are pam2exu's native pass on the coordinates it returns, which
are always x, y, fi of every solid (``kinematics.pose``), whatever the backend solves
internally. What a backend can do beyond the positions it declares by class attributes of
``Backend``; the analyses read those declarations and never probe the object.
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from enum import Enum
from typing import ClassVar

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


@dataclass
class Trajectory:
    """A fixed-step integrator's answer to ``Backend.integrate``.

    Attributes
    ----------
    q, qd : numpy.ndarray
        (len(times), nq): x, y, fi of every solid and their rates at the output times (the
        first row the start); NaN from where the integration failed.
    steps : int
        The steps taken over the whole run.
    error : str or None
        The integrator's own words when it failed (quoted in messages); None on success.
    """

    q: np.ndarray
    qd: np.ndarray
    steps: int
    error: str | None = None


@dataclass
class Reactions:
    """A backend's answer to ``Backend.reactions``.

    Attributes
    ----------
    wrenches : numpy.ndarray
        (n, constraints, 3): each constraint element's wrench on its receiving solid
        (``Element.receiver``), force x, y [N] and moment [N·m] about the solid's origin,
        in ``Mechanism.constraints`` order (as the native pass's Cqᵀ λ on that solid).
    kinetic : numpy.ndarray
        (n,) the kinetic energy [J] (the power balance).
    modes : numpy.ndarray or None
        With redundant constraints, (n, r, constraints, 3): the wrenches of r independent
        self-stresses (constraint forces in equilibrium without any load); the analysis
        adds the combination that makes the reported components least in norm, as its
        native pass does. None without redundant constraints.
    """

    wrenches: np.ndarray
    kinetic: np.ndarray
    modes: np.ndarray | None = None


class Integrator(Enum):
    """How a backend integrates the equations of motion (``Backend.integrator``)."""

    #: it does not: the dynamic analysis refuses free solids on it
    NONE = "none"
    #: ``Backend.integrate`` with a given number of equal steps; the analysis refines the
    #: step (Richardson, Romberg) until the error estimate meets the tolerance
    FIXED_STEP = "fixed step"
    #: ``Backend.motion`` meets the tolerance itself; the analysis takes its answer
    ADAPTIVE = "adaptive"


class Backend(ABC):
    """Base class of the backends: a formulation of the constraints with its solvers.

    To implement a new backend, follow these rules:

        1. Subclass ``Backend`` in a module or package of ``pam2exu/backend/`` and add one
           ``registry.BackendType`` naming it (``'pam2exu.backend.<module>:<Class>'``) to
           ``registry.BACKENDS``; ``BackendType.create`` calls the class with no argument,
           once per run (an instance may keep what it built for a mechanism).
        2. Set the identity attributes ``name``, ``label``, ``solver_name`` and
           ``Settings`` (see Attributes); the class refuses to be defined without them.
        3. Implement ``solve_positions``, the one method every analysis calls. It returns
           x, y, fi of every solid (``kinematics.pose``)
           in a ``Positions``, whatever the backend's own coordinates are. A solve that
           does not converge is no exception: return the rows solved (``solved``), the
           solver's own words (``error``) and where it stopped (``last``); the analyses
           write the message (``analyses.failure``), naming the backend by its ``label``.
        4. Declare what else it can do by the capability attributes below and implement
           the method each names; the defaults declare nothing, and a class that declares
           a capability without overriding its method is refused when it is defined
           (TypeError):

           =============================  =================================================
           declaration                    what the analyses then do
           =============================  =================================================
           ``gives_rates = True``         ``solve_positions(..., rates=True)`` fills
                                          ``Positions.qd``, ``qdd``; the kinematic
                                          analyses and the branch following use them
                                          instead of the native pass's
           ``moves_free_solids = True``   the equilibrium analysis descends the potential
                                          energy by ``static_equilibrium``; without it, it
                                          refuses free degrees of freedom on this backend
           ``integrator = FIXED_STEP``    the dynamic analysis calls ``integrate`` with 2,
                                          4, 8 … times the steps and extrapolates
                                          (Richardson, Romberg) to its tolerance
           ``integrator = ADAPTIVE``      the dynamic analysis calls ``motion``, which
                                          meets the tolerance itself
           ``integrator = NONE``          the dynamic analysis refuses free degrees of
                                          freedom on this backend (a fully driven model
                                          runs as kinetostatic)
           ``solves_variants = True``     a study solves a chunk's variants together by
                                          ``solved_variants`` and runs each variant's
                                          analysis on the backend it returns for it
           ``gives_reactions = True``     the kinetostatic analysis asks ``reactions``
                                          for every constraint element's wrench from the
                                          backend's own inverse dynamics, instead of
                                          solving Cqᵀ λ = Q_inertia − Q_applied natively
                                          (a None answer: it does); the quasi-static one
                                          asks them at rest (q̇ = q̈ = 0)
           =============================  =================================================

        5. Keep the console quiet unless ``settings.verbose`` (or ``verbose``) is > 0.
        6. Test it against the Exudyn backend on the examples (as
           ``tests/backend/test_natural.py`` does the natural backend), and give it a row
           in ``docs/architecture.md``.

    Attributes
    ----------
    name : str
        Its name in ``registry.BACKENDS`` (``[analysis] backend``, ``--backend``).
    label : str
        How messages and the checks name it ("… Exudyn said: …", "Exudyn's multipliers").
    solver_name : str
        How messages name its position solver ("Exudyn's static solver did not converge").
    Settings : type
        Its settings class, called with no argument for the defaults; an instance has at
        least ``tolerance`` (Newton's, relative to the mechanism's length) and ``verbose``
        (0: quiet).
    gives_rates : bool
        ``solve_positions(..., rates=True)`` returns velocities and accelerations too.
        Default False.
    moves_free_solids : bool
        It implements ``static_equilibrium``. Default False.
    integrator : Integrator
        How it integrates the equations of motion: ``FIXED_STEP`` (it implements
        ``integrate``), ``ADAPTIVE`` (it implements ``motion``) or ``NONE``. Default NONE.
    integrator_name : str
        With ``FIXED_STEP``: how messages name its integrator ("Exudyn's generalized-α
        stops improving here").
    solves_variants : bool
        It implements ``solved_variants`` (many variants in one pass). Default False.
    gives_reactions : bool
        It implements ``reactions`` (inverse dynamics in its own coordinates). Default False.
    """

    name: ClassVar[str]
    label: ClassVar[str]
    solver_name: ClassVar[str]
    Settings: ClassVar[type]
    gives_rates: ClassVar[bool] = False
    moves_free_solids: ClassVar[bool] = False
    integrator: ClassVar[Integrator] = Integrator.NONE
    integrator_name: ClassVar[str] = ""
    solves_variants: ClassVar[bool] = False
    gives_reactions: ClassVar[bool] = False

    def __init_subclass__(cls, **kwargs):
        """A subclass declares its identity, and a method for each capability it declares."""
        super().__init_subclass__(**kwargs)
        missing = [a for a in ("name", "label", "solver_name", "Settings") if a not in dir(cls)]
        if missing:
            raise TypeError(f"backend class {cls.__name__} does not set {', '.join(missing)} "
                            "(Backend's identity attributes)")
        needs = {"static_equilibrium": cls.moves_free_solids,
                 "integrate": cls.integrator is Integrator.FIXED_STEP,
                 "motion": cls.integrator is Integrator.ADAPTIVE,
                 "solved_variants": cls.solves_variants,
                 "reactions": cls.gives_reactions}
        for method, declared in needs.items():
            if declared and vars(Backend)[method] is _own(cls, method):
                raise TypeError(f"backend class {cls.__name__} declares what "
                                f"Backend.{method} does but does not implement {method}")
        if cls.integrator is Integrator.FIXED_STEP and not cls.integrator_name:
            raise TypeError(f"backend class {cls.__name__} has a fixed-step integrator: "
                            "name it (integrator_name)")

    @abstractmethod
    def solve_positions(self, mech, times: np.ndarray, start: np.ndarray, settings, *,
                        redundant: bool = False, forces: bool = False,
                        anchor_stiffness: float = 0.0, rates: bool = False) -> Positions:
        """Configurations at the equally spaced ``times``, step after step from ``start``.

        Every analysis calls it: the assembly (one time), the position solve of a run (in
        parts of ``analyses.positions.PART_STEPS`` steps, each from where the last
        ended), the branch following's re-solves, and the quasi-static check of the
        reactions (``forces``, one time each).

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

        Returns
        -------
        Positions
            ``q`` (len(times), nq) with NaN from ``solved`` on; ``multipliers`` with
            ``forces``; ``qd``, ``qdd`` with ``rates`` on a backend that ``gives_rates``;
            ``iterations`` if it counts them.
        """

    def static_equilibrium(self, mech, t: float, start: np.ndarray, settings, *,
                           redundant: bool = False,
                           anchor_stiffness: float = 0.0) -> Positions:
        """A static equilibrium at time t, the free degrees of freedom moved to it from
        ``start`` (with ``moves_free_solids``): what the ``equilibrium`` analysis's
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
        raise NotImplementedError(f"the {self.name} backend does not move free solids "
                                  "(moves_free_solids is False)")

    def integrate(self, mech, times: np.ndarray, q0: np.ndarray, qd0: np.ndarray,
                  substeps: int, verbose: int = 0) -> Trajectory:
        """The motion from (q0, q̇0) at ``times[0]`` through the equally spaced ``times``,
        by ``substeps`` equal steps per interval (with ``integrator = FIXED_STEP``): what
        the ``dynamic`` analysis's step refinement calls (``analyses.dynamic.romberg``).

        The equations of motion with the constraints, the actuators following their laws
        at the integrator's own time, the masses, gravity, the torsors, the springs and
        the dampers, the solids the model holds kept still. The method's error must fall
        with the step at a known order (the analysis extrapolates two runs, assuming
        order 2 or more), without the analysis's tolerance: the analysis refines.

        Parameters
        ----------
        mech : Mechanism
        times : numpy.ndarray
            The output times [s], equally spaced, ``times[0]`` the start (one time: the
            start alone, no step).
        q0, qd0 : numpy.ndarray
            (nq,) x, y, fi of every solid and their rates at ``times[0]``, consistent with
            the constraints.
        substeps : int
            Steps per interval of ``times``.
        verbose : int
            0: quiet.

        Returns
        -------
        Trajectory
            q, q̇ (len(times), nq), the steps taken, and the integrator's ``error`` when it
            failed (the analysis then tries again with twice the steps, and quotes the
            error when the finest run allowed fails too).
        """
        raise NotImplementedError(f"the {self.name} backend has no fixed-step integrator "
                                  f"(integrator is {self.integrator.name})")

    def motion(self, mech, times: np.ndarray, q0: np.ndarray, qd0: np.ndarray,
               tolerance: float, verbose: int = 0):
        """The motion from (q0, q̇0) at ``times[0]`` through ``times``, to ``tolerance``
        (with ``integrator = ADAPTIVE``): what the ``dynamic`` analysis calls instead of
        refining steps itself (``analyses.dynamic.romberg``).

        The same equations as ``integrate``, integrated to tolerance · (1 + |value|) on
        every x, y, fi and rate by the backend's own error control.

        Parameters
        ----------
        mech : Mechanism
        times : numpy.ndarray
            The output times [s], ``times[0]`` the start.
        q0, qd0 : numpy.ndarray
            (nq,) x, y, fi of every solid and their rates at ``times[0]``, consistent with
            the constraints.
        tolerance : float
            The analysis's ``[analysis] tolerance``, per unit of value.
        verbose : int
            0: quiet.

        Returns
        -------
        q, qd : numpy.ndarray
            (len(times), nq) at ``times``, the first row the start.
        estimate : float
            The error estimate reached, per unit of value (above ``tolerance`` when the
            backend could not meet it: the analysis warns).
        steps : int
            The steps of its finest run.
        """
        raise NotImplementedError(f"the {self.name} backend has no adaptive integrator "
                                  f"(integrator is {self.integrator.name})")

    def solved_variants(self, mechs: list, times: np.ndarray, settings) -> list:
        """Many variants of one mechanism solved together over ``times`` from each one's
        guess (with ``solves_variants``): what a study calls for a chunk of variants.

        Parameters
        ----------
        mechs : list of Mechanism
            The variants (one model's, their dimensions varied).
        times : numpy.ndarray
            The solve grid of their runs (``analyses.grid.plan``), the same for all.
        settings
            The backend's settings.

        Returns
        -------
        list
            For each variant, a backend (of this class) that answers the position solves
            of its run from what was found, or None where the variant is to be solved
            alone (it did not fit the pass, or failed in it: its own run says why).
        """
        raise NotImplementedError(f"the {self.name} backend does not solve variants "
                                  "together (solves_variants is False)")

    def reactions(self, mech, times: np.ndarray, q: np.ndarray, qd: np.ndarray,
                  qdd: np.ndarray, redundant: bool = False) -> Reactions | None:
        """Every constraint element's wrench on its receiving solid at every step, from the
        backend's own inverse dynamics of the motion (with ``gives_reactions``): what the
        ``kinetostatic`` analysis calls instead of its native pass, and the ``quasi_static``
        one with q̇ = q̈ = 0 (its static equilibrium: the inverse dynamics at rest).

        The wrenches are the constraint forces that make the motion: with the masses,
        gravity, the torsors, the springs and the dampers, the same as the native pass's
        Cqᵀ λ = Q_inertia − Q_applied on each receiving solid (to round-off); where
        constraints are redundant, one solution and the self-stresses (``Reactions.modes``),
        of which the analysis takes the least norm over the reported components.

        Parameters
        ----------
        mech : Mechanism
        times : numpy.ndarray
            (n,) the times [s].
        q, qd, qdd : numpy.ndarray
            (n, nq) x, y, fi of every solid and their rates, consistent with the
            constraints (the kinematic analysis's).
        redundant : bool
            The constraint Jacobian is rank deficient (consistent redundant constraints).

        Returns
        -------
        Reactions or None
            None where the backend does not handle the model: the analysis's native pass
            then computes the reactions.
        """
        raise NotImplementedError(f"the {self.name} backend has no inverse dynamics of its "
                                  "own (gives_reactions is False)")


def _own(cls: type, method: str):
    """The function that ``cls`` resolves ``method`` to (the most derived definition)."""
    return next(vars(c)[method] for c in cls.__mro__ if method in vars(c))

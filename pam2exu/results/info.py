"""The facts of a run that are not columns: ``Results.info``, one typed field each."""
from __future__ import annotations

import warnings
from collections.abc import MutableMapping
from dataclasses import dataclass, fields

from ..errors import closest


@dataclass
class RunInfo(MutableMapping):
    """Facts about a run, set by the analyses (None: not measured by this run).

    It reads as a dictionary of the facts that are set (``res.info["max_residual"]``,
    ``"equilibrium_error" in res.info``, ``dict(res.info)``); setting a name that is not a
    field is a KeyError, so that no module can write a fact nobody reads. The old name
    ``exudyn_seconds`` still reads and writes ``backend_seconds``, with a
    DeprecationWarning (``RENAMED``).

    Attributes
    ----------
    dof : int
        Degrees of freedom not driven (rank test at the initial guess).
    redundant_equations : int
        Redundant constraint equations (rank test at the initial guess).
    condition_number : float
        Condition number of the constraint Jacobian at the initial guess (equilibrated;
        ``analyses.rank.condition_numbers``) [-].
    max_residual : float
        Largest constraint residual at the backend's positions [m or rad].
    backend_seconds : float
        Time in the backend's position solves, building included [s] (``exudyn_seconds``
        before: deprecated, still read).
    substeps : int
        Position solves per user step, when the motion per step needed more than one.
    max_condition_number : float
        Worst condition number sampled over the run (kinematic, kinetostatic, dynamic)
        [-].
    branch_resolves : int
        Steps solved again by the branch following (kinematic, kinetostatic, dynamic).
    equilibrium_error : float
        quasi_static, equilibrium: the backend's multipliers against the native equilibrium at the
        checked steps, relative [-].
    reactions_from : str
        quasi_static, equilibrium: how the reactions were computed (quasi_static: the native
        solve, or the backend's own inverse dynamics at rest); kinetostatic: set when the
        backend's own inverse dynamics computed them (``Backend.gives_reactions``).
    power_balance_error : float
        kinetostatic, dynamic: largest violation of the power balance [W].
    power_balance_tolerance : float
        kinetostatic, dynamic: its tolerance, from the finite difference's own error [W].
    power_balance_steps : int
        kinetostatic, dynamic: steps at which the power balance was checked.
    power_balance : str
        kinetostatic, dynamic: why the power balance was not checked (too few rows).
    stiffness_eigenvalue : float
        equilibrium: the smallest eigenvalue of the reduced tangent stiffness, angles scaled
        by the length scale (> 0: stable) [N/m].
    integration_error : float
        dynamic: the estimate of the time integration's error reached, per unit of value
        (|error| / (1 + |value|), largest over coordinates, rates and rows) [-].
    integration_steps : int
        dynamic: the steps of the finest run of a segment (of the backend's integrator).
    clearance_method : str
        clearance: how the clearance of least norm was computed (the slides' ODE, Newton
        at every row with ``method = "newton"``, or, with no clearance joint and no varied
        anchor, the kinematic positions).
    undefined : str
        Columns asked for that are NaN by definition at some rows, and why (an
        instantaneous centre where its solid translates: ``points.columns``).

    Examples
    --------
    >>> info = RunInfo(max_residual=3e-15)
    >>> info["max_residual"], "equilibrium_error" in info, dict(info)
    (3e-15, False, {'max_residual': 3e-15})
    >>> info["max_residul"] = 1.0
    Traceback (most recent call last):
    ...
    KeyError: "no run fact 'max_residul' (did you mean 'max_residual'?)"
    """

    dof: int | None = None
    redundant_equations: int | None = None
    condition_number: float | None = None
    max_residual: float | None = None
    backend_seconds: float | None = None
    substeps: int | None = None
    max_condition_number: float | None = None
    branch_resolves: int | None = None
    equilibrium_error: float | None = None
    reactions_from: str | None = None
    power_balance_error: float | None = None
    power_balance_tolerance: float | None = None
    power_balance_steps: int | None = None
    power_balance: str | None = None
    undefined: str | None = None
    stiffness_eigenvalue: float | None = None
    integration_error: float | None = None
    integration_steps: int | None = None
    clearance_method: str | None = None

    def _field(self, key: str) -> str:
        if key in RENAMED:
            warnings.warn(f"the run fact {key!r} is now {RENAMED[key]!r}: {key!r} is "
                          "deprecated", DeprecationWarning, stacklevel=3)
            return RENAMED[key]
        if key not in _NAMES:
            raise KeyError(f"no run fact {key!r}{closest(key, _NAMES)}")
        return key

    def __getitem__(self, key: str):
        value = getattr(self, self._field(key))
        if value is None:
            raise KeyError(key)
        return value

    def __setitem__(self, key: str, value) -> None:
        setattr(self, self._field(key), value)

    def __delitem__(self, key: str) -> None:
        name = self._field(key)
        if getattr(self, name) is None:
            raise KeyError(key)
        setattr(self, name, None)

    def checks(self, backend: str = "") -> list[str]:
        """The consistency checks the run made, one phrase each (``Results.checks``).

        Parameters
        ----------
        backend : str
            The backend that ran, as messages name it (``Backend.label``; '' when unknown:
            "the backend").

        Returns
        -------
        list of str
            The constraint residual [m], the backend's multipliers against the native
            equilibrium (quasi_static, relative), the power balance (kinetostatic, [W]),
            the reduced stiffness (equilibrium), the integration error (dynamic); those set.

        Examples
        --------
        >>> facts = RunInfo(max_residual=3e-15, equilibrium_error=2e-15)
        >>> facts.checks("Exudyn")[1]
        "Exudyn's multipliers vs native equilibrium 2.0e-15 (relative)"
        >>> facts.checks("the natural-coordinate backend")[1][:45]
        "the natural-coordinate backend's multipliers "
        """
        out = []
        if "max_residual" in self:
            out.append(f"constraint residual {self['max_residual']:.1e} m")
        if "equilibrium_error" in self:
            out.append(f"{backend or 'the backend'}'s multipliers vs native equilibrium "
                       f"{self['equilibrium_error']:.1e} (relative)")
        if "power_balance_error" in self:
            out.append(f"power balance {self['power_balance_error']:.2g} W "
                       f"(finite-difference tolerance {self['power_balance_tolerance']:.2g} W)")
        if "stiffness_eigenvalue" in self:
            value = self["stiffness_eigenvalue"]
            out.append(f"reduced stiffness {value:.3g} N/m ({'' if value > 0 else 'not '}stable)")
        if "integration_error" in self:
            out.append(f"integration error estimate {self['integration_error']:.1e} "
                       f"(per unit of value, {self['integration_steps']} steps)")
        return out

    def __iter__(self):
        return (name for name in _NAMES if getattr(self, name) is not None)

    def __len__(self) -> int:
        return sum(1 for _ in self)


_NAMES = tuple(f.name for f in fields(RunInfo))
#: run facts renamed, old name → new: the old name still reads and writes the new one
#: (deprecated, with a DeprecationWarning)
RENAMED = {"exudyn_seconds": "backend_seconds"}

"""The analyses and backends pam2exu knows: one declaration each.

Everything that needs to know which analyses or backends exist reads these tables: the
model (names and PAM's Catalan aliases, in its validation), ``pam2exu.analyses`` (what an
analysis computes, whether it needs every degree of freedom driven, which function runs
it), the CLI and the generated reference pages.

Adding an analysis is one module with its function ``f(job) -> Results`` and one entry in
``ANALYSES``; adding a backend is one module (or package) with a subclass of
``pam2exu.backend.Backend`` (its contract) and one entry in ``BACKENDS``.

A declaration names what implements it as ``'module:attribute'``, imported when first
used (a callable may be given instead): so reading and validating a model loads neither
the analyses nor Exudyn, and this module imports nothing of the package but the output
levels.
"""
from __future__ import annotations

import importlib
from dataclasses import dataclass
from typing import Any, Callable

from .elements.base import ACCELERATION, CLEARANCE, FORCE, POSITION, VELOCITY


def resolve(target: str | Callable) -> Any:
    """The object a declaration names: ``'package.module:attribute'`` imported, or itself."""
    if not isinstance(target, str):
        return target
    module, _, attribute = target.partition(":")
    return getattr(importlib.import_module(module), attribute)


@dataclass(frozen=True)
class AnalysisType:
    """One analysis: its names, what it gives, what it needs, and the function that runs it.

    Parameters
    ----------
    name : str
        Its name in ``[analysis] type`` and ``-a`` (the contract's).
    alias : str
        PAM's Catalan name, read as ``name``.
    levels : frozenset of str
        The kinds of output it gives (``POSITION``, ``VELOCITY``, ``ACCELERATION``,
        ``FORCE``), which select the output columns it can produce.
    driven : bool
        Every degree of freedom must be driven by an actuator (else ``MobilityError``).
    at_start : bool
        It solves t = 0 only (one row).
    element_outputs : bool
        The elements' outputs of its levels are among its columns (default). The assembly
        gives only the solids' x, y, fi; the clearance analysis the solids' x, y, fi and its
        clearance parameters (the contract's columns: an element's outputs there would be
        computed at the nominal dimensions).
    summary : str
        One line for help texts.
    function : str or callable
        ``'module:function'`` of ``f(job) -> Results``, or the function itself.
    integrates : bool
        Its results come from a time integration to ``[analysis] tolerance`` (the others
        ignore the tolerance).
    """

    name: str
    alias: str
    levels: frozenset
    driven: bool
    at_start: bool
    summary: str
    function: str | Callable
    element_outputs: bool = True
    integrates: bool = False

    def run(self, job):
        """Run the analysis on a prepared ``Job``."""
        return resolve(self.function)(job)


@dataclass(frozen=True)
class BackendType:
    """One backend: its name, what it is, and the class implementing ``Backend``."""

    name: str
    summary: str
    implementation: str | Callable

    def create(self):
        """A new instance of the backend."""
        return resolve(self.implementation)()


_ALL = frozenset({POSITION, VELOCITY, ACCELERATION, FORCE})

#: the analyses, in the contract's order
ANALYSES: dict[str, AnalysisType] = {a.name: a for a in (
    AnalysisType("assembly", "ensamblatge", frozenset({POSITION}), driven=False,
                 at_start=True, summary="the constraints solved at t = 0 from the guess",
                 function="pam2exu.analyses.assembly:assembly", element_outputs=False),
    AnalysisType("quasi_static", "quasi_estatica", frozenset({POSITION, FORCE}), driven=True,
                 at_start=False, summary="positions and static equilibrium, no rates",
                 function="pam2exu.analyses.quasi_static:quasi_static"),
    AnalysisType("kinematic", "cinematica", frozenset({POSITION, VELOCITY, ACCELERATION}),
                 driven=True, at_start=False,
                 summary="positions, velocities and accelerations",
                 function="pam2exu.analyses.kinematic:kinematic"),
    AnalysisType("kinetostatic", "cinetostatica", _ALL, driven=True, at_start=False,
                 summary="the kinematic analysis, then every force (inverse dynamics)",
                 function="pam2exu.analyses.kinetostatic:kinetostatic"),
    AnalysisType("clearance", "joc", frozenset({POSITION, CLEARANCE}), driven=False,
                 at_start=False,
                 summary="the clearance of least norm of an over-constrained mechanism as "
                 "its dimensions vary",
                 function="pam2exu.analyses.clearance:clearance", element_outputs=False),
    AnalysisType("equilibrium", "equilibri", frozenset({POSITION, FORCE}), driven=False,
                 at_start=True,
                 summary="the free degrees of freedom in stable static equilibrium at t = 0",
                 function="pam2exu.analyses.equilibrium:equilibrium"),
    AnalysisType("dynamic", "dinamica", _ALL, driven=False, at_start=False,
                 summary="forward dynamics: the free degrees of freedom move under the "
                 "loads, to [analysis] tolerance",
                 function="pam2exu.analyses.dynamic:dynamic", integrates=True),
)}

#: the backends; the first is the default
BACKENDS: dict[str, BackendType] = {b.name: b for b in (
    BackendType("exudyn", "Exudyn's static solver on the translated model",
                "pam2exu.backend.exudyn:Exudyn"),
    BackendType("natural", "natural coordinates (basic points, unit vectors, angles) solved "
                "by pam2exu's vectorised Newton method: a second, independent formulation",
                "pam2exu.backend.natural:Natural"),
)}
DEFAULT_BACKEND = "exudyn"


def backends_that(can: Callable[[type], bool]) -> list[str]:
    """The names of the backends whose class ``can`` accepts (what a backend declares it
    can do: ``Backend.moves_free_solids``, ``integrator``), for messages that say where
    to run instead; imports every backend."""
    return [name for name, b in BACKENDS.items() if can(resolve(b.implementation))]


def analysis_type(name: str) -> AnalysisType | None:
    """The analysis called ``name`` or whose Catalan alias is ``name``; None if there is none."""
    if name in ANALYSES:
        return ANALYSES[name]
    return next((a for a in ANALYSES.values() if a.alias == name), None)


def analyses_giving(level: str, owner: str = "element") -> list[str]:
    """The analyses (names, in order) whose outputs include the variables of ``level`` of a
    ``'solid'`` or an ``'element'`` (one without ``element_outputs`` gives no element
    outputs but those of its own levels)."""
    # the levels that only analyses without element outputs give (the clearance parameters)
    own = {lv for a in ANALYSES.values() for lv in a.levels} - {
        lv for a in ANALYSES.values() if a.element_outputs for lv in a.levels}
    return [a.name for a in ANALYSES.values() if level in a.levels
            and (owner == "solid" or a.element_outputs or level in own)]

"""The analyses and backends pam2exu knows: one declaration each.

Everything that needs to know which analyses or backends exist reads these tables: the
model (names and PAM's Catalan aliases, in its validation), ``pam2exu.analyses`` (what an
analysis computes, whether it needs every degree of freedom driven, which function runs
it), the CLI and the generated reference pages. The ``AnalysisType`` itself, not its name,
travels with a run (``Job.analysis_type``, ``Results.analysis_type``): whoever needs to know
what an analysis gives (motion, forces, one row, a time integration) asks it, and no
module but this one compares an analysis's name.

The options some analyses take besides type, t_end, steps, outputs and backend
(``tolerance`` today) are declared once, in ``OPTIONS``: the model's ``[analysis]`` keys,
their defaults and checks, ``run``'s keywords, the job's ``options``, the command line's
``--NAME`` and the docs' checks read them from there, and an ``AnalysisType`` names the
ones it reads (``options``).

Adding an analysis is one module with its function ``f(job) -> Results`` and one entry in
``ANALYSES``; an option, one entry in ``OPTIONS`` (and its name in the ``options`` of the
analyses that read it); adding a backend is one module (or package) with a subclass of
``pam2exu.backend.Backend`` (its contract) and one entry in ``BACKENDS``.

A declaration names what implements it as ``'module:attribute'``, imported when first
used (a callable may be given instead): so reading and validating a model loads neither
the analyses nor Exudyn, and this module imports nothing of the package but the output
levels and what an option's message is written with (``errors.echo``, ``limits.is_number``).
"""
from __future__ import annotations

import importlib
import textwrap
from dataclasses import dataclass
from typing import Any, Callable

from .elements.base import ACCELERATION, CLEARANCE, FORCE, POSITION, VELOCITY
from .errors import echo
from .limits import is_number


def resolve(target: str | Callable) -> Any:
    """The object a declaration names: ``'package.module:attribute'`` imported, or itself."""
    if not isinstance(target, str):
        return target
    module, _, attribute = target.partition(":")
    return getattr(importlib.import_module(module), attribute)


@dataclass(frozen=True)
class AnalysisOption:
    """A setting that some analyses take besides type, t_end, steps, outputs and backend.

    One declaration read by: the model (its ``[analysis]`` key, an attribute of
    ``Model.analysis`` with this default, checked by ``Analysis.problems``), ``run`` (a
    keyword of that name), the job (``Job.options``), the command line (``--NAME`` of
    ``run`` and ``export``, refused for an analysis that does not read it) and the docs'
    checks (docs/model-format.md lists the key).

    Parameters
    ----------
    name : str
        Its ``[analysis]`` key, ``run``'s keyword and the command line's ``--NAME``.
    default : float
        Its value when neither the model nor the run gives one.
    low, high : float
        The values allowed: low < value ≤ high.
    meaning : str
        What the value is, for the message of a value out of range.
    owner : str
        Whose option it is (``"the time integration's"``), for the command line's refusal.
    help : str
        ``pam2exu run --help``'s text.
    brief : str
        A short name for ``pam2exu export --help`` (``"… (default: the model's)"``).
    metavar : str
        The command line's placeholder of its value.
    doc : str
        What the value is, in full, for its entry in ``model.Analysis``'s docstring (and
        docs/api.md); ``meaning`` when empty.
    choices : tuple of str
        The values allowed of an option that is a choice (its default one of them; ``low``
        and ``high`` then unused); empty for a number.
    """

    name: str
    default: float
    low: float
    high: float
    meaning: str
    owner: str
    help: str
    brief: str
    metavar: str = "VALUE"
    doc: str = ""
    choices: tuple[str, ...] = ()

    def parameter_doc(self) -> str:
        """Its entry in the Parameters section of ``model.Analysis``'s docstring."""
        readers = " and ".join(f"``{a}``" for a in analyses_reading(self.name))
        allowed = (f"one of {', '.join(repr(c) for c in self.choices)}, default "
                   f"{self.default!r}" if self.choices else
                   f"{self.low:g} < {self.name} ≤ {self.high:g}, default {self.default:g}")
        text = (f"An analysis option (``registry.OPTIONS``) of {readers}, which the other "
                f"analyses ignore: {self.doc or self.meaning}; {allowed}.")
        return (f"    {self.name} : {type(self.default).__name__}\n"
                + textwrap.fill(text, 92, initial_indent=" " * 8, subsequent_indent=" " * 8)
                + "\n")

    def problem(self, value) -> str | None:
        """What is wrong with ``value`` (one message), None when it is allowed."""
        if self.choices:
            if isinstance(value, str) and value in self.choices:
                return None
            return (f"{self.name} must be one of {', '.join(repr(c) for c in self.choices)}, "
                    f"{self.meaning}, got {echo(value)}")
        if is_number(value) and self.low < value <= self.high:
            return None
        return (f"{self.name} must be a number in ({self.low:g}, {self.high:g}], "
                f"{self.meaning}, got {echo(value)}")


#: the options of the analyses, in the order of the [analysis] table
OPTIONS: dict[str, AnalysisOption] = {o.name: o for o in (
    AnalysisOption("tolerance", 1e-8, 0.0, 1e-2,
                   meaning="the error allowed per unit of a coordinate or rate",
                   owner="the time integration's",
                   help="dynamic: the time integration's error allowed per unit of each "
                        "coordinate and rate (default: the model's [analysis] tolerance, "
                        "else 1e-8)",
                   brief="the dynamic analysis's tolerance", metavar="TOL",
                   doc="the accuracy required of the time integration: its error at most "
                       "tolerance · (1 + |value|) on every coordinate and rate, SI units [-]"),
    AnalysisOption("method", "ode", 0.0, 0.0, choices=("ode", "newton"),
                   meaning="how the clearance of least norm is followed",
                   owner="the clearance analysis's",
                   help="clearance: how the least-norm clearance is followed: 'ode' (the "
                        "slides' differential equation, corrected by Newton at every row; "
                        "the default) or 'newton' (Newton on the Lagrange conditions at "
                        "every row from the previous one: the reference, slower)",
                   brief="the clearance analysis's method", metavar="METHOD",
                   doc="how the clearance of least norm is followed from row to row: "
                       "'ode', the slides' differential equation y′ = −h_y⁻¹ h_t corrected "
                       "by Newton at every row, or 'newton', Newton's method on the "
                       "Lagrange conditions at every row from the previous row's solution "
                       "(they agree to 1e-9)"),
)}


def with_options(settings: type) -> type:
    """The class ``settings`` (``model.Analysis``, before ``@dataclass`` makes its fields)
    given one annotated attribute more per option, of its name and default: the fields
    the ``[analysis]`` table and ``run`` take; and their entries
    (``AnalysisOption.parameter_doc``) in its docstring's Parameters, before its Examples."""
    for option in OPTIONS.values():
        settings.__annotations__[option.name] = type(option.default).__name__
        setattr(settings, option.name, option.default)
    entries = "".join(option.parameter_doc() for option in OPTIONS.values())
    if settings.__doc__:                          # (none under python -OO)
        settings.__doc__ = settings.__doc__.replace("\n    Examples\n",
                                                    f"{entries}\n    Examples\n", 1)
    return settings


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
        It integrates the motion in time (its free solids move under the loads): pictures
        over time show it, ``export`` writes its integration script.
    options : tuple of str
        The ``OPTIONS`` it reads (the others are refused on the command line and ignored
        by ``run``).
    in_studies : bool
        A study (``pam2exu.studies``) runs it for its variants.
    first_order : bool
        The first-order method of a study (``method = "linear"``) differentiates it
        (``analyses.sensitivity``): its positions follow from the constraints alone and its
        rates and forces from the native passes.
    one_pass : bool
        A study may solve its variants' positions in one pass (``Backend.solved_variants``):
        it solves the constraints on its grid from the model's guess, which the backend's
        answers then give each variant's run.
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
    options: tuple = ()
    in_studies: bool = False
    first_order: bool = False
    one_pass: bool = False

    def run(self, job):
        """Run the analysis on a prepared ``Job``."""
        return resolve(self.function)(job)

    @property
    def parts_as_made(self) -> bool:
        """A study gives it a variant's points and lines as fixed deviations from the nominal
        dimensions (``[[variation]]`` ``fixed_dx`` …), reached from the nominal assembly:
        it gives clearances (an over-constrained mechanism assembles only nominal)."""
        return CLEARANCE in self.levels

    @property
    def gives_forces(self) -> bool:
        """Its outputs include forces (reactions, actuators' forces and torques)."""
        return FORCE in self.levels

    @property
    def gives_rates(self) -> bool:
        """It gives velocities, accelerations and forces over an interval (what the energy
        account needs)."""
        return {VELOCITY, ACCELERATION, FORCE} <= self.levels and not self.at_start


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
                 function="pam2exu.analyses.assembly:assembly", element_outputs=False,
                 in_studies=True, first_order=True, one_pass=True),
    AnalysisType("quasi_static", "quasi_estatica", frozenset({POSITION, FORCE}), driven=True,
                 at_start=False, summary="positions and static equilibrium, no rates",
                 function="pam2exu.analyses.quasi_static:quasi_static", in_studies=True,
                 first_order=True, one_pass=True),
    AnalysisType("kinematic", "cinematica", frozenset({POSITION, VELOCITY, ACCELERATION}),
                 driven=True, at_start=False,
                 summary="positions, velocities and accelerations",
                 function="pam2exu.analyses.kinematic:kinematic", in_studies=True,
                 first_order=True, one_pass=True),
    AnalysisType("kinetostatic", "cinetostatica", _ALL, driven=True, at_start=False,
                 summary="the kinematic analysis, then every force (inverse dynamics)",
                 function="pam2exu.analyses.kinetostatic:kinetostatic", in_studies=True,
                 first_order=True, one_pass=True),
    AnalysisType("clearance", "joc", frozenset({POSITION, CLEARANCE}), driven=False,
                 at_start=False,
                 summary="the clearance of least norm of an over-constrained mechanism as "
                 "its dimensions vary",
                 function="pam2exu.analyses.clearance:clearance", element_outputs=False,
                 options=("method",), in_studies=True),
    AnalysisType("equilibrium", "equilibri", frozenset({POSITION, FORCE}), driven=False,
                 at_start=True,
                 summary="the free degrees of freedom in stable static equilibrium at t = 0",
                 function="pam2exu.analyses.equilibrium:equilibrium", in_studies=True),
    AnalysisType("dynamic", "dinamica", _ALL, driven=False, at_start=False,
                 summary="forward dynamics: the free degrees of freedom move under the "
                 "loads, to [analysis] tolerance",
                 function="pam2exu.analyses.dynamic:dynamic", integrates=True,
                 options=("tolerance",), in_studies=True),
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
#: the second formulation, which ``pam2exu verify`` holds against the default by default
SECOND_FORMULATION = "natural"


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


def refuse_unknown_options(options: dict, caller: str = "run") -> None:
    """TypeError, as Python's for a keyword a function does not take, for a name of
    ``options`` that is no analysis option (``OPTIONS``)."""
    unknown = [k for k in options if k not in OPTIONS]
    if unknown:
        raise TypeError(f"{caller}() got an unexpected keyword argument {unknown[0]!r}")


def analyses_reading(option: str) -> list[str]:
    """The analyses (names, in order) that read the option ``option`` (``OPTIONS``)."""
    return [a.name for a in ANALYSES.values() if option in a.options]


def analyses_giving(level: str, owner: str = "element") -> list[str]:
    """The analyses (names, in order) whose outputs include the variables of ``level`` of a
    ``'solid'`` or an ``'element'`` (one without ``element_outputs`` gives no element
    outputs but those of its own levels)."""
    # the levels that only analyses without element outputs give (the clearance parameters)
    own = {lv for a in ANALYSES.values() for lv in a.levels} - {
        lv for a in ANALYSES.values() if a.element_outputs for lv in a.levels}
    return [a.name for a in ANALYSES.values() if level in a.levels
            and (owner == "solid" or a.element_outputs or level in own)]

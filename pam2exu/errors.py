"""Every error pam2exu raises on purpose and every warning it issues, one class each, with
what it means."""
from __future__ import annotations

import difflib
import os
import sys
import warnings
from dataclasses import dataclass


#: characters of a user's value that a message quotes (``echo``)
ECHOED = 80
#: problems a ModelError's message lists (``ModelError.problems`` keeps them all)
LISTED = 20


def echo(value, width: int = ECHOED) -> str:
    """A user's value as a message quotes it: a string in single quotes, anything else as
    Python writes it, cut to ``width`` characters with how long it was.

    Examples
    --------
    >>> echo("crank"), echo(["crank"]), echo(2.5)
    ("'crank'", "['crank']", '2.5')
    >>> echo("x" * 1000, width=5)
    "'xxxxx… (1000 characters)'"
    """
    if isinstance(value, str):
        text = value if len(value) <= width else f"{value[:width]}… ({len(value)} characters)"
        return f"'{text}'"
    try:
        text = repr(value)
    except Exception:                      # a value whose repr fails still gets a message
        text = f"<{type(value).__name__}>"
    return text if len(text) <= width else f"{text[:width]}… ({len(text)} characters)"


class Pam2ExuError(Exception):
    """Base class of pam2exu's errors: the message is meant for the user, as is.

    Catch this class to handle every error pam2exu raises on purpose (``ModelError``,
    ``MobilityError``, ``SolverError``, ``TranslationError``, ``CompareInputError``,
    ``PictureError``, ``OutputError``).

    Parameters
    ----------
    message : str
        What went wrong and what to change, one paragraph (``str(error)``).

    Examples
    --------
    >>> import pam2exu
    >>> try:
    ...     pam2exu.loads("")          # a model without solids
    ... except pam2exu.Pam2ExuError as error:
    ...     print(type(error).__name__, "-", error)
    ModelError - <string>: model: there are no solids: add at least one [[solid]]
    """


@dataclass(frozen=True)
class Problem:
    """One thing wrong with a model: where it is and what to change.

    ``ModelError.problems`` is a list of these; ``Model.problems()`` returns one.
    ``str(problem)`` is ``"<where>: <message>"`` (just the message when ``where`` is empty).

    Parameters
    ----------
    where : str
        The place in the model: ``"[[solid]] #2 'crank'"``, ``"[[element]] #3 'A'
        (revolute)"``, ``"[analysis]"``, ``"[model]"``, … ('' when it concerns no one place).
    message : str
        What is wrong and what to change.

    Examples
    --------
    >>> str(Problem("[analysis]", "steps must be a positive whole number, got 0"))
    '[analysis]: steps must be a positive whole number, got 0'
    """

    where: str
    message: str

    def __str__(self) -> str:
        return f"{self.where}: {self.message}" if self.where else self.message


class ModelError(Pam2ExuError):
    """The model is wrong: every problem found is listed, nothing was computed.

    Raised by ``load``, ``loads``, ``Model.validate``, ``Model.mechanism``, ``run`` (also
    for analysis settings that are out of range and ``outputs`` patterns that match no
    column) and ``export``. CLI exit code 2.

    Parameters
    ----------
    problems : list of Problem, Problem or str
        Every problem found; a str is a problem without a place.
    source : str, optional
        The model file (or ``"<string>"``), put in front of the message.
    kind : str
        What the file is, as the message's head names it (``"3 problems in the study"``):
        ``"model"`` (the default) or ``"study"`` (a study file, ``pam2exu.studies``).

    Attributes
    ----------
    problems : list of Problem
        Every problem found, in file order.
    source : str or None
        The model file, when known.

    Examples
    --------
    >>> error = ModelError([Problem("[model]", "gravity must be ≥ 0"), "no solids"], "m.toml")
    >>> print(error)
    m.toml: 2 problems in the model:
      - [model]: gravity must be ≥ 0
      - no solids
    >>> [p.where for p in error.problems]
    ['[model]', '']
    """

    def __init__(self, problems: list[Problem] | Problem | str, source: str | None = None,
                 kind: str = "model"):
        if isinstance(problems, (Problem, str)):
            problems = [problems]
        self.problems = [p if isinstance(p, Problem) else Problem("", p) for p in problems]
        self.source = source
        self.kind = kind
        super().__init__(self._text())

    def _text(self) -> str:
        head = f"{self.source}: " if self.source else ""
        if len(self.problems) == 1:
            return head + str(self.problems[0])
        lines = [f"{head}{len(self.problems)} problems in the {self.kind}:"]
        lines += [f"  - {p}" for p in self.problems[:LISTED]]
        if len(self.problems) > LISTED:
            lines.append(f"  … and {len(self.problems) - LISTED} more (error.problems lists "
                         "them all; fix these first)")
        return "\n".join(lines)


class MobilityError(ModelError):
    """The actuators do not drive every degree of freedom.

    A ``ModelError`` (CLI exit code 2): the quasi_static, kinematic and kinetostatic analyses
    (and ``export``) need every degree of freedom driven by an actuator or a fixed link; the
    assembly, equilibrium and dynamic analyses accept free degrees of freedom. The message names the solids that can
    still move. (Constraints that contradict each other are found by the solver instead: a
    ``SolverError`` naming the constraints that cannot all hold.)

    Parameters
    ----------
    problems : list of Problem, Problem or str
        As for ``ModelError``.
    source : str, optional
        The model file.
    kind : str
        As for ``ModelError`` (``"model"``).
    """


class SolverError(Pam2ExuError):
    """Exudyn's solver did not converge, the mechanism reached a singular position, or
    redundant constraints contradict each other.

    Carries the time and step where it happened and the elements whose constraints are
    violated most. CLI exit code 1.

    Parameters
    ----------
    message : str
        What happened, where, and what to try.
    time : float, optional
        Time where it happened [s] (for a dead point: the last time solved before it).
    step : int, optional
        Index of the time step where it happened (0 is t = 0).
    elements : tuple of str
        Descriptions of the elements whose constraints are violated most, worst first
        (``"'B' (revolute)"``); empty when not known.
    partial : Results, optional
        The rows computed before the failure, where the analysis keeps them (the clearance
        analysis does; ``pam2exu run --partial -o FILE`` writes them).

    Attributes
    ----------
    time : float or None
        As the parameter [s].
    step : int or None
        As the parameter.
    elements : tuple of str
        As the parameter.
    partial : Results or None
        As the parameter (None: no row kept).

    Examples
    --------
    >>> error = SolverError("did not converge", time=0.25, step=50)
    >>> error.time, error.step, error.elements, error.partial
    (0.25, 50, (), None)
    """

    def __init__(self, message: str, time: float | None = None, step: int | None = None,
                 elements: tuple[str, ...] = (), partial=None):
        self.time, self.step, self.elements = time, step, tuple(elements)
        self.partial = partial
        super().__init__(message)


class TranslationError(Pam2ExuError):
    """The backend's configuration does not satisfy pam2exu's own constraint equations.

    This is a bug in the translation of the named element, not a user error. Raised by the
    self-checks after an analysis: the constraint residual at the backend's configuration,
    and (quasi_static) the backend's multipliers against the native equilibrium. CLI exit
    code 1.

    Parameters
    ----------
    message : str
        The element, the time and the size of the violation.
    """


class CompareInputError(Pam2ExuError):
    """The tables cannot be compared (missing file, no ``t`` column, nothing in common, …).

    The message names the file (and the line and column, for a bad value) and what to
    change. Raised by ``compare``, ``read_names``, ``read_csv`` and ``plot`` (for a CSV
    file). CLI exit code 2.

    Parameters
    ----------
    message : str
        What is wrong with which file, and what to change.
    """


class PictureError(Pam2ExuError):
    """A picture cannot be made as asked: an image format that is not supported, ffmpeg
    missing for an MP4 file, nothing to plot. CLI exit code 2.

    Raised by ``plot``, ``pictures.draw`` and ``pictures.animate``; the message says what to
    change.

    Parameters
    ----------
    message : str
        What cannot be done, and what to do instead.
    """


class OutputError(Pam2ExuError):
    """A result cannot be written as asked: a file suffix that names no format pam2exu
    writes, a separator and decimal mark that clash, or a format whose optional library is
    not installed (the message names the extra to install, e.g. ``pip install
    "pam2exu[excel]"``). CLI exit code 2.

    Raised by ``Results.to_csv``, ``to_excel``, ``to_parquet``, ``to_pandas`` and
    ``results.writers.write``; the message says what to change.

    Parameters
    ----------
    message : str
        What cannot be written, and what to do instead.
    """


def closest(name: str, candidates) -> str:
    """' (did you mean 'x'?)' for the nearest candidate, or ''."""
    if len(str(name)) > 4 * ECHOED:       # no name is this long; difflib would take seconds
        return ""
    match = difflib.get_close_matches(str(name), [str(c) for c in candidates], n=1, cutoff=0.5)
    return f" (did you mean '{match[0]}'?)" if match else ""


# ---- warnings: the run goes on, the text is kept in Results.warnings too --------------

class RedundancyWarning(UserWarning):
    """Redundant (consistent) constraints: positions are unique, reactions are not.

    Issued once per run, naming the elements among which the redundant equations are
    (e.g. a parallelogram with a fifth bar). Positions, velocities and accelerations are
    exact; the reactions of these elements are the minimum-norm solution, one of infinitely
    many. The text is also kept in ``Results.warnings``.

    Parameters
    ----------
    message : str
        The number of redundant equations and the elements concerned.

    Examples
    --------
    >>> import warnings
    >>> import pam2exu
    >>> from pam2exu.analyses import RedundancyWarning
    >>> with warnings.catch_warnings():
    ...     warnings.simplefilter("ignore", RedundancyWarning)
    ...     res = pam2exu.run("tests/data/parallelogram5.toml")   # doctest: +SKIP
    """


class ConsistencyWarning(UserWarning):
    """A physics check after an analysis (the power balance) did not hold.

    kinetostatic: Σ actuator power must equal d(kinetic + potential energy)/dt + damper
    dissipation − torsor power [W], to within the error of the finite difference (checked
    when the run has at least 9 rows, i.e. steps ≥ 8, away from the laws' breakpoints).
    When it does not, the forces may be wrong: please report it with the model file. The
    text is also kept in ``Results.warnings``; the numbers are in ``Results.info``
    (``power_balance_error``, ``power_balance_tolerance`` [W]).

    Parameters
    ----------
    message : str
        The largest difference [W] and the tolerance [W].
    """


class ConditionWarning(UserWarning):
    """The mechanism passes at or near a singular position: results there are less exact.

    Issued by the quasi_static, kinematic and kinetostatic analyses when the constraint
    Jacobian is ill-conditioned somewhere in the interval (with the time [s], the condition
    number and the relative error to expect), and by the kinematic analysis when a step is
    exactly at a singular position (a change point), where velocities and accelerations
    are interpolated from the neighbouring steps (the force analyses stop there with a
    ``SolverError``: the reactions are undefined). The run follows the branch it starts
    on. The text is also kept in ``Results.warnings``;
    ``Results.info["max_condition_number"]`` is the worst condition number sampled.

    Parameters
    ----------
    message : str
        Where [s], how ill-conditioned, and the error to expect.
    """


class VariationWarning(UserWarning):
    """A ``[[variation]]`` varies a point or line that no constraint uses: it has no effect.

    Issued once per model when it is validated (``load``, ``loads``, ``Model.validate``,
    ``Model.mechanism``), naming the entry and its anchor; ``Model.warnings()`` lists the
    same texts. Variations are read by the clearance analysis only (docs/clearance.md).

    Parameters
    ----------
    message : str
        The entry, its anchor, and that no constraint element anchors it.
    """


class InputWarning(UserWarning):
    """A value of the model that is allowed but most likely a mistake: the run goes on.

    Issued by ``run`` (and kept in ``Results.warnings``), naming the solid or element and the
    value: an angle of a radians model above a full turn (degrees given by mistake:
    ``pam2exu check`` prints the same texts); initial rates (``Dx``, ``Dy``, ``Dfi``) of a
    dynamic model that the constraints do not allow, replaced by the nearest that they do
    (the given and the used values); a law whose value jumps within one step of the run.

    Parameters
    ----------
    message : str
        Where, which value, and what to change if it is a mistake.
    """


def warn_outside(text: str, category) -> None:
    """``warnings.warn`` at the caller's first line outside the pam2exu package."""
    package = os.path.dirname(os.path.abspath(__file__))
    frame, level = sys._getframe(1), 2
    while frame is not None and frame.f_code.co_filename.startswith(package):
        frame, level = frame.f_back, level + 1
    warnings.warn(text, category, stacklevel=level)

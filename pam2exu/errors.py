"""Every error pam2exu raises on purpose, one class each, with what it means."""
from __future__ import annotations

import difflib
from dataclasses import dataclass


class Pam2ExuError(Exception):
    """Base class of pam2exu's errors: the message is meant for the user, as is."""


@dataclass(frozen=True)
class Problem:
    """One thing wrong with a model: where it is and what to change."""

    where: str
    message: str

    def __str__(self) -> str:
        return f"{self.where}: {self.message}" if self.where else self.message


class ModelError(Pam2ExuError):
    """The model is wrong: every problem found is listed, nothing was computed.

    CLI exit code 2.
    """

    def __init__(self, problems: list[Problem] | Problem | str, source: str | None = None):
        if isinstance(problems, (Problem, str)):
            problems = [problems]
        self.problems = [p if isinstance(p, Problem) else Problem("", p) for p in problems]
        self.source = source
        super().__init__(self._text())

    def _text(self) -> str:
        head = f"{self.source}: " if self.source else ""
        if len(self.problems) == 1:
            return head + str(self.problems[0])
        lines = [f"{head}{len(self.problems)} problems in the model:"]
        lines += [f"  - {p}" for p in self.problems]
        return "\n".join(lines)


class MobilityError(ModelError):
    """The actuators do not drive every degree of freedom, or the constraints contradict each other."""


class SolverError(Pam2ExuError):
    """Exudyn's solver did not converge, or the mechanism reached a singular position.

    Carries the time and step where it happened and the elements whose constraints are
    violated most. CLI exit code 1.
    """

    def __init__(self, message: str, time: float | None = None, step: int | None = None,
                 elements: tuple[str, ...] = ()):
        self.time, self.step, self.elements = time, step, tuple(elements)
        super().__init__(message)


class TranslationError(Pam2ExuError):
    """Exudyn's configuration does not satisfy pam2exu's own constraint equations.

    This is a bug in the translation of the named element, not a user error.
    """


def closest(name: str, candidates) -> str:
    """' (did you mean 'x'?)' for the nearest candidate, or ''."""
    match = difflib.get_close_matches(str(name), [str(c) for c in candidates], n=1, cutoff=0.5)
    return f" (did you mean '{match[0]}'?)" if match else ""

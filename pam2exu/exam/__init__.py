"""Exam variants with checked answers (``pam2exu exam``, docs/teaching.md).

N variants of a model, each with its dimensions drawn around the model's values (the
studies' parameters: ``studies.parameters.targets``, a uniform draw of nominal ± tol from
``scipy.stats``, each value rounded to a tenth of its tolerance's decade so that the data
read well), and the values asked (``VAR@T``: an output at a time) computed by pam2exu for
each. Every variant is first run on both backends and compared (``verify``, the outputs
asked over [0, the latest time asked]); a variant whose backends disagree, or that does not
assemble or run, is replaced by the next draw, and the exam says which and why.

``Exam.write_pdf`` writes one page per variant (the drawing at the first time asked, the
data, the questions) then the solutions (``pdf``); ``Exam.moodle`` the Moodle XML quiz, one
numerical question per variant and value asked, with a relative tolerance (``moodle``).
"""
from __future__ import annotations

import math
import re
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import ModelError, Pam2ExuError, Problem
from ..model import Model, load
from ..model.loader import decode
from ..laws import LAWS
from ..registry import ANALYSES
from ..studies.parameters import targets, varied
from ..studies.sampling import Parameter, design

#: how many draws an exam may use for its N variants (N · this), before it gives up
DRAWS_PER_VARIANT = 10
#: the relative tolerance of a Moodle answer (``--tolerance``)
TOLERANCE = 0.01
#: the analyses an exam's outputs may come from, the plainest first
ANALYSES_ASKED = ("kinematic", "kinetostatic")
#: the seed of the draws when none is given
SEED = 0

_ASK = re.compile(r"^\s*([^@\s]+)\s*@\s*([-+0-9.eE]+)\s*$")
_VARY = re.compile(r"^\s*([^=\s]+)\s*=\s*(?:±|\+-|\+/-)?\s*([0-9.eE+-]+)\s*$")


@dataclass(frozen=True)
class Question:
    """One value asked: ``output`` at time ``t``."""

    output: str
    t: float

    def __str__(self) -> str:
        return f"{self.output} at t = {self.t:g} s"


@dataclass
class Variant:
    """One variant of the exam: its number (1 …), the draw it came from, its parameter
    values (rounded, as printed), its model, and every answer with its unit."""

    number: int
    draw: int
    values: dict[str, float]
    model: Model
    answers: dict[Question, float]
    units: dict[str, str]


@dataclass
class Exam:
    """N checked variants of a model (``exam``)."""

    source: str
    analysis: str
    parameters: list[Parameter]
    questions: list[Question]
    variants: list[Variant]
    tolerance: float = TOLERANCE
    #: (draw, why) of every draw that was replaced
    replaced: list[tuple[int, str]] = field(default_factory=list)
    seed: int = SEED

    def moodle(self) -> str:
        """The Moodle XML quiz (``moodle.quiz``)."""
        from .moodle import quiz
        return quiz(self)

    def write_moodle(self, path: str | Path) -> Path:
        """Write ``moodle()`` to ``path``."""
        path = Path(path)
        path.write_text(self.moodle(), encoding="utf-8")
        return path

    def write_pdf(self, path: str | Path) -> Path:
        """One page per variant, then the solutions (``pdf.write``)."""
        from .pdf import write
        return write(self, Path(path))


def data_lines(exam, variant) -> list[str]:
    """The data of a variant as a student needs them: every solid's points in its own frame
    (with its mass properties when the forces are asked), every driver's law, and which
    numbers this variant drew."""
    model, forces = variant.model, exam.analysis == "kinetostatic"
    lines = [f"Solids (points in each solid's frame, m; gravity {model.gravity:g} m/s²):"]
    for s in model.solids:
        points = ", ".join(f"{k} ({x:g}, {y:g})" for k, (x, y) in s.points.items())
        mass = (f"; m = {s.mass:g} kg, J_G = {s.inertia:g} kg·m², G ({s.cog[0]:g}, "
                f"{s.cog[1]:g})") if forces and s.mass else ""
        lines.append(f"    {s.name}: {points}{mass}")
    lines.append("Drivers:")
    for el in model.mechanism().drivers:
        law = el.time_law()
        formula = (LAWS[law.name].function.__doc__ or "").strip().splitlines()[0]
        constants = ", ".join(f"{c:g}" for c in law.C)
        lines.append(f"    {el.name} ({el.type}): {law.name}, C = ({constants}); {formula}")
    drawn = ", ".join(f"{p.name} = {variant.values[p.name]:g} {p.unit}".rstrip()
                      for p in exam.parameters)
    lines.append(f"This variant: {drawn}." if drawn else "The model's own dimensions.")
    return lines


def parse_ask(text: str) -> Question:
    """``VAR@T`` → Question; ValueError saying the form."""
    m = _ASK.match(text)
    if not m:
        raise ValueError(f"--ask {text!r}: write an output and a time as OUTPUT@T, e.g. "
                         "rocker.Dfi@0.1")
    t = float(m.group(2))
    if not math.isfinite(t) or t < 0:
        raise ValueError(f"--ask {text!r}: the time must be a number ≥ 0")
    return Question(m.group(1), t)


def parse_vary(text: str) -> tuple[str, float]:
    """``PARAM=±TOL`` → (name, tol); ValueError saying the form."""
    m = _VARY.match(text)
    tol = float(m.group(2)) if m else math.nan
    if not m or not math.isfinite(tol) or tol <= 0:
        raise ValueError(f"--vary {text!r}: write a parameter and its tolerance as "
                         "PARAM=±TOL with TOL > 0, e.g. coupler.B.x=±0.02")
    return m.group(1), tol


def resolution(tol: float) -> float:
    """The rounding of a drawn value: a tenth of its tolerance's decade, 10^(⌊log₁₀ tol⌋ − 1)."""
    return 10.0 ** (math.floor(math.log10(tol)) - 1)


def rounded(value: float, step: float) -> float:
    """value to the nearest multiple of step, printed without round-off noise."""
    digits = max(0, -math.floor(math.log10(step)))
    return round(round(value / step) * step, digits)


def first_sentence(text: str, most: int = 200) -> str:
    """A message's first sentence (up to '. '), at most ``most`` characters."""
    line = text.splitlines()[0].split(". ")[0]
    return line if len(line) <= most else line[:most - 1] + "…"


def steps_to(model: Model, t: float) -> int:
    """Steps of a run from 0 to t with the model's own step length (at least 4)."""
    a = model.analysis
    return max(4, math.ceil(t / (a.t_end / a.steps) - 1e-9))


def analysis_of(model: Model, questions: list[Question]) -> str:
    """The plainest analysis that gives every output asked; ModelError naming those that no
    analysis gives."""
    from ..analyses.job import available_columns
    from ..results.names import select_columns
    mech = model.mechanism()
    for name in ANALYSES_ASKED:
        columns = list(available_columns(mech, ANALYSES[name]))
        try:
            select_columns(columns, [q.output for q in questions])
            return name
        except ModelError:
            continue
    raise ModelError([Problem("--ask", f"{q.output!r} is not an output of the model's "
                                       f"{' or '.join(ANALYSES_ASKED)} analysis")
                      for q in questions], model.source)


def answers(model: Model, analysis: str, questions: list[Question]):
    """({question: value}, {output: unit}) of one model: per time asked, a run from 0 to it
    with the model's step length, its last row (its first at t = 0)."""
    from ..analyses import run
    out, units = {}, {}
    for t in sorted({q.t for q in questions}):
        asked = [q for q in questions if q.t == t]
        end = t if t > 0 else model.analysis.t_end / model.analysis.steps
        res = run(model, analysis, t_end=end, steps=steps_to(model, end),
                  outputs=list(dict.fromkeys(q.output for q in asked)))
        row = -1 if t > 0 else 0
        for q in asked:
            out[q] = float(np.asarray(res[q.output])[row])
            units[q.output] = res.units.get(q.output, "")
    return out, units


def checked(model: Model, analysis: str, questions: list[Question]) -> str | None:
    """None when both backends agree on every output asked over [0, the latest time]
    (``verify``), else why not."""
    from ..verify import verify
    end = max(q.t for q in questions) or model.analysis.t_end / model.analysis.steps
    report = verify(model, analysis, t_end=end, steps=steps_to(model, end),
                    outputs=list(dict.fromkeys(q.output for q in questions)))
    return None if report.ok else f"the backends disagree on {', '.join(report.differing)}"


def exam(model_path: str | Path, variants: int, asks: list[str], vary: list[str] = (),
         seed: int = SEED, tolerance: float = TOLERANCE, progress=None) -> Exam:
    """``variants`` checked variants of the model file (module doc).

    Parameters
    ----------
    model_path : str or Path
        The model file.
    variants : int
        How many variants (≥ 1).
    asks : list of str
        The values asked, ``OUTPUT@T`` each.
    vary : list of str
        ``PARAM=±TOL`` each: what varies (``studies.parameters.targets``), uniformly within
        nominal ± TOL; none: every variant is the model itself.
    seed : int
        The seed of the draws: the same arguments give the same exam.
    tolerance : float
        The relative tolerance of a Moodle answer.
    progress : callable, optional
        Called with (variants done, variants asked) after each accepted variant.

    Raises
    ------
    ModelError
        A bad model, parameter, output or time (naming it), or fewer than ``variants``
        draws of the first ``DRAWS_PER_VARIANT`` × ``variants`` could be checked (the
        reasons listed).
    """
    path = Path(model_path)
    model = load(path)
    text = decode(path.read_bytes(), str(path))
    problems = []
    if not isinstance(variants, int) or variants < 1:
        problems.append(Problem("--variants", f"must be a whole number ≥ 1, got {variants!r}"))
    if not 0 < tolerance < 1:
        problems.append(Problem("--tolerance", f"must be a fraction in (0, 1), got {tolerance!r}"))
    questions, parameters = [], []
    for a in asks:
        try:
            questions.append(parse_ask(a))
        except ValueError as exc:
            problems.append(Problem("--ask", str(exc)))
    if not asks:
        problems.append(Problem("--ask", "ask at least one value, OUTPUT@T"))
    found = targets(model)
    for v in vary:
        try:
            name, tol = parse_vary(v)
        except ValueError as exc:
            problems.append(Problem("--vary", str(exc)))
            continue
        if name not in found:
            close = ", ".join(n for n in found if n.split(".")[0] == name.split(".")[0])[:200]
            problems.append(Problem("--vary", f"the model has no number {name!r} to vary"
                                              + (f"; its solid's: {close}" if close else "")))
            continue
        parameters.append(Parameter(name, "uniform", found[name].nominal, tol=tol,
                                    unit=found[name].unit))
    if problems:
        raise ModelError(problems, str(path))
    analysis = analysis_of(model, questions)
    late = [q for q in questions if q.t > model.analysis.t_end * 100]
    if late:
        raise ModelError([Problem("--ask", f"{q}: far beyond the model's t_end "
                                           f"{model.analysis.t_end:g} s") for q in late],
                         str(path))
    out, replaced = [], []
    draws = variants * DRAWS_PER_VARIANT
    rows = design("monte_carlo", parameters, draws, seed, 0, draws) if parameters \
        else np.zeros((draws, 0))
    for k in range(draws):
        if len(out) == variants:
            break
        values = {p.name: rounded(float(x), resolution(p.tol))
                  for p, x in zip(parameters, rows[k])}
        why = None
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                m = varied(text, values, str(path))
                why = checked(m, analysis, questions)
                if why is None:
                    got, units = answers(m, analysis, questions)
            except Pam2ExuError as exc:
                why = first_sentence(f"{type(exc).__name__}: {exc}")
        if why is not None:
            replaced.append((k, why))
            continue
        out.append(Variant(len(out) + 1, k, values, m, got, units))
        if progress is not None:
            progress(len(out), variants)
    if len(out) < variants:
        reasons = "; ".join(f"draw {k}: {why}" for k, why in replaced[:5])
        raise ModelError([Problem("--variants", f"only {len(out)} of {draws} draws could be "
                                                f"checked ({reasons}): vary less, or ask "
                                                "at other times")], str(path))
    return Exam(str(path), analysis, parameters, questions, out, tolerance, replaced, seed)

"""Reading a study file (TOML, shared contract "Studies"): ``[study]``, ``[[parameter]]``,
``[[requirement]]``; every problem collected at once, each naming its entry and what to
change (as the model loader does)."""
from __future__ import annotations

import difflib
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputWarning, ModelError, Problem, closest, echo, warn_outside
from ..limits import is_number, shown
from ..model import Analysis, Model, load
from ..registry import DEFAULT_BACKEND
from ..model.loader import decode
from ..results.names import select_columns, spelled
from .parameters import Target, targets
from .reduce import REDUCTIONS, Requirement
from .sampling import DISTRIBUTIONS, METHODS, Parameter, design, grid_size

#: the methods that draw ``samples`` variants from a ``seed``
SAMPLED = ("monte_carlo", "latin_hypercube", "sobol")
#: the most variants a study runs: every variant's values and its row of the table are held
#: in memory (a million already give a yield of 99 % within ± 0.02 %, its Wilson interval)
MAX_SAMPLES = 10_000_000

_TABLES = ("study", "parameter", "requirement")
_STUDY_KEYS = ("model", "analysis", "t_end", "steps", "method", "samples", "seed", "outputs",
               "reduce", "series", "backend", "batched")
_PARAMETER_KEYS = ("name", "distribution", "mean", "tol", "std", "low", "high", "values")
_REQUIREMENT_KEYS = ("output", "min", "max")


@dataclass
class Study:
    """A validated study: the model, the analysis settings, the parameters, the method.

    Attributes
    ----------
    source : str
        The study file (or ``"<string>"``).
    model_path : Path
        The model file, resolved against the study file's folder.
    model_text : str
        The model file's text (what workers receive).
    model : Model
        The nominal model.
    analysis, t_end, steps
        The analysis to run (default the model's [analysis]).
    method : str
        One of ``sampling.METHODS``.
    samples : int
        The number of variants (a grid's product of the value lists; 1 for linear).
    seed : int
        The seed of the sampled methods (default 0).
    outputs : list of str or None
        Output names and patterns (default the model's; None: every output).
    reduce : list of str
        Reductions (``reduce.REDUCTIONS``; default all seven).
    series : bool
        Keep every variant's time series.
    parameters : list of Parameter
    requirements : list of Requirement
        ``reduce.Requirement`` (output, min, max), what ``reduce.status`` reads.
    backend : str
        What solves each variant's positions (``registry.BACKENDS``; default the model's
        [analysis] backend).
    batched : bool
        Solve a chunk's variants in one pass where the backend can
        (``Backend.solves_variants``) and the analysis allows (``AnalysisType.one_pass``);
        False: each variant alone (the reference the pass is tested against).
    """

    source: str
    model_path: Path
    model_text: str
    model: Model
    analysis: str
    t_end: float
    steps: int
    method: str
    samples: int
    seed: int
    outputs: list[str] | None
    reduce: list[str]
    series: bool
    parameters: list[Parameter] = field(default_factory=list)
    requirements: list[Requirement] = field(default_factory=list)
    backend: str = DEFAULT_BACKEND
    batched: bool = True

    @property
    def names(self) -> list[str]:
        """The parameters' names, in study order (the columns of ``variants``)."""
        return [p.name for p in self.parameters]

    def variants(self, start: int = 0, stop: int | None = None) -> np.ndarray:
        """Rows [start, stop) of the variants' values (``variants``)."""
        return variants(self, start, stop)

    def sigmas(self) -> np.ndarray:
        """σ_p of every parameter, in study order (for the linear method)."""
        return np.array([p.sigma for p in self.parameters])


def variants(study: Study, start: int = 0, stop: int | None = None) -> np.ndarray:
    """Rows [start, stop) of the study's variants, (rows, parameters), in model units.

    Row i depends only on the seed, the method, the samples, the parameter list and i:
    any chunking gives the rows of the whole design, bit for bit.

    Examples
    --------
    >>> study = loads_study('''
    ... [study]
    ... model = "examples/four_bar.toml"
    ... method = "grid"
    ... [[parameter]]
    ... name = "coupler.B.x"
    ... values = [0.34, 0.35]
    ... [[parameter]]
    ... name = "model.gravity"
    ... values = [9.81, 0.0, 1.62]
    ... ''')
    >>> variants(study, 2, 4).tolist()
    [[0.34, 1.62], [0.35, 9.81]]
    """
    stop = study.samples if stop is None else stop
    return design(study.method, study.parameters, study.samples, study.seed, start, stop)


def load_study(path: str | Path) -> Study:
    """Read and validate a study file; raises ModelError naming the file and every problem.

    Parameters
    ----------
    path : str or Path
        The study file; its ``model`` is read relative to its folder.

    Returns
    -------
    Study

    Raises
    ------
    ModelError
        The file cannot be read, is not TOML, or has problems (every one listed): unknown
        tables or keys, an unknown parameter name, distribution, method or reduction, bad
        numbers, a missing model file, a requirement on an output that is not reduced.
    """
    path = Path(path)
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise ModelError(f"cannot read the study file: {exc.strerror or exc}", str(path)) \
            from None
    return loads_study(decode(raw, str(path)), source=str(path), folder=path.parent)


def loads_study(text: str, source: str = "<string>", folder: str | Path = ".") -> Study:
    """Parse and validate a study from TOML text (see ``load_study``).

    Parameters
    ----------
    text : str
        The study, in the TOML format of a study file.
    source : str
        Where the text comes from, named in messages.
    folder : str or Path
        The folder the ``model`` path is relative to.
    """
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ModelError(f"not valid TOML: {exc}", source) from None
    problems: list[Problem] = []
    for key in data:
        if key not in _TABLES:
            problems.append(Problem(f"[{echo(key)[1:-1]}]",
                                    f"unknown table{closest(key, _TABLES)}; a study has "
                                    f"{', '.join(_TABLES)}"))
    head = data.get("study", {})
    if not isinstance(head, dict):
        problems.append(Problem("[study]", "must be a table [study]"))
        head = {}
    _unknown_keys(head, _STUDY_KEYS, "[study]", problems)
    model_path, model_text, model = _model(head, Path(folder), problems)
    if model is None:
        raise ModelError(problems, source, kind="study")
    settings = _settings(head, model, problems)
    found = targets(model)
    parameters = _parameters(_array(data, "parameter", problems), found, settings["method"],
                             problems)
    reduce = settings["reduce"]
    requirements = _requirements(_array(data, "requirement", problems), settings["outputs"],
                                 reduce, problems)
    method, samples = settings["method"], settings["samples"]
    if method == "grid" and parameters and all(p.values for p in parameters):
        samples = grid_size(parameters)
        if samples > MAX_SAMPLES:
            problems.append(Problem("[[parameter]]", too_many(
                f"the values lists make a grid of {samples:,} variants")))
    elif method == "linear":
        samples = 1
    if problems:
        raise ModelError(problems, source, kind="study")
    if method == "sobol" and samples & (samples - 1):
        below = 1 << (samples.bit_length() - 1)
        warn_outside(f"{source}: [study]: samples = {samples} is not a power of 2: scrambled "
                     f"Sobol' points keep their balance only for a power of 2 (use {below} or "
                     f"{2 * below}); the study runs the first {samples} points", InputWarning)
    return Study(source, model_path, model_text, model, settings["analysis"],
                 settings["t_end"], settings["steps"], method, samples, settings["seed"],
                 settings["outputs"], reduce, settings["series"], parameters, requirements,
                 backend=settings["backend"], batched=settings["batched"])


def _model(head: dict, folder: Path, problems: list[Problem]):
    """(path, text, model) of ``[study] model``; Nones with a problem when it cannot be read."""
    given = head.get("model")
    if not isinstance(given, str):
        problems.append(Problem("[study]", "'model' is missing: the model file, relative to "
                                           "the study file" if given is None else
                                           f"'model' must be a file name, got {echo(given)}"))
        return None, None, None
    path = folder / given
    try:
        raw = path.read_bytes()
    except OSError as exc:
        problems.append(Problem("[study]", f"model = {echo(given)}: cannot read '{path}' "
                                           f"({exc.strerror or exc}); the path is relative to "
                                           "the study file's folder"))
        return None, None, None
    text = decode(raw, str(path))
    try:
        return path, text, load(path)
    except ModelError as exc:
        problems += [Problem(f"[study] model {echo(given)}: {p.where}".rstrip(": "), p.message)
                     for p in exc.problems]
        return None, None, None


def _settings(head: dict, model: Model, problems: list[Problem]) -> dict:
    """The [study] values with their defaults (the model's [analysis]); problems added."""
    where = "[study]"
    out = {"analysis": head.get("analysis", model.analysis.type),
           "t_end": head.get("t_end", model.analysis.t_end),
           "steps": head.get("steps", model.analysis.steps),
           "outputs": head.get("outputs", model.analysis.outputs),
           "method": head.get("method", "monte_carlo"), "samples": head.get("samples"),
           "seed": head.get("seed", 0), "reduce": head.get("reduce", list(REDUCTIONS)),
           "series": head.get("series", False),
           "backend": head.get("backend", model.analysis.backend),
           "batched": head.get("batched", True)}
    settings = Analysis(out["analysis"], t_end=out["t_end"], steps=out["steps"],
                        outputs=out["outputs"], backend=out["backend"])
    problems += [Problem(where, m) for m in settings.problems()]
    out["analysis"] = settings.type
    if out["method"] not in METHODS:
        problems.append(Problem(where, f"unknown method {echo(out['method'])}"
                                       f"{closest(str(out['method']), METHODS)}; known methods: "
                                       f"{', '.join(METHODS)}"))
    samples = out["samples"]
    if out["method"] in SAMPLED:
        if samples is None:
            problems.append(Problem(where, f"'samples' is missing: the number of variants "
                                           f"{out['method']} draws"))
        elif not _whole(samples) or samples < 1:
            problems.append(Problem(where, f"samples must be a whole number ≥ 1, got "
                                           f"{echo(samples)}"))
        elif samples > MAX_SAMPLES:
            problems.append(Problem(where, too_many(f"samples = {samples:,}")))
    elif samples is not None and out["method"] in METHODS:
        problems.append(Problem(where, f"a {out['method']} study takes no samples (a grid runs "
                                       "every combination of the values lists, linear the "
                                       "nominal variant): remove 'samples'"))
    if not _whole(out["seed"]) or out["seed"] < 0:
        problems.append(Problem(where, f"seed must be a whole number ≥ 0, got "
                                       f"{echo(out['seed'])}"))
    reduce = out["reduce"]
    if not isinstance(reduce, list) or not reduce:
        problems.append(Problem(where, f"reduce must be a list of reductions, some of "
                                       f"{', '.join(REDUCTIONS)}"))
        out["reduce"] = []
    else:
        for r in reduce:
            if r not in REDUCTIONS:
                problems.append(Problem(where, f"unknown reduction {echo(r)}"
                                               f"{closest(str(r), REDUCTIONS)}; known: "
                                               f"{', '.join(REDUCTIONS)}"))
    for key in ("series", "batched"):
        if not isinstance(out[key], bool):
            problems.append(Problem(where, f"{key} must be true or false, got "
                                           f"{echo(out[key])}"))
    return out


def too_many(what: str) -> str:
    """The problem of a study of more than ``MAX_SAMPLES`` variants, ``what`` saying how
    many it asks."""
    return (f"{what}: more than a study runs (at most {MAX_SAMPLES:,}; every variant's values "
            "and row are held in memory): run fewer, a million give a yield of 99 % within "
            "± 0.02 %")


def _whole(value) -> bool:
    """A whole number (not a bool)."""
    return isinstance(value, int) and not isinstance(value, bool)


def _parameters(entries: list[dict], found: dict[str, Target], method: str,
                problems: list[Problem]) -> list[Parameter]:
    """The [[parameter]] entries, validated against what the model can vary."""
    out: list[Parameter] = []
    seen: dict[str, str] = {}
    for k, entry in enumerate(entries, start=1):
        name = entry.get("name")
        where = f"[[parameter]] #{k}" + (f" '{shown(name)}'" if isinstance(name, str) else "")
        _unknown_keys(entry, _PARAMETER_KEYS, where, problems)
        before = len(problems)
        if not isinstance(name, str):
            problems.append(Problem(where, "'name' is missing: what varies, e.g. "
                                           "'coupler.B.x'" if name is None else
                                           f"'name' must be a string, got {echo(name)}"))
        elif name not in found:
            problems.append(Problem(where, f"the model has no number '{shown(name)}' to vary"
                                           f"{_closest_names(name, found)}"))
        elif name in seen:
            problems.append(Problem(where, f"'{shown(name)}' is varied by {seen[name]} already: "
                                           "give each parameter once"))
        else:
            seen[name] = where
        kind = entry.get("distribution", "values" if "values" in entry else None)
        if kind not in DISTRIBUTIONS:
            problems.append(Problem(where, "'distribution' is missing; one of "
                                           f"{', '.join(DISTRIBUTIONS)}" if kind is None else
                                           f"unknown distribution {echo(kind)}"
                                           f"{closest(str(kind), DISTRIBUTIONS)}; known: "
                                           f"{', '.join(DISTRIBUTIONS)}"))
        else:
            problems += [Problem(where, m) for m in _distribution_problems(kind, entry, method)]
        if len(problems) == before:
            target = found[name]
            out.append(Parameter(name, kind, target.nominal, unit=target.unit,
                                 **{key: entry.get(key) for key in _PARAMETER_KEYS[2:]}))
            problems += [Problem(where, m) for m in _centre_problems(out[-1])]
    if not entries:
        problems.append(Problem("[[parameter]]", "there are no parameters: add at least one "
                                                 "[[parameter]] with the name of what varies"))
    return out


def _closest_names(name: str, found: dict[str, Target], n: int = 5) -> str:
    """'; the closest: a, b, c' among the names that can vary (or how to list them)."""
    close = difflib.get_close_matches(name, list(found), n=n, cutoff=0.5)
    return (f"; the closest: {', '.join(close)}" if close else
            "; names are solid.point.x, solid.mass, element.C1, model.gravity, …")


def _distribution_problems(kind: str, entry: dict, method: str) -> list[str]:
    """What is wrong with a parameter's distribution keys (empty when they are sound)."""
    out = []
    for key in ("mean", "tol", "std", "low", "high"):
        if key in entry and not is_number(entry[key]):
            out.append(f"{key} must be a number, got {echo(entry[key])}")
    if out:
        return out
    for key in ("tol", "std"):
        if key in entry and entry[key] <= 0:
            out.append(f"{key} = {entry[key]!r} must be > 0 (a parameter that does not vary "
                       "needs no [[parameter]])")
    values = entry.get("values")
    if values is not None and (not isinstance(values, list) or not values
                               or not all(is_number(v) for v in values)):
        out.append(f"values must be a non-empty list of numbers, got {echo(values)}")
    if method == "grid" and values is None:
        out.append("a grid study needs a 'values' list for every parameter")
    if kind == "normal" and ("tol" in entry) == ("std" in entry):
        out.append("a normal distribution takes tol (3σ) or std (σ), one of them")
    if kind == "normal" and ("low" in entry or "high" in entry):
        out.append("a normal distribution takes no low/high: give tol or std")
    if kind in ("uniform", "triangular"):
        bounds = ("low" in entry) + ("high" in entry)
        if bounds == 1 or (bounds == 2) == ("tol" in entry):
            out.append(f"a {kind} distribution takes low and high, or tol (mean ± tol)")
        elif bounds == 2 and entry["low"] >= entry["high"]:
            out.append(f"low = {entry['low']!r} must be less than high = {entry['high']!r}")
        if "std" in entry:
            out.append(f"a {kind} distribution takes no std: give low and high, or tol")
        if kind == "uniform" and "mean" in entry and bounds == 2:
            out.append("a uniform distribution between low and high takes no mean (mean ± "
                       "tol is the other way to give it)")
    if kind == "values" and values is None:
        out.append("a values distribution needs values = [...]")
    if kind == "values" and any(k in entry for k in ("tol", "std", "low", "high", "mean")):
        out.append("a values distribution takes only values = [...]")
    return out


def _centre_problems(p: Parameter) -> list[str]:
    """A triangular's mode (its mean, default nominal) outside its low … high."""
    if p.distribution == "triangular" and p.low is not None \
            and not p.low <= p.centre <= p.high:
        return [f"the triangular's mode (mean, default the nominal {p.centre!r}) lies outside "
                f"low … high = {p.low!r} … {p.high!r}: give mean within them"]
    return []


def _requirements(entries: list[dict], outputs, reduce: list[str],
                  problems: list[Problem]) -> list[Requirement]:
    """The [[requirement]] entries: each on a reduced output, with min and/or max."""
    out = []
    for k, entry in enumerate(entries, start=1):
        name = entry.get("output")
        where = f"[[requirement]] #{k}" + (f" '{shown(name)}'" if isinstance(name, str) else "")
        _unknown_keys(entry, _REQUIREMENT_KEYS, where, problems)
        before = len(problems)
        if not isinstance(name, str):
            problems.append(Problem(where, "'output' is missing: a reduced output, e.g. "
                                           "'motor.Mz.absmax'"))
        else:
            message = _reduced_problem(name, outputs, reduce)
            if message:
                problems.append(Problem(where, message))
        bounds = [entry.get(key) for key in ("min", "max")]
        if bounds == [None, None]:
            problems.append(Problem(where, "give min, max or both"))
        for key, value in zip(("min", "max"), bounds):
            if value is not None and not is_number(value):
                problems.append(Problem(where, f"{key} must be a number, got {echo(value)}"))
        if len(problems) == before and None not in bounds and bounds[0] > bounds[1]:
            problems.append(Problem(where, f"min = {bounds[0]!r} is above max = {bounds[1]!r}"))
        if len(problems) == before:
            out.append(Requirement(name, *(None if v is None else float(v) for v in bounds)))
    return out


def _reduced_problem(name: str, outputs, reduce: list[str]) -> str | None:
    """Why ``name`` is no ``<output>.<reduction>`` of the study's outputs and reductions."""
    output, _, reduction = name.rpartition(".")
    reduce = [r for r in reduce if r in REDUCTIONS]
    if reduction not in reduce:
        return (f"'{shown(name)}' is not a reduced output: it must end in one of the study's "
                f"reductions ({', '.join(reduce) or 'none'}), as 'motor.Mz.absmax'"
                + ("" if reduction not in REDUCTIONS else
                   f"; or add '{reduction}' to [study] reduce"))
    if not isinstance(outputs, list) or not all(isinstance(o, str) for o in outputs):
        return None                          # every output, or a bad list already reported
    for pattern in outputs:
        try:
            if select_columns([spelled(output)], [pattern]):
                return None
        except ModelError:
            continue
    return (f"'{shown(output)}' is not among the study's outputs ({', '.join(outputs)}): add "
            f"it to [study] outputs, or require a reduced output of them")


def _array(data: dict, key: str, problems: list[Problem]) -> list[dict]:
    """An array of tables [[key]] (none: [])."""
    value = data.get(key, [])
    if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
        problems.append(Problem(f"[[{key}]]", f"must be an array of tables [[{key}]]"))
        return []
    return value


def _unknown_keys(entry: dict, allowed, where: str, problems: list[Problem]) -> None:
    """A problem per key of ``entry`` not in ``allowed``, with the closest."""
    for key in entry:
        if key not in allowed:
            problems.append(Problem(where, f"unknown key {echo(key)}{closest(key, allowed)}; "
                                           f"allowed keys: {', '.join(allowed)}"))

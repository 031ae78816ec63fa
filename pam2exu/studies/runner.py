"""Running a study: every check before any variant runs, each variant built and run in a
worker from the model's text and its values, the chunks of variants run and merged in
variant order, the result (``result.StudyResult``).

A worker receives a payload of plain data (``payload``: the model's text, the analysis
settings, the reductions, the requirements, the parameters' names), never solver objects,
with its chunk's variants' values only, and runs rows ``start … stop − 1``
(``run_variants``). A variant that fails is a row with status ``error``: a pam2exu error
with its class and message, any other exception named as a fault of pam2exu. It never
stops the study.
"""
from __future__ import annotations

import contextlib
import dataclasses
import gc
import os
import tempfile
import warnings
from pathlib import Path

import numpy as np

from ..analyses.rank import references
from ..errors import (InputWarning, ModelError, OutputError, Pam2ExuError, Problem,
                      warn_outside)
from ..registry import ANALYSES, analysis_type
from .batch import answered, one_pass, one_pass_of
from .execute import open_executor, run_chunks, warm, workers_of
from .messages import WARNINGS, kind
from .nominal import shares_nominal, sharing
from .parameters import varied
from .parts import clear_parts, plan_chunks
from .linear import LinearResult, sensitivities
from .reduce import (ERROR, LINEAR_STD, Variant, output_columns, reduce_run, reduced_names,
                     status, variant_table)
from .result import StudyResult, check_out
from .series import (WARN_BYTES, chunk_series, long_table, memory_problem, memory_text,
                     series_bytes, series_outputs, series_rows, split, variant_series)
from .study import MAX_SAMPLES, SAMPLED, Study, load_study, too_many

#: the analyses a study runs today, as the registry declares them (``in_studies``: each
#: variant runs as a single run would, the equilibrium and dynamic analyses with the model's
#: [analysis] tolerance, the clearance analysis from the nominal assembly to the parts as
#: made: ``AnalysisType.parts_as_made``)
STUDY_ANALYSES = tuple(a.name for a in ANALYSES.values() if a.in_studies)
#: the analyses the first-order method differentiates (``AnalysisType.first_order``)
FIRST_ORDER_ANALYSES = tuple(a.name for a in ANALYSES.values() if a.first_order)
#: the methods a study runs: sampled, a grid, and first order (``linear.py``)
STUDY_METHODS = SAMPLED + ("grid", "linear")
#: variants a chunk holds at least when they are solved in one pass (``batch``): the pass
#: costs about 7 µs per variant-step for 400 four-bars against 55 for 50 (in-process, idle)
ONE_PASS_VARIANTS = 400
#: what an error row's message says of an exception that is not a pam2exu error
FAULT = "fault of pam2exu (please report it with the study)"
#: the estimate of a variant's work per row of its result [s] (for the chunks' size; no
#: result depends on it): 1.3 ms measured for the slider-crank's kinetostatic analysis
SECONDS_PER_ROW = 1.5e-3


def error_text(exc: BaseException) -> str:
    """An error row's ``error``: '<class>: <message>' of a pam2exu error, else the fault's."""
    head = type(exc).__name__ if isinstance(exc, Pam2ExuError) else \
        f"{FAULT}: {type(exc).__name__}"
    return f"{head}: {exc}"


def run_variant(payload: dict, values: np.ndarray, made=None, solved=None, engine=None):
    """One variant's (reduced outputs, status, warnings, series), or (None, error text,
    warnings, None): an ``Exception`` of the variant is never raised (KeyboardInterrupt and
    SystemExit pass), its warnings are not issued but returned (``warned``). The series
    (``series.variant_series``: t, then each output) only when the payload asks for them,
    else None. ``made``: (its model, the warnings making it gave) from ``made_variant``
    (None: made here); ``solved``: (its mechanism, the backend holding its answers) from
    ``batch.answered``; else ``engine``, the chunk's backend (``nominal.sharing``), solves
    it, or None: the payload's backend by name."""
    from ..analyses import run
    model, early = made if made is not None else (None, [])
    with warnings.catch_warnings(record=True) as caught:   # each variant's: not the study's
        warnings.simplefilter("always")
        try:
            if model is None:
                model = variant_model(payload, values)
            subject, backend = solved if solved is not None else (
                model, engine if engine is not None else payload.get("backend"))
            res = run(subject, payload["analysis"], t_end=payload["t_end"],
                      steps=payload["steps"], outputs=payload["outputs"], backend=backend)
            reduced = reduce_run(res, payload["outputs"], payload["reduce"])
            kept = None if payload.get("series") is None else \
                variant_series(res, output_columns(res.columns, payload["outputs"]),
                               payload.get("series"))
            return (reduced, status(reduced, payload["requirements"]),
                    warned(early + caught), kept)
        except Exception as exc:                      # noqa: BLE001 (a failure is data)
            return None, error_text(exc), warned(early + caught), None


def variant_model(payload: dict, values: np.ndarray):
    """The variant's model: the payload's model text with its values (``varied``)."""
    return varied(payload["model_text"], dict(zip(payload["names"], values)),
                  payload["source"], as_made=payload.get("as_made", False))


def made_variant(payload: dict, values: np.ndarray):
    """(the variant's model, the warnings making it gave), or (None, []) when it cannot be
    made (its ``run_variant`` then makes it again and reports why)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            return variant_model(payload, values), caught
        except Exception:                             # noqa: BLE001 (its run reports it)
            return None, []


def warned(caught: list) -> str:
    """A variant's warnings, one line each ('<class>: <first line of the message>'), the
    first of each kind (``messages.kind``) only, in the order issued; '' for none."""
    lines: dict[str, str] = {}
    for w in caught:
        line = f"{w.category.__name__}: {str(w.message).splitlines()[0] if str(w.message) else ''}"
        lines.setdefault(kind(line), line)
    return "\n".join(lines.values())


def run_variants(payload: dict, start: int, stop: int, values: np.ndarray
                 ) -> dict[str, np.ndarray]:
    """The per-variant columns of rows ``start … stop − 1`` (``reduce.variant_table``),
    their warnings (the column ``messages.WARNINGS``, which ``StudyResult`` takes out) and,
    with a study that keeps them, the series' 2-D columns (``series.chunk_series``): the
    worker's task, a top-level function of plain data.

    Parameters
    ----------
    payload : dict
        ``payload(study, outputs)``: model text and source, analysis, t_end, steps,
        outputs, reduce, requirements, the parameters' names, the rows of a variant's
        series (None: no series).
    start, stop : int
        The rows.
    values : array (stop − start, parameters)
        The chunk's variants' values (its rows of ``Study.variants``).
    """
    rows, warned_rows, kept = [], [], []
    made = solved = [None] * (stop - start)
    frozen = False
    engine = (sharing(payload["backend"])   # (no backend named: each run's own, alone)
              if payload.get("shares_nominal") and payload.get("backend") else None)
    try:
        if one_pass(payload):              # the chunk's positions in one pass
            (made, solved), frozen = set_apart(lambda: _one_pass(payload, values))
        with references():                 # the condition checks bound κ from the first's
            for i in range(start, stop):
                row = values[i - start]
                reduced, outcome, warned_text, series = run_variant(
                    payload, row, made[i - start], solved[i - start], engine)
                made[i - start] = solved[i - start] = None       # its objects may go now
                rows.append(Variant(i, ERROR, outcome, tuple(row), None) if reduced is None
                            else Variant(i, outcome, "", tuple(row), reduced))
                warned_rows.append(warned_text)
                kept.append(series)
    finally:
        if frozen:
            gc.unfreeze()
    table = variant_table(payload["names"], payload["reduced"], rows)
    table[WARNINGS] = np.array(warned_rows, dtype=str)
    if payload.get("series") is not None:
        table.update(chunk_series(kept, len(series_outputs(payload["reduced"])),
                                  payload.get("series")))
    return table


def _one_pass(payload: dict, values: np.ndarray) -> tuple[list, list]:
    """(made, solved) of a chunk's variants: each one's model (``made_variant``) and its
    answers from the one pass (``batch.answered``)."""
    made = [made_variant(payload, v) for v in values]
    return made, answered(payload, [model for model, _ in made])


def set_apart(make):
    """(``make()``, frozen): ``make()`` run with Python's cyclic garbage collector paused,
    and every object alive then set apart from the collector (``gc.freeze``: frozen True;
    the caller's ``gc.unfreeze`` gives them back), unless objects were set apart already
    (by the program that runs the study: its own are left as they are).

    The one pass makes objects that all live until their variants have run: the
    collector's passes over them would free nothing, and one full pass over the ~170,000
    objects of 400 four-bars costs ~0.1–0.2 s (2–4 % of the chunk). Objects that go are
    still freed by their reference counts."""
    enabled, frozen = gc.isenabled(), gc.get_freeze_count() == 0
    gc.disable()
    try:
        out = make()
        if frozen:
            gc.freeze()
        return out, frozen
    finally:
        if enabled:
            gc.enable()


def payload(study: Study, reduced: list[str]) -> dict:
    """What every worker receives: plain data, no solver objects, and not the variants'
    values (each chunk is sent its own rows of ``Study.variants``: ``run_chunks``' rows)."""
    return {"model_text": study.model_text, "source": str(study.model_path),
            "analysis": study.analysis, "t_end": study.t_end, "steps": study.steps,
            "outputs": study.outputs, "reduce": list(study.reduce),
            "requirements": [tuple(r) for r in study.requirements], "names": study.names,
            "reduced": reduced,
            "series": series_rows(analysis_type(study.analysis).at_start, study.steps)
            if study.series else None,
            "as_made": analysis_type(study.analysis).parts_as_made,
            "shares_nominal": shares_nominal(study),
            "backend": study.backend, "batched": study.batched}


def prepared(study: Study, samples: int | None = None) -> Study:
    """The study as it will run (``samples`` overriding its own); ``ModelError`` naming the
    entry for what a study cannot do today (a linear study of an analysis it cannot
    differentiate)."""
    problems = []
    if study.method not in STUDY_METHODS:
        problems.append(Problem("[study]", f"method = '{study.method}' is not available yet: "
                                           f"a study runs {', '.join(STUDY_METHODS)} today"))
    kind = analysis_type(study.analysis)
    if study.method == "linear" and kind is not None and not kind.first_order:
        problems.append(Problem("[study]", f"method = 'linear' differentiates the "
                                           f"{', '.join(FIRST_ORDER_ANALYSES)} analyses, "
                                           f"not {study.analysis}: sample it instead "
                                           "(monte_carlo, latin_hypercube, sobol)"))
    elif kind is not None and not kind.in_studies:
        problems.append(Problem("[study]", f"analysis = '{study.analysis}' is not available in "
                                           f"a study yet: a study runs "
                                           f"{', '.join(STUDY_ANALYSES)} analyses today"))
    if samples is not None:
        if isinstance(samples, bool) or not isinstance(samples, int) or samples < 1:
            problems.append(Problem("samples", f"must be a whole number ≥ 1, got {samples!r}"))
        elif samples > MAX_SAMPLES:
            problems.append(Problem("samples", too_many(f"{samples:,} variants")))
        elif study.method not in SAMPLED:
            problems.append(Problem("samples", f"a {study.method} study takes no samples: it "
                                               "runs every combination of the values lists"))
        else:
            study = dataclasses.replace(study, samples=samples)
    if problems:
        raise ModelError(problems, study.source, kind="study")
    return study


def nominal(study: Study):
    """The nominal model's run (its warnings issued): the reduced outputs' names and units;
    ``ModelError`` when it fails (a study varies a model that runs)."""
    from ..analyses import run
    try:
        res = run(study.model, study.analysis, t_end=study.t_end, steps=study.steps,
                  outputs=study.outputs, backend=study.backend)
    except ModelError as exc:
        raise ModelError([Problem(f"[study] model '{study.model_path}'", str(exc))],
                         study.source, kind="study") from None
    except Pam2ExuError as exc:
        raise ModelError([Problem("[study]", f"the nominal model fails ({type(exc).__name__}: "
                                             f"{exc}): a study varies a model that runs")],
                         study.source, kind="study") from None
    names = reduced_names(res.columns, study.outputs, study.reduce)
    missing = [Problem(f"[[requirement]] '{r.output}'", f"'{r.output}' is not among the "
                                                        f"reduced outputs of the {study.analysis} "
                                                        "analysis")
               for r in study.requirements if r.output not in names]
    if missing:
        raise ModelError(missing, study.source, kind="study")
    if study.series:
        check_series_memory(study, len(res.t), len(series_outputs(names)))
    units = {n: res.units.get(n.rpartition(".")[0], "") for n in names}
    units.update({c: res.units.get(c, "") for c in series_outputs(names)} if study.series
                 else {})
    return names, units


def check_series_memory(study: Study, rows: int, outputs: int) -> None:
    """A study whose series would not fit in this machine's memory is a ``ModelError``
    (``series.memory_problem``); one that would take more than ``series.WARN_BYTES``, an
    ``InputWarning`` saying how much."""
    problem = memory_problem(study.samples, rows, outputs)
    if problem:
        raise ModelError([Problem("[study] series", problem)], study.source, kind="study")
    if series_bytes(study.samples, rows, outputs) > WARN_BYTES:
        warn_outside(f"{study.source}: [study] {memory_text(study.samples, rows, outputs)}",
                     InputWarning)


def chunks_of(study: Study, workers: int) -> list[tuple[int, int]]:
    """The chunks of the study's variants (``parts.plan_chunks``), from an estimate of a
    variant's work that does not depend on timing (its rows × ``SECONDS_PER_ROW``); at
    least ``ONE_PASS_VARIANTS`` a chunk when its variants are solved in one pass."""
    least = ONE_PASS_VARIANTS if one_pass_of(study) else 1
    return plan_chunks(study.samples, (study.steps + 1) * SECONDS_PER_ROW, workers, least)


def linear_estimate(run_as: Study, names: list[str], asked: bool = False):
    """The sensitivities at the nominal variant of a sampled study (``linear.py``): for the
    linear σ of its ``final`` and ``mean`` reductions, or ``asked`` (a tornado plot). (None,
    why) when the study has no use for them or they cannot be given; ``ModelError`` when
    they were asked for and cannot be given."""
    kind = analysis_type(run_as.analysis)
    if asked and run_as.method not in SAMPLED:
        raise ModelError([Problem("[study]", f"no sensitivities for a {run_as.method} study: "
                                             "the tornado weighs them by the parameters' "
                                             "distributions; sample the study "
                                             "(monte_carlo, latin_hypercube, sobol) or use "
                                             "method = 'linear'")],
                         run_as.source, kind="study")
    if run_as.method not in SAMPLED or not (asked or any(r in LINEAR_STD
                                                         for r in run_as.reduce)):
        return None, ""
    if not kind.first_order:
        why = f"the first-order method does not differentiate the {run_as.analysis} analysis"
        if asked:
            raise ModelError([Problem("[study]", f"no sensitivities: {why}")], run_as.source,
                             kind="study")
        return None, f"linear σ: {why}"
    try:
        return sensitivities(run_as), ""
    except ModelError as exc:
        if asked:
            raise
        return None, f"linear σ not available: {exc}"


def checked(study_or_path, out=None, resume: bool = False, samples: int | None = None):
    """Every check before any variant runs: (the study as it runs, its reduced outputs'
    names and units, ``out`` checked); ``ModelError`` or ``OutputError`` otherwise."""
    given = study_or_path if isinstance(study_or_path, Study) else load_study(study_or_path)
    run_as = prepared(given, samples)
    if out is not None:
        out = check_out(out)
    elif resume:
        raise OutputError("resume needs out: the finished chunks are under OUT.parts/")
    names, units = nominal(run_as)
    return run_as, names, units, out


def run_checked(run_as: Study, names: list[str], units: dict, out=None, executor=None,
                resume: bool = False, workers: int = 1, progress: bool = False,
                first_order: bool = False) -> StudyResult:
    """Run a checked study's chunks on ``executor`` (``execute.run_chunks``; parts under
    ``OUT.parts/``, removed once the files are written) and build its result; a linear
    study: its sensitivities at the nominal variant (``linear.py``), in this process.
    ``first_order``: a sampled study's sensitivities are wanted (a tornado plot), not only
    for the linear σ of its ``final`` and ``mean`` reductions."""
    if run_as.method == "linear":
        result = LinearResult(run_as, sensitivities(run_as), names)
        if out is not None:
            result.write(out)
        return result
    sens, note = linear_estimate(run_as, names, first_order)
    with contextlib.ExitStack() as stack:
        parts = Path(f"{out}.parts") if out is not None else \
            Path(stack.enter_context(tempfile.TemporaryDirectory(prefix="pam2exu-study-")))
        done = run_chunks(run_variants, payload(run_as, names), chunks_of(run_as, workers),
                          parts, executor, resume=resume, progress=progress,
                          rows=run_as.variants())
    table, series = split(done.columns)
    result = StudyResult(run_as, table, names, units,
                         long_table(table, series, series_outputs(names)) if series else None,
                         sens, note)
    if out is not None:
        result.write(out)
        clear_parts(parts)
    return result


def study(study_or_path, executor=None, out=None, resume: bool = False,
          samples: int | None = None, workers: int | None = None,
          progress: bool = False, first_order: bool = False):
    """Run a study: every variant of it, reduced, with the summary and the yield.

    Parameters
    ----------
    study_or_path : Study, str or Path
        A study (``load_study``) or its file.
    executor : concurrent.futures.Executor or dask.distributed.Client, optional
        Runs the chunks of variants (default: this process, or a process pool of
        ``workers``); the table is the same, bit for bit, whatever runs it.
    out : str or Path, optional
        The per-variant table's file, ``.parquet`` or ``.csv`` (the summary beside it,
        ``OUT.summary.csv``, and with ``series = true`` ``OUT.series.parquet`` or
        ``OUT.series.csv``); checked before any variant runs. None: nothing written.
    resume : bool
        Run only the chunks missing under ``OUT.parts/`` (a study interrupted keeps every
        finished chunk there; the parts are removed once the files are written).
    samples : int, optional
        The number of variants, instead of the study's (sampled methods).
    workers : int, optional
        Local worker processes (default 1: this process); with ``executor``, the processes
        it runs at once, for the chunks' size (default: a Dask cluster's threads, else the
        cores).
    progress : bool
        A progress bar on a terminal (variants done, rate, time left).
    first_order : bool
        Also compute a sampled study's sensitivities at the nominal variant
        (``StudyResult.sensitivities``, ``StudyResult.tornado``), not only for the linear
        σ of its ``final`` and ``mean`` reductions.

    Returns
    -------
    StudyResult or LinearResult
        A linear study (``method = "linear"``) gives a ``linear.LinearResult``: its table
        is one row per output time (t, each output, its σ and its ∂y/∂p).

    Raises
    ------
    ModelError
        The study file has problems, asks what a study cannot do (``linear`` of an
        analysis it cannot differentiate), or its nominal model does not run; nothing is
        written.
    OutputError
        ``out`` has an unknown suffix or needs a library that is not installed; ``resume``
        without ``out``.
    ChunkError
        A chunk's worker was lost more often than it is retried (the finished chunks are
        kept under ``OUT.parts/`` for ``resume``).

    Examples
    --------
    >>> import pam2exu
    >>> result = pam2exu.study("examples/studies/slider_crank_tolerance.toml",
    ...                        samples=3)                                # doctest: +SKIP
    >>> result.yield_.share                                              # doctest: +SKIP
    1.0
    """
    if executor is None:                 # the pool's server imports meanwhile
        warm(workers or 1)
    run_as, names, units, out = checked(study_or_path, out, resume, samples)
    if executor is not None:
        return run_checked(run_as, names, units, out, executor, resume,
                           workers or workers_of(executor, os.cpu_count() or 1), progress,
                           first_order)
    with open_executor(workers or 1) as pool:
        return run_checked(run_as, names, units, out, pool, resume, workers or 1, progress,
                           first_order)

"""Section 6: the two backends side by side, on the same runs of the same benchmark run.

``side_by_side`` times every configuration on each backend of ``Plan.backends`` end to end
through ``pam2exu.run(model, analysis=..., steps=..., backend=...)`` at the backend's default
settings (a loaded ``Model``; no ``solver`` argument), best of several repeats taken round
the grid with the backends in alternation (their order swapped every repeat), so that a
ratio of the two comes from runs a few seconds apart. Its cases: the four-bar
(examples/four_bar.toml), kinematic and kinetostatic, ``Plan.backend_steps`` steps; the
chain of N four-bar loops (cases.py), kinematic and kinetostatic, N = ``Plan.chain_sizes``,
``Plan.chain_steps`` steps. Errors against the closed forms and the Newton–Euler references
as everywhere in the benchmark (measure.error_summary), from each backend's first run.

``memory`` runs the kinematic four-bar with ``Plan.memory_steps`` steps once per backend,
each in a fresh Python process (``python -m benchmarks.backends --memory BACKEND STEPS``,
``memory_child``): the peak resident set size of that process, read in it right after
``pam2exu.run`` returns (or fails), before anything else is computed: ``VmHWM`` of
/proc/self/status (``peak_kib``). Not ``ru_maxrss``: on Linux a child started from this
process inherits its high-water mark through fork and exec (RUSAGE_SELF in the child and
RUSAGE_CHILDREN here would both report at least the benchmark's own size); ``ru_maxrss``
is the fallback where /proc is missing.

A run that raises is recorded as a ``Failure`` (the exception and the last lines of its
traceback) and reported as such; it is not repeated.
"""
from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import time
import traceback
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

if __package__ in (None, ""):          # python benchmarks/backends.py: the clone's packages
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import pam2exu  # noqa: E402
from pam2exu import registry  # noqa: E402

from benchmarks.cases import CHAIN, chain_model, chain_reference, four_bar_case  # noqa: E402
from benchmarks.measure import ROOT, Run, error_summary, log  # noqa: E402

#: the name of each backend on the page
LABELS = {"exudyn": "Exudyn", "natural": "natural"}


def label(backend):
    return LABELS.get(backend, backend)


def default_tolerance(backend):
    """The default tolerance of a backend's own settings class."""
    return registry.BACKENDS[backend].create().Settings().tolerance


@dataclass
class Failure:
    """A run that raised: what and where."""

    backend: str
    text: str                    # "SolverError: the message"
    trace: str                   # the last lines of the traceback

    @classmethod
    def of(cls, backend, exc):
        lines = traceback.format_exception(type(exc), exc, exc.__traceback__)
        return cls(backend, f"{type(exc).__name__}: {exc}", "".join(lines[-4:]).rstrip())

    @property
    def short(self):
        first = self.text.splitlines()[0]
        return first if len(first) <= 240 else first[:237] + "…"


def run_backend(model, analysis, steps, backend, t_end=1.0):
    """One end-to-end run at the backend's default settings: (wall seconds, Results)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        start = time.perf_counter()
        res = pam2exu.run(model, analysis=analysis, t_end=t_end, steps=steps, backend=backend)
        return time.perf_counter() - start, res


@dataclass
class Config:
    """One case and analysis, run on every backend."""

    case: str
    model: object
    analysis: str
    steps: int
    repeats: int
    N: int | None = None

    def __post_init__(self):
        self.runs = {}           # backend -> Run or Failure


def _first(config, backend, kin, forces, L, w):
    """The first run of a configuration on one backend: a Run with its errors, or a Failure."""
    try:
        seconds, res = run_backend(config.model, config.analysis, config.steps, backend)
    except Exception as exc:      # every failure is a result of the benchmark
        failure = Failure.of(backend, exc)
        log(f"  {config.case} {config.analysis} {config.steps:,} steps, {label(backend)}: "
            f"FAILED\n{failure.trace}")
        return failure
    errors = error_summary(res, kin, forces if config.analysis == "kinetostatic" else None,
                           L, w)
    return Run(config.case, config.analysis, config.steps, default_tolerance(backend), seconds,
               res.info["backend_seconds"] or 0.0, errors, "", list(res.warnings))


def chain_repeats(plan, N):
    """Repeats of the chain of N loops in section 6: 3 up to N = 8, then 2 (fewer with
    fewer ``Plan.backend_repeats``)."""
    return min(plan.backend_repeats, 3 if N <= 8 else 2)


def side_by_side(plan):
    """Section 6's timed runs. Returns {"four_bar": [Config], "chain": [Config]}, each
    Config's ``runs`` the Run (or Failure) of every backend."""
    backends = plan.backends
    model, reference, L, w = four_bar_case()
    steps = plan.backend_steps
    kin, forces = reference(np.arange(steps + 1) / steps)
    four_bar = [Config("four-bar", model, analysis, steps, plan.backend_repeats)
                for analysis in ("kinematic", "kinetostatic")]
    for c in four_bar:
        for b in backends:
            c.runs[b] = _first(c, b, kin, forces, L, w)
        log(f"  four-bar {c.analysis:12s} {steps:,} steps: " + compare_line(c))
    del kin, forces
    chain = []
    t = np.arange(plan.chain_steps + 1) / plan.chain_steps
    for N in plan.chain_sizes:
        model = chain_model(N)
        kin, forces = chain_reference(N, t)
        w = float(np.max(np.abs(kin[f"L{N}.Dfi"])))
        L = 0.4 + N * CHAIN["d"]
        repeats = chain_repeats(plan, N)
        for analysis in ("kinematic", "kinetostatic"):
            c = Config(f"chain N={N}", model, analysis, plan.chain_steps, repeats, N)
            for b in backends:
                c.runs[b] = _first(c, b, kin, forces, L, w)
            chain.append(c)
            log(f"  chain N={N:3d} {analysis:12s}: " + compare_line(c))
    configs = four_bar + chain
    for k in range(1, max(c.repeats for c in configs)):
        order = backends if k % 2 == 0 else tuple(reversed(backends))
        for c in configs:
            if k >= c.repeats:
                continue
            for b in order:
                r = c.runs[b]
                if isinstance(r, Failure):
                    continue
                try:
                    seconds, res = run_backend(c.model, c.analysis, c.steps, b)
                except Exception as exc:     # failed now, not the first time: noted
                    log(f"  {c.case} {c.analysis}, {label(b)}: repeat {k + 1} failed: "
                        f"{type(exc).__name__}: {exc}")
                    continue
                if seconds < r.seconds:
                    r.seconds, r.exudyn_seconds = seconds, res.info["backend_seconds"] or 0.0
        log(f"  repeat {k + 1} done")
    for c in configs:
        log(f"  {c.case:12s} {c.analysis:12s} best: " + compare_line(c))
    return {"four_bar": four_bar, "chain": chain}


def compare_line(config):
    parts = []
    for b, r in config.runs.items():
        if isinstance(r, Failure):
            parts.append(f"{label(b)} failed ({r.short[:80]})")
        else:
            pos = r.errors.get("positions", (math.nan, ""))[0]
            parts.append(f"{label(b)} {r.us:.2f} µs/step (positions solve "
                         f"{r.exudyn_us:.2f}), positions {pos:.1e}")
    return "; ".join(parts)


# ---- peak memory, one process per run ------------------------------------------------------

def memory(plan):
    """{backend: dict} of the memory runs (``memory_child``'s numbers, or the crash)."""
    out = {}
    for b in plan.backends:
        command = [sys.executable, "-m", "benchmarks.backends", "--memory", b,
                   str(plan.memory_steps)]
        start = time.perf_counter()
        done = subprocess.run(command, cwd=ROOT, capture_output=True, text=True)
        line = next((x for x in reversed(done.stdout.splitlines())
                     if x.startswith("MEMORY ")), None)
        if line is None:              # the process itself died (killed, out of memory)
            out[b] = {"backend": b, "steps": plan.memory_steps, "ok": False,
                      "seconds": time.perf_counter() - start, "peak_kib": None,
                      "error": f"the process ended with code {done.returncode}",
                      "trace": done.stderr.strip()[-1500:]}
        else:
            out[b] = json.loads(line[len("MEMORY "):])
        r = out[b]
        peak = f"{r['peak_kib'] * 1024 / 1e6:.0f} MB" if r["peak_kib"] else "–"
        log(f"  {label(b)}: {plan.memory_steps:,} steps, peak {peak}, {r['seconds']:.1f} s"
            + ("" if r["ok"] else f", FAILED: {r['error'][:300]}\n{r.get('trace', '')}"))
    return out


def peak_kib():
    """(peak resident set size of this process [KiB], how it was read): VmHWM of
    /proc/self/status, else ru_maxrss (which may include a parent's high-water mark)."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmHWM:"):
                return int(line.split()[1]), "VmHWM"
    except OSError:
        pass
    import resource
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss, "ru_maxrss"


def memory_child(backend, steps):
    """One kinematic four-bar run of ``steps`` steps in this process; prints one line
    ``MEMORY {json}``: wall seconds, the peak RSS before and after the run [KiB]
    (``peak_kib``), the size of the result table, and the largest position error against
    the closed form (computed after the peak was read)."""
    import exudyn  # noqa: F401  (loaded before the baseline, whichever backend runs)

    model, reference, L, w = four_bar_case()
    baseline, how = peak_kib()
    out = {"backend": backend, "steps": steps, "baseline_kib": baseline, "measure": how}
    res = None
    start = time.perf_counter()
    try:
        _, res = run_backend(model, "kinematic", steps, backend)
    except Exception as exc:      # reported with its peak so far
        failure = Failure.of(backend, exc)
        out.update(error=failure.text, trace=failure.trace)
    out["seconds"] = time.perf_counter() - start
    out["peak_kib"] = peak_kib()[0]
    out["ok"] = res is not None
    if res is not None:
        out["columns"] = len(res.columns)
        out["table_bytes"] = 8 * len(res.t) * (1 + len(res.columns))
        kin, _ = reference(res.t, forces=False)
        out["positions"] = list(error_summary(res, kin, None, L, w)["positions"])
    print("MEMORY " + json.dumps(out), flush=True)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description="one memory run of section 6")
    parser.add_argument("--memory", nargs=2, metavar=("BACKEND", "STEPS"), required=True)
    args = parser.parse_args()
    memory_child(args.memory[0], int(args.memory[1]))

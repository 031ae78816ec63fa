"""How one configuration is measured: the grids, best-of timing, and the errors against the
references.

``Plan`` holds the grids of a run (``FULL``, ``QUICK``). ``measure`` times one pam2exu
configuration (best of several ``pam2exu.run`` calls, ``run_pam``) and scores it against
its references (``error_summary``: the largest relative error of each kind of output, with
the error measures of references/closed_form.py and references/slider_crank.py); the
result is a ``Run``. ``machine`` describes the computer and the commit measured.
"""
from __future__ import annotations

import contextlib
import math
import os
import platform
import subprocess
import time
import warnings
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path

import exudyn as exu
import numpy as np

import pam2exu
from pam2exu.analyses import checks
from pam2exu.backend import SolveSettings
from references import closed_form, slider_crank

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_TOLERANCE = SolveSettings().tolerance
CATEGORIES = {"positions": ("x", "y", "fi"), "velocities": ("Dx", "Dy", "Dfi"),
              "accelerations": ("DDx", "DDy", "DDfi")}
KINDS = ("positions", "velocities", "accelerations", "reactions")


# ---- what to run ---------------------------------------------------------------------------

@dataclass
class Plan:
    """The grids of one benchmark run."""

    steps: tuple = (1000, 10000)
    big_steps: int = 100000                  # one more step count, four-bar only
    tolerances: tuple = (1e-6, 1e-9, 1e-13)
    repeats: int = 5
    big_repeats: int = 3                     # repeats of the runs of 100,000 steps
    compare_steps: tuple = (1000, 10000, 100000)
    compare_repeats: int = 10                # rounds, spread over the run
    chain_sizes: tuple = (1, 2, 4, 8, 16, 32, 64)
    chain_steps: int = 500
    long_turns: int = 100
    long_steps: int = 100000
    backends: tuple = ("exudyn", "natural")  # section 6: the backends side by side
    backend_steps: int = 100000              # four-bar steps of section 6
    backend_repeats: int = 4                 # its repeats (chain: 3 up to N = 8, then 2)
    memory_steps: int = 1000000              # four-bar steps of the memory runs
    clearance_repeats: int = 3               # section 7: repeats of each clearance way
    dynamic_tolerances: tuple = (1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10)   # section 8
    dynamic_repeats: int = 3                 # its repeats (one for a run over 20 s)
    study_variants: int = 2000               # section 9: the four-bar study's variants
    study_steps: int = 100                   # and each variant's steps


FULL = Plan()
QUICK = Plan(steps=(1000,), big_steps=0, tolerances=(1e-6, 1e-13), repeats=2, big_repeats=1,
             compare_steps=(2000,), compare_repeats=5, chain_sizes=(1, 2, 4, 8),
             chain_steps=200, long_turns=10, long_steps=10000, backend_steps=5000,
             backend_repeats=1, memory_steps=20000, clearance_repeats=1,
             dynamic_tolerances=(1e-4, 1e-6), dynamic_repeats=1, study_variants=40,
             study_steps=20)


# ---- timing --------------------------------------------------------------------------------

def best_of(fn, repeats):
    """(least wall time [s], the result of that run) over ``repeats`` calls of fn()."""
    best, out = math.inf, None
    for _ in range(repeats):
        start = time.perf_counter()
        value = fn()
        seconds = time.perf_counter() - start
        if seconds < best:
            best, out = seconds, value
    return best, out


@contextlib.contextmanager
def residual_check_off():
    """Switch off pam2exu's after-run residual check (loose tolerances only, marked †)."""
    saved = checks.RESIDUAL_TOLERANCE
    checks.RESIDUAL_TOLERANCE = math.inf
    try:
        yield
    finally:
        checks.RESIDUAL_TOLERANCE = saved


@dataclass
class Run:
    """One timed pam2exu configuration."""

    case: str
    analysis: str
    steps: int
    tolerance: float
    seconds: float                          # best total wall time
    exudyn_seconds: float                   # its res.info['backend_seconds']
    errors: dict = field(default_factory=dict)   # kind -> (max relative error, column)
    note: str = ""
    warnings: list = field(default_factory=list)  # res.warnings (texts)

    @property
    def us(self):
        return 1e6 * self.seconds / self.steps

    @property
    def exudyn_us(self):
        return 1e6 * self.exudyn_seconds / self.steps


def run_pam(model, analysis, steps, t_end, tolerance, repeats, dense=None):
    """Best-of-``repeats`` timing of pam2exu.run; returns (seconds, result, note).

    pam2exu's warnings are not shown (they are kept in ``res.warnings`` and reported).
    A tolerance too loose for pam2exu's residual check (constraint residual above 1e-8 of
    the length scale: pam2exu stops with TranslationError) is run again with the check
    switched off, so that its error can still be measured; the note says so.
    """
    def once():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return pam2exu.run(model, analysis=analysis, t_end=t_end, steps=steps,
                               solver=SolveSettings(tolerance=tolerance, dense=dense))
    try:
        seconds, res = best_of(once, repeats)
        return seconds, res, ""
    except pam2exu.TranslationError:
        with residual_check_off():
            seconds, res = best_of(once, repeats)
        return seconds, res, "†"


def measure(case, model, analysis, steps, t_end, tolerance, repeats, kin, forces, L, w,
            dense=None, keep=False):
    """Time one configuration and compare it with its references; a Run (with the Results
    as ``run.res`` if ``keep``)."""
    seconds, res, note = run_pam(model, analysis, steps, t_end, tolerance, repeats, dense)
    errors = error_summary(res, kin, forces if analysis == "kinetostatic" else None, L, w)
    run = Run(case, analysis, steps, tolerance, seconds, res.info["backend_seconds"], errors,
              note, list(res.warnings))
    if keep:
        run.res = res
    return run


def describe(run):
    return (f"{run.us:8.1f} µs/step (Exudyn {run.exudyn_us:7.1f}) "
            + " ".join(f"{k[:3]} {v[0]:.1e}" for k, v in run.errors.items()) + run.note
            + (f" [{len(run.warnings)} warning(s)]" if run.warnings else ""))


def warning_summary(runs):
    """The distinct warnings of some runs, each shortened to its first clause."""
    texts = [w.split(":")[0].split(" (")[0] for r in runs for w in r.warnings]
    return "; ".join(dict.fromkeys(texts))


# ---- errors --------------------------------------------------------------------------------

def error_summary(res, kin_ref, force_ref, L, w):
    """{kind: (max relative error, worst column)} for the kinds the references cover.

    Kinematics: ``errors`` of references/closed_form.py (per column max |res − ref| over
    the largest |ref| of that column; a column whose reference is ~0 uses the natural
    scale L, L·w, L·w²). Reactions: ``errors`` of references/slider_crank.py (the same; a
    ~0 column uses the largest |ref| of all reaction columns).
    """
    out = {}
    kin = closed_form.errors(res, {c: v for c, v in kin_ref.items() if c in res.columns}, L, w)
    for kind, suffixes in CATEGORIES.items():
        cols = {c: v for c, v in kin.items() if c.rsplit(".", 1)[1] in suffixes}
        if cols:
            worst = max(cols, key=cols.get)
            out[kind] = (cols[worst], worst)
    if force_ref and all(c in res.columns for c in force_ref):
        forces = slider_crank.errors(res, force_ref)
        worst = max(forces, key=forces.get)
        out["reactions"] = (forces[worst], worst)
    return out


def at_row(res, ref, row, L, w):
    """The kinematic errors of one row only, with the scales of ``error_summary`` (the
    largest |reference| of each column over the whole run)."""
    fallback = closed_form.natural_scales(L, w)
    out = {}
    for kind, suffixes in CATEGORIES.items():
        worst, where = 0.0, ""
        for c, v in ref.items():
            suffix = c.rsplit(".", 1)[1]
            if suffix not in suffixes or c not in res.columns:
                continue
            v = np.broadcast_to(np.asarray(v, dtype=float), res.t.shape)
            scale = float(np.max(np.abs(v)))
            if scale < 1e-9 * fallback[suffix]:
                scale = fallback[suffix]
            e = abs(float(res[c][row]) - float(v[row])) / scale
            if e >= worst:
                worst, where = e, c
        out[kind] = (worst, where)
    return out


class LastRow:
    """The last row of a Results, for the error functions of the tests."""

    def __init__(self, res):
        self.res, self.t = res, res.t[-1:]

    def __getitem__(self, c):
        return self.res[c][-1:]


def fit_exponent(N, y):
    """p of y ≈ C N^p, least squares in log-log."""
    return float(np.polyfit(np.log(N), np.log(y), 1)[0])


# ---- the machine and the log -------------------------------------------------------------

def machine():
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    ram = ""
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemTotal"):
                ram = f"{int(line.split()[1]) / 2**20:.0f} GiB"
    except OSError:
        pass
    os_name = platform.platform()
    try:
        for line in Path("/etc/os-release").read_text().splitlines():
            if line.startswith("PRETTY_NAME="):
                os_name = line.split("=", 1)[1].strip('"') + f" (Linux {platform.release()})"
    except OSError:
        pass
    version = pam2exu.__version__
    try:
        head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, text=True,
                              capture_output=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--", "pam2exu"], cwd=ROOT,
                               text=True, capture_output=True, check=True).stdout.strip()
        version += f", commit {head}" + (" with uncommitted changes in pam2exu/" if dirty
                                         else "")
    except (OSError, subprocess.CalledProcessError):
        pass
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    return {"CPU": cpu, "cores": str(os.cpu_count()), "RAM": ram, "OS": os_name,
            "Python": platform.python_version(), "NumPy": np.__version__,
            "Exudyn": exu.__version__, "pam2exu": version,
            "date (UTC)": datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M"),
            "load averages at the start (1, 5, 15 min)": load}


def log(text):
    print(text, flush=True)

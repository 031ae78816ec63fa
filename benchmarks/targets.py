"""Issue 25's targets, every ratio measured in one run: the section "Targets of issue 25" of
docs/performance.md.

    python benchmarks/targets.py              # rewrites its section of docs/performance.md
    python benchmarks/targets.py --quick      # smoke run, tiny sizes, to a temporary directory
    python benchmarks/targets.py --variants 500 --passes 1   # smaller, to a temporary directory

One row per row of the issue's table, each ratio's two sides timed in this run, paired:

- clearance / kinematic (locomotive, 400 steps; ``all_elements``): ``clearance_speed.ratio``,
  the two analyses of one loaded model in alternation, best of each;
- natural / Exudyn (four-bar kinematic, 100 steps; the chain of 12 loops, kinetostatic,
  200 steps): ``natural_speed.paired``, the two backends in alternation, order swapped every
  repeat;
- the natural backend's kinetostatic four-bar per step / the plain Exudyn script's positions
  per step (``plain_exudyn.plain_exudyn_four_bar``, symbolic driver), 100,000 steps, with the
  Exudyn backend's kinetostatic run beside, the three in rotation;
- the issue's study as shipped (``STUDY_FILE``: the four-bar's kinetostatic tolerance study,
  2,000 variants × 100 steps, natural backend, variants in one pass) through the studies API
  (``workers.run_fresh``: ``pam2exu.studies``' ``study`` on the executor the command line would
  open, in-process and 2 worker processes, each in a fresh interpreter with pam2exu imported,
  so each pays its own executor's start as ``pam2exu study`` does, never one an earlier run
  left warm; the order swapped every other pass), its time per variant-step / the plain
  script's positions per step (timed just before and after it), and 1 worker / 2 workers
  (from asking for the executor until it is closed, each side), with the cores two
  processes got at once just before and after (``workers.cores_free``: on a shared machine,
  the most a pool of 2 can gain then); beside it the
  same study on the Exudyn backend (in-process) and pylinkage's ``analyze_tolerance`` where
  pylinkage imports (``studies.pylinkage_rows``);
- the Exudyn backend's positions (``predictor.pam_seconds``, the predictor as the run decides)
  / the plain script, and the four-bar at 0.003 rad per step (``predictor.slow_four_bar``),
  default / predictor never: in rounds, each side once per round in alternation.

The whole set is measured ``--passes`` times (default 2), one pass after the other, the order
of the groups reversed in every other pass; a row's *measured* is the mean of its passes'
ratios, with their range, and its verdict says whether every pass met the target. The
machine is shared: the load averages before and after are on the page, and only ratios of
the same pass are formed. pylinkage is not a dependency of pam2exu: run this file with an
interpreter that has it (``studies.py`` says how) to measure it.
"""
from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

if __package__ in (None, ""):          # python benchmarks/targets.py: the clone's packages
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import pam2exu  # noqa: E402

from benchmarks import clearance_speed, natural_speed, predictor, studies, workers  # noqa: E402
from benchmarks.dynamics import replace_section  # noqa: E402
from benchmarks.measure import ROOT, log, machine  # noqa: E402
from benchmarks.plain_exudyn import plain_exudyn_four_bar  # noqa: E402
from pam2exu.studies import load_study  # noqa: E402

BEGIN = ("<!-- targets of issue 25: written by benchmarks/targets.py (python "
         "benchmarks/targets.py rewrites it alone) -->")
END = "<!-- end of targets of issue 25 -->"
#: a page without the section gets it before this line
BEFORE = "## 1. Work against precision: four-bar and slider-crank"
#: the issue's study, as shipped: the four-bar's kinetostatic tolerance study, 2,000 variants
#: × 100 steps, on the natural backend (variants in one pass)
STUDY_FILE = ROOT / "examples" / "studies" / "four_bar_tolerance.toml"
TOLERANCE = 1e-13                       # the plain script's Newton tolerance (pam2exu's default)
VERDICTS = ("met", "not met", "met in", "not measured")


@dataclass(frozen=True)
class Sizes:
    """The sizes of one run (``FULL``: the issue's)."""

    passes: int = 2
    clearance_repeats: int = clearance_speed.REPEATS
    short_quick: bool = False            # natural_speed.RATIOS' fewer repeats
    long_steps: int = 100_000            # the four-bar's long runs
    long_repeats: int = 3                # their repeats (rounds)
    slow_steps: int = 110_000            # the four-bar at 0.003 rad per step
    variants: int = 2000                 # the study's
    study_steps: int = 100
    quick: bool = False


FULL = Sizes()
SIZE_LABELS = {"long_steps": "the four-bar's long runs, steps", "slow_steps": "steps at 0.003 "
               "rad per step", "variants": "the study's variants", "study_steps": "each "
               "variant's steps", "passes": "passes", "long_repeats": "rounds of the long runs",
               "clearance_repeats": "repeats of each clearance run"}
QUICK = Sizes(passes=1, clearance_repeats=1, short_quick=True, long_steps=5000,
              long_repeats=1, slow_steps=5500, variants=6, study_steps=10, quick=True)


@dataclass(frozen=True)
class Target:
    """One row of the issue's table."""

    key: str
    what: str
    target: float
    at_least: bool = False               # the ratio must be ≥ the target (a speed-up)

    def met(self, ratio: float) -> bool:
        return ratio >= self.target if self.at_least else ratio <= self.target

    @property
    def goal(self) -> str:
        value = f"{self.target:.1f}" if self.target == 1 else f"{self.target:g}"
        return f"{'≥' if self.at_least else '≤'} {value}×"


@dataclass
class Figure:
    """One pass's ratio of a row: the ratio, the figures it is made of, what is beside."""

    key: str
    ratio: float
    detail: str
    beside: str = "–"


@dataclass
class Measured:
    sizes: Sizes
    figures: dict = field(default_factory=dict)       # key -> [Figure, one per pass]
    loads: list = field(default_factory=list)         # (before, after) of each pass
    info: dict = field(default_factory=dict)
    minutes: float = 0.0
    pylinkage_note: str = ""


def targets(s: Sizes) -> list[Target]:
    """The issue's rows, with this run's sizes."""
    study = f"study, four-bar kinetostatic, {s.variants:,} variants × {s.study_steps} steps"
    return [
        Target("locomotive", clearance_speed.CASES[0][0], clearance_speed.CASES[0][3]),
        Target("all_elements", clearance_speed.CASES[1][0], clearance_speed.CASES[1][3]),
        Target("four_bar_short", "four-bar kinematic, 100 steps, natural / Exudyn",
               natural_speed.RATIOS[0][6]),
        Target("chain", "chain of 12 loops, kinetostatic, 200 steps, natural / Exudyn",
               natural_speed.RATIOS[1][6]),
        Target("natural_per_step", f"four-bar kinetostatic, {s.long_steps:,} steps, natural, "
               "per step / plain Exudyn script's positions per step", 0.12),
        Target("study", f"{study}, one worker, per variant-step / plain Exudyn positions per "
               "step", 0.3),
        Target("workers", "the same study, 2 workers / 1 worker (how many times faster)", 1.7,
               at_least=True),
        Target("positions", f"four-bar positions, {s.long_steps:,} steps / the plain Exudyn "
               "script, same run", 1.0),
        Target("predictor", f"four-bar at 0.003 rad per step ({s.slow_steps:,} steps): "
               "predictor on (the default, decided by the run) / off", 1.0),
    ]


# ---- measuring: each group of rows pairs what it compares -------------------------------

def four_bar():
    return pam2exu.load(ROOT / "examples" / "four_bar.toml")


def plain_seconds(steps: int) -> float:
    """One run of the plain Exudyn script's positions (building, solving, reading)."""
    return plain_exudyn_four_bar(steps, TOLERANCE, "symbolic")[1]


def clearance_rows(s: Sizes, _m: Measured):
    for key, (what, path, steps, _) in zip(("locomotive", "all_elements"),
                                           clearance_speed.CASES):
        c, k = clearance_speed.ratio(path, steps, s.clearance_repeats)
        yield Figure(key, c / k, f"clearance {c:.3f} s / kinematic {k:.3f} s (Exudyn "
                                 "backend)")


def natural_rows(s: Sizes, _m: Measured):
    for key, (_, make, analysis, steps, repeats, few, _) in zip(
            ("four_bar_short", "chain"), natural_speed.RATIOS):
        best = natural_speed.paired(make(), analysis, steps, few if s.short_quick else repeats)
        yield Figure(key, best["natural"] / best["exudyn"],
                     f"natural {1e3 * best['natural']:.1f} ms / Exudyn "
                     f"{1e3 * best['exudyn']:.1f} ms")


def natural_per_step_rows(s: Sizes, _m: Measured):
    model, n = four_bar(), s.long_steps
    jobs = {"natural": lambda: natural_speed.timed(model, "kinetostatic", n, "natural"),
            "plain": lambda: plain_seconds(n),
            "exudyn": lambda: natural_speed.timed(model, "kinetostatic", n, "exudyn")}
    best = rounds(jobs, s.long_repeats)
    us = {k: 1e6 * v / n for k, v in best.items()}
    yield Figure("natural_per_step", us["natural"] / us["plain"],
                 f"natural {us['natural']:.2f} µs/step / plain {us['plain']:.1f} µs/step",
                 f"Exudyn backend, kinetostatic: {us['exudyn']:.1f} µs/step, "
                 f"{us['exudyn'] / us['plain']:.2f}× the plain script")


def the_study(s: Sizes):
    """The issue's study as shipped (``STUDY_FILE``), at this run's size."""
    return replace(load_study(STUDY_FILE), samples=s.variants, steps=s.study_steps)


def study_rows(s: Sizes, m: Measured):
    studies.workers_see_this_clone()
    study = the_study(s)
    plain = plain_seconds(s.long_steps)
    second = len(m.loads) % 2 == 1              # every other pass: 2 workers first
    runs = [("in-process", 1), ("2 worker processes", 2)]
    done, table, free = {}, None, [workers.cores_free()]
    for label, count in (reversed(runs) if second else runs):
        row, out = workers.run_fresh(label, count, study, table)
        done[count], table = row, table if table is not None else out
    free.append(workers.cores_free())
    exudyn, _ = studies.run_on("in-process", 1, None, replace(study, backend="exudyn"))
    plain = min(plain, plain_seconds(s.long_steps))
    plain_us = 1e6 * plain / s.long_steps
    one, two = done[1], done[2]
    pylinkage, m.pylinkage_note = studies.pylinkage_rows(s.variants, [s.study_steps])
    p = pylinkage[0]
    beside = (f"the same study on the Exudyn backend (each variant its own run), one worker: "
              + (f"failed: {exudyn.failure}" if exudyn.failure else
                 f"{exudyn.us_per_variant_step:.0f} µs per variant-step, "
                 f"{exudyn.us_per_variant_step / plain_us:.2f}× the plain script") + "; "
              + (f"pylinkage {p.version} `analyze_tolerance`, {p.samples:,} samples × "
                 f"{p.steps} steps: {p.us_per_sample_step:.1f} µs per sample-step, "
                 f"{p.us_per_sample_step / plain_us:.2f}× the plain script" if p.version else
                 "pylinkage: not installed in this interpreter, not measured"))
    if one.failure:
        yield Figure("study", float("nan"), f"failed: {one.failure}", beside)
    else:
        yield Figure("study", one.us_per_variant_step / plain_us,
                     f"{study.backend} backend, batched = {str(study.batched).lower()}: "
                     f"{one.us_per_variant_step:.1f} µs per variant-step ({one.seconds:.1f} s "
                     f"in all) / plain {plain_us:.1f} µs/step ({s.long_steps:,} steps)", beside)
    if one.failure or two.failure:
        yield Figure("workers", float("nan"), f"failed: {one.failure or two.failure}")
    else:
        yield Figure("workers", one.total / two.total,
                     f"1 worker's time / 2 workers': {one.total:.1f} s / {two.total:.1f} s "
                     f"(of which the pool's start and stop outside the study "
                     f"{two.start + two.stop:.2f} s; load {loads(one.load)} / "
                     f"{loads(two.load)})",
                     "tables bit-identical: "
                     + ("yes" if done[1 if second else 2].identical else "**no**")
                     + "; the cores two processes got at once just before and after "
                     f"(workers.cores_free, 2.0 idle): {free[0]:.2f}, {free[1]:.2f}")


def exudyn_rows(s: Sizes, _m: Measured):
    model, n = four_bar(), s.long_steps
    slow, slow_t_end = predictor.slow_four_bar(s.slow_steps)
    jobs = {"auto": lambda: predictor.pam_seconds(model, n, 1.0, "auto"),
            "plain": lambda: plain_seconds(n),
            "slow auto": lambda: predictor.pam_seconds(slow, s.slow_steps, slow_t_end, "auto"),
            "slow off": lambda: predictor.pam_seconds(slow, s.slow_steps, slow_t_end, False)}
    best = rounds(jobs, s.long_repeats)
    us = {k: 1e6 * v / (s.slow_steps if k.startswith("slow") else n) for k, v in best.items()}
    yield Figure("positions", best["auto"] / best["plain"],
                 f"Exudyn backend {us['auto']:.1f} µs/step / plain {us['plain']:.1f} µs/step")
    yield Figure("predictor", best["slow auto"] / best["slow off"],
                 f"default {us['slow auto']:.1f} µs/step / predictor never "
                 f"{us['slow off']:.1f} µs/step")


def rounds(jobs: dict, repeats: int) -> dict:
    """{job: least seconds} of ``repeats`` rounds, each job once per round, the order
    reversed every other round."""
    best = dict.fromkeys(jobs, float("inf"))
    for r in range(repeats):
        for key in (list(jobs) if r % 2 == 0 else list(reversed(jobs))):
            best[key] = min(best[key], jobs[key]())
    return best


GROUPS = (clearance_rows, natural_rows, natural_per_step_rows, study_rows, exudyn_rows)


def measure(s: Sizes) -> Measured:
    """Every row, ``s.passes`` times."""
    m = Measured(s, info=machine())
    begin = time.perf_counter()
    for p in range(s.passes):
        before = os.getloadavg()
        for group in (GROUPS if p % 2 == 0 else reversed(GROUPS)):
            for figure in group(s, m):
                m.figures.setdefault(figure.key, []).append(figure)
                log(f"  pass {p + 1}: {figure.key} {figure.ratio:.2f}× ({figure.detail})")
        m.loads.append((before, os.getloadavg()))
    m.minutes = (time.perf_counter() - begin) / 60
    return m


# ---- the section -----------------------------------------------------------------------

def verdict(target: Target, ratios: list[float]) -> str:
    """met (every pass), not met (none), met in k of n passes; not measured (a failure)."""
    if not ratios or any(r != r for r in ratios):
        return "not measured"
    k = sum(target.met(r) for r in ratios)
    if k == len(ratios):
        return "met"
    return "not met" if k == 0 else f"met in {k} of {len(ratios)} passes"


def measured_cell(ratios: list[float]) -> str:
    if not ratios or any(r != r for r in ratios):
        return "–"
    mean = sum(ratios) / len(ratios)
    if len(ratios) == 1:
        return f"{mean:.2f}×"
    return f"{mean:.2f}× ({min(ratios):.2f}–{max(ratios):.2f}× over {len(ratios)} passes)"


def loads(pair) -> str:
    return ", ".join(f"{x:.1f}" for x in pair)


def section(m: Measured) -> list[str]:
    """The page's section, BEGIN … END."""
    s, info = m.sizes, m.info
    rows = []
    for t in targets(s):
        figures = m.figures.get(t.key, [])
        ratios = [f.ratio for f in figures]
        rows.append("| " + " | ".join([
            t.what, measured_cell(ratios), t.goal, verdict(t, ratios),
            "; ".join(f"pass {i + 1}: {f.ratio:.2f}× = {f.detail}"
                      for i, f in enumerate(figures)) or "–",
            " / ".join(dict.fromkeys(f.beside for f in figures)) or "–"]) + " |")
    reduced = [f"{label} {getattr(s, name):,} (full size: {getattr(FULL, name):,})"
               for name, label in SIZE_LABELS.items() if getattr(s, name) != getattr(FULL, name)]
    lines = [BEGIN, "## Targets of issue 25", ""]
    if s.quick:
        lines += ["**`--quick` smoke run: tiny sizes, numbers not representative.**", ""]
    lines += [
        f"Written by `benchmarks/targets.py` on {info['date (UTC)']} UTC in one run of "
        f"{m.minutes:.1f} minutes on this page's machine ({info['CPU']}, {info['cores']} "
        f"cores, a shared virtual machine; Python {info['Python']}, Exudyn {info['Exudyn']}, "
        f"pam2exu {info['pam2exu']}). Load averages (1, 5, 15 min) "
        + "; ".join(f"pass {i + 1}: {loads(b)} before, {loads(a)} after"
                    for i, (b, a) in enumerate(m.loads))
        + ". Every ratio is of two figures of the same pass, timed in alternation (best of "
        "each side's repeats; the file's docstring says how each row pairs them). The run "
        f"measured every row {s.passes} time{'s' if s.passes > 1 else ''}, one pass after "
        "the other; *measured* is the mean of the passes' ratios with their range, and the "
        "verdict is *met* when every pass met the target.", ""]
    if reduced:
        lines += ["**Sizes reduced** to fit this run's time: " + ", ".join(reduced)
                  + ".", ""]
    lines += ["| what | measured | target | verdict | from | beside |",
              "|---|---|---|---|---|---|", *rows, "",
              "*From*: the figures of each pass (the Exudyn backend is pam2exu's default; "
              "*plain*: the plain, hand-written Exudyn script of section 2, symbolic driver, "
              f"positions only). The study is `examples/studies/four_bar_tolerance.toml` run "
              "through the studies API as a user's `pam2exu.study` runs it, so its rows "
              f"measure the engine of this commit. pylinkage: {m.pylinkage_note or 'not run'}.",
              END]
    return lines


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true",
                        help="tiny sizes, one pass; written to a temporary directory")
    parser.add_argument("--variants", type=int, default=None, help="the study's variants")
    parser.add_argument("--passes", type=int, default=None, help="times every row is measured")
    parser.add_argument("--out", type=Path, default=None,
                        help="directory holding performance.md (default: docs/, or a "
                             "temporary directory with --quick or other sizes)")
    args = parser.parse_args(argv)
    sizes = QUICK if args.quick else FULL
    if args.variants:
        sizes = replace(sizes, variants=args.variants)
    if args.passes:
        sizes = replace(sizes, passes=args.passes)
    resized = args.quick or args.variants or args.passes
    out_dir = args.out or (Path(tempfile.mkdtemp(prefix="pam2exu-targets-")) if resized
                           else ROOT / "docs")
    log(f"targets of issue 25 ({machine()['pam2exu']}), load {loads(os.getloadavg())}")
    lines = section(measure(sizes))
    out_dir.mkdir(parents=True, exist_ok=True)
    replace_section(out_dir / "performance.md", lines, BEGIN, END, before=BEFORE)
    print("\n".join(lines))
    log(f"wrote the targets of issue 25 in {out_dir / 'performance.md'}")


if __name__ == "__main__":
    main()

"""Speed against error of pam2exu, measured in one run; writes docs/performance.md.

    python benchmarks/speed_vs_error.py            # full run (about 8 minutes on 2 cores)
    python benchmarks/speed_vs_error.py --quick    # smoke test (under a minute), written to
                                                   # a temporary directory, not to docs/
    python benchmarks/speed_vs_error.py --no-memory   # without section 6's million-step runs

What it measures (each section of docs/performance.md is one of these):

1. Work against precision: the slider-crank and the four-bar, kinematic and kinetostatic,
   over a grid of step counts and Exudyn tolerances; wall time per step (best of several
   repeats) and the largest relative error of positions, velocities, accelerations and
   reactions against closed-form and Newton–Euler references.
2. pam2exu against a plain, hand-written Exudyn script doing the same four-bar position
   solve, with the driver as a Python pre-step function and as a symbolic offset function;
   Newton iterations per step of that solve.
3. Hard cases: a slider-crank through both dead centres (in line and offset), a long run
   (100 turns, 100,000 steps: the error at the end), the redundant parallelogram.
4. Size: a chain of N four-bar loops (each loop's output link is the next loop's input
   link, one motor drives them all), N = 1 … 64; time per step against N and the fitted
   exponent; errors against the chained closed form and a Newton–Euler solution.
5. Where the time goes: a cProfile of three runs.
6. The two backends (Exudyn, natural coordinates) side by side on the same runs, against
   issue 12's targets: the four-bar, kinematic and kinetostatic, 100,000 steps; the chain,
   N = 1 … 64, and the exponent of its cost; the peak memory of 1,000,000 steps of the
   kinematic four-bar, each backend in its own process; the largest position error.
7. The clearance analysis (issue 13) on its two examples: the slides' ODE against Newton
   step by step, time and agreement (clearance.py).
8. The dynamic analysis (issue 15) on both backends (Exudyn's generalized-α, the natural
   backend's DOP853): a free pendulum, the free four-bar and Andrews' squeezer at
   tolerances 1e-4 … 1e-10, time against the error achieved and the estimate reported,
   AccuracyWarnings and failures, the faster backend per tolerance, scipy's DOP853 beside
   them (dynamics.py; ``python benchmarks/dynamics.py`` reruns this section alone and
   replaces it in docs/performance.md).
9. Studies (issue 24): the four-bar's kinetostatic study of 2,000 variants × 100 steps in this
   process, on 2 worker processes and on a Dask LocalCluster(2), variants per second and time
   per variant-step, beside pylinkage's Monte-Carlo ``analyze_tolerance`` when it imports
   (studies.py; ``python benchmarks/studies.py`` reruns this section alone).

References (the top-level ``references`` package, shared with the tests; nothing comes from
pam2exu). Kinematics: the closed forms of references/closed_form.py (``four_bar``, chained
loop by loop for the chain) and references/slider_crank.py (``kinematics``: offset
slider-crank with the slider's pin off its line). Forces: ``newton_euler`` of
references/slider_crank.py for the slider-crank; for the four-bar and the chain,
``revolute_newton_euler`` of references/revolute.py (Σ F = m a_G, Σ M_G = J α per body,
solved at every step), which checks itself by the power balance before it is used.

Layout: this file is the command line and the order of the run. Measuring:
cases.py (the mechanisms and their references), plain_exudyn.py (the hand-written Exudyn
four-bar), measure.py (grids, timing, errors of one configuration), sections.py (the
sections 1–5 above), backends.py (section 6), clearance.py (section 7), dynamics.py
(section 8), studies.py (section 9). Reporting: report.py (docs/performance.md),
report_backends.py (its section 6), plot.py (docs/img/work_precision.png); the sections
other scripts write alone (targets.py, clearance_speed.py, natural_speed.py, predictor.py)
stay on the page as they were (page.py). The file puts the repository root on ``sys.path`` so that
``benchmarks`` and ``references`` import from a clone (``python -m benchmarks.speed_vs_error``
from the root does the same).
"""
from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))          # this clone's benchmarks, references (and pam2exu)

from benchmarks.backends import memory, run_backend, side_by_side  # noqa: E402
from benchmarks.clearance import measure as measure_clearance  # noqa: E402
from benchmarks.dynamics import measure as measure_dynamics, plot_dynamic  # noqa: E402
from benchmarks.cases import chain_model, four_bar_case  # noqa: E402
from benchmarks.measure import DEFAULT_TOLERANCE, FULL, QUICK, log, machine, run_pam  # noqa: E402
from benchmarks.plain_exudyn import plain_exudyn_four_bar  # noqa: E402
from benchmarks.plot import plot  # noqa: E402
from benchmarks.report import write_report  # noqa: E402
from benchmarks.studies import measure as measure_studies  # noqa: E402
from benchmarks.sections import (AgainstPlain, chain, hard_cases, newton_grid,  # noqa: E402
                                 profile, work_precision)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true",
                        help="small grids, under a minute; written to a temporary directory")
    parser.add_argument("--out", type=Path, default=None,
                        help="directory for performance.md and img/ (default: docs/, or a "
                             "temporary directory with --quick)")
    parser.add_argument("--no-memory", action="store_true",
                        help="leave out section 6's peak-memory runs (1,000,000 steps per "
                             "backend, about half a minute)")
    args = parser.parse_args(argv)
    plan = QUICK if args.quick else FULL
    out_dir = args.out or (Path(tempfile.mkdtemp(prefix="pam2exu-bench-")) if args.quick
                           else ROOT / "docs")
    start = time.perf_counter()
    info = machine()                     # before the run: the commit that is measured
    run_pam(four_bar_case()[0], "kinetostatic", 200, 1.0, DEFAULT_TOLERANCE, 1)   # warm-up
    plain_exudyn_four_bar(200, DEFAULT_TOLERANCE, "symbolic")
    for backend in plan.backends:
        try:
            run_backend(four_bar_case()[0], "kinetostatic", 200, backend)
        except Exception as exc:  # section 6 records it
            log(f"warm-up on the {backend} backend failed: {type(exc).__name__}: {exc}")
    sections = {}

    def section(title, fn, *args):
        log(title)
        begin = time.perf_counter()
        value = fn(*args)
        sections[title] = time.perf_counter() - begin
        log(f"  ({sections[title]:.0f} s)")
        return value
    comparison = AgainstPlain(plan)
    # its rounds are spread over the run: before, between and after the other sections
    spread = [max(1, plan.compare_repeats // 5)] * 5
    spread[0] += plan.compare_repeats - sum(spread)

    def compare_rounds(k):
        for _ in range(spread[k]):
            comparison.round()
    section("2. pam2exu against plain Exudyn (rounds 1)", compare_rounds, 0)
    grid = section("1. work against precision", work_precision, plan)
    section("2. pam2exu against plain Exudyn (rounds 2)", compare_rounds, 1)
    newton = section("2b. Newton iterations of the plain solve", newton_grid, plan)
    hard = section("3. hard cases", hard_cases, plan)
    section("2. pam2exu against plain Exudyn (rounds 3)", compare_rounds, 2)
    chain_rows = section("4. chain", chain, plan)
    section("2. pam2exu against plain Exudyn (rounds 4)", compare_rounds, 3)
    side = section("6. two backends side by side", side_by_side, plan)
    section("2. pam2exu against plain Exudyn (rounds 5)", compare_rounds, 4)
    plain_rows = section("2c. plain solve: Newton iterations and error", comparison.rows)
    compare = max(plan.compare_steps, key=lambda n: (n <= 10000, n))
    profiles = section("5. profiles", lambda: {
        f"four-bar, kinematic, {compare:,} steps":
            profile(four_bar_case()[0], "kinematic", compare),
        f"four-bar, kinetostatic, {compare:,} steps":
            profile(four_bar_case()[0], "kinetostatic", compare),
        f"chain N = {plan.chain_sizes[-1]}, kinematic, {plan.chain_steps:,} steps":
            profile(chain_model(plan.chain_sizes[-1]), "kinematic", plan.chain_steps)})
    peaks = None if args.no_memory else section("6b. peak memory, one process per run",
                                                 memory, plan)
    clearance = section("7. clearance: ODE against Newton", measure_clearance, plan)
    dynamics = section("8. dynamic: work against precision", measure_dynamics, plan)
    studies = section("9. studies: variants per second", measure_studies, plan)
    elapsed = time.perf_counter() - start
    info["load averages at the end (1, 5, 15 min)"] = ", ".join(f"{x:.2f}"
                                                               for x in os.getloadavg())
    out_dir.mkdir(parents=True, exist_ok=True)
    plot(out_dir / "img" / "work_precision.png", grid, chain_rows, side)
    plot_dynamic(out_dir / "img" / "dynamic_work_precision.png", dynamics)
    write_report(out_dir, info, plan, args.quick, grid, hard, chain_rows, plain_rows, newton,
                 profiles, sections, elapsed, side, peaks, clearance, dynamics, studies)
    log(f"wrote {out_dir / 'performance.md'} and {out_dir / 'img' / 'work_precision.png'} "
        f"({elapsed / 60:.1f} minutes)")


if __name__ == "__main__":
    main()

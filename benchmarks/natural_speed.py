"""The natural backend's speed where users live (issue 25, item 2), ratios from one run.

Every configuration is run end to end through ``pam2exu.run(model, analysis=...,
steps=..., backend=...)`` (a loaded ``Model``, default settings) on the natural and the
Exudyn backends in alternation, their order swapped every repeat, best of the repeats; the
per-step figures at 100,000 steps are timed beside the plain Exudyn script's positions
(``plain_exudyn.plain_exudyn_four_bar``, symbolic driver, default tolerance), also in
alternation. The load averages before and after are printed with the table: the machine
is shared, and only ratios from the same run are compared.

    python benchmarks/natural_speed.py            # replaces its section of docs/performance.md
    python benchmarks/natural_speed.py --quick    # a smoke test: fewer repeats, printed only
"""
from __future__ import annotations

import argparse
import os
from contextlib import contextmanager
import sys
import time
import warnings
from pathlib import Path

if __package__ in (None, ""):          # python benchmarks/natural_speed.py: the clone's packages
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import pam2exu  # noqa: E402
from pam2exu.backend.natural import Natural  # noqa: E402

from benchmarks.cases import chain_model  # noqa: E402
from benchmarks.dynamics import replace_section  # noqa: E402
from benchmarks.measure import ROOT, log, machine  # noqa: E402
from benchmarks.plain_exudyn import plain_exudyn_four_bar  # noqa: E402

BEGIN = ("<!-- natural backend speed: written by benchmarks/natural_speed.py "
         "(python benchmarks/natural_speed.py rewrites it alone) -->")
END = "<!-- end of natural backend speed -->"

#: (label, model maker, analysis, steps, repeats, repeats with --quick, target natural/Exudyn)
RATIOS = [
    ("four-bar, kinematic, 100 steps", lambda: pam2exu.load(ROOT / "examples" / "four_bar.toml"),
     "kinematic", 100, 31, 5, 1.0),
    ("chain of 12 loops, kinetostatic, 200 steps", lambda: chain_model(12),
     "kinetostatic", 200, 11, 2, 1.0),
]
#: (label, analysis, target µs/step, natural inverse dynamics) of the four-bar at PER_STEP
#: steps on the natural backend; the last row is the kinetostatic run with the analyses'
#: reference-point force pass instead (``Natural.gives_reactions`` off), timed beside it
PER_STEP_RUNS = [("four-bar, kinematic", "kinematic", 1.5, True),
                 ("four-bar, kinetostatic", "kinetostatic", 2.0, True),
                 ("four-bar, kinetostatic, reference-point force pass", "kinetostatic", 2.0,
                  False)]
PER_STEP = 100_000
#: repeats of the per-step rows (best of them; the position solve varies by 2x on a loaded
#: machine)
PER_STEP_REPEATS = 5


def timed(model, analysis, steps, backend) -> float:
    """Wall seconds of one end-to-end run."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        start = time.perf_counter()
        pam2exu.run(model, analysis=analysis, steps=steps, backend=backend)
        return time.perf_counter() - start


def paired(model, analysis, steps, repeats) -> dict:
    """{backend: best wall seconds} of the natural and Exudyn backends' runs, in alternation
    with their order swapped every repeat, after a warm-up run of each."""
    best = {"natural": float("inf"), "exudyn": float("inf")}
    timed(model, analysis, steps, "natural")            # warm-up (imports, caches)
    timed(model, analysis, steps, "exudyn")
    for r in range(repeats):
        for backend in (("natural", "exudyn") if r % 2 else ("exudyn", "natural")):
            best[backend] = min(best[backend], timed(model, analysis, steps, backend))
    return best


def measure(quick: bool = False) -> dict:
    """Best wall times of every configuration, with the load averages around them."""
    out = {"load_before": os.getloadavg(), "ratios": [], "per_step": []}
    for label, make, analysis, steps, repeats, few, target in RATIOS:
        best = paired(make(), analysis, steps, few if quick else repeats)
        out["ratios"].append((label, best["natural"], best["exudyn"], target))
        log(f"  {label}: natural {best['natural'] * 1e3:.1f} ms, "
            f"Exudyn {best['exudyn'] * 1e3:.1f} ms")
    steps = 10_000 if quick else PER_STEP
    model = pam2exu.load(ROOT / "examples" / "four_bar.toml")
    plain, best = float("inf"), [float("inf")] * len(PER_STEP_RUNS)
    for r in range(1 if quick else PER_STEP_REPEATS):  # the rows in alternation, order swapped
        order = list(enumerate(PER_STEP_RUNS))
        for k, (label, analysis, target, own) in (order[::-1] if r % 2 else order):
            with natural_reactions(own):
                best[k] = min(best[k], timed(model, analysis, steps, "natural"))
        plain = min(plain, plain_exudyn_four_bar(steps, 1e-13, "symbolic")[1])
    for (label, analysis, target, own), b in zip(PER_STEP_RUNS, best):
        out["per_step"].append((label, b / steps * 1e6, target))
        log(f"  {label}, {steps:,} steps: natural {b / steps * 1e6:.2f} µs/step")
    out["plain"], out["steps"] = plain / steps * 1e6, steps
    out["load_after"] = os.getloadavg()
    return out


@contextmanager
def natural_reactions(on: bool):
    """The natural backend's kinetostatic reactions from its own inverse dynamics (on) or
    from the analyses' reference-point force pass (off), for the runs inside."""
    before = Natural.gives_reactions
    Natural.gives_reactions = on
    try:
        yield
    finally:
        Natural.gives_reactions = before


def verdict(value: float, target: float) -> str:
    return "met" if value <= target else f"not met ({value / target:.2f}× the target)"


def section(m: dict) -> list[str]:
    """The section's markdown lines (BEGIN … END)."""
    info = machine()
    load = ", ".join(f"{a:.1f}" for a in m["load_before"]) + " before, " + \
        ", ".join(f"{a:.1f}" for a in m["load_after"]) + " after"
    lines = [BEGIN, "## 10. The natural backend where users live (issue 25)", "",
             f"Written by `benchmarks/natural_speed.py` (pam2exu {info['pam2exu']}; load "
             f"averages over 1, 5 and 15 minutes: {load}). End to end, as section 6: "
             "`pam2exu.run(model, analysis=..., steps=..., backend=...)` on a loaded model at "
             "each backend's default settings, the two backends in alternation with their "
             "order swapped every repeat, best of the repeats; the ratio is natural / Exudyn "
             "from the same run.", "",
             "| what | natural | Exudyn | natural / Exudyn | target | verdict |",
             "|---|---|---|---|---|---|"]
    for label, natural, exudyn, target in m["ratios"]:
        ratio = natural / exudyn
        lines.append(f"| {label} | {natural * 1e3:.1f} ms | {exudyn * 1e3:.1f} ms | "
                     f"{ratio:.2f}× | ≤ {target:.1f}× | {verdict(ratio, target)} |")
    lines += ["", f"The four-bar at {m['steps']:,} steps on the natural backend, per step, "
              f"beside the plain Exudyn script's positions (symbolic driver, "
              f"{m['plain']:.1f} µs/step in the same run):", "",
              "| what | µs/step | / plain Exudyn positions | target | verdict |",
              "|---|---|---|---|---|"]
    for label, per_step, target in m["per_step"]:
        lines.append(f"| {label} | {per_step:.2f} | {per_step / m['plain']:.2f}× | "
                     f"≤ {target:g} µs | {verdict(per_step, target)} |")
    lines += ["", *WHAT_CHANGED, END]
    return lines


#: what the backend does to get there (kept beside the numbers it explains)
WHAT_CHANGED = [
    "What the natural backend does for short runs and large mechanisms:",
    "",
    "- **Kept per mechanism**: the terms' index and coefficient arrays (compiled once with "
    "the formulation), the weights, the sums that give x, y, fi, the angle kinds, the pivot "
    "order at the run's start; the laws' values are computed once at all the run's times "
    "(its coarse steps and a short fill read their rows).",
    "- **Every equation at once**: the terms of all equations are summed per row by one "
    "`numpy.bincount` for up to 256 steps (one call, the same additions in the same order as "
    "the sparse summing matrix used for many steps: the same bits), and Newton at one step "
    "runs without the bookkeeping of a batch. A step of a mechanism with 40 coordinates or "
    "more is solved dense while steps × coordinates² ≤ 20,000 (the chain of 12 loops: "
    "a dense solve instead of a sparse LU's set-up); the steps between its coarse steps are "
    "solved as the small systems' are, one sparse LU of their block-diagonal Jacobian per "
    "Newton iteration, whose last factors also give ż and z̈ (no second pass for the rates).",
    "- **The coarse pass sized by the run**: its interval doubles where the Taylor "
    "predictor missed by less than 1/16 of what it may miss, up to twice its start and 64 "
    "steps, so a slow motion takes fewer sequential steps (the four-bar at 100 steps: 14 "
    "instead of 25; the chain at 200 steps: 26 instead of 50); four times lost the branch "
    "next to a change point, and a long run's intervals do not grow (longer ones cost its "
    "batched steps more Newton iterations than they save).",
    "- **A short run's sequential steps**: Newton and the rates at one step (the coarse "
    "pass's) evaluate Φ, Φ_z (summed straight into its dense matrix) and γ on 1-D arrays "
    "and solve with numpy's own LAPACK kernel without its wrapper (the same bits); the run "
    "starts from the assembly's natural coordinates instead of solving t0 again; Newton stops "
    "after the step whose successor, under quadratic convergence, would be 1000 times below "
    "the tolerance (the iteration that would only confirm it is not taken: a coarse step of "
    "the four-bar takes 3 iterations instead of 4; results move by round-off, at most "
    "1.4e-14 of a unit's scale in the snapshot of every example and test model).",
    "",
    "- **Each check's equations evaluated once**: the mobility check evaluates pam2exu's "
    "equations at the guess once for the definedness test, the rank's SVD and the "
    "condition number (three times before); a run short enough for its condition numbers "
    "to be taken at every step takes them from the Jacobian its rates were computed with "
    "(on the natural backend, C and Cq of the residual check in one evaluation); the "
    "constraints' points are built at once after the first evaluation. Newton step by "
    "step gathers the terms once and sums Φ and Φ_z in one call. Every result is the "
    "same to the bit (`python -m tests.snapshot`).",
    "",
    "- **Inverse dynamics in natural coordinates**: the kinetostatic runs on this backend "
    "take their reactions from M z̈ + Φ_zᵀ μ = Q with each solid's constant mass matrix "
    "and per-body equilibrium at the shared basic points (`Natural.reactions`, "
    "docs/natural-coordinates.md), not from the analyses' reference-point force pass: no "
    "reference-point Jacobian is built and no 9 × 9 system solved per step; the constant "
    "products are sparse (single-threaded: a threaded BLAS product of this size is a "
    "hundred times slower on a loaded machine). The force columns are the reference-point "
    "pass's to 1e-13. The last row of the per-step table is the same kinetostatic run "
    "with the reference-point force pass (what this backend ran before), the rows timed "
    "in alternation.",
    "",
    "What is left: beside the backend, every run also pays the analyses' own checks (the "
    "mobility's rank, the condition numbers' SVDs, the residual check), the same on both "
    "backends: lowering them lowers both backends' times, not the ratio; and the "
    "kinetostatic run the report frames and force elements' outputs of the analyses "
    "(`force_pass.over_time_given`).",
]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true",
                        help="fewer repeats and 10,000 steps; printed, not written")
    args = parser.parse_args(argv)
    lines = section(measure(args.quick))
    if args.quick:
        print("\n".join(lines))
    else:
        replace_section(ROOT / "docs" / "performance.md", lines, BEGIN, END)
        log("wrote the natural backend's section of docs/performance.md")


if __name__ == "__main__":
    main()

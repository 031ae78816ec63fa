"""The natural backend's fill guess: the quintic through z, ż, z̈ against the cubic through z,
ż, paired in one interpreter (docs/performance.md, "The fill's first guess").

A run's fill (``solver.Solver._fill``) starts the steps between its coarse steps from the
quintic where the block's largest coarse miss says so (``solver.quintic_guess``: above
``QUINTIC_MISS``, or small enough for the quintic to be within the tolerance); patching it
to answer False gives the cubic everywhere, the code as it was. A study's pass
(``variants._fill``) always takes the quintic; the cubic is patched in for the comparison
(its Newton iteration, ``variants.solve``, on the variants' stacked equations).
Each pair runs the two in alternation, their order swapped every round, CPU seconds of this
process (``time.process_time``: a busy machine's other jobs are not counted); the ratio is
the median of the rounds' quintic / cubic. Newton's iterations per step are counted, not
timed: they do not depend on the machine.

    python benchmarks/fill_guess.py              # 9 rounds
    python benchmarks/fill_guess.py --rounds 3   # quicker
"""
from __future__ import annotations

import argparse
import os
import sys
import time
import warnings
from dataclasses import replace
from pathlib import Path

if __package__ in (None, ""):          # python benchmarks/fill_guess.py: the clone's packages
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402

import pam2exu.backend.natural.solver as solver  # noqa: E402
from pam2exu.analyses.grid import plan  # noqa: E402
from pam2exu.analyses.job import prepare  # noqa: E402
from pam2exu.backend.natural import Natural, variants  # noqa: E402
from pam2exu.model import Mechanism  # noqa: E402
from pam2exu.studies import load_study  # noqa: E402
from pam2exu.studies.runner import made_variant, nominal, payload, prepared  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
#: (model, steps) of the single runs compared
RUNS = [(model, steps) for model in ("four_bar", "slider_crank")
        for steps in (300, 1000, 3000, 10000)]
#: the study whose pass is compared, and its variants
STUDY, VARIANTS = ROOT / "examples" / "studies" / "four_bar_tolerance.toml", 400


def cubic_fill(stack, z, zd, zdd, coarse, alive, tolerance, max_iterations):
    """``variants._fill`` with the cubic through z and ż at the ends (the fill before)."""
    saved = variants.quintic_hermite

    def cubic_as_quintic(u, h):
        w = solver.cubic_hermite(u, h)
        zero = np.zeros_like(w[0])
        return w[0], w[1], zero, w[2], w[3], zero

    variants.quintic_hermite = cubic_as_quintic
    try:
        return QUINTIC_FILL(stack, z, zd, zdd, coarse, alive, tolerance, max_iterations)
    finally:
        variants.quintic_hermite = saved


QUINTIC_FILL = variants._fill


def paired(run, set_cubic, rounds: int):
    """(median quintic / cubic CPU seconds, Newton iterations cubic, quintic) of ``run()``,
    which returns its iteration count; ``set_cubic(flag)`` switches the guess."""
    seconds = {True: [], False: []}
    iterations = {}
    for flag in (True, False):                     # warm-up
        set_cubic(flag)
        run()
    for r in range(rounds):
        for flag in ((True, False) if r % 2 else (False, True)):
            set_cubic(flag)
            start = time.process_time()
            iterations[flag] = run()
            seconds[flag].append(time.process_time() - start)
    set_cubic(False)
    ratio = float(np.median(np.array(seconds[False]) / np.array(seconds[True])))
    return ratio, iterations[True], iterations[False]


def single_runs(rounds: int) -> list[str]:
    """One row per run of ``RUNS``: its positions and rates on the natural backend."""
    lines = []
    quintic_guess = solver.quintic_guess

    def set_cubic(flag):
        solver.quintic_guess = (lambda miss, tolerance: False) if flag else quintic_guess

    for model, steps in RUNS:
        job = prepare(ROOT / "examples" / f"{model}.toml", analysis="kinematic", steps=steps,
                      backend="natural")

        def run():
            found = job.backend.solve_positions(job.mech, job.times, job.mech.initial_q(),
                                                job.solver, rates=True)
            return found.iterations / len(job.times)

        ratio, cubic, quintic = paired(run, set_cubic, rounds)
        lines.append(f"| {model.replace('_', '-')}, {steps:,} steps | {cubic:.3f} | "
                     f"{quintic:.3f} | {ratio:.2f}× |")
    return lines


def study_pass(rounds: int) -> str:
    """The row of a study's one pass: the Newton iteration of ``variants.solve`` on the
    stacked equations of the shipped four-bar study's first VARIANTS variants."""
    study = prepared(replace(load_study(STUDY), samples=VARIANTS))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        names, _ = nominal(study)
        p = payload(study, names)
        mechs = [Mechanism(made_variant(p, v)[0])
                 for v in np.asarray(study.variants())[:VARIANTS]]
    times = plan(mechs[0], p["t_end"], p["steps"], 1).times
    backend = Natural()
    forms = [backend.formulation(m) for m in mechs]
    stack = variants.Stack([f.terms for f in forms],
                           [backend.weights(f, m) for f, m in zip(forms, mechs)], times)
    z0 = np.stack([f.from_q(m.initial_q())[0] for f, m in zip(forms, mechs)], axis=1)
    settings = backend.Settings()

    def run():
        out = variants.solve(stack, z0, settings.tolerance, settings.max_iterations)
        return out.iterations / (len(mechs) * len(times))

    def set_cubic(flag):
        variants._fill = cubic_fill if flag else QUINTIC_FILL

    ratio, cubic, quintic = paired(run, set_cubic, rounds)
    return (f"| four-bar study's pass (`variants.solve`), {len(mechs)} variants × "
            f"{len(times) - 1} steps, per variant-step | {cubic:.3f} | {quintic:.3f} | "
            f"{ratio:.2f}× |")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=9, help="pairs per row")
    args = parser.parse_args(argv)
    before = os.getloadavg()
    lines = ["| what | Newton iterations per step, cubic | quintic | CPU time, quintic / "
             "cubic (median of pairs) |", "|---|---|---|---|"]
    lines += single_runs(args.rounds)
    lines.append(study_pass(args.rounds))
    after = os.getloadavg()
    print("\n".join(lines))
    print(f"\n{args.rounds} rounds; load averages {before[0]:.1f}, {before[1]:.1f} before, "
          f"{after[0]:.1f}, {after[1]:.1f} after")


if __name__ == "__main__":
    main()

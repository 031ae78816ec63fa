"""The Exudyn backend's position solve (modified Newton, the predictor decided by measurement)
against the plain Exudyn script.

    python benchmarks/predictor.py            # rewrites its section of docs/performance.md
    python benchmarks/predictor.py --quick    # one round of 10,000 steps, printed only

Times, in rounds, each configuration once per round in alternation (the order reversed every
other round), in-process with the model loaded: the four-bar (examples/four_bar.toml,
θ = 2π t, 1 s) positions only (``outputs=["x", "y", "fi"]``), 100,000 steps, with the
predictor as decided by the run (the default, ``predictor="auto"``), always and never, and
the default by full Newton (``modified_newton=False``, a Jacobian every iteration), beside
the plain hand-written Exudyn script (``plain_exudyn_four_bar``, symbolic driver: building,
solving and reading the sensors; full Newton); and the four-bar turning 0.003 rad per step
(θ = 10 t, 110,000 steps over 34.6 s) each way. Each configuration's best round, and the
ratios of the best times; *per round*: the range of the ratios of the runs of one round
(seconds apart). Newton iterations per step and the probe's decision are read from every
run of ``ExudynSystem.solve_positions`` (wrapped here).
"""
from __future__ import annotations

import argparse
import os
import sys
import time
import warnings
from pathlib import Path

import numpy as np

if __package__ in (None, ""):          # python benchmarks/predictor.py: the clone's packages
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import pam2exu  # noqa: E402
from pam2exu.backend import SolveSettings  # noqa: E402
from pam2exu.backend.exudyn import system  # noqa: E402
from pam2exu.backend.exudyn.predictor import PROBE_FROM  # noqa: E402

from benchmarks.dynamics import replace_section  # noqa: E402
from benchmarks.measure import ROOT, log, machine  # noqa: E402
from benchmarks.plain_exudyn import plain_exudyn_four_bar  # noqa: E402
from benchmarks.report import table, verdict  # noqa: E402

BEGIN = ("<!-- section predictor: written by benchmarks/predictor.py (python "
         "benchmarks/predictor.py rewrites it alone) -->")
END = "<!-- end of section predictor -->"
#: configuration -> (predictor, modified_newton)
SETTINGS = {"auto": ("auto", True), "on": (True, True), "off": (False, True),
            "full": ("auto", False)}
LABEL = {"auto": 'default (`"auto"`)', "on": "predictor always", "off": "predictor never",
         "full": 'default (`"auto"`), full Newton'}


class Recorder:
    """Wraps ``ExudynSystem.solve_positions`` to keep, of every solve of ``PROBE_FROM`` steps
    or more (a run of over 50,000 steps is solved in parts, each probed), whether the
    predictor was used and the Newton iterations."""

    def __init__(self):
        self.calls = []
        self.original = system.ExudynSystem.solve_positions

        def wrapped(ex, times, *args, **kwargs):
            out = self.original(ex, times, *args, **kwargs)
            if len(times) >= PROBE_FROM:
                self.calls.append((ex.predicted, ex.newton_iterations, len(times)))
            return out
        system.ExudynSystem.solve_positions = wrapped

    def take(self):
        """(parts solved with the predictor, parts, Newton iterations per step) since the
        last call."""
        calls, self.calls = self.calls, []
        steps = sum(n for *_, n in calls)
        return (sum(bool(p) for p, *_ in calls), len(calls),
                sum(i for _, i, _ in calls) / steps if steps else float("nan"))

    def close(self):
        system.ExudynSystem.solve_positions = self.original


def pam_seconds(model, steps, t_end, predictor, modified_newton=True):
    """Wall seconds of one positions-only run."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        start = time.perf_counter()
        pam2exu.run(model, analysis="kinematic", steps=steps, t_end=t_end,
                    outputs=["x", "y", "fi"],
                    solver=SolveSettings(predictor=predictor, modified_newton=modified_newton))
        return time.perf_counter() - start


def predictor_call_seconds(model, calls=20_000, repeats=5):
    """Seconds of one call of the predictor (``Predictor``: read Exudyn's coordinates, keep
    them, extrapolate, set them) on the four-bar's Exudyn system, best of ``repeats``."""
    from pam2exu.analyses.job import prepare
    job = prepare(model, analysis="kinematic", steps=10)
    ex = system.ExudynSystem(job.mech)
    best = float("inf")
    for _ in range(repeats):
        predict = system.Predictor(ex.mbs.systemData)
        start = time.perf_counter()
        for k in range(calls):
            predict(k)
        best = min(best, (time.perf_counter() - start) / calls)
    return best


def slow_four_bar(slow_steps):
    """(the four-bar turning at 10 rad/s, t_end): 0.0031 rad per step over ``slow_steps``
    steps (110,000 steps over 34.6 s)."""
    slow = pam2exu.load(ROOT / "examples" / "four_bar.toml")
    slow["motor"].C = [0.0, 10.0, 0.0, 0.0]
    return slow, 34.6 * slow_steps / 110_000


def measure(rounds, steps, slow_steps):
    """{config: [(seconds, parts predicted, parts, iterations per step), one per round]}."""
    model = pam2exu.load(ROOT / "examples" / "four_bar.toml")
    slow, slow_t_end = slow_four_bar(slow_steps)
    jobs = {"plain": lambda: plain_exudyn_four_bar(steps, 1e-13, "symbolic")[1]}
    cpu = {key: [] for key in ("plain", *(f"{c} {k}" for c in ("fast", "slow")
                                           for k in SETTINGS))}
    for key, setting in SETTINGS.items():
        jobs[f"fast {key}"] = (lambda s=setting: pam_seconds(model, steps, 1.0, *s))
        jobs[f"slow {key}"] = (lambda s=setting: pam_seconds(slow, slow_steps, slow_t_end, *s))
    out = {key: [] for key in jobs}
    recorder = Recorder()
    try:
        for r in range(rounds):
            order = list(jobs) if r % 2 == 0 else list(reversed(jobs))
            for key in order:
                start = time.process_time()
                seconds = jobs[key]()
                cpu[key].append(time.process_time() - start)
                out[key].append((seconds, *recorder.take()))
            log(f"  round {r + 1}/{rounds}: " + ", ".join(
                f"{key} "
                f"{1e6 * out[key][-1][0] / (slow_steps if key.startswith('slow') else steps):.1f}"
                for key in jobs) + f" µs/step; load {os.getloadavg()[0]:.2f}")
    finally:
        recorder.close()
    out["cpu"] = cpu
    out["call"] = predictor_call_seconds(model)
    out["plain iterations"] = plain_exudyn_four_bar(steps, 1e-13, "symbolic",
                                                    count_iterations=True)[3][0]
    return out, slow_t_end


def section(out, steps, slow_steps, slow_t_end, info, load_before, load_after, minutes):
    """The page's section, as lines (BEGIN … END)."""
    def per_step(key):
        return steps if not key.startswith("slow") else slow_steps

    plain_iterations = out.pop("plain iterations")
    cpu = out.pop("cpu")
    call = out.pop("call")
    cpu_best = {k: min(v) / per_step(k) for k, v in cpu.items()}
    best = {k: min(s for s, *_ in v) / per_step(k) for k, v in out.items()}

    def ratio(a, b):
        rounds = [x[0] / y[0] * per_step(b) / per_step(a) for x, y in zip(out[a], out[b])]
        return best[a] / best[b], min(rounds), max(rounds)

    rows = []
    r_fast = ratio("fast auto", "plain")
    r_slow = ratio("slow auto", "slow off")
    r_full = ratio("fast auto", "fast full")
    rows.append(["four-bar positions, 100,000 steps, default / the plain Exudyn script, same run"
                 if steps == 100_000 else f"four-bar positions, {steps:,} steps / plain script",
                 f"{r_fast[0]:.2f}× ({1e6 * best['fast auto']:.1f} / {1e6 * best['plain']:.1f} "
                 f"µs/step; per round {r_fast[1]:.2f}–{r_fast[2]:.2f}×; CPU time "
                 f"{cpu_best['fast auto'] / cpu_best['plain']:.2f}×)", "≤ 1.0×",
                 verdict(r_fast[0], 1.0)])
    rows.append([f"four-bar at 0.003 rad per step ({slow_steps:,} steps): default / predictor "
                 "never", f"{r_slow[0]:.2f}× ({1e6 * best['slow auto']:.1f} / "
                 f"{1e6 * best['slow off']:.1f} µs/step; per round {r_slow[1]:.2f}–"
                 f"{r_slow[2]:.2f}×; CPU time "
                 f"{cpu_best['slow auto'] / cpu_best['slow off']:.2f}×)",
                 "≤ 1.0×", verdict(r_slow[0], 1.0)])
    rows.append([f"four-bar positions, {steps:,} steps: default (modified Newton) / full Newton",
                 f"{r_full[0]:.2f}× ({1e6 * best['fast auto']:.1f} / "
                 f"{1e6 * best['fast full']:.1f} µs/step; per round {r_full[1]:.2f}–"
                 f"{r_full[2]:.2f}×; CPU time "
                 f"{cpu_best['fast auto'] / cpu_best['fast full']:.2f}×)", "–", "–"])
    detail = []
    for case, label in (("fast", f"θ = 2π t, {steps:,} steps over 1 s"),
                        ("slow", f"θ = 10 t, {slow_steps:,} steps over {slow_t_end:.1f} s")):
        for key in SETTINGS:
            runs = out[f"{case} {key}"]
            used = sum(r[1] for r in runs)
            parts = sum(r[2] for r in runs)
            its = np.mean([r[3] for r in runs])
            detail.append([label, LABEL[key], f"{1e6 * best[f'{case} {key}']:.1f}",
                           f"{1e6 * cpu_best[f'{case} {key}']:.1f}",
                           f"{best[f'{case} {key}'] / best[f'{case} off']:.2f}×",
                           f"{its:.2f}", f"{used} of {parts}"])
    detail.append([f"θ = 2π t, {steps:,} steps over 1 s", "plain Exudyn script (symbolic)",
                   f"{1e6 * best['plain']:.1f}", f"{1e6 * cpu_best['plain']:.1f}", "–",
                   f"{plain_iterations:.2f}", "–"])
    return [
        BEGIN,
        "## The Exudyn backend's position solve: modified Newton, the predictor decided by "
        "measurement",
        "",
        f"Generated by `benchmarks/predictor.py` on {info['date (UTC)']} UTC in one run of "
        f"{minutes:.1f} minutes, on this page's machine ({info['CPU']}, {info['cores']} "
        f"cores; pam2exu {info['pam2exu']}, Exudyn {info['Exudyn']}); load averages "
        f"(1, 5, 15 min) {load_before} at the start, {load_after} at the end: the machine "
        "was shared, so read the ratios, each of two runs of the same round, not the times. "
        f"{len(next(iter(out.values())))} rounds, each configuration once per round in "
        "alternation; best round of each.",
        "",
        "Each step of a run is solved by Exudyn's modified Newton (`SolveSettings."
        "modified_newton`, docs/analyses.md): the Jacobian is computed and factorised once "
        "per step and reused by the step's further iterations, where full Newton (the plain "
        "script's) computes and factorises it at every iteration: one Jacobian per step "
        "instead of one per iteration, for an iteration more where the reused Jacobian "
        "falls just short of the tolerance (the table's iterations per step), and the same "
        "positions to the tolerance. A run it leaves unsolved (it can diverge next to a change point) is "
        "solved again by full Newton.",
        "",
        "The predictor (`SolveSettings.predictor`, docs/analyses.md) sets Exudyn's "
        "coordinates before each load step to the parabola through the last three steps, "
        "from a Python pre-step function: one Newton iteration per step instead of two, for "
        "a call per step whose cost depends on the machine and its load. By default a run "
        "of 4,096 steps or more first solves a probe of 200 steps (blocks of 32 with the "
        "predictor and without it, in turn, each step timed) and goes on with the predictor "
        "only if its median step was shorter by 5 % (the pre-step call that both ways pay in "
        "the probe and only the predictor's after it); else it goes on without any pre-step "
        "function.",
        "",
        "```bash",
        "python benchmarks/predictor.py            # rewrites this section (about 5 minutes)",
        "python benchmarks/predictor.py --quick    # 10,000 steps, one round, printed only",
        "```",
        "",
        table(["what", "measured", "target", "verdict"], rows),
        "",
        table(["motion", "predictor", "µs/step (best)", "CPU µs/step (best)",
               "/ predictor never",
               "Newton it./step (mean)", "predictor kept"], detail),
        "",
        f"One call of the predictor (`Predictor`: read Exudyn's coordinates, keep them, "
        f"extrapolate, set them; 20,000 calls in a loop, best of 5, measured after the rounds) "
        f"took {1e6 * call:.1f} µs. Net of that call, predicting (one Newton iteration per "
        f"step fewer) saved {1e6 * (best['fast off'] - best['fast on']):.1f} µs per step on "
        f"the four-bar at 100,000 steps and {1e6 * (best['slow off'] - best['slow on']):.1f} "
        "at 0.003 rad per step (predictor never − always, best rounds; negative: it cost "
        "more than it saved). The default measures which way is faster in each run.",
        "",
        "*Predictor kept*: in how many of the rounds' solves the predictor was used (a run of "
        "more than 50,000 steps is solved in parts of 50,000, each with its own probe); *CPU*: the process's CPU time (`time.process_time`), "
        "which leaves out the time the process waited for a core. Positions only: "
        "kinematic with `outputs=[\"x\", "
        "\"y\", \"fi\"]`, the whole `pam2exu.run` with a loaded model.",
        END,
    ]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="one round of 10,000 steps")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "performance.md")
    args = parser.parse_args(argv)
    steps, slow_steps, rounds = ((10_000, 11_000, 1) if args.quick
                                 else (100_000, 110_000, args.rounds))
    info = machine()
    load_before = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    begin = time.perf_counter()
    log(f"predictor: {rounds} rounds ({info['pam2exu']}), load {load_before}")
    out, slow_t_end = measure(rounds, steps, slow_steps)
    load_after = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    lines = section(out, steps, slow_steps, slow_t_end, info, load_before, load_after,
                    (time.perf_counter() - begin) / 60)
    if args.quick:
        print("\n".join(lines))
        return
    replace_section(args.out, lines, BEGIN, END)
    log(f"wrote the predictor section of {args.out}")


if __name__ == "__main__":
    main()

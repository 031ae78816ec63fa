"""The sections of the benchmark, each producing the numbers of one part of docs/performance.md.

1. ``work_precision``: four-bar and slider-crank over steps × tolerances.
2. ``AgainstPlain``: pam2exu against the plain Exudyn script (plain_exudyn.py), in rounds
   spread over the run; ``newton_grid``: Newton iterations of the plain solve.
3. ``hard_cases``: dead centres, a long run, the redundant parallelogram.
4. ``chain``: a chain of N four-bar loops.
5. ``profile``: where the time of one run goes.
"""
from __future__ import annotations

import cProfile
import contextlib
import math
import pstats
import tempfile
import time
import warnings
from pathlib import Path
from types import SimpleNamespace

import exudyn as exu
import numpy as np

import pam2exu
from pam2exu.analyses.job import prepare
from pam2exu.backend import ExudynSystem, SolveSettings
from references import slider_crank

from .cases import (CHAIN, TWO_PI, chain_model, chain_reference, four_bar_case,
                    parallelogram_case, slider_crank_case)
from .measure import (DEFAULT_TOLERANCE, ROOT, LastRow, at_row, describe, log, measure,
                      residual_check_off, run_pam)
from .plain_exudyn import plain_exudyn_four_bar


def work_precision(plan):
    """Section 1: the grid. Returns a list of Run.

    The repeats go round the whole grid (every configuration once, then again), so that a
    slow spell of the machine costs one repeat of several configurations rather than every
    repeat of one."""
    fb_model, fb_ref, fb_L, fb_w = four_bar_case()
    sc_model, sc_ref, sc_L, sc_w, sc_p = slider_crank_case()
    cases = [("four-bar", fb_model, fb_ref, fb_L, fb_w, 1.0,
              tuple(plan.steps) + ((plan.big_steps,) if plan.big_steps else ())),
             ("slider-crank", sc_model, sc_ref, sc_L, sc_w, sc_p["t_end"], tuple(plan.steps))]
    configs = []
    for case, model, reference, L, w, t_end, step_list in cases:
        for steps in step_list:
            kin, forces = reference(t_end * np.arange(steps + 1) / steps)
            for analysis in ("kinematic", "kinetostatic"):
                for tol in plan.tolerances:
                    r = measure(case, model, analysis, steps, t_end, tol, 1, kin, forces, L, w)
                    log(f"  {case:12s} {analysis:12s} {steps:6d} steps tol {tol:.0e}: "
                        + describe(r))
                    configs.append((r, model, t_end))
    for k in range(1, plan.repeats):
        for r, model, t_end in configs:
            if r.steps >= 100000 and k >= plan.big_repeats:
                continue
            with residual_check_off() if r.note else contextlib.nullcontext():
                seconds, res, _ = run_pam(model, r.analysis, r.steps, t_end, r.tolerance, 1)
            if seconds < r.seconds:
                r.seconds, r.exudyn_seconds = seconds, res.info["backend_seconds"]
        log(f"  repeat {k + 1} of {plan.repeats} done")
    for r, _, _ in configs:
        log(f"  {r.case:12s} {r.analysis:12s} {r.steps:6d} steps tol {r.tolerance:.0e}: "
            f"best {r.us:6.1f} µs/step (Exudyn {r.exudyn_us:5.1f})")
    return [r for r, _, _ in configs]


def hard_cases(plan):
    """Section 3. Returns a list of (Run, extra dict)."""
    out = []
    # slider-crank through both dead centres: the motor turns two full turns from 0
    motor = {"C": (0.0, 6.0, 2 * TWO_PI - 6.0 + 0.05, 0.0)}     # θ(1) = 4π + 0.05
    for label, rail in (("slider-crank in line, 2 turns through both dead centres",
                         (0.0, -0.015)),      # rail y + pin offset (0.015) = 0
                        ("offset slider-crank (offset 0.085 = 0.85 r), 2 turns",
                         (0.0, 0.07))):
        model, reference, L, w, _ = slider_crank_case(
            ground={"rail_point": rail}, motor=motor, steps=2000)
        kin, forces = reference(np.arange(2001) / 2000)
        r = measure(label, model, "kinetostatic", 2000, 1.0, DEFAULT_TOLERANCE, plan.repeats,
                    kin, forces, L, w)
        out.append((r, {}))
        log(f"  {label}: " + describe(r))
    # a long run: 100 turns at one turn per second
    steps, turns = plan.long_steps, plan.long_turns
    model, reference, L, w = four_bar_case(t_end=float(turns))
    kin, forces = reference(turns * np.arange(steps + 1) / steps)
    label = f"four-bar, {turns} turns"
    r = measure(label, model, "kinetostatic", steps, float(turns), DEFAULT_TOLERANCE,
                max(1, plan.big_repeats - 1), kin, forces, L, w, keep=True)
    res = r.res
    del r.res
    end = at_row(res, kin, steps, L, w)
    end_forces = slider_crank.errors(LastRow(res), {c: v[-1:] for c, v in forces.items()})
    end["reactions"] = (max(end_forces.values()), max(end_forces, key=end_forces.get))
    angle_error = max(abs(res[f"{s}.fi"][-1] - kin[f"{s}.fi"][-1])
                      for s in ("crank", "coupler", "rocker"))
    out.append((r, {"end": end, "angle_error": angle_error,
                    "crank_angle": float(kin["crank.fi"][-1])}))
    log(f"  {label}: " + describe(r)
        + "; at the end: " + " ".join(f"{k[:3]} {v[0]:.1e}" for k, v in end.items()))
    # the redundant parallelogram
    model, reference, L, w = parallelogram_case()
    for steps in (400, 10000):
        kin, _ = reference(np.arange(steps + 1) / steps)
        label = "redundant parallelogram (5 bars)"
        r = measure(label, model, "kinematic", steps, 1.0, DEFAULT_TOLERANCE, plan.repeats,
                    kin, None, L, w)
        out.append((r, {}))
        log(f"  {label} {steps}: " + describe(r))
    return out


def default_is_sparse(model):
    """Whether pam2exu's default settings choose Exudyn's sparse solver for this model (read
    from pam2exu's own rule; False if that cannot be read)."""
    try:
        ss = ExudynSystem.simulation_settings(SimpleNamespace(mech=model.mechanism()),
                                              SolveSettings(), False)
        return ss.linearSolver.solverType == exu.LinearSolverType.EigenSparse
    except (AttributeError, TypeError):
        return False


def chain(plan):
    """Section 4. Returns a list of dicts, one per N: kinematic and kinetostatic runs at the
    default settings, and a kinematic run with Exudyn's sparse solver forced (the default
    run itself where pam2exu already chooses the sparse solver, above DENSE_UP_TO
    coordinates)."""
    rows = []
    steps = plan.chain_steps
    t = np.arange(steps + 1) / steps
    for N in plan.chain_sizes:
        model = chain_model(N)
        kin, forces = chain_reference(N, t)
        w = float(np.max(np.abs(kin[f"L{N}.Dfi"])))
        L = 0.4 + N * CHAIN["d"]
        row = {"N": N, "solids": len(model.solids), "nq": 3 * (len(model.solids) - 1),
               "default_sparse": default_is_sparse(model)}
        repeats = plan.repeats if N < 16 else (2 if N < 32 else 1)
        for key, analysis, dense in (("kinematic", "kinematic", None),
                                     ("kinetostatic", "kinetostatic", None),
                                     ("sparse", "kinematic", False)):
            if key == "sparse" and row["default_sparse"]:
                row[key] = row["kinematic"]
                continue
            row[key] = measure(f"chain N={N}" + (" (sparse)" if dense is False else ""),
                               model, analysis, steps, 1.0, DEFAULT_TOLERANCE, repeats, kin,
                               forces, L, w, dense=dense)
        rows.append(row)
        log(f"  chain N={N:3d}: kinematic {describe(row['kinematic'])}; sparse "
            f"{row['sparse'].us:.1f} (Exudyn {row['sparse'].exudyn_us:.1f}); kinetostatic "
            + describe(row["kinetostatic"]))
    return rows


class AgainstPlain:
    """Section 2: pam2exu against the two plain Exudyn variants, four-bar, default
    tolerance. pam2exu runs: kinematic with only the solids' x, y, fi (*positions*, with
    and without the predictor), kinematic and kinetostatic with every output, kinematic
    with every output written to CSV, and quasi-static with every output. ``round()``
    times every configuration once, in alternation; the rounds are spread over the whole
    benchmark (between its sections), so that a slow spell of the machine spoils one
    round, not the comparison. ``rows()``: the best of all rounds, with Newton iterations
    per step (plain script, pam2exu with and without predictor) and the plain script's
    error."""

    PAM = {"positions": ("kinematic", ["x", "y", "fi"], "auto", False),
           "positions_no_predictor": ("kinematic", ["x", "y", "fi"], False, False),
           "kinematic": ("kinematic", None, True, False),
           "kinematic_csv": ("kinematic", None, True, True),
           "quasi_static": ("quasi_static", None, True, False),
           "kinetostatic": ("kinetostatic", None, True, False)}
    KEYS = (*PAM, "prestep", "symbolic")

    def __init__(self, plan):
        self.plan = plan
        self.model, self.reference, _, _ = four_bar_case()
        self.best = {n: {k: (math.inf, None) for k in self.KEYS} for n in plan.compare_steps}
        self.rounds = 0
        self.scratch = Path(tempfile.mkdtemp(prefix="pam2exu-bench-csv-"))

    def pam(self, key, steps):
        """(wall seconds, Exudyn seconds) of one pam2exu run of configuration ``key``."""
        analysis, outputs, predictor, csv = self.PAM[key]
        start = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = pam2exu.run(self.model, analysis=analysis, steps=steps, outputs=outputs,
                              solver=SolveSettings(predictor=predictor))
        if csv:
            res.to_csv(self.scratch / "four_bar.csv")
        return time.perf_counter() - start, res.info["backend_seconds"]

    def round(self):
        self.rounds += 1
        for steps, best in self.best.items():
            if steps >= 100000 and self.rounds > self.plan.big_repeats:
                continue
            for key in self.PAM:
                seconds, exudyn_seconds = self.pam(key, steps)
                if seconds < best[key][0]:
                    best[key] = (seconds, exudyn_seconds)
            for driver in ("prestep", "symbolic"):
                _, total, solve, _ = plain_exudyn_four_bar(steps, DEFAULT_TOLERANCE, driver)
                if total < best[driver][0]:
                    best[driver] = (total, solve)

    def pam_iterations(self, steps, predictor):
        """Newton iterations per step of pam2exu's position solve (Exudyn's counter)."""
        job = prepare(self.model, analysis="kinematic", steps=steps)
        system = ExudynSystem(job.mech)
        system.solve_positions(job.times, SolveSettings(predictor=predictor))
        return system.newton_iterations / len(job.times)

    def rows(self):
        rows = []
        for steps, best in self.best.items():
            _, _, _, (iterations, jacobians) = plain_exudyn_four_bar(
                steps, DEFAULT_TOLERANCE, "symbolic", count_iterations=True)
            # the plain solve against the closed form
            kin, _ = self.reference(np.arange(steps + 1) / steps)
            q, *_ = plain_exudyn_four_bar(steps, DEFAULT_TOLERANCE, "symbolic")
            plain_err = max(float(np.max(np.abs(q[:, 3 * i + 2] - kin[f"{s}.fi"])))
                            for i, s in enumerate(("crank", "coupler", "rocker")))
            rows.append({"steps": steps, "iterations": iterations, "jacobians": jacobians,
                         "pam_iterations": self.pam_iterations(steps, True),
                         "pam_iterations_no_predictor": self.pam_iterations(steps, False),
                         "plain_angle_error": plain_err, **best})
            us = {k: 1e6 * v[0] / steps for k, v in best.items()}
            log(f"  {steps:6d} steps: pam2exu positions {us['positions']:.1f} µs/step "
                f"(no predictor {us['positions_no_predictor']:.1f}), kinematic "
                f"{us['kinematic']:.1f} (Exudyn {1e6 * best['kinematic'][1] / steps:.1f}; "
                f"with CSV {us['kinematic_csv']:.1f}), quasi-static {us['quasi_static']:.1f}, "
                f"kinetostatic {us['kinetostatic']:.1f}; plain pre-step {us['prestep']:.1f} "
                f"(solve {1e6 * best['prestep'][1] / steps:.1f}), symbolic "
                f"{us['symbolic']:.1f} (solve {1e6 * best['symbolic'][1] / steps:.1f}); Newton "
                f"{iterations:.2f} it/step plain, {rows[-1]['pam_iterations']:.2f} pam2exu")
        return rows


def newton_grid(plan):
    """Newton iterations per step and solve time of the plain (symbolic) Exudyn four-bar over
    the grid of step counts and tolerances (repeats round the grid, as in
    ``work_precision``); and a least-squares split of the solve time into a cost per step
    and a cost per Newton iteration."""
    rows = []
    step_list = tuple(plan.steps) + ((plan.big_steps,) if plan.big_steps else ())
    for steps in step_list:
        for tol in plan.tolerances:
            _, _, solve, (it, _) = plain_exudyn_four_bar(steps, tol, "symbolic",
                                                         count_iterations=True)
            rows.append({"steps": steps, "tolerance": tol, "iterations": it,
                         "solve_us": 1e6 * solve / (steps + 1)})
    for k in range(plan.repeats):
        for r in rows:
            if r["steps"] >= 100000 and k >= plan.big_repeats:
                continue
            solve = plain_exudyn_four_bar(r["steps"], r["tolerance"], "symbolic")[2]
            r["solve_us"] = min(r["solve_us"], 1e6 * solve / (r["steps"] + 1))
    X = np.array([[1.0, r["iterations"]] for r in rows])
    y = np.array([r["solve_us"] for r in rows])
    per_step, per_iteration = np.linalg.lstsq(X, y, rcond=None)[0]
    return rows, float(per_step), float(per_iteration)


def profile(model, analysis, steps, top=10):
    """Where the time of one run goes (cProfile, which slows Python code somewhat): the
    functions with the most time of their own (not counting the functions they call, so
    the rows add up). Returns (total seconds, [(function, calls, own seconds)])."""
    pr = cProfile.Profile()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        start = time.perf_counter()
        pr.enable()
        pam2exu.run(model, analysis=analysis, t_end=1.0, steps=steps)
        pr.disable()
        total = time.perf_counter() - start
    def label(filename, name):
        path = Path(filename)
        if "exudynCPP.SolveSystem" in name:
            return "Exudyn's static solve (C++)"
        if path.is_relative_to(ROOT / "pam2exu"):
            return f"`{'.'.join(path.relative_to(ROOT / 'pam2exu').with_suffix('').parts)}.{name}`"
        if "numpy" in path.parts:
            module = ".".join(p for p in path.with_suffix("").parts[path.parts.index("numpy"):]
                              if not p.startswith("_"))
            return f"`{module}.{name}`"
        if filename == "~":
            return f"`{name.strip('<>')}`"
        return f"`{path.name}:{name}`"

    rows = []
    for (filename, _, name), (_, calls, own, _, callers) in pstats.Stats(pr).stats.items():
        text = label(filename, name)
        if "numpy" in Path(filename).parts and "linalg" in filename and callers:
            by = sorted(callers.items(), key=lambda kv: -kv[1][2])[:2]
            text += " from " + ", ".join(label(f, n).replace("`pam2exu.", "`")
                                         for (f, _, n), _ in by)
        rows.append((text, calls, own))
    rows.sort(key=lambda r: -r[2])
    shown = rows[:top]
    shown.append(("everything else", sum(r[1] for r in rows[top:]),
                  sum(r[2] for r in rows[top:])))
    return total, shown

"""Section 6 of docs/performance.md: the two backends side by side (backends.py's numbers),
with issue 12's targets and their verdicts. Nothing is measured here."""
from __future__ import annotations

import math

import numpy as np

from .backends import Failure, chain_repeats, default_tolerance, label
from .measure import KINDS, fit_exponent, warning_summary

#: issue 12's targets (for the natural backend; the Exudyn backend is held to the same)
KINEMATIC_US = 1.5
KINETOSTATIC_US = 2.0
EXPONENT = 1.1
MEMORY_BYTES = 1e9
POSITIONS = 1e-12


def judge(value, target, failed=None):
    """'met', or 'not met' with how far; a failed or missing measurement is not met."""
    if failed:
        return f"not met ({failed})"
    if value is None or not math.isfinite(value):
        return "not determined"
    if value <= target:
        return "met"
    return f"not met ({value / target:.3g}× the target)"


def _table(header, rows):
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(str(c).replace("|", "\\|") for c in row) + " |"
              for row in rows]
    return "\n".join(lines)


def _code(text):
    """Inline code on the page (a backtick inside would end it)."""
    return "`" + text.replace("`", "'") + "`"


def _ok(r):
    return r is not None and not isinstance(r, Failure)


def chain_exponents(chain, backend, analysis):
    """{part: (p over all N, p over N ≥ 8 or None, Ns)} of one backend's chain runs."""
    rows = [(c.N, c.runs[backend]) for c in chain if c.analysis == analysis
            and _ok(c.runs.get(backend))]
    if len(rows) < 2:
        return {}
    N = np.array([n for n, _ in rows], dtype=float)
    parts = {"total": [r.us for _, r in rows], "positions solve": [r.exudyn_us for _, r in rows],
             "native": [max(r.us - r.exudyn_us, 1e-3) for _, r in rows]}
    out = {}
    for part, y in parts.items():
        y = np.array(y)
        tail = N >= 8
        out[part] = (fit_exponent(N, y),
                     fit_exponent(N[tail], y[tail]) if tail.sum() >= 2 else None,
                     [int(n) for n in N])
    return out


def worst_positions(side, memory, backend):
    """(error, where) of the largest position error over section 6's runs of a backend."""
    worst = (-1.0, "–")
    for c in side["four_bar"] + side["chain"]:
        r = c.runs.get(backend)
        if _ok(r) and "positions" in r.errors and r.errors["positions"][0] > worst[0]:
            e, col = r.errors["positions"]
            worst = (e, f"{c.case}, {c.analysis}, {c.steps:,} steps, {col}")
    m = (memory or {}).get(backend)
    if m and m.get("ok") and m["positions"][0] > worst[0]:
        worst = (m["positions"][0], f"four-bar, kinematic, {m['steps']:,} steps (memory run), "
                                    f"{m['positions'][1]}")
    return worst if worst[0] >= 0 else (None, "no run succeeded")


def _us_cell(r):
    if not _ok(r):
        return "failed"
    return f"{r.us:.2f} (positions solve {r.exudyn_us:.2f}, native {r.us - r.exudyn_us:.2f})"


def _mb(kib):
    return kib * 1024 / 1e6


def target_rows(plan, side, memory):
    """The rows of the targets table: [target, goal, then per backend measured, verdict,
    and the ratio of the second backend to the first]."""
    backends = plan.backends
    rows = []

    def ratio(values):
        a, b = values[0], values[-1] if len(values) > 1 else None
        return (f"{b / a:.2f}×" if a is not None and b is not None and a > 0 and len(values) > 1
                else "–")
    for c, goal in zip(side["four_bar"], (KINEMATIC_US, KINETOSTATIC_US)):
        cells, values = [], []
        for b in backends:
            r = c.runs.get(b)
            cells += [f"{r.us:.2f} µs" if _ok(r) else "failed",
                      judge(r.us, goal) if _ok(r) else judge(None, goal, "the run failed")]
            values.append(r.us if _ok(r) else None)
        rows.append([f"four-bar, {c.analysis}, {c.steps:,} steps: time per step (end to end)",
                     f"≤ {goal:g} µs", *cells, ratio(values)])
    for analysis in ("kinematic", "kinetostatic"):
        cells = []
        for b in backends:
            fit = chain_exponents(side["chain"], b, analysis).get("total")
            if not fit:
                cells += ["–", judge(None, EXPONENT, "fewer than two sizes ran")]
                continue
            p, tail, Ns = fit
            text = f"{p:.2f} (N = {Ns[0]} … {Ns[-1]})" + (f"; {tail:.2f} for N ≥ 8"
                                                           if tail is not None else "")
            missing = [N for N in plan.chain_sizes if N not in Ns]
            verdict = judge(p, EXPONENT, f"failed at N = {missing}" if missing else None)
            if verdict == "met" and tail is not None and tail > EXPONENT:
                verdict = (f"met over N = {Ns[0]} … {Ns[-1]}; not met over N ≥ 8 "
                           f"({tail:.2f})")
            cells += [text, verdict]
        rows.append([f"chain of N loops, {analysis}: exponent p of time/step ∝ N^p",
                     f"≤ {EXPONENT:g}", *cells, "–"])
    cells, values = [], []
    for b in backends:
        m = (memory or {}).get(b)
        if m is None:
            cells += ["not measured in this run", "not determined"]
            values.append(None)
            continue
        peak = _mb(m["peak_kib"]) if m.get("peak_kib") else None
        if m["ok"]:
            cells += [f"{peak:.0f} MB", judge(peak * 1e6, MEMORY_BYTES)]
            values.append(peak)
        else:
            cells += ["failed" + (f" (peak {peak:.0f} MB until then)" if peak else ""),
                      judge(None, MEMORY_BYTES, "the run failed")]
            values.append(None)
    rows.append([f"four-bar, kinematic, {plan.memory_steps:,} steps: peak memory",
                 f"< {MEMORY_BYTES / 1e9:g} GB", *cells, ratio(values)])
    cells, values = [], []
    for b in backends:
        e, where = worst_positions(side, memory, b)
        cells += [f"{e:.1e} ({where})" if e is not None else where,
                  judge(e, POSITIONS, None if e is not None else "no run succeeded")]
        values.append(e)
    rows.append(["positions, largest relative error against the closed forms (every run of "
                 "this section)", f"≤ {POSITIONS:.0e}", *cells, "–"])
    return rows


def backends_section(plan, quick, side, memory):
    """The lines of section 6."""
    lines = []
    add = lines.append
    backends = plan.backends
    names = " and ".join(f"{label(b)} (default tolerance {default_tolerance(b):g})"
                         for b in backends)
    add("## 6. Two backends side by side")
    add("")
    add(f"The same runs on the {names} backends, each end to end through "
        "`pam2exu.run(model, analysis=..., steps=..., backend=...)` at the backend's default "
        "settings (a loaded `Model`; building the backend's system, its position solve, the "
        "native pass, the checks after the run and the result table). The backends are "
        "timed in alternation, their order swapped every repeat, round the whole grid of "
        f"this section: best of {plan.backend_repeats} repeats (chain: "
        f"{chain_repeats(plan, 1)} up to N = 8, {chain_repeats(plan, 16)} above), so every "
        "ratio below comes from runs of this benchmark run a few seconds apart. *Positions solve* is `res.info['backend_seconds']`, the time in the backend's "
        "`solve_positions` (for the natural backend: its Newton solve, and its own "
        "velocities and accelerations, which the analyses then use); *native* is the rest. "
        "Errors as in section 1, against the closed forms and the Newton–Euler references, "
        "from each backend's first run.")
    add("")
    add("### Targets (issue 12)")
    add("")
    add("The targets were set for the natural backend; the Exudyn backend is held to the same "
        "numbers beside it, for comparison."
        + (" This is a --quick smoke run: the step counts and sizes are smaller than the "
           "targets name, and the verdicts do not judge them." if quick else ""))
    add("")
    header = ["target", "goal"]
    for b in backends:
        header += [f"{label(b)} backend", "verdict"]
    header.append(f"{label(backends[-1])} / {label(backends[0])}")
    add(_table(header, target_rows(plan, side, memory)))
    add("")

    # the four-bar
    add(f"### Four-bar, {plan.backend_steps:,} steps")
    add("")
    rows = []
    for c in side["four_bar"]:
        first = c.runs.get(backends[0])
        for b in backends:
            r = c.runs.get(b)
            if not _ok(r):
                rows.append([c.analysis, label(b), "failed", "", "", *(["–"] * len(KINDS)),
                             r.short if r else "not run"])
                continue
            rel = (f"{r.us / first.us:.2f}×" if _ok(first) and b != backends[0] else "")
            rows.append([c.analysis, label(b), f"{r.us:.2f}", f"{r.exudyn_us:.2f}",
                         f"{r.us - r.exudyn_us:.2f}", *[f"{r.errors[k][0]:.1e}"
                                                        if k in r.errors else "–"
                                                        for k in KINDS],
                         (rel + "; " if rel else "") + (warning_summary([r]) or "–")])
    add(_table(["analysis", "backend", "µs/step", "positions solve", "native", *KINDS,
                f"against {label(backends[0])}; pam2exu's warnings"], rows))
    add("")

    notes = []
    for c, goal in zip(side["four_bar"], (KINEMATIC_US, KINETOSTATIC_US)):
        a, r = c.runs.get(backends[0]), c.runs.get(backends[-1])
        if len(backends) < 2 or not (_ok(a) and _ok(r)):
            continue
        notes.append(f"- {c.analysis.capitalize()}: the {label(backends[-1])} backend takes "
                     f"{r.us / a.us:.2f}× the {label(backends[0])} backend's time; of its "
                     f"{r.us:.2f} µs/step, {r.exudyn_us:.2f} µs are its positions solve and "
                     f"{r.us - r.exudyn_us:.2f} the native pass"
                     + (f", so its solve alone is {r.exudyn_us / goal:.1f}× the whole "
                        f"{goal:g} µs target" if r.exudyn_us > goal else "") + ".")
    if notes:
        add("What the measurements show:")
        add("")
        lines.extend(notes)
        add("")

    # the chain
    add(f"### Chain of N four-bar loops, {plan.chain_steps:,} steps")
    add("")
    add("The chain of section 4 (same model, references and scales), default settings of "
        "each backend (for Exudyn: its dense solver up to 40 coordinates, sparse above).")
    add("")
    by = {(c.N, c.analysis): c for c in side["chain"]}
    rows = []
    for N in dict.fromkeys(c.N for c in side["chain"]):
        row = [N]
        for analysis in ("kinematic", "kinetostatic"):
            c = by[(N, analysis)]
            us = [c.runs[b].us if _ok(c.runs.get(b)) else None for b in backends]
            row += [f"{u:.0f}" if u is not None else "failed" for u in us]
            if len(backends) > 1:
                row.append(f"{us[-1] / us[0]:.2f}×" if None not in us else "–")
        for b in backends:
            errs = [by[(N, a)].runs.get(b) for a in ("kinematic", "kinetostatic")]
            e = [r.errors["positions"][0] for r in errs if _ok(r) and "positions" in r.errors]
            row.append(f"{max(e):.1e}" if e else "–")
        rows.append(row)
    header = ["N"]
    for analysis in ("kinematic", "kinetostatic"):
        header += [f"{analysis} µs/step: {label(b)}" for b in backends]
        if len(backends) > 1:
            header.append(f"{label(backends[-1])} / {label(backends[0])}")
    header += [f"positions error: {label(b)}" for b in backends]
    add(_table(header, rows))
    add("")
    add("Fitted exponents p (time per step ∝ N^p, least squares in log-log over the sizes "
        "that ran; over N ≥ 8 in brackets):")
    add("")
    rows = []
    for analysis in ("kinematic", "kinetostatic"):
        fits = {b: chain_exponents(side["chain"], b, analysis) for b in backends}
        for part in ("total", "positions solve", "native"):
            row = [f"{analysis}, {part}"]
            for b in backends:
                f = fits[b].get(part)
                row.append("–" if not f else f"{f[0]:.2f}"
                           + (f" ({f[1]:.2f})" if f[1] is not None else ""))
            rows.append(row)
    add(_table(["part", *(f"{label(b)} backend" for b in backends)], rows))
    add("")

    # memory
    add(f"### Peak memory: the kinematic four-bar, {plan.memory_steps:,} steps")
    add("")
    if not memory:
        add("Not measured in this run (`--no-memory`).")
        add("")
    else:
        how = {m.get("measure", "ru_maxrss") for m in memory.values()}
        add("Each backend in a fresh Python process (`python -m benchmarks.backends --memory "
            "BACKEND STEPS`): the peak resident set size of that process, read in it right "
            "after `pam2exu.run` returns or fails (so it includes the interpreter, NumPy, "
            "Exudyn and the result table; the position error is computed after the reading), "
            + ("`VmHWM` of `/proc/self/status`. Not `resource.getrusage(...).ru_maxrss`: on "
               "Linux a process started from the benchmark inherits the benchmark's own "
               "high-water mark through fork and exec, so `RUSAGE_SELF` in the child and "
               "`RUSAGE_CHILDREN` in the benchmark would both report at least the "
               "benchmark's size" if how == {"VmHWM"} else
               "`resource.getrusage(RUSAGE_SELF).ru_maxrss` (no /proc here: it may include "
               "the benchmark's own high-water mark)")
            + ". *Before the run*: the same reading after the imports and loading the model. "
            "MB = 10⁶ bytes.")
        add("")
        rows = []
        for b in backends:
            m = memory.get(b)
            if m is None:
                continue
            peak = f"{_mb(m['peak_kib']):.0f}" if m.get("peak_kib") else "–"
            base = f"{_mb(m['baseline_kib']):.0f}" if m.get("baseline_kib") else "–"
            table = f"{m['table_bytes'] / 1e6:.0f} ({m['columns']} columns)" if m["ok"] else "–"
            error = f"{m['positions'][0]:.1e} ({m['positions'][1]})" if m["ok"] else "–"
            rows.append([label(b), f"{m['steps']:,}", f"{m['seconds']:.1f}", peak, base, table,
                         error, "completed" if m["ok"] else "failed: " + m["error"][:160]
                         + ("…" if len(m["error"]) > 160 else "") + " (Failures, below)"])
        add(_table(["backend", "steps", "wall s", "peak RSS, MB", "before the run, MB",
                    "result table, MB", "positions error", "outcome"], rows))
        add("")

    for b in backends:
        m = (memory or {}).get(b)
        if m and m["ok"] and m.get("peak_kib") and m.get("baseline_kib"):
            extra = _mb(m["peak_kib"] - m["baseline_kib"])
            add(f"- {label(b)}: the run raised the peak by {extra:.0f} MB, of which the "
                f"result table (rows × (1 + columns) × 8 bytes) is {m['table_bytes'] / 1e6:.0f} "
                f"MB: {extra / (m['steps'] / 1e6):.0f} bytes per step in all, "
                f"{(extra * 1e6 - m['table_bytes']) / m['steps']:.0f} of them beyond the table.")
    if memory and any(m["ok"] for m in memory.values()):
        add("")

    # failures
    failures = [(c, c.runs[b]) for c in side["four_bar"] + side["chain"]
                for b in backends if isinstance(c.runs.get(b), Failure)]
    failures += [(None, m) for m in (memory or {}).values() if not m["ok"]]
    add("### Failures")
    add("")
    if not failures:
        add("None: every run of this section completed.")
        add("")
    for c, f in failures:
        if c is None:
            add(f"- {label(f['backend'])} backend, four-bar, kinematic, {f['steps']:,} steps "
                f"(memory run): {_code(f['error'][:400])}")
            trace = f.get("trace", "")
        else:
            add(f"- {label(f.backend)} backend, {c.case}, {c.analysis}, {c.steps:,} steps: "
                f"{_code(f.short)}")
            trace = f.trace
        if trace:
            add("")
            add("  ```text")
            lines += ["  " + x for x in trace.splitlines()[-6:]]
            add("  ```")
        add("")
    return lines

"""Section 8: the dynamic analysis, work against precision (issue 15).

    python benchmarks/dynamics.py            # measures, writes docs/img/dynamic_work_precision.png
                                             # and replaces section 8 of docs/performance.md
    python benchmarks/dynamics.py --quick    # two tolerances, one repeat, to a temporary directory

For each tolerance of ``Plan.dynamic_tolerances`` (1e-4 … 1e-10), three free mechanisms run
with ``analysis="dynamic"`` on each backend of ``BACKENDS`` (Exudyn's generalized-α with
Richardson–Romberg, the natural backend's adaptive DOP853): wall time (best of
``Plan.dynamic_repeats``; one run where a run takes more than ``LONG`` seconds), the error
achieved against a reference computed without pam2exu, the estimate pam2exu reports
(``res.info["integration_error"]``), its step count (``res.info["integration_steps"]``: Exudyn's
fixed steps of its finest run, the natural backend's adaptive steps of its finest run), and
whether an ``AccuracyWarning`` was issued. A run that raises is a row too, with its message.
Errors are measured as the tolerance is defined (docs/model-format.md): the largest
|value − reference| / (1 + |reference|) over coordinates and rates.

- **pendulum**: a free compound pendulum (m 2 kg, d 0.25 m, I_G 0.02 kg·m², g 9.81), let go
  at rest 2.5 rad from hanging, over one period (scipy's complete elliptic integral), 10
  rows. Reference: DOP853 at rtol 1e-13 on I_O θ̈ = −m g d cos θ. Beside it, scipy's
  ``solve_ivp`` (DOP853, rtol = atol = tolerance) on the same one-DOF equation.
- **four-bar**: examples/equilibrium/spring_four_bar.toml let go (0.5 s, 25 rows). Reference:
  its energy T + V, constant in theory, from the result columns; the error is its range over
  the rows / (1 + |E0|), as tests/analyses/test_dynamic.py measures it.
- **Andrews**: examples/dynamics/andrews.toml to t = 0.03 s (3 rows). References
  (references/andrews.py): the test set's published state at 0.03 s (β … ε and their rates),
  and the test set's equations integrated by DOP853 at rtol 1e-13 (the published values are
  themselves off by up to 5e-8 in the rates). Beside it, ``solve_ivp`` (DOP853, rtol =
  tolerance) on those hand-written 7-DOF equations.

``measure(plan)`` is section 8 of benchmarks/speed_vs_error.py; ``dynamic_section`` writes its
Markdown between ``BEGIN`` and ``END``, which this file's own run replaces in an existing
docs/performance.md (the rest of the page stays as the last full run wrote it).
"""
from __future__ import annotations

import argparse
import math
import sys
import tempfile
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path

if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402

import pam2exu  # noqa: E402
from references import andrews  # noqa: E402

from pam2exu.analyses.dynamic import AccuracyWarning  # noqa: E402

from benchmarks.measure import FULL, QUICK, ROOT, log, machine  # noqa: E402
from references.pendulum import D, G, IO, M, pendulum_toml, swing  # noqa: E402

BEGIN = ("<!-- section 8: written by benchmarks/dynamics.py (python benchmarks/dynamics.py "
         "rewrites it alone) -->")
END = "<!-- end of section 8 -->"
#: a run longer than this many seconds is timed once
LONG = 20.0
#: a ratio of times below this is a tie (single timings vary by 10–30 % on this machine)
TIE = 1.15
#: the backends measured, and their names in the section
BACKENDS = {"exudyn": "Exudyn", "natural": "natural"}
AMPLITUDE = 2.5
#: references.pendulum's pendulum released at rest 2.5 rad from hanging, 10 rows
PENDULUM = pendulum_toml(AMPLITUDE - math.pi / 2, analysis='type = "dynamic"\nsteps = 10')


@dataclass
class DynamicRow:
    """One model at one tolerance on one backend (``failure``: the message of a run that
    raised; its numbers are then NaN)."""

    case: str
    tolerance: float
    seconds: float
    repeats: int
    steps: int
    estimate: float
    error: float                       # against the reference named in the section
    error_published: float | None = None   # Andrews: against the published values
    warnings: list = field(default_factory=list)
    backend: str = "exudyn"
    accuracy_warning: bool = False
    failure: str | None = None

    @property
    def met(self) -> bool:
        """The error achieved is within the tolerance (whatever the run warned)."""
        return self.failure is None and self.error <= self.tolerance

    @property
    def clean(self) -> bool:
        """Met, and no AccuracyWarning: the run both reached and reported the tolerance."""
        return self.met and not self.accuracy_warning


@dataclass
class ScipyRow:
    """scipy's solve_ivp (DOP853) on a model's hand-written ODE, at rtol = tolerance."""

    case: str
    tolerance: float
    seconds: float
    evaluations: int
    error: float


def _period():
    from scipy.special import ellipk
    return 4.0 * math.sqrt(IO / (M * G * D)) * ellipk(math.sin(AMPLITUDE / 2) ** 2)


def _pendulum_reference(times, rtol=1e-13):
    from scipy.integrate import solve_ivp
    sol = solve_ivp(swing, (0.0, times[-1]), [AMPLITUDE - math.pi / 2, 0.0],
                    method="DOP853", rtol=rtol, atol=rtol, t_eval=times)
    return sol.y.T, sol.nfev


def _relative(ours, ref):
    return float(np.max(np.abs(ours - ref) / (1.0 + np.abs(ref))))


def _andrews_state(res):
    fi = {i: res[f"body{i}.fi"][-1] for i in range(1, 8)}
    dfi = {i: res[f"body{i}.Dfi"][-1] for i in range(1, 8)}
    return np.r_[andrews.benchmark_angles(fi), andrews.benchmark_angles(dfi)]


def _energy(model, res):
    """T + V of the free four-bar at every row, from the columns (gravity and the spring)."""
    mech = model.mechanism()
    g = model.gravity
    energy = np.zeros(len(res))
    for s in mech.solids:
        fi = res[f"{s.name}.fi"]
        dx, dy, dfi = (res[f"{s.name}.D{k}"] for k in ("x", "y", "fi"))
        gx, gy = s.cog
        c, n = np.cos(fi), np.sin(fi)
        vx, vy = dx - dfi * (n * gx + c * gy), dy + dfi * (c * gx - n * gy)
        energy += 0.5 * s.mass * (vx ** 2 + vy ** 2) + 0.5 * s.inertia * dfi ** 2
        energy += s.mass * g * (res[f"{s.name}.y"] + n * gx + c * gy)
    spring = next(e for e in model.elements if e.type == "spring")
    _, k, free, _ = (list(spring.C) + [0.0] * 4)[:4]
    return energy + 0.5 * k * (res["spring.ro"] - free) ** 2


def cases():
    """(name, model, run keywords, error function of a result: (error, published error))."""
    pendulum = pam2exu.loads(PENDULUM)
    period = _period()
    times = np.linspace(0.0, period, 11)
    ref, _ = _pendulum_reference(times)

    def pendulum_error(res):
        ours = np.column_stack([res["lever.fi"], res["lever.Dfi"]])
        return _relative(ours, ref), None

    four_bar = pam2exu.load(ROOT / "examples" / "equilibrium" / "spring_four_bar.toml")

    def four_bar_error(res):
        e = _energy(four_bar, res)
        return float(np.ptp(e) / (1.0 + abs(e[0]))), None

    squeezer = pam2exu.load(ROOT / "examples" / "dynamics" / "andrews.toml")
    dop_q, dop_qd = andrews.integrate()
    dop = np.r_[dop_q, dop_qd]
    published = np.r_[andrews.PUBLISHED_Q, andrews.PUBLISHED_QD]

    def andrews_error(res):
        ours = _andrews_state(res)
        return _relative(ours, dop), _relative(ours, published)

    return [("pendulum", pendulum, dict(t_end=period, steps=10), pendulum_error),
            ("four-bar", four_bar, dict(t_end=0.5, steps=25), four_bar_error),
            ("Andrews", squeezer, dict(t_end=andrews.T_END, steps=3), andrews_error)]


def _scipy(tolerances):
    """solve_ivp's DOP853 at rtol = atol = tolerance (Andrews: atol = tolerance / 100, as
    its reference) on the pendulum's and Andrews' hand-written ODEs; best of 3."""
    from scipy.integrate import solve_ivp
    rows = []
    period = _period()
    times = np.linspace(0.0, period, 11)
    ref, _ = _pendulum_reference(times)
    dop = np.r_[tuple(andrews.integrate())]
    for tol in tolerances:
        best = np.inf
        for _ in range(3):
            begin = time.perf_counter()
            sol = solve_ivp(swing, (0.0, period), [AMPLITUDE - math.pi / 2, 0.0],
                            method="DOP853", rtol=tol, atol=tol, t_eval=times)
            best = min(best, time.perf_counter() - begin)
        rows.append(ScipyRow("pendulum", tol, best, sol.nfev, _relative(sol.y.T, ref)))
        best = np.inf
        for _ in range(3):
            begin = time.perf_counter()
            sol = solve_ivp(andrews.rhs, (0.0, andrews.T_END),
                            np.r_[andrews.Y0, np.zeros(7)], method="DOP853", rtol=tol,
                            atol=tol * 1e-2)
            best = min(best, time.perf_counter() - begin)
        rows.append(ScipyRow("Andrews", tol, best, sol.nfev, _relative(sol.y[:, -1], dop)))
    return rows


def _one(model, backend, tol, kw, repeats):
    """(best seconds, runs, result, AccuracyWarning issued, failure message or None)."""
    best, runs, res, accuracy = np.inf, 0, None, False
    while runs < repeats and (runs == 0 or best <= LONG):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            begin = time.perf_counter()
            try:
                res = pam2exu.run(model, analysis="dynamic", backend=backend, tolerance=tol,
                                  **kw)
            except Exception as exc:        # noqa: BLE001 - a failure is a measurement
                return (time.perf_counter() - begin, runs + 1, None, False,
                        f"{type(exc).__name__}: {exc}")
            best = min(best, time.perf_counter() - begin)
        accuracy = any(issubclass(w.category, AccuracyWarning) for w in caught)
        runs += 1
    return best, runs, res, accuracy, None


def measure(plan):
    """(pam2exu rows, scipy rows): every case at every tolerance of the plan, on every
    backend of ``BACKENDS``."""
    rows = []
    for name, model, kw, error in cases():
        for backend in BACKENDS:
            for tol in plan.dynamic_tolerances:
                best, runs, res, accuracy, failure = _one(model, backend, tol, kw,
                                                          plan.dynamic_repeats)
                if failure is not None:
                    rows.append(DynamicRow(name, tol, best, runs, 0, math.nan, math.nan, None,
                                           [], backend, False, failure))
                    log(f"  {name}, {backend}, tolerance {tol:g}: FAILED after {best:.2f} s: "
                        f"{failure}")
                    continue
                err, published = error(res)
                rows.append(DynamicRow(name, tol, best, runs,
                                       int(res.info["integration_steps"]),
                                       float(res.info["integration_error"]), err, published,
                                       list(res.warnings), backend, accuracy))
                log(f"  {name}, {backend}, tolerance {tol:g}: {best:.2f} s, "
                    f"{rows[-1].steps:,} steps, estimate {rows[-1].estimate:.1e}, error "
                    f"{err:.1e}" + (f" (published {published:.1e})" if published is not None
                                    else "") + (" AccuracyWarning" if accuracy else ""))
    return rows, _scipy(plan.dynamic_tolerances)


def _fmt(x: float) -> str:
    return "–" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.1e}"


def _seconds(x: float) -> str:
    return f"{x:.2f}" if x >= 0.01 else f"{x:.3f}"


def _growth(rows, backend):
    """Steps per decade of tolerance, from the loosest to the tightest tolerance met without
    a warning, per model: '<model> 1.78×'."""
    out = []
    for case in dict.fromkeys(r.case for r in rows):
        met = [r for r in rows if r.case == case and r.backend == backend and r.clean]
        if len(met) >= 2 and met[0].tolerance != met[-1].tolerance and met[0].steps > 0:
            decades = math.log10(met[0].tolerance / met[-1].tolerance)
            out.append(f"{case} {(met[-1].steps / met[0].steps) ** (1 / decades):.2f}×")
    return out


def _choice(rows):
    """{tolerance: {model: (winner backend or None, text of the cell)}}: the faster of the
    backends whose error met the tolerance."""
    choice = {}
    for tol in dict.fromkeys(r.tolerance for r in rows):
        choice[tol] = {}
        for case in dict.fromkeys(r.case for r in rows):
            mine = {r.backend: r for r in rows if r.case == case and r.tolerance == tol}
            ok = {b: r for b, r in mine.items() if r.met}
            times = ", ".join(f"{BACKENDS[b]} {_seconds(r.seconds)} s" if r.failure is None
                              else f"{BACKENDS[b]} failed" for b, r in mine.items())
            if not ok:
                choice[tol][case] = (None, f"neither met it ({times})")
                continue
            winner = min(ok, key=lambda b: ok[b].seconds)
            others = [r for b, r in mine.items() if b != winner]
            if others and all(o.met for o in others):
                ratio = max(o.seconds for o in others) / ok[winner].seconds
                if ratio < TIE:
                    choice[tol][case] = ("tie", f"about equal, {ratio:.2f}× ({times})")
                    continue
                text = f"**{BACKENDS[winner]}**, {ratio:.1f}× faster ({times})"
            else:
                text = f"**{BACKENDS[winner]}**, the other did not meet it ({times})"
            choice[tol][case] = (winner, text)
    return choice


def _recommendation(rows, choice) -> str:
    """The section's advice, from the winners of ``_choice``: per model, the loosest
    tolerance from which the natural backend is the faster one (or as fast) at every tighter
    tolerance too, its crossover."""
    tols = sorted(choice, reverse=True)
    cases_ = list(dict.fromkeys(r.case for r in rows))

    def row(case, backend, tol):
        return next((r for r in rows if r.case == case and r.backend == backend
                     and r.tolerance == tol), None)

    exudyn_all = [t for t in tols if all(choice[t][c][0] == "exudyn" for c in cases_)]
    cross, ties = {}, {}
    for c in cases_:
        for t in reversed(tols):                      # from the tightest up
            if choice[t][c][0] not in ("natural", "tie"):
                break
            cross[c] = t
        while c in cross and choice[cross[c]][c][0] == "tie":     # a crossover wins
            ties.setdefault(c, []).append(cross[c])
            tighter = [t for t in tols if t < cross[c]]
            if not tighter:
                del cross[c]
                break
            cross[c] = max(tighter)
    parts = []
    if exudyn_all:
        parts.append("the Exudyn backend is the faster on every model at "
                     + ", ".join(f"{t:.0e}" for t in exudyn_all))
    for c in cases_:
        if c in cross:
            parts.append(f"on {c} the natural backend is the faster from {cross[c]:.0e} down"
                         + (" (" + ", ".join(f"{t:.0e}" for t in ties[c]) + ": about equal)"
                            if c in ties else ""))
        elif all(choice[t][c][0] == "exudyn" for t in tols):
            ratios = [row(c, "natural", t).seconds / row(c, "exudyn", t).seconds
                      for t in tols if row(c, "natural", t) and row(c, "natural", t).met]
            parts.append(f"on {c} Exudyn is the faster at every tolerance"
                         + (f" ({min(ratios):.1f}–{max(ratios):.1f}×)" if ratios else ""))
    text = "**Which backend**, from these numbers: " + "; ".join(parts) + ". "
    natural = [c for c in cases_ if c in cross]
    exudyn_only = [c for c in cases_ if c not in cross
                   and all(choice[t][c][0] == "exudyn" for t in tols)]
    nat_rows = [r for r in rows if r.backend == "natural" and r.failure is None]
    if natural:
        gains = [(row(c, "exudyn", t).seconds / row(c, "natural", t).seconds, c, t)
                 for c in natural for t in tols if t <= cross[c]
                 and row(c, "exudyn", t) and row(c, "natural", t)
                 and row(c, "exudyn", t).failure is None]
        g, gc, gt = max(gains)
        text += ("So: keep the Exudyn backend (the default) for tolerances of "
                 + (f"{min(exudyn_all):.0e} and looser" if exudyn_all else "none of these")
                 + ", where its fixed-step runs are short and the natural backend's fixed cost "
                 "dominates (two DOP853 runs at least, of a Python right-hand side with a "
                 f"projection per step: never under {min(r.seconds for r in nat_rows):.2f} s "
                 f"here); choose `backend=\"natural\"` (`--backend natural`) from "
                 f"{max(cross[c] for c in natural):.0e} down for mechanisms of several bodies "
                 f"({', '.join(natural)}): Exudyn's steps double per decade of tolerance and "
                 f"DOP853's barely grow, so the gain widens as the tolerance tightens, up to "
                 f"{g:.1f}× on {gc} at {gt:.0e} ({_seconds(row(gc, 'exudyn', gt).seconds)} s "
                 f"against {_seconds(row(gc, 'natural', gt).seconds)} s). ")
    if exudyn_only:
        text += ("A mechanism as small as " + " or ".join(f"the {c}" for c in exudyn_only)
                 + " (one free body) stays faster on Exudyn at every tolerance: its "
                 "generalized-α runs are cheap enough that even 1e-10 costs less than the "
                 "natural backend's fixed cost. ")
    floor = [r for r in rows if r.backend == "exudyn" and r.accuracy_warning]
    if floor:
        text += ("Where Exudyn stopped at its floor with an AccuracyWarning ("
                 + ", ".join(f"{r.case} {r.tolerance:.0e}: {_seconds(r.seconds)} s, error "
                             f"{r.error:.1e}" for r in floor) + "), the natural backend took "
                 + ", ".join(f"{_seconds(n.seconds)} s, error {n.error:.1e}"
                             + (" (with an AccuracyWarning)" if n.accuracy_warning else "")
                             for r in floor for n in rows
                             if n.backend == "natural" and n.case == r.case
                             and n.tolerance == r.tolerance and n.failure is None) + ". ")
    failed = [r for r in rows if r.failure is not None]
    if failed:
        text += ("Failed runs (table above): " + ", ".join(
            f"{r.case} on {BACKENDS[r.backend]} at {r.tolerance:.0e}" for r in failed) + ". ")
    return text


def dynamic_section(measured) -> list[str]:
    """Section 8 of docs/performance.md, between ``BEGIN`` and ``END``."""
    rows, scipy_rows = measured
    order = {b: i for i, b in enumerate(BACKENDS)}
    cases_ = list(dict.fromkeys(r.case for r in rows))
    out = [BEGIN, "## 8. dynamic: work against precision", "",
           "The `dynamic` analysis (docs/analyses.md, \"Forward dynamics\") asked for "
           "tolerances from 1e-4 to 1e-10 on three free mechanisms, on both backends: "
           "**Exudyn** (the default: generalized-α, order 2, refined by Richardson and Romberg "
           "until two successive extrapolations agree) and **natural** (`backend=\"natural\"`: "
           "the equations of motion in natural coordinates, scipy's adaptive DOP853 projected "
           "onto the constraints after every step, rerun at rtol/16 until two runs agree). "
           "Wall time of `pam2exu.run(model, analysis=\"dynamic\", backend=..., "
           "tolerance=...)` (a loaded `Model`; best "
           f"of the runs shown, one run where a run took over {LONG:.0f} s); the steps of "
           "its finest run (`res.info[\"integration_steps\"]`: Exudyn's fixed steps, the "
           "natural backend's adaptive DOP853 steps, each costing 12 right-hand sides); the "
           "estimate it reports (`res.info[\"integration_error\"]`) and the error achieved, "
           "both per unit of value: max |value − reference| / (1 + |reference|) over the "
           "coordinates and rates; *≤ tol*: the error achieved is within the tolerance; "
           "*AccuracyWarning*: the run said it did not reach the tolerance. References, none "
           "from pam2exu: **pendulum**, a free compound pendulum let go 2.5 rad from "
           "hanging, over one period (10 rows), against DOP853 at rtol 1e-13 on its one-DOF "
           "equation; **four-bar**, examples/equilibrium/spring_four_bar.toml let go (0.5 s, "
           "25 rows), its energy T + V from the columns, whose range over the rows / "
           "(1 + |E0|) is the error; **Andrews**, examples/dynamics/andrews.toml to 0.03 s "
           "(3 rows), the seven angles β … ε and their rates against the IVP test set's "
           "equations integrated by DOP853 at rtol 1e-13 (references/andrews.py) and, in "
           "the column *vs published*, against the test set's published values, which that "
           "integration finds off by up to 2.8e-10 (angles) and 5.1e-8 (rates).", "",
           "| model | tolerance | backend | time [s] | runs | steps | estimate | error | "
           "vs published | ≤ tol | AccuracyWarning |",
           "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in sorted(rows, key=lambda r: (cases_.index(r.case), -r.tolerance,
                                         order.get(r.backend, 9))):
        name = BACKENDS.get(r.backend, r.backend)
        if r.failure is not None:
            message = r.failure.replace("|", "\\|").replace("\n", " ")
            out.append(f"| {r.case} | {r.tolerance:.0e} | {name} | {_seconds(r.seconds)} | "
                       f"{r.repeats} | – | – | – | – | **failed**: {message} | – |")
            continue
        out.append(f"| {r.case} | {r.tolerance:.0e} | {name} | {_seconds(r.seconds)} | "
                   f"{r.repeats} | {r.steps:,} | {_fmt(r.estimate)} | {_fmt(r.error)} | "
                   f"{_fmt(r.error_published)} | {'yes' if r.met else '**no**'} | "
                   f"{'**yes**' if r.accuracy_warning else 'no'} |")
    out += ["", "Beside them, scipy's `solve_ivp` (DOP853, rtol = atol = tolerance; Andrews "
            "atol = tolerance / 100) on the same models' hand-written ODEs (the pendulum's "
            "one DOF; Andrews' seven angles, index 1), best of 3, errors against the same "
            "references:", "",
            "| model | tolerance | time [s] | right-hand sides | error |",
            "|---|---|---|---|---|"]
    for r in sorted(scipy_rows, key=lambda r: (r.case, -r.tolerance)):
        out.append(f"| {r.case} | {r.tolerance:.0e} | {r.seconds:.4f} | {r.evaluations:,} | "
                   f"{r.error:.1e} |")
    choice = _choice(rows)
    out += ["", "The faster backend among those whose error met the tolerance:", "",
            "| tolerance | " + " | ".join(cases_) + " |",
            "|---|" + "---|" * len(cases_)]
    for tol in sorted(choice, reverse=True):
        out.append(f"| {tol:.0e} | " + " | ".join(choice[tol][c][1] for c in cases_) + " |")
    failed = [r for r in rows if r.failure is not None]
    over = [r for r in rows if r.failure is None and r.error > r.estimate]
    warned = [r for r in rows if r.accuracy_warning]
    reading = ("Reading it: generalized-α is of order 2 and pam2exu refines its step by "
               "Richardson and Romberg until the estimate meets the tolerance; the "
               "extrapolated error falls as h³, so its steps should grow by 10^(1/3) ≈ 2.15× "
               "per decade of tolerance (measured, from the loosest to the tightest tolerance "
               "met without a warning: " + ", ".join(_growth(rows, "exudyn")) + "). The "
               "natural backend's DOP853 is of order 8: 10^(1/8) ≈ 1.33× per decade ("
               + ", ".join(_growth(rows, "natural")) + "), but each of its steps is 12 "
               "evaluations of a Python right-hand side and a projection, and it makes at "
               "least two runs (rtol 0.1 tol, then /16 …): a fixed cost that Exudyn's loose "
               "runs do not pay. ")
    reading += ("The error achieved exceeded the estimate in " + "; ".join(
        f"{r.case} at {r.tolerance:.0e} on {BACKENDS[r.backend]} ({r.error:.1e} against "
        f"{r.estimate:.1e})" for r in over) + ": the estimate is not a bound there. "
        if over else "Every error achieved was at or below the estimate reported. ")
    reading += "".join(
        f"{r.case} at {r.tolerance:.0e} on {BACKENDS[r.backend]} stopped at {r.steps:,} "
        f"steps with an estimate of {r.estimate:.1e} and an AccuracyWarning (error achieved "
        f"{r.error:.1e}{', within the tolerance' if r.met else ''}). " for r in warned)
    reading += "".join(
        f"{r.case} at {r.tolerance:.0e} on {BACKENDS[r.backend]} failed after "
        f"{_seconds(r.seconds)} s: {r.failure.splitlines()[0]} " for r in failed)
    out += ["", "![dynamic work against precision](img/dynamic_work_precision.png)", "",
            reading, "", _recommendation(rows, choice), "", END]
    return out


def plot_dynamic(path, measured):
    """docs/img/dynamic_work_precision.png: time against error, one colour per model, one
    marker and line style per backend; filled markers the error achieved, open ones the
    estimate reported; squares dashed scipy's DOP853 on the hand-written ODE."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    rows, scipy_rows = measured
    fig, ax = plt.subplots(figsize=(10, 7))
    colours = {"pendulum": "C0", "four-bar": "C1", "Andrews": "C2"}
    style = {"exudyn": dict(marker="o", ls="-"), "natural": dict(marker="^", ls="-.")}
    estimate_ls = {"exudyn": ":", "natural": (0, (1, 3))}
    offset = {"exudyn": (4, -9), "natural": (4, 4)}
    for case, colour in colours.items():
        for backend in BACKENDS:
            mine = sorted((r for r in rows if r.case == case and r.backend == backend
                           and r.failure is None), key=lambda r: -r.tolerance)
            if not mine:
                continue
            st = style.get(backend, dict(marker="D", ls="--"))
            ax.loglog([r.error for r in mine], [r.seconds for r in mine], color=colour,
                      marker=st["marker"], ls=st["ls"], ms=6)
            ax.loglog([r.estimate for r in mine], [r.seconds for r in mine], color=colour,
                      marker=st["marker"], ls=estimate_ls.get(backend, ":"), mfc="none",
                      ms=6, alpha=0.7)
            warned = [r for r in mine if r.accuracy_warning]
            if warned:
                ax.loglog([r.error for r in warned], [r.seconds for r in warned], "o",
                          ms=14, mfc="none", mec="red", mew=1.2)
            if case == "Andrews":
                ax.loglog([r.error_published for r in mine], [r.seconds for r in mine],
                          "x" if backend == "exudyn" else "+", color=colour, ms=7)
            for r in mine:
                ax.annotate(f"{r.tolerance:.0e}", (r.error, r.seconds), fontsize=6,
                            xytext=offset.get(backend, (4, -9)), textcoords="offset points",
                            color=colour)
        theirs = sorted((r for r in scipy_rows if r.case == case), key=lambda r: -r.tolerance)
        if theirs:
            ax.loglog([r.error for r in theirs], [r.seconds for r in theirs], "s--",
                      color=colour, alpha=0.5, ms=4)
    handles = [Line2D([], [], color=c, lw=6, label=case) for case, c in colours.items()]
    for backend, name in BACKENDS.items():
        st = style.get(backend, dict(marker="D", ls="--"))
        handles.append(Line2D([], [], color="k", marker=st["marker"], ls=st["ls"],
                              label=f"{name} backend: error achieved"))
        handles.append(Line2D([], [], color="k", marker=st["marker"], mfc="none",
                              ls=estimate_ls.get(backend, ":"), alpha=0.7,
                              label=f"{name} backend: estimate reported"))
    handles += [Line2D([], [], color="k", marker="s", ls="--", alpha=0.5, ms=4,
                       label="scipy DOP853 on the hand-written ODE"),
                Line2D([], [], color="k", marker="x", ls="none",
                       label="Andrews vs published values (x Exudyn, + natural)"),
                Line2D([], [], marker="o", ms=12, mfc="none", mec="red", ls="none",
                       label="AccuracyWarning issued")]
    failed = [r for r in rows if r.failure is not None]
    if failed:
        handles.append(Line2D([], [], ls="none", label="failed (not drawn): " + ", ".join(
            f"{r.case} {BACKENDS[r.backend]} {r.tolerance:.0e}" for r in failed)))
    ax.set_xlabel("error per unit of value at the rows, max |y − ref| / (1 + |ref|)")
    ax.set_ylabel("wall time [s]")
    ax.set_title("dynamic, both backends: work against precision "
                 "(labels: the tolerance asked)")
    ax.grid(True, which="both", alpha=0.3)
    ax.invert_xaxis()
    ax.legend(handles=handles, fontsize=7, loc="upper left")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def replace_section(page: Path, lines: list[str], begin: str = BEGIN, end: str = END,
                    before: str | None = None) -> None:
    """Put ``lines`` (begin … end) in place of the page's section between those markers
    (default section 8's); a page without it gets it before the line ``before`` if it has
    that line, else at its end."""
    text = page.read_text(encoding="utf-8") if page.exists() else ""
    block = "\n".join(lines)
    if begin in text and end in text:
        head, rest = text.split(begin, 1)
        _, tail = rest.split(end, 1)
        text = head + block + tail
    elif before is not None and f"\n{before}\n" in text:
        head, tail = text.split(f"\n{before}\n", 1)
        text = f"{head}\n{block}\n\n{before}\n{tail}"
    else:
        text = text.rstrip("\n") + ("\n\n" if text else "") + block + "\n"
    page.write_text(text, encoding="utf-8")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true",
                        help="two tolerances, one repeat; written to a temporary directory")
    parser.add_argument("--out", type=Path, default=None,
                        help="directory holding performance.md and img/ (default: docs/)")
    args = parser.parse_args(argv)
    plan = QUICK if args.quick else FULL
    out_dir = args.out or (Path(tempfile.mkdtemp(prefix="pam2exu-dyn-")) if args.quick
                           else ROOT / "docs")
    log(f"8. dynamic: work against precision ({machine()['pam2exu']})")
    begin = time.perf_counter()
    measured = measure(plan)
    plot_dynamic(out_dir / "img" / "dynamic_work_precision.png", measured)
    replace_section(out_dir / "performance.md", dynamic_section(measured))
    log(f"wrote section 8 of {out_dir / 'performance.md'} and "
        f"{out_dir / 'img' / 'dynamic_work_precision.png'} "
        f"({(time.perf_counter() - begin) / 60:.1f} minutes)")


if __name__ == "__main__":
    main()

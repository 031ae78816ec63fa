"""Section 8: the dynamic analysis, work against precision (issue 15).

    python benchmarks/dynamics.py            # measures, writes docs/img/dynamic_work_precision.png
                                             # and replaces section 8 of docs/performance.md
    python benchmarks/dynamics.py --quick    # two tolerances, one repeat, to a temporary directory

For each tolerance of ``Plan.dynamic_tolerances`` (1e-4 … 1e-10), three free mechanisms run
with ``analysis="dynamic"``: wall time (best of ``Plan.dynamic_repeats``; one run where a run
takes more than ``LONG`` seconds), the error achieved against a reference computed without
pam2exu, the estimate pam2exu reports (``res.info["integration_error"]``) and its step count.
Errors are measured as the tolerance is defined (shared/spec/dynamics.md): the largest
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

from benchmarks.measure import FULL, QUICK, ROOT, log, machine  # noqa: E402

BEGIN = ("<!-- section 8: written by benchmarks/dynamics.py (python benchmarks/dynamics.py "
         "rewrites it alone) -->")
END = "<!-- end of section 8 -->"
#: a run longer than this many seconds is timed once
LONG = 20.0
G, M, D, IG = 9.81, 2.0, 0.25, 0.02
IO = IG + M * D * D
AMPLITUDE = 2.5

PENDULUM = f"""
[model]
name = "pendulum"
gravity = {G}

[[solid]]
name = "ground"

[[solid]]
name = "lever"
fi = {AMPLITUDE - math.pi / 2!r}
mass = {M}
inertia = {IG}
cog = [{D}, 0.0]
points = {{ O = [0.0, 0.0] }}

[[element]]
type = "fixed"
name = "base"
anc1 = "ground"

[[element]]
type = "revolute"
name = "pivot"
anc1 = "ground"
anc2 = "lever.O"

[analysis]
type = "dynamic"
steps = 10
"""


@dataclass
class DynamicRow:
    """One model at one tolerance."""

    case: str
    tolerance: float
    seconds: float
    repeats: int
    steps: int
    estimate: float
    error: float                       # against the reference named in the section
    error_published: float | None = None   # Andrews: against the published values
    warnings: list = field(default_factory=list)


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


def _pendulum_ode(t, y):
    return [y[1], -M * G * D * math.cos(y[0]) / IO]


def _pendulum_reference(times, rtol=1e-13):
    from scipy.integrate import solve_ivp
    sol = solve_ivp(_pendulum_ode, (0.0, times[-1]), [AMPLITUDE - math.pi / 2, 0.0],
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
            sol = solve_ivp(_pendulum_ode, (0.0, period), [AMPLITUDE - math.pi / 2, 0.0],
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


def measure(plan):
    """(pam2exu rows, scipy rows): every case at every tolerance of the plan."""
    rows = []
    for name, model, kw, error in cases():
        for tol in plan.dynamic_tolerances:
            best, runs = np.inf, 0
            while runs < plan.dynamic_repeats and (runs == 0 or best <= LONG):
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    begin = time.perf_counter()
                    res = pam2exu.run(model, analysis="dynamic", tolerance=tol, **kw)
                    best = min(best, time.perf_counter() - begin)
                runs += 1
            err, published = error(res)
            rows.append(DynamicRow(name, tol, best, runs, int(res.info["integration_steps"]),
                                   float(res.info["integration_error"]), err, published,
                                   list(res.warnings)))
            log(f"  {name}, tolerance {tol:g}: {best:.2f} s, {rows[-1].steps:,} steps, "
                f"estimate {rows[-1].estimate:.1e}, error {err:.1e}"
                + (f" (published {published:.1e})" if published is not None else ""))
    return rows, _scipy(plan.dynamic_tolerances)


def dynamic_section(measured) -> list[str]:
    """Section 8 of docs/performance.md, between ``BEGIN`` and ``END``."""
    rows, scipy_rows = measured
    out = [BEGIN, "## 8. dynamic: work against precision", "",
           "The `dynamic` analysis (docs/analyses.md, \"Forward dynamics\") asked for "
           "tolerances from 1e-4 to 1e-10 on three free mechanisms: wall time of "
           "`pam2exu.run(model, analysis=\"dynamic\", tolerance=...)` (a loaded `Model`; best "
           f"of the repeats shown, one run where a run took over {LONG:.0f} s), the steps "
           "of its finest Exudyn run, the estimate it reports (`res.info[\"integration_"
           "error\"]`) and the error achieved, both per unit of value: max |value − "
           "reference| / (1 + |reference|) over the coordinates and rates. References, none "
           "from pam2exu: **pendulum**, a free compound pendulum let go 2.5 rad from "
           "hanging, over one period (10 rows), against DOP853 at rtol 1e-13 on its one-DOF "
           "equation; **four-bar**, examples/equilibrium/spring_four_bar.toml let go (0.5 s, "
           "25 rows), its energy T + V from the columns, whose range over the rows / "
           "(1 + |E0|) is the error; **Andrews**, examples/dynamics/andrews.toml to 0.03 s "
           "(3 rows), the seven angles β … ε and their rates against the IVP test set's "
           "equations integrated by DOP853 at rtol 1e-13 (references/andrews.py) and, in "
           "the last column, against the test set's published values, which that "
           "integration finds off by up to 2.8e-10 (angles) and 5.1e-8 (rates).", "",
           "| model | tolerance | time [s] | runs | steps | estimate | error | error vs "
           "published | met |",
           "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        met = r.error <= r.tolerance and not r.warnings
        out.append(f"| {r.case} | {r.tolerance:.0e} | {r.seconds:.2f} | {r.repeats} | "
                   f"{r.steps:,} | {r.estimate:.1e} | {r.error:.1e} | "
                   + ("–" if r.error_published is None else f"{r.error_published:.1e}")
                   + f" | {'yes' if met else 'no' + (' (AccuracyWarning)' if r.warnings else '')} |")
    out += ["", "Beside them, scipy's `solve_ivp` (DOP853, rtol = atol = tolerance; Andrews "
            "atol = tolerance / 100) on the same models' hand-written ODEs (the pendulum's "
            "one DOF; Andrews' seven angles, index 1), best of 3, errors against the same "
            "references:", "",
            "| model | tolerance | time [s] | right-hand sides | error |",
            "|---|---|---|---|---|"]
    for r in sorted(scipy_rows, key=lambda r: (r.case, -r.tolerance)):
        out.append(f"| {r.case} | {r.tolerance:.0e} | {r.seconds:.4f} | {r.evaluations:,} | "
                   f"{r.error:.1e} |")
    missed = [r for r in rows if r.warnings]
    over = [r for r in rows if r.error > r.estimate]
    growth = []
    for case in dict.fromkeys(r.case for r in rows):
        met = [r for r in rows if r.case == case and not r.warnings]
        if len(met) >= 2 and met[0].tolerance != met[-1].tolerance:
            decades = math.log10(met[0].tolerance / met[-1].tolerance)
            growth.append(f"{case} {(met[-1].steps / met[0].steps) ** (1 / decades):.2f}×")
    out += ["", "![dynamic work against precision](img/dynamic_work_precision.png)", "",
            "Reading it: generalized-α is of order 2 and pam2exu refines its step by "
            "Richardson and Romberg until the estimate meets the tolerance; the extrapolated "
            "error falls as h³, so the steps should grow by 10^(1/3) ≈ 2.15× per decade of "
            "tolerance (measured, from the loosest to the tightest tolerance met: "
            + ", ".join(growth) + "), against DOP853's order 8 on a plain ODE. "
            + ("The error achieved exceeded the estimate in " + "; ".join(
                f"{r.case} at {r.tolerance:.0e} ({r.error:.1e} against {r.estimate:.1e})"
                for r in over) + ": the estimate is not a bound. " if over else
               "Every error achieved was below the estimate reported. ")
            + ("".join(f"{r.case} at {r.tolerance:.0e} stopped at {r.steps:,} steps with an "
                       f"estimate of {r.estimate:.1e} and an AccuracyWarning. "
                       for r in missed))
            + "This section measures the Exudyn backend (the default) only: the "
            "natural-coordinates backend's integrator (backend/natural/dynamics.py) is not "
            "in it yet.", "", END]
    return out


def plot_dynamic(path, measured):
    """docs/img/dynamic_work_precision.png: time against error, one colour per model;
    filled markers the error achieved, open ones the estimate reported, dashed scipy."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows, scipy_rows = measured
    fig, ax = plt.subplots(figsize=(9, 6.5))
    colours = {"pendulum": "C0", "four-bar": "C1", "Andrews": "C2"}
    for case, colour in colours.items():
        mine = sorted((r for r in rows if r.case == case), key=lambda r: -r.tolerance)
        if not mine:
            continue
        ax.loglog([r.error for r in mine], [r.seconds for r in mine], "o-", color=colour,
                  label=f"{case}: pam2exu dynamic, error achieved")
        ax.loglog([r.estimate for r in mine], [r.seconds for r in mine], "o:", color=colour,
                  mfc="none", label=f"{case}: pam2exu, error estimate reported")
        if case == "Andrews":
            ax.loglog([r.error_published for r in mine], [r.seconds for r in mine], "x",
                      color=colour, label="Andrews: error against the published values")
        for r in mine:
            ax.annotate(f"{r.tolerance:.0e}", (r.error, r.seconds), fontsize=7,
                        xytext=(4, -8), textcoords="offset points", color=colour)
        theirs = sorted((r for r in scipy_rows if r.case == case), key=lambda r: -r.tolerance)
        if theirs:
            ax.loglog([r.error for r in theirs], [r.seconds for r in theirs], "s--",
                      color=colour, alpha=0.6,
                      label=f"{case}: scipy DOP853 on its hand-written ODE")
    ax.set_xlabel("error per unit of value at the rows, max |y − ref| / (1 + |ref|)")
    ax.set_ylabel("wall time [s]")
    ax.set_title("dynamic: work against precision (labels: the tolerance asked)")
    ax.grid(True, which="both", alpha=0.3)
    ax.invert_xaxis()
    ax.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def replace_section(page: Path, lines: list[str]) -> None:
    """Put ``lines`` (BEGIN … END) in place of the page's section 8, or at its end."""
    text = page.read_text(encoding="utf-8") if page.exists() else ""
    block = "\n".join(lines)
    if BEGIN in text and END in text:
        head, rest = text.split(BEGIN, 1)
        _, tail = rest.split(END, 1)
        text = head + block + tail
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

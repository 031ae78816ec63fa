"""The clearance analysis against the kinematic one, in one run (issue 25): the section
"Clearance at kinematic speed" of docs/performance.md.

For the locomotive (examples/clearance/locomotive.toml, 400 steps) and
examples/all_elements.toml (no clearance joint), the wall time of ``pam2exu.run`` of the
clearance analysis and of the kinematic analysis of the same loaded model, in alternation,
best of ``REPEATS`` each: their ratio against the issue's target. Also the closure
evaluations of a locomotive run (right-hand sides of the slides' ODE, rows evaluated at
once) and the time of a run whose fixed deviations cannot be absorbed (axle 3 0.3 m
across the frame: it stops at the fold of the least-norm clearance).

    python benchmarks/clearance_speed.py            # rewrites its section of docs/performance.md
    python benchmarks/clearance_speed.py --out DIR  # DIR/performance.md instead
"""
from __future__ import annotations

import argparse
import os
import sys
import time
import warnings
from pathlib import Path

if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import pam2exu  # noqa: E402
from pam2exu.analyses import closures as closures_module  # noqa: E402

from benchmarks.dynamics import replace_section  # noqa: E402
from benchmarks.measure import ROOT, log  # noqa: E402

BEGIN = ("<!-- clearance at kinematic speed: written by benchmarks/clearance_speed.py (python "
         "benchmarks/clearance_speed.py rewrites it alone) -->")
END = "<!-- end of clearance at kinematic speed -->"
#: timed runs of each analysis, in alternation
REPEATS = 5
#: (what, model, steps, target ratio clearance / kinematic)
CASES = (("locomotive clearance, 400 steps / its kinematic run",
          "examples/clearance/locomotive.toml", 400, 5.0),
         ("`all_elements` clearance / its kinematic run", "examples/all_elements.toml",
          None, 3.0))


def ratio(path: str, steps: int | None, repeats: int = REPEATS) -> tuple[float, float]:
    """(best clearance [s], best kinematic [s]) of the model, in alternation, ``repeats``
    runs of each."""
    model = pam2exu.load(ROOT / path)
    kw = {} if steps is None else {"steps": steps}
    best = {"clearance": float("inf"), "kinematic": float("inf")}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        pam2exu.run(model, analysis="clearance", **kw)            # imports, caches
        for _ in range(repeats):
            for analysis in best:
                begin = time.perf_counter()
                pam2exu.run(model, analysis=analysis, **kw)
                best[analysis] = min(best[analysis], time.perf_counter() - begin)
    return best["clearance"], best["kinematic"]


def evaluations(path: str, steps: int) -> tuple[int, int]:
    """(right-hand sides of the ODE, evaluations of rows at once) of one clearance run."""
    counts = {"rate": 0, "rows": 0}
    cls = closures_module.Closures
    rate, rows = cls.evaluate_rate, cls.evaluate_rows

    def counted_rate(self, *args, **kw):
        counts["rate"] += 1
        return rate(self, *args, **kw)

    def counted_rows(self, *args, **kw):
        counts["rows"] += 1
        return rows(self, *args, **kw)
    cls.evaluate_rate, cls.evaluate_rows = counted_rate, counted_rows
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            pam2exu.run(ROOT / path, steps=steps)
    finally:
        cls.evaluate_rate, cls.evaluate_rows = rate, rows
    return counts["rate"], counts["rows"]


def newton_agreement(path: str) -> tuple[float, float]:
    """(max |ODE − Newton at every row| over the table, Newton's time / the ODE's) of the
    clearance run of the model (``method``, its default steps)."""
    model = pam2exu.load(ROOT / path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        begin = time.perf_counter()
        ode = pam2exu.run(model, analysis="clearance")
        middle = time.perf_counter()
        newton = pam2exu.run(model, analysis="clearance", method="newton")
        end = time.perf_counter()
    gap = float(abs(ode.to_numpy() - newton.to_numpy()).max())
    return gap, (end - middle) / (middle - begin)


def fold_seconds() -> tuple[float, str]:
    """(seconds, the message's first words) of the locomotive with axle 3 0.3 m across."""
    text = (ROOT / "examples/clearance/locomotive.toml").read_text(encoding="utf-8")
    text = text.replace("steps = 400", "steps = 2").replace("t_end = 9.66643893412244",
                                                            "t_end = 0.2")
    head, _, tail = text.partition("[analysis]")
    model = pam2exu.loads(f'{head}[[variation]]\nanchor = "frame.O3"\nfixed_dy = 0.3\n\n'
                          f'[analysis]{tail}')
    begin = time.perf_counter()
    try:
        pam2exu.run(model)
        said = "no error"
    except pam2exu.SolverError as error:
        said = str(error).split("(of 0")[0].split("it stops at ")[-1]
    return time.perf_counter() - begin, said


def section() -> list[str]:
    load = os.getloadavg()
    rows = []
    for what, path, steps, target in CASES:
        clearance, kinematic = ratio(path, steps)
        rows.append(f"| {what} | {clearance:.3f} | {kinematic:.3f} | "
                    f"{clearance / kinematic:.1f}× | ≤ {target:g}× | "
                    f"{'met' if clearance / kinematic <= target else 'not met'} |")
    rhs, batches = evaluations("examples/clearance/locomotive.toml", 400)
    fold, said = fold_seconds()
    agree = [(Path(path).stem, *newton_agreement(path)) for path in (
        "examples/clearance/locomotive.toml", "examples/clearance/slider_guided_twice.toml")]
    after = os.getloadavg()
    return [BEGIN, "## Clearance at kinematic speed (issue 25)", "",
            f"Wall time of `pam2exu.run` of a loaded model, clearance and kinematic in "
            f"alternation, best of {REPEATS} each, measured in one run (load averages "
            f"{load[0]:.1f} before, {after[0]:.1f} after, on 2 shared cores: read the "
            f"ratios).", "",
            "| what | clearance [s] | kinematic [s] | ratio | target | verdict |",
            "|---|---|---|---|---|---|", *rows, "",
            "Before (issue 25's measurements): 66× and 115–170×; h_t was central "
            "differences in t, three closure evaluations per right-hand side, each a "
            "State with second derivatives at one time, and every row's Newton "
            "correction, strict-minimum check and first-order estimate one evaluation at a "
            "time; `all_elements` followed the empty clearance by the ODE.", "",
            f"A locomotive run of 400 steps evaluates the closure {rhs} times for the "
            f"right-hand sides of the slides' ODE (one evaluation each: h_t exact, by a "
            f"complex step in the varied dimensions) and {batches} times on all its rows at "
            f"once (the Newton corrections, the strict-minimum checks, the first-order "
            f"estimate). `all_elements` has no clearance joint: its positions are the "
            f"kinematic ones, refined by Newton on the closure. The locomotive with axle 3 "
            f"0.3 m across the frame (fixed deviations that cannot be absorbed) stops at "
            f"{said.strip()} in {fold:.2f} s.", "",
            "Newton at every row (`method = \"newton\"`, the reference) against the ODE, "
            "default steps: " + "; ".join(
                f"{name}: the tables agree to {gap:.2g} (target 1e-9), Newton takes "
                f"{slower:.1f}× the ODE's time" for name, gap, slower in agree) + ".",
            "", END]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=ROOT / "docs",
                        help="directory holding performance.md (default: docs/)")
    args = parser.parse_args(argv)
    log("clearance at kinematic speed")
    lines = section()
    replace_section(args.out / "performance.md", lines, BEGIN, END)
    print("\n".join(lines))


if __name__ == "__main__":
    main()

"""The ``pam2exu`` command: run and check PAM models, compare result files.

Exit codes: 0 success, 1 solver failure, 2 model error (or bad command line).
``compare``: 0 every variable within the tolerance, 1 some outside, 2 bad input.
Errors are printed to stderr as one paragraph; ``--debug`` shows the traceback.
"""
from __future__ import annotations

import argparse
import sys
import warnings

from . import __version__
from .errors import ModelError, Pam2ExuError, SolverError


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="pam2exu", description=
                                "Run PAM planar mechanism models on the Exudyn multibody library.")
    p.add_argument("--version", action="version", version=f"pam2exu {__version__}")
    p.add_argument("--debug", action="store_true", help="show tracebacks of errors")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")

    run = sub.add_parser("run", help="run an analysis and print a summary or write CSV",
                         description="Run the model's analysis (settings of its [analysis] "
                                     "table, overridden by the options).")
    run.add_argument("model", help="model file (TOML)")
    run.add_argument("--analysis", "-a", metavar="TYPE",
                     help="assembly, kinematic, quasi_static or kinetostatic")
    run.add_argument("--t-end", type=float, metavar="T", help="end of the interval [s]")
    run.add_argument("--steps", type=int, metavar="N", help="number of intervals (N + 1 rows)")
    run.add_argument("--outputs", nargs="+", metavar="PAT",
                     help="columns to keep: names, 'solid.*', '*.Fx' or bare 'Fx'")
    run.add_argument("-o", "--output", metavar="OUT.csv", help="write all rows as CSV")
    run.add_argument("--verbose", action="store_true", help="show Exudyn's solver output")
    run.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                     help=argparse.SUPPRESS)

    check = sub.add_parser("check", help="validate a model, print its mobility and elements")
    check.add_argument("model", help="model file (TOML)")
    check.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                       help=argparse.SUPPRESS)

    from .results.compare import ATOL, RTOL
    comp = sub.add_parser(
        "compare", help="compare a result CSV with a reference CSV, variable by variable",
        description="For each variable in both files: max absolute and relative error, the "
                    "time where it occurs, and pass when max |result - reference| <= "
                    "atol + rtol * max |reference|. Exit 0 when every variable passes, 1 "
                    "otherwise, 2 for bad input. See docs/compare.md.")
    comp.add_argument("result", help="result CSV (pam2exu run MODEL -o FILE.csv)")
    comp.add_argument("reference", help="reference CSV (another run, or exported from PAM)")
    comp.add_argument("--rtol", type=float, default=RTOL, metavar="R",
                      help=f"relative tolerance, times max |reference| (default {RTOL:g})")
    comp.add_argument("--atol", type=float, default=ATOL, metavar="A",
                      help=f"absolute tolerance, SI units (default {ATOL:g})")
    comp.add_argument("--columns", nargs="+", metavar="PAT",
                      help="variables to compare: names, 'solid.*', '*.Fx' or bare 'Fx'")
    comp.add_argument("--names", metavar="MAP",
                      help="names map for the reference's columns: two-column CSV "
                           "'pam_name,pam2exu_name'")
    comp.add_argument("--format", choices=["md", "csv"], default="md",
                      help="md: Markdown table (default); csv: CSV on stdout, notes on stderr")
    comp.add_argument("--interp", choices=["cubic", "linear"], default="cubic",
                      help="interpolation of the result when the times differ (default cubic)")
    comp.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                      help=argparse.SUPPRESS)
    return p


def _run(args) -> int:
    from .analyses import run
    from .backend import SolveSettings
    solver = SolveSettings(verbose=1 if args.verbose else 0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")      # warnings are carried in res.warnings
        res = run(args.model, analysis=args.analysis, t_end=args.t_end, steps=args.steps,
                  outputs=args.outputs, solver=solver)
    if args.output:
        path = res.to_csv(args.output)
        print(f"wrote {len(res)} rows × {len(res.columns) + 1} columns to {path}")
        for w in res.warnings:
            print(f"warning: {w}", file=sys.stderr)
    else:
        print(res.summary())
    return 0


def _check(args) -> int:
    import numpy as np

    from .analyses.native import mobility
    from .model import load
    model = load(args.model)
    mech = model.mechanism()
    mob = mobility(mech, 0.0, mech.initial_q())
    print(f"model '{model.name}' ({args.model}): {len(mech.solids)} solids, "
          f"{len(mech.elements)} elements, {mech.nq} coordinates, "
          f"{mech.n_equations} constraint equations")
    print(f"degrees of freedom not driven: {mob.dof}"
          + (f" (solids free to move: {', '.join(mob.free_solids)})" if mob.dof else ""))
    print(f"redundant constraint equations: {mob.redundant}"
          + (f" (among {', '.join(mob.redundant_elements)})" if mob.redundant else ""))
    if np.isfinite(mob.condition):
        print(f"condition number of the constraint Jacobian at the initial guess: "
              f"{mob.condition:.3g}")
    a = model.analysis
    print(f"analysis: {a.type}, t = 0 … {a.t_end} s in {a.steps} steps")
    print()
    width = max([len(e.name) for e in mech.elements] + [4])
    for e in mech.elements:
        anchors = ", ".join(str(getattr(e, f"anc{k + 1}")) for k in range(len(e.anchors)))
        print(f"  {e.name:<{width}}  {e.type:<17} {anchors}")
    return 0


def _compare(args) -> int:
    from .results.compare import CompareInputError, compare
    try:
        table = compare(args.result, args.reference, rtol=args.rtol, atol=args.atol,
                        columns=args.columns, names=args.names, method=args.interp)
    except CompareInputError as exc:
        if args.debug:
            raise
        print(f"pam2exu: compare: {exc}", file=sys.stderr)
        return 2
    if args.format == "csv":
        for line in table.header():
            print(line, file=sys.stderr)
        sys.stdout.write(table.to_csv())
        print(table.verdict(), file=sys.stderr)
    else:
        print(table.to_markdown())
    return 0 if table.passed else 1


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    try:
        return {"run": _run, "check": _check, "compare": _compare}[args.command](args)
    except BrokenPipeError:              # output piped into head & co.
        sys.stderr.close()
        return 0
    except Exception as exc:
        if args.debug:
            raise
        if isinstance(exc, ModelError):
            code, kind = 2, "model error"
        elif isinstance(exc, SolverError):
            code, kind = 1, "solver failure"
        elif isinstance(exc, Pam2ExuError):
            code, kind = 1, "error"
        else:
            code, kind = 1, f"unexpected error ({type(exc).__name__}; rerun with --debug)"
        print(f"pam2exu: {kind}: {exc}", file=sys.stderr)
        return code


if __name__ == "__main__":
    sys.exit(main())

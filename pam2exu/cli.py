"""The ``pam2exu`` command: run and check PAM models, compare result files.

Exit codes: 0 success, 1 solver failure, 2 model error (or bad command line, options that
do not go together, or an output file that cannot be written as asked: an unknown suffix, a
missing optional library; ``run`` checks these before it runs anything).
``compare``: 0 every variable within the tolerance, 1 some outside, 2 bad input.
``verify``: 0 the two backends agree, 1 they differ or a run fails, 2 bad input.
``plot``, ``draw``, ``animate``: 2 also for a picture that cannot be made as asked (an
unknown image format, no ffmpeg for .mp4, a variable that matches nothing).
Errors are printed to stderr as one paragraph; ``--debug`` shows the traceback.
"""
from __future__ import annotations

import argparse
import sys
import warnings

from .errors import ModelError, OutputError, Pam2ExuError, SolverError
from .console import UsageError, Warnings, checked_model, run_outputs
from .registry import ANALYSES, BACKENDS, DEFAULT_BACKEND
from .verify import BACKENDS_COMPARED, verify
from .version import __version__


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
                     help=", ".join(ANALYSES) + " (or PAM's Catalan names: "
                          + ", ".join(a.alias for a in ANALYSES.values()) + ")")
    run.add_argument("--backend", metavar="NAME",
                     help="what solves the positions: " + ", ".join(BACKENDS)
                          + f" (default: the model's [analysis] backend, else "
                            f"{DEFAULT_BACKEND})")
    run.add_argument("--t-end", type=float, metavar="T", help="end of the interval [s]")
    run.add_argument("--steps", type=int, metavar="N", help="number of intervals (N + 1 rows)")
    run.add_argument("--tolerance", type=float, metavar="TOL",
                     help="dynamic: the time integration's error allowed per unit of each "
                          "coordinate and rate (default: the model's [analysis] tolerance, "
                          "else 1e-8)")
    run.add_argument("--outputs", nargs="+", metavar="PAT",
                     help="columns to keep: names, 'solid.*', '*.Fx' or bare 'Fx'")
    run.add_argument("-o", "--output", metavar="OUT.csv",
                     help="write all rows: .csv, .xlsx (pam2exu[excel]) or .parquet "
                          "(pam2exu[parquet]), the format from the suffix")
    run.add_argument("--sep", default=",", metavar="SEP",
                     help="CSV separator: ',' (default), ';' or tab")
    run.add_argument("--decimal", default=".", metavar="MARK",
                     help="CSV decimal mark: '.' (default) or ',' (with --sep ';': the "
                          "CSV Excel opens in Catalan or Spanish)")
    run.add_argument("--bom", action="store_true",
                     help="start the CSV with a UTF-8 byte-order mark (for Excel)")
    run.add_argument("--at", nargs="+", type=float, metavar="T",
                     help="print every variable at these times [s], one block per solid and "
                          "element (between rows: the cubic spline of compare, said so)")
    run.add_argument("--partial", action="store_true",
                     help="if the run fails, write the rows computed before the failure to "
                          "-o (the clearance analysis keeps them); the exit status stays 1")
    run.add_argument("--verbose", action="store_true", help="show the backend's solver output")
    run.add_argument("--plot", nargs="+", metavar="VAR",
                     help="plot these variables against t (names or patterns, as --outputs)")
    run.add_argument("--plot-file", metavar="FIG.png",
                     help="image file of --plot (default: <model>_plot.png)")
    run.add_argument("--x", metavar="VAR",
                     help="the x axis of --plot: a variable such as crank.fi (default t)")
    run.add_argument("--energy", metavar="FIG.png",
                     help="kinetostatic, dynamic: plot the energy account (kinetic, "
                          "potential, work of actuators and torsors, dissipated, balance)")
    run.add_argument("--angles", choices=("rad", "deg"),
                     help="unit of the angular results: rad (rad/s, rad/s²) or deg (deg/s, "
                          "deg/s²); default: the model's [model] angles")

    check = sub.add_parser(
        "check", help="validate a model, print its mobility and elements",
        description="Everything run checks before solving: the model, the analysis settings, "
                    "the plan of the run (laws over the interval, sub-steps, work), the "
                    "mobility. Exit 2, with run's message, when the analysis needs every "
                    "degree of freedom driven and one is not.")
    check.add_argument("model", help="model file (TOML)")
    check.add_argument("--analysis", "-a", metavar="TYPE",
                       help="the analysis to check for (default: the model's)")
    check.add_argument("--t-end", type=float, metavar="T", help="end of the interval [s]")
    check.add_argument("--steps", type=int, metavar="N", help="number of intervals")
    check.add_argument("--backend", metavar="NAME",
                       help="what solves the positions: " + ", ".join(BACKENDS))

    elements = sub.add_parser(
        "elements", help="the element types: keys, anchors, outputs and sign conventions",
        description="Without TYPE: every element type (Catalan PAM names in brackets) and the "
                    "time laws. With TYPE (English or Catalan): its keys, defaults, constraint "
                    "equations, outputs with units, and where its reaction is reported. The "
                    "same text as docs/model-format.md.")
    elements.add_argument("types", nargs="*", metavar="TYPE", help="e.g. revolute, piu_guia")

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
    comp.add_argument("--wrap-angles", action="store_true",
                      help="compare angles (rad) modulo 2π, for exports whose angles wrap at "
                           "±π (PAM's)")
    comp.add_argument("--angles", choices=("rad", "deg"),
                      help="compare the angular variables in rad (default) or deg (--atol "
                           "then in deg for them); a file in degrees is read as such either "
                           "way")

    ver = sub.add_parser(
        "verify", help="run the model on two backends and compare them, variable by variable",
        description="Run the analysis on two backends (two formulations of the constraints) "
                    "and print, per variable, the largest difference, where it occurs and "
                    "whether it is within a tolerance derived from the solvers' tolerances "
                    "and the condition number. Exit 0 when they agree, 1 when they differ "
                    "(or a run fails), 2 for bad input. See docs/verify.md.")
    ver.add_argument("model", help="model file (TOML)")
    ver.add_argument("--analysis", "-a", metavar="TYPE",
                     help="the analysis (default: the model's)")
    ver.add_argument("--steps", type=int, metavar="N", help="number of intervals (N + 1 rows)")
    ver.add_argument("--t-end", type=float, metavar="T", help="end of the interval [s]")
    ver.add_argument("--against", metavar="BACKEND", default=BACKENDS_COMPARED[1],
                     help=f"the backend verified against {BACKENDS_COMPARED[0]} (default "
                          f"{BACKENDS_COMPARED[1]}; known: " + ", ".join(BACKENDS) + ")")

    exp = sub.add_parser(
        "export", help="write a standalone Exudyn script of the model (positions to CSV)",
        description="Write a Python script that imports only exudyn and numpy, builds the "
                    "model's Exudyn system (one commented block per solid and element), "
                    "solves the positions over the [analysis] interval with Exudyn's static "
                    "solver and writes x, y, fi of every solid as CSV. See docs/export.md.")
    exp.add_argument("model", help="model file (TOML)")
    exp.add_argument("-o", "--output", required=True, metavar="FILE.py",
                     help="the script to write")
    exp.add_argument("--t-end", type=float, metavar="T", help="end of the interval [s]")
    exp.add_argument("--steps", type=int, metavar="N", help="number of intervals (N + 1 rows)")
    exp.add_argument("--forces", action="store_true",
                     help="include masses, gravity, springs and loads (same positions)")
    exp.add_argument("-a", "--analysis", metavar="NAME", help="default: the model's [analysis] "
                     "type; dynamic (a DOF free): the SolveDynamic script")
    exp.add_argument("--tolerance", type=float, metavar="TOL",
                     help="the dynamic analysis's tolerance (default: the model's)")

    _picture_parsers(sub)
    return p


def _picture_parsers(sub) -> None:
    """plot, draw and animate (see docs/pictures.md)."""
    plot = sub.add_parser(
        "plot", help="plot variables of a result CSV against t (PNG, SVG, PDF)",
        description="Plot variables of a result file against t, labelled with their PAM "
                    "names and units; variables of one unit share a panel. Exit 2 for bad "
                    "input. See docs/pictures.md.")
    plot.add_argument("results", help="result CSV (pam2exu run MODEL -o FILE.csv)")
    plot.add_argument("variables", nargs="+", metavar="VAR",
                      help="names or patterns: crank.fi, 'crank.*', '*.Fx' or a bare Fx")
    plot.add_argument("-o", "--output", metavar="FIG.png",
                      help="image file, format from the suffix (default: <results>.png)")
    plot.add_argument("--model", metavar="MODEL",
                      help="the model, for the units of f(t) and Df(t) (rad or m)")
    plot.add_argument("--x", metavar="VAR",
                      help="the x axis: a variable such as crank.fi (default t)")
    plot.add_argument("--angles", choices=("rad", "deg"),
                      help="show the angular variables in rad or deg (default: as the file "
                           "has them)")
    draw = sub.add_parser(
        "draw", help="draw the mechanism at a configuration (PNG, SVG, PDF)",
        description="Draw the solids and elements of a model: assembled at t = 0, or at "
                    "time T of a kinematic run (dynamic, for a model whose analysis is "
                    "dynamic). See docs/pictures.md.")
    draw.add_argument("model", help="model file (TOML)")
    draw.add_argument("--t", type=float, default=0.0, metavar="T",
                      help="time [s] (default 0: the assembly)")
    draw.add_argument("-o", "--output", metavar="FIG.png",
                      help="image file, format from the suffix (default: <model>.png)")
    draw.add_argument("--vectors", choices=("v", "a", "F"),
                      help="arrows to scale at T: v velocities or a accelerations of the "
                           "solids' points (kinematic run), F the joints' reaction forces "
                           "(kinetostatic run)")
    draw.add_argument("--guess", action="store_true",
                      help="draw the initial guess (x, y, fi as given, not assembled), the "
                           "constraints it does not meet in red")
    draw.add_argument("--ic", action="store_true",
                      help="mark each moving solid's instantaneous centre of rotation at T")
    anim = sub.add_parser(
        "animate", help="animate the model's kinematic or dynamic run (GIF; MP4 with ffmpeg)",
        description="An animation of the kinematic run (dynamic, for a model whose analysis "
                    "is dynamic) over the model's interval, with the paths of traced "
                    "points. A progress bar shows on a terminal. See docs/pictures.md.")
    anim.add_argument("model", help="model file (TOML)")
    anim.add_argument("-o", "--output", metavar="ANIM.gif",
                      help="animation file: .gif, or .mp4 when ffmpeg is installed "
                           "(default: <model>.gif)")
    anim.add_argument("--steps", type=int, metavar="N",
                      help="number of intervals: N + 1 frames (default: the model's steps, "
                           "at most 100)")
    anim.add_argument("--t-end", type=float, metavar="T", help="end of the motion [s]")
    anim.add_argument("--trace", nargs="+", metavar="SOLID.POINT", default=(),
                      help="points whose paths are drawn (coupler curves)")
    anim.add_argument("--fps", type=float, help="frames per second (default: real time, "
                                                 "2 to 30)")
    for sub_parser in sub.choices.values():     # --debug after the subcommand, too
        sub_parser.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                                help=argparse.SUPPRESS)


def _run(args) -> int:
    from .analyses import run
    from .results.writers import write
    sep = "\t" if args.sep in ("tab", "\\t") else args.sep
    model = checked_model(args, sep)             # nothing runs, nothing is written before
    backend = BACKENDS.get(args.backend or model.analysis.backend)
    # the backend's settings (an unknown name: run's model error names the known ones)
    solver = backend.create().Settings(verbose=1 if args.verbose else 0) if backend else None
    try:
        res = run(model, analysis=args.analysis, t_end=args.t_end, steps=args.steps,
                  outputs=run_outputs(args), solver=solver, backend=args.backend, angles=args.angles,
                  tolerance=args.tolerance)
    except SolverError as exc:
        if args.partial and args.output and exc.partial is not None:
            path = write(exc.partial, args.output, sep, args.decimal, args.bom)
            print(f"wrote the {len(exc.partial)} rows before the failure to {path}")
        raise
    for w in res.warnings:                       # those not issued as they arose
        _WARNINGS.say(w)
    table = res.select(args.outputs) if args.outputs and (args.plot or args.energy) else res
    from .results.extremes import extremes_path, extremes_table, write_extremes
    extremes = extremes_table(table)             # a clearance run's, else ""
    if args.output:
        path = write(table, args.output, sep, args.decimal, args.bom)
        print(f"wrote {len(table)} rows × {len(table.columns) + 1} columns to {path}")
        if table.checks():
            print("checks: " + "; ".join(table.checks()))
        if extremes:                             # beside the result
            print(f"wrote the extremes to {write_extremes(table, extremes_path(path))}")
    elif not args.at:
        print(table.summary(warnings=False))     # the warnings went to stderr
    if args.at:                                  # every variable at those times
        from .results.instant import kinds_of, report
        print(report(table, args.at, kinds_of(model), warnings=False))
    if extremes:
        print(extremes)
    code = _run_plot(args, res) if args.plot else 0
    return code or (_run_energy(args, model, res) if args.energy else 0)


def _run_energy(args, model, res) -> int:
    """``run --energy FIG``: the run's energy account (``analyses.energy``), plotted."""
    from .analyses.energy import account
    from .results.plot import plot
    acc = account(model, res)
    print(f"energy: largest |balance| {max(abs(acc['energy.balance'])):.2g} J")

    def make():
        plot(acc, None, args.energy)
        return args.energy
    return _picture("energy", make, args.debug)


def _run_plot(args, res) -> int:
    """``run --plot``: the plot of the run's variables, units from the run."""
    from pathlib import Path

    from .results.plot import plot
    out = args.plot_file or f"{Path(args.model).stem}_plot.png"

    def make():
        plot(res, args.plot, out, x=args.x)
        return out
    return _picture("plot", make, args.debug)


def _check(args) -> int:
    """What ``run`` checks before the numerics (the model, the settings, the plan of the run,
    the mobility), printed; exit 2 with ``run``'s message when the analysis needs every
    degree of freedom driven and one is not."""
    import numpy as np

    from .analyses.job import check_mobility, prepare
    from .analyses.rank import require_driven
    job = prepare(args.model, args.analysis, args.t_end, args.steps, backend=args.backend)
    mech = job.mech
    model = mech.model
    mob = check_mobility(job, mech.initial_q(), need_driven=False)
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
    steps = (len(job.times) - 1) // job.every
    at_start = ANALYSES[job.analysis].at_start
    print(f"analysis: {job.analysis}, t = 0 … {job.times[-1]:g} s in {steps} steps"
          if not at_start else f"analysis: {job.analysis}, t = 0")
    if job.every > 1:
        name, moved, unit = job.motion
        print(f"'{name}' moves {moved:.3g} {unit} per step: positions are solved in "
              f"{job.every} sub-steps per step")
    if model.encoding != "utf-8":
        print("the file is not UTF-8: it was read as Windows-1252")
    from .model.mistakes import input_warnings
    for problem in input_warnings(model):
        _WARNINGS.say(str(problem))
    print()
    width = max([len(e.name) for e in mech.elements] + [4])
    for e in mech.elements:
        anchors = ", ".join(str(a) for a in e.given_anchors())
        print(f"  {e.name:<{width}}  {e.type:<17} {anchors}")
    if ANALYSES[job.analysis].driven:
        sys.stdout.flush()
        require_driven(mech, mob, job.analysis)
    return 0


def _elements(args) -> int:
    from . import reference
    if not args.types:
        from .elements import ELEMENTS
        width = max(len(t) + len(c.alias) for t, c in ELEMENTS.items()) + 3
        for kind, cls in ELEMENTS.items():
            anchors = ", ".join(reference.anchor_meaning(cls, k) for k in range(len(cls.anchors)))
            print(f"{f'{kind} [{cls.alias}]':<{width}}  {anchors}: {cls.summary}")
        print("\ntime laws (law = ..., constants C = [C1, C2, C3, C4]):\n")
        print(reference.laws_markdown())
        print("pam2exu elements TYPE: keys, outputs and sign conventions of one type")
        return 0
    try:
        classes = [reference.element_class(name) for name in args.types]
    except KeyError as exc:
        raise ModelError(exc.args[0]) from None
    print("\n".join(reference.element_markdown(cls, anchor=False) for cls in classes), end="")
    return 0


def _compare(args) -> int:
    from .results.compare import CompareInputError, compare
    try:
        table = compare(args.result, args.reference, rtol=args.rtol, atol=args.atol,
                        columns=args.columns, names=args.names, method=args.interp,
                        wrap_angles=args.wrap_angles, angles=args.angles)
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


def _verify(args) -> int:
    found = verify(args.model, analysis=args.analysis, steps=args.steps,
                   t_end=args.t_end, backends=(BACKENDS_COMPARED[0], args.against))
    for res in (found.reference, found.result):
        for w in res.warnings:                   # those not issued as they arose
            _WARNINGS.say(w)
    print(found.to_markdown())
    return 0 if found.ok else 1


def _picture(kind: str, make, debug: bool = False) -> int:
    """Run ``make()``; bad input for a picture (PictureError, unreadable CSV) exits 2."""
    from .results.compare import CompareInputError
    from .results.plot import PictureError
    try:
        path = make()
    except (PictureError, CompareInputError) as exc:
        if debug:
            raise
        print(f"pam2exu: {kind}: {exc}", file=sys.stderr)
        return 2
    print(f"wrote {path}")
    return 0


def _plot(args) -> int:
    from pathlib import Path

    from .results.plot import plot
    out = args.output or Path(args.results).with_suffix(".png").name

    def make():
        plot(args.results, args.variables, out, model=args.model, x=args.x,
             angles=args.angles)
        return out
    return _picture("plot", make, args.debug)


def _draw(args) -> int:
    from pathlib import Path

    from .pictures import draw
    out = args.output or Path(args.model).with_suffix(".png").name

    def make():
        draw(args.model, t=args.t, path=out, vectors=args.vectors, guess=args.guess,
             ic=args.ic)
        return out
    return _picture("draw", make, args.debug)


def _animate(args) -> int:
    from pathlib import Path

    from .pictures import animate
    out = args.output or Path(args.model).with_suffix(".gif").name
    return _picture("animate", lambda: animate(args.model, out, steps=args.steps,
                                               t_end=args.t_end, trace=args.trace,
                                               fps=args.fps), args.debug)


def _export(args) -> int:
    from .export import export
    path = export(args.model, args.output, t_end=args.t_end, steps=args.steps,
                  forces=args.forces, analysis=args.analysis, tolerance=args.tolerance)
    print(f"wrote {path}; run it with: python {path} [OUT.csv]")
    return 0


_WARNINGS = Warnings()                    # the running command's (``main`` makes one each)


def main(argv=None) -> int:
    global _WARNINGS
    args = _parser().parse_args(argv)
    _WARNINGS = Warnings()
    with warnings.catch_warnings():
        warnings.simplefilter("always", UserWarning)    # each reaches show, which dedupes
        warnings.showwarning = _WARNINGS.show
        return _main(args)


def _main(args) -> int:
    try:
        return {"run": _run, "check": _check, "elements": _elements, "compare": _compare,
                "verify": _verify, "export": _export, "plot": _plot, "draw": _draw,
                "animate": _animate}[args.command](args)
    except BrokenPipeError:              # output piped into head & co.
        sys.stderr.close()
        return 0
    except Exception as exc:
        if args.debug:
            raise
        if isinstance(exc, ModelError):
            code, kind = 2, "model error"
        elif isinstance(exc, OutputError):
            code, kind = 2, "output error"
        elif isinstance(exc, UsageError):
            code, kind = 2, "command line"
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

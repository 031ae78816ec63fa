"""``pam2exu run``: run the model's analysis and print a summary, write the table (-o), print
the variables at given times (--at), plot them (--plot) or the energy account (--energy)."""
from __future__ import annotations

from ..console import analysis_options, checked_model, run_outputs
from ..errors import SolverError
from ..registry import ANALYSES, BACKENDS, DEFAULT_BACKEND, OPTIONS
from .pictures import picture


def add_parser(sub) -> None:
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
    for option in OPTIONS.values():              # the analysis options, as declared
        run.add_argument(f"--{option.name}", type=type(option.default),
                         choices=option.choices or None,
                         metavar=option.metavar, help=option.help)
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


def command(args, warnings) -> int:
    from ..analyses import run
    from ..results.writers import write
    sep = "\t" if args.sep in ("tab", "\\t") else args.sep
    model = checked_model(args, sep)             # nothing runs, nothing is written before
    backend = BACKENDS.get(args.backend or model.analysis.backend)
    # the backend's settings (an unknown name: run's model error names the known ones)
    solver = backend.create().Settings(verbose=1 if args.verbose else 0) if backend else None
    try:
        res = run(model, analysis=args.analysis, t_end=args.t_end, steps=args.steps,
                  outputs=run_outputs(args), solver=solver, backend=args.backend, angles=args.angles,
                  **analysis_options(args))
    except SolverError as exc:
        if args.partial and args.output and exc.partial is not None:
            path = write(exc.partial, args.output, sep, args.decimal, args.bom)
            print(f"wrote the {len(exc.partial)} rows before the failure to {path}")
        raise
    for w in res.warnings:                       # those not issued as they arose
        warnings.say(w)
    table = res.select(args.outputs) if args.outputs and (args.plot or args.energy) else res
    from ..results.extremes import extremes_path, extremes_table, write_extremes
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
        from ..results.instant import kinds_of, report
        print(report(table, args.at, kinds_of(model), warnings=False))
    if extremes:
        print(extremes)
    code = _plot(args, res) if args.plot else 0
    return code or (_energy(args, model, res) if args.energy else 0)


def _energy(args, model, res) -> int:
    """``run --energy FIG``: the run's energy account (``analyses.energy``), plotted."""
    from ..analyses.energy import account
    from ..results.plot import plot
    acc = account(model, res)
    print(f"energy: largest |balance| {max(abs(acc['energy.balance'])):.2g} J")

    def make():
        plot(acc, None, args.energy)
        return args.energy
    return picture("energy", make, args.debug)


def _plot(args, res) -> int:
    """``run --plot``: the plot of the run's variables, units from the run."""
    from pathlib import Path

    from ..results.plot import plot
    out = args.plot_file or f"{Path(args.model).stem}_plot.png"

    def make():
        plot(res, args.plot, out, x=args.x)
        return out
    return picture("plot", make, args.debug)

"""``pam2exu study``: run a study (docs/studies.md), print its summary, yield and errors,
write its per-variant table (-o), ``OUT.summary.csv`` (and ``OUT.series.*``) beside it, and
the pictures asked for (``--hist``, ``--band``, ``--scatter``, ``--tornado``) as ``OUT.<kind>.<names>.png``."""
from __future__ import annotations

import os
from pathlib import Path


def add_parser(sub) -> None:
    st = sub.add_parser(
        "study", help="run a study: one analysis for many variants of a model's values",
        description="Run the study file's analysis for every variant of its parameters, "
                    "print the summary over the variants, the yield and the variants in "
                    "error grouped by message; with -o write the per-variant table and "
                    "OUT.summary.csv beside it. Exit 0 when the study ran (even with "
                    "variants in error), 2 for bad input. See docs/studies.md.")
    st.add_argument("study", help="study file (TOML)")
    st.add_argument("-o", "--output", metavar="OUT.parquet",
                    help="the per-variant table: .parquet (pam2exu[parquet]) or .csv; the "
                         "summary goes to OUT.summary.csv")
    st.add_argument("--samples", type=int, metavar="N",
                    help="number of variants, instead of the study's (sampled methods)")
    st.add_argument("--workers", type=int, metavar="N",
                    help="local worker processes (default: one per core; 1: this process)")
    st.add_argument("--dask", metavar="ADDRESS",
                    help="run on the Dask cluster of this scheduler (host:port; "
                         "pam2exu[dask])")
    st.add_argument("--dask-local", type=int, metavar="N",
                    help="run on a Dask LocalCluster of N worker processes started for the "
                         "study (pam2exu[dask])")
    st.add_argument("--resume", action="store_true",
                    help="run only the chunks missing under OUT.parts/")
    st.add_argument("--hist", action="append", default=[], metavar="OUTPUT",
                    help="histogram of a reduced output (motor.Mz.absmax) with its "
                         "requirements: OUT.hist.OUTPUT.png (repeatable)")
    st.add_argument("--band", action="append", default=[], metavar="OUTPUT",
                    help="1/5/50/95/99 %% percentiles of an output's series (motor.Mz) over "
                         "t, needs series = true: OUT.band.OUTPUT.png (repeatable)")
    st.add_argument("--tornado", action="append", default=[], metavar="OUTPUT",
                    help="tornado of a reduced output's first-order sensitivities "
                         "∂y/∂p·σ_p at the nominal variant: OUT.tornado.OUTPUT.png "
                         "(repeatable)")
    st.add_argument("--scatter", action="append", default=[], nargs=2,
                    metavar=("OUTPUT", "PARAMETER"),
                    help="a reduced output against a parameter, a point per variant: "
                         "OUT.scatter.OUTPUT.vs.PARAMETER.png (repeatable)")


def command(args, warnings) -> int:
    from ..console import UsageError
    from ..studies.result import summary_path
    from ..studies.series import series_path
    from ..studies.execute import open_executor, warm, workers_of
    from ..studies.runner import checked, run_checked
    if args.workers is not None and args.workers < 1:
        raise UsageError(f"--workers must be ≥ 1, got {args.workers}")
    if args.resume and not args.output:
        raise UsageError("--resume needs -o OUT: the finished chunks are under OUT.parts/")
    if args.workers is not None and (args.dask or args.dask_local is not None):
        raise UsageError("--workers and --dask/--dask-local do not go together: give one")
    warm(args.workers, args.dask, args.dask_local)     # the workers' imports, meanwhile
    run_as, names, units, out = checked(args.study, args.output, args.resume, args.samples)
    pictures = planned_pictures(args, run_as, names)
    workers = args.dask_local or args.workers or os.cpu_count() or 1
    with open_executor(args.workers, args.dask, args.dask_local) as executor:
        result = run_checked(run_as, names, units, out, executor, args.resume,
                             workers_of(executor, workers), progress=True,
                             first_order=bool(args.tornado))
    print(result.report())
    if args.output:
        print(f"wrote {len(result)} {result.ROWS} to {args.output} and the summary to "
              f"{summary_path(args.output)}")
        if result.series is not None:
            print(f"wrote the series, {len(result.series['t'])} rows, to "
                  f"{series_path(args.output)}")
    from ..results.plot import save
    for draw, asked, path in pictures:
        ax = draw(result, *asked)
        print(f"wrote {save(ax.figure, path)}")
    return 0


def planned_pictures(args, study, names: list[str]) -> list[tuple]:
    """(drawing function, its names, image path) of every picture the options ask for,
    checked before any variant runs: an output the study does not reduce (or keep the
    series of), a parameter it does not vary, is a ``UsageError`` naming the option and the
    closest names. The images go beside -o (``OUT.hist.motor.Mz.absmax.png``), else
    beside the study file's name in this folder."""
    from ..console import UsageError
    from ..errors import PictureError
    from ..studies import plots
    from ..studies.series import series_outputs
    base = Path(args.output).with_suffix("") if args.output else Path(Path(args.study).stem)
    series = series_outputs(names) if study.series else None
    planned = []
    try:
        for output in args.hist:
            plots.check_reduced(output, names, "--hist")
            planned.append((plots.hist, (output,), plots.picture_path(base, "hist", output)))
        for output in args.band:
            plots.check_series(output, series, "--band", study.source)
            planned.append((plots.band, (output,), plots.picture_path(base, "band", output)))
        for output, parameter in args.scatter:
            plots.check_reduced(output, names, "--scatter")
            plots.check_parameter(parameter, study.names, "--scatter")
            planned.append((plots.scatter, (output, parameter),
                            plots.picture_path(base, "scatter", output, parameter)))
        for output in args.tornado:
            plots.check_reduced(output, names, "--tornado")
            planned.append((tornado, (output,), plots.picture_path(base, "tornado", output)))
        if study.method == "linear" and len(planned) > len(args.tornado):
            raise PictureError("a linear study has no variants to draw: --hist, --band and "
                               "--scatter need a sampled study (its --tornado draws the "
                               "sensitivities)")
    except PictureError as exc:
        raise UsageError(str(exc)) from None
    return planned


def tornado(result, output: str):
    """``result.tornado(output)``: the drawing function of ``--tornado``."""
    return result.tornado(output)

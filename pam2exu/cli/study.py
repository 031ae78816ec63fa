"""``pam2exu study``: run a study (docs/studies.md), print its summary, yield and errors,
write its per-variant table (-o) and ``OUT.summary.csv`` beside it."""
from __future__ import annotations

import os


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


def command(args, warnings) -> int:
    from ..console import UsageError
    from ..studies.result import summary_path
    from ..studies.execute import open_executor
    from ..studies.runner import checked, run_checked
    if args.workers is not None and args.workers < 1:
        raise UsageError(f"--workers must be ≥ 1, got {args.workers}")
    if args.resume and not args.output:
        raise UsageError("--resume needs -o OUT: the finished chunks are under OUT.parts/")
    if args.workers is not None and (args.dask or args.dask_local is not None):
        raise UsageError("--workers and --dask/--dask-local do not go together: give one")
    run_as, names, units, out = checked(args.study, args.output, args.resume, args.samples)
    workers = args.dask_local or args.workers or os.cpu_count() or 1
    with open_executor(args.workers, args.dask, args.dask_local) as executor:
        result = run_checked(run_as, names, units, out, executor, args.resume, workers,
                             progress=True)
    print(result.report())
    if args.output:
        print(f"wrote {len(result)} {result.ROWS} to {args.output} and the summary to "
              f"{summary_path(args.output)}")
    return 0

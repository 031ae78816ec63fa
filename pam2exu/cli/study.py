"""``pam2exu study``: run a study (docs/studies.md), print its summary, yield and errors,
write its per-variant table (-o) and ``OUT.summary.csv`` beside it."""
from __future__ import annotations


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
                    help="local worker processes (default 1: this process)")
    st.add_argument("--resume", action="store_true",
                    help="run only the chunks missing under OUT.parts/")


def command(args, warnings) -> int:
    from ..console import UsageError
    from ..studies.result import summary_path
    from ..studies.runner import study
    if args.workers is not None and args.workers < 1:
        raise UsageError(f"--workers must be ≥ 1, got {args.workers}")
    if args.resume and not args.output:
        raise UsageError("--resume needs -o OUT: the finished chunks are under OUT.parts/")
    result = study(args.study, out=args.output, resume=args.resume, samples=args.samples,
                   workers=args.workers)
    print(result.report())
    if args.output:
        print(f"wrote {len(result)} variants to {args.output} and the summary to "
              f"{summary_path(args.output)}")
    return 0

"""``pam2exu compare``: a result CSV against a reference CSV, variable by variable."""
from __future__ import annotations

import sys


def add_parser(sub) -> None:
    from ..results.compare import ATOL, RTOL
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


def command(args, warnings) -> int:
    from ..results.compare import CompareInputError, compare
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

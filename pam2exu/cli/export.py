"""``pam2exu export``: the model as a standalone Exudyn script (docs/export.md)."""
from __future__ import annotations

from ..registry import OPTIONS


def add_parser(sub) -> None:
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
    for option in OPTIONS.values():              # the analysis options, as declared
        exp.add_argument(f"--{option.name}", type=type(option.default),
                         choices=option.choices or None,
                         metavar=option.metavar, help=f"{option.brief} (default: the model's)")


def command(args, warnings) -> int:
    from ..console import analysis_options
    from ..export import export
    path = export(args.model, args.output, t_end=args.t_end, steps=args.steps,
                  forces=args.forces, analysis=args.analysis, **analysis_options(args))
    print(f"wrote {path}; run it with: python {path} [OUT.csv]")
    return 0

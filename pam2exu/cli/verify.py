"""``pam2exu verify``: the model's analysis on two backends, compared variable by variable."""
from __future__ import annotations

from ..registry import BACKENDS
from ..verify import BACKENDS_COMPARED, verify


def add_parser(sub) -> None:
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


def command(args, warnings) -> int:
    found = verify(args.model, analysis=args.analysis, steps=args.steps,
                   t_end=args.t_end, backends=(BACKENDS_COMPARED[0], args.against))
    for res in (found.reference, found.result):
        for w in res.warnings:                   # those not issued as they arose
            warnings.say(w)
    print(found.to_markdown())
    return 0 if found.ok else 1

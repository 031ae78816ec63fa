"""``pam2exu exam``: N variants of a model with checked answers, as a PDF and a Moodle quiz."""
from __future__ import annotations

import sys
from pathlib import Path

from ..console import UsageError
from ..exam import SEED, TOLERANCE, exam


def add_parser(sub) -> None:
    ex = sub.add_parser(
        "exam", help="exam variants of a model with checked answers (PDF, Moodle XML)",
        description="Draw N variants of the model (each --vary parameter uniform within "
                    "nominal ± TOL, rounded), compute every value asked (--ask OUTPUT@T), "
                    "check each variant on both backends (a variant they disagree on, or "
                    "that does not run, is replaced by the next draw), and write one PDF "
                    "page per variant and the solutions, and optionally a Moodle XML quiz. "
                    "See docs/teaching.md.")
    ex.add_argument("model", help="model file (TOML)")
    ex.add_argument("--variants", type=int, default=1, metavar="N",
                    help="how many variants (default 1)")
    ex.add_argument("--seed", type=int, default=SEED, metavar="S",
                    help=f"the seed of the draws (default {SEED}): the same command gives "
                         "the same exam")
    ex.add_argument("--vary", nargs="+", default=[], metavar="PARAM=±TOL",
                    help="what varies, as a study names it (coupler.B.x=±0.02)")
    ex.add_argument("--ask", nargs="+", required=True, metavar="OUTPUT@T",
                    help="the values asked: an output at a time (rocker.Dfi@0.1)")
    ex.add_argument("-o", "--output", required=True, metavar="EXAM.pdf",
                    help="the PDF: a page per variant, then the solutions")
    ex.add_argument("--moodle", metavar="EXAM.xml",
                    help="also a Moodle XML quiz, one numerical question per variant and value")
    ex.add_argument("--tolerance", type=float, default=TOLERANCE, metavar="REL",
                    help=f"the Moodle answers' relative tolerance (default {TOLERANCE:g})")


def command(args, warnings) -> int:
    for path, suffix, option in ((args.output, ".pdf", "-o"), (args.moodle, ".xml", "--moodle")):
        if path is not None and Path(path).suffix.lower() != suffix:
            raise UsageError(f"{option} {path}: the file must end in {suffix}")
        if path is not None and not Path(path).resolve().parent.is_dir():
            raise UsageError(f"{option} {path}: its folder does not exist")

    def progress(done, total):
        print(f"\rvariant {done} of {total} checked", end="" if done < total else "\n",
              file=sys.stderr, flush=True)

    found = exam(args.model, args.variants, args.ask, args.vary, seed=args.seed,
                 tolerance=args.tolerance, progress=progress if sys.stderr.isatty() else None)
    found.write_pdf(args.output)
    wrote = [f"{len(found.variants)} variants and their solutions to {args.output}"]
    if args.moodle:
        found.write_moodle(args.moodle)
        wrote.append(f"{len(found.variants) * len(found.questions)} questions to {args.moodle}")
    for k, why in found.replaced:
        print(f"draw {k} replaced: {why}")
    print(f"{found.analysis} analysis; wrote " + " and ".join(wrote))
    return 0

"""The ``pam2exu`` command: run and check PAM models, compare result files.

Exit codes: 0 success, 1 solver failure, 2 model error (or bad command line, options that
do not go together, or an output file that cannot be written as asked: an unknown suffix, a
missing optional library; ``run`` checks these before it runs anything).
``compare``: 0 every variable within the tolerance, 1 some outside, 2 bad input.
``verify``: 0 the two backends agree, 1 they differ or a run fails, 2 bad input.
``study``: 0 the study ran (even with variants in error), 2 bad input (nothing written).
``exam``: 0 the exam was written, 2 bad input or too few variants could be checked.
``plot``, ``draw``, ``animate``: 2 also for a picture that cannot be made as asked (an
unknown image format, no ffmpeg for .mp4, a variable that matches nothing).
Errors are printed to stderr as one paragraph; ``--debug`` shows the traceback.

Each command is a module of this package with its parser (``add_parser``) and its function
(``command(args, warnings) -> exit code``): ``run``, ``check``, ``elements``, ``compare``,
``verify``, ``export``, ``study``, ``exam``, ``classify``, and ``pictures`` for plot, draw and
animate.
"""
from __future__ import annotations

import argparse
import sys
import warnings

from ..console import UsageError, Warnings
from ..errors import ModelError, OutputError, Pam2ExuError, SolverError
from ..version import __version__
from . import check, classify, compare, elements, exam, export, pictures, run, study, verify

#: each command's function, ``f(args, warnings) -> exit code``
COMMANDS = {"run": run.command, "check": check.command, "elements": elements.command,
            "compare": compare.command, "verify": verify.command, "export": export.command,
            "plot": pictures.plot, "draw": pictures.draw, "animate": pictures.animate,
            "study": study.command, "exam": exam.command, "classify": classify.command}


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="pam2exu", description=
                                "Run PAM planar mechanism models on the Exudyn multibody library.")
    p.add_argument("--version", action="version", version=f"pam2exu {__version__}")
    p.add_argument("--debug", action="store_true", help="show tracebacks of errors")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for command in (run, check, classify, elements, compare, verify, export, study, exam):
        command.add_parser(sub)
    pictures.add_parsers(sub)
    for sub_parser in sub.choices.values():     # --debug after the subcommand, too
        sub_parser.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                                help=argparse.SUPPRESS)
    return p


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    said = Warnings()                   # the running command's warnings, each said once
    with warnings.catch_warnings():
        warnings.simplefilter("always", UserWarning)    # each reaches show, which dedupes
        warnings.showwarning = said.show
        return _main(args, said)


def _main(args, said: Warnings) -> int:
    try:
        return COMMANDS[args.command](args, said)
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

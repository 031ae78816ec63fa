"""What the command line checks before a run, and how it prints warnings.

``check_options`` refuses options that need one another (``--x`` without ``--plot``, the CSV
options without ``-o``, an image suffix that cannot be written) before the model is read;
``check_analysis_options`` and ``check_at`` those the run's analysis cannot use, before it
runs: nothing runs, nothing is written (``UsageError`` or ``ModelError``, exit 2).
``Warnings`` prints every warning of a command once, as one line ``pam2exu: warning: …``.
"""
from __future__ import annotations

import sys

from .errors import ModelError, Pam2ExuError, PictureError, Problem
from .registry import OPTIONS, analysis_type, analyses_reading


class UsageError(Pam2ExuError):
    """Options that do not go together, or one that needs another (exit 2, before the run)."""


def check_options(args) -> None:
    """UsageError for options that need one another (before the model is read)."""
    csv = [name for name, value, default in
           (("--sep", args.sep, ","), ("--decimal", args.decimal, "."), ("--bom", args.bom, False))
           if value != default]
    if csv and not args.output:
        raise UsageError(f"{' and '.join(csv)} {'is' if len(csv) == 1 else 'are'} for the CSV "
                         f"file of -o: give -o OUT.csv, or drop {' and '.join(csv)}")
    if args.partial and not args.output:
        raise UsageError("--partial writes the rows kept before a failure to the result file "
                         "of -o: give -o OUT.csv, or drop --partial")
    alone = [name for name, value in (("--x", args.x), ("--plot-file", args.plot_file))
             if value is not None]
    if alone and not args.plot:
        raise UsageError(f"{' and '.join(alone)} {'is' if len(alone) == 1 else 'are'} for "
                         f"--plot: give --plot VAR …, or drop {' and '.join(alone)}")
    from .results.plot import image_format
    for option, path in (("--energy", args.energy), ("--plot-file", args.plot_file)):
        try:
            if path is not None:
                image_format(path)
        except PictureError as exc:
            raise UsageError(f"{option}: {exc}") from None


def checked_model(args, sep: str):
    """``run``'s model, read after its options are checked and before anything runs: the
    options that need one another, the output file (a bad name or suffix), then the options
    the model's analysis does not use and the --at times outside its run."""
    from .model import load
    from .results.writers import check
    check_options(args)
    if args.output:
        check(args.output, sep, args.decimal, args.bom)
    model = load(args.model)
    check_analysis_options(args, model)
    if args.at:
        check_at(args, model)
    return model


def run_outputs(args) -> list[str] | None:
    """The columns ``run`` computes: --outputs, and with --plot or --energy also the plotted
    variables (and the x axis) and the energy account's (the default ones, "*", to which a
    plot may add opt-in ones such as coupler.P.x); --outputs then selects what is shown."""
    if not (args.plot or args.energy):
        return args.outputs
    return [*(["*"] if args.energy else []), *(args.outputs or ["*"]), *(args.plot or []),
            *([args.x] if args.x else [])]


def analysis_options(args) -> dict:
    """The analysis options (``registry.OPTIONS``) as the command line gives them
    (``--NAME``; None: the model's)."""
    return {name: getattr(args, name) for name in OPTIONS}


def check_analysis_options(args, model) -> None:
    """UsageError for analysis options (``--tolerance``, ``registry.OPTIONS``) the run's
    analysis does not read, ModelError for ``--energy`` of an analysis without rates and
    forces: before the run."""
    from .analyses.energy import require_rates
    name = args.analysis or model.analysis.type
    kind = analysis_type(name) if isinstance(name, str) else None
    if kind is None:
        return                                   # run reports the settings
    for option, value in analysis_options(args).items():
        if value is not None and option not in kind.options:
            known = ", ".join(analyses_reading(option))
            raise UsageError(f"--{option} is {OPTIONS[option].owner} ({known}); the "
                             f"{kind.name} analysis does not use it: drop --{option}")
    if args.energy:
        require_rates(kind.name, model.source)


def check_at(args, model) -> None:
    """ModelError (exit 2) for a ``--at`` time outside the run's interval, 0 … t_end (only 0
    for an analysis at t = 0)."""
    kind = analysis_type(args.analysis or model.analysis.type)
    end = args.t_end if args.t_end is not None else model.analysis.t_end
    if kind is None or not isinstance(end, (int, float)):
        return                                   # run reports the settings
    end = 0.0 if kind.at_start else float(end)
    bad = [t for t in args.at if not 0.0 <= t <= end]
    if bad:
        times = (f"the {kind.name} analysis solves t = 0 only" if kind.at_start else
                 f"give times in the run's interval, t = 0 … {end:g} s")
        raise ModelError(Problem("--at", f"t = {bad[0]:g} s is outside the run: {times}"),
                         model.source)


class Warnings:
    """The warnings of one command, each printed once on stderr as one line ``pam2exu:
    warning: …``: those issued (``warnings.warn``, through ``show``) and those a result
    carries (``say``). A text already said with a prefix (the model file's name) is not said
    again without it, nor the other way round."""

    def __init__(self):
        self.said: list[str] = []

    def say(self, text) -> None:
        text = " ".join(str(text).split())
        if any(text == old or old.endswith(": " + text) or text.endswith(": " + old)
               for old in self.said):
            return
        self.said.append(text)
        print(f"pam2exu: warning: {text}", file=sys.stderr)

    def show(self, message, category, filename, lineno, file=None, line=None) -> None:
        """``warnings.showwarning``: the message only (no source line)."""
        self.say(message)

"""``pam2exu plot``, ``draw`` and ``animate`` (docs/pictures.md), and how a command makes a
picture (``picture``: bad input for it exits 2)."""
from __future__ import annotations

import sys


def add_parsers(sub) -> None:
    """plot, draw and animate (see docs/pictures.md)."""
    plot = sub.add_parser(
        "plot", help="plot variables of a result CSV against t (PNG, SVG, PDF)",
        description="Plot variables of a result file against t, labelled with their PAM "
                    "names and units; variables of one unit share a panel. Exit 2 for bad "
                    "input. See docs/pictures.md.")
    plot.add_argument("results", help="result CSV (pam2exu run MODEL -o FILE.csv)")
    plot.add_argument("variables", nargs="+", metavar="VAR",
                      help="names or patterns: crank.fi, 'crank.*', '*.Fx' or a bare Fx")
    plot.add_argument("-o", "--output", metavar="FIG.png",
                      help="image file, format from the suffix (default: <results>.png)")
    plot.add_argument("--model", metavar="MODEL",
                      help="the model, for the units of f(t) and Df(t) (rad or m)")
    plot.add_argument("--x", metavar="VAR",
                      help="the x axis: a variable such as crank.fi (default t)")
    plot.add_argument("--angles", choices=("rad", "deg"),
                      help="show the angular variables in rad or deg (default: as the file "
                           "has them)")
    draw = sub.add_parser(
        "draw", help="draw the mechanism at a configuration (PNG, SVG, PDF)",
        description="Draw the solids and elements of a model: assembled at t = 0, or at "
                    "time T of a kinematic run (dynamic, for a model whose analysis is "
                    "dynamic). See docs/pictures.md.")
    draw.add_argument("model", help="model file (TOML)")
    draw.add_argument("--t", type=float, default=0.0, metavar="T",
                      help="time [s] (default 0: the assembly)")
    draw.add_argument("-o", "--output", metavar="FIG.png",
                      help="image file, format from the suffix (default: <model>.png)")
    draw.add_argument("--vectors", choices=("v", "a", "F"),
                      help="arrows to scale at T: v velocities or a accelerations of the "
                           "solids' points (kinematic run), F the joints' reaction forces "
                           "(kinetostatic run)")
    draw.add_argument("--guess", action="store_true",
                      help="draw the initial guess (x, y, fi as given, not assembled), the "
                           "constraints it does not meet in red")
    draw.add_argument("--ic", nargs="?", const=True, default=False, choices=("all",),
                      help="mark each moving solid's instantaneous centre of rotation at T; "
                           "--ic all: every centre I_ij, relative ones included, with the "
                           "Kennedy lines")
    draw.add_argument("--polygon", choices=("v", "a"),
                      help="the velocity (v) or acceleration (a) polygon at T beside the "
                           "mechanism, to scale with a scale bar (kinematic run)")
    draw.add_argument("--centrodes", metavar="SOLID",
                      help="the fixed and moving centrodes of SOLID over the model's run and "
                           "its inflection circle at T")
    anim = sub.add_parser(
        "animate", help="animate the model's kinematic or dynamic run (GIF; MP4 with ffmpeg)",
        description="An animation of the kinematic run (dynamic, for a model whose analysis "
                    "is dynamic) over the model's interval, with the paths of traced "
                    "points. A progress bar shows on a terminal. See docs/pictures.md.")
    anim.add_argument("model", help="model file (TOML)")
    anim.add_argument("-o", "--output", metavar="ANIM.gif",
                      help="animation file: .gif, or .mp4 when ffmpeg is installed "
                           "(default: <model>.gif)")
    anim.add_argument("--steps", type=int, metavar="N",
                      help="number of intervals: N + 1 frames (default: the model's steps, "
                           "at most 100)")
    anim.add_argument("--t-end", type=float, metavar="T", help="end of the motion [s]")
    anim.add_argument("--trace", nargs="+", metavar="SOLID.POINT", default=(),
                      help="points whose paths are drawn (coupler curves)")
    anim.add_argument("--fps", type=float, help="frames per second (default: real time, "
                                                 "2 to 30)")


def picture(kind: str, make, debug: bool = False) -> int:
    """Run ``make()``; bad input for a picture (PictureError, unreadable CSV) exits 2."""
    from ..results.compare import CompareInputError
    from ..results.plot import PictureError
    try:
        path = make()
    except (PictureError, CompareInputError) as exc:
        if debug:
            raise
        print(f"pam2exu: {kind}: {exc}", file=sys.stderr)
        return 2
    print(f"wrote {path}")
    return 0


def plot(args, warnings) -> int:
    from pathlib import Path

    from ..results.plot import plot
    out = args.output or Path(args.results).with_suffix(".png").name

    def make():
        plot(args.results, args.variables, out, model=args.model, x=args.x,
             angles=args.angles)
        return out
    return picture("plot", make, args.debug)


def draw(args, warnings) -> int:
    from pathlib import Path

    from ..pictures import draw
    out = args.output or Path(args.model).with_suffix(".png").name

    def make():
        draw(args.model, t=args.t, path=out, vectors=args.vectors, guess=args.guess,
             ic=args.ic, polygon=args.polygon, centrodes=args.centrodes)
        return out
    return picture("draw", make, args.debug)


def animate(args, warnings) -> int:
    from pathlib import Path

    from ..pictures import animate
    out = args.output or Path(args.model).with_suffix(".gif").name
    return picture("animate", lambda: animate(args.model, out, steps=args.steps,
                                              t_end=args.t_end, trace=args.trace,
                                              fps=args.fps), args.debug)

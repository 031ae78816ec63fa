"""Draw the figures of docs/teaching.md's four-bar lesson (and of the graphical methods'
sections of docs/teaching.md and docs/pictures.md) from the code.

    python docs/make_teaching.py            # (re)draw them into docs/img
    python docs/make_teaching.py OUT_DIR    # elsewhere

Each figure is what the command the page shows beside it draws (``FIGURES``: the file, the
command, and the same call in Python); the exam's page is the first page ``pam2exu exam``
writes for the page's command. tests/test_teaching.py checks that the page shows every
command and figure listed here, and draws one of them.

Docs tooling beside docs/make_api.py: pam2exu never imports it. Run from a clone, it puts the
repository root on ``sys.path``.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FOUR_BAR = "examples/four_bar.toml"

#: (file in docs/img, the command the page shows, draw()'s keywords for the same figure)
FIGURES = (
    ("lesson_velocity.png", f"pam2exu draw {FOUR_BAR} --t 0.1 --polygon v",
     dict(t=0.1, polygon="v")),
    ("four_bar_polygon.png", f"pam2exu draw {FOUR_BAR} --t 0.1 --polygon a",
     dict(t=0.1, polygon="a")),
    ("lesson_centres.png", f"pam2exu draw {FOUR_BAR} --t 0.1 --ic all",
     dict(t=0.1, ic="all")),
    ("four_bar_centrodes.png", f"pam2exu draw {FOUR_BAR} --t 0.6 --ic all --centrodes coupler",
     dict(t=0.6, ic="all", centrodes="coupler")),
)
#: the exam the lesson shows, as the page's command gives it
EXAM = dict(variants=2, asks=["rocker.Dfi@0.1", "coupler.P.v@0.25"],
            vary=["coupler.B.x=±0.02", "crank.A.x=±0.01"], seed=1)
EXAM_COMMAND = (f"pam2exu exam {FOUR_BAR} --variants 2 --seed 1 "
                "--vary coupler.B.x=±0.02 crank.A.x=±0.01 "
                "--ask rocker.Dfi@0.1 coupler.P.v@0.25 -o exam.pdf --moodle exam.xml")
EXAM_FIGURE = "lesson_exam.png"


def draw_figure(name: str, out: Path) -> Path:
    """Draw the figure ``name`` of ``FIGURES`` into the folder ``out``."""
    from pam2exu.pictures import draw
    keywords = {f: k for f, _, k in FIGURES}[name]
    path = out / name
    draw(ROOT / FOUR_BAR, path=path, **keywords)
    return path


def draw_exam_page(out: Path) -> Path:
    """The exam's first page (variant 1) as a PNG in ``out``."""
    from pam2exu.exam import exam
    from pam2exu.exam.pdf import page
    found = exam(ROOT / FOUR_BAR, EXAM["variants"], EXAM["asks"], EXAM["vary"],
                 seed=EXAM["seed"])
    path = out / EXAM_FIGURE
    page(found, found.variants[0], solution=False).savefig(path, dpi=80)
    return path


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", nargs="?", default=str(ROOT / "docs" / "img"))
    out = Path(parser.parse_args(argv).out)
    out.mkdir(parents=True, exist_ok=True)
    for name, _, _ in FIGURES:
        print(draw_figure(name, out))
    print(draw_exam_page(out))
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    sys.exit(main())

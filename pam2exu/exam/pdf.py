"""An exam as one PDF (matplotlib, no LaTeX): a page per variant (the drawing at the first
time asked, the data, the questions), then a page of solutions per variant (every answer,
and the drawing with its velocity polygon at the first time asked)."""
from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np

#: an A4 page [in]
PAGE = (8.27, 11.69)
#: characters per line of the page's text (monospace, 8.5 pt, inside the margins)
WIDTH = 96


def write(exam, path: Path) -> Path:
    """Write the exam's PDF to ``path`` (a temporary file, then renamed: never half-written)."""
    import matplotlib
    from matplotlib.backends.backend_pdf import PdfPages
    matplotlib.use("Agg", force=False)
    temporary = path.with_name(f".{path.name}.part")
    try:
        with PdfPages(temporary) as pdf:
            for variant in exam.variants:
                pdf.savefig(page(exam, variant, solution=False))
            for variant in exam.variants:
                pdf.savefig(page(exam, variant, solution=True))
        temporary.replace(path)
    finally:
        temporary.unlink(missing_ok=True)
    return path


def page(exam, variant, solution: bool):
    """One page of the exam (a matplotlib Figure, A4): the variant's questions, or with
    ``solution`` its answers and velocity polygon."""
    from matplotlib.figure import Figure
    from ..pictures import draw
    from . import data_lines
    fig = Figure(figsize=PAGE)
    first = min(q.t for q in exam.questions)
    head = "Solutions, variant" if solution else "Variant"
    fig.text(0.08, 0.96, f"{head} {variant.number} of {len(exam.variants)} — "
                         f"{Path(exam.source).name}", fontsize=14, weight="bold")
    picture = draw(variant.model, t=first, polygon="v" if solution else None)
    picture.canvas.draw()
    image = np.asarray(picture.canvas.buffer_rgba())
    ax = fig.add_axes((0.08, 0.47, 0.84, 0.47))
    ax.imshow(image)
    ax.set_axis_off()
    lines = data_lines(exam, variant)
    lines.append("")
    lines.append(f"{exam.analysis.capitalize()} analysis; the drawing is at t = {first:g} s.")
    lines.append("")
    for j, q in enumerate(exam.questions, start=1):
        unit = variant.units.get(q.output, "")
        if solution:
            lines.append(f"  {j}. {q}:  {variant.answers[q]:.6g} {unit}".rstrip())
        else:
            lines.append(f"  {j}. {q} = ____________ {unit}".rstrip())
    wrapped = [w for line in lines for w in textwrap.wrap(line, WIDTH, subsequent_indent=" " * 8)
               or [""]]
    fig.text(0.08, 0.43, "\n".join(wrapped), fontsize=8.5, va="top", family="monospace")
    return fig

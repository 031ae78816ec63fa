"""How a ``Model`` shows itself in a Jupyter notebook: the drawing of its notebook view.

The view itself (the head line, the solids, the elements) is the model's own
(``pam2exu.model.describe.html``, which ``Model._repr_html_`` returns); the drawing needs the
pictures and the analyses, above the model, so this module registers it there when the
package is imported (``describe.register_drawing``): the import points down. A ``Results``
table shows itself with ``results.writers.Exports._repr_html_``; an animation in a notebook
is ``pictures.animate(model, html=True)``. docs/getting-started.md links the example
notebook, examples/getting_started.ipynb.
"""
from __future__ import annotations

import base64
import html
import io

from .errors import Pam2ExuError
from .model import describe
from .pictures import draw

#: size of the drawing in a notebook [in] and its resolution [dots per inch]
SIZE, DPI = (6.4, 4.8), 80


def drawing_png(model) -> str:
    """The model drawn assembled at t = 0, as PNG base64 text (``pictures.draw``)."""
    fig = draw(model, size=SIZE, dpi=DPI)
    out = io.BytesIO()
    fig.savefig(out, format="png", dpi=DPI)
    return base64.b64encode(out.getvalue()).decode("ascii")


def drawing_html(model) -> str:
    """The drawing of a model's notebook view: an <img> of base64 PNG at t = 0, or, when the
    model cannot be drawn (a problem in it, an assembly that fails), the message instead."""
    e = html.escape
    try:
        return (f"<img alt='{e(model.name)} at t = 0' "
                f"src='data:image/png;base64,{drawing_png(model)}'/>")
    except Pam2ExuError as exc:
        return f"<p>no drawing: {e(str(exc))}</p>"


describe.register_drawing(drawing_html)

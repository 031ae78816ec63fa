"""How a ``Model`` shows itself in a Jupyter notebook: its solids and elements, and a drawing.

``Model._repr_html_`` calls ``model_html`` through the registry's lazy ``resolve`` (the model
package knows neither the analyses nor the pictures, which the drawing needs). A ``Results``
table shows itself with ``results.writers.Exports._repr_html_``; an animation in a notebook
is ``pictures.animate(model, html=True)``. docs/getting-started.md links the example
notebook, examples/getting_started.ipynb.
"""
from __future__ import annotations

import base64
import html
import io

from .errors import Pam2ExuError
from .pictures import draw

#: size of the drawing in a notebook [in] and its resolution [dots per inch]
SIZE, DPI = (6.4, 4.8), 80


def drawing_png(model) -> str:
    """The model drawn assembled at t = 0, as PNG base64 text (``pictures.draw``)."""
    fig = draw(model, size=SIZE, dpi=DPI)
    out = io.BytesIO()
    fig.savefig(out, format="png", dpi=DPI)
    return base64.b64encode(out.getvalue()).decode("ascii")


def model_html(model) -> str:
    """The notebook view of a model: its head line, the solids, the elements (name, type,
    anchors) and a drawing at t = 0, an <img> of base64 PNG; when the model cannot be drawn
    (a problem in it, an assembly that fails), the message instead of the drawing."""
    e = html.escape
    a = model.analysis
    head = (f"model '{e(model.name)}'" + (f" ({e(str(model.source))})" if model.source else "")
            + f": {len(model.solids)} solids, {len(model.elements)} elements, gravity "
              f"{model.gravity:g} m/s², {e(a.type)} analysis, t = 0 … {a.t_end:g} s in "
              f"{a.steps} steps")
    rows = ["<tr><th>name</th><th>type</th><th>anchors (a solid: its points)</th></tr>"]
    for s in model.solids:
        points = ", ".join(s.points)
        rows.append(f"<tr><td>{e(s.name)}</td><td>solid</td><td>{e(points)}</td></tr>")
    for el in model.elements:
        anchors = ", ".join(str(getattr(el, f"anc{k + 1}")) for k in range(len(el.anchors)))
        rows.append(f"<tr><td>{e(el.name)}</td><td>{e(el.type)}</td><td>{e(anchors)}</td></tr>")
    try:
        picture = (f"<img alt='{e(model.name)} at t = 0' "
                   f"src='data:image/png;base64,{drawing_png(model)}'/>")
    except Pam2ExuError as exc:
        picture = f"<p>no drawing: {e(str(exc))}</p>"
    return (f"<div class='pam2exu-model'><p><b>{head}</b></p>"
            f"<table>{''.join(rows)}</table>\n{picture}</div>")

"""How a model describes itself: the one line ``print(model)`` shows, and its notebook view
(``Model._repr_html_``: the solids, the elements and a drawing).

The drawing needs the pictures and the analyses, which the model layer does not know: the
notebook module (``pam2exu.notebook``, imported with the package) registers it here with
``register_drawing``, so the arrow points down (notebook → model).
"""
from __future__ import annotations

import html as _html
from typing import Callable

from .. import registry

#: what draws a model for its notebook view, ``f(model) -> str`` (HTML): the last one
#: registered (``register_drawing``); none, no drawing
_DRAWINGS: list[Callable] = []


def register_drawing(drawing: Callable) -> None:
    """Use ``drawing(model) -> str`` (an HTML fragment) as the drawing of the notebook view."""
    _DRAWINGS.append(drawing)


def plural(count: int, noun: str) -> str:
    """'1 solid', '4 solids'."""
    return f"{count} {noun}{'s' * (count != 1)}"


def one_line(model) -> str:
    """``<Model 'four-bar' from examples/four_bar.toml: 4 solids, 6 elements; kinematic
    analysis, t = 0 … 1 s in 200 steps>``: the variations counted when there are any, no
    interval for an analysis at t = 0 only, a setting that is not a number shown as given
    (never raises, even for a model with problems)."""
    a = model.analysis
    kind = registry.analysis_type(a.type) if isinstance(a.type, str) else None
    if kind is not None and kind.at_start:
        interval = ""
    elif isinstance(a.t_end, (int, float)) and isinstance(a.steps, int):
        interval = f", t = 0 … {a.t_end:g} s in {a.steps} steps"
    else:
        interval = f", t_end = {a.t_end!r}, steps = {a.steps!r}"
    source = f" from {model.source}" if model.source else ""
    counts = ", ".join([plural(len(model.solids), "solid"),
                        plural(len(model.elements), "element"),
                        *([plural(len(model.variations), "variation")]
                          if model.variations else [])])
    return f"<Model {model.name!r}{source}: {counts}; {a.type} analysis{interval}>"


def html(model) -> str:
    """The notebook view of a model: its head line, the solids, the elements (name, type,
    anchors) and the registered drawing (``register_drawing``), if any."""
    e = _html.escape
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
        anchors = ", ".join(str(a) for a in el.given_anchors())
        rows.append(f"<tr><td>{e(el.name)}</td><td>{e(el.type)}</td><td>{e(anchors)}</td></tr>")
    picture = _DRAWINGS[-1](model) if _DRAWINGS else ""
    return (f"<div class='pam2exu-model'><p><b>{head}</b></p>"
            f"<table>{''.join(rows)}</table>\n{picture}</div>")

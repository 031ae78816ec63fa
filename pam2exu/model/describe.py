"""What ``print(model)`` shows: one line with the model's name, file, counts and analysis."""
from __future__ import annotations

from .. import registry


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

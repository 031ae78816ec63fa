"""What a valid model says that is allowed but most likely a mistake: ``run`` warns of it
(``InputWarning``), ``pam2exu check`` prints it; one list, so both say the same."""
from __future__ import annotations

from ..errors import Problem
from .angles import angle_warnings


def input_warnings(model) -> list[Problem]:
    """The likely mistakes of a valid model, each with its solid or element, in model order.

    The angles of a radians model above a full turn (``angles.angle_warnings``), then the
    elements' own (``Element.mistakes``: a transition law given fewer than four constants).

    Parameters
    ----------
    model : Model
        A valid model.

    Returns
    -------
    list of Problem
        Each with ``where`` and ``message``; empty when nothing looks wrong.
    """
    return angle_warnings(model) + [Problem(el.where, m) for el in model.elements
                                    for m in el.mistakes()]

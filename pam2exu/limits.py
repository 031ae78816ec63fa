"""The ranges a model's numbers and names must lie in, and the most work one run may take.

Wider than any mechanism a course or a design office models, narrower than where floating
point goes wrong (a length of 1e300 m squared is infinite; a time step of 5e-324 s is zero).
A value outside its range is a model error that names the entry and the key; the limits
are listed in docs/model-format.md ("Ranges").
"""
from __future__ import annotations

import math
import numbers
import unicodedata

from .errors import echo

#: |coordinate| of any point, origin, centre of mass or line [m]; also spring free
#: lengths and the distances of linear actuators' laws
LENGTH = 1e6
#: |angle| of a solid's guess, a line, a torsional spring's C3, a transmission's C, and of
#: angular actuators' laws over the run [rad] (160,000 turns)
ANGLE = 1e7
#: |value| of every other number: masses [kg], inertias [kg·m²], gravity [m/s²], forces [N],
#: moments [N·m], stiffnesses, dampings, law constants, gear ratios
VALUE = 1e12
#: the analysis interval t_end [s]
T_END = (1e-9, 1e9)
#: characters of a solid's or element's name
NAME = 100
#: characters of the model's name (titles of pictures and tables show it whole)
MODEL_NAME = 200
#: position solves of one run: steps × the sub-steps that keep the motion per solve small
#: (so also the most steps a run may have: results have steps + 1 rows)
SOLVE_STEPS = 2_000_000
#: bytes of the arrays one run holds (coordinates, rates and result columns)
MEMORY = 4 * 2**30


def is_number(v) -> bool:
    """A finite real number (not a bool), one a float can hold (not an integer of 400 digits)."""
    if type(v) is float:                 # the usual case, without the ABC's check
        return math.isfinite(v)
    if not isinstance(v, numbers.Real) or isinstance(v, bool):
        return False
    try:
        return math.isfinite(v)
    except OverflowError:
        return False



def out_of_range(value, limit: float) -> bool:
    """A finite number whose magnitude exceeds ``limit``."""
    return is_number(value) and abs(value) > limit


def one_form(value):
    """A string in one Unicode form (NFC); any other value unchanged.

    A name typed with a combining accent (``a`` + U+0301) is then the same as ``á``
    everywhere: anchors, result columns, CSV files (which read back in this form).

    Examples
    --------
    >>> one_form("a\u0301") == "\u00e1", one_form(3)
    (True, 3)
    """
    return unicodedata.normalize("NFC", value) if isinstance(value, str) else value


def name_problem(name) -> str | None:
    """What is wrong with a solid's or element's name, or None.

    A name is a non-empty string of at most ``NAME`` printable characters without '.'
    (which separates a solid from its point or line in anchors and result columns).

    Examples
    --------
    >>> name_problem("crank"), name_problem("Força 2")
    (None, None)
    >>> name_problem("a.b")
    "name 'a.b' contains '.', which separates a solid from its point or line: rename it"
    """
    if not isinstance(name, str) or not name.strip():
        return f"name must be a non-empty string, got {echo(name)}"
    if len(name) > NAME:
        return f"name is {len(name)} characters long: at most {NAME} are allowed"
    if not name.isprintable():
        return (f"name {name!r} contains a control character (a line break, a tab…): "
                "use printable characters only")
    if name != name.strip():
        return f"name {name!r} starts or ends with blanks: remove them"
    if "." in name:
        return (f"name '{name}' contains '.', which separates a solid from its point or "
                "line: rename it")
    return None


def shown(name, width: int = 40) -> str:
    """A name as messages show it: cut to ``width`` characters (a name of any type)."""
    text = str(name)
    return text if len(text) <= width else text[:width - 3] + "..."

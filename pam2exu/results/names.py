"""Column names in pam2exu's spelling: PAM's own spellings, names maps, lists of names, and
the columns a list of patterns chooses (``select_columns``).

A column is ``<name>.<variable>``. Files exported from PAM spell some variables otherwise
(``Forca``, ``f``, ``Df``); ``SPELLINGS`` brings them to pam2exu's (``Força``, ``f(t)``,
``Df(t)``). A names map (PAM name → pam2exu name, ``reading.read_names``) renames whole
columns or the solid or element before the dot. ``compare``, ``read_csv``, ``plot`` and
``units.unit_of`` all spell names this way.
"""
from __future__ import annotations

import fnmatch
import functools

from ..errors import ModelError, Problem, closest
from ..limits import one_form
from ..points import OPT_IN

# PAM spellings of variable names -> pam2exu's (applied to the part after the last dot)
SPELLINGS = {"Forca": "Força", "f": "f(t)", "Df": "Df(t)"}
_SHOWN = 8                  # names listed in a note before "… and n more"


def canonical_name(column: str, names: dict[str, str] | None = None) -> str:
    """pam2exu's name of a column: the names map (whole column, else the part before the dot),
    then ``SPELLINGS`` on the part after the dot (Forca → Força, f → f(t), Df → Df(t)).

    Examples
    --------
    >>> canonical_name("motor.Forca"), canonical_name("Solid1.fi", {"Solid1": "crank"})
    ('motor.Força', 'crank.fi')
    """
    return canonical(column, names or {})[0]


def spelled(pattern: str) -> str:
    """A name or pattern in pam2exu's spelling: ``canonical_name`` with a dot, else the bare
    variable through ``SPELLINGS`` (what ``--outputs``, ``plot`` and ``compare`` accept).

    Examples
    --------
    >>> spelled("Forca"), spelled("*.Forca"), spelled("motor.f"), spelled("crank.*")
    ('Força', '*.Força', 'motor.f(t)', 'crank.*')
    """
    return canonical_name(pattern) if "." in pattern else SPELLINGS.get(clean(pattern), pattern)


def canonical(column: str, names: dict[str, str]) -> tuple[str, tuple[str, ...]]:
    """``canonical_name`` and the map keys it used."""
    col = clean(column)
    if col in names:
        return names[col], (col,)
    owner, dot, variable = col.rpartition(".")
    if not dot:
        return col, ()
    used = (owner,) if owner in names else ()
    full = f"{names.get(owner, owner)}.{SPELLINGS.get(variable, variable)}"
    if full in names:
        return names[full], used + (full,)
    return full, used


def clean(name: str) -> str:
    """Strip blanks and use one Unicode form (NFC, ``limits.one_form``, the form of the
    model's names), so 'Força' typed either way matches."""
    return one_form(name.strip())


def spellings() -> str:
    """'Forca → Força, f → f(t), Df → Df(t)'."""
    return ", ".join(f"{k} → {v}" for k, v in SPELLINGS.items())


def listing(names, n: int = _SHOWN) -> str:
    """'a, b, c' with at most n names, then '… and k more'."""
    names = list(names)
    more = f", … and {len(names) - n} more" if len(names) > n else ""
    return ", ".join(names[:n]) + more


def selects(pattern: str, column: str) -> bool:
    """Whether an ``outputs`` pattern (a dot already added to a bare name) chooses a column.

    Shell-style (``fnmatch``, case-sensitive), with two rules for the opt-in columns
    (``points.is_opt_in``): a pattern matches only columns of as many parts (a point's
    ``solid.point.variable`` only a pattern of three: ``coupler.P.*``, ``*.P.x``, ``*.*.v``),
    and chooses an instantaneous centre or a transmission angle (``points.OPT_IN``) only
    when its variable part starts with a letter, not a wildcard (``*.IC*``, ``crank.ICx``,
    ``transmission_angle``; not ``crank.*`` nor ``*x``).

    Examples
    --------
    >>> [selects(p, "crank.A.x") for p in ("crank.*", "crank.A.*", "*.*.x")]
    [False, True, True]
    >>> [selects(p, "crank.ICx") for p in ("crank.*", "*.*x", "*.IC*", "*.ICx")]
    [False, False, True, True]
    """
    if pattern.count(".") != column.count(".") or not fnmatch.fnmatchcase(column, pattern):
        return False
    variable = column.rpartition(".")[2]
    return variable not in OPT_IN or pattern.rpartition(".")[2][:1] not in ("*", "?", "[", "")


def _pattern(p: str) -> str:
    """A bare variable name ``Fx`` means every ``*.Fx``."""
    return p if "." in p or p == "t" else f"*.{p}"


def select_columns(columns: list[str], patterns) -> list[str]:
    """Columns matching any pattern: full names, ``solid.*``, ``*.Fx`` or a bare ``Fx``.

    Patterns are shell-style (``fnmatch``, case-sensitive); one without a dot means that
    variable of every solid and element (``Fx`` is ``*.Fx``). ``t`` matches nothing and is
    no error (it is always in a table). PAM's spellings are read as pam2exu's
    (``names.spelled``: ``Forca`` is ``Força``, ``motor.f`` is ``motor.f(t)``).

    Parameters
    ----------
    columns : list of str
        The column names to choose from.
    patterns : str or list of str
        The patterns; None chooses every column.

    Returns
    -------
    list of str
        The columns matching any pattern, in the order of ``columns``.

    Raises
    ------
    ModelError
        A pattern matches no column (one problem per pattern, with the nearest name).

    Examples
    --------
    >>> select_columns(["crank.fi", "crank.Dfi", "B.Fx", "C.Fx"], ["Fx", "crank.fi"])
    ['crank.fi', 'B.Fx', 'C.Fx']
    >>> select_columns(["crank.fi"], "crank.fy")
    Traceback (most recent call last):
    ...
    pam2exu.errors.ModelError: outputs: 'crank.fy' matches no variable...(did you mean 'crank.fi'?)
    """
    if patterns is None:
        return list(columns)
    if isinstance(patterns, str):
        patterns = [patterns]
    chosen, problems = _chosen(tuple(columns), tuple(patterns))
    if problems:
        raise ModelError(list(problems))
    return list(chosen)


@functools.lru_cache(maxsize=256)
def _chosen(columns: tuple[str, ...], patterns: tuple[str, ...]):
    """(the columns chosen, in order; the problems of patterns that match none): what
    ``select_columns`` decides, once per columns and patterns (a study's variants ask the
    same question thousands of times)."""
    chosen, problems = set(), []
    for p in map(spelled, patterns):
        hits = [c for c in columns if selects(_pattern(p), c)]
        if not hits and p != "t":
            problems.append(Problem("outputs", f"'{p}' matches no variable of this analysis"
                                               f"{closest(p, columns)}"))
        chosen.update(hits)
    return tuple(c for c in columns if c in chosen), tuple(problems)

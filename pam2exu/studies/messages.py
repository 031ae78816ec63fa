"""The variants' errors and warnings grouped by kind, for the printed report.

Two variants that fail the same way rarely say it in the same words: the time, the residuals
and the lengths differ, and so may the order in which a loop or the violated joints are
listed. A message's kind (``kind``) is its head with its numbers masked (``masked``): the
class, then the message's first line up to the end of its first phrase, the first ': ' after
a part that holds a space (a file name alone does not end it). So every

    SolverError: the mechanism cannot be assembled at t = 0 s: the loop coupler –B– …

is of the kind 'SolverError: the mechanism cannot be assembled at t = … s', whatever loop and
residuals follow, and a variant's model error (a normal distribution's negative mass) of the
kind of its place, "ModelError: four_bar.toml: [[solid]] #… 'coupler'".

A group (``Group``) shows its head with each number's range over its variants
(``t = [0.375 … 0.4] s``; one value when they agree), its variants, and the first variant's
whole first line.
"""
from __future__ import annotations

import re
from dataclasses import dataclass

#: a number in a message: not inside a name (body1, O2, C2, B.F1, pytest-291), an exponent
#: allowed
NUMBER = re.compile(r"(?<![\w.-])-?(?:\d+(?:\.\d+)?|\.\d+)(?:[eE][-+]?\d+)?(?!\w|\.\d)")
#: what a masked number becomes in a kind
MASK = "…"
#: the per-variant column of a chunk that holds its warnings (``runner.run_variants``), one
#: line each ('<class>: <first line of the message>'); not a column of the table's files
WARNINGS = "warnings"
#: the groups the printed report lists (the others are counted)
GROUPS_SHOWN = 10
#: the samples a group lists
SAMPLES_SHOWN = 10


@dataclass(frozen=True)
class Group:
    """Variants whose messages are of one kind.

    Attributes
    ----------
    kind : str
        The head with its numbers masked (``kind``): what the variants share.
    head : str
        The head with each number's range over the variants (``[low … high]``), or its
        value when they agree.
    samples : tuple of int
        The variants, in variant order (each once).
    example : str
        The first variant's message, its first line.
    """

    kind: str
    head: str
    samples: tuple
    example: str


def masked(text: str) -> str:
    """``text`` with every number replaced by ``MASK``.

    Examples
    --------
    >>> masked("between t = 0.375 s and t = 0.4 s (steps 8 and 9 of 20), 'O4' by 1.1e-3")
    "between t = … s and t = … s (steps … and … of …), 'O4' by …"
    """
    return NUMBER.sub(MASK, text)


def head(text: str) -> str:
    """The head of a message '<class>: <message>': the class, then the message's first line
    up to its first ': ' after a part that holds a space.

    Examples
    --------
    >>> head("SolverError: the mechanism cannot be assembled at t = 0 s: the loop A –B– C")
    'SolverError: the mechanism cannot be assembled at t = 0 s'
    >>> head("ModelError: f.toml: [[solid]] #3 'coupler': mass is negative (-1.0): it must be ≥ 0")
    "ModelError: f.toml: [[solid]] #3 'coupler'"
    """
    line = text.split("\n", 1)[0]
    cls, colon, rest = line.partition(": ")
    parts = []
    for part in rest.split(": ") if colon else []:
        parts.append(part)
        if " " in part:
            break
    return ": ".join([cls, *parts])


def kind(text: str) -> str:
    """The kind of a message: its head with its numbers masked (``head``, ``masked``)."""
    return masked(head(text))


def ranged(heads: list[str]) -> str:
    """The first of ``heads`` (of one kind) with each number shown as its range over them,
    '[low … high]', or as it is where they all agree."""
    values = [[float(x) for x in NUMBER.findall(h)] for h in heads]
    if any(len(v) != len(values[0]) for v in values):   # a '…' of its own where one has a number
        return masked(heads[0])
    pieces = NUMBER.split(heads[0])
    texts = NUMBER.findall(heads[0])
    out = [pieces[0]]
    for k, text in enumerate(texts):
        column = [v[k] for v in values]
        low, high = min(column), max(column)
        out.append(text if low == high else f"[{low:.6g} … {high:.6g}]")
        out.append(pieces[k + 1])
    return "".join(out)


def group(messages) -> list[Group]:
    """The messages grouped by kind, the most frequent kind first (ties: the one met first).

    Parameters
    ----------
    messages : iterable of (int, str)
        (sample, message) pairs in variant order; a sample with two messages of one kind
        counts once in its group.

    Examples
    --------
    >>> found = group([(1, "E: at t = 0.5 s: x"), (2, "F: y"), (4, "E: at t = 0.25 s: z")])
    >>> [(g.head, g.samples, g.example) for g in found]
    [('E: at t = [0.25 … 0.5] s', (1, 4), 'E: at t = 0.5 s: x'), ('F: y', (2,), 'F: y')]
    """
    found: dict[str, list] = {}
    for sample, message in messages:
        key = kind(message)
        heads, samples, first = found.setdefault(key, ([], [], message.split("\n", 1)[0]))
        if not samples or samples[-1] != int(sample):
            heads.append(head(message))
            samples.append(int(sample))
    groups = [Group(key, ranged(heads), tuple(samples), first)
              for key, (heads, samples, first) in found.items()]
    return sorted(groups, key=lambda g: -len(g.samples))


def warning_groups(warned, samples) -> list[Group]:
    """The variants' warnings grouped by kind (``group``): ``warned`` holds each variant's
    warnings, one line each ('' for none), ``samples`` the variants' indices."""
    return group((i, line) for text, i in zip(warned, samples)
                 for line in str(text).split("\n") if line)


def report_lines(groups: list[Group], noun: str = "errors") -> list[str]:
    """The report's lines of ``groups``: per group 'N × head', its samples (the first
    ``SAMPLES_SHOWN``), and the first variant's message when it says more than the head;
    at most ``GROUPS_SHOWN`` groups, the others counted."""
    lines = []
    for g in groups[:GROUPS_SHOWN]:
        shown = ", ".join(map(str, g.samples[:SAMPLES_SHOWN])) + \
            (", …" if len(g.samples) > SAMPLES_SHOWN else "")
        lines.append(f"  {len(g.samples)} × {g.head}")
        lines.append(f"      samples {shown}")
        if g.example != g.head:
            lines.append(f"      sample {g.samples[0]}: {g.example}")
    if len(groups) > GROUPS_SHOWN:
        lines.append(f"  … and {len(groups) - GROUPS_SHOWN} other kinds of {noun}")
    return lines

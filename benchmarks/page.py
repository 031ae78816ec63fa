"""docs/performance.md's sections written by scripts of their own, kept through a full
regeneration.

A script that writes one section alone (dynamics.py, studies.py, clearance_speed.py,
natural_speed.py, predictor.py, targets.py) puts it between two marker lines,
``<!-- NAME: written by benchmarks/SCRIPT ... -->`` and ``<!-- end of NAME -->``
(``dynamics.replace_section``); a section written by hand from measurements it names
between ``<!-- NAME: written by hand ... -->`` and the same end line. ``keep_sections``
gives a regenerated page every such section of the old page that the new one does not
write itself, unchanged and where it was: before the first heading or marker line that
followed it on the old page and is on the new one, or at the end.
"""
from __future__ import annotations

import re
from pathlib import Path

#: one separately written section (by a script or by hand): its first marker line, its
#: lines, its end marker line
SECTION = re.compile(r"^<!-- (?P<name>[^:\n]+): written by (?:benchmarks/|hand)[^\n]*-->$"
                     r".*?^<!-- end of (?P=name) -->$", re.M | re.S)
#: a line a kept section may be put before: a heading, or a section's first marker line
ANCHOR = re.compile(r"^(#{1,3} |<!-- (?!end of ))")


def sections(text: str) -> dict[str, re.Match]:
    """The separately written sections of a page, by name, in the page's order."""
    return {m["name"]: m for m in SECTION.finditer(text)}


def keep_sections(old: str, new: str) -> str:
    """``new`` with every separately written section of ``old`` that ``new`` lacks, each
    before the first heading or marker line after it in ``old`` that is a line of ``new``
    (after the others kept before the same line, in ``old``'s order), else at the end."""
    own = sections(new)
    new_lines = set(new.splitlines())
    before: dict[str | None, list[str]] = {}
    for name, m in sections(old).items():
        if name in own:
            continue
        anchor = next((line for line in old[m.end():].splitlines()
                       if ANCHOR.match(line) and line in new_lines), None)
        before.setdefault(anchor, []).append(m.group(0))
    lines = new.rstrip("\n").split("\n")
    out = []
    for line in lines:
        if line in before:
            for block in before.pop(line):
                out += [block, ""]
        out.append(line)
    text = "\n".join(out)
    for blocks in before.values():          # no anchor on the new page: at the end
        for block in blocks:
            text += "\n\n" + block
    return text + "\n"


def write_page(page: Path, text: str) -> None:
    """Write a regenerated page, keeping the old page's separately written sections."""
    old = page.read_text(encoding="utf-8") if page.exists() else ""
    page.write_text(keep_sections(old, text), encoding="utf-8")

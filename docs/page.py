"""What the page generators share (docs/make_api.py, docs/make_natural.py): write a page, or
with ``--check`` tell whether the page on disk is what the code gives."""
from __future__ import annotations

import sys
from pathlib import Path


def write_or_check(output: Path, text: str, check: bool, shown: str, stale: str,
                   command: str) -> int:
    """Write ``text`` to ``output`` (0), or with ``check`` compare it with the file: 0 when
    equal, else 1 with the first differing line on stderr. ``shown``: how messages name
    the page; ``stale``: what a stale page is ("it is not what the docstrings give");
    ``command``: the command that regenerates it."""
    if check:
        old = output.read_text(encoding="utf-8") if output.exists() else None
        if old == text:
            print(f"{shown} is up to date")
            return 0
        if old is None:
            where = "it does not exist"
        else:
            a, b = old.splitlines(), text.splitlines()
            line = next((k for k, (x, y) in enumerate(zip(a, b)) if x != y), min(len(a), len(b)))
            where = f"first difference at line {line + 1}"
        print(f"{shown} is stale ({where}): {stale}. Run: {command}", file=sys.stderr)
        return 1
    output.write_text(text, encoding="utf-8")
    print(f"wrote {shown} ({len(text.splitlines())} lines)")
    return 0

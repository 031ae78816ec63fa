"""The element reference, written from the element declarations so it cannot drift.

Every table here is read from the classes in ``pam2exu.elements`` (their keys, anchors,
parameters, outputs and reporting frames), from the solid outputs and analysis levels of
``pam2exu.analyses``, and from the time laws of ``pam2exu.laws``. It feeds three places:

- ``pam2exu elements [TYPE ...]`` on the command line;
- the generated regions of ``docs/model-format.md`` and ``docs/glossary.md``, between
  ``<!-- BEGIN generated: NAME -->`` and ``<!-- END generated: NAME -->``;
- ``python -m pam2exu.reference [--check] PAGE ...`` rewrites (or checks) those regions.
"""
from __future__ import annotations

import argparse
import dataclasses
import inspect
import re
import sys
from pathlib import Path

from .elements import ALIASES, ELEMENTS, FORCE, Element
from .elements.base import Param
from .errors import closest
from .laws import LAW_ALIASES, LAWS
from .model.solid import SOLID_OUTPUTS
from .registry import analyses_giving

_ANCHOR_FORMS = {
    "solid": "a solid name",
    "point": '`"solid.point"`, or a solid name for its origin',
    "line": '`"solid.line"`, or a solid name for its local x axis',
}


def element_class(name: str) -> type[Element]:
    """The element class of a type name or a Catalan alias (KeyError with the known names)."""
    kind = ALIASES.get(name, name)
    if kind not in ELEMENTS:
        known = ", ".join(ELEMENTS)
        raise KeyError(f"unknown element type '{name}'{closest(name, [*ELEMENTS, *ALIASES])}; "
                       f"known types: {known} "
                       f"(Catalan names: {', '.join(ALIASES)})")
    return ELEMENTS[kind]


def anchor_meaning(cls: type[Element], k: int) -> str:
    """What anchor k (0-based) names, e.g. 'line of solid 1 (the guide)'."""
    kind = cls.anchors[k]
    owner = "the solid" if len(cls.anchors) == 1 else f"solid {k + 1}"
    text = owner if kind == "solid" else f"{kind} of {owner}"
    role = cls.roles[k] if k < len(cls.roles) else ""
    return f"{text} ({role})" if role else text


def _default(cls: type[Element], key: str) -> str:
    param = cls.params[key]
    if param.required:
        return "required"
    field = next((f for f in dataclasses.fields(cls) if f.name == key), None)
    value = None if field is None else field.default
    if value is None:
        return "–"
    if isinstance(value, bool):
        return f"`{str(value).lower()}`"          # as TOML writes it
    if isinstance(value, tuple):
        if all(v == 0 for v in value):
            return "zeros"
        value = list(value)
    return f"`{value!r}`".replace("'", '"')


def _what_to_write(param: Param) -> str:
    """A key's meaning, then the values it takes (``Param.values``), each as TOML writes it:
    a law's names with their Catalan aliases, a choice's choices."""
    if param.kind == "law":
        aliases = {law: alias for alias, law in LAW_ALIASES.items()}
        return param.meaning + ": " + ", ".join(
            f'`"{n}"`' + (f' (or `"{aliases[n]}"`)' if n in aliases else "") for n in LAWS)
    if param.values():
        return param.meaning + ": " + " or ".join(f'`"{c}"`' for c in param.values())
    return param.meaning


def _analyses(level: str, owner: str = "element") -> str:
    """The analyses giving a variable of ``level`` (``registry.analyses_giving``)."""
    return ", ".join(analyses_giving(level, owner))


def _first_line(function) -> str:
    return (inspect.getdoc(function) or "").splitlines()[0]


def reported_at(cls: type[Element]) -> str:
    """Where and in which basis a constraint element's reaction is reported, in words,
    to follow "reported" ('at the joint, global basis')."""
    text = _first_line(cls.report_frame).rstrip(".")
    return text[:1].lower() + text[1:]


def _table(header: tuple[str, ...], rows) -> list[str]:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return lines


def _sentence(text: str) -> str:
    """``text`` as a sentence: a leading word capitalised (not a formula's symbol, 'fi2'),
    a full stop at the end."""
    word = text.split(" ", 1)[0]
    return (text[:1].upper() + text[1:] if word.isalpha() else text) + "."


def element_markdown(cls: type[Element], level: int = 3, anchor: bool = True) -> str:
    """One element's section: what it does, its keys, its equations and its outputs
    (``anchor``: with an HTML anchor named after the type, for links within a page)."""
    alias = f" [`{cls.alias}`]" if cls.alias != cls.type else ""
    lines = [f'<a id="{cls.type}"></a>', ""] if anchor else []
    lines += [f"{'#' * level} `{cls.type}`{alias}", "", _sentence(cls.summary), ""]
    if cls.extension:
        lines += [f"An extension of the format ({cls.extension}), not one of PAM's types.", ""]
    or_alias = f' (or `"{cls.alias}"`)' if cls.alias != cls.type else ""
    keys = [("type", f'`"{cls.type}"`{or_alias}', "required"),
            ("name", "unique name", f"`{cls.type}<n>`")]
    for k in range(len(cls.anchors)):
        keys.append((f"anc{k + 1}", f"{anchor_meaning(cls, k)}: {_ANCHOR_FORMS[cls.anchors[k]]}",
                     "required"))
    for key, param in cls.params.items():
        keys.append((key, _what_to_write(param), _default(cls, key)))
    lines += _table(("key", "what to write", "default"),
                    ((f"`{k}`", m, d) for k, m, d in keys))
    lines.append("")
    if cls.equations:
        equation = _first_line(cls.constraint).rstrip(".")
        plural = "s" if cls.equations > 1 else ""
        lines += [f"Constraint: {cls.equations} equation{plural}, {equation}.", ""]
    else:
        lines += ["A force element: it adds no constraint equation.", ""]
    if cls.outputs:
        lines += _table(("output", "unit", "given by", "meaning"),
                        ((f"`<name>.{v.name}`", v.unit, _analyses(v.level), v.meaning)
                         for v in cls.outputs))
        lines.append("")
    if cls.wrench:
        lines += [f"Reaction reported: {reported_at(cls)}.", ""]
    return "\n".join(lines)


def elements_markdown() -> str:
    """Every element type, in the contract's order, with a summary table first."""
    rows = []
    for cls in ELEMENTS.values():
        anchors = [anchor_meaning(cls, k) for k in range(2)] if len(cls.anchors) == 2 else \
            [anchor_meaning(cls, 0) if cls.anchors else "–", "–"]
        rows.append((f"[`{cls.type}`](#{cls.type}) [`{cls.alias}`]", *anchors,
                     ", ".join(f"`{k}`" for k, p in cls.params.items() if not p.extension)
                     or "–", cls.summary))
    lines = _table(("type [alias]", "anc1", "anc2", "other keys", "constraint or action"), rows)
    lines.append("")
    return "\n".join(lines) + "\n" + "\n".join(element_markdown(cls) for cls in ELEMENTS.values())


def laws_markdown() -> str:
    """The time laws: name, Catalan alias, f(t) as the law function's docstring states it."""
    aliases = {law: alias for alias, law in LAW_ALIASES.items()}
    rows = []
    for name, form in LAWS.items():
        alias = f" [`{aliases[name]}`]" if name in aliases else ""
        formula = _first_line(form.function).rstrip(".")
        rows.append((f"`{name}`{alias}", formula, "C1 < C2" if form.interval else "–"))
    return "\n".join(_table(("law", "f(t)", "needs"), rows)) + "\n"


def outputs_markdown() -> str:
    """Every output variable: owner, PAM name, unit, which analyses give it, meaning."""
    rows = [("solid", f"`{v.name}`", v.unit, _analyses(v.level, "solid"), v.meaning)
            for v in SOLID_OUTPUTS]
    for cls in ELEMENTS.values():
        rows += [(f"[`{cls.type}`](#{cls.type})", f"`{v.name}`", v.unit,
                  _analyses(v.level), v.meaning) for v in cls.outputs]
        rows += [(f"[`{cls.type}`](#{cls.type}), `clearance = true`", f"`{v.name}`", v.unit,
                  _analyses(v.level), v.meaning)
                 for v in cls.clearance_parameters + cls.clearance_derived]
    return "\n".join(_table(("owner", "variable", "unit", "given by", "meaning"), rows)) + "\n"


def reactions_markdown() -> str:
    """One entry per element type with force outputs: its sketch, point, basis and signs."""
    lines = []
    for cls in ELEMENTS.values():
        forces = [v for v in cls.outputs if v.level == FORCE]
        if not forces and (cls.equations or cls.outputs):
            continue
        lines += [f'<a id="{cls.type}"></a>', "", f"### `{cls.type}`", "",
                  f"![free-body sketch of {cls.type}](img/fbd_{cls.type}.png)", ""]
        if cls.wrench:
            lines += [f"Reported {reported_at(cls)}.", ""]
        lines += [f"- `{v.name}` [{v.unit}]: {v.meaning}" for v in forces]
        if not forces:         # an applied load: its constants are inputs, not outputs
            lines += ["An input, not an output: " + "; ".join(
                f"`{key}`: {param.meaning}" for key, param in cls.params.items()) + "."]
        lines.append("")
    return "\n".join(lines)


#: generated region name -> its text
REGIONS = {"elements": elements_markdown, "laws": laws_markdown,
           "outputs": outputs_markdown, "reactions": reactions_markdown}

_REGION = re.compile(r"(<!-- BEGIN generated: (\w+) -->\n)(.*?)(<!-- END generated: \2 -->)",
                     re.S)


def refresh(text: str) -> str:
    """``text`` with every generated region written anew."""
    def body(match):
        name = match.group(2)
        if name not in REGIONS:
            raise KeyError(f"unknown generated region '{name}'; known: {', '.join(REGIONS)}")
        return match.group(1) + "\n" + REGIONS[name]().rstrip("\n") + "\n\n" + match.group(4)
    return _REGION.sub(body, text)


def regions(text: str) -> list[str]:
    """The names of the generated regions in ``text``."""
    return [m.group(2) for m in _REGION.finditer(text)]


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m pam2exu.reference",
                                description="Rewrite the generated regions of reference pages.")
    p.add_argument("pages", nargs="+", type=Path)
    p.add_argument("--check", action="store_true",
                   help="exit 1 when a page is stale instead of rewriting it")
    args = p.parse_args(argv)
    stale = []
    for page in args.pages:
        old = page.read_text(encoding="utf-8")
        new = refresh(old)
        if new != old:
            stale.append(page)
            if not args.check:
                page.write_text(new, encoding="utf-8")
    if args.check and stale:
        print("stale: " + ", ".join(map(str, stale)) + "; run python -m pam2exu.reference "
              + " ".join(map(str, args.pages)), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())

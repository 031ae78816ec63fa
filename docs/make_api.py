"""Write docs/api.md, the reference of pam2exu's Python API, from the docstrings.

    python docs/make_api.py            # (re)write docs/api.md
    python docs/make_api.py --check    # exit 1 when docs/api.md differs from what it writes

The docstrings are numpydoc: a summary, a description, then sections (``Parameters``,
``Returns``, ``Raises``, ``Examples``, …) headed by a line of dashes. Each public object gets
a section: its signature, then the docstring as Markdown (parameter lists as tables, examples
as ``pycon`` blocks, which docs tests do not execute). The element classes are described by
their declarations (type, anchors, keys, outputs; ``element_docstring``). The output depends
only on the code: no dates, no paths, no addresses. Standard library and pam2exu only.
"""
from __future__ import annotations

import argparse
import importlib
import inspect
import re
import sys
import types
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
for path in (ROOT, ROOT / "docs"):     # run from a clone without installing; docs/page.py
    if str(path) not in sys.path:
        sys.path.insert(0, str(path))

import pam2exu
from page import write_or_check  # noqa: E402  (docs/page.py)
from pam2exu.elements import ACCELERATION, ELEMENTS, FORCE, POSITION, VELOCITY

OUTPUT = ROOT / "docs" / "api.md"

#: (title, introduction, [(module, name), …]) in the order of the page
SECTIONS: list[tuple[str, str, list[tuple[str, str]]]] = [
    ("Running an analysis",
     ("Load or build a model, run one of PAM's four analyses or an extension (clearance, "
      "equilibrium, dynamic), get a `Results` table; `energy` gives the energy account of a "
      "kinetostatic or dynamic run."),
     [("pam2exu", "run"), ("pam2exu.analyses", "run"), ("pam2exu", "energy")]),
    ("Models",
     ("A model is solids, elements and analysis settings. `load` and `loads` read the TOML "
      "format of [model-format.md](model-format.md); `Model` builds the same in Python."),
     [("pam2exu", "load"), ("pam2exu", "loads"), ("pam2exu", "Model"), ("pam2exu", "Solid"),
      ("pam2exu.model", "Analysis"), ("pam2exu.model", "Mechanism"),
      ("pam2exu.model", "Variation"), ("pam2exu.model", "ramped_cosine")]),
    ("Element types",
     ("The ten PAM element types, one class each, made by `Model.add(\"<type>\", …)` or "
      "directly (`m.add(pam2exu.Revolute(name=\"A\", anc1=\"crank.A\", anc2=\"rod.A\"))`). "
      "Their keys are those of an `[[element]]` table. An output variable is a column "
      "`<element>.<variable>` of the results of the analyses that provide its level: "
      "position — every analysis (assembly: solids only); velocity and acceleration — "
      "kinematic, kinetostatic; force — quasi_static, kinetostatic. Sign conventions and "
      "reporting frames: [model-format.md](model-format.md), [analyses.md](analyses.md)."),
     [("pam2exu", "ELEMENTS"),
      *[("pam2exu", cls.__name__) for cls in ELEMENTS.values()]]),
    ("Results",
     "Every analysis returns a `Results` table; `read_csv` reads one back from a file.",
     [("pam2exu", "Results"), ("pam2exu.results", "RunInfo"), ("pam2exu", "read_csv"),
      ("pam2exu.results", "select_columns"), ("pam2exu.results.units", "unit_of")]),
    ("Comparing results",
     ("`compare` checks a result against a reference, variable by variable; the user guide "
      "is [compare.md](compare.md)."),
     [("pam2exu", "compare"), ("pam2exu", "Comparison"),
      ("pam2exu.results", "VariableComparison"), ("pam2exu.results", "read_names")]),
    ("Verifying a model on two backends",
     ("`verify` runs one analysis on two backends (two formulations of the constraints) and "
      "compares them within a tolerance derived from the solvers' tolerances and the "
      "condition number; the user guide is [verify.md](verify.md)."),
     [("pam2exu", "verify"), ("pam2exu", "Verification"), ("pam2exu.verify", "Rule"),
      ("pam2exu.verify", "agreement")]),
    ("Exporting to Exudyn",
     "A standalone Exudyn script of a model; the user guide is [export.md](export.md).",
     [("pam2exu", "export"), ("pam2exu.export", "script")]),
    ("Studies",
     ("One analysis of one model run for many variants of its values (tolerances, sweeps); "
      "the user guide is [studies.md](studies.md)."),
     [("pam2exu", "study"), ("pam2exu.studies.result", "StudyResult"),
      ("pam2exu.studies", "load_study")]),
    ("Pictures",
     ("Plots of variables against time, drawings and animations of the mechanism. Figures "
      "use matplotlib's Agg canvas (no window); the user guide is [pictures.md](pictures.md)."),
     [("pam2exu", "plot"), ("pam2exu", "draw"),
      ("pam2exu", "animate"), ("pam2exu.pictures", "pose"),
      ("pam2exu.pictures", "configurations")]),
    ("Time laws",
     "The laws f(t) the actuators follow (`law` and `C` of an actuator).",
     [("pam2exu", "Law"), ("pam2exu.laws", "law_names")]),
    ("Errors",
     ("Every error pam2exu raises on purpose is a `Pam2ExuError`; its message is meant for "
      "the user as it is. Command-line exit codes: 2 for `ModelError` (and "
      "`CompareInputError`, `PictureError`, `OutputError`), 1 for the others."),
     [("pam2exu", "Pam2ExuError"), ("pam2exu", "ModelError"), ("pam2exu", "MobilityError"),
      ("pam2exu", "SolverError"), ("pam2exu", "TranslationError"), ("pam2exu.errors", "Problem"),
      ("pam2exu", "CompareInputError"), ("pam2exu", "PictureError"),
      ("pam2exu", "OutputError")]),
    ("Warnings",
     ("Issued with `warnings.warn` at the caller's line and kept in `Results.warnings`; "
      "filter them with the `warnings` module."),
     [("pam2exu", "RedundancyWarning"), ("pam2exu", "ConsistencyWarning"),
      ("pam2exu", "ConditionWarning"), ("pam2exu", "VariationWarning"),
      ("pam2exu", "InputWarning")]),
]

#: descriptions of data objects (they have no docstring of their own)
DATA = {
    ("pam2exu", "ELEMENTS"): (
        "dict[str, type[Element]]",
        ("Type name → element class, in the order of the table below: the only registry of "
         "element types (``Model.add``, ``load``). ``pam2exu.elements.ALIASES`` maps PAM's "
         "Catalan type names to these.")),
}

#: numpydoc sections rendered as tables: section -> column titles (name, type, description)
TABLES = {
    "Parameters": ("Parameter", "Type", "Description"),
    "Other Parameters": ("Parameter", "Type", "Description"),
    "Attributes": ("Attribute", "Type", "Description"),
    "Returns": ("Name", "Type", "Description"),
    "Yields": ("Name", "Type", "Description"),
    "Raises": ("Exception", None, "When"),
    "Warns": ("Warning", None, "When"),
}
SECTION_NAMES = (*TABLES, "Examples", "Notes", "See Also", "References")
#: dunder methods documented as members (the others are described in the class docstring)
DUNDERS = ("__call__",)
#: signatures longer than this are written one parameter a line
WIDTH = 92

_ANCHORS = {
    "solid": 'a solid: ``"<solid>"``',
    "point": 'a point: ``"<solid>.<point>"`` (a bare ``"<solid>"``: its origin)',
    "line": 'a line: ``"<solid>.<line>"`` (a bare ``"<solid>"``: its local x axis)',
}
_KINDS = {"constants": "list of float", "number": "float", "law": "str", "solid": "str",
          "choice": "str", "boolean": "bool"}
_LEVELS = {POSITION: "position", VELOCITY: "velocity", ACCELERATION: "acceleration",
           FORCE: "force"}


# ---- objects --------------------------------------------------------------------------------

def resolve(module: str, name: str):
    """The object ``name`` of ``module`` (``sys.modules``' module, not a same-named attribute)."""
    return getattr(importlib.import_module(module), name)


def entries() -> list[tuple[str, str, object]]:
    """(module, name, object) of every documented object, in the order of the page."""
    return [(m, n, resolve(m, n)) for _, _, items in SECTIONS for m, n in items]


def missing_from_page() -> list[str]:
    """Names of ``pam2exu.__all__`` that no section documents (must be empty)."""
    shown = {id(obj) for _, _, obj in entries()}
    return [n for n in pam2exu.__all__ if id(getattr(pam2exu, n)) not in shown]


def is_element(obj) -> bool:
    return isinstance(obj, type) and obj in ELEMENTS.values()


#: base classes whose methods are documented as their subclass's own (``Results``' other
#: forms live in pam2exu/results/writers.py, its values at one time in results/instant.py)
MIXINS = ("Exports", "Instants")


def members(cls) -> list[tuple[str, object]]:
    """(name, attribute) of the public methods and properties a class defines, in source order
    (then those of its ``MIXINS`` bases)."""
    out = []
    own = dict(vars(cls))
    for base in cls.__mro__[1:]:
        if base.__name__ in MIXINS:
            own.update({k: v for k, v in vars(base).items() if k not in own})
    for name, attr in own.items():
        if name.startswith("_") and name not in DUNDERS:
            continue
        if isinstance(attr, (staticmethod, classmethod)):
            attr = attr.__func__
        if isinstance(attr, property) or inspect.isfunction(attr):
            out.append((name, attr))
    return out


def alias_of(cls, name: str, attr) -> str | None:
    """The name of an earlier member that is the same function (``add_element = add``)."""
    for other, value in vars(cls).items():
        if other == name:
            return None
        if value is attr:
            return other
    return None


def element_docstring(cls) -> str:
    """A numpydoc docstring of an element class, from its declarations.

    Parameters: name, one row per anchor, one per key of ``params``, and every other
    argument of the class's signature (a key the type does not take says so).
    """
    params = inspect.signature(cls).parameters
    anchors = {f"anc{k + 1}": kind for k, kind in enumerate(cls.anchors)}
    lines = [inspect.getdoc(cls) or "", "",
             f"Type ``{cls.type}`` (PAM: ``{cls.alias}``): {cls.summary}.", "",
             "Parameters", "----------"]
    for name, p in params.items():
        if name == "name":
            lines += ["name : str, optional",
                      ("    Unique name among the solids and elements; default "
                       "``<type><n>`` (``Model.add``).")]
        elif name in anchors:
            lines += [f"{name} : str", f"    Anchor {name[-1]}, {_ANCHORS[anchors[name]]}."]
        elif name in cls.params:
            spec = cls.params[name]
            kind = _KINDS.get(spec.kind, spec.kind)
            if spec.kind == "constants":
                kind += f" (at most {spec.size})"
            if spec.values():
                kind += ", one of " + ", ".join(repr(c) for c in spec.values())
            default = "" if spec.required or p.default is None else \
                f" Default ``{_default(p.default)}``."
            law = next((v for v in cls.outputs if v.name == "f(t)"), None)
            if name == "C" and "law" in cls.params and law is not None:
                default += f" Units: see ``Law``, with [u] = [{law.unit}]."
            lines += [f"{name} : {kind}{'' if spec.required else ', optional'}",
                      (f"    {spec.meaning[:1].upper()}{spec.meaning[1:]}."
                       f"{' Required.' if spec.required else default}")]
        elif name == "position":
            lines += ["position : int, optional",
                      ("    1-based position in the model file's ``[[element]]`` array, for "
                       "messages (set by the loader, or by ``Model.add``).")]
        elif name.startswith("anc"):
            lines += [f"{name} : None",
                      (f"    Not taken by a ``{cls.type}`` (it has {len(anchors)} anchor"
                       f"{'s' if len(anchors) != 1 else ''}): leave it out.")]
        # any other argument stays undocumented: tests/test_api_docs.py reports it
    return "\n".join(lines)


def docstring(obj, module: str = "", name: str = "") -> str:
    """The (numpydoc) docstring the page renders for an object."""
    if is_element(obj):
        return element_docstring(obj)
    if (module, name) in DATA:
        return DATA[module, name][1]
    return inspect.getdoc(obj) or ""


# ---- signatures -----------------------------------------------------------------------------

def _default(value) -> str:
    """A default value as written in a signature, the same on every machine."""
    if isinstance(value, types.ModuleType):
        return value.__name__
    if isinstance(value, (types.FunctionType, type)):
        return value.__qualname__
    return repr(value)


def _annotation(a) -> str:
    """An annotation as written (``from __future__ import annotations``: a string)."""
    if not isinstance(a, str):
        return inspect.formatannotation(a)
    return a[1:-1] if len(a) > 1 and a[0] == a[-1] and a[0] in "'\"" else a


def signature(obj, title: str, method: bool = False) -> str:
    """``title(params) -> return`` (wrapped one parameter a line when long); '' if none."""
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        return f"{title}(*args)" if isinstance(obj, type) else ""
    parts, star = [], False
    for p in sig.parameters.values():
        if method and p.name in ("self", "cls") and not parts:
            continue
        if p.kind is p.KEYWORD_ONLY and not star:
            parts.append("*")
        star = star or p.kind in (p.KEYWORD_ONLY, p.VAR_POSITIONAL)
        if p.kind is p.VAR_POSITIONAL:
            text = f"*{p.name}"
        elif p.kind is p.VAR_KEYWORD:
            text = f"**{p.name}"
        else:
            text = p.name
        if p.annotation is not p.empty:
            text += f": {_annotation(p.annotation)}"
        if p.default is not p.empty:
            text += (" = " if p.annotation is not p.empty else "=") + _default(p.default)
        parts.append(text)
    ret = ""
    if sig.return_annotation is not sig.empty and not isinstance(obj, type):
        ret = f" -> {_annotation(sig.return_annotation)}"
    one = f"{title}({', '.join(parts)}){ret}"
    if len(one) <= WIDTH:
        return one
    return f"{title}(\n" + "".join(f"    {p},\n" for p in parts) + f"){ret}"


# ---- numpydoc -> Markdown -------------------------------------------------------------------

def split_sections(doc: str) -> tuple[list[str], list[tuple[str, list[str]]]]:
    """(description lines, [(section title, body lines), …]) of a numpydoc docstring."""
    lines = doc.splitlines()
    head, sections, current = [], [], None
    k = 0
    while k < len(lines):
        line = lines[k]
        nxt = lines[k + 1] if k + 1 < len(lines) else ""
        if (line.strip() in SECTION_NAMES and nxt.strip()
                and set(nxt.strip()) == {"-"} and not line.startswith(" ")):
            current = (line.strip(), [])
            sections.append(current)
            k += 2
            continue
        (current[1] if current else head).append(line)
        k += 1
    return head, sections


def parse_entries(body: list[str]) -> list[tuple[str, str, list[str]]]:
    """(name, type, description lines) of the entries of a Parameters-like section."""
    out: list[tuple[str, str, list[str]]] = []
    for line in body:
        if line.strip() and not line.startswith(" "):
            name, _, kind = line.partition(" : ")
            out.append((name.strip(), kind.strip(), []))
        elif out:
            out[-1][2].append(line.strip())
    return out


def _code(text: str) -> str:
    """RST ``literals`` as Markdown `code`; '<' outside code escaped (no HTML tags)."""
    parts = re.split(r"(``.+?``|`[^`]+`)", text)
    out = []
    for k, part in enumerate(parts):
        if k % 2:
            out.append(f"`{part.strip('`')}`")
        else:
            out.append(part.replace("<", "&lt;"))
    return "".join(out)


def paragraphs(lines: list[str]) -> list[list[str]]:
    """Blocks of lines separated by blank lines."""
    out: list[list[str]] = [[]]
    for line in lines:
        if line.strip():
            out[-1].append(line)
        elif out[-1]:
            out.append([])
    return [p for p in out if p]


def text(lines: list[str]) -> str:
    """Description text as Markdown: paragraphs, ``- `` lists, ``>>>`` examples."""
    blocks = []
    for para in paragraphs(lines):
        if para[0].lstrip().startswith(">>>"):
            blocks.append(examples(para))
        elif para[0].lstrip().startswith("- "):
            items: list[str] = []
            for line in para:
                if line.lstrip().startswith("- "):
                    items.append(line.strip()[2:])
                else:
                    items[-1] += " " + line.strip()
            blocks.append("\n".join(f"- {_code(i)}" for i in items))
        else:
            blocks.append(_code(" ".join(line.strip() for line in para)))
    return "\n\n".join(blocks)


def _cell(lines: list[str]) -> str:
    """Description lines as one table cell: paragraphs joined by <br>, '|' escaped."""
    paras = [" ".join(line.strip() for line in p) for p in paragraphs(lines)]
    return "<br>".join(_code(p) for p in paras).replace("|", "\\|")


def _names(name: str) -> str:
    return ", ".join(f"`{n.strip()}`" for n in name.split(","))


def table(title: str, body: list[str]) -> str:
    """A Parameters-like section as a Markdown table."""
    found = parse_entries(body)
    first, second, third = TABLES[title]
    if title in ("Returns", "Yields") and not any(kind for _, kind, _ in found):
        # type-only entries ("Results" then its description)
        rows = [f"| {n.replace('|', chr(92) + '|')} | {_cell(d)} |" for n, _, d in found]
        return "\n".join(["| Type | Description |", "|---|---|", *rows])
    if second is None:
        rows = [f"| {_names(n)} | {_cell(d)} |" for n, _, d in found]
        return "\n".join([f"| {first} | {third} |", "|---|---|", *rows])
    rows = [f"| {_names(n)} | {_code(k).replace('|', chr(92) + '|')} | {_cell(d)} |"
            for n, k, d in found]
    return "\n".join([f"| {first} | {second} | {third} |", "|---|---|---|", *rows])


def examples(body: list[str]) -> str:
    """An Examples section: doctest lines as ``pycon`` blocks (no doctest directives),
    prose between them as paragraphs."""
    out, block, prose = [], [], []

    def flush_block():
        while block and not block[-1].strip():
            block.pop()
        if block:
            out.append("```pycon\n" + "\n".join(block) + "\n```")
        block.clear()

    in_example = False
    for line in body + [""]:
        stripped = line.strip()
        if stripped.startswith((">>>", "...")) and (stripped.startswith(">>>") or in_example):
            if prose:
                out.append(text(prose))
                prose.clear()
            in_example = True
            block.append(re.sub(r"\s*# doctest:.*$", "", line.rstrip()))
        elif in_example and stripped:
            block.append("" if stripped == "<BLANKLINE>" else line.rstrip())
        elif in_example:
            in_example = False
            block.append("")
        else:
            if block and stripped:
                flush_block()
            prose.append(line)
    flush_block()
    if any(p.strip() for p in prose):
        out.append(text(prose))
    return "\n\n".join(out)


def see_also(body: list[str]) -> str:
    items = []
    for line in body:
        if line.strip() and not line.startswith(" "):
            name, _, what = line.partition(" : ")
            items.append(f"- `{name.strip()}`" + (f": {_code(what.strip())}" if what else ""))
        elif line.strip() and items:
            items[-1] += " " + _code(line.strip())
    return "\n".join(items)


def render_doc(doc: str, level: int) -> str:
    """A numpydoc docstring as Markdown; section titles are bold lines."""
    head, sections = split_sections(doc)
    blocks = [text(head)] if any(line.strip() for line in head) else []
    for title, body in sections:
        if title in TABLES:
            content = table(title, body)
        elif title == "Examples":
            content = examples(body)
        elif title == "See Also":
            content = see_also(body)
        else:
            content = text(body)
        blocks.append(f"**{title}**\n\n{content}")
    return "\n\n".join(b for b in blocks if b)


# ---- the page -------------------------------------------------------------------------------

def slug(heading: str) -> str:
    """GitHub's anchor of a heading."""
    s = heading.strip().lower()
    s = re.sub(r"[^\w\- ]", "", s)
    return s.replace(" ", "-")


def kind_of(obj) -> str:
    if isinstance(obj, type):
        if issubclass(obj, Warning):
            return "warning"
        if issubclass(obj, BaseException):
            return "exception"
        return "class"
    return "function" if callable(obj) else "data"


def _bases(cls) -> str:
    bases = [b for b in cls.__bases__ if b is not object]
    return ", ".join(f"`{b.__name__}`" for b in bases)


def render_object(module: str, name: str, obj) -> str:
    title = f"{module}.{name}"
    kind = kind_of(obj)
    out = [f"### `{title}`", ""]
    if kind == "data":
        annotation, _ = DATA[module, name]
        out += ["```text", f"{title}: {annotation}", "```", "",
                render_doc(docstring(obj, module, name), 4), ""]
        if obj is ELEMENTS:
            out += ["| type | PAM (Catalan) | class | anchors | what it does |",
                    "|---|---|---|---|---|"]
            out += [f"| `{t}` | `{c.alias}` | [`{c.__name__}`](#{slug('pam2exu.' + c.__name__)}) "
                    f"| {', '.join(c.anchors)} | {_code(c.summary)} |"
                    for t, c in ELEMENTS.items()]
            out.append("")
        return "\n".join(out)
    prefix = "class " if isinstance(obj, type) else ""
    out += ["```text", prefix + signature(obj, title), "```", ""]
    line = f"*{kind}*" + (f", import: `from {module} import {name}`" if module != "pam2exu"
                          else "")
    if kind in ("exception", "warning"):
        line += f"; bases: {_bases(obj)}"
    out += [line, "", render_doc(docstring(obj, module, name), 4), ""]
    if is_element(obj):
        out += ["Outputs (columns `<name>.<variable>`):", "",
                "| variable | unit | level | meaning |", "|---|---|---|---|"]
        out += [f"| `{v.name}` | {v.unit} | {_LEVELS[v.level]} | {_code(v.meaning)} |"
                for v in obj.outputs] or ["| – | | | no outputs |"]
        out.append("")
    elif isinstance(obj, type):
        for member, attr in members(obj):
            out += render_member(obj, member, attr)
    return "\n".join(out)


def render_member(cls, name: str, attr) -> list[str]:
    title = f"{cls.__name__}.{name}"
    out = [f"#### `{title}`", ""]
    same = alias_of(cls, name, attr)
    if same:
        return out + [(f"The same method as [`{cls.__name__}.{same}`]"
                      f"(#{slug(cls.__name__ + '.' + same)})."), ""]
    if isinstance(attr, property):
        ret = inspect.signature(attr.fget).return_annotation
        ret = "" if ret is inspect.Signature.empty else f": {_annotation(ret)}"
        out += ["```text", f"{title}{ret}", "```", "", "*property*", ""]
        doc = inspect.getdoc(attr) or ""
    else:
        out += ["```text", signature(attr, title, method=True), "```", ""]
        doc = inspect.getdoc(attr) or ""
    return out + [render_doc(doc, 5), ""]


def render() -> str:
    """The whole of docs/api.md."""
    missing = missing_from_page()
    if missing:
        raise SystemExit(f"make_api.py: pam2exu.__all__ has {', '.join(missing)}, which no "
                         "section of SECTIONS documents: add them")
    out = ["# Python API reference", "",
           ("<!-- Generated by docs/make_api.py from the docstrings: do not edit by hand. "
            "Run `python docs/make_api.py` after changing a docstring. -->"), "",
           ("The public Python API of pam2exu, from its docstrings. Physical quantities are "
            "in SI units, given in brackets: times [s], lengths [m], angles [rad], forces [N], "
            "moments [N·m]; a result column's unit is in `Results.units`. Examples are "
            "doctests (`tests/test_api_docs.py` runs those that need no files). The command "
            "line is described in the [README](../README.md)."), ""]
    for title, _, items in SECTIONS:
        out.append(f"- [{title}](#{slug(title)}): "
                   + ", ".join(f"[`{m}.{n}`](#{slug(m + '.' + n)})" for m, n in items))
    out.append("")
    for title, intro, items in SECTIONS:
        out += [f"## {title}", "", _code(intro), ""]
        for module, name in items:
            out.append(render_object(module, name, resolve(module, name)))
    text_ = "\n".join(out)
    text_ = re.sub(r"\n{3,}", "\n\n", text_).rstrip("\n") + "\n"
    return text_


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description="Write docs/api.md from pam2exu's docstrings.")
    p.add_argument("--check", action="store_true",
                   help="exit 1 when docs/api.md is not what this script writes")
    args = p.parse_args(argv)
    return write_or_check(OUTPUT, render(), args.check, str(OUTPUT.relative_to(ROOT)),
                          "it is not what the docstrings give", "python docs/make_api.py")


if __name__ == "__main__":
    sys.exit(main())

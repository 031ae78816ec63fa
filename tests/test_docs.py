"""The user documentation is self-contained and states every key the loader accepts.

- No page of the README or docs/ (nor a generator of those pages, nor a shipped example)
  mentions ``shared/``: a clone of the repository does not have it. No page links outside
  the repository, and every relative link (and its #anchor) resolves in it.
- docs/model-format.md lists exactly the keys the loader accepts: the tables of a model
  file and the keys of [model], [[solid]] (and of a line), [analysis], [[variation]] and of
  every element type, read from the code's declarations (``pam2exu.model.loader``,
  ``Element.keys()``, ``Param.values()``, ``pam2exu.registry``, ``pam2exu.laws``), with the
  values of the keys that take names (analysis types, backends, angle units, laws, choices).
  A key added to the loader without docs, or documented but refused, fails here.
"""
import ast
import re
from pathlib import Path

import pytest

from pam2exu import registry
from pam2exu.elements import ELEMENTS
from pam2exu.laws import LAW_ALIASES, LAWS
from pam2exu.model import angles, loader
from pam2exu.model.solid import LINE_KEYS

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
MODEL_FORMAT = ROOT / "docs" / "model-format.md"


def _text_files() -> list[Path]:
    """What users read: the pages, the scripts that write pages, the shipped examples."""
    examples = [p for p in (ROOT / "examples").rglob("*")
                if p.suffix in (".toml", ".py", ".ipynb", ".md")]
    return [*PAGES, *sorted((ROOT / "docs").glob("*.py")), *sorted(examples)]


@pytest.mark.parametrize("path", _text_files(), ids=lambda p: str(p.relative_to(ROOT)))
def test_no_mention_of_shared(path):
    text = path.read_text(encoding="utf-8")
    lines = [n for n, line in enumerate(text.splitlines(), 1) if "shared/" in line]
    assert not lines, f"{path.relative_to(ROOT)} mentions shared/ at lines {lines}"


def _strings(source: str) -> list[tuple[int, str]]:
    """(line, text) of every string constant of a module that is not a docstring: its
    messages, help texts and summaries (docstrings reach users through docs/api.md)."""
    tree = ast.parse(source)
    docstrings = {id(node.body[0].value) for node in ast.walk(tree)
                  if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef,
                                       ast.AsyncFunctionDef))
                  and node.body and isinstance(node.body[0], ast.Expr)
                  and isinstance(node.body[0].value, ast.Constant)}
    return [(node.lineno, node.value) for node in ast.walk(tree)
            if isinstance(node, ast.Constant) and isinstance(node.value, str)
            and id(node) not in docstrings]


def test_no_message_of_the_package_mentions_shared():
    """What the package prints (errors, warnings, help texts) sends no one to shared/."""
    found = [f"{path.relative_to(ROOT)}:{line}"
             for path in sorted((ROOT / "pam2exu").rglob("*.py"))
             for line, text in _strings(path.read_text(encoding="utf-8")) if "shared/" in text]
    assert not found, found
    # a message split over two literals is one string; a docstring is not a message
    assert _strings('"""shared/ doc."""\nx = f"a {1} (shared/" "spec)"\n') == [
        (2, "a "), (2, " (shared/spec)")]


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_no_link_outside_the_repository(page):
    text = page.read_text(encoding="utf-8")
    found = re.findall(r"\w+://\S+", text)
    assert not found, f"{page.relative_to(ROOT)} links outside the repository: {found}"


# ---- links and anchors -------------------------------------------------------------------

def _prose(text: str) -> str:
    """The text without its fenced code blocks (their '#' lines are comments, not headings,
    and their brackets are TOML, not links)."""
    return re.sub(r"^(```|~~~).*?^\1[^\n]*$", "", text, flags=re.S | re.M)


def slug(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, only letters, digits, '_', '-' and
    spaces kept, spaces turned into '-'."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def anchors(text: str) -> set[str]:
    """The anchors of a page: its headings' slugs (a repeated one numbered -1, -2, … as
    GitHub does) and its ``<a id="…">`` tags."""
    out, seen = set(), {}
    for heading in re.findall(r"^#{1,6} +(.+?) *#*$", _prose(text), re.M):
        base = slug(heading)
        n = seen.get(base, 0)
        out.add(base if n == 0 else f"{base}-{n}")
        seen[base] = n + 1
    return out | set(re.findall(r'<a id="([^"]+)"', text))


def links(text: str) -> list[str]:
    """The targets of a page's Markdown links and images."""
    return re.findall(r"\]\(([^)\s]+)\)", _prose(text))


def broken_links(page: Path) -> list[str]:
    """The links of ``page`` whose file or anchor does not exist in the repository."""
    bad = []
    for target in links(page.read_text(encoding="utf-8")):
        path, _, anchor = target.partition("#")
        file = (page.parent / path).resolve() if path else page
        if ROOT not in file.parents and file != ROOT:
            bad.append(f"{target} (outside the repository)")
        elif not file.exists():
            bad.append(f"{target} (no such file)")
        elif anchor and file.suffix == ".md" and anchor not in anchors(
                file.read_text(encoding="utf-8")):
            bad.append(f"{target} (no such anchor in {file.name})")
    return bad


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_relative_links_resolve(page):
    assert broken_links(page) == [], page.relative_to(ROOT)


def test_link_check_can_fail(tmp_path, monkeypatch):
    monkeypatch.setattr(f"{__name__}.ROOT", tmp_path)
    (tmp_path / "a.md").write_text("# Top\n## Two words (`x`)\n", encoding="utf-8")
    page = tmp_path / "b.md"
    page.write_text("[ok](a.md#two-words-x) [ok](#here) [no](c.md) [no](a.md#three)\n"
                    "[out](../x.md)\n## Here\n```bash\n# not a heading\n[not](a link)\n```\n",
                    encoding="utf-8")
    assert broken_links(page) == ["c.md (no such file)", "a.md#three (no such anchor in a.md)",
                                  "../x.md (outside the repository)"]
    assert slug("`fixed` [`enllac_fix`]") == "fixed-enllac_fix"
    assert slug("The exact velocity term γ") == "the-exact-velocity-term-γ"


# ---- docs/model-format.md against the loader ---------------------------------------------

def _sections(text: str) -> list[tuple[int, str, str]]:
    """(level, heading, body) of every heading; a body runs to the next heading of the
    same or a higher level (so it holds its subsections)."""
    prose = _prose(text)
    heads = [(m.start(), len(m.group(1)), m.group(2), m.end())
             for m in re.finditer(r"^(#{1,6}) +(.+)$", prose, re.M)]
    out = []
    for k, (_, level, title, end) in enumerate(heads):
        stop = next((start for start, lv, _, _ in heads[k + 1:] if lv <= level), len(prose))
        out.append((level, title, prose[end:stop]))
    return out


def _tables(body: str) -> list[list[list[str]]]:
    """The Markdown tables of a body: rows of cells, the header first, the rule left out."""
    tables, rows = [], []
    for line in body.splitlines() + [""]:
        if line.startswith("|"):
            cells = [c.strip() for c in re.split(r"(?<!\\)\|", line.strip()[1:-1])]
            if not all(re.fullmatch(r":?-+:?", c) for c in cells):
                rows.append(cells)
        elif rows:
            tables.append(rows)
            rows = []
    return tables


def _key_tables(body: str) -> list[dict[str, list[str]]]:
    """The tables headed ``| key | …`` of a body, own text only: {key: row's cells}, one
    entry per name of a row such as ``x, y, fi``."""
    out = []
    for table in _tables(body):
        if table[0][0] == "key":
            keys = {}
            for row in table[1:]:
                for key in row[0].replace("`", "").split(","):
                    assert key.strip() not in keys, f"key '{key.strip()}' documented twice"
                    keys[key.strip()] = row
            out.append(keys)
    return out


def _quoted(cell: str) -> set[str]:
    """The values a cell gives as TOML strings in code: `"deg"`."""
    return set(re.findall(r'`"([^"`]+)"`', cell))


def _difference(what: str, documented, accepted) -> list[str]:
    documented, accepted = set(documented), set(accepted)
    out = []
    if accepted - documented:
        out.append(f"{what}: accepted but not documented: {sorted(accepted - documented)}")
    if documented - accepted:
        out.append(f"{what}: documented but refused: {sorted(documented - accepted)}")
    return out


def model_format_problems(text: str) -> list[str]:
    """Where the page and the loader's declarations differ (empty when they agree)."""
    sections = _sections(text)
    tables = {}                 # table name -> the body of the section headed `[name]`
    for _, title, body in sections:
        for name in re.findall(r"`\[\[?(\w+)\]\]?`", title):
            assert name not in tables, f"two sections are headed [{name}]"
            tables[name] = body
    problems = _difference("tables", tables, loader._TABLES)

    def key_tables(name: str, count: int) -> list[dict]:
        found = _key_tables(tables.get(name, ""))
        if len(found) != count:
            problems.append(f"[{name}]: {len(found)} key tables, expected {count}")
            return [{}] * count
        return found

    (model,) = key_tables("model", 1)
    problems += _difference("[model]", model, loader._MODEL_KEYS)
    solid, line = key_tables("solid", 2)
    problems += _difference("[[solid]]", solid, loader._SOLID_KEYS)
    problems += _difference("a solid's line", line, LINE_KEYS)
    (analysis,) = key_tables("analysis", 1)
    problems += _difference("[analysis]", analysis, loader._ANALYSIS_KEYS)
    (variation,) = key_tables("variation", 1)
    problems += _difference("[[variation]]", variation, loader._VARIATION_KEYS)

    # the keys that take names: every value accepted is written `"value"` in its row
    if "angles" in model:
        problems += _difference("[model] angles", _quoted(model["angles"][1]), angles.UNITS)
    if "backend" in analysis:
        problems += _difference("[analysis] backend", _quoted(analysis["backend"][1]),
                                registry.BACKENDS)
    types = [t for t in _tables(tables.get("analysis", "")) if t[0][0].startswith("type")]
    problems += _difference(
        "[analysis] type", {v for t in types for row in t[1:] for v in _quoted(row[0])},
        [*registry.ANALYSES, *(a.alias for a in registry.ANALYSES.values())])
    laws = [t for _, title, body in sections if title.startswith("Time laws")
            for t in _tables(body) if t[0][0] == "law"]
    problems += _difference("laws", {n for t in laws for row in t[1:]
                                     for n in re.findall(r"`(\w+)`", row[0])},
                            [*LAWS, *LAW_ALIASES])

    # every element type: a section ### `type` in [[element]] with its keys and values
    elements = {re.match(r"`(\w+)`", title)[1]: body for level, title, body
                in _sections(tables.get("element", "")) if level == 3
                and re.match(r"`(\w+)`", title)}
    problems += _difference("element types", elements, ELEMENTS)
    for kind, body in elements.items():
        cls = ELEMENTS.get(kind)
        found = _key_tables(body)
        if cls is None or len(found) != 1:
            continue
        keys = found[0]
        problems += _difference(f"[[element]] {kind}", keys, cls.keys())
        if "type" in keys:
            problems += _difference(f"{kind} type", _quoted(keys["type"][1]),
                                    {cls.type, cls.alias})
        for key, param in cls.params.items():
            if param.values() and key in keys:
                problems += _difference(f"{kind} {key}", _quoted(keys[key][1]),
                                        param.values())
    return problems


def test_model_format_lists_every_key_the_loader_accepts():
    assert model_format_problems(MODEL_FORMAT.read_text(encoding="utf-8")) == []


def test_a_key_added_to_the_loader_without_docs_fails(monkeypatch):
    monkeypatch.setattr(loader, "_SOLID_KEYS", (*loader._SOLID_KEYS, "spin"))
    monkeypatch.setattr(loader, "_ANALYSIS_KEYS",
                        tuple(k for k in loader._ANALYSIS_KEYS if k != "tolerance"))
    assert model_format_problems(MODEL_FORMAT.read_text(encoding="utf-8")) == [
        "[[solid]]: accepted but not documented: ['spin']",
        "[analysis]: documented but refused: ['tolerance']"]


def test_a_key_documented_but_refused_fails():
    text = MODEL_FORMAT.read_text(encoding="utf-8")
    row = "| mass | kg | 0 |\n"
    assert text.count(row) == 1
    text = text.replace(row, row + "| spin | rad/s | 0 |\n")
    text = text.replace("| backend | what solves the positions: ",     # whatever it lists
                        '| backend | what solves the positions: `"opensim"`, ')
    text = text.replace("| `axes` |", "| `frame` |")
    assert model_format_problems(text) == [
        "[[solid]]: documented but refused: ['spin']",
        "[analysis] backend: documented but refused: ['opensim']",
        "[[element]] torsor: accepted but not documented: ['axes']",
        "[[element]] torsor: documented but refused: ['frame']"]

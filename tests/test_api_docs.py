"""The Python API reference: docs/api.md is what docs/make_api.py writes, every public object
documents every parameter (numpydoc), the docstrings' examples run, physical parameters have
units."""
import doctest
import importlib
import importlib.util
import inspect
import re
from pathlib import Path

import pytest

import pam2exu
from pam2exu.results import Results

ROOT = Path(__file__).resolve().parents[1]


def _make_api():
    spec = importlib.util.spec_from_file_location("make_api", ROOT / "docs" / "make_api.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


make_api = _make_api()


# ---- a small numpydoc reader, independent of the generator's ------------------------------

def sections(doc: str) -> dict[str, list[str]]:
    """Section title -> body lines, for sections headed by a line of dashes."""
    lines = doc.splitlines()
    out, current = {}, None
    for k, line in enumerate(lines):
        if k + 1 < len(lines) and line.strip() and re.fullmatch(r"-{3,}", lines[k + 1].strip()) \
                and not line.startswith(" "):
            current = out.setdefault(line.strip(), [])
            continue
        if current is not None and not re.fullmatch(r"-{3,}", line.strip()):
            current.append(line)
    return out


def entries(body: list[str]) -> dict[str, tuple[str, str]]:
    """Documented name -> (type, description) of a Parameters-like section ("x, y : float"
    documents x and y; "**settings" documents settings)."""
    out, names = {}, []
    for line in body:
        if line.strip() and not line.startswith(" "):
            head, _, kind = line.partition(" : ")
            names = [n.strip().lstrip("*") for n in head.split(",")]
            for n in names:
                out[n] = (kind.strip(), "")
        elif line.strip() and names:
            for n in names:
                out[n] = (out[n][0], (out[n][1] + " " + line.strip()).strip())
    return out


def documented(obj, doc: str) -> dict[str, tuple[str, str]]:
    """The parameters a docstring documents (dataclasses: Attributes count too)."""
    found = sections(doc)
    names = entries(found.get("Parameters", []))
    if isinstance(obj, type) and hasattr(obj, "__dataclass_fields__"):
        names = {**entries(found.get("Attributes", [])), **names}
    return names


def problems_of(obj, doc: str) -> list[str]:
    """What is wrong with the Parameters section of ``doc`` for ``obj``'s signature."""
    if not doc.strip():
        return ["no docstring"]
    try:
        params = list(inspect.signature(obj).parameters.values())
    except (TypeError, ValueError):          # a builtin __init__ (exceptions): *args
        return []
    if params and params[0].name in ("self", "cls") and not isinstance(obj, type):
        params = params[1:]
    names = documented(obj, doc)
    out = []
    if params and "Parameters" not in sections(doc) and not names:
        out.append("no Parameters section")
    out += [f"parameter '{p.name}' not documented" for p in params if p.name not in names]
    has_kwargs = any(p.kind is p.VAR_KEYWORD for p in params)
    if not has_kwargs and not isinstance(obj, type):
        signature = {p.name for p in params}
        out += [f"'{n}' documented but not a parameter" for n in names if n not in signature]
    return out


def public_objects():
    """(title, object, docstring) of every object the reference documents, members included,
    and of everything in pam2exu.__all__ and the public methods of Model and Results."""
    seen, out = set(), []

    def add(title, obj, doc):
        if title not in seen:
            seen.add(title)
            out.append((title, obj, doc))

    for module, name, obj in make_api.entries():
        if make_api.kind_of(obj) == "data":
            continue
        add(f"{module}.{name}", obj, make_api.docstring(obj, module, name))
        if isinstance(obj, type) and not make_api.is_element(obj):
            for member, attr in make_api.members(obj):
                if not isinstance(attr, property):
                    add(f"{module}.{name}.{member}", attr, inspect.getdoc(attr) or "")
    for name in pam2exu.__all__:
        obj = getattr(pam2exu, name)
        if callable(obj):
            add(f"pam2exu.{name}", obj, make_api.docstring(obj, "pam2exu", name))
    for prefix, cls in (("pam2exu.Model", pam2exu.Model), ("pam2exu.results.Results", Results)):
        for name, attr in inspect.getmembers(cls):
            if not name.startswith("_") and inspect.isfunction(attr):
                add(f"{prefix}.{name}", attr, inspect.getdoc(attr) or "")
    return out


OBJECTS = public_objects()


# ---- (a) docs/api.md is generated ------------------------------------------------------------

def test_api_md_is_what_the_generator_writes():
    written = (ROOT / "docs" / "api.md").read_text(encoding="utf-8")
    assert written == make_api.render(), \
        "docs/api.md is stale: run `python docs/make_api.py` and commit the result"


def test_generator_is_deterministic():
    assert make_api.render() == make_api.render()
    text = make_api.render()
    assert " at 0x" not in text and str(ROOT) not in text


def test_check_option_reports_a_stale_page(tmp_path, monkeypatch, capsys):
    page = tmp_path / "api.md"
    monkeypatch.setattr(make_api, "ROOT", tmp_path)
    monkeypatch.setattr(make_api, "OUTPUT", page)
    page.write_text(make_api.render().replace("Results", "Result", 1), encoding="utf-8")
    assert make_api.main(["--check"]) == 1
    assert "api.md is stale" in capsys.readouterr().err
    assert make_api.main([]) == 0
    assert make_api.main(["--check"]) == 0


def test_page_has_no_executed_python_blocks():
    """tests/test_readme.py runs every ```python block of docs/*.md: examples are pycon."""
    text = (ROOT / "docs" / "api.md").read_text(encoding="utf-8")
    assert "```python" not in text
    assert text.count("```pycon") >= 30


def test_every_public_name_has_a_section():
    assert make_api.missing_from_page() == []
    text = (ROOT / "docs" / "api.md").read_text(encoding="utf-8")
    for name in pam2exu.__all__:
        assert f"### `pam2exu.{name}`" in text, name
    for cls in (pam2exu.Model, Results):
        for name, _ in make_api.members(cls):
            assert f"#### `{cls.__name__}.{name}`" in text, name


def test_table_of_contents_links_resolve():
    text = (ROOT / "docs" / "api.md").read_text(encoding="utf-8")
    anchors = {make_api.slug(h.replace("`", "")) for h in re.findall(r"^#+ (.+)$", text,
                                                                       re.MULTILINE)}
    links = re.findall(r"\]\(#([^)]+)\)", text)
    assert links and not [link for link in links if link not in anchors]


# ---- (b) every parameter documented ------------------------------------------------------

@pytest.mark.parametrize("title, obj, doc", OBJECTS, ids=[o[0] for o in OBJECTS])
def test_parameters_are_documented(title, obj, doc):
    assert problems_of(obj, doc) == []


def test_the_objects_checked_include_the_public_api():
    titles = {t for t, _, _ in OBJECTS}
    assert {f"pam2exu.{n}" for n in pam2exu.__all__ if n != "ELEMENTS"} <= titles
    for name in ("add_solid", "add", "add_element", "problems", "validate", "mechanism"):
        assert f"pam2exu.Model.{name}" in titles
    for name in ("to_csv", "to_numpy", "select", "summary", "checks"):
        assert f"pam2exu.results.Results.{name}" in titles
    assert len(OBJECTS) >= 60


def test_the_parameter_check_can_fail():
    def documented_once(model, t_end=None):
        """Run.

        Parameters
        ----------
        model : Model
            The model.
        steps : int
            Gone.
        """

    assert problems_of(documented_once, inspect.getdoc(documented_once)) == [
        "parameter 't_end' not documented", "'steps' documented but not a parameter"]
    assert problems_of(documented_once, "") == ["no docstring"]


def test_element_parameters_come_from_their_declarations():
    """A key added to an element class without a ``params`` declaration is not documented."""
    from dataclasses import dataclass

    @dataclass(eq=False)
    class Extra(pam2exu.Revolute):
        stiffness: float = 0.0

    assert problems_of(Extra, make_api.element_docstring(Extra)) == [
        "parameter 'stiffness' not documented"]


# ---- (c) the examples in the docstrings run ----------------------------------------------

DOCTEST_MODULES = ["pam2exu", "pam2exu.errors", "pam2exu.laws", "pam2exu.model.model",
                   "pam2exu.model.analysis",
                   "pam2exu.model.solid", "pam2exu.model.loader", "pam2exu.analyses",
                   "pam2exu.results.table", "pam2exu.results.table_csv", "pam2exu.results.names", "pam2exu.results.reading",
                   "pam2exu.results.compare", "pam2exu.results.comparison",
                   "pam2exu.results.units", "pam2exu.results.plot", "pam2exu.results.info",
                   "pam2exu.pictures.mechanism", "pam2exu.export", "pam2exu.verify"]


@pytest.mark.parametrize("name", DOCTEST_MODULES)
def test_doctests(name, monkeypatch):
    monkeypatch.chdir(ROOT)
    module = importlib.import_module(name)
    finder = doctest.DocTestFinder()
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS)
    report = []
    tests = [t for t in finder.find(module, name) if t.examples]
    assert tests, f"{name} has no examples"
    for test in tests:
        runner.run(test, out=report.append)
    result = runner.summarize(verbose=False)
    assert result.failed == 0, "".join(report)


def test_doctests_do_run():
    """Most examples run (only those that need files or take long are skipped)."""
    run, skipped = 0, 0
    for name in DOCTEST_MODULES:
        module = importlib.import_module(name)
        for test in doctest.DocTestFinder().find(module, name):
            for example in test.examples:
                if example.options.get(doctest.SKIP):
                    skipped += 1
                else:
                    run += 1
    assert run >= 80 and run > 3 * skipped


# ---- (d) units of physical parameters ----------------------------------------------------

#: parameter name -> the bracketed unit its description must give
UNITS = {
    "t_end": "[s]", "t": "[s]", "time": "[s]", "t_at_max": "[s]", "overlap": "[s]",
    "gravity": "[m/s²]", "x": "[m]", "y": "[m]", "fi": "[rad]", "mass": "[kg]",
    "inertia": "[kg·m²]", "cog": "[m]", "points": "[m]", "rtol": "[–]",
    "atol": "[SI unit of each variable]", "dpi": "[dots per inch]", "fps": "[1/s]",
    "size": "[in]", "width": "[in]", "height": "[in]",
}
#: (object, parameter) pairs that must be among those checked
MUST_CHECK = [
    ("pam2exu.run", "t_end"), ("pam2exu.analyses.run", "t_end"), ("pam2exu.export", "t_end"),
    ("pam2exu.export.script", "t_end"), ("pam2exu.model.Analysis", "t_end"),
    ("pam2exu.animate", "t_end"), ("pam2exu.pictures.configurations", "t_end"),
    ("pam2exu.draw", "t"), ("pam2exu.pictures.pose", "t"),
    ("pam2exu.compare", "rtol"), ("pam2exu.compare", "atol"),
    ("pam2exu.Comparison", "rtol"), ("pam2exu.Comparison", "atol"),
    ("pam2exu.Model", "gravity"), ("pam2exu.Solid", "x"), ("pam2exu.Solid", "y"),
    ("pam2exu.Solid", "fi"), ("pam2exu.Solid", "mass"), ("pam2exu.Solid", "inertia"),
    ("pam2exu.Solid", "cog"), ("pam2exu.SolverError", "time"), ("pam2exu.plot", "dpi"),
    ("pam2exu.animate", "fps"), ("pam2exu.Law.__call__", "t"),
    ("pam2exu.Law.value", "t"), ("pam2exu.Results", "t"),
]
#: float parameters without a unit: ratios, counts of the variable's own unit
DIMENSIONLESS = {"T"}


def _documented_parameters():
    """(object, parameter, type, description) of every Parameters/Attributes entry."""
    out = []
    for title, obj, doc in OBJECTS:
        found = sections(doc)
        for section in ("Parameters", "Attributes"):
            for name, (kind, text) in entries(found.get(section, [])).items():
                out.append((title, name, kind, text))
    return out


def test_physical_parameters_have_units():
    params = _documented_parameters()
    checked = set()
    wrong = []
    for title, name, kind, text in params:
        if name in UNITS:
            checked.add((title, name))
            if UNITS[name] not in text:
                wrong.append(f"{title}: '{name}' needs {UNITS[name]}: {text!r}")
    assert wrong == []
    assert [pair for pair in MUST_CHECK if pair not in checked] == []


def test_every_float_parameter_has_a_unit():
    """A float parameter or attribute says its unit in brackets (or is dimensionless)."""
    missing = [f"{title}: '{name}' ({kind})" for title, name, kind, text in
               _documented_parameters()
               if "float" in kind and name not in DIMENSIONLESS
               and not re.search(r"\[[^\]]+\]", text)]
    assert missing == []


def test_the_unit_check_can_fail():
    doc = "Parameters\n----------\nt_end : float\n    End of the interval.\n"
    found = entries(sections(doc)["Parameters"])
    assert UNITS["t_end"] not in found["t_end"][1]


def test_property_t_has_its_unit():
    assert "[s]" in inspect.getdoc(Results.t)
    assert "[s]" in inspect.getdoc(pam2exu.Law.__call__)

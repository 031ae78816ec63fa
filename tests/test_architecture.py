"""The package's structure: its import graph, the registry's door for a new analysis, and
docs/architecture.md kept true.

References: the source itself (``ast``), and the page docs/architecture.md.
"""
from __future__ import annotations

import ast
import importlib
import re
import sys
from pathlib import Path

import numpy as np
import pytest

import pam2exu
from pam2exu import registry
from pam2exu.analyses.job import check_mobility, collect
from pam2exu.analyses.positions import positions

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "pam2exu"


def _module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {_module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


def _target(module: str, node: ast.ImportFrom | ast.Import, is_package: bool) -> list[str]:
    """The pam2exu modules an import statement loads (a.b.c also loads a and a.b)."""
    if isinstance(node, ast.Import):
        names = [a.name for a in node.names]
    else:
        base = module if is_package else module.rpartition(".")[0]
        for _ in range(node.level - 1):
            base = base.rpartition(".")[0]
        source = (f"{base}.{node.module}" if node.module else base) if node.level else node.module
        names = [f"{source}.{a.name}" if f"{source}.{a.name}" in MODULES else source
                 for a in node.names]
    out = set()
    for name in names:
        parts = name.split(".")
        out |= {".".join(parts[:k]) for k in range(1, len(parts) + 1)} & set(MODULES)
    # a module's own packages are being imported already when it runs (Python made them
    # first): an edge to one of them is no dependency
    ancestors = {module.rsplit(".", k)[0] for k in range(1, module.count(".") + 1)}
    return sorted(out - {module} - ancestors)


def _imports(module: str) -> tuple[set[str], set[str], set[str]]:
    """(module-level, lazy, annotation) pam2exu dependencies of a module: its imports at
    module level; its imports inside functions and the modules its ``'pam2exu.module:name'``
    strings name (the registry's declarations, ``registry.resolve``: imported when first
    used); and its ``if TYPE_CHECKING:`` imports (never run, but documented dependencies)."""
    path = MODULES[module]
    return _dependencies(module, path.read_text(encoding="utf-8"), path.name == "__init__.py")


def _dependencies(module: str, source: str, is_package: bool):
    """``_imports`` of a module whose text is ``source``."""
    tree = ast.parse(source)
    top, inner, typing = set(), set(), set()

    def visit(node, in_function, in_typing):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            in_typing = True
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            (typing if in_typing else inner if in_function else top).update(
                _target(module, node, is_package))
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            inner.update(_named_module(node.value))
        for child in ast.iter_child_nodes(node):
            visit(child, in_function or isinstance(node, (ast.FunctionDef,
                                                          ast.AsyncFunctionDef, ast.Lambda)),
                  in_typing)
    visit(tree, False, False)
    return top, inner, typing


def _named_module(text: str) -> set[str]:
    """The module a ``'pam2exu.module:attribute'`` string names (``registry.resolve``)."""
    found = re.fullmatch(r"(pam2exu(?:\.\w+)*):\w+", text)
    return {found.group(1)} if found else set()


def _face_imports(module: str) -> list[str]:
    """The names a module imports from the package face ``pam2exu`` (its ``__init__``)
    that are no submodule: ``from pam2exu import run``, ``from . import __version__``."""
    path = MODULES[module]
    out = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            base = module if path.name == "__init__.py" else module.rpartition(".")[0]
            for _ in range(node.level - 1):
                base = base.rpartition(".")[0]
            source = ((f"{base}.{node.module}" if node.module else base) if node.level
                      else node.module)
            out += [a.name for a in node.names
                    if source == "pam2exu" and f"pam2exu.{a.name}" not in MODULES]
    return out


GRAPH = {m: _imports(m) for m in MODULES}

#: the registry's doors: its declarations name the analyses' functions and the backends'
#: classes as strings (imported when first used), while the model and the analyses read its
#: tables; these edges, and only these, may close a loop
PLUG_INS = ("pam2exu.analyses.", "pam2exu.backend.")
REGISTRY = "pam2exu.registry"

#: what the model layer must not know (docs/architecture.md: nothing imports upwards)
ABOVE_THE_MODEL = ("pam2exu.analyses", "pam2exu.backend", "pam2exu.results",
                   "pam2exu.pictures", "pam2exu.notebook", "pam2exu.cli", "pam2exu.console",
                   "pam2exu.export", "pam2exu.export_dynamic", "pam2exu.verify")


def _lazy_graph(graph) -> dict[str, set[str]]:
    """Every dependency (module level, lazy, annotations) but the registry's plug-in doors."""
    return {m: top | inner | typing if m != REGISTRY else
            top | typing | {n for n in inner if not n.startswith(PLUG_INS)}
            for m, (top, inner, typing) in graph.items()}


def _cycle(edges: dict[str, set[str]]) -> list[str] | None:
    """A cycle of the directed graph, or None."""
    state: dict[str, int] = {}
    stack: list[str] = []

    def walk(m):
        state[m] = 1
        stack.append(m)
        for n in sorted(edges.get(m, ())):
            if state.get(n) == 1:
                return stack[stack.index(n):] + [n]
            if n not in state:
                found = walk(n)
                if found:
                    return found
        stack.pop()
        state[m] = 2
        return None
    for m in sorted(edges):
        if m not in state:
            found = walk(m)
            if found:
                return found
    return None


def test_the_walker_finds_imports_and_cycles():
    """The walker itself: the package's own imports are seen, and a cycle is found."""
    top, _, _ = GRAPH["pam2exu.analyses.job"]
    assert {"pam2exu.registry", "pam2exu.backend", "pam2exu.model", "pam2exu.model.solid",
            "pam2exu.analyses.grid"} <= top
    assert _cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert _cycle({"a": {"b"}, "b": {"c"}}) is None


def test_the_walker_sees_annotations_and_the_registry_strings():
    """``if TYPE_CHECKING:`` imports and ``'pam2exu.module:name'`` strings are edges: the
    registry's into the analyses and the backends; in a module of the model, an annotation
    of the Job and a string naming the notebook (as ``Model._repr_html_`` had)."""
    _, inner, _ = GRAPH[REGISTRY]
    assert {"pam2exu.analyses.kinematic", "pam2exu.analyses.dynamic",
            "pam2exu.backend.natural"} <= inner
    source = ("from typing import TYPE_CHECKING\n"
              "if TYPE_CHECKING:\n    from ..analyses.job import Job\n"
              "def view(model):\n"
              "    return registry.resolve('pam2exu.notebook:model_html')(model)\n")
    top, inner, typing = _dependencies("pam2exu.model.model", source, False)
    assert (top, inner, typing) == (set(), {"pam2exu.notebook"}, {"pam2exu.analyses",
                                                                  "pam2exu.analyses.job"})


def test_the_import_graph_has_no_cycle():
    """Module-level imports, with every package's __init__, form no cycle."""
    assert _cycle({m: top for m, (top, _, _) in GRAPH.items()}) is None


def test_the_annotations_form_no_cycle():
    """``if TYPE_CHECKING:`` imports (annotations only) are dependencies too: with the
    module-level imports they form no cycle."""
    assert _cycle({m: top | typing for m, (top, _, typing) in GRAPH.items()}) is None


def test_no_import_inside_a_function_dodges_a_cycle():
    """Imports of pam2exu modules inside functions (kept lazy so that ``import pam2exu``
    loads neither Exudyn nor matplotlib) and ``'module:name'`` strings would form no cycle
    at module level either: only the registry's doors into its plug-ins may close a loop."""
    assert _cycle(_lazy_graph(GRAPH)) is None


def test_the_registry_strings_point_only_into_its_plug_ins():
    """The registry's ``'module:name'`` strings name existing modules of the analyses and
    the backends, nothing above them (the command, the pictures, the notebook)."""
    text = MODULES[REGISTRY].read_text(encoding="utf-8")
    named = set(re.findall(r"[\"'](pam2exu(?:\.\w+)+):\w+[\"']", text))
    assert named and sorted(named - set(MODULES)) == []
    assert sorted(n for n in named if not n.startswith(PLUG_INS)) == []


def test_the_model_layer_knows_nothing_above_it():
    """No module of ``pam2exu.model`` depends, in any way (imports at module level, in
    functions, annotations, ``'module:name'`` strings), on the analyses, the backends, the
    results, the pictures, the notebook or the commands."""
    up = {m: sorted(n for n in top | inner | typing if n.startswith(ABOVE_THE_MODEL))
          for m, (top, inner, typing) in GRAPH.items() if m.startswith("pam2exu.model")}
    assert {m: n for m, n in up.items() if n} == {}


def _layers() -> dict[str, int]:
    """The layer of each top-level module or package, read from docs/architecture.md's
    numbered list between ``<!-- layers -->`` and ``<!-- /layers -->`` (1 lowest)."""
    text = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    block = text.split("<!-- layers -->")[1].split("<!-- /layers -->")[0]
    return {name: int(k) for k, row in re.findall(r"^(\d+)\. (.+)$", block, re.M)
            for name in re.findall(r"`(\w+)`", row)}


def _top(module: str) -> str:
    """``pam2exu.analyses.job`` → ``analyses``; the package itself → ``__init__``."""
    return module.split(".")[1] if "." in module else "__init__"


def test_the_layers_import_only_downwards():
    """Every module's dependencies (module level, lazy, annotations; the registry's doors
    into its plug-ins excepted) lie in its own layer of docs/architecture.md or below, and
    every top-level module and package of pam2exu has a layer there."""
    layer = _layers()
    assert sorted({_top(m) for m in MODULES} - set(layer)) == []
    up = sorted(f"{m} -> {n}" for m, edges in _lazy_graph(GRAPH).items() for n in edges
                if layer[_top(n)] > layer[_top(m)])
    assert up == []


def test_the_layer_check_sees_an_arrow_up():
    """The model importing the analyses (layer 3 → 6) is an arrow up."""
    layer = _layers()
    assert layer[_top("pam2exu.model.model")] < layer[_top("pam2exu.analyses.job")]
    assert layer["__init__"] == max(layer.values()) and layer["errors"] == 1


def test_no_module_imports_from_the_package_face():
    """The package face (``pam2exu/__init__.py``) only re-exports: no module of the package
    imports a name from it (``__version__`` is ``pam2exu.version``'s)."""
    found = {m: names for m in MODULES if m != "pam2exu" and (names := _face_imports(m))}
    assert found == {}


def test_no_module_is_longer_than_500_lines():
    long = {m: n for m, p in MODULES.items()
            if (n := len(p.read_text(encoding="utf-8").splitlines())) > 500}
    assert not long, long


def test_importing_pam2exu_loads_neither_exudyn_nor_matplotlib():
    """Nor does the natural backend (one process for both: each costs a Python start)."""
    import subprocess
    code = ("import sys, pam2exu.backend.natural; print('exudyn' in sys.modules); "
            "import pam2exu; pam2exu.load('examples/four_bar.toml'); "
            "print(sorted(m for m in sys.modules if m.split('.')[0] in "
            "('exudyn', 'matplotlib')))")
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True,
                         text=True, check=True).stdout
    assert out.split("\n")[:2] == ["False", "[]"]


# ---- adding an analysis: one registry entry and its function -------------------------------

def test_a_dummy_analysis_needs_only_its_registry_entry_and_function(monkeypatch):
    """An analysis 'centre' (the solids' x, y after the assembly and a constant shift) added
    by one entry whose function uses the shared pieces: the model accepts its name and its
    Catalan alias, run dispatches to it, its columns follow its declared levels, and a
    model whose DOF is not driven is refused as the entry says (driven=True)."""
    calls = []

    def centre(job):
        calls.append(job.analysis_type.name)
        check_mobility(job, job.mech.initial_q())
        q = positions(job, redundant=False)
        return collect(job, q + 1.0)

    entry = registry.AnalysisType("centre", "centre_ca", frozenset({"position"}), driven=True,
                                  at_start=False, summary="a test", function=centre)
    monkeypatch.setitem(registry.ANALYSES, "centre", entry)
    path = ROOT / "examples" / "four_bar.toml"
    res = pam2exu.run(path, analysis="centre_ca", steps=4)
    kin = pam2exu.run(path, analysis="kinematic", steps=4, outputs=list(res.columns))
    assert calls == ["centre"] and res.analysis == "centre" and res.analysis_type is entry
    assert res.columns == kin.columns and "motor.f(t)" in res.columns
    np.testing.assert_array_equal(res["crank.x"], kin["crank.x"] + 1.0)
    model = pam2exu.load(path)
    model.elements.remove(model["motor"])
    with pytest.raises(pam2exu.MobilityError):
        pam2exu.run(model, analysis="centre", steps=4)


def test_an_analysis_option_is_read_from_its_declaration(monkeypatch, capsys):
    """``tolerance``, declared once in ``registry.OPTIONS``: the model's attribute and its
    default, the loader's key, the range checked, run's keyword (another one a TypeError),
    the job's value, the command line's --tolerance (its help; refused for an analysis
    whose entry does not name it) all follow the declaration, changed here."""
    from dataclasses import replace

    import argparse

    from pam2exu.analyses.job import prepare
    from pam2exu.cli import main
    from pam2exu.console import check_analysis_options
    from pam2exu.model import Analysis, loader

    path = str(ROOT / "examples" / "four_bar.toml")
    declared = registry.OPTIONS["tolerance"]
    assert Analysis().tolerance == declared.default == 1e-8
    assert "tolerance" in loader._ANALYSIS_KEYS and "tolerance" in Analysis.EXTENSIONS
    assert registry.analyses_reading("tolerance") == ["dynamic"]
    monkeypatch.setitem(registry.OPTIONS, "tolerance", replace(
        declared, high=1e-6, owner="a test's", help="the help of the declaration"))
    assert Analysis(tolerance=1e-5).problems() == [
        "tolerance must be a number in (0, 1e-06], the error allowed per unit of a "
        "coordinate or rate, got 1e-05"]
    assert prepare(path, "dynamic", steps=2, tolerance=1e-7).options["tolerance"] == 1e-7
    with pytest.raises(TypeError, match="unexpected keyword argument 'tolerence'"):
        prepare(path, "dynamic", steps=2, tolerence=1e-7)
    with pytest.raises(SystemExit):
        main(["run", "--help"])
    assert "the help of the declaration" in " ".join(capsys.readouterr().out.split())
    assert main(["run", path, "-a", "kinematic", "--tolerance", "1e-9"]) == 2
    assert capsys.readouterr().err == (
        "pam2exu: command line: --tolerance is a test's (dynamic); the kinematic analysis "
        "does not use it: drop --tolerance\n")
    monkeypatch.setitem(registry.ANALYSES, "assembly", replace(
        registry.ANALYSES["assembly"], options=("tolerance",)))
    given = argparse.Namespace(analysis="assembly", energy=None,
                               **{**dict.fromkeys(registry.OPTIONS), "tolerance": 1e-9})
    assert check_analysis_options(given, pam2exu.load(path)) is None    # now it reads it


def test_the_options_document_themselves_in_the_analysis_settings(monkeypatch):
    """``Model.analysis``'s docstring (and so docs/api.md) has each option's entry, written
    from its declaration: its readers, what it is, its range and default."""
    from dataclasses import replace

    from pam2exu.model import Analysis

    entry = registry.OPTIONS["tolerance"].parameter_doc()
    assert entry in Analysis.__doc__ and entry.startswith("    tolerance : float\n")
    words = " ".join(entry.split())
    assert "of ``dynamic``, which the other analyses ignore" in words
    assert "0 < tolerance ≤ 0.01, default 1e-08." in words
    monkeypatch.setitem(registry.ANALYSES, "assembly", replace(
        registry.ANALYSES["assembly"], options=("tolerance",)))
    assert "of ``assembly`` and ``dynamic``," in " ".join(
        registry.OPTIONS["tolerance"].parameter_doc().split())


def test_every_analysis_and_backend_of_the_registry_resolves():
    for a in registry.ANALYSES.values():
        assert callable(registry.resolve(a.function)), a.name
        assert registry.analysis_type(a.alias) is a
    for b in registry.BACKENDS.values():
        backend = b.create()
        assert backend.name == b.name and hasattr(backend.Settings(), "tolerance")
        if backend.moves_free_solids:        # the equilibrium analysis calls it
            assert callable(getattr(backend, "static_equilibrium", None)), b.name


# ---- docs/architecture.md stays true -----------------------------------------------------

ARCHITECTURE = ROOT / "docs" / "architecture.md"


def _named_files() -> set[str]:
    """The files and folders docs/architecture.md names: `pam2exu/…`, `docs/…`, `tests/…`,
    `references/`, `benchmarks/`, and the bare `x.py` of a row that names its folder."""
    text = ARCHITECTURE.read_text(encoding="utf-8")
    named = set(re.findall(r"`((?:pam2exu|docs|tests|references|benchmarks)/[\w/.]*)`", text))
    for row in text.splitlines():
        folder = re.match(r"\| `((?:pam2exu|benchmarks)/\w*/?)`", row)
        if folder and folder.group(1).endswith("/"):
            named |= {folder.group(1) + f for f in re.findall(r"`(\w+\.py)`", row)}
    return named


def test_every_file_the_architecture_page_names_exists():
    named = _named_files()
    assert len(named) > 40
    assert [n for n in sorted(named) if not (ROOT / n).exists()] == []


def test_every_module_of_the_package_is_on_the_architecture_page():
    named = {n for n in _named_files() if n.endswith(".py")}
    modules = {str(p.relative_to(ROOT)) for p in PACKAGE.rglob("*.py")
               if p.name not in ("__init__.py", "__main__.py")}
    assert sorted(modules - named) == []

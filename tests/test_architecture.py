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


def _imports(module: str) -> tuple[set[str], set[str]]:
    """(module-level, function-level) pam2exu imports of a module; ``if TYPE_CHECKING:``
    blocks (annotations only, never run) are left out."""
    path = MODULES[module]
    tree = ast.parse(path.read_text(encoding="utf-8"))
    top, inner = set(), set()

    def visit(node, in_function):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            return
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            (inner if in_function else top).update(
                _target(module, node, path.name == "__init__.py"))
        for child in ast.iter_child_nodes(node):
            visit(child, in_function or isinstance(node, (ast.FunctionDef,
                                                          ast.AsyncFunctionDef, ast.Lambda)))
    visit(tree, False)
    return top, inner


GRAPH = {m: _imports(m) for m in MODULES}


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
    top, _ = GRAPH["pam2exu.analyses.job"]
    assert {"pam2exu.registry", "pam2exu.backend", "pam2exu.model", "pam2exu.model.solid",
            "pam2exu.analyses.checks"} <= top
    assert _cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert _cycle({"a": {"b"}, "b": {"c"}}) is None


def test_the_import_graph_has_no_cycle():
    """Module-level imports, with every package's __init__, form no cycle."""
    assert _cycle({m: top for m, (top, _) in GRAPH.items()}) is None


def test_no_import_inside_a_function_dodges_a_cycle():
    """Imports of pam2exu modules inside functions (kept lazy so that ``import pam2exu``
    loads neither Exudyn nor matplotlib) would form no cycle at module level either."""
    assert _cycle({m: top | inner for m, (top, inner) in GRAPH.items()}) is None


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
        calls.append(job.analysis)
        check_mobility(job, job.mech.initial_q())
        q = positions(job, redundant=False)
        return collect(job, q + 1.0)

    entry = registry.AnalysisType("centre", "centre_ca", frozenset({"position"}), driven=True,
                                  at_start=False, summary="a test", function=centre)
    monkeypatch.setitem(registry.ANALYSES, "centre", entry)
    path = ROOT / "examples" / "four_bar.toml"
    res = pam2exu.run(path, analysis="centre_ca", steps=4)
    kin = pam2exu.run(path, analysis="kinematic", steps=4, outputs=list(res.columns))
    assert calls == ["centre"] and res.analysis == "centre"
    assert res.columns == kin.columns and "motor.f(t)" in res.columns
    np.testing.assert_array_equal(res["crank.x"], kin["crank.x"] + 1.0)
    model = pam2exu.load(path)
    model.elements.remove(model["motor"])
    with pytest.raises(pam2exu.MobilityError):
        pam2exu.run(model, analysis="centre", steps=4)


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

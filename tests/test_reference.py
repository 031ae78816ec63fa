"""The element reference agrees with the contract and cannot drift from the declarations.

Reference: the model-format contract, kept verbatim in tests/data/model-format-contract.md
(a copy of shared/spec/model-format.md). Its tables are parsed here and compared with the
element declarations (pam2exu/elements/) the reference pages are generated from.
"""
import dataclasses
import importlib.util
import re
import subprocess
import sys
from pathlib import Path

import pytest

from pam2exu import reference
from pam2exu.model.solid import SOLID_OUTPUTS
from pam2exu.elements import ACCELERATION, ALIASES, CLEARANCE, ELEMENTS, FORCE, POSITION, VELOCITY
from pam2exu.laws import LAW_ALIASES, LAWS
from pam2exu.model.analysis import Analysis
from pam2exu.model.solid import Solid
from pam2exu.registry import ANALYSES, OPTIONS

ROOT = Path(__file__).resolve().parents[1]
CONTRACT = (ROOT / "tests" / "data" / "model-format-contract.md").read_text(encoding="utf-8")
PAGES = [ROOT / "docs" / "model-format.md", ROOT / "docs" / "glossary.md"]
#: the contract's types: every type but those an extension of the format adds
#: (``Element.extension``), which the contract's tables do not list
CONTRACT_TYPES = [kind for kind, cls in ELEMENTS.items() if not cls.extension]


def _section(title: str) -> str:
    return re.search(rf"^## {re.escape(title)}.*?\n(.*?)(?=^## |\Z)", CONTRACT, re.S | re.M)[1]


def _rows(title: str) -> list[list[str]]:
    """The cells of the first Markdown table of a contract section (header excluded)."""
    lines = [ln for ln in _section(title).splitlines() if ln.startswith("|")]
    return [[c.strip() for c in ln.strip("|").split("|")] for ln in lines[2:]]


def _names(cell: str) -> list[str]:
    return re.findall(r"`([^`]+)`", cell)


def test_contract_copy_is_the_shared_contract():
    shared = ROOT.parent / "shared" / "spec" / "model-format.md"
    if not shared.exists():
        pytest.skip("shared/spec is not next to this clone")
    assert shared.read_text(encoding="utf-8") == CONTRACT


def test_element_table_matches_the_contract():
    """Type, alias, anchor kinds, keys and the action text, row by row and in order."""
    rows = _rows("Elements")
    assert [_names(r[0])[0] for r in rows] == CONTRACT_TYPES
    for (kinds, anc1, anc2, keys, action) in rows:
        kind, alias = _names(kinds)
        cls = ELEMENTS[kind]
        assert cls.alias == alias and ALIASES[alias] == kind
        cells = [anc1, anc2][:len(cls.anchors)]
        assert [c for c in (anc1, anc2)[len(cls.anchors):]] == ["–"] * (2 - len(cls.anchors))
        for k, cell in enumerate(cells):
            assert cls.anchors[k] in cell.split()[0:2], (kind, k, cell)
            named = re.search(r"\((\w+)\)|point (\w) of", cell)      # (guide), point P of
            if named:
                assert cls.roles[k] == (named[1] or named[2]), (kind, k, cell)
        declared = [re.split(r"[ =]", n)[0] for n in _names(keys)]
        assert [n for n in declared if not n.startswith('"')] == [
            k for k, p in cls.params.items() if not p.extension], kind   # clearance.md's keys
        assert cls.summary == action, kind


def test_output_table_matches_the_contract():
    rows = {r[0]: [v.strip() for v in r[1].split(",")] for r in _rows("Output variables")}
    assert rows.pop("solid") == [v.name for v in SOLID_OUTPUTS]
    assert rows == {kind: [v.name for v in ELEMENTS[kind].outputs]
                    for kind in CONTRACT_TYPES if ELEMENTS[kind].outputs}


def test_contract_output_meanings_are_in_the_declarations():
    """The contract's words on who acts on whom, and where, are in each force output's
    meaning (which the reference pages and `pam2exu elements` print)."""
    rows = {r[0]: r[2].replace("-", "−") for r in _rows("Output variables")}
    must = {"fixed": ["receives", "local origin"], "revolute": ["solid 1 exerts on solid 2"],
            "prismatic": ["solid 1 exerts on solid 2", "defining point of solid 2's line"],
            "pin_slot": ["(guide)", "solid 2", "pin"],
            "transmission": ["solid 2 receives", "−T·Parell on solid 1", "(T−1)·Parell on the arm",
                             "no tooth force enters the bearings"],
            "spring": ["attraction"], "angular_actuator": ["on solid 2"],
            "linear_actuator": ["repulsion between P and Q"]}
    for kind, words in must.items():
        meanings = " ".join(v.meaning for v in ELEMENTS[kind].outputs).replace("guide (solid 1)",
                                                                               "solid 1 (guide)")
        for word in words:
            assert word in rows[kind], (kind, word)      # the contract says it
            assert word in meanings, (kind, word)        # and so does the declaration


def test_law_table_matches_the_contract():
    rows = _rows("Time laws")
    names = {_names(r[0])[0]: (_names(r[0])[1:] or [None])[0] for r in rows}
    assert list(names) == list(LAWS)
    assert {alias: law for law, alias in names.items() if alias} == LAW_ALIASES


def test_solid_and_analysis_keys_match_the_contract():
    solid_keys = [k for r in _rows("Solids") for k in r[0].split(", ")]
    assert solid_keys == [f.name for f in dataclasses.fields(Solid)
                          if f.name != "position" and f.name not in Solid.EXTENSIONS]
    assert [r[0] for r in _rows("Analysis")] == [f.name for f in dataclasses.fields(Analysis)
                                                 if f.name not in Analysis.EXTENSIONS]
    # documented in docs/model-format.md; the analysis options (tolerance:
    # shared/spec/dynamics.md's) are the registry's
    assert Analysis.EXTENSIONS == ("backend", *OPTIONS) and "tolerance" in OPTIONS
    assert Solid.EXTENSIONS == ("Dx", "Dy", "Dfi")                   # dynamics.md


def test_levels_of_the_reference_are_those_the_analyses_use():
    """Which analyses give each kind of output (the contract's analysis table: assembly
    gives only the solids' x, y, fi; clearance.md: clearance gives the solids' x, y, fi and
    its clearance parameters; dynamics.md: equilibrium gives quasi_static's outputs, dynamic
    kinetostatic's), as the registry declares and the pages say (an analysis added since
    is its own test's)."""
    known = ("assembly", "quasi_static", "kinematic", "kinetostatic", "clearance",
             "equilibrium", "dynamic")

    def shown(names: str) -> str:
        return ", ".join(n for n in names.split(", ") if n in known)
    expected = {POSITION: "quasi_static, kinematic, kinetostatic, equilibrium, dynamic",
                VELOCITY: "kinematic, kinetostatic, dynamic",
                ACCELERATION: "kinematic, kinetostatic, dynamic",
                FORCE: "quasi_static, kinetostatic, equilibrium, dynamic",
                CLEARANCE: "clearance"}
    for level, analyses in expected.items():
        assert shown(reference._analyses(level)) == analyses
        assert set(analyses.split(", ")) == {
            a.name for a in ANALYSES.values() if level in a.levels and a.name in known
            and (a.element_outputs or level == CLEARANCE)}
    assert shown(reference._analyses(POSITION, "solid")) == ", ".join(known)


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_generated_regions_are_current(page):
    text = page.read_text(encoding="utf-8")
    assert reference.regions(text)
    assert reference.refresh(text) == text, (
        f"{page.name} is stale: run python -m pam2exu.reference docs/model-format.md "
        "docs/glossary.md")


def test_refresh_rewrites_a_stale_region_and_check_fails(tmp_path):
    page = tmp_path / "p.md"
    page.write_text("x\n<!-- BEGIN generated: laws -->\nold\n<!-- END generated: laws -->\n",
                    encoding="utf-8")
    assert reference.main(["--check", str(page)]) == 1
    assert reference.main([str(page)]) == 0
    assert "`bezier_c2`" in page.read_text(encoding="utf-8")
    assert reference.main(["--check", str(page)]) == 0


def test_model_format_page_has_every_element_key_and_output():
    text = PAGES[0].read_text(encoding="utf-8")
    for kind, cls in ELEMENTS.items():
        section = text.split(f'<a id="{kind}"></a>')[1].split("<a id=")[0]
        for key in cls.keys():
            assert f"| `{key}` |" in section, (kind, key)
        for v in cls.outputs:
            assert f"`<name>.{v.name}` | {v.unit} |" in section, (kind, v.name)


def _free_body_types() -> tuple[str, ...]:
    """FREE_BODY_TYPES of docs/make_free_body.py (docs tooling, loaded by its path)."""
    spec = importlib.util.spec_from_file_location("make_free_body",
                                                  ROOT / "docs" / "make_free_body.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["make_free_body"] = module      # its dataclasses look their module up
    spec.loader.exec_module(module)
    return module.FREE_BODY_TYPES


def test_glossary_has_a_sketch_for_every_force_output_and_load():
    FREE_BODY_TYPES = _free_body_types()
    text = PAGES[1].read_text(encoding="utf-8")
    for kind, cls in ELEMENTS.items():
        if any(v.level == FORCE for v in cls.outputs) or kind in FREE_BODY_TYPES:
            assert f"](img/fbd_{kind}.png)" in text
            assert (ROOT / "docs" / "img" / f"fbd_{kind}.png").exists(), kind


@pytest.mark.parametrize("name", ["pin_slot", "piu_guia"])
def test_cli_elements_shows_one_type(name):
    done = subprocess.run([sys.executable, "-m", "pam2exu", "elements", name],
                          capture_output=True, text=True, cwd=ROOT)
    assert done.returncode == 0, done.stderr
    assert "`anc1` | line of solid 1 (guide)" in done.stdout
    assert "`<name>.Fnormal` | N | quasi_static, kinetostatic" in done.stdout


def test_cli_elements_lists_every_type_and_law():
    done = subprocess.run([sys.executable, "-m", "pam2exu", "elements"],
                          capture_output=True, text=True, cwd=ROOT)
    assert done.returncode == 0
    for kind, cls in ELEMENTS.items():
        assert f"{kind} [{cls.alias}]" in done.stdout
    for law in LAWS:
        assert f"`{law}`" in done.stdout


def test_cli_elements_unknown_type_is_a_model_error():
    done = subprocess.run([sys.executable, "-m", "pam2exu", "elements", "articulation"],
                          capture_output=True, text=True, cwd=ROOT)
    assert done.returncode == 2
    assert "unknown element type 'articulation'" in done.stderr
    assert "articulacio" in done.stderr


def test_a_type_an_extension_adds_is_marked_as_one():
    """``Element.extension``: its section says so (the contract's types say nothing)."""
    from dataclasses import dataclass

    @dataclass(eq=False)
    class Rod(ELEMENTS["linear_actuator"]):
        type, extension = "rod", "rod.md"
    assert "An extension of the format (rod.md), not one of PAM's types." in \
        reference.element_markdown(Rod)
    assert "extension" not in reference.element_markdown(ELEMENTS["revolute"])


def test_migration_page_maps_every_pam_element_and_law():
    text = (ROOT / "docs" / "migrating.md").read_text(encoding="utf-8")
    for kind in CONTRACT_TYPES:
        assert f"`{kind}` (`{ELEMENTS[kind].alias}`)" in text, kind
    for law in LAWS:
        assert f'`"{law}"`' in text, law
    for alias in LAW_ALIASES:
        assert f'`"{alias}"`' in text, alias


def test_the_ranges_on_the_model_format_page_are_those_of_limits():
    """docs/model-format.md, "Ranges, names and encodings", states pam2exu/limits.py."""
    from pam2exu import limits
    section = PAGES[0].read_text(encoding="utf-8").split("## Ranges, names and encodings")[1]
    section = section.split("\n## ")[0]
    for value in (limits.LENGTH, limits.ANGLE, limits.VALUE, *limits.T_END):
        assert f"{value:.0e}" in section, value
    assert f"| `steps` | 1 … {limits.SOLVE_STEPS:,} |" in section           # one solve a step
    assert f"at most {limits.SOLVE_STEPS:,} position solves" in section
    assert f"{limits.MEMORY // 2**30} GiB" in section and f"at most {limits.NAME}" in section
    assert f"at most {limits.MODEL_NAME} characters" in section

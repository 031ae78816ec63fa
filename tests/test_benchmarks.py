"""docs/performance.md's sections (benchmarks/): a full regeneration keeps the sections other
scripts wrote alone, and issue 25's targets section has one row per row of the issue's table
with a verdict. Never a time: only the page's structure."""
from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path

import pytest

from benchmarks import targets
from benchmarks.dynamics import replace_section
from benchmarks.page import sections, write_page

OLD = """# Performance

## Targets

old table

<!-- targets of issue 25: written by benchmarks/targets.py (it alone) -->
## Targets of issue 25
| a | 0.9× | ≤ 1.0× | met |
<!-- end of targets of issue 25 -->

## 1. Work

old numbers

<!-- section 9: written by benchmarks/studies.py (it alone) -->
## 9. Studies
old study
<!-- end of section 9 -->

<!-- natural backend speed: written by benchmarks/natural_speed.py (it alone) -->
## 10. The natural backend
| b | 1.3× | ≤ 1.0× | not met |
<!-- end of natural backend speed -->

<!-- section predictor: written by benchmarks/predictor.py (it alone) -->
## The predictor
| c | 0.9× | ≤ 1.0× | met |
<!-- end of section predictor -->
"""

#: what a full regeneration writes: its own sections, section 9 measured anew
NEW = """# Performance

## Targets

new table

## 1. Work

new numbers

<!-- section 9: written by benchmarks/studies.py (it alone) -->
## 9. Studies
new study
<!-- end of section 9 -->
"""

ROOT = Path(__file__).resolve().parents[1]


def block(text, name):
    return re.search(rf"<!-- {name}: written.*?<!-- end of {name} -->", text, re.S).group(0)


def test_a_full_regeneration_keeps_the_sections_written_alone(tmp_path):
    """The regenerated page has its own numbers and section 9 anew, and every section that
    another script wrote alone, unchanged and in its place: issue 25's targets before
    section 1, the natural backend's and the predictor's at the end (before: the page was
    written from the regeneration's lines alone, and those three were lost)."""
    page = tmp_path / "performance.md"
    page.write_text(OLD, encoding="utf-8")
    write_page(page, NEW)
    kept = [block(OLD, n) for n in ("targets of issue 25", "natural backend speed",
                                    "section predictor")]
    expected = NEW.replace("## 1. Work", kept[0] + "\n\n## 1. Work") + "\n" + kept[1] + \
        "\n\n" + kept[2] + "\n"
    assert page.read_text(encoding="utf-8") == expected
    assert "old study" not in expected and "old numbers" not in expected
    write_page(page, NEW)                       # a second regeneration: the same page
    assert page.read_text(encoding="utf-8") == expected


def test_a_full_regeneration_keeps_the_sections_written_by_hand(tmp_path):
    """A section written by hand from the measurements it names is kept as a script's is
    (before: only ``written by benchmarks/`` markers were, and a regeneration would have
    dropped the page's ~1,100 lines of hand-written analysis)."""
    hand = ("<!-- fixed costs: written by hand from `python benchmarks/fixed_costs.py` -->\n"
            "## Fixed costs\nmeasured by hand\n<!-- end of fixed costs -->")
    page = tmp_path / "performance.md"
    page.write_text(OLD.replace("<!-- section 9:", hand + "\n\n<!-- section 9:"),
                    encoding="utf-8")
    write_page(page, NEW)
    text = page.read_text(encoding="utf-8")
    assert hand in text and text.index(hand) < text.index("## 9. Studies")
    # the page itself: every hand-written section is one that a regeneration keeps
    real = (ROOT / "docs" / "performance.md").read_text(encoding="utf-8")
    marked = re.findall(r"^<!-- ([^:\n]+): written by hand", real, re.M)
    assert {"rows not met", "studies on 2 workers", "fixed costs"} <= set(marked)
    assert set(marked) <= set(sections(real))


def test_a_new_section_goes_before_the_line_asked(tmp_path):
    page = tmp_path / "performance.md"
    page.write_text(NEW, encoding="utf-8")
    lines = [targets.BEGIN, "## Targets of issue 25", "| x |", targets.END]
    replace_section(page, lines, targets.BEGIN, targets.END, before="## 1. Work")
    assert page.read_text(encoding="utf-8") == NEW.replace(
        "## 1. Work", "\n".join(lines) + "\n\n## 1. Work")


INFO = {"date (UTC)": "2026-11-28 03:00", "CPU": "a CPU", "cores": "2", "Python": "3.11",
        "Exudyn": "1.13", "pam2exu": "0.1.0, commit abc"}
ROW = re.compile(r"^\| (?P<what>[^|]+) \| (?P<measured>[^|]+) \| (?P<target>[≤≥] [\d.]+×) \| "
                 r"(?P<verdict>[^|]+) \| (?P<from>[^|]+) \| (?P<beside>[^|]+) \|$", re.M)


def rows_of(lines):
    text = "\n".join(lines)
    assert text.startswith(targets.BEGIN) and text.endswith(targets.END)
    return [m.groupdict() for m in ROW.finditer(text)]


def test_the_targets_section_has_every_row_of_the_issue_with_its_verdict():
    """Two passes of made-up ratios: a row per row of the issue's table, in its order, the
    mean and range of the passes, and the verdict: met by both passes, by one, by none, or
    not measured (a failure)."""
    sizes = replace(targets.QUICK, passes=2)
    measured = targets.Measured(sizes, info=INFO, loads=[((1, 1, 1), (2, 2, 2))] * 2)
    pairs = {"locomotive": (3.0, 4.0), "all_elements": (0.9, 1.1), "four_bar_short": (0.9, 1.3),
             "chain": (1.2, 1.4), "natural_per_step": (0.4, 0.5), "study": (float("nan"),) * 2,
             "workers": (1.8, 1.6), "positions": (1.0, 0.98), "predictor": (0.9, 0.95)}
    for key, ratios in pairs.items():
        measured.figures[key] = [targets.Figure(key, r, f"{r} s / 1 s") for r in ratios]
    rows = rows_of(targets.section(measured))
    assert [r["what"] for r in rows] == [t.what for t in targets.targets(sizes)]
    assert len(rows) == 9
    verdicts = {t.key: r["verdict"] for t, r in zip(targets.targets(sizes), rows)}
    assert verdicts == {"locomotive": "met", "all_elements": "met", "four_bar_short":
                        "met in 1 of 2 passes", "chain": "not met", "natural_per_step":
                        "not met", "study": "not measured", "workers": "met in 1 of 2 passes",
                        "positions": "met", "predictor": "met"}
    assert rows[0]["measured"] == "3.50× (3.00–4.00× over 2 passes)"
    assert rows[6]["target"] == "≥ 1.7×" and rows[7]["target"] == "≤ 1.0×"
    assert rows[0]["from"].startswith("pass 1: 3.00× = 3.0 s / 1 s; pass 2: 4.00×")


@pytest.mark.long
def test_the_quick_run_writes_the_section(tmp_path):
    """``targets.py --quick`` (tiny sizes, one pass) measures every row: nine rows, each with
    a ratio and a verdict, none failed; the section says the run was a smoke run."""
    targets.main(["--quick", "--out", str(tmp_path)])
    text = (tmp_path / "performance.md").read_text(encoding="utf-8")
    lines = block(text, "targets of issue 25").splitlines()
    rows = rows_of(lines)
    assert len(rows) == 9
    for row in rows:
        assert re.fullmatch(r"\d+\.\d\d×", row["measured"]), row
        assert row["verdict"] in ("met", "not met"), row
    assert "smoke run" in text and "Sizes reduced" in text

"""What a new user got wrong and pam2exu let pass or explained badly (issue 22): each test
fails on the code before the fix."""
from __future__ import annotations

from pathlib import Path

import pytest

from pam2exu import ModelError, load, loads

ROOT = Path(__file__).resolve().parents[2]

SOLIDS = """
[[solid]]
name = "ground"
points = { O = [0.0, 0.0] }

[[solid]]
name = "crank"
points = { O = [0.0, 0.0], A = [0.1, 0.0] }
"""

DRIVE = """
[[element]]
type = "revolute"
name = "O"
anc1 = "ground.O"
anc2 = "crank.O"

[[element]]
type = "fixed"
anc1 = "ground"

[[element]]
type = "angular_actuator"
name = "motor"
anc1 = "ground"
anc2 = "crank"
"""


def error_of(text: str, tmp_path=None) -> ModelError:
    """The ModelError of a model that must fail (read from a file when tmp_path is given)."""
    with pytest.raises(ModelError) as info:
        if tmp_path is None:
            loads(text)
        else:
            path = tmp_path / "m.toml"
            path.write_text(text, encoding="utf-8")
            load(path)
    return info.value


# ---- C given as a number, or nested -----------------------------------------------------------

def test_constants_given_as_one_number_are_refused(tmp_path):
    """C = 360.0 was read silently as C1 = 360 (the motor stood still at 360 rad)."""
    error = error_of(SOLIDS + DRIVE + "C = 360.0\n", tmp_path)
    text = str(error)
    assert len(error.problems) == 1
    assert text.startswith(str(tmp_path / "m.toml") + ": [[element]] #3 'motor' "
                                                      "(angular_actuator): ")
    assert "'C' must be a list, C = [C1, C2, C3, C4]" in text
    assert "write C = [360.0] if it is C1" in text


def test_nested_constants_say_the_list_must_be_flat():
    """C = [[1.0, 2.0]] answered "'C' must hold numbers, got [1.0, 2.0]"."""
    text = str(error_of(SOLIDS + DRIVE + "C = [[1.0, 2.0]]\n"))
    assert text.endswith("'C' must be a flat list of numbers, C = [C1, C2, …] (constants C1…C4 "
                         "of the law), got a nested list [[1.0, 2.0]]")


# ---- values quoted once, and not without end ----------------------------------------------------

def test_an_anchor_that_is_not_a_string_is_quoted_once():
    """anc1 = ["crank"] gave "anc1 = '['crank']': no solid '['crank']'"."""
    text = str(error_of(SOLIDS + '[[element]]\ntype = "revolute"\nanc1 = ["crank"]\n'
                                 'anc2 = "crank.O"\n'))
    assert "'[" not in text and "]'" not in text
    assert text.endswith("'anc1' must be a string naming a point (\"solid.point\", or \"solid\" "
                         "for its origin), got ['crank']")


def test_a_variation_anchor_that_is_not_a_string_is_quoted_once():
    text = str(error_of(SOLIDS + '[[variation]]\nanchor = ["crank"]\ndx = 1e-3\n'))
    assert "(anchor ['crank'])" in text and "'[" not in text


def test_a_huge_value_is_echoed_cut():
    """A 900,000-character type was echoed whole (and difflib took seconds on it)."""
    text = str(error_of(SOLIDS + f'[[element]]\ntype = "{"x" * 900_000}"\n'))
    assert len(text) < 600
    assert f"unknown element type '{'x' * 80}… (900000 characters)'" in text


def test_a_long_list_of_problems_is_cut_with_the_count():
    """2,000 problems were listed in 385 kB: the message lists 20 and says how many more."""
    text = "".join(f'[[solid]]\nname = "s{k}"\nmass = -1.0\n' for k in range(2000))
    error = error_of(text)
    assert len(error.problems) == 2000
    lines = str(error).splitlines()
    assert lines[0] == "<string>: 2000 problems in the model:"
    assert len(lines) == 22
    assert lines[1] == "  - [[solid]] #1 's0': mass is negative (-1.0): it must be ≥ 0"
    assert lines[-1].startswith("  … and 1980 more")


# ---- encodings ----------------------------------------------------------------------------------

@pytest.mark.parametrize("encoding,name", [("utf-16", "UTF-16"), ("utf-16-be", "UTF-16"),
                                           ("utf-16-le", "UTF-16"), ("utf-32", "UTF-32")])
def test_a_utf16_file_says_to_save_it_as_utf8(tmp_path, encoding, name):
    """Notepad's "Unicode" (UTF-16 with BOM FF FE) gave "not valid TOML: Invalid statement
    (at line 1, column 1)"; without a BOM it is known by its NUL bytes."""
    path = tmp_path / "notepad.toml"
    path.write_bytes((SOLIDS + DRIVE + "C = [0.0, 1.0]\n").encode(encoding))
    with pytest.raises(ModelError) as info:
        load(path)
    text = str(info.value)
    assert text.startswith(f"{path}: the file is {name} text")
    assert "save the file as UTF-8" in text and "TOML" not in text


def test_utf8_with_a_byte_order_mark_loads(tmp_path):
    path = tmp_path / "bom.toml"
    path.write_bytes((SOLIDS + DRIVE + "C = [0.0, 1.0]\n").encode("utf-8-sig"))
    model = load(path)
    assert [s.name for s in model.solids] == ["ground", "crank"] and model.encoding == "utf-8"


# ---- degrees in a radians model -----------------------------------------------------------------

def test_run_warns_of_degrees_in_a_radians_model_as_check_does(tmp_path, capsys):
    """fi = 30.0 and C = [30, 360]: check warned, run said nothing and turned the crank
    360 rad. run issues InputWarning with check's texts, naming the solid and the element."""
    import warnings

    from pam2exu import InputWarning, run
    from pam2exu.cli import main
    text = (ROOT / "examples" / "four_bar.toml").read_text()
    text = text.replace("fi = 0.02", "fi = 30.0").replace(
        "C = [0.0, 6.283185307179586, 0.0, 0.0]", "C = [30.0, 360.0]")
    path = tmp_path / "deg.toml"
    path.write_text(text)
    assert main(["check", str(path)]) == 0
    # the CLI's warnings: one line each on stderr (issue 22)
    printed = [line.removeprefix("pam2exu: warning: ")
               for line in capsys.readouterr().err.splitlines()
               if line.startswith("pam2exu: warning: ")]
    assert printed == [
        "[[solid]] #2 'crank': fi = 30 rad is more than a full turn (2π = 6.28 rad): did you "
        "give degrees? Write fi in radians (30° = 0.5236 rad), or set angles = \"deg\" in "
        "[model] to give every angle of the model in degrees",
        "[[element]] #6 'motor' (angular_actuator): law 'polynomial' C1 = 30 rad is more than "
        "a full turn (2π = 6.28 rad): did you give degrees? Write C1 in radians (30° = "
        "0.5236 rad), or set angles = \"deg\" in [model] to give every angle of the model in "
        "degrees"]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = run(path, "kinematic", steps=4, outputs=["crank.fi"])
    issued = [str(w.message) for w in caught if issubclass(w.category, InputWarning)]
    assert issued == [f"{path}: {p}" for p in printed]
    assert [w for w in res.warnings if "full turn" in w] == issued
    assert float(res["crank.fi"][-1]) == pytest.approx(390.0, rel=1e-12)   # as written


def test_degrees_models_and_rates_do_not_warn():
    """A law's rates (C2 = 360 rad/s) and a harmonic's ω are no angles; a degrees model says
    what it means."""
    from pam2exu.model.angles import angle_warnings
    text = (ROOT / "examples" / "four_bar.toml").read_text()
    assert not angle_warnings(loads(text.replace("C = [0.0, 6.283185307179586, 0.0, 0.0]",
                                                 "C = [0.0, 360.0, 50.0]")))
    assert not angle_warnings(loads(text.replace("C = [0.0, 6.283185307179586, 0.0, 0.0]",
                                                 'C = [1.0, 0.5, 60.0, 30.0]\nlaw = "harmonic"'
                                                 ).replace('law = "polynomial"\n', "")))
    assert not angle_warnings(loads(text.replace(
        "C = [0.0, 6.283185307179586, 0.0, 0.0]", "C = [30.0, 360.0]").replace(
        'name = "four-bar"', 'name = "four-bar"\nangles = "deg"')))


# ---- laws whose value jumps ----------------------------------------------------------------------

def _all_elements(sun_drive_law: str) -> str:
    """examples/all_elements.toml with the law of its gear train's 'sun_drive' replaced."""
    text = (ROOT / "examples" / "all_elements.toml").read_text()
    old = 'law = "ramp"\nC = [0.2, 0.8, 0.0, 0.5]'
    assert old in text
    return text.replace(old, sun_drive_law)


@pytest.mark.parametrize("C", ["[0.2, 0.200000000001, 0.0, 0.5]",       # a row inside it
                               "[0.199999999999, 0.2, 0.0, 0.5]",       # ends on a row
                               "[0.201, 0.201000000001, 0.0, 0.01]"])   # between two rows
def test_a_ramp_shorter_than_a_step_names_the_element_and_its_constants(C):
    """A ramp lasting 1e-12 s on the gear train (fuzz): before, "'sun_drive' turns 2.5e+09
    rad per step" under [analysis], or a run whose sun jumped between two rows."""
    import pam2exu
    model = loads(_all_elements(f'law = "ramp"\nC = {C}'))
    with pytest.raises(ModelError) as info:
        pam2exu.run(model, "kinematic", steps=200, outputs=["sun.fi"])
    (problem,) = info.value.problems
    assert problem.where == "[[element]] #13 'sun_drive' (angular_actuator)"
    assert problem.message.startswith(f"law 'ramp' with C = {C} goes from C3 = 0 to C4 = ")
    assert "in C2 − C1 = 1e-12 s, less than a step of the run (0.005 s): its value jumps" \
        in problem.message


def test_a_tiny_jump_that_sub_steps_follow_still_runs():
    """A ramp of 1e-12 s that moves 1e-9 rad: followed in sub-steps, the run is exact."""
    import pam2exu
    model = loads(_all_elements('law = "ramp"\nC = [0.201, 0.201000000001, 0.0, 1e-9]'))
    res = pam2exu.run(model, "kinematic", steps=200, outputs=["sun_drive.f(t)"])
    f = res["sun_drive.f(t)"]
    assert f[40] == 0.0 and f[41] == 1e-9


def test_a_transition_law_missing_constants_is_warned_of(tmp_path, capsys):
    """bezier_c2 with C = [-0.2173, 0.3127, 32.0427] (fuzz): C4 is 0 by the format's rule,
    most likely not what was meant. run warns, and check prints the same text."""
    import warnings

    from pam2exu import InputWarning, run
    from pam2exu.cli import main
    path = tmp_path / "three.toml"
    path.write_text(_all_elements('law = "bezier_c2"\nC = [0.2, 0.8, 0.5]'))
    expected = ("[[element]] #13 'sun_drive' (angular_actuator): law 'bezier_c2' is given 3 "
                "constants, C = [0.2, 0.8, 0.5]: C4 is taken as 0, so f goes from C3 = 0.5 to "
                "C4 = 0 between t = 0.2 s and 0.8 s; give the four constants "
                "C = [C1, C2, C3, C4] (start [s], end [s], value before, value after)")
    assert main(["check", str(path)]) == 0
    assert f"pam2exu: warning: {expected}" in capsys.readouterr().err.splitlines()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = run(path, "kinematic", steps=20, outputs=["sun.fi"])
    assert [str(w.message) for w in caught if w.category is InputWarning] == \
        [f"{path}: {expected}"]
    assert f"{path}: {expected}" in res.warnings


# ---- the work of a run: bounded, and shown ----------------------------------------------------

def test_more_steps_than_a_run_takes_is_refused_at_once(tmp_path):
    """steps = 5000000 with one output ran 5 min 23 s, while the docs promise to refuse more
    than 2,000,000 position solves: the bound is a model error, saying how to split."""
    text = (ROOT / "examples" / "four_bar.toml").read_text()
    assert "steps = 200" in text
    error = error_of(text.replace("steps = 200", "steps = 5000000"), tmp_path)
    (problem,) = error.problems
    assert problem.where == "[analysis]"
    assert problem.message.startswith("steps = 5000000 is more than pam2exu runs: one run "
                                      "solves the positions at most 2,000,000 times")
    assert "Use fewer steps" in problem.message and "several runs" in problem.message


def test_a_long_run_shows_its_progress_on_stderr(monkeypatch):
    """A run of several parts (PART_STEPS made 7 here: the rule, not a time, decides) draws
    a bar on stderr when it is a terminal; the results are those of one part to within
    Newton's tolerance."""
    import sys

    import numpy as np

    import pam2exu
    from pam2exu.analyses import positions
    from tests.conftest import Terminal

    monkeypatch.delenv("PAM2EXU_PROGRESS", raising=False)
    path = ROOT / "examples" / "four_bar.toml"
    whole = pam2exu.run(path, "kinematic", steps=50)
    monkeypatch.setattr(positions, "PART_STEPS", 7)
    monkeypatch.setattr(sys, "stderr", Terminal())
    parts = pam2exu.run(path, "kinematic", steps=50)
    bar = sys.stderr.getvalue()
    assert "solving the positions [" in bar and "100%" in bar and bar.endswith("\r")
    for name in whole.columns:
        scale = max(1.0, float(np.max(np.abs(whole[name]))))
        assert np.max(np.abs(parts[name] - whole[name])) < 1e-11 * scale, name


# ---- names in one Unicode form -------------------------------------------------------------------

def test_a_name_with_a_combining_accent_reads_back_from_csv(tmp_path):
    """A solid named 'a' + U+0301 was written as given and read back NFC ('á'): the columns
    differed. Names are put in one form (NFC) on input, anchors too, whichever way typed."""
    import unicodedata

    import numpy as np

    import pam2exu
    decomposed, composed = "cra\u0301nk", "cr\u00e1nk"
    text = (ROOT / "examples" / "four_bar.toml").read_text()
    text = (text.replace('name = "crank"', f'name = "{decomposed}"')
            .replace('anc2 = "crank.O"', f'anc2 = "{decomposed}.O"')     # typed decomposed
            .replace('anc1 = "crank.A"', f'anc1 = "{composed}.A"')       # typed composed
            .replace('anc2 = "crank"', f'anc2 = "{decomposed}"'))
    model = loads(text)
    assert [s.name for s in model.solids][1] == composed
    res = pam2exu.run(model, "kinematic", steps=4, outputs=[f"{decomposed}.*", "motor.f(t)"])
    assert res.columns[0] == f"{composed}.x"
    path = tmp_path / "accent.csv"
    res.to_csv(path)
    back = pam2exu.read_csv(path)
    assert back.columns == res.columns
    assert all(unicodedata.is_normalized("NFC", c) for c in back.columns)
    np.testing.assert_array_equal(back.to_numpy(), res.to_numpy())


def test_a_results_table_made_by_hand_reads_back_the_same():
    """Results built in Python with a decomposed name: its columns are in the one form, and
    indexing by either spelling finds the column."""
    import numpy as np

    from pam2exu import Results, read_csv
    res = Results([0.0, 1.0], {"a\u0301.x": np.array([0.5, 0.25])}, {"a\u0301.x": "m"})
    assert res.columns == ["\u00e1.x"] and res.units["\u00e1.x"] == "m"
    assert "a\u0301.x" in res and res["a\u0301.x"].tolist() == [0.5, 0.25]
    import tempfile
    from pathlib import Path
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "by_hand.csv"
        res.to_csv(path)
        assert read_csv(path).columns == res.columns

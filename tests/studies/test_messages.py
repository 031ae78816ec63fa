"""The variants' errors and warnings grouped by kind (pam2exu/studies/messages.py) and the
warnings of a study's variants (runner.run_variant, StudyResult.warnings, the report).

References: messages of real failures (pam2exu.analyses.failure's texts, a ModelError of a
negative mass, a fault), written out here; a variant's warnings against the warnings a
single ``pam2exu.run`` of the model with its value written into the text by hand issues.
"""
import csv
import doctest
import warnings
from pathlib import Path

import numpy as np

import pam2exu
from pam2exu.cli import main
from pam2exu.studies import messages
from pam2exu.studies.messages import group, head, kind, masked, report_lines, warning_groups
from pam2exu.studies.runner import FAULT

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"

ASSEMBLY = ("SolverError: the mechanism cannot be assembled at t = 0 s: the loop {loop} "
            "cannot close at t = 0 s (its lengths: coupler.A–coupler.B {b} m): where the fixed "
            "links and the actuators ('motor') put them, crank.A and ground.O4 are 0.3 m apart. "
            "The constraints cannot all hold: still violated at the closest configuration: "
            "{violated}. Exudyn said: SolveStatic terminated due to errors")
DEAD = ("SolverError: between t = {t0} s and t = {t1} s (between steps 8 and 9 of 20) the "
        "mechanism reached a singular (dead-point) position: the actuator(s) 'motor' drive it "
        "to a limit position it cannot pass. After it the constraints cannot all hold (still "
        "violated at the closest configuration: 'B' (revolute) by {r}).")


def test_numbers_are_masked_but_not_the_digits_of_names():
    assert masked("'O4' (revolute) by 1.1e-3, body1.fi = -0.5 at t = .25 s (step 8 of 20).") \
        == "'O4' (revolute) by …, body1.fi = … at t = … s (step … of …)."
    assert masked("C2 = 7 rad, B.F1 and 2π = 6.28 rad; 1e+05 N in run-12/a.toml") == \
        "C2 = … rad, B.F1 and 2π = … rad; … N in run-12/a.toml"


def test_a_kind_is_the_first_phrase_whatever_follows():
    a = ASSEMBLY.format(loop="coupler –B– rocker –O4– ground –O2– crank –A– coupler", b=0.7,
                        violated="'B' (revolute) by 0.025, 'O2' (revolute) by 0.025")
    b = ASSEMBLY.format(loop="ground –O4– rocker –B– coupler –A– crank –O2– ground", b=0.65,
                        violated="'O4' (revolute) by 0.0125, 'A' (revolute) by 0.0125")
    assert masked(a) != masked(b)                    # the numbers are not all that differ
    assert kind(a) == kind(b) == "SolverError: the mechanism cannot be assembled at t = … s"
    assert kind(DEAD.format(t0=0.4, t1=0.425, r=3e-4)) == (
        "SolverError: between t = … s and t = … s (between steps … and … of …) the "
        "mechanism reached a singular (dead-point) position")
    # a model error's file name alone does not end the head: its place does
    assert head("ModelError: f.toml: [[solid]] #3 'coupler': mass is negative (-1.0): it "
                "must be ≥ 0") == "ModelError: f.toml: [[solid]] #3 'coupler'"
    assert head("ModelError: f.toml: 2 problems in the model:\n  - [[solid]] #2 'crank': x") \
        == "ModelError: f.toml: 2 problems in the model:"
    assert kind(f"{FAULT}: ValueError: boom") == f"{FAULT}: ValueError: boom"
    assert head("SolverError") == "SolverError" and head("") == ""


def test_a_group_shows_its_numbers_range_its_samples_and_its_first_message():
    texts = {3: DEAD.format(t0=0.4, t1=0.425, r=3e-4), 4: DEAD.format(t0=0.375, t1=0.4, r=1e-3),
             9: DEAD.format(t0=0.4, t1=0.425, r=2e-4), 5: "SolverError: other"}
    found = group(sorted(texts.items()))
    assert [(g.samples, g.example) for g in found] == [((3, 4, 9), texts[3]),
                                                        ((5,), "SolverError: other")]
    assert found[0].head == ("SolverError: between t = [0.375 … 0.4] s and t = [0.4 … 0.425] s "
                             "(between steps 8 and 9 of 20) the mechanism reached a singular "
                             "(dead-point) position")
    assert report_lines(found) == [f"  3 × {found[0].head}", "      samples 3, 4, 9",
                                   f"      sample 3: {texts[3]}",
                                   "  1 × SolverError: other", "      samples 5"]


def test_a_head_with_an_ellipsis_of_its_own_is_shown_masked():
    found = group([(0, "E: from 1 … 2 m"), (1, "E: from 1 5 2 m")])
    assert [(g.head, g.samples) for g in found] == [("E: from … … … m", (0, 1))]


def test_a_long_report_counts_what_it_does_not_list():
    found = group((i, f"E{i}: x") for i in range(13)) + group((i, "F: y") for i in range(30))
    lines = report_lines(found, "warnings")
    assert len(lines) == 2 * messages.GROUPS_SHOWN + 1
    assert lines[-1] == "  … and 4 other kinds of warnings"
    many = report_lines(group((i, "F: y") for i in range(30)))
    assert many == ["  30 × F: y", "      samples 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, …"]


def test_a_variant_counts_once_per_kind_of_warning():
    found = warning_groups(["", "W: a at 1 s\nW: a at 2 s\nV: b", "W: a at 3 s"], [0, 1, 2])
    assert [(g.head, g.samples) for g in found] == [("W: a at [1 … 3] s", (1, 2)),
                                                    ("V: b", (1,))]


def test_the_examples_in_the_docstrings_run():
    assert doctest.testmod(messages).failed == 0


WARNING_STUDY = """
[study]
model = "four_bar.toml"
analysis = "kinematic"
steps = 4
t_end = 0.3
method = "grid"
outputs = ["rocker.fi"]
reduce = ["max"]
[[parameter]]
name = "motor.C1"
values = [0.0, 7.0, 0.5, 7.5]
"""


def _single_run_warnings(model_text: str, c1: float, source: str) -> list[str]:
    """'<class>: <first line>' of the warnings a single run issues with the motor's C1."""
    old = "C = [0.0, 6.283185307179586,"
    assert model_text.count(old) == 1
    model = pam2exu.loads(model_text.replace(old, f"C = [{c1!r}, 6.283185307179586,"),
                          source=source)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        pam2exu.run(model, "kinematic", t_end=0.3, steps=4, outputs=["rocker.fi"])
    return [f"{w.category.__name__}: {str(w.message).splitlines()[0]}" for w in caught]


def test_the_variants_warnings_are_counted_by_kind_not_written_to_the_table(tmp_path, capsys):
    """Two variants whose crank starts more than a full turn round (7 and 7.5 rad) warn as a
    single run of each does; the report counts them as one kind; the files keep their
    columns; nothing of the variants' warnings reaches the study's caller."""
    text = (EXAMPLES / "four_bar.toml").read_text()
    (tmp_path / "four_bar.toml").write_text(text)
    (tmp_path / "s.toml").write_text(WARNING_STUDY)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = pam2exu.study(tmp_path / "s.toml", out=tmp_path / "o.csv")
    assert caught == []                              # the nominal model does not warn
    assert result.table["status"].tolist() == ["ok"] * 4
    for i, c1 in enumerate([0.0, 7.0, 0.5, 7.5]):
        single = _single_run_warnings(text, c1, str(tmp_path / "four_bar.toml"))
        assert result.warnings[i] == "\n".join(single)
        assert bool(single) == (c1 > 2 * np.pi)
    assert "C1 = 7 rad is more than a full turn" in result.warnings[1]
    found = result.warning_groups()
    assert [(g.kind, g.samples) for g in found] == [
        (f"InputWarning: {tmp_path / 'four_bar.toml'}: [[element]] #… 'motor' "
         "(angular_actuator)", (1, 3))]
    report = result.report().splitlines()
    k = report.index("variants that warned: 2 of 4")
    assert report[k + 1:k + 4] == [f"  2 × {found[0].head}", "      samples 1, 3",
                                   f"      sample 1: {result.warnings[1]}"]
    header = next(csv.reader(open(tmp_path / "o.csv", encoding="utf-8")))
    assert header == ["sample", "status", "error", "motor.C1", "rocker.fi.max"]
    assert list(result.table) == header
    assert main(["study", str(tmp_path / "s.toml"), "--workers", "1"]) == 0
    assert "variants that warned: 2 of 4" in capsys.readouterr().out


def test_a_study_without_warnings_says_nothing_of_them():
    from pam2exu.studies import loads_study
    result = pam2exu.study(loads_study(WARNING_STUDY.replace("[0.0, 7.0, 0.5, 7.5]", "[0.5]"),
                                       folder=EXAMPLES))
    assert result.warnings.tolist() == [""] and result.warning_groups() == []
    assert "warned" not in result.report()

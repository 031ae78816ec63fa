"""The shipped sweep examples/studies/four_bar_coupler_sweep.toml (docs/studies.md, "A sweep
of the four-bar's coupler length") against the four-bar's transmission angle in closed form.

Reference, nothing from pam2exu: with crank a, coupler b, rocker c, ground d and crank angle
θ, the law of cosines in the triangles (A, B, O4) and (O2, A, O4) gives the angle γ between
coupler and rocker, cos γ = (b² + c² − a² − d² + 2ad cos θ) / (2bc); the transmission angle
is its acute version, μ = arccos |cos γ|. The study's reductions are the min and max of μ
over the rows θ_k = 2π k / steps.
"""
import dataclasses
import math
import re
from pathlib import Path

import numpy as np
import pytest

from pam2exu.studies import load_study
from pam2exu.studies.result import grid_lines
from pam2exu.studies.runner import study as run_study

ROOT = Path(__file__).resolve().parents[2]
SWEEP = ROOT / "examples" / "studies" / "four_bar_coupler_sweep.toml"
#: examples/four_bar.toml: crank a, rocker c, ground d [m]; θ = 2π t
A, C, D = 0.1, 0.3, 0.4
#: few rows, 0 and π among them (where μ is extreme for this crank-rocker)
STEPS = 6


def transmission_angle(a, b, c, d, theta):
    """μ = arccos |(b² + c² − a² − d² + 2ad cos θ) / (2bc)|: the four-bar's transmission
    angle, acute."""
    return np.arccos(np.abs((b * b + c * c - a * a - d * d + 2 * a * d * np.cos(theta))
                            / (2 * b * c)))


@pytest.fixture(scope="module")
def sweep():
    study = dataclasses.replace(load_study(SWEEP), steps=STEPS)
    return study, run_study(study)


def test_the_sweeps_transmission_angles_are_the_closed_forms(sweep):
    study, result = sweep
    theta = 2 * math.pi * np.arange(STEPS + 1) / STEPS
    lengths = result.table["coupler.B.x"]
    assert lengths.tolist() == study.parameters[0].values
    assert set(result.table["status"]) <= {"ok", "rejected"}
    for b, low, high in zip(lengths, result.table["coupler.transmission_angle.min"],
                            result.table["coupler.transmission_angle.max"]):
        mu = transmission_angle(A, b, C, D, theta)
        assert abs(low - mu.min()) <= 1e-9 and abs(high - mu.max()) <= 1e-9, b


def test_the_sweep_accepts_the_lengths_whose_angle_stays_above_40_degrees(sweep):
    _, result = sweep
    theta = 2 * math.pi * np.arange(STEPS + 1) / STEPS
    expected = ["ok" if transmission_angle(A, b, C, D, theta).min() >= math.radians(40)
                else "rejected" for b in result.table["coupler.B.x"]]
    assert result.table["status"].tolist() == expected
    assert expected.count("ok") == 5 and expected.count("rejected") == 3


def test_a_grid_study_prints_each_variant_with_its_values(sweep):
    _, result = sweep
    lines = result.report().splitlines()
    head = next(k for k, line in enumerate(lines) if line.startswith("sample "))
    assert lines[head].split() == ["sample", "status", "coupler.B.x",
                                   "coupler.transmission_angle.min",
                                   "coupler.transmission_angle.max"]
    rows = [line.split() for line in lines[head + 1:]]
    table = result.table
    assert [int(r[0]) for r in rows] == table["sample"].tolist()
    assert [r[1] for r in rows] == table["status"].tolist()
    for k, name in enumerate(("coupler.B.x", "coupler.transmission_angle.min",
                              "coupler.transmission_angle.max"), start=2):
        assert np.allclose([float(r[k]) for r in rows], table[name], rtol=5e-5, atol=0)


def test_grid_lines_leave_an_error_rows_outputs_empty_and_count_the_rest():
    table = {"sample": np.arange(3), "status": np.array(["ok", "error", "rejected"]),
             "p": np.array([1.0, 2.0, 3.0]), "y.min": np.array([0.5, np.nan, 0.25])}
    lines = grid_lines(table, ["p", "y.min"], shown=2)
    assert [line.split() for line in lines[1:3]] == [["0", "ok", "1", "0.5"],
                                                     ["1", "error", "2"]]
    assert lines[3] == "… and the other 1 of the 3 variants (-o OUT writes them all)"
    assert len(grid_lines(table, ["p", "y.min"])) == 4


def test_the_docs_show_the_shipped_sweep_file():
    """docs/studies.md shows the file as shipped (its opening comment aside)."""
    page = (ROOT / "docs" / "studies.md").read_text(encoding="utf-8")
    shown = re.search(r"```toml\n(\[study\]\nmodel = \"\.\./four_bar\.toml\".*?)```", page,
                      re.S).group(1)
    text = SWEEP.read_text(encoding="utf-8")
    assert shown == text[text.index("[study]"):]

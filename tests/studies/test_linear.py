"""The first-order method of a study (pam2exu/studies/linear.py, ``method = "linear"``),
and the linear σ beside a sampled study.

References: the nominal values against a single ``pam2exu.run`` of the model; σ_y(t) and
the reductions' σ against sqrt(Σ (∂y/∂p σ_p)²) computed here from the table's own
columns and the parameters' σ (normal: tol/3; uniform: tol/√3); the Monte-Carlo standard
deviation of ``final`` and ``mean`` reductions against the linear σ within 3 standard
errors of a sample standard deviation, σ/√(2(N − 1)), for tolerances small enough that
the response is linear; the tornado's bars against the contributions.
"""
import math
from pathlib import Path

import numpy as np
import pytest

import pam2exu
from pam2exu.cli import main
from pam2exu.studies import loads_study
from pam2exu.studies.linear import LinearResult
from pam2exu.studies.runner import study

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"

LINEAR = f"""
[study]
model = "{(EXAMPLES / 'slider_crank.toml').as_posix()}"
analysis = "kinetostatic"
steps = 8
t_end = 0.5
method = "linear"
outputs = ["motor.Mz", "slider.x"]
reduce = ["final", "mean", "absmax"]
[[parameter]]
name = "crank.A.x"
distribution = "normal"
tol = 3e-4
[[parameter]]
name = "rod.B.x"
distribution = "uniform"
tol = 3e-4
[[parameter]]
name = "rod.mass"
distribution = "normal"
std = 0.05
[[requirement]]
output = "slider.x.final"
min = 0.3
"""


@pytest.fixture(scope="module")
def linear():
    return study(loads_study(LINEAR, source=str(ROOT / "linear.toml")))


def test_the_nominal_values_are_a_single_run(linear):
    res = pam2exu.run(str(EXAMPLES / "slider_crank.toml"), "kinetostatic", steps=8,
                      t_end=0.5, outputs=["motor.Mz", "slider.x"])
    assert isinstance(linear, LinearResult)
    assert np.array_equal(linear.table["t"], res.t)
    for c in ("motor.Mz", "slider.x"):
        assert np.array_equal(linear.table[c], res[c])
    row = {r.output: r for r in linear.summary}
    assert row["motor.Mz.absmax"].mean == np.max(np.abs(res["motor.Mz"]))
    assert row["slider.x.final"].mean == res["slider.x"][-1]
    assert row["yield"].mean == 1.0 and linear.yield_.share == 1.0


def test_sigma_is_the_root_sum_of_squares_of_the_derivatives_times_sigma_p(linear):
    sigmas = np.array([3e-4 / 3, 3e-4 / math.sqrt(3), 0.05])
    t = linear.table
    for c in ("motor.Mz", "slider.x"):
        d = np.column_stack([t[f"{c}.d.{p}"] for p in ("crank.A.x", "rod.B.x", "rod.mass")])
        assert np.allclose(t[f"{c}.std"], np.sqrt(np.sum((d * sigmas) ** 2, axis=1)),
                           rtol=1e-12, atol=0)
        row = {r.output: r for r in linear.summary}
        assert row[f"{c}.final"].linear_std == pytest.approx(t[f"{c}.std"][-1], rel=1e-12)
        mean = np.sqrt(np.sum((d.mean(axis=0) * sigmas) ** 2))
        assert row[f"{c}.mean"].linear_std == pytest.approx(mean, rel=1e-12)
        assert np.isnan(row[f"{c}.absmax"].linear_std)      # the contract: final and mean
    # the slider's position does not depend on the rod's mass; at t = 0 (crank along the
    # guide) it moves one for one with the crank and the rod
    assert np.all(t["slider.x.d.rod.mass"] == 0)
    assert t["slider.x.d.crank.A.x"][0] == pytest.approx(1.0, abs=1e-12)
    assert t["slider.x.d.rod.B.x"][0] == pytest.approx(1.0, abs=1e-12)


def test_the_tornado_draws_the_contributions(linear):
    ax = linear.tornado("motor.Mz.absmax")
    sens = linear.sensitivities
    want = sens.contributions("motor.Mz", "absmax")
    widths = [p.get_width() for p in ax.patches]
    names = [t.get_text() for t in ax.get_yticklabels()]
    assert names == sorted(want, key=lambda n: -abs(want[n]))
    assert widths == pytest.approx([want[n] for n in names], rel=1e-15)


MONTE_CARLO = f"""
[study]
model = "{(EXAMPLES / 'slider_crank.toml').as_posix()}"
analysis = "kinematic"
steps = 3
t_end = 0.2
method = "monte_carlo"
samples = SAMPLES
seed = 4
outputs = ["slider.x", "rod.Dfi"]
reduce = ["final", "mean"]
[[parameter]]
name = "crank.A.x"
distribution = "normal"
tol = 3e-5
[[parameter]]
name = "rod.B.x"
distribution = "normal"
tol = 6e-5
[[parameter]]
name = "motor.C2"
distribution = "uniform"
tol = 0.01
"""


def _monte_carlo_within_three_standard_errors(samples):
    result = study(loads_study(MONTE_CARLO.replace("SAMPLES", str(samples)),
                               source=str(ROOT / "mc.toml")))
    checked = 0
    for row in result.summary[:-1]:
        se = row.linear_std / math.sqrt(2 * (row.count - 1))
        assert row.count == samples
        assert abs(row.std - row.linear_std) <= 3 * se, (row.output, row.std, row.linear_std)
        checked += 1
    assert checked == 4
    return result


def test_monte_carlo_scatter_agrees_with_the_linear_sigma():
    result = _monte_carlo_within_three_standard_errors(40)
    assert "linear_std" in result.report()


@pytest.mark.long
def test_monte_carlo_scatter_agrees_with_the_linear_sigma_on_many_variants():
    _monte_carlo_within_three_standard_errors(600)


def test_a_linear_study_through_the_command_line(tmp_path, capsys):
    (tmp_path / "s.toml").write_text(LINEAR)
    out = tmp_path / "o.csv"
    assert main(["study", str(tmp_path / "s.toml"), "-o", str(out),
                 "--tornado", "motor.Mz.final"]) == 0
    printed = capsys.readouterr().out
    assert "first order at the nominal variant, 3 parameters" in printed
    assert "wrote 9 output times" in printed
    header = out.read_text().splitlines()[0].split(",")
    k = header.index("motor.Mz")
    assert header[0] == "t" and header[k:k + 5] == [
        "motor.Mz", "motor.Mz.std", "motor.Mz.d.crank.A.x", "motor.Mz.d.rod.B.x",
        "motor.Mz.d.rod.mass"] and len(header) == 11
    summary = (tmp_path / "o.summary.csv").read_text().splitlines()
    assert summary[0].endswith(",linear_std") and summary[-1].startswith("yield,1,1,")
    assert (tmp_path / "o.tornado.motor.Mz.final.png").stat().st_size > 0


def test_a_linear_study_has_no_variants_to_draw(tmp_path, capsys):
    (tmp_path / "s.toml").write_text(LINEAR)
    assert main(["study", str(tmp_path / "s.toml"), "-o", str(tmp_path / "o.csv"),
                 "--hist", "motor.Mz.final"]) == 2
    assert "a linear study has no variants to draw" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml"]


@pytest.mark.filterwarnings("ignore:1 redundant constraint")
def test_a_parameter_the_redundant_constraints_fix_is_named(tmp_path):
    text = f"""
[study]
model = "{(ROOT / 'tests' / 'data' / 'parallelogram5.toml').as_posix()}"
analysis = "kinematic"
steps = 4
method = "linear"
[[parameter]]
name = "crank3.A.x"
distribution = "normal"
tol = 1e-4
"""
    with pytest.raises(pam2exu.ModelError, match=r"\[\[parameter\]\] 'crank3.A.x'.*cannot "
                                                 "vary in this over-constrained mechanism"):
        study(loads_study(text, source=str(tmp_path / "s.toml")))


def test_a_degrees_model_differentiates_per_degree_in_degrees(tmp_path):
    """A model in degrees: an angle parameter per degree, an angular output in degrees
    (against central differences of whole runs of the degrees model)."""
    from pam2exu.studies.parameters import varied
    text = (EXAMPLES / "slider_crank.toml").read_text()
    text = text.replace('name = "slider-crank"', 'name = "slider-crank"\nangles = "deg"')
    text = text.replace("fi = -0.2", "fi = -11.459").replace(
        "C = [0.0, 10.0, 0.0, 0.0]", "C = [0.0, 572.9577951308232, 0.0, 0.0]")
    (tmp_path / "deg.toml").write_text(text)
    (tmp_path / "s.toml").write_text("""
[study]
model = "deg.toml"
analysis = "kinetostatic"
steps = 6
t_end = 0.3
method = "linear"
outputs = ["slider.x", "rod.fi", "motor.Mz"]
reduce = ["final"]
[[parameter]]
name = "ground.rail.angle"
distribution = "normal"
tol = 0.1
""")
    result = study(tmp_path / "s.toml")
    runs = [pam2exu.run(varied(text, {"ground.rail.angle": v}), "kinetostatic", steps=6,
                        t_end=0.3) for v in (1e-4, -1e-4)]
    assert result.results().units["rod.fi.d.ground.rail.angle"] == "deg/deg"
    for c in ("slider.x", "rod.fi", "motor.Mz"):
        fd = (runs[0][c] - runs[1][c]) / 2e-4
        assert np.allclose(result.table[f"{c}.d.ground.rail.angle"], fd, rtol=1e-6,
                           atol=1e-9 * np.max(np.abs(fd)))


def test_a_tornado_of_a_grid_study_is_refused_before_any_variant_runs(tmp_path, capsys):
    """A grid has no distributions to weigh the sensitivities by: exit 2, nothing written
    (it used to run every variant, write the files, then fail on the picture)."""
    out = tmp_path / "sweep.csv"
    assert main(["study", str(EXAMPLES / "studies" / "four_bar_coupler_sweep.toml"), "-o",
                 str(out), "--tornado", "coupler.transmission_angle.min",
                 "--workers", "1"]) == 2
    assert "no sensitivities for a grid study" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []

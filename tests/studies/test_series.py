"""The series table of a study and its pictures (pam2exu/studies/series.py, plots.py;
``pam2exu study --hist/--band/--scatter``).

References: each variant's series against a single ``pam2exu.run`` of the model with the
variant's values written in (``parameters.varied``); the band's curves against
``numpy.percentile`` of the series folded by hand, variant by variant; the histogram's bars
against ``numpy.histogram``; the scatter's points and the requirement lines against the
per-variant table and the study file; the files read back with pyarrow and the csv module,
bit for bit. Numbers, not pixels.
"""
import csv
import doctest
import warnings
from pathlib import Path

import numpy as np
import pytest

import pam2exu
from pam2exu.cli import main
from pam2exu.errors import InputWarning, PictureError
from pam2exu.studies import loads_study, plots, runner, series
from pam2exu.studies.parameters import varied
from pam2exu.studies.runner import study

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"

SERIES_STUDY = """
[study]
model = "slider_crank.toml"
analysis = "kinetostatic"
steps = 6
t_end = 0.3
method = "monte_carlo"
samples = 5
seed = 11
series = true
outputs = ["motor.Mz", "slider.x"]
reduce = ["absmax", "range"]
[[parameter]]
name = "crank.A.x"
distribution = "normal"
tol = 1e-3
[[parameter]]
name = "rod.mass"
distribution = "uniform"
tol = 0.5
[[requirement]]
output = "slider.x.range"
min = 0.199
max = 0.2005
"""

# a negative mass is refused when the variant's model is built (a cheap error row)
GRID_STUDY = """
[study]
model = "four_bar.toml"
analysis = "kinematic"
steps = 4
t_end = 0.5
method = "grid"
series = true
outputs = ["rocker.fi", "coupler.P.x"]
reduce = ["max"]
[[parameter]]
name = "coupler.B.x"
values = [0.35, 0.36]
[[parameter]]
name = "coupler.mass"
values = [0.8, -1.0]
[[requirement]]
output = "rocker.fi.max"
max = 2.37
"""


@pytest.fixture(scope="module")
def slider():
    return study(loads_study(SERIES_STUDY, folder=EXAMPLES))


@pytest.fixture(scope="module")
def grid(tmp_path_factory):
    folder = tmp_path_factory.mktemp("grid")
    (folder / "four_bar.toml").write_text((EXAMPLES / "four_bar.toml").read_text())
    (folder / "s.toml").write_text(GRID_STUDY)
    return folder, study(folder / "s.toml", out=folder / "o.parquet")


def _rows(result, sample: int) -> np.ndarray:
    """A variant's rows of the series table."""
    return result.series["sample"] == sample


def test_the_docstring_examples():
    for module in (series, plots):
        assert doctest.testmod(module).failed == 0


def test_each_variants_series_is_a_single_run_of_its_model(slider):
    text = (EXAMPLES / "slider_crank.toml").read_text()
    t = slider.table
    assert t["status"].tolist().count("error") == 0 and "rejected" in t["status"]
    assert list(slider.series) == ["sample", "t", "motor.Mz", "slider.x"]
    assert slider.series["sample"].tolist() == [i for i in range(5) for _ in range(7)]
    for i in range(5):
        values = {n: float(t[n][i]) for n in ("crank.A.x", "rod.mass")}
        res = pam2exu.run(varied(text, values), "kinetostatic", t_end=0.3, steps=6,
                          outputs=["motor.Mz", "slider.x"])
        rows = _rows(slider, i)
        np.testing.assert_allclose(slider.series["t"][rows], res.t, rtol=1e-12, atol=0)
        for name in ("motor.Mz", "slider.x"):
            np.testing.assert_allclose(slider.series[name][rows], res[name], rtol=1e-12,
                                       atol=1e-12 * np.max(np.abs(res[name])))
            assert float(t[f"{name}.absmax"][i]) == np.max(np.abs(slider.series[name][rows]))
    assert slider.units["motor.Mz"] == "N·m" and slider.units["t"] == "s"


def test_variants_in_error_have_no_rows_and_the_files_read_back_bit_for_bit(grid):
    folder, result = grid
    assert result.table["status"].tolist() == ["rejected", "error", "ok", "error"]
    assert result.series["sample"].tolist() == [0] * 5 + [2] * 5
    result.write(folder / "o.csv")
    import pyarrow.parquet as pq
    back = pq.read_table(folder / "o.series.parquet")
    assert back.schema.field("sample").type == "int64"
    assert back.schema.field("rocker.fi").metadata[b"unit"] == b"rad"
    rows = list(csv.reader(open(folder / "o.series.csv", encoding="utf-8")))
    assert rows[0] == list(result.series) == back.column_names
    for j, (name, column) in enumerate(result.series.items()):
        from_csv = np.array([float(r[j]) for r in rows[1:]]).astype(column.dtype)
        for got in (back.column(name).to_numpy(), from_csv):
            assert got.dtype == column.dtype and got.tobytes() == column.tobytes(), name
    assert rows[6][0] == "2"                                # the sample as an integer
    df = result.to_pandas(series=True)
    assert df["sample"].tolist() == result.series["sample"].tolist()
    assert df.attrs["units"]["coupler.P.x"] == "m"


def test_the_series_are_the_same_bytes_whatever_the_chunks(slider, monkeypatch):
    monkeypatch.setattr(runner, "chunks_of", lambda s, w: [(0, 1), (1, 3), (3, 5)])
    again = study(loads_study(SERIES_STUDY, folder=EXAMPLES))
    assert list(again.series) == list(slider.series)
    for name, column in slider.series.items():
        assert again.series[name].tobytes() == column.tobytes(), name


@pytest.mark.long                      # 2.5 s: two worker processes start and import pam2exu
def test_two_worker_processes_give_the_same_series_bit_for_bit(slider):
    again = study(loads_study(SERIES_STUDY, folder=EXAMPLES), workers=2)
    for name, column in slider.series.items():
        assert again.series[name].tobytes() == column.tobytes(), name


def test_series_too_large_for_the_memory_is_refused_and_large_warned():
    loaded = runner.prepared(loads_study(SERIES_STUDY, folder=EXAMPLES))
    need = series.series_bytes(5, 7, 2)
    assert need == 16 * 5 * 7 * 4
    assert series.memory_problem(5, 7, 2, memory=need) is None
    problem = series.memory_problem(10**6, 1001, 20, memory=8 * 2**30)
    assert problem.startswith("series = true keeps 1000000 variants × 1001 rows × 20 outputs, "
                              "about 328 GiB in memory, more than this machine's 8 GiB")
    runner.check_series_memory(loaded, 7, 2)           # small: quiet
    big = runner.dataclasses.replace(loaded, samples=10**9)
    with pytest.raises(pam2exu.ModelError, match=r"\[study\] series: series = true keeps "
                                                 r"1000000000 variants"):
        runner.check_series_memory(big, 1001, 20)
    with pytest.warns(InputWarning, match=r"about 2.09e-06 GiB in memory"):
        with pytest.MonkeyPatch.context() as m:
            m.setattr(runner, "WARN_BYTES", need - 1)
            runner.check_series_memory(loaded, 7, 2)


def test_the_histograms_bars_are_numpys_and_the_requirements_are_lines(slider):
    ax = slider.hist("slider.x.range")
    values = slider.table["slider.x.range"]
    counts, edges = np.histogram(values, bins="auto")
    assert [p.get_height() for p in ax.patches] == counts.tolist()
    np.testing.assert_allclose([p.get_x() for p in ax.patches], edges[:-1], rtol=1e-12)
    np.testing.assert_allclose([p.get_x() + p.get_width() for p in ax.patches], edges[1:],
                               rtol=1e-12)
    assert [(line.get_label(), line.get_xdata()[0]) for line in ax.lines] == \
        [("required min 0.199", 0.199), ("required max 0.2005", 0.2005)]
    assert ax.get_xlabel() == "slider.x.range [m]"
    assert len(slider.hist("motor.Mz.absmax").lines) == 0    # no requirement on it


def test_the_bands_curves_are_the_percentiles_of_the_series_at_each_t(slider):
    ax = slider.band("motor.Mz")
    t = slider.series["t"][_rows(slider, 0)]
    y = np.array([slider.series["motor.Mz"][_rows(slider, i)] for i in range(5)])
    lines = {line.get_label(): line for line in ax.lines}
    assert list(lines) == ["q01", "q05", "q50", "q95", "q99"]
    for p, line in zip((1, 5, 50, 95, 99), lines.values()):
        assert np.array_equal(line.get_xdata(), t)
        np.testing.assert_allclose(line.get_ydata(), np.percentile(y, p, axis=0),
                                   rtol=1e-12, atol=1e-12 * np.max(np.abs(y)))
    assert ax.get_ylabel() == "motor.Mz [N·m]" and ax.get_xlabel() == "t [s]"


def test_the_scatters_points_are_the_tables_columns(grid):
    _, result = grid
    ax = result.scatter("rocker.fi.max", "coupler.B.x")
    t = result.table
    got = {c.get_label(): c.get_offsets() for c in ax.collections}
    assert list(got) == ["ok (1)", "rejected (1)"]             # variants in error: none
    assert got["ok (1)"].tolist() == [[t["coupler.B.x"][2], t["rocker.fi.max"][2]]]
    assert got["rejected (1)"].tolist() == [[t["coupler.B.x"][0], t["rocker.fi.max"][0]]]
    assert [line.get_ydata()[0] for line in ax.lines] == [2.37]


def test_the_tornado_ranks_the_signed_contributions():
    ax = plots.tornado("motor.Mz.final", {"a.P.x": 0.2, "b.Q.y": -0.5, "model.gravity": 0.01},
                       unit="N·m")
    assert [t.get_text() for t in ax.get_yticklabels()] == ["b.Q.y", "a.P.x", "model.gravity"]
    assert [p.get_width() for p in ax.patches] == [-0.5, 0.2, 0.01]
    assert ax.yaxis_inverted() and ax.get_xlabel() == "∂y/∂p · σ_p [N·m]"
    with pytest.raises(PictureError, match="no parameter"):
        plots.tornado("motor.Mz.final", {})


def test_pictures_of_unknown_names_or_without_series_say_so(slider, grid):
    with pytest.raises(PictureError, match=r"hist 'motor.Mz.absmx' is not a reduced output of "
                                           r"the study \(did you mean 'motor.Mz.absmax'\?\)"):
        slider.hist("motor.Mz.absmx")
    with pytest.raises(PictureError, match=r"band 'motor.Mz.absmax' is not an output whose "
                                           r"series the study keeps"):
        slider.band("motor.Mz.absmax")
    with pytest.raises(PictureError, match=r"scatter 'crank.A.y' is not a parameter of the "
                                           r"study \(did you mean 'crank.A.x'\?\)"):
        slider.scatter("motor.Mz.absmax", "crank.A.y")
    plain = study(loads_study(SERIES_STUDY.replace("series = true", "").replace(
        "samples = 5", "samples = 1"), folder=EXAMPLES))
    assert plain.series is None
    with pytest.raises(PictureError, match="band 'motor.Mz' needs the series of the variants: "
                                           "set series = true"):
        plain.band("motor.Mz")
    with pytest.raises(PictureError, match="needs the series table"):
        plain.to_pandas(series=True)


def test_the_command_writes_the_pictures_beside_out(tmp_path, capsys):
    (tmp_path / "slider_crank.toml").write_text((EXAMPLES / "slider_crank.toml").read_text())
    (tmp_path / "s.toml").write_text(SERIES_STUDY.replace("samples = 5", "samples = 2"))
    out = tmp_path / "r.csv"
    assert main(["study", str(tmp_path / "s.toml"), "-o", str(out), "--workers", "1",
                 "--band", "motor.Mz"]) == 0            # one picture: each takes ~0.3 s
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        ["r.csv", "r.series.csv", "r.summary.csv", "s.toml", "slider_crank.toml",
         "r.band.motor.Mz.png"])
    assert (tmp_path / "r.band.motor.Mz.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    printed = capsys.readouterr().out
    assert f"wrote the series, 14 rows, to {tmp_path / 'r.series.csv'}" in printed
    assert f"wrote {tmp_path / 'r.band.motor.Mz.png'}" in printed


def test_the_pictures_the_options_ask_for_and_their_files():
    from argparse import Namespace
    from pam2exu.cli.study import planned_pictures
    loaded = loads_study(SERIES_STUDY, folder=EXAMPLES)
    names = ["motor.Mz.absmax", "motor.Mz.range", "slider.x.absmax", "slider.x.range"]
    args = Namespace(output="out/tol.parquet", study="s.toml", hist=["slider.x.range"],
                     band=["motor.Mz"], scatter=[["motor.Mz.absmax", "rod.mass"]],
                     tornado=["motor.Mz.range"])
    assert [(f.__name__, a, str(p)) for f, a, p in planned_pictures(args, loaded, names)] == [
        ("hist", ("slider.x.range",), "out/tol.hist.slider.x.range.png"),
        ("band", ("motor.Mz",), "out/tol.band.motor.Mz.png"),
        ("scatter", ("motor.Mz.absmax", "rod.mass"),
         "out/tol.scatter.motor.Mz.absmax.vs.rod.mass.png"),
        ("tornado", ("motor.Mz.range",), "out/tol.tornado.motor.Mz.range.png")]
    args.output = None                                  # beside the study's name, here
    assert str(planned_pictures(args, loaded, names)[0][2]) == "s.hist.slider.x.range.png"
    assert str(plots.picture_path("a", "hist", "Força 1/x.Fx.max")) == \
        "a.hist.Força_1_x.Fx.max.png"


@pytest.mark.parametrize("options, named", [
    (["--hist", "motor.Mz.absmx"], "--hist 'motor.Mz.absmx' is not a reduced output of the "
                                   "study (did you mean 'motor.Mz.absmax'?)"),
    (["--band", "motor.Mz"], "--band 'motor.Mz' needs the series of the variants"),
    (["--scatter", "motor.Mz.absmax", "rod.mas"], "--scatter 'rod.mas' is not a parameter "
                                                  "of the study (did you mean 'rod.mass'?)"),
])
def test_bad_picture_options_exit_2_and_write_nothing(options, named, tmp_path, capsys):
    (tmp_path / "slider_crank.toml").write_text((EXAMPLES / "slider_crank.toml").read_text())
    (tmp_path / "s.toml").write_text(SERIES_STUDY.replace("series = true", ""))
    assert main(["study", str(tmp_path / "s.toml"), "-o", str(tmp_path / "r.parquet"),
                 "--workers", "1", *options]) == 2
    assert named in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml", "slider_crank.toml"]

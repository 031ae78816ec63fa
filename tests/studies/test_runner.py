"""Running a study (pam2exu/studies/runner.py, result.py, ``pam2exu study``).

References: each variant's reductions against a single ``pam2exu.run`` of the model file
with that variant's values written into its text by hand (string replacement of the
TOML, not ``parameters.varied``), reduced with NumPy; the yield against the Wilson
interval's closed form; the files read back with pyarrow and the csv module, bit for bit.
"""
import csv
import math
import re
from pathlib import Path

import numpy as np
import pytest

import pam2exu
from pam2exu.cli import main
from pam2exu.studies import loads_study
from pam2exu.registry import ANALYSES
from pam2exu.studies.runner import FAULT, STUDY_ANALYSES, prepared, run_variants, study

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
NUMPY = {"min": np.min, "max": np.max, "absmax": lambda y: np.max(np.abs(y)),
         "mean": np.mean, "rms": lambda y: np.sqrt(np.mean(y * y)), "final": lambda y: y[-1],
         "range": lambda y: np.max(y) - np.min(y)}


def _by_hand(model_text: str, edits, analysis, steps, t_end, outputs, reduce):
    """The reductions of one run of the model text with ``edits`` (old, new) applied."""
    for old, new in edits:
        assert model_text.count(old) == 1, old
        model_text = model_text.replace(old, new)
    res = pam2exu.run(pam2exu.loads(model_text), analysis, t_end=t_end, steps=steps,
                      outputs=outputs)
    return {f"{c}.{r}": float(NUMPY[r](np.asarray(res[c]))) for c in res.columns
            for r in reduce}


def _close(a: float, b: float) -> bool:
    return abs(a - b) <= 1e-12 * max(abs(a), abs(b), 1e-300) or a == b


SLIDER_STUDY = """
[study]
model = "slider_crank.toml"
analysis = "kinetostatic"
steps = 6
t_end = 0.3
method = "monte_carlo"
samples = 3
seed = 7
outputs = ["motor.Mz", "B.F*", "slider.x"]
reduce = ["min", "max", "absmax", "mean", "rms", "final", "range"]
[[parameter]]
name = "crank.A.x"
distribution = "normal"
tol = 1e-3
[[parameter]]
name = "rod.B.x"
distribution = "uniform"
low = 0.29
high = 0.31
[[parameter]]
name = "rod.mass"
distribution = "triangular"
tol = 0.5
[[parameter]]
name = "model.gravity"
distribution = "normal"
std = 0.5
"""

FOUR_BAR_STUDY = """
[study]
model = "four_bar.toml"
analysis = "kinematic"
steps = 5
t_end = 0.4
method = "latin_hypercube"
samples = 3
seed = 3
outputs = ["rocker.fi", "coupler.P.*", "rocker.DDfi"]
reduce = ["absmax", "mean", "final", "range"]
[[parameter]]
name = "coupler.B.x"
distribution = "normal"
tol = 2e-3
[[parameter]]
name = "rocker.B.x"
distribution = "uniform"
tol = 1e-3
[[parameter]]
name = "motor.C2"
distribution = "uniform"
low = 5.0
high = 7.0
"""


@pytest.fixture(scope="module")
def slider():
    return study(loads_study(SLIDER_STUDY, folder=EXAMPLES))


@pytest.fixture(scope="module")
def four_bar():
    return study(loads_study(FOUR_BAR_STUDY, folder=EXAMPLES))


def test_kinetostatic_variants_equal_single_runs_by_hand(slider):
    text = (EXAMPLES / "slider_crank.toml").read_text()
    t = slider.table
    assert t["status"].tolist() == ["ok"] * 3 and t["sample"].tolist() == [0, 1, 2]
    assert len(slider.outputs) == 4 * 7               # Mz, B.Fx, B.Fy, slider.x
    for i in range(3):
        a, b, m, g = (float(t[n][i]) for n in ("crank.A.x", "rod.B.x", "rod.mass",
                                               "model.gravity"))
        edits = [("A = [0.1, 0.0] }", f"A = [{a!r}, 0.0] }}"),
                 ("B = [0.3, 0.0]", f"B = [{b!r}, 0.0]"),
                 ("mass = 2.0", f"mass = {m!r}"),
                 ('name = "slider-crank"', f'name = "slider-crank"\ngravity = {g!r}')]
        want = _by_hand(text, edits, "kinetostatic", 6, 0.3, ["motor.Mz", "B.F*", "slider.x"],
                        list(NUMPY))
        assert sorted(want) == sorted(slider.outputs)
        for name, value in want.items():
            assert _close(float(t[name][i]), value), (i, name, t[name][i], value)
    assert len({float(x) for x in t["motor.Mz.absmax"]}) == 3        # the variants differ


def test_kinematic_variants_equal_single_runs_by_hand(four_bar):
    text = (EXAMPLES / "four_bar.toml").read_text()
    t = four_bar.table
    assert t["status"].tolist() == ["ok"] * 3
    for i in range(3):
        b, c, w = (float(t[n][i]) for n in ("coupler.B.x", "rocker.B.x", "motor.C2"))
        edits = [("B = [0.35, 0.0]", f"B = [{b!r}, 0.0]"),
                 ("O = [0.0, 0.0], B = [0.3, 0.0]", f"O = [0.0, 0.0], B = [{c!r}, 0.0]"),
                 ("C = [0.0, 6.283185307179586,", f"C = [0.0, {w!r},")]
        want = _by_hand(text, edits, "kinematic", 5, 0.4,
                        ["rocker.fi", "coupler.P.*", "rocker.DDfi"],
                        ["absmax", "mean", "final", "range"])
        assert list(want) == four_bar.outputs or sorted(want) == sorted(four_bar.outputs)
        for name, value in want.items():
            assert _close(float(t[name][i]), value), (i, name, t[name][i], value)


def test_yield_row_is_the_share_ok_with_its_wilson_interval(slider, four_bar):
    for result in (slider, four_bar):
        row = result.summary[-1]
        n = len(result)
        k = int(np.count_nonzero(result.table["status"] == "ok"))
        z = 1.959963984540054
        p = k / n
        centre = (p + z * z / (2 * n)) / (1 + z * z / n)
        half = z / (1 + z * z / n) * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
        assert (row.output, row.count, row.mean) == ("yield", n, p)
        assert row.min == pytest.approx(centre - half, rel=1e-12)
        assert row.max == pytest.approx(min(centre + half, 1.0), rel=1e-12)
        assert result.yield_[:2] == (row.mean, row.min)


GRID_STUDY = """
[study]
model = "four_bar.toml"
analysis = "kinematic"
steps = 4
t_end = 0.5
method = "grid"
outputs = ["rocker.fi"]
reduce = ["max", "range"]
[[parameter]]
name = "coupler.B.x"
values = [0.35, 0.7, 0.36, 0.19]
[[requirement]]
output = "rocker.fi.max"
max = 2.37
"""


#: GRID_STUDY with one more coupler length that cannot close the loop (its message lists the
#: loop from another joint and the violated joints in another order) and one more ok
GRID_FAILING = GRID_STUDY.replace("values = [0.35, 0.7, 0.36, 0.19]",
                                  "values = [0.35, 0.7, 0.36, 0.19, 0.65, 0.37]")


def _single_run_error(model_text: str, b: float) -> str:
    """'<class>: <message>' of the error a single run raises with coupler.B.x = b."""
    text = model_text.replace("B = [0.35, 0.0]", f"B = [{b!r}, 0.0]")
    with pytest.raises(pam2exu.Pam2ExuError) as caught:
        pam2exu.run(pam2exu.loads(text), "kinematic", t_end=0.5, steps=4, outputs=["rocker.fi"])
    return f"{type(caught.value).__name__}: {caught.value}"


def test_unassemblable_variants_are_error_rows_and_the_study_exits_0(tmp_path, capsys):
    """The issue's acceptance: exit 0, the failing variants error rows with a single run's
    error, every other row a single run's reductions (1e-12), the errors grouped by kind."""
    (tmp_path / "four_bar.toml").write_text((EXAMPLES / "four_bar.toml").read_text())
    (tmp_path / "s.toml").write_text(GRID_FAILING)
    out = tmp_path / "out.csv"
    assert main(["study", str(tmp_path / "s.toml"), "-o", str(out), "--workers", "1"]) == 0
    printed = capsys.readouterr().out
    rows = list(csv.reader(open(out, encoding="utf-8")))       # its numbers read back exactly
    assert rows[0] == ["sample", "status", "error", "coupler.B.x", "rocker.fi.max",
                       "rocker.fi.range"]
    table = {name: np.array([float(r[j]) if r[j] else np.nan for r in rows[1:]])
             if j > 2 else np.array([r[j] for r in rows[1:]]) for j, name in enumerate(rows[0])}
    assert table["status"].tolist() == ["rejected", "error", "ok", "error", "error", "ok"]
    text = (EXAMPLES / "four_bar.toml").read_text()
    values = [0.35, 0.7, 0.36, 0.19, 0.65, 0.37]
    assert table["coupler.B.x"].tolist() == values
    for i, b in enumerate(values):
        if table["status"][i] == "error":
            assert table["error"][i] == _single_run_error(text, b), i
            assert np.isnan(table["rocker.fi.max"][i]) and np.isnan(table["rocker.fi.range"][i])
            continue
        want = _by_hand(text, [("B = [0.35, 0.0]", f"B = [{b!r}, 0.0]")], "kinematic", 4,
                        0.5, ["rocker.fi"], ["max", "range"])
        assert table["error"][i] == ""
        assert all(_close(float(table[n][i]), v) for n, v in want.items()), i
        assert (table["status"][i] == "ok") == (want["rocker.fi.max"] <= 2.37)   # the rejection
    unassembled = [str(e) for e in table["error"][[1, 4]]]
    assert all(e.startswith("SolverError: the mechanism cannot be assembled at t = 0 s: ")
               for e in unassembled)
    masked = {re.sub(r"\d+(\.\d+)?", "#", e) for e in unassembled}
    assert len(masked) == 2            # not the same words: numbers masked do not merge them
    assert table["error"][3].startswith("SolverError: between t = ")
    assert "in error: 3" in printed and "yield: 0.3333 (2 of 6 variants ok)" in printed
    lines = printed.splitlines()
    k = lines.index("  2 × SolverError: the mechanism cannot be assembled at t = 0 s")
    assert lines[k + 1:k + 3] == ["      samples 1, 4", f"      sample 1: {unassembled[0]}"]
    k = lines.index("  1 × SolverError: between t = 0.40625 s and t = 0.4375 s (between steps 3 "
                    "and 4 of 4) the mechanism reached a singular (dead-point) position")
    assert lines[k + 1:k + 3] == ["      samples 3", f"      sample 3: {table['error'][3]}"]
    assert (tmp_path / "out.summary.csv").exists()


def test_a_failure_is_an_error_row_and_a_fault_names_itself(monkeypatch):
    payload = {"model_text": (EXAMPLES / "four_bar.toml").read_text(), "source": "f.toml",
               "analysis": "kinematic", "t_end": 0.1, "steps": 2, "outputs": ["rocker.fi"],
               "reduce": ["max"], "requirements": [], "names": ["coupler.B.x"],
               "reduced": ["rocker.fi.max"]}
    values = np.array([[0.35], [0.7], [0.36]])
    table = run_variants(payload, 1, 3, values[1:3])
    assert table["status"].tolist() == ["error", "ok"] and table["sample"].tolist() == [1, 2]
    assert table["error"][0].startswith("SolverError: ") and np.isnan(table["rocker.fi.max"][0])

    def broken(*args):
        raise ValueError("boom")
    monkeypatch.setattr("pam2exu.studies.runner.reduce_run", broken)
    table = run_variants(payload, 0, 1, values[:1])
    assert table["error"].tolist() == [f"{FAULT}: ValueError: boom"]


BAD = {  # (what to change in SLIDER_STUDY, a piece of the message that names the entry)
    "unknown parameter": (('name = "rod.mass"', 'name = "rod.mas"'),
                          "[[parameter]] #3 'rod.mas'"),
    "negative std": (("std = 0.5", "std = -0.5"), "[[parameter]] #4 'model.gravity'"),
    "low > high": (("low = 0.29", "low = 0.32"), "[[parameter]] #2 'rod.B.x'"),
    "unknown distribution": (('distribution = "triangular"', 'distribution = "triangle"'),
                             "unknown distribution 'triangle'"),
    "unknown method": (('method = "monte_carlo"', 'method = "montecarlo"'),
                       "unknown method 'montecarlo'"),
    "samples = 0": (("samples = 3", "samples = 0"), "samples must be a whole number ≥ 1"),
    "unreduced requirement": (("[[parameter]]\nname = \"crank.A.x\"",
                               "[[requirement]]\noutput = \"motor.Mz.q99\"\nmax = 1.0\n"
                               "[[parameter]]\nname = \"crank.A.x\""),
                              "[[requirement]] #1 'motor.Mz.q99'"),
    "missing model": (('model = "slider_crank.toml"', 'model = "slider_crank2.toml"'),
                      "slider_crank2.toml"),
    "linear of an analysis it cannot differentiate": (
        ('analysis = "kinetostatic"\nsteps = 6\nt_end = 0.3\nmethod = "monte_carlo"\n'
         'samples = 3', 'analysis = "dynamic"\nsteps = 6\nt_end = 0.3\nmethod = "linear"'),
        "method = 'linear' differentiates the assembly, quasi_static, kinematic, "
        "kinetostatic analyses, not dynamic"),
    "an output the analysis does not give": (
        ("[[parameter]]\nname = \"crank.A.x\"",
         "[[requirement]]\noutput = \"B.Fz.max\"\nmax = 1.0\n[[parameter]]\nname = \"crank.A.x\""),
        "[[requirement]] 'B.Fz.max': 'B.Fz.max' is not among the reduced outputs of the "
        "kinetostatic analysis"),
    "samples absurdly large": (("samples = 3", "samples = 1000000000000"),
                               "[study]: samples = 1,000,000,000,000: more than a study runs "
                               "(at most 10,000,000;"),
}


@pytest.mark.parametrize("case", BAD)
def test_bad_input_exits_2_naming_the_entry_and_writes_nothing(case, tmp_path, capsys):
    (old, new), named = BAD[case]
    (tmp_path / "slider_crank.toml").write_text((EXAMPLES / "slider_crank.toml").read_text())
    assert SLIDER_STUDY.count(old) == 1
    (tmp_path / "s.toml").write_text(SLIDER_STUDY.replace(old, new))
    assert main(["study", str(tmp_path / "s.toml"), "-o", str(tmp_path / "o.parquet")]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"pam2exu: model error: {tmp_path / 's.toml'}: ") and named in err
    assert case != "unknown parameter" or "the closest: rod.mass" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml", "slider_crank.toml"]


@pytest.mark.parametrize("samples, named", [
    ("0", "samples: must be a whole number ≥ 1, got 0"),
    ("1000000000000", "samples: 1,000,000,000,000 variants: more than a study runs (at most "
                      "10,000,000;")])
def test_bad_samples_on_the_command_line_exit_2_and_write_nothing(samples, named, tmp_path,
                                                                   capsys):
    (tmp_path / "slider_crank.toml").write_text((EXAMPLES / "slider_crank.toml").read_text())
    (tmp_path / "s.toml").write_text(SLIDER_STUDY)
    assert main(["study", str(tmp_path / "s.toml"), "-o", str(tmp_path / "o.csv"),
                 "--samples", samples]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"pam2exu: model error: {tmp_path / 's.toml'}: {named}")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml", "slider_crank.toml"]


def test_the_files_read_back_bit_for_bit(tmp_path):
    (tmp_path / "four_bar.toml").write_text((EXAMPLES / "four_bar.toml").read_text())
    (tmp_path / "s.toml").write_text(GRID_STUDY)
    result = study(tmp_path / "s.toml", out=tmp_path / "o.parquet")
    result.to_csv(tmp_path / "o.csv")
    import pyarrow.parquet as pq
    back = pq.read_table(tmp_path / "o.parquet").to_pydict()
    rows = list(csv.reader(open(tmp_path / "o.csv", encoding="utf-8")))
    assert list(back) == list(result.table) == rows[0]
    for j, (name, column) in enumerate(result.table.items()):
        if column.dtype.kind == "f":
            from_csv = np.array([float(r[j]) if r[j] else np.nan for r in rows[1:]])
            for got in (np.array(back[name], dtype=float), from_csv):
                assert np.array_equal(got.view(np.int64), column.view(np.int64)), name
        else:
            assert [str(v) for v in back[name]] == [str(v) for v in column] \
                == [r[j] for r in rows[1:]]
    assert back["sample"] == [0, 1, 2, 3]
    summary = (tmp_path / "o.summary.csv").read_text().splitlines()
    assert summary[-1].startswith("yield,4,2.5e-1,,")
    df = result.to_pandas()
    assert df["status"].tolist() == ["rejected", "error", "ok", "error"]


@pytest.mark.long                      # 2.5 s: two worker processes start and import pam2exu
def test_two_worker_processes_give_the_same_table_bit_for_bit(slider):
    again = study(loads_study(SLIDER_STUDY, folder=EXAMPLES), workers=2)
    assert list(again.table) == list(slider.table)
    for name, column in slider.table.items():
        other = again.table[name]
        same = np.array_equal(other.view(np.int64), column.view(np.int64)) \
            if column.dtype.kind == "f" else np.array_equal(other, column)
        assert same, name


def test_a_deleted_part_and_resume_give_the_same_files(tmp_path, monkeypatch):
    (tmp_path / "four_bar.toml").write_text((EXAMPLES / "four_bar.toml").read_text())
    (tmp_path / "s.toml").write_text(GRID_STUDY.replace("steps = 4", "steps = 4\nseries = true"))
    whole = study(tmp_path / "s.toml", out=tmp_path / "whole.csv")
    from pam2exu.studies import runner
    monkeypatch.setattr(runner, "chunks_of", lambda s, w: [(0, 1), (1, 2), (2, 4)])

    def interrupted(self, out):
        raise KeyboardInterrupt
    with monkeypatch.context() as m:
        m.setattr(runner.StudyResult, "write", interrupted)
        with pytest.raises(KeyboardInterrupt):
            study(tmp_path / "s.toml", out=tmp_path / "o.csv")
    parts = sorted((tmp_path / "o.csv.parts").iterdir())
    assert len(parts) == 3 and not (tmp_path / "o.csv").exists()
    parts[1].unlink()
    ran = []
    engine = runner.run_chunks
    monkeypatch.setattr(runner, "run_chunks",
                        lambda *a, **k: ran.append(engine(*a, **k)) or ran[-1])
    study(tmp_path / "s.toml", out=tmp_path / "o.csv", resume=True)
    assert [tuple(c) for c in ran[0].computed] == [(1, 2)]   # only the missing chunk
    for name in ("o.csv", "o.series.csv"):               # the series are in the parts too
        assert (tmp_path / name).read_bytes() == \
            (tmp_path / name.replace("o.", "whole.")).read_bytes()
    assert not (tmp_path / "o.csv.parts").exists()
    assert whole.table["status"].tolist() == ["rejected", "error", "ok", "error"]


@pytest.mark.long                      # 5 s: a Dask LocalCluster starts and stops
def test_a_dask_local_cluster_writes_the_same_bytes(tmp_path, capsys):
    pytest.importorskip("distributed")
    (tmp_path / "four_bar.toml").write_text((EXAMPLES / "four_bar.toml").read_text())
    (tmp_path / "s.toml").write_text(GRID_STUDY)
    assert main(["study", str(tmp_path / "s.toml"), "-o", str(tmp_path / "a.csv"),
                 "--workers", "1"]) == 0
    assert main(["study", str(tmp_path / "s.toml"), "-o", str(tmp_path / "b.csv"),
                 "--dask-local", "2"]) == 0
    assert (tmp_path / "a.csv").read_bytes() == (tmp_path / "b.csv").read_bytes()


def test_the_analyses_a_study_runs_are_the_registrys_declaration():
    """``AnalysisType.in_studies`` decides, by the type, not by its name: PAM's Catalan name
    of the kinematic analysis is run (it was refused when the runner listed names); the
    analyses refused are named with the declared list (test_free_analyses.py)."""
    assert STUDY_ANALYSES == tuple(a.name for a in ANALYSES.values() if a.in_studies)
    text = ('[study]\nmodel = "slider_crank.toml"\nanalysis = "{}"\nsamples = 2\n'
            '[[parameter]]\nname = "crank.A.x"\ndistribution = "normal"\ntol = 1e-4\n')
    folder = Path(__file__).resolve().parents[2] / "examples"
    assert prepared(loads_study(text.format("cinematica"), folder=folder)).samples == 2

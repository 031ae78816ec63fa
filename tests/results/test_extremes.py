"""The extremes CSV of a clearance run (shared/spec/clearance.md, "Extremes").

Reference: numpy's min and max of each column and the first row reaching them, computed
here; the file read back with float() (full precision: the same floats, bit for bit).
"""
from pathlib import Path

import numpy as np
import pytest

from pam2exu.cli import main
from pam2exu.results import Results
from pam2exu.results.extremes import (clearance_columns, extremes, extremes_path,
                                      write_extremes)

T = np.linspace(0.0, 1.0, 6)
COLUMNS = {"crank.fi": T * 2.0,
           "A2.jx": np.array([0.0, 3e-4, -1e-4, 3e-4, 0.1 / 3, -1e-4]),   # max at 0.8
           "A2.jr": np.array([0.0, 1e-4, 2e-4, 2e-4, 1e-4, 0.0]),         # ties: first
           "slot.jn": np.array([0.0, -2e-4, -2e-4, 1e-5, 1e-5, 1e-5])}


def _run(analysis="clearance"):
    return Results(T, dict(COLUMNS), analysis=analysis)


def test_the_clearance_columns_in_the_results_order():
    assert clearance_columns(_run()) == ["A2.jx", "A2.jr", "slot.jn"]
    assert clearance_columns(_run("kinematic")) == []


def test_min_max_and_the_first_rows_reaching_them():
    for e in extremes(_run()):
        values = COLUMNS[e.column]
        assert (e.min, e.max) == (values.min(), values.max())
        assert e.t_min == T[np.argmin(values)] and e.t_max == T[np.argmax(values)]
    jr = next(e for e in extremes(_run()) if e.column == "A2.jr")
    assert (jr.t_min, jr.t_max) == (0.0, 0.4)           # the first of two equal rows


def test_written_beside_the_result_at_full_precision(tmp_path):
    path = extremes_path(tmp_path / "run.csv")
    assert path.name == "run.extremes.csv"
    # a workbook's or a Parquet file's extremes are CSV too, and named so (fuzz seed 100072:
    # a CSV was written as run.extremes.xlsx)
    assert extremes_path(tmp_path / "run.xlsx").name == "run.extremes.csv"
    assert extremes_path(tmp_path / "run.parquet").name == "run.extremes.csv"
    write_extremes(_run(), path)
    lines = path.read_text(encoding="utf-8").splitlines()
    assert lines[0] == "column,min,t_min,max,t_max"
    assert [line.split(",")[0] for line in lines[1:]] == ["A2.jx", "A2.jr", "slot.jn"]
    for line, e in zip(lines[1:], extremes(_run())):
        assert [float(v) for v in line.split(",")[1:]] == [e.min, e.t_min, e.max, e.t_max]
    assert float(lines[1].split(",")[3]) == 0.1 / 3       # bit for bit


def test_the_cli_writes_the_extremes_of_a_clearance_run_only(tmp_path, request, capsys):
    root = Path(request.config.rootpath)
    text = (root / "tests/data/parallelogram5.toml").read_text(encoding="utf-8")
    text = text.replace('anc2 = "coupler.A2"', 'anc2 = "coupler.A2"\nclearance = true')
    text = text.replace("[analysis]", '[[variation]]\nanchor = "ground.O2"\ndx = 3.7e-3\n\n'
                        "[analysis]")
    model = tmp_path / "pc.toml"
    model.write_text(text, encoding="utf-8")
    assert main(["run", str(model), "-a", "clearance", "--steps", "10",
                 "-o", str(tmp_path / "pc.csv")]) == 0
    lines = (tmp_path / "pc.extremes.csv").read_text(encoding="utf-8").splitlines()
    assert [line.split(",")[0] for line in lines] == ["column", "A2.jx", "A2.jy", "A2.jr"]
    assert "A2.jr" in capsys.readouterr().out             # the printed table
    assert main(["run", str(model), "-a", "kinematic", "--steps", "10",
                 "-o", str(tmp_path / "k.csv")]) == 0
    assert not (tmp_path / "k.extremes.csv").exists()


def _parallelogram_with(tmp_path, root, joint_extra="", variation='anchor = "ground.O2"\n'
                        'dx = 3.7e-3'):
    text = (root / "tests/data/parallelogram5.toml").read_text(encoding="utf-8")
    text = text.replace('anc2 = "coupler.A2"', f'anc2 = "coupler.A2"\n{joint_extra}')
    text = text.replace("[analysis]", f"[[variation]]\n{variation}\n\n[analysis]")
    model = tmp_path / "bad.toml"
    model.write_text(text, encoding="utf-8")
    return model


@pytest.mark.parametrize("joint, variation, words", [
    ("clearance = true", 'anchor = "ground.O2"\ntua = 1.0', "unknown key 'tua'"),
    ("clearance = true", 'anchor = "ground.O2"\ndx = 1e-3\n\n[[variation]]\n'
     'anchor = "ground.O2"\ndy = 1e-3', "is already varied by [[variation]] #1"),
    ("clearance = true", 'anchor = "ground.O2"\ntau = 0.0', "must be > 0"),
    ("clearance = true", 'anchor = "ground"', "is a bare solid"),
    ("clearance = 1", 'anchor = "ground.O2"', "clearance"),
    ("", 'anchor = "ground.O2"\ndx = 3.7e-3', "(condition (i): a self-stress"),
])
def test_bad_clearance_input_is_an_error_naming_it_with_nothing_written(
        tmp_path, request, capsys, joint, variation, words):
    """Issue 13's bad input, through the CLI: exit status 2 (a model error), the message
    names the entry (and the file, except condition (i)'s, which the contract makes begin
    with t=0:), and neither the result nor its extremes file exists."""
    model = _parallelogram_with(tmp_path, Path(request.config.rootpath), joint, variation)
    out = tmp_path / "bad.csv"
    assert main(["run", str(model), "-a", "clearance", "--steps", "10", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert words in err and ("bad.toml" in err or words.startswith("(condition (i)"))
    assert not out.exists() and not (tmp_path / "bad.extremes.csv").exists()


def test_clearance_on_a_spring_is_an_error_with_nothing_written(tmp_path, request, capsys):
    root = Path(request.config.rootpath)
    text = (root / "examples/all_elements.toml").read_text(encoding="utf-8")
    assert 'type = "spring"' in text
    text = text.replace('type = "spring"', 'type = "spring"\nclearance = true', 1)
    model = tmp_path / "spring.toml"
    model.write_text(text, encoding="utf-8")
    out = tmp_path / "spring.csv"
    assert main(["run", str(model), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "spring.toml" in err and "clearance" in err and "spring" in err
    assert not out.exists()

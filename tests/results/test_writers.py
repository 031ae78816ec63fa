"""Results in other forms (pam2exu/results/writers.py): the CSV Excel opens with a decimal
comma, the Excel workbook, Parquet, pandas, the notebook HTML, and ``run -o`` choosing the
format from the suffix.

References: the '.'-CSV of ``Results.to_csv`` (the contract's file, itself checked bit for bit
in test_table.py), read back with the standard csv module and ``float``; each other format
read back with its own library (openpyxl, pyarrow, pandas). Equality is of the floats' bits
(``view(int64)``), NaN included.
"""
from __future__ import annotations

import csv
import sys

import numpy as np
import pytest

import pam2exu
from pam2exu.cli import main
from pam2exu.errors import OutputError
from pam2exu.results import Results, read_csv
from pam2exu.results.writers import BOM


def _bits(a) -> np.ndarray:
    """The floats' bits, every NaN as numpy's (a NaN's sign is not written: 'nan')."""
    a = np.array(a, dtype=float)
    a[np.isnan(a)] = np.nan
    return a.view(np.int64)


@pytest.fixture(scope="module")
def tricky() -> Results:
    """Floats that trip writers: every exponent, 0.1 + 0.2, ±0, subnormals, extremes, NaN, ±inf,
    names with ',' ';' and 'ç'."""
    rng = np.random.default_rng(14)
    n = 400
    a = rng.standard_normal(n) * 10.0 ** rng.integers(-300, 300, n)
    a[:8] = [0.1 + 0.2, -0.0, 0.0, 5e-324, -1e-310, 1.7976931348623157e308, 1 / 3, 2.0]
    b = rng.uniform(-1, 1, n)
    b[:3] = [np.nan, np.inf, -np.inf]
    return Results(np.linspace(0.0, 1.0, n), {"crank.fi": a, "motor.Força": b, "a,b;c.x": -b},
                   {"crank.fi": "rad", "motor.Força": "N"}, "kinematic", "tricky",
                   warnings=["a warning"], info={"max_residual": 3e-15})


@pytest.fixture(scope="module")
def slider() -> Results:
    return pam2exu.run("examples/slider_crank.toml", analysis="kinetostatic", steps=20)


# ---- CSV with a decimal comma ---------------------------------------------------------------

def _csv_module(path, sep, decimal, encoding="utf-8"):
    """Names and values (rows × columns) read by the standard csv module and float()."""
    with open(path, newline="", encoding=encoding) as fh:
        rows = list(csv.reader(fh, delimiter=sep))
    return rows[0], np.array([[float(c.replace(decimal, ".")) for c in r] for r in rows[1:]])


@pytest.mark.parametrize("sep", [";", "\t"])
def test_decimal_comma_csv_has_the_same_numbers_as_the_point_csv(tricky, tmp_path, sep):
    point, comma = tmp_path / "point.csv", tmp_path / "comma.csv"
    tricky.to_csv(point)
    tricky.to_csv(comma, sep=sep, decimal=",", bom=True)
    raw = comma.read_bytes()
    assert raw.startswith(BOM) and b"." not in raw.split(b"\n", 1)[1]
    # the same digits, only ',' → sep and '.' → ','
    assert raw[len(BOM):].split(b"\n", 1)[1] == point.read_bytes().split(b"\n", 1)[1] \
        .replace(b",", b"\0").replace(b".", b",").replace(b"\0", sep.encode())
    names_p, values_p = _csv_module(point, ",", ".")
    names_c, values_c = _csv_module(comma, sep, ",", encoding="utf-8-sig")
    assert names_c == names_p == ["t", "crank.fi", "motor.Força", "a,b;c.x"]
    assert np.array_equal(_bits(values_c), _bits(values_p))
    assert np.array_equal(_bits(values_p), _bits(tricky.to_numpy()))
    back = read_csv(comma)
    assert back.columns == tricky.columns
    assert np.array_equal(_bits(back.to_numpy()), _bits(tricky.to_numpy()))


def test_compare_reads_the_decimal_comma_csv(slider, tmp_path, capsys):
    slider.to_csv(tmp_path / "point.csv")
    slider.to_csv(tmp_path / "comma.csv", sep=";", decimal=",", bom=True)
    comparison = pam2exu.compare(tmp_path / "comma.csv", tmp_path / "point.csv", rtol=0, atol=0)
    assert comparison.passed and len(comparison.rows) == len(slider.columns)
    assert max(v.max_abs_error for v in comparison.rows) == 0.0
    assert main(["compare", str(tmp_path / "comma.csv"), str(tmp_path / "point.csv"),
                 "--rtol", "0", "--atol", "0"]) == 0


def test_clashing_or_unknown_separators_are_refused(tricky, tmp_path):
    with pytest.raises(OutputError, match="sep=';'"):
        tricky.to_csv(tmp_path / "x.csv", decimal=",")
    with pytest.raises(OutputError, match="separator is ',', ';' or a tab"):
        tricky.to_csv(tmp_path / "x.csv", sep="|")
    assert not list(tmp_path.iterdir())


# ---- Excel, Parquet, pandas -----------------------------------------------------------------

def test_workbook_holds_the_same_numbers_and_the_units(tricky, tmp_path):
    openpyxl = pytest.importorskip("openpyxl")
    path = tricky.to_excel(tmp_path / "run.xlsx")
    book = openpyxl.load_workbook(path, read_only=True)
    assert book.sheetnames == ["results", "model"]
    rows = list(book["results"].iter_rows(values_only=True))
    assert list(rows[0]) == ["t", *tricky.columns]
    assert list(rows[1]) == ["s", "rad", "N", None]          # no unit known for a,b;c.x
    words = {"nan": np.nan, "infinity": np.inf, "-infinity": -np.inf}
    values = np.array([[words[v] if isinstance(v, str) else v for v in r] for r in rows[2:]])
    assert np.array_equal(_bits(values), _bits(tricky.to_numpy()))
    facts = dict(r for r in book["model"].iter_rows(values_only=True))
    assert facts["model"] == "tricky" and facts["rows"] == len(tricky)
    assert facts["check"] == "constraint residual 3.0e-15 m"
    assert facts["warning"] == "a warning" and facts["info: max_residual"] == 3e-15


def test_parquet_reads_back_bit_for_bit(tricky, tmp_path):
    parquet = pytest.importorskip("pyarrow.parquet")
    table = parquet.read_table(tricky.to_parquet(tmp_path / "run.parquet"))
    assert table.column_names == ["t", *tricky.columns]
    for name in table.column_names:
        assert np.array_equal(_bits(table[name].to_numpy()), _bits(tricky[name]))
    assert table.schema.field("crank.fi").metadata == {b"unit": b"rad"}
    assert b'"model": "tricky"' in table.schema.metadata[b"pam2exu"]


def test_to_pandas_is_bit_identical_and_a_copy(tricky):
    pytest.importorskip("pandas")
    df = tricky.to_pandas()
    assert df.columns.tolist() == ["t", *tricky.columns]
    assert np.array_equal(_bits(df.to_numpy()), _bits(tricky.to_numpy()))
    assert df.attrs["units"]["crank.fi"] == "rad" and df.attrs["model"] == "tricky"
    df.loc[0, "t"] = 99.0
    assert tricky.t[0] == 0.0


@pytest.mark.parametrize("module, extra, write", [
    ("openpyxl", "excel", lambda r, p: r.to_excel(p / "x.xlsx")),
    ("pyarrow", "parquet", lambda r, p: r.to_parquet(p / "x.parquet")),
    ("pandas", "pandas", lambda r, p: r.to_pandas())])
def test_a_missing_library_names_its_extra(tricky, tmp_path, monkeypatch, module, extra, write):
    monkeypatch.setitem(sys.modules, module, None)          # import module → ImportError
    with pytest.raises(OutputError, match=rf'not installed: pip install "pam2exu\[{extra}\]"'):
        write(tricky, tmp_path)
    assert not list(tmp_path.iterdir())


# ---- pam2exu run -o -------------------------------------------------------------------------

def test_run_writes_the_format_of_the_suffix_and_the_checks(tmp_path, capsys, slider):
    pytest.importorskip("openpyxl")
    model = "examples/slider_crank.toml"
    for name in ("run.xlsx", "run.parquet", "run.CSV"):
        assert main(["run", model, "--steps", "20", "-o", str(tmp_path / name)]) == 0
        out = capsys.readouterr().out
        assert "checks: constraint residual" in out and "power balance" in out
    assert read_csv(tmp_path / "run.CSV").columns == slider.columns
    assert (tmp_path / "run.xlsx").read_bytes()[:2] == b"PK"        # a zip: a real workbook
    assert (tmp_path / "run.parquet").read_bytes()[:4] == b"PAR1"


def test_run_refuses_an_unknown_suffix_before_running(tmp_path, capsys, monkeypatch):
    assert main(["run", "examples/slider_crank.toml", "-o", str(tmp_path / "run.txt")]) == 2
    err = capsys.readouterr().err
    assert "run.txt" in err and ".csv (CSV), .xlsx (Excel workbook), .parquet" in err
    assert main(["run", "examples/slider_crank.toml", "-o", str(tmp_path / "r.xlsx"),
                 "--decimal", ","]) == 2
    assert "for .csv files only" in capsys.readouterr().err
    monkeypatch.setitem(sys.modules, "openpyxl", None)
    assert main(["run", "examples/nothing.toml", "-o", str(tmp_path / "run.xlsx")]) == 2
    assert 'pip install "pam2exu[excel]"' in capsys.readouterr().err    # before the model
    assert not list(tmp_path.iterdir())


def test_run_writes_the_decimal_comma_csv(tmp_path, capsys):
    path = tmp_path / "run.csv"
    assert main(["run", "examples/slider_crank.toml", "--steps", "5", "-o", str(path),
                 "--sep", ";", "--decimal", ",", "--bom", "--outputs", "motor.Mz", "crank.fi"]) == 0
    raw = path.read_bytes()
    assert raw.startswith(BOM + b"t;crank.fi;motor.Mz\n")
    res = pam2exu.run("examples/slider_crank.toml", steps=5, outputs=["motor.Mz", "crank.fi"])
    assert np.array_equal(_bits(_csv_module(path, ";", ",", "utf-8-sig")[1]),
                          _bits(res.to_numpy()))


def test_outputs_accept_pam_spellings():
    """``Forca`` (the files' spelling) chooses the linear actuator's ``Força`` column."""
    spelled = pam2exu.run("examples/all_elements.toml", analysis="kinetostatic", steps=2,
                          outputs=["Forca", "*.f"])
    right = pam2exu.run("examples/all_elements.toml", analysis="kinetostatic", steps=2,
                        outputs=["Força", "*.f(t)"])
    assert spelled.columns == right.columns and any(c.endswith(".Força") for c in right.columns)
    assert np.array_equal(_bits(spelled.to_numpy()), _bits(right.to_numpy()))


# ---- notebooks ------------------------------------------------------------------------------

def test_results_show_names_units_and_checks_in_a_notebook(slider):
    page = slider._repr_html_()
    assert "kinetostatic analysis of 'slider-crank': 21 rows" in page
    for name in ("<th>t</th>", "<th>crank.x</th>", "<td>s</td>", "<td>rad</td>", "<td>m</td>"):
        assert name in page
    assert f"<td>{slider.t[1]:.6g}</td>" in page and "16 more rows" in page
    assert "checks: " + "; ".join(slider.checks()) in page
    assert f"and {len(slider.columns) + 1 - 12} more columns" in page

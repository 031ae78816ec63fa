"""Notebooks: examples/getting_started.ipynb runs (nbclient, a real kernel), and a Model, a
Results table and an animation show themselves as HTML.

References: the notebook's numbers against the same run made here; the HTML against the
model's own element list and the table's columns and checks; the animation's frames against
the steps asked for.
"""
from __future__ import annotations

import base64
import re
import shutil
from pathlib import Path

import numpy as np
import pytest

import pam2exu
from pam2exu.pictures import animate

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOK = ROOT / "examples" / "getting_started.ipynb"


def _html(cell) -> str:
    return "".join(o.get("data", {}).get("text/html", "") for o in cell.outputs)


def test_the_getting_started_notebook_runs(tmp_path):
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    openpyxl = pytest.importorskip("openpyxl")
    for name in (NOTEBOOK, ROOT / "examples" / "slider_crank.toml"):
        shutil.copy(name, tmp_path)
    nb = nbformat.read(tmp_path / NOTEBOOK.name, as_version=4)
    nbclient.NotebookClient(nb, timeout=600, kernel_name="python3",
                            resources={"metadata": {"path": str(tmp_path)}}).execute()
    code = [c for c in nb.cells if c.cell_type == "code"]
    assert not [o for c in code for o in c.outputs if o.output_type == "error"]
    model, table, torque, pictures, animation, frame, files = code
    res = pam2exu.run(ROOT / "examples" / "slider_crank.toml", analysis="kinetostatic",
                      steps=100)
    assert "<img" in _html(model) and "angular_actuator" in _html(model)
    assert "checks: " + "; ".join(res.checks()) in _html(table)
    assert torque.outputs[0].text == \
        f"largest motor torque {abs(res['motor.Mz']).max():.3f} N·m\n"
    assert [sorted(o.data) for o in pictures.outputs] == [["image/png", "text/plain"]] * 2
    assert _html(animation).count("data:image/png;base64") == 25        # steps=24
    assert "motor.Mz" in _html(frame)
    book = openpyxl.load_workbook(tmp_path / "slider_crank.xlsx", read_only=True)
    rows = list(book["results"].iter_rows(values_only=True))
    j = rows[0].index("motor.Mz")
    assert rows[1][j] == "N·m"
    assert np.array_equal([r[j] for r in rows[2:]], res["motor.Mz"])
    assert (tmp_path / "slider_crank_comma.csv").read_bytes().startswith(b"\xef\xbb\xbft;")


def test_a_model_shows_its_elements_and_a_drawing():
    model = pam2exu.load(ROOT / "examples" / "four_bar.toml")
    page = model._repr_html_()
    for el in model.elements:
        assert f"<td>{el.name}</td><td>{el.type}</td>" in page
    for s in model.solids:
        assert f"<td>{s.name}</td><td>solid</td><td>{', '.join(s.points)}</td>" in page
    png = re.search(r"src='data:image/png;base64,([^']+)'", page).group(1)
    assert base64.b64decode(png).startswith(b"\x89PNG\r\n\x1a\n")


def test_a_model_that_cannot_be_drawn_says_why():
    model = pam2exu.Model("empty")
    page = model._repr_html_()
    assert "<img" not in page and "no drawing: " in page and "add at least one [[solid]]" in page


def test_animate_returns_an_inline_animation():
    page = animate(ROOT / "examples" / "four_bar.toml", html=True, steps=6)
    assert page.count("data:image/png;base64") == 7 and "<script" in page
    with pytest.raises(pam2exu.PictureError, match="html=True"):
        animate(ROOT / "examples" / "four_bar.toml")

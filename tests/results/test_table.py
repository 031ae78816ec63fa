"""The Results table: named columns, CSV of the contract, NumPy without copies, selection."""
import csv

import numpy as np
import pytest

import pam2exu
from pam2exu.errors import ModelError
from pam2exu.results import Results, select_columns

COLUMNS = ["crank.x", "crank.fi", "guide.Fx", "motor.f(t)", "spring.Força", "rod.Fx"]


def table():
    t = np.linspace(0.0, 1.0, 5)
    return Results(t, {c: np.arange(5) * (i + 1) + 1 / 3 for i, c in enumerate(COLUMNS)},
                   units={"crank.x": "m"}, analysis="kinematic", model="m")


def test_columns_and_views():
    res = table()
    assert res.columns == COLUMNS
    np.testing.assert_array_equal(res.t, np.linspace(0.0, 1.0, 5))
    arr = res.to_numpy()
    assert arr.shape == (5, 1 + len(COLUMNS))
    assert np.shares_memory(arr, res["crank.fi"])        # no copies
    np.testing.assert_array_equal(arr[:, 2], res["crank.fi"])
    with pytest.raises(KeyError, match="did you mean 'crank.fi'"):
        res["crank.fj"]


def test_csv_round_trip_full_precision_utf8(tmp_path):
    res = table()
    path = res.to_csv(tmp_path / "r.csv")
    with open(path, encoding="utf-8") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == ["t", *COLUMNS]                    # 'Força' kept as UTF-8
    values = np.array(rows[1:], dtype=float)
    np.testing.assert_array_equal(values, res.to_numpy())  # bit for bit
    assert not (tmp_path / "r.csv.part").exists()


@pytest.mark.parametrize("patterns, expected", [
    (["crank.*"], ["crank.x", "crank.fi"]),
    (["*.Fx"], ["guide.Fx", "rod.Fx"]),
    (["Fx"], ["guide.Fx", "rod.Fx"]),                     # bare name = every *.Fx
    (["f(t)", "crank.fi"], ["crank.fi", "motor.f(t)"]),
    (["spring.Força"], ["spring.Força"]),
    (None, COLUMNS),
])
def test_output_patterns(patterns, expected):
    assert select_columns(COLUMNS, patterns) == expected


def test_pattern_matching_nothing_is_a_model_error():
    with pytest.raises(ModelError, match=r"'Fy' matches no variable.*\n.*did you mean 'crank.fi'"):
        select_columns(COLUMNS, ["Fy", "crank.fj"])


def test_run_outputs_selects_and_computes_only_those(examples):
    res = pam2exu.run(examples / "slider_crank.toml", analysis="kinematic", steps=20,
                      outputs=["slider.x", "Df(t)"])
    assert res.columns == ["slider.x", "motor.Df(t)"]
    assert res.units == {"t": "s", "slider.x": "m", "motor.Df(t)": "rad/s"}
    assert len(res) == 21

"""Result files in degrees (issue 14 item 1): the CSV's units line, read back by read_csv,
plot and compare (which compares in radians, or in degrees with angles='deg')."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import pam2exu
from pam2exu import CompareInputError, compare, read_csv
from pam2exu.cli import main
from pam2exu.results import plot

ROOT = Path(__file__).resolve().parents[2]
FOUR_BAR = ROOT / "examples" / "four_bar.toml"
ANGULAR = {"rad": "deg", "rad/s": "deg/s", "rad/s²": "deg/s²"}


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """The four-bar's kinematic run written in radians and in degrees (--angles deg)."""
    tmp = tmp_path_factory.mktemp("degrees")
    rad, deg = tmp / "rad.csv", tmp / "deg.csv"
    for path, angles in ((rad, "rad"), (deg, "deg")):
        assert main(["run", str(FOUR_BAR), "--steps", "24", "--angles", angles,
                     "-o", str(path)]) == 0
    return rad, deg


def test_units_line_only_in_degrees(files):
    rad, deg = files
    rad_lines, deg_lines = rad.read_text().splitlines(), deg.read_text().splitlines()
    assert deg_lines[0] == rad_lines[0]                       # the same header
    res = pam2exu.run(FOUR_BAR, steps=24)
    expected = ["s", *(ANGULAR.get(res.units[c], res.units[c]) for c in res.columns)]
    assert deg_lines[1] == "# units: " + ",".join(expected)
    assert "deg/s²" in expected and "m/s" in expected
    assert rad_lines[1][0].isdigit() and len(rad_lines) == len(deg_lines) - 1


def test_read_back(files):
    rad, deg = files
    res = pam2exu.run(FOUR_BAR, steps=24, angles="deg")
    back = read_csv(deg)
    assert back.columns == res.columns and back.units == res.units
    assert np.array_equal(back.to_numpy(), res.to_numpy())            # bit for bit
    assert read_csv(rad).units["crank.fi"] == "rad"


def test_compare_degrees_file_with_radians_file(files):
    rad, deg = files
    table = compare(deg, rad, rtol=1e-12, atol=0.0)
    assert table.passed
    row = {r.name: r for r in table.rows}
    assert row["crank.fi"].unit == "rad" and row["rocker.DDfi"].unit == "rad/s²"
    assert row["crank.fi"].scale == pytest.approx(2 * math.pi, rel=1e-15)
    assert max(r.max_rel_error for r in table.rows if r.scale > 0) <= 1e-15
    assert any("given in degrees, compared in radians" in n for n in table.notes)
    in_deg = compare(rad, deg, rtol=1e-12, atol=0.0, angles="deg")
    row = {r.name: r for r in in_deg.rows}
    assert in_deg.passed and row["crank.fi"].unit == "deg" and row["coupler.x"].unit == "m"
    assert row["crank.fi"].scale == pytest.approx(360.0, rel=1e-15)
    assert row["rocker.Dfi"].scale == pytest.approx(
        float(np.max(np.abs(read_csv(rad)["rocker.Dfi"]))) * 180 / math.pi, rel=1e-15)
    # a real difference is found in either unit: 1e-6 rad on one angle
    res = read_csv(rad)
    res["coupler.fi"][7] += 1e-6
    worse = {r.name: r for r in compare(res, deg, atol=0.0, angles="deg").rows}
    assert worse["coupler.fi"].max_abs_error == pytest.approx(1e-6 * 180 / math.pi, rel=1e-6)
    assert not worse["coupler.fi"].passed
    with pytest.raises(CompareInputError, match="modulo 2π are compared in radians"):
        compare(rad, deg, angles="deg", wrap_angles=True)
    assert main(["compare", str(deg), str(rad), "--angles", "deg"]) == 0


def test_plot_a_degrees_file(files):
    rad, deg = files
    fig = plot(deg, "rocker.fi", x="crank.fi")
    ax = fig.axes[0]
    assert ax.get_xlabel() == "crank.fi [deg]" and ax.get_ylabel() == "rocker.fi [deg]"
    assert ax.lines[0].get_xdata()[-1] == pytest.approx(360.0, rel=1e-14)
    back = plot(deg, "rocker.fi", x="crank.fi", angles="rad").axes[0]
    np.testing.assert_allclose(back.lines[0].get_ydata(), read_csv(rad)["rocker.fi"],
                               rtol=1e-15)
    assert back.get_xlabel() == "crank.fi [rad]"
    converted = plot(rad, "rocker.fi", x="crank.fi", angles="deg").axes[0]
    np.testing.assert_allclose(converted.lines[0].get_xdata(), read_csv(deg)["crank.fi"],
                               rtol=1e-15)

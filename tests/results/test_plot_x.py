"""Plots against a variable (``plot(..., x=)``, ``pam2exu plot --x``, ``run --plot --x``;
issue 14 item 4): the drawn lines' data are the chosen columns, the axes say their units."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import pam2exu
from pam2exu.cli import main
from pam2exu.results import plot, read_csv
from pam2exu.results.plot import PictureError

ROOT = Path(__file__).resolve().parents[2]
FOUR_BAR = ROOT / "examples" / "four_bar.toml"


def _degrees_text() -> str:
    """The four-bar written in degrees: fi guesses and the motor's 360°/s."""
    text = FOUR_BAR.read_text().replace('name = "four-bar"', 'name = "four-bar"\nangles = "deg"')
    for rad in ("0.02", "0.9", "1.85"):
        text = text.replace(f"\nfi = {rad}\n", f"\nfi = {math.degrees(float(rad))!r}\n")
    return text.replace("C = [0.0, 6.283185307179586, 0.0, 0.0]", "C = [0.0, 360.0, 0.0, 0.0]")


@pytest.fixture(scope="module")
def torque_run():
    """Kinetostatic run of the four-bar model written in degrees."""
    return pam2exu.run(pam2exu.loads(_degrees_text()), analysis="kinetostatic", steps=36)


def test_torque_against_crank_angle_of_a_degrees_model(torque_run):
    res = torque_run
    fig = plot(res, ["motor.Mz", "B.*"], x="crank.fi")
    ax_torque, ax_force = fig.axes
    line = ax_torque.lines[0]
    assert np.array_equal(line.get_xdata(), res["crank.fi"])          # the column itself
    assert np.array_equal(line.get_ydata(), res["motor.Mz"])
    assert res["crank.fi"][-1] == pytest.approx(360.0, rel=1e-14)     # degrees, not 2π
    assert ax_force.get_xlabel() == "crank.fi [deg]" and ax_torque.get_xlabel() == ""
    assert ax_torque.get_ylabel() == "motor.Mz [N·m]"
    assert [ln.get_label() for ln in ax_force.lines] == ["B.Fx [N]", "B.Fy [N]"]
    for ln, c in zip(ax_force.lines, ("B.Fx", "B.Fy")):
        assert np.array_equal(ln.get_xdata(), res["crank.fi"])
        assert np.array_equal(ln.get_ydata(), res[c])


def test_x_is_not_plotted_against_itself_and_angles_convert_both_axes():
    res = pam2exu.run(FOUR_BAR, analysis="kinematic", steps=20)          # radians
    fig = plot(res, ["crank.*"], x="crank.fi", angles="deg")
    labels = [ln.get_label() for ax in fig.axes for ln in ax.lines]
    assert "crank.fi [deg]" not in labels and "crank.Dfi [deg/s]" in labels
    dfi = next(ln for ax in fig.axes for ln in ax.lines if ln.get_label() == "crank.Dfi [deg/s]")
    np.testing.assert_allclose(dfi.get_xdata(), res["crank.fi"] * 180 / math.pi, rtol=1e-15)
    np.testing.assert_allclose(dfi.get_ydata(), res["crank.Dfi"] * 180 / math.pi, rtol=1e-15)
    assert fig.axes[-1].get_xlabel() == "crank.fi [deg]"
    assert plot(res, "rocker.fi", x="crank.fi").axes[0].get_xlabel() == "crank.fi [rad]"
    assert plot(res, "rocker.fi").axes[0].get_xlabel() == "t [s]"


def test_bad_x(torque_run):
    with pytest.raises(PictureError, match=r"the x axis 'crank.phi' is not a column of the "
                                           r"results \(did you mean 'crank.fi'\?\)"):
        plot(torque_run, "motor.Mz", x="crank.phi")
    with pytest.raises(PictureError, match="the x axis is one variable, not a pattern"):
        plot(torque_run, "motor.Mz", x="crank.*")
    with pytest.raises(PictureError, match="nothing to plot: choose variables besides t and "
                                           "the x axis 'crank.fi'"):
        plot(torque_run, "crank.fi", x="crank.fi")


def test_cli_plot_and_run_with_x(tmp_path, capsys):
    model = tmp_path / "four_bar_deg.toml"
    model.write_text(_degrees_text())
    csv, fig = tmp_path / "run.csv", tmp_path / "torque.png"
    assert main(["run", str(model), "-a", "kinetostatic", "--steps", "12", "--outputs",
                 "motor.Mz", "crank.fi", "-o", str(csv), "--plot", "motor.Mz", "--x",
                 "crank.fi", "--plot-file", str(fig)]) == 0
    assert fig.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    out = tmp_path / "from_csv.png"
    assert main(["plot", str(csv), "motor.Mz", "--x", "crank.fi", "-o", str(out)]) == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    capsys.readouterr()
    assert main(["plot", str(csv), "motor.Mz", "--x", "crank.fy", "-o", str(out)]) == 2
    assert "the x axis 'crank.fy' is not a column" in capsys.readouterr().err
    # a run without --outputs computes the x axis too
    assert main(["run", str(model), "-a", "kinematic", "--steps", "6", "--outputs",
                 "rocker.fi", "--plot", "rocker.fi", "--x", "crank.fi", "--plot-file",
                 str(fig)]) == 0
    assert read_csv(csv).columns == ["crank.fi", "motor.Mz"]

"""Pictures: plots against t, drawings of the mechanism, animations, the progress bar.

Images are checked as files (signature, size in pixels, frames) and as matplotlib figures
(labels with PAM names and units, one artist per element). Positions in a drawing are
checked against the closed form of the four-bar's crank (f(t) = 2π t, crank 0.1 m).
"""
import io
import math
import warnings

import numpy as np
import pytest
from PIL import Image

import pam2exu
from pam2exu.cli import main
from pam2exu.elements import ELEMENTS
from pam2exu.pictures import animate, draw
from pam2exu.progress import Progress
from pam2exu.results import plot, read_csv
from pam2exu.results.plot import DPI, MARGIN, PANEL, WIDTH, PictureError
from pam2exu.results.units import unit_of
from tests.conftest import Terminal

PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def slider_crank():
    from pathlib import Path
    path = Path(__file__).resolve().parents[1] / "examples" / "slider_crank.toml"
    return pam2exu.run(path, analysis="kinetostatic", steps=40)


def _png_size(path):
    assert path.read_bytes()[:8] == PNG
    with Image.open(path) as im:
        im.verify()
    with Image.open(path) as im:
        return im.size


def _texts(fig):
    """Every axis label and legend entry of a figure."""
    out = []
    for ax in fig.axes:
        out += [ax.get_xlabel(), ax.get_ylabel()]
        if ax.get_legend():
            out += [t.get_text() for t in ax.get_legend().get_texts()]
    return out


# --- plots against t ------------------------------------------------------------------------

def test_plot_labels_have_pam_names_and_units(slider_crank, tmp_path):
    out = tmp_path / "fig.png"
    fig = plot(slider_crank, ["motor.Mz", "crank.fi", "Fx"], out)
    # one panel per unit, in the order asked: N·m, rad, N
    assert _png_size(out) == (round(WIDTH * DPI), round((MARGIN + 3 * PANEL) * DPI))
    assert [ax.get_ylabel() for ax in fig.axes] == ["motor.Mz [N·m]", "crank.fi [rad]",
                                                    "Fx [N]"]
    assert fig.axes[-1].get_xlabel() == "t [s]"
    legend = [t.get_text() for t in fig.axes[2].get_legend().get_texts()]
    assert legend == ["base.Fx [N]", "O.Fx [N]", "A.Fx [N]", "B.Fx [N]"]
    line = fig.axes[0].get_lines()[0]
    np.testing.assert_array_equal(line.get_xdata(), slider_crank.t)
    np.testing.assert_array_equal(line.get_ydata(), slider_crank["motor.Mz"])


def test_plot_from_csv_derives_units_from_the_declarations(slider_crank, tmp_path, examples):
    csv = slider_crank.to_csv(tmp_path / "sc.csv")
    fig = plot(csv, ["motor.*"])
    texts = _texts(fig)
    assert "motor.Mz [N·m]" in texts
    assert "motor.f(t)" in texts            # rad for an angular actuator, m for a linear one
    fig = plot(csv, ["motor.f", "Df"], model=examples / "slider_crank.toml")  # PAM spellings
    assert _texts(fig)[:4] == ["", "motor.f(t) [rad]", "t [s]", "motor.Df(t) [rad/s]"]


def test_unit_of_reads_every_declaration():
    assert unit_of("crank.fi") == "rad" and unit_of("slider.DDx") == "m/s²"
    assert unit_of("B.Fx") == unit_of("guide.Fnormal") == unit_of("spring.Forca") == "N"
    assert unit_of("motor.Mz") == unit_of("mesh.Parell") == "N·m"
    assert unit_of("s.ro") == "m" and unit_of("s.Dfi_rel") == "rad/s"
    assert unit_of("motor.f(t)") == "" and unit_of("t") == "s"
    model = pam2exu.load(__import__("pathlib").Path(__file__).resolve().parents[1]
                         / "examples" / "all_elements.toml")
    assert unit_of("cylinder.f(t)", model) == "m" and unit_of("motor.Df(t)", model) == "rad/s"


def test_read_csv_keeps_pam_spellings_and_units(tmp_path):
    path = tmp_path / "pam.csv"
    path.write_text("t;spring.Forca;crank.fi\n0;1,5;0\n0,1;2,5;1\n", encoding="utf-8")
    res = read_csv(path)
    assert res.columns == ["spring.Força", "crank.fi"]
    assert res.units["spring.Força"] == "N" and res.units["crank.fi"] == "rad"
    np.testing.assert_allclose(res["spring.Força"], [1.5, 2.5])


def test_plot_names_an_unknown_variable(slider_crank):
    with pytest.raises(PictureError, match=r"'motr.Mz' matches no variable.*did you mean "
                                           r"'motor.Mz'"):
        plot(slider_crank, ["motr.Mz"])
    with pytest.raises(PictureError, match="image format"):
        plot(slider_crank, ["Mz"], "fig.xyz")


# --- drawings -------------------------------------------------------------------------------

def _gids(fig):
    ax = fig.axes[0]
    return {a.get_gid() for a in ax.get_children() if a.get_gid()}


def test_draw_has_an_artist_for_every_element_and_solid(examples, tmp_path):
    path = examples / "all_elements.toml"
    model = pam2exu.load(path)
    # every type of the contract is in it (an extension's type is drawn by its own test)
    assert {e.type for e in model.elements} == {k for k, c in ELEMENTS.items() if not c.extension}
    out = tmp_path / "all.png"
    fig = draw(path, path=out)
    assert _png_size(out) == (800, 600)
    gids = _gids(fig)
    for el in model.elements:
        assert f"{el.type}:{el.name}" in gids, el.name
    for s in model.solids:
        assert f"solid:{s.name}" in gids
    assert "frame" in gids
    names = {t.get_text() for t in fig.axes[0].texts}
    assert {s.name for s in model.solids} <= names
    assert fig.axes[0].get_xlabel() == "x [m]" and fig.axes[0].get_ylabel() == "y [m]"
    assert fig.axes[0].get_aspect() == 1.0                     # equal scales


def test_draw_at_a_time_uses_the_kinematic_positions(examples):
    """Four-bar: f(t) = 2π t, crank 0.1 m: at t = 0.25 s joint A is at (0, 0.1)."""
    from matplotlib.patches import Circle
    fig = draw(examples / "four_bar.toml", t=0.25)
    joint = [a for a in fig.axes[0].patches if a.get_gid() == "revolute:A"
             and isinstance(a, Circle)]
    assert len(joint) == 1
    np.testing.assert_allclose(joint[0].center, (0.0, 0.1), atol=1e-9)
    assert "t = 0.25 s" in fig.axes[0].get_title()


@pytest.mark.parametrize("t", [0.0, 0.25])
def test_draw_ignores_the_models_outputs(examples, t):
    """A model whose [analysis] outputs keep only t (fuzz seed 2048: before, draw failed
    with "no column 'ground.x'" from the assembly it ran with those outputs)."""
    from matplotlib.patches import Circle
    model = pam2exu.load(examples / "four_bar.toml")
    model.analysis.outputs = ["t"]
    fig = draw(model, t=t)
    joint = [a for a in fig.axes[0].patches if a.get_gid() == "revolute:A"
             and isinstance(a, Circle)]
    np.testing.assert_allclose(joint[0].center, (0.1 * math.cos(2 * math.pi * t),
                                                 0.1 * math.sin(2 * math.pi * t)), atol=1e-9)


# --- animations -----------------------------------------------------------------------------

def test_animate_writes_a_gif_with_one_frame_per_step(examples, tmp_path):
    out = tmp_path / "fb.gif"
    assert animate(examples / "four_bar.toml", out, steps=4, trace=["coupler.P"]) == out
    assert out.read_bytes()[:6] == b"GIF89a"
    with Image.open(out) as im:
        assert im.size == (640, 480) and im.n_frames == 5
        frames = []
        for k in range(im.n_frames):
            im.seek(k)
            frames.append(np.asarray(im.convert("RGB")))
    assert not np.array_equal(frames[0], frames[2])            # the mechanism moves


def test_animate_refuses_what_it_cannot_write(examples, tmp_path, monkeypatch):
    from matplotlib import animation
    monkeypatch.setattr(animation.writers, "is_available", lambda name: False)
    with pytest.raises(PictureError, match="MP4 needs ffmpeg"):
        animate(examples / "four_bar.toml", tmp_path / "fb.mp4", steps=2)
    with pytest.raises(PictureError, match=r"\.gif"):
        animate(examples / "four_bar.toml", tmp_path / "fb.avi", steps=2)
    with pytest.raises(pam2exu.ModelError, match="has no point 'Q'.*A, B, P"):
        animate(examples / "four_bar.toml", tmp_path / "fb.gif", steps=2,
                trace=["coupler.Q"])


# --- command line ---------------------------------------------------------------------------

def test_cli_plot_draw_animate(examples, tmp_path, capsys):
    csv = tmp_path / "sc.csv"
    fig = tmp_path / "run.png"
    assert main(["run", str(examples / "slider_crank.toml"), "-a", "kinematic", "--steps",
                 "20", "--outputs", "crank.fi", "-o", str(csv), "--plot", "slider.Dx",
                 "--plot-file", str(fig)]) == 0
    assert read_csv(csv).columns == ["crank.fi"]                # --plot does not widen -o
    assert _png_size(fig)[0] == round(WIDTH * DPI)
    assert main(["plot", str(csv), "crank.fi", "-o", str(tmp_path / "p.png")]) == 0
    assert main(["draw", str(examples / "slider_crank.toml"), "--t", "0.1",
                 "-o", str(tmp_path / "d.svg")]) == 0
    assert (tmp_path / "d.svg").read_text(encoding="utf-8").lstrip().startswith("<?xml")
    assert main(["animate", str(examples / "four_bar.toml"), "--steps", "2",
                 "-o", str(tmp_path / "a.gif")]) == 0
    captured = capsys.readouterr()
    assert captured.err == ""                    # no progress bar: stderr is not a terminal
    assert f"wrote {tmp_path / 'a.gif'}" in captured.out
    assert main(["plot", str(csv), "crank.fy"]) == 2
    assert "did you mean 'crank.fi'" in capsys.readouterr().err


# --- progress bar ---------------------------------------------------------------------------


def test_progress_bar_only_on_a_terminal(monkeypatch):
    monkeypatch.delenv("PAM2EXU_PROGRESS", raising=False)
    piped = io.StringIO()
    with Progress(10, "frames", stream=piped) as bar:
        for k in range(10):
            bar.update(k + 1)
    assert piped.getvalue() == ""
    tty = Terminal()
    with Progress(4, "frames", stream=tty) as bar:
        for k in range(4):
            bar.update(k + 1)
    text = tty.getvalue()
    assert "frames [" in text and " 50%" in text and "100%" in text
    assert text.endswith("\r") and "\n" not in text            # the line is erased at the end
    monkeypatch.setenv("PAM2EXU_PROGRESS", "0")
    off = Terminal()
    with Progress(4, "frames", stream=off) as bar:
        bar.update(2)
    assert off.getvalue() == ""
    assert not Progress(1, "one chunk", stream=Terminal()).enabled


def test_progress_bar_reaches_the_native_pass(monkeypatch, examples):
    """The native pass reports its chunks (several here: a tiny chunk size)."""
    import sys

    from pam2exu.analyses import native
    monkeypatch.delenv("PAM2EXU_PROGRESS", raising=False)
    monkeypatch.setattr(native, "CHUNK_BYTES", 8 * 9 * 12 * 10)   # 10 steps a chunk
    tty = Terminal()
    monkeypatch.setattr(sys, "stderr", tty)
    res = pam2exu.run(examples / "slider_crank.toml", analysis="kinematic", steps=50)
    assert "velocities and accelerations [" in tty.getvalue()
    assert res["crank.Dfi"] == pytest.approx(10.0)
    assert math.isclose(float(res["crank.fi"][-1]), 10.0 * res.t[-1], rel_tol=1e-12)


def test_draw_rings_the_joints_with_clearance(request, guides):
    """pam2exu draw marks the clearance joints (issue 13): one dashed ring per joint with
    clearance = true (revolute, pin_slot, prismatic), none on the others."""
    model = pam2exu.load(request.config.rootpath / "tests/data/parallelogram5.toml")

    def rings(fig):
        return sorted(a.get_gid() for a in fig.axes[0].patches
                      if a.get_linestyle() not in ("-", "solid") and a.get_facecolor()[3] == 0)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pam2exu.RedundancyWarning)   # over-constrained
        assert rings(draw(model)) == []
        model["A2"].clearance = True
        model["A3"].clearance = True
        assert rings(draw(model)) == ["revolute:A2", "revolute:A3"]
    slides = guides(guide_clearance=False)
    assert rings(draw(slides)) == ["pin_slot:slot"]
    slides["guide"].clearance = True
    assert rings(draw(slides)) == ["pin_slot:slot", "prismatic:guide"]

"""Pictures of a dynamic model (issue 15 item 5): draw and animate let its free solids move.

Reference: the dynamic run itself (pam2exu.run), whose positions at the drawn time the
picture's pose must equal; a kinematic run of the same model is refused (a free degree of
freedom), which is what draw and animate did before.
"""
import numpy as np
import pytest

import pam2exu
from pam2exu.pictures import configurations, pose

ROOT = pam2exu.__file__.replace("pam2exu/__init__.py", "")


def _dynamic_four_bar():
    text = open(ROOT + "examples/equilibrium/spring_four_bar.toml", encoding="utf-8").read()
    return pam2exu.loads(text.replace('type = "equilibrium"',
                                      'type = "dynamic"\nt_end = 0.2\nsteps = 10'))


def test_the_pose_of_a_dynamic_model_is_its_dynamic_run():
    model = _dynamic_four_bar()
    res = pam2exu.run(model)
    mech, q = pose(model, 0.2)
    expected = [res[f"{s.name}.{k}"][-1] for s in mech.solids for k in ("x", "y", "fi")]
    np.testing.assert_allclose(q, expected, atol=1e-12)
    assert abs(q[5] - res["crank.fi"][0]) > 0.1                 # it fell
    with pytest.raises(pam2exu.MobilityError):
        configurations(model, analysis="kinematic")


def test_animate_and_draw_a_dynamic_model(tmp_path):
    model = _dynamic_four_bar()
    mech, t, q = configurations(model)
    assert len(t) == 11
    pam2exu.animate(model, tmp_path / "fall.gif", steps=10)
    assert (tmp_path / "fall.gif").stat().st_size > 1000
    fig = pam2exu.draw(model, t=0.2, path=tmp_path / "fall.png")
    assert "dynamic run" in fig.axes[0].get_title()


def test_the_animation_of_a_dynamic_model_says_dynamic_run(tmp_path, monkeypatch):
    """Issue 22: the animation of a dynamic model was titled "kinematic run" although its
    frames are the dynamic run's; a kinematic model's still says kinematic."""
    from pam2exu.pictures import animation
    titles = []
    real = animation.fit_title

    def recorded(fig, ax, text):
        titles.append(text)
        real(fig, ax, text)
    monkeypatch.setattr(animation, "fit_title", recorded)
    pam2exu.animate(_dynamic_four_bar(), tmp_path / "fall.gif", steps=4)
    pam2exu.animate(ROOT + "examples/four_bar.toml", tmp_path / "turn.gif", steps=4)
    assert titles == ["'four-bar held by a spring' — dynamic run, t = 0 … 0.2 s",
                      "'four-bar' — kinematic run, t = 0 … 1 s"]


@pytest.mark.parametrize("size", [(8.0, 6.0), (4.0, 3.0)])
def test_a_long_title_is_wrapped_to_fit(tmp_path, size):
    """Issue 22: ``draw --guess`` cut its title ("… 12 constraints not met" ran past the
    figure's edge with a longer model name). The title keeps every word and lies inside the
    figure, wrapped onto more lines."""
    model = pam2exu.load(ROOT + "examples/all_elements.toml")
    model.name = "all the elements of pam2exu, each one at least once"
    fig = pam2exu.draw(model, guess=True, size=size)
    title = fig.axes[0].title
    box = title.get_window_extent(fig.canvas.get_renderer())
    assert fig.bbox.x0 <= box.x0 and box.x1 <= fig.bbox.x1, (box, fig.bbox)
    assert title.get_text().count("\n") >= 1
    assert " ".join(title.get_text().split()) == (
        "'all the elements of pam2exu, each one at least once' — initial guess (x, y, fi as "
        "given, not assembled); 12 constraints not met")

"""Names in drawings (issue 14, item 7): every solid, joint and actuator is named, and no two
names overlap, on every shipped example (the renderer's boxes of the texts)."""
import warnings
from pathlib import Path

import numpy as np
import pytest

import pam2exu
from pam2exu.pictures import draw
from pam2exu.pictures.labels import box_at, candidates, overlap, place

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = sorted((ROOT / "examples").glob("*.toml")) + sorted(
    (ROOT / "examples" / "clearance").glob("*.toml"))


def _boxes(fig):
    """The window extents (x0, y0, x1, y1) [px] of every visible text in the drawing's axes."""
    renderer = fig.canvas.get_renderer()
    ax = fig.axes[0]
    return {t.get_text(): t.get_window_extent(renderer).extents for t in ax.texts
            if t.get_visible() and t.get_text()}


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_names_do_not_overlap(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fig = draw(path)
    model = pam2exu.load(path)
    boxes = _boxes(fig)
    named = {s.name for s in model.solids} | {e.name for e in model.elements if e.equations}
    assert named <= set(boxes)                                  # every name is drawn
    items = list(boxes.items())
    frame = fig.axes[0].bbox.extents
    for i, (a, box_a) in enumerate(items):
        for b, box_b in items[i + 1:]:
            assert overlap(box_a, box_b) == 0.0, (a, b, box_a, box_b)
        if a in named:                                          # inside the axes
            assert box_a[0] >= frame[0] - 1 and box_a[2] <= frame[2] + 1, a
            assert box_a[1] >= frame[1] - 1 and box_a[3] <= frame[3] + 1, a


def test_overlap_is_the_area_in_common():
    assert overlap(np.array([0.0, 0.0, 2.0, 3.0]), [[1.0, 1.0, 5.0, 5.0]]) == 2.0
    assert overlap(np.array([0.0, 0.0, 2.0, 3.0]), [[2.0, 0.0, 5.0, 5.0]]) == 0.0
    assert overlap(np.array([0.0, 0.0, 2.0, 3.0]), [[1.0, 1.0, 5.0, 5.0],
                                                    [-1.0, -1.0, 1.0, 1.0]]) == 3.0


def test_candidates_touch_the_reach():
    """Each place tried has the box's side (or corner) nearest the anchor at reach + k·gap."""
    size = np.array([30.0, 10.0])
    for centre, rank, ring in candidates((100.0, 50.0), 8.0, size, None, 4.0):
        box = box_at(centre, size)
        near = np.clip((100.0, 50.0), box[:2], box[2:])
        d = np.hypot(*(near - (100.0, 50.0)))
        assert d >= 8.0 - 1e-9
    east = candidates((0.0, 0.0), 8.0, size, None, 4.0)[0]
    np.testing.assert_allclose(east[0], (8.0 + 15.0, 0.0))


def test_place_puts_four_names_of_one_point_apart():
    """Four equal names on one anchor: the greedy placement separates them all."""
    n = 4
    centres = place(np.zeros((n, 2)), [5.0] * n, [(40.0, 12.0)] * n, [None] * n,
                    frame=np.array([-200.0, -200.0, 200.0, 200.0]))
    boxes = [box_at(c, (40.0, 12.0)) for c in centres]
    for i in range(n):
        for j in range(i + 1, n):
            assert overlap(boxes[i], boxes[j]) == 0.0

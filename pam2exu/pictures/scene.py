"""A mechanism on matplotlib Axes: the box it moves in and one configuration drawn in it.

``extent`` is the box of everything drawn (the origin, every solid's origin and points, every
element's anchor points, and extra points such as traced paths) over every configuration to
be shown; ``Scene`` fixes the axes' limits to that box with a margin, draws the global frame
once, and ``Scene.show(t, q)`` draws one configuration with a ``Pen`` (each solid by
``Pen.solid``, each element by its own ``draw``, then the names), removing the previous one.
``draw`` shows one scene, ``animate`` one per frame.
"""
from __future__ import annotations

import numpy as np

from ..kinematics import State
from .pen import Pen
from .sheet import PALETTE

#: margin around the box the mechanism moves in, fraction of its larger side
MARGIN = 0.12
#: room the axis labels and the title take from the figure [in] (width, height)
LABEL_ROOM = np.array([0.9, 0.9])


#: the smallest font a title is shrunk to when its wrapped lines are still too wide [pt]
SMALLEST_TITLE = 6.0


def fit_title(fig, ax, text: str) -> None:
    """Give ``ax`` the title ``text``, wrapped onto more lines (then in a smaller font) as
    far as needed to stay inside the figure: centred over the axes, each half of it must fit
    between the axes' centre and the figure's nearer edge."""
    import textwrap
    ax.set_title(text)
    renderer = fig.canvas.get_renderer()

    def excess() -> float:
        """How much wider than its room the title is (≤ 1: it fits), after a layout."""
        fig.canvas.draw()
        box, axes = ax.title.get_window_extent(renderer), ax.get_window_extent(renderer)
        centre = 0.5 * (axes.x0 + axes.x1)
        room = 2.0 * min(centre - fig.bbox.x0, fig.bbox.x1 - centre) * 0.98
        return box.width / max(room, 1.0)

    over = excess()
    if over <= 1.0:
        return
    ax.set_title("\n".join(textwrap.wrap(text, max(12, int(len(text) / over * 0.95)))))
    size = ax.title.get_fontsize()
    while (over := excess()) > 1.0 and size > SMALLEST_TITLE:
        size = max(SMALLEST_TITLE, size / over)
        ax.title.set_fontsize(size)


def extent(mech, q_all, extra=()) -> tuple[np.ndarray, np.ndarray]:
    """Lower-left and upper-right corners [m] of the origin, every solid's origin and
    points, and every element's anchor points, over every row of q_all (n, 3·solids), and
    the ``extra`` points (k, 2)."""
    q_all = np.atleast_2d(q_all)
    st = State(np.zeros(len(q_all)), q_all)
    pts = [np.zeros((1, 2))]
    for i, s in enumerate(mech.solids):
        pts.append(st.point(i, (0.0, 0.0)).value)
        for p in s.points.values():
            pts.append(st.point(i, [float(v) for v in p]).value)
    for el in mech.elements:                   # line points, anchors given as bare solids
        for ref in el.refs:
            pts.append(st.point(ref.solid, ref.anchor_point).value)
    if len(extra):
        pts.append(np.asarray(extra, dtype=float).reshape(-1, 2))
    pts = np.vstack(pts)
    pts = pts[np.isfinite(pts).all(axis=1)]
    return pts.min(axis=0), pts.max(axis=0)


class Scene:
    """A mechanism on an Axes: fixed limits (the box it moves in), the global frame, and
    ``show(t, q)`` to draw one configuration (removing the previous one).

    ``extra`` points (n, 2) widen the box (traced paths).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The Axes to draw on; its limits, aspect, labels (``x [m]``, ``y [m]``) and grid
        are set here.
    mech : Mechanism
        The mechanism (``Model.mechanism()``).
    q_all : numpy.ndarray
        Every configuration that will be shown, shape (n, 3·solids) [m, m, rad]: the box
        holds all of them.
    extra : array_like
        More points to keep inside the box, shape (k, 2) [m].
    room : (float, float), optional
        Width and height [in] the axes may take (default: the figure less ``LABEL_ROOM``;
        a figure of two panels gives each its part).
    """

    def __init__(self, ax, mech, q_all: np.ndarray, extra=(), room=None):
        self.ax, self.mech = ax, mech
        self.locals = [np.array([[float(v) for v in p] for p in s.points.values()]
                                if s.points else np.zeros((0, 2))) for s in mech.solids]
        lo, hi = self._box(q_all, extra)
        self.size = float(max(hi - lo)) or 1.0
        moving = [i for i in range(len(mech.solids)) if i not in mech.held]
        colors = {i: PALETTE[k % len(PALETTE)] for k, i in enumerate(moving)}
        self.pen = Pen(ax, self.size, mech.held, colors)
        # the box with a margin, widened to the shape of the axes (the figure less room
        # for the labels and the title), then equal scales by shrinking the axes a little
        lo, hi = lo - MARGIN * self.size, hi + MARGIN * self.size
        width, height = (ax.figure.get_size_inches() - LABEL_ROOM if room is None
                         else np.asarray(room, dtype=float))
        centre, half = (lo + hi) / 2, (hi - lo) / 2
        half = np.maximum(half, half[::-1] * np.array([width / height, height / width]))
        ax.set_xlim(centre[0] - half[0], centre[0] + half[0])
        ax.set_ylim(centre[1] - half[1], centre[1] + half[1])
        ax.set_aspect("equal", adjustable="box")
        ax.set_autoscale_on(False)
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.grid(True, alpha=0.2)
        with self.pen.owner("frame"):
            self.pen.frame()
        self.pen.freeze()                      # the frame stays from frame to frame

    def _box(self, q_all, extra):
        """Lower-left and upper-right corners of everything drawn, over every row of q."""
        return extent(self.mech, q_all, extra)

    def show(self, t: float, q: np.ndarray) -> None:
        """Draw the configuration q (3·solids,) at time t.

        Parameters
        ----------
        t : float
            Time [s] (for elements whose symbol depends on it).
        q : array_like
            x [m], y [m], fi [rad] of each solid, shape (3·solids,).
        """
        self.pen.clear()
        st = State([t], np.asarray(q, dtype=float)[None, :])
        pen = self.pen
        for i, s in enumerate(self.mech.solids):
            origin = st.point(i, (0.0, 0.0)).value[0]
            points = np.array([st.point(i, p).value[0] for p in self.locals[i]]) \
                if len(self.locals[i]) else np.zeros((0, 2))
            with pen.owner(f"solid:{s.name}"):
                pen.solid(i, s.name, points, origin)
        for el in self.mech.elements:
            with pen.owner(f"{el.type}:{el.name}"):
                el.draw(pen, st)
                if el.equations:               # joints and actuators: their names
                    pen.name(el.name)
        pen.place_labels()

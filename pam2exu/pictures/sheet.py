"""What every symbol of a kinematic diagram is drawn with: the look and the bookkeeping.

The look: the colours, the sizes (fractions of ``size``, the larger side of the box the
mechanism moves in, so a drawing looks the same at any scale), the fonts and the drawing
order. ``Sheet``, the base of ``Pen`` (``pen.py``), keeps every artist it draws in
``artists`` (an animation removes them before the next frame), tags each with the gid of its
owner (``"revolute:A"``, ``"solid:crank"``), records the lines drawn (``marks``: what the
names keep off) and where each owner's symbol is, draws the primitive shapes in metres
(lines, polygons, circles, arrows, ground hatching), and writes texts and names, which
``place_labels`` moves where they overlap no other (the search is ``labels.py``).
"""
from __future__ import annotations

from contextlib import contextmanager

import numpy as np

#: colours of the moving solids, in model order (matplotlib's tab10 without its grey)
PALETTE = ("#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#bcbd22",
           "#17becf", "#393b79")   # (tab10 without its grey and its red, which is the actuators')
INK = "#222222"            # joints, springs, guides
GROUND = "#7f7f7f"         # grounded solids and supports
ACTUATOR = "#c0392b"       # actuators
LOAD = "#1e8449"           # applied torsors
UNMET = "#e6194b"          # constraints an initial guess does not meet
#: arrows of ``draw --vectors``: velocities, accelerations, reaction forces
VECTOR_COLORS = {"v": "#0d3b8c", "a": "#7b1fa2", "F": "#d35400"}

#: radius of a joint circle, as a fraction of the drawing's size
JOINT = 0.012
#: half-length of the guide of a moving solid, beyond its two points, fraction of the size
GUIDE = 0.12
#: length of a force arrow and of the global frame's axes, fraction of the size
ARROW, FRAME = 0.10, 0.08
#: height of the legend of ``vectors``, in axes fractions (under the x axis's label)
KEY_BELOW = -0.135
#: gap between a symbol and its name [points]
LABEL_OFFSET = 4.0
#: font sizes of the names of solids and of joints and actuators [points]
SOLID_FONT, ELEMENT_FONT = 9, 8

# drawing order (larger on top)
Z_GUIDE, Z_SOLID, Z_BAR, Z_SPRING, Z_BLOCK, Z_SUPPORT, Z_JOINT, Z_LOAD, Z_TEXT = range(1, 10)


def _unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    n = float(np.hypot(*v))
    return v / n if n > 0 else np.array([1.0, 0.0])


def _normal(d) -> np.ndarray:
    return np.array([-d[1], d[0]])


def hull(points: np.ndarray, tol: float = 0.0) -> np.ndarray:
    """Convex hull of 2-D points, counter-clockwise (monotone chain); collinear points are
    left out, so two points come back for a straight solid and one for a single point."""
    pts = np.unique(np.round(np.asarray(points, dtype=float), 12), axis=0)
    if len(pts) <= 2:
        return pts

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    def chain(seq):
        out = []
        for p in seq:
            while len(out) >= 2 and cross(out[-2], out[-1], p) <= tol:
                out.pop()
            out.append(p)
        return out

    lower, upper = chain(pts), chain(pts[::-1])
    return np.array(lower[:-1] + upper[:-1])


class Sheet:
    """The artists a pen draws on ``ax``, their owners and the names to place; sizes scale
    with ``size`` [m].

    Parameters
    ----------
    ax : matplotlib Axes
    size : float
        The larger side of the box the mechanism moves in [m].
    grounded : set of int
        Solids held by a fixed link: drawn in grey, their joints on supports.
    colors : dict
        Solid index → colour.
    """

    def __init__(self, ax, size: float, grounded=(), colors=None):
        self.ax = ax
        self.size = float(size)
        self.r = JOINT * self.size
        self.grounded = set(grounded)
        self.colors = dict(colors or {})
        self.artists: list = []
        #: names to place (``place_labels``): dicts of artist, anchor [m], reach [m],
        #: extra reach [points] and preferred direction
        self.labels: list[dict] = []
        #: what the drawing covers, in metres: polylines the names keep off
        self.marks: list[np.ndarray] = []
        #: where each owner's symbol is: gid → (point [m], reach [m], colour)
        self.symbols: dict[str, tuple[np.ndarray, float, str]] = {}
        #: the global frame's lines and texts, kept from frame to frame (``freeze``)
        self.static_marks: list[np.ndarray] = []
        self.static_texts: list = []
        #: the thin lines from a symbol to its name when it is far (``place_labels``)
        self.leaders: list = []
        self._gid: str | None = None

    # ---- bookkeeping -------------------------------------------------------------------
    @contextmanager
    def owner(self, gid: str):
        """Tag what is drawn inside the block with ``gid`` (``"type:name"``)."""
        before, self._gid = self._gid, gid
        try:
            yield self
        finally:
            self._gid = before

    def clear(self) -> None:
        """Remove everything this pen drew (since ``freeze``)."""
        for a in self.artists:
            a.remove()
        self.artists, self.labels, self.marks, self.symbols = [], [], [], {}
        self.leaders = []

    def freeze(self) -> None:
        """Keep what is drawn so far (the global frame) through every ``clear``: its lines and
        texts stay obstacles for the names."""
        from matplotlib.text import Text
        self.static_marks += self.marks
        self.static_texts += [a for a in self.artists if isinstance(a, Text)]
        self.artists, self.marks = [], []

    def _mark(self, xy) -> None:
        self.marks.append(np.asarray(xy, dtype=float).reshape(-1, 2))

    def _symbol(self, p, reach: float, color=INK) -> None:
        """Record the owner's symbol (its first one) for its name: at p, ``reach`` [m]."""
        if self._gid is not None and self._gid not in self.symbols:
            self.symbols[self._gid] = (np.asarray(p, dtype=float), float(reach), color)

    def color(self, solid: int) -> str:
        return GROUND if solid in self.grounded else self.colors.get(solid, INK)

    def _keep(self, artist):
        artist.set_gid(self._gid)
        self.artists.append(artist)
        return artist

    def _patch(self, patch):
        # add_artist, not add_patch: the limits are fixed, and updating the data limits
        # (Bézier extents of every patch) would cost more than drawing it
        return self._keep(self.ax.add_artist(patch))

    def _line(self, xy, **style):
        from matplotlib.lines import Line2D
        xy = np.asarray(xy, dtype=float)
        self._mark(xy)
        return self._keep(self.ax.add_artist(Line2D(xy[:, 0], xy[:, 1], **style)))

    def _polygon(self, xy, **style):
        from matplotlib.patches import Polygon
        xy = np.asarray(xy, dtype=float)
        self._mark(np.vstack([xy, xy[:1]]))
        return self._patch(Polygon(xy, closed=True, **style))

    def _circle(self, p, radius, **style):
        from matplotlib.patches import Circle
        a = np.linspace(0.0, 2.0 * np.pi, 17)
        self._mark(np.asarray(p, dtype=float) + radius * np.column_stack([np.cos(a), np.sin(a)]))
        return self._patch(Circle(tuple(p), radius, **style))

    def _arrow(self, a, b, color, width=2.0, head=12, z=Z_LOAD):
        from matplotlib.patches import FancyArrowPatch
        self._mark([a, b])
        return self._patch(FancyArrowPatch(tuple(a), tuple(b), arrowstyle="-|>",
                                           mutation_scale=head, color=color, lw=width,
                                           shrinkA=0, shrinkB=0, zorder=z))

    def _arc_arrow(self, c, radius, start, sweep, color, width=1.8):
        """An arc about c from angle ``start`` through ``sweep`` [rad] (counter-clockwise when
        positive) with an arrowhead at its end."""
        a = start + np.linspace(0.0, sweep, 40)
        xy = np.asarray(c) + radius * np.column_stack([np.cos(a), np.sin(a)])
        self._line(xy, color=color, lw=width, solid_capstyle="butt", zorder=Z_LOAD)
        end, tangent = xy[-1], np.sign(sweep) * _normal(_unit(xy[-1] - np.asarray(c)))
        h = 0.9 * self.r
        tip = end + 1.6 * h * tangent
        base = end - 0.2 * h * tangent
        n = _normal(tangent)
        self._polygon([tip, base + h * n, base - h * n], color=color, zorder=Z_LOAD)

    def _hatch(self, centre, width: float):
        """A ground line of ``width`` centred at ``centre`` with short strokes below it."""
        centre = np.asarray(centre, dtype=float)
        left, right = centre - [width / 2, 0.0], centre + [width / 2, 0.0]
        self._line([left, right], color=INK, lw=1.6, zorder=Z_SUPPORT)
        k = max(3, int(round(width / (1.2 * self.r))))
        x = np.linspace(left[0] + 0.9 * self.r, right[0], k)
        y = np.full(k, centre[1])
        gap = np.full(k, np.nan)                 # the strokes as one line, NaN-separated
        strokes = np.column_stack([x, y, x - 0.9 * self.r, y - 0.9 * self.r, gap, gap])
        self._line(strokes.reshape(-1, 2), color=INK, lw=0.9, zorder=Z_SUPPORT)

    def text(self, p, text: str, color=INK, offset=(0.0, 0.0), **style):
        """Text centred ``offset`` points away from p (data coordinates), outlined in white."""
        import matplotlib.patheffects as pe
        t = self.ax.annotate(text, tuple(p), xytext=tuple(offset), textcoords="offset points",
                             color=color, ha="center", va="center", zorder=Z_TEXT,
                             annotation_clip=True,
                             path_effects=[pe.withStroke(linewidth=3, foreground="white")],
                             **{"fontsize": 9, **style})
        return self._keep(t)

    def label(self, p, text: str, away, color, reach: float = 0.0, extra: float = 0.0,
              **style):
        """A name near p, placed by ``place_labels`` (after everything is drawn) where it
        overlaps no other name: preferably along ``away`` (zero: on p; None: any side),
        clear of ``reach`` [m] plus ``extra`` [points] around p."""
        t = self.text(p, text, color, **style)
        self.labels.append(dict(artist=t, anchor=np.asarray(p, dtype=float), reach=reach,
                                extra=extra, prefer=None if away is None
                                else np.asarray(away, dtype=float)))
        return t

    def name(self, text: str) -> None:
        """The name of the owner (a joint, an actuator) beside its symbol, in its colour;
        nothing when the owner drew no symbol with a place (``_symbol``)."""
        if self._gid in self.symbols:
            p, reach, color = self.symbols[self._gid]
            self.label(p, text, None, color, reach=reach, extra=1.0, fontsize=ELEMENT_FONT)

    def place_labels(self) -> None:
        """Move every name to its place (``labels.place``): no two names overlap when it
        can be helped, few lines are covered. Uses the figure's renderer: call it once the
        axes have their final size."""
        from .labels import place, sample
        for line in self.leaders:              # placed before: placed again
            line.remove()
            self.artists.remove(line)
        self.leaders = []
        if not self.labels:
            return
        fig = self.ax.figure
        renderer = fig.canvas.get_renderer()
        to_px = self.ax.transData.transform
        px_per_m = float(np.hypot(*(to_px([1.0, 0.0]) - to_px([0.0, 0.0]))))
        px_per_pt = fig.dpi / 72.0
        anchors, sizes = [], []
        for lab in self.labels:
            lab["artist"].xyann = (0.0, 0.0)
            box = lab["artist"].get_window_extent(renderer)
            anchors.append(to_px(lab["anchor"]))
            sizes.append((box.width + 2.0 * px_per_pt, box.height))   # the white outline
        reaches = [lab["reach"] * px_per_m + (lab["extra"] + LABEL_OFFSET) * px_per_pt
                   for lab in self.labels]
        marks = self.static_marks + self.marks
        lines = np.vstack([sample(to_px(m)) for m in marks]) if marks else ()
        fixed = [t.get_window_extent(renderer).extents for t in self.static_texts]
        centres = place(np.array(anchors), reaches, sizes, [lab["prefer"] for lab in self.labels],
                        lines, fixed, self.ax.bbox.extents, gap=LABEL_OFFSET * px_per_pt)
        to_data = self.ax.transData.inverted().transform
        gap = LABEL_OFFSET * px_per_pt
        for lab, centre, anchor, size, reach in zip(self.labels, centres, anchors, sizes,
                                                    reaches):
            lab["artist"].xyann = tuple((centre - anchor) / px_per_pt)
            # far from its symbol (a crowd): a thin leader from the symbol to the name
            half = np.asarray(size) / 2
            near = np.clip(anchor, centre - half, centre + half)
            if np.hypot(*(near - anchor)) > reach + 2.0 * gap:
                u = _unit(near - anchor)
                ends = to_data(np.array([anchor + (reach - gap) * u, near - 2.0 * u]))
                self.leaders.append(self._line(ends, color=lab["artist"].get_color(), lw=0.6,
                                               alpha=0.7, zorder=Z_TEXT))
                self.marks.pop()

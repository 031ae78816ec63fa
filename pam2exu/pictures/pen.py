"""The symbols of a kinematic diagram, drawn on a matplotlib Axes in metres.

Each element class says *what* its picture is and *where* (``Element.draw(pen, st)``: a
pin joint at this point, a guide along this line, a spring between these two points), the
way ``Element.build(ex)`` says which Exudyn items it becomes. ``Pen`` says *how* each symbol
looks: sizes, colours, line styles. So the element modules never import matplotlib, and a
new symbol or a new look is a change here only.

Sizes are fractions of ``size``, the larger side of the box the mechanism moves in, so a
drawing looks the same at any scale. Every artist a pen draws is kept in ``artists`` (an
animation removes them before the next frame) and tagged with the gid of its owner
(``"revolute:A"``, ``"solid:crank"``), which tests and SVG files can look up.
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


class Pen:
    """Draws diagram symbols on ``ax``; sizes scale with ``size`` [m].

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

    # ---- solids ------------------------------------------------------------------------
    def solid(self, solid: int, name: str, points: np.ndarray, origin: np.ndarray) -> None:
        """A solid: the convex hull of its points and origin (a bar when they are collinear),
        its name beside it. A grounded solid: grey dots at its points, its name at its
        origin (its points may lie far apart: a hull would cover the drawing)."""
        color = self.color(solid)
        everything = np.vstack([origin[None], points]) if len(points) else origin[None]
        if solid in self.grounded:
            self._line(everything, linestyle="none", marker="o", markersize=3.5,
                       color=GROUND, zorder=Z_SOLID)
            self.label(origin, name, np.array([0.0, -1.0]), GROUND, reach=2.8 * self.r,
                       fontstyle="italic", fontsize=SOLID_FONT)
            return
        shape = hull(everything, tol=1e-12 * self.size ** 2)
        extra = 0.0
        if len(shape) == 1:
            self._circle(shape[0], 0.8 * self.r, color=color, zorder=Z_SOLID)
            where, away = shape[0], np.array([0.0, 1.0])
        elif len(shape) == 2:
            self._line(shape, color=color, lw=7, alpha=0.85, solid_capstyle="round",
                       zorder=Z_SOLID)
            where, extra = shape.mean(axis=0), 3.5          # half the bar's width [points]
            away = _normal(_unit(shape[1] - shape[0]))
            away = away if away[1] >= 0 else -away
        else:
            self._polygon(shape, facecolor=color, alpha=0.30, edgecolor="none",
                          zorder=Z_SOLID)
            self._polygon(shape, facecolor="none", edgecolor=color, lw=2.2,
                          joinstyle="round", zorder=Z_SOLID)
            where, away = shape.mean(axis=0), np.zeros(2)
        self.label(where, name, away, color, reach=0.8 * self.r if len(shape) == 1 else 0.0,
                   extra=extra, fontweight="bold", fontsize=SOLID_FONT)

    def frame(self) -> None:
        """The global frame's x and y axes at the origin."""
        length = FRAME * self.size
        for d, name in (([1.0, 0.0], "x"), ([0.0, 1.0], "y")):
            tip = length * np.asarray(d)
            self._arrow([0.0, 0.0], tip, GROUND, width=1.0, head=8, z=Z_GUIDE)
            self.text(tip, name, GROUND, offset=(-7, 4) if name == "y" else (4, -7),
                      fontstyle="italic")

    # ---- joints ------------------------------------------------------------------------
    def joint(self, p, solids=()) -> None:
        """A pin joint: a circle; on a support (triangle and ground) when it holds a
        grounded solid to a moving one."""
        p = np.asarray(p, dtype=float)
        r = self.r
        self._symbol(p, r)
        if any(s in self.grounded for s in solids) and not all(s in self.grounded
                                                                for s in solids):
            self._polygon([p, p + [-1.7 * r, -2.8 * r], p + [1.7 * r, -2.8 * r]],
                          facecolor="#dddddd", edgecolor=INK, lw=1.2, zorder=Z_SUPPORT)
            self._hatch(p + [0.0, -2.8 * r], 5.0 * r)
        self._circle(p, r, facecolor="white", edgecolor=INK, lw=1.5, zorder=Z_JOINT)

    def clearance(self, p) -> None:
        """A joint with clearance (``clearance = true``, the clearance analysis): a dashed
        ring around its symbol."""
        self._circle(p, 2.2 * self.r, facecolor="none", edgecolor=INK, lw=1.1,
                     linestyle=(0, (3, 2)), zorder=Z_JOINT)

    def pin(self, p) -> None:
        """A pin that slides in a slot: a small filled circle."""
        self._symbol(p, 0.65 * self.r)
        self._circle(p, 0.65 * self.r, facecolor=INK, edgecolor="white", lw=0.8,
                     zorder=Z_JOINT)

    def ground(self, p) -> None:
        """A fixed link: a wide ground line under the point."""
        self._symbol(np.asarray(p, dtype=float) + [0.0, -3.2 * self.r], 0.6 * self.r)
        self._hatch(np.asarray(p, dtype=float) + [0.0, -2.8 * self.r], 8.0 * self.r)

    def guide(self, p, direction, follower, solid: int) -> None:
        """A guide line through p along ``direction``: across the whole drawing when its
        solid is grounded, else from p to past the follower (the other solid's point)."""
        p, d = np.asarray(p, dtype=float), _unit(direction)
        if solid in self.grounded:
            a, b = -3.0 * self.size, 3.0 * self.size
        else:
            s = float(np.dot(np.asarray(follower, dtype=float) - p, d))
            a, b = min(0.0, s) - GUIDE * self.size, max(0.0, s) + GUIDE * self.size
        self._line([p + a * d, p + b * d], color=self.color(solid), lw=1.3,
                   linestyle=(0, (7, 4)), zorder=Z_GUIDE)

    def block(self, p, direction, solid: int) -> None:
        """A slider block centred at p, along ``direction``."""
        p, d = np.asarray(p, dtype=float), _unit(direction)
        n, a, b = _normal(d), 2.6 * self.r, 1.6 * self.r
        self._symbol(p, 2.0 * self.r)
        self._polygon([p - a * d - b * n, p + a * d - b * n, p + a * d + b * n,
                       p - a * d + b * n], facecolor=self.color(solid), alpha=0.9,
                      edgecolor=INK, lw=1.2, zorder=Z_BLOCK)

    def gears(self, c1, c2, ratio: float, solids) -> None:
        """Pitch circles of a gear pair whose centres are c1, c2: radii in the ratio |T|,
        touching (r1 + r2 = |c1c2|); fixed radii when the centres coincide."""
        c1, c2 = np.asarray(c1, dtype=float), np.asarray(c2, dtype=float)
        d = float(np.hypot(*(c2 - c1)))
        k = abs(float(ratio)) or 1.0
        if d < 1e-9 * self.size:
            r1, r2 = 4.0 * self.r, 4.0 * self.r / k
        else:
            r2 = d / (1.0 + k)
            r1 = d - r2
        self._symbol(c1 + r1 * _unit(c2 - c1), 0.5 * self.r)
        for c, radius, s in ((c1, r1, solids[0]), (c2, r2, solids[1])):
            self._circle(c, radius, facecolor="none", edgecolor=self.color(s), lw=1.6,
                         linestyle="-.", zorder=Z_SPRING)

    # ---- forces ------------------------------------------------------------------------
    def zigzag(self, p, q, coils: int = 6) -> None:
        """A spring between p and q: straight leads, then a zigzag."""
        p, q = np.asarray(p, dtype=float), np.asarray(q, dtype=float)
        length = float(np.hypot(*(q - p)))
        for end in (p, q):
            self._circle(end, 0.35 * self.r, color=INK, zorder=Z_SPRING)
        if length < 1e-9 * self.size:
            return
        d, n = (q - p) / length, _normal((q - p) / length)
        s = np.r_[0.0, 0.2, 0.2 + 0.6 * (np.arange(2 * coils) + 0.5) / (2 * coils), 0.8, 1.0]
        side = np.r_[0.0, 0.0, np.tile([1.0, -1.0], coils), 0.0, 0.0]
        xy = p + np.outer(s * length, d) + np.outer(side * 1.1 * self.r, n)
        self._line(xy, color=INK, lw=1.3, solid_joinstyle="miter", zorder=Z_SPRING)

    def spiral(self, c) -> None:
        """A torsional spring about c: a spiral of two and a half turns."""
        a = np.linspace(0.0, 5.0 * np.pi, 200)
        radius = self.r * (1.3 + 2.2 * a / a[-1])
        xy = np.asarray(c, dtype=float) + np.column_stack([radius * np.cos(a),
                                                           radius * np.sin(a)])
        self._line(xy, color=INK, lw=1.1, zorder=Z_SPRING)

    def force(self, p, f) -> None:
        """An applied force at p: an arrow from p along f (fixed length, not to scale)."""
        p = np.asarray(p, dtype=float)
        self._arrow(p, p + ARROW * self.size * _unit(f), LOAD)

    def moment(self, p, m: float) -> None:
        """An applied moment at p: an arc arrow, counter-clockwise when m > 0."""
        self._arc_arrow(p, 2.4 * self.r, -0.75 * np.pi * np.sign(m) + np.pi / 2,
                        1.5 * np.pi * np.sign(m), LOAD)

    def rotation(self, c) -> None:
        """An angular actuator about c: an arc arrow, counter-clockwise (the sense of a
        positive f(t)), open at the bottom, where a support may be."""
        self._symbol(c, 4.2 * self.r, ACTUATOR)
        self._arc_arrow(c, 3.6 * self.r, -0.5 * np.pi + 0.75, 2.0 * np.pi - 1.9, ACTUATOR,
                        width=2.2)

    def cylinder(self, p, q) -> None:
        """A linear actuator: a thick bar from P to Q."""
        self._symbol((np.asarray(p, dtype=float) + q) / 2, 0.6 * self.r, ACTUATOR)
        self._line([p, q], color=ACTUATOR, lw=9, alpha=0.45, solid_capstyle="butt",
                   zorder=Z_BAR)
        self._line([p, q], color=ACTUATOR, lw=1.5, zorder=Z_BAR)

    def centre(self, p, solid: int, name: str) -> None:
        """A solid's instantaneous centre of rotation: a ringed cross in its colour, named
        ``I <solid>``."""
        p, r, color = np.asarray(p, dtype=float), 1.1 * self.r, self.color(solid)
        self._circle(p, r, facecolor="white", edgecolor=color, lw=1.4, zorder=Z_LOAD)
        self._line([p - [1.8 * r, 0.0], p + [1.8 * r, 0.0], [np.nan, np.nan],
                    p - [0.0, 1.8 * r], p + [0.0, 1.8 * r]], color=color, lw=1.2,
                   zorder=Z_LOAD)
        self.label(p, f"I {name}", None, color, reach=1.8 * r, fontsize=ELEMENT_FONT,
                   fontstyle="italic")

    def unmet(self, points) -> None:
        """A constraint the drawing does not meet (an initial guess): a red dotted line
        through its anchor points, and its name in red."""
        points = np.asarray(points, dtype=float).reshape(-1, 2)
        if len(points) > 1:
            self._line(points, color=UNMET, lw=1.4, linestyle=(0, (1.5, 1.5)),
                       marker="x", markersize=5, zorder=Z_TEXT)
        for lab in self.labels:
            if lab["artist"].get_gid() == self._gid:
                lab["artist"].set_color(UNMET)

    def vectors(self, points, values, scale: float, color, key: tuple[float, str]):
        """Arrows from ``points`` (n, 2) [m] along ``values`` (n, 2), ``scale`` metres of
        drawing per unit (a quiver: its U, V are the values, its X, Y the points, its
        scale 1 / ``scale`` in x units, the same as y units), and the
        legend's arrow standing for ``key`` = (value, text), under the axes. Zero arrows
        (and all when ``scale`` is 0) are left out."""
        points, values = np.asarray(points, dtype=float), np.asarray(values, dtype=float)
        drawn = (np.hypot(*values.T) * scale > 1e-9 * self.size if scale
                 else np.zeros(len(values), bool))
        # the legend: the key's arrow (its length the round one), then the text, under the
        # x axis's label (a text of the axes, so that the layout makes room for it)
        x0, x1 = self.ax.get_xlim()
        arrow = key[0] * scale / (x1 - x0)
        where = KEY_BELOW
        self._keep(self.ax.text(arrow + 0.015 if np.any(drawn) else 0.0, where, key[1],
                                transform=self.ax.transAxes, color=color, fontsize=9,
                                ha="left", va="center", gid=self._gid))
        if not np.any(drawn):
            return None
        points, values = points[drawn], values[drawn]
        for p, v in zip(points, values):
            self._mark([p, p + scale * v])
        style = dict(color=color, width=0.004, headwidth=3.5, headlength=4.5,
                     headaxislength=4.0, zorder=Z_LOAD)
        q = self._keep(self.ax.quiver(points[:, 0], points[:, 1], values[:, 0], values[:, 1],
                                      # lengths and angles in data units (equal
                                      # scales); "xy" would divide by the size of the
                                      # data limits, 0 for arrows from one point
                                      angles=np.degrees(np.arctan2(values[:, 1],
                                                                   values[:, 0])),
                                      scale_units="x", scale=1.0 / scale,
                                      **style))
        self._keep(self.ax.quiverkey(q, arrow, where, key[0], " ", labelpos="E",
                                     coordinates="axes", color=color))
        return q

    # ---- free-body sketches (docs/make_free_body.py) ------------------------------------
    def arrow(self, a, b, color=INK, width: float = 2.0, head: float = 12) -> None:
        """A straight arrow from a to b: a force of a free-body sketch, drawn to scale."""
        self._arrow(a, b, color, width=width, head=head)

    def arc_arrow(self, c, radius: float, start: float, sweep: float, color=INK,
                  width: float = 1.8) -> None:
        """An arc arrow about c (a moment) from angle ``start`` through ``sweep`` [rad],
        counter-clockwise when ``sweep`` > 0, its head at the end."""
        self._arc_arrow(c, radius, start, sweep, color, width)

    def plate(self, outline, color, alpha: float = 0.30) -> None:
        """A solid of any shape: the polygon ``outline``, lightly filled and outlined (the
        look of ``solid`` for a solid with three points or more)."""
        self._polygon(outline, facecolor=color, alpha=alpha, edgecolor="none", zorder=Z_SOLID)
        self._polygon(outline, facecolor="none", edgecolor=color, lw=2.2, joinstyle="round",
                      zorder=Z_SOLID)

    def bar(self, p, q, color, width: float = 7.0) -> None:
        """A straight solid from p to q with round ends (the look of ``solid`` for a solid
        whose points are collinear)."""
        self._line([p, q], color=color, lw=width, alpha=0.85, solid_capstyle="round",
                   zorder=Z_SOLID)

    def basis(self, p, direction, length: float, names=("x", "y"), color=GROUND) -> None:
        """Small axes at p: x along ``direction``, y turned +90° from it, each labelled
        beside its tip (``names``)."""
        p, d = np.asarray(p, dtype=float), _unit(direction)
        for axis, name in ((d, names[0]), (_normal(d), names[1])):
            tip = p + length * axis
            self._arrow(p, tip, color, width=1.0, head=8, z=Z_GUIDE)
            side = -_normal(axis) if axis is d else _normal(axis)   # x below, y to the left
            self.text(tip, name, color, offset=tuple(8.0 * side + 3.0 * axis),
                      fontstyle="italic")

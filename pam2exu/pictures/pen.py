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

#: radius of a joint circle, as a fraction of the drawing's size
JOINT = 0.012
#: half-length of the guide of a moving solid, beyond its two points, fraction of the size
GUIDE = 0.12
#: length of a force arrow and of the global frame's axes, fraction of the size
ARROW, FRAME = 0.10, 0.08
#: gap between a solid's shape and its name [points]
LABEL_OFFSET = 7.0

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
        self.labels: list[np.ndarray] = []          # where the solids' names are
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
        """Remove everything this pen drew."""
        for a in self.artists:
            a.remove()
        self.artists, self.labels = [], []

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
        return self._keep(self.ax.add_artist(Line2D(xy[:, 0], xy[:, 1], **style)))

    def _polygon(self, xy, **style):
        from matplotlib.patches import Polygon
        return self._patch(Polygon(np.asarray(xy, dtype=float), closed=True, **style))

    def _circle(self, p, radius, **style):
        from matplotlib.patches import Circle
        return self._patch(Circle(tuple(p), radius, **style))

    def _arrow(self, a, b, color, width=2.0, head=12, z=Z_LOAD):
        from matplotlib.patches import FancyArrowPatch
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
                             color=color, fontsize=9, ha="center", va="center",
                             zorder=Z_TEXT, annotation_clip=True,
                             path_effects=[pe.withStroke(linewidth=3, foreground="white")],
                             **style)
        return self._keep(t)

    def label(self, p, text: str, away, color, **style):
        """A solid's name near p, ``LABEL_OFFSET`` points along ``away``; on the other side
        when another name is already close there."""
        p, away = np.asarray(p, dtype=float), np.asarray(away, dtype=float)
        near = 5.0 * self.r
        for side in (away, -away):
            if not any(np.hypot(*(q - (p + near * side))) < near for q in self.labels):
                away = side
                break
        self.labels.append(p + near * away)
        # clear of the shape: the text's half extent along ``away`` (9-point letters about
        # 5.6 points wide), plus the gap
        reach = LABEL_OFFSET + abs(away[0]) * 2.8 * len(text) + abs(away[1]) * 4.5
        return self.text(p, text, color, offset=reach * away, **style)

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
            self.label(origin, name, np.array([0.0, -1.9]), GROUND, fontstyle="italic")
            return
        shape = hull(everything, tol=1e-12 * self.size ** 2)
        if len(shape) == 1:
            self._circle(shape[0], 0.8 * self.r, color=color, zorder=Z_SOLID)
            where, away = shape[0], np.array([0.0, 1.0])
        elif len(shape) == 2:
            self._line(shape, color=color, lw=7, alpha=0.85, solid_capstyle="round",
                       zorder=Z_SOLID)
            where = shape.mean(axis=0)
            away = _normal(_unit(shape[1] - shape[0]))
            away = away if away[1] >= 0 else -away
        else:
            self._polygon(shape, facecolor=color, alpha=0.30, edgecolor="none",
                          zorder=Z_SOLID)
            self._polygon(shape, facecolor="none", edgecolor=color, lw=2.2,
                          joinstyle="round", zorder=Z_SOLID)
            where, away = shape.mean(axis=0), np.zeros(2)
        self.label(where, name, away, color, fontweight="bold")

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
        self._circle(p, 0.65 * self.r, facecolor=INK, edgecolor="white", lw=0.8,
                     zorder=Z_JOINT)

    def ground(self, p) -> None:
        """A fixed link: a wide ground line under the point."""
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
        self._arc_arrow(c, 3.6 * self.r, -0.5 * np.pi + 0.75, 2.0 * np.pi - 1.9, ACTUATOR,
                        width=2.2)

    def cylinder(self, p, q) -> None:
        """A linear actuator: a thick bar from P to Q."""
        self._line([p, q], color=ACTUATOR, lw=9, alpha=0.45, solid_capstyle="butt",
                   zorder=Z_BAR)
        self._line([p, q], color=ACTUATOR, lw=1.5, zorder=Z_BAR)

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

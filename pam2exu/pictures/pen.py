"""The symbols of a kinematic diagram, drawn on a matplotlib Axes in metres.

Each element class says *what* its picture is and *where* (``Element.draw(pen, st)``: a
pin joint at this point, a guide along this line, a spring between these two points), the
way ``Element.build(ex)`` says which Exudyn items it becomes. ``Pen`` says *how* each symbol
looks: sizes, colours, line styles. So the element modules never import matplotlib, and a
new symbol or a new look is a change here (and in ``sheet.py``) only.

Sizes are fractions of ``size``, the larger side of the box the mechanism moves in, so a
drawing looks the same at any scale. Every artist a pen draws is kept in ``artists`` (an
animation removes them before the next frame) and tagged with the gid of its owner
(``"revolute:A"``, ``"solid:crank"``), which tests and SVG files can look up. Here are
the symbols; the colours, sizes and drawing order, the primitive shapes and the names'
placement are ``Sheet``'s (``sheet.py``), re-exported here.
"""
from __future__ import annotations

import numpy as np

from .sheet import (ACTUATOR, ARROW, ELEMENT_FONT, FRAME, GROUND, GUIDE, INK, JOINT, KEY_BELOW,
                    LABEL_OFFSET, LOAD, PALETTE, SOLID_FONT, UNMET, VECTOR_COLORS, Z_BAR,
                    Z_BLOCK, Z_GUIDE, Z_JOINT, Z_LOAD, Z_SOLID, Z_SPRING, Z_SUPPORT, Z_TEXT,
                    Sheet, _normal, _unit, hull)

#: the look is ``sheet.py``'s, and importable from here, where it was first defined
__all__ = ["Pen", "hull", "PALETTE", "INK", "GROUND", "ACTUATOR", "LOAD", "UNMET",
           "VECTOR_COLORS", "JOINT", "GUIDE", "ARROW", "FRAME", "KEY_BELOW", "LABEL_OFFSET",
           "SOLID_FONT", "ELEMENT_FONT", "Z_GUIDE", "Z_SOLID", "Z_BAR", "Z_SPRING", "Z_BLOCK",
           "Z_SUPPORT", "Z_JOINT", "Z_LOAD", "Z_TEXT"]


class Pen(Sheet):
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
        self.mark(p, f"I {name}", self.color(solid))

    def mark(self, p, text: str, color=INK) -> None:
        """A point of a construction (an instantaneous centre, a pole): a ringed cross in
        ``color``, named ``text`` in italics."""
        p, r = np.asarray(p, dtype=float), 1.1 * self.r
        self._circle(p, r, facecolor="white", edgecolor=color, lw=1.4, zorder=Z_LOAD)
        self._line([p - [1.8 * r, 0.0], p + [1.8 * r, 0.0], [np.nan, np.nan],
                    p - [0.0, 1.8 * r], p + [0.0, 1.8 * r]], color=color, lw=1.2,
                   zorder=Z_LOAD)
        self.label(p, text, None, color, reach=1.8 * r, fontsize=ELEMENT_FONT,
                   fontstyle="italic")

    def construction(self, xy, color=GROUND, linestyle="-", width: float = 1.0) -> None:
        """A line of a construction (a Kennedy line, a centrode, a circle): the polyline
        ``xy`` (k, 2) [m], broken at rows of NaN, under the solids."""
        self._line(xy, color=color, lw=width, linestyle=linestyle, zorder=Z_GUIDE)

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

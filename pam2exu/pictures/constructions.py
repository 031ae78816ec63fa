"""The graphical methods drawn: the polygon beside the mechanism (``draw --polygon v|a``),
every instantaneous centre with the Kennedy lines (``draw --ic all``), and a solid's
centrodes with its inflection circle (``draw --centrodes SOLID``).

The numbers are ``graphical.py``'s (``Polygon``, ``Centres``, ``Centrodes``); here is only
how they look. Every artist carries a gid: ``polygon:absolute:<point>``,
``polygon:relative:<solid>.<Q>/<P>``, ``polygon:normal:…``, ``polygon:tangential:…``,
``polygon:scale``, ``centre:I13``, ``kennedy:1-2-3``, ``centrode:fixed``,
``centrode:moving``, ``inflection``.
"""
from __future__ import annotations

import numpy as np

from .sheet import ELEMENT_FONT, GROUND, INK, VECTOR_COLORS, Z_LOAD, Sheet, _unit
from .vectors import round_length

#: the scale bar is about this fraction of the polygon's size (a round value)
SCALE_BAR = 0.25
#: margin around the polygon, fraction of its size
POLYGON_MARGIN = 0.15
#: what the line styles of the polygon mean (its legend)
POLYGON_KEY = "— absolute (from the pole o)   - - relative, in the link's colour"
ACCELERATION_KEY = "   ··· normal −ω²(Q − P)   -· tangential α Ω(Q − P)"
#: the fixed and the moving centrode, the inflection circle
FIXED_CENTRODE, INFLECTION = "#222222", "#c0392b"


class PolygonPen(Sheet):
    """Draws a polygon on its own Axes, in units of the vectors (m/s or m/s²): ``size`` is
    the polygon's larger side."""

    def vector(self, a, b, color, linestyle="-", width=1.6) -> None:
        """An arrow from a to b (left out when shorter than 1e-9 of the size)."""
        from matplotlib.patches import FancyArrowPatch
        a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
        if np.hypot(*(b - a)) <= 1e-9 * self.size:
            return
        self._mark([a, b])
        self._patch(FancyArrowPatch(tuple(a), tuple(b), arrowstyle="-|>", mutation_scale=11,
                                    color=color, lw=width, linestyle=linestyle, shrinkA=0,
                                    shrinkB=0, zorder=Z_LOAD))

    def pole(self, text: str) -> None:
        """The pole o at the origin of the polygon, with ``text``."""
        self._circle((0.0, 0.0), 0.5 * self.r, color=INK, zorder=Z_LOAD)
        self.label((0.0, 0.0), text, np.array([-1.0, -1.0]), INK, reach=self.r, extra=1.0,
                   fontsize=ELEMENT_FONT, fontweight="bold")

    def scale_bar(self, length: float, unit: str, lo) -> None:
        """A bar of ``length`` [unit] with end ticks and its value, above the corner ``lo``."""
        lo = np.asarray(lo, dtype=float)
        tick = np.array([0.0, 0.6 * self.r])
        ends = [lo + tick, lo, lo + [length, 0.0], lo + [length, 0.0] + tick]
        self._line(ends, color=INK, lw=2.0, zorder=Z_LOAD)
        self.text(lo + [length / 2, 0.0], f"{length:g} {unit}", offset=(0.0, 9.0),
                  fontsize=ELEMENT_FONT)


def _fmt(x: float, unit: str) -> str:
    return f"{x:.4g} {unit}"


def draw_polygon(ax, poly, colors: dict[str, str]) -> PolygonPen:
    """The polygon ``poly`` (``graphical.Polygon``) on ``ax``: the absolute vectors from the
    pole o (points with the same vector share one arrow and one name), each link's relative
    vectors between its points' images in its colour (for accelerations also their normal
    and tangential components, head to tail; one from a point at the pole is its absolute
    vector, drawn once), a scale bar and the legend; returns the pen
    (its names are placed once the figure is laid out: ``Sheet.place_labels``)."""
    ends = [np.zeros((1, 2))] + [v.value[None] for v in poly.absolute]
    ends += [(poly.image(f"{r.solid}.{r.start}" if r.start else r.solid) + r.normal)[None]
             for r in poly.relative if r.normal is not None]
    pts = np.vstack(ends)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    size = float(max(hi - lo)) or 1.0
    lo, hi = lo - POLYGON_MARGIN * size, hi + POLYGON_MARGIN * size
    lo[1] -= 0.1 * size                                       # room for the scale bar
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal", adjustable="box")
    ax.set_autoscale_on(False)
    ax.set_axis_off()
    pen = PolygonPen(ax, size)
    color = VECTOR_COLORS[poly.kind]
    groups: dict[tuple, list] = {}
    for v in poly.absolute:
        key = tuple(np.round(v.value / (1e-9 * size)).astype(int))
        groups.setdefault(key, []).append(v)
    at_pole = []
    for members in groups.values():
        tip = members[0].value
        names = ", ".join(v.name for v in members)
        if np.hypot(*tip) <= 1e-9 * size:
            at_pole += [v.name for v in members]
            continue
        with pen.owner(f"polygon:absolute:{members[0].name}"):
            pen.vector((0.0, 0.0), tip, color, width=2.0)
            pen.label(tip, f"{names}\n{_fmt(float(np.hypot(*tip)), poly.unit)}", tip, color,
                      reach=pen.r, fontsize=ELEMENT_FONT)
    with pen.owner("polygon:pole"):
        pen.pole("o" + (f" ({', '.join(at_pole)})" if at_pole else ""))
    for r in poly.relative:
        start = poly.image(f"{r.solid}.{r.start}" if r.start else r.solid)
        end = start + r.value
        link = colors.get(r.solid, INK)
        if r.normal is not None:
            with pen.owner(f"polygon:normal:{r.name}"):
                pen.vector(start, start + r.normal, link, linestyle=":", width=1.2)
            with pen.owner(f"polygon:tangential:{r.name}"):
                pen.vector(start + r.normal, end, link, linestyle="-.", width=1.2)
        if np.hypot(*start) <= 1e-9 * size:       # from the pole: the absolute vector
            continue
        with pen.owner(f"polygon:relative:{r.name}"):
            pen.vector(start, end, link, linestyle="--", width=1.3)
            if np.hypot(*r.value) > 1e-9 * size:
                pen.label((start + end) / 2, f"{r.end}/{r.start} "
                          f"{_fmt(float(np.hypot(*r.value)), poly.unit)}", None, link,
                          fontsize=ELEMENT_FONT - 1)
    with pen.owner("polygon:scale"):
        bar = round_length(SCALE_BAR * size)
        pen.scale_bar(bar, poly.unit, lo + 0.04 * size)
    what = "velocity" if poly.kind == "v" else "acceleration"
    ax.set_title(f"{what} polygon, t = {poly.t:g} s", fontsize=10)
    ax.text(0.0, -0.02, POLYGON_KEY + (ACCELERATION_KEY if poly.kind == "a" else ""),
            transform=ax.transAxes, fontsize=7, color=GROUND, va="top", ha="left")
    return pen


def visible(points, lo, hi, far: float, size: float) -> np.ndarray:
    """Which points (n, 2) are finite and within ``far`` sizes of the box [lo, hi]."""
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    off = np.maximum(np.maximum(lo - p, p - hi), 0.0)
    ok = np.isfinite(p).all(axis=1)
    ok[ok] = off[ok].max(axis=1) <= far * size
    return ok


def draw_centres(pen, found, shown: set) -> None:
    """Every centre of ``found`` (``graphical.Centres``) whose label is in ``shown`` (a ringed
    cross, ``I13``), and each Kennedy line with two or three of them shown, through them and
    a little beyond (thin, dashed, grey)."""
    for line in found.lines:
        pts = [c.point for c in line.centres if c.label in shown]
        if len(pts) < 2:
            continue
        pts = np.array(pts)
        a, b = max(((a, b) for a in pts for b in pts), key=lambda ab: np.hypot(*(ab[1] - ab[0])))
        d = _unit(b - a)
        s = (pts - pts[0]) @ d
        a, b = pts[0] + (s.min() - 0.06 * pen.size) * d, pts[0] + (s.max() + 0.06 * pen.size) * d
        with pen.owner("kennedy:" + "-".join(map(str, line.bodies))):
            pen.construction([a, b], GROUND, linestyle=(0, (5, 3)), width=0.8)
    for c in found.centres:
        if c.label in shown:
            with pen.owner(f"centre:{c.label}"):
                pen.mark(c.point, c.label, INK)


def _broken(points, ok) -> np.ndarray:
    """The polyline ``points`` with NaN where ``ok`` is False (matplotlib breaks it there)."""
    out = np.array(points, dtype=float)
    out[~ok] = np.nan
    return out


def draw_centrodes(pen, found, lo, hi, far: float, color) -> None:
    """The fixed centrode (dark, full), the moving centrode where the solid is at t (its
    colour, dashed), both cut where they leave ``far`` sizes around the box [lo, hi]; the
    pole I and the inflection circle (red, dotted) at t."""
    size = pen.size
    with pen.owner("centrode:fixed"):
        pen.construction(_broken(found.fixed, visible(found.fixed, lo, hi, far, size)),
                         FIXED_CENTRODE, width=1.4)
    with pen.owner("centrode:moving"):
        pen.construction(_broken(found.moving_at, visible(found.moving_at, lo, hi, far, size)),
                         color, linestyle="--", width=1.4)
    with pen.owner("inflection"):
        a = np.linspace(0.0, 2.0 * np.pi, 181)
        circle = found.inflection_centre + found.inflection_radius * np.column_stack(
            [np.cos(a), np.sin(a)])
        pen.construction(circle, INFLECTION, linestyle=":", width=1.1)
        pen.label(found.inflection_centre + found.inflection_radius * np.array([0.0, -1.0]),
                  "inflection circle", None, INFLECTION, fontsize=ELEMENT_FONT - 1)
    with pen.owner(f"pole:{found.solid}"):
        pen.mark(found.pole, f"I {found.solid}", INFLECTION)

"""Free-body sketches: the sign convention of every force output, one picture per element type.

Each sketch shows the bodies an element joins (solid 1 and solid 2, or guide and pin, P and
Q), cut free where that helps, the point and the basis in which the element reports its
wrench (small axes; x', y' for a rotated basis), and one arrow per force output, pointing in
the output's **positive** sense and labelled with its PAM name (``Fx``, ``Fnormal``, ``Mz``,
``Força``, ``Parell``): straight arrows for forces, arc arrows for moments. Every arrow reads
"its label, in the arrow's sense": grey arrows are what the other bodies receive in return
(``Fx`` pointing the other way on solid 1 of a revolute, ``−T·Parell`` counter-clockwise on
solid 1 of a transmission); thin grey dimensions are the position outputs a force depends on
(``ro``, ``fi_rel``, ``f(t)``). The conventions are those of docs/model-format.md ("Output
variables") and docs/analyses.md ("Reactions: which wrench, where, in which basis"), and
they were checked against the code they come from: each element class's ``wrench``,
``report_frame``, ``receiver`` and ``loads`` (pam2exu/elements/), and
``analyses.force_pass.element_wrench``.

The symbols are ``Pen``'s (pam2exu/pictures/pen.py), so a sketch looks like a ``pam2exu
draw`` picture: solid 1 blue, solid 2 orange, ground and arm grey, actuators red, applied
torsors green, reactions dark. The element itself, cut away, is drawn faintly where it has a
symbol between the bodies (spring, actuators).

``free_body_sketch(element_type, path)`` writes one sketch and returns what it drew
(``FreeBody``); ``python docs/make_free_body.py OUTDIR`` writes ``OUTDIR/fbd_<type>.png``
for every type in ``FREE_BODY_TYPES`` (docs/img/ holds them, for the glossary of output
names), or for the types named after it:

    python docs/make_free_body.py docs/img
    python docs/make_free_body.py docs/img linear_actuator

Docs tooling beside docs/make_api.py: pam2exu never imports it (tests/test_free_body.py
loads it by its path). Run from a clone, it puts the repository root on ``sys.path``.
"""
from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:          # run from a clone without installing
    sys.path.insert(0, str(ROOT))

from pam2exu.errors import PictureError, closest  # noqa: E402
from pam2exu.pictures.pen import ACTUATOR, GROUND, INK, LOAD, PALETTE, Pen  # noqa: E402
from pam2exu.results.plot import save  # noqa: E402

#: size of a sketch [in] and its resolution (300 × 240 pixels)
SIZE = (3.0, 2.4)
DPI = 100
#: solid 1 (guide, P), solid 2 (pin, Q), the other bodies' actions and dimensions
SOLID1, SOLID2 = PALETTE[0], PALETTE[1]
OTHER = "#9a9a9a"
DIMENSION = "#6f6f6f"
#: the pen's size: joint circles of 0.06 in (6 pixels)
PEN_SIZE = 5.0
#: length of a force arrow [in]
ARROW = 0.55


def _e(angle_deg: float) -> np.ndarray:
    """Unit vector at ``angle_deg`` degrees, counter-clockwise from x."""
    a = np.radians(angle_deg)
    return np.array([np.cos(a), np.sin(a)])


def _p(*xy) -> np.ndarray:
    return np.array(xy, dtype=float)


@dataclass(frozen=True)
class Arrow:
    """A force drawn: its label, which list it is in (``kind``), the body it acts on, and
    the arrow from ``tail`` to ``tip`` (the force's positive sense)."""

    label: str
    kind: str
    on: str
    tail: tuple[float, float]
    tip: tuple[float, float]


@dataclass(frozen=True)
class Turn:
    """A moment drawn: its label, ``kind``, the body it acts on, its centre, and its positive
    sense (``ccw``: counter-clockwise)."""

    label: str
    kind: str
    on: str
    centre: tuple[float, float]
    ccw: bool


@dataclass
class FreeBody:
    """What a sketch drew.

    outputs:    labels of the arrows that show an output's positive sense: exactly PAM names,
                each once, in the order drawn (``labels`` is the same list)
    others:     labels of the grey arrows, what the other bodies receive (a revolute's ``Fx``
                on solid 1, pointing the other way; a transmission's ``−T·Parell``)
    applied:    labels of applied loads (a torsor's ``Fx``, ``Fy``, ``M``: inputs, not outputs)
    dimensions: labels of the thin dimension lines (``ro``, ``fi_rel``, ``f(t)``)
    arrows, turns: every force and moment drawn, with its geometry
    points:     named points (``O``, ``D``, ``P``, ``Q``, ``pin``) → position
    bases:      (point, unit x direction, axis names) of each basis drawn
    """

    type: str
    outputs: list[str] = field(default_factory=list)
    others: list[str] = field(default_factory=list)
    applied: list[str] = field(default_factory=list)
    dimensions: list[str] = field(default_factory=list)
    arrows: list[Arrow] = field(default_factory=list)
    turns: list[Turn] = field(default_factory=list)
    points: dict[str, tuple[float, float]] = field(default_factory=dict)
    bases: list[tuple[tuple[float, float], tuple[float, float], tuple[str, str]]] = \
        field(default_factory=list)
    path: Path | None = None

    @property
    def labels(self) -> list[str]:
        """The output arrows' labels (``outputs``)."""
        return self.outputs


def _xy(p) -> tuple[float, float]:
    return (float(p[0]), float(p[1]))


class _Sketch:
    """One sketch: a 3 × 2.4 in figure whose data units are inches, and a Pen on it."""

    def __init__(self, element_type: str, title: str, caption: str):
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
        self.fig = Figure(figsize=SIZE, dpi=DPI, facecolor="white")
        FigureCanvasAgg(self.fig)
        ax = self.fig.add_axes((0.0, 0.0, 1.0, 1.0))
        ax.set_xlim(0.0, SIZE[0])
        ax.set_ylim(0.0, SIZE[1])
        ax.set_aspect("equal")
        ax.set_axis_off()
        self.ax = ax
        self.pen = Pen(ax, PEN_SIZE)
        self.drawn = FreeBody(element_type)
        ax.text(0.07, SIZE[1] - 0.07, title, ha="left", va="top", fontsize=9,
                fontweight="bold", color=INK)
        ax.text(SIZE[0] / 2, 0.05, caption, ha="center", va="bottom", fontsize=7,
                color="#444444", linespacing=1.15)

    # ---- labels ------------------------------------------------------------------------
    def note(self, p, text: str, color=INK, **style) -> None:
        """A small name (a body, a point) centred at p."""
        import matplotlib.patheffects as pe
        style.setdefault("fontsize", 8)
        self.ax.text(*p, text, color=color, ha="center", va="center", zorder=9,
                     path_effects=[pe.withStroke(linewidth=2.5, foreground="white")], **style)

    def _label(self, p, label: str, color, kind: str) -> None:
        names = getattr(self.drawn, kind)
        if label not in names:
            names.append(label)
        self.pen.text(p, label, color, fontweight="normal" if kind == "others" else "bold")

    # ---- forces and moments ------------------------------------------------------------
    def force(self, p, angle_deg: float, label: str, at, on: str, kind: str = "outputs",
              color=INK, length: float = ARROW) -> None:
        """A force on the body ``on`` at p: an arrow from p along ``angle_deg`` (its positive
        sense), its label centred at ``at``."""
        p = np.asarray(p, dtype=float)
        tip = p + length * _e(angle_deg)
        color = OTHER if kind == "others" else color
        self.pen.arrow(p, tip, color, width=1.5 if kind == "others" else 2.0,
                       head=10 if kind == "others" else 12)
        self._label(at, label, color, kind)
        self.drawn.arrows.append(Arrow(label, kind, on, _xy(p), _xy(tip)))

    def moment(self, c, radius: float, label: str, at, on: str, ccw: bool = True,
               start_deg: float = -45.0, sweep_deg: float = 270.0, kind: str = "outputs",
               color=INK) -> None:
        """A moment on the body ``on``: an arc arrow about c through ``sweep_deg`` from
        ``start_deg``, counter-clockwise or clockwise (its positive sense)."""
        color = OTHER if kind == "others" else color
        sweep = np.radians(sweep_deg) * (1.0 if ccw else -1.0)
        self.pen.arc_arrow(c, radius, np.radians(start_deg), sweep, color,
                           width=1.4 if kind == "others" else 1.8)
        self._label(at, label, color, kind)
        self.drawn.turns.append(Turn(label, kind, on, _xy(c), ccw))

    # ---- points, bases, dimensions -----------------------------------------------------
    def point(self, p, name: str, at=None, color=INK) -> None:
        """A named point: a small dot and its name at ``at`` (none: only recorded)."""
        self.drawn.points[name] = _xy(p)
        if at is not None:
            self.ax.plot(*p, marker="o", markersize=3.2, color=color, zorder=8)
            self.note(at, name, color, fontsize=8, fontstyle="italic")

    def basis(self, p, direction, names=("x'", "y'"), length: float = 0.3,
              x_length: float | None = None, x_at=None, color=GROUND) -> None:
        """The reporting basis at p: small axes, x along ``direction``. ``x_length``: a
        longer x axis drawn on top (out of a body drawn over it), named at ``x_at``."""
        p, d = np.asarray(p, dtype=float), np.asarray(direction, dtype=float)
        d = d / np.hypot(*d)
        self.drawn.bases.append((_xy(p), _xy(d), tuple(names)))
        if x_length is None:
            self.pen.basis(p, d, length, names, color=color)
            return
        self.pen.basis(p, d, length, ("", names[1]), color=color)
        self.pen.arrow(p, p + x_length * d, color, width=1.0, head=8)
        self.note(x_at, names[0], color, fontsize=9, fontstyle="italic")

    def global_basis(self, p) -> None:
        """The global x, y axes at p, small, named "global"."""
        self.basis(p, (1.0, 0.0), ("x", "y"))
        self.note(np.asarray(p) + _p(0.2, 0.15), "global", GROUND, fontsize=7)

    def length(self, p, q, offset: float, label: str) -> None:
        """A distance between p and q: a thin line with arrowheads, ``offset`` to the left
        of PQ, extension lines to p and q, the label beside its middle."""
        from matplotlib.patches import FancyArrowPatch
        p, q = np.asarray(p, dtype=float), np.asarray(q, dtype=float)
        d = (q - p) / np.hypot(*(q - p))
        n = np.array([-d[1], d[0]])
        a, b = p + offset * n, q + offset * n
        for end in (p, q):
            self.ax.plot(*np.transpose([end + 0.06 * np.sign(offset) * n,
                                        end + (offset + 0.05 * np.sign(offset)) * n]),
                         color=DIMENSION, lw=0.6, zorder=2)
        self.ax.add_patch(FancyArrowPatch(tuple(a), tuple(b), arrowstyle="<|-|>",
                                          mutation_scale=7, color=DIMENSION, lw=0.8,
                                          shrinkA=0, shrinkB=0, zorder=2))
        self._dimension((a + b) / 2 + 0.13 * np.sign(offset) * n, label)

    def angle(self, c, radius: float, from_deg: float, to_deg: float, label: str, at) -> None:
        """An angle about c, from ``from_deg`` to ``to_deg``: a thin arc, its head at the end."""
        from matplotlib.patches import FancyArrowPatch
        a = np.radians(np.linspace(from_deg, to_deg, 40))
        xy = np.asarray(c) + radius * np.column_stack([np.cos(a), np.sin(a)])
        self.ax.plot(*xy[:-2].T, color=DIMENSION, lw=0.8, zorder=2)
        self.ax.add_patch(FancyArrowPatch(tuple(xy[-3]), tuple(xy[-1]), arrowstyle="-|>",
                                          mutation_scale=7, color=DIMENSION, lw=0.8,
                                          shrinkA=0, shrinkB=0, zorder=2))
        self._dimension(at, label)

    def _dimension(self, p, label: str) -> None:
        if label not in self.drawn.dimensions:
            self.drawn.dimensions.append(label)
        self.note(p, label, DIMENSION, fontsize=8, fontstyle="italic")

    def faint(self, draw, *args, alpha: float = 0.3) -> None:
        """Draw a pen symbol faintly (an element cut away: its forces are the arrows)."""
        k = len(self.pen.artists)
        draw(*args)
        for a in self.pen.artists[k:]:
            a.set_alpha(alpha)


# ---- the sketches ------------------------------------------------------------------------
# Each function draws one element type. Positions are in inches on the 3 × 2.4 in sketch.

def _fixed(s: _Sketch) -> None:
    """Fx, Fy, Mz: the wrench the fixed solid receives from the link, at its local origin O,
    global basis."""
    O = _p(1.25, 1.2)
    outline = O + np.array([[-0.85, -0.5], [0.6, -0.55], [0.8, 0.3], [-0.3, 0.62],
                            [-0.95, 0.25]])
    s.pen.plate(outline, GROUND, alpha=0.22)
    s.note(O + _p(-0.45, -0.33), "fixed solid", GROUND, fontweight="bold")
    s.pen.ground(O + _p(0.0, -0.6))
    s.note(O + _p(0.72, -0.77), "fixed link (cut)", GROUND, fontsize=7)
    s.point(O, "O", O + _p(0.11, 0.12))
    s.force(O, 0.0, "Fx", O + _p(ARROW + 0.17, 0.0), "fixed solid")
    s.force(O, 90.0, "Fy", O + _p(0.0, ARROW + 0.11), "fixed solid")
    s.moment(O, 0.22, "Mz", O + _p(-0.38, 0.05), "fixed solid", start_deg=105.0,
             sweep_deg=220.0)
    s.global_basis(_p(2.4, 1.72))


def _revolute(s: _Sketch) -> None:
    """Fx, Fy: the force solid 1 exerts on solid 2 at the joint, global basis; solid 1
    receives the opposite (greyed: the same labels, the arrows reversed)."""
    J2, J1 = _p(1.75, 1.05), _p(1.05, 1.05)
    s.pen.bar(J2, J2 + 0.95 * _e(42.0), SOLID2)
    s.pen.bar(J1, J1 + 0.85 * _e(222.0), SOLID1)
    s.pen.joint(J2)
    s.pen.joint(J1)
    s.note(J2 + 0.6 * _e(42.0) + _p(0.22, -0.12), "solid 2", SOLID2, fontweight="bold")
    s.note(J1 + 0.55 * _e(222.0) + _p(-0.2, 0.14), "solid 1", SOLID1, fontweight="bold")
    s.force(J2, 0.0, "Fx", J2 + _p(ARROW + 0.16, 0.0), "solid 2")
    s.force(J2, 90.0, "Fy", J2 + _p(-0.15, ARROW), "solid 2")
    s.force(J1, 180.0, "Fx", J1 + _p(-ARROW - 0.16, 0.0), "solid 1", kind="others")
    s.force(J1, 270.0, "Fy", J1 + _p(0.16, -ARROW + 0.02), "solid 1", kind="others")
    s.ax.plot(*np.transpose([J1 + _p(0.09, 0.0), J2 - _p(0.09, 0.0)]), color=INK, lw=0.8,
              linestyle=(0, (1.5, 2.5)), zorder=2)
    s.note((J1 + J2) / 2 + _p(0.0, 0.13), "joint, cut", INK, fontsize=7)
    s.global_basis(_p(0.3, 1.65))


def _prismatic(s: _Sketch) -> None:
    """Fnormal, Mz: the wrench solid 1 exerts on solid 2, at the defining point D of solid 2's
    line, x' along that line in its own sense, Fnormal along y' (+90°)."""
    th = 18.0
    d, n = _e(th), _e(th + 90.0)
    D = _p(1.3, 1.12)
    # solid 1: the rail, a long flat bar along line 1 (below the block)
    a, b = D - 1.2 * d - 0.17 * n, D + 1.3 * d - 0.17 * n
    s.pen.plate([a - 0.05 * n, b - 0.05 * n, b + 0.05 * n, a + 0.05 * n], SOLID1, alpha=0.35)
    s.note(D + 0.95 * d - 0.42 * n, "solid 1", SOLID1, fontweight="bold")
    # solid 2: the block, and its line through D
    hx, hy = 0.34, 0.12
    s.pen.plate([D - hx * d - hy * n, D + hx * d - hy * n, D + hx * d + hy * n,
                 D - hx * d + hy * n], SOLID2, alpha=0.45)
    s.note(D + 0.62 * d + 0.36 * n, "solid 2", SOLID2, fontweight="bold")
    s.ax.plot(*np.transpose([D - 0.95 * d, D + 1.0 * d]), color=SOLID2, lw=1.0,
              linestyle=(0, (5, 3)), zorder=2)
    s.note(D + 1.12 * d + 0.12 * n, "line 2", SOLID2, fontsize=7)
    s.basis(D, d, length=0.36, x_length=0.6, x_at=D + 0.66 * d - 0.1 * n)
    s.point(D, "D", D + 0.17 * _e(th + 45.0))
    s.force(D, th + 90.0, "Fnormal", D + (ARROW + 0.13) * n + 0.06 * d, "solid 2")
    s.moment(D, 0.3, "Mz", D - 0.6 * d + 0.1 * n, "solid 2", start_deg=th + 112.0,
             sweep_deg=200.0)


def _pin_slot(s: _Sketch) -> None:
    """Fnormal: the force the guide (solid 1) exerts on the pin (solid 2), at the pin, along
    the guide's x direction turned +90°."""
    th = 15.0
    d, n = _e(th), _e(th + 90.0)
    P = _p(1.45, 1.0)
    a, b = P - 1.05 * d, P + 1.05 * d
    # the guide: a slotted bar (the slot in white), its x direction past the right end
    s.pen.bar(a, b, SOLID1, width=13.0)
    s.ax.plot(*np.transpose([a + 0.1 * d, b - 0.1 * d]), color="white", lw=5.5,
              solid_capstyle="round", zorder=2)
    s.pen.arrow(b + 0.08 * d, b + 0.36 * d, SOLID1, width=1.2, head=9)
    s.note(b + 0.2 * d - 0.2 * n, "guide x", SOLID1, fontsize=7)
    s.note(a + 0.45 * d - 0.27 * n, "guide (solid 1)", SOLID1, fontweight="bold")
    # the pin and the solid that carries it
    s.pen.bar(P, P + 0.72 * _e(152.0), SOLID2)
    s.pen.pin(P)
    s.note(P + 0.72 * _e(152.0) + _p(0.0, 0.16), "pin (solid 2)", SOLID2, fontweight="bold")
    s.point(P, "pin")
    s.basis(P, d, length=0.36, x_length=0.6, x_at=P + 0.64 * d - 0.15 * n)
    s.force(P, th + 90.0, "Fnormal", P + (ARROW + 0.12) * n + 0.2 * d, "pin (solid 2)")


def _transmission(s: _Sketch) -> None:
    """Parell: the torque solid 2 receives, counter-clockwise; −T·Parell on solid 1 and
    (T − 1)·Parell on the arm, all pure torques (no tooth force)."""
    from matplotlib.patches import Circle
    C1, C2 = _p(0.72, 1.33), _p(1.6, 1.33)
    r1, r2 = 0.52, 0.36
    for c, r, color in ((C1, r1, SOLID1), (C2, r2, SOLID2)):
        s.ax.add_patch(Circle(tuple(c), r, facecolor=color, alpha=0.22, edgecolor="none",
                              zorder=1))
        s.ax.add_patch(Circle(tuple(c), r, facecolor="none", edgecolor=color, lw=1.6,
                              linestyle="-.", zorder=1))
    # the arm carries both gears: hinges at the centres
    A = C2 + _p(0.82, 0.0)
    s.pen.bar(C1, A + _p(0.1, 0.0), GROUND, width=6.0)
    s.pen.joint(C1)
    s.pen.joint(C2)
    s.note(C1 + _p(-0.2, r1 + 0.13), "solid 1", SOLID1, fontweight="bold")
    s.note(C2 + _p(0.15, r2 + 0.13), "solid 2", SOLID2, fontweight="bold")
    s.note(A + _p(0.0, 0.33), "arm", GROUND, fontweight="bold")
    s.moment(C2, 0.2, "Parell", C2 + _p(0.05, -r2 - 0.15), "solid 2", start_deg=70.0)
    s.moment(C1, 0.24, "−T·Parell", C1 + _p(0.0, -r1 - 0.14), "solid 1", start_deg=110.0,
             kind="others")
    s.moment(A, 0.18, "(T−1)·Parell", A + _p(-0.05, -0.36), "arm", start_deg=-60.0,
             kind="others")


def _spring(s: _Sketch) -> None:
    """Força: positive = attraction, the pair of forces pulling P and Q towards each other;
    ro = |PQ|."""
    P, Q = _p(0.75, 0.93), _p(2.2, 1.55)
    u = (Q - P) / np.hypot(*(Q - P))
    ang = np.degrees(np.arctan2(u[1], u[0]))
    n = np.array([-u[1], u[0]])
    s.pen.plate(P + np.array([[-0.5, -0.3], [0.1, -0.35], [0.16, 0.1], [-0.35, 0.22]]), SOLID1)
    s.pen.plate(Q + np.array([[-0.13, -0.12], [0.5, -0.28], [0.42, 0.3], [-0.1, 0.2]]),
                SOLID2)
    s.note(P + _p(-0.2, -0.47), "solid 1", SOLID1, fontweight="bold")
    s.note(Q + _p(0.45, 0.42), "solid 2", SOLID2, fontweight="bold")
    s.faint(s.pen.zigzag, P, Q)
    s.point(P, "P", P + _p(-0.12, 0.08))
    s.point(Q, "Q", Q + _p(0.12, 0.1))
    s.force(P, ang, "Força", P + 0.3 * u - 0.22 * n, "solid 1", length=0.48)
    s.force(Q, ang + 180.0, "Força", Q - 0.3 * u - 0.22 * n, "solid 2", length=0.48)
    s.length(P, Q, 0.36, "ro")


def _torsional_spring(s: _Sketch) -> None:
    """Parell: counter-clockwise on solid 1, clockwise on solid 2; fi_rel = fi2 − fi1."""
    H = _p(0.85, 0.72)
    a1, a2 = -4.0, 52.0
    s.pen.bar(H, H + 1.85 * _e(a1), SOLID1)
    s.pen.bar(H, H + 1.45 * _e(a2), SOLID2)
    s.pen.spiral(H)
    s.pen.joint(H)
    s.note(H + 0.8 * _e(a1) + _p(0.0, -0.19), "solid 1", SOLID1, fontweight="bold")
    s.note(H + 1.1 * _e(a2) + _p(-0.34, 0.06), "solid 2", SOLID2, fontweight="bold")
    s.angle(H, 0.55, a1, a2, "fi_rel", H + 0.7 * _e((a1 + a2) / 2) + _p(0.12, 0.0))
    c1, c2 = H + 1.5 * _e(a1), H + 1.2 * _e(a2)
    s.moment(c1, 0.17, "Parell", c1 + _p(0.05, 0.32), "solid 1", ccw=True)
    s.moment(c2, 0.17, "Parell", c2 + _p(0.42, -0.05), "solid 2", ccw=False,
             start_deg=180.0)


def _angular_actuator(s: _Sketch) -> None:
    """Mz: the torque on solid 2, counter-clockwise; solid 1 receives the opposite (Mz
    clockwise); f(t) = fi2 − fi1."""
    H = _p(0.85, 0.72)
    a1, a2 = -4.0, 52.0
    s.pen.bar(H, H + 1.85 * _e(a1), SOLID1)
    s.pen.bar(H, H + 1.45 * _e(a2), SOLID2)
    s.faint(s.pen.rotation, H)
    s.pen.joint(H)
    s.note(H + 0.8 * _e(a1) + _p(0.0, -0.19), "solid 1", SOLID1, fontweight="bold")
    s.note(H + 1.1 * _e(a2) + _p(-0.34, 0.06), "solid 2", SOLID2, fontweight="bold")
    s.angle(H, 0.55, a1, a2, "f(t)", H + 0.7 * _e((a1 + a2) / 2) + _p(0.1, 0.0))
    c1, c2 = H + 1.5 * _e(a1), H + 1.2 * _e(a2)
    s.moment(c2, 0.17, "Mz", c2 + _p(0.36, -0.05), "solid 2", color=ACTUATOR)
    s.moment(c1, 0.17, "Mz", c1 + _p(0.05, 0.32), "solid 1", ccw=False, start_deg=225.0,
             kind="others")


def _linear_actuator(s: _Sketch) -> None:
    """Força: positive = repulsion, the pair of forces pushing P and Q apart along PQ; reported
    at Q, x' from P to Q."""
    P, Q = _p(0.88, 1.0), _p(2.02, 1.42)
    u = (Q - P) / np.hypot(*(Q - P))
    ang = np.degrees(np.arctan2(u[1], u[0]))
    n = np.array([-u[1], u[0]])
    s.pen.plate(P + np.array([[-0.3, -0.3], [0.12, -0.28], [0.12, 0.1], [-0.25, 0.18]]), SOLID1)
    s.pen.plate(Q + np.array([[-0.12, -0.2], [0.3, -0.25], [0.33, 0.18], [-0.08, 0.15]]),
                SOLID2)
    s.note(P + _p(-0.28, -0.42), "solid 1", SOLID1, fontweight="bold")
    s.note(Q + _p(0.62, -0.2), "solid 2", SOLID2, fontweight="bold")
    s.faint(s.pen.cylinder, P, Q, alpha=0.45)
    s.point(P, "P", P + _p(0.04, 0.15))
    s.point(Q, "Q", Q + _p(-0.06, 0.15))
    s.basis(Q, u)
    s.force(Q, ang, "Força", Q + 0.6 * u + 0.18 * n, "solid 2", length=0.45,
            color=ACTUATOR)
    s.force(P, ang + 180.0, "Força", P - 0.45 * u + 0.24 * n, "solid 1", length=0.45,
            color=ACTUATOR)
    s.length(P, Q, -0.5, "f(t)")


def _torsor(s: _Sketch) -> None:
    """Fx, Fy, M: an applied force at the point A and a moment, components along the global
    axes (axes = "global") or along the solid's axes x', y' (axes = "solid")."""
    for cx, axes, fi in ((0.72, "global", 0.0), (2.2, "solid", 30.0)):
        A = _p(cx, 1.1)
        d, n = _e(fi), _e(fi + 90.0)
        rot = np.array([[d[0], d[1]], [n[0], n[1]]])
        corners = np.array([[-0.36, -0.26], [0.3, -0.27], [0.27, 0.15], [-0.3, 0.24]])
        s.pen.plate(A + corners @ rot, SOLID2)
        s.point(A, "A", A + 0.15 * _e(fi + 45.0))
        on = f'axes = "{axes}"'
        s.note(_p(cx + 0.1, 1.98), on, INK, fontsize=7)
        if axes == "solid":
            O = A + _p(0.4, -0.6)
            s.basis(O, d, length=0.26, color=OTHER)
        s.force(A, fi, "Fx", A + (ARROW + 0.14) * d, on, kind="applied", color=LOAD)
        s.force(A, fi + 90.0, "Fy", A + (ARROW + 0.1) * n, on, kind="applied", color=LOAD)
        s.moment(A, 0.19, "M", A - 0.36 * d - 0.02 * n, on, start_deg=fi + 100.0,
                 sweep_deg=215.0, kind="applied", color=LOAD)
    s.global_basis(_p(1.25, 0.5))


#: element type -> (sketch function, caption lines)
_SKETCHES = {
    "fixed": (_fixed, ("wrench the fixed solid receives from the link,",
                       "at its local origin O, global basis")),
    "revolute": (_revolute, ("force solid 1 exerts on solid 2 at the joint, global basis;",
                             "solid 1 receives the opposite")),
    "prismatic": (_prismatic, ("wrench solid 1 exerts on solid 2 at D, the defining point",
                               "of solid 2's line; x' along that line, its own sense")),
    "pin_slot": (_pin_slot, ("force the guide exerts on the pin, at the pin;",
                             "x' along the guide's x direction")),
    "transmission": (_transmission, (
        "pure torques, counter-clockwise positive:",
        "Parell on solid 2, −T·Parell on solid 1, (T−1)·Parell on arm")),
    "torsor": (_torsor, ("applied force at A and moment M (counter-clockwise);",
                         "components along x, y or along the solid's x', y'")),
    "spring": (_spring, ("Força > 0: attraction, P and Q pulled together;",
                         "ro = distance PQ")),
    "torsional_spring": (_torsional_spring, ("Parell > 0: counter-clockwise on solid 1,",
                                             "clockwise on solid 2; fi_rel = fi2 − fi1")),
    "angular_actuator": (_angular_actuator, ("Mz: torque on solid 2, counter-clockwise;",
                                             "the opposite on solid 1; f(t) = fi2 − fi1")),
    "linear_actuator": (_linear_actuator, (
        "Força > 0: repulsion, P and Q pushed apart along PQ;",
        "reported at Q, x' from P to Q; f(t) = |PQ|")),
}

#: element types with a free-body sketch, in the order of ``elements.ELEMENTS``: every type
#: that reports a force or a torque, and the applied torsor
FREE_BODY_TYPES: tuple[str, ...] = tuple(_SKETCHES)


def free_body_figure(element_type: str):
    """(matplotlib Figure, FreeBody) of the sketch of ``element_type``."""
    if element_type not in _SKETCHES:
        raise PictureError(f"no free-body sketch for element type '{element_type}'"
                           f"{closest(element_type, FREE_BODY_TYPES)}; there is one for "
                           f"{', '.join(FREE_BODY_TYPES)}")
    draw, caption = _SKETCHES[element_type]
    sketch = _Sketch(element_type, element_type, "\n".join(caption))
    draw(sketch)
    return sketch.fig, sketch.drawn


def free_body_sketch(element_type: str, path: str | Path) -> FreeBody:
    """Write the free-body sketch of ``element_type`` to ``path`` (the format from its
    suffix; PNG: 300 × 240 pixels) and return what it drew (``FreeBody``: the output
    arrows' labels in ``outputs``). PictureError for an unknown type or image format."""
    fig, drawn = free_body_figure(element_type)
    drawn.path = save(fig, path)
    return drawn


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(
        prog="python docs/make_free_body.py",
        description="Write OUTDIR/fbd_<type>.png, the free-body sketch of every element type "
                    "that reports a force or a torque (and of the applied torsor).")
    parser.add_argument("outdir", type=Path, help="directory to write to (created if missing)")
    parser.add_argument("types", nargs="*", metavar="TYPE",
                        help="only these element types (default: every one)")
    args = parser.parse_args(argv)
    args.outdir.mkdir(parents=True, exist_ok=True)
    for t in args.types or FREE_BODY_TYPES:
        drawn = free_body_sketch(t, args.outdir / f"fbd_{t}.png")
        print(drawn.path)
    return 0


if __name__ == "__main__":
    sys.exit(main())

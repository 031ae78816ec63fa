"""``draw``: one configuration of a mechanism as a figure.

``draw`` takes a configuration from the analyses (``poses.py``: the assembly at t = 0 or a
kinematic run to t) or the initial guess (not assembled), shows it in a ``Scene``
(``scene.py``), and may add vectors to scale (``vectors.py``), the instantaneous centres, or
the constraints a guess does not meet. Each solid is drawn by ``Pen.solid``, each element by
its own ``draw`` method (``pam2exu/elements/``), the symbols themselves by ``Pen``
(``pen.py``). ``animate`` (``animation.py``), ``Scene``, ``extent``, ``configurations`` and
``pose`` are re-exported here, where they were first defined. Figures use the Agg canvas,
never a window.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..kinematics import State
from ..results.plot import DPI, PictureError, figure, save
from .animation import ANIMATION_SIZE, FPS, FRAMES, animate
from .poses import _model, configurations, motion, pose
from .scene import LABEL_ROOM, MARGIN, Scene, extent, fit_title

__all__ = ["draw", "animate", "configurations", "pose", "extent", "Scene", "DRAW_SIZE",
           "ANIMATION_SIZE", "FAR_CENTRE", "MARGIN", "LABEL_ROOM", "FPS", "FRAMES"]

#: figure size of a drawing [in]
DRAW_SIZE = (8.0, 6.0)
#: instantaneous centres farther than this many sizes out of the mechanism's box are not
#: drawn (``draw(ic=True)``, ``ic='all'``, ``centrodes=``): the drawing would shrink to nothing
FAR_CENTRE = 1.5
#: figure size of a drawing with its polygon beside it (``draw(polygon=…)``) [in]
POLYGON_SIZE = (13.0, 6.0)


def draw(model, t: float = 0.0, path: str | Path | None = None, dpi: float = DPI,
         size: tuple[float, float] = DRAW_SIZE, vectors: str | None = None,
         guess: bool = False, ic: bool | str = False, polygon: str | None = None,
         centrodes: str | None = None):
    """Draw the mechanism at time t; returns the matplotlib Figure.

    Solids, joints, guides, springs, actuators, torsors and the global frame, on axes
    ``x [m]``, ``y [m]`` with equal scales. ``pam2exu draw`` calls this function; the
    figure is on the Agg canvas (no window opens).

    Parameters
    ----------
    model : Model, str or Path
        A model, or the path of a model file.
    t : float
        Time [s], ≥ 0. 0 (default): the assembled configuration at t = 0; else the
        positions of a kinematic run from 0 to t (with the model's step length, see
        ``pose``).
    path : str or Path, optional
        Image file to write (.png, .svg, .pdf, …); None writes nothing.
    dpi : float
        Resolution [dots per inch].
    size : (float, float)
        Width and height of the figure [in] (``size`` × ``dpi`` pixels).
    vectors : str, optional
        Arrows to scale at time t (``pictures.vectors``): ``'v'`` the velocity or ``'a'``
        the acceleration of every declared point of the moving solids (a kinematic run),
        ``'F'`` the force of every joint and actuator on its solid 2 at its point (a
        kinetostatic run); the longest arrow is 0.15 of the mechanism's size, the legend
        under the axes says what a round length stands for. The configuration is then the
        run's at t (at t = 0 its first row).
    guess : bool
        Draw the initial guess: every solid at the x, y, fi given in the model, not
        assembled (no analysis runs, so a model that does not assemble can be seen);
        not with a time, vectors, centres, a polygon or centrodes.
    ic : bool or 'all'
        True: mark each moving solid's instantaneous centre of rotation at t (``I crank``;
        from a kinematic run, ``points.instantaneous_centre``); a solid that translates has
        none, one farther than ``FAR_CENTRE`` sizes from the mechanism is left out and named
        in the title. ``'all'``: every centre I_ij of two bodies, relative ones included
        (body 1 the ground, then the moving solids; the title numbers them), and the
        Kennedy line through the three centres of every three bodies
        (``graphical.all_centres``); those far off or at infinity are named in the title.
    polygon : {'v', 'a'}, optional
        The velocity or acceleration polygon at t in a second panel, right of the
        mechanism (``graphical.polygon``; the figure is ``POLYGON_SIZE`` unless ``size`` is
        given): every point's absolute vector from the pole o, each link's relative vectors
        (for accelerations with their normal and tangential components), names and values,
        a scale bar.
    centrodes : str, optional
        A moving solid's name: its fixed centrode and its moving centrode over the model's
        kinematic run (the moving one where the solid is at t), its pole I and its
        inflection circle at t (``graphical.centrodes``); the drawing widens to hold the
        circle when its radius is at most ``FAR_CENTRE`` sizes, and the centrodes are cut
        where they pass ``FAR_CENTRE`` sizes from the mechanism.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    PictureError
        ``t`` is negative or not a number, ``vectors`` is not v, a or F, ``polygon`` not
        v or a, ``ic`` not True, False or 'all', ``centrodes`` not a moving solid (or it
        translates at t), ``guess`` is given with a time, vectors, centres, a polygon or
        centrodes, or the image format of ``path`` is not supported.
    ModelError
        The model has problems (``MobilityError`` for t > 0 when a degree of freedom is not
        driven).
    SolverError
        Exudyn's solver did not converge.

    Examples
    --------
    >>> import pam2exu
    >>> from pam2exu.pictures import draw
    >>> m = pam2exu.Model("crank", gravity=0.0)
    >>> m.add_solid("ground").name, m.add("fixed", anc1="ground").name
    ('ground', 'fixed1')
    >>> m.add_solid("crank", fi=0.5, points={"O": [0, 0], "A": [0.1, 0]}).name
    'crank'
    >>> m.add("revolute", anc1="ground", anc2="crank.O").name
    'revolute1'
    >>> fig = draw(m)                                     # free crank: the assembly is allowed
    >>> fig.axes[0].get_title()
    "'crank' — assembled at t = 0"
    >>> draw("examples/four_bar.toml", t=0.25, path="four_bar.svg")   # doctest: +SKIP
    <Figure size 800x600 with 1 Axes>
    """
    from . import constructions, graphical
    from .pen import VECTOR_COLORS
    from .vectors import KINDS, at_instant, centres
    model = _model(model)
    arrows = None
    if ic not in (True, False, "all"):
        raise PictureError(f"--ic alone marks each solid's centre, --ic all every centre; "
                           f"not {ic!r}")
    if guess:
        if t or vectors or ic or polygon or centrodes:
            raise PictureError("the initial guess is the model's x, y, fi as given: draw it "
                               "without a time, vectors, centres, a polygon or centrodes")
        mech = model.mechanism()
        q = mech.initial_q()
        when = "initial guess (x, y, fi as given, not assembled)"
    elif vectors:
        mech, q, arrows = at_instant(model, t, vectors)
        when = f"t = {t:g} s ({KINDS[vectors][0]} run)"
    else:
        mech, q = pose(model, t)
        when = f"t = {t:g} s ({motion(model)} run)" if t else "assembled at t = 0"
    lo, hi = extent(mech, q)
    mech_size = float(max(hi - lo)) or 1.0
    extra = []
    if arrows is not None:
        arrows.scaled(mech_size)
        extra.append(arrows.tips)
    shown, far = [], []
    found_all = poly = curves = None
    if ic == "all":
        found_all = graphical.all_centres(model, t)
        finite = [c for c in found_all.centres if c.finite]
        ok = constructions.visible([c.point for c in finite], lo, hi, FAR_CENTRE, mech_size)
        shown_all = {c.label for c, k in zip(finite, ok) if k}
        extra += [c.point[None, :] for c in finite if c.label in shown_all]
        off = [c.label for c in found_all.centres if c.label not in shown_all and c.defined]
        together = [c.label for c in found_all.centres if not c.defined]
        when += ("; centres I_ij of " + ", ".join(f"{k} {n}" for k, n in
                                                   enumerate(found_all.bodies, start=1))
                 + (f" ({', '.join(off)}: far off or at infinity)" if off else "")
                 + (f" ({', '.join(together)}: none, the two move together)" if together
                    else ""))
    elif ic:
        _, _, found = centres(model, t)
        for name, p in found:
            off = np.maximum(np.maximum(lo - p, p - hi), 0.0)
            (shown if max(off) <= FAR_CENTRE * mech_size else far).append((name, p))
        extra += [p[None, :] for _, p in shown]
        when += "; centres I" + (f" ({', '.join(n for n, _ in far)}: far off)" if far else "")
    if centrodes is not None:
        curves = graphical.centrodes(model, centrodes, t)
        if np.all(constructions.visible(curves.pole[None], lo, hi, FAR_CENTRE, mech_size)):
            extra.append(curves.pole[None])
        if curves.inflection_radius <= FAR_CENTRE * mech_size:      # the whole circle
            extra.append(curves.inflection_centre + curves.inflection_radius * np.array(
                [[1.0, 1.0], [-1.0, -1.0]]))
        when += f"; centrodes of {centrodes}: fixed (full), moving (dashed), inflection circle"
    if polygon is not None:
        poly = graphical.polygon(model, t, polygon)
        if size == DRAW_SIZE:
            size = POLYGON_SIZE
    fig = figure(*size, dpi)
    ax = fig.add_subplot(1, 2, 1) if poly is not None else fig.add_subplot()
    room = None if poly is None else np.array([size[0] / 2, size[1]]) - LABEL_ROOM
    scene = Scene(ax, mech, q[None, :], np.vstack(extra) if extra else (), room=room)
    scene.show(t, q)
    if found_all is not None:
        constructions.draw_centres(scene.pen, found_all, shown_all)
    if curves is not None:
        index = {s.name: i for i, s in enumerate(mech.solids)}
        constructions.draw_centrodes(scene.pen, curves, lo, hi, FAR_CENTRE,
                                     scene.pen.color(index[centrodes]))
    pens = [scene.pen]
    if poly is not None:
        colors = {s.name: scene.pen.color(i) for i, s in enumerate(mech.solids)}
        pens.append(constructions.draw_polygon(fig.add_subplot(1, 2, 2), poly, colors))
    index = {s.name: i for i, s in enumerate(mech.solids)}
    for name, p in shown:
        with scene.pen.owner(f"centre:{name}"):
            scene.pen.centre(p, index[name], name)
    if arrows is not None:
        with scene.pen.owner(f"vectors:{arrows.kind}"):
            scene.pen.vectors(arrows.points, arrows.values, arrows.scale,
                              VECTOR_COLORS[arrows.kind], arrows.legend(mech_size))
    if guess:
        unmet = _mark_unmet(scene, q, mech_size)
        when += f"; {len(unmet)} constraint{'s' * (len(unmet) != 1)} not met" if unmet else ""
    fit_title(fig, ax, f"'{mech.name}' — {when}")
    _settle(fig, pens)
    if path is not None:
        save(fig, path)
    return fig


def _mark_unmet(scene, q, size: float) -> list[str]:
    """Mark the constraints the configuration q does not meet (residual above 1e-9 of the
    mechanism's size, or 1e-9 rad): their anchor points joined by a red dotted line, their
    names in red; returns their names."""
    from ..analyses.native import equations
    mech = scene.mech
    st = State([0.0], np.asarray(q, dtype=float)[None, :])
    residual = equations(mech, st, jacobian=False).residual[0]
    unmet = []
    for el, rows in zip(mech.constraints, mech.rows):
        if np.max(np.abs(residual[rows]), initial=0.0) <= 1e-9 * max(size, 1.0):
            continue
        unmet.append(el.name)
        points = [st.point(r.solid, r.anchor_point).value[0] for r in el.refs]
        with scene.pen.owner(f"{el.type}:{el.name}"):
            scene.pen.unmet(points)
    return unmet


def _settle(fig, pens) -> None:
    """Lay the figure out once and keep that layout, then place the names of every pen for
    it (their places depend on the axes' size in pixels)."""
    fig.canvas.draw()
    fig.set_layout_engine("none")
    for pen in pens:
        pen.place_labels()

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
#: drawn (``draw(ic=True)``): the drawing would shrink to nothing
FAR_CENTRE = 1.5


def draw(model, t: float = 0.0, path: str | Path | None = None, dpi: float = DPI,
         size: tuple[float, float] = DRAW_SIZE, vectors: str | None = None,
         guess: bool = False, ic: bool = False):
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
        not with a time, vectors or centres.
    ic : bool
        Mark each moving solid's instantaneous centre of rotation at t (``I crank``; from a
        kinematic run, ``points.instantaneous_centre``); a solid that translates has none,
        one farther than ``FAR_CENTRE`` sizes from the mechanism is left out and named in
        the title.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    PictureError
        ``t`` is negative or not a number, ``vectors`` is not v, a or F, ``guess`` is
        given with a time or vectors, or the image format of ``path`` is not supported.
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
    from .pen import VECTOR_COLORS
    from .vectors import KINDS, at_instant, centres
    model = _model(model)
    arrows = None
    if guess:
        if t or vectors or ic:
            raise PictureError("the initial guess is the model's x, y, fi as given: draw it "
                               "without a time or vectors")
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
    if ic:
        _, _, found = centres(model, t)
        for name, p in found:
            off = np.maximum(np.maximum(lo - p, p - hi), 0.0)
            (shown if max(off) <= FAR_CENTRE * mech_size else far).append((name, p))
        extra += [p[None, :] for _, p in shown]
        when += "; centres I" + (f" ({', '.join(n for n, _ in far)}: far off)" if far else "")
    fig = figure(*size, dpi)
    ax = fig.add_subplot()
    scene = Scene(ax, mech, q[None, :], np.vstack(extra) if extra else ())
    scene.show(t, q)
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
    _settle(fig, scene)
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


def _settle(fig, scene) -> None:
    """Lay the figure out once and keep that layout, then place the names for it (their
    places depend on the axes' size in pixels)."""
    fig.canvas.draw()
    fig.set_layout_engine("none")
    scene.pen.place_labels()

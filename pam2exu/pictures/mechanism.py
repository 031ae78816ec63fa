"""Pictures of a mechanism: one configuration (``draw``) or its motion (``animate``).

The configurations come from the analyses: the assembly at t = 0, or the positions of a
kinematic run (Exudyn's static solver, on the branch the mechanism starts on). Each solid is
drawn by ``Pen.solid``, each element by its own ``draw`` method (``pam2exu/elements/``), the
symbols themselves by ``Pen`` (``pen.py``). Figures use the Agg canvas, never a window.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..errors import ModelError, Problem
from ..kinematics import State
from ..progress import Progress
from ..results.plot import DPI, PictureError, figure, save
from .pen import PALETTE, Pen

#: figure sizes [in]: a drawing, an animation (smaller: every frame is stored)
DRAW_SIZE = (8.0, 6.0)
ANIMATION_SIZE = (6.4, 4.8)
#: instantaneous centres farther than this many sizes out of the mechanism's box are not
#: drawn (``draw(ic=True)``): the drawing would shrink to nothing
FAR_CENTRE = 1.5
#: margin around the box the mechanism moves in, fraction of its larger side
MARGIN = 0.12
#: room the axis labels and the title take from the figure [in] (width, height)
LABEL_ROOM = np.array([0.9, 0.9])
#: frames per second of an animation are steps / t_end (real time), within these bounds
FPS = (2.0, 30.0)
#: most frames of an animation by default (the model's steps, up to this)
FRAMES = 100
#: coordinates asked of a kinematic run (a velocity makes it follow the branch)
_POSE = ("*.x", "*.y", "*.fi", "*.Dfi")


def _model(model):
    from ..model import Model, load
    return model if isinstance(model, Model) else load(model)


def configurations(model, t_end: float | None = None, steps: int | None = None,
                   analysis: str = "kinematic") -> tuple[object, np.ndarray, np.ndarray]:
    """(mechanism, t (n,), q (n, 3·solids)) of a run: the assembly (one row at t = 0), or
    the positions of a kinematic run over [0, t_end] in ``steps`` intervals.

    Parameters
    ----------
    model : Model, str or Path
        A model, or the path of a model file.
    t_end : float, optional
        End of the interval [s] (default: the model's t_end); not used by an assembly.
    steps : int, optional
        Number of intervals (default: the model's steps); not used by an assembly.
    analysis : str
        ``'kinematic'`` (default; needs every degree of freedom driven) or
        ``'assembly'`` (t = 0 only; free degrees of freedom allowed).

    Returns
    -------
    mechanism : Mechanism
        ``model.mechanism()``.
    t : numpy.ndarray
        Times [s], shape (n,).
    q : numpy.ndarray
        Shape (n, 3·solids): x [m], y [m], fi [rad] of each solid in order.

    Raises
    ------
    ModelError
        The model has problems (``MobilityError``: a degree of freedom is not driven, for
        a kinematic run).
    SolverError
        Exudyn's solver did not converge.
    """
    from ..analyses import run
    model = _model(model)
    mech = model.mechanism()
    if analysis == "assembly":
        res = run(model, analysis="assembly", outputs=list(_POSE[:3]), angles="rad")
    else:
        res = run(model, analysis="kinematic", t_end=t_end, steps=steps, outputs=list(_POSE),
                  angles="rad")
    q = np.column_stack([res[f"{s.name}.{k}"] for s in mech.solids for k in ("x", "y", "fi")])
    return mech, np.array(res.t), q


def pose(model, t: float = 0.0):
    """(mechanism, q) at time t: the assembly at t = 0, else a kinematic run from 0 to t
    with the model's step length.

    Parameters
    ----------
    model : Model, str or Path
        A model, or the path of a model file.
    t : float
        Time [s], ≥ 0. 0: the assembly (free degrees of freedom allowed); else the last
        row of a kinematic run over [0, t] in ceil(steps · t / t_end) intervals (the
        model's step length, or a little shorter), so it follows the same branch as
        ``run``.

    Returns
    -------
    mechanism : Mechanism
        ``model.mechanism()``.
    q : numpy.ndarray
        Shape (3·solids,): x [m], y [m], fi [rad] of each solid at t.

    Raises
    ------
    PictureError
        ``t`` is negative or not a number.
    ModelError
        The model has problems (``MobilityError`` for t > 0 when a degree of freedom is not
        driven).
    SolverError
        Exudyn's solver did not converge.
    """
    model = _model(model)
    if not t:
        mech, _, q = configurations(model, analysis="assembly")
        return mech, q[0]
    a = model.analysis
    if not (isinstance(t, (int, float)) and math.isfinite(t) and t > 0):
        raise PictureError(f"the time of a drawing must be a number ≥ 0 [s], not {t!r}")
    steps = max(1, math.ceil(a.steps * t / a.t_end - 1e-9))
    mech, _, q = configurations(model, t_end=float(t), steps=steps)
    return mech, q[-1]


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
        for ref in getattr(el, "refs", ()):
            local = getattr(ref, "local", getattr(ref, "point", (0.0, 0.0)))
            pts.append(st.point(ref.solid, local).value)
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
    """

    def __init__(self, ax, mech, q_all: np.ndarray, extra=()):
        self.ax, self.mech = ax, mech
        self.locals = [np.array([[float(v) for v in p] for p in s.points.values()]
                                if s.points else np.zeros((0, 2))) for s in mech.solids]
        lo, hi = self._box(q_all, extra)
        self.size = float(max(hi - lo)) or 1.0
        grounded = {el.ref1.solid for el in mech.elements if el.grounds}
        moving = [i for i in range(len(mech.solids)) if i not in grounded]
        colors = {i: PALETTE[k % len(PALETTE)] for k, i in enumerate(moving)}
        self.pen = Pen(ax, self.size, grounded, colors)
        # the box with a margin, widened to the shape of the axes (the figure less room
        # for the labels and the title), then equal scales by shrinking the axes a little
        lo, hi = lo - MARGIN * self.size, hi + MARGIN * self.size
        width, height = ax.figure.get_size_inches() - LABEL_ROOM
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
    from .vectors import at_instant, centres
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
        analysis = "kinetostatic" if vectors == "F" else "kinematic"
        when = f"t = {t:g} s ({analysis} run)"
    else:
        mech, q = pose(model, t)
        when = f"t = {t:g} s (kinematic run)" if t else "assembled at t = 0"
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
    ax.set_title(f"'{mech.name}' — {when}")
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
        points = [st.point(r.solid, getattr(r, "local", getattr(r, "point", (0.0, 0.0))))
                  .value[0] for r in getattr(el, "refs", ())]
        with scene.pen.owner(f"{el.type}:{el.name}"):
            scene.pen.unmet(points)
    return unmet


def _settle(fig, scene) -> None:
    """Lay the figure out once and keep that layout, then place the names for it (their
    places depend on the axes' size in pixels)."""
    fig.canvas.draw()
    fig.set_layout_engine("none")
    scene.pen.place_labels()


def _traces(mech, names) -> list[tuple[str, int, tuple[float, float]]]:
    """(name, solid, local point) of each ``solid.point`` to trace; ModelError naming every
    one that does not exist."""
    from ..model.solid import Scope
    scope, out, problems = Scope(mech.solids), [], []
    for name in names or ():
        try:
            ref = scope.point(name)
        except LookupError as exc:
            problems.append(Problem(f"trace '{name}'", f"{exc}; give a point as solid.point "
                                                       "(or a solid's name for its origin)"))
            continue
        out.append((name, ref.solid, ref.local))
    if problems:
        raise ModelError(problems, mech.model.source)
    return out


def _writer(path: Path, fps: float):
    """None for .gif (written by ``_write_gif``, Pillow); matplotlib's ffmpeg writer for
    .mp4 when ffmpeg is installed."""
    from matplotlib import animation
    suffix = path.suffix.lower()
    if suffix == ".gif":
        return None
    if suffix == ".mp4":
        if not animation.writers.is_available("ffmpeg"):
            raise PictureError(f"cannot write '{path}': MP4 needs ffmpeg, which is not "
                               "installed (or not on PATH); write a .gif instead")
        return animation.FFMpegWriter(fps=fps)
    raise PictureError(f"cannot write '{path}': an animation is a .gif file (or .mp4 "
                       "when ffmpeg is installed)")


def animate(model, path: str | Path | None = None, steps: int | None = None,
            t_end: float | None = None, trace=(), fps: float | None = None, dpi: float = DPI,
            size: tuple[float, float] = ANIMATION_SIZE, html: bool = False) -> Path | str:
    """Write an animation of the model's kinematic run; returns the path (or, with
    ``html=True``, the animation as HTML for a notebook).

    The frames are the positions of a kinematic run over [0, t_end] (the branch ``run``
    follows), with a clock and the paths of the traced points. A progress bar shows on
    stderr while the frames are written, when it is a terminal. ``pam2exu animate`` calls
    this function.

    Parameters
    ----------
    model : Model, str or Path
        A model, or the path of a model file; every degree of freedom must be driven.
    path : str or Path, optional
        ``.gif`` (Pillow), or ``.mp4`` when ffmpeg is installed; None with ``html=True``.
    steps : int, optional
        Number of intervals: steps + 1 frames (default: the model's steps, at most
        ``FRAMES`` = 100).
    t_end : float, optional
        End of the motion [s] (default: the model's t_end).
    trace : list of str
        Points whose paths are drawn (``coupler.P``; a solid's name for its origin): the
        whole path faintly, the part travelled so far in full.
    fps : float, optional
        Frames per second [1/s]; default steps / t_end (real time) within ``FPS`` (2 to
        30).
    dpi : float
        Resolution of each frame [dots per inch].
    size : (float, float)
        Width and height of each frame [in].
    html : bool
        Return the animation as HTML with play controls (matplotlib's ``to_jshtml``: the
        frames as inline PNG and JavaScript) instead of writing a file; in a notebook,
        ``IPython.display.HTML(animate(model, html=True))`` shows it.

    Returns
    -------
    Path or str
        ``path``; with ``html=True``, the HTML text.

    Raises
    ------
    PictureError
        ``path`` is not .gif or .mp4, or it is .mp4 and ffmpeg is not installed (checked
        before the run); neither ``path`` nor ``html`` is given.
    ModelError
        The model has problems, or a traced point does not exist (``MobilityError``: a
        degree of freedom is not driven).
    SolverError
        Exudyn's solver did not converge.

    Examples
    --------
    >>> from pam2exu.pictures import animate
    >>> animate("examples/four_bar.toml", "four_bar.gif", trace=["coupler.P"])  # doctest: +SKIP
    PosixPath('four_bar.gif')
    """
    if path is None and not html:
        raise PictureError("animate needs the file to write (.gif, or .mp4 with ffmpeg), or "
                           "html=True for a notebook")
    path = None if html else Path(path)
    model = _model(model)
    a = model.analysis
    steps = int(steps or min(a.steps, FRAMES))
    t_end = float(t_end or a.t_end)
    fps = float(fps or min(max(steps / t_end, FPS[0]), FPS[1]))
    writer = None if html else _writer(path, fps)   # fail before the run, not after it
    mech = model.mechanism()
    traced = _traces(mech, trace)
    mech, t, q = configurations(model, t_end=t_end, steps=steps)
    st = State(t, q)
    paths = [st.point(solid, local).value for _, solid, local in traced]

    fig = figure(*size, dpi)
    ax = fig.add_subplot()
    scene = Scene(ax, mech, q, np.vstack(paths) if paths else ())
    ax.set_title(f"'{mech.name}' — kinematic run, t = 0 … {t_end:g} s")
    clock = ax.text(0.015, 0.975, "", transform=ax.transAxes, ha="left", va="top",
                    fontsize=10, family="monospace", zorder=10,
                    bbox=dict(facecolor="white", edgecolor="none", alpha=0.8))
    moving = []
    for k, ((name, _, _), xy) in enumerate(zip(traced, paths)):
        color = ("#444444", "#d62728", "#1f77b4", "#2ca02c")[k % 4]
        ax.plot(*xy.T, color=color, lw=1.0, alpha=0.5, linestyle=":", zorder=0.5,
                gid=f"trace:{name}")
        line, = ax.plot([], [], color=color, lw=1.6, zorder=0.6, label=f"path of {name}",
                        gid=f"trace:{name}")
        moving.append(line)
    if traced:
        ax.legend(loc="upper right", fontsize="small")

    def frame(k: int):
        scene.show(float(t[k]), q[k])
        for line, xy in zip(moving, paths):
            line.set_data(xy[:k + 1, 0], xy[:k + 1, 1])
        clock.set_text(f"t = {t[k]:.3f} s")
        return []

    # the layout is computed once, on the first frame, then kept (it would be redone at
    # every frame)
    frame(0)
    fig.canvas.draw()
    fig.set_layout_engine("none")
    if html:                                    # matplotlib's to_jshtml: PNG frames and JS
        from matplotlib.animation import FuncAnimation
        return FuncAnimation(fig, frame, frames=len(t), interval=1000.0 / fps).to_jshtml(
            fps=fps, default_mode="loop")
    with Progress(len(t), f"writing {path.name}") as bar:
        if writer is None:
            _write_gif(fig, path, fps, len(t), frame,
                       lambda: [*scene.pen.artists, *moving, clock], bar)
        else:
            with writer.saving(fig, path, dpi):
                for k in range(len(t)):
                    frame(k)
                    writer.grab_frame()
                    bar.update(k + 1)
    return path


def _write_gif(fig, path: Path, fps: float, frames: int, show, dynamic, bar) -> None:
    """Write a GIF with Pillow: the static part of the figure (axes, ticks, grid, global
    frame, whole traced paths) is drawn once and restored at each frame, over which only the
    artists of ``dynamic()`` are drawn; one palette for all frames (no flicker)."""
    from PIL import Image
    canvas = fig.canvas
    ax = fig.axes[0]
    for a in dynamic():
        a.set_visible(False)
    canvas.draw()
    background = canvas.copy_from_bbox(fig.bbox)
    size = canvas.get_width_height()
    images = []
    for k in range(frames):
        show(k)
        canvas.restore_region(background)
        for a in sorted(dynamic(), key=lambda a: a.get_zorder()):
            a.set_visible(True)
            ax.draw_artist(a)
        images.append(Image.frombuffer("RGBA", size, canvas.buffer_rgba(), "raw", "RGBA", 0, 1)
                      .convert("RGB"))
        bar.update(k + 1)
    # the palette from the first, middle and last frames together
    sample = Image.new("RGB", (size[0], 3 * size[1]))
    for j, k in enumerate((0, frames // 2, frames - 1)):
        sample.paste(images[k], (0, j * size[1]))
    palette = sample.quantize(colors=255, method=Image.Quantize.FASTOCTREE)
    frames_p = [im.quantize(palette=palette, dither=Image.Dither.NONE) for im in images]
    tmp = path.with_name(path.name + ".part")
    frames_p[0].save(tmp, format="GIF", save_all=True, append_images=frames_p[1:],
                     duration=round(1000.0 / fps), loop=0, optimize=False)
    tmp.replace(path)

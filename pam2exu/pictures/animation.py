"""``animate``: the motion of a mechanism as a GIF, an MP4 or HTML for a notebook.

The frames are the positions of a kinematic run (dynamic, for a model whose analysis is
dynamic: ``poses.configurations``), each drawn by a
``Scene``, with a clock and the paths of traced points. The writers: a GIF is written with
Pillow by ``_write_gif``, which draws the static part of the figure once and only the moving
artists at each frame, on one palette; an MP4 by matplotlib's ffmpeg writer, checked before
the run; HTML by matplotlib's ``to_jshtml``. Figures use the Agg canvas, never a window.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import ModelError, Problem
from ..kinematics import State
from ..progress import Progress
from ..results.plot import DPI, PictureError, figure
from ..results.writers import write_whole
from .poses import _model, configurations, motion
from .scene import Scene, fit_title

#: figure size of an animation [in] (smaller than a drawing: every frame is stored)
ANIMATION_SIZE = (6.4, 4.8)
#: frames per second of an animation are steps / t_end (real time), within these bounds
FPS = (2.0, 30.0)
#: most frames of an animation by default (the model's steps, up to this)
FRAMES = 100


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
    """Write an animation of the model's kinematic run (dynamic run, for a model whose
    analysis is dynamic); returns the path (or, with ``html=True``, the animation as HTML
    for a notebook).

    The frames are the positions of that run over [0, t_end] (the branch ``run``
    follows), with a clock and the paths of the traced points. A progress bar shows on
    stderr while the frames are written, when it is a terminal. ``pam2exu animate`` calls
    this function.

    Parameters
    ----------
    model : Model, str or Path
        A model, or the path of a model file; every degree of freedom must be driven,
        unless its analysis is dynamic.
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
    fit_title(fig, ax, f"'{mech.name}' — {motion(model)} run, t = 0 … {t_end:g} s")
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
    write_whole(path, lambda tmp: frames_p[0].save(
        tmp, format="GIF", save_all=True, append_images=frames_p[1:],
        duration=round(1000.0 / fps), loop=0, optimize=False))

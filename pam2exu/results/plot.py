"""Plots of result variables against time or another variable (``pam2exu plot``,
``pam2exu run --plot``, ``--x``).

Figures are made with matplotlib's object-oriented API on the Agg canvas (``figure``): no
pyplot, no window, no global backend state, so plotting works the same on a server, in CI
and in a script. Variables that share a unit share a panel; every line is labelled with its
PAM name and unit (``motor.Mz [N·m]``), every panel's y axis with its variables and unit.
"""
from __future__ import annotations

from pathlib import Path

from ..errors import ModelError, PictureError, closest
from ..model import Model, load
from .names import SPELLINGS, canonical_name
from .reading import read_csv
from .names import select_columns
from .table import Results
from .units import in_angles, unit_of

#: default resolution [dots per inch]; with ``WIDTH`` inches a plot is 880 px wide
DPI = 100
WIDTH = 8.8
#: height of one panel and of the space around the panels [in]
PANEL, MARGIN = 2.4, 0.9
#: legends with more entries than this go to the right of their panel
LEGEND_INSIDE = 4


def figure(width: float, height: float, dpi: float = DPI):
    """A matplotlib Figure on the Agg canvas (never a window), constrained layout.

    Parameters
    ----------
    width, height : float
        Size of the figure [in].
    dpi : float
        Resolution [dots per inch].

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    fig = Figure(figsize=(width, height), dpi=dpi, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def save(fig, path: str | Path) -> Path:
    """Write the figure at its own size and resolution; the format from the suffix.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        A figure with a canvas (``figure``).
    path : str or Path
        The image file; its suffix chooses the format (.png, .svg, .pdf, …).

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    PictureError
        The canvas cannot write that format.
    """
    path = Path(path)
    fig.savefig(path, dpi=fig.dpi, format=image_format(path))
    return path


def image_format(path: str | Path) -> str:
    """The image format of a file's suffix ('png', 'svg', …), or PictureError: what ``save``
    writes, checked before a run too.

    Raises
    ------
    PictureError
        The Agg canvas cannot write that format.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    fmt = Path(path).suffix[1:].lower()
    formats = FigureCanvasAgg.get_supported_filetypes()
    if fmt not in formats:
        raise PictureError(f"cannot write '{path}': the image format is chosen by the file "
                           f"suffix, one of {', '.join('.' + f for f in sorted(formats))}")
    return fmt


def label(name: str, unit: str) -> str:
    """``crank.fi [rad]`` (no brackets for a variable without a known unit).

    Parameters
    ----------
    name : str
        A variable's name.
    unit : str
        Its SI unit, or ''.

    Returns
    -------
    str

    Examples
    --------
    >>> label("crank.fi", "rad"), label("crank.fi", "")
    ('crank.fi [rad]', 'crank.fi')
    """
    return f"{name} [{unit}]" if unit else name


def plot(source, names=None, path: str | Path | None = None, model=None,
         title: str | None = None, dpi: float = DPI, x: str | None = None,
         angles: str | None = None):
    """Plot variables of a result table against t (or ``x``); returns the matplotlib Figure.

    Variables with the same unit share a panel, panels in the order the variables are
    asked for; every line is labelled with its name and unit (``motor.Mz [N·m]``), the x
    axis is ``t [s]``, or the variable ``x`` with its unit (``crank.fi [deg]``: the
    motor torque against the crank angle). ``pam2exu plot`` and ``pam2exu run --plot``
    call this function. The figure is on the Agg canvas: no window opens.

    Parameters
    ----------
    source : Results, str or Path
        A Results table (its ``units`` are used) or a result CSV file (units from the
        output declarations, see ``units.unit_of``).
    names : str or list of str, optional
        Variables: full names (``crank.fi``), ``crank.*``, ``*.Fx`` or a bare ``Fx``, as for
        ``--outputs``; PAM spellings (``Forca``, ``f``, ``Df``) are accepted. Default:
        every column.
    path : str or Path, optional
        Image file to write (.png, .svg, .pdf, …); None writes nothing.
    model : Model or path, optional
        For a CSV file: the model, which gives the units of ``f(t)`` and ``Df(t)``.
    title : str, optional
        Default: the model's name and the analysis (for a CSV file: its name).
    dpi : float
        Resolution [dots per inch]; the image is ``WIDTH`` × (``MARGIN`` + ``PANEL`` ×
        panels) inches (8.8 × (0.9 + 2.4 × panels) in).
    x : str, optional
        The variable on the x axis, one column (``crank.fi``; PAM spellings accepted),
        the axis labelled with its unit ([deg], [m], …); default ``t`` [s]. It is not
        plotted against itself.
    angles : str, optional
        ``"deg"`` or ``"rad"``: the angular columns (x included) in that unit
        (``units.in_angles``); default: as the table has them (a CSV file written in
        degrees says so on its units line).

    Returns
    -------
    matplotlib.figure.Figure
        One Axes per unit, sharing the t axis.

    Raises
    ------
    PictureError
        A name or ``x`` matches no column (the message suggests the nearest), ``x`` is
        a pattern, nothing is left to plot, or the image format of ``path`` is not
        supported.
    CompareInputError
        The CSV file is missing or unreadable.
    ModelError
        ``model`` is a model file with problems.

    Examples
    --------
    >>> from pam2exu.results import Results, plot
    >>> res = Results([0.0, 0.5, 1.0], {"crank.fi": [0.0, 3.0, 6.0], "B.Fx": [1.0, 0.0, -1.0],
    ...               "B.Fy": [0.0, 2.0, 0.0]}, {"crank.fi": "rad", "B.Fx": "N", "B.Fy": "N"})
    >>> fig = plot(res, ["B.*", "crank.fi"])
    >>> [ax.get_ylabel() for ax in fig.axes]
    ['Fx, Fy [N]', 'crank.fi [rad]']
    >>> fig = plot(res, "B.Fx", x="crank.fi", angles="deg")
    >>> fig.axes[0].get_xlabel(), fig.axes[0].lines[0].get_xdata().tolist()[:2]
    ('crank.fi [deg]', [0.0, 171.88733853924697])
    >>> plot("results.csv", "motor.Mz", "torque.png")        # doctest: +SKIP
    <Figure size 880x330 with 1 Axes>
    """
    if model is not None and not isinstance(model, Model):
        model = load(model)
    if isinstance(source, Results):
        res = source
    else:
        res = read_csv(source, model)
        if title is None:
            title = f"{Path(source).name}" + (f" ('{model.name}')" if model else "")
    where = f"'{source}'" if not isinstance(source, Results) else "the results"
    if angles is not None:
        res = in_angles(_with_units(res, model), angles)
    x = "t" if x is None else _x_column(res.columns, x, where)
    columns = [c for c in _in_order(res.columns, names, where) if c != x]
    if not columns:
        raise PictureError("nothing to plot: choose variables besides t"
                           + (f" and the x axis '{x}'" if x != "t" else ""))
    panels: dict[str, list[str]] = {}
    for c in columns:
        unit = res.units.get(c) or unit_of(c, model)
        panels.setdefault(unit, []).append(c)
    fig = figure(WIDTH, MARGIN + PANEL * len(panels), dpi)
    axes = fig.subplots(len(panels), 1, sharex=True, squeeze=False)[:, 0]
    marker = "o" if len(res) == 1 else None
    for ax, (unit, cols) in zip(axes, panels.items()):
        for c in cols:
            ax.plot(res[x], res[c], marker=marker, label=label(c, unit))
        if len(cols) == 1:
            ax.set_ylabel(label(cols[0], unit))
        else:
            variables = list(dict.fromkeys(c.rpartition(".")[2] for c in cols))
            ax.set_ylabel(label(", ".join(variables[:3]) + (", …" if len(variables) > 3
                                                            else ""), unit))
            if len(cols) <= LEGEND_INSIDE:
                ax.legend(fontsize="small")
            else:
                ax.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.01, 1.0))
        ax.grid(True, alpha=0.3)
    axes[-1].set_xlabel(label(x, res.units.get(x) or unit_of(x, model)))
    if title is None:
        title = " — ".join(x for x in (f"'{res.model}'" if res.model else "",
                                       f"{res.analysis} analysis" if res.analysis else "") if x)
    if title:
        fig.suptitle(title)
    if path is not None:
        save(fig, path)
    return fig


def _with_units(res: Results, model) -> Results:
    """``res`` with the units its table lacks found from the declarations (and ``model``)."""
    missing = {c: unit_of(c, model) for c in res.columns if not res.units.get(c)}
    if not any(missing.values()):
        return res
    return Results(res.t, {c: res[c] for c in res.columns}, {**res.units, **missing},
                   res.analysis, res.model, res.warnings, res.info, res.backend)


def _x_column(columns: list[str], x: str, where: str) -> str:
    """The one column ``x`` names (PAM spellings accepted); PictureError naming the nearest."""
    name = canonical_name(x) if "." in x else x
    if name == "t" or name in columns:
        return name
    if any(c in x for c in "*?["):
        raise PictureError(f"the x axis is one variable, not a pattern: got '{x}'; give a "
                           f"full name such as crank.fi")
    raise PictureError(f"the x axis '{x}' is not a column of {where}"
                       f"{closest(name, ['t', *columns])}; give a full name such as crank.fi")


def _in_order(columns: list[str], names, where: str) -> list[str]:
    """The columns matching ``names``, in the order of the patterns (then of the table);
    PictureError naming every pattern that matches nothing."""
    if names is None:
        return [c for c in columns if c != "t"]
    names = [names] if isinstance(names, str) else list(names)
    # PAM spellings as in the files: motor.Forca, f, Df
    names = [canonical_name(n) if "." in n else SPELLINGS.get(n, n) for n in names]
    try:
        select_columns(columns, names)
    except ModelError as exc:
        raise PictureError("; ".join(p.message.replace("of this analysis", f"of {where}")
                                     for p in exc.problems)
                           + "; use full names (crank.fi), 'crank.*', '*.Fx' or a bare "
                             "variable (Fx)") from None
    out: dict[str, None] = {}
    for p in names:
        out.update(dict.fromkeys(c for c in select_columns(columns, [p]) if c != "t"))
    return list(out)

"""The pictures of a study: the histogram of a reduced output with its requirements'
limits, the percentile band of an output's series over t, a reduced output against a
parameter, and the tornado of first-order contributions (``pam2exu study --hist``,
``--band``, ``--scatter``; ``StudyResult.hist``, ``band``, ``scatter``).

Each function draws on the Axes it is given, or on a new figure on the Agg canvas
(``results.plot.figure``: no window, no pyplot), and returns the Axes (its ``figure`` is
the Figure, ``results.plot.save`` writes it). The statistics are over the variants that ran
(status ok or rejected); a variant in error has no values. The numbers drawn are the
table's: the histogram's bars are ``numpy.histogram(values, bins="auto")``, the band's
curves ``numpy.quantile`` of the series at each t (its default, linear method, as the
summary's quantiles), the scatter's points the per-variant table's columns.

Bad input (an output the study does not reduce or keep, a parameter it does not vary, a
band without ``series = true``) is a ``PictureError`` naming what asked for it, the name
and the closest names; ``pam2exu study`` checks it before any variant runs
(``check_reduced``, ``check_series``, ``check_parameter``).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import PictureError, closest
from ..results.plot import WIDTH, figure, label
from .reduce import ERROR, REDUCTIONS
from .summary import QUANTILES

#: height of a study's picture [in] (its width is ``results.plot.WIDTH``)
HEIGHT = 4.0
#: the names an error message lists at most
LISTED = 12
#: the band's shades: the 1–99 % and the 5–95 % ranges
SHADES = (("q01", "q99", 0.18), ("q05", "q95", 0.35))
#: characters of a name that do not go into a file name
UNSAFE = '/\\:*?"<>| '


def _unknown(what: str, name: str, kind: str, known: list[str]) -> PictureError:
    """The error of a name that is not among ``known`` (with the closest, and the list)."""
    listed = ", ".join(known[:LISTED]) + (", …" if len(known) > LISTED else "")
    return PictureError(f"{what} '{name}' is not {kind} of the study{closest(name, known)}; "
                        f"the study's: {listed or 'none'}")


def check_reduced(output: str, outputs: list[str], what: str = "hist") -> None:
    """PictureError unless ``output`` is one of the reduced outputs (``motor.Mz.absmax``)."""
    if output not in outputs:
        raise _unknown(what, output, "a reduced output", list(outputs))


def check_series(output: str, series: list[str] | None, what: str = "band",
                 source: str = "the study file") -> None:
    """PictureError unless the study keeps its series (``series`` not None) and ``output``
    is one of their outputs (``motor.Mz``); ``source`` names the study file."""
    if series is None:
        raise PictureError(f"{what} '{output}' needs the series of the variants: set "
                           f"series = true in the [study] table of {source}")
    if output not in series:
        raise _unknown(what, output, "an output whose series the study keeps", list(series))


def check_parameter(parameter: str, parameters: list[str], what: str = "scatter") -> None:
    """PictureError unless ``parameter`` is one the study varies (``crank.A.x``)."""
    if parameter not in parameters:
        raise _unknown(what, parameter, "a parameter", list(parameters))


def picture_path(base: str | Path, kind: str, *names: str) -> Path:
    """``<base>.<kind>.<name>[.vs.<name>].png``, the characters a file name cannot hold as
    '_': ``picture_path("tol", "hist", "motor.Mz.absmax")`` is tol.hist.motor.Mz.absmax.png.
    """
    safe = [n.translate({ord(c): "_" for c in UNSAFE}) for n in names]
    return Path(f"{base}.{kind}.{'.vs.'.join(safe)}.png")


def _axes(ax):
    """``ax``, or the Axes of a new figure on the Agg canvas."""
    return figure(WIDTH, HEIGHT).add_subplot() if ax is None else ax


def ran(result) -> np.ndarray:
    """The mask of the variants that ran (status ok or rejected)."""
    return result.table["status"] != ERROR


def _requirements(result, output: str) -> list[tuple[str, float]]:
    """('min' or 'max', bound) of every requirement on ``output``."""
    return [(side, bound) for r in result.study.requirements if r.output == output
            for side, bound in (("min", r.min), ("max", r.max)) if bound is not None]


def _values(result, output: str, what: str) -> np.ndarray:
    """The reduced output's values of the variants that ran; PictureError when none ran."""
    check_reduced(output, result.outputs, what)
    values = result.table[output][ran(result)]
    if values.size == 0:
        raise PictureError(f"{what} '{output}': no variant of the study ran (every one is in "
                           f"error), so there is nothing to draw")
    return values


def hist(result, output: str, ax=None, bins="auto"):
    """The histogram of a reduced output over the variants that ran, a dashed line at each
    bound of a requirement on it.

    Parameters
    ----------
    result : StudyResult
    output : str
        A reduced output (``motor.Mz.absmax``).
    ax : matplotlib.axes.Axes, optional
        Where to draw; default a new figure.
    bins : int, sequence or str
        As ``numpy.histogram``'s (default ``"auto"``).

    Returns
    -------
    matplotlib.axes.Axes
        Its ``patches`` are the bars (heights: ``numpy.histogram``'s counts), its ``lines``
        the requirements' bounds (labelled ``required min …``, ``required max …``).
    """
    values = _values(result, output, "hist")
    ax = _axes(ax)
    counts, edges = np.histogram(values, bins=bins)
    ax.hist(values, bins=edges, color="C0", edgecolor="white", label=f"{values.size} variants")
    for side, bound in _requirements(result, output):
        ax.axvline(bound, color="C3", linestyle="--", label=f"required {side} {bound:.6g}")
    ax.set_xlabel(label(output, result.units.get(output, "")))
    ax.set_ylabel("variants")
    ax.set_title(f"{output}: {values.size} variants that ran")
    ax.legend(loc="best")
    return ax


def band_curves(series: dict, output: str) -> tuple[np.ndarray, np.ndarray]:
    """(t, the 1, 5, 50, 95 and 99 % quantiles of ``output`` at each t): the series table
    (long format, the variants that ran) folded to one row per variant; PictureError when
    the variants' times differ or no variant ran."""
    samples = series["sample"]
    count = np.unique(samples).size
    if count == 0:
        raise PictureError(f"band '{output}': no variant of the study ran (every one is in "
                           f"error), so there is nothing to draw")
    t = series["t"].reshape(count, -1)
    if not (t == t[0]).all():
        raise PictureError(f"band '{output}': the variants' series have different times")
    y = series[output].reshape(count, -1)
    return t[0].copy(), np.quantile(y, list(QUANTILES.values()), axis=0)


def band(result, output: str, ax=None):
    """The percentile band of an output's series over t: the 1 … 99 % and 5 … 95 % ranges
    shaded, each quantile a line, the median bold.

    Parameters
    ----------
    result : StudyResult
        Of a study with ``series = true``.
    output : str
        An output whose series the study keeps (``motor.Mz``).
    ax : matplotlib.axes.Axes, optional

    Returns
    -------
    matplotlib.axes.Axes
        Its ``lines``, labelled ``q01``, ``q05``, ``q50``, ``q95``, ``q99``, are the curves
        (``band_curves``).
    """
    series = result.series
    check_series(output, None if series is None else list(series)[2:], "band",
                 result.study.source)
    t, curves = band_curves(series, output)
    q = dict(zip(QUANTILES, curves))
    ax = _axes(ax)
    shades = [ax.fill_between(t, q[low], q[high], color="C0", alpha=alpha, linewidth=0,
                              label=f"{low[1:]} … {high[1:]} %")
              for low, high, alpha in SHADES]
    lines = {name: ax.plot(t, curve, color="C0", label=name,
                           **({"linewidth": 2.0} if name == "q50" else
                              {"linewidth": 0.5, "alpha": 0.5}))[0]
             for name, curve in q.items()}
    ax.set_xlabel(label("t", "s"))
    ax.set_ylabel(label(output, result.units.get(output, "")))
    ax.set_title(f"{output}: percentiles over {np.unique(series['sample']).size} variants")
    ax.legend(handles=[*shades, lines["q50"]], labels=["1 … 99 %", "5 … 95 %", "median"],
              loc="best")
    return ax


def scatter(result, output: str, parameter: str, ax=None):
    """A reduced output against a parameter, a point per variant that ran (ok and rejected
    in their own colours), a dashed line at each bound of a requirement on the output.

    Parameters
    ----------
    result : StudyResult
    output : str
        A reduced output (``motor.Mz.absmax``).
    parameter : str
        A parameter of the study (``crank.A.x``).
    ax : matplotlib.axes.Axes, optional

    Returns
    -------
    matplotlib.axes.Axes
        Its ``collections`` are the points, one per status that occurs (``ok``, then
        ``rejected``); its ``lines`` the requirements' bounds.
    """
    check_parameter(parameter, result.parameters, "scatter")
    _values(result, output, "scatter")
    ax = _axes(ax)
    status = result.table["status"]
    for which, colour in (("ok", "C0"), ("rejected", "C3")):
        chosen = status == which
        if chosen.any():
            ax.scatter(result.table[parameter][chosen], result.table[output][chosen], s=14,
                       color=colour, label=f"{which} ({int(chosen.sum())})")
    for side, bound in _requirements(result, output):
        ax.axhline(bound, color="C3", linestyle="--", label=f"required {side} {bound:.6g}")
    ax.set_xlabel(label(parameter, result.units.get(parameter, "")))
    ax.set_ylabel(label(output, result.units.get(output, "")))
    ax.set_title(f"{output} against {parameter}")
    ax.legend(loc="best")
    return ax


def tornado(output: str, contributions: dict, ax=None, unit: str = ""):
    """The tornado of first-order contributions to an output: one bar per parameter, its
    signed ∂y/∂p · σ_p, the largest |contribution| on top.

    Parameters
    ----------
    output : str
        The output (``motor.Mz.final``), for the title.
    contributions : dict of str to float
        Parameter → ∂y/∂p · σ_p [the output's unit].
    ax : matplotlib.axes.Axes, optional
    unit : str
        The output's unit.

    Returns
    -------
    matplotlib.axes.Axes
        Its ``patches`` are the bars, top to bottom in the order of decreasing
        |contribution| (widths: the contributions); its y tick labels the parameters.

    Examples
    --------
    >>> ax = tornado("slider.x.final", {"crank.A.x": 1e-4, "rod.B.x": -3e-4})
    >>> [t.get_text() for t in ax.get_yticklabels()], [float(p.get_width()) for p in ax.patches]
    (['rod.B.x', 'crank.A.x'], [-0.0003, 0.0001])
    """
    if not contributions:
        raise PictureError(f"tornado '{output}': no parameter's contribution to draw")
    ranked = sorted(contributions.items(), key=lambda item: -abs(item[1]))
    names = [n for n, _ in ranked]
    values = np.array([v for _, v in ranked], dtype=float)
    rows = np.arange(len(ranked))
    ax = _axes(ax)
    ax.barh(rows, values, color=np.where(values >= 0, "C0", "C3"))
    ax.axvline(0.0, color="black", linewidth=0.8)
    ax.set_yticks(rows, labels=names)
    ax.invert_yaxis()                                   # the largest on top
    ax.set_xlabel(label("∂y/∂p · σ_p", unit))
    ax.set_title(f"{output}: first-order contributions")
    return ax


def sensitivity_tornado(sensitivities, output: str, ax=None):
    """The tornado of a reduced output (``motor.Mz.final``) from a study's sensitivities at
    its nominal variant (``linear.Sensitivities``): ∂y_r/∂p · σ_p of every parameter."""
    column, _, reduction = output.rpartition(".")
    if column not in sensitivities.nominal or reduction not in REDUCTIONS:
        known = [f"{c}.{r}" for c in sensitivities.nominal for r in REDUCTIONS]
        raise _unknown("tornado", output, "a reduced output", known)
    return tornado(output, sensitivities.contributions(column, reduction), ax,
                   sensitivities.units.get(column, ""))

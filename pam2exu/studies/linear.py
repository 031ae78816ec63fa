"""The first-order method of a study (``method = "linear"``), and the linear σ beside a
sampled study's summary.

At the nominal variant: ∂y/∂p of every output series to every parameter, from the solved
equations themselves (``analyses.sensitivity``: the implicit-function theorem through the
positions, velocities, accelerations and forces, by the complex step, never a difference
of runs); σ_y(t) = sqrt(Σ_p (∂y/∂p σ_p)²) with σ_p the parameter's standard deviation;
and the same for each reduced output, ∂y_r/∂p from each reduction's ``derivative`` (``reduce.REDUCTIONS``).

A linear study's table (``OUT.parquet`` or ``.csv``) has one row per output time: ``t``,
then for each output ``<output>`` (nominal), ``<output>.std`` (σ_y(t)) and
``<output>.d.<parameter>`` (∂y/∂p). Its summary has one row per reduced output with
``count`` = 1, ``mean`` = the nominal value, ``linear_std`` for the ``final`` and ``mean``
reductions; then the row ``yield``: whether the nominal variant meets the requirements.
"""
from __future__ import annotations

import copy
import os
import warnings
from pathlib import Path

import numpy as np

from ..errors import ModelError, Pam2ExuError, Problem
from ..results import Results
from ..results.units import angle_factor, in_angles
from . import plots
from .parameters import targets, write
from .reduce import LINEAR_STD, OK, REDUCTIONS, status
from .result import Yield, check_out, summary_path
from .summary import SummaryRow, write_summary

#: the parameters a report lists per reduced output, largest contribution first
SHOWN_PARAMETERS = 3


class Sensitivities:
    """∂y/∂p of a study's output series at its nominal variant.

    Parameters
    ----------
    t : numpy.ndarray
        The output rows' times (n,).
    nominal : dict of str to numpy.ndarray
        Output column → its nominal series (n,).
    derivative : dict of str to numpy.ndarray
        Output column → ∂y/∂p (n, P), one column per parameter.
    parameters : list of str
        The parameters' names (P).
    sigmas : numpy.ndarray
        σ_p of each parameter (P,), in the parameter's unit.
    units : dict of str to str
        Each output column's and parameter's unit.
    """

    def __init__(self, t, nominal, derivative, parameters, sigmas, units):
        self.t = np.asarray(t, dtype=float)
        self.nominal = nominal
        self.derivative = derivative
        self.parameters = list(parameters)
        self.sigmas = np.asarray(sigmas, dtype=float)
        self.units = units

    @property
    def columns(self) -> list[str]:
        """The output columns, in the analysis' order."""
        return list(self.nominal)

    def std(self, column: str) -> np.ndarray:
        """σ_y(t) = sqrt(Σ_p (∂y/∂p σ_p)²) of an output series (n,)."""
        return np.sqrt(np.sum(np.square(self.derivative[column] * self.sigmas), axis=1))

    def reduced(self, column: str, reduction: str) -> tuple[float, np.ndarray]:
        """(y_r, ∂y_r/∂p (P,)) of a reduced output at the nominal variant."""
        y, dy = self.nominal[column], self.derivative[column]
        reduce = REDUCTIONS[reduction]
        return reduce(y), reduce.derivative(y, dy)

    def contributions(self, column: str, reduction: str) -> dict[str, float]:
        """∂y_r/∂p σ_p of every parameter (signed): the bars of a tornado plot."""
        return dict(zip(self.parameters, self.reduced(column, reduction)[1] * self.sigmas))

    def reduced_std(self, column: str, reduction: str) -> float:
        """The first-order σ of a reduced output: sqrt(Σ_p (∂y_r/∂p σ_p)²)."""
        return float(np.sqrt(np.sum(np.square(self.reduced(column, reduction)[1]
                                              * self.sigmas))))

    def linear_std(self, reduced: list[str]) -> dict[str, float]:
        """The summary's ``linear_std`` of the reduced outputs that have one (``final``,
        ``mean``: ``reduce.LINEAR_STD``), by reduced name."""
        out = {}
        for name in reduced:
            column, _, reduction = name.rpartition(".")
            if reduction in LINEAR_STD and column in self.nominal:
                out[name] = self.reduced_std(column, reduction)
        return out

    def table(self) -> dict[str, np.ndarray]:
        """The linear study's columns: ``t``, then per output ``<output>``,
        ``<output>.std`` and ``<output>.d.<parameter>``."""
        out = {"t": self.t}
        for c in self.columns:
            out[c] = self.nominal[c]
            out[f"{c}.std"] = self.std(c)
            for k, p in enumerate(self.parameters):
                out[f"{c}.d.{p}"] = self.derivative[c][:, k]
        return out


def sensitivities(study) -> Sensitivities:
    """∂y/∂p of the study's outputs at its nominal variant (``analyses.sensitivity``).

    Parameters
    ----------
    study : Study
        A study of an analysis the first-order method differentiates
        (``AnalysisType.first_order``), with parameters that have a σ.

    Returns
    -------
    Sensitivities

    Raises
    ------
    ModelError
        The nominal model fails, or a parameter cannot be differentiated (an
        over-constrained mechanism that cannot follow it, a law's time at a row's time…),
        naming the parameter.
    """
    from ..analyses import run
    from ..analyses.job import check_mobility, prepare
    from ..analyses.sensitivity import STEP, derivatives, nominal
    model = study.model
    job = prepare(model, study.analysis, t_end=study.t_end, steps=study.steps,
                  outputs=study.outputs)
    mech = job.mech
    mobility = check_mobility(job, mech.initial_q())
    if mobility.dof:
        raise ModelError([Problem("[study]", f"the first-order method needs every degree of "
                                             f"freedom driven: the model has {mobility.dof} "
                                             "free (add actuators, or sample the study)")],
                         study.source, kind="study")
    wanted = list(dict.fromkeys([*job.columns, *mech.coordinate_columns("")]))
    with warnings.catch_warnings():                  # the nominal run warned in ``nominal``
        warnings.simplefilter("ignore")
        res = run(model, study.analysis, t_end=study.t_end, steps=study.steps, outputs=wanted,
                  backend=study.backend)
    t, q = res.t, mech.coordinates(in_angles(res, "rad"))    # the passes work in radians
    at = nominal(job, t, q, mobility.redundant > 0)          # Cq there, for every parameter
    # ∂y/∂p in the result's units: an angular output in degrees in a degrees model
    factor = {c: angle_factor(job.units.get(c, ""), model.angles)[0] for c in job.columns}
    found = targets(model)
    derivative = {c: np.empty((len(t), len(study.names))) for c in job.columns}
    problems = []
    for k, name in enumerate(study.names):
        target = found[name]
        shifted = copy.deepcopy(model)
        write(shifted, target, complex(target.nominal, STEP))
        try:
            d = derivatives(job, at, shifted, STEP, parameter=f"parameter '{name}'")
        except Pam2ExuError as exc:
            problems.append(Problem(f"[[parameter]] '{name}'", str(exc)))
            continue
        for c in job.columns:
            derivative[c][:, k] = d[c] * factor[c]
    if problems:
        raise ModelError(problems, study.source, kind="study")
    units = {**{c: res.units.get(c, "") for c in job.columns},
             **{p.name: p.unit for p in study.parameters}}
    return Sensitivities(t, {c: np.array(res[c]) for c in job.columns}, derivative,
                         study.names, study.sigmas(), units)


class LinearResult:
    """The result of a linear study: the sensitivities' table, its summary, the nominal
    variant's status against the requirements.

    Parameters
    ----------
    study : Study
        The study as it ran.
    sens : Sensitivities
        ∂y/∂p at the nominal variant.
    reduced : list of str
        The reduced outputs (``<output>.<reduction>``).
    """

    #: what a row of the table is, for messages
    ROWS = "output times"

    def __init__(self, study, sens: Sensitivities, reduced: list[str]):
        self.study, self.sensitivities, self.outputs = study, sens, list(reduced)
        self.series = None                     # the table is the series: no series table
        self.table = sens.table()
        self.values = {n: sens.reduced(*n.rsplit(".", 1))[0] for n in self.outputs}
        self.status = status(self.values, study.requirements)
        stds = sens.linear_std(self.outputs)
        self.summary = [SummaryRow(n, 1, mean=self.values[n], linear_std=stds.get(n, np.nan))
                        for n in self.outputs]
        self.summary.append(SummaryRow("yield", 1, mean=float(self.status == OK)))

    def __len__(self) -> int:
        return len(self.table["t"])

    def __repr__(self) -> str:
        return (f"<LinearResult {self.study.analysis} of '{self.study.model_path}': "
                f"{len(self.sensitivities.parameters)} parameters, {len(self)} rows>")

    @property
    def yield_(self) -> Yield:
        """Whether the nominal variant meets the requirements (share 1 or 0 of 1)."""
        ok = int(self.status == OK)
        return Yield(float(ok), np.nan, np.nan, ok, 1)

    def results(self) -> Results:
        """The table as a ``Results`` (units, writers, ``to_pandas``)."""
        units = self.sensitivities.units
        cols = {n: c for n, c in self.table.items() if n != "t"}
        unit = {}
        for n in cols:
            base, _, parameter = n.partition(".d.")
            u, per = units.get(base.removesuffix(".std"), ""), units.get(parameter, "")
            unit[n] = f"{u or '1'}/{per}" if per else u
        return Results(self.table["t"], cols, unit, self.study.analysis, self.study.model_path.stem)

    def tornado(self, output: str, ax=None):
        """The tornado of a reduced output (``motor.Mz.final``): each parameter's
        first-order contribution ∂y_r/∂p · σ_p, the largest on top; returns the matplotlib
        Axes.

        Parameters
        ----------
        output : str
            A reduced output (``motor.Mz.absmax``).
        ax : matplotlib.axes.Axes, optional
            Where to draw; default a new figure on the Agg canvas.
        """
        return plots.sensitivity_tornado(self.sensitivities, output, ax)

    def to_pandas(self):
        """The table as a pandas DataFrame (``pip install "pam2exu[pandas]"``)."""
        return self.results().to_pandas()

    def to_parquet(self, path) -> Path:
        """Write the table as Parquet (``pip install "pam2exu[parquet]"``)."""
        return self.results().to_parquet(path)

    def to_csv(self, path) -> Path:
        """Write the table as CSV (the numbers read back bit for bit)."""
        return self.results().to_csv(path)

    def write(self, out) -> tuple[Path, Path]:
        """Write ``OUT.parquet`` or ``OUT.csv`` (by suffix) and ``OUT.summary.csv``."""
        out = check_out(out)
        written = self.to_parquet(out) if out.suffix.lower() == ".parquet" else self.to_csv(out)
        return written, write_summary(self.summary, summary_path(out))

    def report(self) -> str:
        """The printed form: each reduced output's nominal value, its first-order σ and the
        parameters that contribute most."""
        s, sens = self.study, self.sensitivities
        lines = [f"study of {os.path.normpath(s.model_path)}: {s.analysis}, first order at the "
                 f"nominal variant, {len(sens.parameters)} parameters, {s.steps} steps to "
                 f"t = {s.t_end:.6g} s"]
        width = max([len("output"), *(len(n) for n in self.outputs)])
        lines.append(f"{'output':<{width}}  {'nominal':>11}  {'linear σ':>11}  largest "
                     "contributions ∂y/∂p·σ_p")
        for n in self.outputs:
            column, _, reduction = n.rpartition(".")
            parts = sorted(sens.contributions(column, reduction).items(),
                           key=lambda item: -abs(item[1]))[:SHOWN_PARAMETERS]
            largest = abs(parts[0][1]) if parts else 0.0
            parts = [(p, v) for p, v in parts if abs(v) > 1e-9 * largest]   # not round-off
            shown = ", ".join(f"{p} {v:+.3g}" for p, v in parts)
            lines.append(f"{n:<{width}}  {self.values[n]:>11.5g}  "
                         f"{sens.reduced_std(column, reduction):>11.5g}  {shown}")
        lines.append(f"nominal variant: {self.status} against the requirements")
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.report()

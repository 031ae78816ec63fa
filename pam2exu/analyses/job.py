"""An analysis before its numerics: the Job (model, grid, columns, backend), how it is
prepared from a model and the overrides, the mobility check, the warnings kept with it,
and the Results table it ends in."""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from .. import points, registry
from ..backend import Backend
from ..elements import ACCELERATION, CLEARANCE, FORCE, POSITION, VELOCITY, Var
from ..errors import (InputWarning, ModelError, Problem, RedundancyWarning, SolverError,
                      warn_outside)
from ..kinematics import State, column
from ..model import Mechanism, Model, load
from ..model.mistakes import input_warnings
from ..model.solid import SOLID_OUTPUTS
from ..model.variation import pace_problems
from ..results import Results, select_columns
from ..results.info import RunInfo
from . import grid, rank


@dataclass
class Job:
    """One analysis of one mechanism, with everything decided before the numerics.

    ``times`` is the grid positions are solved on; the results keep every ``every``-th row
    of it (the user's times, ``grid.Plan``).
    """

    mech: object
    #: the analysis (its declaration: ``registry.AnalysisType``), asked what it gives
    analysis_type: registry.AnalysisType
    times: np.ndarray
    columns: list[str]
    units: dict[str, str]
    levels: set[str]
    #: what solves the positions, and its settings (``backend.Settings``)
    backend: Backend
    solver: object
    warnings: list[str] = field(default_factory=list)
    info: RunInfo = field(default_factory=RunInfo)
    every: int = 1
    #: (actuator, its largest motion per user step, unit), for messages
    motion: tuple | None = None
    #: what the analysis is doing, for the message of an unexpected failure
    stage: str = "checking the analysis settings"
    #: the value of every analysis option (``registry.OPTIONS``: name → value); the
    #: analysis reads those its type declares (``AnalysisType.options``)
    options: dict = field(default_factory=lambda: {o.name: o.default
                                                    for o in registry.OPTIONS.values()})


def available_columns(mech, kind: registry.AnalysisType,
                      derived: bool = True) -> dict[str, Var]:
    """Every column the analysis ``kind`` can produce, in order: solids, then elements;
    without ``derived``, not the opt-in columns of ``derived_columns`` (the default outputs
    leave them out). Made once per structure (``_structure``: a study's variants share it;
    a copy each time)."""
    key = (kind, derived, _structure(mech))
    if key not in _COLUMNS:
        if len(_COLUMNS) >= KEPT_COLUMNS:
            _COLUMNS.pop(next(iter(_COLUMNS)))
        _COLUMNS[key] = _available(mech, kind, derived)
    return dict(_COLUMNS[key])


#: ``available_columns`` by analysis, ``derived`` and structure: at most KEPT_COLUMNS, the
#: oldest dropped first
_COLUMNS: dict = {}
KEPT_COLUMNS = 32


def _structure(mech) -> tuple:
    """What a mechanism's columns are made of: each solid's name and points' names, each
    element's type, name, clearance, equations and solids (its references'), the ground."""
    return (tuple((s.name, tuple(s.points)) for s in mech.solids),
            tuple((type(el), el.name, el.clearance, el.equations, el.solids,
                   tuple(r.solid for r in el.refs)) for el in mech.elements),
            mech.held)


def _available(mech, kind: registry.AnalysisType, derived: bool) -> dict[str, Var]:
    """``available_columns``, made."""
    out, levels = {}, kind.levels
    own = [var for var in SOLID_OUTPUTS if var.level in levels]
    extra = _derived(mech, levels) if kind.element_outputs and derived else None
    for i, s in enumerate(mech.solids):
        for var in own:
            out[f"{s.name}.{var.name}"] = var
        if extra:                                # opt-in: points, centres, couplers
            out.update(extra[i])
    for el in mech.elements if kind.element_outputs else ():
        for var in el.outputs:
            if var.level in levels:
                out[f"{el.name}.{var.name}"] = var
    if CLEARANCE in levels:                      # the joints with clearance = true
        for el in mech.elements:
            if el.clearance:
                for var in el.clearance_parameters + el.clearance_derived:
                    out[f"{el.name}.{var.name}"] = var
    return out


def derived_columns(mech) -> list[tuple[str, Var]]:
    """The opt-in columns (``points``), in order: per solid its instantaneous centre (if it
    is not fixed), its transmission angle (if it is a coupler), then its points' motion."""
    return [c for columns in _derived(mech) for c in columns]


def _derived(mech, levels=None) -> list[list[tuple[str, Var]]]:
    """``derived_columns`` of each solid, those of the ``levels`` given (default all)."""
    def kept(variables):
        return [var for var in variables if levels is None or var.level in levels]
    centre, coupler, point = (kept(points.CENTRE_OUTPUTS), kept(points.COUPLER_OUTPUTS),
                              kept(points.POINT_OUTPUTS))
    ground, coupled = mech.held, {c.solid for c in points.couplers(mech)}
    out = []
    for i, s in enumerate(mech.solids):
        columns = []
        if i not in ground:
            columns += [(f"{s.name}.{var.name}", var) for var in centre]
        if i in coupled:
            columns += [(f"{s.name}.{var.name}", var) for var in coupler]
        columns += [(f"{s.name}.{p}.{var.name}", var) for p in s.points for var in point]
        out.append(columns)
    return out


def prepare(model, analysis=None, t_end=None, steps=None, outputs=None, solver=None,
            backend=None, **options) -> Job:
    """Load and validate the model (a ``Mechanism``: the model it was made of, validated
    already), apply the overrides, choose the columns and the backend
    (``solver``: the backend's settings, default ``backend.Settings()``; ``backend``: a
    name of ``registry.BACKENDS``, or a ``Backend`` instance to use); ``options``: the
    analysis options (``registry.OPTIONS``, e.g. ``tolerance``), TypeError for another
    keyword."""
    registry.refuse_unknown_options(options)
    engine = backend if isinstance(backend, Backend) else None
    if engine is not None:                       # an instance (one holding answers)
        backend = engine.name
    mech = model if isinstance(model, Mechanism) else None
    if mech is not None:                         # validated and resolved already
        model = mech.model
    elif not isinstance(model, Model):
        model = load(model)
    settings = replace(model.analysis, **{k: v for k, v in
                                          dict(type=analysis, t_end=t_end, steps=steps,
                                               outputs=outputs, backend=backend,
                                               **options).items()
                                          if v is not None})
    problems = [Problem("[analysis]", m) for m in settings.problems()]
    if problems:
        raise ModelError(problems, model.source)
    mech = mech or model.mechanism()
    kind = registry.ANALYSES[settings.type]
    if CLEARANCE in kind.levels:                 # the analysis that reads the variations
        too_fast = pace_problems(mech.variations, settings.t_end, settings.steps)
        if too_fast:
            raise ModelError([Problem(*p) for p in too_fast], model.source)
    # the default outputs leave the derived columns out: they are not made then
    available = available_columns(mech, kind, derived=settings.outputs is not None)
    try:
        if settings.outputs is None:             # the default: every column not opt-in
            columns = [c for c in available if not points.is_opt_in(c)]
        else:
            columns = select_columns(list(available), settings.outputs)
    except ModelError as exc:
        raise ModelError(exc.problems, model.source) from None
    if kind.at_start:
        plan = grid.Plan(np.zeros(1), 1, None)
        grid.check_laws(mech, plan.times)        # the actuators' values at t = 0
    else:
        plan = grid.plan(mech, settings.t_end, settings.steps, len(columns))
    levels = {available[c].level for c in columns} | {POSITION}
    if FORCE in levels and ACCELERATION in kind.levels:
        levels.add(ACCELERATION)                 # the inertia forces need qdd
    if ACCELERATION in levels:
        levels.add(VELOCITY)
    engine = engine or registry.BACKENDS[settings.backend].create()
    job = Job(mech, kind, plan.times, columns, {c: available[c].unit for c in columns},
              levels, engine, solver if solver is not None else engine.Settings(),
              every=plan.every, motion=plan.motion,
              options={o: getattr(settings, o) for o in registry.OPTIONS})
    if plan.every > 1:
        job.info["substeps"] = plan.every
    return job


def check_mobility(job: Job, q0: np.ndarray, need_driven: bool | None = None) -> rank.Mobility:
    """Rank test at the initial guess, before the backend is called (``warn_redundant``
    follows once positions are solved); ``need_driven`` (default: what the analysis
    declares, ``AnalysisType.driven``) raises MobilityError for a DOF not driven."""
    if need_driven is None:
        need_driven = job.analysis_type.driven
    t0 = float(job.times[0])
    eq = rank.at_guess(job.mech, t0, q0)          # evaluated once for both
    rank.require_defined(job.mech, t0, q0, eq)
    mob = rank.mobility(job.mech, t0, q0, jacobian=eq.jacobian[0])
    job.info.update(dof=mob.dof, redundant_equations=mob.redundant,
                    condition_number=mob.condition)
    if need_driven:
        rank.require_driven(job.mech, mob, job.analysis_type.name)
    return mob


def warn_redundant(job: Job, q: np.ndarray) -> None:
    """Warn once about redundant constraints, naming the elements of the self-stress found
    at the first solved configuration (where the rank test is exact)."""
    mob = rank.mobility(job.mech, float(job.times[0]), q)
    if not mob.redundant or mob.dof:
        return
    names = ", ".join(f"'{n}'" for n in mob.redundant_elements)
    text = (f"{mob.redundant} redundant constraint equation(s) among {names}: positions, "
            f"velocities and accelerations are unique, the reactions of these elements "
            f"are not (they are given as the minimum-norm solution)")
    warn(job, text, RedundancyWarning)


def warn_input(job: Job) -> None:
    """Warn of the model's likely mistakes that still run (``InputWarning``): what
    ``model.mistakes.input_warnings`` lists and ``pam2exu check`` prints."""
    source = job.mech.model.source
    for problem in input_warnings(job.mech.model):
        warn(job, f"{source}: {problem}" if source else str(problem), InputWarning)


def warn(job: Job, text: str, category) -> None:
    """Keep a warning with the results and issue it at the caller's line outside pam2exu."""
    job.warnings.append(text)
    warn_outside(text, category)


def collect(job: Job, q, qd=None, qdd=None, extra: dict | None = None) -> Results:
    """The Results table of the chosen columns, on the user's times (rows of the solve grid).

    The last guard of every analysis: a value that is not finite is a SolverError naming
    the columns and the first time, never a result.
    """
    job.stage = "collecting the result columns"
    mech, rows = job.mech, slice(None, None, job.every)
    t = job.times[rows]
    q, qd, qdd = (None if a is None else a[rows] for a in (q, qd, qdd))
    extra = {k: v[rows] for k, v in (extra or {}).items()}
    values, notes = column_values(job, t, q, qd, qdd, extra)
    if notes:
        job.info["undefined"] = "; ".join(notes)
    data = np.empty((1 + len(job.columns), len(t)))
    data[0] = t
    for row, c in zip(data[1:], job.columns):
        _plus_zero(values[c], row)       # no negative zeros in tables
    res = Results._on(job.columns, data, job.units, job.analysis_type, mech.name,
                      job.warnings, job.info, job.backend.label)
    table = data[1:].T                   # a view of the table's storage: no copies
    wanted = set(job.columns)
    if not (np.isfinite(table).all() and _finite([v for k, v in values.items()
                                                  if k not in wanted])):
        # an instantaneous centre is NaN by definition where the solid translates
        check_finite(job, t, {k: v for k, v in values.items()
                              if k.rpartition(".")[2] not in ("ICx", "ICy")})
    return res


def _plus_zero(values, row: np.ndarray) -> None:
    """row = values + 0.0 (−0.0 becomes 0.0), in the copy into the table; the bits of
    copying first and adding 0.0 after (a column that is not float64 is copied first)."""
    if isinstance(values, np.ndarray) and values.dtype == np.float64:
        np.add(values, 0.0, out=row)
    else:
        row[...] = values
        np.add(row, 0.0, out=row)


def _finite(arrays: list) -> bool:
    """Every value of every array is finite (one test of them joined when all are 1-D)."""
    if all(isinstance(a, np.ndarray) and a.ndim == 1 for a in arrays):
        return bool(np.isfinite(np.concatenate(arrays)).all()) if arrays else True
    return all(np.isfinite(a).all() for a in arrays)


def column_values(job: Job, t, q, qd=None, qdd=None, extra: dict | None = None):
    """(column → values at the rows given, one note per solid whose centre is undefined
    somewhere): every column of ``job.columns`` (and the derived ones computed with them)
    from the solids' coordinates and rates and the analysis' own columns ``extra``.
    Complex in, complex out: the complex step of ``sensitivity``."""
    mech, wanted = job.mech, set(job.columns)
    extra = extra or {}
    values: dict[str, np.ndarray] = {}
    for i, s in enumerate(mech.solids):
        for k, var in enumerate(SOLID_OUTPUTS):
            name = f"{s.name}.{var.name}"
            if name in wanted:
                source = (q, qd, qdd)[k // 3]
                values[name] = source[:, column(i, k % 3)]
    st = None
    for el in mech.elements:
        names = {v.name for v in el.outputs
                 if (c := f"{el.name}.{v.name}") in wanted and c not in extra}
        if names:                           # (the analysis' own columns replace these)
            if st is None:
                st = State(t, q, qd if VELOCITY in job.levels else None)
            for var, v in el.compute(st, names).items():
                if var in names:
                    values[f"{el.name}.{var}"] = v
    derived, notes = points.columns(mech, t, q, qd, qdd, wanted)
    values.update(derived)
    values.update(extra)
    return values, notes


def check_finite(job: Job, t: np.ndarray, values: dict[str, np.ndarray]) -> None:
    """SolverError when a column has a value that is not finite (NaN, ±inf)."""
    bad = {name: np.nonzero(~np.isfinite(v))[0] for name, v in values.items()}
    bad = {name: rows for name, rows in bad.items() if rows.size}
    if not bad:
        return
    k = min(int(rows[0]) for rows in bad.values())
    names = [name for name, rows in bad.items() if rows[0] == k]
    shown = ", ".join(names[:8]) + (f" and {len(names) - 8} more" if len(names) > 8 else "")
    raise SolverError(
        f"the {job.analysis_type.name} analysis gave values that are not numbers (NaN or "
        f"infinite) first at t = {t[k]:.6g} s (row {k}), in {shown}"
        + (f"; {len(bad)} columns in all" if len(bad) > len(names) else "")
        + ". The mechanism is at or near a position where these are not defined (a "
          "singular position, two points of an element that coincide): end the interval "
          "before this time, or change the model so it avoids that position.",
        time=float(t[k]), step=k)

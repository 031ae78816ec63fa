"""Verify a model with two formulations (``pam2exu verify``): the same analysis run on two
backends, compared variable by variable within a tolerance the runs themselves justify.

The tolerance of a variable (``Rule``; the user guide is docs/verify.md):

    allowed = rtol_p · S_u,    rtol_p = max(FLOOR, SAFETY · tol · κ^p)

tol is the larger of the two backends' Newton tolerances (relative to the mechanism's length
scale L), κ the worst condition number of the constraint Jacobian over both runs, p = 1 for
positions and 2 for velocities, accelerations and forces (a position error δ makes rates and
forces err by about κ·δ: ``analyses.branch`` warns with κ²·tol). S_u is the scale of the
variable's unit: L for lengths and 1 for angles (Newton's tolerance is absolute); for the
other units the largest value of its family in either run (m/s with rad/s × L, N with
N·m / L, …), accelerations at least ω²·L (ω the largest angular velocity; rad/s² ≥ ω²).

A ``dynamic`` run is two time integrations, each within its tolerance T
(``[analysis] tolerance``) of the exact motion per unit of value: their difference is
allowed, besides, INTEGRATION · T · (1 + S), S the column's own scale for positions and
rates (the promise is per coordinate and rate) and its unit's S_u for accelerations and
forces (computed from them by the equations of motion: an error there is a share of the
largest values of its kind, as in the rest of the rule).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from .errors import ModelError, SolverError, TranslationError, closest
from .model import Model, load
from .registry import BACKENDS, DEFAULT_BACKEND, SECOND_FORMULATION
from .results.compare import compare
from .results.comparison import Comparison
from .results.names import listing
from .results.table import Results

#: the backends compared by default: the default one, and the one it is verified against
BACKENDS_COMPARED = (DEFAULT_BACKEND, SECOND_FORMULATION)
#: margin over the estimated error, and the smallest relative tolerance
SAFETY, FLOOR = 100.0, 1e-10
#: unit → (family, power of the length scale L in it)
UNITS = {"m": ("position", 1), "rad": ("position", 0), "m/s": ("velocity", 1),
         "rad/s": ("velocity", 0), "m/s²": ("acceleration", 1), "rad/s²": ("acceleration", 0),
         "N": ("force", 0), "N·m": ("force", 1)}
#: power of κ in each family's relative tolerance
POWERS = {"position": 1, "velocity": 2, "acceleration": 2, "force": 2}
#: condition numbers are computed at most at this many rows of each run
SAMPLES = 400
#: a dynamic run: the margin over the two integrations' tolerance T (each within T)
INTEGRATION = 10.0


@dataclass(frozen=True)
class Rule:
    """The tolerance of a verification: a variable of unit u agrees when its largest
    difference is at most rtol_p · S_u, rtol_p = max(FLOOR, SAFETY · max(tolerances) · κ^p),
    p = 1 for positions and 2 for the rest; S_u = L for m, 1 for rad, else the family's
    scale times L^k (docs/verify.md). A dynamic run allows at least INTEGRATION · T ·
    (1 + S), T its integration tolerance, S the variable's scale for positions and rates
    and S_u for accelerations and forces.

    Attributes
    ----------
    tolerances : dict
        Backend name → its Newton tolerance, relative to the length scale [–].
    condition : float
        κ, the worst condition number of the constraint Jacobian over both runs [–].
    length : float
        L, the mechanism's length scale (``Mechanism.scale``) [m].
    scales : dict
        Family (``position``, ``velocity``, …) → its scale per unit of L^k [SI unit / m^k]:
        1 for positions, else the largest |value| of the family in either run.
    integration : float
        T, the integration tolerance of a ``dynamic`` run (0 for the other analyses) [–].
    """

    tolerances: dict
    condition: float
    length: float
    scales: dict
    integration: float = 0.0

    def rtol(self, family: str) -> float:
        """The relative tolerance of a family: max(FLOOR, SAFETY · max(tolerances) · κ^p).

        Parameters
        ----------
        family : str
            ``position`` (p = 1), ``velocity``, ``acceleration`` or ``force`` (p = 2).

        Returns
        -------
        float
            rtol_p [–].
        """
        tol = max(self.tolerances.values())
        return max(FLOOR, SAFETY * tol * self.condition ** POWERS[family])

    def scale(self, unit: str) -> float:
        """S_u, the scale of a unit: its family's scale times L^k.

        Parameters
        ----------
        unit : str
            An SI unit of ``UNITS`` (``m``, ``rad``, ``m/s``, …, ``N·m``).

        Returns
        -------
        float
            S_u [unit]: L for m, 1 for rad; nan for a unit the rule does not know.
        """
        if unit not in UNITS:
            return math.nan
        family, k = UNITS[unit]
        return self.scales.get(family, 0.0) * self.length ** k

    def allowed(self, unit: str, scale: float) -> float:
        """The largest difference allowed for a variable: rtol_p · S_u.

        Parameters
        ----------
        unit : str
            The variable's SI unit.
        scale : float
            Its largest |value| [unit]; used only for a unit the rule does not know
            (rtol of p = 2 times ``scale``).

        Returns
        -------
        float
            The tolerance [unit].
        """
        if unit not in UNITS:
            static = self.rtol("force") * scale
        else:
            static = self.rtol(UNITS[unit][0]) * self.scale(unit)
        if not self.integration:
            return static
        family = UNITS.get(unit, ("force", 0))[0]
        size = scale if family in ("position", "velocity") else self.scale(unit)
        return max(static, INTEGRATION * self.integration * (1.0 + size))

    def lines(self) -> list[str]:
        """The rule's numbers, one line each, for the header of the table.

        Returns
        -------
        list of str
            The solver tolerances, L and κ; rtol per family; S per unit.
        """
        tols = ", ".join(f"{name} {tol:g}" for name, tol in self.tolerances.items())
        families = ", ".join(f"{f} {self.rtol(f):.2g}" for f in POWERS)
        units = ", ".join(f"{u} {self.scale(u):.3g}" for u in UNITS
                          if self.scales.get(UNITS[u][0]))
        dynamic = [f"two time integrations, each within T = {self.integration:g} per unit of "
                   f"value: at least {INTEGRATION:g} · T · (1 + S), S the variable's own "
                   "scale for positions and rates, its unit's for accelerations and forces"
                   ] if self.integration else []
        return [f"solver tolerances (relative to L = {self.length:g} m): {tols}; worst "
                f"condition number κ = {self.condition:.3g}",
                f"rtol = max({FLOOR:g}, {SAFETY:g} · {max(self.tolerances.values()):g} · κ^p), "
                f"p = 1 for positions, 2 otherwise: {families}",
                f"a variable agrees when max |difference| ≤ rtol · S, S the scale of its unit: "
                f"{units}", *dynamic]


@dataclass
class Verification:
    """What ``verify`` returns: the two runs, the rule and the comparison table.

    ``str(verification)`` is ``to_markdown()``: the backends, the rule's numbers and the
    comparison table (``Comparison.to_markdown``), ending with the verdict.

    Attributes
    ----------
    backends : tuple of str
        (reference, result): the backend whose run is the reference, and the other.
    reference, result : Results
        The runs of the two backends.
    rule : Rule
        The tolerance applied.
    comparison : Comparison
        One row per variable: the largest difference, the time where it occurs, the
        tolerance and the verdict.
    """

    backends: tuple
    reference: Results
    result: Results
    rule: Rule
    comparison: Comparison

    @property
    def ok(self) -> bool:
        """Every variable agrees, and both runs have the same columns."""
        c = self.comparison
        return c.passed and not c.only_in_result and not c.only_in_reference

    @property
    def differing(self) -> list[str]:
        """The variables that differ beyond their tolerance (and those of one run only)."""
        c = self.comparison
        return c.failed + c.only_in_result + c.only_in_reference

    def verdict(self) -> str:
        """One line: whether the backends agree, naming the variables that differ.

        Returns
        -------
        str
            ``AGREE: … agree on all n variables within the tolerance`` or ``DISAGREE: …
            differ on k of n variables: …`` (at most 20 names).
        """
        ref, res = self.backends
        n = len(self.comparison.rows)
        if self.ok:
            return f"AGREE: {res} and {ref} agree on all {n} variables within the tolerance"
        return (f"DISAGREE: {res} and {ref} differ on {len(self.differing)} of {n} variables: "
                + listing(self.differing, 20))

    def to_markdown(self) -> str:
        """The backends, the rule's numbers, the comparison table and the verdict.

        What ``pam2exu verify`` prints.

        Returns
        -------
        str
            Markdown text.
        """
        ref, res = self.backends
        head = [f"verify: the {self.reference.analysis} analysis of '{self.reference.model}' "
                f"on two backends, {res} (result) against {ref} (reference)",
                *self.rule.lines()]
        return "\n".join([*(f"- {h}" for h in head), self.comparison.to_markdown(),
                          "", self.verdict()])

    def __str__(self) -> str:
        return self.to_markdown()


def verify(model, analysis=None, steps=None, t_end=None, backends=BACKENDS_COMPARED,
           outputs=None, solvers=None, tolerance=None) -> Verification:
    """Run one analysis of a model on two backends and compare them variable by variable.

    The first backend's run is the reference. A variable agrees when its largest difference
    is within rtol_p · S_u (``Rule``; the user guide is docs/verify.md), from the backends'
    tolerances and the worst condition number of the two runs. Angles are compared as they
    are (both runs give them continuous): a difference of 2π is a disagreement.

    Parameters
    ----------
    model : Model, str or Path
        A model, or the path of a model file.
    analysis : str, optional
        The analysis (default: the model's).
    steps : int, optional
        Number of intervals (default: the model's).
    t_end : float, optional
        End of the interval [s] (default: the model's).
    backends : (str, str)
        The reference backend and the one verified against it (``registry.BACKENDS``).
    outputs : list of str, optional
        Names or patterns of the columns to compare (default: every column).
    solvers : dict, optional
        Backend name → its settings (``Settings`` of the backend); default: its defaults.
    tolerance : float, optional
        The integration tolerance of a ``dynamic`` analysis (default: the model's), per unit
        of value [-]; the rule then allows ``INTEGRATION`` · tolerance · (1 + S).

    Returns
    -------
    Verification
        ``.ok``, ``.differing``, ``.comparison``, ``.rule``; prints as the table.

    Raises
    ------
    ModelError
        The model or a setting has problems, or a backend is unknown.
    SolverError, TranslationError
        A backend's run failed (the message starts with the backend's name).

    Examples
    --------
    >>> import pam2exu
    >>> v = pam2exu.verify("examples/four_bar.toml", steps=20)
    >>> v.ok, v.rule.rtol("position"), v.comparison["rocker.fi"].max_abs_error < 1e-12
    (True, 1e-10, True)
    >>> print(v.verdict())
    AGREE: natural and exudyn agree on all 38 variables within the tolerance
    """
    backends = tuple(backends)
    unknown = [b for b in backends if b not in BACKENDS]
    if len(backends) != 2 or unknown:
        raise ModelError(f"verify needs two backends among {', '.join(BACKENDS)}, not "
                         f"{backends!r}" + (closest(unknown[0], BACKENDS) if unknown else ""))
    if not isinstance(model, Model):
        model = load(model)
    solvers = {b: (solvers or {}).get(b) or BACKENDS[b].create().Settings() for b in backends}
    settings = dict(analysis=analysis, steps=steps, t_end=t_end, outputs=outputs,
                    tolerance=tolerance)
    runs = [_run(model, b, solvers[b], **settings) for b in backends]
    mech = model.mechanism()
    if _other_branch(runs, mech):
        # a guess between two assembly branches (fuzz seed 106649: a four-bar's guess moved
        # by up to 1): the backends' Newton iterations may land on different ones, which
        # says nothing of the formulations; the second starts from the first's assembly
        runs[1] = _run(_started_from(model, runs[0]), backends[1], solvers[backends[1]],
                       **settings)
        runs[1].warnings.append(
            f"{backends[0]} and {backends[1]} assembled different branches from the model's "
            f"guess; {backends[1]} was run again from {backends[0]}'s assembly (give a guess "
            f"nearer the configuration you mean)")
    dynamic = runs[0].info.get("integration_error") is not None
    rule = Rule({b: float(solvers[b].tolerance) for b in backends},
                max(_condition(mech, r) for r in runs), mech.scale(), _scales(runs, mech.scale()),
                float(tolerance if tolerance is not None else model.analysis.tolerance)
                if dynamic else 0.0)
    return Verification(backends, runs[0], runs[1], rule, agreement(runs[1], runs[0], rule,
                                                                     backends))


def agreement(result: Results, reference: Results, rule: Rule, backends) -> Comparison:
    """``compare``'s table of two runs, each variable held to ``rule.allowed``.

    Parameters
    ----------
    result, reference : Results
        The runs compared (the same times).
    rule : Rule
        The tolerance.
    backends : (str, str)
        The names of the reference's and the result's backends, for the table's header.

    Returns
    -------
    Comparison
        Its ``tolerance`` and ``passed`` per row from the rule; ``rule`` says so.
    """
    table = compare(result, reference, rtol=0.0, atol=0.0)
    rows = []
    for row in table.rows:
        allowed = rule.allowed(row.unit, row.scale)
        rows.append(replace(row, tolerance=allowed, passed=bool(row.max_abs_error <= allowed)))
    ref, res = backends
    return replace(table, rows=rows, rtol=math.nan, atol=math.nan,
                   result=f"{res} backend: {table.result}",
                   reference=f"{ref} backend: {table.reference}",
                   rule="rule: a variable passes when max |result − reference| ≤ its "
                        "tolerance, rtol · S of its unit (above)")


def _run(model, backend: str, solver, **settings) -> Results:
    """One run; a solver failure or a failed self-check names the backend."""
    from .analyses import run
    try:
        # in SI radians, whatever the model's angles: the tolerances are per SI unit
        return run(model, backend=backend, solver=solver, angles="rad", **settings)
    except (SolverError, TranslationError) as exc:
        exc.args = (f"{backend} backend: {exc.args[0]}", *exc.args[1:])
        raise


def _other_branch(runs, mech) -> bool:
    """Whether the two runs start on different assembly branches: a solid's x, y or fi at
    the first row differs by more than 1e-6 of the mechanism's size (or 1e-6 rad)."""
    size = mech.scale()
    for s in mech.solids:
        for v, unit in (("x", size), ("y", size), ("fi", 1.0)):
            name = f"{s.name}.{v}"
            if name in runs[0].columns and name in runs[1].columns and \
                    abs(runs[0][name][0] - runs[1][name][0]) > 1e-6 * unit:
                return True
    return False


def _started_from(model: Model, res: Results) -> Model:
    """A copy of ``model`` whose solids' guesses are the first row of ``res`` (in SI
    radians), in the model's angle unit."""
    import copy
    import math
    moved = copy.deepcopy(model)
    for s in moved.solids:
        s.x, s.y = float(res[f"{s.name}.x"][0]), float(res[f"{s.name}.y"][0])
        fi = float(res[f"{s.name}.fi"][0])
        s.fi = math.degrees(fi) if moved.angles == "deg" else fi
    return moved


def _condition(mech, res: Results) -> float:
    """The worst finite condition number of a run: those it reports, and those at (at most
    SAMPLES of) its rows when it has the positions of every solid."""
    values = [res.info.get("max_condition_number"), res.info.get("condition_number")]
    if mech.n_equations and all(n in res.columns for n in mech.coordinate_columns()):
        from .analyses.rank import condition_numbers
        rows = np.unique(np.linspace(0, len(res) - 1, min(len(res), SAMPLES)).astype(int))
        values += list(condition_numbers(mech, res.t[rows], mech.coordinates(res, rows=rows)))
    finite = [float(v) for v in values if v is not None and np.isfinite(v)]
    return max(finite, default=1.0)


def _scales(runs, length: float) -> dict:
    """Family → scale per unit of L^k: 1 for positions, else the largest |value| of the
    family's columns in either run (each divided by L^k); accelerations at least the
    velocities' squared (ω²·L: a uniform rotation has no angular acceleration)."""
    scales = {"position": 1.0}
    for res in runs:
        for name in res.columns:
            family, k = UNITS.get(res.units.get(name, ""), ("", 0))
            values = np.abs(res[name][np.isfinite(res[name])])
            if family and family != "position" and values.size:
                scales[family] = max(scales.get(family, 0.0), float(values.max()) / length ** k)
    if "acceleration" in scales:
        scales["acceleration"] = max(scales["acceleration"], scales.get("velocity", 0.0) ** 2)
    return scales

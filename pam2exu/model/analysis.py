"""The analysis settings of a model: the ``[analysis]`` table of a file, ``Model.analysis`` in
Python, and what is wrong with them."""
from __future__ import annotations

from dataclasses import dataclass

from .. import limits, registry
from ..errors import closest, echo
from ..limits import is_number as _number

@dataclass
@registry.with_options
class Analysis:
    """What to run: ``type``, the interval [0, ``t_end``] in ``steps`` intervals, ``outputs``.

    The ``[analysis]`` table of a model file, ``Model.analysis`` in Python: the defaults of
    ``run``, whose arguments override them for one run. Values are checked by
    ``problems`` (called by ``Model.problems`` and by ``run``), not here. Besides the
    parameters of every analysis, it has one attribute per analysis option
    (``pam2exu.registry.OPTIONS``: its declaration gives the default and the check).

    Parameters
    ----------
    type : str
        The name of an analysis of ``pam2exu.registry.ANALYSES`` (``'assembly'``,
        ``'quasi_static'``, ``'kinematic'``, ``'kinetostatic'``, …); its Catalan alias
        (PAM's ``'ensamblatge'``, ``'cinematica'``, …) is read as it.
    t_end : float
        End of the interval [0, t_end] [s], > 0 (not used by an assembly, which solves
        t = 0 only).
    steps : int
        Number of intervals, ≥ 1: results have steps + 1 rows at t_k = k t_end / steps.
    outputs : list of str, optional
        Names or patterns of the columns to compute and keep (``crank.fi``, ``crank.*``,
        ``*.Fx`` or a bare ``Fx``); None keeps every column of the analysis.
    backend : str
        What solves the positions: ``'exudyn'`` (the default; ``pam2exu.registry.BACKENDS``
        lists the backends).

    Examples
    --------
    >>> Analysis("kinematic", t_end=0.0, steps=10).problems()
    ['t_end must be a positive number of seconds, got 0.0']
    """

    type: str = "kinematic"
    t_end: float = 1.0
    steps: int = 100
    outputs: list[str] | None = None
    backend: str = registry.DEFAULT_BACKEND

    #: keys beyond the contract's [analysis] table (docs/model-format.md says so)
    EXTENSIONS = ("backend", *registry.OPTIONS)

    def __post_init__(self):
        self._canonical_type()

    def _canonical_type(self) -> None:
        """A Catalan analysis name becomes the contract's."""
        kind = registry.analysis_type(self.type) if isinstance(self.type, str) else None
        if kind is not None:
            self.type = kind.name

    def problems(self) -> list[str]:
        """What is wrong with these settings, one message each (empty when they are sound).

        Returns
        -------
        list of str
            Messages without a place (``Model.problems`` puts them under
            ``"[analysis]"``).
        """
        out = []
        self._canonical_type()
        if not isinstance(self.type, str) or self.type not in registry.ANALYSES:
            names = list(registry.ANALYSES)
            aliases = [a.alias for a in registry.ANALYSES.values()]
            out.append(f"unknown analysis type {echo(self.type)}"
                       f"{closest(str(self.type), names + aliases)}; known types: "
                       f"{', '.join(names)} (Catalan: {', '.join(aliases)})")
        if not isinstance(self.backend, str) or self.backend not in registry.BACKENDS:
            names = list(registry.BACKENDS)
            out.append(f"unknown backend {echo(self.backend)}{closest(str(self.backend), names)}; "
                       f"known backends: {', '.join(names)}")
        low, high = limits.T_END
        if not _number(self.t_end) or self.t_end <= 0:
            out.append(f"t_end must be a positive number of seconds, got {echo(self.t_end)}")
        elif not low <= self.t_end <= high:
            out.append(f"t_end = {self.t_end:g} s is out of range: it must lie between "
                       f"{low:g} s and {high:g} s")
        if isinstance(self.steps, bool) or not isinstance(self.steps, int) or self.steps < 1:
            out.append(f"steps must be a positive whole number, got {echo(self.steps)}")
        elif self.steps > limits.SOLVE_STEPS:
            out.append(f"steps = {self.steps} is more than pam2exu runs: one run solves the "
                       f"positions at most {limits.SOLVE_STEPS:,} times, once a step at least. "
                       "Use fewer steps (every row is exact, whatever the step), or split "
                       "the interval into several runs, each over a shorter t_end")
        if self.outputs is not None and (
                not isinstance(self.outputs, (list, tuple))
                or not all(isinstance(o, str) for o in self.outputs)):

            out.append("outputs must be a list of names or patterns, e.g. [\"crank.*\", \"Fx\"]")
        out += [p for o in registry.OPTIONS.values() if (p := o.problem(getattr(self, o.name)))]
        return out

"""Dimension variations (``[[variation]]``, shared/spec/clearance.md): a point's or a line's
local dimensions u moving away from their nominal u0 along a ramped cosine, the path u(t) the
clearance analysis follows, on top of a fixed deviation δ (``fixed_dx``, ``fixed_dy``,
``fixed_dangle``: the part as made, an extension of the contract) that the analysis reaches
at t = 0 along the straight path u0 + s δ, s from 0 to 1. The other analyses ignore them
(nominal dimensions)."""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import limits
from ..errors import closest, echo
from ..limits import is_number
from .solid import LineRef, PointRef, Scope, _table

#: the keys of a [[variation]] table, in the contract's order
KEYS = ("anchor", "dx", "dy", "dangle", "w", "wx", "wy", "wangle", "tau", "fixed_dx",
        "fixed_dy", "fixed_dangle")
#: the varied components, in the order of ``Variation.offsets``' columns: (name, Δ key,
#: ω key, range, unit, δ key)
COMPONENTS = (("x", "dx", "wx", limits.LENGTH, "m", "fixed_dx"),
              ("y", "dy", "wy", limits.LENGTH, "m", "fixed_dy"),
              ("angle", "dangle", "wangle", limits.ANGLE, "rad", "fixed_dangle"))
#: the most a variation's cos(ω t) may advance between two output rows, ω t_end/steps [rad]:
#: at π the rows sample each period twice (the Nyquist limit); beyond it they alias the
#: variation into a slower false one, and following it between rows is work for nothing
PHASE_PER_STEP = math.pi


def ramped_cosine(t, delta: float, omega: float, tau: float) -> tuple[np.ndarray, np.ndarray]:
    """u(t) − u0 = (1 − e^(−t/τ)) (Δ/2) cos(ω t), and its time derivative u'(t).

    Parameters
    ----------
    t : float or array_like
        Times [s], ≥ 0.
    delta : float
        Δ, the full range of the component [m or rad]; may be negative.
    omega : float
        ω [rad/s].
    tau : float
        τ, the time constant of the ramp [s], > 0.

    Returns
    -------
    u : numpy.ndarray
        u(t) − u0, the shape of ``t`` (0 at t = 0).
    du : numpy.ndarray
        u'(t) = (Δ/2) [e^(−t/τ)/τ cos(ω t) − (1 − e^(−t/τ)) ω sin(ω t)], the shape of ``t``.

    Examples
    --------
    >>> u, du = ramped_cosine([0.0, 1.0], delta=2.0, omega=0.0, tau=1.0)
    >>> [round(float(v), 12) for v in u], [round(float(v), 12) for v in du]
    ([0.0, 0.632120558829], [1.0, 0.367879441171])
    """
    t = np.asarray(t, dtype=float)
    decay = np.exp(-t / tau)
    ramp = -np.expm1(-t / tau)                  # 1 − e^(−t/τ), exact for small t/τ
    cos, sin = np.cos(omega * t), np.sin(omega * t)
    half = 0.5 * delta
    return ramp * half * cos, half * (decay / tau * cos - ramp * omega * sin)


@dataclass(eq=False)
class Variation:
    """One ``[[variation]]``: a declared point or line whose local dimensions vary with time.

    Each component (the point's local x and y, or the line's defining point and angle)
    follows u(t) = u0 + δ + (1 − e^(−t/τ)) (Δ/2) cos(ω t) (``ramped_cosine``), wherever
    the point or line is an anchor; the clearance analysis reaches the fixed deviation δ
    at t = 0 along the straight path u0 + s δ, s from 0 to 1 (``offsets(t, reached=s)``). Only the clearance analysis reads it. Usually made by
    ``Model.add_variation`` or a ``[[variation]]`` table; values are checked by
    ``Model.problems``, not here.

    Parameters
    ----------
    anchor : str
        ``"solid.point"`` or ``"solid.line"``: a declared point or line (not a bare solid).
    dx, dy : float
        Δ of the point's local coordinates (of a line's defining point), in the solid's
        frame [m].
    dangle : float
        Δ of a line's angle [rad] (lines only).
    w : float
        ω of every component [rad/s].
    wx, wy, wangle : float, optional
        ω of one component [rad/s]; None: ``w``.
    tau : float
        τ, the time constant of the ramp [s], > 0.
    fixed_dx, fixed_dy : float
        δ, the fixed deviation of the point's local coordinates (of a line's defining
        point) as made [m].
    fixed_dangle : float
        δ of a line's angle as made [rad] (lines only).
    position : int, optional
        1-based position in the model file's ``[[variation]]`` array, for messages (set
        by the loader, or by ``Model.add_variation``).

    Attributes
    ----------
    kind : str
        ``'point'`` or ``'line'`` (set by ``bind``, in ``Mechanism.variations``).
    ref : PointRef or LineRef
        The varied point or line with its nominal u0 (set by ``bind``).

    Examples
    --------
    >>> v = Variation("ground.O2", dx=3.7e-4, wx=1.91)
    >>> v.omega("x"), v.omega("y")
    (1.91, 1.0)
    """

    anchor: str | None = None
    dx: float = 0.0
    dy: float = 0.0
    dangle: float = 0.0
    w: float = 1.0
    wx: float | None = None
    wy: float | None = None
    wangle: float | None = None
    tau: float = 1.0
    fixed_dx: float = 0.0
    fixed_dy: float = 0.0
    fixed_dangle: float = 0.0
    #: 1-based position in the file's [[variation]] array (set by the loader or the model)
    position: int | None = field(default=None, repr=False, kw_only=True)

    def __post_init__(self):
        """Its anchor in one Unicode form (``limits.one_form``), as the solids' names."""
        self.anchor = limits.one_form(self.anchor)

    @property
    def where(self) -> str:
        """Where it is in the model: ``"[[variation]] #2 (anchor 'crank.A')"``."""
        at = f" #{self.position}" if self.position else ""
        anchor = f" (anchor {echo(self.anchor, 40)})" if self.anchor is not None else ""
        return f"[[variation]]{at}{anchor}"

    def omega(self, component: str) -> float:
        """ω of one component: its own ``wx``, ``wy`` or ``wangle``, else ``w``.

        Parameters
        ----------
        component : str
            ``'x'``, ``'y'`` or ``'angle'``.

        Returns
        -------
        float
            ω [rad/s].
        """
        own = getattr(self, "w" + component)
        return float(self.w if own is None else own)

    @property
    def fixed(self) -> np.ndarray:
        """δ: the fixed deviations of x [m], y [m] and the angle [rad] (0 for a point)."""
        return np.array([float(getattr(self, c[5])) for c in COMPONENTS])

    @property
    def has_fixed(self) -> bool:
        """Some component has a fixed deviation δ ≠ 0."""
        return bool(np.any(self.fixed != 0.0))

    def offsets(self, t, reached: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
        """u(t) − u0 = s δ + (1 − e^(−t/τ)) (Δ/2) cos(ω t) and u'(t) of the components
        x [m], y [m], angle [rad].

        Parameters
        ----------
        t : float or array_like
            Times [s].
        reached : float
            s [–], how far along the straight path u0 + s δ the fixed deviation is: 1 (its
            value) at every time of the motion, 0 … 1 on the path at t = 0.

        Returns
        -------
        u : numpy.ndarray
            Shape (n, 3): u(t) − u0 of the local x, y [m] and the angle [rad] (0 for a
            point), one row per time.
        du : numpy.ndarray
            Shape (n, 3): their time derivatives [m/s, m/s, rad/s].
        """
        t = np.atleast_1d(np.asarray(t, dtype=float))
        pairs = [ramped_cosine(t, float(getattr(self, key)), self.omega(name), float(self.tau))
                 for name, key, *_ in COMPONENTS]
        return (reached * self.fixed + np.stack([u for u, _ in pairs], axis=1),
                np.stack([du for _, du in pairs], axis=1))

    @property
    def nominal(self) -> tuple[float, float, float]:
        """u0 (after ``bind``): local x, y [m] of the point (of a line's defining point)
        and the line's angle [rad] (0 for a point)."""
        if isinstance(self.ref, LineRef):
            return (*self.ref.point, self.ref.angle)
        return (*self.ref.local, 0.0)

    def bind(self, scope: Scope) -> None:
        """Resolve the anchor: set ``kind`` and ``ref`` (``Mechanism`` calls it once the
        model is valid).

        Parameters
        ----------
        scope : Scope
            The model's solids (``pam2exu.model.solid.Scope``).
        """
        self.kind = _kind(scope, self.anchor)
        self.ref: PointRef | LineRef = scope.resolve(self.kind, self.anchor)

    def problems(self, scope: Scope) -> list[str]:
        """Every problem with this entry's values and anchor (empty when it is sound).

        A point or line varied twice is found by ``Model.problems``, which sees every entry.

        Parameters
        ----------
        scope : Scope
            The model's solids (``pam2exu.model.solid.Scope``).

        Returns
        -------
        list of str
            Messages without a place (``Model.problems`` puts them under ``where``).
        """
        out = []
        for key, limit, unit in (("dx", limits.LENGTH, "m"), ("dy", limits.LENGTH, "m"),
                                 ("dangle", limits.ANGLE, "rad"), ("w", limits.VALUE, "rad/s"),
                                 ("fixed_dx", limits.LENGTH, "m"),
                                 ("fixed_dy", limits.LENGTH, "m"),
                                 ("fixed_dangle", limits.ANGLE, "rad"),
                                 ("wx", limits.VALUE, "rad/s"), ("wy", limits.VALUE, "rad/s"),
                                 ("wangle", limits.VALUE, "rad/s")):
            value = getattr(self, key)
            if value is None and key.startswith("w") and key != "w":
                continue
            if not is_number(value):
                out.append(f"'{key}' must be a number [{unit}], got {echo(value)}")
            elif abs(value) > limit:
                out.append(f"'{key}' = {value:g} {unit} is out of range: its magnitude must be "
                           f"at most {limit:g} {unit} (are the units right?)")
        low, high = limits.T_END
        if not is_number(self.tau):
            out.append(f"'tau' must be a number of seconds, got {echo(self.tau)}")
        elif self.tau <= 0:
            out.append(f"'tau' = {self.tau:g} s: the time constant of the ramp must be > 0 "
                       f"(1 s is the slides' law)")
        elif not low <= self.tau <= high:
            out.append(f"'tau' = {self.tau:g} s is out of range: it must lie between {low:g} s "
                       f"and {high:g} s")
        try:
            kind = _kind(scope, self.anchor)
        except LookupError as exc:
            return out + [str(exc)]
        if kind == "point":
            out += [f"'{key}' varies a line's angle, and '{self.anchor}' is a point: remove "
                    f"'{key}', or vary a line" for key in ("dangle", "wangle", "fixed_dangle")
                    if getattr(self, key) not in (None, 0, 0.0)]
        return out


def pace_problems(variations: list[Variation], t_end: float, steps: int) -> \
        list[tuple[str, str]]:
    """(where, message) of every varied component whose ω t_end/steps, the phase its
    cos(ω t) advances between two output rows, exceeds ``PHASE_PER_STEP``."""
    out = []
    for v in variations:
        for name, delta, own, *_ in COMPONENTS:
            omega = abs(v.omega(name))
            if getattr(v, delta) == 0 or omega * t_end / steps <= PHASE_PER_STEP:
                continue
            key = own if getattr(v, own) is not None else "w"
            out.append((v.where, (
                f"'{key}' = {omega:g} rad/s is too fast for the output grid: {delta} turns "
                f"by ω·t_end/steps = {omega * t_end / steps:.3g} rad between two rows "
                f"(t_end = {t_end:g} s, steps = {steps}), and the rows cannot follow more "
                f"than π ({PHASE_PER_STEP:.4g} rad, two rows per period): give steps ≥ "
                f"{math.ceil(omega * t_end / PHASE_PER_STEP)}, a shorter t_end, or '{key}' "
                f"≤ {PHASE_PER_STEP * steps / t_end:.4g} rad/s")))
    return out


def _kind(scope: Scope, anchor) -> str:
    """'point' or 'line': what ``anchor`` ("solid.item") names (LookupError saying what to
    write when it names neither, a bare solid, or both)."""
    if not isinstance(anchor, str):
        raise LookupError(f"'anchor' must be \"solid.point\" or \"solid.line\", got "
                          f"{echo(anchor)}" if anchor is not None else
                          "'anchor' is missing: name the point or line to vary, "
                          "\"solid.point\" or \"solid.line\"")
    name, dot, item = anchor.partition(".")
    if name not in scope.index:
        raise LookupError(f"anchor {echo(anchor)}: no solid '{name}'{closest(name, scope.index)}")
    solid = scope.solids[scope.index[name]]
    points, lines = _table(solid.points), _table(solid.lines)
    declared = ", ".join([*(f"'{name}.{p}'" for p in points),
                          *(f"'{name}.{ln}'" for ln in lines)]) or "none"
    if not dot:
        raise LookupError(f"anchor {echo(anchor)} is a bare solid: a variation changes a declared "
                          f"point or line, name it as \"solid.point\" or \"solid.line\" "
                          f"(the points and lines of '{name}': {declared})")
    if item in points and item in lines:
        raise LookupError(f"anchor {echo(anchor)}: solid '{name}' has a point and a line named "
                          f"'{item}': rename one of them")
    if item not in points and item not in lines:
        raise LookupError(f"anchor {echo(anchor)}: solid '{name}' has no point or line "
                          f"'{item}'{closest(item, [*points, *lines])}; its points and "
                          f"lines: {declared}")
    return "point" if item in points else "line"


def variation_problems(variations: list[Variation], scope: Scope, elements) -> \
        tuple[list[tuple[str, str]], list[tuple[str, str]]]:
    """(problems, warnings) of every variation, each as (where, message), in file order.

    A problem: a bad value or anchor, a point or line varied twice. A warning: a varied
    point or line that no constraint element anchors (the variation has no effect).
    """
    problems, warnings, seen = [], [], {}
    used = _anchored(elements)
    for v in variations:
        found = v.problems(scope)
        problems += [(v.where, m) for m in found]
        if found:
            continue
        key = (_kind(scope, v.anchor), v.anchor)
        if key in seen:
            problems.append((v.where, f"{key[0]} '{v.anchor}' is already varied by "
                                      f"{seen[key]}: put both changes in one entry"))
            continue
        seen[key] = v.where
        if key not in used:
            warnings.append((v.where, f"no constraint element anchors the {key[0]} "
                                      f"'{v.anchor}': the variation has no effect"))
    return problems, warnings


def _anchored(elements) -> set[tuple[str, str]]:
    """(kind, "solid.item") of every point and line a constraint element anchors."""
    return {(kind, anchor) for el in elements if el.equations
            for kind, anchor in zip(el.anchors, el.given_anchors())
            if kind in ("point", "line") and isinstance(anchor, str)}


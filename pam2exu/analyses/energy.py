"""The energy account of a run with rates and forces (``kinetostatic`` or ``dynamic``):
``pam2exu energy MODEL`` and ``pam2exu.energy``.

Kinetic energy T = Σ ½ m v_G² + ½ I_G ω², potential energy V of gravity and the springs,
and, since t = 0, the work W_act of the actuators (∫ Mz·Df or Força·Df), the work W_tor of
the torsors (∫ Q_torsorᵀ q̇) and the energy D the dampers dissipated (∫ C4 rate²), so that

    balance = (T + V) − (T0 + V0) − W_act − W_tor + D

is zero up to the quadrature of the works over the result's rows (cumulative Simpson,
error O(dt⁴) where the motion is smooth; a law breakpoint, where the power jumps, adds
O(dt²) there; a law whose rate jumps, a ramp, moves its actuator by an impulse there, whose
work the rows cannot see: the balance steps by that work). A column per quantity, in J,
as ``energy.<quantity>``.
"""
from __future__ import annotations

import numpy as np

from ..kinematics import State
from ..model import Model, load
from ..results import Results
from . import force_pass

#: the columns, in order, and what each is
QUANTITIES = {
    "kinetic": "T = Σ ½ m v_G² + ½ I_G ω²",
    "potential": "V of gravity and the springs",
    "actuators": "work of the actuators since t = 0",
    "torsors": "work of the torsors since t = 0",
    "dissipated": "energy the dampers dissipated since t = 0",
    "balance": "(T + V) − (T0 + V0) − work of actuators and torsors + dissipated",
}


def energy(model, analysis: str | None = None, **settings) -> Results:
    """The energy account of a kinetostatic or dynamic run of ``model`` (columns
    ``energy.kinetic``, ``.potential``, ``.actuators``, ``.torsors``, ``.dissipated``,
    ``.balance``, in J; the run's warnings and facts kept).

    Parameters
    ----------
    model : Model, str or Path
        A model, or the path of a model file.
    analysis : str, optional
        ``'kinetostatic'`` or ``'dynamic'``; default: the model's, which must be one of
        them.
    **settings
        ``pam2exu.run``'s overrides (``t_end``, ``steps``, ``tolerance``, …).

    Examples
    --------
    >>> account = energy("examples/slider_crank.toml", steps=200)      # doctest: +SKIP
    >>> abs(account["energy.balance"]).max() < 1e-6                     # doctest: +SKIP
    True
    """
    from . import run

    if not isinstance(model, Model):
        model = load(model)
    kind = analysis or model.analysis.type
    require_rates(kind, model.source)
    return account(model, run(model, kind, angles="rad", **settings))


def account(model, res: Results) -> Results:
    """The energy account (``energy``) of a kinetostatic or dynamic result ``res`` of
    ``model`` (in radians or degrees), with every solid's x … DDfi and the actuators'
    forces among its columns (the default outputs)."""
    from ..errors import ModelError
    from ..results.units import in_angles

    res = in_angles(res, "rad")
    if not isinstance(model, Model):
        model = load(model)
    require_rates(res.analysis, model.source)
    mech = model.mechanism()
    wanted = [c for d in ("", "D", "DD") for c in mech.coordinate_columns(d)] + [
        f"{el.name}.{next(w for w in el.wrench if w is not None)}" for el in mech.drivers]
    missing = [c for c in wanted if c not in res]
    if missing:
        raise ModelError(f"the energy account needs every solid's x … DDfi and the actuators' "
                         f"forces, and the result has no {', '.join(missing[:4])}"
                         f"{' …' if len(missing) > 4 else ''}: run without --outputs",
                         model.source)
    q, qd, qdd = (mech.coordinates(res, d) for d in ("", "D", "DD"))
    st = State(res.t, q, qd)
    applied = force_pass.applied_forces(mech, st, damping=True)
    _, kinetic = force_pass.inertia_forces(mech, st, qdd)
    outputs = {c: res[c] for c in res.columns}
    works = {"actuators": force_pass.actuator_power(mech, st, outputs),
             "torsors": np.sum(applied.external * qd, axis=1),
             "dissipated": applied.dissipation}
    columns = {"kinetic": kinetic, "potential": applied.potential}
    columns.update({k: _since_start(res.t, p) for k, p in works.items()})
    total = kinetic + applied.potential
    columns["balance"] = (total - total[0] - columns["actuators"] - columns["torsors"]
                          + columns["dissipated"])
    return Results(res.t, {f"energy.{k}": v for k, v in columns.items()},
                   {f"energy.{k}": "J" for k in columns}, res.analysis, res.model,
                   res.warnings, res.info, res.backend)


def require_rates(kind: str, source) -> None:
    """ModelError unless the analysis named ``kind`` gives what the account needs:
    velocities, accelerations and forces over an interval (``AnalysisType.gives_rates``:
    kinetostatic, dynamic). An unknown name passes: ``run`` says which names there are."""
    from ..errors import ModelError
    from ..registry import ANALYSES, analysis_type

    found = analysis_type(kind)
    if found is not None and not found.gives_rates:
        names = [a.name for a in ANALYSES.values() if a.gives_rates]
        raise ModelError(f"the energy account needs velocities, accelerations and forces: "
                         f"a {' or '.join(names)} run, not {kind!r} "
                         f"({' or '.join('-a ' + n for n in names)})", source)


def _since_start(t: np.ndarray, power: np.ndarray) -> np.ndarray:
    """∫_0^t P: cumulative Simpson over the rows (trapezoid with fewer than 3)."""
    if len(t) < 3:
        return np.r_[0.0, np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(t))]
    from scipy.integrate import cumulative_simpson   # (a run that asks for no energy: not imported)
    return cumulative_simpson(power, x=t, initial=0.0)

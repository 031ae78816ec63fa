"""Vectors drawn on a mechanism (``draw(..., vectors=…)``, ``pam2exu draw --vectors``).

At one instant t: the velocity (``v``) or acceleration (``a``) of every declared point of the
moving solids, from a kinematic run, or the reaction force (``F``) of every joint and
actuator at its point, from a kinetostatic run. Arrows are to scale: the longest is
``LONGEST`` of the mechanism's size, and a legend says what a round length stands for.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..kinematics import State, perp
from ..points import instantaneous_centre, point_motion
from ..results.plot import PictureError

#: the longest arrow, as a fraction of the mechanism's size (the larger side of its box)
LONGEST = 0.15
#: the legend's arrow is about this fraction of the mechanism's size (a round length)
KEY = 0.08
#: what each kind is: analysis, what the legend calls it
KINDS = {
    "v": ("kinematic", "velocity of each point"),
    "a": ("kinematic", "acceleration of each point"),
    "F": ("kinetostatic", "force of each joint and actuator on its solid 2, at its point"),
}


def in_global(components, direction):
    """F = c_x e + c_y Ω e: components (n, 2) in the basis whose x axis is ``direction``."""
    c, e = np.asarray(components, dtype=float), np.asarray(direction, dtype=float)
    return c[..., :1] * e + c[..., 1:] * perp(e)


def round_length(x: float) -> float:
    """The largest 1, 2 or 5 × 10^k not above x > 0."""
    k = math.floor(math.log10(x))
    return max(m * 10.0 ** k for m in (1.0, 2.0, 5.0) if m * 10.0 ** k <= x * (1 + 1e-12))


@dataclass
class Arrows:
    """Vectors to draw: where (n, 2) [m], what (n, 2) [unit], their names, the scale."""

    kind: str
    points: np.ndarray
    values: np.ndarray
    names: list
    unit: str
    #: drawing length per unit of the vectors [m per unit]; 0 when they are all zero
    scale: float = 0.0

    def scaled(self, size: float) -> "Arrows":
        """The scale making the longest arrow ``LONGEST`` × size [m]."""
        longest = float(np.max(np.hypot(*self.values.T))) if len(self.values) else 0.0
        self.scale = LONGEST * size / longest if longest > 0 else 0.0
        return self

    @property
    def tips(self) -> np.ndarray:
        return self.points + self.scale * self.values

    def legend(self, size: float) -> tuple[float, str]:
        """(value the legend's arrow stands for, its text): a round length of the drawing."""
        what = KINDS[self.kind][1]
        if not self.scale:
            return 0.0, f"{self.kind}: {what} (all zero)"
        length = round_length(KEY * size)
        value = length / self.scale
        return value, f"{self.kind}: {what}; arrow of {length:g} m = {value:.3g} {self.unit}"


def _row(model, t: float, analysis: str, outputs):
    """(results, row) of ``analysis`` at time t: the last row of a run over [0, t] with the
    model's step length (as ``pose``), or the first row of a one-step run for t = 0."""
    from ..analyses import run
    a = model.analysis
    if t > 0:
        steps = max(1, math.ceil(a.steps * t / a.t_end - 1e-9))
        res = run(model, analysis=analysis, t_end=float(t), steps=steps, outputs=outputs,
                  angles="rad")
        return res, -1
    res = run(model, analysis=analysis, t_end=a.t_end / a.steps, steps=1, outputs=outputs,
              angles="rad")
    return res, 0


def at_instant(model, t: float, kind: str):
    """(mechanism, q (3·solids,), Arrows) at time t for ``kind`` 'v', 'a' or 'F'.

    Raises
    ------
    PictureError
        ``kind`` is not one of them.
    """
    if kind not in KINDS:
        raise PictureError(f"--vectors is v (velocities), a (accelerations) or F (reaction "
                           f"forces), not {kind!r}")
    mech = model.mechanism()
    if kind == "F":
        return _forces(model, mech, t)
    rates = ("Dx", "Dy", "Dfi") + (("DDx", "DDy", "DDfi") if kind == "a" else ())
    res, k = _row(model, t, KINDS[kind][0], mech.coordinate_columns()
                  + [f"{s.name}.{r}" for s in mech.solids for r in rates])
    q = mech.coordinates(res)[k]
    points, values, names = [], [], []
    for i, s in enumerate(mech.solids):
        if i in mech.held:
            continue
        get = lambda *rs: np.array([[float(res[f"{s.name}.{r}"][k]) for r in rs]])  # noqa: E731
        local = {n: tuple(float(c) for c in p) for n, p in s.points.items()} or {"": (0, 0)}
        for name, p in local.items():
            x, v, a = point_motion(get("x", "y"), get("Dx", "Dy"),
                                   get("DDx", "DDy") if kind == "a" else None,
                                   get("fi")[0], get("Dfi")[0],
                                   get("DDfi")[0] if kind == "a" else None, p)
            points.append(x[0])
            values.append((v if kind == "v" else a)[0])
            names.append(f"{s.name}.{name}" if name else s.name)
    unit = "m/s" if kind == "v" else "m/s²"
    return mech, q, Arrows(kind, np.array(points).reshape(-1, 2),
                           np.array(values).reshape(-1, 2), names, unit)


def _forces(model, mech, t):
    """The reaction of every element with equations and a force in its wrench, at its
    report point (``Element.report_frame``) in the global basis."""
    carriers = [el for el in mech.elements if el.equations and el.wrench
                and (el.wrench[0] or el.wrench[1])]
    wanted = [f"{el.name}.{w}" for el in carriers for w in el.wrench[:2] if w]
    res, k = _row(model, t, KINDS["F"][0], mech.coordinate_columns() + wanted)
    q = mech.coordinates(res)[k]
    st = State([t], q[None, :])
    points, values = [], []
    for el in carriers:
        point, direction = el.report_frame(st)
        c = [float(res[f"{el.name}.{w}"][k]) if w else 0.0 for w in el.wrench[:2]]
        points.append(np.asarray(point, dtype=float)[0])
        values.append(in_global(c, np.asarray(direction, dtype=float)[0]))
    return mech, q, Arrows("F", np.array(points).reshape(-1, 2),
                           np.array(values).reshape(-1, 2), [el.name for el in carriers], "N")


def centres(model, t: float):
    """(mechanism, q, [(solid, I (2,))]) at time t: the instantaneous centre of every solid
    not fixed (``points.instantaneous_centre``, from a kinematic run as for ``v``); a solid
    that translates at t has none (left out)."""
    mech = model.mechanism()
    res, k = _row(model, t, KINDS["v"][0], mech.coordinate_columns()
                  + [f"{s.name}.{r}" for s in mech.solids for r in ("Dx", "Dy", "Dfi")])
    q = mech.coordinates(res)[k]
    out = []
    for i, s in enumerate(mech.solids):
        if i in mech.held:
            continue
        get = lambda *rs: np.array([[float(res[f"{s.name}.{r}"][k]) for r in rs]])  # noqa: E731
        centre = instantaneous_centre(get("x", "y"), get("Dx", "Dy"), get("Dfi")[0],
                                      mech.scale())[0]
        if np.all(np.isfinite(centre)):
            out.append((s.name, centre))
    return mech, q, out

"""The time grid of a run, decided before any numerics: laws, motion per step, work.

``plan(mech, t_end, steps)`` returns the grid positions are solved on. It checks that

- every actuator's law f(t), f'(t), f''(t) is finite and within range over the run, and a
  linear actuator's distance f(t) stays positive (a length of zero has no direction);
- no actuator moves more than ``MAX_ANGLE_STEP`` [rad] or ``MAX_LENGTH_STEP`` × the
  mechanism's length [m] from one position solve to the next: Newton's iteration started
  from the previous configuration then stays on the mechanism's branch. Where the user's
  steps are longer, each is solved in ``every`` equal sub-steps and the results are
  reported on the user's grid (``Plan.output``);
- the run's position solves and memory stay within ``limits.SOLVE_STEPS`` and
  ``limits.MEMORY``: a run that would need more is a ModelError that says how far each
  actuator moves per step and how many steps would do.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import limits
from ..errors import ModelError, Problem

#: the most an angular actuator may turn between two position solves [rad]
MAX_ANGLE_STEP = 0.25
#: the most a linear actuator may move between two position solves [× the length scale]
MAX_LENGTH_STEP = 0.05


@dataclass(frozen=True)
class Plan:
    """The grid positions are solved on, and which of its rows the user asked for.

    times:  the solve grid, t_k = k t_end / (steps · every) [s]
    every:  sub-steps per user step (1: the user's grid itself)
    motion: (actuator name, its motion per user step, unit) of the actuator that moves
            most per step relative to its limit; None without sub-steps
    """

    times: np.ndarray
    every: int
    motion: tuple[str, float, str] | None

    @property
    def output(self) -> slice:
        """The rows of the solve grid that are the user's times."""
        return slice(None, None, self.every)


def driver_unit(el) -> tuple[str, float]:
    """(unit, most motion per solve step) of an actuator: rad, or m for a linear one."""
    return ("rad", MAX_ANGLE_STEP) if el.angular else ("m", MAX_LENGTH_STEP)


def motion_per_step(law, times: np.ndarray, values=None) -> float:
    """max_k max(|f(t_k+1) − f(t_k)|, |f'(t)| Δt): the most the law moves in one step, f'
    taken at the grid's times and inside its transition (C1 … C2, which may fall between
    two of them); ``values``: (f, f', f'') at ``times`` when already evaluated."""
    with np.errstate(all="ignore"):
        f, df, _ = law(times) if values is None else values
        dt = float(times[1] - times[0])
        rate = np.abs(df).max()
        inside = transition_times(law, float(times[0]), float(times[-1]))
        if inside.size:                          # (a law without a transition: none)
            rate = max(rate, np.abs(law(inside)[1]).max())
        return float(max(np.abs(f[1:] - f[:-1]).max(), rate * dt))


def transition_times(law, start: float, end: float, count: int = 17) -> np.ndarray:
    """``count`` equally spaced times of the law's transition C1 … C2 within [start, end]
    (its middle, where a bezier moves fastest, among them); none for a law without one."""
    if not law.breakpoints():
        return np.empty(0)
    c1, c2 = law.breakpoints()
    low, high = max(c1, start), min(c2, end)
    return np.linspace(low, high, count) if low < high else np.empty(0)


def jump(el, dt: float) -> str | None:
    """What to say when the actuator's law moves (C3 → C4) in less than ``dt`` [s], a step of
    the run: its value jumps from one position solve to the next. None otherwise."""
    law = el.time_law()
    if not law.breakpoints():
        return None
    c1, c2, c3, c4 = law.C
    unit, _ = driver_unit(el)
    if c2 - c1 >= dt or c3 == c4:
        return None
    return (f"law '{law.name}' with C = {list(law.C)} goes from C3 = {c3:g} to C4 = {c4:g} "
            f"{unit} in C2 − C1 = {c2 - c1:.3g} s, less than a step of the run ({dt:.3g} s): "
            f"its value jumps. Make the motion last longer (C1 and C2 are the times it starts "
            f"and ends [s]), or check the constants")


def law_values(mech, times: np.ndarray) -> list[tuple]:
    """(law, (f, f', f'') at ``times``) of every actuator (``mech.drivers`` order), evaluated
    once for the checks and the motion per step of a plan."""
    out = []
    with np.errstate(all="ignore"):
        for el in mech.drivers:
            law = el.time_law()
            out.append((law, law(times)))
    return out


def check_laws(mech, times: np.ndarray, ranges: bool = True, evaluated=None) -> None:
    """ModelError unless every law is finite (and, with ``ranges``, within range) at every
    time of the grid; ``evaluated``: ``law_values(mech, times)`` when already evaluated."""
    problems = []
    for el, (law, values) in zip(mech.drivers, evaluated or law_values(mech, times)):
        unit, _ = driver_unit(el)
        limit = limits.LENGTH if unit == "m" else limits.ANGLE
        if _fine(values, limit if ranges else None, ranges and unit == "m"):
            continue                             # (the usual case: nothing to name)
        for order, v in enumerate(values):
            bad = ~np.isfinite(v)
            if order == 0 and ranges:
                bad |= np.abs(v) > limit
            if bad.any():
                k = int(np.argmax(bad))
                name = ("f(t)", "f'(t)", "f''(t)")[order]
                value = f"{v[k]:g}" if np.isfinite(v[k]) else "not finite"
                range_ = f" (at most {limit:g} {unit})" if order == 0 else ""
                problems.append(Problem(el.where, (
                    f"law '{law.name}' with C = {list(law.C)}: {name} is {value} at "
                    f"t = {times[k]:g} s{range_}; check the constants and their units")))
                break
        else:
            if ranges and unit == "m" and np.min(values[0]) <= 0:
                k = int(np.argmax(values[0] <= 0))          # the first time
                problems.append(Problem(el.where, (
                    f"the distance PQ must stay positive, but law '{law.name}' with "
                    f"C = {list(law.C)} gives f(t) = {values[0][k]:g} m at t = {times[k]:g} s: "
                    f"the actuator would have no direction; change the constants")))
    if problems:
        raise ModelError(problems, mech.model.source)


def _fine(values, limit: float | None, positive: bool) -> bool:
    """Whether ``check_laws`` finds nothing in a law's (f, f', f'') at once: all finite,
    |f| ≤ ``limit`` (None: any size) and, when ``positive``, f > 0."""
    f = values[0]
    return bool(np.isfinite(values).all()
                and (limit is None or np.abs(f).max() <= limit)
                and (not positive or f.min() > 0))


def plan(mech, t_end: float, steps: int, columns: int) -> Plan:
    """The solve grid of a run over [0, t_end] in ``steps`` steps (see the module's doc).

    ``columns`` is the number of result columns, for the memory bound. The grid of the same
    laws, interval and steps is made once (``_PLANS``: the variants of a study share it).
    """
    key = _key(mech, t_end, steps)
    made = _PLANS.get(key) if key is not None else None
    if made is None:
        made = _planned(mech, t_end, steps)
        if key is not None:
            if len(_PLANS) >= KEPT_PLANS:
                _PLANS.pop(next(iter(_PLANS)))
            _PLANS[key] = made
    times = made.times
    memory = 8 * (len(times) * (4 * mech.nq + mech.n_equations)
                  + (int(steps) + 1) * (columns + 1))
    if memory > limits.MEMORY:
        raise ModelError(Problem(
            "[analysis]",
            f"this run would hold {memory / 2**30:.3g} GiB of coordinates and results "
            f"({len(times):,} solve steps, {columns} columns), more than pam2exu allows "
            f"({limits.MEMORY / 2**30:g} GiB): use fewer steps, or fewer outputs "
            f"(--outputs)"), mech.model.source)
    return Plan(times.copy(), made.every, made.motion)


#: the plans made (``plan``), by ``_key``: at most KEPT_PLANS, the oldest dropped first
_PLANS: dict = {}
KEPT_PLANS = 32


def _key(mech, t_end, steps) -> tuple | None:
    """What a plan is made of (``_planned``): the interval, the steps, each actuator's
    name, kind and law, the length scale when an actuator is linear, and the limits; None
    when a law's constants are not hashable."""
    drivers = tuple((el.name, el.angular, el.time_law()) for el in mech.drivers)
    key = (float(t_end), int(steps), drivers,
           None if all(angular for _, angular, _ in drivers) else mech.scale(),
           MAX_ANGLE_STEP, MAX_LENGTH_STEP, limits.SOLVE_STEPS, limits.LENGTH, limits.ANGLE)
    try:
        hash(key)
    except TypeError:
        return None
    return key


def _planned(mech, t_end: float, steps: int) -> Plan:
    """``plan`` without its memory bound: the laws checked, the sub-steps, the grid."""
    user = np.linspace(0.0, float(t_end), int(steps) + 1)
    evaluated = law_values(mech, user)       # each law once on the user's grid
    check_laws(mech, user, ranges=False, evaluated=evaluated)  # the motion per step first
    every, worst = 1, None
    for el, (law, values) in zip(mech.drivers, evaluated):
        unit, most = driver_unit(el)
        size = most * (mech.scale() if unit == "m" else 1.0)
        moved = motion_per_step(law, user, values)
        # (a motion of exactly the limit, up to round-off, needs no sub-step)
        needed = math.ceil(moved / size - 1e-9) if math.isfinite(moved) else math.inf
        if needed > every or worst is None:
            worst = (el, moved, unit)
        every = max(every, needed)
    if steps * every > limits.SOLVE_STEPS:
        el, moved, unit = worst
        verb = "turns" if unit == "rad" else "moves"
        _, most = driver_unit(el)
        total = steps * every
        why = jump(el, float(t_end) / steps)
        if why:
            raise ModelError(Problem(el.where, (
                f"{why} (following it in steps of at most {most:g} {unit} would take "
                f"{total:.2g} position solves, more than pam2exu runs: "
                f"{limits.SOLVE_STEPS:,})")), mech.model.source)
        raise ModelError(Problem(
            "[analysis]",
            f"'{el.name}' {verb} {moved:.2g} {unit} per step (t_end = {t_end:g} s in {steps} "
            f"steps). Positions are solved in steps of at most {most:g} "
            f"{unit if unit == 'rad' else '× the mechanism size'}, so that the solver stays "
            f"on the mechanism's branch: this run would take {total:.2g} position solves, more "
            f"than pam2exu runs ({limits.SOLVE_STEPS:,}). Shorten t_end, or slow the law down "
            f"(were degrees given where radians are expected?)."), mech.model.source)
    every = int(every)
    times = np.linspace(0.0, float(t_end), int(steps) * every + 1) if every > 1 else user
    check_laws(mech, times, evaluated=evaluated if every == 1 else None)
    times.setflags(write=False)                  # (kept in ``_PLANS``: ``plan`` copies it)
    return Plan(times, every, (worst[0].name, *worst[1:]) if every > 1 else None)

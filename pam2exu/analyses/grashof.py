"""The closed forms of a four-bar and a slider-crank loop (``pam2exu classify``): the
Grashof class, the range of the input link, and the name of an assembly mode.

Pure functions of lengths and points, no mechanism: ``classify`` measures the loops and
calls them. Angles in radians here; the atlas prints degrees.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: relative tolerance of "s + l = p + q" (a change-point linkage) and of "r + |e| = L"
EQUAL = 1e-9

#: the Grashof classes (``pam2exu classify``'s words)
CLASSES = ("crank-rocker", "double-crank", "double-rocker", "change-point", "non-grashof")


@dataclass(frozen=True)
class Grashof:
    """A loop's class with the numbers that decide it: ``left`` (s + l, or r + |e|) against
    ``right`` (p + q, or L), in words in ``condition``."""

    kind: str
    left: float
    right: float
    condition: str

    def as_dict(self) -> dict:
        return {"class": self.kind, "left": self.left, "right": self.right,
                "condition": self.condition}


def four_bar_class(frame: float, input_: float, coupler: float, output: float,
                   names: dict[str, str] | None = None) -> Grashof:
    """Grashof's law s + l ≤ p + q, and which link is the shortest: the frame (double-crank),
    a link next to it (crank-rocker), the coupler (double-rocker); = (change-point); >
    (non-grashof, a triple rocker). ``names``: the solids of the roles, for the words."""
    lengths = {"frame": frame, "input": input_, "coupler": coupler, "output": output}
    ordered = sorted(lengths.values())
    s, l = ordered[0], ordered[-1]
    left, right = s + l, ordered[1] + ordered[2]
    condition = f"s + l = {s:.6g} + {l:.6g} = {left:.6g}"
    if abs(left - right) <= EQUAL * right:
        return Grashof("change-point", left, right, condition + f" = p + q = {right:.6g}")
    if left > right:
        return Grashof("non-grashof", left, right, condition + f" > p + q = {right:.6g}")
    shortest = min(lengths, key=lengths.get)
    kind = {"frame": "double-crank", "coupler": "double-rocker"}.get(shortest, "crank-rocker")
    who = f" '{names[shortest]}'" if names else ""
    return Grashof(kind, left, right, condition + f" < p + q = {right:.6g} "
                   f"(the shortest link: the {shortest}{who})")


def slider_crank_class(crank: float, rod: float, offset: float) -> Grashof:
    """The crank turns fully when r + |e| < L (``crank-rocker``: the slider reciprocates);
    = (``change-point``); > (``non-grashof``: the crank only rocks)."""
    left = crank + abs(offset)
    condition = f"r + |e| = {crank:.6g} + {abs(offset):.6g} = {left:.6g}"
    if abs(left - rod) <= EQUAL * rod:
        return Grashof("change-point", left, rod, condition + f" = L = {rod:.6g}")
    if left > rod:
        return Grashof("non-grashof", left, rod, condition + f" > L = {rod:.6g}")
    return Grashof("crank-rocker", left, rod, condition + f" < L = {rod:.6g}")


def cosine_range(lo: float, hi: float) -> list[tuple[float, float]]:
    """The angles θ (rad, in (−2π, 2π), each interval increasing) with lo ≤ cos θ ≤ hi;
    [(−π, π)] for every angle, [] for none."""
    lo = -1.0 if lo <= -1 + EQUAL else lo       # a change point reaches cos θ = ±1
    hi = 1.0 if hi >= 1 - EQUAL else hi
    if lo > hi or lo > 1 or hi < -1:
        return []
    if lo <= -1 and hi >= 1:
        return [(-np.pi, np.pi)]
    if hi >= 1:
        return [(-float(np.arccos(lo)), float(np.arccos(lo)))]
    if lo <= -1:
        return [(float(np.arccos(hi)), 2 * np.pi - float(np.arccos(hi)))]
    a, b = float(np.arccos(hi)), float(np.arccos(lo))
    return [(-b, -a), (a, b)]


def four_bar_input_range(frame: float, input_: float, coupler: float,
                         output: float) -> list[tuple[float, float]]:
    """The angles θ of the input link from the frame line with |b − c| ≤ δ ≤ b + c, δ² =
    a² + d² − 2ad cos θ: the pin the input carries reaches the dyad (``cosine_range``)."""
    a, d = input_, frame
    cos = (lambda delta: (a * a + d * d - delta * delta) / (2 * a * d))
    return cosine_range(cos(coupler + output), cos(coupler - output))


def crank_range(crank: float, rod: float, offset: float) -> list[tuple[float, float]]:
    """The crank angles θ from the guide's direction with |r sin θ − e| ≤ L: the crank pin
    within L of the slider pin's path (e its offset)."""
    lo, hi = (offset - rod) / crank, (offset + rod) / crank
    turns = cosine_range(lo, hi)             # sin θ ∈ [lo, hi] is cos(θ − π/2) ∈ [lo, hi]
    if turns == [(-np.pi, np.pi)]:
        return turns
    return [(a + np.pi / 2, b + np.pi / 2) for a, b in turns]


def slider_range(crank: float, rod: float, offset: float) -> list[tuple[float, float]]:
    """The slider pin's places x along its path from the foot of the crank's pivot with
    |L − r| ≤ √(x² + e²) ≤ L + r [m]."""
    far = (rod + crank) ** 2 - offset ** 2
    if far < 0:
        return []
    near = (rod - crank) ** 2 - offset ** 2
    x1 = float(np.sqrt(far))
    if near <= 0:
        return [(-x1, x1)]
    x0 = float(np.sqrt(near))
    return [(-x1, -x0), (x0, x1)]


def dyad_side(a, b, p) -> float:
    """(b − a) × (b − p): the sign of the angle from the coupler (a → b) to the output link
    (p → b), which tells the dyad's two assembly modes apart."""
    return float((b[0] - a[0]) * (b[1] - p[1]) - (b[1] - a[1]) * (b[0] - p[0]))


def four_bar_mode(a, b, p) -> str:
    """``open`` when sin(θ_out − θ_coupler) > 0, angles counter-clockwise (Norton's open
    circuit: coupler a → b, output link p → b), else ``crossed``."""
    return "open" if dyad_side(a, b, p) > 0 else "crossed"


def slider_mode(a, b, direction) -> str:
    """``open`` when the slider pin b is ahead of the coupler's other pin a along the guide
    ((b − a) · d > 0: cos θ_coupler > 0 in Norton's slider-crank), else ``crossed``."""
    return "open" if (b[0] - a[0]) * direction[0] + (b[1] - a[1]) * direction[1] > 0 \
        else "crossed"


def degrees(ranges) -> list[list[float]]:
    """Intervals in radians, as lists in degrees."""
    return [[float(np.degrees(a)), float(np.degrees(b))] for a, b in ranges]

"""A compound pendulum, free or hanging from a driven slider: the models as TOML and their
one-degree-of-freedom equation, for the dynamic, equilibrium and energy tests.

The pendulum ``lever`` turns about its frame origin O, pinned to the ground; its centre of
mass G is at distance D along its local x axis, θ = fi is measured from the global x axis.
With I_O = I_G + m D², Lagrange's equation is

    I_O θ̈ = m D sin θ ẍ_s − m g D cos θ,

where x_s is the pivot's horizontal position (0 for a fixed pivot; the slider's law for the
pendulum on a slider, ``SLIDER``). ``swing`` is its right-hand side and ``reference`` its
integration by scipy's DOP853 at rtol 1e-13.
"""
from __future__ import annotations

import math

import numpy as np

#: gravity [m/s²], mass [kg], distance O–G [m], inertia about G [kg·m²], about O
G, M, D, IG = 9.81, 2.0, 0.25, 0.02
IO = IG + M * D * D


def pendulum_toml(fi: float = 0.3, dfi: float = 0.0, dx: float = 0.0, elements: str = "",
                  mass: float = M, inertia: float = IG,
                  analysis: str = 'type = "dynamic"') -> str:
    """The free pendulum released at θ = fi with the initial-velocity guesses Dfi = dfi,
    Dx = dx; ``elements``: more [[element]] tables (springs, torsors); ``analysis``: the
    body of its [analysis] table."""
    return f"""
[model]
name = "pendulum"
gravity = {G}

[[solid]]
name = "ground"

[[solid]]
name = "lever"
fi = {fi!r}
Dx = {dx!r}
Dfi = {dfi!r}
mass = {mass!r}
inertia = {inertia!r}
cog = [{D}, 0.0]
points = {{ O = [0.0, 0.0], A = [0.5, 0.0] }}

[[element]]
type = "fixed"
name = "base"
anc1 = "ground"

[[element]]
type = "revolute"
name = "pivot"
anc1 = "ground"
anc2 = "lever.O"
{elements}
[analysis]
{analysis}
"""


def slider_toml(law: str = "bezier_c2", C=(0.2, 0.7, 0.5, 0.9)) -> str:
    """The pendulum (θ0 = −1.2, at rest) hinged on a slider of 1 kg that a linear actuator
    moves along the ground's x axis by ``law`` with constants ``C`` (its distance from the
    ground's origin), 1 s in 50 steps."""
    return f"""
[model]
name = "pendulum on a slider"
gravity = {G}

[[solid]]
name = "ground"
points = {{ O = [0.0, 0.0] }}

[[solid]]
name = "slider"
x = {C[2]!r}
mass = 1.0
inertia = 0.01

[[solid]]
name = "lever"
x = {C[2]!r}
fi = -1.2
mass = {M}
inertia = {IG}
cog = [{D}, 0.0]

[[element]]
type = "fixed"
anc1 = "ground"

[[element]]
type = "prismatic"
name = "rail"
anc1 = "ground"
anc2 = "slider"

[[element]]
type = "linear_actuator"
name = "drive"
anc1 = "ground.O"
anc2 = "slider"
law = "{law}"
C = {list(C)!r}

[[element]]
type = "revolute"
name = "hinge"
anc1 = "slider"
anc2 = "lever"

[analysis]
type = "dynamic"
t_end = 1.0
steps = 50
"""


def swing(t: float, y, xdd: float = 0.0) -> list[float]:
    """(θ̇, θ̈) with I_O θ̈ = m D sin θ ẍ_s − m g D cos θ."""
    return [y[1], (M * D * math.sin(y[0]) * xdd - M * G * D * math.cos(y[0])) / IO]


def reference(t_eval, y0, slider_acceleration=None):
    """(θ, θ̇) at ``t_eval`` by DOP853 (rtol 1e-13, atol 1e-14) from y0 = (θ0, θ̇0) at
    t_eval[0]; ``slider_acceleration``: ẍ_s(t) (None: a fixed pivot)."""
    from scipy.integrate import solve_ivp

    t_eval = np.asarray(t_eval, dtype=float)
    accel = slider_acceleration or (lambda t: 0.0)
    found = solve_ivp(lambda t, y: swing(t, y, accel(t)), (t_eval[0], t_eval[-1]), list(y0),
                      method="DOP853", rtol=1e-13, atol=1e-14, t_eval=t_eval)
    return found.y

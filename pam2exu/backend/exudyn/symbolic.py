"""Time laws as Exudyn symbolic user functions: evaluated in C++, no Python call per step.

The laws in ``pam2exu.laws`` are written against an array namespace ``xp``; here that
namespace builds Exudyn symbolic expressions (``exudyn.symbolic``) instead of NumPy arrays,
so the driver of an actuator is the very same formula, compiled into an expression tree.
"""
from __future__ import annotations

import exudyn as exu

esym = exu.symbolic

#: a load step's time is on the grid when within this fraction of a step of a grid time:
#: Exudyn adds up its step times, which drift by round-off (past 1e-6 of a step after
#: ~240,000 steps), while a step it cut short is at least 1/64 of a step off the grid
ON_GRID = 1e-3


def _real(v):
    """A symbolic Real from a number or an expression."""
    return v if isinstance(v, esym.Real) else esym.Real(float(v))


class SymbolicNamespace:
    """The ``xp`` the laws need (cos, sin, where), for symbolic expressions."""

    cos = staticmethod(esym.cos)
    sin = staticmethod(esym.sin)

    @staticmethod
    def where(condition, a, b):
        """IfThenElse(condition, a, b)."""
        return esym.IfThenElse(condition, _real(a), _real(b))


def grid_time(t, dt: float):
    """τ = (k − 1)·dt at load step k (t ≈ k·dt, up to Exudyn's accumulated round-off), else t − dt."""
    k = esym.round(t / dt)
    return esym.IfThenElse(esym.abs(t / dt - k) < ON_GRID, (k - 1.0) * dt, t - dt)


def offset_function(mbs, obj, law, shift: float, dt: float):
    """An ObjectConnectorCoordinate offsetUserFunction giving f(τ) + shift (keep it alive)."""
    from exudyn.advancedUtilities import CreateSymbolicUserFunction

    def offset(mbs, t, itemNumber, lOffset):
        return law(grid_time(t, dt), xp=SymbolicNamespace)[0] + shift

    return CreateSymbolicUserFunction(mbs, offset, "offsetUserFunction", obj)

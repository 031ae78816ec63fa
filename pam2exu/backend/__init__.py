"""Backends: formulations of the constraints with a position solver (``base.Backend``).

``Exudyn`` (the package ``exudyn``: its translation ``system``, the standalone script
``script``, the time integration ``integrate``) is the default and the only code that
imports exudyn.
"""
from .base import Backend, Positions
from .exudyn import Exudyn
from .exudyn.system import ExudynSystem, SolveSettings

__all__ = ["Backend", "Positions", "Exudyn", "ExudynSystem", "SolveSettings"]

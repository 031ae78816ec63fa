"""Backends: formulations of the constraints with a position solver (``base.Backend``).

``Exudyn`` (``exudyn_backend``) is the default and, with ``system`` (the translation) and
``script`` (the standalone script), the only code that imports exudyn.
"""
from .base import Backend, Positions
from .exudyn_backend import Exudyn
from .system import ExudynSystem, SolveSettings

__all__ = ["Backend", "Positions", "Exudyn", "ExudynSystem", "SolveSettings"]

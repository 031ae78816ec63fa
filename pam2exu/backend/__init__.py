"""The Exudyn backend: the only package that imports exudyn."""
from .system import ExudynSystem, SolveSettings

__all__ = ["ExudynSystem", "SolveSettings"]

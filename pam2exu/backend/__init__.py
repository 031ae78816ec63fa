"""Backends: formulations of the constraints with a position solver (``base.Backend``).

``Exudyn`` (the package ``exudyn``: its translation ``system``, the standalone script
``script``, the time integration ``integrate``) is the default and the only code that
imports exudyn; ``natural`` is the second formulation and loads no Exudyn. The Exudyn
backend's names here (``pam2exu.backend.SolveSettings``, ``ExudynSystem``, ``Exudyn``) are
imported, with exudyn, on first use.
"""
from importlib import import_module

from .base import Backend, Integrator, Positions, Trajectory

__all__ = ["Backend", "Integrator", "Positions", "Trajectory", "Exudyn", "ExudynSystem",
           "SolveSettings"]

#: the Exudyn backend's names offered here, and the module each comes from
_EXUDYN_NAMES = {"Exudyn": "pam2exu.backend.exudyn",
                 "ExudynSystem": "pam2exu.backend.exudyn.system",
                 "SolveSettings": "pam2exu.backend.exudyn.system"}


def __getattr__(name: str):
    """The Exudyn backend's names, imported on first use (PEP 562): ``import
    pam2exu.backend.natural`` passes through this package and must not load exudyn."""
    if name not in _EXUDYN_NAMES:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(import_module(_EXUDYN_NAMES[name]), name)

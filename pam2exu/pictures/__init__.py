"""Pictures of mechanisms: ``draw`` one configuration, ``animate`` the motion.

Plots of result variables against time are ``pam2exu.results.plot``. The user guide is
docs/pictures.md.
"""
from .animation import animate
from .mechanism import draw
from .pen import Pen
from .poses import configurations, pose
from .scene import Scene

__all__ = ["draw", "animate", "configurations", "pose", "Scene", "Pen"]

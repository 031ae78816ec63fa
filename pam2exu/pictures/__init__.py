"""Pictures of mechanisms: ``draw`` one configuration, ``animate`` the motion.

Plots of result variables against time are ``pam2exu.results.plot``. The user guide is
docs/pictures.md.
"""
from .mechanism import Scene, animate, configurations, draw, pose
from .pen import Pen

__all__ = ["draw", "animate", "configurations", "pose", "Scene", "Pen"]

"""Model layer: parse and validate PAM models (no Exudyn import here)."""
from ..laws import LAWS, Law
from .loader import load, loads
from .model import Analysis, Mechanism, Model
from .solid import Solid

__all__ = ["Model", "Solid", "Analysis", "Mechanism", "Law", "LAWS", "load", "loads"]

"""Model layer: parse and validate PAM models (no Exudyn import here)."""
from ..laws import LAWS, Law
from .loader import load, loads
from .analysis import Analysis
from .mechanism import Mechanism
from .model import Model
from .solid import Solid
from .variation import Variation, ramped_cosine

__all__ = ["Model", "Solid", "Analysis", "Mechanism", "Variation", "ramped_cosine", "Law", "LAWS",
           "load", "loads"]

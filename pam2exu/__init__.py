"""pam2exu: PAM planar mechanism models, run on the Exudyn multibody library.

>>> import pam2exu
>>> model = pam2exu.load("examples/slider_crank.toml")      # doctest: +SKIP
>>> res = pam2exu.run(model, analysis="kinematic")          # doctest: +SKIP
>>> res["slider.Dx"]                                        # doctest: +SKIP
"""
from .elements import (ELEMENTS, AngularActuator, Fixed, LinearActuator, PinSlot, Prismatic,
                       Revolute, Spring, Torsor, TorsionalSpring, Transmission)
from .errors import (MobilityError, ModelError, Pam2ExuError, SolverError, TranslationError)
from .export import export
from .model import Law, Model, Solid, load, loads
from .results.compare import compare

__version__ = "0.1.0"


def run(model, analysis=None, **settings):
    """Run an analysis of a model (a Model or a path); returns a Results table.

    See ``pam2exu.analyses.run`` for the settings.
    """
    from .analyses import run as _run
    return _run(model, analysis=analysis, **settings)


__all__ = ["Model", "Solid", "Law", "load", "loads", "run", "compare", "export", "ELEMENTS",
           "Fixed", "Revolute", "Prismatic", "PinSlot", "Transmission", "Torsor", "Spring",
           "TorsionalSpring", "AngularActuator", "LinearActuator", "Pam2ExuError", "ModelError",
           "MobilityError", "SolverError", "TranslationError"]

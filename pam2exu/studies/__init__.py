"""Studies: one analysis of one model, run for many variants of its values.

The study file (``study.py``), what can vary in a model and a variant written into it
(``parameters.py``), the variants' values (``sampling.py``), what a study makes of each
variant's run (``reduce.py``) and of all of them (``summary.py``).
"""
from .parameters import Target, targets, varied
from .sampling import DISTRIBUTIONS, METHODS, Parameter, design
from .study import Study, load_study, loads_study, variants

__all__ = ["DISTRIBUTIONS", "METHODS", "Parameter", "Study", "Target", "design",
           "load_study", "loads_study", "targets", "variants", "varied"]

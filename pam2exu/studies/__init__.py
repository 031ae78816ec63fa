"""Studies: one analysis of one model, run for many variants of its values.

The study file (``study.py``), what can vary in a model and a variant written into it
(``parameters.py``), the variants' values (``sampling.py``), what a study makes of each
variant's run (``reduce.py``) and of all of them (``summary.py``); running a study
(``runner.py``: ``study``, as ``pam2exu.study``; the name ``pam2exu.studies.study`` is
the study file's module) and its result (``result.py``: ``StudyResult``).
"""
from .parameters import Target, targets, varied
from .sampling import DISTRIBUTIONS, METHODS, Parameter, design
from .result import StudyResult
from .study import Study, load_study, loads_study, variants

__all__ = ["DISTRIBUTIONS", "METHODS", "Parameter", "Study", "StudyResult", "Target", "design",
           "load_study", "loads_study", "targets", "variants", "varied"]

"""A parts-as-made study's position solves, made once per chunk.

A study of an analysis that reaches the parts as made from the nominal assembly
(``AnalysisType.parts_as_made``: the clearance analysis) whose parameters are all
dimensions (points' and lines' coordinates, ``parameters.is_dimension``) writes each
variant's values as the fixed deviations of its ``[[variation]]`` entries and keeps the
nominal dimensions (``parameters.write_deviation``). No backend reads the variations (the
clearance analysis's closures do), so every position solve a variant's run asks of its
backend (its nominal assembly, the nominal motion its first-order estimate is compared
with) is the same for all the variants of the study: ~20 % of a locomotive variant of 400
steps (docs/studies.md, "Clearance studies").

A chunk of such a study runs its variants on one backend (``sharing``) that keeps each
solve's answer by its request (times, start, settings, options) and gives the next run
asking the same a copy: the same bits as its own solve, solved once.
"""
from __future__ import annotations

import copy
import functools

import numpy as np

from ..backend import Backend
from ..registry import BACKENDS, analysis_type, resolve
from .parameters import is_dimension, targets


def shares_nominal(study) -> bool:
    """Whether the variants of ``study`` (a ``Study``) share their position solves: its
    analysis reaches the parts as made and every parameter is a dimension."""
    if not analysis_type(study.analysis).parts_as_made:
        return False
    found = targets(study.model)
    return all(is_dimension(found[name]) for name in study.names)


def sharing(name: str) -> Backend:
    """The backend ``name`` (``registry.BACKENDS``) whose ``solve_positions`` answers a
    request it has solved already (the same times, start, settings and options) with a copy
    of that answer, whatever mechanism asks: for the variants of one chunk of a study that
    ``shares_nominal`` only."""
    return _sharing_class(resolve(BACKENDS[name].implementation))()


@functools.cache
def _sharing_class(engine: type) -> type:
    """A subclass of the backend class ``engine`` that keeps its position solves
    (``sharing``); everything else, its identity and its messages included, is
    ``engine``'s."""

    class Sharing(engine):
        def solve_positions(self, mech, times, start, settings, **options):
            """``engine.solve_positions``, once per request (a copy of its answer)."""
            key = (np.asarray(times, dtype=float).tobytes(),
                   np.asarray(start, dtype=float).tobytes(), repr(settings),
                   tuple(sorted(options.items())))
            kept = self.__dict__.setdefault("_answers", {})
            if key not in kept:
                kept[key] = super().solve_positions(mech, times, start, settings, **options)
            return copy.deepcopy(kept[key])

    Sharing.__name__ = Sharing.__qualname__ = f"Sharing{engine.__name__}"
    return Sharing

"""Variants in one pass: a chunk's variants solved together by the backend
(``Backend.solved_variants``: the natural backend stacks their equations and runs Newton on
all of them at once, and turns every variant's answers into x, y, fi at once), then each
variant's analysis run as a single run would, its positions read from the pass. The checks,
the force columns and the warnings of every variant are its own run's; what the pass shares
is Newton's iterations, the conversion to x, y, fi with their rates and, on the natural
backend, the reactions' inverse dynamics (``backend.natural.population``: made for all
variants when the first run asks, read by each run whose motion is the pass's).

A variant that does not fit the pass (another structure of equations, a redundant one), or
fails in it, gets no answers: its run solves it alone and says why it fails, exactly as the
study without the pass would.
"""
from __future__ import annotations

import warnings

import numpy as np

from ..errors import Pam2ExuError
from ..model import Mechanism
from ..registry import BACKENDS, analysis_type, resolve


def one_pass(payload: dict) -> bool:
    """Whether the chunks of the study of this payload (``runner.payload``) are solved in
    one pass: asked (``[study] batched``), the backend can (``solves_variants``) and the
    analysis allows it (``one_pass``)."""
    return takes_one_pass(payload.get("backend"), payload["analysis"], payload.get("batched"))


def one_pass_of(study) -> bool:
    """``one_pass`` of a ``Study``."""
    return takes_one_pass(study.backend, study.analysis, study.batched)


def takes_one_pass(backend: str | None, analysis: str, batched) -> bool:
    """Asked, the backend named (None: each run's own) can and the analysis allows it."""
    return bool(batched) and backend is not None \
        and resolve(BACKENDS[backend].implementation).solves_variants \
        and analysis_type(analysis).one_pass


def answered(payload: dict, models: list) -> list:
    """For each variant's model (``runner.made_variant``: validated; None: it could not be
    made), (its mechanism, the backend
    holding its answers from the pass) for its run, or None (its run makes and solves it
    alone). Variants are solved together with those of the same solve grid (sub-steps may
    differ), so that a variant's answers do not depend on the others in its chunk."""
    from ..analyses.grid import plan
    kind = analysis_type(payload["analysis"])
    engine = resolve(BACKENDS[payload["backend"]].implementation)()
    groups: dict[bytes, tuple[np.ndarray, list[int], list]] = {}
    with warnings.catch_warnings():        # each variant's run issues its own warnings
        warnings.simplefilter("ignore")
        for i, model in enumerate(models):
            if model is None:
                continue
            try:
                mech = Mechanism(model)         # validated by ``varied`` already
                times = np.zeros(1) if kind.at_start else plan(
                    mech, payload["t_end"], payload["steps"], 1).times
            except Pam2ExuError:                # its run says why
                continue
            group = groups.setdefault(times.tobytes(), (times, [], []))
            group[1].append(i)
            group[2].append(mech)
        out: list = [None] * len(models)
        for times, members, mechs in groups.values():
            for i, mech, backend in zip(members, mechs,
                                        engine.solved_variants(mechs, times, engine.Settings())):
                out[i] = None if backend is None else (mech, backend)
    return out

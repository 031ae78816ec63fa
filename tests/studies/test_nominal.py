"""A parts-as-made study's position solves, made once per chunk (pam2exu/studies/nominal.py).

Reference: the same chunk with every variant solving its own positions (``shares_nominal``
off in the payload): the tables are the same bits, warnings included; the backend's own
solver is called once per distinct request instead of once per variant.
"""
import dataclasses
from pathlib import Path

import numpy as np

from pam2exu.backend.exudyn import Exudyn
from pam2exu.model import load
from pam2exu.studies import loads_study
from pam2exu.studies.nominal import shares_nominal, sharing
from pam2exu.studies.runner import nominal, payload, run_variants

ROOT = Path(__file__).resolve().parents[2]
CLEARANCE = ROOT / "examples" / "clearance"

STUDY = """
[study]
model = "locomotive.toml"
analysis = "clearance"
t_end = 0.2
steps = 4
method = "monte_carlo"
samples = 3
seed = 2
outputs = ["pin2.jr", "pin3.jr", "rod.x"]
reduce = ["max", "mean"]
[[parameter]]
name = "wheel2.A.x"
distribution = "normal"
tol = 3e-4
[[parameter]]
name = "frame.O3.y"
distribution = "normal"
tol = 3e-4
"""


def _counted(monkeypatch) -> list:
    """The Exudyn backend's own position solves, counted (the times' lengths)."""
    calls, solve = [], Exudyn.solve_positions

    def counted(self, mech, times, *args, **kwargs):
        calls.append(len(times))
        return solve(self, mech, times, *args, **kwargs)
    monkeypatch.setattr(Exudyn, "solve_positions", counted)
    return calls


def test_a_clearance_chunk_solves_its_nominal_once_and_gives_the_same_table(monkeypatch):
    study = loads_study(STUDY, folder=CLEARANCE)
    assert shares_nominal(study)
    shared = payload(study, nominal(study)[0])
    assert shared["shares_nominal"]
    alone = {**shared, "shares_nominal": False}
    values = study.variants()
    calls = _counted(monkeypatch)
    own = run_variants(alone, 0, 3, values)
    assert calls == [1, 5] * 3             # each variant: its assembly, its nominal motion
    calls.clear()
    once = run_variants(shared, 0, 3, values)
    assert calls == [1, 5]                 # the first variant's, shared by the others
    assert list(once) == list(own)
    for name in own:
        assert np.array_equal(once[name], own[name]), name
    assert len(set(once["pin2.jr.max"].tolist())) == 3          # three variants, not one


def test_only_a_parts_as_made_study_of_dimensions_shares_its_nominal():
    study = loads_study(STUDY, folder=CLEARANCE)
    assert shares_nominal(study)
    # the drive's law constant is written into the model: the nominal differs by variant
    law = loads_study(STUDY + '[[parameter]]\nname = "drive.C2"\ndistribution = "normal"\n'
                              'tol = 1e-3\n', folder=CLEARANCE)
    assert not shares_nominal(law)
    assert not shares_nominal(dataclasses.replace(study, analysis="kinematic"))


def test_the_shared_backend_answers_each_request_with_a_copy_of_its_solve():
    model = load(CLEARANCE / "locomotive.toml")
    mech = model.mechanism()
    engine = sharing("exudyn")
    assert isinstance(engine, Exudyn) and engine.label == Exudyn.label
    settings = engine.Settings()
    times, start = np.linspace(0.0, 0.2, 5), mech.initial_q()
    first = engine.solve_positions(mech, times, start, settings, redundant=True)
    fresh = Exudyn().solve_positions(mech, times, start, settings, redundant=True)
    assert first.solved == 5 and np.array_equal(first.q, fresh.q)
    first.q[:] = np.nan                            # the caller's copy, not the one kept
    again = engine.solve_positions(mech, times, start, settings, redundant=True)
    assert np.array_equal(again.q, fresh.q)
    # another request (fewer times, or other options) is solved, not answered
    shorter = engine.solve_positions(mech, times[:3], start, settings, redundant=True)
    assert shorter.q.shape[0] == 3
    plain = engine.solve_positions(mech, times, start, settings)        # not redundant
    assert plain.solved < 5


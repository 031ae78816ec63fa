"""A study's variants in one pass (pam2exu/studies/batch.py, ``[study] batched``).

Reference: the same study with ``batched = false``, every variant solved alone by the
same backend (the per-variant runs the pass is held against). Every reduced output agrees
to 1e-12 of its column's largest value; status, error and warnings are the same text.
"""
import dataclasses
from pathlib import Path

import numpy as np
import pytest

from pam2exu.errors import ModelError
from pam2exu.studies import loads_study
from pam2exu.studies.batch import answered, one_pass
from pam2exu.studies.runner import made_variant, nominal, payload, study

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"

FOUR_BAR = """
[study]
model = "four_bar.toml"
analysis = "kinetostatic"
backend = "natural"
steps = 16
method = "grid"
outputs = ["motor.Mz", "coupler.fi", "A.F*", "coupler.P.DDx"]
reduce = ["min", "max", "absmax", "mean", "rms", "final", "range"]
[[parameter]]
name = "coupler.B.x"          # 0.10 m: non-Grashof, fails part-way
values = [0.35, 0.10, 0.352]
[[parameter]]
name = "rocker.B.x"           # 0.12 m: non-Grashof too
values = [0.30, 0.12]
[[requirement]]
output = "motor.Mz.absmax"
max = 0.5
"""

SLIDER = """
[study]
model = "slider_crank.toml"
analysis = "kinematic"
backend = "natural"
steps = 80
method = "latin_hypercube"
samples = 6
seed = 4
outputs = ["slider.x", "slider.DDx", "rod.Dfi"]
reduce = ["absmax", "mean", "final"]
[[parameter]]
name = "crank.A.x"
distribution = "normal"
tol = 2e-3
[[parameter]]
name = "rod.B.x"
distribution = "uniform"
tol = 3e-3
"""


def _both(text: str, folder: Path = EXAMPLES):
    """The study run in one pass, and with every variant alone."""
    s = loads_study(text, folder=folder)
    return study(s, workers=1), study(dataclasses.replace(s, batched=False), workers=1)


def _same(a, b):
    assert list(a.table) == list(b.table)
    for c in a.table:
        x, y = np.asarray(a.table[c]), np.asarray(b.table[c])
        if x.dtype.kind == "f":
            assert np.array_equal(np.isnan(x), np.isnan(y)), c
            scale = np.nanmax(np.abs(y), initial=0.0) or 1.0
            assert np.nanmax(np.abs(x - y), initial=0.0) <= 1e-12 * scale, c
        else:
            assert x.tolist() == y.tolist(), c
    assert a.warnings.tolist() == b.warnings.tolist()


@pytest.fixture(scope="module")
def four_bar():
    return _both(FOUR_BAR)


def test_four_bar_variants_in_one_pass_equal_their_own_runs(four_bar):
    batched, alone = four_bar
    _same(batched, alone)
    status = batched.table["status"].tolist()
    assert status.count("error") == 4 and status.count("rejected") == 2   # in one chunk


def test_the_pass_solves_the_variants_it_can(four_bar):
    s = loads_study(FOUR_BAR, folder=EXAMPLES)
    p = payload(s, nominal(s)[0])
    assert one_pass(p)
    made = [made_variant(p, v) for v in s.variants()]
    found = answered(p, [m for m, _ in made])
    # the non-Grashof variants fail in the pass (their runs say why); the others are solved
    assert [b is not None for b in found] == [True, False, False, False, True, False]


def test_slider_crank_variants_in_one_pass_equal_their_own_runs():
    _same(*_both(SLIDER))


def test_which_studies_take_the_pass():
    s = loads_study(SLIDER, folder=EXAMPLES)
    p = payload(s, nominal(s)[0])
    assert one_pass(p)
    assert not one_pass({**p, "batched": False})
    assert not one_pass({**p, "backend": "exudyn"})        # it solves one run at a time
    assert not one_pass({**p, "analysis": "dynamic"})      # it integrates, no grid solve
    # the clearance analysis solves each variant's parts as made alone: batched = true or
    # false runs the same per-variant runs, so its tables are the reference's
    assert not one_pass({**p, "analysis": "clearance"})


@pytest.mark.parametrize("line, says", [
    ('backend = "natral"', "natral"),
    ("batched = 1", "batched must be true or false"),
])
def test_bad_backend_or_batched_is_named(line, says):
    text = SLIDER.replace('backend = "natural"', line)
    with pytest.raises(ModelError, match=says):
        loads_study(text, folder=EXAMPLES)


def _chain_text(N: int) -> str:
    """The model file of ``benchmarks.cases.chain_model(N)`` (N four-bar loops in a chain),
    written as TOML with the same solids, guesses and elements."""
    from benchmarks.cases import CHAIN, CHAIN_LAW, COUPLER, LINK, chain_kinematics
    a, b, c, d = (CHAIN[key] for key in "abcd")
    solids, _ = chain_kinematics(N, np.zeros(1))

    def solid(name, points, inertial):
        (r, _, _), (fi, _, _) = solids[name]
        pts = ", ".join(f"{k} = [{x!r}, {y!r}]" for k, (x, y) in points.items())
        return (f'[[solid]]\nname = "{name}"\nx = {float(r[0, 0])!r}\ny = {float(r[1, 0])!r}\n'
                f'fi = {float(fi[0])!r}\nmass = {inertial["mass"]!r}\n'
                f'inertia = {inertial["inertia"]!r}\ncog = {list(inertial["cog"])!r}\n'
                f'points = {{ {pts} }}\n')

    def element(kind, name, anc1, anc2=None):
        return (f'[[element]]\ntype = "{kind}"\nname = "{name}"\nanc1 = "{anc1}"\n'
                + (f'anc2 = "{anc2}"\n' if anc2 else ""))

    ground = ", ".join(f"P{i} = [{i * d!r}, 0.0]" for i in range(N + 1))
    out = [f'[model]\nname = "chain of {N}"\ngravity = 9.81\n',
           f'[[solid]]\nname = "ground"\npoints = {{ {ground} }}\n', element("fixed", "base",
                                                                            "ground")]
    for i in range(N + 1):
        points = {"O": (0.0, 0.0)}
        if i < N:
            points["A"] = (a, 0.0) if i == 0 else (-a, 0.0)
        if i > 0:
            points["B"] = (c, 0.0)
        out += [solid(f"L{i}", points, LINK), element("revolute", f"O{i}", f"ground.P{i}",
                                                      f"L{i}.O")]
    for j in range(1, N + 1):
        out += [solid(f"K{j}", {"A": (0.0, 0.0), "B": (b, 0.0)}, COUPLER),
                element("revolute", f"A{j}", f"L{j - 1}.A", f"K{j}.A"),
                element("revolute", f"B{j}", f"K{j}.B", f"L{j}.B")]
    out.append(element("angular_actuator", "motor", "ground", "L0")
               + f'law = "polynomial"\nC = [{CHAIN_LAW[0]!r}, {CHAIN_LAW[1]!r}, 0.0, 0.0]\n')
    return "\n".join(out)


def test_chain_of_four_loops_in_one_pass_equals_its_own_runs(tmp_path):
    (tmp_path / "chain4.toml").write_text(_chain_text(4))
    text = """
[study]
model = "chain4.toml"
analysis = "kinetostatic"
backend = "natural"
t_end = 0.25
steps = 20
method = "monte_carlo"
samples = 3
seed = 2
outputs = ["motor.Mz", "L4.fi", "B4.F*"]
reduce = ["absmax", "mean", "final"]
[[parameter]]
name = "K2.B.x"
distribution = "normal"
tol = 2e-3
[[parameter]]
name = "L3.B.x"
distribution = "uniform"
tol = 2e-3
"""
    s = loads_study(text, folder=tmp_path)
    p = payload(s, nominal(s)[0])
    assert all(b is not None for b in answered(p, [m for m, _ in
                                                   (made_variant(p, v) for v in s.variants())]))
    batched, alone = _both(text, tmp_path)
    _same(batched, alone)
    assert batched.table["status"].tolist() == ["ok"] * 3


def test_the_shipped_one_pass_study_runs_its_first_variants_as_their_own_runs():
    """examples/studies/four_bar_tolerance.toml: 2,000 variants on the natural backend; its
    first 6 (``--samples 6``), in one pass and each alone."""
    from pam2exu.studies import load_study
    from pam2exu.studies.runner import prepared
    s = prepared(load_study(EXAMPLES / "studies" / "four_bar_tolerance.toml"), 6)
    assert s.backend == "natural" and s.batched
    _same(study(s, workers=1), study(dataclasses.replace(s, batched=False), workers=1))


def test_a_chunk_gives_the_garbage_collector_back_as_it_found_it(monkeypatch):
    """The one pass pauses Python's cyclic collector and sets its objects apart
    (``runner.set_apart``): after the chunk, or when the pass raises, the collector is on
    again with nothing set apart; a program's own frozen objects are left frozen."""
    import gc
    from pam2exu.studies import runner
    s = loads_study(SLIDER, folder=EXAMPLES)
    names, _ = nominal(s)
    p = payload(s, names)
    values = s.variants()[:2]
    assert gc.isenabled() and gc.get_freeze_count() == 0
    table = runner.run_variants(p, 0, 2, values)
    assert gc.isenabled() and gc.get_freeze_count() == 0
    assert list(table["status"]) == ["ok", "ok"]

    def fails(*_):
        raise RuntimeError("the pass failed")
    monkeypatch.setattr(runner, "answered", fails)
    with pytest.raises(RuntimeError):
        runner.run_variants(p, 0, 2, values)
    assert gc.isenabled() and gc.get_freeze_count() == 0

    monkeypatch.undo()
    mine = [[]]                                    # a program's own object, frozen
    gc.freeze()
    try:
        runner.run_variants(p, 0, 2, values)
        assert gc.get_freeze_count() > 0 and gc.isenabled()     # not unfrozen by the chunk
    finally:
        gc.unfreeze()
    assert mine


def test_the_pass_makes_the_reactions_of_its_variants(monkeypatch):
    """A kinetostatic study on the natural backend: the reactions of the variants the pass
    solved come from its one inverse dynamics of them all (``population.Group``); only the
    variants it left out compute their own, in their own runs."""
    import pam2exu.backend.natural as natural
    from pam2exu.studies.runner import run_variants
    s = loads_study(FOUR_BAR, folder=EXAMPLES)
    p = payload(s, nominal(s)[0])
    own = []
    original = natural.constraint_wrenches
    monkeypatch.setattr(natural, "constraint_wrenches",
                        lambda form, *a, **k: own.append(form.mech) or original(form, *a, **k))
    values = np.asarray(s.variants())
    table = run_variants(p, 0, len(values), values)
    status = table["status"].tolist()
    assert status.count("ok") + status.count("rejected") == 2
    assert own == []                          # the 4 others fail before their forces


def test_quasi_static_variants_share_their_reactions_at_rest(monkeypatch):
    """A quasi-static study on the natural backend: the pass's variants take their reactions
    from its one inverse dynamics of them all at rest (``population.Group.reactions``,
    ż = z̈ = 0), none computes its own, and every reduced output, status and warning equals
    the study with each variant alone (which solves its own inverse dynamics at rest)."""
    import pam2exu.backend.natural as natural
    from pam2exu.studies.runner import run_variants
    text = FOUR_BAR.replace('analysis = "kinetostatic"', 'analysis = "quasi_static"').replace(
        ', "coupler.P.DDx"', "")
    s = loads_study(text, folder=EXAMPLES)
    values = np.asarray(s.variants())
    model = nominal(s)[0]
    own = []
    original = natural.constraint_wrenches
    with monkeypatch.context() as patch:
        patch.setattr(natural, "constraint_wrenches",
                      lambda form, *a, **k: own.append(form.mech) or original(form, *a, **k))
        for batched in (True, False):
            p = payload(dataclasses.replace(s, batched=batched), model)
            table = run_variants(p, 0, len(values), values)
            status = table["status"].tolist()
            assert status.count("ok") + status.count("rejected") == 2
            # in one pass none of its own (the 4 others fail before their forces); alone,
            # each of the 2 that get there its own
            assert len(own) == (0 if batched else 2)
    _same(*_both(text))

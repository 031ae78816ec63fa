"""Studies of the analyses with free degrees of freedom: ``equilibrium`` and ``dynamic``
(``AnalysisType.in_studies``): each variant runs as a single run would.

References: three variants of each study against single ``pam2exu.run`` calls of the model
built with ``parameters.varied`` from the variant's values (1e-12 relative), reduced with
NumPy; a pendulum held by a spring (written here: the equilibrium and the motion are its own
closed forms' business in tests/analyses, here only the identity with single runs counts);
with --long the shipped examples/equilibrium/spring_four_bar.toml and
examples/dynamics/andrews.toml.
"""
from pathlib import Path

import numpy as np
import pytest

import pam2exu
from pam2exu.registry import ANALYSES
from pam2exu.studies import loads_study
from pam2exu.studies.parameters import varied
from pam2exu.studies.runner import prepared, study

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
NUMPY = {"min": np.min, "max": np.max, "absmax": lambda y: np.max(np.abs(y)),
         "mean": np.mean, "rms": lambda y: np.sqrt(np.mean(y * y)), "final": lambda y: y[-1],
         "range": lambda y: np.max(y) - np.min(y)}

PENDULUM = """
[model]
name = "pendulum held by a spring"
gravity = 9.81

[[solid]]
name = "ground"
points = { O = [0.0, 0.0], S = [0.3, 0.2] }

[[solid]]
name = "arm"
fi = 0.1
mass = 0.5
inertia = 2e-3
cog = [0.1, 0.0]
points = { O = [0.0, 0.0], P = [0.2, 0.0] }

[[element]]
type = "fixed"
name = "base"
anc1 = "ground"

[[element]]
type = "revolute"
name = "O"
anc1 = "ground.O"
anc2 = "arm.O"

[[element]]
type = "spring"
name = "spring"
anc1 = "ground.S"
anc2 = "arm.P"
C = [0.0, 100.0, 0.1, 0.0]

[analysis]
type = "equilibrium"
"""

PENDULUM_STUDY = """
[study]
model = "pendulum.toml"
analysis = "{analysis}"
t_end = 0.1
steps = 4
method = "monte_carlo"
samples = 3
seed = 11
reduce = ["min", "max", "absmax", "mean", "rms", "final", "range"]
[[parameter]]
name = "spring.C2"
distribution = "uniform"
tol = 20.0
[[parameter]]
name = "arm.P.x"
distribution = "normal"
tol = 0.01
[[parameter]]
name = "arm.mass"
distribution = "triangular"
tol = 0.1
[[parameter]]
name = "model.gravity"
distribution = "normal"
std = 0.5
"""


def _close(a: float, b: float) -> bool:
    return abs(a - b) <= 1e-12 * max(abs(a), abs(b), 1e-300) or a == b


def _check_against_single_runs(result, model_text: str, source: str) -> None:
    """Every reduction of every variant equals a single run of ``varied`` at 1e-12."""
    s = result.study
    t = result.table
    assert t["status"].tolist() == ["ok"] * len(result)
    for i in range(len(result)):
        values = {name: float(t[name][i]) for name in s.names}
        single = pam2exu.run(varied(model_text, values, source), s.analysis, t_end=s.t_end,
                             steps=s.steps, outputs=s.outputs)
        want = {f"{c}.{r}": float(NUMPY[r](np.asarray(single[c]))) for c in single.columns
                for r in s.reduce}
        assert sorted(want) == sorted(result.outputs)
        for name, value in want.items():
            assert _close(float(t[name][i]), value), (s.analysis, i, name, t[name][i], value)
    final = next(n for n in result.outputs if n.endswith(".fi.final") and "ground" not in n)
    assert len({float(x) for x in t[final]}) == len(result)       # the variants differ


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    folder = tmp_path_factory.mktemp("free")
    (folder / "pendulum.toml").write_text(PENDULUM)
    return folder


@pytest.mark.parametrize("analysis", ["equilibrium", "dynamic"])
def test_a_variant_runs_as_a_single_run_would(analysis, folder):
    """0.7 s each: three variants and three single runs of a pendulum held by a spring."""
    text = PENDULUM_STUDY.format(analysis=analysis)
    result = study(loads_study(text, source=str(folder / "s.toml"), folder=folder))
    assert result.study.analysis == analysis
    rows = 1 if analysis == "equilibrium" else 5
    assert rows == len(pam2exu.run(pam2exu.loads(PENDULUM), analysis, t_end=0.1, steps=4).t)
    _check_against_single_runs(result, PENDULUM, str(folder / "pendulum.toml"))


def test_the_analyses_a_study_refuses_are_named_with_those_it_runs():
    refused = [a.name for a in ANALYSES.values() if not a.in_studies]
    runs = ", ".join(a.name for a in ANALYSES.values() if a.in_studies)
    assert {"equilibrium", "dynamic"} <= {a.name for a in ANALYSES.values() if a.in_studies}
    text = ('[study]\nmodel = "slider_crank.toml"\nanalysis = "{}"\nsamples = 2\n'
            '[[parameter]]\nname = "crank.A.x"\ndistribution = "normal"\ntol = 1e-4\n')
    for name in refused:
        with pytest.raises(pam2exu.ModelError, match=f"analysis = '{name}' is not available "
                           f"in a study yet: a study runs {runs} analyses today"):
            prepared(loads_study(text.format(name), folder=EXAMPLES))


EXAMPLE_STUDIES = {
    "equilibrium": ("equilibrium/spring_four_bar.toml", "", """
[[parameter]]
name = "spring.C2"
distribution = "normal"
tol = 20.0
[[parameter]]
name = "coupler.P.x"
distribution = "uniform"
tol = 0.005
"""),
    "dynamic": ("dynamics/andrews.toml", "t_end = 0.001\nsteps = 2\n", """
[[parameter]]
name = "spring.C2"
distribution = "normal"
tol = 300.0
[[parameter]]
name = "mom.C3"
distribution = "uniform"
tol = 0.003
[[parameter]]
name = "body3.D.x"
distribution = "normal"
tol = 1e-4
"""),
}


@pytest.mark.long                    # 10-20 s: the shipped models' runs take 0.4-2 s each
@pytest.mark.parametrize("analysis", EXAMPLE_STUDIES)
def test_the_shipped_examples_variants_run_as_single_runs(analysis):
    model, times, parameters = EXAMPLE_STUDIES[analysis]
    text = (f'[study]\nmodel = "{model}"\n{times}method = "latin_hypercube"\nsamples = 3\n'
            f'seed = 5\nreduce = ["absmax", "mean", "final"]\n{parameters}')
    result = study(loads_study(text, folder=EXAMPLES))
    assert result.study.analysis == analysis
    _check_against_single_runs(result, (EXAMPLES / model).read_text(), str(EXAMPLES / model))


@pytest.mark.long                    # 3 s: two worker processes start and import pam2exu
def test_a_dynamic_study_on_two_workers_gives_the_same_table_bit_for_bit(folder, monkeypatch):
    from pam2exu.studies import runner
    text = PENDULUM_STUDY.format(analysis="dynamic").replace("samples = 3", "samples = 5")
    whole = study(loads_study(text, folder=folder))
    monkeypatch.setattr(runner, "chunks_of", lambda s, w: [(0, 2), (2, 5)])
    again = study(loads_study(text, folder=folder), workers=2)
    assert list(again.table) == list(whole.table)
    for name, column in whole.table.items():
        other = again.table[name]
        assert np.array_equal(other.view(np.int64), column.view(np.int64)) \
            if column.dtype.kind == "f" else np.array_equal(other, column), name

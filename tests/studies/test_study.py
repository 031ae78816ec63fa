"""Reading a study file (pam2exu/studies/study.py): defaults from the model, and every
problem of the file in one ModelError naming the file, the entry and what to change."""
import shutil
import warnings
from pathlib import Path

import pytest

import pam2exu
from pam2exu.errors import InputWarning
from pam2exu.studies import load_study, loads_study
from pam2exu.studies.reduce import Requirement

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"

GOOD = '''
[study]
model = "four_bar.toml"
method = "latin_hypercube"
samples = 16
seed = 1
outputs = ["motor.*", "coupler.fi"]
reduce = ["absmax", "final"]

[[parameter]]
name = "coupler.B.x"
distribution = "normal"
tol = 1e-4

[[requirement]]
output = "motor.Mz.absmax"
max = 12.0
'''


def problems(text: str) -> list[str]:
    """The problems of a study on examples/four_bar.toml."""
    with pytest.raises(pam2exu.ModelError) as caught:
        loads_study(text, source="s.toml", folder=EXAMPLES)
    head = str(caught.value).splitlines()[0]
    assert head.startswith("s.toml: ")
    assert len(caught.value.problems) == 1 or head == \
        f"s.toml: {len(caught.value.problems)} problems in the study:"
    return [str(p) for p in caught.value.problems]


def test_a_study_file_beside_its_model_with_the_models_defaults(tmp_path):
    shutil.copy(EXAMPLES / "four_bar.toml", tmp_path)
    (tmp_path / "study.toml").write_text(GOOD)
    study = load_study(tmp_path / "study.toml")
    # examples/four_bar.toml's [analysis]: kinematic, t_end = 1, steps = 200
    assert (study.analysis, study.t_end, study.steps) == ("kinematic", 1.0, 200)
    assert study.model_path == tmp_path / "four_bar.toml"
    assert study.model_text == (EXAMPLES / "four_bar.toml").read_text()
    assert (study.method, study.samples, study.seed, study.series) == \
        ("latin_hypercube", 16, 1, False)
    assert study.requirements == [Requirement("motor.Mz.absmax", None, 12.0)]
    p = study.parameters[0]
    assert (p.name, p.nominal, p.unit, p.sigma) == ("coupler.B.x", 0.35, "m",
                                                    pytest.approx(1e-4 / 3, rel=1e-15))
    assert study.variants().shape == (16, 1)


def test_defaults_of_a_minimal_study():
    study = loads_study('[study]\nmodel = "four_bar.toml"\nsamples = 4\n[[parameter]]\n'
                        'name = "model.gravity"\ndistribution = "uniform"\nlow = 9.7\n'
                        'high = 9.9\n', folder=EXAMPLES)
    assert (study.method, study.seed, study.outputs, study.reduce) == \
        ("monte_carlo", 0, None, ["min", "max", "absmax", "mean", "rms", "final", "range"])


def test_a_grid_runs_the_product_of_its_values_lists():
    study = loads_study('[study]\nmodel = "four_bar.toml"\nmethod = "grid"\n'
                        '[[parameter]]\nname = "coupler.B.x"\nvalues = [0.34, 0.35, 0.36]\n'
                        '[[parameter]]\nname = "crank.A.x"\nvalues = [0.09, 0.1]\n',
                        folder=EXAMPLES)
    assert study.samples == 6 and study.variants(4, 6).tolist() == [[0.36, 0.09], [0.36, 0.1]]


def test_every_problem_at_once_each_naming_its_entry():
    found = problems('''
[study]
model = "four_bar.toml"
method = "monte_carlo"
samples = 0
sed = 1
reduce = ["absmax", "maen"]
outputs = ["motor.*"]

[[parameter]]
name = "coupler.B.z"
distribution = "normal"
tol = 1e-4

[[parameter]]
name = "crank.A.x"
distribution = "normal"
std = -1e-4

[[parameter]]
name = "crank.A.x"
distribution = "uniform"
low = 0.2
high = 0.1

[[parameter]]
name = "rocker.mass"
distribution = "nromal"
tol = 0.01

[[requirement]]
output = "motor.Mz.rms"
max = 12.0

[[requirement]]
output = "coupler.fi.absmax"
min = 0.5
''')
    expected = [
        "[study]: unknown key 'sed' (did you mean 'seed'?); allowed keys: model, analysis, "
        "t_end, steps, method, samples, seed, outputs, reduce, series, backend, batched",
        "[study]: samples must be a whole number ≥ 1, got 0",
        "[study]: unknown reduction 'maen' (did you mean 'mean'?); known: min, max, absmax, "
        "mean, rms, final, range",
        "[[parameter]] #1 'coupler.B.z': the model has no number 'coupler.B.z' to vary; the "
        "closest: coupler.B.y, coupler.B.x, coupler.P.y, coupler.P.x, coupler.A.y",
        "[[parameter]] #2 'crank.A.x': std = -0.0001 must be > 0 (a parameter that does not "
        "vary needs no [[parameter]])",
        "[[parameter]] #3 'crank.A.x': 'crank.A.x' is varied by [[parameter]] #2 'crank.A.x' "
        "already: give each parameter once",
        "[[parameter]] #3 'crank.A.x': low = 0.2 must be less than high = 0.1",
        "[[parameter]] #4 'rocker.mass': unknown distribution 'nromal' (did you mean "
        "'normal'?); known: normal, "
        "uniform, triangular, values",
        "[[requirement]] #1 'motor.Mz.rms': 'motor.Mz.rms' is not a reduced output: it must "
        "end in one of the study's reductions (absmax), as 'motor.Mz.absmax'; or "
        "add 'rms' to [study] reduce",
        "[[requirement]] #2 'coupler.fi.absmax': 'coupler.fi' is not among the study's "
        "outputs (motor.*): add it to [study] outputs, or require a reduced output of them",
    ]
    assert found == expected


def test_unknown_method_and_samples_not_whole():
    found = problems('[study]\nmodel = "four_bar.toml"\nmethod = "latin_hypercub"\n'
                     'samples = 2.5\n[[parameter]]\nname = "crank.mass"\ntol = 0.01\n'
                     'distribution = "triangular"\n')
    assert found == ["[study]: unknown method 'latin_hypercub' (did you mean "
                     "'latin_hypercube'?); known methods: monte_carlo, latin_hypercube, sobol, "
                     "grid, linear"]
    found = problems('[study]\nmodel = "four_bar.toml"\nsamples = 2.5\n[[parameter]]\n'
                     'name = "crank.mass"\ntol = 0.01\ndistribution = "triangular"\n')
    assert found == ["[study]: samples must be a whole number ≥ 1, got 2.5"]


def test_grid_without_values_and_a_normal_without_its_width():
    found = problems('[study]\nmodel = "four_bar.toml"\nmethod = "grid"\n[[parameter]]\n'
                     'name = "crank.mass"\ndistribution = "normal"\n[[parameter]]\n'
                     'name = "model.gravity"\nvalues = [9.81, 1.62]\n')
    assert found == ["[[parameter]] #1 'crank.mass': a grid study needs a 'values' list for "
                     "every parameter",
                     "[[parameter]] #1 'crank.mass': a normal distribution takes tol (3σ) or "
                     "std (σ), one of them"]


def test_a_missing_model_file_names_the_path_tried(tmp_path):
    (tmp_path / "study.toml").write_text(GOOD)
    with pytest.raises(pam2exu.ModelError) as caught:
        load_study(tmp_path / "study.toml")
    assert str(caught.value) == (
        f"{tmp_path / 'study.toml'}: [study]: model = 'four_bar.toml': cannot read "
        f"'{tmp_path / 'four_bar.toml'}' (No such file or directory); the path is relative "
        "to the study file's folder")


def test_sobol_warns_when_samples_is_not_a_power_of_two():
    text = GOOD.replace('"latin_hypercube"', '"sobol"')
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert loads_study(text, folder=EXAMPLES).samples == 16       # 2⁴: no warning
    with pytest.warns(InputWarning, match=r"samples = 20 is not a power of 2: .*use 16 or 32"):
        study = loads_study(text.replace("samples = 16", "samples = 20"), folder=EXAMPLES)
    assert study.variants().shape == (20, 1)       # the first 20 points of the sequence


def test_zero_tol_a_uniform_with_low_high_and_mean_and_outputs_not_a_list():
    found = problems('[study]\nmodel = "four_bar.toml"\nsamples = 4\noutputs = "motor.*"\n'
                     '[[parameter]]\nname = "crank.mass"\ntol = 0.0\ndistribution = "normal"\n'
                     '[[parameter]]\nname = "rocker.mass"\ndistribution = "uniform"\n'
                     'low = 0.5\nhigh = 0.7\nmean = 0.6\n'
                     '[[requirement]]\noutput = "motor.Mz.absmax"\nmax = 1.0\n')
    assert found == [
        "[study]: outputs must be a list of names or patterns, e.g. [\"crank.*\", \"Fx\"]",
        "[[parameter]] #1 'crank.mass': tol = 0.0 must be > 0 (a parameter that does not vary "
        "needs no [[parameter]])",
        "[[parameter]] #2 'rocker.mass': a uniform distribution between low and high takes no "
        "mean (mean ± tol is the other way to give it)"]


def test_a_study_of_absurdly_many_variants_is_refused_before_anything_is_drawn():
    """10¹² variants (or a grid of 31⁵ ≈ 2.9·10⁷) would be drawn and held in memory: refused
    naming the entry; a million, within the limit, give a yield of 99 % within ± 0.02 %."""
    found = problems('[study]\nmodel = "four_bar.toml"\nsamples = 1000000000000\n'
                     '[[parameter]]\nname = "crank.mass"\ntol = 0.01\n'
                     'distribution = "normal"\n')
    assert found == ["[study]: samples = 1,000,000,000,000: more than a study runs (at most "
                     "10,000,000; every variant's values and row are held in memory): run "
                     "fewer, a million give a yield of 99 % within ± 0.02 %"]
    values = "values = [" + ", ".join(str(0.3 + k / 1000) for k in range(31)) + "]"
    grid = '[study]\nmodel = "four_bar.toml"\nmethod = "grid"\n' + "".join(
        f'[[parameter]]\nname = "{name}"\n{values}\n'
        for name in ("crank.mass", "coupler.mass", "rocker.mass", "coupler.B.x", "rocker.B.x"))
    assert problems(grid) == ["[[parameter]]: the values lists make a grid of 28,629,151 "
                              "variants: more than a study runs (at most 10,000,000; every "
                              "variant's values and row are held in memory): run fewer, a "
                              "million give a yield of 99 % within ± 0.02 %"]
    from pam2exu.studies.summary import wilson_interval
    low, high = wilson_interval(990_000, 1_000_000)
    assert 0.99 - 0.0002 < low < high < 0.99 + 0.0002
    study = loads_study(grid.replace(values, "values = [0.3, 0.31]"), folder=EXAMPLES)
    assert study.samples == 32 and study.variants().shape == (32, 5)

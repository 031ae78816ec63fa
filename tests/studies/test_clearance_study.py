"""Clearance studies (shared/spec/studies.md, "Clearance studies"; docs/studies.md): a
variant's points and lines are fixed deviations from the nominal dimensions, reached at
t = 0 from the nominal assembly along the straight path u0 + s δ (the model's
``[[variation]]`` ``fixed_dx``, ``fixed_dy``, ``fixed_dangle``, docs/clearance.md).

References: each variant's reductions against a single ``pam2exu run`` of the model file
with the variant's deviations written into its text by hand (string edits of the TOML, not
``parameters.varied``), its CSV reduced with NumPy; the state at t = 0 against Newton's
continuation along the straight path (``least_norm.step_by_step``, no ODE) and against the
time path of a ramp that has settled (``dx`` = 2 δ, ω = 0, τ small: another code path).
"""
import csv
import warnings
from pathlib import Path

import numpy as np
import pytest

import pam2exu
from pam2exu.analyses.clearance import Closures
from pam2exu.analyses.least_norm import kkt_residual, lagrange, step_by_step
from pam2exu.cli import main
from pam2exu.studies.summary import needed_for_yield
from pam2exu.studies.runner import study

ROOT = Path(__file__).resolve().parents[2]
LOCOMOTIVE = (ROOT / "examples/clearance/locomotive.toml").read_text(encoding="utf-8")
REDUCE = ["min", "max", "absmax", "mean", "rms", "final", "range"]
NUMPY = {"min": np.min, "max": np.max, "absmax": lambda y: np.max(np.abs(y)),
         "mean": np.mean, "rms": lambda y: np.sqrt(np.mean(y * y)), "final": lambda y: y[-1],
         "range": lambda y: np.max(y) - np.min(y)}
#: the study's parameters: (name, nominal, how its deviation is written by hand: the
#: [[variation]] line it goes below, or None for a new entry of that anchor)
PARAMETERS = (("frame.O2.x", 1.5, 'anchor = "frame.O2"', "fixed_dx"),
              ("wheel2.A.x", 0.25, None, "fixed_dx"),
              ("frame.O3.y", 0.0, None, "fixed_dy"),
              ("rod.B3.x", 3.0, None, "fixed_dx"))
STUDY = """
[study]
model = "locomotive.toml"
analysis = "clearance"
t_end = 0.2
steps = 2
method = "monte_carlo"
samples = 3
seed = 11
outputs = ["pin2.j*", "pin3.jr"]
reduce = ["min", "max", "absmax", "mean", "rms", "final", "range"]
""" + "".join(f'[[parameter]]\nname = "{name}"\ndistribution = "normal"\ntol = 3e-4\n'
              for name, *_ in PARAMETERS)


def by_hand(values, tmp_path: Path, k: int) -> dict[str, float]:
    """The reductions of ``pam2exu run`` of the locomotive with the variant's deviations
    (value − nominal) written into its text: below the model's own entry of the anchor, or
    as a new ``[[variation]]``; its result CSV reduced with NumPy (absolute values)."""
    text = LOCOMOTIVE.replace("steps = 400", "steps = 2").replace(
        "t_end = 9.66643893412244", "t_end = 0.2")
    for (name, nominal, below, key), value in zip(PARAMETERS, values):
        line = f"{key} = {float(value - nominal)!r}"
        if below is not None:
            assert text.count(below) == 1
            text = text.replace(below, f"{below}\n{line}")
        else:
            anchor = name.rpartition(".")[0]
            head, _, tail = text.partition("[analysis]")
            text = f'{head}[[variation]]\nanchor = "{anchor}"\n{line}\n\n[analysis]{tail}'
    model, out = tmp_path / f"v{k}.toml", tmp_path / f"v{k}.csv"
    model.write_text(text, encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert main(["run", str(model), "-o", str(out)]) == 0
    rows = list(csv.reader(open(out, encoding="utf-8")))
    columns = {h: np.array([float(r[i]) for r in rows[1:]]) for i, h in enumerate(rows[0])}
    return {f"{c}.{r}": float(NUMPY[r](np.abs(columns[c]))) for c in
            ("pin2.jx", "pin2.jy", "pin2.jr", "pin3.jr") for r in REDUCE}


def run_study(tmp: Path, samples: int, text: str = STUDY):
    """The study of ``samples`` random variants of the locomotive (4 deviations each), and
    each variant's single run by hand."""
    (tmp / "locomotive.toml").write_text(LOCOMOTIVE, encoding="utf-8")
    (tmp / "s.toml").write_text(text, encoding="utf-8")
    result = study(tmp / "s.toml", samples=samples)
    names = [p[0] for p in PARAMETERS]
    return result, [by_hand([result.table[n][k] for n in names], tmp, k)
                    for k in range(samples)]


def check_equal(result, hand):
    """Every reduction of every variant equals its single run's, to 1e-12 relative."""
    assert result.table["status"].tolist() == ["ok"] * len(hand)
    assert len(result.outputs) == 4 * len(REDUCE)
    for k, reduced in enumerate(hand):
        for name in result.outputs:
            got, want = result.table[name][k], reduced[name]
            assert abs(got - want) <= 1e-12 * abs(want), (k, name, got, want)
    # clearances of the order of the deviations
    assert np.all((result.table["pin2.jr.max"] > 1e-5) & (result.table["pin2.jr.max"] < 2e-3))


def test_a_variant_equals_a_single_run_with_its_deviations_and_reports_its_clearance(tmp_path):
    """One variant (about 2 s): its reductions are the single run's; the report's line is
    its jr.max, the q99 of one value."""
    result, hand = run_study(tmp_path, 1)
    check_equal(result, hand)
    assert result.clearance_needed() == {n: result.table[n][0]
                                         for n in ("pin2.jr.max", "pin3.jr.max")}
    value = result.table["pin2.jr.max"][0]
    assert (f"radial clearance for a 99 % yield: pin2 needs {value:.4g} m (pin2.jr.max, its "
            f"q99 over the 1 variants)") in result.report()


@pytest.mark.long
def test_every_reduction_of_three_random_variants_equals_a_single_run(tmp_path):
    """Three random variants (about 6 s); the clearance a 99 % yield needs is each joint's
    q99 of jr.max, the summary's."""
    result, hand = run_study(tmp_path, 3)
    check_equal(result, hand)
    assert len(set(result.table["pin2.jr.max"])) == 3
    needed = result.clearance_needed()
    assert list(needed) == ["pin2.jr.max", "pin3.jr.max"]
    for name, value in needed.items():
        y = np.sort(result.table[name])
        assert value == pytest.approx(y[1] + 0.98 * (y[2] - y[1]), rel=1e-14)  # (n − 1) 0.99
        assert value == next(r for r in result.summary if r.output == name).q99
        assert f"radial clearance for a 99 % yield: {name.split('.')[0]} needs {value:.4g} m " \
               f"({name}, its q99 over the 3 variants)" in result.report()


@pytest.mark.long
def test_deviations_that_cannot_be_absorbed_are_a_row_in_error(tmp_path, capsys):
    """Axle 3 30 cm off (about 10 s: the integration crawls to the fold of the least-norm
    clearance): status error with the message, the study exits 0, and no clearance reaches
    a 99 % yield with one variant of two in error."""
    text = STUDY.replace('method = "monte_carlo"', 'method = "grid"').replace(
        "samples = 3\n", "")
    text = text[:text.index("[[parameter]]")] + (
        '[[parameter]]\nname = "frame.O3.y"\ndistribution = "values"\nvalues = [1e-4, 0.3]\n')
    (tmp_path / "locomotive.toml").write_text(LOCOMOTIVE, encoding="utf-8")
    (tmp_path / "s.toml").write_text(text, encoding="utf-8")
    assert main(["study", str(tmp_path / "s.toml"), "-o", str(tmp_path / "o.csv"),
                 "--workers", "1"]) == 0
    out = capsys.readouterr().out
    rows = list(csv.DictReader(open(tmp_path / "o.csv", encoding="utf-8")))
    assert [r["status"] for r in rows] == ["ok", "error"]
    assert rows[1]["error"].startswith("SolverError: t=0: the clearance of least norm of ")
    assert "cannot absorb the fixed deviations of its [[variation]] entries" in rows[1]["error"]
    assert rows[1]["pin2.jr.max"] == "" and float(rows[0]["pin2.jr.max"]) > 0
    assert "1 × SolverError: t=0: the clearance of least norm of" in out
    assert ("radial clearance for a 99 % yield: none is enough for pin2: 1 of 2 variants are "
            "in error, and the q99 over all of them falls among those") in out


def test_variants_in_error_count_against_the_yield_of_a_clearance():
    """yield = share ok over every variant: one in error of 200 leaves the 99 % quantile
    among the others; three of 200 put it out of reach."""
    y = np.arange(200, dtype=float)
    statuses = ["ok"] * 200
    statuses[5] = "error"                      # its value is not a clearance
    y[5] = np.nan
    # order statistics of 199 values and one +inf: (n − 1) 0.99 = 197.01, between 198, 199
    assert needed_for_yield(y, statuses) == pytest.approx(198 + 0.01 * 1, rel=1e-13)
    assert needed_for_yield(np.arange(200.0), ["ok"] * 200) == np.quantile(np.arange(200.0),
                                                                            0.99)
    for k in (5, 17, 80):
        statuses[k] = "error"
    assert needed_for_yield(y, statuses) == np.inf


def _fixed_only(t_end: float = 1.0, steps: int = 1, **keys) -> pam2exu.Model:
    """The locomotive without its own variations, axle 2 and crank 3 as made."""
    text = LOCOMOTIVE[:LOCOMOTIVE.index("[[variation]]")]
    text += ('[[variation]]\nanchor = "frame.O2"\n'
             + "".join(f"{k} = {v!r}\n" for k, v in keys.items())
             + '\n[[variation]]\nanchor = "wheel3.A"\nfixed_dx = 4e-4\n\n'
             + f'[analysis]\ntype = "clearance"\nt_end = {t_end}\nsteps = {steps}\n')
    return pam2exu.loads(text)


def test_the_dimensions_as_made_are_reached_at_t0_along_the_straight_path():
    """The row t = 0 of fixed deviations: the closure holds at u0 + δ, j is a least norm
    (KKT), and it is Newton's continuation from the nominal assembly along u0 + s δ in 40
    steps of s (no ODE), to 1e-12 relative."""
    model = _fixed_only(fixed_dx=3e-4, fixed_dy=-2e-4)
    res = pam2exu.run(model, t_end=0.1, steps=1)
    mech = model.mechanism()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")                  # redundant: the nominal loop
        nominal = pam2exu.run(model, "assembly")
    q0 = np.array([nominal[f"{s.name}.{c}"][0] for s in mech.solids for c in ("x", "y", "fi")])
    closures = Closures(mech, q0)
    p, nq, m = closures.p, closures.nq, closures.m
    path = np.linspace(0.0, 1.0, 41)
    y, ok = step_by_step(lambda s, q, lam: closures.evaluate(0.0, q, lam, reached=s), path,
                         np.r_[np.zeros(p), q0, np.zeros(m)], p, nq)
    assert ok.all()
    j = np.array([res[n][0] for n in closures.names])
    assert np.max(np.abs(j - y[-1, :p])) <= 1e-12 * np.max(np.abs(j))
    q = np.array([res[f"{s.name}.{c}"][0] for s in mech.solids for c in ("x", "y", "fi")])
    c = closures.evaluate(0.0, q, np.zeros(m))
    assert np.max(np.abs(c.F + c.Fj @ j)) <= 1e-10
    assert kkt_residual(j, c) <= 1e-8 * np.max(np.abs(j))
    assert np.max(np.abs(j)) > 1e-4                  # a clearance of the deviations' size


@pytest.mark.long
def test_a_fixed_deviation_equals_a_settled_ramp_of_twice_its_range():
    """(About 5 s.) u0 + δ at t = 0 and for ever (fixed_dx) is the ramp u0 + (1 − e^(−t/τ)) (Δ/2) with
    Δ = 2δ, ω = 0, once e^(−t/τ) = 0 in floating point: the clearance and the positions at
    t = 1 s agree (the time path, another branch of the code, followed to 1e-10)."""
    fixed = pam2exu.run(_fixed_only(fixed_dx=3e-4, fixed_dy=-2e-4), t_end=1.0, steps=1)
    ramp = pam2exu.run(_fixed_only(dx=6e-4, dy=-4e-4, w=0.0, tau=1e-3), t_end=1.0, steps=1)
    assert np.exp(-1.0 / 1e-3) == 0.0
    for c in fixed.columns:
        assert abs(fixed[c][-1] - ramp[c][-1]) <= 1e-11, c

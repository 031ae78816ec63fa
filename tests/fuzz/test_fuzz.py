"""The mutation fuzzer (issue 10): the generator, the runner's classification, and a
fixed-seed campaign that must find no fault (``--fuzz-long``: 10,000 mutants instead)."""
import os
import signal
import time
import tomllib

import numpy as np
import pytest

import pam2exu

from . import runner
from .mutants import KINDS, SOURCES, dumps, generate, mutant, source_doc

#: the CI campaign: seeds CI_SEED … CI_SEED + CI_COUNT - 1 on 2 workers. Its verdict reads
#: no clock: each case's work is bounded by the fast campaign's caps (mutants.py), and the
#: runner's hang guard (runner.TIMEOUT, 600 s) only aborts a true hang
CI_SEED, CI_COUNT = 0, 200
LONG_COUNT = 10_000


def _seed_of(source, n_mutations=0):
    """A seed whose mutant is made from ``source``."""
    return next(s for s in range(1000) if generate(s, n_mutations).source == source)


# ------------------------------------------------------------------------- the generator

def test_same_seed_same_bytes():
    for seed in range(300):
        first, again = mutant(seed), mutant(seed)
        assert first == again, seed
    assert len({mutant(seed)[1] for seed in range(300)}) > 250


def test_every_kind_is_produced_and_applies():
    applied = {}
    for seed in range(3000):
        m = generate(seed)
        assert 1 <= len(m.kinds) <= 3
        for kind, note in zip(m.kinds, m.notes, strict=True):
            applied.setdefault(kind, 0)
            applied[kind] += "not applicable" not in note
    assert set(applied) == set(KINDS)
    assert all(applied.values()), [k for k, v in applied.items() if not v]


def test_writer_round_trips_every_source():
    for source in SOURCES:
        doc = source_doc(source)
        assert tomllib.loads(dumps(doc)) == doc, source


def test_unchanged_mutant_is_the_source():
    for source in SOURCES:
        m = generate(_seed_of(source), n_mutations=0)
        assert m.kinds == [] and m.description.endswith("(unchanged)")
        assert tomllib.loads(m.data.decode("utf-8")) == source_doc(source)


def test_cp1252_mutant_is_not_utf8():
    seeds = [s for s in range(2000) if generate(s).kinds == ["cp1252"]]
    assert len(seeds) >= 5
    for seed in seeds:
        data = generate(seed).data
        with pytest.raises(UnicodeDecodeError):
            data.decode("utf-8")
        text = data.decode("cp1252")
        assert any(ord(ch) > 127 for ch in text)
        tomllib.loads(text)                 # valid TOML once decoded as Windows-1252


# ------------------------------------------------------------------------- the runner

#: the clearance examples' unchanged runs take 5-6 s each (idle, 2 cores): with --long
LONG_SOURCES = ("examples/clearance/locomotive.toml",
                "examples/clearance/slider_guided_twice.toml")


@pytest.mark.parametrize("source", [pytest.param(s, marks=pytest.mark.long)
                                    if s in LONG_SOURCES else s for s in SOURCES])
def test_unchanged_model_is_classified_success(source):
    outcome = runner.run_case(_seed_of(source), timeout=runner.TIMEOUT, n_mutations=0,
                              cli=True)
    expected = "clean error" if source.endswith("every_element.toml") else "success"
    # every_element.toml does not assemble (it is for Jacobians at arbitrary poses)
    assert (outcome.status, outcome.fault) == (expected, ""), outcome
    assert outcome.calls >= 5          # 2 in-process, run, check, run -o out.csv, …


def _patched_case(monkeypatch, fake, timeout=None):
    monkeypatch.setattr(pam2exu, "run", fake)
    return runner.run_case(_seed_of("examples/four_bar.toml"), timeout=timeout,
                           n_mutations=0, cli=False)


def test_runner_classifies_an_exception(monkeypatch):
    def fake(path, analysis=None):
        raise ValueError("boom")
    outcome = _patched_case(monkeypatch, fake)
    assert outcome.status == "fault"
    assert outcome.fault.startswith("exception ValueError at ")
    assert outcome.message == "ValueError: boom"


def test_runner_classifies_a_self_declared_fault_as_its_cause(monkeypatch):
    def fake(path, analysis=None):
        try:
            raise IndexError("list index out of range")
        except IndexError as exc:
            raise pam2exu.SolverError("the kinematic analysis of m.toml failed unexpectedly "
                                      "(IndexError). This is a fault of pam2exu") from exc
    outcome = _patched_case(monkeypatch, fake)
    assert outcome.fault.startswith("exception IndexError at ")
    assert "raised as SolverError" in outcome.message


def test_runner_notes_a_foreign_cause_of_a_clean_error(monkeypatch):
    def fake(path, analysis=None):
        try:
            float("x")
        except ValueError as exc:
            raise pam2exu.ModelError("'x' is not a number") from exc
    outcome = _patched_case(monkeypatch, fake)
    assert outcome.status == "clean error" and outcome.cause.startswith("ValueError at ")


def test_runner_classifies_an_empty_message(monkeypatch):
    def fake(path, analysis=None):
        raise pam2exu.SolverError("")
    assert _patched_case(monkeypatch, fake).fault == "empty message SolverError"


def test_runner_accepts_a_clean_error(monkeypatch):
    def fake(path, analysis=None):
        raise pam2exu.ModelError("no solids")
    outcome = _patched_case(monkeypatch, fake)
    assert (outcome.status, outcome.fault) == ("clean error", "")


def test_runner_classifies_non_finite_values(monkeypatch):
    def fake(path, analysis=None):
        return pam2exu.Results([0.0, 1.0], {"crank.fi": [0.0, np.nan]})
    assert _patched_case(monkeypatch, fake).fault == "non-finite"


def test_runner_classifies_a_csv_that_does_not_read_back(monkeypatch):
    def fake(path, analysis=None):
        return pam2exu.Results([0.0, 1.0], {"a\nb.fi": [0.0, 1.0]})     # a line break
    assert _patched_case(monkeypatch, fake).fault == "csv"


def test_runner_classifies_a_stray_file(monkeypatch):
    def fake(path, analysis=None):
        open("left_over.txt", "w").close()
        return pam2exu.Results([0.0, 1.0], {"crank.fi": [0.0, 1.0]})
    outcome = _patched_case(monkeypatch, fake)
    assert outcome.fault == "stray file" and "left_over.txt" in outcome.message


def test_runner_interrupts_a_hang(monkeypatch):
    """A case that never ends is interrupted by the guard and classified a hang (no clock
    read here: without the interruption the fake would sleep for an hour)."""
    def fake(path, analysis=None):
        time.sleep(3600)
    outcome = _patched_case(monkeypatch, fake, timeout=0.5)
    assert outcome.fault == "hang" and outcome.sub == "interrupted"
    assert signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)


def test_campaign_kills_hung_and_replaces_dead_workers(monkeypatch):
    def fake(path, analysis=None):
        if "scotch_yoke" in path or "slider_crank" in path:
            os._exit(3)                                              # a crash
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGALRM})   # a hang SIGALRM
        time.sleep(60)                                               # cannot interrupt
    monkeypatch.setattr(pam2exu, "run", fake)
    # the guard's 3 + 3 s leave a crashing case, which ends at once, time to start even on a
    # busy machine; the hung ones cost 6 s each
    result = runner.campaign(6, workers=2, seed=0, timeout=3.0, margin=3.0)
    assert sum(result.counts.values()) == 6
    assert set(result.faults) <= {"hang", "crash"} and result.n_faults == 6
    crashed = {o.seed for o in result.faults.get("crash", [])}
    assert crashed == {s for s in range(6)
                       if any(n in generate(s).name for n in ("scotch_yoke", "slider_crank"))}
    assert all(o.sub == "killed" for o in result.faults.get("hang", []))


# ------------------------------------------------------------------------- the campaign

def test_fuzz_campaign(request):
    """A fixed-seed campaign: every mutant runs or stops on a clean Pam2ExuError."""
    count = LONG_COUNT if request.config.getoption("--fuzz-long") else CI_COUNT
    result = runner.campaign(count, workers=2, seed=CI_SEED)
    print(result.summary())
    assert result.n_faults == 0, "\n" + result.report()

"""How a clearance run ends when the least-norm clearance cannot be followed (issue 22, items 4
and 6): the time where the integration stopped, the condition there, what to try, the rows
before it kept (``SolverError.partial``, ``pam2exu run --partial``); a variation faster than
the output grid refused before the run; a run that crawls ended by the work limit.

The near-dead-centre triple crank is tests/data/triple_crank_dead_centre.toml (the locomotive
linkage driven to 0.02 rad of its dead centre at t = 5 s). Before, its run said
``t=0.5: … could not be followed to here`` (the first row: every row was discarded).
"""
import warnings
from pathlib import Path

import numpy as np
import pytest

import pam2exu
from pam2exu.analyses import least_norm as ln
from pam2exu.analyses.clearance import Closures
from pam2exu.cli import main

ROOT = Path(__file__).resolve().parents[2]
TRIPLE = ROOT / "tests" / "data" / "triple_crank_dead_centre.toml"


def _run(model, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return pam2exu.run(model, **kw)


@pytest.fixture(scope="module")
def lost():
    """The SolverError of the triple crank's clearance run (12 steps of 0.5 s)."""
    with pytest.raises(pam2exu.SolverError) as error:
        _run(TRIPLE)
    return error.value


def test_the_failure_names_the_time_where_the_integration_stopped(lost):
    """The time named is where the integration stopped: after the last row kept and within
    one output step of it (measured: 4.40 s, rows kept up to 4 s)."""
    dt = 0.5
    assert str(lost).startswith(f"t={lost.time:.6g}: the clearance of least norm of ")
    assert str(TRIPLE) in str(lost)
    last = lost.partial.t[-1]
    assert last < lost.time <= last + dt
    assert 4.0 < lost.time < 5.0                    # before the dead centre at t = 5 s
    assert lost.step == round(last / dt) + 1        # the first row not computed
    text = str(lost)
    assert "reduced Hessian" in text and "dead centre" in text
    assert "Try clearance = true on another joint" in text and "smaller variations" in text
    assert f"t_end below {lost.time:.6g} s" in text


def test_the_rows_before_the_failure_are_kept_and_right(lost):
    """``partial``: the rows of the grid before the failure (measured: 0 … 4 s) with the run's
    columns, equal to Newton step by step on the Lagrange conditions (the reference of
    tests/analyses/test_clearance.py)."""
    part = lost.partial
    assert len(part) >= 9
    np.testing.assert_allclose(part.t, 0.5 * np.arange(len(part)), atol=1e-12)
    mech = pam2exu.load(TRIPLE).mechanism()
    q = np.column_stack([part[f"{s.name}.{k}"] for s in mech.solids for k in ("x", "y", "fi")])
    closures = Closures(mech, q[0])
    assert part.columns[-6:] == ["pin2.jx", "pin2.jy", "pin2.jr", "pin3.jx", "pin3.jy",
                                 "pin3.jr"]
    y0 = np.r_[np.zeros(closures.p), q[0], np.zeros(closures.m)]
    y, ok = ln.step_by_step(closures.evaluate, part.t, y0, closures.p, closures.nq)
    assert ok.all()
    j = np.column_stack([part[name] for name in closures.names])
    np.testing.assert_allclose(y[:, :closures.p], j, atol=1e-9)
    np.testing.assert_allclose(y[:, closures.p:closures.p + closures.nq], q, atol=1e-9)
    assert np.max(np.abs(j)) > 1e-5


def test_run_partial_writes_the_rows_kept(lost, tmp_path, monkeypatch, capsys):
    """``pam2exu run --partial -o FILE``: the rows of ``partial`` in FILE, exit status 1
    and the error's message; without --partial nothing is written; --partial without -o
    is refused before the run."""
    import pam2exu.analyses

    def fails(*args, **kw):
        raise lost
    monkeypatch.setattr(pam2exu.analyses, "run", fails)
    out = tmp_path / "kept.csv"
    assert main(["run", str(TRIPLE), "--partial", "-o", str(out)]) == 1
    printed = capsys.readouterr()
    assert f"wrote the {len(lost.partial)} rows before the failure to" in printed.out
    assert f"t={lost.time:.6g}: the clearance of least norm" in printed.err
    back = pam2exu.read_csv(out)
    np.testing.assert_array_equal(back.t, lost.partial.t)
    for name in lost.partial.columns:
        np.testing.assert_allclose(back[name], lost.partial[name], rtol=1e-15, atol=0)
    other = tmp_path / "none.csv"
    assert main(["run", str(TRIPLE), "-o", str(other)]) == 1
    assert not other.exists()
    assert main(["run", str(TRIPLE), "--partial"]) == 2
    assert "--partial writes the rows kept before a failure" in capsys.readouterr().err


def test_a_variation_faster_than_the_output_grid_is_refused(tmp_path):
    """Issue 22, item 6 (fuzz): w = 1e6 rad/s on the second guide made the integration crawl
    for ever. ω t_end/steps above π is a ModelError naming the file, the entry, the key and
    what would do; at π it runs (the slider example, 4 steps: w = π · 4 / 2 s)."""
    text = (ROOT / "examples/clearance/slider_guided_twice.toml").read_text()
    fast = tmp_path / "fast.toml"
    fast.write_text(text.replace("wy = 0.8", "wy = 1e6"))
    with pytest.raises(pam2exu.ModelError) as error:
        _run(fast)
    message = str(error.value)
    assert message.startswith(f"{fast}: [[variation]] #1 (anchor 'ground.slot'): 'wy' = "
                              "1e+06 rad/s is too fast for the output grid")
    assert "ω·t_end/steps = 5e+03 rad" in message
    assert "steps ≥ 636620" in message and "'wy' ≤ 628.3 rad/s" in message
    limit = tmp_path / "limit.toml"
    limit.write_text(text.replace("wy = 0.8", f"wy = {np.pi * 4 / 2.0!r}")
                     .replace("steps = 400", "steps = 4"))
    assert len(_run(limit)) == 5
    with pytest.raises(pam2exu.ModelError, match="'wy' = 6.28319 rad/s is too fast"):
        _run(limit, steps=3)
    assert len(_run(limit, analysis="kinematic", steps=3)) == 4   # only clearance reads it


def test_a_run_that_crawls_ends_with_the_time_and_the_cause(tmp_path, monkeypatch):
    """Issue 22, item 6 (fuzz): the locomotive example with [model] angles = "deg" (its
    cranks then start 1.57° from their dead centre and swing 1.2° about it) never ended, its
    steps shrinking (with h_t by central differences, whose round-off the integrator's error
    control chased near the dead centre). Since issue 25 (h_t exact) it runs through in at
    most 8 steps per output step; the work limit, set to 2 steps here, ends it with the time
    and the cause."""
    text = (ROOT / "examples/clearance/locomotive.toml").read_text()
    deg = tmp_path / "locomotive_deg.toml"
    deg.write_text(text.replace('gravity = 0.0', 'gravity = 0.0\nangles = "deg"')
                   .replace("steps = 400", "steps = 60"))
    monkeypatch.setattr(ln, "MAX_STEPS", 2)
    with pytest.raises(pam2exu.SolverError) as error:
        _run(deg)
    lost = error.value
    text = str(lost)
    assert text.startswith(f"t={lost.time:.6g}: the clearance of least norm of {deg}")
    assert "the integration took 2 steps in one output step" in text
    dt = 9.66643893412244 / 60
    last = lost.partial.t[-1] if lost.partial is not None else 0.0
    assert last < lost.time <= last + dt

"""What a run evaluates once (issue 25, the per-run fixed costs), checked by counting the
evaluations and comparing bits, never by time: the mobility check's one evaluation of the
equations at the guess, a short run's condition numbers from the Jacobian the rates were
computed with, the natural backend's one-pass Φ and Φ_z for a few steps. References: the
same quantities evaluated separately (``native.equations``, ``Terms.residual_cols`` and
``jacobian_cols``)."""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import pam2exu
from pam2exu.analyses import job as job_module
from pam2exu.analyses import native, rank
from pam2exu.backend.natural import Natural
from pam2exu.kinematics import State

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def four_bar():
    return pam2exu.load(ROOT / "examples" / "four_bar.toml")


@pytest.fixture
def counted(monkeypatch):
    """The number of evaluations of the equations by the rank tests (``rank.equations``)."""
    calls = []

    def equations(mech, st, jacobian=True):
        calls.append(st.n)
        return native.equations(mech, st, jacobian)

    monkeypatch.setattr(rank, "equations", equations)
    return calls


def test_the_mobility_check_evaluates_the_equations_once(four_bar, counted):
    """require_defined, the rank's SVD and the condition number share one evaluation at the
    guess (three before), and the condition number is the one evaluated apart."""
    job = job_module.prepare(four_bar, "kinematic", steps=10, backend="natural")
    q0 = job.mech.initial_q()
    mob = job_module.check_mobility(job, q0)
    assert counted == [1]
    alone = rank.condition_numbers(job.mech, [0.0], q0[None])[0]
    assert mob.condition == alone and job.info["condition_number"] == alone


@pytest.mark.parametrize("backend", ["natural", "exudyn"])
def test_a_short_run_takes_its_condition_numbers_from_the_rates_jacobian(four_bar, counted,
                                                                          backend):
    """A 100-step kinematic run evaluates the rank tests' equations only at the guess (its
    condition numbers reuse Cq of the rates' pass); the largest equals the one computed
    from Cq evaluated at every step apart."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = pam2exu.run(four_bar, "kinematic", steps=100, backend=backend)
    assert counted == [1]
    mech = four_bar.mechanism()
    q = mech.coordinates(res)
    jacobian = native.equations(mech, State(res.t, q)).jacobian
    apart = rank.condition_numbers(mech, res.t, q, jacobian)
    assert res.info["max_condition_number"] == float(np.max(apart))


@pytest.mark.parametrize("steps", [1, 7, 32, 33, 40])
def test_phi_and_its_jacobian_in_one_pass_are_the_separate_bits(four_bar, steps):
    """``residual_jacobian_cols`` (one gather, one bincount for a few steps) gives Φ and
    Φ_z bit for bit as ``residual_cols`` and ``jacobian_cols``."""
    mech = four_bar.mechanism()
    form = Natural().formulation(mech)
    terms = form.terms
    rng = np.random.default_rng(steps)
    z = form.from_q(mech.initial_q()[None]).T + 0.1 * rng.standard_normal((form.nz, steps))
    t = np.linspace(0.0, 0.5, steps)
    phi, data = terms.residual_jacobian_cols(t, z)
    assert phi.tobytes() == terms.residual_cols(t, z).tobytes()
    assert data.tobytes() == terms.jacobian_cols(z).tobytes()

"""What a run evaluates once (issue 25, the per-run fixed costs), checked by counting the
evaluations and comparing bits, never by time: the mobility check's one evaluation of the
equations at the guess, a short run's condition numbers from the Jacobian the rates were
computed with, the natural backend's one-pass Φ and Φ_z for a few steps and at one step
(Newton step by step). References: the same quantities evaluated separately
(``native.equations``, ``Terms.residual_cols`` and ``jacobian_cols``, a batch of steps)."""
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


@pytest.mark.parametrize("steps", [1, 7, 32, 33, 40, 257, 300])
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


@pytest.fixture(scope="module", params=["four_bar", "slider_crank", "chain_4"])
def natural_solver(request):
    """(formulation, Solver, z near the assembly (nz, 3)) of a model."""
    from benchmarks.cases import chain_model
    from pam2exu.backend.natural.solver import NaturalSettings, Solver
    model = chain_model(4) if request.param == "chain_4" else \
        pam2exu.load(ROOT / "examples" / f"{request.param}.toml")
    mech = model.mechanism()
    backend = Natural()
    form = backend.formulation(mech)
    solver = Solver(form.terms, backend.weights(form, mech), NaturalSettings(), False)
    rng = np.random.default_rng(7)
    z = form.from_q(mech.initial_q()[None]).T + 0.01 * rng.standard_normal((form.nz, 3))
    return form, solver, z


def test_one_step_evaluations_are_their_column_of_many(natural_solver):
    """Φ, Φ_z and γ at one step (``residual_jacobian_one``, ``jacobian_one``,
    ``gamma_one``: 1-D arrays, for Newton step by step) are, bit for bit, that step's
    column of the evaluation of three steps (``*_cols``)."""
    form, _, z = natural_solver
    terms = form.terms
    t = np.array([0.01, 0.02, 0.05])
    zd = np.cos(z)                                   # any rates
    phi, data = terms.residual_jacobian_cols(t, z)
    gamma = terms.gamma_cols(t, z, zd)
    g0, g2 = terms.targets(t, 0), terms.targets(t, 2)
    for k in range(3):
        phi1, J1 = terms.residual_jacobian_one(z[:, k], g0[:, k])
        dense = terms.dense_cols(data[:, k:k + 1])[:, :, 0]
        assert phi1.tobytes() == phi[:, k].tobytes()
        assert J1.tobytes() == dense.tobytes()
        assert terms.jacobian_one(z[:, k]).tobytes() == dense.tobytes()
        assert terms.gamma_one(z[:, k], zd[:, k], g2[:, k]).tobytes() == gamma[:, k].tobytes()


def test_newton_and_rates_at_one_step_are_the_batch_bits(natural_solver):
    """Newton's iteration and the rates at one step (the coarse pass's) give, bit for bit,
    what the same step gives solved in a batch of two (numpy's batched dense solve)."""
    form, solver, z = natural_solver
    t = np.array([0.02])
    one, ok = solver.newton(t, z[:, :1].T)
    two, ok2 = solver.newton(np.r_[t, t], np.repeat(z[:, :1].T, 2, axis=0))
    assert ok[0] and ok2.all()
    assert one[0].tobytes() == two[0].tobytes()
    zd, zdd = solver.rates(t, one)
    zd2, zdd2 = solver.rates(np.r_[t, t], np.repeat(one, 2, axis=0))
    assert zd[0].tobytes() == zd2[0].tobytes() and zdd[0].tobytes() == zdd2[0].tobytes()


def test_the_pivot_order_at_one_configuration_is_the_batched_one(natural_solver):
    """The equations' pivot order at the run's start (one configuration, eliminated in 2-D)
    is the batched elimination's (``batched.lu_factor``) for that configuration, exchanges
    included."""
    form, solver, z = natural_solver
    rng = np.random.default_rng(3)
    many = np.concatenate([z.T, z.T[:1] + rng.standard_normal((20, form.nz))])
    batched = solver.pivot_orders(many)
    assert any((o != np.arange(form.m)).any() for o in batched)
    for k, zk in enumerate(many):
        assert (solver.pivot_orders(zk[None])[0] == batched[k]).all()


def test_a_singular_step_gives_nan_quietly(natural_solver):
    """At a configuration where Φ_z is singular (every coordinate 0), Newton at one step
    fails and the rates at one step are NaN, as a batch's (least squares: NaN), without a
    numpy warning (the one-step solves run LAPACK's gesv without numpy's wrapper)."""
    form, solver, _ = natural_solver
    t, z = np.array([0.01]), np.zeros((1, form.nz))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        zd, zdd = solver.rates(t, z)
        many = solver.rates(np.r_[t, t], np.r_[z, z])
        _, ok = solver.newton(t, z)
    assert np.isnan(zd).all() and np.isnan(zdd).all() and not ok[0]
    assert np.isnan(many[0]).all() and np.isnan(many[1]).all()


def test_a_kinetostatic_run_of_positions_only_takes_the_backends_rates(four_bar, monkeypatch):
    """Positions only (``rocker.fi``): the branch is still followed on the rates, now the
    natural backend's (as for the full run), not a native pass besides; the column is the
    full run's, bit for bit, and so are the warnings."""
    passes, rates = [], native.rates
    monkeypatch.setattr(native, "rates", lambda *a, **k: passes.append(1) or rates(*a, **k))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        alone = pam2exu.run(four_bar, "kinetostatic", steps=40, backend="natural",
                            outputs=["rocker.fi"])
        full = pam2exu.run(four_bar, "kinetostatic", steps=40, backend="natural")
    assert passes == []
    assert alone["rocker.fi"].tobytes() == full["rocker.fi"].tobytes()
    assert alone.warnings == full.warnings


def _jacobians(rng, steps, m, nq, drift):
    """Cq along a straight path between two random matrices of very different column
    scales (``drift``: how far), with exact ties, a nearly singular step and a zero row."""
    base = rng.standard_normal((m, nq)) * rng.choice([1e-3, 1.0, 1e3], size=nq)
    J = base + np.linspace(0.0, 1.0, steps)[:, None, None] * drift * rng.standard_normal((m, nq))
    J[steps // 2] = J[0]                                   # the largest may be tied
    J[steps // 3, :, 0] = J[steps // 3, :, 1] * (1 + 1e-12)   # κ ~ 1e12 at one step
    J[-1, 0] = 0.0
    return J


@pytest.mark.parametrize("m, nq", [(12, 12), (9, 12), (14, 12)])
@pytest.mark.parametrize("drift", [1e-9, 1e-3, 1.0])
def test_the_largest_condition_number_is_the_one_of_every_steps_svd(m, nq, drift):
    """rank.largest_condition (SVDs only where the Gram eigenvalues cannot rule a step
    out) gives the bits and the first step of the largest of condition_numbers (an SVD at
    every step): tied, flat, varying, singular steps, fewer or more equations than q."""
    rng = np.random.default_rng(m * 100 + nq + int(-np.log10(drift)))

    class Mech:
        pass

    mech = Mech()
    mech.nq = nq
    for steps in (1, 7, 40):
        J = _jacobians(rng, steps, m, nq, drift)
        for rows in (slice(None), [0, -1], [steps - 1]):
            every = rank.condition_numbers(mech, None, None, J[rows])
            k = int(np.argmax(every))
            assert rank.largest_condition(mech, None, None, J[rows]) == (k, float(every[k]))


def test_a_short_run_takes_the_svd_of_the_steps_that_can_be_the_worst(four_bar, monkeypatch):
    """The 100-step four-bar's condition check: one SVD, of one step (101 before), and the
    run's largest condition number is that of every step's SVD."""
    svds, kappa = [], rank._kappa
    monkeypatch.setattr(rank, "_kappa", lambda A, r: svds.append(len(A)) or kappa(A, r))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = pam2exu.run(four_bar, "kinematic", steps=100, backend="natural")
    assert svds == [1]         # the run's (the guess's with its rank test: _regular_condition)
    mech = four_bar.mechanism()
    q = np.column_stack([res[f"{s.name}.{v}"] for s in mech.solids for v in ("x", "y", "fi")])
    every = rank.condition_numbers(mech, res.t, q)
    assert res.info["max_condition_number"] == float(np.max(every))


def test_the_columns_of_a_structure_are_made_once(four_bar, monkeypatch):
    """``available_columns`` of a mechanism whose solids, points and elements are those of
    one made before is its columns again (a copy, equal to them made afresh); a point
    more, another analysis or ``derived`` make their own."""
    from pam2exu import registry
    monkeypatch.setattr(job_module, "_COLUMNS", {})
    made = []
    available = job_module._available
    monkeypatch.setattr(job_module, "_available",
                        lambda *a: made.append(a[1:]) or available(*a))
    kinetostatic = registry.ANALYSES["kinetostatic"]
    mech = four_bar.mechanism()
    first = job_module.available_columns(mech, kinetostatic)
    other = pam2exu.load(ROOT / "examples" / "four_bar.toml")
    other["motor"].C = [0.0, 3.0, 0.0, 0.0]                 # (not the columns')
    again = job_module.available_columns(other.mechanism(), kinetostatic)
    assert len(made) == 1 and again == first and again is not first
    again.clear()
    assert job_module.available_columns(mech, kinetostatic) == available(mech, kinetostatic,
                                                                          True)
    pointed = pam2exu.load(ROOT / "examples" / "four_bar.toml")
    pointed.solids[2].points["extra"] = [0.1, 0.0]
    columns = job_module.available_columns(pointed.mechanism(), kinetostatic)
    assert len(made) == 2 and any(".extra." in c for c in columns)
    job_module.available_columns(mech, registry.ANALYSES["kinematic"])
    job_module.available_columns(mech, kinetostatic, derived=False)
    assert len(made) == 4

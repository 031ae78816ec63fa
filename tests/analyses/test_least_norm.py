"""least_norm: Rameau's Lagrange conditions, Newton on them, the slides' ODE, the conditions.

References, independent of the module: the closed-form least-norm solution of a linear
closure (from the KKT conditions by hand, below), and scipy.optimize.minimize (SLSQP) on
½‖j‖² with the closure as equality constraints for a nonlinear one.
"""
import numpy as np
import pytest
from scipy.linalg import null_space
from scipy.optimize import minimize

from pam2exu.analyses import least_norm as ln

RNG = np.random.default_rng(7)
A = RNG.standard_normal((3, 2))                  # F_j: 3 equations, 2 clearances
B = RNG.standard_normal((3, 2))                  # F_q: 2 positions, over-constrained


def c_of(t):
    return np.array([0.3 * np.sin(t), -0.2 * t, 0.1 * np.cos(2 * t) - 0.1])


def linear(t, q, lam):
    """F = A j + B q − c(t), W = 0."""
    return ln.Closure(B @ q - c_of(t), B, A, np.zeros((2, 2)))


def linear_reference(t):
    """min ½‖j‖² s.t. A j + B q = c: λ ∈ ker Bᵀ = span N, j = −Aᵀλ, so
    j = Aᵀ N (Nᵀ A Aᵀ N)⁻¹ Nᵀ c and B q = c − A j."""
    N = null_space(B.T)
    c = c_of(t)
    j = A.T @ N @ np.linalg.solve(N.T @ A @ A.T @ N, N.T @ c)
    q = np.linalg.lstsq(B, c - A @ j, rcond=None)[0]
    return j, q


def test_newton_on_a_linear_closure_gives_the_closed_form():
    y0 = np.zeros(2 + 2 + 3)
    y0[2:4] = linear_reference(0.0)[1]
    for t in (0.3, 1.1, 2.0):
        y, ok = ln.newton(linear, t, y0, 2, 2)
        j, q = linear_reference(t)
        assert ok
        np.testing.assert_allclose(y[:2], j, atol=1e-14)
        np.testing.assert_allclose(y[2:4], q, atol=1e-14)


# ---- a nonlinear closure: a point on three circles, two of them with clearance -----------

P = np.array([[0.0, 0.0], [1.0, 0.0], [0.3, 0.9]])
X0 = np.array([0.4, 0.35])
R0 = np.linalg.norm(X0 - P, axis=1)              # at t = 0 the three circles meet at X0
FJ = np.array([[1.0, 0.0], [0.0, 1.0], [0.0, 0.0]])


def radii(t):
    return R0 + (1 - np.exp(-t)) * np.array([0.02, -0.015, 0.01]) / 2 * np.cos([1.3 * t, 0.7 * t, 2.1 * t])


def circles(t, q, lam):
    """F_i = |q − P_i|² − r_i(t)² + (F_j j)_i, F_q = 2 (q − P_i)ᵀ, W = 2 Σλ_i I."""
    d = q - P
    return ln.Closure(np.sum(d * d, axis=1) - radii(t) ** 2, 2 * d, FJ, 2 * np.sum(lam) * np.eye(2))


def minimised(t, start):
    """(j, q) by SLSQP: min ½‖j‖² over (j, q) with the three closure equations."""
    cons = {"type": "eq", "fun": lambda x: circles(t, x[2:], np.zeros(3)).F + FJ @ x[:2],
            "jac": lambda x: np.hstack([FJ, circles(t, x[2:], np.zeros(3)).Fq])}
    res = minimize(lambda x: 0.5 * x[:2] @ x[:2], start, jac=lambda x: np.r_[x[:2], 0, 0],
                   constraints=[cons], method="SLSQP", options={"ftol": 1e-14, "maxiter": 1000})
    assert res.success
    return res.x[:2], res.x[2:]


@pytest.fixture(scope="module")
def paths():
    times = np.linspace(0.0, 6.0, 61)
    y0 = np.r_[0.0, 0.0, X0, 0.0, 0.0, 0.0]
    ode = ln.follow(circles, ln.time_rate(circles, 2), times, y0, 2, 2)[:2]
    newton = ln.step_by_step(circles, times, y0, 2, 2)
    return times, ode, newton


def test_the_ode_and_newton_step_by_step_agree(paths):
    times, (ode, ok_ode), (newton, ok_newton) = paths
    assert ok_ode.all() and ok_newton.all()
    np.testing.assert_allclose(ode, newton, atol=1e-12)
    assert np.max(np.abs(ode[:, :2])) > 1e-3          # a clearance there is


def test_the_clearance_followed_is_the_least_norm_one(paths):
    times, (ode, _), _ = paths
    for k in (10, 35, 60):
        j, q = minimised(times[k], ode[k, :4] + 1e-3)
        np.testing.assert_allclose(ode[k, :2], j, atol=1e-8)
        np.testing.assert_allclose(ode[k, 2:4], q, atol=1e-8)


def test_every_row_meets_the_closure_and_the_optimality_conditions(paths):
    """The contract's items 1–3, from the results alone."""
    times, (ode, _), _ = paths
    for t, y in zip(times, ode):
        j, q, lam = ln.split(y, 2, 2)
        c = circles(t, q, lam)
        assert np.max(np.abs(c.F + FJ @ j)) <= 1e-13
        assert ln.kkt_residual(j, c) <= 1e-12
        assert ln.applicability(c).hessian > 1e-9


def test_with_no_variation_the_clearance_is_zero():
    times = np.linspace(0.0, 1.0, 11)
    y0 = np.r_[0.0, 0.0, X0, 0.0, 0.0, 0.0]
    fixed = lambda t, q, lam: circles(0.0, q, lam)          # noqa: E731
    y, ok, stop = ln.follow(fixed, ln.time_rate(fixed, 2), times, y0, 2, 2)
    assert stop is None
    assert ok.all() and np.max(np.abs(y[:, :2])) < 1e-14
    np.testing.assert_allclose(y[:, 2:4], np.tile(X0, (len(times), 1)), atol=1e-14)


def test_the_conditions_name_what_fails():
    """(i): a self-stress that loads no clearance (the third circle's twin, no clearance on
    either); (ii): a free position (one circle only, two coordinates)."""
    c = circles(0.0, X0, np.zeros(3))
    assert ln.applicability(c).holds
    twin = ln.Closure(np.r_[c.F, c.F[2]], np.vstack([c.Fq, c.Fq[2]]),
                      np.vstack([FJ, [0.0, 0.0]]), c.W)
    found = ln.applicability(twin)
    assert found.ratio_i <= ln.RANK and not found.holds and found.self_stress.shape == (4, 1)
    stress = found.self_stress[:, 0] / np.max(np.abs(found.self_stress))
    np.testing.assert_allclose(np.abs(stress), [0, 0, 1, 1], atol=1e-12)  # rows 3 and 4
    alone = ln.Closure(c.F[:1], c.Fq[:1], np.array([[1.0, 0.0]]), c.W)
    found = ln.applicability(alone)
    assert found.ratio_ii <= ln.RANK and found.free.shape == (2, 1)
    np.testing.assert_allclose(c.Fq[0] @ found.free, 0.0, atol=1e-14)
    assert ln.applicability(c).self_stress.shape == (3, 0)   # none where (i) holds


# ---- where the branch ends: a fold at t = 5, like a crank at its dead centre ----------------

FOLD = 5.0
C_FOLD = 0.3


def fold(t, q, lam):
    """F = (q² + t − 5, q + j − 0.3): the first row fixes q = √(5 − t) (no clearance),
    which ends at t = 5 where F_q = 2q vanishes (a dead centre); W = 2 λ1."""
    return ln.Closure(np.array([q[0] ** 2 + t - FOLD, q[0] - C_FOLD]),
                      np.array([[2 * q[0]], [1.0]]), np.array([[0.0], [1.0]]),
                      np.array([[2 * lam[0]]]))


def test_follow_stops_where_the_branch_ends_and_keeps_the_rows_before():
    """Issue 22, item 4: the branch q = √(5 − t), j = 0.3 − q ends at t = 5. ``follow``
    stops within one output step of it and of where scipy's own solve_ivp (the old
    integration) stops, and keeps every row before, equal to the closed form (before, a
    failed integration made every row NaN)."""
    from scipy.integrate import solve_ivp
    times = np.linspace(0.0, 6.0, 25)                       # Δt = 0.25
    y0 = np.array([C_FOLD - np.sqrt(FOLD), np.sqrt(FOLD), 0.0, 0.0])
    h_t = ln.time_rate(fold, 1)
    y, ok, stop = ln.follow(fold, h_t, times, y0, 1, 1)
    # its steps shrink towards the fold: the work limit ends the crawl, 1.5e-8 s before it
    assert stop is not None and stop.cause == ln.Stop.WORK
    dt = times[1] - times[0]
    assert FOLD - 1e-6 < stop.time < FOLD
    kept = times < stop.time
    assert ok[kept].all() and not ok[~kept].any() and np.isnan(y[~kept]).all()
    assert kept.sum() == 20                                 # t = 0 … 4.75
    np.testing.assert_allclose(y[kept, 1], np.sqrt(FOLD - times[kept]), atol=1e-12)
    np.testing.assert_allclose(y[kept, 0], C_FOLD - np.sqrt(FOLD - times[kept]), atol=1e-12)

    def rhs(t, y):
        c = fold(t, y[1:2], y[2:])
        return -np.linalg.solve(ln.lagrange_jacobian(c), h_t(t, y[1:2], y[2:]))
    old = solve_ivp(rhs, (0.0, 6.0), y0, method="DOP853", rtol=1e-10, atol=1e-12)
    assert not old.success and abs(old.t[-1] - stop.time) < dt


def test_follow_bounds_its_work_per_output_step():
    """Issue 22, item 6: a closure varying at 1e6 rad/s against output steps of 0.1 s
    made the integration crawl for ever; ``follow`` now stops after ``max_steps`` steps in
    one output interval (``Stop.WORK``), before the first row after t = 0."""
    def fast(t, q, lam):
        return ln.Closure(B @ q - c_of(t) - 1e-3 * np.cos(1e6 * t), B, A, np.zeros((2, 2)))
    times = np.linspace(0.0, 1.0, 11)
    y0 = np.r_[0.0, 0.0, linear_reference(0.0)[1], 0.0, 0.0, 0.0]
    y, ok, stop = ln.follow(fast, ln.time_rate(fast, 2), times, y0, 2, 2, max_steps=50)
    assert stop.cause == ln.Stop.WORK and stop.steps == 50
    assert 0.0 < stop.time < times[1]
    assert ok.tolist() == [True] + [False] * 10


@pytest.mark.parametrize("ratio, holds", [(2e-9, True), (1e-6, True), (5e-10, False)])
def test_a_condition_fails_at_the_contracts_rank_ratio_1e_9(ratio, holds):
    """The contract (docs/clearance.md, 'conditions of applicability'): (ii) fails when
    σ_min/σ_max of F_q is ≤ 1e-9, and not above. F_q = diag(1, ratio) has exactly that
    ratio; F_j = (0, 1)ᵀ and W = I keep (i) (σ 1 and √(1 + ratio²)) and the reduced
    Hessian (1) away from it: (ii) decides alone."""
    c = ln.Closure(np.zeros(2), np.diag([1.0, ratio]), np.array([[0.0], [1.0]]), np.eye(2))
    found = ln.applicability(c)
    assert found.ratio_ii == pytest.approx(ratio, rel=1e-12)
    assert found.ratio_i == pytest.approx(1.0, abs=1e-12)
    assert found.hessian == pytest.approx(1.0, abs=1e-12)
    assert bool(found.holds) is holds
    assert found.free.shape[1] == (0 if holds else 1)


def test_the_kernel_of_every_row_is_orthonormal_and_annihilated():
    """``kernel_rows``: of full row rank from the QR of Aᵀ, of lower rank from the SVD;
    reference: scipy.linalg.null_space of each matrix (the same subspace: the projectors
    agree)."""
    rng = np.random.default_rng(11)
    full = rng.standard_normal((5, 3, 6))                   # rank 3 of 6 columns
    low = full.copy()
    low[:, 2] = low[:, 0] - 2 * low[:, 1]                    # rank 2: the third row repeats
    for stack, rank in ((full, 3), (low, 2)):
        Z = ln.kernel_rows(stack, rank)
        assert Z.shape == (5, 6, 6 - rank)
        for A, z in zip(stack, Z):
            assert np.max(np.abs(A @ z)) < 1e-14 * np.max(np.abs(A))
            np.testing.assert_allclose(z.T @ z, np.eye(6 - rank), rtol=0, atol=1e-14)
            N = null_space(A, rcond=1e-12)
            np.testing.assert_allclose(z @ z.T, N @ N.T, rtol=0, atol=1e-13)


def test_the_strict_minimum_of_many_rows_equals_the_conditions_row_by_row():
    """``strict_minimum_rows`` (the clearance run's screen) against ``applicability`` at each
    row, rows of full rank and one whose [F_j F_q] lost a rank among them; the reduced
    Hessian's eigenvalue does not depend on the kernel's basis (QR or SVD), so the two
    agree to round-off."""
    rng = np.random.default_rng(5)
    n, m, p, nq = 6, 4, 2, 5
    Fj = rng.standard_normal((m, p))
    Fj[3] = Fj[0] + Fj[1]                 # F_j's rows dependent: F_q's make them independent
    Fq = rng.standard_normal((n, m, nq))
    Fq[3, 3] = Fq[3, 0] + Fq[3, 1]        # … except at row 3: [F_j F_q] of rank 3 there
    W = rng.standard_normal((n, nq, nq))
    W = W + np.transpose(W, (0, 2, 1))
    ratio, hessian = ln.strict_minimum_rows(Fj, Fq, W)
    assert ratio[3] < 1e-15 and np.all(np.delete(ratio, 3) > 1e-3)
    for k in range(n):
        found = ln.applicability(ln.Closure(np.zeros(m), Fq[k], Fj, W[k]))
        assert ratio[k] == pytest.approx(found.ratio_i, rel=1e-12, abs=1e-15)
        assert hessian[k] == pytest.approx(found.hessian, rel=1e-12, abs=1e-13)

"""The native pass: each element's Jacobian and convective term against finite differences.

Reference: along a path q(s) = q0 + v s + a s²/2, every constraint quantity g(q) has
dg/ds = Cq v and d²g/ds² = Cq a + conv at s = 0. Central differences of g along the path
(fourth-order stencils, step h = 1e-3, error O(h⁴)) are computed here independently of ``kinematics``'s derivatives.
"""
import numpy as np
import pytest

import pam2exu
from pam2exu.analyses import native
from pam2exu.kinematics import State


@pytest.fixture(scope="module")
def every(request):
    return pam2exu.load(request.config.rootpath / "tests/data/every_element.toml").mechanism()


@pytest.mark.parametrize("seed", [3, 4])
def test_jacobian_rate_and_convective_term_match_finite_differences(every, seed):
    rng = np.random.default_rng(seed)
    q0 = every.initial_q() + 0.05 * rng.standard_normal(every.nq)
    v, a = rng.standard_normal(every.nq), rng.standard_normal(every.nq)
    h = 1e-3
    path = lambda s: q0 + v * s + 0.5 * a * s * s  # noqa: E731
    for el in every.constraints:
        g = lambda s: el.constraint(State([0.0], path(s)[None]))[0].value[0]  # noqa: E731
        g2, g1, g0, g_1, g_2 = (g(k * h) for k in (2, 1, 0, -1, -2))
        dg = (8 * (g1 - g_1) - (g2 - g_2)) / (12 * h)
        ddg = (-g2 + 16 * g1 - 30 * g0 + 16 * g_1 - g_2) / (12 * h * h)
        quantity = el.constraint(State([0.0], q0[None], v[None]))[0]
        J = np.zeros((1, el.equations, every.nq))
        quantity.rows(J, 0)
        scale = 1.0 + np.abs(ddg)
        np.testing.assert_allclose(J[0] @ v, dg, atol=1e-9, err_msg=el.name)
        np.testing.assert_allclose(quantity.rate[0], J[0] @ v, atol=1e-14, err_msg=el.name)
        np.testing.assert_allclose((J[0] @ a + quantity.conv[0]) / scale, ddg / scale,
                                   atol=1e-7, err_msg=el.name)


@pytest.mark.parametrize("seed", [5, 6])
def test_second_derivatives_match_finite_differences_of_the_jacobian(every, seed):
    """Σ_d w_d ∂²v_d/∂q² (``Quantity.hess``, the clearance analysis's Σλ F_qq) of every
    element's constraint: against central differences of its analytic Jacobian (fourth
    order, h = 1e-4, error O(h⁴)), column by column, so that the whole matrix is checked
    (not only its quadratic form); and its quadratic form against the convective term,
    which for a constraint without time is vᵀ (∂²v/∂q²) v (both analytic: round-off)."""
    rng = np.random.default_rng(seed)
    nq = every.nq
    q0 = every.initial_q() + 0.05 * rng.standard_normal(nq)
    v = rng.standard_normal(nq)
    h = 1e-4
    for el in every.constraints:
        w = rng.standard_normal((1, el.equations))

        def weighted_jacobian(q):
            J = np.zeros((1, el.equations, nq))
            el.constraint(State([0.0], q[None]))[0].rows(J, 0)
            return w[0] @ J[0]

        quantity = el.constraint(State([0.0], q0[None], v[None], hessians=True))[0]
        H = np.zeros((1, nq, nq))
        quantity.weighted_hessian(w, H)
        for k in range(nq):
            e = np.zeros(nq)
            e[k] = h
            column = (8 * (weighted_jacobian(q0 + e) - weighted_jacobian(q0 - e))
                      - (weighted_jacobian(q0 + 2 * e) - weighted_jacobian(q0 - 2 * e))) / (12 * h)
            np.testing.assert_allclose(H[0, :, k], column, atol=1e-9,
                                       err_msg=f"{el.name}, column {k}")
        np.testing.assert_allclose(H[0], H[0].T, atol=1e-15, err_msg=el.name)
        np.testing.assert_allclose(v @ H[0] @ v, w[0] @ quantity.conv[0],
                                   atol=1e-12 * (1 + abs(v @ H[0] @ v)), err_msg=el.name)


def test_gamma_of_actuators_includes_the_law():
    """Cq qdd = γ: for fi2 − fi1 = f(t) with everything else at rest, γ = f''(t)."""
    m = pam2exu.Model("motor", gravity=0.0)
    m.add_solid("ground")
    m.add_solid("crank")
    m.add("fixed", anc1="ground")
    m.add("angular_actuator", name="motor", anc1="ground", anc2="crank", law="polynomial",
          C=[0.0, 1.0, 2.0, 3.0])
    mech = m.mechanism()
    t = np.array([0.0, 0.5, 1.0])
    q = np.zeros((3, 6))
    eq = native.equations(mech, State(t, q, np.zeros_like(q)))
    row = mech.rows[1].start
    np.testing.assert_allclose(eq.gamma[:, row], 4.0 + 18.0 * t, rtol=1e-15)
    np.testing.assert_allclose(eq.c_t[:, row], -(1.0 + 4.0 * t + 9.0 * t * t), rtol=1e-15)


def test_results_do_not_depend_on_chunking(examples, monkeypatch):
    """Residuals, velocities and accelerations are computed in step chunks: 7-step chunks
    must give bit-identical results to one chunk."""
    whole = pam2exu.run(examples / "four_bar.toml", steps=50)
    monkeypatch.setattr(native, "CHUNK_BYTES", 8 * 12 * 12 * 7)
    assert len(list(native.chunks(whole_mech := pam2exu.load(examples / "four_bar.toml")
                                  .mechanism(), 51))) == 8
    assert whole_mech.nq == 12
    chunked = pam2exu.run(examples / "four_bar.toml", steps=50)
    np.testing.assert_array_equal(chunked.to_numpy(), whole.to_numpy())
    assert chunked.info["max_residual"] == whole.info["max_residual"]


@pytest.mark.parametrize("analysis", ["kinematic", "kinetostatic"])
def test_sparse_and_dense_solves_agree(examples, monkeypatch, analysis):
    """Large mechanisms solve a chunk of steps as one sparse block-diagonal system; forced
    on a small one, it must give what the dense batched solves give (to 1e-12 relative)."""
    path = examples / "all_elements.toml"
    dense = pam2exu.run(path, analysis=analysis, steps=60)
    monkeypatch.setattr(native, "SPARSE_FROM", 0)
    monkeypatch.setattr(native, "SPARSE_CHUNK", 500)        # several chunks
    sparse = pam2exu.run(path, analysis=analysis, steps=60)
    assert dense.columns == sparse.columns
    for c in dense.columns:
        scale = max(np.max(np.abs(dense[c])), 1.0)       # round-off of zero columns
        np.testing.assert_allclose(sparse[c], dense[c], rtol=0, atol=1e-12 * scale, err_msg=c)

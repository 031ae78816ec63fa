"""The checks of every run done with less work (issue 25, the per-run costs), checked by
comparing bits with the plain computations, never by time: the equilibration of Cq in place,
the condition check's eigenvalues at the steps that can be the worst only."""
from __future__ import annotations

import numpy as np
import pytest

from pam2exu.analyses import rank


def _norm_equilibrated(J):
    """Rows and columns of J scaled to unit length, three passes, by np.linalg.norm."""
    for _ in range(3):
        J = J / np.maximum(np.linalg.norm(J, axis=2, keepdims=True), 1e-300)
        J = J / np.maximum(np.linalg.norm(J, axis=1, keepdims=True), 1e-300)
    return J


@pytest.mark.parametrize("m, nq", [(1, 3), (5, 6), (12, 12), (9, 12), (14, 12), (40, 45)])
def test_the_equilibration_is_the_norms_bits(m, nq):
    """``_equilibrated`` (squares summed in place) gives np.linalg.norm's passes bit for bit,
    zero rows and columns and scales from 1e-6 to 1e6 included, complex too."""
    rng = np.random.default_rng(m * 100 + nq)
    J = rng.standard_normal((7, m, nq)) * rng.choice([1e-6, 1.0, 1e6], size=nq)
    J[2, 0] = 0.0
    J[3, :, -1] = 0.0
    assert rank._equilibrated(J).tobytes() == _norm_equilibrated(J).tobytes()
    Z = J + 1e-20j * rng.standard_normal(J.shape)
    assert rank._equilibrated(Z).tobytes() == _norm_equilibrated(Z).tobytes()



@pytest.mark.parametrize("n, m, nq", [(20, 12, 12), (101, 12, 12), (21, 1, 1), (40, 3, 7),
                                      (20, 9, 8), (33, 14, 9), (22, 5, 15), (23, 20, 16),
                                      (25, 6, 17), (20, 30, 24), (21, 4, 127), (20, 3, 128)])
def test_the_equilibration_of_a_stack_is_the_norms_bits(n, m, nq):
    """From ``STACKED`` matrices on, ``_equilibrated`` works entry by entry along the steps
    (each row's squares summed as numpy's reduce sums a row: in order below 8, in 8 partial
    sums from 8 to 128): np.linalg.norm's passes bit for bit, scales from 1e-8 to 1e8,
    zeros, NaN and a view that is not C-ordered (the plain passes then) included."""
    assert n >= rank.STACKED
    rng = np.random.default_rng(n * 10_000 + m * 100 + nq)
    J = rng.standard_normal((n, m, nq)) * 10.0 ** rng.uniform(-8, 8, (n, m, nq))
    J[rng.random(J.shape) < 0.2] = 0.0
    J[1, 0] = 0.0
    J[2, :, -1] = 0.0
    J[3, -1, 0] = np.nan
    assert rank._equilibrated(J).tobytes() == _norm_equilibrated(J).tobytes()
    F = np.asfortranarray(J)
    assert rank._equilibrated(F).tobytes() == _norm_equilibrated(F).tobytes()

def _smooth(rng, steps, m, nq, peak):
    """Equilibrated Cq along a smooth closed path whose κ peaks near step ``peak``."""
    a, b, c = (0.1 * rng.standard_normal((m, nq)) for _ in range(3))
    s = np.linspace(0.0, 2 * np.pi, steps)[:, None, None]
    J = np.eye(m, nq) + a + np.cos(s) * b + np.sin(s) * c
    J[:, :, 0] += 0.5 * np.exp(-((s[:, :, 0] - s[peak, 0, 0]) ** 2)) * J[:, :, 1]
    return rank._equilibrated(J)


@pytest.mark.parametrize("steps, peak", [(101, 50), (101, 3), (102, 101), (5, 2), (400, 217)])
def test_steps_ruled_out_by_a_probed_neighbour_are_below_the_largest(steps, peak, monkeypatch):
    """On a smooth motion the Gram eigenvalues are taken at fewer steps than the run's
    (every PROBE-th step, then those Weyl's bound from a probed neighbour cannot rule out),
    and the largest condition number and its step are still every step's SVD's."""
    rng = np.random.default_rng(steps + peak)
    A = _smooth(rng, steps, 12, 12, peak)
    sizes, eigvalsh = [], np.linalg.eigvalsh
    monkeypatch.setattr(np.linalg, "eigvalsh", lambda G: sizes.append(len(G)) or eigvalsh(G))

    class Mech:
        nq = 12

    every = rank.condition_numbers(Mech, None, None, A)
    k = int(np.argmax(every))
    sizes.clear()
    assert rank.largest_condition(Mech, None, None, A) == (k, float(every[k]))
    if steps > 5:
        assert sum(sizes) < steps
    assert k in rank._candidates(rank._equilibrated(A))


@pytest.mark.parametrize("peak, other", [(3, 3), (50, 3), (99, 60)])
def test_a_reference_stack_leaves_the_largest_condition_the_same(peak, other, monkeypatch):
    """Within ``references`` a stack is bounded from the first one of its shape: variants
    a little apart (their κ peaks where the reference's does, or elsewhere) and a stack
    far from it (the usual probes then) give every step's SVD's largest κ and its step,
    the near ones with the eigenvalues at fewer steps than without a reference."""
    rng = np.random.default_rng(peak + other)
    A = _smooth(rng, 101, 12, 12, peak)
    B = _smooth(np.random.default_rng(peak + other), 101, 12, 12, other)
    near = rank._equilibrated(A + 1e-5 * np.random.default_rng(7).standard_normal(A.shape))
    far = _smooth(np.random.default_rng(99), 101, 12, 12, 20)
    sizes, eigvalsh = [], np.linalg.eigvalsh
    monkeypatch.setattr(np.linalg, "eigvalsh", lambda G: sizes.append(len(G)) or eigvalsh(G))

    class Mech:
        nq = 12

    def largest(S):
        every = rank.condition_numbers(Mech, None, None, S)
        return int(np.argmax(every)), float(every[int(np.argmax(every))])

    with rank.references():
        assert rank.largest_condition(Mech, None, None, A) == largest(A)    # the reference
        for S in (near, B, far, A):
            without = sum(sizes)
            assert rank.largest_condition(Mech, None, None, S) == largest(S)
            if S is near or S is A:
                assert sum(sizes) - without < 101 // 2
    assert rank._REFERENCES.get() is None


def test_the_continuity_defect_is_the_plain_expressions_bits():
    """``continuity_defect`` (buffers reused over its blocks, the rows' largest column by
    column) gives max |q̇_k − q̇_j − dt (q̈_k + q̈_j)/2| / scale bit for bit, over a block
    boundary, with NaN and infinite rates and a breakpoint; ``finite_rows`` and
    ``branch._scales`` are the plain expressions' too."""
    from pam2exu.analyses import branch, continuity
    rng = np.random.default_rng(5)
    n = continuity.RESIDUAL_CHUNK + 300
    t = np.cumsum(rng.random(n))
    qd, qdd = rng.standard_normal((2, n, 12))
    qd[17, 4], qdd[8200, 0], qd[40, 2] = np.nan, np.inf, -np.inf
    scale = rng.random(12) + 0.1
    dt = np.diff(t)[:, None]
    with np.errstate(invalid="ignore"):
        plain = np.max(np.abs(qd[1:] - qd[:-1] - dt * (qdd[1:] + qdd[:-1]) / 2) / scale, axis=1)
    plain = np.r_[0.0, np.where(np.isnan(plain), np.inf, plain)]
    plain[1:][(t[:-1] < t[500] - 1e-9) & (t[500] - 1e-9 <= t[1:])] = 0.0
    with np.errstate(invalid="ignore"):
        found = continuity.continuity_defect(t, qd, qdd, scale, [t[500] - 1e-9])
    assert found.tobytes() == plain.tobytes()
    rows = np.isfinite(qd).all(axis=1) & np.isfinite(qdd).all(axis=1)
    assert (continuity.finite_rows(qd, qdd) == rows).all()
    assert continuity.finite_rows(qd[:10], qdd[:10]).all()

    class Mech:
        solids = [None] * 4

        @staticmethod
        def scale():
            return 0.35

    weights = np.tile([1.0, 1.0, 0.35], 4)
    speed = np.max(np.abs(np.where(np.isfinite(qd), qd, 0.0) * weights), initial=0.0)
    assert branch._scales(Mech, qd).tobytes() == (speed / weights).tobytes()
    assert branch._scales(Mech, qd[50:60]).tobytes() == \
        (np.max(np.abs(qd[50:60] * weights)) / weights).tobytes()


def test_the_default_outputs_do_not_make_the_derived_columns(monkeypatch):
    """A run with the default outputs (which leave the points, centres and transmission
    angles out) does not list those columns at all; its columns are those of the full list
    without the opt-in ones, and asking for one still makes them."""
    from pam2exu.analyses import job as job_module
    from pam2exu import load
    from pathlib import Path
    model = load(Path(__file__).resolve().parents[2] / "examples" / "four_bar.toml")
    made, derived = [], job_module._derived
    monkeypatch.setattr(job_module, "_derived",
                        lambda *a: made.append(1) or derived(*a))
    monkeypatch.setattr(job_module, "_COLUMNS", {})     # (the columns made once per structure)
    job = job_module.prepare(model, "kinetostatic", steps=10)
    assert made == []
    every = job_module.available_columns(job.mech, job.analysis_type)
    from pam2exu.points import is_opt_in
    assert job.columns == [c for c in every if not is_opt_in(c)]
    made.clear()
    job_module._COLUMNS.clear()
    asked = job_module.prepare(model, "kinetostatic", steps=10, outputs=["coupler.P.x"])
    assert made == [1] and asked.columns == ["coupler.P.x"]


def _regular(mech, J, rtol: float) -> bool:
    """The reference for ``rank._regular_condition``'s test: Cq square, its scaled singular
    values alone (one SVD of that matrix), the smallest over twice the rank threshold."""
    if J.shape[0] != J.shape[1] or J.shape[0] == 0:
        return False
    s = np.linalg.svd(rank._scaled(mech, J), compute_uv=False)
    return bool(s[-1] > 2 * rtol * max(1.0, s[0]))


@pytest.mark.parametrize("smallest", [None, 3.0, 2.01, 1.99, 0.5, 0.0])
def test_a_regular_jacobians_mobility_is_the_one_of_the_svd_with_vectors(smallest,
                                                                        monkeypatch):
    """``mobility`` of a square Cq of full rank takes its singular values alone
    (``_regular_condition``, with the condition number's in one call): the same Mobility, condition number's bits included, as the SVD with
    vectors, at the four-bar's guess and with Cq's smallest singular value set to
    ``smallest`` × the rank threshold (1e-9 of the largest) around the margin of 2 (s_max = 4.15)."""
    from pathlib import Path
    import pam2exu
    mech = pam2exu.load(Path(__file__).resolve().parents[2] / "examples" /
                        "four_bar.toml").mechanism()
    q0 = mech.initial_q()
    J = rank.at_guess(mech, 0.0, q0).jacobian[0]
    if smallest is not None:
        scale = rank._scaled(mech, np.ones((1, mech.nq)))
        U, s, Vt = np.linalg.svd(J * scale)
        s[-1] = smallest * 1e-9 * s[0]
        J = (U * s) @ Vt / scale
    assert _regular(mech, J, 1e-9) == (smallest is None or smallest > 2.0)
    regular, condition = rank._regular_condition(mech, J, 1e-9)    # (one SVD call)
    assert regular == _regular(mech, J, 1e-9)
    assert str(condition) == str(rank._condition(mech, 0.0, q0, J))
    fast = rank.mobility(mech, 0.0, q0, jacobian=J)
    monkeypatch.setattr(rank, "_regular_condition", lambda *_: (False, None))
    full = rank.mobility(mech, 0.0, q0, jacobian=J)
    assert fast == full and str(fast.condition) == str(full.condition)
    assert (fast.dof, fast.redundant) == ((0, 0) if smallest is None or smallest > 1.5
                                          else (1, 1))


@pytest.mark.parametrize("name", ["four_bar", "all_elements"])
def test_the_equations_residual_and_c_t_are_the_targets_bits(name):
    """``native.equations`` writes C_t only where the target moves (a law; a constant's
    rows keep −0.0, −f' of f' = 0.0) and subtracts a float target as itself: C and C_t bit
    for bit the plain v − f and −f' of every element's ``target_values``."""
    from pathlib import Path
    import pam2exu
    from pam2exu.analyses import native
    from pam2exu.kinematics import State
    mech = pam2exu.load(Path(__file__).resolve().parents[2] / "examples" /
                        f"{name}.toml").mechanism()
    t = np.linspace(0.0, 0.7, 4)
    st = State(t, np.repeat(mech.initial_q()[None], len(t), axis=0))
    eq = native.equations(mech, st)
    for el, rows in zip(mech.constraints, mech.rows):
        v, target = el.constraint(st)
        f, df, _ = native.target_values(np.asarray(target) if isinstance(target, float)
                                        else target, t, el.equations)
        shape = (len(t), el.equations)
        assert eq.residual[:, rows].tobytes() == np.broadcast_to(v.value - f,
                                                                 shape).tobytes()
        assert eq.c_t[:, rows].tobytes() == np.broadcast_to(np.negative(df), shape).tobytes()


def test_the_rank_tests_coordinates_are_cq_times_the_length_scale_per_solid():
    """``_scaled``: Cq's angle columns times 1 / the length scale in place of a tiled
    (1, 1, 1/scale) row, bit for bit (−0.0 and NaN included), all_elements' 36 columns."""
    from pathlib import Path
    import pam2exu
    mech = pam2exu.load(Path(__file__).resolve().parents[2] / "examples" /
                        "all_elements.toml").mechanism()
    J = rank.at_guess(mech, 0.0, mech.initial_q()).jacobian[0]
    J[0, 2], J[1, 5] = -0.0, np.nan
    tiled = J * np.tile([1.0, 1.0, 1.0 / mech.scale()], len(mech.solids))
    assert rank._scaled(mech, J).tobytes() == tiled.tobytes()

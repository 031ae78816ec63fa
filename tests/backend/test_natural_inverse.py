"""Inverse dynamics in natural coordinates (backend/natural/inverse.py): each solid's
constraint forces W_b = M_b ζ̈_b − Q_b with its constant mass matrix, and the multipliers of
M z̈ + Φ_zᵀ μ = Q.

References, independent of inverse.py: the reference-point force pass's Q_inertia −
Q_applied and kinetic energy (analyses/force_pass.py: m a_G at G and J_G α, the elements'
own loads) on the same motion turned into x, y, fi (``Natural.to_rates``);
``Formulation.mass_matrix``; and, for an angular actuator, whose equation is fi2 − fi1 =
f(t) in both formulations, the reference-point multiplier of its row (μ = −λ: the two
passes put the constraint forces on opposite sides).
"""
import warnings
from pathlib import Path

import numpy as np
import pytest

import pam2exu
from pam2exu.analyses import force_pass
from pam2exu.backend.natural import Natural, inverse
from pam2exu.elements.actuators import AngularActuator
from pam2exu.kinematics import State

ROOT = Path(__file__).resolve().parents[2]
STEPS = 12


def _redundant():
    """The parallelogram with a fifth bar (one redundant constraint), with masses and
    gravity."""
    model = pam2exu.load(ROOT / "tests/data/parallelogram5.toml")
    model.gravity = 9.81
    for k, name in enumerate(("crank1", "crank2", "crank3", "coupler")):
        model[name].mass, model[name].inertia = 0.5 + k, 0.01 * (k + 1)
    return model, True


def _six_bar():
    """A Stephenson six-bar: a ternary coupler (its third basic point tied by rigid-body
    rows), a spring and a torsor on it."""
    m = pam2exu.Model("stephenson", gravity=9.81)
    m.add_solid("ground", points={"O1": [0, 0], "O2": [0.4, 0], "O3": [0.6, 0.5]})
    m.add_solid("crank", points={"O": [0, 0], "A": [0.1, 0]}, mass=0.3, inertia=2e-4,
                cog=[0.05, 0])
    m.add_solid("coupler", points={"A": [0, 0], "B": [0.35, 0], "C": [0.2, 0.15]}, mass=0.8,
                inertia=8e-3, cog=[0.18, 0.05], x=0.1, fi=0.9)
    m.add_solid("rocker", points={"O": [0, 0], "B": [0.3, 0]}, mass=0.6, inertia=4e-3,
                cog=[0.15, 0], x=0.4, fi=1.6)
    m.add_solid("link", points={"C": [0, 0], "D": [0.4, 0]}, mass=0.4, inertia=3e-3,
                cog=[0.2, 0.01], x=0.15, y=0.3, fi=0.2)
    m.add_solid("rocker2", points={"O": [0, 0], "D": [0.3, 0]}, mass=0.5, inertia=3e-3,
                cog=[0.12, 0], x=0.6, y=0.5, fi=3.5)
    m.add("fixed", anc1="ground")
    for name, a, b in [("R1", "ground.O1", "crank.O"), ("R2", "crank.A", "coupler.A"),
                       ("R3", "coupler.B", "rocker.B"), ("R4", "ground.O2", "rocker.O"),
                       ("R5", "coupler.C", "link.C"), ("R6", "link.D", "rocker2.D"),
                       ("R7", "ground.O3", "rocker2.O")]:
        m.add("revolute", name=name, anc1=a, anc2=b)
    m.add("spring", name="S", anc1="ground.O3", anc2="coupler.C", C=[1.0, 50.0, 0.5, 0.3])
    m.add("torsor", name="T", anc1="link.C", C=[0.5, -1.0, 0.2])
    m.add("angular_actuator", name="motor", anc1="ground", anc2="crank", C=[0.0, 2.0])
    return m, False


MODELS = {
    "four_bar": lambda: (pam2exu.load(ROOT / "examples/four_bar.toml"), False),
    "slider_crank": lambda: (pam2exu.load(ROOT / "examples/slider_crank.toml"), False),
    "all_elements": lambda: (pam2exu.load(ROOT / "examples/all_elements.toml"), False),
    "parallelogram5": _redundant,
    "six_bar": _six_bar,
}


@pytest.fixture(scope="module", params=list(MODELS))
def motion(request):
    """The natural kinematic run's z, ż, z̈ (ż, z̈ from the formulation's own velocity and
    acceleration equations, least norm) and the same motion in x, y, fi."""
    model, redundant = MODELS[request.param]()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = pam2exu.run(model, analysis="kinematic", steps=STEPS, backend="natural")
    mech = model.mechanism()
    backend = Natural()
    form = backend.formulation(mech)
    t, q = np.asarray(res.t), mech.coordinates(res)
    z = form.from_q(q)
    pinv = np.linalg.pinv(form.terms.dense(form.terms.jacobian(z)), rcond=1e-12)
    zd = np.einsum("nzm,nm->nz", pinv, form.terms.velocity_rhs(t))
    zdd = np.einsum("nzm,nm->nz", pinv, form.terms.gamma(t, z, zd))
    qd, qdd = backend.to_rates(form, mech, z, zd, zdd)
    return dict(name=request.param, mech=mech, form=form, redundant=redundant, t=t, q=q,
                qd=qd, qdd=qdd, z=z, zd=zd, zdd=zdd)


def test_the_solids_mass_matrices_sum_to_the_formulation_s(motion):
    """Σ A_bᵀ M_b A_b = Formulation.mass_matrix() (measured: ≤ 1.1e-16)."""
    form = motion["form"]
    bd = inverse.bodies(form)
    M = np.einsum("bkz,bkl,blw->zw", bd.A, bd.mass, bd.A)
    np.testing.assert_allclose(M, form.mass_matrix(), rtol=0, atol=1e-15)


def test_the_constraint_forces_are_the_reference_point_pass_s(motion):
    """W on x, y, fi = Q_inertia − Q_applied of the native pass (dampers included), and
    Σ ½ ζ̇ᵀ M_b ζ̇ its kinetic energy, to 1e-12 of their largest (measured: ≤ 1.0e-14
    and 1.3e-14)."""
    m = motion
    st = State(m["t"], m["q"], m["qd"])
    inertia, kinetic = force_pass.inertia_forces(m["mech"], st, m["qdd"])
    native = inertia - force_pass.applied_forces(m["mech"], st, damping=True).force
    W = inverse.constraint_forces(m["form"], m["t"], m["z"], m["zd"], m["zdd"], m["q"])
    found = inverse.on_pose(m["form"], m["z"], m["q"], W)
    assert np.abs(native).max() > 0
    np.testing.assert_allclose(found, native, rtol=0, atol=1e-12 * np.abs(native).max())
    np.testing.assert_allclose(inverse.kinetic_energy(m["form"], m["zd"]), kinetic,
                               rtol=0, atol=1e-12 * np.abs(kinetic).max())


def test_the_multipliers_balance_the_equations_of_motion(motion):
    """M z̈ + Φ_zᵀ μ = Q (Q from the loads alone), to 1e-12 of |Q| + |M z̈| (measured:
    ≤ 1.0e-14, the redundant parallelogram's least-norm μ)."""
    m, form = motion, motion["form"]
    W = inverse.constraint_forces(form, m["t"], m["z"], m["zd"], m["zdd"], m["q"])
    mu = inverse.multipliers(form, m["z"], W, m["redundant"])
    bd = inverse.bodies(form)
    Q = np.einsum("bkz,nbk->nz", bd.A, inverse.applied(form, m["t"], m["z"], m["q"], m["zd"]))
    J = form.terms.dense(form.terms.jacobian(m["z"]))
    inertia = m["zdd"] @ form.mass_matrix().T
    left = inertia + np.einsum("nmz,nm->nz", J, mu)
    scale = np.abs(Q).max() + np.abs(inertia).max()
    np.testing.assert_allclose(left, Q, rtol=0, atol=1e-12 * scale)


def test_an_angular_actuator_s_multiplier_is_its_reference_point_one(motion):
    """fi2 − fi1 = f(t) is the same equation in both formulations, so its natural multiplier
    is minus the reference-point pass's λ of its row (measured: ≤ 8.8e-15 of the largest)."""
    m, form, mech = motion, motion["form"], motion["mech"]
    if m["redundant"]:
        pytest.skip("least norm differs between the formulations (other unknowns)")
    st = State(m["t"], m["q"], m["qd"])
    inertia, _ = force_pass.inertia_forces(mech, st, m["qdd"])
    rhs = inertia - force_pass.applied_forces(mech, st, damping=True).force
    lam = force_pass.multipliers(mech, st, rhs, False)
    W = inverse.constraint_forces(form, m["t"], m["z"], m["zd"], m["zdd"], m["q"])
    mu = inverse.multipliers(form, m["z"], W, False)
    checked = 0
    for el, rows in zip(mech.constraints, mech.rows):
        if not isinstance(el, AngularActuator):
            continue
        row = form.labels.index(f"'{el.name}' ({el.type})")
        scale = np.abs(lam[:, rows.start]).max()
        np.testing.assert_allclose(mu[:, row], -lam[:, rows.start], rtol=0,
                                   atol=1e-10 * scale)
        checked += 1
    assert checked


# ---- the kinetostatic analysis through them (backend/natural/reactions.py) -----------------

def _natural(model, gives_reactions, monkeypatch, analysis="kinetostatic"):
    with monkeypatch.context() as patch:
        patch.setattr(Natural, "gives_reactions", gives_reactions)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return pam2exu.run(model, analysis=analysis, steps=STEPS, backend="natural")


@pytest.mark.parametrize("name", list(MODELS))
def test_kinetostatic_reactions_equal_the_reference_point_pass(name, monkeypatch):
    """The natural backend's kinetostatic run takes its reactions from natural-coordinate
    inverse dynamics (``reactions_from``); every force column equals the reference-point
    pass's on the same motion (that backend declaring no reactions of its own) to 1e-9 of
    the column's largest value, or of its element's other columns where it is zero (the
    slider-crank's guide.Mz: 8.9e-16 N·m against 0) (measured: ≤ 7.1e-14, all_elements'
    guide.Mz; the redundant parallelogram's least norm 2.6e-14), and the power balance is
    checked on both."""
    model, _ = MODELS[name]()
    natural = _natural(model, True, monkeypatch)
    native = _natural(model, False, monkeypatch)
    assert natural.info["reactions_from"] == "the natural-coordinate backend's inverse dynamics"
    assert "reactions_from" not in native.info
    assert list(natural.columns) == list(native.columns)
    for column in native.columns:            # a column that is zero: its element's scale
        element = column.split(".")[0]
        scale = max(np.abs(native[c]).max() for c in native.columns
                    if c == column or (c.startswith(element + ".") and not native[column].any()))
        np.testing.assert_allclose(natural[column], native[column], rtol=0,
                                   atol=1e-9 * scale + 1e-300, err_msg=column)
    assert natural.info["power_balance_steps"] == native.info["power_balance_steps"] > 0
    assert natural.info["power_balance_error"] <= natural.info["power_balance_tolerance"]


@pytest.mark.parametrize("name", list(MODELS))
def test_quasi_static_reactions_are_the_inverse_dynamics_at_rest(name, monkeypatch):
    """The quasi-static equilibrium Cqᵀ λ = −Q_applied is the inverse dynamics of the
    configurations at rest (q̇ = q̈ = 0: no inertia, no damper force): the natural backend's
    quasi-static run takes its reactions from its own inverse dynamics at rest
    (``reactions_from``), and every force column equals the reference-point pass's static
    solve on the same motion (the backend declaring no reactions of its own) to 1e-9 of the
    largest of its element's columns, plus round-off of the run's largest (1e-13 of it: a
    column that is round-off on both, as all_elements' gear mesh, which transmits nothing
    at rest, 1.1e-17 N on each) (measured: ≤ 5.3e-14 of its element's largest, the
    redundant parallelogram's least norm; all_elements' spring-damper and its torsional
    one at rest: no damper force in either)."""
    model, _ = MODELS[name]()
    natural, native = (_natural(model, gives, monkeypatch, "quasi_static")
                       for gives in (True, False))
    assert natural.info["reactions_from"].startswith(
        "the natural-coordinate backend's inverse dynamics at rest")
    assert native.info["reactions_from"].startswith("native")
    assert list(natural.columns) == list(native.columns)
    forces = [c for c in native.columns if c.split(".")[-1] in ("Fx", "Fy", "Mz", "F", "M")]
    assert forces
    largest = max(np.abs(native[c]).max() for c in forces)
    for column in native.columns:
        element = column.split(".")[0]
        scale = max(np.abs(native[c]).max() for c in native.columns
                    if c.startswith(element + "."))
        np.testing.assert_allclose(natural[column], native[column], rtol=0,
                                   atol=1e-9 * scale + 1e-13 * largest, err_msg=column)


def test_a_mechanism_whose_every_solid_is_held_gets_the_reference_point_pass():
    """No natural coordinate at all (every solid held by a fixed link): the natural backend
    leaves the reactions to the reference-point pass, which holds the bar's weight (m g at
    its centre of mass, the moment m g x_G about its origin); it raised a ValueError."""
    m = pam2exu.Model("held", gravity=9.81)
    m.add_solid("ground")
    m.add_solid("bar", points={"O": [0, 0], "A": [0.1, 0]}, mass=2.0, inertia=0.01,
                cog=[0.05, 0.0])
    m.add("fixed", anc1="ground")
    m.add("fixed", name="hold", anc1="bar")
    res = pam2exu.run(m, analysis="kinetostatic", steps=4, backend="natural")
    assert "reactions_from" not in res.info
    np.testing.assert_allclose(res["hold.Fy"], 2.0 * 9.81, rtol=1e-14)
    np.testing.assert_allclose(res["hold.Mz"], 2.0 * 9.81 * 0.05, rtol=1e-14)


def test_csr_is_scipys_matrix_of_the_dense_array():
    """inverse.csr builds the matrix scipy.sparse.csr_matrix(dense) makes: the same data,
    column indices and row starts (so the same sums in every product), zeros and negative
    zeros left out, an empty row kept."""
    from scipy import sparse
    dense = np.array([[0.0, 2.5, -0.0, 1.0], [0.0, 0.0, 0.0, 0.0], [-3.0, 0.0, 0.125, 0.0]])
    ours, theirs = inverse.csr(dense), sparse.csr_matrix(dense)
    for name in ("data", "indices", "indptr"):
        assert np.array_equal(getattr(ours, name), getattr(theirs, name))
    assert ours.shape == theirs.shape and ours.has_sorted_indices
    x = np.array([[1.0, -2.0, 3.0, 0.5], [0.1, 0.2, 0.3, 0.4]])
    assert np.array_equal(inverse.times(x, ours), inverse.times(x, theirs))


def test_csr_of_one_pattern_shares_the_indices_and_keeps_its_own_numbers():
    """A second matrix of one nonzero pattern (a study's next variant) gets scipy's matrix of
    its own numbers, sharing the first's read-only index arrays; the first keeps its numbers;
    a matrix whose zeros fall elsewhere gets its own pattern."""
    from scipy import sparse
    dense = np.array([[0.0, 2.5, 0.0], [-3.0, 0.0, 0.125]])
    first = inverse.csr(dense)
    second = inverse.csr(dense * 7.0 - 0.5 * (dense != 0))
    theirs = sparse.csr_matrix(dense * 7.0 - 0.5 * (dense != 0))
    for name in ("data", "indices", "indptr"):
        assert np.array_equal(getattr(second, name), getattr(theirs, name))
    assert second.indices is first.indices and second.indptr is first.indptr
    assert not first.indices.flags.writeable and not first.indptr.flags.writeable
    assert np.array_equal(first.data, [2.5, -3.0, 0.125])
    moved = dense.copy()
    moved[0, 1], moved[0, 0] = 0.0, 1.0
    assert np.array_equal(inverse.csr(moved).indices, sparse.csr_matrix(moved).indices)


@pytest.mark.parametrize("d", [1.0, -1.0])
def test_one_revolute_incidence_is_its_own_inverse(d):
    """A pin of one revolute on one moving solid: D = [[±1]], D⁺ = D exactly (pinv's)."""
    from pam2exu.backend.natural.reactions import _incidence_inverse
    D = np.array([[d]])
    assert np.array_equal(_incidence_inverse(D), np.linalg.pinv(D))
    two = np.array([[1.0, -1.0]])
    assert np.array_equal(_incidence_inverse(two), np.linalg.pinv(two))


def _four_bar(o4=0.4, b=0.35):
    """The four-bar with its rocker's ground pin at (o4, 0) and its coupler's B at (b, 0)."""
    model = pam2exu.load(ROOT / "examples/four_bar.toml")
    model["ground"].points["O4"], model["coupler"].points["B"] = [o4, 0.0], [b, 0.0]
    return model


def test_plans_of_one_structure_share_their_shape_and_keep_their_numbers(monkeypatch):
    """A variant of the four-bar (another ground pin and coupler: one structure) gets the
    first's plan shape (the same read-only index arrays and pins' incidences) with its own
    ground points and rates, and its reactions from the shared shape are, bit for bit,
    those of its plan made afresh."""
    from pam2exu.backend.natural import reactions
    from pam2exu.backend.natural.formulation import Formulation
    monkeypatch.setattr(reactions, "_SHAPES", {})
    runs = []
    for fresh in (True, False):
        if fresh:
            reactions._SHAPES.clear()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            runs.append(pam2exu.run(_four_bar(0.41, 0.36), analysis="kinetostatic", steps=6,
                                    backend="natural"))
        first = reactions.plan(Formulation(_four_bar().mechanism()))
    assert runs[1].info.reactions_from.endswith("inverse dynamics")
    for name in ("B.Fx", "B.Fy", "motor.Mz", "base.Mz"):
        assert np.array_equal(runs[0][name], runs[1][name]), name
    other = reactions.plan(Formulation(_four_bar(0.41, 0.36).mechanism()))
    assert other.rows_of is first.rows_of and other.copy_terms is first.copy_terms
    assert not first.hat_frames[0].flags.writeable and not first.y_rows.flags.writeable
    ground = [p for p in other.ordered_pins if p.columns is None]
    assert [p.inverse is q.inverse for p, q in zip(ground, first.ordered_pins[2:])] == [1, 1]
    assert [list(p.constant) for p in ground] == [[0.0, 0.0], [0.41, 0.0]]
    assert [list(p.constant) for p in first.ordered_pins[2:]] == [[0.0, 0.0], [0.4, 0.0]]
    assert not np.array_equal(other.rates.toarray(), first.rates.toarray())


@pytest.mark.parametrize("index", [[2, 3, 4], [0], [0, 2], [3, 2], []])
def test_taken_indices_are_a_slice_where_consecutive_and_take_the_same_entries(index):
    """The wrench pass's indices: a slice (a view) where consecutive, the array elsewhere;
    either takes the same entries."""
    from pam2exu.backend.natural.reactions import _taken
    x = np.arange(30.0).reshape(6, 5)
    taken = _taken(index)
    consecutive = len(index) > 0 and list(index) == list(range(index[0], index[0] + len(index)))
    assert isinstance(taken, slice) == consecutive
    assert np.array_equal(x[taken], x[np.array(index, dtype=int)])


@pytest.mark.parametrize("massless", [None, "link"])
def test_gravity_is_each_solid_s_weight_at_its_centre_of_mass(massless):
    """Loads.gravity, made for all solids at once, is bit for bit what Loads.force gives
    for (0, −m g) at each solid's centre of mass, solid by solid (a massless solid in
    between: the solids are not consecutive)."""
    from pam2exu.backend.natural.formulation import Formulation
    from pam2exu.backend.natural.loads import Loads
    model = _six_bar()[0]
    if massless:
        model[massless].mass = 0.0
    mech = model.mechanism()
    form = Formulation(mech)
    made, expected = (Loads(form, np.zeros((3, form.nz)), np.zeros((3, mech.nq)))
                      for _ in range(2))
    made.gravity(mech.gravity)
    for i, s in enumerate(mech.solids):
        if float(s.mass):
            expected.force(i, (float(s.cog[0]), float(s.cog[1])),
                           np.tile([0.0, -float(s.mass) * mech.gravity], (3, 1)))
    assert np.array_equal(made.Q, expected.Q) and np.any(made.Q)


def _rigid_rows_made(form):
    """Each moving solid's rigid-body rows made by ``Formulation._rigid_equations`` alone
    (every other solid taken as ground), their solid for each: the reference."""
    from pam2exu.backend.natural.formulation import Formulation
    owners = []
    for i in range(len(form.frames)):
        if i in form.grounds:
            continue
        alone = object.__new__(Formulation)
        alone.mech, alone.frames, alone.own = form.mech, form.frames, form.own
        alone.grounds = {j: None for j in range(len(form.frames)) if j != i}
        alone._rows = []
        alone._rigid_equations()
        owners += [i] * len(alone._rows)
    return owners


def test_rigid_rows_counted_are_the_rows_made_solid_by_solid():
    """The owners the formulation records for its rigid-body rows (|v|², further basic
    points, its angle; what the reaction plan reads) are those of the rows made solid by
    solid, on models with a ternary solid, unit vectors, angle coordinates (an actuator,
    every solid's) and a solid held by two ground pins."""
    from pam2exu.backend.natural.formulation import Formulation
    models = [_six_bar()[0], _redundant()[0]] + [pam2exu.load(ROOT / p) for p in (
        "examples/all_elements.toml", "examples/slider_crank.toml", "examples/scotch_yoke.toml",
        "tests/data/every_element.toml")]
    for model in models:
        mech = model.mechanism()
        for all_angles in (False, True):
            form = Formulation(mech, all_angles=all_angles)
            made = _rigid_rows_made(form)
            assert form.rigid_owners == made and len(made) > 0, model.name


def test_solids_matrices_are_shared_between_formulations_of_one_structure():
    """Two formulations of one mechanism (a study's variants) share the CSR matrices of
    their solids' A (made once per exact matrix); another A gets its own, scipy's."""
    from scipy import sparse
    from pam2exu.backend.natural.formulation import Formulation
    mech = pam2exu.load(ROOT / "examples/four_bar.toml").mechanism()
    one, two = (inverse.bodies(Formulation(mech)) for _ in range(2))
    assert one.flat is two.flat and one.flat_t is two.flat_t
    assert (one.flat != sparse.csr_matrix(one.A.reshape(len(one.A) * 4, -1))).nnz == 0
    other = one.A.reshape(len(one.A) * 4, -1).copy()
    other[0, 0] += 1.0
    assert inverse.shared_csr(other) is not one.flat

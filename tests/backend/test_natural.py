"""The natural-coordinate backend against independent computations.

References: the Exudyn backend on the same models (a different formulation and solver); the
native pass (pam2exu's reference-point Jacobian) for the velocities and accelerations the
natural backend computes itself; the kinetic energy of a rigid body from its mass at G and
its inertia about G; pam2exu's own force pass for the static multipliers.
"""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import pam2exu
from pam2exu.analyses import native
from pam2exu.analyses.job import prepare
from pam2exu.backend.natural import Natural
from pam2exu.elements.forces import Spring
from pam2exu.kinematics import column
from pam2exu.registry import ANALYSES

ROOT = Path(__file__).resolve().parents[2]
MODELS = sorted((ROOT / "examples").glob("*.toml")) + [ROOT / "tests/data/parallelogram5.toml"]


#: the clearance analysis's refusal of a self-stress without clearance (condition (i))
CONDITION_I = (r"^t=0: the clearance analysis of .* cannot start: the elements .* "
               r"\(condition \(i\): a self-stress")


def quietly(function, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")        # parallelogram5: redundant constraints
        return function(*args, **kwargs)


def relative_difference(a, b) -> tuple[float, str]:
    """Largest |a − b| of any column over the largest |value| of its unit in a, and where."""
    scale: dict[str, float] = {}
    for c in a.columns:
        scale[a.units[c]] = max(scale.get(a.units[c], 0.0), float(np.max(np.abs(a[c]))))
    worst = (0.0, "")
    for c in a.columns:
        d = float(np.max(np.abs(a[c] - b[c]))) / max(scale[a.units[c]], 1e-300)
        worst = max(worst, (d, c))
    return worst


@pytest.mark.parametrize("analysis", list(ANALYSES))
@pytest.mark.parametrize("path", MODELS, ids=[p.stem for p in MODELS])
def test_both_backends_give_the_same_results(path, analysis, request):
    """Issue 12 acceptance: every shipped model, every analysis, 1e-9 relative (per unit).
    The over-constrained parallelogram has no clearance joint: the clearance analysis
    refuses it (condition (i)) on both backends. all_elements' clearance run over its whole
    second takes a minute on two cores: its first 0.1 s here, the whole run with --long."""
    if analysis == "clearance" and path.stem == "parallelogram5":
        for backend in ("exudyn", "natural"):
            with pytest.raises(pam2exu.ModelError, match=CONDITION_I):
                quietly(pam2exu.run, path, analysis=analysis, backend=backend)
        return
    settings = {}
    if (analysis == "clearance" and path.stem == "all_elements"
            and not request.config.getoption("--long")):
        settings = {"t_end": 0.1, "steps": 10}
    exudyn = quietly(pam2exu.run, path, analysis=analysis, **settings)
    natural = quietly(pam2exu.run, path, analysis=analysis, backend="natural", **settings)
    assert natural.columns == exudyn.columns
    difference, where = relative_difference(exudyn, natural)
    assert difference < 1e-9, (where, difference)


@pytest.mark.parametrize("name", ["four_bar", "all_elements", "slider_crank", "scotch_yoke"])
def test_own_rates_equal_the_native_pass(name):
    """The backend's q̇, q̈ (its own linear solves, exact quadratic velocity terms) against
    the native reference-point pass at the same positions."""
    job = prepare(ROOT / "examples" / f"{name}.toml", analysis="kinematic", steps=100)
    backend = Natural()
    found = backend.solve_positions(job.mech, job.times, job.mech.initial_q(), job.solver,
                                    rates=True)
    assert found.solved == len(job.times)
    qd, qdd, _ = native.rates(job.mech, job.times, found.q, True, False)
    speed = np.max(np.abs(qd)) + 1e-300
    assert np.max(np.abs(found.qd - qd)) < 1e-11 * speed
    assert np.max(np.abs(found.qdd - qdd)) < 1e-10 * np.max(np.abs(qdd))


def kinetic_energy(solid, x_dot, y_dot, fi, fi_dot) -> float:
    """T = ½ m |v_G|² + ½ I_G ω², v_G = Ṙ + ω Ω A(fi) s_G (the reference-point formula)."""
    gx, gy = (float(c) for c in solid.cog)
    c, s = np.cos(fi), np.sin(fi)
    AsG = np.array([c * gx - s * gy, s * gx + c * gy])
    vG = np.array([x_dot, y_dot]) + fi_dot * np.array([-AsG[1], AsG[0]])
    return 0.5 * float(solid.mass) * vG @ vG + 0.5 * float(solid.inertia) * fi_dot ** 2


@pytest.mark.parametrize("name", ["four_bar", "all_elements", "slider_crank", "scotch_yoke"])
def test_constant_mass_matrix_gives_each_bodys_kinetic_energy(name):
    """Issue 12 acceptance: for each body and random rigid velocities, ½ żᵀ M_body ż equals
    the body's kinetic energy from m at G and I_G, to 1e-13 relative."""
    job = prepare(ROOT / "examples" / f"{name}.toml", analysis="assembly")
    form = Natural().formulation(job.mech)
    q = quietly(pam2exu.run, ROOT / "examples" / f"{name}.toml", analysis="assembly")
    q = np.array([q[f"{s.name}.{v}"][0] for s in job.mech.solids for v in ("x", "y", "fi")])
    z = form.from_q(q)[0]
    rng = np.random.default_rng(12)
    J = form.terms.dense(form.terms.jacobian(z[None]))[0]
    checked = 0
    for i, solid in enumerate(job.mech.solids):
        if i in form.grounds or not (float(solid.mass) or float(solid.inertia)):
            continue
        rows = [r for r, label in enumerate(form.labels)
                if label == f"rigid '{solid.name}'"]          # the body stays rigid
        null = np.linalg.svd(J[rows])[2][len(rows):].T
        for _ in range(5):
            zd = null @ rng.normal(size=null.shape[1])
            f = form.frames[i]
            v, vd = form.matrix(f.v) @ z + form.constants(f.v), form.matrix(f.v) @ zd
            p_dot = form.matrix(f.p) @ zd
            w = (v[0] * vd[1] - v[1] * vd[0]) / (v @ v)
            fi = q[column(i, 2)]
            c, s = np.cos(fi), np.sin(fi)
            Asp = np.array([c * f.sp[0] - s * f.sp[1], s * f.sp[0] + c * f.sp[1]])
            R_dot = p_dot - w * np.array([-Asp[1], Asp[0]])
            reference = kinetic_energy(solid, *R_dot, fi, w)
            got = 0.5 * zd @ form.mass_matrix([i]) @ zd
            assert got == pytest.approx(reference, rel=1e-13, abs=1e-300)
            checked += 1
    assert checked >= 5


def test_quasi_static_multipliers_come_from_natural_forces():
    """The quasi-static check holds the natural backend's static multipliers (forces taken
    from natural coordinates: gravity, torsors, springs, torsional springs) against pam2exu's
    own equilibrium; a spring whose natural-coordinate force is off by 1e-6 is caught."""
    path = ROOT / "examples" / "all_elements.toml"
    res = quietly(pam2exu.run, path, analysis="quasi_static", backend="natural")
    assert res.info["equilibrium_error"] < 1e-12


def test_a_wrong_natural_force_is_caught(monkeypatch):
    path = ROOT / "examples" / "all_elements.toml"
    right = Spring.natural_loads

    def off(self, nl):
        class Scaled:                 # the spring's force 1e-6 too large
            def __getattr__(self, name):
                return getattr(nl, name)

            def force(self, solid, local, force):
                nl.force(solid, local, force * (1 + 1e-6))
        right(self, Scaled())

    monkeypatch.setattr(Spring, "natural_loads", off)
    with pytest.raises(pam2exu.TranslationError, match="multipliers"):
        quietly(pam2exu.run, path, analysis="quasi_static", backend="natural")


def test_free_assembly_is_the_nearest_configuration():
    """Without its motor the four-bar has a free degree of freedom: both backends settle it
    nearest the guess (the same weighted distance), to 1e-9."""
    model = pam2exu.load(ROOT / "examples" / "four_bar.toml")
    model.elements = [e for e in model.elements if e.name != "motor"]
    exudyn = quietly(pam2exu.run, model, analysis="assembly")
    natural = quietly(pam2exu.run, model, analysis="assembly", backend="natural")
    difference, where = relative_difference(exudyn, natural)
    assert difference < 1e-9, (where, difference)
    assert abs(natural["crank.fi"][0] - 0.02) > 1e-6        # the crank did move


def test_fi_follows_the_solids_vector_not_the_anti_aligned_angle():
    """The tie v × e(θ) = 0 of an angle coordinate also holds at θ + π: x, y, fi come from
    the vector (θ only numbers the turns), so such a solution shows as a violated actuator
    (π) in pam2exu's residual check instead of passing as a crank turned half a turn."""
    job = prepare(ROOT / "examples" / "four_bar.toml", analysis="assembly")
    backend = Natural()
    form = backend.formulation(job.mech)
    q0 = quietly(pam2exu.run, ROOT / "examples" / "four_bar.toml", analysis="assembly")
    q0 = np.array([q0[f"{s.name}.{v}"][0] for s in job.mech.solids for v in ("x", "y", "fi")])
    z = form.from_q(q0)
    crank = job.mech.index["crank"]
    z[0, form.frames[crank].angle] += np.pi + 4 * np.pi           # anti-aligned, 2 turns on
    q = backend.to_q(form, job.mech, z, q0)[0]
    assert q[column(crank, 2)] == pytest.approx(q0[column(crank, 2)] + 4 * np.pi, abs=1e-12)
    motor = next(r for el, r in zip(job.mech.constraints, job.mech.rows) if el.name == "motor")
    residual = native.residuals(job.mech, [0.0], q[None])[0, motor]
    assert abs(abs(residual[0]) - 4 * np.pi) < 1e-12


def test_a_solid_held_by_two_ground_pins_adds_no_equation():
    """A bracket pinned to both ground pivots of the four-bar: its two basic points are
    constants, so its rigid-body equation has no coordinate and is left out (a zero row
    otherwise); both backends give the same motion (redundant constraints in pam2exu's)."""
    model = pam2exu.load(ROOT / "examples" / "four_bar.toml")
    model.add_solid("bracket", points={"a": [0.0, 0.0], "b": [0.4, 0.0]})
    model.add("revolute", name="Pa", anc1="ground.O2", anc2="bracket.a")
    model.add("revolute", name="Pb", anc1="ground.O4", anc2="bracket.b")
    form = Natural().formulation(model.mechanism())
    assert "rigid 'bracket'" not in form.labels
    exudyn = quietly(pam2exu.run, model, analysis="kinematic", steps=50)
    natural = quietly(pam2exu.run, model, analysis="kinematic", steps=50, backend="natural")
    difference, where = relative_difference(exudyn, natural)
    assert difference < 1e-9, (where, difference)


def test_chunked_solves_and_conversions_give_the_same_run(monkeypatch):
    """Memory is bounded by solving and converting the steps in chunks (1,000,000 steps of
    the four-bar: 985 MB peak, docs/performance.md): chunks of a few hundred steps give the
    run of one chunk, bit for bit."""
    import pam2exu.backend.natural as natural
    from pam2exu.backend.natural import linear, solver
    path = ROOT / "examples" / "four_bar.toml"
    whole = pam2exu.run(path, analysis="kinematic", steps=5000, backend="natural")
    monkeypatch.setattr(linear, "CHUNK_BYTES", 200_000)
    monkeypatch.setattr(natural, "CONVERT_ROWS", 333)
    job = prepare(path, analysis="kinematic", steps=5000)
    assert Natural().formulation(job.mech) is not None
    assert solver.Solver(Natural().formulation(job.mech).terms, np.ones(5), None,
                         False).rows_per_chunk() < 1000
    chunked = pam2exu.run(path, analysis="kinematic", steps=5000, backend="natural")
    for c in whole.columns:
        np.testing.assert_array_equal(chunked[c], whole[c], err_msg=c)


def test_the_unwrapping_is_numpys_bit_for_bit():
    """The conversion's unwrapping of the free angles (``_unwrapped``: corrections only at
    the wraps) gives ``numpy.unwrap``'s bits: wraps either way, steps of exactly ±π (numpy's
    boundary rule), −0.0 (numpy's + 0.0), more wraps than MOST_WRAPS, non-finite values."""
    from pam2exu.backend import natural
    rng = np.random.default_rng(7)
    turning = np.linspace(0.0, 40.0, 3001)
    angles = np.arctan2(np.sin([turning, -0.7 * turning + 1.0]),
                        np.cos([turning, -0.7 * turning + 1.0]))
    cases = [angles, angles[:, :2], np.array([[0.0, np.pi, 0.0, -np.pi, -0.0, 2 * np.pi]]),
             np.array([[-0.0, -0.0, 4.0, -0.0]]),
             np.arctan2(np.sin(np.linspace(0, 900, 2000)), np.cos(np.linspace(0, 900, 2000)))[None],
             np.array([[0.1, 3.5, np.inf, 2.0, np.nan]])]
    cases += [np.cumsum(rng.normal(0.0, 2.5, (2, 50)), axis=1) for _ in range(20)]
    with np.errstate(invalid="ignore"):
        for raw in cases:
            assert natural._unwrapped(raw).tobytes() == np.unwrap(raw, axis=1).tobytes()


def test_from_q_of_an_assembled_pose_is_on_the_constraints_with_a_ground_point_at_1():
    """``Formulation.from_q`` of a configuration that satisfies the constraints gives z with
    Φ(z) = 0 (each coordinate a basic point's x, y, or an angle, of that configuration).
    A ground point at x = 1.0 m is the constant 1.0, whose linear form {1: 1.0} looks like
    a coordinate of coefficient 1: it was written into the last coordinate (the crank's
    angle: 1.0 instead of 0.0). Reference: the four-bar moved 0.6 m to the right, its
    assembled pose at t = 0 from the Exudyn backend."""
    from pam2exu.backend.natural.formulation import Formulation
    text = (ROOT / "examples" / "four_bar.toml").read_text()
    text = (text.replace("O4 = [0.4, 0.0]", "O4 = [1.0, 0.0]")
            .replace("x = 0.4\ny = 0.0\nfi = 1.85", "x = 1.0\ny = 0.0\nfi = 1.85")
            .replace("B = [0.35, 0.0], P", "B = [0.95, 0.0], P"))
    model = pam2exu.loads(text)
    res = pam2exu.run(model, "assembly", backend="exudyn")
    mech = model.mechanism()
    q = np.array([[res[f"{s.name}.{k}"][0] for s in mech.solids for k in ("x", "y", "fi")]])
    form = Formulation(mech)
    z = form.from_q(q)
    names = [c.name for c in form.coordinates]
    assert z[0, names.index("crank.fi")] == q[0, column(1, 2)] == pytest.approx(0.0)
    assert np.max(np.abs(form.terms.residual(np.zeros(1), z))) < 1e-12


def test_pose_forms_are_the_frames_origins_and_axes_as_linear_forms():
    """K [z; 1] = (x, y, cos fi, sin fi) per solid: K's rows hold, bit for bit, the
    coefficients of each frame's ``origin()`` and ``cos_sin()`` expressions."""
    from pam2exu.backend.natural.forms import ONE
    from pam2exu.backend.natural.formulation import Formulation
    root = Path(__file__).parents[2] / "examples"
    for name in ("all_elements.toml", "slider_crank.toml"):
        f = Formulation(pam2exu.load(root / name).mechanism(), all_angles=True)
        K = np.zeros((4 * len(f.frames), f.nz + 1))
        for k, frame in enumerate(f.frames):
            o, (c, s) = frame.origin(), frame.cos_sin()
            for r, e in enumerate((o.x, o.y, c, s)):
                for i, v in e.linear().items():
                    K[4 * k + r, f.nz if i == ONE else i] += v
        assert f.pose_forms().tobytes() == K.tobytes()

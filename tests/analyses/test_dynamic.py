"""The dynamic analysis (shared/spec/dynamics.md, ``dynamic``).

References, each computed without pam2exu's code (the models and the one-DOF equation are in
references/pendulum.py):
- a free compound pendulum (I_O θ̈ = −m g d cos θ, θ from the +x axis): its period for any
  amplitude θ0 from the hanging position, T = 4 √(I_O / (m g d)) K(sin²(θ0/2)) (scipy's
  complete elliptic integral), the small-amplitude limit 2π √(I_O / (m g d)), its energy,
  and scipy's DOP853 on its equation (rtol 1e-13);
- the pivot force of the pendulum, m a_G − m g, with a_G from θ, θ̇, θ̈;
- a pendulum hanging from a slider that a linear actuator drives (bezier_c2): its one-DOF
  equation I_O θ̈ = m d sin θ ẍ_s − m g d cos θ integrated by DOP853;
- a fully driven model gives the kinetostatic results.
"""
import math
import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.special import ellipk

import pam2exu
from pam2exu.laws import Law
from references.pendulum import D, G, IO, M, pendulum_toml, reference, slider_toml, swing

def pendulum(fi, dfi=0.0, dx=0.0):
    return pam2exu.loads(pendulum_toml(fi, dfi, dx))


def _run(model, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return pam2exu.run(model, **kw)


def _period(amplitude):
    """T = 4 √(I_O/(m g d)) K(k²), k = sin(θ0/2), θ0 the amplitude from hanging."""
    return 4.0 * math.sqrt(IO / (M * G * D)) * ellipk(math.sin(amplitude / 2) ** 2)


@pytest.mark.parametrize("amplitude, tolerance", [(1e-3, 1e-10), (2.5, 1e-8)])
def test_free_pendulum_returns_after_its_period(amplitude, tolerance):
    """Released at rest θ0 from hanging: one period later, back at rest at θ0."""
    T = _period(amplitude)
    if amplitude < 0.01:       # the small-amplitude limit, to 4e-8 relative here
        assert T == pytest.approx(2 * math.pi * math.sqrt(IO / (M * G * D)), rel=1e-7)
    start = -math.pi / 2 + amplitude
    res = _run(pendulum(start), t_end=T, steps=40, tolerance=tolerance)
    assert res.info["integration_error"] <= tolerance
    assert res["lever.fi"][-1] == pytest.approx(start, abs=tolerance * (1 + abs(start)))
    assert res["lever.Dfi"][-1] == pytest.approx(0.0, abs=tolerance)
    half = res["lever.fi"][20]                                   # t = T/2: the far side
    assert half == pytest.approx(-math.pi / 2 - amplitude, abs=tolerance * (1 + abs(half)))


@pytest.mark.parametrize("tolerance", [1e-6, 1e-8, 1e-10])
def test_free_pendulum_against_an_independent_integration(tolerance):
    """Every row within the tolerance of DOP853 on θ̈ = −m g d cos θ / I_O, the energy
    constant to the tolerance, θ̈ from the equation itself, and the pivot force m a_G − m g
    (measured at 1e-8: θ 1.7e-9, θ̇ 1.5e-8 with |θ̇| ≤ 4 rad/s)."""
    res = _run(pendulum(0.3), t_end=2.0, steps=50, tolerance=tolerance)
    ref = reference(res.t, (0.3, 0.0))
    th, w, a = res["lever.fi"], res["lever.Dfi"], res["lever.DDfi"]
    assert np.all(np.abs(th - ref[0]) <= tolerance * (1 + np.abs(ref[0])))
    assert np.all(np.abs(w - ref[1]) <= tolerance * (1 + np.abs(ref[1])))
    np.testing.assert_allclose(a, -M * G * D * np.cos(th) / IO, rtol=1e-12, atol=1e-12)
    energy = 0.5 * IO * w ** 2 + M * G * D * np.sin(th)
    assert np.max(np.abs(energy - energy[0])) <= tolerance * (1 + abs(energy[0])) * 10
    aGx = D * (-np.sin(th) * a - np.cos(th) * w ** 2)
    aGy = D * (np.cos(th) * a - np.sin(th) * w ** 2)
    np.testing.assert_allclose(res["pivot.Fx"], M * aGx, atol=1e-10)
    np.testing.assert_allclose(res["pivot.Fy"], M * aGy + M * G, atol=1e-10)
    np.testing.assert_allclose(res["lever.x"], 0.0, atol=1e-12)       # on its pivot


def test_initial_velocities_are_the_nearest_consistent_ones():
    """Dx = 1 m/s cannot hold at a pivot: the nearest velocities keep Dfi and drop Dx, and
    run says so (issue 22: before, without a word)."""
    with pytest.warns(pam2exu.InputWarning) as caught:
        res = pam2exu.run(pendulum(-math.pi / 2, dfi=2.0, dx=1.0), t_end=0.1, steps=4)
    assert [str(w.message) for w in caught] == [
        "<string>: [[solid]] #2 'lever': the constraints do not allow the initial rates "
        "given, the run starts from the nearest that they do: Dx = 1 m/s given, 0 m/s used"]
    assert res.warnings == [str(caught[0].message)]
    assert res["lever.Dfi"][0] == pytest.approx(2.0, abs=1e-15)
    assert res["lever.Dx"][0] == pytest.approx(0.0, abs=1e-15)
    assert res["lever.Dy"][0] == pytest.approx(0.0, abs=1e-15)


def test_changed_initial_rates_name_each_solid_and_both_values():
    """The free four-bar given Dfi = 2 rad/s on the crank and on the rocker, which the loop
    does not allow together: a warning per solid with the values given and those the run
    starts from (its first row); consistent rates (the pendulum's Dfi) give none."""
    path = pam2exu.__file__.replace("pam2exu/__init__.py",
                                    "examples/equilibrium/spring_four_bar.toml")
    model = pam2exu.load(path)
    model["crank"].Dfi = model["rocker"].Dfi = 2.0
    with pytest.warns(pam2exu.InputWarning) as caught:
        res = pam2exu.run(model, "dynamic", t_end=0.01, steps=2)
    texts = [str(w.message) for w in caught]
    assert len(texts) == 2                 # the coupler was given no rate: not named
    for name in ("crank", "rocker"):
        (text,) = [t for t in texts if f"'{name}':" in t]
        assert f"Dfi = 2 rad/s given, {res[f'{name}.Dfi'][0]:.6g} rad/s used" in text
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        pam2exu.run(pendulum(-math.pi / 2, dfi=2.0), t_end=0.01, steps=2)


def test_pendulum_on_a_driven_slider_against_its_one_dof_equation():
    law = Law("bezier_c2", [0.2, 0.7, 0.5, 0.9])
    res = _run(pam2exu.loads(slider_toml()))
    ref = reference(res.t, (-1.2, 0.0), lambda t: law(np.array([t]))[2][0])
    np.testing.assert_allclose(res["slider.x"], law(res.t)[0], atol=1e-12)
    assert np.max(np.abs(res["lever.fi"] - ref[0])) <= 1e-8 * 3
    assert np.max(np.abs(res["lever.Dfi"] - ref[1])) <= 1e-8 * 10


def test_a_fully_driven_model_gives_the_kinetostatic_results():
    path = pam2exu.__file__.replace("pam2exu/__init__.py", "examples/four_bar.toml")
    res = _run(path, analysis="dynamic", steps=20)
    ref = _run(path, analysis="kinetostatic", steps=20)
    assert res.columns == ref.columns
    np.testing.assert_array_equal(res.to_numpy(), ref.to_numpy())


def test_a_free_motion_without_mass_is_an_error_naming_the_solids():
    model = pam2exu.loads(pendulum_toml(0.3, mass=0.0, inertia=0.0))
    with pytest.raises(pam2exu.ModelError,
                       match="free motion of the solids 'lever' moves no mass and no inertia"):
        pam2exu.run(model)


@pytest.mark.parametrize("backend", ["exudyn", "natural"])
@pytest.mark.parametrize("C1, C2", [(0.2, 0.7), (0.215, 0.705)])    # on rows, between rows
def test_a_ramp_jolts_the_pendulum_by_the_least_kinetic_energy_impulse(C1, C2, backend):
    """A ramp's velocity jumps by v at C1 and back at C2: the plastic impulse of the
    contract changes θ̇ by m d sin θ Δẋ / I_O (the least (Δq̇)ᵀ M Δq̇ with the slider's new
    velocity); a row at a breakpoint reports the values after the jump. Breakpoints on the
    rows and between them, on both backends (measured: Exudyn θ 2e-10, θ̇ 1.6e-8 between
    them; natural 7.6e-11 rad, 5.5e-10 rad/s on them)."""
    C = [C1, C2, 0.5, 0.9]
    res = _run(pam2exu.loads(slider_toml("ramp", C)), backend=backend)
    law = Law("ramp", C)
    v = 0.4 / (C2 - C1)

    y, t_eval = [-1.2, 0.0], res.t
    ref = np.empty((2, len(t_eval)))
    for a, b, jump in ((0.0, C1, v), (C1, C2, -v), (C2, 1.0, 0.0)):
        rows = (t_eval >= a - 1e-12) & ((t_eval < b - 1e-12) | (b == 1.0))
        part = solve_ivp(swing, (a, b), y, method="DOP853", rtol=1e-13, atol=1e-14,
                         dense_output=True)
        ref[:, rows] = part.sol(np.clip(t_eval[rows], a, b))
        y = part.sol(b)
        y = [y[0], y[1] + M * D * math.sin(y[0]) * jump / IO]
    np.testing.assert_allclose(res["slider.x"], law(res.t)[0], atol=1e-12)
    np.testing.assert_allclose(res["slider.Dx"], law(res.t)[1], atol=1e-12)
    assert np.max(np.abs(res["lever.fi"] - ref[0])) <= 3e-8
    assert np.max(np.abs(res["lever.Dfi"] - ref[1])) <= 1e-7


@pytest.mark.parametrize("backend", ["exudyn", "natural"])
def test_a_free_four_bar_keeps_its_energy(backend):
    """The four-bar of examples/equilibrium/spring_four_bar.toml let go from its motor's
    pose (no damper, no torsor): T + V constant to the tolerance, T = ½ q̇ᵀ M q̇ and V of
    gravity and the spring computed here from the result columns, on both backends
    (measured at 1e-8: Exudyn 2.7e-10 J, natural 1.1e-11 relative)."""
    path = pam2exu.__file__.replace("pam2exu/__init__.py",
                                    "examples/equilibrium/spring_four_bar.toml")
    model = pam2exu.load(path)
    res = _run(model, analysis="dynamic", t_end=0.5, steps=25, tolerance=1e-8,
               backend=backend)
    mech = model.mechanism()
    energy = np.zeros(len(res))
    for s in mech.solids:
        x, y, fi = (res[f"{s.name}.{k}"] for k in ("x", "y", "fi"))
        dx, dy, dfi = (res[f"{s.name}.D{k}"] for k in ("x", "y", "fi"))
        gx, gy = s.cog
        c, n = np.cos(fi), np.sin(fi)
        vx = dx - dfi * (n * gx + c * gy)
        vy = dy + dfi * (c * gx - n * gy)
        energy += 0.5 * s.mass * (vx ** 2 + vy ** 2) + 0.5 * s.inertia * dfi ** 2
        energy += s.mass * G * (y + n * gx + c * gy)
    k, free = 400.0, 0.1
    energy += 0.5 * k * (res["spring.ro"] - free) ** 2
    assert np.ptp(energy) <= 1e-8 * (1 + abs(energy[0]))
    assert np.ptp(res["crank.fi"]) > 0.5                     # it moved


def test_the_reactions_pass_the_free_body_checks():
    """Each moving solid of the free four-bar, from the result columns alone: the revolute
    forces (Fx, Fy: solid 1 on solid 2 at the joint, model-format.md), the spring's Força
    (> 0 pulls P towards S) and the weight give m a_G and, about G, I_G θ̈."""
    path = pam2exu.__file__.replace("pam2exu/__init__.py",
                                    "examples/equilibrium/spring_four_bar.toml")
    model = pam2exu.load(path)
    res = _run(model, analysis="dynamic", t_end=0.3, steps=15, tolerance=1e-8)
    solids = {s.name: s for s in model.mechanism().solids}

    def at(name, local):
        x, y, fi = (res[f"{name}.{k}"] for k in ("x", "y", "fi"))
        c, s = np.cos(fi), np.sin(fi)
        return np.array([x + c * local[0] - s * local[1], y + s * local[0] + c * local[1]])

    def accel_G(name):
        s = solids[name]
        fi, w, a = (res[f"{name}.{k}"] for k in ("fi", "Dfi", "DDfi"))
        c, n = np.cos(fi), np.sin(fi)
        r = np.array([c * s.cog[0] - n * s.cog[1], n * s.cog[0] + c * s.cog[1]])
        return (np.array([res[f"{name}.DDx"], res[f"{name}.DDy"]])
                + a * np.array([-r[1], r[0]]) - w ** 2 * r)

    def joint(name):
        return np.array([res[f"{name}.Fx"], res[f"{name}.Fy"]])

    P, S = at("coupler", solids["coupler"].points["P"]), np.array([[0.25], [-0.15]])
    spring = res["spring.Força"] * (S - P) / np.linalg.norm(S - P, axis=0)  # on the coupler
    loads = {   # name: [(force on the solid, where)]
        "crank": [(joint("O2"), at("crank", (0.0, 0.0))), (-joint("A"), at("crank", (0.1, 0)))],
        "coupler": [(joint("A"), at("coupler", (0.0, 0.0))),
                    (-joint("B"), at("coupler", (0.35, 0.0))), (spring, P)],
        "rocker": [(joint("B"), at("rocker", (0.3, 0.0))), (joint("O4"), at("rocker", (0, 0)))],
    }
    for name, forces in loads.items():
        s = solids[name]
        G_ = at(name, s.cog)
        weight = np.array([np.zeros(len(res)), -s.mass * G * np.ones(len(res))])
        total = sum(f for f, _ in forces) + weight
        moment = sum((p - G_)[0] * f[1] - (p - G_)[1] * f[0] for f, p in forces)
        scale = max(np.max(np.abs(f)) for f, _ in forces)
        np.testing.assert_allclose(total, s.mass * accel_G(name), atol=1e-9 * scale)
        np.testing.assert_allclose(moment, s.inertia * res[f"{name}.DDfi"], atol=1e-9 * scale * 0.4)


@pytest.mark.parametrize("where", [(0.0, 0.0, 0.0), (0.2, -0.1, 0.3)])
def test_a_fixed_solid_is_reported_exactly_where_it_is_held(where):
    """Issue 22: the ground of a dynamic run was reported at fi = 3e-81 … 9e-32 and moving
    at 7e-31 m/s: the least-norm projections onto the constraints (``dynamic.project``,
    ``nearest_velocities``) spread round-off onto the coordinates a fixed link holds. They
    are now the fixed link's pose exactly (==, the ground also moved to x, y, fi = 0.2,
    −0.1, 0.3), at rest exactly, on both backends, and the free crank still falls."""
    path = pam2exu.__file__.replace("pam2exu/__init__.py",
                                    "examples/equilibrium/spring_four_bar.toml")
    text = open(path, encoding="utf-8").read()
    model = pam2exu.loads(text.replace('type = "equilibrium"',
                                       'type = "dynamic"\nt_end = 0.1\nsteps = 5'))
    ground = model["ground"]
    ground.x, ground.y, ground.fi = where
    for backend in ("exudyn", "natural"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = pam2exu.run(model, backend=backend)
        for k, value in zip(("x", "y", "fi"), where):
            assert np.all(res[f"ground.{k}"] == value), (backend, k, res[f"ground.{k}"])
            for rate in ("D", "DD"):
                assert np.all(res[f"ground.{rate}{k}"] == 0.0), (backend, rate + k)
        assert abs(res["crank.fi"][-1] - res["crank.fi"][0]) > 1e-3


def test_a_slider_already_moving_at_t0_carries_the_pendulum_as_a_free_one():
    """The pendulum on a slider driven at a constant 0.8 m/s from t = 0 (x = 0.5 + 0.8 t),
    given no initial rates. The nearest velocities that satisfy C_q q̇ = −C_t (C_t = −0.8
    on the slider's row) are, in closed form, the slider's and the lever's Dx = 0.8 m/s,
    everything else 0. In the frame moving with the slider (no acceleration: Galilean) the
    lever swings as the free pendulum from θ0 = −1.2 at rest: ``reference`` without a
    slider acceleration. With −C_t the run started at Dx = −0.8. (The nearest velocities
    are the analysis's, not the backend's: Exudyn's run, 0.45 s, covers both.)"""
    law = Law("polynomial", [0.5, 0.8, 0.0])
    model = pam2exu.loads(slider_toml("polynomial", law.C))
    model["slider"].x = model["lever"].x = 0.5         # the guesses (slider_toml's: C[2])
    res = _run(model, t_end=0.4, steps=8)
    for name in ("slider", "lever"):
        assert res[f"{name}.Dx"][0] == pytest.approx(0.8, abs=1e-12), name
        assert res[f"{name}.Dy"][0] == pytest.approx(0.0, abs=1e-12), name
    assert res["lever.Dfi"][0] == pytest.approx(0.0, abs=1e-12)
    np.testing.assert_allclose(res["slider.x"], law(res.t)[0], atol=1e-12)
    np.testing.assert_allclose(res["lever.x"], res["slider.x"], atol=1e-12)
    ref = reference(res.t, (-1.2, 0.0))
    assert np.max(np.abs(res["lever.fi"] - ref[0]) / (1 + np.abs(ref[0]))) <= 1e-8
    assert np.max(np.abs(res["lever.Dfi"] - ref[1]) / (1 + np.abs(ref[1]))) <= 1e-8

"""The native force pass against Exudyn, and the physics checks of the force analyses.

References:
- Exudyn itself: the static solver's multipliers (quasi-static), and ``ComputeMassMatrix``
  with ``ComputeODE2RHS`` (M qdd − f at a given state, kinetostatic);
- conservation of energy (power balance) and the definition of the minimum-norm solution
  (the reported reactions are orthogonal to every self-stress of a redundant mechanism).
"""
from pathlib import Path

import numpy as np
import pytest

import exudyn as exu

import pam2exu
from pam2exu.analyses import ConsistencyWarning, RedundancyWarning
from pam2exu.analyses import force_pass as forces
from pam2exu.backend import ExudynSystem, SolveSettings
from pam2exu.elements import ELEMENTS, Prismatic, Spring
from pam2exu.kinematics import State

ROOT = Path(__file__).resolve().parents[2]
ALL = ROOT / "examples" / "all_elements.toml"


def _force_columns(res):
    return [c for c in res.columns if c.split(".")[-1] in
            {"Fx", "Fy", "Mz", "Fnormal", "Parell", "Força"}]


@pytest.mark.parametrize("backend", ["exudyn", "natural"])
def test_the_backend_check_evaluates_pams_forces_once_for_its_steps(backend, monkeypatch):
    """The quasi-static check solves the backend's static equilibrium at each of its 3
    steps, then evaluates pam2exu's own Jacobian and applied forces at the 3 configurations
    in one call each; its error is the largest per-step relative one, the same number as 3
    one-step evaluations give (reference: ``equilibrium_error`` step by step)."""
    from pam2exu.analyses import native, quasi_static
    from pam2exu.analyses.job import prepare
    job = prepare(ALL, analysis="quasi_static", steps=40, backend=backend)
    res = pam2exu.run(ALL, analysis="quasi_static", steps=40, backend=backend)
    q = job.mech.coordinates(res)
    rows = quasi_static.checked_steps(len(job.times))
    calls = []
    equations = native.equations
    with monkeypatch.context() as patch:
        patch.setattr(native, "equations",
                      lambda mech, st, **k: calls.append(st.n) or equations(mech, st, **k))
        worst = quasi_static.backend_equilibrium_error(job, q, rows)
    assert calls.count(len(rows)) == 1 and len(rows) == 3
    steps = []
    for k in rows:
        found = job.backend.solve_positions(job.mech, job.times[k:k + 1], q[k], job.solver,
                                            forces=True)
        st = State(job.times[k:k + 1], found.q)
        steps.append(quasi_static.equilibrium_error(
            job.mech, st, found.multipliers,
            forces.applied_forces(job.mech, st, damping=False).force,
            native.equations(job.mech, st).jacobian))
    assert worst == max(steps) and 0 < worst < 1e-12


@pytest.mark.parametrize("path", [ALL, ROOT / "examples" / "slider_crank.toml"])
def test_quasi_static_reactions_from_exudyn_equal_the_native_solve(path):
    """Exudyn's multipliers (static solver) and the native solve of Cqᵀ λ = −Q_applied
    give the same reported reactions at every step, to 1e-9 of each column's scale."""
    res = pam2exu.run(path, analysis="quasi_static", steps=40)
    assert res.info["reactions_from"] == "native solve, Exudyn's multipliers agree at 3 steps"
    mech = pam2exu.load(path).mechanism()
    q = np.column_stack([res[f"{s.name}.{k}"] for s in mech.solids for k in ("x", "y", "fi")])
    st = State(res.t, q)
    applied = forces.applied_forces(mech, st, damping=False)
    lam = forces.multipliers(mech, st, -applied.force, redundant=False)
    native_columns = {**forces.reactions(mech, st, lam), **applied.outputs}
    columns = _force_columns(res)
    assert len(columns) >= 10
    for c in columns:
        scale = max(np.max(np.abs(native_columns[c])), 1e-3)
        np.testing.assert_allclose(res[c], native_columns[c], rtol=0, atol=1e-9 * scale,
                                   err_msg=c)


def test_all_elements_model_reports_every_reaction_type():
    res = pam2exu.run(ALL, analysis="quasi_static", steps=4)
    types = {pam2exu.load(ALL)[c.split(".")[0]].type for c in _force_columns(res)}
    assert types == {k for k, cls in ELEMENTS.items() if not cls.extension} - {"torsor"}


def _exudyn_generalized_forces(mech, q, qd):
    """M qdd − f from Exudyn needs M and f: (M, f) at state (q, qd) of the force system."""
    system = ExudynSystem(mech, forces=True, velocity_forces=True)
    mbs = system.mbs
    solver = exu.MainSolverStatic()
    solver.InitializeSolver(mbs, system.simulation_settings(SolveSettings(), redundant=False))
    mbs.systemData.SetODE2Coordinates(list(q), configuration=exu.ConfigurationType.Current)
    mbs.systemData.SetODE2Coordinates_t(list(qd), configuration=exu.ConfigurationType.Current)
    # the torsional spring's C1 torques and the torsor are loads: ODE2RHS includes them
    solver.ComputeMassMatrix(mbs)
    M = np.array(solver.GetSystemMassMatrix())
    solver.ComputeODE2RHS(mbs)
    f = np.array(solver.GetSystemResidual())[:mech.nq]
    solver.FinalizeSolver(mbs, system.simulation_settings(SolveSettings(), redundant=False))
    return M, f


def test_inertia_and_applied_forces_equal_exudyns_mass_matrix_and_rhs():
    """Q_inertia − Q_applied (native) equals Exudyn's M qdd − f (mass matrix with the centre
    of mass off the node, gravity, springs, dampers, torsors, centrifugal terms)."""
    res = pam2exu.run(ALL, analysis="kinematic", steps=50)
    mech = pam2exu.load(ALL).mechanism()
    cols = lambda kind: np.column_stack([res[f"{s.name}.{kind}{k}"] for s in mech.solids  # noqa: E731
                                         for k in ("x", "y", "fi")])
    q, qd, qdd = cols(""), cols("D"), cols("DD")
    st = State(res.t, q, qd)
    applied = forces.applied_forces(mech, st, damping=True)
    inertia, _ = forces.inertia_forces(mech, st, qdd)
    for k in (0, 17, 33, 50):
        M, f = _exudyn_generalized_forces(mech, q[k], qd[k])
        exudyn = M @ qdd[k] - f
        ours = inertia[k] - applied.force[k]
        np.testing.assert_allclose(ours, exudyn, rtol=0, atol=1e-10 * np.max(np.abs(exudyn)),
                                   err_msg=f"step {k}")


def test_tangential_components_are_zero_for_any_multipliers():
    """Whatever the multipliers, a prismatic and a pin_slot push normal to the line, a
    revolute has no moment at the joint, a linear actuator pushes along PQ, an angular
    actuator and a transmission give pure torques: the routine leaves those components at
    round-off (and ``reactions`` raises if they are not). Assembled configurations only:
    elsewhere a prismatic's lines are not parallel."""
    res = pam2exu.run(ALL, analysis="kinematic", steps=19, outputs=["*.x", "*.y", "*.fi"])
    mech = pam2exu.load(ALL).mechanism()
    rng = np.random.default_rng(3)
    q = np.column_stack([res[f"{s.name}.{k}"] for s in mech.solids for k in ("x", "y", "fi")])
    st = State(res.t, q)
    for el in mech.constraints:
        lam = 100.0 * rng.standard_normal((20, el.equations))
        wrench = forces.element_wrench(el, st, lam)
        size = np.max(np.abs(lam))
        for k, name in enumerate(el.wrench):
            if name is None:
                assert np.max(np.abs(wrench[:, k])) <= 1e-12 * size, (el.name, k)
            else:
                assert np.max(np.abs(wrench[:, k])) > 1e-3 * size, (el.name, k)


def test_a_wrong_reporting_basis_is_caught(monkeypatch):
    """The zero-component check can fail: a prismatic reported in a basis turned by 90°
    has its normal force along x, which must raise."""
    frame = Prismatic.report_frame

    def turned(self, st):
        point, direction = frame(self, st)
        return point, direction[:, ::-1] * [-1.0, 1.0]
    monkeypatch.setattr(Prismatic, "report_frame", turned)
    with pytest.raises(pam2exu.TranslationError, match="'guide' \\(prismatic\\)"):
        pam2exu.run(ROOT / "examples" / "slider_crank.toml", analysis="quasi_static", steps=5)


def test_a_wrong_exudyn_force_translation_is_caught(monkeypatch):
    """The always-on equilibrium check compares Exudyn's multipliers with the native forces:
    a spring built with the wrong sign in Exudyn must raise a TranslationError."""
    build = Spring.build

    def flipped(self, ex):
        C = self.C
        self.C = [-C[0], *C[1:]]                # the preload's sign
        try:
            build(self, ex)
        finally:
            self.C = C
    monkeypatch.setattr(Spring, "build", flipped)
    with pytest.raises(pam2exu.TranslationError, match="equilibrium"):
        pam2exu.run(ALL, analysis="quasi_static", steps=5)


# ---- power balance -----------------------------------------------------------------------

FOUR_BAR = ROOT / "examples" / "four_bar.toml"


def _four_bar_with_spring_dampers():
    model = pam2exu.load(FOUR_BAR)
    model.solids[0].points["K"] = [0.1, 0.3]
    model.add("spring", name="spring", anc1="ground.K", anc2="coupler.P",
              C=[3.0, 250.0, 0.2, 4.0])
    model.add("torsional_spring", name="torsion", anc1="ground", anc2="rocker",
              C=[0.5, 2.0, 1.9, 0.3])
    model.add("torsor", name="load", anc1="rocker.B", C=[1.0, -2.0, 0.4], axes="solid")
    return model


def test_power_balance_holds_for_a_four_bar_with_spring_dampers():
    """Σ actuator power = d/dt(T + V) + C4 Dro² + C4 Dfi_rel² − torsor power.

    Computed here from the result columns only: T from the velocities, masses and
    inertias; V from y_G, ro and fi_rel; dE/dt by a fourth-order central difference
    (error ~ dt⁴); the torsor's power from the rocker's velocity. The motor power
    motor.Mz · motor.Df(t) must match to 1e-7 of its range. pam2exu's own check
    (fourth order, Richardson tolerance) must pass as well.
    """
    model = _four_bar_with_spring_dampers()
    res = pam2exu.run(model, analysis="kinetostatic", steps=2000)
    assert not res.warnings
    assert res.info["power_balance_steps"] == 1993
    assert res.info["power_balance_error"] <= res.info["power_balance_tolerance"]
    g, n = 9.81, len(res.t)
    energy, dissipation = np.zeros(n), np.zeros(n)
    for s in model.solids:
        if not s.mass:
            continue
        fi, w = res[f"{s.name}.fi"], res[f"{s.name}.Dfi"]
        cx, cy = s.cog
        Acx, Acy = np.cos(fi) * cx - np.sin(fi) * cy, np.sin(fi) * cx + np.cos(fi) * cy
        vx, vy = res[f"{s.name}.Dx"] - w * Acy, res[f"{s.name}.Dy"] + w * Acx
        energy += 0.5 * s.mass * (vx**2 + vy**2) + 0.5 * s.inertia * w**2
        energy += s.mass * g * (res[f"{s.name}.y"] + Acy)
    for name, var in (("spring", "ro"), ("torsion", "fi_rel")):
        c1, c2, c3, c4 = model[name].C
        x, dx = res[f"{name}.{var}"], res[f"{name}.D{var}"]
        energy += c1 * x + 0.5 * c2 * (x - c3) ** 2
        dissipation += c4 * dx**2
    fi, w = res["rocker.fi"], res["rocker.Dfi"]
    Fx, Fy = np.cos(fi) * 1.0 + np.sin(fi) * 2.0, np.sin(fi) * 1.0 - np.cos(fi) * 2.0
    vBx, vBy = res["rocker.Dx"] - w * 0.3 * np.sin(fi), res["rocker.Dy"] + w * 0.3 * np.cos(fi)
    torsor = Fx * vBx + Fy * vBy + 0.4 * w
    dt = res.t[1] - res.t[0]
    k = np.arange(2, n - 2)
    dE = (-energy[k + 2] + 8 * energy[k + 1] - 8 * energy[k - 1] + energy[k - 2]) / (12 * dt)
    motor = (res["motor.Mz"] * res["motor.Df(t)"])[k]
    balance = motor - (dE + dissipation[k] - torsor[k])
    assert np.ptp(motor) > 1.0                   # the motor does real work
    assert np.max(np.abs(balance)) < 1e-7 * np.ptp(motor)


def test_power_balance_check_detects_a_wrong_damper_force(monkeypatch):
    """A damper force with the wrong sign breaks the balance and gives a warning."""
    loads = Spring.loads

    def wrong(self, st, damping):
        load = loads(self, st, damping)
        if damping:                 # remove the damper from the forces, keep its dissipation
            c4 = self.C[3]
            ro = self.measure(st)
            for s, block in ro.jac.items():
                load.force[s] = load.force[s] + c4 * ro.rate[:, 0][:, None] * block[:, 0, :]
        return load
    monkeypatch.setattr(Spring, "loads", wrong)
    with pytest.warns(ConsistencyWarning, match="power balance"):
        res = pam2exu.run(_four_bar_with_spring_dampers(), analysis="kinetostatic", steps=2000)
    assert res.info["power_balance_error"] > 10 * res.info["power_balance_tolerance"]


# ---- redundant constraints -----------------------------------------------------------------

def _heavy_parallelogram(data):
    model = pam2exu.load(data / "parallelogram5.toml")
    model.gravity = 9.81
    for name, mass in (("crank1", 0.4), ("crank2", 0.5), ("crank3", 0.3), ("coupler", 2.0)):
        model[name].mass = mass
        model[name].inertia = 0.01
        model[name].cog = [0.15, 0.02] if name != "coupler" else [0.4, 0.05]
    return model


@pytest.mark.parametrize("analysis", ["quasi_static", "kinetostatic"])
def test_redundant_parallelogram_reactions_are_minimum_norm(data, analysis):
    """The fifth bar makes one self-stress: axial tensions (1, 1, −2) in the three parallel
    cranks (crank i: O_i.F = A_i.F = t_i u, u the crank direction; Σ t_i = 0 balances the
    coupler's forces, t2·1.0 + t3·0.5 = 0 its moment; the ground gets no net force). Any
    multiple can be added to the reactions; the minimum-norm one is orthogonal to it.
    Equilibrium of the coupler (Newton–Euler, forces from the three cranks) holds too."""
    model = _heavy_parallelogram(data)
    with pytest.warns(RedundancyWarning, match="'O1', 'O2', 'O3', 'A1', 'A2', 'A3'.*not"):
        res = pam2exu.run(model, analysis=analysis, steps=100)
    fi = res["crank1.fi"]
    u = np.column_stack([np.cos(fi), np.sin(fi)])
    R = np.hstack([np.column_stack([res[f"{j}.Fx"], res[f"{j}.Fy"]])
                   for j in ("O1", "O2", "O3", "A1", "A2", "A3")])
    S = np.hstack([t * u for t in (1.0, 1.0, -2.0)] * 2)
    assert np.max(np.abs(np.sum(R * S, axis=1))) < 1e-9 * np.max(np.abs(R))
    # coupler: Σ A_i.F − m g = m a_G (zero acceleration in quasi-static)
    m = 2.0
    if analysis == "kinetostatic":
        fc = res["coupler.fi"]
        a = np.column_stack([res["coupler.DDx"], res["coupler.DDy"]])
        # G = R + A(fc)(0.4, 0.05); the coupler translates (fc constant): a_G = R̈
        assert np.ptp(fc) < 1e-12
    else:
        a = np.zeros((len(res.t), 2))
    total = sum(np.column_stack([res[f"{j}.Fx"], res[f"{j}.Fy"]]) for j in ("A1", "A2", "A3"))
    np.testing.assert_allclose(total + [0.0, -m * 9.81], m * a, rtol=0, atol=1e-9 * m * 9.81)


@pytest.mark.parametrize("k, C", [(1, -50.0), (2, -0.1)], ids=["negative stiffness",
                                                             "negative free length"])
def test_spring_constants_exudyn_refuses_are_translated_exactly(k, C):
    """F = C1 + C2 (ro − C3) holds for any C2 and C3 (the contract); Exudyn's
    ObjectConnectorSpringDamper refuses C2 < 0 and C3 < 0 (fuzz seed 8245), so they are
    given to it as a force function of ro. Exudyn's multipliers balance the native forces,
    and the spring force is the formula."""
    model = pam2exu.load(ALL)
    spring = model["return_spring"]
    constants = list(spring.C)
    constants[k] = C
    spring.C = constants
    res = pam2exu.run(model, analysis="quasi_static", steps=10)
    assert res.info["equilibrium_error"] < 1e-12
    c1, c2, c3, _ = constants
    np.testing.assert_allclose(res["return_spring.Força"],
                               c1 + c2 * (res["return_spring.ro"] - c3), rtol=1e-14, atol=1e-12)

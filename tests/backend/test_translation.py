"""The Exudyn translation against pam2exu's own constraint equations.

Reference: Exudyn itself. ``MainSolverStatic.ComputeJacobianAE`` gives Exudyn's Cq and
``ComputeAlgebraicEquations`` its residual C(q, t); both must equal the native ones, row
by row (same equation forms and signs, see each element's ``constraint`` docstring), at
arbitrary, non-assembled poses of a model with every element type.
"""
import numpy as np
import pytest

import exudyn as exu
from exudyn.solver import ComputeSystemDegreeOfFreedom

import pam2exu
from pam2exu.analyses import native, rank
from pam2exu.backend import ExudynSystem, SolveSettings
from pam2exu.elements import ELEMENTS
from pam2exu.kinematics import State


def exudyn_equations(system, q):
    """(Cq, C) from Exudyn at coordinates q and t = 0, rows in Exudyn's AE order."""
    mbs = system.mbs
    solver = exu.MainSolverStatic()
    settings = system.simulation_settings(SolveSettings(), redundant=False)
    solver.InitializeSolver(mbs, settings)          # resets the state: set q afterwards
    mbs.systemData.SetODE2Coordinates(list(q), configuration=exu.ConfigurationType.Current)
    solver.ComputeJacobianODE2RHS(mbs, scalarFactor_ODE2=0.0, scalarFactor_ODE2_t=0.0,
                                  scalarFactor_ODE1=0.0)
    solver.ComputeJacobianAE(mbs, scalarFactor_ODE2=1.0, scalarFactor_ODE2_t=0.0,
                             scalarFactor_ODE1=1.0, velocityLevel=False)
    n2 = solver.GetODE2size()
    jacobian = np.array(solver.GetSystemJacobian())
    solver.ComputeAlgebraicEquations(mbs)
    residual = np.array(solver.GetSystemResidual())[n2:]
    solver.FinalizeSolver(mbs, settings)
    return jacobian[:n2, n2:].T, residual


@pytest.fixture(scope="module")
def every(request):
    path = request.config.rootpath / "tests" / "data" / "every_element.toml"
    return pam2exu.load(path).mechanism()


def test_model_has_every_element_type(every):
    assert {e.type for e in every.elements} == set(ELEMENTS)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_native_jacobian_and_residual_equal_exudyns(every, seed):
    system = ExudynSystem(every, forces=True)
    q = every.initial_q() + 0.1 * np.random.default_rng(seed).standard_normal(every.nq)
    cq, c = exudyn_equations(system, q)
    eq = native.equations(every, State([0.0], q[None]))
    compared = 0
    for el, rows in zip(every.constraints, every.rows):
        ae = [i for kind, obj in system.objects[el.name] if kind == "object"
              for i in system.mbs.systemData.GetObjectLTGAE(obj)]
        if el.type == "pin_slot":
            # ObjectJointPrismatic2D without rotation keeps an unused multiplier (λ1 = 0)
            assert np.all(cq[ae[1]] == 0.0)
            ae = ae[:1]
        assert len(ae) == el.equations, el.name
        np.testing.assert_allclose(cq[ae], eq.jacobian[0][rows], rtol=0, atol=1e-13,
                                   err_msg=f"Jacobian of {el.name} ({el.type})")
        np.testing.assert_allclose(c[ae], eq.residual[0][rows], rtol=0, atol=1e-13,
                                   err_msg=f"residual of {el.name} ({el.type})")
        compared += 1
    assert compared == len(every.constraints)


def test_kinematic_system_has_no_masses_loads_or_springs(every):
    """A kinematic run builds constraints only."""
    mbs = ExudynSystem(every, forces=False).mbs
    assert mbs.systemData.NumberOfLoads() == 0
    kinds = {str(mbs.GetObject(i)["objectType"]) for i in range(mbs.systemData.NumberOfObjects())}
    assert not any("SpringDamper" in k for k in kinds)
    for i in range(mbs.systemData.NumberOfObjects()):
        obj = mbs.GetObject(i)
        if obj["objectType"] == "RigidBody2D":
            assert obj["mass"] == 0.0 and obj["inertia"] == 0.0


def test_force_system_has_masses_gravity_and_loads(every):
    system = ExudynSystem(every, forces=True)
    mbs = system.mbs
    # gravity on the 2 solids with mass, torsor: force + torque, torsional spring: 2 torques
    assert mbs.systemData.NumberOfLoads() == 2 + 2 + 2
    crank = mbs.GetObject(system.bodies[every.index["crank"]])
    assert crank["mass"] == 1.0
    # Exudyn's inertia is about the body's reference point: J_G + m |G|²
    assert crank["inertia"] == pytest.approx(0.01 + 1.0 * (0.05**2 + 0.01**2), rel=1e-15)


def _slider_crank(path, drop=()):
    model = pam2exu.load(path)
    model.elements = [e for e in model.elements if e.name not in drop]
    return model.mechanism()


@pytest.mark.parametrize("drop, dof", [((), 0), (("motor",), 1), (("motor", "guide"), 3)])
def test_degrees_of_freedom_agree_with_exudyn(examples, drop, dof):
    mech = _slider_crank(examples / "slider_crank.toml", drop)
    ours = rank.mobility(mech, 0.0, mech.initial_q())
    theirs = ComputeSystemDegreeOfFreedom(ExudynSystem(mech).mbs)
    assert ours.dof == theirs["degreeOfFreedom"] == dof
    assert ours.redundant == theirs["redundantConstraints"] == 0



def test_fixed_solids_modelled_as_ground_give_the_same_positions(examples,
                                                                  moved):
    """The constraints-only system models fixed solids as Exudyn ground (at a rotated,
    shifted pose here); the force system keeps them as bodies held by three coordinate
    constraints. Both must give the same configurations."""
    mech = moved(examples / "all_elements.toml").mechanism()
    t = np.linspace(0.0, 1.0, 41)
    grounded = ExudynSystem(mech)
    assert grounded.grounded == {mech.index["ground"]}
    q1, n1 = grounded.solve_positions(t)
    q2, n2 = ExudynSystem(mech, forces=True, velocity_forces=False).solve_positions(t)
    assert n1 == n2 == len(t)
    np.testing.assert_allclose(q1, q2, rtol=0, atol=1e-12)


def test_a_rigidly_moved_mechanism_moves_the_same(examples, moved):
    """Moving every solid by one rigid motion (x0, y0, fi0) moves the results by it:
    fi + fi0 for every solid, (x, y) rotated by fi0 and shifted, reactions rotated."""
    x0, y0, fi0 = 0.3, -0.2, 0.7
    path = examples / "all_elements.toml"
    model = pam2exu.load(path)
    model.gravity = 0.0
    shifted = moved(path, x0, y0, fi0)
    shifted.gravity = 0.0
    a = pam2exu.run(model, analysis="kinetostatic", steps=30)
    b = pam2exu.run(shifted, analysis="kinetostatic", steps=30)
    c, s = np.cos(fi0), np.sin(fi0)
    for solid in model.solids:
        n = solid.name
        np.testing.assert_allclose(b[f"{n}.fi"], a[f"{n}.fi"] + fi0, atol=1e-12)
        np.testing.assert_allclose(b[f"{n}.x"], x0 + c * a[f"{n}.x"] - s * a[f"{n}.y"],
                                   atol=1e-12)
        np.testing.assert_allclose(b[f"{n}.DDy"], s * a[f"{n}.DDx"] + c * a[f"{n}.DDy"],
                                   atol=1e-9)
    np.testing.assert_allclose(b["motor.Mz"], a["motor.Mz"], atol=1e-9)
    np.testing.assert_allclose(b["guide.Fnormal"], a["guide.Fnormal"], atol=1e-9)
    np.testing.assert_allclose(b["O1.Fy"], s * a["O1.Fx"] + c * a["O1.Fy"], atol=1e-9)

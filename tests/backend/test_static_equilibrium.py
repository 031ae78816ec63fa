"""``Backend.static_equilibrium``, the contract the equilibrium analysis's descent relies on,
held on every backend that declares ``moves_free_solids``.

Reference, computed here without pam2exu's code: a lever (references.pendulum: mass M, its
centre of mass at D from the pivot) with a torsional spring of stiffness K to the ground,
tied to its start angle fi_s by the anchor spring k L² (L the length scale). Its stationary
point on the pivot solves, by the moments about the pivot,

    K fi + M G D cos(fi) + k L² (fi − fi_s) = 0            (brentq),

and the pivot's reaction carries the weight; the anchor springs on x, y do nothing there.
"""
import math

import numpy as np
import pytest
from scipy.optimize import brentq

import pam2exu
from pam2exu.analyses import force_pass
from pam2exu.kinematics import State
from pam2exu.registry import BACKENDS
from references.pendulum import D, G, M, pendulum_toml

K = 20.0          # the torsional spring [N·m/rad]
SOLVING = [name for name, b in BACKENDS.items() if b.create().moves_free_solids]


def _lever(stiffness=K, torque=None):
    spring = (f'\n[[element]]\ntype = "torsional_spring"\nname = "spring"\nanc1 = "ground"\n'
              f'anc2 = "lever"\nC = [0.0, {stiffness!r}, 0.0, 0.0]\n')
    torsor = ("" if torque is None else
              f'\n[[element]]\ntype = "torsor"\nname = "torque"\nanc1 = "lever"\n'
              f"C = [0.0, 0.0, {torque!r}]\n")
    return pam2exu.loads(pendulum_toml(0.3, elements=spring + torsor,
                                       analysis='type = "equilibrium"')).mechanism()


def _pose(fi):
    """ground at the origin, the lever on its pivot at angle fi."""
    return np.array([0.0, 0.0, 0.0, 0.0, 0.0, fi])


def test_both_shipped_backends_solve_it():
    assert SOLVING == list(BACKENDS)


@pytest.mark.parametrize("backend", SOLVING)
@pytest.mark.parametrize("k", [0.0, 50.0, 400.0])
def test_the_stationary_point_with_the_anchor_springs(backend, k):
    mech = _lever()
    L = mech.scale()
    fi_s = 0.3
    b = BACKENDS[backend].create()
    found = b.static_equilibrium(mech, 0.0, _pose(fi_s), b.Settings(), anchor_stiffness=k)
    fi = brentq(lambda f: K * f + M * G * D * math.cos(f) + k * L * L * (f - fi_s), -1.5, 1.5,
                xtol=1e-15)
    assert found.solved == 1 and found.error is None
    assert found.q.shape == (1, mech.nq)
    np.testing.assert_allclose(found.q[0], _pose(fi), atol=1e-12)
    # f + Cqᵀλ = 0, f the loads and the anchor springs on x, y, fi
    st = State([0.0], found.q)
    f = force_pass.applied_forces(mech, st, damping=False).force[0]
    f[5] -= k * L * L * (found.q[0, 5] - fi_s)
    J = np.zeros((1, mech.n_equations, mech.nq))
    for el, rows in zip(mech.constraints, mech.rows):
        el.constraint(st)[0].rows(J, rows.start)
    assert found.multipliers.shape == (1, mech.n_equations)
    np.testing.assert_allclose(f + J[0].T @ found.multipliers[0], 0.0, atol=1e-9)


@pytest.mark.parametrize("backend", SOLVING)
def test_a_start_on_an_equilibrium_is_returned_as_it_is(backend):
    """The top of a pendulum (no spring), unstable: Newton's first step is within the
    tolerance, and the answer is the start to round-off (the descent's sign that it started
    on an equilibrium: ``STILL``; measured: Exudyn moves fi by 2.2e-16 with the anchor
    springs, the natural backend not at all)."""
    mech = _lever(stiffness=0.0)
    b = BACKENDS[backend].create()
    start = _pose(math.pi / 2)
    for k in (0.0, 10.0):
        found = b.static_equilibrium(mech, 0.0, start, b.Settings(), anchor_stiffness=k)
        assert found.solved == 1
        assert np.max(np.abs(found.q[0] - start)) <= 1e-15


@pytest.mark.parametrize("backend", SOLVING)
def test_no_equilibrium_is_reported_unsolved(backend):
    """A torque twice what the weight can hold, no spring: nothing to converge to."""
    mech = _lever(stiffness=0.0, torque=2 * M * G * D)
    b = BACKENDS[backend].create()
    found = b.static_equilibrium(mech, 0.0, _pose(0.0), b.Settings())
    assert found.solved == 0 and found.error
    assert np.isnan(found.q).all()

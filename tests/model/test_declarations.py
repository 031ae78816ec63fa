"""What the elements declare about themselves (``Element.ties``, ``pins``, ``slides``,
``tie_length``, ``holds``, ``clearance``; the anchors' ``anchor_point``) and what the
mechanism computes once from it (``Mechanism.held``, ``Mechanism.coordinates``)."""
import numpy as np
import pytest

from pam2exu.elements import ELEMENTS
from pam2exu.model import Model
from pam2exu.model.solid import LineRef, PointRef, SolidRef
from pam2exu.results import Results

#: type -> (ties, pins, slides, grounds, drives) of the contract's ten types: the roles the
#: loops' diagnosis, the couplers, the drawings and the backends ask for (a type an extension
#: adds, ``Element.extension``, pins its roles in its own test)
ROLES = {
    "fixed": (False, False, False, True, False),
    "revolute": (True, True, False, False, False),
    "prismatic": (True, False, True, False, False),
    "pin_slot": (True, False, False, False, False),
    "transmission": (False, False, False, False, False),
    "torsor": (False, False, False, False, False),
    "spring": (False, False, False, False, False),
    "torsional_spring": (False, False, False, False, False),
    "angular_actuator": (False, False, False, False, True),
    "linear_actuator": (True, False, False, False, True),
}


def test_the_roles_cover_the_contracts_types():
    assert list(ROLES) == [kind for kind, cls in ELEMENTS.items() if not cls.extension]


@pytest.mark.parametrize("kind", list(ROLES))
def test_each_type_declares_its_roles(kind):
    cls = ELEMENTS[kind]
    assert (cls.ties, cls.pins, cls.slides, cls.grounds, cls.drives) == ROLES[kind]


@pytest.mark.parametrize("kind", list(ELEMENTS))
def test_the_roles_of_each_type_are_consistent(kind):
    """A tie needs two anchors that stand for points; a pin or a slider is a tie."""
    cls = ELEMENTS[kind]
    assert not cls.ties or len(cls.anchors) == 2 and "solid" not in cls.anchors
    assert cls.ties or not (cls.pins or cls.slides)


def test_the_anchor_point_of_each_reference():
    """A solid stands for its origin, a point for itself, a line for its defining point."""
    assert SolidRef(0, "s").anchor_point == (0.0, 0.0)
    assert PointRef(0, (0.1, -0.2), "s.P").anchor_point == (0.1, -0.2)
    assert LineRef(0, (0.3, 0.4), 0.5, "s.l").anchor_point == (0.3, 0.4)


def _two_grounds() -> Model:
    """Two fixed solids ('left', 'right': indices 0 and 2), a crank driven on the left one,
    and a free solid 'loose' held by nothing."""
    m = Model("two grounds")
    m.add_solid("left", points={"O": [0.0, 0.0]})
    m.add_solid("crank", points={"O": [0.0, 0.0], "A": [0.1, 0.0]})
    m.add_solid("right", x=0.5, y=0.1, fi=0.3)
    m.add_solid("loose", x=1.0)
    m.add("fixed", anc1="left")
    m.add("revolute", anc1="left.O", anc2="crank.O")
    m.add("angular_actuator", anc1="left", anc2="crank", law="polynomial", C=[0.0, 1.0])
    m.add("fixed", anc1="right")
    m.add("linear_actuator", anc1="crank.A", anc2="loose", law="ramp", C=[0.0, 1.0, 0.2, 0.4])
    return m


def test_held_solids_of_a_model_with_two_fixed_links():
    mech = _two_grounds().mechanism()
    assert mech.held == {0, 2}
    assert [el.holds for el in mech.elements] == [0, None, None, 2, None]


def test_tie_length_is_zero_for_a_pin_and_f_of_t_for_a_distance_actuator():
    mech = _two_grounds().mechanism()
    pin, motor, distance = mech.elements[1], mech.elements[2], mech.elements[4]
    assert pin.tie_length(0.7) == 0.0
    assert motor.tie_length(0.7) is None                   # an angle, not a distance
    # ramp from 0.2 m to 0.4 m over [0, 1] s: 0.2 + 0.2 · 0.25 at t = 0.25 s
    assert distance.tie_length(0.25) == pytest.approx(0.25, abs=1e-15)


def test_clearance_is_false_unless_the_joint_says_true():
    m = _two_grounds()
    m.elements[1].clearance = True
    els = m.mechanism().elements
    assert [el.clearance for el in els] == [False, True, False, False, False]


@pytest.fixture(scope="module")
def table():
    """The two-grounds mechanism and a result table of 5 rows whose every column (in an
    order of its own: fi before x, rates before positions) holds distinct random numbers."""
    mech = _two_grounds().mechanism()
    rng = np.random.default_rng(23)
    names = [f"{s.name}.{d}{v}" for d in ("DD", "D", "") for v in ("fi", "y", "x")
             for s in mech.solids]
    return mech, Results(np.linspace(0.0, 1.0, 5), {n: rng.normal(size=5) for n in names})


def test_coordinates_are_the_result_columns_side_by_side(table):
    """q[:, 3i + k] is solid i's column x, y, fi (k = 0, 1, 2), and likewise for the
    rates "D" and "DD"; ``rows`` takes some rows."""
    mech, res = table
    for rate in ("", "D", "DD"):
        q = mech.coordinates(res, rate)
        assert q.shape == (len(res), mech.nq)
        for i, s in enumerate(mech.solids):
            for k, v in enumerate(("x", "y", "fi")):
                assert np.array_equal(q[:, 3 * i + k], res[f"{s.name}.{rate}{v}"])
    rows = np.array([0, 3])
    assert np.array_equal(mech.coordinates(res, rows=rows), mech.coordinates(res)[rows])
    assert mech.coordinate_columns("D")[:3] == [f"{mech.solids[0].name}.D{v}"
                                                for v in ("x", "y", "fi")]

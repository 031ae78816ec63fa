"""Time laws f(t), f'(t), f''(t) against closed forms written here, independently of pam2exu.laws.

Every reference value below comes from the law table of the model-format contract
(shared/spec/model-format.md, "Time laws"), differentiated by hand:

    polynomial  f = C1 + C2 t + C3 t² + C4 t³
    harmonic    f = C1 + C2 cos(C3 t + C4)
    ramp        f = C3 + (C4 − C3) u
    bezier_c1   f = C3 + (C4 − C3)(3u² − 2u³)
    bezier_c2   f = C3 + (C4 − C3)(6u⁵ − 15u⁴ + 10u³)

with u = (t − C1)/(C2 − C1) on C1 ≤ t < C2; before C1 the last three give C3, from C2 on C4.
A derivative that jumps at a breakpoint takes the right-hand limit there.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from pam2exu import Law
from pam2exu.laws import LAW_ALIASES, LAWS

RTOL = 1e-12


# ---- reference closed forms (scalar, plain Python floats) ------------------------------

def ref_polynomial(t, C):
    """Contract: f = C1 + C2 t + C3 t² + C4 t³; f' = C2 + 2 C3 t + 3 C4 t²; f'' = 2 C3 + 6 C4 t."""
    c1, c2, c3, c4 = C
    return (c1 + c2 * t + c3 * t ** 2 + c4 * t ** 3,
            c2 + 2 * c3 * t + 3 * c4 * t ** 2,
            2 * c3 + 6 * c4 * t)


def ref_harmonic(t, C):
    """Contract: f = C1 + C2 cos(C3 t + C4); f' = −C2 C3 sin(·); f'' = −C2 C3² cos(·)."""
    c1, c2, c3, c4 = C
    a = c3 * t + c4
    return c1 + c2 * math.cos(a), -c2 * c3 * math.sin(a), -c2 * c3 ** 2 * math.cos(a)


# shapes s(u), s'(u), s''(u) in expanded polynomial form (hand derivatives of the table)
def _s_ramp(u):
    return u, 1.0, 0.0


def _s_bezier_c1(u):
    # s = 3u² − 2u³, s' = 6u − 6u², s'' = 6 − 12u
    return 3 * u ** 2 - 2 * u ** 3, 6 * u - 6 * u ** 2, 6 - 12 * u


def _s_bezier_c2(u):
    # s = 6u⁵ − 15u⁴ + 10u³, s' = 30u⁴ − 60u³ + 30u², s'' = 120u³ − 180u² + 60u
    return (6 * u ** 5 - 15 * u ** 4 + 10 * u ** 3,
            30 * u ** 4 - 60 * u ** 3 + 30 * u ** 2,
            120 * u ** 3 - 180 * u ** 2 + 60 * u)


def _ref_transition(shape):
    def ref(t, C):
        """Contract: C3 before C1; C3 + (C4 − C3) s(u) on [C1, C2) (chain rule: du/dt = 1/(C2 − C1));
        C4 with zero derivatives from C2 on."""
        c1, c2, c3, c4 = C
        if t < c1:
            return c3, 0.0, 0.0
        if t >= c2:
            return c4, 0.0, 0.0
        d = c2 - c1
        s, ds, dds = shape((t - c1) / d)
        return c3 + (c4 - c3) * s, (c4 - c3) * ds / d, (c4 - c3) * dds / d ** 2
    return ref


REFERENCE = {
    "polynomial": ref_polynomial,
    "harmonic": ref_harmonic,
    "ramp": _ref_transition(_s_ramp),
    "bezier_c1": _ref_transition(_s_bezier_c1),
    "bezier_c2": _ref_transition(_s_bezier_c2),
}
TRANSITIONS = ("ramp", "bezier_c1", "bezier_c2")

#: constants used for every law: rising and falling, offset and negative breakpoints
CONSTANTS = [
    (0.2, 0.7, 0.45, 1.3),
    (-0.5, 1.5, 2.0, -1.0),
    (1.0, 3.0, -0.25, 0.75),
]

#: every law name the contract accepts, with the canonical law it means (aliases included)
ALL_NAMES = [(name, name) for name in REFERENCE] + [
    ("polinomica", "polynomial"), ("harmonica", "harmonic"), ("rampa", "ramp")]


def magnitude(canonical, t, C):
    """Size of the terms that make up f, f', f'' (the scale of their rounding errors)."""
    c1, c2, c3, c4 = (abs(c) for c in C)
    if canonical == "polynomial":
        return ref_polynomial(abs(t), (c1, c2, c3, c4))
    if canonical == "harmonic":
        return c1 + c2, c2 * c3, c2 * c3 ** 2
    d, rise = abs(C[1] - C[0]), abs(C[3] - C[2])
    return c3 + c4 + rise, 10 * rise / d, 100 * rise / d ** 2


def _close(actual, expected, scale=1.0):
    """|actual − expected| ≤ RTOL·max(|expected|, scale)."""
    assert abs(float(actual) - expected) <= RTOL * max(abs(expected), scale), (actual, expected)


def _check(law, canonical, C, times):
    f, df, ddf = law(np.array(times))
    for k, t in enumerate(times):
        expected = REFERENCE[canonical](t, C)
        scales = magnitude(canonical, t, C)
        for got, ref, scale in zip((f[k], df[k], ddf[k]), expected, scales):
            _close(got, ref, scale)
        # the scalar call gives the same values
        for got, ref, scale in zip(law(t), (f[k], df[k], ddf[k]), scales):
            _close(got, float(ref), scale)


# ---- the table ---------------------------------------------------------------------------

def test_every_contract_law_is_known():
    assert set(LAWS) == set(REFERENCE)
    assert LAW_ALIASES == {"polinomica": "polynomial", "harmonica": "harmonic", "rampa": "ramp"}


@pytest.mark.parametrize("C", CONSTANTS)
@pytest.mark.parametrize("name,canonical", ALL_NAMES)
def test_values_between_breakpoints(name, canonical, C):
    """Many times strictly inside (C1, C2), plus a wide range for the smooth laws."""
    c1, c2 = C[0], C[1]
    times = list(np.linspace(c1, c2, 41)[1:-1])
    if canonical in ("polynomial", "harmonic"):
        times += list(np.linspace(-3.0, 4.0, 29))
    _check(Law(name, C), canonical, C, times)


@pytest.mark.parametrize("C", CONSTANTS)
@pytest.mark.parametrize("name,canonical", ALL_NAMES)
def test_values_at_and_around_breakpoints(name, canonical, C):
    """Exactly at t = C1 and t = C2, one ulp before and after, and well before / after."""
    c1, c2 = C[0], C[1]
    times = [c1 - 1.0, np.nextafter(c1, -np.inf), c1, np.nextafter(c1, np.inf),
             np.nextafter(c2, -np.inf), c2, np.nextafter(c2, np.inf), c2 + 1.0]
    _check(Law(name, C), canonical, C, [float(t) for t in times])


# ---- breakpoints, written out ------------------------------------------------------------

@pytest.mark.parametrize("name", ["ramp", "rampa"])
def test_ramp_at_breakpoints(name):
    """Contract table + right-hand limits: f' jumps to (C4 − C3)/(C2 − C1) at C1 and back to 0 at C2."""
    c1, c2, c3, c4 = 0.5, 2.5, 1.0, 5.0
    law = Law(name, (c1, c2, c3, c4))
    slope = (c4 - c3) / (c2 - c1)                       # = 2.0
    assert [float(v) for v in law(c1)] == [c3, slope, 0.0]
    assert [float(v) for v in law(c2)] == [c4, 0.0, 0.0]
    assert [float(v) for v in law(c1 - 0.1)] == [c3, 0.0, 0.0]
    assert [float(v) for v in law(c2 + 0.1)] == [c4, 0.0, 0.0]
    f, df, ddf = law(1.0)                               # u = 0.25
    _close(f, 2.0)
    _close(df, slope)
    assert float(ddf) == 0.0


def test_bezier_c1_at_breakpoints():
    """s = 3u² − 2u³: f' is continuous (0 at both ends); f'' jumps to 6(C4 − C3)/(C2 − C1)² at C1
    (right-hand limit) and is 0 from C2 on (the right-hand limit there, not −6(C4 − C3)/(C2 − C1)²)."""
    c1, c2, c3, c4 = 1.0, 3.0, -1.0, 3.0
    law = Law("bezier_c1", (c1, c2, c3, c4))
    f, df, ddf = (float(v) for v in law(c1))
    assert (f, df) == (c3, 0.0)
    _close(ddf, 6 * (c4 - c3) / (c2 - c1) ** 2)        # = 6.0
    assert [float(v) for v in law(c2)] == [c4, 0.0, 0.0]
    # the left-hand limit of f'' at C2 is −6.0: just before C2 it is close to it
    _close(law(np.nextafter(c2, -np.inf))[2], -6.0, 1e3)
    # mid-point: u = 1/2, s = 1/2, s' = 3/2, s'' = 0
    f, df, ddf = law(2.0)
    _close(f, 1.0)
    _close(df, 4.0 * 1.5 / 2.0)
    assert abs(float(ddf)) <= 1e-12


def test_bezier_c2_at_breakpoints():
    """s = 6u⁵ − 15u⁴ + 10u³: f, f', f'' are all continuous; f' and f'' are 0 at both ends."""
    c1, c2, c3, c4 = -1.0, 1.0, 2.0, 0.0
    law = Law("bezier_c2", (c1, c2, c3, c4))
    assert [float(v) for v in law(c1)] == [c3, 0.0, 0.0]
    assert [float(v) for v in law(c2)] == [c4, 0.0, 0.0]
    # mid-point: u = 1/2, s = 1/2, s' = 15/8, s'' = 0
    f, df, ddf = law(0.0)
    _close(f, 1.0)
    _close(df, -2.0 * (15 / 8) / 2.0)
    assert abs(float(ddf)) <= 1e-12
    # u = 1/4: s'' = 120/64 − 180/16 + 15 = 5.625
    _close(law(-0.5)[2], -2.0 * 5.625 / 4.0)


@pytest.mark.parametrize("name", TRANSITIONS)
def test_value_at_breakpoint_is_right_hand_limit(name):
    """Right-hand limit: the value at a breakpoint continues smoothly into the times after it."""
    C = (0.3, 1.1, -0.4, 0.9)
    law = Law(name, C)
    for t in C[:2]:
        at = np.array([float(v) for v in law(t)])
        after = np.array([float(v) for v in law(t + 1e-9)])
        assert np.allclose(at, after, rtol=0, atol=1e-6), (t, at, after)


# ---- finite differences ------------------------------------------------------------------

@pytest.mark.parametrize("C", CONSTANTS)
@pytest.mark.parametrize("name", list(REFERENCE))
def test_derivatives_match_central_differences(name, C):
    """f' ≈ (f(t+h) − f(t−h))/2h and f'' ≈ (f'(t+h) − f'(t−h))/2h at interior points.

    Truncation error h²/6·|f'''| and round-off ε|f|/h: with h = 1e-6 and the constants here,
    both stay below 1e-7 relative to the size of the derivative.
    """
    c1, c2 = C[0], C[1]
    law = Law(name, C)
    h = 1e-6
    t = np.linspace(c1, c2, 23)[1:-1]                  # interior: at least 0.04 from a breakpoint
    f, df, ddf = law(t)
    fp, dfp, _ = law(t + h)
    fm, dfm, _ = law(t - h)
    scale = max(map(abs, C))
    assert np.allclose((fp - fm) / (2 * h), df, rtol=1e-7, atol=1e-7 * scale ** 2)
    assert np.allclose((dfp - dfm) / (2 * h), ddf, rtol=1e-7, atol=1e-7 * scale ** 3)


# ---- calling conventions -----------------------------------------------------------------

@pytest.mark.parametrize("name", list(REFERENCE))
def test_vectorised_over_arrays_keeps_shape(name):
    law = Law(name, (0.1, 0.9, -1.0, 2.0))
    t = np.linspace(-0.5, 1.5, 12).reshape(3, 4)
    out = law(t)
    assert len(out) == 3
    for k, values in enumerate(out):
        assert values.shape == (3, 4)
        for i in range(3):
            for j in range(4):
                assert math.isclose(float(values[i, j]), float(law(float(t[i, j]))[k]),
                                    rel_tol=1e-14, abs_tol=1e-14)
    # a Python list and a 1-D array work too
    assert [v.shape for v in law([0.0, 0.5, 1.0])] == [(3,)] * 3
    # a scalar gives 0-d results, usable as floats
    for v in law(0.5):
        assert np.shape(v) == ()
        float(v)


@pytest.mark.parametrize("name", list(REFERENCE))
def test_constant_results_broadcast_to_the_time_array(name):
    """A law whose f'' (or f') does not depend on t still returns one value per time."""
    law = Law(name, (0.0, 1.0, 0.0, 0.0))       # polynomial f = t: f'' is a constant 0
    t = np.zeros((2, 5))
    for values in law(t):
        assert values.shape == (2, 5)


@pytest.mark.parametrize("name", list(REFERENCE))
def test_results_are_arrays_of_their_own(name):
    """f, f', f'' are three separate writable arrays: writing into one changes neither the
    times, nor the others, nor a later call; complex constants (a complex step) give the
    same values as the law's function copied by ``* 1.0``."""
    law = Law(name, (0.1, 0.9, -1.0, 2.0))
    t = np.linspace(-0.5, 1.5, 9)
    kept = t.copy()
    out = law(t)
    again = [v.copy() for v in law(t)]
    assert len({id(v) for v in out}) == 3
    for v in out:
        assert v.flags.writeable and not np.shares_memory(v, t)
        assert not any(np.shares_memory(v, w) for w in out if w is not v)
        v[:] = 7.0
    assert np.array_equal(t, kept)
    assert all(np.array_equal(a, b) for a, b in zip(law(t), again))
    stepped = Law(name, (0.1, 0.9, complex(-1.0, 1e-20), 2.0))
    direct = LAWS[name].function(t, stepped.C)
    for a, b in zip(stepped(t), direct):
        assert a.dtype == complex and np.array_equal(a, np.broadcast_to(b, t.shape) * 1.0)


@pytest.mark.parametrize("name", ALL_NAMES)
def test_value_returns_python_float(name):
    law = Law(name[0], (0.2, 0.7, 0.45, 1.3))
    for t in (0.0, 0.2, 0.5, 0.7, 2, np.float64(0.3)):
        v = law.value(t)
        assert type(v) is float
        assert math.isclose(v, REFERENCE[name[1]](float(t), (0.2, 0.7, 0.45, 1.3))[0],
                            rel_tol=RTOL)


def test_missing_constants_are_zero():
    """Contract: "missing entries of C are 0"; law defaults to polynomial."""
    assert Law().name == "polynomial"
    assert Law().C == (0.0, 0.0, 0.0, 0.0)
    assert Law("polynomial", (1.5,)).C == (1.5, 0.0, 0.0, 0.0)
    assert Law("harmonic", [1, 2]).C == (1.0, 2.0, 0.0, 0.0)
    assert Law("ramp", (0.0, 2.0)).C == (0.0, 2.0, 0.0, 0.0)
    assert all(type(c) is float for c in Law("polynomial", (1, 2)).C)
    # f = 1.5 + 2 t with C3 = C4 = 0
    f, df, ddf = Law("polynomial", (1.5, 2.0))(np.array([0.0, 1.0, 2.0]))
    assert f.tolist() == [1.5, 3.5, 5.5] and df.tolist() == [2.0] * 3 and ddf.tolist() == [0.0] * 3
    # harmonic with C3 = C4 = 0: f = C1 + C2 cos 0, constant
    f, df, ddf = Law("harmonic", (1.0, 2.0))(np.array([0.0, 5.0]))
    assert f.tolist() == [3.0, 3.0] and df.tolist() == [0.0, 0.0] and ddf.tolist() == [0.0, 0.0]
    # ramp with C3 = C4 = 0 stays 0
    assert [v.tolist() for v in Law("ramp", (0.0, 2.0))(np.array([1.0]))] == [[0.0]] * 3


def test_actuator_constants_default_to_zero():
    """An actuator's C with fewer than four entries is padded with zeros (contract)."""
    from pam2exu import AngularActuator, LinearActuator
    assert AngularActuator(C=[0.0, 10.0]).time_law() == Law("polynomial", (0.0, 10.0, 0.0, 0.0))
    assert LinearActuator(law="rampa", C=[0.0, 1.0, 0.2]).time_law() == Law("ramp",
                                                                           (0.0, 1.0, 0.2, 0.0))
    assert AngularActuator().time_law() == Law("polynomial", (0.0, 0.0, 0.0, 0.0))


@pytest.mark.parametrize("alias,canonical", [("polinomica", "polynomial"),
                                             ("harmonica", "harmonic"), ("rampa", "ramp")])
def test_catalan_aliases_are_the_same_law(alias, canonical):
    C = (0.1, 0.8, -0.3, 0.6)
    assert Law(alias, C) == Law(canonical, C)
    assert Law(alias, C).name == canonical
    t = np.linspace(-1.0, 2.0, 31)
    for a, b in zip(Law(alias, C)(t), Law(canonical, C)(t)):
        assert np.array_equal(a, b)


def test_unknown_law_or_too_many_constants_fail_at_construction():
    with pytest.raises(ValueError, match="unknown law 'cubic'; known laws: polynomial"):
        Law("cubic", [0.0])
    with pytest.raises(ValueError, match="at most four constants"):
        Law("polynomial", [1.0, 2.0, 3.0, 4.0, 5.0])
    assert Law("polynomial", 2.0).C == (2.0, 0.0, 0.0, 0.0)

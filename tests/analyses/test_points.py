"""Points, instantaneous centres and transmission angles (pam2exu/points.py) against closed
forms derived here and in references/closed_form.py, by hand.

Notation as in references/closed_form.py: e(a) = (cos a, sin a), n(a) = (−sin a, cos a).

- Coupler point P = A + R(φ) p of the four-bar, with its rates (``rigid_point``:
  p' = r' + φ' Ω R p, p'' = r'' + φ'' Ω R p − φ'² R p), from the circle-intersection
  closed form ``four_bar``.
- Instantaneous centre of the four-bar's coupler: the intersection of the crank line O2A
  and the rocker line O4B (the velocities of A and B are normal to them). With O2 = 0,
  O4 = (d, 0): s e(θ) = O4 + u e(ψ); crossing with e(ψ): s sin(ψ − θ) = d sin ψ, so
  I = d sin ψ / sin(ψ − θ) e(θ). The crank's centre is O2, the rocker's O4.
- Slider-crank rod: A moves normal to the crank, B along the rail (y = 0), so I lies on the
  crank line and on the vertical through B: I = (x_B, x_B tan θ).
- Transmission angle of the four-bar: the law of cosines on the diagonal A–O4 in the two
  triangles, a² + d² − 2ad cos θ = b² + c² − 2bc cos γ (γ: the angle at B between coupler
  and rocker), so μ = acos|cos γ| = acos(|b² + c² − a² − d² + 2ad cos θ| / (2bc)). Of the
  slider-crank (rail y = h): the rod's angle to the rail normal, cos μ = |sin φ| =
  |h − r sin θ| / l.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import pam2exu
from pam2exu.points import couplers, instantaneous_centre, is_opt_in, point_motion
from references.closed_form import FOUR_BAR, e, four_bar, n, rigid_point
from references.laws import actuator_law

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
COUPLER_P = np.array([0.2, 0.1])
POINT_OUTPUTS = ("x", "y", "Dx", "Dy", "v", "DDx", "DDy", "a")


@pytest.fixture(scope="module", params=list(pam2exu.registry.BACKENDS))
def four_bar_run(request):
    """The four-bar with an accelerating crank (θ'' ≠ 0), 2 s in 2000 steps, its point,
    centre and transmission-angle columns, on each backend."""
    model = pam2exu.load(EXAMPLES / "four_bar.toml")
    model["motor"].law, model["motor"].C = "polynomial", [0.3, 4.0, 3.0, -1.0]
    res = pam2exu.run(model, analysis="kinematic", t_end=2.0, steps=2000, backend=request.param,
                      outputs=["coupler.P.*", "*.IC*", "transmission_angle"])
    th, dth, ddth = actuator_law(model, "motor", res.t)
    (phi, dphi, ddphi), (psi, dpsi, ddpsi) = four_bar(**FOUR_BAR, th=th, dth=dth, ddth=ddth)
    return res, (th, dth, ddth), (phi, dphi, ddphi), (psi, dpsi, ddpsi)


def test_four_bar_coupler_point(four_bar_run):
    """coupler.P.x … a against P = A + R(φ) p of the closed form, A = a e(θ): every column
    within 1e-12 of its largest value (measured ≤ 4e-14 on both backends)."""
    res, (th, dth, ddth), (phi, dphi, ddphi), _ = four_bar_run
    a = FOUR_BAR["a"]
    A, dA, ddA = a * e(th), a * dth * n(th), a * ddth * n(th) - a * dth**2 * e(th)
    P, dP, ddP = rigid_point(A, dA, ddA, phi, dphi, ddphi, COUPLER_P)
    ref = dict(zip(POINT_OUTPUTS, (P[0], P[1], dP[0], dP[1], np.hypot(*dP),
                                   ddP[0], ddP[1], np.hypot(*ddP))))
    for var, value in ref.items():
        err = np.max(np.abs(res[f"coupler.P.{var}"] - value)) / np.max(np.abs(value))
        assert err <= 1e-12, (var, err)
    assert res.units["coupler.P.DDx"] == "m/s²" and res.units["coupler.P.v"] == "m/s"


def test_four_bar_centres(four_bar_run):
    """The coupler's centre against the intersection of the crank and rocker lines,
    I = d sin ψ / sin(ψ − θ) e(θ): within 1e-12 of its distance from A where it is within
    10 lengths (measured ≤ 1e-13), and within 1e-12 · dist · (1 + dist / L) everywhere (its
    error grows as dist² near an instantaneous translation, dist up to 7,500 m here;
    measured ≤ 1e-11 · dist). The crank's centre is O2 and the rocker's O4 (1e-15)."""
    res, (th, _, _), _, (psi, _, _) = four_bar_run
    a, d, L = FOUR_BAR["a"], FOUR_BAR["d"], 0.4
    ref = d * np.sin(psi) / np.sin(psi - th) * e(th)
    got = np.stack([res["coupler.ICx"], res["coupler.ICy"]])
    dist = np.hypot(*(ref - a * e(th)))
    err = np.hypot(*(got - ref))
    near = dist < 10 * L
    assert near.sum() > 1500 and dist.max() > 1000          # both regimes are exercised
    assert np.all(err[near] <= 1e-12 * dist[near])
    assert np.all(err <= 1e-12 * dist * (1 + dist / L))
    np.testing.assert_allclose(res["crank.ICx"], 0.0, rtol=0, atol=1e-15)
    np.testing.assert_allclose(res["crank.ICy"], 0.0, rtol=0, atol=1e-15)
    np.testing.assert_allclose(res["rocker.ICx"], d, rtol=0, atol=1e-15)
    np.testing.assert_allclose(res["rocker.ICy"], 0.0, rtol=0, atol=1e-15)
    assert "ground.ICx" not in res and "undefined" not in res.info


def test_four_bar_transmission_angle(four_bar_run):
    """μ = acos(|b² + c² − a² − d² + 2ad cos θ| / (2bc)) (law of cosines), to 1e-13 rad
    (measured ≤ 1e-14); only the coupler has the column."""
    res, (th, _, _), _, _ = four_bar_run
    a, b, c, d = (FOUR_BAR[k] for k in "abcd")
    ref = np.arccos(np.abs(b * b + c * c - a * a - d * d + 2 * a * d * np.cos(th)) / (2 * b * c))
    np.testing.assert_allclose(res["coupler.transmission_angle"], ref, rtol=0, atol=1e-13)
    assert [c for c in res.columns if c.endswith("transmission_angle")] == [
        "coupler.transmission_angle"]
    assert res.units["coupler.transmission_angle"] == "rad"


def test_slider_crank_centre_and_angle():
    """examples/slider_crank.toml (r = 0.1, l = 0.3, rail y = 0, θ = 10 t), one turn in 200
    steps: the rod's centre (x_B, x_B tan θ) within 1e-12 of its distance from A where
    |cos θ| > 0.01; NaN exactly at the two rows θ = π/2, 3π/2 (the rod translates), and
    the slider's NaN at every row, both said in ``info['undefined']``; the transmission
    angle acos|r sin θ / l| to 1e-13."""
    model = pam2exu.load(EXAMPLES / "slider_crank.toml")
    res = pam2exu.run(model, analysis="kinematic", steps=200,
                      outputs=["*.IC*", "rod.transmission_angle", "slider.x"])
    th = actuator_law(model, "motor", res.t)[0]
    r, l = 0.1, 0.3
    xB = res["slider.x"]
    ref = np.stack([xB, xB * np.tan(th)])
    got = np.stack([res["rod.ICx"], res["rod.ICy"]])
    fine = np.abs(np.cos(th)) > 0.01
    dist = np.hypot(*(ref - r * e(th)))
    assert np.all(np.hypot(*(got - ref))[fine] <= 1e-12 * dist[fine])
    undefined = np.flatnonzero(np.isnan(res["rod.ICx"]))
    np.testing.assert_allclose(th[undefined], [np.pi / 2, 3 * np.pi / 2], rtol=1e-12)
    assert np.isnan(res["slider.ICx"]).all() and np.isnan(res["slider.ICy"]).all()
    note = res.info["undefined"]
    assert "rod.ICx, rod.ICy are NaN at 2 of 201 rows" in note
    assert "slider.ICx, slider.ICy are NaN at 201 of 201 rows" in note
    np.testing.assert_allclose(res["rod.transmission_angle"],
                               np.arccos(np.abs(r * np.sin(th) / l)), rtol=0, atol=1e-13)


@pytest.mark.parametrize("backend", list(pam2exu.registry.BACKENDS))
def test_a_solid_at_rest_but_for_round_off_has_no_centre(backend):
    """examples/all_elements.toml: the sun's ramp turns it from t = 0.2 s to 0.8 s (0.5 rad,
    0.833 rad/s) and holds it before and after, where its Dfi is round-off (≤ 6e-16 rad/s
    on either backend). Its centre is then undefined: NaN at exactly those 81 of 201 rows,
    the same on both backends, and said in ``info['undefined']``. (Before, round-off Dfi
    gave it its pivot, (0.6, 0), at some of those rows and NaN where Dfi happened to be 0:
    6 rows of 40 on Exudyn, 20 on the natural backend, stop 37's CI.)"""
    res = pam2exu.run(EXAMPLES / "all_elements.toml", analysis="kinematic", backend=backend,
                      outputs=["sun.IC*", "sun.Dfi"])
    held = (res.t < 0.2 - 1e-9) | (res.t > 0.8 - 1e-9)
    assert np.count_nonzero(held) == 81
    assert np.abs(res["sun.Dfi"][held]).max() < 1e-14
    np.testing.assert_allclose(res["sun.Dfi"][~held], 0.5 / 0.6, rtol=1e-12)
    np.testing.assert_array_equal(np.isnan(res["sun.ICx"]), held)
    np.testing.assert_array_equal(np.isnan(res["sun.ICy"]), held)
    np.testing.assert_allclose(res["sun.ICx"][~held], 0.6, rtol=0, atol=1e-15)
    assert "sun.ICx, sun.ICy are NaN at 81 of 201 rows, first t = 0 s" in res.info["undefined"]


def test_round_off_motion_is_rest_and_a_slow_one_is_kept():
    """``instantaneous_centre`` with the mechanism's fastest motion (0.2 m/s): a solid whose
    velocity field is round-off (|u| + |Dfi| L = 4e-17 m/s) has no centre, one turning at
    1e-6 of the fastest about (0.3, 0.1) keeps it (to round-off), and one translating has
    none either way."""
    r = np.array([[1.0, 0.0], [1.0, 0.0], [1.0, 0.0]])
    w = np.array([3.7e-17, 2e-7, 0.0])
    v = np.array([[0.0, 0.0], [0.0, 0.0], [0.1, 0.0]])
    v[1] = w[1] * np.array([-(r[1, 1] - 0.1), r[1, 0] - 0.3])       # ω Ω (r − c)
    got = instantaneous_centre(r, v, w, 1.0, fastest=np.full(3, 0.2))
    assert np.isnan(got[0]).all() and np.isnan(got[2]).all()
    np.testing.assert_allclose(got[1], [0.3, 0.1], rtol=0, atol=1e-15)
    without = instantaneous_centre(r, v, w, 1.0)
    np.testing.assert_array_equal(without[0], r[0])       # round-off's centre: anywhere


def test_points_are_opt_in(examples):
    """The default columns have no point, centre or transmission angle; ``coupler.*``,
    ``*``, ``x`` and ``*x`` choose none either; three-part patterns choose points,
    ``*.IC*`` the centres of every moving solid."""
    default = pam2exu.run(examples / "four_bar.toml", steps=4)
    assert not any(is_opt_in(c) for c in default.columns) and len(default.columns) == 38
    job = pam2exu.analyses.job

    def chosen(*patterns):
        return job.prepare(examples / "four_bar.toml", steps=4, outputs=list(patterns)).columns

    assert chosen("coupler.*") == [f"coupler.{v}" for v in
                                   ("x", "y", "fi", "Dx", "Dy", "Dfi", "DDx", "DDy", "DDfi")]
    assert not any(is_opt_in(c) for c in chosen("*") + chosen("x") + chosen("*x"))
    assert chosen("*.P.x") == ["coupler.P.x"]
    assert chosen("*.A.v") == ["crank.A.v", "coupler.A.v"]
    assert chosen("coupler.P.*") == [f"coupler.P.{v}" for v in POINT_OUTPUTS]
    assert chosen("*.IC*") == ["crank.ICx", "crank.ICy", "coupler.ICx", "coupler.ICy",
                               "rocker.ICx", "rocker.ICy"]
    assert chosen("ICy", "transmission_angle") == ["crank.ICy", "coupler.ICy",
                                                   "coupler.transmission_angle", "rocker.ICy"]
    with pytest.raises(pam2exu.ModelError, match="'coupler.Q.x' matches no variable"):
        chosen("coupler.Q.x")


def test_levels():
    """quasi_static gives points' positions and transmission angles, not their rates nor
    centres (velocity level); the point columns of a position-only run equal the formula."""
    cols = pam2exu.analyses.job.available_columns(
        pam2exu.load(EXAMPLES / "four_bar.toml").mechanism(),
        pam2exu.registry.ANALYSES["quasi_static"])
    assert "coupler.P.x" in cols and "coupler.transmission_angle" in cols
    assert "coupler.P.Dx" not in cols and "coupler.ICx" not in cols
    res = pam2exu.run(EXAMPLES / "four_bar.toml", analysis="quasi_static", steps=10,
                      outputs=["coupler.P.*", "coupler.x", "coupler.y", "coupler.fi"])
    fi = res["coupler.fi"]
    px = res["coupler.x"] + np.cos(fi) * COUPLER_P[0] - np.sin(fi) * COUPLER_P[1]
    np.testing.assert_allclose(res["coupler.P.x"], px, rtol=0, atol=1e-15)
    assert [c for c in res.columns if c.startswith("coupler.P.")] == ["coupler.P.x",
                                                                     "coupler.P.y"]


def test_point_motion_is_rigid():
    """For a random motion r(t) = r0 + v0 t + a0 t²/2, fi(t) = fi0 + w t + α t²/2: the
    point's velocity equals the central difference of its position (h = 1e-5, to 1e-9) and
    its acceleration the second difference (h = 1e-4, to 1e-6: the differences' own
    errors, measured 1.2e-10 and 2.4e-8), and |p − r| stays |s| (1e-15)."""
    rng = np.random.default_rng(5)
    s = rng.normal(size=2)
    r0, v0, a0 = rng.normal(size=(3, 2))
    fi0, w, alpha = rng.normal(size=3)

    def motion(h):
        t = np.array([-h, 0.0, h])
        r = r0 + np.outer(t, v0) + 0.5 * np.outer(t * t, a0)
        return r, point_motion(r, v0 + np.outer(t, a0), np.tile(a0, (3, 1)),
                               fi0 + w * t + 0.5 * alpha * t * t, w + alpha * t,
                               np.full(3, alpha), s)

    _, (x, v, _) = motion(1e-5)
    np.testing.assert_allclose(v[1], (x[2] - x[0]) / 2e-5, rtol=0, atol=1e-9)
    r, (x, _, a) = motion(1e-4)
    np.testing.assert_allclose(a[1], (x[2] - 2 * x[1] + x[0]) / 1e-8, rtol=0, atol=1e-6)
    np.testing.assert_allclose(np.hypot(*(x - r).T), np.hypot(*s), rtol=1e-15)


def test_centre_is_at_rest():
    """v + Dfi Ω (I − r) = 0 at the centre (1e-15); NaN for Dfi = 0 and beyond FAR lengths."""
    r = np.array([[0.3, -0.2], [1.0, 1.0], [0.0, 0.0], [0.0, 0.0]])
    v = np.array([[0.5, 2.0], [-1.0, 0.25], [1.0, 0.0], [1.0, 0.0]])
    w = np.array([3.0, -0.7, 0.0, 1e-12])
    c = instantaneous_centre(r, v, w, length=1.0)
    rel = c[:2] - r[:2]
    np.testing.assert_allclose(v[:2] + w[:2, None] * np.stack([-rel[:, 1], rel[:, 0]], 1),
                               0.0, atol=1e-15)
    assert np.isnan(c[2:]).all()


def test_which_solids_are_couplers():
    """Four-bar: the coupler; slider-crank: the rod; with the motor moved to the rocker the
    crank becomes the output (its pin A the coupler's output pin); a coupler with a third
    joint has none."""
    mech = pam2exu.load(EXAMPLES / "four_bar.toml").mechanism()
    (c,) = couplers(mech)
    assert mech.solids[c.solid].name == "coupler" and c.output_pin.label == "coupler.B"
    assert c.pivot.label == "ground.O4" and c.guide is None
    (c,) = couplers(pam2exu.load(EXAMPLES / "slider_crank.toml").mechanism())
    assert c.output_pin.label == "rod.B" and c.guide.label == "ground.rail"
    model = pam2exu.load(EXAMPLES / "four_bar.toml")
    model["motor"].anc2 = "rocker"
    (c,) = couplers(model.mechanism())
    assert c.output_pin.label == "coupler.A" and c.pivot.label == "ground.O2"
    model.add("spring", name="s", anc1="ground.O2", anc2="coupler.P", C=[0, 1.0, 0, 0])
    assert len(couplers(model.mechanism())) == 1           # a force element is no joint
    model.add("pin_slot", name="slot", anc1="ground", anc2="coupler.P")
    assert couplers(model.mechanism()) == []


def test_cli_plots_a_coupler_curve(examples, tmp_path, capsys):
    """``run --plot coupler.P.y --x coupler.P.x`` without --outputs: the plotted point columns
    are computed besides the default ones (one command for a coupler curve)."""
    from pam2exu.cli import main
    out = tmp_path / "curve.png"
    assert main(["run", str(examples / "four_bar.toml"), "--steps", "20", "--plot",
                 "coupler.P.y", "--x", "coupler.P.x", "--plot-file", str(out)]) == 0
    printed = capsys.readouterr().out
    assert out.stat().st_size > 0
    names = [line.split()[0] for line in printed.splitlines()[3:] if line.strip()]
    names = names[:names.index("checks:")]
    default = pam2exu.run(examples / "four_bar.toml", steps=4).columns
    assert [n for n in names if not is_opt_in(n)] == default
    assert [n for n in names if is_opt_in(n)] == ["coupler.P.x", "coupler.P.y"]

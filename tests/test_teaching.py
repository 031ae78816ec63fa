"""The teaching scripts examples/*.py.

1. Every script runs as ``python examples/X.py -o out/X.png`` from a directory outside the
   repository, exits 0 and writes a real image there, and nothing else.
2. Each script's ``main`` returns its key numbers; they are checked here against references
   derived in this file from the plain dimensions (the model files read with ``tomllib``, or
   the script's own input constants), never from pam2exu. Each test's docstring gives the
   derivation. Where a closed form exists the tolerance is 1e-9 relative (errors are
   measured against the largest value of the quantity over the run).
"""
from __future__ import annotations

import importlib.util
import inspect
import math
import subprocess
import sys
import tomllib
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.image as mpimg
import numpy as np
import pytest

from references import slider_crank

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
SCRIPTS = sorted(EXAMPLES.glob("*.py"))
RTOL = 1e-9


def load_script(path: Path):
    """Import a script by its file path (its ``__main__`` block does not run)."""
    spec = importlib.util.spec_from_file_location(f"teaching_{path.stem}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def rel_err(value, reference) -> float:
    """max |value − reference| / max |reference|."""
    value, reference = np.asarray(value, dtype=float), np.asarray(reference, dtype=float)
    return float(np.max(np.abs(value - reference)) / np.max(np.abs(reference)))


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    """{script stem: main(...)'s dict}, each script's main run once."""
    out_dir = tmp_path_factory.mktemp("teaching")
    cache = {}

    def get(stem):
        if stem not in cache:
            cache[stem] = load_script(EXAMPLES / f"{stem}.py").main(out_dir / f"{stem}.png")
        return cache[stem]
    return get


# ---- 1. every script runs from anywhere and writes its figure ---------------------------

def test_the_teaching_scripts_are_there():
    assert {"coupler_curve.py", "motor_torque.py", "quick_return.py",
            "natural_jacobian.py"} <= {p.name for p in SCRIPTS}


#: the scripts whose run from another directory is long (5-10 s on two cores each): their
#: numbers are held against closed forms below in CI all the same
LONG_SCRIPTS = ("natural_jacobian", "quick_return")


@pytest.mark.parametrize("script", [pytest.param(p, marks=pytest.mark.long)
                                    if p.stem in LONG_SCRIPTS else p for p in SCRIPTS],
                         ids=lambda p: getattr(p, "stem", None) or p.values[0].stem)
def test_script_runs_from_any_directory_and_writes_its_figure(script, tmp_path):
    figure = Path("out") / f"{script.stem}.png"          # relative: lands in the cwd
    done = subprocess.run([sys.executable, str(script), "-o", str(figure)], cwd=tmp_path,
                          capture_output=True, text=True, timeout=300, check=False)
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stderr and "Warning" not in done.stderr, done.stderr
    assert str(figure) in done.stdout                    # the summary names the figure
    assert sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*")) == [Path("out"), figure]
    image = mpimg.imread(tmp_path / figure)
    assert image.ndim == 3 and image.shape[2] in (3, 4)
    assert image.shape[0] >= 300 and image.shape[1] >= 500
    colours = np.unique(image.reshape(-1, image.shape[2]), axis=0)
    assert len(colours) > 10                             # not blank
    assert (tmp_path / figure).stat().st_size > 10_000


@pytest.mark.parametrize("script", SCRIPTS, ids=lambda p: p.stem)
def test_script_main_writes_its_figure_in_the_current_directory_by_default(script):
    main = load_script(script).main
    assert inspect.signature(main).parameters["figure_path"].default == f"{script.stem}.png"


# ---- 2a. coupler curve: loop closure by circle intersection -------------------------------

def four_bar_reference(t):
    """The four-bar of examples/four_bar.toml in closed form, from the file's numbers.

    Crank: θ = f(t) = C1 + C2 t (polynomial law), A = O2 + a e(θ), a = |crank.A|.
    B is the intersection of the circles |B − A| = b (coupler) and |B − O4| = c (rocker):
    with δ = O4 − A, s = |δ|, h = (b² − c² + s²) / (2 s), k = √(b² − h²),
        B = A + h δ/s + k n(δ/s),   n(v) = v turned by +90°,
    the + sign being the assembly mode with the coupler above the ground line (the one the
    file describes: coupler fi = 0.948 rad at θ = 0). Then φ3 = atan2(B − A),
    φ4 = atan2(B − O4) and P = A + R(φ3) p, p = coupler.P (the coupler's x axis is along
    AB: B = (b, 0) in its frame).
    Velocities from the derivative of the loop A + (B − A) = O4 + (B − O4):
        a θ' n(θ) + b φ3' n(φ3) = c φ4' n(φ4)     (two linear equations in φ3', φ4'),
        v_P = a θ' n(θ) + φ3' k × R(φ3) p.
    """
    data = tomllib.loads((EXAMPLES / "four_bar.toml").read_text(encoding="utf-8"))
    solid = {s["name"]: s for s in data["solid"]}
    motor = next(e for e in data["element"] if e["type"] == "angular_actuator")
    O2, O4 = (np.array(solid["ground"]["points"][k]) for k in ("O2", "O4"))
    a = np.hypot(*solid["crank"]["points"]["A"])
    b = np.hypot(*solid["coupler"]["points"]["B"])
    c = np.hypot(*solid["rocker"]["points"]["B"])
    assert solid["coupler"]["points"]["A"] == [0.0, 0.0] and solid["coupler"]["points"]["B"][1] == 0
    p = np.array(solid["coupler"]["points"]["P"])
    C1, C2 = motor["C"][:2]
    th, dth = C1 + C2 * t, C2 + 0 * t
    e = lambda x: np.stack([np.cos(x), np.sin(x)], axis=-1)
    turn = lambda v: np.stack([-v[..., 1], v[..., 0]], axis=-1)
    A = O2 + a * e(th)
    delta = O4 - A
    s = np.linalg.norm(delta, axis=1)[:, None]
    h = (b**2 - c**2 + s**2) / (2 * s)
    B = A + h * delta / s + np.sqrt(b**2 - h**2) * turn(delta / s)
    phi3 = np.arctan2(*(B - A).T[::-1])
    phi4 = np.arctan2(*(B - O4).T[::-1])
    Rp = np.stack([np.cos(phi3) * p[0] - np.sin(phi3) * p[1],
                   np.sin(phi3) * p[0] + np.cos(phi3) * p[1]], axis=-1)
    vA = a * dth[:, None] * turn(e(th))
    M = np.stack([b * turn(e(phi3)), -c * turn(e(phi4))], axis=-1)       # (n, 2, 2)
    dphi3, dphi4 = np.linalg.solve(M, -vA[..., None])[..., 0].T
    return {"theta": th, "P": A + Rp, "vP": vA + dphi3[:, None] * turn(Rp), "phi4": phi4,
            "a": a, "b": b, "c": c, "d": np.linalg.norm(O4 - O2),
            "O2": O2, "O4": O4, "A": A, "B": B, "phi3": phi3, "dtheta": dth, "vA": vA,
            "dphi3": dphi3, "dphi4": dphi4}


def test_coupler_curve_against_the_circle_intersection(results):
    """P and its velocity at every step (361 crank angles), the curve's extent and the
    rocker's angle against ``four_bar_reference`` (circle intersection)."""
    out = results("coupler_curve")
    ref = four_bar_reference(out["t"])
    assert rel_err(np.radians(out["crank_deg"]), ref["theta"]) < RTOL
    assert rel_err(out["P"], ref["P"]) < RTOL
    assert rel_err(out["P_velocity"], ref["vP"]) < RTOL
    assert rel_err(np.radians(out["rocker_deg"]), ref["phi4"]) < RTOL
    assert out["width"] == pytest.approx(np.ptp(ref["P"][:, 0]), rel=RTOL)
    assert out["height"] == pytest.approx(np.ptp(ref["P"][:, 1]), rel=RTOL)
    speed = np.hypot(*ref["vP"].T)
    assert out["max_speed"] == pytest.approx(speed.max(), rel=RTOL)
    # a few crank angles on their own, to read: 0°, 90°, 180°, 270° (steps 0, 90, 180, 270)
    for k in (0, 90, 180, 270):
        assert out["crank_deg"][k] == pytest.approx(k, abs=1e-9)
        np.testing.assert_allclose(out["P"][k], ref["P"][k], rtol=0, atol=RTOL * 0.3)


def test_coupler_curve_rocker_swing_against_the_limit_positions(results):
    """The rocker's extreme angles come where crank and coupler are in line, O2B = b ± a;
    the triangle O2 O4 B then gives, by the cosine rule, the angle γ at O4:
    cos γ = (d² + c² − (b ± a)²) / (2 d c), rocker fi = π − γ (O2 lies along −x from O4).
    The script reports the extremes over its 361 samples (1° of crank apart), so they may
    only fall short of the true extremes, by less than the change over half a step."""
    out = results("coupler_curve")
    ref = four_bar_reference(np.array([0.0]))
    a, b, c, d = ref["a"], ref["b"], ref["c"], ref["d"]
    low, high = (math.degrees(math.pi - math.acos((d**2 + c**2 - L**2) / (2 * d * c)))
                 for L in (b + a, b - a))
    lo, hi = out["rocker_swing_deg"]
    assert low - 1e-9 <= lo <= low + 0.01
    assert high - 0.01 <= hi <= high + 1e-9


# ---- 2b. motor torque: Newton–Euler and the closed-form energies --------------------------

def newton_euler_module():
    """The hand Newton–Euler slider-crank of references/slider_crank.py (which
    tests/analyses/test_newton_euler.py checks by itself and against pam2exu)."""
    return slider_crank


def slider_crank_parameters(ne, gravity=None):
    """examples/slider_crank.toml (read with tomllib) as that module's parameter set:
    ground at the origin, massless, the rail its x axis; slider pin at its origin; no torsor."""
    data = tomllib.loads((EXAMPLES / "slider_crank.toml").read_text(encoding="utf-8"))
    solid = {s["name"]: s for s in data["solid"]}
    motor = next(e for e in data["element"] if e["type"] == "angular_actuator")
    body = lambda s: {"mass": s.get("mass", 0.0), "inertia": s.get("inertia", 0.0),
                      "cog": tuple(s.get("cog", (0.0, 0.0)))}
    assert solid["ground"]["lines"]["rail"] == {"point": [0.0, 0.0], "angle": 0.0}
    return ne.slider_crank_params(
        gravity=data["model"].get("gravity", 9.81) if gravity is None else gravity,
        ground={"pose": (0.0, 0.0, 0.0), "mass": 0.0, "inertia": 0.0, "cog": (0.0, 0.0),
                "O": (0.0, 0.0), "rail_point": (0.0, 0.0), "rail_angle": 0.0},
        crank={**body(solid["crank"]), "r": solid["crank"]["points"]["A"][0]},
        rod={**body(solid["rod"]), "l": solid["rod"]["points"]["B"][0], "T": (0.0, 0.0)},
        slider={**body(solid["slider"]), "B": (0.0, 0.0), "axis_point": (0.0, 0.0),
                "axis_angle": 0.0, "sense": +1},
        torsor={"C": (0.0, 0.0, 0.0), "axes": "global"},
        motor={"C": tuple(motor["C"])})


def test_motor_torque_against_newton_euler(results):
    """motor.Mz, and its inertia part, against the hand Newton–Euler solution of
    references/slider_crank.py (12 equations ΣF = m a_G, ΣM_G = J_G α for ground,
    crank, rod and slider, closed-form slider-crank kinematics sin φ = −r sin θ / l),
    solved at the script's times: with gravity for Mz, without it for the inertia part
    (dT/dt)/ω. The gravity part (dV/dt)/ω in closed form: y_G of the crank is c_c sin θ, of
    the rod r sin θ + c_r sin φ = r (1 − c_r/l) sin θ, of the slider 0 (c = cog along the
    link), so dV/dθ = g (m_c c_c + m_r r (1 − c_r/l)) cos θ. The kinetic and potential
    energies from the same closed-form kinematics, T = Σ m |v_G|²/2 + J ω²/2, V = Σ m g y_G.
    The motor does no net work over a turn (T and V are periodic)."""
    out = results("motor_torque")
    ne = newton_euler_module()
    t = out["t"]
    p = slider_crank_parameters(ne)
    Mz_ref = ne.newton_euler(p, t)["motor.Mz"]
    inertia_ref = ne.newton_euler(slider_crank_parameters(ne, gravity=0.0), t)["motor.Mz"]
    th = p["motor"]["C"][0] + p["motor"]["C"][1] * t
    cr, rd, g = p["crank"], p["rod"], p["gravity"]
    gravity_ref = g * (cr["mass"] * cr["cog"][0]
                       + rd["mass"] * cr["r"] * (1 - rd["cog"][0] / rd["l"])) * np.cos(th)
    assert rd["cog"][1] == 0 and cr["cog"][1] == 0 and p["slider"]["cog"] == (0.0, 0.0)
    bodies, _, _ = ne.kinematics(p, t)
    T = sum(0.5 * p[n]["mass"] * (b["G"][1] ** 2).sum(axis=0)
            + 0.5 * p[n]["inertia"] * b["fi"][1] ** 2 for n, b in bodies.items())
    V = sum(p[n]["mass"] * g * b["G"][0][1] for n, b in bodies.items())

    assert rel_err(np.radians(out["crank_deg"]), th) < RTOL
    assert rel_err(out["Mz"], Mz_ref) < RTOL
    assert rel_err(out["inertia_part"], inertia_ref) < RTOL
    assert rel_err(out["gravity_part"], gravity_ref) < RTOL
    assert rel_err(out["kinetic_energy"], T) < RTOL
    assert rel_err(out["potential_energy"], V) < RTOL
    assert rel_err(out["inertia_part"] + out["gravity_part"], Mz_ref) < RTOL
    scale = np.max(np.abs(Mz_ref))
    assert out["balance_error"] < RTOL * scale
    assert abs(out["work_per_turn"]) < RTOL * scale * 2 * math.pi
    assert out["peak_Mz"] == pytest.approx(Mz_ref[np.argmax(np.abs(Mz_ref))], rel=RTOL)


# ---- 2c. quick return: the lever tangent to the crank circle -------------------------------

def test_quick_return_against_the_closed_form(results):
    """Crank radius r about O2 = (0, d), lever pivot O4 = (0, 0), crank angle θ = ω t (the
    script's input constants R, D, OMEGA). The pin (r cos θ, d + r sin θ) lies on the slot,
    so the lever's angle is φ = atan2(d + r sin θ, r cos θ) and
        dφ/dt = ω (x y_θ − y x_θ)/(x² + y²) = ω r (r + d sin θ) / (r² + d² + 2 r d sin θ);
    at θ = 0, 90°, 270°: ω r²/(r² + d²), ω r/(d + r), −ω r/(d − r).
    The lever stops (a stroke ends) where r + d sin θ = 0, i.e. the slot is tangent to the
    crank circle (O2-pin ⟂ O4-pin): θ1 = π + asin(r/d) (end of the forward stroke, the
    lever at φ = π/2 + asin(r/d)) and θ2 = 2π − asin(r/d) (end of the return, φ =
    π/2 − asin(r/d)). So the lever swings α = 2 asin(r/d), the return lasts
    (θ2 − θ1)/ω = (π − α)/ω, the forward stroke (π + α)/ω, and the time ratio is
    (π + α)/(π − α)."""
    module = load_script(EXAMPLES / "quick_return.py")
    r, d, w = module.R, module.D, module.OMEGA
    out = results("quick_return")
    t = out["t"]
    th = w * t
    ref = w * r * (r + d * np.sin(th)) / (r**2 + d**2 + 2 * r * d * np.sin(th))
    assert rel_err(np.radians(out["crank_deg"]), th) < RTOL
    assert rel_err(out["lever_Dfi"], ref) < RTOL
    scale = np.max(np.abs(ref))
    for k, value in ((0, w * r**2 / (r**2 + d**2)), (90, w * r / (d + r)),
                     (270, -w * r / (d - r))):
        assert out["crank_deg"][k] == pytest.approx(k, abs=1e-9)
        assert out["lever_Dfi"][k] == pytest.approx(value, rel=0, abs=RTOL * scale)

    s = math.asin(r / d)
    alpha = 2 * s
    th1, th2 = math.pi + s, 2 * math.pi - s
    period = 2 * math.pi / w
    assert out["stroke_end_times"][0] == pytest.approx(th1 / w, rel=0, abs=RTOL * period)
    assert out["stroke_end_times"][1] == pytest.approx(th2 / w, rel=0, abs=RTOL * period)
    assert math.radians(out["stroke_end_crank_deg"][0]) == pytest.approx(th1, rel=RTOL)
    assert math.radians(out["stroke_end_crank_deg"][1]) == pytest.approx(th2, rel=RTOL)
    assert math.radians(out["lever_swing_deg"]) == pytest.approx(alpha, rel=RTOL)
    assert out["forward_time"] == pytest.approx((math.pi + alpha) / w, rel=RTOL)
    assert out["return_time"] == pytest.approx((math.pi - alpha) / w, rel=RTOL)
    assert out["time_ratio"] == pytest.approx((math.pi + alpha) / (math.pi - alpha), rel=RTOL)
    assert out["time_ratio_formula"] == pytest.approx((math.pi + alpha) / (math.pi - alpha),
                                                      rel=1e-15)


# ---- 2d. natural Jacobian: the four-bar's constraint gradients in closed form --------------

def _parallel_rows(M, reference, tol=1e-12):
    """Each row of M is parallel to exactly one row of ``reference``, all of them used."""
    unit = lambda X: X / np.linalg.norm(X, axis=1, keepdims=True)          # noqa: E731
    cos = np.abs(unit(np.asarray(M, dtype=float)) @ unit(np.asarray(reference, dtype=float)).T)
    match = [np.flatnonzero(c > 1 - tol) for c in cos]
    assert all(len(m) == 1 for m in match), cos
    assert sorted(int(m[0]) for m in match) == list(range(len(reference)))


def test_natural_jacobian_against_the_closed_form(results):
    """The four-bar at t = 0 from ``four_bar_reference`` (circle intersection: θ = 0, A, B,
    φ3, φ4 and the rates θ', φ3', φ4'). The script's q0 is x, y, fi of ground (0, 0, 0),
    crank (O2, θ), coupler (A, φ3: its origin is its point A) and rocker (O4, φ4).

    Reference-point rows (columns x, y, fi of the four solids), each up to a factor:
    the fixed link, ∂x_g, ∂y_g, ∂fi_g; a revolute joining s_i of solid i and s_j of solid j,
    the gradients of the two components of r_j − r_i, r = (x, y) + R(fi) s, whose fi entries
    are ∓(R s)_y, ±(R s)_x; the motor, fi_crank − fi_ground.
    Natural rows (columns A, B, θ, named by the script after the crank's point (0.1, 0),
    the coupler's point (0.35, 0) and crank.fi), the gradients of |A − O2|² = a²,
    (A − O2) × e(θ) = 0 (the crank along θ), |B − A|² = b², |B − O4|² = c², θ = f(t).
    Both matrices are square and regular (ranks 12 and 5), and the velocities both give are
    the closed-form ones: ẋ, ẏ of the coupler = v_A = a θ' n(θ), its fi rate φ3', the rocker's
    φ4', the crank's θ' = C2, the rest 0; ż = (v_A, v_B = c φ4' n(φ4), θ')."""
    out = results("natural_jacobian")
    ref = four_bar_reference(np.array([0.0]))
    th, phi3, phi4 = ref["theta"][0], ref["phi3"][0], ref["phi4"][0]
    O2, O4, A, B = ref["O2"], ref["O4"], ref["A"][0], ref["B"][0]
    data = tomllib.loads((EXAMPLES / "four_bar.toml").read_text(encoding="utf-8"))
    solids = [s["name"] for s in data["solid"]]
    points = {s["name"]: s["points"] for s in data["solid"]}
    pose = {"ground": (0.0, 0.0, 0.0), "crank": (*O2, th), "coupler": (*A, phi3),
            "rocker": (*O4, phi4)}
    q0 = np.array([v for name in solids for v in pose[name]])
    assert out["Cq_columns"] == [f"{n}.{v}" for n in solids for v in ("x", "y", "fi")]
    assert rel_err(out["q0"], q0) < RTOL

    col = {name: k for k, name in enumerate(out["Cq_columns"])}
    rows = []
    for el in data["element"]:
        if el["type"] == "fixed":
            for v in ("x", "y", "fi"):
                rows.append(np.eye(12)[col[f"{el['anc1']}.{v}"]])
        elif el["type"] == "revolute":
            for k in (0, 1):
                row = np.zeros(12)
                for sign, anchor in ((-1, el["anc1"]), (1, el["anc2"])):
                    solid, point = anchor.split(".")
                    fi = pose[solid][2]
                    s = points[solid][point]
                    Rs = np.array([np.cos(fi) * s[0] - np.sin(fi) * s[1],
                                   np.sin(fi) * s[0] + np.cos(fi) * s[1]])
                    row[col[f"{solid}.{'xy'[k]}"]] += sign
                    row[col[f"{solid}.fi"]] += sign * (-Rs[1] if k == 0 else Rs[0])
                rows.append(row)
        elif el["type"] == "angular_actuator":
            row = np.zeros(12)
            row[col[f"{el['anc2']}.fi"]], row[col[f"{el['anc1']}.fi"]] = 1.0, -1.0
            rows.append(row)
    assert np.shape(out["Cq"]) == (12, 12) and len(out["Cq_rows"]) == 12
    _parallel_rows(out["Cq"], rows)

    # the natural columns: A, B by the local point each names, θ
    where = {"crank(0.1,0)": "A", "coupler(0.35,0)": "B"}
    assert sorted(out["Phi_columns"]) == sorted(
        [f"{p}.{v}" for p in where for v in "xy"] + ["crank.fi"])
    assert points["crank"]["A"] == [0.1, 0.0] and points["coupler"]["B"] == [0.35, 0.0]
    order = {"A.x": 0, "A.y": 1, "B.x": 2, "B.y": 3, "crank.fi": 4}
    perm = [order[where[c[:-2]] + c[-2:] if c != "crank.fi" else c] for c in out["Phi_columns"]]
    e = np.array([np.cos(th), np.sin(th)])
    reference = np.array([
        [*2 * (A - O2), 0, 0, 0],
        [e[1], -e[0], 0, 0, (A - O2) @ e],
        [*-2 * (B - A), *2 * (B - A), 0],
        [0, 0, *2 * (B - O4), 0],
        [0, 0, 0, 0, 1],
    ])[:, perm]
    assert np.shape(out["Phi_z"]) == (5, 5) and len(out["Phi_rows"]) == 5
    _parallel_rows(out["Phi_z"], reference)
    assert out["ranks"] == (12, 5)

    qd = {"ground": (0.0, 0.0, 0.0), "crank": (0.0, 0.0, ref["dtheta"][0]),
          "coupler": (*ref["vA"][0], ref["dphi3"][0]), "rocker": (0.0, 0.0, ref["dphi4"][0])}
    qd = np.array([v for name in solids for v in qd[name]])
    assert rel_err(out["qd_reference"], qd) < RTOL
    assert rel_err(out["qd_natural"], qd) < RTOL
    assert out["velocity_difference"] < RTOL * np.max(np.abs(qd))
    turn = lambda v: np.array([-v[1], v[0]])                              # noqa: E731
    vB = ref["c"] * ref["dphi4"][0] * turn(np.array([np.cos(phi4), np.sin(phi4)]))
    zd = np.array([*ref["vA"][0], *vB, ref["dtheta"][0]])[perm]
    assert rel_err(out["zd"], zd) < RTOL


def _make_teaching():
    """docs/make_teaching.py, loaded by its path (docs/ is not a package)."""
    spec = importlib.util.spec_from_file_location("make_teaching",
                                                  ROOT / "docs" / "make_teaching.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_lessons_figures_are_the_commands_the_page_shows(tmp_path):
    """Every figure of the four-bar lesson is drawn by docs/make_teaching.py with the
    command the page shows beside it; the page names each, and draw one again here."""
    make = _make_teaching()
    page = (ROOT / "docs" / "teaching.md").read_text(encoding="utf-8")
    for name, command, _ in make.FIGURES:
        assert command in page and f"img/{name}" in page, name
        assert (ROOT / "docs" / "img" / name).is_file(), \
            f"missing docs/img/{name}: run python docs/make_teaching.py"
    assert make.EXAM_COMMAND in page and f"img/{make.EXAM_FIGURE}" in page
    assert (ROOT / "docs" / "img" / make.EXAM_FIGURE).is_file()
    path = make.draw_figure("lesson_centres.png", tmp_path)
    assert path.read_bytes().startswith(b"\x89PNG")

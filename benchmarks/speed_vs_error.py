"""Speed against error of pam2exu, measured in one run; writes docs/performance.md.

    python benchmarks/speed_vs_error.py            # full run (about 5 minutes on 2 cores)
    python benchmarks/speed_vs_error.py --quick    # smoke test (under a minute), written to
                                                   # a temporary directory, not to docs/

What it measures (each section of docs/performance.md is one of these):

1. Work against precision: the slider-crank and the four-bar, kinematic and kinetostatic,
   over a grid of step counts and Exudyn tolerances; wall time per step (best of several
   repeats) and the largest relative error of positions, velocities, accelerations and
   reactions against closed-form and Newton–Euler references.
2. pam2exu against a plain, hand-written Exudyn script doing the same four-bar position
   solve, with the driver as a Python pre-step function and as a symbolic offset function;
   Newton iterations per step of that solve.
3. Hard cases: a slider-crank through both dead centres (in line and offset), a long run
   (100 turns, 100,000 steps: the error at the end), the redundant parallelogram.
4. Size: a chain of N four-bar loops (each loop's output link is the next loop's input
   link, one motor drives them all), N = 1 … 64; time per step against N and the fitted
   exponent; errors against the chained closed form and a Newton–Euler solution.

References (the top-level ``references`` package, shared with the tests). Kinematics: the
closed forms of references/closed_form.py (``four_bar``, chained loop by loop for the chain)
and references/slider_crank.py (``kinematics``: offset slider-crank with the slider's pin
off its line). Forces: ``newton_euler`` of references/slider_crank.py for the slider-crank; for the four-bar and the
chain, ``revolute_newton_euler`` below (Σ F = m a_G, Σ M_G = J α per body, solved at every
step), which checks itself by the power balance before it is used. No reference comes
from pam2exu.
"""
from __future__ import annotations

import argparse
import contextlib
import math
import os
import platform
import sys
import tempfile
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))          # the references/ package at the repository root

import exudyn as exu
from exudyn import itemInterface as items

import references.closed_form as kcf  # noqa: E402
import references.slider_crank as ne  # noqa: E402
from references.laws import actuator_law  # noqa: E402

from pam2exu.analyses.native import SPARSE_FROM  # noqa: E402
from pam2exu.backend.system import DENSE_UP_TO  # noqa: E402
import pam2exu
from pam2exu.analyses import common
from pam2exu.backend import SolveSettings

TWO_PI = 2.0 * math.pi
DEFAULT_TOLERANCE = SolveSettings().tolerance
CATEGORIES = {"positions": ("x", "y", "fi"), "velocities": ("Dx", "Dy", "Dfi"),
              "accelerations": ("DDx", "DDy", "DDfi")}
KINDS = ("positions", "velocities", "accelerations", "reactions")


# ---- what to run ---------------------------------------------------------------------------

@dataclass
class Plan:
    """The grids of one benchmark run."""

    steps: tuple = (1000, 10000)
    big_steps: int = 100000                  # one more step count, four-bar only
    tolerances: tuple = (1e-6, 1e-9, 1e-13)
    repeats: int = 5
    big_repeats: int = 3                     # repeats of the runs of 100,000 steps
    compare_steps: tuple = (1000, 10000, 100000)
    compare_repeats: int = 10                # rounds, spread over the run
    chain_sizes: tuple = (1, 2, 4, 8, 16, 32, 64)
    chain_steps: int = 500
    long_turns: int = 100
    long_steps: int = 100000


FULL = Plan()
QUICK = Plan(steps=(1000,), big_steps=0, tolerances=(1e-6, 1e-13), repeats=2, big_repeats=1,
             compare_steps=(2000,), compare_repeats=5, chain_sizes=(1, 2, 4, 8),
             chain_steps=200, long_turns=10, long_steps=10000)


# ---- timing --------------------------------------------------------------------------------

def best_of(fn, repeats):
    """(least wall time [s], the result of that run) over ``repeats`` calls of fn()."""
    best, out = math.inf, None
    for _ in range(repeats):
        start = time.perf_counter()
        value = fn()
        seconds = time.perf_counter() - start
        if seconds < best:
            best, out = seconds, value
    return best, out


@contextlib.contextmanager
def residual_check_off():
    """Switch off pam2exu's after-run residual check (loose tolerances only, marked †)."""
    saved = common.RESIDUAL_TOLERANCE
    common.RESIDUAL_TOLERANCE = math.inf
    try:
        yield
    finally:
        common.RESIDUAL_TOLERANCE = saved


@dataclass
class Run:
    """One timed pam2exu configuration."""

    case: str
    analysis: str
    steps: int
    tolerance: float
    seconds: float                          # best total wall time
    exudyn_seconds: float                   # its res.info['exudyn_seconds']
    errors: dict = field(default_factory=dict)   # kind -> (max relative error, column)
    note: str = ""
    warnings: list = field(default_factory=list)  # res.warnings (texts)

    @property
    def us(self):
        return 1e6 * self.seconds / self.steps

    @property
    def exudyn_us(self):
        return 1e6 * self.exudyn_seconds / self.steps


def run_pam(model, analysis, steps, t_end, tolerance, repeats, dense=None):
    """Best-of-``repeats`` timing of pam2exu.run; returns (seconds, result, note).

    pam2exu's warnings are not shown (they are kept in ``res.warnings`` and reported).
    A tolerance too loose for pam2exu's residual check (constraint residual above 1e-8 of
    the length scale: pam2exu stops with TranslationError) is run again with the check
    switched off, so that its error can still be measured; the note says so.
    """
    def once():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return pam2exu.run(model, analysis=analysis, t_end=t_end, steps=steps,
                               solver=SolveSettings(tolerance=tolerance, dense=dense))
    try:
        seconds, res = best_of(once, repeats)
        return seconds, res, ""
    except pam2exu.TranslationError:
        with residual_check_off():
            seconds, res = best_of(once, repeats)
        return seconds, res, "†"


def measure(case, model, analysis, steps, t_end, tolerance, repeats, kin, forces, L, w,
            dense=None, keep=False):
    """Time one configuration and compare it with its references; a Run (with the Results
    as ``run.res`` if ``keep``)."""
    seconds, res, note = run_pam(model, analysis, steps, t_end, tolerance, repeats, dense)
    errors = error_summary(res, kin, forces if analysis == "kinetostatic" else None, L, w)
    run = Run(case, analysis, steps, tolerance, seconds, res.info["exudyn_seconds"], errors,
              note, list(res.warnings))
    if keep:
        run.res = res
    return run


def describe(run):
    return (f"{run.us:8.1f} µs/step (Exudyn {run.exudyn_us:7.1f}) "
            + " ".join(f"{k[:3]} {v[0]:.1e}" for k, v in run.errors.items()) + run.note
            + (f" [{len(run.warnings)} warning(s)]" if run.warnings else ""))


def warning_summary(runs):
    """The distinct warnings of some runs, each shortened to its first clause."""
    texts = [w.split(":")[0].split(" (")[0] for r in runs for w in r.warnings]
    return "; ".join(dict.fromkeys(texts))


# ---- errors --------------------------------------------------------------------------------

def error_summary(res, kin_ref, force_ref, L, w):
    """{kind: (max relative error, worst column)} for the kinds the references cover.

    Kinematics: ``errors`` of test_kinematic_closed_form (per column max |res − ref| over
    the largest |ref| of that column; a column whose reference is ~0 uses the natural
    scale L, L·w, L·w²). Reactions: ``errors`` of test_newton_euler (the same; a ~0 column
    uses the largest |ref| of all reaction columns).
    """
    out = {}
    kin = kcf.errors(res, {c: v for c, v in kin_ref.items() if c in res.columns}, L, w)
    for kind, suffixes in CATEGORIES.items():
        cols = {c: v for c, v in kin.items() if c.rsplit(".", 1)[1] in suffixes}
        if cols:
            worst = max(cols, key=cols.get)
            out[kind] = (cols[worst], worst)
    if force_ref and all(c in res.columns for c in force_ref):
        forces = ne.errors(res, force_ref)
        worst = max(forces, key=forces.get)
        out["reactions"] = (forces[worst], worst)
    return out


def at_row(res, ref, row, L, w):
    """The kinematic errors of one row only, with the scales of ``error_summary`` (the
    largest |reference| of each column over the whole run)."""
    fallback = kcf.natural_scales(L, w)
    out = {}
    for kind, suffixes in CATEGORIES.items():
        worst, where = 0.0, ""
        for c, v in ref.items():
            suffix = c.rsplit(".", 1)[1]
            if suffix not in suffixes or c not in res.columns:
                continue
            v = np.broadcast_to(np.asarray(v, dtype=float), res.t.shape)
            scale = float(np.max(np.abs(v)))
            if scale < 1e-9 * fallback[suffix]:
                scale = fallback[suffix]
            e = abs(float(res[c][row]) - float(v[row])) / scale
            if e >= worst:
                worst, where = e, c
        out[kind] = (worst, where)
    return out


# ---- Newton–Euler for mechanisms of revolute joints -------------------------------------------

@dataclass
class Body:
    """Mass m at G, inertia J about G; G (2, k) with its two rates, angle rates w, alpha (k,)."""

    m: float
    J: float
    G: np.ndarray
    vG: np.ndarray
    aG: np.ndarray
    w: np.ndarray
    alpha: np.ndarray


def body(m, J, cog, origin, fi):
    """Body from its origin (r, r', r'') and angle (fi, fi', fi'') and G's local position."""
    G, vG, aG = ne.rigid_point(*origin, *fi, cog)
    return Body(m, J, G, vG, aG, fi[1], fi[2])


def revolute_newton_euler(bodies, links, gravity, chunk=32):
    """Reactions of a planar mechanism whose first body is fixed, joined by revolutes and
    driven by angular actuators; {column: (k,) array}, as pam2exu names them.

    ``links``: ("fixed", name, body) — wrench the body receives at its origin (Fx, Fy, Mz,
    the body's origin being (0, 0) here); ("revolute", name, body1, body2, P) — force body1
    exerts on body2 at P (2, k) (Fx, Fy; body1 receives the opposite); ("motor", name,
    body1, body2) — torque Mz on body2, −Mz on body1.
    Equations, 3 per body: Σ F = m a_G, Σ (P − G) × F + Σ M = J α, with the weight
    m (0, −g) at G; solved at every step (dense, ``chunk`` steps at a time).
    """
    names = list(bodies)
    row = {b: 3 * i for i, b in enumerate(names)}
    cols, entries = [], []                # entries: (column, body, kind, sign, direction, P)
    for link in links:
        kind, name = link[0], link[1]
        if kind == "fixed":
            for comp, u in (("Fx", (1.0, 0.0)), ("Fy", (0.0, 1.0))):
                entries.append((len(cols), link[2], "force", 1.0, u, None))
                cols.append(f"{name}.{comp}")
            entries.append((len(cols), link[2], "couple", 1.0, None, None))
            cols.append(f"{name}.Mz")
        elif kind == "revolute":
            _, _, b1, b2, P = link
            for comp, u in (("Fx", (1.0, 0.0)), ("Fy", (0.0, 1.0))):
                entries.append((len(cols), b2, "force", 1.0, u, P))
                entries.append((len(cols), b1, "force", -1.0, u, P))
                cols.append(f"{name}.{comp}")
        elif kind == "motor":
            _, _, b1, b2 = link
            entries.append((len(cols), b2, "couple", 1.0, None, None))
            entries.append((len(cols), b1, "couple", -1.0, None, None))
            cols.append(f"{name}.Mz")
    n = 3 * len(names)
    assert len(cols) == n, (len(cols), n)
    k = next(iter(bodies.values())).G.shape[1]
    x = np.empty((k, n))
    for a in range(0, k, chunk):
        s = slice(a, min(k, a + chunk))
        A = np.zeros((s.stop - s.start, n, n))
        rhs = np.zeros((s.stop - s.start, n))
        for j, b, kind, sign, u, P in entries:
            i = row[b]
            if kind == "couple":
                A[:, i + 2, j] += sign
                continue
            A[:, i, j] += sign * u[0]
            A[:, i + 1, j] += sign * u[1]
            arm = (np.zeros((2, s.stop - s.start)) if P is None else P[:, s]) - bodies[b].G[:, s]
            A[:, i + 2, j] += sign * (arm[0] * u[1] - arm[1] * u[0])
        for b in names:
            i, B = row[b], bodies[b]
            rhs[:, i] = B.m * B.aG[0, s]
            rhs[:, i + 1] = B.m * (B.aG[1, s] + gravity)
            rhs[:, i + 2] = B.J * B.alpha[s]
        x[s] = np.linalg.solve(A, rhs[..., None])[..., 0]
    out = {c: x[:, j] for j, c in enumerate(cols)}
    check_power(bodies, links, out, gravity)
    return out


def check_power(bodies, links, out, gravity):
    """Self-check of the reference: ideal joints and a fixed first body do no work, so
    Σ motor power = Σ (m a_G·v_G + J α ω + m g v_Gy) (the rate of kinetic + potential energy)."""
    motor = sum(out[f"{name}.Mz"] * (bodies[b2].w - bodies[b1].w)
                for kind, name, *rest in links if kind == "motor" for b1, b2 in [rest])
    energy = sum(B.m * np.sum(B.aG * B.vG, axis=0) + B.J * B.alpha * B.w
                 + B.m * gravity * B.vG[1] for B in bodies.values())
    scale = max(float(np.max(np.abs(motor))), 1e-300)
    err = float(np.max(np.abs(motor - energy))) / scale
    assert err < 1e-9, f"Newton–Euler reference fails its power balance: {err:.3g}"


# ---- the mechanisms and their references ---------------------------------------------------------

def still_body(x, y, k):
    z = np.zeros(k)
    return ((np.stack([x + z, y + z]), np.zeros((2, k)), np.zeros((2, k))), (z, z, z))


def solid_columns(name, origin, fi):
    return kcf.solid(name, origin[0], fi[0], origin[1], fi[1], origin[2], fi[2])


def four_bar_case(t_end=1.0, C=None):
    """examples/four_bar.toml (optionally another polynomial law) and its references."""
    model = pam2exu.load(ROOT / "examples" / "four_bar.toml")
    if C is not None:
        model["motor"].C = list(C)

    def reference(t):
        a, b, c, d = (kcf.FOUR_BAR[key] for key in "abcd")
        th, dth, ddth = actuator_law(model, "motor", t)
        (phi, dphi, ddphi), (psi, dpsi, ddpsi) = kcf.four_bar(a, b, c, d, th, dth, ddth)
        k = len(t)
        z = np.zeros(k)
        Z = np.zeros((2, k))
        origin = {"ground": (Z, Z, Z), "crank": (Z, Z, Z),
                  "coupler": (a * kcf.e(th), a * dth * kcf.n(th),
                              a * ddth * kcf.n(th) - a * dth**2 * kcf.e(th)),
                  "rocker": (np.stack([d + z, z]), Z, Z)}
        angle = {"ground": (z, z, z), "crank": (th, dth, ddth), "coupler": (phi, dphi, ddphi),
                 "rocker": (psi, dpsi, ddpsi)}
        kin = {}
        bodies = {}
        for name, r in origin.items():
            kin.update(solid_columns(name, r, angle[name]))
            s = model[name]
            bodies[name] = body(float(s.mass), float(s.inertia), [float(v) for v in s.cog],
                                r, angle[name])
        A = origin["coupler"][0]
        B = A + b * kcf.e(phi)
        links = [("fixed", "base", "ground"),
                 ("revolute", "O2", "ground", "crank", Z),
                 ("revolute", "A", "crank", "coupler", A),
                 ("revolute", "B", "coupler", "rocker", B),
                 ("revolute", "O4", "ground", "rocker", origin["rocker"][0]),
                 ("motor", "motor", "ground", "crank")]
        forces = revolute_newton_euler(bodies, links, float(model.gravity))
        return kin, forces
    w = float(np.max(np.abs(actuator_law(model, "motor", np.linspace(0, t_end, 101))[1])))
    return model, reference, 0.4, w


def slider_crank_case(**over):
    """The Newton–Euler slider-crank of test_newton_euler (offset pin, centres of mass off
    the axes, gravity, a torsor on the rod, an accelerating motor) and its references."""
    p = ne.slider_crank_params(**over)
    model = pam2exu.loads(ne.model_toml(p, "kinematic"))

    def reference(t):
        return ne.kinematic_ref(p, t, with_rates=True), ne.newton_euler(p, t)
    th = ne.law_polynomial(np.linspace(0, p["t_end"], 101), p["motor"]["C"])
    return model, reference, 0.4, float(np.max(np.abs(th[1]))), p


def parallelogram_case():
    """tests/data/parallelogram5.toml: three parallel cranks 0.3 at x = 0, 0.5, 1 turned by
    θ = π/2 + 1.2 cos 2πt; the coupler translates, its origin A1 = 0.3 e(θ), fi = 0."""
    model = pam2exu.load(ROOT / "tests" / "data" / "parallelogram5.toml")

    def reference(t):
        th, dth, ddth = actuator_law(model, "motor", t)
        k = len(t)
        z = np.zeros(k)
        Z = np.zeros((2, k))
        r = 0.3
        kin = {**kcf.still("ground", 0.0, 0.0, 0.0, k),
               **solid_columns("coupler", (r * kcf.e(th), r * dth * kcf.n(th),
                                           r * ddth * kcf.n(th) - r * dth**2 * kcf.e(th)),
                               (z, z, z))}
        for name, x in (("crank1", 0.0), ("crank2", 1.0), ("crank3", 0.5)):
            kin.update(solid_columns(name, (np.stack([x + z, z]), Z, Z), (th, dth, ddth)))
        return kin, None
    return model, reference, 1.0, 1.2 * TWO_PI


# ---- the chain of four-bar loops ---------------------------------------------------------------

#: each loop: input link a, coupler b, output link c, ground d (the shortest: a drag link,
#: Grashof, both links turn fully); the shared link carries the next loop's input point at
#: −a (opposite its output point), which keeps the speed ratio of the whole chain bounded
CHAIN = {"a": 0.3, "b": 0.32, "c": 0.3, "d": 0.1}
LINK = {"mass": 0.4, "inertia": 0.012, "cog": (0.01, 0.005)}
COUPLER = {"mass": 0.3, "inertia": 0.0026, "cog": (0.16, 0.01)}
CHAIN_LAW = (0.3, TWO_PI)                        # θ = 0.3 + 2π t


def chain_kinematics(N, t):
    """Closed form of the chain, loop by loop (``four_bar`` of the tests, shifted by j·d):
    link i pivots at P_i = (i d, 0); loop j turns link j−1 (input point at angle
    fi_{j−1} + α, α = 0 for the crank, π after) and link j (output point at angle fi_j).
    Returns ({solid: (origin, angle)}, {joint: point}) with rates."""
    a, b, c, d = (CHAIN[key] for key in "abcd")
    k = len(t)
    z = np.zeros(k)
    Z = np.zeros((2, k))
    th = (CHAIN_LAW[0] + CHAIN_LAW[1] * t, CHAIN_LAW[1] + z, z)
    solids = {"L0": ((Z, Z, Z), th)}
    joints = {"O0": Z}
    for j in range(1, N + 1):
        alpha = 0.0 if j == 1 else math.pi
        fi_in, dfi_in, ddfi_in = solids[f"L{j - 1}"][1]
        ti = fi_in + alpha
        (phi, dphi, ddphi), (psi, dpsi, ddpsi) = kcf.four_bar(a, b, c, d, ti, dfi_in, ddfi_in)
        P = np.stack([(j - 1) * d + z, z])
        A = (P + a * kcf.e(ti), a * dfi_in * kcf.n(ti),
             a * ddfi_in * kcf.n(ti) - a * dfi_in**2 * kcf.e(ti))
        solids[f"K{j}"] = (A, (phi, dphi, ddphi))
        solids[f"L{j}"] = ((np.stack([j * d + z, z]), Z, Z), (psi, dpsi, ddpsi))
        joints[f"A{j}"] = A[0]
        joints[f"B{j}"] = A[0] + b * kcf.e(phi)
        joints[f"O{j}"] = np.stack([j * d + z, z])
    return solids, joints


def chain_model(N):
    """N loops, assembled exactly at t = 0 from ``chain_kinematics`` (initial guesses)."""
    a, b, c, d = (CHAIN[key] for key in "abcd")
    solids, _ = chain_kinematics(N, np.zeros(1))
    m = pam2exu.Model(f"chain of {N} four-bar loops", gravity=9.81)
    m.add_solid("ground", points={f"P{i}": [i * d, 0.0] for i in range(N + 1)})
    m.add("fixed", name="base", anc1="ground")
    for i in range(N + 1):
        (r, _, _), (fi, _, _) = solids[f"L{i}"]
        points = {"O": [0.0, 0.0]}
        if i < N:
            points["A"] = [a, 0.0] if i == 0 else [-a, 0.0]
        if i > 0:
            points["B"] = [c, 0.0]
        m.add_solid(f"L{i}", x=float(r[0, 0]), y=float(r[1, 0]), fi=float(fi[0]),
                    points=points, **LINK)
        m.add("revolute", name=f"O{i}", anc1=f"ground.P{i}", anc2=f"L{i}.O")
    for j in range(1, N + 1):
        (r, _, _), (fi, _, _) = solids[f"K{j}"]
        m.add_solid(f"K{j}", x=float(r[0, 0]), y=float(r[1, 0]), fi=float(fi[0]),
                    points={"A": [0.0, 0.0], "B": [b, 0.0]}, **COUPLER)
        m.add("revolute", name=f"A{j}", anc1=f"L{j - 1}.A", anc2=f"K{j}.A")
        m.add("revolute", name=f"B{j}", anc1=f"K{j}.B", anc2=f"L{j}.B")
    m.add("angular_actuator", name="motor", anc1="ground", anc2="L0", law="polynomial",
          C=[CHAIN_LAW[0], CHAIN_LAW[1], 0.0, 0.0])
    return m


def chain_reference(N, t):
    solids, joints = chain_kinematics(N, t)
    k = len(t)
    kin = dict(kcf.still("ground", 0.0, 0.0, 0.0, k))
    bodies = {"ground": body(0.0, 0.0, (0.0, 0.0), *still_body(0.0, 0.0, k))}
    for name, (origin, angle) in solids.items():
        kin.update(solid_columns(name, origin, angle))
        inertial = LINK if name.startswith("L") else COUPLER
        bodies[name] = body(inertial["mass"], inertial["inertia"], inertial["cog"], origin, angle)
    links = [("fixed", "base", "ground")]
    for i in range(N + 1):
        links.append(("revolute", f"O{i}", "ground", f"L{i}", joints[f"O{i}"]))
    for j in range(1, N + 1):
        links.append(("revolute", f"A{j}", f"L{j - 1}", f"K{j}", joints[f"A{j}"]))
        links.append(("revolute", f"B{j}", f"K{j}", f"L{j}", joints[f"B{j}"]))
    links.append(("motor", "motor", "ground", "L0"))
    return kin, revolute_newton_euler(bodies, links, 9.81)


def fit_exponent(N, y):
    """p of y ≈ C N^p, least squares in log-log."""
    return float(np.polyfit(np.log(N), np.log(y), 1)[0])


# ---- a plain, hand-written Exudyn four-bar ----------------------------------------------------

def plain_exudyn_four_bar(steps, tolerance, driver, count_iterations=False):
    """The four-bar's position solve (examples/four_bar.toml, θ = 2π t, 1 s) written
    directly in Exudyn, with the settings pam2exu uses: one static load step per time
    t_k = k/steps (k = 0 … steps; load step k + 1 solves t_k), Newton tolerance
    ``tolerance`` × 0.4 m (not below the round-off floor 16 ε · max|θ|), dense solver,
    sensors storing the node coordinates.

    driver: "prestep" (the crank's ConnectorCoordinate offset set by a Python
    PreStepUserFunction) or "symbolic" (an exudyn.symbolic offsetUserFunction).
    Returns (q (steps + 1, 9), seconds to build + solve + read, seconds of the solve,
    (Newton iterations, Jacobians) per step with ``count_iterations``, else None).
    """
    start = time.perf_counter()
    a, b, c, d = 0.1, 0.35, 0.3, 0.4
    omega, dt, n = TWO_PI, 1.0 / steps, steps + 1
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    ground = mbs.AddObject(items.ObjectGround())
    nodes, bodies = [], []
    for q0 in ([0.0, 0.0, 0.02], [0.11, 0.01, 0.9], [0.4, 0.0, 1.85]):   # the example's guesses
        node = mbs.AddNode(items.NodeRigidBody2D(referenceCoordinates=[0.0, 0.0, 0.0],
                                                 initialCoordinates=q0))
        nodes.append(node)
        bodies.append(mbs.AddObject(items.ObjectRigidBody2D(nodeNumber=node, mass=0.0,
                                                            inertia=0.0)))
    crank, coupler, rocker = bodies

    def marker(body_, x, y=0.0):
        return mbs.AddMarker(items.MarkerBodyRigid(bodyNumber=body_, localPosition=[x, y, 0.0]))

    for m1, m2 in ((marker(ground, 0.0), marker(crank, 0.0)),
                   (marker(crank, a), marker(coupler, 0.0)),
                   (marker(coupler, b), marker(rocker, c)),
                   (marker(ground, d), marker(rocker, 0.0))):
        mbs.AddObject(items.ObjectJointRevolute2D(markerNumbers=[m1, m2]))
    ground_node = mbs.AddNode(items.NodePointGround())
    m_ground = mbs.AddMarker(items.MarkerNodeCoordinate(nodeNumber=ground_node, coordinate=0))
    m_fi = mbs.AddMarker(items.MarkerNodeCoordinate(nodeNumber=nodes[0], coordinate=2))
    drive = mbs.AddObject(items.ObjectConnectorCoordinate(markerNumbers=[m_ground, m_fi]))
    sensors = [mbs.AddSensor(items.SensorNode(nodeNumber=node, storeInternal=True,
                                              writeToFile=False,
                                              outputVariableType=exu.OutputVariableType.Coordinates))
               for node in nodes]
    symbolic = None
    if driver == "prestep":
        def pre_step(mbs, t):
            mbs.SetObjectParameter(drive, "offset", omega * (t - dt))
            return True
        mbs.SetPreStepUserFunction(pre_step)
    else:
        from exudyn.advancedUtilities import CreateSymbolicUserFunction

        def offset(mbs, t, itemNumber, lOffset):
            return omega * (t - dt)
        symbolic = CreateSymbolicUserFunction(mbs, offset, "offsetUserFunction", drive)
        mbs.SetObjectParameter(drive, "offsetUserFunction", symbolic)
    mbs.Assemble()
    ss = exu.SimulationSettings()
    ss.solution.file.write = False
    ss.solution.sensors.writePeriod = 0.0
    ss.staticSolver.verboseMode = 0
    ss.staticSolver.useLoadFactor = False
    ss.staticSolver.numberOfLoadSteps = n
    ss.staticSolver.loadStepDuration = n * dt
    ss.staticSolver.newton.absoluteTolerance = max(tolerance * d,
                                                   16 * np.finfo(float).eps * omega)
    ss.staticSolver.newton.relativeTolerance = tolerance
    ss.linearSolver.solverType = exu.LinearSolverType.EigenDense
    exu.config.printToConsole = False
    solve_start = time.perf_counter()
    iterations = None
    if count_iterations:
        solver = exu.MainSolverStatic()
        solver.SolveSystem(mbs, ss)
        iterations = (solver.it.newtonStepsCount / n, solver.it.newtonJacobiCount / n)
    else:
        mbs.SolveStatic(ss)
    solve_seconds = time.perf_counter() - solve_start
    q = np.hstack([np.asarray(mbs.GetSensorStoredData(s))[1:, 1:4] for s in sensors])
    del symbolic
    return q, time.perf_counter() - start, solve_seconds, iterations


# ---- the benchmark sections ---------------------------------------------------------------------

def log(text):
    print(text, flush=True)


def work_precision(plan):
    """Section 1: the grid. Returns a list of Run.

    The repeats go round the whole grid (every configuration once, then again), so that a
    slow spell of the machine costs one repeat of several configurations rather than every
    repeat of one."""
    fb_model, fb_ref, fb_L, fb_w = four_bar_case()
    sc_model, sc_ref, sc_L, sc_w, sc_p = slider_crank_case()
    cases = [("four-bar", fb_model, fb_ref, fb_L, fb_w, 1.0,
              tuple(plan.steps) + ((plan.big_steps,) if plan.big_steps else ())),
             ("slider-crank", sc_model, sc_ref, sc_L, sc_w, sc_p["t_end"], tuple(plan.steps))]
    configs = []
    for case, model, reference, L, w, t_end, step_list in cases:
        for steps in step_list:
            kin, forces = reference(t_end * np.arange(steps + 1) / steps)
            for analysis in ("kinematic", "kinetostatic"):
                for tol in plan.tolerances:
                    r = measure(case, model, analysis, steps, t_end, tol, 1, kin, forces, L, w)
                    log(f"  {case:12s} {analysis:12s} {steps:6d} steps tol {tol:.0e}: "
                        + describe(r))
                    configs.append((r, model, t_end))
    for k in range(1, plan.repeats):
        for r, model, t_end in configs:
            if r.steps >= 100000 and k >= plan.big_repeats:
                continue
            with residual_check_off() if r.note else contextlib.nullcontext():
                seconds, res, _ = run_pam(model, r.analysis, r.steps, t_end, r.tolerance, 1)
            if seconds < r.seconds:
                r.seconds, r.exudyn_seconds = seconds, res.info["exudyn_seconds"]
        log(f"  repeat {k + 1} of {plan.repeats} done")
    for r, _, _ in configs:
        log(f"  {r.case:12s} {r.analysis:12s} {r.steps:6d} steps tol {r.tolerance:.0e}: "
            f"best {r.us:6.1f} µs/step (Exudyn {r.exudyn_us:5.1f})")
    return [r for r, _, _ in configs]


def hard_cases(plan):
    """Section 3. Returns a list of (Run, extra dict)."""
    out = []
    # slider-crank through both dead centres: the motor turns two full turns from 0
    motor = {"C": (0.0, 6.0, 2 * TWO_PI - 6.0 + 0.05, 0.0)}     # θ(1) = 4π + 0.05
    for label, rail in (("slider-crank in line, 2 turns through both dead centres",
                         (0.0, -0.015)),      # rail y + pin offset (0.015) = 0
                        ("offset slider-crank (offset 0.085 = 0.85 r), 2 turns",
                         (0.0, 0.07))):
        model, reference, L, w, _ = slider_crank_case(
            ground={"rail_point": rail}, motor=motor, steps=2000)
        kin, forces = reference(np.arange(2001) / 2000)
        r = measure(label, model, "kinetostatic", 2000, 1.0, DEFAULT_TOLERANCE, plan.repeats,
                    kin, forces, L, w)
        out.append((r, {}))
        log(f"  {label}: " + describe(r))
    # a long run: 100 turns at one turn per second
    steps, turns = plan.long_steps, plan.long_turns
    model, reference, L, w = four_bar_case(t_end=float(turns))
    kin, forces = reference(turns * np.arange(steps + 1) / steps)
    label = f"four-bar, {turns} turns"
    r = measure(label, model, "kinetostatic", steps, float(turns), DEFAULT_TOLERANCE,
                max(1, plan.big_repeats - 1), kin, forces, L, w, keep=True)
    res = r.res
    del r.res
    end = at_row(res, kin, steps, L, w)
    end_forces = ne.errors(_Last(res), {c: v[-1:] for c, v in forces.items()})
    end["reactions"] = (max(end_forces.values()), max(end_forces, key=end_forces.get))
    angle_error = max(abs(res[f"{s}.fi"][-1] - kin[f"{s}.fi"][-1])
                      for s in ("crank", "coupler", "rocker"))
    out.append((r, {"end": end, "angle_error": angle_error,
                    "crank_angle": float(kin["crank.fi"][-1])}))
    log(f"  {label}: " + describe(r)
        + "; at the end: " + " ".join(f"{k[:3]} {v[0]:.1e}" for k, v in end.items()))
    # the redundant parallelogram
    model, reference, L, w = parallelogram_case()
    for steps in (400, 10000):
        kin, _ = reference(np.arange(steps + 1) / steps)
        label = "redundant parallelogram (5 bars)"
        r = measure(label, model, "kinematic", steps, 1.0, DEFAULT_TOLERANCE, plan.repeats,
                    kin, None, L, w)
        out.append((r, {}))
        log(f"  {label} {steps}: " + describe(r))
    return out


class _Last:
    """The last row of a Results, for the error functions of the tests."""

    def __init__(self, res):
        self.res, self.t = res, res.t[-1:]

    def __getitem__(self, c):
        return self.res[c][-1:]


def default_is_sparse(model):
    """Whether pam2exu's default settings choose Exudyn's sparse solver for this model (read
    from pam2exu's own rule; False if that cannot be read)."""
    from types import SimpleNamespace

    from pam2exu.backend import ExudynSystem
    try:
        ss = ExudynSystem.simulation_settings(SimpleNamespace(mech=model.mechanism()),
                                              SolveSettings(), False)
        return ss.linearSolver.solverType == exu.LinearSolverType.EigenSparse
    except (AttributeError, TypeError):
        return False


def chain(plan):
    """Section 4. Returns a list of dicts, one per N: kinematic and kinetostatic runs at the
    default settings, and a kinematic run with Exudyn's sparse solver forced (the default
    run itself where pam2exu already chooses the sparse solver, above DENSE_UP_TO
    coordinates)."""
    rows = []
    steps = plan.chain_steps
    t = np.arange(steps + 1) / steps
    for N in plan.chain_sizes:
        model = chain_model(N)
        kin, forces = chain_reference(N, t)
        w = float(np.max(np.abs(kin[f"L{N}.Dfi"])))
        L = 0.4 + N * CHAIN["d"]
        row = {"N": N, "solids": len(model.solids), "nq": 3 * (len(model.solids) - 1),
               "default_sparse": default_is_sparse(model)}
        repeats = plan.repeats if N < 16 else (2 if N < 32 else 1)
        for key, analysis, dense in (("kinematic", "kinematic", None),
                                     ("kinetostatic", "kinetostatic", None),
                                     ("sparse", "kinematic", False)):
            if key == "sparse" and row["default_sparse"]:
                row[key] = row["kinematic"]
                continue
            row[key] = measure(f"chain N={N}" + (" (sparse)" if dense is False else ""),
                               model, analysis, steps, 1.0, DEFAULT_TOLERANCE, repeats, kin,
                               forces, L, w, dense=dense)
        rows.append(row)
        log(f"  chain N={N:3d}: kinematic {describe(row['kinematic'])}; sparse "
            f"{row['sparse'].us:.1f} (Exudyn {row['sparse'].exudyn_us:.1f}); kinetostatic "
            + describe(row["kinetostatic"]))
    return rows


class AgainstPlain:
    """Section 2: pam2exu against the two plain Exudyn variants, four-bar, default
    tolerance. pam2exu runs: kinematic with only the solids' x, y, fi (*positions*, with
    and without the predictor), kinematic and kinetostatic with every output, kinematic
    with every output written to CSV, and quasi-static with every output. ``round()``
    times every configuration once, in alternation; the rounds are spread over the whole
    benchmark (between its sections), so that a slow spell of the machine spoils one
    round, not the comparison. ``rows()``: the best of all rounds, with Newton iterations
    per step (plain script, pam2exu with and without predictor) and the plain script's
    error."""

    PAM = {"positions": ("kinematic", ["x", "y", "fi"], True, False),
           "positions_no_predictor": ("kinematic", ["x", "y", "fi"], False, False),
           "kinematic": ("kinematic", None, True, False),
           "kinematic_csv": ("kinematic", None, True, True),
           "quasi_static": ("quasi_static", None, True, False),
           "kinetostatic": ("kinetostatic", None, True, False)}
    KEYS = (*PAM, "prestep", "symbolic")

    def __init__(self, plan):
        self.plan = plan
        self.model, self.reference, _, _ = four_bar_case()
        self.best = {n: {k: (math.inf, None) for k in self.KEYS} for n in plan.compare_steps}
        self.rounds = 0
        self.scratch = Path(tempfile.mkdtemp(prefix="pam2exu-bench-csv-"))

    def pam(self, key, steps):
        """(wall seconds, Exudyn seconds) of one pam2exu run of configuration ``key``."""
        analysis, outputs, predictor, csv = self.PAM[key]
        start = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = pam2exu.run(self.model, analysis=analysis, steps=steps, outputs=outputs,
                              solver=SolveSettings(predictor=predictor))
        if csv:
            res.to_csv(self.scratch / "four_bar.csv")
        return time.perf_counter() - start, res.info["exudyn_seconds"]

    def round(self):
        self.rounds += 1
        for steps, best in self.best.items():
            if steps >= 100000 and self.rounds > self.plan.big_repeats:
                continue
            for key in self.PAM:
                seconds, exudyn_seconds = self.pam(key, steps)
                if seconds < best[key][0]:
                    best[key] = (seconds, exudyn_seconds)
            for driver in ("prestep", "symbolic"):
                _, total, solve, _ = plain_exudyn_four_bar(steps, DEFAULT_TOLERANCE, driver)
                if total < best[driver][0]:
                    best[driver] = (total, solve)

    def pam_iterations(self, steps, predictor):
        """Newton iterations per step of pam2exu's position solve (Exudyn's counter)."""
        from pam2exu.analyses.common import prepare
        from pam2exu.backend import ExudynSystem
        job = prepare(self.model, analysis="kinematic", steps=steps)
        system = ExudynSystem(job.mech)
        system.solve_positions(job.times, SolveSettings(predictor=predictor))
        return system.newton_iterations / len(job.times)

    def rows(self):
        rows = []
        for steps, best in self.best.items():
            _, _, _, (iterations, jacobians) = plain_exudyn_four_bar(
                steps, DEFAULT_TOLERANCE, "symbolic", count_iterations=True)
            # the plain solve against the closed form
            kin, _ = self.reference(np.arange(steps + 1) / steps)
            q, *_ = plain_exudyn_four_bar(steps, DEFAULT_TOLERANCE, "symbolic")
            plain_err = max(float(np.max(np.abs(q[:, 3 * i + 2] - kin[f"{s}.fi"])))
                            for i, s in enumerate(("crank", "coupler", "rocker")))
            rows.append({"steps": steps, "iterations": iterations, "jacobians": jacobians,
                         "pam_iterations": self.pam_iterations(steps, True),
                         "pam_iterations_no_predictor": self.pam_iterations(steps, False),
                         "plain_angle_error": plain_err, **best})
            us = {k: 1e6 * v[0] / steps for k, v in best.items()}
            log(f"  {steps:6d} steps: pam2exu positions {us['positions']:.1f} µs/step "
                f"(no predictor {us['positions_no_predictor']:.1f}), kinematic "
                f"{us['kinematic']:.1f} (Exudyn {1e6 * best['kinematic'][1] / steps:.1f}; "
                f"with CSV {us['kinematic_csv']:.1f}), quasi-static {us['quasi_static']:.1f}, "
                f"kinetostatic {us['kinetostatic']:.1f}; plain pre-step {us['prestep']:.1f} "
                f"(solve {1e6 * best['prestep'][1] / steps:.1f}), symbolic "
                f"{us['symbolic']:.1f} (solve {1e6 * best['symbolic'][1] / steps:.1f}); Newton "
                f"{iterations:.2f} it/step plain, {rows[-1]['pam_iterations']:.2f} pam2exu")
        return rows


def newton_grid(plan):
    """Newton iterations per step and solve time of the plain (symbolic) Exudyn four-bar over
    the grid of step counts and tolerances (repeats round the grid, as in
    ``work_precision``); and a least-squares split of the solve time into a cost per step
    and a cost per Newton iteration."""
    rows = []
    step_list = tuple(plan.steps) + ((plan.big_steps,) if plan.big_steps else ())
    for steps in step_list:
        for tol in plan.tolerances:
            _, _, solve, (it, _) = plain_exudyn_four_bar(steps, tol, "symbolic",
                                                         count_iterations=True)
            rows.append({"steps": steps, "tolerance": tol, "iterations": it,
                         "solve_us": 1e6 * solve / (steps + 1)})
    for k in range(plan.repeats):
        for r in rows:
            if r["steps"] >= 100000 and k >= plan.big_repeats:
                continue
            solve = plain_exudyn_four_bar(r["steps"], r["tolerance"], "symbolic")[2]
            r["solve_us"] = min(r["solve_us"], 1e6 * solve / (r["steps"] + 1))
    X = np.array([[1.0, r["iterations"]] for r in rows])
    y = np.array([r["solve_us"] for r in rows])
    per_step, per_iteration = np.linalg.lstsq(X, y, rcond=None)[0]
    return rows, float(per_step), float(per_iteration)


def profile(model, analysis, steps, top=10):
    """Where the time of one run goes (cProfile, which slows Python code somewhat): the
    functions with the most time of their own (not counting the functions they call, so
    the rows add up). Returns (total seconds, [(function, calls, own seconds)])."""
    import cProfile
    import pstats
    pr = cProfile.Profile()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        start = time.perf_counter()
        pr.enable()
        pam2exu.run(model, analysis=analysis, t_end=1.0, steps=steps)
        pr.disable()
        total = time.perf_counter() - start
    def label(filename, name):
        path = Path(filename)
        if "exudynCPP.SolveSystem" in name:
            return "Exudyn's static solve (C++)"
        if path.is_relative_to(ROOT / "pam2exu"):
            return f"`{'.'.join(path.relative_to(ROOT / 'pam2exu').with_suffix('').parts)}.{name}`"
        if "numpy" in path.parts:
            module = ".".join(p for p in path.with_suffix("").parts[path.parts.index("numpy"):]
                              if not p.startswith("_"))
            return f"`{module}.{name}`"
        if filename == "~":
            return f"`{name.strip('<>')}`"
        return f"`{path.name}:{name}`"

    rows = []
    for (filename, _, name), (_, calls, own, _, callers) in pstats.Stats(pr).stats.items():
        text = label(filename, name)
        if "numpy" in Path(filename).parts and "linalg" in filename and callers:
            by = sorted(callers.items(), key=lambda kv: -kv[1][2])[:2]
            text += " from " + ", ".join(label(f, n).replace("`pam2exu.", "`")
                                         for (f, _, n), _ in by)
        rows.append((text, calls, own))
    rows.sort(key=lambda r: -r[2])
    shown = rows[:top]
    shown.append(("everything else", sum(r[1] for r in rows[top:]),
                  sum(r[2] for r in rows[top:])))
    return total, shown


# ---- the report ------------------------------------------------------------------------------

def machine():
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    ram = ""
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemTotal"):
                ram = f"{int(line.split()[1]) / 2**20:.0f} GiB"
    except OSError:
        pass
    os_name = platform.platform()
    try:
        for line in Path("/etc/os-release").read_text().splitlines():
            if line.startswith("PRETTY_NAME="):
                os_name = line.split("=", 1)[1].strip('"') + f" (Linux {platform.release()})"
    except OSError:
        pass
    version = pam2exu.__version__
    try:
        import subprocess
        head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, text=True,
                              capture_output=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--", "pam2exu"], cwd=ROOT,
                               text=True, capture_output=True, check=True).stdout.strip()
        version += f", commit {head}" + (" with uncommitted changes in pam2exu/" if dirty
                                         else "")
    except (OSError, subprocess.CalledProcessError):
        pass
    return {"CPU": cpu, "cores": str(os.cpu_count()), "RAM": ram, "OS": os_name,
            "Python": platform.python_version(), "NumPy": np.__version__,
            "Exudyn": exu.__version__, "pam2exu": version}


def fmt_err(e):
    return "–" if e is None else f"{e:.1e}"


def err_cells(errors):
    return [fmt_err(errors[k][0]) if k in errors else "–" for k in KINDS]


def table(header, rows):
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def worst_at_default(runs):
    """{kind: (error, where)} over every run at the default tolerance."""
    out = {}
    for r in runs:
        if r.tolerance != DEFAULT_TOLERANCE or r.note:
            continue
        for kind, (e, col) in r.errors.items():
            if kind not in out or e > out[kind][0]:
                out[kind] = (e, f"{r.case}, {r.analysis}, {r.steps:,} steps, {col}")
    return out


def verdict(value, target, lower_is_better=True):
    ok = value <= target if lower_is_better else value >= target
    if ok:
        return "met"
    return f"missed by {value / target:.2f}×" if target > 0 else "missed"


def chain_fits(chain_rows):
    """Fitted exponents of each part of the chain's time per step, over all N and over N ≥ 8."""
    N = np.array([r["N"] for r in chain_rows], dtype=float)
    parts = {
        "kinematic total": [r["kinematic"].us for r in chain_rows],
        "kinetostatic total": [r["kinetostatic"].us for r in chain_rows],
        "Exudyn": [r["kinematic"].exudyn_us for r in chain_rows],
        "native, kinematic": [r["kinematic"].us - r["kinematic"].exudyn_us for r in chain_rows],
        "native, kinetostatic": [r["kinetostatic"].us - r["kinetostatic"].exudyn_us
                                 for r in chain_rows],
        "kinematic total (sparse)": [r["sparse"].us for r in chain_rows],
        "Exudyn (sparse)": [r["sparse"].exudyn_us for r in chain_rows],
        "native, kinematic (sparse)": [r["sparse"].us - r["sparse"].exudyn_us
                                       for r in chain_rows],
    }
    out = {"all": {k: f"{fit_exponent(N, v):.2f}" for k, v in parts.items()}, "tail": {}}
    tail = N >= 8
    if tail.sum() >= 2:
        out["tail"] = {k: f"{fit_exponent(N[tail], np.array(v)[tail]):.2f}"
                       for k, v in parts.items()}
    return out


def write_report(out_dir, info, plan, quick, grid, hard, chain_rows, plain_rows, newton,
                 profiles, sections, elapsed):
    lines = []
    add = lines.append
    add("# Performance: speed against error")
    add("")
    add("Generated by `benchmarks/speed_vs_error.py`"
        + (" (**--quick smoke run: small grids, numbers not representative**)" if quick else "")
        + f" in one run of {elapsed / 60:.1f} minutes. Every number on this page comes from "
          f"that run. Timings are the best of {plan.repeats} repeats ({plan.big_repeats} for "
          f"runs of 100,000 steps; section 2: {plan.compare_repeats}; chain: "
          f"{plan.repeats} up to N = 8, 2 for N = 16, 1 above), errors the largest relative "
          "error against closed-form or hand-written Newton–Euler references (never against "
          "pam2exu itself).")
    add("")
    add("## Machine")
    add("")
    add(table(["", ""], [[k, v] for k, v in info.items()]))
    add("")
    add("The machine is a shared virtual machine: single timings vary by 10–30 %, and for a "
        "few seconds at a time by up to 2×. Hence the best of several repeats, taken round "
        "the grid rather than one configuration after another, and pam2exu and the plain "
        "Exudyn script timed in alternation, in rounds spread over the run.")
    add("")
    add("## How to reproduce")
    add("")
    add("```bash")
    add("pip install \".[test]\"                         # pytest: the references live in tests/")
    add("python benchmarks/speed_vs_error.py           # rewrites docs/performance.md and "
        "docs/img/work_precision.png")
    add("python benchmarks/speed_vs_error.py --quick   # smoke test, under a minute, "
        "written to a temporary directory")
    add("```")
    add("")
    add("Time per step is the wall time of `pam2exu.run(model, analysis=..., steps=..., "
        "solver=SolveSettings(tolerance=...))` (a loaded `Model`, so without parsing the "
        "TOML) divided by the number of steps: building the Exudyn system, Exudyn's static "
        "solve, the native pass (velocities, accelerations, forces), the checks after the run "
        "and the result table. *Exudyn* is `res.info['exudyn_seconds']` (building, solving "
        "and reading the Exudyn system); *native* is the rest.")
    add("")

    # targets
    cmp10 = next((r for r in plain_rows if r["steps"] == 10000), plain_rows[-1])
    s = cmp10["steps"]
    kin_us = 1e6 * cmp10["kinematic"][0] / s
    kin_exu = 1e6 * cmp10["kinematic"][1] / s
    dyn_us = 1e6 * cmp10["kinetostatic"][0] / s
    dyn_exu = 1e6 * cmp10["kinetostatic"][1] / s
    pre_us, pre_solve = (1e6 * v / s for v in cmp10["prestep"])
    sym_us, sym_solve = (1e6 * v / s for v in cmp10["symbolic"])
    ratio_sym, ratio_pre = kin_us / sym_us, kin_us / pre_us
    Ns = np.array([r["N"] for r in chain_rows], dtype=float)
    fits = chain_fits(chain_rows)
    all_runs = grid + [r for r, _ in hard] + [row[a] for row in chain_rows
                                              for a in ("kinematic", "kinetostatic")]
    worst = worst_at_default(all_runs)
    add("## Targets")
    add("")
    add(f"Four-bar (`examples/four_bar.toml`), {s:,} steps, default tolerance "
        f"({DEFAULT_TOLERANCE:g}); accuracy over every run at the default settings on this "
        "page (grid, hard cases, chain).")
    add("")
    trows = [
        ["kinematic four-bar, time per step", "≤ 20 µs",
         f"{kin_us:.1f} µs (Exudyn {kin_exu:.1f}, native {kin_us - kin_exu:.1f})",
         verdict(kin_us, 20.0)],
        ["kinematic four-bar / plain Exudyn (symbolic driver)", "≤ 1.3×",
         f"{ratio_sym:.2f}× ({kin_us:.1f} / {sym_us:.1f} µs)", verdict(ratio_sym, 1.3)],
        ["kinematic four-bar / plain Exudyn (Python pre-step driver)", "≤ 1.3×",
         f"{ratio_pre:.2f}× ({kin_us:.1f} / {pre_us:.1f} µs)", verdict(ratio_pre, 1.3)],
        ["kinetostatic four-bar, time per step", "≤ 30 µs",
         f"{dyn_us:.1f} µs (Exudyn {dyn_exu:.1f}, native {dyn_us - dyn_exu:.1f})",
         verdict(dyn_us, 30.0)],
    ]
    for label, part in (("kinematic", "kinematic total"), ("kinetostatic", "kinetostatic total"),
                        ("kinematic, Exudyn's sparse solver forced", "kinematic total (sparse)")):
        p = float(fits["all"][part])
        trows.append([f"chain of N loops, {label}: exponent p of time/step ∝ N^p",
                      "≈ 1 (≤ 1.15)", f"{p:.2f} (N = {int(Ns[0])} … {int(Ns[-1])})"
                      + (f"; {fits['tail'][part]} for N ≥ 8" if fits["tail"] else ""),
                      verdict(p, 1.15)])
    for kind, target in (("positions", 1e-10), ("velocities", 1e-10),
                         ("accelerations", 1e-8), ("reactions", 1e-8)):
        e, where = worst.get(kind, (float("nan"), "–"))
        trows.append([f"{kind}, worst relative error at default settings", f"≤ {target:.0e}",
                      f"{e:.1e} ({where})", verdict(e, target)])
    pos_us = 1e6 * cmp10["positions"][0] / s
    csv_us = 1e6 * cmp10["kinematic_csv"][0] / s
    qs_us = 1e6 * cmp10["quasi_static"][0] / s
    for label, value, goal in (
            ("kinematic four-bar, positions only (x, y, fi) / plain Exudyn (symbolic driver)",
             pos_us, 1.0),
            ("kinematic four-bar, every output / plain Exudyn (symbolic driver)", kin_us, 1.5),
            ("kinematic four-bar, every output written to CSV / plain Exudyn (symbolic "
             "driver)", csv_us, 1.7)):
        ratio = value / sym_us
        trows.append([label, f"≤ {goal:.1f}×", f"{ratio:.2f}× ({value:.1f} / {sym_us:.1f} µs)",
                      verdict(ratio, goal)])
    trows.append(["quasi-static four-bar (every output) / kinematic (every output)", "≤ 1.2×",
                  f"{qs_us / kin_us:.2f}× ({qs_us:.1f} / {kin_us:.1f} µs)",
                  verdict(qs_us / kin_us, 1.2)])
    add(table(["target", "goal", "measured", "verdict"], trows))
    add("")

    # why
    it10 = cmp10["iterations"]
    ns_rows, per_step, per_it = newton
    add("### What the measurements say about the time targets")
    add("")
    add(f"- **Exudyn's static solve is most of the time.** The plain, hand-written Exudyn "
        f"script alone needs {sym_solve:.1f} µs/step for its solve ({sym_us:.1f} µs/step "
        f"with building and reading the sensors) with the symbolic driver, and "
        f"{pre_solve:.1f} µs/step ({pre_us:.1f}) with the Python pre-step driver. Newton takes "
        f"{it10:.2f} iterations per step at {s:,} steps and tolerance {DEFAULT_TOLERANCE:g} "
        "(counted with `exu.MainSolverStatic().SolveSystem(mbs, ss)`, "
        f"`solver.it.newtonStepsCount`), and each iteration assembles and factorises the full "
        f"Jacobian: {cmp10['jacobians']:.2f} Jacobians per step "
        "(`solver.it.newtonJacobiCount`; full Newton, `useModifiedNewton = False`).")
    add(f"- A least-squares fit over the grid below splits the plain solve into "
        f"{per_step:.1f} µs per step plus {per_it:.1f} µs per Newton iteration. Exudyn's "
        "static solver starts each load step from the previous step's solution (its "
        "settings offer no predictor), so in the plain script one iteration suffices only "
        "when the motion per step is small enough for a single Newton update to reach the "
        "tolerance"
        + (": in this grid " + ", ".join(f"{r['steps']:,} steps at {r['tolerance']:.0e}"
                                         for r in ns_rows if r["iterations"] < 1.05)
           if any(r["iterations"] < 1.05 for r in ns_rows) else "")
        + ".")
    pos_off_us = 1e6 * cmp10["positions_no_predictor"][0] / s
    add(f"- **The predictor.** pam2exu sets Exudyn's coordinates before each load step to "
        "the parabola through the last three steps (`SolveSettings.predictor`, a Python "
        "pre-step function): Newton then takes "
        + ", ".join(f"{r['pam_iterations']:.2f} iterations per step at {r['steps']:,} steps "
                    f"(without it {r['pam_iterations_no_predictor']:.2f})" for r in plain_rows)
        + f". At {s:,} steps the positions-only run takes {pos_us:.1f} µs/step with it and "
        f"{pos_off_us:.1f} without: it pays "
        + ("wherever the plain solve needs more than one iteration per step (the pre-step "
           "call costs less than an iteration)" if pos_us < pos_off_us else
           "nothing here")
        + "; it is off for redundant mechanisms (docs/analyses.md).")
    add(f"- pam2exu's own Exudyn part ({kin_exu:.1f} µs/step) is within "
        f"{kin_exu / sym_us:.2f}× of the whole plain script; the rest is pam2exu's native "
        f"pass ({kin_us - kin_exu:.1f} µs/step kinematic, {dyn_us - dyn_exu:.1f} µs/step "
        "kinetostatic: equations, Jacobian, two linear solves per step for velocities and "
        "accelerations, one more for the multipliers, the checks, the table). "
        + (f"A 20 µs/step total leaves {20 - sym_us:.1f} µs/step for everything beyond the "
           f"plain Exudyn script, against {kin_us - kin_exu:.1f} µs/step of native pass now"
           if sym_us < 20 else
           f"The plain Exudyn script alone ({sym_us:.1f} µs/step) is already above 20 µs/step, "
           "so that target cannot be met with this solve")
        + f"; 1.3× the plain symbolic script is {1.3 * sym_us:.1f} µs/step, which would leave "
        f"{0.3 * sym_us:.1f} µs/step for the native pass if pam2exu's Exudyn part equalled "
        "the plain script.")
    add("")

    # section 1
    add("## 1. Work against precision: four-bar and slider-crank")
    add("")
    add("The **four-bar** is `examples/four_bar.toml` (crank 0.1, coupler 0.35, rocker 0.3, "
        "ground 0.4; masses at offset centres, gravity; θ = 2π t over 1 s). Kinematic "
        "reference: `four_bar` of `tests/analyses/test_kinematic_closed_form.py`; reactions: "
        "`revolute_newton_euler` of the benchmark (Newton–Euler per body, checked by the power "
        "balance to 1e-9). The **slider-crank** is the offset slider-crank of "
        "`tests/analyses/test_newton_euler.py` (`slider_crank_params`: pin off the slider's "
        "line, centres of mass off the axes, gravity, a torsor on the rod, θ = 0.3 + 6t + 2t² "
        "over 1 s), with its references `kinematics` and `newton_euler`.")
    add("")
    add("Errors: per column max |pam2exu − reference| over the largest |reference| of that "
        "column (`errors` of the tests; a column that is identically 0 uses the natural "
        "scale), then the worst column of each kind. Reactions: every joint force, the "
        "fixed link's wrench and the motor torque. *it./step*: Newton iterations per step of "
        "the plain Exudyn four-bar at the same steps and tolerance.")
    add("")
    its = {(r["steps"], r["tolerance"]): r["iterations"] for r in ns_rows}
    rows = []
    for r in grid:
        it = its.get((r.steps, r.tolerance)) if r.case == "four-bar" else None
        rows.append([r.case, r.analysis, f"{r.steps:,}", f"{r.tolerance:.0e}" + r.note,
                     f"{r.us:.1f}", f"{r.exudyn_us:.1f}", f"{r.us - r.exudyn_us:.1f}",
                     "–" if it is None else f"{it:.2f}", *err_cells(r.errors)])
    add(table(["mechanism", "analysis", "steps", "tolerance", "µs/step", "Exudyn",
               "native", "it./step", *KINDS], rows))
    add("")
    if any(r.note for r in grid):
        add("† pam2exu stops this run with a `TranslationError`: its check after the run "
            "finds Exudyn's constraint residual above 1e-8 of the length scale (the check "
            "that guards against a wrong translation). The run was repeated with that check "
            "switched off (`pam2exu.analyses.common.RESIDUAL_TOLERANCE = inf`, in the "
            "benchmark only) to measure its speed and error. So a tolerance looser than about "
            "1e-8 is not usable as pam2exu stands.")
        add("")
    add("The time grid t_k = k·dt plays no part in the error: positions are solved at each "
        "time to the tolerance, and velocities and accelerations come from exact linear "
        "solves at that position (no differencing). The error is set by the tolerance alone; "
        "the number of steps sets the cost per step, through the Newton iterations that "
        "each step needs from the previous step's solution.")
    add("")
    add("![Work against precision, and time per step against the size of the chain]"
        "(img/work_precision.png)")
    add("")

    # plain Exudyn
    add("## 2. pam2exu against a plain Exudyn script")
    add("")
    add("`plain_exudyn_four_bar` in the benchmark writes the four-bar's position solve "
        "directly in Exudyn: a `NodeRigidBody2D` and an `ObjectRigidBody2D` per moving link, "
        "`ObjectGround`, four `ObjectJointRevolute2D`, the crank's angle driven by an "
        "`ObjectConnectorCoordinate`; the static solver with one load step per time step "
        "(steps + 1 load steps, as pam2exu), the same Newton tolerances and dense solver, "
        "sensors storing the node coordinates. The driver is either a Python "
        "`PreStepUserFunction` setting the offset, or an `exudyn.symbolic` "
        "`offsetUserFunction` (compiled, no Python call per step; pam2exu uses this). "
        "*Total* is building, solving and reading the sensors; *solve* is `SolveStatic` "
        "alone. pam2exu and the plain variants are timed in alternation, default tolerance, in "
        f"{plan.compare_repeats} rounds spread over the whole benchmark run "
        f"({plan.big_repeats} for 100,000 steps); best of the rounds.")
    add("")
    rows = []
    for r in plain_rows:
        st = r["steps"]

        def us(v, st=st):
            return f"{1e6 * v / st:.1f}"
        rows.append([f"{st:,}", us(r["positions"][0]), us(r["positions_no_predictor"][0]),
                     us(r["kinematic"][0]), us(r["kinematic"][1]), us(r["kinematic_csv"][0]),
                     us(r["quasi_static"][0]), us(r["kinetostatic"][0]),
                     f"{us(r['prestep'][0])} / {us(r['prestep'][1])}",
                     f"{us(r['symbolic'][0])} / {us(r['symbolic'][1])}",
                     f"{r['positions'][0] / r['symbolic'][0]:.2f}×",
                     f"{r['kinematic'][0] / r['symbolic'][0]:.2f}×",
                     f"{r['kinematic_csv'][0] / r['symbolic'][0]:.2f}×",
                     f"{r['pam_iterations']:.2f} / {r['pam_iterations_no_predictor']:.2f} / "
                     f"{r['iterations']:.2f}", f"{r['plain_angle_error']:.0e}"])
    add(table(["steps", "pam2exu positions µs/step", "positions, no predictor",
               "kinematic, every output", "of which Exudyn", "kinematic + CSV",
               "quasi-static", "kinetostatic", "plain, pre-step: total / solve",
               "plain, symbolic: total / solve", "positions / plain symbolic",
               "kinematic / plain symbolic", "kinematic + CSV / plain symbolic",
               "Newton it./step: pam2exu / no predictor / plain",
               "plain: max angle error, rad"], rows))
    add("")
    add("*Positions*: kinematic with `outputs=[\"x\", \"y\", \"fi\"]` (no rates are computed); "
        "*kinematic + CSV*: every output, then `Results.to_csv`; *quasi-static* and "
        "*kinetostatic*: every output.")
    add("")
    largest = plain_rows[-1]
    pam_err = next((r.errors["positions"][0] for r in grid
                    if r.case == "four-bar" and r.analysis == "kinematic"
                    and r.steps == largest["steps"] and r.tolerance == DEFAULT_TOLERANCE), None)
    if pam_err is not None:
        add(f"*Plain: max angle error* is against the closed form, in radians. It grows with "
            f"the number of steps ({largest['plain_angle_error']:.0e} rad at "
            f"{largest['steps']:,} steps): the plain script evaluates its driver at Exudyn's "
            "load-step time t − dt, and that time accumulates round-off step by step. pam2exu "
            "rounds the load-step time to its grid (`grid_time` in "
            "`pam2exu/backend/symbolic.py`), and its largest relative position error at "
            f"{largest['steps']:,} steps is {pam_err:.0e} (section 1).")
        add("")
    add("Newton iterations and solve time of the plain (symbolic) script over the grid, with "
        f"the fit solve ≈ {per_step:.1f} µs + {per_it:.1f} µs × iterations (per step):")
    add("")
    add(table(["steps", "tolerance", "Newton it./step", "solve µs/step", "fit µs/step"],
              [[f"{r['steps']:,}", f"{r['tolerance']:.0e}", f"{r['iterations']:.2f}",
                f"{r['solve_us']:.1f}", f"{per_step + per_it * r['iterations']:.1f}"]
               for r in ns_rows]))
    add("")

    # hard cases
    add("## 3. Hard cases")
    add("")
    add("Default tolerance. Errors as in section 1 (largest over the whole run).")
    add("")
    rows = []
    notes = []
    for r, extra in hard:
        rows.append([r.case, r.analysis, f"{r.steps:,}", f"{r.us:.1f}", *err_cells(r.errors),
                     warning_summary([r]) or "–"])
        if "end" in extra:
            rows.append(["… the same, error at the last step only", "", "", "",
                         *err_cells(extra["end"]), ""])
            notes.append(f"- Long run: after {extra['crank_angle'] / TWO_PI:.0f} turns the "
                         f"crank angle is {extra['crank_angle']:.3f} rad (never wrapped); "
                         f"the largest absolute angle error at the end is "
                         f"{extra['angle_error']:.1e} rad, "
                         f"{extra['angle_error'] / np.spacing(extra['crank_angle']):.2g} ulp "
                         "of the crank angle.")
    add(table(["case", "analysis", "steps", "µs/step", *KINDS, "pam2exu's warnings"], rows))
    add("")
    add("- Slider-crank (the Newton–Euler slider-crank of the tests, rail moved): in line "
        "(pin on the crank's centre line) and offset by 0.085 m = 0.85 crank radii; the crank "
        "turns through 0 … 4π + 0.05, so both dead centres are passed twice. The crank drives, "
        "so the dead centres are not singular: the slider stops and turns back.")
    for note in dict.fromkeys(notes):
        add(note)
    add("- Parallelogram: `tests/data/parallelogram5.toml`, three parallel cranks "
        "θ = π/2 + 1.2 cos 2πt; reference: every crank at θ, the coupler translating with "
        "its origin at 0.3 e(θ). Reactions are not unique (minimum-norm, documented) and "
        "are not compared. Its cost per step is several times the four-bar's: redundant "
        "constraints make pam2exu use Exudyn's dense solver with `ignoreSingularJacobian`, "
        "and SVDs instead of LU factorisations in the native pass.")
    add("")

    # chain
    add("## 4. Size: a chain of N four-bar loops")
    add("")
    a, b, c, d = (CHAIN[k] for k in "abcd")
    add(f"Links L0 … LN pivot on the ground at (i·{d}, 0); loop j joins L(j−1) and Lj by a "
        f"coupler Kj. Each loop is a drag link (input {a}, coupler {b}, output {c}, ground "
        f"{d}: Grashof with the ground the shortest, so both links turn fully); a shared link "
        f"carries its next loop's input point opposite its output point, which keeps the "
        f"speed ratio along the chain between about 0.6 and 1.6. One motor turns L0 "
        f"(θ = {CHAIN_LAW[0]} + 2πt, one turn), {plan.chain_steps:,} steps, default "
        "tolerance; masses on every link, gravity. Initial guesses: the exact pose at t = 0, "
        "loop by loop. References: the chained `four_bar` closed form, and "
        "`revolute_newton_euler` for the reactions (all 6N + 6 of them).")
    add("")
    rows = []
    for row in chain_rows:
        k_, d_, s_ = row["kinematic"], row["kinetostatic"], row["sparse"]
        rows.append([row["N"], row["nq"], f"{k_.us:.0f}", f"{k_.exudyn_us:.0f}",
                     f"{k_.us - k_.exudyn_us:.0f}", f"{d_.us:.0f}",
                     f"{d_.us - d_.exudyn_us:.0f}", f"{s_.us:.0f}", f"{s_.exudyn_us:.0f}",
                     *err_cells(d_.errors), warning_summary([k_, d_]) or "–"])
    add(table(["N", "moving coordinates", "kinematic µs/step", "Exudyn", "native",
               "kinetostatic µs/step", "native", "kinematic, sparse: µs/step", "Exudyn",
               *KINDS, "pam2exu's warnings"], rows))
    add("")
    add("*kinematic, sparse*: the same kinematic run with "
        "`SolveSettings(dense=False)` (Exudyn's sparse solver at every size). Errors: the "
        "kinetostatic run (the kinematic runs give the same positions, velocities and "
        "accelerations).")
    add("")
    add(f"Fitted exponents p (time per step ∝ N^p, least squares in log-log over N = "
        f"{int(Ns[0])} … {int(Ns[-1])}"
        + ("; over N ≥ 8 in brackets" if fits["tail"] else "") + "):")
    add("")

    def exponent(part):
        if part not in fits["all"]:
            return "–"
        return fits["all"][part] + (f" ({fits['tail'][part]})" if fits["tail"] else "")
    add(table(["part", "default settings", "Exudyn's sparse solver forced"],
              [[part, exponent(part), exponent(f"{part} (sparse)")]
               for part in ("kinematic total", "kinetostatic total", "Exudyn",
                            "native, kinematic", "native, kinetostatic")]))
    add("")
    crossover = next((r for r in chain_rows
                      if r["sparse"].exudyn_us < r["kinematic"].exudyn_us), None)
    dense_rows = [r for r in chain_rows if not r["default_sparse"]]
    last = chain_rows[-1]
    chain_profile = next((rows for title, (_, rows) in profiles.items()
                          if title.startswith("chain")), [])
    chain_total = next((total for title, (total, _) in profiles.items()
                        if title.startswith("chain")), 1.0)
    native_top = [f"{name} {100 * sec / chain_total:.0f} %" for name, _, sec in chain_profile
                  if "Exudyn" not in name and name != "everything else"][:3]
    add("What the measurements show:")
    add("")
    if dense_rows:
        worst = dense_rows[-1]
        add(f"- **Exudyn's dense solver makes Exudyn's part superlinear.** pam2exu chooses it "
            f"here for N ≤ {worst['N']} ({worst['nq']} moving coordinates; its rule is up to "
            f"{DENSE_UP_TO} coordinates). Exudyn factorises the whole system of coordinates and "
            "constraint equations (about twice the coordinates) at every Newton iteration, "
            f"O(n³): at N = {worst['N']} its part is {worst['kinematic'].exudyn_us:.0f} µs/step "
            f"dense against {worst['sparse'].exudyn_us:.0f} µs/step sparse. The sparse solver "
            "is "
            + (f"faster from N = {crossover['N']} on ({crossover['nq']} moving coordinates)"
               if crossover else "not faster at any size measured")
            + "; with it, Exudyn's part grows with exponent "
            f"{fits['all']['Exudyn (sparse)']}.")
    native_p = max(float(fits['all']['native, kinematic']),
                   float(fits['all']['native, kinetostatic']))
    if native_p <= 1.15:
        add(f"- **The native pass grows linearly.** Its exponent is "
            f"{fits['all']['native, kinematic']} (kinematic) and "
            f"{fits['all']['native, kinetostatic']} (kinetostatic); at N = {last['N']} it "
            f"costs {last['kinematic'].us - last['kinematic'].exudyn_us:.0f} µs/step "
            f"kinematic and {last['kinetostatic'].us - last['kinetostatic'].exudyn_us:.0f} "
            f"kinetostatic, against {last['kinematic'].exudyn_us:.0f} for Exudyn. From "
            f"{SPARSE_FROM} constraint equations on, pam2exu solves each chunk of steps as one "
            "sparse, block-diagonal system (one LU for Cq q̇ = −C_t and Cq q̈ = γ, one for "
            "Cqᵀ λ = Q), whose cost is linear in the chain's length, and samples the "
            "condition number at fewer steps the larger the mechanism.")
    else:
        add(f"- **The native pass is superlinear.** Its exponent is "
            f"{fits['all']['native, kinematic']} (kinematic) and "
            f"{fits['all']['native, kinetostatic']} (kinetostatic); at N = {last['N']} it "
            f"costs {last['kinematic'].us - last['kinematic'].exudyn_us:.0f} µs/step "
            f"kinematic and {last['kinetostatic'].us - last['kinetostatic'].exudyn_us:.0f} "
            f"kinetostatic, against {last['kinematic'].exudyn_us:.0f} for Exudyn."
            + (f" The largest native items of the N = {last['N']} profile (section 5): "
               + ", ".join(native_top) + "." if native_top else ""))
    add("")
    add("## 5. Where the time goes")
    add("")
    add("One run each under `cProfile` (which slows the Python parts somewhat): the "
        "functions with the most time of their own (without the functions they call, so the "
        "rows add up to the run).")
    add("")
    for title, (total, rows) in profiles.items():
        add(f"**{title}**: {total:.2f} s in all.")
        add("")
        add(table(["function", "calls", "own seconds", "share of the run"],
                  [[name, calls, f"{sec:.3f}", f"{100 * sec / total:.0f} %"]
                   for name, calls, sec in rows]))
        add("")
    add("Run time of each section of this benchmark: "
        + ", ".join(f"{k.split('. ', 1)[1]} {v:.0f} s" for k, v in sections.items()
                    if "(rounds" not in k)
        + f", the {plan.compare_repeats} rounds of section 2 "
          f"{sum(v for k, v in sections.items() if '(rounds' in k):.0f} s"
        + f"; {elapsed / 60:.1f} minutes in all.")
    add("")
    (out_dir / "performance.md").write_text("\n".join(lines) + "\n", encoding="utf-8")


def plot(path, grid, chain_rows):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FormatStrFormatter

    fig, axes = plt.subplots(1, 3, figsize=(16, 5))
    markers = {t: m for t, m in zip(sorted({r.tolerance for r in grid}), "o^sD")}
    colours = {}
    for ax, kinds, title in ((axes[0], ("positions", "velocities"), "positions and velocities"),
                             (axes[1], ("accelerations", "reactions"),
                              "accelerations and reactions")):
        for r in grid:
            e = max((r.errors[k][0] for k in kinds if k in r.errors), default=None)
            if e is None:
                continue
            key = (r.case, r.analysis)
            if key not in colours:
                colours[key] = f"C{len(colours)}"
            ax.loglog(r.us, max(e, 1e-17), markers[r.tolerance], color=colours[key],
                      markerfacecolor="none" if r.note else colours[key], markersize=7)
            ax.annotate(f"{r.steps // 1000}k", (r.us, max(e, 1e-17)), fontsize=6,
                        xytext=(3, 3), textcoords="offset points")
        ax.xaxis.set_major_formatter(FormatStrFormatter("%g"))
        ax.xaxis.set_minor_formatter(FormatStrFormatter("%g"))
        ax.tick_params(axis="x", which="minor", labelsize=7)
        ax.set_xlabel("wall time per step [µs]  (label: steps)")
        ax.set_ylabel("max relative error")
        ax.set_title(f"work against precision: {title}")
        ax.grid(True, which="both", alpha=0.3)
    handles = [plt.Line2D([], [], color=c, marker="o", ls="", label=f"{k[0]}, {k[1]}")
               for k, c in colours.items()]
    handles += [plt.Line2D([], [], color="k", marker=m, ls="", markerfacecolor="none",
                           label=f"tolerance {t:.0e}") for t, m in markers.items()]
    handles.append(plt.Line2D([], [], color="k", marker="o", ls="", markerfacecolor="none",
                              label="hollow: residual check off (†)"))
    axes[0].legend(handles=handles, fontsize=7, loc="best")
    ax = axes[2]
    N = np.array([r["N"] for r in chain_rows], dtype=float)
    series = (("kinematic total", [r["kinematic"].us for r in chain_rows], "o-", "C0"),
              ("kinetostatic total", [r["kinetostatic"].us for r in chain_rows], "o-", "C1"),
              ("kinematic total, sparse Exudyn", [r["sparse"].us for r in chain_rows], "o-",
               "C2"),
              (f"Exudyn part (default: dense ≤ {DENSE_UP_TO} coord.)",
               [r["kinematic"].exudyn_us for r in chain_rows], "s--", "C3"),
              ("Exudyn part, sparse", [r["sparse"].exudyn_us for r in chain_rows], "s--", "C4"),
              ("native part, kinematic",
               [r["kinematic"].us - r["kinematic"].exudyn_us for r in chain_rows], "^:", "C5"))
    for label, y, style, c in series:
        y = np.maximum(np.array(y), 1e-3)
        ax.loglog(N, y, style, color=c, label=f"{label} (N^{fit_exponent(N, y):.2f})")
    y0 = chain_rows[0]["sparse"].exudyn_us
    ax.loglog(N, y0 * N, "k-", alpha=0.25, lw=4, label="∝ N")
    ax.set_xticks(N)
    ax.set_xticklabels([f"{int(v)}" for v in N])
    ax.minorticks_off()
    ax.set_xlabel("loops N")
    ax.set_ylabel("wall time per step [µs]")
    ax.set_title("chain of N four-bar loops")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true",
                        help="small grids, under a minute; written to a temporary directory")
    parser.add_argument("--out", type=Path, default=None,
                        help="directory for performance.md and img/ (default: docs/, or a "
                             "temporary directory with --quick)")
    args = parser.parse_args(argv)
    plan = QUICK if args.quick else FULL
    out_dir = args.out or (Path(tempfile.mkdtemp(prefix="pam2exu-bench-")) if args.quick
                           else ROOT / "docs")
    start = time.perf_counter()
    info = machine()                     # before the run: the commit that is measured
    run_pam(four_bar_case()[0], "kinetostatic", 200, 1.0, DEFAULT_TOLERANCE, 1)   # warm-up
    plain_exudyn_four_bar(200, DEFAULT_TOLERANCE, "symbolic")
    sections = {}

    def section(title, fn, *args):
        log(title)
        begin = time.perf_counter()
        value = fn(*args)
        sections[title] = time.perf_counter() - begin
        log(f"  ({sections[title]:.0f} s)")
        return value
    comparison = AgainstPlain(plan)
    # its rounds are spread over the run: before, between and after the other sections
    spread = [max(1, plan.compare_repeats // 5)] * 5
    spread[0] += plan.compare_repeats - sum(spread)

    def compare_rounds(k):
        for _ in range(spread[k]):
            comparison.round()
    section("2. pam2exu against plain Exudyn (rounds 1)", compare_rounds, 0)
    grid = section("1. work against precision", work_precision, plan)
    section("2. pam2exu against plain Exudyn (rounds 2)", compare_rounds, 1)
    newton = section("2b. Newton iterations of the plain solve", newton_grid, plan)
    hard = section("3. hard cases", hard_cases, plan)
    section("2. pam2exu against plain Exudyn (rounds 3)", compare_rounds, 2)
    chain_rows = section("4. chain", chain, plan)
    section("2. pam2exu against plain Exudyn (rounds 4)", compare_rounds, 3)
    section("2. pam2exu against plain Exudyn (rounds 5)", compare_rounds, 4)
    plain_rows = section("2c. plain solve: Newton iterations and error", comparison.rows)
    compare = max(plan.compare_steps, key=lambda n: (n <= 10000, n))
    profiles = section("5. profiles", lambda: {
        f"four-bar, kinematic, {compare:,} steps":
            profile(four_bar_case()[0], "kinematic", compare),
        f"four-bar, kinetostatic, {compare:,} steps":
            profile(four_bar_case()[0], "kinetostatic", compare),
        f"chain N = {plan.chain_sizes[-1]}, kinematic, {plan.chain_steps:,} steps":
            profile(chain_model(plan.chain_sizes[-1]), "kinematic", plan.chain_steps)})
    elapsed = time.perf_counter() - start
    out_dir.mkdir(parents=True, exist_ok=True)
    plot(out_dir / "img" / "work_precision.png", grid, chain_rows)
    write_report(out_dir, info, plan, args.quick, grid, hard, chain_rows, plain_rows, newton,
                 profiles, sections, elapsed)
    log(f"wrote {out_dir / 'performance.md'} and {out_dir / 'img' / 'work_precision.png'} "
        f"({elapsed / 60:.1f} minutes)")


if __name__ == "__main__":
    main()

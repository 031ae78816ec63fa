"""Andrews' squeezing mechanism: the published reference and the benchmark's own equations.

The seven-body benchmark of Hairer & Wanner, Solving ODEs II, sec. VII.7 (eq. 7.11), as the
Test Set for IVP Solvers (Mazzia, Iavernaro, Magherini; problem "andrews") states it. The
numbers are copied from the test set's Fortran, andrews.F rev. 1.2 (2006-10-02), read in the
copy rforge/bvpsolve pkg/deTestSet/src/Ex_andrews.f (its parameters, ``y0`` and subroutine
``andsoln``); the Python port vick2075/Test-Set-for-IVP-solvers DAEs/andrews.py has the same
parameters, equations and y0. The model in pam2exu's format is
examples/dynamics/andrews.toml (how each body maps to the benchmark: its header).

- ``Y0``: the initial angles β, Θ, γ, Φ, δ, Ω, ε (rates 0).
- ``PUBLISHED_Q``, ``PUBLISHED_QD``: the test set's reference at t = 0.03 s (computed with
  PSIDE at rtol = atol = 1e-14 on a Cray C90, as its comment says).
- ``integrate(t_end, rtol)``: the test set's equations M(q) q̈ = f(q, q̇) − G(q)ᵀ λ, g(q) = 0
  (the Fortran's m, ff, gp, g written out below), reduced to index 1 (G q̈ = −(d²/ds²)
  g(q + s q̇) at s = 0, exact: every term of g is a·cos or a·sin of a sum of angles) and
  integrated by scipy's DOP853. At rtol 1e-13 (0.4 s) it keeps g(q) = 0 to 2e-15 and differs
  from the published values by at most 2.8e-10 relative in the angles (γ) and 5.1e-8 in the
  rates (ε'): the published reference's own accuracy, as pam2exu's dynamic analysis, a
  different formulation (absolute coordinates on Exudyn), agrees with this integration to
  5e-12 in the angles at tolerance 1e-9.

Nothing here imports pam2exu.
"""
from __future__ import annotations

import numpy as np

#: the test set's parameters (SI)
P = dict(m1=.04325, m2=.00365, m3=.02373, m4=.00706, m5=.07050, m6=.00706, m7=.05498,
         xa=-.06934, ya=-.00227, xb=-0.03635, yb=.03273, xc=.014, yc=.072, c0=4530.0,
         i1=2.194e-6, i2=4.410e-7, i3=5.255e-6, i4=5.667e-7, i5=1.169e-5, i6=5.667e-7,
         i7=1.912e-5, d=28e-3, da=115e-4, e=2e-2, ea=1421e-5, rr=7e-3, ra=92e-5,
         l0=7785e-5, ss=35e-3, sa=1874e-5, sb=1043e-5, sc=18e-3, sd=2e-2, ta=2308e-5,
         tb=916e-5, u=4e-2, ua=1228e-5, ub=449e-5, zf=2e-2, zt=4e-2, fa=1421e-5, mom=33e-3)

#: β, Θ, γ, Φ, δ, Ω, ε at t = 0 (the test set's y0; the rates are 0)
Y0 = np.array([-0.0617138900142764496358948458001, 0.0, 0.455279819163070380255912382449,
               0.222668390165885884674473185609, 0.487364979543842550225598953530,
               -0.222668390165885884674473185609, 1.23054744454982119249735015568])

#: the published reference at t = 0.03 s: β, Θ, γ, Φ, δ, Ω, ε (andsoln y(1..7))
PUBLISHED_Q = np.array([0.1581077119629904e+2, -0.1575637105984298e+2,
                        0.4082224013073101e-1, -0.5347301163226948e+0,
                        0.5244099658805304e+0, 0.5347301163226948e+0,
                        0.1048080741042263e+1])
#: and their rates (andsoln y(8..14))
PUBLISHED_QD = np.array([0.1139920302151208e+4, -0.1424379294994111e+4,
                         0.1103291221937134e+2, 0.1929337464421385e+2,
                         0.5735699284790808e+0, -0.1929337464421385e+2,
                         0.3231791658026955e+0])
T_END = 0.03
NAMES = ("beta", "Theta", "gamma", "Phi", "delta", "Omega", "epsilon")


def _mass_and_forces(q, qd):
    """M (7, 7) and ff (7) of the Fortran's andfunc."""
    p = P
    _, th, ga, ph, _, om, _ = q
    bep, thp, _, php, dep, omp, epp = qd
    m2, m4, m6 = p["m2"], p["m4"], p["m6"]
    da, rr, e, ea, zt, zf, fa, u = p["da"], p["rr"], p["e"], p["ea"], p["zt"], p["zf"], \
        p["fa"], p["u"]
    M = np.zeros((7, 7))
    M[0, 0] = p["m1"] * p["ra"] ** 2 + m2 * (rr ** 2 - 2 * da * rr * np.cos(th) + da ** 2) \
        + p["i1"] + p["i2"]
    M[1, 0] = m2 * (da ** 2 - da * rr * np.cos(th)) + p["i2"]
    M[1, 1] = m2 * da ** 2 + p["i2"]
    M[2, 2] = p["m3"] * (p["sa"] ** 2 + p["sb"] ** 2) + p["i3"]
    M[3, 3] = m4 * (e - ea) ** 2 + p["i4"]
    M[4, 3] = m4 * ((e - ea) ** 2 + zt * (e - ea) * np.sin(ph)) + p["i4"]
    M[4, 4] = m4 * (zt ** 2 + 2 * zt * (e - ea) * np.sin(ph) + (e - ea) ** 2) \
        + p["m5"] * (p["ta"] ** 2 + p["tb"] ** 2) + p["i4"] + p["i5"]
    M[5, 5] = m6 * (zf - fa) ** 2 + p["i6"]
    M[6, 5] = m6 * ((zf - fa) ** 2 - u * (zf - fa) * np.sin(om)) + p["i6"]
    M[6, 6] = m6 * ((zf - fa) ** 2 - 2 * u * (zf - fa) * np.sin(om) + u ** 2) \
        + p["m7"] * (p["ua"] ** 2 + p["ub"] ** 2) + p["i6"] + p["i7"]
    M = np.tril(M) + np.tril(M, -1).T
    sg, cg = np.sin(ga), np.cos(ga)
    xd = p["sd"] * cg + p["sc"] * sg + p["xb"]
    yd = p["sd"] * sg - p["sc"] * cg + p["yb"]
    length = np.hypot(xd - p["xc"], yd - p["yc"])
    force = -p["c0"] * (length - p["l0"]) / length
    fx, fy = force * (xd - p["xc"]), force * (yd - p["yc"])
    ff = np.array([
        p["mom"] - m2 * da * rr * thp * (thp + 2 * bep) * np.sin(th),
        m2 * da * rr * bep ** 2 * np.sin(th),
        fx * (p["sc"] * cg - p["sd"] * sg) + fy * (p["sd"] * cg + p["sc"] * sg),
        m4 * zt * (e - ea) * dep ** 2 * np.cos(ph),
        -m4 * zt * (e - ea) * php * (php + 2 * dep) * np.cos(ph),
        -m6 * u * (zf - fa) * epp ** 2 * np.cos(om),
        m6 * u * (zf - fa) * omp * (omp + 2 * epp) * np.cos(om)])
    return M, ff


def constraints(q):
    """g (6): E reached from the crank equals E reached through bodies 3, 4-5 and 6-7."""
    p = P
    be, th, ga, ph, de, om, ep = q
    fx = p["rr"] * np.cos(be) - p["d"] * np.cos(be + th)
    fy = p["rr"] * np.sin(be) - p["d"] * np.sin(be + th)
    return np.array([
        fx - p["ss"] * np.sin(ga) - p["xb"],
        fy + p["ss"] * np.cos(ga) - p["yb"],
        fx - p["e"] * np.sin(ph + de) - p["zt"] * np.cos(de) - p["xa"],
        fy + p["e"] * np.cos(ph + de) - p["zt"] * np.sin(de) - p["ya"],
        fx - p["zf"] * np.cos(om + ep) - p["u"] * np.sin(ep) - p["xa"],
        fy - p["zf"] * np.sin(om + ep) + p["u"] * np.cos(ep) - p["ya"]])


def jacobian(q):
    """gp (6, 7) = ∂g/∂q."""
    p = P
    be, th, ga, ph, de, om, ep = q
    a = -p["rr"] * np.sin(be) + p["d"] * np.sin(be + th)
    b = p["rr"] * np.cos(be) - p["d"] * np.cos(be + th)
    J = np.zeros((6, 7))
    J[0::2, 0], J[0::2, 1] = a, p["d"] * np.sin(be + th)
    J[1::2, 0], J[1::2, 1] = b, -p["d"] * np.cos(be + th)
    J[0, 2], J[1, 2] = -p["ss"] * np.cos(ga), -p["ss"] * np.sin(ga)
    J[2, 3] = -p["e"] * np.cos(ph + de)
    J[2, 4] = -p["e"] * np.cos(ph + de) + p["zt"] * np.sin(de)
    J[3, 3] = -p["e"] * np.sin(ph + de)
    J[3, 4] = -p["e"] * np.sin(ph + de) - p["zt"] * np.cos(de)
    J[4, 5] = p["zf"] * np.sin(om + ep)
    J[4, 6] = p["zf"] * np.sin(om + ep) - p["u"] * np.cos(ep)
    J[5, 5] = -p["zf"] * np.cos(om + ep)
    J[5, 6] = -p["zf"] * np.cos(om + ep) - p["u"] * np.sin(ep)
    return J


def _curvature(q, qd):
    """(d²/ds²) g(q + s q̇) at s = 0: each term a·trig(c·q) of g gives −a·trig(c·q)(c·q̇)²."""
    p = P
    be, th, ga, ph, de, om, ep = q
    b, t, c, f, dl, o, x = qd
    base = np.array([-p["rr"] * np.cos(be) * b ** 2 + p["d"] * np.cos(be + th) * (b + t) ** 2,
                     -p["rr"] * np.sin(be) * b ** 2 + p["d"] * np.sin(be + th) * (b + t) ** 2])
    return np.array([
        base[0] + p["ss"] * np.sin(ga) * c ** 2,
        base[1] - p["ss"] * np.cos(ga) * c ** 2,
        base[0] + p["e"] * np.sin(ph + de) * (f + dl) ** 2 + p["zt"] * np.cos(de) * dl ** 2,
        base[1] - p["e"] * np.cos(ph + de) * (f + dl) ** 2 + p["zt"] * np.sin(de) * dl ** 2,
        base[0] + p["zf"] * np.cos(om + ep) * (o + x) ** 2 + p["u"] * np.sin(ep) * x ** 2,
        base[1] + p["zf"] * np.sin(om + ep) * (o + x) ** 2 - p["u"] * np.cos(ep) * x ** 2])


def rhs(t, y):
    """(q̇, q̈) of [[M, Gᵀ], [G, 0]] [q̈; λ] = [ff; −curvature]."""
    q, qd = y[:7], y[7:]
    M, ff = _mass_and_forces(q, qd)
    J = jacobian(q)
    A = np.block([[M, J.T], [J, np.zeros((6, 6))]])
    return np.r_[qd, np.linalg.solve(A, np.r_[ff, -_curvature(q, qd)])[:7]]


def integrate(t_end: float = T_END, rtol: float = 1e-13):
    """(q, q̇) at ``t_end`` by DOP853 from ``Y0`` at rest (atol = rtol / 100)."""
    from scipy.integrate import solve_ivp
    sol = solve_ivp(rhs, (0.0, t_end), np.r_[Y0, np.zeros(7)], method="DOP853", rtol=rtol,
                    atol=rtol * 1e-2)
    return sol.y[:7, -1], sol.y[7:, -1]


def benchmark_angles(fi: dict) -> np.ndarray:
    """β … ε from the solids' absolute angles fi[1..7] (examples/dynamics/andrews.toml):
    β = fi1, Θ = fi2 − fi1, γ = fi3, Φ = fi4 − fi5, δ = fi5, Ω = fi6 − fi7, ε = fi7."""
    return np.array([fi[1], fi[2] - fi[1], fi[3], fi[4] - fi[5], fi[5], fi[6] - fi[7], fi[7]])

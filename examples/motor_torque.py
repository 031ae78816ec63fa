"""The motor torque of a slider-crank, and where it goes: the power balance.

The crank of examples/slider_crank.toml turns at a constant speed ω = 10 rad/s. The
kinetostatic analysis (inverse dynamics) gives the torque motor.Mz the motor must apply.
With ideal joints (no friction) the constraint forces do no work, so the motor's power
goes into the kinetic energy T and the potential energy V of the mechanism:

    Mz ω = dT/dt + dV/dt,
    T = Σ (m v_G·v_G / 2 + J_G Dfi² / 2),        V = Σ m g y_G,
    dT/dt = Σ (m v_G·a_G + J_G Dfi DDfi),        dV/dt = Σ m g vy_G,

sums over the solids; G is a solid's centre of mass, J_G its moment of inertia about G.

This script computes both parts from the solids' result columns (x ... DDfi, and the centre
of mass G of each solid), and checks that they add up to pam2exu's motor torque. The
inertia part averages to zero over a turn, and so does the gravity part: a crank turning
at constant speed needs no net work per turn.

Run from anywhere:  python examples/motor_torque.py [-o motor_torque.png] [--show]
"""
import argparse
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
import numpy as np

import pam2exu

MODEL = Path(__file__).resolve().with_name("slider_crank.toml")
STEPS = 360                      # one crank turn, one degree per step


def centre_of_mass(res, solid):
    """Position, velocity and acceleration (each n × 2) of the solid's centre of mass G:
    r_G = r_O + c,  v_G = v_O + Dfi k × c,  a_G = a_O + DDfi k × c − Dfi² c,  c = R(fi) cog."""
    n, (gx, gy) = solid.name, solid.cog
    fi, dfi, ddfi = res[f"{n}.fi"], res[f"{n}.Dfi"], res[f"{n}.DDfi"]
    cx, cy = np.cos(fi) * gx - np.sin(fi) * gy, np.sin(fi) * gx + np.cos(fi) * gy
    r = np.column_stack([res[f"{n}.x"] + cx, res[f"{n}.y"] + cy])
    v = np.column_stack([res[f"{n}.Dx"] - dfi * cy, res[f"{n}.Dy"] + dfi * cx])
    a = np.column_stack([res[f"{n}.DDx"] - ddfi * cy - dfi**2 * cx,
                         res[f"{n}.DDy"] + ddfi * cx - dfi**2 * cy])
    return r, v, a


def main(figure_path="motor_torque.png", show=False) -> dict:
    model = pam2exu.load(MODEL)
    omega = model["motor"].C[1]                            # rad/s (f(t) = ω t)
    res = pam2exu.run(model, analysis="kinetostatic", t_end=2 * np.pi / omega, steps=STEPS)
    crank = np.degrees(res["crank.fi"])
    Mz = res["motor.Mz"]

    # the power balance, solid by solid
    T = V = dT = dV = 0.0
    for s in model.solids:
        rG, vG, aG = centre_of_mass(res, s)
        dfi, ddfi = res[f"{s.name}.Dfi"], res[f"{s.name}.DDfi"]
        T = T + s.mass * (vG**2).sum(axis=1) / 2 + s.inertia * dfi**2 / 2
        V = V + s.mass * model.gravity * rG[:, 1]
        dT = dT + s.mass * (vG * aG).sum(axis=1) + s.inertia * dfi * ddfi
        dV = dV + s.mass * model.gravity * vG[:, 1]
    Dfi = res["crank.Dfi"]                                 # = ω
    inertia_part, gravity_part = dT / Dfi, dV / Dfi
    balance_error = float(np.max(np.abs(Mz - inertia_part - gravity_part)))
    # work of the motor over the turn (trapezoid rule): zero, the energies are periodic
    work = float(np.sum((Mz[1:] + Mz[:-1]) / 2 * np.diff(res["crank.fi"])))
    peak = int(np.argmax(np.abs(Mz)))

    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(8, 6.4),
                                      height_ratios=(1, 1.6), layout="constrained")
    top.plot(crank, T, color="C0", label="kinetic energy T")
    top.plot(crank, V - V.min(), color="C2", label="potential energy V (above its minimum)")
    top.set_ylabel("energy [J]")
    top.legend(fontsize=9, loc="upper right")
    top.set_title("Slider-crank (examples/slider_crank.toml), crank at ω = "
                  f"{omega:g} rad/s:  Mz ω = dT/dt + dV/dt")
    bottom.plot(crank, Mz, color="k", lw=2.4, label="motor.Mz (pam2exu, kinetostatic)")
    bottom.plot(crank, inertia_part, color="C0", label="inertia part  (dT/dt) / ω")
    bottom.plot(crank, gravity_part, color="C2", label="gravity part  (dV/dt) / ω")
    bottom.plot(crank[::10], (inertia_part + gravity_part)[::10], "o", mfc="none",
                color="C3", label="sum of the two parts")
    bottom.axhline(0, color="0.5", lw=0.8)
    bottom.margins(y=0.3)                                  # room for the legend and the text
    bottom.set_ylabel("torque on the crank [N·m]")
    bottom.set_xlabel("crank angle [°]")
    bottom.set_xticks(np.arange(0, 361, 45))
    bottom.legend(fontsize=9, loc="upper right")
    bottom.text(0.01, 0.03, f"max |Mz − sum of the parts| = {balance_error:.1e} N·m\n"
                f"motor work per turn ∮ Mz dfi = {work:.1e} J",
                transform=bottom.transAxes, fontsize=9, va="bottom")
    for ax in (top, bottom):
        ax.grid(alpha=0.3)
    Path(figure_path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(figure_path, dpi=100)
    if show:
        plt.show()
    plt.close(fig)

    out = {
        "t": res.t, "crank_deg": crank, "Mz": Mz, "inertia_part": inertia_part,
        "gravity_part": gravity_part, "kinetic_energy": T, "potential_energy": V,
        "balance_error": balance_error, "work_per_turn": work,
        "peak_Mz": float(Mz[peak]), "peak_at_deg": float(crank[peak]),
        "power_balance_error": res.info["power_balance_error"], "figure": str(figure_path),
    }
    print(f"peak motor torque {out['peak_Mz']:.3f} N·m at crank angle {out['peak_at_deg']:.0f}°")
    print(f"inertia part: up to {np.max(np.abs(inertia_part)):.3f} N·m, "
          f"gravity part: up to {np.max(np.abs(gravity_part)):.3f} N·m")
    print(f"Mz ω = dT/dt + dV/dt holds to {balance_error:.1e} N·m; "
          f"motor work per turn {work:.1e} J")
    print(f"figure: {figure_path}")
    return out


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", default="motor_torque.png", help="figure file")
    parser.add_argument("--show", action="store_true", help="also open a window")
    args = parser.parse_args()
    if not args.show:
        matplotlib.use("Agg")            # write the file only, never open a window
    main(args.output, show=args.show)

"""A quick-return mechanism: crank and slotted lever (as in a shaping machine).

A crank of radius r turns at constant speed about O2. Its pin slides in the slot of a
lever pivoted at O4, a distance d > r below O2 (a pin_slot joint), so the lever swings to
and fro. A stroke ends where the lever stops: there the slot is tangent to the crank
circle, sin(α/2) = r/d, and the lever's two end positions make the angle

    α = 2 arcsin(r/d).

Between them the crank turns 180° + α for the forward (working) stroke, over the far
side of its circle, and only 180° − α for the return stroke: the return is quicker, and

    time ratio = forward time / return time = (180° + α) / (180° − α).

This script builds the model in Python (pam2exu.Model), runs the kinematic analysis over
one crank turn, finds the stroke ends where the lever's angular velocity is zero, and
compares the measured time ratio with the formula. The lever's angular velocity is

    Dfi_lever = ω r (r + d sin θ) / (r² + d² + 2 r d sin θ)      (θ the crank angle).

Run from anywhere:  python examples/quick_return.py [-o quick_return.png] [--show]
"""
import argparse
import math
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
import numpy as np

import pam2exu

R = 0.10                         # crank radius O2-pin [m]
D = 0.25                         # distance between the pivots O2 and O4 [m]
L = 0.40                         # lever length [m]
OMEGA = 2 * math.pi              # crank speed [rad/s]: one turn per second
STEPS = 360                      # one crank degree per step


def build_model():
    """O4 at the origin, O2 straight above it; the crank starts pointing along +x."""
    m = pam2exu.Model("quick-return", gravity=0.0)
    m.add_solid("ground", points={"O2": [0.0, D], "O4": [0.0, 0.0]})
    m.add_solid("crank", y=D, points={"O": [0.0, 0.0], "pin": [R, 0.0]})
    m.add_solid("lever", fi=1.2, points={"O": [0.0, 0.0], "tip": [L, 0.0]},
                lines={"slot": {"point": [0.0, 0.0], "angle": 0.0}})    # the slot: its x axis
    m.add("fixed", name="base", anc1="ground")
    m.add("revolute", name="O2", anc1="ground.O2", anc2="crank.O")
    m.add("revolute", name="O4", anc1="ground.O4", anc2="lever.O")
    m.add("pin_slot", name="slot", anc1="lever.slot", anc2="crank.pin")
    m.add("angular_actuator", name="motor", anc1="ground", anc2="crank",
          law="polynomial", C=[0.0, OMEGA])                           # f(t) = ω t
    return m


def stroke_end(model, t):
    """The time near t where the lever stops (Dfi = 0), by Newton's method
    t ← t − Dfi/DDfi; each Dfi, DDfi is the last row of a run that ends exactly at t."""
    for _ in range(4):
        last = pam2exu.run(model, analysis="kinematic", t_end=t, steps=max(1, round(STEPS * t)),
                           outputs=["crank.fi", "lever.*"])
        t -= last["lever.Dfi"][-1] / last["lever.DDfi"][-1]
    return t, last["crank.fi"][-1], last["lever.fi"][-1]


def main(figure_path="quick_return.png", show=False) -> dict:
    model = build_model()
    res = pam2exu.run(model, analysis="kinematic", t_end=2 * math.pi / OMEGA, steps=STEPS)
    t, crank, lever = res.t, res["crank.fi"], res["lever.Dfi"]

    # the stroke ends: where Dfi changes sign (interpolated between steps, then refined)
    k = np.flatnonzero(np.sign(lever[:-1]) != np.sign(lever[1:]))
    guess = t[k] - lever[k] * (t[k + 1] - t[k]) / (lever[k + 1] - lever[k])
    (t1, th1, fi1), (t2, th2, fi2) = (stroke_end(model, g) for g in guess)
    turn = t[-1]
    back = t2 - t1                               # Dfi < 0 between them: the return
    ratio = (turn - back) / back
    alpha = 2 * math.asin(R / D)
    formula = (math.pi + alpha) / (math.pi - alpha)

    fig, (geo, ax) = plt.subplots(1, 2, figsize=(11, 4.6), width_ratios=(1, 1.5),
                                  layout="constrained")
    # left: the geometry of the two stroke ends
    O2, O4 = np.array([0.0, D]), np.array([0.0, 0.0])
    arc = lambda a, b: O2[:, None] + R * np.array([np.cos(np.linspace(a, b, 100)),
                                                     np.sin(np.linspace(a, b, 100))])
    geo.plot(*arc(th2, th1 + 2 * math.pi), color="C0", lw=4,
             label="forward: crank turns 180° + α")
    geo.plot(*arc(th1, th2), color="C3", lw=4, label="return: crank turns 180° − α")
    for th, fi in ((th1, fi1), (th2, fi2)):
        pin = O2 + R * np.array([math.cos(th), math.sin(th)])
        geo.plot(*np.array([O4, L * np.array([math.cos(fi), math.sin(fi)])]).T, color="0.3",
                 lw=3, solid_capstyle="round")
        geo.plot(*np.array([O2, pin]).T, color="k", lw=1.5)
        geo.plot(*pin, "o", color="k", ms=5)
    top = arc(0.45 * math.pi, 0.55 * math.pi)                # the crank turns anticlockwise
    geo.annotate("", xy=top[:, -1], xytext=top[:, 0],
                 arrowprops={"arrowstyle": "-|>", "color": "C0", "mutation_scale": 22})
    a = np.linspace(fi2, fi1, 50)                          # the angle α at O4
    geo.plot(0.08 * np.cos(a), 0.08 * np.sin(a), color="k", lw=1)
    geo.annotate("α", (0, 0.09), ha="center", va="bottom")
    geo.plot(*np.array([O2, O4]).T, "^", color="0.3", ms=10)
    geo.annotate("O2", O2, xytext=(0, 8), textcoords="offset points", ha="center")
    geo.annotate("O4", O4, xytext=(10, -4), textcoords="offset points")
    geo.set_aspect("equal")
    geo.set_xlim(-0.25, 0.25)
    geo.set_ylim(-0.04, L + 0.1)
    geo.grid(alpha=0.3)
    geo.set_xlabel("x [m]")
    geo.set_ylabel("y [m]")
    geo.set_title(f"lever at the two stroke ends: α = {math.degrees(fi1 - fi2):.2f}°")
    geo.legend(loc="upper center", fontsize=9)

    # right: the lever's angular velocity over one crank turn
    deg = np.degrees(crank)
    ax.plot(deg, lever, color="k", lw=2)
    ax.axvspan(math.degrees(th1), math.degrees(th2), color="C3", alpha=0.15)
    for a, b in ((0, th1), (th2, 2 * math.pi)):
        ax.axvspan(math.degrees(a), math.degrees(b), color="C0", alpha=0.12)
    ax.axhline(0, color="0.5", lw=0.8)
    ax.text(math.degrees(th1) / 2, 0.35 * lever.max(), "forward", ha="center", color="C0")
    ax.text(math.degrees(th1 + th2) / 2, 0.35 * lever.max(), "return", ha="center", color="C3")
    for th, side in ((th1, 1), (th2, -1)):               # the stroke ends
        ax.annotate(f"{math.degrees(th):.1f}°", (math.degrees(th), 0), xytext=(4 * side, 6),
                    textcoords="offset points", ha="left" if side > 0 else "right",
                    fontsize=9)
    ax.text(0.02, 0.04, "forward time / return time\n"
            f"run:      {turn - back:.4f} s / {back:.4f} s = {ratio:.6f}\n"
            f"formula:  (180° + α)/(180° − α) = {formula:.6f}",
            transform=ax.transAxes, fontsize=9, va="bottom", family="monospace")
    ax.set_xticks(np.arange(0, 361, 45))
    ax.set_xlim(0, 360)
    ax.set_ylim(lever.min() - 0.2 * np.ptp(lever), lever.max() + 0.1 * np.ptp(lever))
    ax.grid(alpha=0.3)
    ax.set_xlabel("crank angle θ [°]")
    ax.set_ylabel("lever angular velocity lever.Dfi [rad/s]")
    ax.set_title(f"crank r = {R} m at ω = {OMEGA:.3g} rad/s, pivots d = {D} m apart")
    Path(figure_path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(figure_path, dpi=100)
    if show:
        plt.show()
    plt.close(fig)

    out = {
        "t": t, "crank_deg": np.degrees(crank), "lever_Dfi": lever,
        "stroke_end_times": (t1, t2), "stroke_end_crank_deg": (math.degrees(th1),
                                                                math.degrees(th2)),
        "lever_swing_deg": math.degrees(fi1 - fi2), "forward_time": turn - back,
        "return_time": back, "time_ratio": ratio, "time_ratio_formula": formula,
        "figure": str(figure_path),
    }
    print(f"strokes end at crank angles {out['stroke_end_crank_deg'][0]:.3f}° and "
          f"{out['stroke_end_crank_deg'][1]:.3f}°; the lever swings α = "
          f"{out['lever_swing_deg']:.3f}°")
    print(f"time ratio forward/return: {ratio:.9f} (run), {formula:.9f} "
          "((180° + α)/(180° − α))")
    print(f"figure: {figure_path}")
    return out


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", default="quick_return.png", help="figure file")
    parser.add_argument("--show", action="store_true", help="also open a window")
    args = parser.parse_args()
    if not args.show:
        matplotlib.use("Agg")            # write the file only, never open a window
    main(args.output, show=args.show)

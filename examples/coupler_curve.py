"""The coupler curve of a four-bar linkage.

A point P fixed to the coupler of a four-bar traces a closed curve while the crank turns:
the coupler curve. Linkages that guide a point along a path (straight-line mechanisms,
walking machines, film advance) are designed by choosing it.

For every crank angle the loop-closure equation of the four-bar,

    O2A + AB = O2O4 + O4B        (vectors; |O2A| = a, |AB| = b, |O4B| = c),

fixes the coupler's pose (x, y, fi); pam2exu solves it (kinematic analysis of
examples/four_bar.toml over one crank turn) and P follows from that pose:

    P = (x, y) + R(fi) p,      R(fi) = [[cos fi, -sin fi], [sin fi, cos fi]],

with p = coupler.P in the coupler's own frame. Its velocity is v_P = v_O + Dfi k × R(fi) p.

Run from anywhere:  python examples/coupler_curve.py [-o coupler_curve.png] [--show]
"""
import argparse
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
import numpy as np

import pam2exu

MODEL = Path(__file__).resolve().with_name("four_bar.toml")
STEPS = 360                      # the crank turns once in 1 s: one degree per step
SHOWN = (0, 90, 180, 270)        # crank angles [deg] at which the linkage is drawn


def point(res, solid, p):
    """Position and velocity (each n × 2) of the point p (local coordinates) of a solid."""
    fi, dfi = res[f"{solid}.fi"], res[f"{solid}.Dfi"]
    px = np.cos(fi) * p[0] - np.sin(fi) * p[1]          # R(fi) p
    py = np.sin(fi) * p[0] + np.cos(fi) * p[1]
    position = np.column_stack([res[f"{solid}.x"] + px, res[f"{solid}.y"] + py])
    velocity = np.column_stack([res[f"{solid}.Dx"] - dfi * py, res[f"{solid}.Dy"] + dfi * px])
    return position, velocity


def main(figure_path="coupler_curve.png", show=False) -> dict:
    model = pam2exu.load(MODEL)
    res = pam2exu.run(model, analysis="kinematic", t_end=1.0, steps=STEPS)

    pts = lambda solid, name: point(res, solid, model[solid].points[name])[0]
    O2, O4 = pts("ground", "O2")[0], pts("ground", "O4")[0]
    A, B = pts("crank", "A"), pts("rocker", "B")
    P, vP = point(res, "coupler", model["coupler"].points["P"])
    crank = np.degrees(res["crank.fi"])
    rocker = np.degrees(res["rocker.fi"])
    speed = np.hypot(vP[:, 0], vP[:, 1])
    fastest = int(np.argmax(speed))

    fig, ax = plt.subplots(figsize=(7.5, 5.6), layout="constrained")
    ax.plot(P[:, 0], P[:, 1], color="k", lw=2.2, label="coupler curve of P")
    for color, deg in zip(("C0", "C1", "C2", "C4"), SHOWN):
        i = int(np.argmin(np.abs(crank - deg)))            # the step nearest that angle
        ax.plot(*np.array([O2, A[i], B[i], O4]).T, "-o", color=color, lw=1.3, ms=4,
                label=f"crank at {deg}°")
        ax.fill(*np.array([A[i], B[i], P[i]]).T, facecolor=color, edgecolor=color,
                alpha=0.3, lw=0.8)                         # the coupler: triangle A B P
        ax.plot(*P[i], "o", color=color, ms=7, mec="k", zorder=4)
    ax.annotate("", xy=P[fastest + 3], xytext=P[fastest],   # the sense of travel
                arrowprops={"arrowstyle": "-|>", "color": "k", "lw": 2,
                             "mutation_scale": 18})
    ax.plot(*np.array([O2, O4]).T, "^", color="0.3", ms=12, zorder=5)
    for name, q in (("O2", O2), ("O4", O4)):
        ax.annotate(name, q, xytext=(0, -20), textcoords="offset points", ha="center")
    ax.set_aspect("equal")
    ax.grid(alpha=0.3)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title("Four-bar linkage (examples/four_bar.toml): coupler curve of P")
    ax.legend(loc="lower right", bbox_to_anchor=(0.9, 0.0), fontsize=9)
    Path(figure_path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(figure_path, dpi=100)
    if show:
        plt.show()
    plt.close(fig)

    out = {
        "t": res.t, "crank_deg": crank, "P": P, "P_velocity": vP, "rocker_deg": rocker,
        "width": float(np.ptp(P[:, 0])), "height": float(np.ptp(P[:, 1])),
        "max_speed": float(speed[fastest]), "max_speed_at_deg": float(crank[fastest]),
        "rocker_swing_deg": (float(rocker.min()), float(rocker.max())),
        "figure": str(figure_path),
    }
    print(f"coupler curve of P: {out['width'] * 1000:.1f} mm wide, "
          f"{out['height'] * 1000:.1f} mm high")
    print(f"P is fastest, {out['max_speed']:.3f} m/s, at crank angle "
          f"{out['max_speed_at_deg']:.0f}°")
    print("the rocker swings between {:.1f}° and {:.1f}°".format(*out["rocker_swing_deg"]))
    print(f"figure: {figure_path}")
    return out


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", default="coupler_curve.png", help="figure file")
    parser.add_argument("--show", action="store_true", help="also open a window")
    args = parser.parse_args()
    if not args.show:
        matplotlib.use("Agg")            # write the file only, never open a window
    main(args.output, show=args.show)

"""Two Jacobians of one four-bar: reference-point and natural coordinates.

The same mechanism can be described by different coordinates, and its constraint Jacobian
(the matrix of the velocity equations) changes with them:

* reference-point coordinates (Exudyn's, pam2exu's x, y, fi): three per solid, the position
  of the solid's frame and its angle. Every joint is equations between them, r_i = r_j for a
  revolute with r = (x, y) + R(fi) s: the entries hold sines and cosines of the angles;

      Cq q̇ = −C_t          q = (x, y, fi) of the 4 solids: 12 columns

* natural coordinates (Unda and García de Jalón): the global x, y of the points that
  revolutes join (A and B of the four-bar; the ground's points O2, O4 are constants), plus
  the crank's angle because the motor drives it. The equations are rigid-body distances
  |B − A|² = b², a tie of the angle to the crank, and the motor fi = f(t): the entries are
  linear in the coordinates;

      Φ_z ż = g′(t)         z = (A.x, A.y, B.x, B.y, crank.fi): 5 columns.

This script assembles examples/four_bar.toml at t = 0, prints both Jacobians with named rows
and columns, their sizes and ranks, solves both velocity systems and converts the natural
velocities back to x, y, fi rates (the natural backend's own conversion): they agree. It
draws the mechanism with its basic points beside the two matrices. Every step is explained,
with the generated tables, in docs/natural-coordinates.md.

Run from anywhere:  python examples/natural_jacobian.py [-o natural_jacobian.png] [--show]
"""
import argparse
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
import numpy as np

import pam2exu
from pam2exu.analyses.native import equations
from pam2exu.backend.natural import Formulation, Natural
from pam2exu.kinematics import State

MODEL = Path(__file__).resolve().with_name("four_bar.toml")
T0 = 0.0                         # the configuration compared: the assembly at t = 0
ROW_NAMES = {"fixed": ("x", "y", "fi"), "revolute": ("x", "y")}


def reference_point(mech, q0):
    """Cq (m × 12) at q0 with row and column names, and q̇ from Cq q̇ = −C_t."""
    eq = equations(mech, State([T0], q0[None]))
    Cq, c_t = eq.jacobian[0], eq.c_t[0]
    columns = [f"{s.name}.{v}" for s in mech.solids for v in ("x", "y", "fi")]
    rows = []
    for el in mech.constraints:
        suffix = ROW_NAMES.get(el.type, ("",) * el.equations)
        rows += [f"{el.name} ({el.type}) {k}".rstrip() for k in suffix]
    return Cq, rows, columns, np.linalg.solve(Cq, -c_t)


def natural(mech, q0):
    """Φ_z (m × nz) at q0 with row and column names, ż from Φ_z ż = g′, z̈ from Φ_z z̈ = γ,
    and q̇ of x, y, fi from them (``Natural.to_rates``)."""
    form = Formulation(mech)
    t = np.array([T0])
    z0 = form.from_q(q0[None])                      # (1, nz): the same configuration
    Phi_z = form.terms.dense(form.terms.jacobian(z0))[0]
    zd = np.linalg.solve(Phi_z, form.terms.velocity_rhs(t)[0])
    zdd = np.linalg.solve(Phi_z, form.terms.gamma(t, z0, zd[None])[0])
    qd, _ = Natural().to_rates(form, mech, z0, zd[None], zdd[None])
    columns = [c.name for c in form.coordinates]
    return form, Phi_z, list(form.labels), columns, z0[0], zd, qd[0]


def what_it_is(form, model, k):
    """The model's words for natural coordinate k: 'crank.A = coupler.A', 'angle of crank'."""
    c = form.coordinates[k]
    if c.kind == "angle":
        return f"angle fi of {c.name.split('.')[0]}"
    axis = c.name[-1]
    j = k if axis == "x" else k - 1
    points = [f"{s.name}.{name}" for i, s in enumerate(model.solids)
              for name, local in s.points.items()
              if (vec := form.basic.get((i, tuple(map(float, local))))) is not None
              and vec.x.linear() == {j: 1.0}]       # the model points that are this one
    return f"{axis} of " + (" = ".join(points) or c.name[:-2])


def print_matrix(title, M, rows, columns, groups=None, width=9):
    """M as a table with named rows and columns ('·' for a zero entry); ``groups``: a
    header line above the columns (the solid of x, y, fi)."""
    label = max(len(r) for r in rows) + 2
    width = max(width, *(len(c) + 1 for c in columns)) if groups is None else width
    print(f"\n{title}")
    if groups is not None:
        line = " " * label
        for name in dict.fromkeys(groups):
            line += name.ljust(width * groups.count(name))
        print(line.rstrip())
    print(" " * label + "".join(c.rjust(width) for c in columns))
    for r, name in enumerate(rows):
        cells = ("·" if abs(v) < 1e-12 else f"{v:.4g}" for v in M[r])
        print(name.ljust(label) + "".join(c.rjust(width) for c in cells))


def draw_matrix(ax, M, rows, columns, title):
    """A matrix as coloured cells (red > 0, blue < 0, white 0) with its values."""
    limit = np.max(np.abs(M))
    ax.imshow(M, cmap="RdBu_r", vmin=-limit, vmax=limit)
    for (r, c), v in np.ndenumerate(M):
        if abs(v) >= 1e-12:
            ax.text(c, r, f"{v:.2g}", ha="center", va="center", fontsize=6.5,
                    color="w" if abs(v) > 0.6 * limit else "k")
    ax.set_xticks(range(len(columns)), columns, rotation=90, fontsize=7)
    ax.set_yticks(range(len(rows)), rows, fontsize=7)
    ax.set_xticks(np.arange(-0.5, len(columns)), minor=True)
    ax.set_yticks(np.arange(-0.5, len(rows)), minor=True)
    ax.grid(which="minor", color="0.85", lw=0.5)
    ax.tick_params(which="minor", length=0)
    ax.set_title(title, fontsize=10)


def main(figure_path="natural_jacobian.png", show=False) -> dict:
    model = pam2exu.load(MODEL)
    mech = model.mechanism()
    res = pam2exu.run(model, analysis="assembly")            # x, y, fi at t = 0
    q0 = np.array([res[c][0] for c in (f"{s.name}.{v}" for s in mech.solids
                                        for v in ("x", "y", "fi"))])

    Cq, cq_rows, cq_columns, qd_reference = reference_point(mech, q0)
    form, Phi_z, phi_rows, phi_columns, z0, zd, qd_natural = natural(mech, q0)
    rank_cq, rank_phi = np.linalg.matrix_rank(Cq), np.linalg.matrix_rank(Phi_z)

    print(f"{model.name} assembled at t = {T0:g} s ({MODEL.name})")
    print_matrix(f"reference-point Jacobian Cq: {Cq.shape[0]} × {Cq.shape[1]}, rank {rank_cq}",
                 Cq, cq_rows, [c.split(".")[1] for c in cq_columns],
                 groups=[c.split(".")[0] for c in cq_columns])
    print_matrix(f"natural-coordinate Jacobian Φ_z: {Phi_z.shape[0]} × {Phi_z.shape[1]}, "
                 f"rank {rank_phi}", Phi_z, phi_rows, phi_columns)
    print("\nthe natural coordinates:")
    for k, c in enumerate(form.coordinates):
        print(f"  {c.name:<20}{c.kind:<8}{z0[k]:>10.6g}   {what_it_is(form, model, k)}")

    print("\nvelocities at t = 0: Cq q̇ = −C_t against Φ_z ż = g′ converted to x, y, fi")
    print(f"  {'variable':<14}{'reference-point':>16}{'natural':>16}{'difference':>13}")
    for name, a, b in zip(cq_columns, qd_reference, qd_natural):
        solid, var = name.split(".")
        print(f"  {solid + '.D' + var:<14}{a:>16.9f}{b:>16.9f}{b - a:>13.2e}")
    difference = float(np.max(np.abs(qd_natural - qd_reference)))
    verdict = "agree" if difference < 1e-9 else "DIFFER"
    print(f"largest difference {difference:.2g} (m/s, rad/s): the two {verdict}")

    # the figure: the mechanism with its natural coordinates, and the two matrices
    fig = plt.figure(figsize=(13, 5.2), layout="constrained")
    geo, left, right = fig.subplots(1, 3, width_ratios=(1.0, 1.25, 0.8))
    point = lambda solid, name: (res[f"{solid}.x"][0] + np.cos(res[f"{solid}.fi"][0])
                                 * model[solid].points[name][0]
                                 - np.sin(res[f"{solid}.fi"][0]) * model[solid].points[name][1],
                                 res[f"{solid}.y"][0] + np.sin(res[f"{solid}.fi"][0])
                                 * model[solid].points[name][0]
                                 + np.cos(res[f"{solid}.fi"][0]) * model[solid].points[name][1])
    O2, A, B, O4, P = (np.array(point(*p)) for p in (("ground", "O2"), ("crank", "A"),
                                                      ("rocker", "B"), ("ground", "O4"),
                                                      ("coupler", "P")))
    geo.plot(*np.array([O2, A, B, O4]).T, "-", color="0.3", lw=3, solid_capstyle="round")
    geo.fill(*np.array([A, B, P]).T, facecolor="C1", alpha=0.3, edgecolor="C1")
    geo.plot(*np.array([O2, O4]).T, "^", color="0.3", ms=12)
    geo.plot(*np.array([A, B]).T, "o", color="C3", ms=10, zorder=4)
    for p, text, offset, align in ((O2, "O2: constant", (-4, -20), "center"),
                                   (O4, "O4: constant", (4, -20), "center"),
                                   (A, "A = (z1, z2)", (6, -18), "left"),
                                   (B, "B = (z3, z4)", (8, 6), "left")):
        geo.annotate(text, p, xytext=offset, textcoords="offset points", ha=align, fontsize=9)
    geo.annotate("crank.fi = z5", (O2 + A) / 2, xytext=(0, 8), textcoords="offset points",
                 ha="center", fontsize=9)
    geo.set_aspect("equal")
    geo.margins(0.2)
    geo.grid(alpha=0.3)
    geo.set_xlabel("x [m]")
    geo.set_ylabel("y [m]")
    geo.set_title("four-bar at t = 0: basic points A, B (red)", fontsize=10)
    draw_matrix(left, Cq, cq_rows, cq_columns,
                f"reference-point Cq, {Cq.shape[0]} × {Cq.shape[1]}, rank {rank_cq}")
    draw_matrix(right, Phi_z, phi_rows, phi_columns,
                f"natural Φ_z, {Phi_z.shape[0]} × {Phi_z.shape[1]}, rank {rank_phi}")
    Path(figure_path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(figure_path, dpi=100)
    if show:
        plt.show()
    plt.close(fig)

    print(f"figure: {figure_path}")
    return {
        "q0": q0, "z0": z0, "zd": zd,
        "Cq": Cq, "Cq_rows": cq_rows, "Cq_columns": cq_columns,
        "Phi_z": Phi_z, "Phi_rows": phi_rows, "Phi_columns": phi_columns,
        "ranks": (int(rank_cq), int(rank_phi)),
        "qd_reference": qd_reference, "qd_natural": qd_natural,
        "velocity_difference": difference, "figure": str(figure_path),
    }


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", default="natural_jacobian.png", help="figure file")
    parser.add_argument("--show", action="store_true", help="also open a window")
    args = parser.parse_args()
    if not args.show:
        matplotlib.use("Agg")            # write the file only, never open a window
    main(args.output, show=args.show)

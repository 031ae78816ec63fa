"""docs/img/work_precision.png: work against precision (section 1), the chain's time per
step against its size (section 4), and the same for both backends (section 6)."""
from __future__ import annotations

import numpy as np

from pam2exu.backend.exudyn.system import DENSE_UP_TO

from .backends import Failure
from .backends import label as backend_label
from .measure import fit_exponent


def plot(path, grid, chain_rows, side=None):
    """Write the figure to ``path`` (matplotlib's Agg backend, chosen here: no display);
    ``side``: section 6's runs, a fourth panel."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FormatStrFormatter

    fig, axes = plt.subplots(2, 2, figsize=(14, 10))
    axes = axes.ravel()
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
    if side is not None:
        backends_panel(axes[3], side)
    else:
        axes[3].axis("off")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def backends_panel(ax, side):
    """Section 6: the chain's time per step against N on each backend."""
    styles = {"kinematic": "o-", "kinetostatic": "s--"}
    backends = list(dict.fromkeys(b for c in side["chain"] for b in c.runs))
    N_all = sorted({c.N for c in side["chain"]})
    for i, b in enumerate(backends):
        for analysis, style in styles.items():
            pts = [(c.N, c.runs[b].us) for c in side["chain"]
                   if c.analysis == analysis and not isinstance(c.runs.get(b), Failure)]
            if len(pts) < 2:
                continue
            N, y = (np.array(v, dtype=float) for v in zip(*pts))
            ax.loglog(N, y, style, color=f"C{i}",
                      label=f"{backend_label(b)}, {analysis} (N^{fit_exponent(N, y):.2f})")
    first = next((c.runs[b].us for c in side["chain"] for b in backends
                  if c.N == N_all[0] and not isinstance(c.runs.get(b), Failure)), None)
    if first:
        N = np.array(N_all, dtype=float)
        ax.loglog(N, first * N, "k-", alpha=0.25, lw=4, label="∝ N")
    ax.set_xticks(N_all)
    ax.set_xticklabels([str(n) for n in N_all])
    ax.minorticks_off()
    ax.set_xlabel("loops N")
    ax.set_ylabel("wall time per step [µs], end to end")
    ax.set_title("chain of N four-bar loops: the two backends")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)

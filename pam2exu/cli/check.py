"""``pam2exu check``: what ``run`` checks before the numerics (the model, the settings, the
plan of the run, the mobility), printed."""
from __future__ import annotations

import sys

from ..registry import BACKENDS


def add_parser(sub) -> None:
    check = sub.add_parser(
        "check", help="validate a model, print its mobility and elements",
        description="Everything run checks before solving: the model, the analysis settings, "
                    "the plan of the run (laws over the interval, sub-steps, work), the "
                    "mobility. Exit 2, with run's message, when the analysis needs every "
                    "degree of freedom driven and one is not.")
    check.add_argument("model", help="model file (TOML)")
    check.add_argument("--analysis", "-a", metavar="TYPE",
                       help="the analysis to check for (default: the model's)")
    check.add_argument("--t-end", type=float, metavar="T", help="end of the interval [s]")
    check.add_argument("--steps", type=int, metavar="N", help="number of intervals")
    check.add_argument("--backend", metavar="NAME",
                       help="what solves the positions: " + ", ".join(BACKENDS))


def command(args, warnings) -> int:
    """What ``run`` checks before the numerics (the model, the settings, the plan of the run,
    the mobility), printed; exit 2 with ``run``'s message when the analysis needs every
    degree of freedom driven and one is not."""
    import numpy as np

    from ..analyses.job import check_mobility, prepare
    from ..analyses.rank import require_driven
    job = prepare(args.model, args.analysis, args.t_end, args.steps, backend=args.backend)
    mech, kind = job.mech, job.analysis_type
    model = mech.model
    mob = check_mobility(job, mech.initial_q(), need_driven=False)
    print(f"model '{model.name}' ({args.model}): {len(mech.solids)} solids, "
          f"{len(mech.elements)} elements, {mech.nq} coordinates, "
          f"{mech.n_equations} constraint equations")
    print(f"degrees of freedom not driven: {mob.dof}"
          + (f" (solids free to move: {', '.join(mob.free_solids)})" if mob.dof else ""))
    print(f"redundant constraint equations: {mob.redundant}"
          + (f" (among {', '.join(mob.redundant_elements)})" if mob.redundant else ""))
    if np.isfinite(mob.condition):
        print(f"condition number of the constraint Jacobian at the initial guess: "
              f"{mob.condition:.3g}")
    steps = (len(job.times) - 1) // job.every
    print(f"analysis: {kind.name}, t = 0 … {job.times[-1]:g} s in {steps} steps"
          if not kind.at_start else f"analysis: {kind.name}, t = 0")
    if job.every > 1:
        name, moved, unit = job.motion
        print(f"'{name}' moves {moved:.3g} {unit} per step: positions are solved in "
              f"{job.every} sub-steps per step")
    if model.encoding != "utf-8":
        print("the file is not UTF-8: it was read as Windows-1252")
    from ..model.mistakes import input_warnings
    for problem in input_warnings(model):
        warnings.say(str(problem))
    print()
    width = max([len(e.name) for e in mech.elements] + [4])
    for e in mech.elements:
        anchors = ", ".join(str(a) for a in e.given_anchors())
        print(f"  {e.name:<{width}}  {e.type:<17} {anchors}")
    if kind.driven:
        sys.stdout.flush()
        require_driven(mech, mob, kind.name)
    return 0

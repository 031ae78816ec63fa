"""``pam2exu classify``: the atlas of a mechanism before its run (mobility, loops, Grashof
classes, assembly modes, dead points, transmission angles), printed or as JSON."""
from __future__ import annotations

import json

from ..registry import BACKENDS


def add_parser(sub) -> None:
    cls = sub.add_parser(
        "classify", help="the atlas of a mechanism: mobility, loops, Grashof, dead points",
        description="Before any run: the Grübler–Kutzbach count and the rank-based "
                    "mobility, the independent loops with their kind, Grashof class and "
                    "input range, the assembly modes at t = 0 and the one the guess "
                    "selects, the dead and change points the driver meets over the run, "
                    "and each loop's transmission angle (min, max). See docs/teaching.md.")
    cls.add_argument("model", help="model file (TOML)")
    cls.add_argument("--json", action="store_true", help="print one JSON object")
    cls.add_argument("--t-end", type=float, metavar="T", help="end of the interval [s]")
    cls.add_argument("--steps", type=int, metavar="N", help="number of intervals")
    cls.add_argument("--backend", metavar="NAME",
                     help="what follows the positions: " + ", ".join(BACKENDS))


def _range(values, unit: str) -> str:
    """An input's range in words."""
    if not values:
        return "none: the loop cannot close"
    if unit == "deg" and len(values) == 1 and values[0][1] - values[0][0] >= 360 - 1e-9:
        return "a full turn"
    mark = "°" if unit == "deg" else f" {unit}"
    return " or ".join(f"{lo:.4g}{mark} … {hi:.4g}{mark}" for lo, hi in values)


def lines(found: dict) -> list[str]:
    """The atlas (``Atlas.as_dict``) in words, one line each."""
    dof = found["mobility"]
    out = [f"model '{found['model']}' ({found['file']})",
           f"mobility: Grübler–Kutzbach {dof['gruebler']}, rank {dof['rank']} "
           f"({dof['meaning']}); actuated {dof['actuated']}, left free {dof['free']}"]
    for k, lp in enumerate(found["loops"], start=1):
        chain = " ".join(f"{s} –{j}–" for s, j in zip(lp["solids"], lp["joints"]))
        out.append(f"loop {k}: {chain} {lp['solids'][0]}: {lp['kind']}")
        if lp["grashof"]:
            out.append(f"  Grashof: {lp['grashof']['class']}, {lp['grashof']['condition']}")
        if lp["input"]:
            frame = ("the guide's direction" if lp["kind"] == "slider-crank" else
                     f"the line of {lp['reference']}'s pivots")
            what = (f"angle from {frame}" if lp["input_unit"] == "deg"
                    else "place along the guide from the foot of the crank's pivot")
            out.append(f"  input '{lp['input']}' ({what}): "
                       f"{_range(lp['input_range'], lp['input_unit'])}")
        mu = lp["transmission_angle"]
        if mu:
            out.append(f"  transmission angle (coupler '{lp['coupler']}', output "
                       f"'{lp['output']}'): min {mu['min']:.4g}° at t = {mu['t_min']:.6g} s, "
                       f"max {mu['max']:.4g}° at t = {mu['t_max']:.6g} s")
    modes = found["assembly_modes"]
    out.append(f"assembly modes at t = 0: {modes['count']}" + "".join(
        f"; loop {m['loop']}: {' / '.join(m['modes'])}, the guess selects {m['selected']}"
        for m in modes["loops"]))
    t0, t1 = found["interval"]
    if found["dead_points"]:
        for p in found["dead_points"]:
            out.append(f"{p['kind']} at t = {p['t']:.12g} s: loop {p['loop']}, "
                       f"joint '{p['joint']}'")
    else:
        out.append(f"no dead point or change point for t = {t0:g} … {t1:g} s")
    if found["note"]:
        out.append(f"note: {found['note']}")
    return out


def command(args, warnings) -> int:
    """Print the atlas of the model (``analyses.classify``), or its JSON object."""
    from ..analyses.classify import classify
    found = classify(args.model, backend=args.backend, t_end=args.t_end,
                     steps=args.steps).as_dict()
    print(json.dumps(found, indent=2, ensure_ascii=False) if args.json
          else "\n".join(lines(found)))
    return 0

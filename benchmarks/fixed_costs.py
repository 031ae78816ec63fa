"""The fixed cost of a short run, this checkout against an earlier commit, paired.

    python benchmarks/fixed_costs.py --against 3b66640            # 5 rounds
    python benchmarks/fixed_costs.py --against 3b66640 --rounds 1 --variants 20   # quick

A short run (100 steps) costs mostly what every run does once: the model, the formulation,
the checks, the reaction plan, the columns, not the steps. So does each variant of a study.
This measures, in fresh interpreters of the two checkouts in alternation (the order swapped
every round, the best of each kept), in milliseconds:

- the four-bar tolerance study's chunk (``examples/studies/four_bar_tolerance.toml``:
  kinetostatic, natural backend, its variants solved in one pass), per variant, from
  ``runner.run_variants`` (in-process, no executor);
- single 100-step kinetostatic runs of the four-bar and the slider-crank on the natural
  backend, and of the four-bar on Exudyn (best of 20 in each interpreter).

The earlier commit is checked out by ``git worktree`` in a temporary folder (removed after).
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: what one interpreter measures (its checkout on sys.path, its examples), as JSON
CHILD = r'''
import inspect, json, sys, time, warnings
from dataclasses import replace
warnings.simplefilter("ignore")
from pam2exu.analyses import run
from pam2exu.model import load
from pam2exu.studies import load_study
from pam2exu.studies.runner import nominal, payload, run_variants
variants = int(sys.argv[1])
study = replace(load_study("examples/studies/four_bar_tolerance.toml"), samples=variants,
                steps=100)
p, values = payload(study, nominal(study)[0]), study.variants()
if "values" in inspect.signature(run_variants).parameters:
    chunk = lambda a, b: run_variants(p, a, b, values[a:b])
else:                                   # before each chunk was sent its own rows
    chunk = lambda a, b: run_variants(p, a, b)
chunk(0, min(10, variants))
begin = time.perf_counter()
chunk(0, variants)
out = {"study, per variant": (time.perf_counter() - begin) / variants * 1e3}
for name, backend in (("four_bar", "natural"), ("slider_crank", "natural"),
                      ("four_bar", "exudyn")):
    model = load(f"examples/{name}.toml")
    run(model, "kinetostatic", steps=100, backend=backend)
    best = float("inf")
    for _ in range(20):
        begin = time.perf_counter()
        run(model, "kinetostatic", steps=100, backend=backend)
        best = min(best, time.perf_counter() - begin)
    out[f"{name}, kinetostatic, 100 steps, {backend}"] = best * 1e3
print(json.dumps(out))
'''


def measure_once(tree: Path, variants: int) -> dict[str, float]:
    """{what: ms} of one fresh interpreter of the checkout ``tree``."""
    done = subprocess.run([sys.executable, "-c", CHILD, str(variants)], cwd=tree,
                          env=dict(os.environ, PYTHONPATH=str(tree)), capture_output=True,
                          text=True, check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def paired(before: Path, after: Path, rounds: int, variants: int) -> tuple[dict, dict]:
    """({what: best ms} of ``before``, of ``after``): ``rounds`` rounds, the order swapped
    every round."""
    best: tuple[dict, dict] = ({}, {})
    for r in range(rounds):
        for side in ((0, 1) if r % 2 == 0 else (1, 0)):
            for key, ms in measure_once((before, after)[side], variants).items():
                best[side][key] = min(best[side].get(key, float("inf")), ms)
    return best


def table(before: dict, after: dict, rev: str) -> list[str]:
    """The Markdown rows: what, at ``rev``, now, now / then."""
    rows = [f"| what | at {rev} | now | now / then |", "|---|---|---|---|"]
    for key, then in before.items():
        rows.append(f"| {key} | {then:.2f} ms | {after[key]:.2f} ms | "
                    f"{after[key] / then:.2f}× |")
    return rows


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--against", required=True, help="the earlier commit")
    parser.add_argument("--rounds", type=int, default=5, help="rounds (default 5)")
    parser.add_argument("--variants", type=int, default=200,
                        help="the study chunk's variants (default 200)")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="pam2exu-fixed-") as folder:
        earlier = Path(folder) / "earlier"
        subprocess.run(["git", "worktree", "add", "--detach", "-q", str(earlier),
                        args.against], cwd=ROOT, check=True)
        try:
            before, after = paired(earlier, ROOT, args.rounds, args.variants)
        finally:
            subprocess.run(["git", "worktree", "remove", "--force", str(earlier)], cwd=ROOT,
                           check=False)
    print("\n".join(table(before, after, args.against)))
    print(f"load averages {', '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()

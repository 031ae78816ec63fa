"""A study variant's instructions part by part: where a chunk of the four-bar tolerance
study spends them, counted by valgrind's callgrind (docs/performance.md, "What is left").

    python benchmarks/stages.py --variants 20        # ~30 min on a 2-core machine

The chunk (``examples/studies/four_bar_tolerance.toml``, 100 steps, natural backend, one
pass) runs once to warm up, then once counted. Each part is a function of the package
(``PARTS``); on entering and on leaving any of them, a client request dumps callgrind's
counters under the name of the part that was running until then, the innermost of them
(``other`` outside all). Each part's count is therefore its own, without the parts it
calls: the one pass's count leaves out the formulations and variant models made in it.
Divided by the variants, the parts add up to the chunk's instructions per variant.

Needs what ``instructions.py`` needs (valgrind with its headers, a C compiler). The
pass's and the condition references' work per chunk weighs less per variant in a larger
chunk; the study's own chunks hold 125–500 variants.
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from collections import Counter
from pathlib import Path

if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.instructions import ROOT, client_library, totals  # noqa: E402

#: (module, function or Class.method, the part's name) in the order of the table
PARTS = (
    ("pam2exu.studies.batch", "answered", "the one pass"),
    ("pam2exu.studies.runner", "made_variant", "the variant's model"),
    ("pam2exu.backend.natural.formulation", "Formulation.__init__", "the formulations"),
    ("pam2exu.analyses.job", "prepare", "the job"),
    ("pam2exu.analyses.job", "warn_input", "the input warnings"),
    ("pam2exu.analyses.job", "check_mobility", "the mobility check"),
    ("pam2exu.analyses.branch", "motion", "the motion's own part"),
    ("pam2exu.analyses.positions", "positions", "the positions"),
    ("pam2exu.analyses.positions", "rates", "the rates"),
    ("pam2exu.analyses.rank", "largest_condition", "the condition check"),
    ("pam2exu.analyses.checks", "check_residual", "the residual check"),
    ("pam2exu.analyses.kinetostatic", "inverse_dynamics", "the inverse dynamics' own part"),
    ("pam2exu.backend.natural.population", "Group._make", "the shared reactions"),
    ("pam2exu.backend.natural.reactions", "Plan.__init__", "the reactions' plans"),
    ("pam2exu.analyses.job", "collect", "the table"),
    ("pam2exu.studies.runner", "reduce_run", "the reductions"),
)
OUTSIDE = "other"

#: the counted process (this checkout on sys.path): argv = client library, variants
CHILD = r'''
import ctypes, gc, importlib, sys, warnings
from dataclasses import replace
warnings.simplefilter("ignore")
client = ctypes.CDLL(sys.argv[1])
n = int(sys.argv[2])
from benchmarks.stages import OUTSIDE, PARTS
from pam2exu.studies import load_study
from pam2exu.studies.runner import nominal, payload, run_variants
running, counting, entered = [OUTSIDE], [False], set()

def part(f, name):
    def counted(*args, **kwargs):
        if counting[0]:
            client.pam2exu_dump(running[-1].encode())
        running.append(name)
        entered.add(name)
        try:
            return f(*args, **kwargs)
        finally:
            if counting[0]:
                client.pam2exu_dump(name.encode())
            running.pop()
    return counted

for module, function, name in PARTS:       # every module's reference to the function
    mod = importlib.import_module(module)
    owner, _, attr = function.rpartition(".")
    if owner:
        cls = getattr(mod, owner)
        setattr(cls, attr, part(cls.__dict__[attr], name))
        continue
    original = getattr(mod, attr)
    for other in list(sys.modules.values()):
        if getattr(other, "__name__", "").startswith("pam2exu") and \
                getattr(other, attr, None) is original:
            setattr(other, attr, part(original, name))
client.pam2exu_start()
study = replace(load_study("examples/studies/four_bar_tolerance.toml"), samples=n, steps=100)
p, values = payload(study, nominal(study)[0]), study.variants()
run_variants(p, 0, n, values[:n])          # warm: parsed, made, cached
gc.collect()
gc.disable()
client.pam2exu_zero()
counting[0] = True
run_variants(p, 0, n, values[:n])
client.pam2exu_dump(OUTSIDE.encode())
print(sorted({name for _, _, name in PARTS} - entered))   # parts never entered
'''


def table(parts: Counter, variants: int) -> list[str]:
    """The parts as Markdown rows, largest first: M instructions a variant and share."""
    whole = sum(parts.values())
    lines = [f"{whole / variants / 1e6:.2f} M instructions a variant ({variants} variants)",
             "| part | M instructions a variant | share |", "|---|---|---|"]
    for name, count in parts.most_common():
        lines.append(f"| {name} | {count / variants / 1e6:.2f} | {100 * count / whole:.0f} % |")
    return lines


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--variants", type=int, default=20,
                        help="the chunk's variants (default 20; more: the counted run and "
                             "its dumps take longer)")
    args = parser.parse_args(argv)
    if args.variants < 1:
        parser.error("--variants must be at least 1")
    with tempfile.TemporaryDirectory(prefix="pam2exu-stages-") as tmp:
        folder = Path(tmp)
        library, out = client_library(folder), folder / "callgrind.stages"
        done = subprocess.run(
            ["valgrind", "--tool=callgrind", "--instr-atstart=no", "--dump-instr=no",
             f"--callgrind-out-file={out}", sys.executable, "-c", CHILD, str(library),
             str(args.variants)],
            cwd=ROOT, env=dict(os.environ, PYTHONPATH=str(ROOT), PYTHONHASHSEED="0"),
            capture_output=True, text=True)
        if done.returncode:
            raise SystemExit(f"the counted run failed:\n{done.stderr[-3000:]}")
        missed = done.stdout.strip().splitlines()[-1]
        if missed != "[]":
            print(f"parts never entered (PARTS no longer names what the run calls): {missed}")
        print("\n".join(table(Counter(totals(out)), args.variants)))


if __name__ == "__main__":
    main()

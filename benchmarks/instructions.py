"""Instructions, not seconds: what a run costs counted by valgrind's callgrind, this
checkout against an earlier commit.

    python benchmarks/instructions.py --against 19ef917            # every workload
    python benchmarks/instructions.py --against 19ef917 --only study
    python benchmarks/instructions.py --against 19ef917 --only clearance   # not in "every"

A 2-core machine shared with other jobs times the same run a fifth apart from one minute to
the next (docs/performance.md); a change of a few percent is lost in that. Callgrind
counts the instructions the processor executes, the same count for the same program and
inputs whatever else the machine does, so a few percent shows. What it does not see:
memory stalls (an instruction that waits for memory counts once), the kernel's work (page
faults of new arrays) and the vector width of a loop. ``--cache`` simulates the caches too
and counts KCachegrind's estimate of the cycles (Ir + 10 × first-level misses + 100 ×
last-level misses): closer to the time of a change that moves memory, still not the time
itself (it gave −1.8 % for the natural kinematic run at 100,000 steps when q was laid out a
column per coordinate, where alternated wall-clock pairs gave about −10 %: a strided
numpy loop costs more than its misses say). A change that moves memory rather than
arithmetic needs its wall-clock pair as well (``fixed_costs.py``, ``targets.py``).

Each checkout runs in one process under ``valgrind --tool=callgrind`` with the
instrumentation started only after the imports (``--instr-atstart=no``: the imports run
uninstrumented, ~5× slower rather than ~50×). Every workload runs once to warm up (the
model parsed, the caches made; a long run's warm-up is 1,000 steps), then once counted: the counters zeroed before it and dumped
after it (callgrind's client requests, from a small C library built here with the machine's
C compiler and valgrind's ``callgrind.h``). ``PYTHONHASHSEED=0``: the same string hashes,
the same sets' orders, in both. Python's cyclic garbage collector is paused during the
counted run (after a full pass): its passes fall where the number of allocations puts them,
which differs between two checkouts for reasons that are not the code measured (a longer
path); the counts leave it out.

The workloads, and what each count is divided by:

- ``study``: the four-bar tolerance study's chunk (``examples/studies/four_bar_tolerance
  .toml``: kinetostatic, natural backend, variants in one pass), per variant;
- ``short``: a 100-step kinetostatic run of the four-bar, natural backend and Exudyn, per
  run;
- ``long``: 100,000-step kinematic and kinetostatic runs of the four-bar, natural backend,
  per step.

Needs valgrind (Debian's package ``valgrind``, with its headers) and a C compiler; takes
~2 minutes a checkout for every workload. The earlier commit is checked out by ``git
worktree``, and this checkout's files copied, in one temporary folder (removed after).
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: the client requests, as a C library that ``ctypes`` loads
CLIENT = r'''
#include <valgrind/callgrind.h>
void pam2exu_start(void) { CALLGRIND_START_INSTRUMENTATION; }
void pam2exu_zero(void) { CALLGRIND_ZERO_STATS; }
void pam2exu_dump(const char *name) { CALLGRIND_DUMP_STATS_AT(name); }
'''

#: what one process counts (its checkout on sys.path, its examples); prints the workloads'
#: divisors as JSON
CHILD = r'''
import ctypes, gc, json, sys, warnings
from dataclasses import replace
warnings.simplefilter("ignore")
client = ctypes.CDLL(sys.argv[1])
only = set(sys.argv[2].split(","))
from pam2exu.analyses import run
from pam2exu.model import load
from pam2exu.studies import load_study
from pam2exu.studies.runner import nominal, payload, run_variants
client.pam2exu_start()


def chunk_of(path, n):
    """A worker's task on the first n variants of the study at path, 100 steps."""
    study = replace(load_study(path), samples=n, steps=100)
    p, values = payload(study, nominal(study)[0]), study.variants()
    return lambda: run_variants(p, 0, n, values[:n])


work = []                                   # (name, divisor, counted run, warm-up)
if "study" in only:
    chunk = chunk_of("examples/studies/four_bar_tolerance.toml", 100)
    work.append(("study, four-bar tolerance, per variant", 100, chunk, chunk))
if "clearance" in only:
    chunk = chunk_of("examples/studies/locomotive_clearance.toml", 6)
    work.append(("clearance study, locomotive, 100 steps, per variant", 6, chunk, chunk))
model = load("examples/four_bar.toml")
if "short" in only:
    for backend in ("natural", "exudyn"):
        short = lambda b=backend: run(model, "kinetostatic", steps=100, backend=b)
        work.append((f"four-bar kinetostatic, 100 steps, {backend}, per run", 1, short, short))
if "long" in only:
    for analysis in ("kinematic", "kinetostatic"):
        work.append((f"four-bar {analysis}, 100,000 steps, natural, per step", 100_000,
                     lambda a=analysis: run(model, a, steps=100_000, backend="natural"),
                     lambda a=analysis: run(model, a, steps=1000, backend="natural")))
divisors = {}
for name, divisor, job, warm in work:
    warm()                                  # parsed, made, cached
    gc.collect()
    gc.disable()                            # (a pass of the collector falls where the
    client.pam2exu_zero()                   # checkout's own allocations put it)
    job()
    client.pam2exu_dump(name.encode())
    gc.enable()
    divisors[name] = divisor
print(json.dumps(divisors))
'''


def client_library(folder: Path) -> Path:
    """The client requests' library, built in ``folder``."""
    compiler = shutil.which("cc") or shutil.which("gcc")
    if compiler is None or shutil.which("valgrind") is None:
        raise SystemExit("benchmarks/instructions.py needs valgrind and a C compiler "
                         "(Debian: apt-get install valgrind gcc)")
    source, library = folder / "client.c", folder / "client.so"
    source.write_text(CLIENT)
    subprocess.run([compiler, "-shared", "-fPIC", "-O1", "-o", str(library), str(source)],
                   check=True)
    return library


#: how a dump made by a client request names it
TRIGGER = "desc: Trigger: Client Request: "


def copied(dest: Path) -> None:
    """This checkout's files as they are now (tracked and new, not ignored) copied to
    ``dest``: both counted checkouts at paths of the same length (a longer path shifts
    every allocation after it, and the allocator's own instructions with them: 0.8 % of a
    100-step run, measured between two copies of one commit)."""
    listed = subprocess.run(["git", "ls-files", "-co", "--exclude-standard", "-z"], cwd=ROOT,
                            capture_output=True, check=True).stdout.decode().split("\0")
    for name in filter(None, listed):
        source = ROOT / name
        if source.is_file():
            (dest / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, dest / name)


def totals(out: Path) -> dict[str, int]:
    """{dump's trigger name: its count, summed over the dumps of that name} of the
    callgrind files ``out``.*: instructions, or with the cache simulated the estimated
    cycles (``estimated``)."""
    found = {}
    for path in sorted(out.parent.glob(out.name + ".*")):
        name = events = counts = None
        for line in path.read_text(errors="replace").splitlines():
            if line.startswith(TRIGGER):
                name = line[len(TRIGGER):]
            elif line.startswith("events: "):
                events = line.split()[1:]
            elif line.startswith(("totals: ", "summary: ")):
                counts = [int(v) for v in line.split()[1:]]
        if name is not None and counts is not None:
            found[name] = found.get(name, 0) + estimated(dict(zip(events or ["Ir"], counts)))
    return found


def estimated(events: dict[str, int]) -> int:
    """Ir alone; with the cache simulated (callgrind's ``--cache-sim=yes``), the cycles
    KCachegrind estimates: Ir + 10 × first-level misses + 100 × last-level misses."""
    first = sum(events.get(k, 0) for k in ("I1mr", "D1mr", "D1mw"))
    last = sum(events.get(k, 0) for k in ("ILmr", "DLmr", "DLmw"))
    return events["Ir"] + 10 * first + 100 * last


def count(tree: Path, library: Path, only: list[str], folder: Path, cache: bool = False
          ) -> dict[str, float]:
    """{workload: instructions (``cache``: estimated cycles) per unit} of the checkout
    ``tree``."""
    out = folder / f"callgrind.{tree.name}"
    done = subprocess.run(
        ["valgrind", "--tool=callgrind", "--instr-atstart=no", "--dump-instr=no",
         f"--cache-sim={'yes' if cache else 'no'}",
         f"--callgrind-out-file={out}", sys.executable, "-c", CHILD, str(library),
         ",".join(only)],
        cwd=tree, env=dict(os.environ, PYTHONPATH=str(tree), PYTHONHASHSEED="0"),
        capture_output=True, text=True)
    if done.returncode:
        raise SystemExit(f"{tree}: the counted run failed:\n{done.stderr[-3000:]}")
    divisors = json.loads(done.stdout.strip().splitlines()[-1])
    counted = totals(out)
    return {name: counted[name] / divisor for name, divisor in divisors.items()}


def table(before: dict, after: dict, rev: str, unit: str = "instructions") -> list[str]:
    """The comparison as Markdown rows."""
    lines = [f"| what ({unit}) | {rev} | this checkout | ratio |", "|---|---|---|---|"]
    for key, old in before.items():
        new = after[key]
        lines.append(f"| {key} | {old:,.0f} | {new:,.0f} | {new / old:.3f}× |")
    return lines


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--against", required=True, help="the earlier commit")
    parser.add_argument("--cache", action="store_true",
                        help="simulate the caches and count estimated cycles (Ir + 10 × "
                             "first-level misses + 100 × last-level misses; ~2× slower)")
    parser.add_argument("--only", default="study,short,long",
                        help="the workloads, comma-separated: study, short, long, "
                             "clearance (a clearance study's chunk: ~5 min under "
                             "valgrind; default study, short, long)")
    args = parser.parse_args(argv)
    only = [w.strip() for w in args.only.split(",") if w.strip()]
    unknown = set(only) - {"study", "short", "long", "clearance"}
    if unknown:
        parser.error(f"unknown workload(s) {', '.join(sorted(unknown))}: "
                     "choose among study, short, long, clearance")
    with tempfile.TemporaryDirectory(prefix="pam2exu-instructions-") as tmp:
        folder = Path(tmp)
        library = client_library(folder)
        earlier, now = folder / "before", folder / "after"      # paths of one length
        copied(now)
        subprocess.run(["git", "worktree", "add", "--detach", "-q", str(earlier),
                        args.against], cwd=ROOT, check=True)
        try:
            before = count(earlier, library, only, folder, args.cache)
            after = count(now, library, only, folder, args.cache)
        finally:
            subprocess.run(["git", "worktree", "remove", "--force", str(earlier)], cwd=ROOT,
                           check=False)
    print("\n".join(table(before, after, args.against,
                           "estimated cycles" if args.cache else "instructions")))


if __name__ == "__main__":
    main()

"""A study on 2 workers against 1, paired fairly on a shared machine (issue 25's row
"workers" of benchmarks/targets.py, docs/performance.md "Studies on 2 workers").

    python benchmarks/workers.py --pool-start 3    # a local pool's start, 3 rounds

- ``run_fresh``: ``studies.run_on`` in a fresh interpreter, so every run starts its executor
  cold, as ``pam2exu study`` does;
- ``pool_ready``: the seconds from opening a local pool of 2 until both workers ran a
  pam2exu task, opened at once or after the study's checks as ``pam2exu study`` does;
- ``cores_free``: the cores two processes get at once on this machine now, the most a pool
  of 2 can gain then;
- ``sending``: what sending a study's chunks costs a Dask cluster when each chunk carries
  every variant's values (as before the engine's ``rows``) against its own rows only;
- ``timeline``: one fresh run as ``run_fresh``'s, with when each chunk starts and ends in
  its worker (and the CPU it took), when the parent's nominal run, each chunk's arrival and
  its part's writing happen, and the parent's CPU time at each.

    python benchmarks/workers.py --pool-start 0 --sending 1000000
    python benchmarks/workers.py --pool-start 0 --timeline 2
"""
from __future__ import annotations

import argparse
import pickle
import subprocess
import sys
import tempfile
import time
from pathlib import Path

if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402

from benchmarks.measure import ROOT  # noqa: E402
from benchmarks.studies import (ExecutorRow, load_average, same_table,  # noqa: E402
                                workers_see_this_clone)


#: ``run_fresh``'s process: the study (a pickle) on the executor of ``workers``, timed from
#: asking for the executor until it is closed, the result's table and times pickled back
FRESH = """
import pickle, sys, time
import scipy.stats, pam2exu.analyses, pam2exu.backend.natural    # what any study's process has
from pam2exu.studies.execute import open_executor
from pam2exu.studies.runner import study as run_study
if __name__ == "__main__":
    study, workers, out = pickle.load(open(sys.argv[1], "rb")), int(sys.argv[2]), sys.argv[3]
    begin = time.perf_counter()
    with open_executor(workers) as executor:
        ready, cpu = time.perf_counter(), time.process_time()
        result = run_study(study, executor=executor, workers=workers)
        done, cpu = time.perf_counter(), time.process_time() - cpu
    closed = time.perf_counter()
    pickle.dump({"start": ready - begin, "seconds": done - ready, "stop": closed - done,
                 "cpu": cpu, "table": result.table}, open(out, "wb"))
"""


def run_fresh(label: str, workers: int, study, reference=None):
    """``run_on`` in a fresh interpreter (``FRESH``): every run starts its executor cold,
    as ``pam2exu study`` does, whatever ran before it in this process (a process pool's
    fork server, once started, serves every later pool of its process with the study's
    modules imported). What this process needs whichever executor runs the variants
    (pam2exu's studies, analyses and natural backend, scipy.stats for the draws) is
    imported before the clock starts. ``ExecutorRow.total`` is the time from asking for the
    executor until it is closed."""
    row = ExecutorRow(label, study.samples, study.steps, workers)
    before = load_average()
    table = None
    with tempfile.TemporaryDirectory(prefix="pam2exu-fresh-") as folder:
        given, back = Path(folder, "study.pkl"), Path(folder, "out.pkl")
        given.write_bytes(pickle.dumps(study))
        done = subprocess.run([sys.executable, "-c", FRESH, str(given), str(workers),
                               str(back)], capture_output=True, text=True, cwd=ROOT)
        if done.returncode != 0 or not back.exists():
            row.failure = (done.stderr.strip().splitlines() or ["no output"])[-1]
        else:
            out = pickle.loads(back.read_bytes())
            row.start, row.seconds, row.stop, row.cpu = (out[k] for k in ("start", "seconds",
                                                                           "stop", "cpu"))
            table = out["table"]
            row.ok = int(np.sum(table["status"] == "ok"))
            if reference is not None:
                row.identical = same_table(table, reference)
    row.load = (before, load_average())
    return row, table


#: ``pool_ready``'s process: (a) a pool opened at once, (b) as ``pam2exu study`` does, the
#: workers' server warmed, the study's checks run, then the pool opened; the seconds from
#: opening the pool until both workers ran a pam2exu task
READY = """
import sys, time, warnings
from concurrent.futures import wait
from dataclasses import replace
from pam2exu.studies import execute, load_study      # what pam2exu study has imported then
from pam2exu.studies.runner import checked, warned
if __name__ == "__main__":
    warnings.simplefilter("ignore")
    if sys.argv[1] == "cli":
        execute.warm(2)
        checked(replace(load_study(sys.argv[2]), samples=8))
    begin = time.perf_counter()
    with execute.open_executor(2) as pool:
        wait([pool.submit(time.sleep, 0.3) for _ in range(2)])   # both workers started
        wait([pool.submit(warned, []) for _ in range(2)])
        print(time.perf_counter() - begin - 0.3)
"""


def pool_ready(after_checks: bool) -> float:
    """Seconds from opening a local pool of 2 until both its workers ran a pam2exu task, in
    a fresh interpreter (``READY``): at once (``after_checks`` False: the server's imports
    all on the way), or after the checks of STUDY_FILE's study as ``pam2exu study`` runs
    them (with their first imports), its workers' server warmed before them
    (``execute.warm``)."""
    study = ROOT / "examples" / "studies" / "four_bar_tolerance.toml"
    done = subprocess.run([sys.executable, "-c", READY, "cli" if after_checks else "api",
                           str(study)], capture_output=True, text=True, cwd=ROOT, check=True)
    return float(done.stdout.split()[-1])


def timed_variants(payload, start, stop, values):
    """``runner.run_variants`` with a column ``TIMED`` (on every row: the worker's process
    id, its clock at the chunk's start and end, the chunk's CPU time), for ``timeline``."""
    import os
    from pam2exu.studies.runner import run_variants
    begin, cpu = time.time(), time.process_time()
    out = run_variants(payload, start, stop, values)
    out[TIMED] = np.array([[os.getpid(), begin, time.time(), time.process_time() - cpu]]
                          * (stop - start))
    return out


TIMED = "__timed__"
#: ``timeline``'s process: ``FRESH``'s study with ``timed_variants`` as the task; the
#: parent's events (clock, its CPU time, what) and the workers' printed in time order
TIMELINE = """
import sys, time
import scipy.stats, pam2exu.analyses, pam2exu.backend.natural
from dataclasses import replace
from pam2exu.studies import execute, load_study, runner
from benchmarks.workers import TIMED, timed_variants
events = []
def mark(what):
    events.append((time.time(), time.process_time(), what))
def wrapped(fn, before, after=None):
    def call(*args, **kwargs):
        mark(before(*args))
        out = fn(*args, **kwargs)
        if after:
            mark(after(*args))
        return out
    return call
def arrived(columns, start, stop, *rest):
    pid, begin, end, cpu = columns.pop(TIMED)[0]
    events.append((begin, None, f"worker {int(pid)} begins {start}-{stop}"))
    events.append((end, None, f"worker {int(pid)} ends {start}-{stop} ({cpu:.2f} s CPU)"))
    return f"arrived {start}-{stop}"
if __name__ == "__main__":
    study = replace(load_study(sys.argv[1]), samples=int(sys.argv[3]))
    workers = int(sys.argv[2])
    runner.nominal = wrapped(runner.nominal, lambda s: "nominal run begins",
                             lambda s: "nominal run ends")
    run_chunks = runner.run_chunks
    runner.run_chunks = lambda task, *a, **k: (mark("chunks begin"),
                                               run_chunks(timed_variants, *a, **k))[1]
    execute.checked_columns = wrapped(execute.checked_columns, arrived)
    execute.write_part = wrapped(execute.write_part, lambda f, a, b, *r: f"writing {a}-{b}",
                                 lambda f, a, b, *r: f"written {a}-{b}")
    print("chunks", runner.chunks_of(runner.prepared(study), workers))
    mark("open the executor")
    with execute.open_executor(workers) as executor:
        runner.study(study, executor=executor, workers=workers)
        mark("study done")
    mark("executor closed")
    zero = events[0][0]
    for at, cpu, what in sorted(events, key=lambda e: e[0]):
        print(f"{at - zero:7.3f} s  " + ("" if cpu is None else f"parent CPU {cpu:6.2f} s  ")
              + what)
"""


def timeline(workers: int, variants: int = 2000) -> str:
    """The events of one fresh run of STUDY_FILE's study (``TIMELINE``), as printed."""
    study = ROOT / "examples" / "studies" / "four_bar_tolerance.toml"
    done = subprocess.run([sys.executable, "-c", TIMELINE, str(study), str(workers),
                           str(variants)], capture_output=True, text=True, cwd=ROOT,
                          check=True)
    return done.stdout


def spin(seconds: float) -> float:
    """Wall time [s] this process takes to burn ``seconds`` of CPU in Python."""
    cpu, begin = time.process_time(), time.perf_counter()
    while time.process_time() - cpu < seconds:
        pass
    return time.perf_counter() - begin


def cores_free(seconds: float = 2.0) -> float:
    """The cores two processes get at once on this machine now: 2 × (the wall time one
    process takes to burn ``seconds`` of CPU) / (the wall time two take at once, the
    slower): 2.0 on an idle 2-core machine, 1.0 when other work leaves only one. A pool of
    2 workers cannot be more times faster than this (beside the workers' row)."""
    from concurrent.futures import ProcessPoolExecutor
    from multiprocessing import get_context
    with ProcessPoolExecutor(2, mp_context=get_context("spawn")) as pool:
        list(pool.map(spin, [0.05, 0.05]))                  # both started
        one = pool.submit(spin, seconds).result()
        two = max(pool.map(spin, [seconds, seconds]))
    return 2 * one / two


def values_sum(payload, start, stop, rows=None):
    """A chunk's task that only reads its variants' values: from every variant's values in
    the payload (``rows`` None), or from its own rows."""
    mine = payload["values"][start:stop] if rows is None else rows
    return {"sum": mine.sum(axis=1)}


def sending(variants: int, chunks: int = 100, parameters: int = 3) -> dict:
    """{way: seconds} to run ``chunks`` chunks of 400 variants of a study of ``variants``
    variants through ``execute.run_chunks`` on a Dask LocalCluster of 2 workers, each chunk
    sent every variant's values in its payload ("whole") or its own rows ("own rows")."""
    import warnings
    from pam2exu.studies.execute import open_executor, run_chunks
    values = np.random.default_rng(1).random((variants, parameters))
    todo = [(400 * k, 400 * (k + 1)) for k in range(chunks)]
    out = {}
    with open_executor(dask_local=2) as client, tempfile.TemporaryDirectory() as folder:
        run_chunks(values_sum, {}, todo[:2], Path(folder, "warm"), client, rows=values,
                   progress=False)
        for way in ("whole", "own rows"):
            begin = time.perf_counter()
            with warnings.catch_warnings():          # Dask's "large graph" warning
                warnings.simplefilter("ignore")
                if way == "whole":
                    run_chunks(values_sum, {"values": values}, todo, Path(folder, way),
                               client, progress=False)
                else:
                    run_chunks(values_sum, {}, todo, Path(folder, way), client, rows=values,
                               progress=False)
            out[way] = time.perf_counter() - begin
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--pool-start", type=int, default=3, metavar="ROUNDS",
                        help="rounds of pool_ready, each way (default 3)")
    parser.add_argument("--sending", type=int, default=0, metavar="VARIANTS",
                        help="time sending 100 chunks of a study of VARIANTS variants to a "
                             "Dask cluster, whole values against each chunk's own rows")
    parser.add_argument("--timeline", type=int, default=0, metavar="WORKERS",
                        help="one fresh run of the four-bar tolerance study on WORKERS "
                             "workers: when each chunk starts and ends, what the parent does")
    args = parser.parse_args(argv)
    if args.timeline:
        workers_see_this_clone()
        print(f"load {load_average():.2f}")
        print(timeline(args.timeline), end="")
    if args.sending:
        took = sending(args.sending)
        print(f"100 chunks of a {args.sending:,}-variant study on a Dask LocalCluster of 2: "
              f"every variant's values in each chunk {took['whole']:.2f} s, each chunk's own "
              f"rows {took['own rows']:.2f} s; load {load_average():.2f}")
    workers_see_this_clone()
    for _ in range(args.pool_start):
        print(f"pool of 2 ready: opened at once {pool_ready(False):.2f} s, after the checks "
              f"{pool_ready(True):.2f} s; load {load_average():.2f}; cores free "
              f"{cores_free():.2f}")


if __name__ == "__main__":
    main()

"""Section 9: studies, variants per second (issue 24).

    python benchmarks/studies.py            # measures and replaces section 9 of docs/performance.md
    python benchmarks/studies.py --quick    # 40 variants × 20 steps, to a temporary directory
    python benchmarks/studies.py --variants 200 --steps 50    # another size, temporary directory

The four-bar's kinetostatic study (examples/four_bar.toml; the crank's, the coupler's and the
rocker's lengths uniform within ± 0.1 mm, pylinkage's kind of tolerance; the motor torque and
the joint B's force, reduced to absmax and rms) of ``Plan.study_variants`` variants (2,000)
× ``Plan.study_steps`` steps (100), run by ``pam2exu.study`` on three executors: in this
process, a local pool of 2 worker processes, and a Dask ``LocalCluster`` of 2 single-threaded
worker processes. Each is one run: wall time from asking for the executor to the result,
with the executor's start (a pool starts its processes lazily, inside the study; a
LocalCluster before it) and stop apart; variants per second and time per variant-step
(wall / (variants × steps)) of the study proper; whether its table is bit-identical to the
in-process one. Beside them, pylinkage's Monte-Carlo ``analyze_tolerance`` on the same four-bar
(the same three lengths, uniform within ± 0.1 mm; the coupler–rocker joint's path), measured
in the same run where pylinkage imports (best of ``PYLINKAGE_REPEATS``), at the study's steps
and at 20 steps, else the figure issue 24 quotes, said so. And where one variant's time goes:
the model from its text with the variant's values, the run (its Exudyn part), the reduction,
each the best of ``ANATOMY_REPEATS`` in this process.

pylinkage is not a dependency of pam2exu: to measure it, run this file with an interpreter
that has it, e.g. a virtual environment made with ``--system-site-packages`` and
``pip install pylinkage`` in it. The worker processes import this clone's pam2exu (the
repository root is put first on ``PYTHONPATH`` for them).

``measure(plan)`` is section 9 of benchmarks/speed_vs_error.py; ``study_section`` writes its
Markdown between ``BEGIN`` and ``END``, which this file's own run replaces in an existing
docs/performance.md (the rest of the page stays as the last full run wrote it).
"""
from __future__ import annotations

import argparse
import dataclasses
import datetime
import importlib.metadata
import math
import os
import sys
import tempfile
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path

if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402

import pam2exu  # noqa: E402
from pam2exu.analyses import run  # noqa: E402
from pam2exu.studies import loads_study  # noqa: E402
from pam2exu.studies.execute import open_executor  # noqa: E402
from pam2exu.studies.parameters import varied  # noqa: E402
from pam2exu.studies.reduce import reduce_run  # noqa: E402
from pam2exu.studies.runner import study as run_study  # noqa: E402

from benchmarks.dynamics import replace_section  # noqa: E402
from benchmarks.measure import FULL, QUICK, ROOT, log, machine  # noqa: E402

BEGIN = ("<!-- section 9: written by benchmarks/studies.py (python benchmarks/studies.py "
         "rewrites it alone) -->")
END = "<!-- end of section 9 -->"
#: the four-bar's link lengths [m] (examples/four_bar.toml) and the tolerance of each
CRANK, COUPLER, ROCKER, GROUND = 0.1, 0.35, 0.3, 0.4
TOL = 1e-4
#: the study: what each variant runs (``{variants}``, ``{steps}`` filled in)
STUDY = """
[study]
model = "four_bar.toml"
analysis = "kinetostatic"
t_end = 1.0
steps = {steps}
method = "monte_carlo"
samples = {variants}
seed = 1
outputs = ["motor.Mz", "B.F*"]
reduce = ["absmax", "rms"]
""" + "".join(f'\n[[parameter]]\nname = "{name}"\ndistribution = "uniform"\ntol = {TOL}\n'
              for name in ("crank.A.x", "coupler.B.x", "rocker.B.x"))
#: the executors: (label, workers, Dask LocalCluster workers)
EXECUTORS = (("in-process", 1, None), ("2 worker processes", 2, None),
             ("Dask LocalCluster(2)", 2, 2))
#: pylinkage's throughput quoted by issue 24 (samples/s of 20 position steps), used when it
#: does not import here
QUOTED = (1800.0, 20)
PYLINKAGE_REPEATS = 3
ANATOMY_REPEATS = 10
#: the anatomy's second run has this many times the study's steps (the cost per step and
#: the fixed cost of a run, from the two)
LONGER = 10


@dataclass
class ExecutorRow:
    """One executor's run of the study (``failure``: the message of a run that raised)."""

    executor: str
    variants: int
    steps: int
    workers: int = 1
    dask: bool = False
    seconds: float = math.nan        # the study, the executor running
    cpu: float = math.nan            # this process's CPU time meanwhile
    start: float = math.nan          # asking for the executor until it is there
    stop: float = math.nan           # closing it
    ok: int = 0
    identical: bool | None = None    # table bit for bit the in-process one's
    load: tuple = ()                 # 1-minute load average before and after
    failure: str | None = None

    @property
    def per_second(self) -> float:
        return self.variants / self.seconds

    @property
    def total(self) -> float:
        """From asking for the executor until it is closed [s]."""
        return self.start + self.seconds + self.stop

    @property
    def us_per_variant_step(self) -> float:
        return 1e6 * self.seconds / (self.variants * self.steps)

    @property
    def cpu_us_per_variant_step(self) -> float:
        return 1e6 * self.cpu / (self.variants * self.steps)


@dataclass
class PylinkageRow:
    """pylinkage's ``analyze_tolerance``: measured here (``version``), or the quoted figure."""

    steps: int
    samples: int
    seconds: float
    version: str | None = None
    cpu: float = math.nan            # this process's CPU time, the best of the repeats

    @property
    def cpu_us_per_sample_step(self) -> float:
        return 1e6 * self.cpu / (self.samples * self.steps)

    @property
    def per_second(self) -> float:
        return self.samples / self.seconds

    @property
    def us_per_sample_step(self) -> float:
        return 1e6 * self.seconds / (self.samples * self.steps)


@dataclass
class Measured:
    variants: int
    steps: int
    rows: list = field(default_factory=list)          # ExecutorRow
    pylinkage: list = field(default_factory=list)     # PylinkageRow
    pylinkage_note: str = ""
    anatomy: dict = field(default_factory=dict)       # part -> seconds of one variant
    info: dict = field(default_factory=dict)


def the_study(variants: int, steps: int):
    return loads_study(STUDY.format(variants=variants, steps=steps),
                       source="benchmarks/studies.py", folder=ROOT / "examples")


def best_cpu_of(fn, repeats):
    """(least CPU time of this process [s], least wall time [s], the result of the run of
    least CPU time) over ``repeats`` calls of fn(): CPU time is what a machine busy with
    other work changes least."""
    cpu, wall, out = math.inf, math.inf, None
    for _ in range(repeats):
        c0, w0 = time.process_time(), time.perf_counter()
        value = fn()
        c1, w1 = time.process_time(), time.perf_counter()
        wall = min(wall, w1 - w0)
        if c1 - c0 < cpu:
            cpu, out = c1 - c0, value
    return cpu, wall, out


def load_average() -> float:
    try:
        return os.getloadavg()[0]
    except OSError:
        return math.nan


def workers_see_this_clone() -> None:
    """Worker processes (pool, Dask) import this clone's pam2exu, not an installed one."""
    paths = [str(ROOT)] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]
    os.environ["PYTHONPATH"] = os.pathsep.join(dict.fromkeys(paths))


def run_on(label: str, workers: int, dask_local: int | None, study, reference=None):
    """One executor's ExecutorRow and its table."""
    row = ExecutorRow(label, study.samples, study.steps, workers, dask_local is not None)
    before = load_average()
    table = None
    try:
        begin = time.perf_counter()
        with open_executor(workers, dask_local=dask_local) as executor:
            ready, cpu = time.perf_counter(), time.process_time()
            result = run_study(study, executor=executor, workers=workers)
            done, row.cpu = time.perf_counter(), time.process_time() - cpu
        row.start, row.seconds, row.stop = ready - begin, done - ready, time.perf_counter() - done
        table = result.table
        row.ok = int(np.sum(table["status"] == "ok"))
        if reference is not None:
            row.identical = same_table(table, reference)
    except Exception as exc:  # noqa: BLE001 (the section reports it)
        row.failure = f"{type(exc).__name__}: {exc}"
    row.load = (before, load_average())
    return row, table


def same_table(a: dict, b: dict) -> bool:
    """Every column equal bit for bit (numbers by their bytes, NaN included)."""
    return a.keys() == b.keys() and all(
        np.asarray(a[k]).dtype == np.asarray(b[k]).dtype
        and np.asarray(a[k]).tobytes() == np.asarray(b[k]).tobytes() for k in a)


def anatomy(study) -> dict:
    """CPU seconds of one variant's parts, each the least of ANATOMY_REPEATS in this
    process: the model built from its text with the variant's values, a run of it (and of
    LONGER times its steps: the cost per step and the fixed cost of a run), the reduction;
    and Exudyn's share of the run's wall time (``res.info["backend_seconds"]``)."""
    values = dict(zip(study.names, study.variants(0, 1)[0]))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model_s, _, model = best_cpu_of(lambda: varied(study.model_text, values,
                                                       "benchmark"), ANATOMY_REPEATS)

        def fresh(steps):
            """A run of a model built anew (as each variant is), less the building."""
            def once():
                start = time.perf_counter()
                res = run(varied(study.model_text, values, "benchmark"), study.analysis,
                          t_end=study.t_end, steps=steps, outputs=study.outputs)
                return res, time.perf_counter() - start
            seconds, _, (res, wall) = best_cpu_of(once, ANATOMY_REPEATS)
            return seconds - model_s, res, wall
        run_s, res, wall = fresh(study.steps)
        long_s, _, _ = fresh(LONGER * study.steps)
    reduce_s, _, _ = best_cpu_of(lambda: reduce_run(res, study.outputs, study.reduce),
                                 ANATOMY_REPEATS)
    per_step = (long_s - run_s) / ((LONGER - 1) * study.steps)
    return {"model": model_s, "run": run_s, "exudyn_share": res.info["backend_seconds"] / wall,
            "reduce": reduce_s, "per_step": per_step, "fixed": run_s - study.steps * per_step}


def pylinkage_four_bar(steps: int):
    """The four-bar in pylinkage's component API (the README's), crank turned once in
    ``steps`` iterations; its constraint names."""
    from pylinkage.actuators import Crank
    from pylinkage.components import Ground
    from pylinkage.dyads import RRRDyad
    from pylinkage.simulation import Linkage
    O2, O4 = Ground(0.0, 0.0, name="O2"), Ground(GROUND, 0.0, name="O4")
    crank = Crank(anchor=O2, radius=CRANK, angular_velocity=2 * math.pi / steps, name="crank")
    pin = RRRDyad(anchor1=crank.output, anchor2=O4, distance1=COUPLER, distance2=ROCKER,
                  name="B")
    return Linkage([O2, O4, crank, pin], name="four-bar"), ("crank_radius", "B_dist1",
                                                           "B_dist2")


def pylinkage_rows(samples: int, steps_list) -> tuple[list, str]:
    """analyze_tolerance measured here, or the quoted figure; and a note saying which."""
    try:
        from pylinkage.linkage.sensitivity import analyze_tolerance
        version = importlib.metadata.version("pylinkage")
    except ImportError:
        per_second, steps = QUOTED
        return [PylinkageRow(steps, samples, samples / per_second)], (
            "pylinkage is not installed in this interpreter: its row is the figure issue 24 "
            f"quotes ({per_second:,.0f} samples/s of {steps} position steps), not measured "
            "in this run")
    rows = []
    for steps in steps_list:
        linkage, names = pylinkage_four_bar(steps)
        cpu, seconds, analysis = best_cpu_of(lambda: analyze_tolerance(
            linkage, {n: TOL for n in names}, iterations=steps, n_samples=samples, seed=1),
            PYLINKAGE_REPEATS)
        assert analysis.output_cloud.shape == (samples, steps, 2), analysis.output_cloud.shape
        rows.append(PylinkageRow(steps, samples, seconds, version, cpu))
    return rows, f"pylinkage {version}, measured in this run"


def measure(plan, variants: int | None = None, steps: int | None = None) -> Measured:
    """Section 9: the study on each executor, pylinkage beside it, one variant's parts."""
    variants = variants or plan.study_variants
    steps = steps or plan.study_steps
    workers_see_this_clone()
    study = the_study(variants, steps)
    out = Measured(variants, steps, info={
        "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        **machine()})
    out.anatomy = anatomy(study)
    log("  one variant: " + ", ".join(f"{k} {v:.0%}" if k.endswith("share") else
                                     f"{k} {1e3 * v:.2f} ms" for k, v in out.anatomy.items()))
    reference = None
    for label, workers, dask_local in EXECUTORS:
        row, table = run_on(label, workers, dask_local, study, reference)
        reference = table if reference is None else reference
        out.rows.append(row)
        log(f"  {label}: " + (row.failure or f"{row.seconds:.1f} s, {row.per_second:.1f} "
                              f"variants/s, {row.us_per_variant_step:.0f} µs/variant-step "
                              f"(CPU here {row.cpu_us_per_variant_step:.0f}), "
                              f"start {row.start:.1f} s, identical {row.identical}"))
    out.pylinkage, out.pylinkage_note = pylinkage_rows(variants, sorted({steps, 20}))
    for r in out.pylinkage:
        log(f"  pylinkage {r.version or '(quoted)'} {r.steps} steps: {r.per_second:.0f} "
            f"samples/s, {r.us_per_sample_step:.1f} µs/sample-step (CPU "
            f"{r.cpu_us_per_sample_step:.1f})")
    return out


# ---- the section ---------------------------------------------------------------------------

def _table(header, rows) -> list[str]:
    return ["| " + " | ".join(header) + " |", "|" + "---|" * len(header),
            *("| " + " | ".join(str(c) for c in r) + " |" for r in rows)]


def _yes(flag) -> str:
    return "–" if flag is None else ("yes" if flag else "**no**")


def study_section(m: Measured) -> list[str]:
    """Section 9's Markdown, BEGIN … END."""
    info = m.info
    lines = [BEGIN, "## 9. Studies: variants per second", ""]
    add = lines.append
    add(f"The four-bar's kinetostatic study (issue 24's benchmark): `examples/four_bar.toml`, "
        f"{m.variants:,} Monte-Carlo variants × {m.steps} steps (t = 0 … 1 s, one crank "
        f"turn), the crank's, the coupler's and the rocker's lengths uniform within "
        f"± {1e3 * TOL:g} mm, the outputs `motor.Mz` and `B.F*` reduced to absmax and rms "
        "(the study is `STUDY` in `benchmarks/studies.py`). Each executor runs it once "
        "through `pam2exu.study(study, executor=..., workers=...)`: *study* is the wall time "
        "with the executor running (its nominal run and checks, the variants, the parts "
        "written and merged), *start* and *stop* the executor's own (a process pool starts "
        "its processes lazily, inside the study; a Dask `LocalCluster` of single-threaded "
        "worker processes before it). Variants per second and time per variant-step "
        "(study / (variants × steps)) are the study's. *CPU here* is the CPU time of the "
        "benchmark's own process meanwhile: all the work in-process, only the client's share "
        "(sending chunks, writing parts, merging) with workers; it is what a machine busy "
        "with other work changes least. Beside them, pylinkage's Monte-Carlo "
        "`analyze_tolerance` on the same four-bar and the same three tolerances (best of "
        f"{PYLINKAGE_REPEATS}, in this process): {m.pylinkage_note}.")
    add("")
    add(f"Measured {info.get('date', '')} on {info.get('CPU', '')} ({info.get('cores', '')} "
        f"cores, a shared virtual machine), Python {info.get('Python', '')}, Exudyn "
        f"{info.get('Exudyn', '')}, pam2exu {info.get('pam2exu', '')}"
        + (f", Dask {_version('distributed')}" if _version("distributed") else "") + ".")
    add("")
    base = next((r for r in m.rows if r.failure is None), None)
    rows = []
    for r in m.rows:
        if r.failure:
            rows.append([r.executor, f"{r.variants:,} × {r.steps}", "failed: " + r.failure]
                        + [""] * 9)
            continue
        rows.append([r.executor, f"{r.variants:,} × {r.steps}", f"{r.seconds:.1f}",
                     f"{r.per_second:.1f}", f"{r.us_per_variant_step:.0f}",
                     f"{r.per_second / base.per_second:.2f}×", f"{r.cpu:.1f}",
                     f"{r.cpu_us_per_variant_step:.0f}",
                     f"{r.start:.1f}" if r.workers == 1 or r.dask else "in the study",
                     f"{r.stop:.1f}", _yes(r.identical) + " / "
                     + " / ".join(f"{x:.1f}" for x in r.load)])
    for p in m.pylinkage:
        name = f"pylinkage {p.version} `analyze_tolerance`" if p.version else \
            "pylinkage `analyze_tolerance` (quoted, not measured)"
        rows.append([name, f"{p.samples:,} × {p.steps}", f"{p.seconds:.2f}",
                     f"{p.per_second:,.0f}", f"{p.us_per_sample_step:.1f}", "",
                     "" if math.isnan(p.cpu) else f"{p.cpu:.2f}",
                     "" if math.isnan(p.cpu) else f"{p.cpu_us_per_sample_step:.1f}", "", "",
                     ""])
    lines += _table(["executor", "variants × steps", "study [s]", "variants/s",
                     "µs per variant-step", "against in-process", "CPU here [s]",
                     "CPU here, µs per variant-step", "start [s]", "stop [s]",
                     "table bit-identical to in-process / load average before / after"], rows)
    add("")
    same = next((p for p in m.pylinkage if p.steps == m.steps), None)
    text = ""
    if base is not None and same is not None and same.version:
        text = (f"Against pylinkage at the same {m.steps} steps, both in this process: per "
                f"step {base.cpu_us_per_variant_step:.0f} µs of CPU against "
                f"{same.cpu_us_per_sample_step:.1f}, "
                f"{base.cpu_us_per_variant_step / same.cpu_us_per_sample_step:.0f}× more "
                f"(wall time: {base.per_second:.1f} variants/s against "
                f"{same.per_second:,.0f} samples/s, "
                f"{same.per_second / base.per_second:.0f}× fewer). ")
    elif base is not None and m.pylinkage:
        p = m.pylinkage[0]
        text = (f"Against pylinkage's quoted {p.per_second:,.0f} samples/s of {p.steps} steps "
                f"({p.us_per_sample_step:.1f} µs per sample-step): pam2exu in-process "
                f"{base.us_per_variant_step:.0f} µs per variant-step, "
                f"{base.us_per_variant_step / p.us_per_sample_step:.0f}× more. ")
    add(text + "The two do not compute the same thing: pylinkage places one joint per step "
        "by a circle–circle intersection in closed form (positions only); each pam2exu "
        "variant builds its mechanism from the model's text, solves the positions by Newton "
        "in Exudyn and then the velocities, accelerations and every joint reaction and the "
        "motor torque (the kinetostatic analysis), checks the run and reduces its outputs.")
    a = m.anatomy
    if a and base is not None:
        alone = a["model"] + a["run"] + a["reduce"]
        add("")
        add(f"Where a variant's time goes (one variant alone, the least CPU time of "
            f"{ANATOMY_REPEATS} in this process): the model from its text with the variant's "
            f"values {1e3 * a['model']:.1f} ms, the run {1e3 * a['run']:.1f} ms (Exudyn, "
            f"building and solving its system, {a['exudyn_share']:.0%} of its wall time; the "
            f"rest is pam2exu's native pass and checks), the reduction "
            f"{1e3 * a['reduce']:.2f} ms: {1e3 * alone:.1f} ms, against "
            f"{1e3 * base.cpu / base.variants:.1f} ms of CPU per variant in the in-process "
            f"study. From a second run of {LONGER} × {m.steps} steps, a run costs "
            f"{1e3 * a['fixed']:.1f} ms whatever its steps (building the mechanism and its "
            f"Exudyn system, assembling, the checks) and {1e6 * a['per_step']:.0f} µs per "
            f"step: {a['fixed'] / a['run']:.0%} of a {m.steps}-step variant's run is that "
            "fixed cost, and the place to gain.")
    cores = float(info.get("cores") or 1)
    busy = [x for r in m.rows for x in r.load if x == x]
    if busy and max(busy) > 0.5 * cores:
        add("")
        add(f"The machine was busy with other work during this run (1-minute load averages "
            f"up to {max(busy):.1f} on {cores:.0f} cores, in the table): the wall times, and "
            "the ratios between executors (whose workers compete for the same cores), are "
            "upper bounds and vary from run to run; the CPU times vary least.")
    lines += ["", END]
    return lines


def _version(name: str) -> str | None:
    try:
        return importlib.metadata.version(name)
    except importlib.metadata.PackageNotFoundError:
        return None


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true",
                        help="40 variants × 20 steps; written to a temporary directory")
    parser.add_argument("--variants", type=int, default=None,
                        help="variants of the study (default 2,000; written to a temporary "
                             "directory unless --out)")
    parser.add_argument("--steps", type=int, default=None, help="steps of each variant "
                                                                "(default 100)")
    parser.add_argument("--out", type=Path, default=None,
                        help="directory holding performance.md (default: docs/)")
    args = parser.parse_args(argv)
    plan = QUICK if args.quick else FULL
    resized = args.quick or args.variants or args.steps
    out_dir = args.out or (Path(tempfile.mkdtemp(prefix="pam2exu-studies-")) if resized
                           else ROOT / "docs")
    log(f"9. studies: variants per second ({machine()['pam2exu']})")
    begin = time.perf_counter()
    measured = measure(plan, args.variants, args.steps)
    out_dir.mkdir(parents=True, exist_ok=True)
    replace_section(out_dir / "performance.md", study_section(measured), BEGIN, END)
    log(f"wrote section 9 of {out_dir / 'performance.md'} "
        f"({(time.perf_counter() - begin) / 60:.1f} minutes)")


if __name__ == "__main__":
    main()

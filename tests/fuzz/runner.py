"""Run fuzz cases (``run_case``) and campaigns of them on worker processes (``campaign``).

A case is the mutant of one seed (``mutants.mutant``), written as bytes into a fresh
temporary directory that becomes the working directory, then run

* in-process: ``pam2exu.run(path)`` (the file's own analysis) and ``pam2exu.run(path,
  analysis=<another one, drawn from the seed>)``, for ``NATURAL_FRACTION`` of the seeds on
  the natural backend, warnings suppressed (another dynamic or clearance analysis over
  ``OTHER_SETTINGS``' short interval in few steps);
* for a fraction of the seeds, through the command line, in-process: ``pam2exu.cli.main``
  with ``run``, ``check``, ``run -o out.csv`` and, for some, one of ``EXTRA_RUNS``
  (``-o out.xlsx``, ``-o out.parquet``, ``--at``, ``--energy``, ``--angles deg``,
  ``--backend natural``) and one of ``NEWER_COMMANDS`` (``verify``, ``export``, ``plot``,
  ``run --plot``, on short runs); rarely ``draw -o x.png``, with ``--vectors``, ``--ic``,
  ``--guess`` or ``--t``.

The contract, for every call: a success whose Results hold only finite values and whose CSV
(``Results.to_csv``) reads back bit for bit with ``pam2exu.read_csv``; or a ``Pam2ExuError``
with a message (command line: exit code 1 or 2 and a message starting ``pam2exu: `` on stderr
that does not say "unexpected error"); nothing else, no hang, and no file left in the working
directory but the model and the files the command line was asked to write.

Outcomes: ``success`` (the file's own analysis ran), ``clean error`` (it stopped on a
Pam2ExuError), or a fault, whose class is one of

* ``exception <Type> at <file>:<line>``: an exception other than a Pam2ExuError, located at
  the innermost frame inside the pam2exu package (the same class whether it came from
  ``pam2exu.run`` or the command line; a command line "unexpected error" is rerun with
  ``--debug`` to locate it);
  A Pam2ExuError that says it is "a fault of pam2exu" (``analyses.run`` turns any foreign
  exception into such a SolverError, its ``__cause__`` kept) counts as the exception it
  wraps, in the same class;
* ``empty message <Type>``: a Pam2ExuError without a message;
* ``cli output``: an exit code or stderr that breaks the command line's contract;
* ``non-finite``: a Results table with NaN or infinite values;
* ``csv``: the CSV does not read back identical (or cannot be written or read);
* ``stray file``: a file left in the working directory;
* ``verify differs``: ``pam2exu verify`` ran both backends and they differ beyond the
  tolerance it derives (the two formulations disagree on the mutant);
* ``hang``: the case did not finish within the hang guard (``TIMEOUT``, far above any case's
  work; interrupted by SIGALRM, or the
  worker killed when it did not answer within the limit and a margin);
* ``crash``: the worker process died (a segmentation fault, ``os._exit``, …).

An Excel or Parquet file written must read back (openpyxl, pyarrow) with finite values.

Command line (from the repository's root)::

    python -m tests.fuzz.runner --count 10000 --workers 2 --seed 0 [--report out.md]

``--extreme`` makes the mutants with ``mutants.generate(..., extreme=True)``: valid values
a run may take long on (tolerances down to 5e-324, initial rates up to 1e12, a dynamic run
over up to 1e7 s) stay, so hangs there say what the analyses do with them; the fast
campaign (the default, and CI's) caps them.
"""
from __future__ import annotations

import argparse
import contextlib
import dataclasses
import io
import multiprocessing as mp
import os
import random
import resource
import shutil
import signal
import sys
import tempfile
import time
import traceback
import warnings
from collections import Counter
from dataclasses import dataclass, field
from multiprocessing.connection import wait
from pathlib import Path

import numpy as np

from .mutants import CLEARANCE_T_END, DYNAMIC_STEPS, DYNAMIC_T_END, generate

ANALYSES = ("assembly", "quasi_static", "kinematic", "kinetostatic", "clearance",
            "equilibrium", "dynamic")
#: the other analysis's settings where they would make a case long (a dynamic run's work
#: grows with its interval and steps, a clearance run's with its interval and steps): the
#: fast campaign's caps (mutants.py), so that no case's work depends on its source's interval
OTHER_SETTINGS = {"dynamic": {"t_end": DYNAMIC_T_END, "steps": DYNAMIC_STEPS // 2},
                  "clearance": {"t_end": CLEARANCE_T_END, "steps": 10}}
#: fraction of the cases also run through the command line (run, check, run -o out.csv)
CLI_FRACTION = 0.25
#: fraction of the command line cases that also run one of EXTRA_RUNS
EXTRA_FRACTION = 0.3
#: the command line's other outputs (run MODEL …)
EXTRA_RUNS = (["-o", "out.xlsx"], ["-o", "out.parquet"], ["--at", "0"], ["--at", "0.37", "0"],
              ["--at", "-1"], ["--at", "1e300"], ["--energy", "energy.png"],
              ["--angles", "deg"], ["--angles", "deg", "-o", "out.csv"],
              ["--backend", "natural"], ["--backend", "natural", "-o", "out.csv"],
              ["-a", "clearance", "--t-end", str(CLEARANCE_T_END), "--steps", "10", "--partial",
               "-o", "out.csv"])
#: the options whose argument is a file the command line is asked to write
WRITES = ("-o", "--energy", "--plot-file")
#: fraction of the cases whose other analysis runs on the natural backend
NATURAL_FRACTION = 0.3
#: fraction of the command line cases that also run one of NEWER_COMMANDS
NEWER_FRACTION = 0.35
#: the newer commands, on short runs (their work bounded like the other analysis's); plot
#: reads the CSV of the case's ``run MODEL -o out.csv``
SHORT = ["--t-end", str(DYNAMIC_T_END), "--steps", str(DYNAMIC_STEPS // 2)]
NEWER_COMMANDS = (["verify", "MODEL", *SHORT], ["verify", "MODEL", "-a", "kinematic"],
                  ["export", "MODEL", "-o", "script.py", *SHORT],
                  ["export", "MODEL", "-o", "script.py", "--forces"],
                  ["plot", "out.csv", "*.fi", "-o", "p.png"],
                  ["plot", "out.csv", "Fx", "--x", "t", "-o", "p.svg"],
                  ["run", "MODEL", "--plot", "*.fi", "--plot-file", "p.png", *SHORT])
#: fraction of the cases also drawn (draw -o x.png)
DRAW_FRACTION = 0.03
#: what a drawing may show besides the configuration at t = 0
DRAW_OPTIONS = ([], ["--vectors", "v"], ["--vectors", "a"], ["--vectors", "F"], ["--ic"],
                ["--guess"], ["--t", "0.3"], ["--t", "0.3", "--vectors", "F", "--ic"])
#: the hang guard: a case still running after TIMEOUT s is interrupted and reported as a
#: hang, a worker silent for TIMEOUT + MARGIN s is killed. It aborts a true hang only and
#: decides nothing else: the fast campaign bounds each case's work by its caps (mutants.py),
#: and its slowest case takes ~10 s on an idle 2-core machine (~25 s with the machine
#: loaded), so the guard sits ~60x above the slowest legitimate case
TIMEOUT = 600.0
MARGIN = 60.0
#: address space a worker may use beyond what it has when it starts [bytes]
MEMORY = 3 * 2**30


class CaseTimeout(BaseException):
    """Raised by SIGALRM in a worker when a case runs past its time limit (a BaseException,
    so that no ``except Exception`` in the package swallows it)."""


@dataclass
class Outcome:
    """The outcome of one case."""

    seed: int
    status: str = "success"        # "success", "clean error" or "fault"
    fault: str = ""                # the fault class (see the module's docstring)
    description: str = ""          # the mutant's description
    kinds: list = field(default_factory=list)
    via: str = ""                  # the call that faulted
    message: str = ""
    detail: str = ""               # the traceback's last frames, or what differs
    sub: str = ""                  # a finer key within the class (non-finite, csv, hang)
    seconds: float = 0.0
    calls: int = 0                 # pam2exu calls made
    successes: int = 0             # of which ran (the others stopped on a clean error)
    cause: str = ""                # a clean error's foreign __cause__: "<Type> at <file>:<line>"


class _Fault(Exception):
    def __init__(self, fault, via, message, detail="", sub=""):
        super().__init__(fault)
        self.fault, self.via, self.message, self.detail, self.sub = (fault, via, message,
                                                                     detail, sub)


def _pkg_dir() -> Path:
    import pam2exu
    return Path(pam2exu.__file__).resolve().parent


def _frames(exc) -> list:
    return traceback.extract_tb(exc.__traceback__) if exc.__traceback__ else []


def location(exc) -> str:
    """``<file>:<line>`` of the innermost frame of ``exc``'s traceback inside the pam2exu
    package (the path relative to the repository), else of the innermost frame."""
    pkg = _pkg_dir()
    frames = _frames(exc)
    inside = [f for f in frames if _under(f.filename, pkg)]
    frame = inside[-1] if inside else (frames[-1] if frames else None)
    if frame is None:
        return "?"
    path = Path(frame.filename)
    if _under(frame.filename, pkg):
        path = Path(frame.filename).resolve().relative_to(pkg.parent)
    return f"{path}:{frame.lineno}"


def _under(filename, pkg: Path) -> bool:
    try:
        Path(filename).resolve().relative_to(pkg)
        return True
    except ValueError:
        return False


def _detail(exc, n=6) -> str:
    frames = _frames(exc)[-n:]
    return "".join(traceback.format_list(frames)).rstrip()


def _cut(text: str, n: int = 400) -> str:
    text = str(text)
    return text if len(text) <= n else f"{text[:n]}…({len(text)} chars)"


def _exception_fault(exc, via) -> _Fault:
    return _Fault(f"exception {type(exc).__name__} at {location(exc)}", via,
                  f"{type(exc).__name__}: {_cut(exc)}", _detail(exc))


#: what analyses.run says of a foreign exception it turns into a SolverError
SELF_DECLARED = "fault of pam2exu"


def _pam2exu_error(exc, via) -> str:
    """Check a Pam2ExuError: '' when it is clean and its cause is pam2exu's own, else the
    foreign cause ("<Type> at <file>:<line>"); _Fault when it is a fault."""
    if not str(exc).strip():
        raise _Fault(f"empty message {type(exc).__name__}", via,
                     f"{type(exc).__name__} with message {str(exc)!r}", _detail(exc))
    cause = exc.__cause__
    if SELF_DECLARED in str(exc):
        inner = cause if cause is not None else exc
        fault = _exception_fault(inner, via)
        fault.message += f" (raised as {type(exc).__name__}: {_cut(exc, 200)})"
        raise fault
    import pam2exu
    if cause is not None and not isinstance(cause, pam2exu.Pam2ExuError):
        return f"{type(cause).__name__} at {location(cause)}"
    return ""


def _settings_args(analysis: str) -> list[str]:
    """The command line options of ``OTHER_SETTINGS[analysis]``."""
    return [a for k, v in OTHER_SETTINGS.get(analysis, {}).items()
            for a in (f"--{k.replace('_', '-')}", str(v))]


def plan(seed: int) -> tuple[str, str | None, list[list[str]]]:
    """The other analysis of a case, the backend it runs on (None: the file's), and the
    case's command lines (with ``MODEL`` for the file)."""
    r = random.Random(f"case-{seed}")
    other = r.choice(ANALYSES)
    backend = "natural" if r.random() < NATURAL_FRACTION else None
    commands = []
    if r.random() < CLI_FRACTION:
        out = ["run", "MODEL", "-o", "out.csv"]
        if r.random() < 0.5:
            analysis = r.choice(ANALYSES)
            out += ["-a", analysis, *_settings_args(analysis)]
        commands += [["run", "MODEL"], ["check", "MODEL"], out]
        if r.random() < EXTRA_FRACTION:
            commands.append(["run", "MODEL", *r.choice(EXTRA_RUNS)])
        if r.random() < NEWER_FRACTION:
            commands.append(list(r.choice(NEWER_COMMANDS)))
    if r.random() < DRAW_FRACTION:
        commands.append(["draw", "MODEL", "-o", "x.png", *r.choice(DRAW_OPTIONS)])
    return other, backend, commands


def _check_results(res, via, scratch) -> None:
    """Finite values; the CSV reads back with the same columns, t and values (bit for bit)."""
    import pam2exu
    data = np.asarray(res.to_numpy())
    if not np.isfinite(data).all():
        names = ["t", *res.columns]
        bad = [names[j] for j in range(data.shape[1]) if not np.isfinite(data[:, j]).all()]
        rows = np.nonzero(~np.isfinite(data).all(axis=1))[0]
        var = sorted({b.rsplit(".", 1)[-1] for b in bad})
        raise _Fault("non-finite", via,
                     f"{len(bad)} columns with NaN/inf, e.g. {_cut(bad[:6], 200)}, "
                     f"from row {rows[0]} of {data.shape[0]}",
                     sub=f"{res.analysis}: {', '.join(var[:6])}")
    path = os.path.join(scratch, "res.csv")
    try:
        res.to_csv(path)
        back = pam2exu.read_csv(path)
    except CaseTimeout:
        raise
    except BaseException as exc:     # noqa: BLE001 - every exception is a finding
        raise _Fault("csv", via, f"{type(exc).__name__}: {_cut(exc)}", _detail(exc),
                     sub=f"{type(exc).__name__} at {location(exc)}") from None
    finally:
        for leftover in os.listdir(scratch):
            os.remove(os.path.join(scratch, leftover))
    if back.columns != res.columns:
        raise _Fault("csv", via, f"columns differ: wrote {len(res.columns)} "
                                 f"{_cut(res.columns[:5], 200)}, read {len(back.columns)} "
                                 f"{_cut(back.columns[:5], 200)}", sub="columns differ")
    a, b = np.ascontiguousarray(data), np.ascontiguousarray(back.to_numpy())
    if a.shape != b.shape or a.dtype != b.dtype or not np.array_equal(a.view(np.uint64),
                                                                     b.view(np.uint64)):
        if a.shape != b.shape:
            what = f"shapes {a.shape} and {b.shape}"
        else:
            i, j = np.argwhere(a.view(np.uint64) != b.view(np.uint64))[0]
            what = (f"column {(['t'] + res.columns)[j]!r} row {i}: wrote {a[i, j]!r}, read "
                    f"{b[i, j]!r}")
        raise _Fault("csv", via, f"values differ: {what}", sub="values differ")


def _check_table_file(path, via) -> None:
    """An Excel or Parquet file of ``run -o`` reads back (openpyxl, pyarrow) with finite
    numbers in its table (an Excel workbook's first sheet: names, units, then the rows)."""
    try:
        if path.endswith(".parquet"):
            import pyarrow.parquet as pq
            table = pq.read_table(path)
            data = np.column_stack([np.asarray(c, dtype=float) for c in table.columns]) \
                if table.num_columns else np.zeros((0, 0))
        else:
            import openpyxl
            book = openpyxl.load_workbook(path, read_only=True)
            try:
                rows = list(book.worksheets[0].iter_rows(values_only=True))
            finally:
                book.close()
            data = np.array([list(row) for row in rows[2:]], dtype=float)
    except CaseTimeout:
        raise
    except BaseException as exc:     # noqa: BLE001
        raise _Fault("cli output", via, f"{path} does not read back: {type(exc).__name__}: "
                     f"{_cut(exc)}", _detail(exc), sub=f"{type(exc).__name__} reading {path}")
    if data.size == 0 or not np.isfinite(data).all():
        raise _Fault("non-finite", via, f"{path} holds no values or NaN/inf values",
                     sub=Path(path).suffix)


def _api_call(name, analysis, scratch, backend=None) -> tuple[bool, str]:
    """One in-process run: (True, '') when it ran, (False, foreign cause or '') for a clean
    error; _Fault otherwise."""
    import pam2exu
    settings = dict(OTHER_SETTINGS.get(analysis, {}))
    if backend is not None:
        settings["backend"] = backend
    via = f"pam2exu.run(path, analysis={analysis!r}" + "".join(
        f", {k}={v!r}" for k, v in settings.items()) + ")"
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = pam2exu.run(name, analysis=analysis, **settings)
    except CaseTimeout:
        raise
    except pam2exu.Pam2ExuError as exc:
        return False, _pam2exu_error(exc, via)
    except BaseException as exc:     # noqa: BLE001
        raise _exception_fault(exc, via) from None
    _check_results(res, via, scratch)
    return True, ""


def _cli_call(argv) -> tuple[int | None, str, BaseException | None]:
    code, err, escaped, _out = _cli_call_out(argv)
    return code, err, escaped


def _cli_call_out(argv) -> tuple[int | None, str, BaseException | None, str]:
    from pam2exu.cli import main
    out, err = io.StringIO(), io.StringIO()
    code, escaped = None, None
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err), \
                warnings.catch_warnings():
            warnings.simplefilter("ignore")
            code = main(argv)
    except CaseTimeout:
        raise
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else 2
        err.write(f"\n[SystemExit({exc.code!r})]")
    except BaseException as exc:     # noqa: BLE001
        escaped = exc
    return code, err.getvalue(), escaped, out.getvalue()


def _cli(argv, scratch) -> bool:
    """One command line run: True for exit 0, False for a clean error; _Fault otherwise."""
    import pam2exu
    via = "pam2exu " + " ".join(argv)
    code, err, escaped, out_text = _cli_call_out(argv)
    if escaped is not None:
        raise _exception_fault(escaped, via)
    if argv[0] == "verify" and code == 1 and not err.startswith("pam2exu: "):
        # both runs ran and the two formulations differ: the finding verify exists for
        differ = [line for line in out_text.splitlines() if "differ" in line.lower()]
        raise _Fault("verify differs", via, _cut(" / ".join(differ[:3]) or out_text, 400),
                     sub=" ".join(argv[2:]) or "model's analysis")
    if code == 0:
        for flag in ("--energy", "--plot-file"):
            if flag in argv and not os.path.isfile(argv[argv.index(flag) + 1]):
                raise _Fault("cli output", via, f"exit 0 but the {flag} figure was not written")
        if "-o" in argv:
            out = argv[argv.index("-o") + 1]
            if not os.path.isfile(out):
                raise _Fault("cli output", via, f"exit 0 but {out} was not written")
            if argv[0] == "export":
                try:
                    with open(out, encoding="utf-8") as fh:
                        compile(fh.read(), out, "exec")
                except CaseTimeout:
                    raise
                except BaseException as exc:     # noqa: BLE001
                    raise _Fault("cli output", via, f"the exported script does not compile: "
                                 f"{type(exc).__name__}: {_cut(exc)}", sub="export")
            elif argv[0] == "run" and not out.endswith(".csv"):
                _check_table_file(out, via)
            elif argv[0] == "run":
                try:
                    back = pam2exu.read_csv(out)
                except CaseTimeout:
                    raise
                except BaseException as exc:     # noqa: BLE001
                    raise _Fault("csv", via, f"{type(exc).__name__}: {_cut(exc)}",
                                 _detail(exc), sub=f"{type(exc).__name__} at {location(exc)}")
                if not np.isfinite(back.to_numpy()).all():
                    raise _Fault("non-finite", via, f"{out} holds NaN/inf values",
                                 sub="cli csv")
        return True
    text = err.strip()
    if (code in (1, 2) and err.startswith("pam2exu: ") and "unexpected error" not in err
            and SELF_DECLARED not in err):
        out = argv[argv.index("-o") + 1] if "-o" in argv else None
        if "--partial" in argv and out and os.path.isfile(out):   # the rows before a failure
            try:
                back = pam2exu.read_csv(out)
            except CaseTimeout:
                raise
            except BaseException as exc:     # noqa: BLE001
                raise _Fault("csv", via, f"the --partial CSV does not read back: "
                             f"{type(exc).__name__}: {_cut(exc)}", sub="partial")
            if not np.isfinite(back.to_numpy()).all():
                raise _Fault("non-finite", via, f"{out} (--partial) holds NaN/inf values",
                             sub="partial csv")
        return False
    if "unexpected error" in err or SELF_DECLARED in err:
        _, _, exc = _cli_call(["--debug", *argv])       # locate it
        if isinstance(exc, pam2exu.Pam2ExuError):
            _pam2exu_error(exc, via)
        elif exc is not None:
            fault = _exception_fault(exc, via)
            fault.message = f"{fault.message} [stderr: {_cut(text, 200)}]"
            raise fault
    raise _Fault("cli output", via, f"exit code {code!r}, stderr {_cut(text, 300)!r}",
                 sub=f"exit {code}")


def _on_alarm(signum, frame):
    raise CaseTimeout()


def run_case(seed: int, timeout: float | None = None, n_mutations: int | None = None,
             cli: bool | None = None, extreme: bool = False) -> Outcome:
    """Run the case of ``seed`` in this process and classify it (see the module docstring).

    ``timeout``: seconds before SIGALRM interrupts the case (main thread only; None: no
    limit). ``n_mutations``: passed to ``mutants.generate`` (0: the unchanged model).
    ``cli``: True/False to force the command line runs on or off (None: as planned).
    ``extreme``: passed to ``mutants.generate`` (valid values a run may take long on kept).
    """
    try:
        m = generate(seed, n_mutations, extreme=extreme)
    except Exception as exc:         # noqa: BLE001 - a fault of the generator itself
        return Outcome(seed, "fault", f"generator {type(exc).__name__} at {location(exc)}",
                       via="mutants.generate", message=f"{type(exc).__name__}: {_cut(exc)}",
                       detail=_detail(exc))
    other, backend, commands = plan(seed)
    if cli is True and not any(c[0] == "check" for c in commands):
        commands = [["run", "MODEL"], ["check", "MODEL"], ["run", "MODEL", "-o", "out.csv"],
                    *commands]
    elif cli is False:
        commands = []
    outcome = Outcome(seed, description=m.description, kinds=list(m.kinds))
    start = time.perf_counter()
    base = tempfile.mkdtemp(prefix="pam2exu-fuzz-")
    work, scratch = os.path.join(base, "work"), os.path.join(base, "scratch")
    os.mkdir(work)
    os.mkdir(scratch)
    old_cwd = os.getcwd()
    step = "writing the mutant"
    armed = False
    try:
        os.chdir(work)
        with open(m.name, "wb") as fh:
            fh.write(m.data)
        allowed = {m.name}
        if timeout:
            signal.signal(signal.SIGALRM, _on_alarm)
            signal.setitimer(signal.ITIMER_REAL, timeout)
            armed = True
        try:
            for k, (analysis, on) in enumerate(((None, None), (other, backend))):
                step = f"pam2exu.run(path, analysis={analysis!r}, backend={on!r})"
                ran, cause = _api_call(m.name, analysis, scratch, on)
                outcome.cause = outcome.cause or cause
                outcome.calls += 1
                outcome.successes += ran
                if k == 0:
                    outcome.status = "success" if ran else "clean error"
            for command in commands:
                argv = [m.name if a == "MODEL" else a for a in command]
                for flag in WRITES:
                    if flag in argv:
                        allowed.add(argv[argv.index(flag) + 1])
                if "-o" in argv and argv[0] == "run":
                    # a clearance run's extremes, as CSV beside its result file
                    allowed.add(os.path.splitext(argv[argv.index("-o") + 1])[0]
                                + ".extremes.csv")
                step = "pam2exu " + " ".join(argv)
                outcome.successes += _cli(argv, scratch)
                outcome.calls += 1
        finally:
            if armed:
                signal.setitimer(signal.ITIMER_REAL, 0)
        stray = sorted(set(os.listdir(work)) - allowed)
        if stray:
            raise _Fault("stray file", step, f"left in the working directory: {_cut(stray, 300)}")
    except _Fault as f:
        outcome.status, outcome.fault, outcome.via = "fault", f.fault, f.via
        outcome.message, outcome.detail, outcome.sub = f.message, f.detail, f.sub
    except CaseTimeout as exc:
        outcome.status, outcome.fault, outcome.via = "fault", "hang", step
        outcome.message = (f"no result after {timeout:g} s, the hang guard, far above any "
                           f"case's work: a hang, interrupted at {location(exc)}")
        outcome.detail, outcome.sub = _detail(exc), "interrupted"
    except BaseException as exc:     # noqa: BLE001 - a fault of the runner itself
        outcome.status, outcome.fault, outcome.via = "fault", f"runner {type(exc).__name__}", step
        outcome.message, outcome.detail = f"{type(exc).__name__}: {_cut(exc)}", _detail(exc)
    finally:
        os.chdir(old_cwd)
        shutil.rmtree(base, ignore_errors=True)
        outcome.seconds = time.perf_counter() - start
    return outcome


# --------------------------------------------------------------------------- workers

def _vm_size() -> int:
    try:
        with open("/proc/self/statm") as fh:
            return int(fh.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except OSError:
        return 0


def _worker(conn, timeout: float, memory: int | None, extreme: bool = False) -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if memory:
        _soft, hard = resource.getrlimit(resource.RLIMIT_AS)
        limit = _vm_size() + memory
        if hard == resource.RLIM_INFINITY or limit < hard:
            resource.setrlimit(resource.RLIMIT_AS, (limit, hard))
    import pam2exu.analyses  # imported once per worker
    import pam2exu.cli  # noqa: F401
    while True:
        try:
            seed = conn.recv()
        except (EOFError, OSError):
            break
        if seed is None:
            break
        outcome = run_case(seed, timeout, extreme=extreme)
        conn.send(dataclasses.asdict(outcome))
        if outcome.fault == "hang":        # interrupted anywhere: start afresh
            break
    conn.close()


class _Worker:
    def __init__(self, ctx, timeout, memory, extreme=False):
        self.conn, child = ctx.Pipe()
        self.proc = ctx.Process(target=_worker, args=(child, timeout, memory, extreme),
                                daemon=True)
        self.proc.start()
        child.close()
        self.seed = None
        self.started = 0.0

    def send(self, seed):
        self.seed, self.started = seed, time.monotonic()
        self.conn.send(seed)

    def kill(self):
        if self.proc.is_alive():
            self.proc.kill()
        self.proc.join(5)
        self.conn.close()


@dataclass
class Campaign:
    """What a campaign found: counts, and the faulty outcomes grouped by class."""

    count: int
    seed: int
    workers: int
    seconds: float = 0.0
    counts: Counter = field(default_factory=Counter)
    faults: dict = field(default_factory=dict)       # class -> list of Outcome, by seed
    calls: int = 0
    successes: int = 0
    case_seconds: list = field(default_factory=list)
    outcomes: list = field(default_factory=list)     # every Outcome, in order of completion
    causes: dict = field(default_factory=dict)       # foreign cause -> seeds (clean errors)

    def add(self, outcome: Outcome) -> None:
        self.outcomes.append(outcome)
        self.counts[outcome.status] += 1
        self.calls += outcome.calls
        self.successes += outcome.successes
        self.case_seconds.append(outcome.seconds)
        if outcome.cause:
            self.causes.setdefault(outcome.cause, []).append(outcome.seed)
        if outcome.status == "fault":
            self.faults.setdefault(outcome.fault, []).append(outcome)

    @property
    def n_faults(self) -> int:
        return sum(len(v) for v in self.faults.values())

    def classes(self) -> list[tuple[str, list[Outcome]]]:
        """Fault classes, most frequent first, each with its outcomes sorted by seed."""
        return sorted(((k, sorted(v, key=lambda o: o.seed)) for k, v in self.faults.items()),
                      key=lambda kv: (-len(kv[1]), kv[0]))

    def summary(self) -> str:
        """The counts as a Markdown table."""
        n = sum(self.counts.values())
        rows = [("mutants", n), ("successes (own analysis ran)", self.counts["success"]),
                ("clean errors (own analysis)", self.counts["clean error"]),
                ("faulty mutants", self.counts["fault"])]
        rows += [(f"fault: {k}", len(v)) for k, v in self.classes() if k != "hang"]
        rows += [("hangs", len(self.faults.get("hang", [])))]
        rows += [("pam2exu calls (in-process and command line)", self.calls),
                 ("of which ran", self.successes)]
        per = self.seconds / n if n else 0.0
        slow = max(self.case_seconds, default=0.0)
        wall = (f"{self.seconds:.1f} s ({per * 1000:.0f} ms per mutant on {self.workers} "
                f"workers; slowest case {slow:.1f} s)")
        rows += [("wall time", wall)]
        width = max(len(r[0]) for r in rows)
        lines = [f"| {'outcome':<{width}} | count |", f"|{'-' * (width + 2)}|-------|"]
        lines += [f"| {a:<{width}} | {b} |" for a, b in rows]
        return "\n".join(lines)

    def report(self, examples: int = 1) -> str:
        """Summary, then each fault class: count, representative seed(s) (``examples`` per
        class; every hang and crash, up to 30), description, the call, the message and where
        (traceback tail)."""
        out = [f"# Fuzz campaign: seeds {self.seed} … {self.seed + self.count - 1}", "",
               self.summary(), ""]
        for k, group in self.classes():
            kinds = Counter(kind for o in group for kind in set(o.kinds))
            subs = Counter(o.sub for o in group if o.sub)
            out += [f"## {k} ({len(group)})", ""]
            out.append(f"- seeds: {', '.join(str(o.seed) for o in group[:20])}"
                       + (" …" if len(group) > 20 else ""))
            out.append(f"- mutation kinds involved: "
                       f"{', '.join(f'{a} ({b})' for a, b in kinds.most_common(6))}")
            if subs and len(subs) > 1 or (subs and k in ("non-finite", "csv")):
                out.append(f"- breakdown: {'; '.join(f'{a} ({b})' for a, b in subs.most_common(10))}")
            shown = group[:30] if k in ("hang", "crash") else group[:examples]
            for o in shown:
                out += [f"- representative seed {o.seed}: {o.description}",
                        f"  - call: `{o.via}`",
                        f"  - message: {o.message}"]
                if o.detail:
                    out += ["  - traceback (innermost frames):", "", "```",
                            o.detail, "```"]
            out.append("")
        if self.causes:
            out += ["## Not faults: clean errors caused by a foreign exception", "",
                    ("A Pam2ExuError raised `from` an exception that is not pam2exu's (the "
                     "contract is met; listed for review):"), ""]
            for cause, seeds in sorted(self.causes.items(), key=lambda kv: -len(kv[1])):
                seeds = sorted(seeds)
                out.append(f"- {cause}: {len(seeds)} mutants, e.g. seed {seeds[0]}")
            out.append("")
        return "\n".join(out)


def campaign(count: int, workers: int = 2, seed: int = 0, timeout: float = TIMEOUT,
             margin: float = MARGIN, memory: int | None = MEMORY, progress=None,
             extreme: bool = False) -> Campaign:
    """Run the cases of seeds ``seed`` … ``seed + count - 1`` on ``workers`` processes.

    Each worker (forked, with pam2exu imported) runs cases in-process with a SIGALRM limit of
    ``timeout`` s; a worker that does not answer within ``timeout + margin`` s is killed and
    the case recorded as a hang, one that dies as a crash; either is replaced and the campaign
    goes on. ``memory``: bytes of address space a worker may add (RLIMIT_AS), so that absurd
    allocations end in MemoryError. ``progress(done, campaign)`` is called after each case.
    ``extreme``: the mutants of ``generate(..., extreme=True)`` (see the module's doc).
    """
    ctx = mp.get_context("fork")
    result = Campaign(count, seed, workers)
    start = time.monotonic()
    seeds = list(range(seed, seed + count))
    seeds.reverse()
    pool = [_Worker(ctx, timeout, memory, extreme) for _ in range(max(1, min(workers, count)))]

    def lost(w, fault, message, sub):
        try:
            m = generate(w.seed, extreme=extreme)
            description, kinds = m.description, list(m.kinds)
        except Exception as exc:     # noqa: BLE001 - reported by run_case's outcome
            description, kinds = f"(no mutant: {type(exc).__name__})", []
        result.add(Outcome(w.seed, "fault", fault, description, kinds, "worker", message,
                           sub=sub, seconds=time.monotonic() - w.started))

    try:
        done = 0
        while seeds or any(w.seed is not None for w in pool):
            for w in pool:
                if w.seed is None and seeds:
                    w.send(seeds.pop())
            busy = [w for w in pool if w.seed is not None]
            ready = wait([w.conn for w in busy], timeout=0.5)
            for i, w in enumerate(pool):
                if w.seed is None:
                    continue
                replace = False
                if w.conn in ready:
                    try:
                        outcome = Outcome(**w.conn.recv())
                    except (EOFError, OSError):
                        w.proc.join(5)
                        lost(w, "crash", f"the worker died (exit code {w.proc.exitcode})",
                             f"exit code {w.proc.exitcode}")
                        replace = True
                    else:
                        result.add(outcome)
                        replace = outcome.fault == "hang"
                elif time.monotonic() - w.started > timeout + margin:
                    lost(w, "hang", f"no answer within {timeout + margin:g} s: worker killed",
                         "killed")
                    replace = True
                else:
                    continue
                done += 1
                if progress:
                    progress(done, result)
                if replace:
                    w.kill()
                    pool[i] = _Worker(ctx, timeout, memory, extreme)
                else:
                    w.seed = None
    finally:
        for w in pool:
            try:
                w.conn.send(None)
            except (OSError, ValueError):
                pass
        for w in pool:
            w.proc.join(2)
            w.kill()
    result.seconds = time.monotonic() - start
    return result


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m tests.fuzz.runner",
                                description="Run a seeded mutation-fuzz campaign of pam2exu.")
    p.add_argument("--count", type=int, default=1000, help="number of mutants (default 1000)")
    p.add_argument("--workers", type=int, default=2, help="worker processes (default 2)")
    p.add_argument("--seed", type=int, default=0, help="first seed (default 0)")
    p.add_argument("--timeout", type=float, default=TIMEOUT,
                   help=f"time limit per case, s (default {TIMEOUT:g})")
    p.add_argument("--report", metavar="OUT.md", help="write the full report here")
    p.add_argument("--examples", type=int, default=1,
                   help="representative cases shown per fault class (default 1)")
    p.add_argument("--jsonl", metavar="OUT.jsonl", help="write every outcome, one JSON a line")
    p.add_argument("--case", type=int, metavar="SEED",
                   help="run one case in this process and print its outcome")
    p.add_argument("--extreme", action="store_true",
                   help="keep valid values a run may take long on (tolerances down to "
                        "5e-324, rates up to 1e12, …) instead of capping them")
    args = p.parse_args(argv)
    if args.case is not None:
        outcome = run_case(args.case, args.timeout, extreme=args.extreme)
        for k, v in dataclasses.asdict(outcome).items():
            print(f"{k}: {v}")
        return 0 if outcome.status != "fault" else 1
    tty = sys.stderr.isatty()

    def progress(done, result):
        if done % 100 == 0 or done == args.count:
            end = "\r" if tty and done != args.count else "\n"
            print(f"{done}/{args.count} mutants, {result.n_faults} faults", end=end,
                  file=sys.stderr, flush=True)
    result = campaign(args.count, args.workers, args.seed, args.timeout, progress=progress,
                      extreme=args.extreme)
    print(result.summary())
    if args.jsonl:
        import json
        with open(args.jsonl, "w", encoding="utf-8") as fh:
            for o in sorted(result.outcomes, key=lambda o: o.seed):
                fh.write(json.dumps(dataclasses.asdict(o), ensure_ascii=False) + "\n")
    if args.report:
        Path(args.report).write_text(result.report(args.examples) + "\n", encoding="utf-8")
        print(f"report written to {args.report}")
    else:
        for k, group in result.classes():
            o = group[0]
            print(f"\n{k} ({len(group)}): seed {o.seed}: {o.description}\n  {o.via}: "
                  f"{o.message}")
    return 1 if result.n_faults else 0


if __name__ == "__main__":
    sys.exit(main())

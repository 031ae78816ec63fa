"""The engine that runs a study's chunks: in-process, on a local process pool or on Dask.

``run_chunks(task, payload, chunks, parts, rows=…)`` computes
``task(payload, start, stop, rows[start:stop])`` for every chunk ``(start, stop)`` and
returns the merged columns in row order. The task is a picklable top-level function
returning ``{column name: values}`` with one entry per row ``start … stop − 1`` along the
first axis (numbers or fixed-width strings, no objects); ``payload`` is what every worker
needs to compute any chunk (the model's text, the analysis settings: small, never solver
objects: the worker builds the mechanism), ``rows`` what only one row needs (the variants'
parameter values): each chunk is sent its own rows only, so that what a chunk costs to send
does not grow with the study (a million variants' values are 24 MB: sent with each of
2,500 chunks they cost a Dask cluster 94 ms a chunk and its "large graph" warning, against
4 ms for the chunk's own rows, measured). The engine knows nothing of what a chunk computes.

Where it runs (``executor``):

- ``None``: in this process, chunk after chunk;
- any ``concurrent.futures.Executor``, typically a ``ProcessPoolExecutor``; at most as many
  chunks as it has workers are in flight. A worker process that dies (a crash, the
  out-of-memory killer, a kill) breaks the pool: the chunks finished so far are kept, a new
  pool of the same size is started and only the chunks that were in flight are submitted
  again, each at most ``retries`` more times, then a ``ChunkError`` names it;
- a ``dask.distributed.Client`` (the optional extra ``pam2exu[dask]``): every chunk is
  submitted at once; the scheduler reruns a task whose worker died on another worker (up to
  its ``distributed.scheduler.allowed-failures``, which ``open_executor`` sets to
  ``retries`` for the ``LocalCluster`` it starts), then a ``ChunkError`` names the chunk.

``open_executor(workers, dask, dask_local)`` makes the executor the command's options ask
for (``--workers N``, ``--dask ADDRESS``, ``--dask-local N``) and closes it afterwards. A
local pool's workers are forked from a server process that imports what they need
(``WORKER_MODULES``) once, as soon as the pool is opened, while the caller goes on (its
nominal run, its checks): a worker then starts in milliseconds, instead of importing
pam2exu, NumPy and SciPy itself (about 2 s of CPU each, measured), all of them at once on
the same cores, before its first chunk. ``warm`` starts that server earlier, before the
caller's own checks.

Every finished chunk is written whole as its part file under ``parts`` as soon as it
arrives (``pam2exu/studies/parts.py``: temporary file, then renamed), so an interrupted study
loses no finished chunk. ``resume=True`` reuses every readable part of the same study
(same ``key``) and computes only the rows they do not cover; without it, the parts folder's
old parts are removed first. A task that raises (a bug: the runner turns a variant's
failure into a row) stops the run once the chunks in flight have finished, with a
``ChunkError`` naming the chunk; the finished chunks stay on disk for ``resume``.
"""
from __future__ import annotations

import contextlib
import importlib
import multiprocessing.forkserver
import os
import sys
import uuid
from collections import Counter, deque
from concurrent.futures import (FIRST_COMPLETED, BrokenExecutor, Executor,
                                ProcessPoolExecutor, wait)
from multiprocessing import get_all_start_methods, get_context
from pathlib import Path
from typing import Callable, NamedTuple

import numpy as np

from ..console import UsageError
from ..errors import OutputError, Pam2ExuError
from ..progress import Progress
from .parts import (Part, clear_parts, covered, fingerprint, merge, missing, part_files,
                    read_part, write_part)

#: more attempts a chunk gets after its worker was lost
RETRIES = 2
#: how worker processes of a local pool start: forked from a clean server process where
#: there is one, else fresh interpreters; never forked from this process, which may run
#: threads (a Dask client, Exudyn)
START_METHOD = "forkserver" if "forkserver" in get_all_start_methods() else "spawn"
#: what a study's worker processes import, once, in the server they are forked from (the
#: start method "forkserver"): the study's task (``runner.run_variants``), the analyses it
#: runs and the natural backend with the SciPy modules it needs (which every worker would
#: otherwise import in its first chunk, 0.6–0.9 s of CPU each, all at once on the cores
#: the chunks need; the server imports them while the caller runs its checks); ``__main__``
#: as Python's own default (a worker then need not run the main script again)
WORKER_MODULES = ("__main__", "pam2exu.studies.runner", "pam2exu.analyses",
                  "pam2exu.backend.natural")


#: where a ``LocalCluster``'s scheduler serves HTTP (health, metrics; the dashboard stays
#: off): a free loopback port, not Dask's default 8787, which another cluster may hold (Dask
#: then warns, "Port 8787 is already in use")
LOCAL_HTTP = "127.0.0.1:0"


class ChunkError(Pam2ExuError):
    """A chunk of a study could not be computed: its task raised (a bug; the error it
    raised is the cause) or its worker was lost more often than the retries allow. Names
    the chunk's rows and where the finished chunks are kept. CLI exit code 1.

    Attributes
    ----------
    start, stop : int
        The chunk's rows ``start … stop − 1``.
    """

    def __init__(self, message: str, start: int, stop: int):
        self.start, self.stop = start, stop
        super().__init__(message)


class Chunked(NamedTuple):
    """What ``run_chunks`` returns: the merged columns in row order, the chunks computed by
    this run and the parts reused from an earlier one (``(start, stop)`` each)."""
    columns: dict
    computed: tuple
    reused: tuple


def dask_module(name: str = "distributed"):
    """Import Dask's ``distributed`` (or another Dask module); OutputError naming the extra
    ``pam2exu[dask]`` when it is not installed."""
    try:
        return importlib.import_module(name)
    except ImportError:
        raise OutputError("running a study on Dask needs the library dask.distributed, which "
                          "is not installed: pip install \"pam2exu[dask]\"") from None


def is_dask_client(executor) -> bool:
    """True for a ``dask.distributed.Client`` (without importing Dask when it is not
    loaded: a Client exists only once it is)."""
    distributed = sys.modules.get("distributed")
    return distributed is not None and isinstance(executor, distributed.Client)


def workers_of(executor, default: int) -> int:
    """The processes that run chunks at once on ``executor``: for a Dask client its
    cluster's threads (``Client.nthreads``, summed over the workers connected now), else
    ``default`` (a pool's size, or this process)."""
    if is_dask_client(executor):
        return max(1, sum(executor.nthreads().values()))
    return default


def start_server(preload=WORKER_MODULES) -> None:
    """With the start method "forkserver": start the server a local pool's processes are
    forked from, with ``preload`` imported, in the background (this call does not wait for
    it): each worker then inherits the modules instead of importing them. A server already
    running (started earlier in this process) is kept as it is."""
    if START_METHOD == "forkserver":
        get_context(START_METHOD).set_forkserver_preload(list(preload))
        multiprocessing.forkserver.ensure_running()


def warm(workers: int | None = None, dask: str | None = None,
         dask_local: int | None = None) -> None:
    """Start now what ``open_executor`` with the same options will use and can start
    early: a local pool's server (``start_server``), which then imports the workers'
    modules while this process does its own serial part (its imports, the study's checks
    and nominal run). Nothing for in-process or Dask."""
    if dask is None and dask_local is None and workers != 1:
        start_server()


def local_pool(workers: int) -> ProcessPoolExecutor:
    """A ``ProcessPoolExecutor`` of ``workers`` processes started the ``START_METHOD`` way,
    its server started now if it is not yet (``start_server``)."""
    start_server()
    return ProcessPoolExecutor(workers, mp_context=get_context(START_METHOD))


@contextlib.contextmanager
def open_executor(workers: int | None = None, dask: str | None = None,
                  dask_local: int | None = None, retries: int = RETRIES):
    """The executor the command's options ask for, closed when the block ends.

    Parameters
    ----------
    workers : int, optional
        ``1``: in-process (yields None); more: a ``ProcessPoolExecutor`` of that many
        processes (``local_pool``); None: one process per core (``os.cpu_count()``).
    dask : str, optional
        Address of a running Dask scheduler (``tcp://host:8786``): a ``Client`` to it.
    dask_local : int, optional
        A Dask ``LocalCluster`` of this many single-threaded worker processes, started for
        the block and stopped after it.
    retries : int
        For the LocalCluster: times the scheduler reruns a task whose worker died.
    """
    if dask is not None and dask_local is not None:
        raise UsageError("--dask and --dask-local do not go together: give one")
    if dask is not None:
        client = dask_module().Client(dask)
        try:
            yield client
        finally:
            client.close()
    elif dask_local is not None:
        if int(dask_local) < 1:
            raise UsageError(f"--dask-local needs at least 1 worker, got {dask_local}")
        distributed = dask_module()
        with dask_module("dask").config.set(
                {"distributed.scheduler.allowed-failures": int(retries)}):
            cluster = distributed.LocalCluster(n_workers=int(dask_local), threads_per_worker=1,
                                               processes=True, dashboard_address=None,
                                               scheduler_kwargs={"dashboard_address": LOCAL_HTTP})
        try:
            with distributed.Client(cluster) as client:
                yield client
        finally:
            cluster.close()
    elif workers == 1:
        yield None
    else:
        if workers is not None and int(workers) < 1:
            raise UsageError(f"--workers needs at least 1, got {workers}")
        pool = local_pool(workers or os.cpu_count())
        try:
            yield pool
        finally:
            pool.shutdown(wait=True, cancel_futures=True)


class Work(NamedTuple):
    """What ``run_chunks`` computes: the task, what every chunk needs, what each row needs."""

    task: Callable
    payload: object
    rows: object = None

    def arguments(self, start: int, stop: int) -> tuple:
        """The task's arguments for rows ``start … stop − 1``: the payload and the chunk's
        own rows only."""
        if self.rows is None:
            return self.payload, start, stop
        return self.payload, start, stop, self.rows[start:stop]


def run_chunks(task: Callable, payload, chunks, parts, executor=None, resume: bool = False,
               progress: bool = True, key: str | None = None,
               retries: int = RETRIES, rows=None) -> Chunked:
    """Compute ``task(payload, start, stop, rows[start:stop])`` for every chunk (without
    ``rows``: ``task(payload, start, stop)``), each written whole under ``parts`` as it
    finishes, and return the columns merged in row order.

    Parameters
    ----------
    task : callable
        A picklable top-level function ``task(payload, start, stop[, rows]) ->
        dict[str, ndarray]`` (rows ``start … stop − 1`` along each array's first axis; the
        same names in every chunk).
    payload : object
        Small and picklable: what every chunk needs (model text, analysis settings).
    chunks : list of (int, int)
        ``(start, stop)`` tiling rows 0 … n − 1 (``parts.plan_chunks``).
    parts : str or Path
        The parts folder (``OUT.parts``); made when missing.
    executor : None, concurrent.futures.Executor or dask.distributed.Client
        Where the chunks run (module docstring); ``open_executor`` makes one.
    resume : bool
        Reuse the readable parts of this study already in ``parts``; compute only the
        rows they do not cover. Without it, old parts are removed first.
    progress : bool
        Show the variants done, their rate and the time left (on a terminal only).
    key : str, optional
        The study's fingerprint, stored in every part; a part with another key is not
        reused. Default: a hash of the task's name, the payload and the rows.
    retries : int
        Times a chunk is run again after its worker process was lost (process pool).
    rows : array (n, …), optional
        What only row i needs, at ``rows[i]`` (a study's variants' values): each chunk is
        sent its own rows only (module docstring).

    Returns
    -------
    Chunked
        ``columns`` (name → array, rows 0 … n − 1), ``computed``, ``reused``.

    Raises
    ------
    ChunkError
        A task raised, returned columns that are not rows of its chunk, or lost its worker
        more than ``retries`` times; the finished chunks are on disk.
    """
    chunks = checked_chunks(chunks)
    variants = chunks[-1][1] if chunks else 0
    folder = Path(parts)
    work = Work(task, payload, rows)
    key = key or fingerprint(task.__module__, task.__qualname__, payload,
                             *(() if rows is None else (np.asarray(rows),)))
    if not resume:
        clear_parts(folder)
    folder.mkdir(parents=True, exist_ok=True)
    done = covered([p for p in map(lambda path: read_part(path, key), part_files(folder))
                    if p is not None], variants)
    reused = tuple((p.start, p.stop) for p in done)
    todo = missing(chunks, done)
    finished: list[Part] = list(done)

    bar = Progress(variants if progress else 0, "variants", rate=True)

    def finish(start: int, stop: int, columns) -> None:
        """A chunk's columns checked, written as its part and counted."""
        columns = checked_columns(columns, start, stop, finished, folder)
        write_part(folder, start, stop, key, columns)
        finished.append(Part(start, stop, columns))
        bar.update(sum(p.stop - p.start for p in finished))

    bar.update(sum(p.stop - p.start for p in done))     # the rate counts from here
    try:
        if is_dask_client(executor):
            run_on_dask(executor, work, todo, finish, folder)
        elif isinstance(executor, Executor):
            run_on_pool(executor, work, todo, finish, folder, retries)
        elif executor is None:
            for start, stop in todo:
                try:
                    columns = work.task(*work.arguments(start, stop))
                except Exception as exc:
                    raise task_error(start, stop, exc, folder) from exc
                finish(start, stop, columns)
        else:
            raise TypeError(f"executor must be None, a concurrent.futures.Executor or a "
                            f"dask.distributed.Client, got {type(executor).__name__}")
    finally:
        bar.close()
    return Chunked(merge(finished), tuple(todo), reused)


def checked_chunks(chunks) -> list[tuple[int, int]]:
    """The chunks as ``(start, stop)`` integer pairs; ValueError unless they tile 0 … n − 1
    in order."""
    out, end = [], 0
    for start, stop in chunks:
        start, stop = int(start), int(stop)
        if start != end or stop <= start:
            raise ValueError(f"chunks must tile the rows from 0 in order, each non-empty: "
                             f"got ({start}, {stop}) after row {end - 1}")
        out.append((start, stop))
        end = stop
    return out


def checked_columns(columns, start: int, stop: int, finished: list[Part], folder: Path):
    """A task's columns as arrays; ChunkError unless each has one entry per row of the
    chunk, none holds Python objects, and the names are those of the chunks before."""
    rows = stop - start
    problem = None
    if not isinstance(columns, dict) or not columns:
        problem = f"returned {type(columns).__name__}, not a dict of columns"
    else:
        columns = {str(n): np.asarray(v) for n, v in columns.items()}
        bad = [n for n, v in columns.items() if v.ndim < 1 or len(v) != rows
               or v.dtype.kind == "O"]
        if bad:
            v = columns[bad[0]]
            problem = (f"returned column '{bad[0]}' of shape {v.shape} and dtype {v.dtype}, "
                       f"not {rows} rows of numbers or strings")
        elif finished and list(columns) != list(finished[0].columns):
            problem = (f"returned the columns {list(columns)}, not those of the other chunks, "
                       f"{list(finished[0].columns)}")
    if problem:
        raise ChunkError(f"the study's chunk of variants {start} … {stop - 1} {problem}"
                         f"{kept(folder)}", start, stop)
    return columns


def kept(folder: Path) -> str:
    """'; the finished chunks are kept under …' for an error's message."""
    return (f"; the finished chunks are kept under {folder}, and a rerun with --resume "
            f"computes only the others")


def task_error(start: int, stop: int, exc: BaseException, folder: Path) -> ChunkError:
    """The ChunkError of a task that raised ``exc`` (its cause)."""
    return ChunkError(f"the study's chunk of variants {start} … {stop - 1} failed: "
                      f"{type(exc).__name__}: {exc}{kept(folder)}", start, stop)


def lost_error(start: int, stop: int, times: str, folder: Path) -> ChunkError:
    """The ChunkError of a chunk whose worker process was lost ``times`` ("3 times")."""
    return ChunkError(f"the study's chunk of variants {start} … {stop - 1}: its worker "
                      f"process was lost {times} (a crash, a kill or the memory running "
                      f"out){kept(folder)}", start, stop)


def run_on_pool(executor: Executor, work: Work, todo, finish, folder: Path,
                retries: int) -> None:
    """The chunks on a ``concurrent.futures`` executor, at most its workers in flight.

    A broken pool is replaced by a new one of the same kind. A chunk that was alone in
    flight when the pool broke lost its worker: it is charged one attempt and run again
    (more than ``retries`` times: ChunkError). The chunks in flight together when it broke
    are suspects, none charged: they are run again one at a time (so the next break has
    one culprit) before the other chunks go on in parallel.
    """
    pending, suspects, lost, pool = deque(todo), deque(), Counter(), executor
    try:
        while pending or suspects:
            queue = suspects if suspects else pending
            broken = pool_round(pool, work, queue, finish, folder,
                                1 if queue is suspects else workers(pool))
            if broken is None:
                continue
            if len(broken) > 1:
                suspects.extend(broken)
            else:
                culprit = broken[0] if broken else queue.popleft()   # broke before it ran
                lost[culprit] += 1
                if lost[culprit] > retries:
                    raise lost_error(*culprit, f"{lost[culprit]} times", folder)
                queue.appendleft(culprit)
            if pool is not executor:
                pool.shutdown(wait=False, cancel_futures=True)
            pool = replacement(executor)
    finally:
        if pool is not executor:
            pool.shutdown(wait=True, cancel_futures=True)


def workers(pool: Executor) -> int:
    """Chunks in flight at once on ``pool``: its workers (the cores when not known)."""
    # a ProcessPoolExecutor's (or ThreadPoolExecutor's) size is not public
    return max(1, getattr(pool, "_max_workers", None) or os.cpu_count() or 1)


def replacement(executor: Executor) -> Executor:
    """A new pool like a broken ``ProcessPoolExecutor`` (its size and start method)."""
    if not isinstance(executor, ProcessPoolExecutor):
        raise TypeError(f"the {type(executor).__name__} broke and cannot be restarted")
    # the size and start method of a ProcessPoolExecutor are not public
    return ProcessPoolExecutor(executor._max_workers, mp_context=executor._mp_context)


def pool_round(pool: Executor, work: Work, pending: deque, finish, folder: Path,
               width: int):
    """Run chunks from ``pending`` on ``pool``, ``width`` in flight, until it is empty
    (None) or the pool breaks: then the chunks that were in flight (the unsubmitted ones
    stay in ``pending``). A task's error is raised once the chunks in flight finished."""
    flight, broken, error = {}, None, None
    try:
        while pending or flight:
            while pending and len(flight) < width and broken is None and error is None:
                chunk = pending.popleft()
                try:
                    flight[pool.submit(work.task, *work.arguments(*chunk))] = chunk
                except BrokenExecutor:
                    pending.appendleft(chunk)
                    broken = []
            if not flight:
                break
            done, _ = wait(flight, return_when=FIRST_COMPLETED)
            for future in done:
                chunk = flight.pop(future)
                exc = future.exception()
                if exc is None:
                    finish(*chunk, future.result())
                elif isinstance(exc, BrokenExecutor):
                    broken = (broken or []) + [chunk]
                elif error is None:
                    error = task_error(*chunk, exc, folder)
                    error.__cause__ = exc
    except BaseException:
        for future in flight:
            future.cancel()
        raise
    if error is not None:
        raise error
    return None if broken is None else sorted(broken)


def run_on_dask(client, work: Work, todo, finish, folder: Path) -> None:
    """The chunks on a Dask cluster, all submitted at once, finished as they arrive; on an
    error, the chunks finished meanwhile are kept before it is raised."""
    distributed = dask_module()
    run = uuid.uuid4().hex[:12]
    futures = {client.submit(work.task, *work.arguments(start, stop), pure=False,
                             key=f"pam2exu-chunk-{start}-{stop}-{run}"):
               (start, stop) for start, stop in todo}
    try:
        for future in distributed.as_completed(futures):
            chunk = futures.pop(future)
            try:
                columns = future.result()
            except distributed.KilledWorker as exc:
                error, cause = lost_error(*chunk, "more often than the scheduler allows "
                                          "(distributed.scheduler.allowed-failures)",
                                          folder), exc
            except Exception as exc:
                error, cause = task_error(*chunk, exc, folder), exc
            else:
                finish(*chunk, columns)
                continue
            client.cancel([f for f in futures if not f.done()])
            for other, rows in futures.items():
                if other.status == "finished":
                    finish(*rows, other.result())
            raise error from cause
    finally:
        client.cancel([f for f in futures if not f.done()])

"""The engine that runs a study's chunks (pam2exu/studies/execute.py, parts.py).

References: the rows computed in one call of the task, in this process (row i depends only
on the seed and i: tests/studies/chunk_tasks.py), against which every executor, chunking
and resume must give the same bytes; the contract's "Results" and "Running"
(shared/spec/studies.md): each chunk written whole, --resume runs only the missing chunks,
a lost worker costs that chunk's retry. The Dask cluster is a real scheduler and two
worker processes over TCP on 127.0.0.1, started once for the module.
"""
import doctest
import socket
import sys
import warnings
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor
from multiprocessing import get_context
from pathlib import Path

import chunk_tasks
import distributed
import numpy as np
import pytest

from pam2exu.errors import OutputError
from pam2exu.studies import execute, parts
from pam2exu.studies.execute import ChunkError, open_executor, run_chunks, workers_of
from pam2exu.studies.parts import part_files, part_path, plan_chunks

ROWS = 23
CHUNKS = [(0, 5), (5, 10), (10, 15), (15, 20), (20, 23)]


@pytest.fixture(scope="module")
def cluster():
    """A Dask LocalCluster of two single-threaded worker processes on 127.0.0.1."""
    local = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                     host="127.0.0.1", dashboard_address=None,
                                     scheduler_kwargs={"dashboard_address": execute.LOCAL_HTTP})
    yield local
    local.close()


@pytest.fixture
def payload(tmp_path):
    calls = tmp_path / "calls"
    calls.mkdir()
    return {"seed": 7, "calls": str(calls), "marker": str(tmp_path / "died"), "die_at": 12,
            "bad": 7}


def calls(payload) -> list[tuple[int, int]]:
    """The chunks the task was called for (one file per call)."""
    return sorted(tuple(int(x) for x in p.name.split("-")[:2])
                  for p in Path(payload["calls"]).iterdir())


def forget_calls(payload) -> None:
    for p in Path(payload["calls"]).iterdir():
        p.unlink()


def expected(payload) -> dict:
    """Every row in one call, in this process."""
    columns = chunk_tasks.rows(payload, 0, ROWS)
    forget_calls(payload)
    return columns


def assert_same_bytes(columns: dict, reference: dict) -> None:
    assert list(columns) == list(reference)
    for name, values in reference.items():
        assert columns[name].dtype == values.dtype and columns[name].shape == values.shape
        assert columns[name].tobytes() == values.tobytes(), name


def test_each_chunk_is_sent_its_own_rows_only(tmp_path, cluster):
    # a study's variants' values go to the chunk that runs them, not to every chunk: what a
    # chunk is sent does not grow with the study
    rows = np.arange(2.0 * ROWS).reshape(ROWS, 2)
    sizes = np.concatenate([np.full(stop - start, stop - start) for start, stop in CHUNKS])
    firsts = np.concatenate([np.full(stop - start, rows[start, 0]) for start, stop in CHUNKS])
    with ProcessPoolExecutor(2, mp_context=get_context(execute.START_METHOD)) as pool, \
            open_executor(dask=cluster.scheduler_address) as client:
        for name, executor in (("in-process", None), ("pool", pool), ("dask", client)):
            run = run_chunks(chunk_tasks.own_rows, {}, CHUNKS, tmp_path / name,
                             executor=executor, rows=rows)
            assert run.columns["x"].tolist() == (2.0 * rows[:, 0]).tolist(), name
            assert run.columns["sent"].tolist() == sizes.tolist(), name
            assert run.columns["first"].tolist() == firsts.tolist(), name


def test_the_rows_are_part_of_the_key(tmp_path):
    # parts of a study with other values are not reused by resume
    rows = np.arange(2.0 * ROWS).reshape(ROWS, 2)
    run_chunks(chunk_tasks.own_rows, {}, CHUNKS, tmp_path / "p", rows=rows)
    again = run_chunks(chunk_tasks.own_rows, {}, CHUNKS, tmp_path / "p", rows=rows,
                       resume=True)
    assert again.reused == tuple(CHUNKS) and again.computed == ()
    other = run_chunks(chunk_tasks.own_rows, {}, CHUNKS, tmp_path / "p", rows=rows + 1.0,
                       resume=True)
    assert other.reused == () and other.columns["x"].tolist() == (2.0 * rows[:, 0] + 2.0).tolist()


def test_the_docstring_examples():
    for module in (parts, execute):
        assert doctest.testmod(module).failed == 0


@pytest.mark.parametrize("variants, seconds, workers", [(1, 0.01, 1), (23, 0.3, 2),
                                                        (10_000, 0.01, 2), (10_000, 2.0, 8),
                                                        (999_983, 1e-4, 64)])
def test_the_chunks_tile_the_rows_with_a_second_or_more_of_work(variants, seconds, workers):
    chunks = plan_chunks(variants, seconds, workers)
    assert chunks == plan_chunks(variants, seconds, workers)
    assert chunks[0][0] == 0 and chunks[-1][1] == variants
    assert all(a[1] == b[0] for a, b in zip(chunks, chunks[1:]))
    sizes = [stop - start for start, stop in chunks]
    assert max(sizes) - min(sizes) <= 1                      # near-equal
    assert all(size * seconds >= parts.MIN_SECONDS for size in sizes) or len(chunks) == 1
    assert all((size - 1) * seconds <= parts.MAX_SECONDS for size in sizes)


def test_in_process_a_pool_and_dask_give_the_same_bytes(tmp_path, payload, cluster):
    reference = expected(payload)
    runs = {}
    runs["in-process"] = run_chunks(chunk_tasks.rows, payload, CHUNKS, tmp_path / "a.parts")
    with ProcessPoolExecutor(2, mp_context=get_context(execute.START_METHOD)) as pool:
        runs["pool"] = run_chunks(chunk_tasks.rows, payload, CHUNKS, tmp_path / "b.parts",
                                  executor=pool)
    with open_executor(dask=cluster.scheduler_address) as client:
        assert cluster.scheduler_address.startswith("tcp://127.0.0.1:")
        runs["dask"] = run_chunks(chunk_tasks.rows, payload, CHUNKS, tmp_path / "c.parts",
                                  executor=client)
    other = [(0, 1), (1, 23)]                  # another chunking: the same table
    runs["chunked otherwise"] = run_chunks(chunk_tasks.rows, payload, other,
                                           tmp_path / "d.parts")
    for name, run in runs.items():
        assert_same_bytes(run.columns, reference)
        assert run.reused == ()
    for folder in ("b.parts", "c.parts"):      # every part the same bytes, too
        for start, stop in CHUNKS:
            assert (part_path(tmp_path / folder, start, stop).read_bytes()
                    == part_path(tmp_path / "a.parts", start, stop).read_bytes())
    assert len(calls(payload)) == 3 * len(CHUNKS) + 2


def test_the_chunks_of_a_dask_cluster_are_sized_for_its_workers_not_this_machines(cluster):
    """A study sent to a cluster of several machines (``--dask ADDRESS``) is cut for the
    cluster's worker processes (they were this machine's cores: too few chunks to keep a
    larger cluster busy)."""
    with open_executor(dask=cluster.scheduler_address) as client:
        assert workers_of(client, 64) == 2            # two single-threaded workers
    assert workers_of(None, 3) == 3
    with ThreadPoolExecutor(5) as pool:
        assert workers_of(pool, 5) == 5
    assert len(plan_chunks(1000, 0.05, 2)) == 8 < len(plan_chunks(1000, 0.05, 64)) == 50


def test_resume_computes_only_the_missing_and_unreadable_parts(tmp_path, payload):
    reference = expected(payload)
    folder = tmp_path / "OUT.parts"
    first = run_chunks(chunk_tasks.rows, payload, CHUNKS, folder)
    saved = {p.name: p.read_bytes() for p in part_files(folder)}
    assert sorted(saved) == sorted(part_path(folder, *c).name for c in CHUNKS)
    part_path(folder, 5, 10).unlink()
    broken = part_path(folder, 15, 20)
    broken.write_bytes(saved[broken.name][:100])          # cut short: rerun
    forget_calls(payload)
    resumed = run_chunks(chunk_tasks.rows, payload, CHUNKS, folder, resume=True)
    assert calls(payload) == [(5, 10), (15, 20)]
    assert resumed.computed == ((5, 10), (15, 20))
    assert resumed.reused == ((0, 5), (10, 15), (20, 23))
    assert_same_bytes(resumed.columns, reference)
    assert_same_bytes(first.columns, reference)
    assert {p.name: p.read_bytes() for p in part_files(folder)} == saved

    # chunked otherwise on resume: nothing to compute; without resume: everything
    forget_calls(payload)
    again = run_chunks(chunk_tasks.rows, payload, [(0, 11), (11, 23)], folder, resume=True)
    assert calls(payload) == [] and again.computed == ()
    assert_same_bytes(again.columns, reference)
    fresh = run_chunks(chunk_tasks.rows, payload, [(0, 11), (11, 23)], folder)
    assert calls(payload) == [(0, 11), (11, 23)] and fresh.reused == ()
    assert [p.name for p in part_files(folder)] == [part_path(folder, 0, 11).name,
                                                     part_path(folder, 11, 23).name]

    # another study (another key) reuses nothing
    forget_calls(payload)
    other = run_chunks(chunk_tasks.rows, dict(payload, seed=8), [(0, 11), (11, 23)], folder,
                       resume=True)
    assert calls(payload) == [(0, 11), (11, 23)]
    assert other.columns["x"].tobytes() != reference["x"].tobytes()


def test_parts_another_version_wrote_are_run_again_not_merged(tmp_path, payload,
                                                              monkeypatch):
    """The key holds ``parts.PART_FORMAT`` (pam2exu's version and the chunks' layout): a
    part of the same study written by another version is not reused."""
    folder = tmp_path / "OUT.parts"
    run_chunks(chunk_tasks.rows, payload, CHUNKS, folder)
    monkeypatch.setattr(parts, "PART_FORMAT", ("pam2exu", "another version", 2))
    forget_calls(payload)
    again = run_chunks(chunk_tasks.rows, payload, CHUNKS, folder, resume=True)
    assert calls(payload) == list(CHUNKS) and again.reused == ()
    assert_same_bytes(again.columns, expected(payload))


def test_a_worker_lost_mid_chunk_is_retried_on_the_pool(tmp_path, payload):
    reference = expected(payload)
    folder = tmp_path / "OUT.parts"
    with ProcessPoolExecutor(2, mp_context=get_context(execute.START_METHOD)) as pool:
        run = run_chunks(chunk_tasks.dies_once, payload, CHUNKS, folder, executor=pool)
    assert (tmp_path / "died").exists()                 # the first attempt did die
    assert_same_bytes(run.columns, reference)
    assert len(part_files(folder)) == len(CHUNKS)


def test_a_worker_lost_too_often_is_an_error_naming_its_chunk(tmp_path, payload):
    """The chunks in flight beside the one that kills its worker are not blamed: they are
    run again one at a time, and only the culprit is charged its retries."""
    folder = tmp_path / "OUT.parts"
    with ProcessPoolExecutor(2, mp_context=get_context(execute.START_METHOD)) as pool:
        with pytest.raises(ChunkError, match=r"chunk of variants 15 … 19: its worker process "
                                             r"was lost 2 times .*--resume") as error:
            run_chunks(chunk_tasks.always_dies, dict(payload, die_at=17), CHUNKS, folder,
                       executor=pool, retries=1)
    assert (error.value.start, error.value.stop) == (15, 20)
    assert [p.name for p in part_files(folder)][:3] == [part_path(folder, *c).name
                                                        for c in CHUNKS[:3]]
    assert not part_path(folder, 15, 20).exists()


def test_a_worker_lost_mid_chunk_is_retried_on_dask(tmp_path, payload, cluster):
    reference = expected(payload)
    with open_executor(dask=cluster.scheduler_address) as client:
        run = run_chunks(chunk_tasks.dies_once, payload, CHUNKS, tmp_path / "OUT.parts",
                         executor=client)
        assert (tmp_path / "died").exists()
        assert_same_bytes(run.columns, reference)

        with pytest.raises(ChunkError, match=r"chunk of variants 5 … 9 failed: "
                                             r"ZeroDivisionError: a bug in the task"):
            run_chunks(chunk_tasks.raises, payload, CHUNKS, tmp_path / "bug.parts",
                       executor=client)


@pytest.mark.parametrize("pooled", [False, True])
def test_a_task_that_raises_stops_the_run_and_keeps_the_finished_chunks(tmp_path, payload,
                                                                        pooled):
    """In-process, and on an executor (one thread: the chunks in order, as in-process)."""
    reference = expected(payload)
    folder = tmp_path / "OUT.parts"
    pool = ThreadPoolExecutor(1) if pooled else None
    try:
        with pytest.raises(ChunkError, match=r"chunk of variants 5 … 9 failed: "
                                             r"ZeroDivisionError: a bug in the task; the "
                                             r"finished chunks are kept under") as error:
            run_chunks(chunk_tasks.raises, payload, CHUNKS, folder, executor=pool, key="k")
    finally:
        if pool:
            pool.shutdown()
    assert isinstance(error.value.__cause__, ZeroDivisionError)
    assert [p.name for p in part_files(folder)] == [part_path(folder, 0, 5).name]
    forget_calls(payload)
    run = run_chunks(chunk_tasks.rows, payload, CHUNKS, folder, resume=True, key="k")
    assert calls(payload) == CHUNKS[1:]
    assert_same_bytes(run.columns, reference)


def test_columns_that_are_not_the_chunks_rows_are_an_error(tmp_path, payload):
    with pytest.raises(ChunkError, match=r"chunk of variants 0 … 4 returned column 'x' of "
                                         r"shape \(4,\) .*not 5 rows"):
        run_chunks(chunk_tasks.short, payload, CHUNKS, tmp_path / "OUT.parts")
    with pytest.raises(ValueError, match="chunks must tile the rows from 0"):
        run_chunks(chunk_tasks.rows, payload, [(0, 5), (6, 9)], tmp_path / "OUT.parts")


def test_dask_missing_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)
    for options in ({"dask": "tcp://127.0.0.1:8786"}, {"dask_local": 2}):
        with pytest.raises(OutputError, match=r'pip install "pam2exu\[dask\]"'):
            with open_executor(**options):
                pass


@pytest.mark.long
def test_a_local_cluster_is_started_and_stopped_by_the_run(tmp_path, payload):
    """``--dask-local 2``; with no retries, the first lost worker is a ChunkError."""
    reference = expected(payload)
    with open_executor(dask_local=2, retries=0) as client:
        run = run_chunks(chunk_tasks.rows, payload, CHUNKS, tmp_path / "OUT.parts",
                         executor=client)
        assert_same_bytes(run.columns, reference)
        # the chunk 10 … 14 kills its worker; a chunk the same worker was running beside it
        # is lost with it, and the scheduler may report either first (seen at load 3)
        with pytest.raises(ChunkError, match=r"chunk of variants \d+ … \d+: its worker "
                                             r"process was lost more often than the "
                                             r"scheduler allows"):
            run_chunks(chunk_tasks.always_dies, payload, CHUNKS, tmp_path / "lost.parts",
                       executor=client)
    assert client.status == "closed"



def test_a_local_cluster_serves_http_on_a_free_port():
    """Dask's scheduler serves HTTP (health, metrics) on port 8787 unless told otherwise, and
    warns when another cluster holds it ("Port 8787 is already in use"); the cluster of
    ``--dask-local`` takes a free loopback port: with 8787 held, no warning."""
    held = socket.socket()
    try:
        held.bind(("127.0.0.1", 8787))
        held.listen()
    except OSError:
        pass                                   # held by another process: busy either way
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            with open_executor(dask_local=1) as client:
                assert client.submit(int, "41").result() == 41
                port = client.cluster.scheduler.http_server.port
        assert port != 8787
        assert not [w for w in caught if "8787" in str(w.message)]
    finally:
        held.close()

@pytest.mark.parametrize("variants, workers, sizes", [
    (2000, 2, [500] * 2 + [250] * 2 + [125] * 4),    # the last chunks shrink
    (2000, 1, [400] * 5),          # one worker: nothing to balance
    (600, 2, [150] * 4),
    (100, 4, [25] * 4),            # every worker gets one
])
def test_one_pass_chunks_are_large_and_shared_equally(variants, workers, sizes):
    """A one-pass study's chunks hold at least ``least`` variants (its pass costs less per
    variant the larger it is) on one worker; on several, the last ones shrink to ``least``
    / TAIL_DIVISOR, in rounds of one chunk per worker, so that the workers finish
    together."""
    chunks = plan_chunks(variants, 0.15, workers, least=400)
    assert [b - a for a, b in chunks] == sizes
    assert chunks[0][0] == 0 and chunks[-1][1] == variants


@pytest.mark.parametrize("variants, workers", [(2000, 2), (1_000_003, 2), (5000, 3), (401, 2),
                                               (3, 4), (2000, 64), (799, 2)])
def test_one_pass_chunks_on_several_workers_shrink_towards_the_end(variants, workers):
    """Every chunk holds at most the one-worker plan's largest share (``chunk_size``), the
    sizes never grow, the last round (one chunk per worker) holds ``least`` /
    TAIL_DIVISOR to 2 · ``least`` / TAIL_DIVISOR variants each when the study has that
    many, and the plan is the same whenever it is made."""
    least = 400
    chunks = plan_chunks(variants, 0.15, workers, least=least)
    assert chunks == plan_chunks(variants, 0.15, workers, least=least)
    assert chunks[0][0] == 0 and chunks[-1][1] == variants
    assert all(a[1] == b[0] for a, b in zip(chunks, chunks[1:]))
    sizes = [b - a for a, b in chunks]
    assert min(sizes) >= 1 and max(sizes) <= parts.chunk_size(0.15, variants, workers, least)
    assert all(b <= a + 1 for a, b in zip(sizes, sizes[1:]))        # equal split: ± 1
    tail = least // parts.TAIL_DIVISOR
    if variants >= 2 * workers * tail:
        assert len(sizes) % workers == 0
        assert all(tail <= s <= 2 * tail for s in sizes[-workers:])


WORKERS_IMPORT = """
import sys
sys.path[:0] = {paths!r}
import chunk_tasks
from pam2exu.studies.execute import open_executor
if __name__ == "__main__":
    with open_executor(2) as pool:
        print(pool.submit(chunk_tasks.imported, ["pam2exu.studies.runner", "pam2exu.analyses",
                                                 "pam2exu.backend.natural",
                                                 "scipy.stats", "scipy.integrate",
                                                 "scipy.optimize"]).result())
"""


@pytest.mark.long
@pytest.mark.skipif(execute.START_METHOD != "forkserver", reason="no fork server here")
def test_a_pools_workers_start_with_the_studys_modules_imported(tmp_path):
    """The server a local pool's workers are forked from has imported the study's task,
    the analyses and the natural backend (``WORKER_MODULES``: a worker does not import
    pam2exu, NumPy and SciPy itself), and not scipy.stats, which only the study's draws need (in this process); in a
    fresh interpreter, whose fork server the pool starts."""
    import subprocess
    script = tmp_path / "pool.py"
    script.write_text(WORKERS_IMPORT.format(paths=[str(Path(__file__).parent),
                                                   str(Path(__file__).parents[2])]))
    out = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                         timeout=120)
    assert out.stdout.strip() == "[True, True, True, False, False, False]", out.stderr


def test_the_workers_modules_leave_out_what_a_study_never_runs():
    """``WORKER_MODULES`` import neither scipy.integrate (the natural dynamics' and the
    energy's integrators) nor scipy.optimize (a dead point's root): 651 modules instead of
    934, what each study's fork server imports before its first chunk (ae6daa2); in a fresh
    interpreter."""
    import subprocess
    code = ("import sys; from pam2exu.studies.execute import WORKER_MODULES as W; "
            "[__import__(m) for m in W if m != '__main__']; "
            "print(sorted(m for m in ('scipy.integrate', 'scipy.optimize', 'scipy.stats') "
            "if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=300, cwd=Path(__file__).parents[2])
    assert out.stdout.strip() == "[]", out.stderr


WARMED = """
import multiprocessing.forkserver, sys
sys.path[:0] = {paths!r}
import chunk_tasks
from pam2exu.studies import execute
if __name__ == "__main__":
    execute.warm({workers})
    multiprocessing.forkserver.set_forkserver_preload([])    # a server started later: bare
    execute.start_server = lambda preload=(): None
    with execute.open_executor(2) as pool:
        print(pool.submit(chunk_tasks.imported, ["pam2exu.studies.runner"]).result())
"""


@pytest.mark.long
@pytest.mark.skipif(execute.START_METHOD != "forkserver", reason="no fork server here")
@pytest.mark.parametrize("workers, started", [(2, True), (None, True), (1, False)])
def test_warm_starts_the_servers_imports_before_the_pool_opens(tmp_path, workers, started):
    """``warm`` (what ``pam2exu study`` calls before its checks) starts the workers' server
    with the study's modules when the options ask for a local pool, and nothing for one
    process; the pool opened after it forks from that server."""
    import subprocess
    script = tmp_path / "warm.py"
    script.write_text(WARMED.format(paths=[str(Path(__file__).parent),
                                           str(Path(__file__).parents[2])], workers=workers))
    out = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                         timeout=120)
    assert out.stdout.strip() == f"[{started}]", out.stderr

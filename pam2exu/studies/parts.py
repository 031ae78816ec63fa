"""A study's chunks on disk: how many variants a chunk holds, and its part file.

A chunk is a range of variants, rows ``start … stop − 1`` of the per-variant table. Each
finished chunk is written whole under the study's parts folder (``OUT.parts/``) as one part
file, ``chunk-<start>-<stop>.npz`` (the numbers zero-padded to nine digits, so the names sort
in row order): first to a temporary name in the same folder, then renamed
(``os.replace``), so a part on disk is always complete and an interrupted study loses no
finished chunk. A part is an uncompressed NumPy ``.npz`` archive as ``numpy.savez`` writes
it, but with fixed time stamps, so the same chunk is the same bytes (no pickles: bit-exact
numbers and fixed-width strings; ``numpy.load`` reads it): ``__key__`` the study's
fingerprint, ``__names__`` the column names in order, and ``c0``, ``c1``, … the columns,
each with one entry per row along its first axis.

``plan_chunks`` chooses the chunk boundaries from the number of variants, an estimate of
the seconds one variant takes and the number of workers, deterministically: the same inputs
give the same parts. A variant's row depends only on the study and its index, so any
chunking gives the same merged table, and ``covered`` lets a resumed study reuse every
readable part of the same study whatever chunking wrote it.
"""
from __future__ import annotations

import hashlib
import itertools
import math
import os
import pickle
import re
import tempfile
import zipfile
from pathlib import Path
from typing import NamedTuple

import numpy as np

from ..version import __version__

#: a part file's name: its rows start … stop − 1
PART = "chunk-{start:09d}-{stop:09d}.npz"
PART_PATTERN = re.compile(r"chunk-(\d+)-(\d+)\.npz")
#: prefix of the temporary files a part is written to before it is renamed
TEMPORARY = ".chunk-"
#: the time stamp of every member of a part (numpy's ``savez`` writes the clock's: a part
#: is then the same bytes whenever it is written)
ZIP_TIME = (1980, 1, 1, 0, 0, 0)
#: seconds of work a chunk holds at least (the cost of a chunk: sending the payload,
#: building the mechanism in the worker, writing the part, is then a small share of it)
MIN_SECONDS = 1.0
#: seconds of work a chunk holds at most (what a lost worker or a Ctrl-C costs, and how
#: often the progress bar moves)
MAX_SECONDS = 60.0
#: chunks per worker, when the chunk sizes above allow it (the last chunks then keep every
#: worker busy until the end)
PER_WORKER = 4
#: the last chunks of a study solved in one pass on several workers shrink to ``least`` /
#: TAIL_DIVISOR variants (``shrinking``): 100 for the runner's 400, whose pass costs about as
#: much per variant (four-bar, 100 steps: 5.7–6.2 ms CPU a variant in chunks of 100 against
#: 5.4–6.1 ms in chunks of 400, in one process, load 1.9)
TAIL_DIVISOR = 4


class Part(NamedTuple):
    """A readable part file: its rows ``start … stop − 1`` and their columns."""
    start: int
    stop: int
    columns: dict


def chunk_size(seconds_per_variant: float, variants: int, workers: int, least: int = 1
               ) -> int:
    """Variants per chunk: n / (PER_WORKER · workers), held between MIN_SECONDS and
    MAX_SECONDS of estimated work (and between 1 and n). With ``least`` > 1 (a study whose
    chunks are solved in one pass: a larger pass costs less per variant), the fewest chunks
    of at least ``least`` variants that keep every worker equally busy: their number a
    multiple of the workers, at least one each.

    Examples
    --------
    >>> chunk_size(0.01, 10_000, 2)      # 1,250 variants: 12.5 s a chunk, 8 chunks
    1250
    >>> chunk_size(0.01, 200, 2)         # at least 1 s of work: 100 variants
    100
    >>> chunk_size(1.0, 10_000, 2)       # at most 60 s
    60
    >>> chunk_size(0.01, 2_000, 2, least=400)     # 4 chunks of 500: 2 for each worker
    500
    >>> chunk_size(0.01, 600, 2, least=400)       # 2 chunks of 300: one each
    300
    """
    workers = max(int(workers), 1)
    if least > 1:
        count = max(workers, (variants // int(least)) // workers * workers)
        return max(1, min(math.ceil(variants / count), variants))
    seconds = max(float(seconds_per_variant), 1e-9)
    balanced = math.ceil(variants / (PER_WORKER * workers))
    size = max(math.ceil(MIN_SECONDS / seconds), min(balanced, math.floor(MAX_SECONDS / seconds)))
    return max(1, min(size, variants))


def plan_chunks(variants: int, seconds_per_variant: float, workers: int = 1, least: int = 1
                ) -> list[tuple[int, int]]:
    """The chunks ``(start, stop)`` of a study of ``variants`` variants, in row order:
    k = ⌈n / chunk_size⌉ chunks of near-equal size (fewer if one would then hold less than
    MIN_SECONDS of work), chunk j starting at ⌊j n / k⌋. A study solved in one pass
    (``least`` > 1) on several workers: chunks of ``chunk_size`` first, the last ones
    shrinking to ``least`` / TAIL_DIVISOR (``shrinking``), so that the workers finish
    together.

    Deterministic given its inputs, so ``seconds_per_variant`` should be an estimate that
    does not depend on timing (e.g. the analysis's steps times a cost per step) when the
    same parts are wanted again; no result depends on it (a variant's row depends only on
    its index).

    Parameters
    ----------
    variants : int
        Rows of the study, n ≥ 0.
    seconds_per_variant : float
        Estimated work of one variant [s].
    workers : int
        Processes that run chunks at once.
    least : int
        Variants a chunk holds at least, while every worker still gets one
        (``chunk_size``); on several workers, the last chunks ``least`` / TAIL_DIVISOR.

    Examples
    --------
    >>> plan_chunks(10, 0.25, 1)         # 4 variants make a second: 2 chunks of 5
    [(0, 5), (5, 10)]
    >>> plan_chunks(0, 0.25, 1)
    []
    >>> plan_chunks(2000, 0.15, 2, least=400)    # doctest: +NORMALIZE_WHITESPACE
    [(0, 500), (500, 1000), (1000, 1250), (1250, 1500), (1500, 1625), (1625, 1750),
     (1750, 1875), (1875, 2000)]
    """
    variants = int(variants)
    if variants <= 0:
        return []
    if least > 1 and workers > 1:
        sizes = shrinking(variants, int(workers), chunk_size(seconds_per_variant, variants,
                                                             workers, least),
                          max(1, int(least) // TAIL_DIVISOR))
        bounds = [0, *itertools.accumulate(sizes)]
        return list(zip(bounds[:-1], bounds[1:]))
    fewest = math.ceil(MIN_SECONDS / max(float(seconds_per_variant), 1e-9))
    count = min(math.ceil(variants / chunk_size(seconds_per_variant, variants, workers, least)),
                max(1, variants // fewest))         # no chunk under MIN_SECONDS of work
    return equal(variants, count)


def equal(variants: int, count: int) -> list[tuple[int, int]]:
    """``count`` chunks of near-equal size tiling rows 0 … n − 1, chunk j starting at
    ⌊j n / count⌋."""
    bounds = [j * variants // count for j in range(count + 1)]
    return list(zip(bounds[:-1], bounds[1:]))


def shrinking(variants: int, workers: int, largest: int, smallest: int) -> list[int]:
    """Chunk sizes whose last ones shrink so that the workers finish together: rounds of
    ``workers`` chunks of ⌈left / (2 · workers)⌉ each (at most ``largest``: each round half
    of what is left), while the round after could still give every worker ``smallest``;
    what is left then in near-equal chunks of ``smallest`` to 2 · ``smallest``, their
    number a multiple of the workers (one per worker, smaller, when there are fewer).

    Every chunk goes to the first worker that is free, so the last one ends at most one of
    these small chunks after the other workers' (a worker slowed by other work on the
    machine takes fewer of them), instead of a whole chunk of ``largest``.

    Examples
    --------
    >>> shrinking(2000, 2, 500, 100)
    [500, 500, 250, 250, 125, 125, 125, 125]
    >>> shrinking(401, 2, 201, 100)
    [100, 100, 100, 101]
    >>> shrinking(100, 4, 25, 100)       # one chunk each
    [25, 25, 25, 25]
    """
    sizes, left = [], variants
    while left > 0:
        size = min(largest, math.ceil(left / (2 * workers)))
        if size < smallest or left - workers * size < workers * smallest:
            count = max(left // smallest // workers * workers, min(workers, left))
            return sizes + [b - a for a, b in equal(left, count)]
        sizes += [size] * workers
        left -= workers * size
    return sizes


#: what a chunk holds and how, with pam2exu's version, in every key: a part another version
#: wrote (its columns or its numbers may differ, e.g. one without the variants' warnings)
#: is not this study's, and is run again rather than merged
PART_FORMAT = ("pam2exu", __version__, 2)


def fingerprint(*items) -> str:
    """SHA-256 of the items' pickle with ``PART_FORMAT``: the default key of a study's parts
    (the task's module and name, and its payload)."""
    return hashlib.sha256(pickle.dumps((PART_FORMAT, *items), protocol=4)).hexdigest()


def part_path(folder: Path, start: int, stop: int) -> Path:
    """The part file of rows ``start … stop − 1``."""
    return Path(folder) / PART.format(start=start, stop=stop)


def write_part(folder: Path, start: int, stop: int, key: str, columns: dict) -> Path:
    """Write a chunk's columns whole: a temporary file in ``folder``, synced, then renamed
    to its part name."""
    path = part_path(folder, start, stop)
    arrays = {"__key__": np.array(key), "__names__": np.array(list(columns), dtype=str)}
    arrays.update({f"c{j}": np.asarray(v) for j, v in enumerate(columns.values())})
    handle, temporary = tempfile.mkstemp(prefix=TEMPORARY, suffix=".tmp", dir=folder)
    try:
        with os.fdopen(handle, "wb") as file:
            with zipfile.ZipFile(file, "w", zipfile.ZIP_STORED) as archive:
                for name, array in arrays.items():
                    info = zipfile.ZipInfo(f"{name}.npy", date_time=ZIP_TIME)
                    with archive.open(info, "w", force_zip64=True) as entry:
                        np.lib.format.write_array(entry, array, allow_pickle=False)
            file.flush()
            os.fsync(file.fileno())
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise
    return path


def read_part(path: Path, key: str) -> Part | None:
    """The part at ``path``, or None when it cannot be read whole or is not the study's
    (another key, a column whose length is not its rows)."""
    found = PART_PATTERN.fullmatch(Path(path).name)
    if not found:
        return None
    start, stop = int(found.group(1)), int(found.group(2))
    try:
        with np.load(path, allow_pickle=False) as archive:
            if str(archive["__key__"]) != key:
                return None
            names = [str(n) for n in archive["__names__"]]
            columns = {n: archive[f"c{j}"] for j, n in enumerate(names)}
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile):
        return None
    if start >= stop or not columns or any(np.ndim(v) < 1 or len(v) != stop - start
                                           for v in columns.values()):
        return None
    return Part(start, stop, columns)


def part_files(folder: Path) -> list[Path]:
    """The part files in ``folder`` (by name), in row order."""
    folder = Path(folder)
    if not folder.is_dir():
        return []
    return sorted(p for p in folder.iterdir() if PART_PATTERN.fullmatch(p.name))


def clear_parts(folder: Path) -> None:
    """Remove the part files and left-over temporary files from ``folder`` (and the folder
    when it is then empty); nothing else in it is touched."""
    folder = Path(folder)
    if not folder.is_dir():
        return
    for path in folder.iterdir():
        if PART_PATTERN.fullmatch(path.name) or (path.name.startswith(TEMPORARY)
                                                 and path.name.endswith(".tmp")):
            path.unlink(missing_ok=True)
    if not any(folder.iterdir()):
        folder.rmdir()


def covered(parts: list[Part], variants: int) -> list[Part]:
    """The parts that tile rows without overlap, lowest start first (a part that overlaps
    one already taken, or reaches past the last row, is left out)."""
    taken, end = [], 0
    for part in sorted(parts, key=lambda p: (p.start, -p.stop)):
        if part.start >= end and part.stop <= variants:
            taken.append(part)
            end = part.stop
    return taken


def missing(chunks: list[tuple[int, int]], done: list[Part]) -> list[tuple[int, int]]:
    """The chunks with the rows of ``done`` taken out (a chunk partly done leaves the
    ranges around the done rows).

    Examples
    --------
    >>> missing([(0, 10), (10, 20)], [Part(5, 12, {})])
    [(0, 5), (12, 20)]
    """
    out = []
    for start, stop in chunks:
        for part in done:
            if part.stop <= start or part.start >= stop:
                continue
            if part.start > start:
                out.append((start, part.start))
            start = max(start, part.stop)
        if start < stop:
            out.append((start, stop))
    return out


def merge(parts: list[Part]) -> dict:
    """The columns of parts that tile the rows, concatenated in row order (bit-identical
    whatever the chunking)."""
    parts = sorted(parts, key=lambda p: p.start)
    if not parts:
        return {}
    names = list(parts[0].columns)
    return {n: np.concatenate([p.columns[n] for p in parts]) for n in names}

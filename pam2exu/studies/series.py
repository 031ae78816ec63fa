"""A study's series table (``series = true``): every variant's full time series of its
outputs, beside the per-variant table.

In a chunk (``runner.run_variants``) the series are 2-D columns, one row per variant and
one column per row of its run: ``series:t`` (the run's times) and ``series:<j>`` for the
j-th output column (``reduce.output_columns``: ``motor.Mz``, ``B.Fx``, …), NaN for a variant
in error. Their names hold no '.', so they never clash with a parameter's or a reduced
output's (both always hold one). The chunks carry them to ``OUT.parts/`` like any other
column, so a resumed study gives the same series, bit for bit.

The table a study returns and writes is in long format (``long_table``): ``sample``
(int64), ``t`` [s], one float64 column per output, the rows of every variant that ran
(status ok or rejected), in variant order, each with its rows t = 0 … t_end. A variant in
error has no rows (its status and message are in the per-variant table). Its file is
``OUT.series.parquet`` beside ``OUT.parquet`` or ``OUT.series.csv`` beside ``OUT.csv``
(``series_path``), read back bit for bit as the per-variant table is.

Memory: the series take about ``series_bytes`` (8 bytes a value, twice: the merged chunks
and the long table). Above ``WARN_BYTES`` the study warns; above the machine's physical
memory it is refused before any variant runs (``memory_problem``).
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..results.table_csv import BLOCK, csv_block, csv_header
from ..results.writers import write_whole
from .reduce import ERROR

#: the chunk column of the runs' times, and the prefix of the outputs' series columns
T_KEY = "series:t"
PREFIX = "series:"
#: the estimate of the series' memory above which a study warns [bytes]
WARN_BYTES = 1 << 30


def series_key(j: int) -> str:
    """The chunk column of the j-th output's series: ``series_key(0)`` is 'series:0'."""
    return f"{PREFIX}{j}"


def series_outputs(reduced: list[str]) -> list[str]:
    """The output columns of the reduced outputs' names, in their order (a reduction's name
    holds no '.').

    >>> series_outputs(["motor.Mz.absmax", "motor.Mz.rms", "B.Fx.absmax"])
    ['motor.Mz', 'B.Fx']
    """
    return list(dict.fromkeys(n.rpartition(".")[0] for n in reduced))


def series_rows(at_start: bool, steps: int) -> int:
    """Rows of a variant's run: 1 for an analysis that solves t = 0 only, else steps + 1."""
    return 1 if at_start else steps + 1


def series_bytes(samples: int, rows: int, outputs: int) -> int:
    """2 × 8 × samples × rows × (outputs + 2): the merged chunks' columns and the long
    table (``sample``, ``t`` and the outputs), float64 each."""
    return 16 * samples * rows * (outputs + 2)


def physical_memory() -> int | None:
    """The machine's physical memory [bytes], or None where the system does not say."""
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (AttributeError, ValueError, OSError):
        return None


def memory_text(samples: int, rows: int, outputs: int) -> str:
    """What the series of a study would take, in words (for the warning and the refusal)."""
    size = series_bytes(samples, rows, outputs)
    return (f"series = true keeps {samples} variants × {rows} rows × {outputs} outputs, about "
            f"{size / 2**30:.3g} GiB in memory")


def memory_problem(samples: int, rows: int, outputs: int,
                   memory: int | None = None) -> str | None:
    """The refusal's text when the series would take more than ``memory`` (default: the
    machine's physical memory), else None."""
    memory = physical_memory() if memory is None else memory
    if memory is None or series_bytes(samples, rows, outputs) <= memory:
        return None
    return (f"{memory_text(samples, rows, outputs)}, more than this machine's "
            f"{memory / 2**30:.3g} GiB: fewer samples, steps or outputs, or series = false")


def variant_series(results, columns: list[str], rows: int) -> list[np.ndarray]:
    """A variant's run as its series: [t, then each output column], float64 each;
    ValueError when the run has not the study's ``rows`` rows (a fault of pam2exu)."""
    if len(results.t) != rows:
        raise ValueError(f"the variant's run has {len(results.t)} rows, the study's "
                         f"nominal run {rows}")
    return [np.asarray(results.t, dtype=float)] + \
        [np.asarray(results[c], dtype=float) for c in columns]


def chunk_series(variants: list, outputs: int, rows: int) -> dict[str, np.ndarray]:
    """A chunk's series columns: ``T_KEY`` and ``series_key(j)``, each (variants, rows);
    a variant in error (None in ``variants``) is NaN."""
    block = np.full((outputs + 1, len(variants), rows), np.nan)
    for k, series in enumerate(variants):
        if series is not None:
            block[:, k, :] = series
    return {T_KEY: block[0], **{series_key(j): block[j + 1] for j in range(outputs)}}


def split(columns: dict) -> tuple[dict, dict]:
    """The merged chunks' columns as (the per-variant table, the series columns)."""
    table = {n: c for n, c in columns.items() if not n.startswith(PREFIX)}
    series = {n: c for n, c in columns.items() if n.startswith(PREFIX)}
    return table, series


def long_table(table: dict, series: dict, outputs: list[str]) -> dict[str, np.ndarray]:
    """The series in long format: ``sample``, ``t``, each output; the rows of the variants
    that ran (status not error) in variant order, each its rows in time order.

    Examples
    --------
    >>> table = {"sample": np.array([0, 1, 2]), "status": np.array(["ok", "error", "rejected"])}
    >>> t = np.array([[0.0, 1.0]] * 3)
    >>> y = np.array([[1.0, 2.0], [np.nan, np.nan], [3.0, 4.0]])
    >>> long = long_table(table, {T_KEY: t, series_key(0): y}, ["motor.Mz"])
    >>> {n: c.tolist() for n, c in long.items()}
    {'sample': [0, 0, 2, 2], 't': [0.0, 1.0, 0.0, 1.0], 'motor.Mz': [1.0, 2.0, 3.0, 4.0]}
    """
    ran = table["status"] != ERROR
    t = series[T_KEY][ran]
    out = {"sample": np.repeat(np.asarray(table["sample"], dtype=np.int64)[ran], t.shape[1]),
           "t": t.reshape(-1).copy()}
    for j, name in enumerate(outputs):
        out[name] = series[series_key(j)][ran].reshape(-1).copy()
    return out


def series_path(out: str | Path) -> Path:
    """``OUT.series.parquet`` beside ``OUT.parquet``, ``OUT.series.csv`` beside ``OUT.csv``."""
    out = Path(out)
    return out.with_name(f"{out.stem}.series{out.suffix}")


def write_csv(series: dict[str, np.ndarray], path: str | Path) -> Path:
    """Write the long table as CSV: a header of its names, then one line per row, the
    sample as an integer, the numbers in the shortest digits that read back exactly;
    ``BLOCK`` values formatted at a time, under a temporary name then renamed."""
    names = list(series)
    samples = series["sample"]
    numbers = [series[n] for n in names[1:]]
    step = max(1, BLOCK // max(len(numbers), 1))

    def write_to(tmp: Path) -> None:
        with open(tmp, "w", encoding="utf-8", newline="\n") as fh:
            fh.write(csv_header(names) + "\n")
            for start in range(0, len(samples), step):
                block = np.column_stack([c[start:start + step] for c in numbers])
                lines = csv_block(block).tobytes().decode("ascii").splitlines()
                fh.writelines(f"{s},{line}\n" for s, line in
                              zip(samples[start:start + step].tolist(), lines))

    return write_whole(Path(path), write_to)

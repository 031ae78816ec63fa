"""A result table as CSV: the writer of ``Results.to_csv`` (the shortest digits that read
back bit for bit, written whole or not at all) and the fast reader of exactly what it
writes (``own_values``; ``reading.read_csv`` reads any other file the general way).
"""
from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np

from .units import units_line
from .writers import BOM, csv_translation, write_whole


def write_csv(path: Path, names: list[str], values: np.ndarray, units: dict[str, str],
              sep: str = ",", decimal: str = ".", bom: bool = False) -> Path:
    """Write the table (``names``, ``t`` first; ``values`` (rows, columns)) as
    ``Results.to_csv`` says, under a temporary name then renamed: a failure leaves
    neither half a file nor the temporary one."""
    translate = csv_translation(sep, decimal)

    def write_to(tmp: Path) -> None:
        with open(tmp, "wb") as fh:
            fh.write((BOM if bom else b"") + (csv_header(names, sep) + "\n").encode())
            fh.write(units_line(names, units, sep).encode())   # degrees only
            for lines in csv_lines(values):
                fh.write(lines if translate is None else translate[lines])

    return write_whole(path, write_to)


#: values the CSV writer formats at once: ~20 bytes each, so its memory stays bounded
BLOCK = 1 << 20
_COMMA, _NEWLINE, _MINUS, _ZERO = b",\n-0"
#: the bytes of the lines of numbers that ``csv_block`` writes (only such text reaches
#: scipy's C++ reader: scipy 1.17's crashes on some other, e.g. a last line '…,7e')
_WRITTEN = b"0123456789.-e,\nnaifty"


def csv_header(names, sep: str = ",") -> str:
    """The header line (no line end): names ``sep`` separated, quoted when CSV needs it.

    A name holding ',', ';', '"' or a line break is written in quotes, '"' doubled.

    Examples
    --------
    >>> csv_header(["t", "a,b.x", 'q"uo.y', "Força.Fx"])
    't,"a,b.x","q""uo.y",Força.Fx'
    """
    return sep.join(csv_field(n) for n in names)


def csv_field(name: str) -> str:
    """A name as a CSV field: in quotes, '"' doubled, when it holds ',', ';', '"' or a
    line break (``csv_header``, the extremes' file)."""
    return '"' + name.replace('"', '""') + '"' if any(c in name for c in ',;"\r\n') else name


def csv_block(values: np.ndarray) -> np.ndarray:
    """CSV lines of a (rows, columns) float block: the shortest digits that read back exactly.

    scipy's Matrix Market writer (fast_matrix_market: shortest round-trip digits, C++,
    several threads) writes the numbers one a line, row after row; every line end but each
    row's last becomes ',', and letters become lower case (``1e-5``, ``nan``, ``infinity``).

    Parameters
    ----------
    values : numpy.ndarray
        float64, shape (rows, columns), rows ≥ 1.

    Returns
    -------
    numpy.ndarray
        The ASCII text as uint8 (writable to a binary file as it is): one line per row, each
        ended by '\\n'.

    Examples
    --------
    >>> csv_block(np.array([[0.1 + 0.2, -0.0, 1e300], [5e-324, 2.0, -np.inf]])).tobytes()
    b'3.0000000000000004e-1,-0,1e300\\n5e-324,2,-infinity\\n'
    """
    import scipy.io
    out = io.BytesIO()
    scipy.io.mmwrite(out, values.T, field="real", symmetry="general")
    head, start = out.getbuffer()[:1024].tobytes(), 0
    while head.startswith(b"%", start):       # the banner and comment lines
        start = head.index(b"\n", start) + 1
    start = head.index(b"\n", start) + 1       # the size line
    text = np.frombuffer(out.getbuffer(), np.uint8, offset=start)
    ends = np.flatnonzero(text == _NEWLINE)
    if ends.size != values.size:
        raise RuntimeError(f"scipy.io.mmwrite wrote {ends.size} lines for {values.size} numbers")
    text |= 0x20                  # 'E' → 'e', 'NaN' → 'nan'; digits, '.', '-' have the bit
    text[ends] = _COMMA
    text[ends[values.shape[1] - 1::values.shape[1]]] = _NEWLINE
    return text



def csv_cells(values: np.ndarray) -> list[list[str]]:
    """The cells of a (rows, columns) float block (``csv_block``'s digits), NaN as an empty
    field: the numbers of a table whose other cells are text.

    >>> csv_cells(np.array([[0.5, np.nan], [16.0, -0.0]]))
    [['5e-1', ''], ['1.6e1', '-0']]
    """
    return [["" if c == "nan" else c for c in line.split(",")]
            for line in csv_block(values).tobytes().decode("ascii").splitlines()]

def csv_lines(values: np.ndarray):
    """``csv_block`` of a (rows, columns) array, ``BLOCK`` values at a time (uint8 text)."""
    step = max(1, BLOCK // max(values.shape[1], 1))
    for start in range(0, values.shape[0], step):
        yield csv_block(values[start:start + step])


def own_values(path: Path) -> tuple[list[str], np.ndarray] | None:
    """A file exactly as ``to_csv`` writes it, read fast; None for any other file.

    scipy's Matrix Market reader (fast_matrix_market: fast_float, correctly rounded, C++)
    reads the numbers; they are taken only when ``csv_lines`` writes them back as the
    file's own bytes, so they are what the general reader (``reading.load_table``, which
    ``compare`` uses) reads, bit for bit, whatever the file holds. Anything else (another
    writer's digits, comments, ';', a byte-order mark, CRLF) is None, and ``read_csv`` reads
    it the general way.

    Parameters
    ----------
    path : Path
        The CSV file.

    Returns
    -------
    (list of str, numpy.ndarray) or None
        The header's names, ``t`` first, and the values, one row per name; None when the
        file is not exactly ``to_csv``'s (or cannot be read: the general reader says why).
    """
    import scipy.io
    try:
        raw = path.read_bytes()
        end = raw.index(b"\n")
        header = raw[:end].decode("utf-8")
        names = next(csv.reader([header]), [])
    except (OSError, ValueError, csv.Error):   # UnicodeDecodeError is a ValueError
        return None
    body = raw[end + 1:]
    rows = body.count(b"\n")
    if rows == 0 or not body.endswith(b"\n") or body.translate(None, _WRITTEN) \
            or names[:1] != ["t"] or len(set(names)) < len(names) or csv_header(names) != header:
        return None
    banner = f"%%MatrixMarket matrix array real general\n{len(names)} {rows}\n".encode()
    try:
        values = scipy.io.mmread(io.BytesIO(banner + body.replace(b",", b"\n")))
    except ValueError:
        return None
    text = np.frombuffer(raw, np.uint8)
    if b"-0," in body or b"-0\n" in body:      # the reader makes "-0" +0.0
        ends = end + 1 + np.flatnonzero((text[end + 1:] == _COMMA) | (text[end + 1:] == _NEWLINE))
        if ends.size != values.size:
            return None
        starts = np.r_[end + 1, ends[:-1] + 1]
        k = np.flatnonzero((ends - starts == 2) & (text[starts] == _MINUS)
                           & (text[starts + 1] == _ZERO))
        values[k % len(names), k // len(names)] = -0.0
    at = end + 1
    for block in csv_lines(values.T):
        if not np.array_equal(text[at:at + block.size], block):
            return None
        at += block.size
    if at != text.size:
        return None
    return names, values

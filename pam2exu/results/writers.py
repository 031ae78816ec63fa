"""A result table in other forms: an Excel workbook, Parquet, a pandas DataFrame, CSV for
locales with a decimal comma, and HTML for notebooks.

``Exports`` holds ``Results``' methods ``to_excel``, ``to_parquet``, ``to_pandas`` and
``_repr_html_`` (``Results`` inherits them); ``csv_translation`` the bytes ``Results.to_csv``
changes for ``sep`` and ``decimal``; ``write`` chooses the format from a file's suffix
(``pam2exu run -o``). The libraries are optional extras, imported only when used: openpyxl
(``pip install "pam2exu[excel]"``), pyarrow (``[parquet]``), pandas (``[pandas]``); without
one, ``OutputError`` names the extra to install. Every number is written exactly: reading
the file back gives the same floats, bit for bit.
"""
from __future__ import annotations

import html
import importlib
import json
from pathlib import Path

import numpy as np

from ..errors import OutputError

#: optional library → the pam2exu extra that installs it
EXTRAS = {"openpyxl": "excel", "pyarrow": "parquet", "pandas": "pandas"}
#: file suffix → what ``write`` writes (``pam2exu run -o``)
FORMATS = {".csv": "CSV", ".xlsx": "Excel workbook", ".parquet": "Parquet"}
#: separators and decimal marks ``to_csv`` writes (the reader takes ';' or tab with ',')
SEPARATORS, DECIMALS = (",", ";", "\t"), (".", ",")
BOM = b"\xef\xbb\xbf"
#: Excel's largest sheet: rows (two header rows) and columns
EXCEL_ROWS, EXCEL_COLUMNS = 1_048_576, 16_384
#: rows and columns a notebook shows of a table
HTML_ROWS, HTML_COLUMNS = 5, 12
#: what ``to_excel`` writes for values that are not finite (Excel has no NaN): CSV's words
NOT_FINITE = {"nan": "nan", "inf": "infinity", "-inf": "-infinity"}


def optional(module: str, purpose: str):
    """Import an optional library; OutputError naming its extra when it is not installed.

    Examples
    --------
    >>> optional("json", "a test").__name__
    'json'
    """
    try:
        return importlib.import_module(module)
    except ImportError:
        extra = EXTRAS.get(module.partition(".")[0], module)
        raise OutputError(f"{purpose} needs the library {module.partition('.')[0]}, which is "
                          f"not installed: pip install \"pam2exu[{extra}]\"") from None


def csv_translation(sep: str = ",", decimal: str = ".") -> np.ndarray | None:
    """Byte map from ``to_csv``'s ',' and '.' to ``sep`` and ``decimal`` (None: no change).

    Parameters
    ----------
    sep : str
        Separator: ',' (default), ';' or a tab.
    decimal : str
        Decimal mark: '.' (default) or ','; ',' needs ``sep`` ';' or a tab.

    Returns
    -------
    numpy.ndarray or None
        256 bytes, indexed by a byte of the '.'-CSV; None for ',' and '.'.

    Raises
    ------
    OutputError
        An unknown separator or decimal mark, or both ','.

    Examples
    --------
    >>> bytes(csv_translation(";", ",")[np.frombuffer(b"1.5,-2e-1", np.uint8)])
    b'1,5;-2e-1'
    """
    if sep not in SEPARATORS or decimal not in DECIMALS:
        raise OutputError(f"CSV separator {sep!r} and decimal mark {decimal!r}: the separator "
                          f"is ',', ';' or a tab, the decimal mark '.' or ','")
    if sep == decimal:
        raise OutputError("a CSV file with a decimal comma needs another separator: "
                          "sep=';' (--sep ';'), as Excel writes it in Catalan or Spanish")
    if (sep, decimal) == (",", "."):
        return None
    table = np.arange(256, dtype=np.uint8)
    table[ord(",")], table[ord(".")] = ord(sep), ord(decimal)
    return table


#: the library each format needs (besides numpy), with what it is for
_LIBRARIES = {".xlsx": ("openpyxl", "an Excel workbook"), ".parquet": ("pyarrow", "a Parquet file")}


def check(path: str | Path, sep: str = ",", decimal: str = ".", bom: bool = False) -> str:
    """The format ``write`` would write ``path`` in (its suffix), or OutputError saying why it
    cannot: checked before a run, so that a long run is not lost to a file name."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in FORMATS:
        known = ", ".join(f"{s} ({what})" for s, what in FORMATS.items())
        raise OutputError(f"cannot write '{path}': the format is chosen by the file suffix, "
                          f"one of {known}")
    if suffix != ".csv" and ((sep, decimal) != (",", ".") or bom):
        raise OutputError(f"cannot write '{path}': the separator, decimal mark and byte-order "
                          f"mark are for .csv files only; drop --sep, --decimal and --bom")
    csv_translation(sep, decimal)
    if suffix in _LIBRARIES:
        optional(*_LIBRARIES[suffix])
    return suffix


def write(res, path: str | Path, sep: str = ",", decimal: str = ".", bom: bool = False) -> Path:
    """Write a Results table in the format of the file's suffix: .csv, .xlsx or .parquet.

    What ``pam2exu run -o`` writes.

    Parameters
    ----------
    res : Results
        The table.
    path : str or Path
        The file; its suffix (any case) chooses the format.
    sep, decimal : str
        CSV only: separator and decimal mark (see ``Results.to_csv``).
    bom : bool
        CSV only: start with a UTF-8 byte-order mark.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    OutputError
        An unknown suffix (never CSV text under another name), CSV options for another
        format, or the format's library not installed.
    """
    suffix = check(path, sep, decimal, bom)
    if suffix == ".xlsx":
        return res.to_excel(path)
    if suffix == ".parquet":
        return res.to_parquet(path)
    return res.to_csv(path, sep=sep, decimal=decimal, bom=bom)


def write_whole(path: Path, write_to) -> Path:
    """Call ``write_to(temporary path)`` then rename it to ``path``: a failure leaves neither
    half a file nor the temporary one."""
    tmp = path.with_name(path.name + ".part")
    try:
        write_to(tmp)
        tmp.replace(path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    return path


def _facts(res) -> list[tuple[str, object]]:
    """(name, value) of what a table knows besides its columns: model, analysis, rows,
    interval, the checks, the warnings and the run facts (``info``)."""
    rows = [("model", res.model), ("analysis", res.analysis), ("rows", len(res)),
            ("columns", len(res.columns))]
    if len(res):
        rows += [("t first [s]", float(res.t[0])), ("t last [s]", float(res.t[-1]))]
    rows += [("check", c) for c in res.checks()]
    rows += [("warning", w) for w in res.warnings]
    return rows + [(f"info: {k}", v) for k, v in dict(res.info).items()]


class Exports:
    """``Results``' other forms: workbook, Parquet, DataFrame, notebook HTML (see the
    module's doc). Uses ``columns``, ``units``, ``to_numpy``, ``checks`` and the run facts."""

    def to_excel(self, path: str | Path) -> Path:
        """Write an Excel workbook (.xlsx): the columns with their units, then the run.

        Sheet ``results``: row 1 the names (``t`` first), row 2 the SI units, then one row
        per time; every number is written with the fewest digits that read back as the same
        float (openpyxl alone would round to 16 digits), values that are not finite as the
        text ``nan``, ``infinity``, ``-infinity`` (Excel has no NaN). Sheet ``model``: the
        model's name, the analysis, rows, interval, the checks, the warnings and the run
        facts, one a row. Written with openpyxl (``pip install "pam2exu[excel]"``), under a
        temporary name then renamed.

        Parameters
        ----------
        path : str or Path
            The workbook to write (replaced if it exists).

        Returns
        -------
        Path
            ``path``.

        Raises
        ------
        OutputError
            openpyxl is not installed, or the table is larger than a sheet (1,048,576 rows,
            16,384 columns: write Parquet or CSV instead).

        Examples
        --------
        >>> from pam2exu import Results
        >>> res = Results([0.0, 1.0], {"crank.fi": [0.0, 6.0]}, {"crank.fi": "rad"})
        >>> res.to_excel("crank.xlsx")                  # doctest: +SKIP
        PosixPath('crank.xlsx')
        """
        openpyxl = optional("openpyxl", "an Excel workbook")
        from openpyxl.cell import WriteOnlyCell
        path = Path(path)
        names = ["t", *self.columns]
        if len(self) + 2 > EXCEL_ROWS or len(names) > EXCEL_COLUMNS:
            raise OutputError(f"cannot write '{path}': {len(self)} rows × {len(names)} columns "
                              f"do not fit in an Excel sheet ({EXCEL_ROWS - 2} rows, "
                              f"{EXCEL_COLUMNS} columns); write .parquet or .csv instead")
        book = openpyxl.Workbook(write_only=True)
        sheet = book.create_sheet("results")
        sheet.freeze_panes = "B3"
        sheet.append(names)
        sheet.append([self.units.get(n, "") for n in names])

        def number(x: float):
            if x != x or x in (np.inf, -np.inf):
                return NOT_FINITE[str(x)]
            cell = WriteOnlyCell(sheet, value=repr(x))   # shortest digits, written as they are
            cell.data_type = "n"
            return cell
        for row in self.to_numpy().tolist():
            sheet.append([number(x) for x in row])
        facts = book.create_sheet("model")
        for name, value in _facts(self):
            facts.append([name, value])
        return write_whole(path, book.save)

    def to_parquet(self, path: str | Path) -> Path:
        """Write a Parquet file: one float64 column per variable, ``t`` first, with units.

        Each column's unit is in its field's metadata (``unit``); the model, analysis,
        checks and warnings in the schema's (``pam2exu``, JSON). Read back with
        ``pyarrow.parquet.read_table`` or ``pandas.read_parquet``: the same floats, bit for
        bit. Written with pyarrow (``pip install "pam2exu[parquet]"``), under a temporary
        name then renamed; suited to large runs.

        Parameters
        ----------
        path : str or Path
            The file to write (replaced if it exists).

        Returns
        -------
        Path
            ``path``.

        Raises
        ------
        OutputError
            pyarrow is not installed.

        Examples
        --------
        >>> from pam2exu import Results
        >>> res = Results([0.0, 1.0], {"crank.fi": [0.0, 6.0]}, {"crank.fi": "rad"})
        >>> res.to_parquet("crank.parquet")             # doctest: +SKIP
        PosixPath('crank.parquet')
        """
        pa = optional("pyarrow", "a Parquet file")
        parquet = optional("pyarrow.parquet", "a Parquet file")
        names = ["t", *self.columns]
        fields = [pa.field(n, pa.float64(), metadata={"unit": self.units.get(n, "")})
                  for n in names]
        about = {"model": self.model, "analysis": self.analysis, "checks": self.checks(),
                 "warnings": list(self.warnings)}
        schema = pa.schema(fields, metadata={"pam2exu": json.dumps(about)})
        data = self.to_numpy().T
        table = pa.Table.from_arrays([pa.array(data[j]) for j in range(len(names))],
                                     schema=schema)
        return write_whole(Path(path), lambda tmp: parquet.write_table(table, tmp))

    def to_pandas(self):
        """The table as a pandas DataFrame: column ``t`` first, then every variable.

        The values are copies of the table's, bit for bit; ``df.attrs`` holds ``units``
        (name → SI unit), ``model``, ``analysis``, ``checks`` and ``warnings``. Needs pandas
        (``pip install "pam2exu[pandas]"``).

        Returns
        -------
        pandas.DataFrame
            One row per time, one float64 column per name of ``["t", *columns]``.

        Raises
        ------
        OutputError
            pandas is not installed.

        Examples
        --------
        >>> from pam2exu import Results
        >>> res = Results([0.0, 1.0], {"crank.fi": [0.0, 6.0]}, {"crank.fi": "rad"})
        >>> df = res.to_pandas()
        >>> df.columns.tolist(), df.attrs["units"]["crank.fi"]
        (['t', 'crank.fi'], 'rad')
        """
        pd = optional("pandas", "a DataFrame")
        names = ["t", *self.columns]
        data = self.to_numpy()
        df = pd.DataFrame({n: data[:, j].copy() for j, n in enumerate(names)})
        df.attrs.update(units={n: self.units.get(n, "") for n in names}, model=self.model,
                        analysis=self.analysis, checks=self.checks(),
                        warnings=list(self.warnings))
        return df

    def _repr_html_(self) -> str:
        """The table in a notebook: its head line, the first rows under names and units
        (at most ``HTML_COLUMNS`` columns), the checks and the warnings."""
        names = ["t", *self.columns]
        shown = names[:HTML_COLUMNS]
        e = html.escape
        head = (f"{e(self.analysis or 'result')} analysis of '{e(self.model)}': {len(self)} "
                f"rows, {len(self.columns)} columns")
        if len(self):
            head += f", t = {self.t[0]:g} … {self.t[-1]:g} s"
        more = len(names) - len(shown)
        cells = lambda row, tag: "".join(f"<{tag}>{x}</{tag}>" for x in row)  # noqa: E731
        rows = [f"<tr>{cells([e(n) for n in shown], 'th')}</tr>",
                f"<tr>{cells([e(self.units.get(n, '')) for n in shown], 'td')}</tr>"]
        data = self.to_numpy()
        for k in range(min(len(self), HTML_ROWS)):
            rows.append(f"<tr>{cells([f'{x:.6g}' for x in data[k, :len(shown)]], 'td')}</tr>")
        if len(self) > HTML_ROWS:
            rows.append(f"<tr><td colspan='{len(shown)}'>… {len(self) - HTML_ROWS} more rows"
                        f"</td></tr>")
        out = [f"<div class='pam2exu-results'><p><b>{head}</b></p>",
               "<table><thead>" + "".join(rows[:2]) + "</thead><tbody>" + "".join(rows[2:])
               + "</tbody></table>"]
        if more:
            out.append(f"<p>… and {more} more columns: {e(', '.join(names[len(shown):][:8]))}"
                       f"{', …' if more > 8 else ''}</p>")
        if self.checks():
            out.append(f"<p>checks: {e('; '.join(self.checks()))}</p>")
        out += [f"<p>warning: {e(w)}</p>" for w in self.warnings]
        return "\n".join(out) + "</div>"

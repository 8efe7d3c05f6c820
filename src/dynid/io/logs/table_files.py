"""Reading numeric columns of delimited text logs, block by block, with errors that name file and line.

Logs of real robots are long (an hour at 1 kHz is 3.6 million lines) and sometimes damaged: the
reader parses blocks of lines with NumPy's C parser, keeps only the requested columns, and on any
problem reports the file, the line number (1-based, counting header lines) and the column.

A file over :data:`ARROW_BYTES` is first read by pyarrow's multithreaded CSV reader where pyarrow is
installed (the ``long-logs`` extra; an hour-long log in 2.6 s instead of 16.1 s): both parsers round every field to
the nearest float64, so the values are the same. Whatever that reader would accept differently from the
line reader (a blank or whitespace-only line, which pyarrow refuses, carriage returns before the first
data line, a field that is not a plain number, NaN, a truncated or odd line, a row range past the end)
sends the file to the line reader, which reads it, or refuses it with its message.
"""

from __future__ import annotations

import datetime
import json
import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..._util.column_store import ColumnFile, StoredColumns
from ...exceptions import DataError
from ...runtime.threads import cores
from ..files import text_encoding_hint

BLOCK = 100_000

ARROW_BYTES = 32 * 2**20
"""Files larger than this are read by pyarrow's CSV reader where it is installed (smaller ones do not repay
its import, 0.04 s)."""

ARROW_BLOCK = 4 * 2**20
"""Bytes of text per block of pyarrow's streaming reader (4 MB: the fastest of 4 and 16 MB on an hour-long log,
and the peak stays one block)."""


@dataclass(frozen=True)
class Table:
    """Columns read from a delimited file.

    Attributes
    ----------
    data : (N, n_columns) array, or StoredColumns
        The requested columns, in the requested order (stored in temporary files when read with ``spool``).
    first_line : int
        File line number (1-based) of the first returned row.
    warnings : tuple of str
        Problems that were fixed (e.g. a truncated last line skipped).
    """

    data: np.ndarray | StoredColumns
    first_line: int
    warnings: tuple[str, ...] = ()


def table_head(fh, delimiter: str, header: bool) -> tuple[str | None, int]:
    """Read a table's head: its comment lines (``#`` first) and its header line, leaving ``fh`` at the first data line.

    A header written as a comment (NumPy's ``savetxt(header=...)`` writes ``# t,q1,…``) is the last comment line
    right before the data.

    Parameters
    ----------
    fh : text file
        At its start; seekable.
    delimiter : str
    header : bool
        Whether the table has a header line.

    Returns
    -------
    header : str or None
        The header's text (without ``#``), None without a header or in an empty file.
    lines : int
        The lines read before the first data line.
    """
    comments, lines = [], 0
    while True:
        at = fh.tell()
        line = fh.readline()
        if not line.lstrip().startswith("#"):
            break
        comments.append(line.lstrip()[1:])
        lines += 1
    if not header:
        fh.seek(at)
        return None, lines
    if comments and is_data_line(line, delimiter):
        fh.seek(at)
        return comments[-1], lines
    return (line or None), lines + 1


def is_data_line(line: str, delimiter: str) -> bool:
    """Whether a table's line is data (its first field a number) rather than a header.

    Parameters
    ----------
    line : str
    delimiter : str

    Returns
    -------
    bool
    """
    fields = line.split() if delimiter == " " else line.split(delimiter)
    try:
        float(fields[0])
    except (ValueError, IndexError):
        return False
    return True


def _split_header(line: str, delimiter: str) -> list[str]:
    return [f.strip().strip('"') for f in line.rstrip("\r\n").split(delimiter)]


def resolve_columns(path: Path, columns, header: list[str] | None, delimiter: str = ",") -> list[int]:
    """0-based indices of columns given as 1-based numbers or header names.

    Parameters
    ----------
    path : Path
        The file, named in errors.
    columns : sequence of int or str
    header : list of str or None
    delimiter : str
        The field separator the header was split on, named in an error where the header is one field.

    Returns
    -------
    list of int

    Raises
    ------
    DataError
        A column the file does not have.
    """
    out = []
    for c in columns:
        if isinstance(c, str):
            if header is None:
                raise DataError(f"{path}: column {c!r} is a name but the file has no header; give 1-based column numbers")
            if c not in header:
                raise DataError(f"{path}: no column named {c!r} in the header (found {', '.join(header)})"
                                + (_separator_hint(header[0], delimiter) if len(header) == 1 else ""))
            if header.count(c) > 1:  # the first was taken in silence (a ROS-style export repeats names)
                where = [str(k + 1) for k, name in enumerate(header) if name == c]
                raise DataError(f"{path}: the header names {header.count(c)} columns {c!r} (columns {', '.join(where)}): "
                                "give the one meant by its 1-based number, or rename the others")
            out.append(header.index(c))
        else:
            if int(c) < 1:
                raise DataError(f"{path}: column numbers are 1-based, got {c}")
            out.append(int(c) - 1)
    return out


def read_table(path: str | Path, columns, *, header: bool = False, delimiter: str = ",",
               n_columns: int | None = None, rows: tuple[int, int] | None = None, spool: bool = False,
               missing: bool = False, stamps=(), decimal: str = ".",
               progress: Callable[[int, int], None] | None = None) -> Table:
    """Read numeric columns from a delimited text file.

    Parameters
    ----------
    path : path
    columns : sequence of int or str
        1-based column numbers, or header names when ``header`` is true.
    header : bool
        Whether the first line holds column names.
    delimiter : str
    n_columns : int, optional
        Number of fields every line must have (default: that of the first data line).
    rows : (first, last), optional
        1-based, inclusive range of data rows (header excluded) to read; default all.
    spool : bool
        Write each block's columns to temporary files (:mod:`dynid._util.column_store`) instead of holding
        them: a long log's memory is then one block, whatever its length.
    missing : bool
        Read an empty field or NaN as NaN (a missing value, for the caller to fill or refuse) instead of refusing it.
    stamps : sequence of int or str
        Columns of ``columns`` that may hold ISO 8601 dates and times (``2026-11-28T01:02:03.250``, a logger's time
        stamps), read as POSIX seconds (UTC where the stamp names no zone).
    decimal : {".", ","}
        The numbers' decimal separator: "," for a spreadsheet's export in a European locale (``0,25;-1,5``), whose
        delimiter is then not a comma.
    progress : callable, optional
        ``progress(done, total)`` in bytes of the file as its blocks are read (about one block of
        :data:`ARROW_BLOCK` bytes or :data:`BLOCK` lines a call).

    Returns
    -------
    Table

    Raises
    ------
    DataError
        Missing file; a line with the wrong number of fields (except a truncated last line without a
        newline, which is skipped with a warning); a field that is not a number; NaN (unless ``missing``) or
        infinity; an empty selection. The message names the file, the line and, where it applies, the column.
    """
    path = Path(path)
    first, last = _checked(path, rows, delimiter, decimal)
    size = path.stat().st_size
    said = progress if progress is not None else (lambda done, total: None)
    fast = _arrow_table(path, columns, header, delimiter, n_columns, rows=(first, last), spool=spool, decimal=decimal,
                        progress=said)
    if fast is not None:
        return fast
    warnings: list[str] = []
    blocks: list[np.ndarray] = []
    files: list[ColumnFile] | None = None
    line_no = 0
    names = None
    cols: list[int] | None = None
    expected = n_columns
    first_line = None
    with open(path, encoding="utf-8-sig", errors="replace", newline="") as fh:  # -sig: a spreadsheet's byte-order mark
        head, line_no = table_head(fh, delimiter, header)
        if header:
            if head is None:
                raise DataError(f"{path}: empty file, expected a header line")
            names = _split_header(head, delimiter)
        cols = resolve_columns(path, columns, names, delimiter)
        dated = {cols[list(columns).index(c)] for c in stamps}
        pending: list[str] = []
        pending_start = None
        data_row = 0
        read = 0  # characters of the lines read (bytes in an ASCII file), for progress

        def flush():
            nonlocal files
            if pending:
                block = _parse_block(path, pending, pending_start, cols, delimiter, missing=missing, dated=dated)
                pending.clear()
                said(min(read, size), size)
                if not spool:
                    blocks.append(block)
                    return
                if files is None:
                    files = [ColumnFile() for _ in range(block.shape[1])]
                for j, f in enumerate(files):
                    f.append(block[:, j])

        for line in fh:
            line_no += 1
            read += len(line)
            if not line.strip():
                continue
            data_row += 1
            if data_row < first:
                continue
            if last is not None and data_row > last:
                break
            n_fields = line.count(delimiter) + 1
            if first_line is None:  # the first data line: the column map must fit it
                expected = n_fields if expected is None else expected
                if max(cols) >= expected:
                    raise DataError(f"{path}: line {line_no}: column {max(cols) + 1} requested but the lines have "
                                f"{expected} columns" + (_separator_hint(line, delimiter) if n_fields == 1 else ""))
            if n_fields != expected:  # the truncated last line (a warning), or a mistake (refused)
                _odd_line(path, line, line_no, n_fields, expected, delimiter=delimiter, warnings=warnings)
                break
            if first_line is None:
                first_line = line_no
            if not pending:
                pending_start = line_no
            pending.append(line if decimal == "." else line.replace(",", "."))
            if len(pending) >= BLOCK:
                flush()
        flush()
    _check_selection(path, not blocks and files is None, data_row, header, rows, bool(warnings))
    return _table_of(blocks, files, first_line, warnings)


def _checked(path: Path, rows: tuple[int, int] | None, delimiter: str, decimal: str) -> tuple[int, int | None]:
    """:func:`read_table`'s checks before it reads: a regular UTF-8 file, a range of rows and a decimal separator that
    can be; the range's first and last rows."""
    if path.exists() and not path.is_file():  # a FIFO or a device: never "not found", never read (a FIFO blocks)
        raise DataError(f"{path}: not a regular file ({'a folder' if path.is_dir() else 'a device, a FIFO or a socket'})"
                        ": give the log's file")
    if not path.is_file():
        raise DataError(f"{path}: file not found")
    hint = text_encoding_hint(path)
    if hint:
        raise DataError(f"{path}: not a UTF-8 text table{hint}")
    first, last = rows if rows is not None else (1, None)
    if first < 1 or (last is not None and last < first):
        raise DataError(f"{path}: rows: expected 1 <= first <= last, got {[first, last]}")
    if decimal not in (".", ",") or decimal == delimiter:
        raise ValueError(f"decimal: expected '.' or ',' and not the delimiter {delimiter!r}, got {decimal!r}")
    return first, last


def _table_of(blocks: list, files: list | None, first_line: int | None, warnings: list[str]) -> Table:
    """:func:`read_table`'s table: its blocks stacked in memory, or its columns' files (a spooled log)."""
    return Table(_stack(blocks) if files is None else StoredColumns(files), int(first_line or 1), tuple(warnings))


def _arrow_table(path: Path, columns, header: bool, delimiter: str, n_columns: int | None, *, rows: tuple,
                 spool: bool, decimal: str = ".", progress: Callable[[int, int], None] = lambda done, total: None
                 ) -> Table | None:
    """:func:`read_table` by pyarrow's streaming CSV reader, or None where the line reader must read the file
    (pyarrow not installed, a file under :data:`ARROW_BYTES`, or anything the line reader may treat otherwise)."""
    size = path.stat().st_size
    if size <= max(ARROW_BYTES, 0):
        return None
    try:
        import pyarrow as pa
        import pyarrow.csv as pc
    except ImportError:
        return None
    first, last = rows
    with open(path, "rb") as fh:  # lines up to the first data line, by "\n" as pyarrow and the line reader count them
        if fh.read(1) in (b"#", b"\xef"):  # comment lines, a header written as one, a byte-order mark: the line reader
            return None
        fh.seek(0)
        head = [fh.readline() for _ in range(int(header) + first - 1)]
        offset = fh.tell()
        line = fh.readline()  # the first data line: its fields are the file's
    if b"\r" in line or any(b"\r" in h or not h.strip() for h in head):  # other line ends, blank lines: the line reader
        return None
    names = _split_header(head[0].decode("utf-8", errors="replace"), delimiter) if header else None
    cols = resolve_columns(path, columns, names, delimiter)
    fields = line.count(delimiter.encode()) + 1
    if not line.strip() or fields != (n_columns or fields) or max(cols) >= fields:
        return None
    wanted = sorted(set(cols))
    order = [wanted.index(c) for c in cols]
    count = None if last is None else last - first + 1
    if pa.cpu_count() > cores():
        pa.set_cpu_count(cores())  # pyarrow's parsing threads: the cores this process may use
    try:
        with pa.OSFile(str(path)) as source:
            source.seek(offset)
            blocks, files, n = _arrow_blocks(pa, pc, source, cols, order, wanted=wanted, delimiter=delimiter, count=count,
                                             spool=spool, decimal=decimal,
                                             progress=lambda k: progress(min(offset + k * ARROW_BLOCK, size), size))
        pa.default_memory_pool().release_unused()  # its parsing buffers, which the pool would keep for reuse
    except (pa.ArrowException, KeyError, ValueError):  # anything it parses otherwise: the line reader decides
        return None
    if n == 0 or (count is not None and n < count):
        return None
    return Table(StoredColumns(files) if spool else _stack(blocks), int(header) + first)


def _arrow_blocks(pa, pc, source, cols: list[int], order: list[int], *, wanted: list[int], delimiter: str,
                  count: int | None, spool: bool, decimal: str = ".",
                  progress: Callable[[int], None] = lambda blocks: None) -> tuple[list, list | None, int]:
    """The blocks of :func:`_arrow_table` (kept, or appended to column files with ``spool``), and their rows;
    ValueError at a value that is not finite. ``progress(k)`` after the k-th block (one block of text each)."""
    reader = pc.open_csv(
        source, read_options=pc.ReadOptions(autogenerate_column_names=True, block_size=ARROW_BLOCK,
                                            use_threads=cores() > 1),
        parse_options=pc.ParseOptions(delimiter=delimiter, quote_char=False, ignore_empty_lines=False),
        convert_options=pc.ConvertOptions(include_columns=[f"f{c}" for c in wanted], null_values=[],
                                          column_types={f"f{c}": pa.float64() for c in wanted},
                                          strings_can_be_null=False, quoted_strings_can_be_null=False,
                                          decimal_point=decimal))
    blocks, files, n = [], None, 0
    for k, batch in enumerate(reader, 1):
        block = np.column_stack([batch.column(k).to_numpy() for k in order]).astype(np.float64, copy=False)
        if count is not None:
            block = block[:count - n]
        if block.size and not np.isfinite(block).all():
            raise ValueError("not finite")
        n += block.shape[0]
        if spool:
            files = files or [ColumnFile() for _ in cols]
            for j, f in enumerate(files):
                f.append(block[:, j])
        else:
            blocks.append(block)
        progress(k)
        if count is not None and n >= count:
            break
    return blocks, files, n


def _odd_line(path: Path, line: str, line_no: int, n_fields: int, expected: int | None, *, delimiter: str,
              warnings: list) -> None:
    """A line with another number of fields than the first: the file's truncated last line (no newline: a warning;
    reading stops there) or a mistake (DataError, with a hint where another delimiter is in the line)."""
    if not line.endswith("\n"):  # only the last line can lack a newline
        warnings.append(f"{path}: line {line_no} is truncated ({n_fields} of {expected} fields, no newline): skipped")
        return
    hint = _separator_hint(line, delimiter) if n_fields == 1 else ""
    raise DataError(f"{path}: line {line_no}: expected {expected} columns, got {n_fields}{hint}")


def _separator_hint(line: str, delimiter: str) -> str:
    """For a line read as one field: the separator it holds instead, and the setting that reads it ("" if none)."""
    other = next((d for d in (";", "\t", "|") if d != delimiter and d in line), None)
    return (f" (fields separated by {other!r}? dynid reads {delimiter!r}: give delimiter = {json.dumps(other)} in the "
            "dataset's table)" if other else "")


def _check_selection(path: Path, empty: bool, data_row: int, header: bool, rows, truncated: bool) -> None:
    """Refuse a table that holds no data row, or a ``rows`` selection that selects nothing or reaches past the end."""
    first, last = rows if rows is not None else (1, None)
    if empty:
        if data_row == 0:
            what = "only a header line" if header else "no data lines"
            raise DataError(f"{path}: {what} (an empty file, or not a text table?)")
        if rows is not None:
            raise DataError(f"{path}: rows = {[first, last]} selects nothing: the file has {data_row} data rows")
        raise DataError(f"{path}: no data rows")
    if last is not None and data_row < last and not truncated:
        raise DataError(f"{path}: rows = {[first, last]} goes beyond the file's end: it has {data_row} data rows")


def _stack(blocks: list[np.ndarray]) -> np.ndarray:
    """``np.concatenate(blocks)``, each block released once copied: the peak is the result and one block,
    not twice the log (an hour at 1 kHz of 19 columns is 550 MB)."""
    data = np.empty((sum(b.shape[0] for b in blocks), blocks[0].shape[1]))
    start = 0
    while blocks:
        block = blocks.pop(0)  # the list's reference goes; the next pop releases this block
        data[start:start + block.shape[0]] = block
        start += block.shape[0]
    return data


_DECIMAL_COMMA = re.compile(r"[+-]?\d*,\d+([eE][+-]?\d+)?")
"""A number written with a decimal comma (a spreadsheet's export in a European locale): ``-0,0131``."""


def decimal_commas(fields: list[str]) -> bool:
    """Whether a data line's fields write their numbers with a decimal comma (``-0,0131``; none with a point).

    Parameters
    ----------
    fields : list of str
        A data line split at its delimiter.

    Returns
    -------
    bool
    """
    commas = sum(_DECIMAL_COMMA.fullmatch(f.strip()) is not None for f in fields)
    return commas > 0 and not any("." in f for f in fields)


def _posix_seconds(text: str) -> float | None:
    """An ISO 8601 date and time as POSIX seconds (UTC where it names no zone), or None if it is not one."""
    try:
        stamp = datetime.datetime.fromisoformat(text)
    except ValueError:
        return None
    return (stamp if stamp.tzinfo is not None else stamp.replace(tzinfo=datetime.UTC)).timestamp()


def _parse_block(path: Path, lines: list[str], start: int, cols: list[int], delimiter: str, *,
                 missing: bool = False, dated: set[int] | frozenset = frozenset()) -> np.ndarray:
    try:
        block = np.loadtxt(lines, delimiter=delimiter, usecols=cols, ndmin=2, dtype=np.float64, comments=None)
    except ValueError:
        block = np.empty((len(lines), len(cols)))
        for k, line in enumerate(lines):  # field by field: an empty one missing (``missing``), else a precise message
            fields = line.rstrip("\r\n").split(delimiter)
            for i, c in enumerate(cols):
                text = fields[c].strip()
                try:
                    block[k, i] = np.nan if missing and not text else float(text)
                except ValueError:
                    if c in dated and (seconds := _posix_seconds(text)) is not None:
                        block[k, i] = seconds
                        continue
                    comma = _DECIMAL_COMMA.fullmatch(text) is not None
                    raise DataError(f"{path}: line {start + k}, column {c + 1}: expected a number, got {text!r}"
                                    + (" (a decimal comma? give decimal = \",\" in the dataset's table)" if comma else "")) from None
    bad = np.isinf(block) if missing else ~np.isfinite(block)
    if bad.any():
        k, c = np.argwhere(bad)[0]
        raise DataError(f"{path}: line {start + int(k)}, column {cols[int(c)] + 1}: "
                        f"{'infinite' if missing else 'NaN or infinite'} value")
    return block

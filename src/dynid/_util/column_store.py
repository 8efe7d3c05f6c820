"""Long logs held column by column in temporary files instead of in memory ("spooled").

An hour of a 6-joint log at 1 kHz is 3.6 million samples: each (N, 6) signal is 173 MB, and reading,
filtering and differentiating positions, velocities and torques held about a gigabyte at once. Every
step of the preprocessing works along time one column at a time (a zero-phase filter, a derivative, a
spectrum), and the regressor pass reads the samples chunk by chunk: so a long log's columns can live in
temporary files, one per column, read and written with ``pread``/``pwrite`` (not memory-mapped, so
that what was read does not stay in the process's memory), and only one column, or one chunk of rows,
is in memory at a time.

:class:`StoredColumns` is the time-first (N, k) float64 array of such a log: ``x[:, j]`` reads column j,
``x[a:b]`` is a view of rows a..b-1 (nothing read), ``x[index]`` with an integer array reads those rows,
and ``np.asarray(x)`` reads everything. :func:`by_column` and :func:`select_rows` apply the same
operation to an in-memory array or to stored columns, with the same numbers.

The files go to the temporary directory (``TMPDIR``); they are deleted when the last array using them
is released, and by the operating system if the process ends.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable

import numpy as np

from ..exceptions import DataError

__all__ = ["SPOOL_BYTES", "ColumnFile", "StoredColumns", "by_column", "correlation_matrix", "root_mean_square",
           "select_rows"]

SPOOL_BYTES = 256 * 2**20
"""Logs whose files hold more than this many bytes are spooled (a 6-minute 1 kHz log of 19 columns is 70 MB
of text and stays in memory; an hour is 700 MB)."""

ROW_CHUNK = 100_000
"""Rows per step of :meth:`StoredColumns.map_rows`."""


class ColumnFile:
    """One float64 column in an anonymous temporary file, appended to and read by offset."""

    __slots__ = ("_file", "n")

    def __init__(self):
        try:
            self._file = tempfile.TemporaryFile(prefix="dynid-column-")
        except OSError as exc:
            raise DataError(f"cannot create a temporary file in {tempfile.gettempdir()} for a long log: {exc.strerror} "
                            "(set TMPDIR to a writable folder)") from None
        self.n = 0

    def append(self, values: np.ndarray) -> None:
        """Append samples at the end of the column.

        Parameters
        ----------
        values : (n,) array_like
            Samples, converted to float64.
        """
        data = np.ascontiguousarray(values, dtype=np.float64).reshape(-1).data.cast("B")
        offset, done = 8 * self.n, 0
        try:
            while done < len(data):
                done += os.pwrite(self._file.fileno(), data[done:], offset + done)
        except OSError as exc:
            raise DataError(f"cannot write a long log's column to {tempfile.gettempdir()}: {exc.strerror} "
                            "(free some space, or set TMPDIR to another folder)") from None
        self.n += len(data) // 8

    def read(self, start: int, stop: int) -> np.ndarray:
        """Read a range of samples.

        Parameters
        ----------
        start, stop : int
            First sample and one past the last (``0 <= start <= stop <= len``).

        Returns
        -------
        (stop - start,) ndarray
            A new float64 array.
        """
        out = np.empty(max(stop - start, 0))
        view, done = out.data.cast("B"), 0
        while done < len(view):
            got = os.preadv(self._file.fileno(), [view[done:]], 8 * start + done)
            if got <= 0:
                raise DataError(f"a long log's temporary column ended early ({start + done // 8} of {stop} samples)")
            done += got
        return out


class StoredColumns:
    """A time-first (N, k) float64 array held in :class:`ColumnFile` s, one per column.

    Parameters
    ----------
    files : sequence of ColumnFile
    start, stop : int
        The rows of the files this array shows (a view; default all).
    """

    ndim = 2
    dtype = np.dtype(np.float64)

    def __init__(self, files, start: int = 0, stop: int | None = None):
        self.files = tuple(files)
        self.start = int(start)
        self.stop = int(min(f.n for f in self.files) if stop is None else stop)

    @classmethod
    def from_columns(cls, columns) -> StoredColumns:
        """Stored copies of 1-D arrays, one file per column.

        Parameters
        ----------
        columns : iterable of (N,) array_like
            The columns, all of one length; a generator keeps one column in memory at a time.

        Returns
        -------
        StoredColumns
            The stored columns, (N, k) with k the number of columns.
        """
        files = []
        for c in columns:
            files.append(ColumnFile())
            files[-1].append(c)
        return cls(files)

    @property
    def shape(self) -> tuple[int, int]:
        """``(rows, columns)`` of the view."""
        return (self.stop - self.start, len(self.files))

    def __len__(self) -> int:
        return self.stop - self.start

    def column(self, j: int) -> np.ndarray:
        """One column.

        Parameters
        ----------
        j : int
            Column index, ``0 <= j < k``.

        Returns
        -------
        (N,) ndarray
            A new float64 array.
        """
        return self.files[j].read(self.start, self.stop)

    def rows(self, a: int, b: int) -> np.ndarray:
        """A block of rows.

        Parameters
        ----------
        a, b : int
            First row and one past the last.

        Returns
        -------
        (b - a, k) ndarray
            A new C-ordered float64 array.
        """
        out = np.empty((max(b - a, 0), len(self.files)))
        for j, f in enumerate(self.files):
            out[:, j] = f.read(self.start + a, self.start + b)
        return out

    def select(self, columns, n_rows: int | None = None) -> StoredColumns:
        """A view of some columns and the first rows; nothing is copied.

        Parameters
        ----------
        columns : sequence of int
            Column indices, in the order wanted.
        n_rows : int, optional
            Keep the first ``n_rows`` rows (all by default).

        Returns
        -------
        StoredColumns
            A view over the same files.
        """
        stop = self.stop if n_rows is None else self.start + n_rows
        return StoredColumns([self.files[int(j)] for j in columns], self.start, stop)

    def map_columns(self, along_time: Callable[[np.ndarray, int], np.ndarray]) -> StoredColumns:
        """New stored columns computed column by column, one column in memory at a time.

        Parameters
        ----------
        along_time : callable
            ``along_time(column_j, j)`` -> (M,) array, the same M for every column.

        Returns
        -------
        StoredColumns
            (M, k) stored columns.
        """
        return StoredColumns.from_columns(along_time(self.column(j), j) for j in range(len(self.files)))

    def map_rows(self, row_wise: Callable[[np.ndarray], np.ndarray], chunk: int | None = None) -> StoredColumns:
        """New stored columns computed chunk of rows by chunk of rows.

        Parameters
        ----------
        row_wise : callable
            An (n, k) -> (n, k') map that treats each row alone.
        chunk : int, optional
            Rows per chunk (:data:`ROW_CHUNK` by default).

        Returns
        -------
        StoredColumns
            (N, k') stored columns.
        """
        chunk = chunk or ROW_CHUNK
        files = None
        for a in range(0, len(self), chunk):
            out = np.asarray(row_wise(self.rows(a, min(a + chunk, len(self)))))
            if files is None:
                files = [ColumnFile() for _ in range(out.shape[1])]
            for j, f in enumerate(files):
                f.append(out[:, j])
        return StoredColumns(files if files is not None else [ColumnFile() for _ in self.files])

    def __getitem__(self, key):
        n = len(self)
        if isinstance(key, slice):
            a, b, step = key.indices(n)
            if step < 1:
                raise TypeError("StoredColumns: rows are read forwards (a slice with a positive step)")
            if step != 1:
                return self.rows(a, b)[::step].copy() if b > a else np.empty((0, len(self.files)))
            return StoredColumns(self.files, self.start + a, self.start + max(a, b))
        if isinstance(key, tuple) and len(key) == 2 and key[0] == slice(None):
            return self.column(int(key[1]))
        index = np.asarray(key)
        if index.dtype.kind in "iu" and index.ndim == 1:
            if index.size == 0:
                return np.empty((0, len(self.files)))
            index = np.where(index < 0, index + n, index)
            if index.min() < 0 or index.max() >= n:
                raise IndexError(f"row index out of range for {n} rows")
            lo, hi = int(index.min()), int(index.max()) + 1
            return self.rows(lo, hi)[index - lo]
        raise TypeError(f"StoredColumns: unsupported index {key!r} (rows a:b, an integer array of rows, or [:, j])")

    def __array__(self, dtype=None, copy=None):
        out = self.rows(0, len(self))
        return out if dtype is None else out.astype(dtype, copy=False)

    def __repr__(self) -> str:
        return f"StoredColumns(shape={self.shape})"


def by_column(x, along_time: Callable[[np.ndarray, int], np.ndarray]):
    """Apply a map along time to each column of a time-first array, as an array of the same kind.

    Parameters
    ----------
    x : (N, ...) ndarray or StoredColumns
        Time-first samples; the trailing axes of an array are flattened into columns and restored.
    along_time : callable
        ``along_time(column_j, j)`` -> (M,) array.

    Returns
    -------
    (M, ...) ndarray or StoredColumns
        Stored columns stay stored; the same numbers either way.
    """
    if isinstance(x, StoredColumns):
        return x.map_columns(along_time)
    x = np.asarray(x, dtype=float)
    flat = x.reshape(x.shape[0], -1)
    out = None
    for c in range(flat.shape[1]):
        y = along_time(flat[:, c], c)
        if out is None:
            out = np.empty((y.shape[0], flat.shape[1]))
        out[:, c] = y
    if out is None:  # no columns
        return x.copy()
    return out.reshape((out.shape[0],) + x.shape[1:])


def select_rows(x, rows):
    """``x[rows]`` for an array or stored columns (which stay stored).

    Parameters
    ----------
    x : (N, ...) ndarray or StoredColumns
        Time-first samples.
    rows : (N,) bool array or (M,) int array
        A boolean mask or row indices.

    Returns
    -------
    (M, ...) ndarray or StoredColumns
        The selected rows.
    """
    if isinstance(x, StoredColumns):
        return x.map_columns(lambda column, j: column[rows])
    return x[rows]


def root_mean_square(x) -> np.ndarray:
    """Root mean square of each column, computed column by column.

    Column by column so that an array and stored columns give the same numbers (a sum along axis 0 of an (N, k)
    array adds in another order).

    Parameters
    ----------
    x : (N, k) ndarray or StoredColumns
        Time-first samples.

    Returns
    -------
    (k,) ndarray
        RMS of each column, in the unit of ``x``.
    """
    if not isinstance(x, StoredColumns):
        x = np.asarray(x, dtype=float)
    return np.array([np.sqrt(np.mean(x[:, j] ** 2)) for j in range(x.shape[1])])


def correlation_matrix(x, columns) -> np.ndarray:
    """The correlation coefficients of some columns (as :func:`numpy.corrcoef` of them), a block of rows at a time.

    Two passes of :data:`ROW_CHUNK` rows (the means, then the centred products), so that neither an array nor stored
    columns is copied whole (``np.corrcoef`` of an hour-long log's six torque columns held three copies of them); the
    same numbers for either.

    Parameters
    ----------
    x : (N, k) ndarray or StoredColumns
        Time-first samples.
    columns : sequence of int
        The columns correlated, in that order.

    Returns
    -------
    (m, m) ndarray
        ``m = len(columns)``; NaN where a column does not vary.
    """
    cols = [int(j) for j in columns]
    n = len(x)
    blocks = [(a, min(a + ROW_CHUNK, n)) for a in range(0, n, ROW_CHUNK)]
    mean = sum((np.asarray(x[a:b], dtype=float)[:, cols].sum(axis=0) for a, b in blocks), np.zeros(len(cols))) / max(n, 1)
    gram = np.zeros((len(cols), len(cols)))
    for a, b in blocks:
        centred = np.asarray(x[a:b], dtype=float)[:, cols] - mean
        gram += centred.T @ centred
    scale = np.sqrt(np.diag(gram))
    with np.errstate(invalid="ignore", divide="ignore"):
        return gram / np.outer(scale, scale)

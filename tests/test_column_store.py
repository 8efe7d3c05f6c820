"""Stored columns behave like the time-first arrays they hold, and a log read spooled gives the same numbers."""

import numpy as np
import pytest

import dynid._util.column_store as column_store
from dynid._util.column_store import ColumnFile, StoredColumns, by_column, root_mean_square, select_rows
from dynid.exceptions import DataError
from dynid.io.logs.table_files import read_table


@pytest.fixture
def x(rng):
    return rng.normal(size=(1000, 4))


@pytest.fixture
def stored(x):
    return StoredColumns.from_columns(x.T)


def test_stored_columns_index_like_the_array(x, stored):
    assert stored.shape == x.shape and len(stored) == 1000
    np.testing.assert_array_equal(np.asarray(stored), x)
    view = stored[100:-100]  # a view: nothing read
    assert isinstance(view, StoredColumns) and view.shape == (800, 4)
    np.testing.assert_array_equal(np.asarray(view[10:20]), x[110:120])
    np.testing.assert_array_equal(view[:, 2], x[100:-100, 2])
    index = np.arange(3, 800, 7)
    np.testing.assert_array_equal(view[index], x[100:-100][index])
    np.testing.assert_array_equal(stored[5:50:4], x[5:50:4])
    np.testing.assert_array_equal(np.asarray(stored.select([3, 1], 600)), x[:600, [3, 1]])
    rows = np.asarray(stored[10:30])
    assert rows.flags.c_contiguous  # the regressor kernel's layout
    with pytest.raises(IndexError):
        stored[np.array([1000])]
    with pytest.raises(TypeError, match="positive step"):
        stored[::-1]


def test_column_and_row_maps_equal_the_array_operations(x, stored):
    gains = np.array([1.0, -2.0, 3.5, 0.25])
    np.testing.assert_array_equal(np.asarray(by_column(stored, lambda c, j: c * gains[j])), by_column(x, lambda c, j: c * gains[j]))
    np.testing.assert_array_equal(by_column(x, lambda c, j: c * gains[j]), x * gains)
    m = np.array([[1.0, 0.2, 0, 0], [0, 1, 0, 0], [0, 0, 1, -0.3], [0, 0, 0, 2]])
    mapped = stored.map_rows(lambda r: r @ m, chunk=128)  # several chunks and a short last one
    np.testing.assert_allclose(np.asarray(mapped), x @ m, rtol=1e-15, atol=1e-15)
    mask = x[:, 0] > 0
    np.testing.assert_array_equal(np.asarray(select_rows(stored, mask)), x[mask])
    np.testing.assert_array_equal(root_mean_square(stored), root_mean_square(x))
    np.testing.assert_allclose(root_mean_square(x), np.sqrt(np.mean(x**2, axis=0)), rtol=1e-14)
    grid = np.linspace(0, 999, 250)  # a map that changes the length (resampling)
    resampled = by_column(stored, lambda c, j: np.interp(grid, np.arange(1000.0), c))
    assert resampled.shape == (250, 4)
    np.testing.assert_array_equal(np.asarray(resampled), by_column(x, lambda c, j: np.interp(grid, np.arange(1000.0), c)))


def test_a_table_read_spooled_equals_the_one_read_in_memory(tmp_path, rng, monkeypatch):
    monkeypatch.setattr("dynid.io.logs.table_files.BLOCK", 37)  # several blocks
    data = rng.normal(size=(200, 5))
    path = tmp_path / "log.csv"
    np.savetxt(path, data, delimiter=",", header="a,b,c,d,e", comments="")
    memory = read_table(path, ["d", "a", "c"], header=True)
    spooled = read_table(path, ["d", "a", "c"], header=True, spool=True)
    assert isinstance(spooled.data, StoredColumns) and spooled.first_line == memory.first_line == 2
    np.testing.assert_array_equal(np.asarray(spooled.data), memory.data)


def test_no_temporary_folder_is_a_one_line_error(tmp_path, monkeypatch):
    monkeypatch.setattr(column_store.tempfile, "tempdir", str(tmp_path / "missing"))
    with pytest.raises(DataError, match=r"cannot create a temporary file in .*missing for a long log.*TMPDIR"):
        ColumnFile()


def test_a_full_disk_is_a_one_line_error(monkeypatch):
    import errno
    import os

    def full(*args):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(column_store.os, "pwrite", full)
    with pytest.raises(DataError, match=r"cannot write a long log's column to .*: No space left on device \(free some space, or set TMPDIR"):
        ColumnFile().append(np.ones(10))


def test_the_correlation_matrix_by_blocks_equals_numpys(rng, monkeypatch):
    """Against ``np.corrcoef`` (independent: whole columns at once) over several blocks of rows and a short last one,
    two columns that are one signal to 1e-6 among them (the misread check's threshold is 0.9999); the same numbers for
    stored columns; a column that does not vary is NaN."""
    monkeypatch.setattr(column_store, "ROW_CHUNK", 128)
    x = rng.normal(size=(1000, 4)) + 50.0  # an offset the means must take out
    x[:, 2] = x[:, 0] + 1e-6 * rng.normal(size=1000)
    x[:, 3] = 2.0
    rho = column_store.correlation_matrix(x, [2, 0, 1])
    np.testing.assert_allclose(rho, np.corrcoef(x[:, [2, 0, 1]].T), rtol=0, atol=1e-12)
    assert rho[0, 1] > 0.9999 and abs(rho[0, 2]) < 0.2
    np.testing.assert_array_equal(column_store.correlation_matrix(StoredColumns.from_columns(x.T), [2, 0, 1]), rho)
    assert np.all(np.isnan(column_store.correlation_matrix(x, [0, 3])[1]))

import numpy as np
import pytest

from dynid.exceptions import DataError
from dynid.io.tables import read_table


def _write(tmp_path, text, name="log.csv"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_columns_by_number_and_name_with_row_range(tmp_path):
    p = _write(tmp_path, "t,a,b\n" + "".join(f"{i},{2 * i},{3 * i}\n" for i in range(10)))
    tb = read_table(p, ["b", 1], header=True, rows=(3, 5))
    np.testing.assert_array_equal(tb.data, [[6, 2], [9, 3], [12, 4]])
    assert tb.first_line == 4 and tb.warnings == ()


def test_truncated_last_line_is_skipped_with_a_warning(tmp_path):
    p = _write(tmp_path, "1,2,3\n4,5,6\n7,8")
    tb = read_table(p, [1, 3])
    assert tb.data.shape == (2, 2)
    assert tb.warnings == (f"{p}: line 3 is truncated (2 of 3 fields, no newline): skipped",)


@pytest.mark.parametrize("text, message", [
    ("1,2,3\n4,5\n7,8,9\n", r"log.csv: line 2: expected 3 columns, got 2"),
    ("1,2,3\n4,nan,6\n", r"log.csv: line 2, column 2: NaN or infinite value"),
    ("1,2,3\n4,x,6\n", r"log.csv: line 2, column 2: expected a number, got 'x'"),
    ("", r"log.csv: no data lines \(an empty file, or not a text table\?\)"),
])
def test_damaged_files_get_one_line_errors_with_file_and_line(tmp_path, text, message):
    p = _write(tmp_path, text)
    with pytest.raises(DataError, match=message):
        read_table(p, [1, 2, 3])


def test_column_errors(tmp_path):
    p = _write(tmp_path, "a,b\n1,2\n")
    with pytest.raises(DataError, match="no column named 'c'"):
        read_table(p, ["c"], header=True)
    with pytest.raises(DataError, match="has no header"):
        read_table(p, ["a"])
    with pytest.raises(DataError, match="file not found"):
        read_table(tmp_path / "missing.csv", [1])


def test_blocks_are_stacked_into_the_same_array_as_one_parse(tmp_path, monkeypatch):
    """Blocks are copied into the result one by one and released (no second copy of a long log): the data
    equal one ``np.loadtxt`` of the whole file, with the requested columns in the requested order."""
    import dynid.io.tables as tables

    monkeypatch.setattr(tables, "BLOCK", 7)
    values = np.random.default_rng(0).normal(size=(50, 4)).round(6)
    p = tmp_path / "log.csv"
    np.savetxt(p, values, delimiter=",", fmt="%.6f")
    np.testing.assert_array_equal(read_table(p, [3, 1, 4]).data, np.loadtxt(p, delimiter=",")[:, [2, 0, 3]])

import re
import tomllib

import numpy as np
import pytest

from dynid.exceptions import DataError
from dynid.io.logs.table_files import read_table


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
    import dynid.io.logs.table_files as tables

    monkeypatch.setattr(tables, "BLOCK", 7)
    values = np.random.default_rng(0).normal(size=(50, 4)).round(6)
    p = tmp_path / "log.csv"
    np.savetxt(p, values, delimiter=",", fmt="%.6f")
    np.testing.assert_array_equal(read_table(p, [3, 1, 4]).data, np.loadtxt(p, delimiter=",")[:, [2, 0, 3]])


@pytest.fixture(params=["line reader", "pyarrow"])
def reader(request, monkeypatch):
    """Both readers of read_table: the line reader, and pyarrow's for every file (its size threshold at 0)."""
    import dynid.io.logs.table_files as tables

    if request.param == "pyarrow":
        pytest.importorskip("pyarrow", exc_type=ImportError)
        monkeypatch.setattr(tables, "ARROW_BYTES", -1)
    return request.param


def test_pyarrow_reads_the_same_values_as_the_line_reader(tmp_path, monkeypatch):
    """Numbers written every way a log writes them (17 digits, exponents, signs, integers, '.5'): pyarrow's reader
    and NumPy's line reader give the same float64, bit for bit, with row ranges and columns in any order."""
    pytest.importorskip("pyarrow", exc_type=ImportError)
    import dynid.io.logs.table_files as tables

    rng = np.random.default_rng(3)
    x = rng.normal(size=(3000, 5)) * 10.0 ** rng.integers(-12, 12, size=(3000, 5))
    forms = ["{:.17g}", "{:.6f}", "{:e}", "{:+.3E}", "{:.0f}"]
    lines = ["t,a,b,c,d"] + [",".join(forms[(i + j) % 5].format(v) for j, v in enumerate(r)) for i, r in enumerate(x)]
    p = tmp_path / "log.csv"
    p.write_text("\n".join(lines).replace(",0.5", ",.5") + "\n")
    for kwargs in ({"rows": None}, {"rows": (17, 2500)}, {"rows": (2999, 3000)}):
        slow = read_table(p, ["d", "t", "b"], header=True, **kwargs)
        monkeypatch.setattr(tables, "ARROW_BYTES", -1)
        monkeypatch.setattr(tables, "ARROW_BLOCK", 4096)  # many blocks
        fast = read_table(p, ["d", "t", "b"], header=True, **kwargs)
        for spool in (False, True):
            s = read_table(p, ["d", "t", "b"], header=True, spool=spool, **kwargs)
            assert s.first_line == slow.first_line
            np.testing.assert_array_equal(np.asarray(s.data[:] if spool else s.data), slow.data)
        rows = kwargs["rows"] or (1, None)
        assert tables._arrow_table(p, ["d", "t", "b"], True, ",", None, rows=rows, spool=False) is not None  # pyarrow read it
        monkeypatch.setattr(tables, "ARROW_BYTES", 32 * 2**20)
        assert fast.first_line == slow.first_line and fast.warnings == slow.warnings
        assert np.array_equal(fast.data, slow.data) and fast.data.dtype == np.float64


@pytest.mark.parametrize("text, expected", [
    ("1,2,3\n\n4,5,6\n", [[1, 3], [4, 6]]),            # a blank line: skipped, and the lines numbered as before
    ("1,2,3\r\n4,5,6\r\n", [[1, 3], [4, 6]]),          # carriage returns
    ("1, 2,3\n4,5 ,6\n", [[1, 3], [4, 6]]),            # spaces around a number
    ("1,x,3\n4,y,6\n", [[1, 3], [4, 6]]),              # text in a column that is not read
    ("1,2,3\n4,5,6\r\n7,8,9\r7,8,9\n", [[1, 3], [4, 6], [7, 9], [7, 9]]),  # carriage returns after the first line
    ("1,2,3\n   \n4,5,6\n", [[1, 3], [4, 6]]),         # a whitespace-only line
])
def test_what_pyarrow_might_read_otherwise_is_read_by_the_line_reader(tmp_path, reader, text, expected):
    p = _write(tmp_path, text)
    np.testing.assert_array_equal(read_table(p, [1, 3]).data, expected)


@pytest.mark.parametrize("text, message", [
    ("1,2,3\n4,5\n7,8,9\n", r"log.csv: line 2: expected 3 columns, got 2"),
    ("1,2,3\n4,nan,6\n", r"log.csv: line 2, column 2: NaN or infinite value"),
    ("1,2,3\n4,inf,6\n", r"log.csv: line 2, column 2: NaN or infinite value"),
    ("1,2,3\n4,x,6\n", r"log.csv: line 2, column 2: expected a number, got 'x'"),
    ("1,2,3\n4,,6\n", r"log.csv: line 2, column 2: expected a number, got ''"),
    ('1,2,3\n4,"5",6\n', r"log.csv: line 2, column 2: expected a number, got '\"5\"'"),
    ("1,2\n3,4\n", r"log.csv: line 1: column 3 requested but the lines have 2 columns"),
])
def test_both_readers_refuse_damaged_files_alike(tmp_path, reader, text, message):
    p = _write(tmp_path, text)
    with pytest.raises(DataError, match=message):
        read_table(p, [1, 2, 3])


def test_both_readers_refuse_a_row_range_past_the_end(tmp_path, reader):
    p = _write(tmp_path, "1,2\n3,4\n5,6\n")
    with pytest.raises(DataError, match=r"rows = \[2, 9\] goes beyond the file's end: it has 3 data rows"):
        read_table(p, [1], rows=(2, 9))
    with pytest.raises(DataError, match=r"rows = \[5, 9\] selects nothing: the file has 3 data rows"):
        read_table(p, [1], rows=(5, 9))
    np.testing.assert_array_equal(read_table(p, [2, 1], rows=(2, 3)).data, [[4, 3], [6, 5]])
    assert read_table(p, [2], rows=(2, 3)).first_line == 2
    if reader == "pyarrow":
        import dynid.io.logs.table_files as tables

        assert tables._arrow_table(p, [2, 1], False, ",", None, rows=(2, 3), spool=False) is not None
        assert tables._arrow_table(p, [1], False, ",", None, rows=(2, 9), spool=False) is None  # past the end: the line reader


def test_missing_values_are_read_as_nan_where_asked(tmp_path, reader):
    """With ``missing``, an empty field and NaN are NaN (the dataset fills or refuses them); infinity and text are
    still refused with their line and column; without it, both are refused as before."""
    p = _write(tmp_path, "1,2,3\n4,,6\n7,nan,9\n")
    np.testing.assert_array_equal(read_table(p, [1, 2, 3], missing=True).data,
                                  [[1, 2, 3], [4, np.nan, 6], [7, np.nan, 9]])
    with pytest.raises(DataError, match=r"log.csv: line 2, column 2: expected a number, got ''"):
        read_table(p, [1, 2, 3])
    for text, message in (("1,2,3\n4,inf,6\n", r"line 2, column 2: infinite value"),
                          ("1,2,3\n4,x,6\n", r"line 2, column 2: expected a number, got 'x'")):
        with pytest.raises(DataError, match=message):
            read_table(_write(tmp_path, text), [1, 2, 3], missing=True)


def test_comment_lines_and_a_header_written_as_one(tmp_path, reader):
    """NumPy's savetxt(header=...) writes the header as a comment ("# t,a,b"): its names are the columns'; comment
    lines before a header or before headerless data are skipped; a message names the line in the file as counted
    with them. ("no column named 't' in the header (found # t, a, b)" before.)"""
    rows = "".join(f"{i},{2 * i},{3 * i}\n" for i in range(5))
    p = _write(tmp_path, "# t,a,b\n" + rows)
    np.testing.assert_array_equal(read_table(p, ["b", "t"], header=True).data, [[3 * i, i] for i in range(5)])
    p = _write(tmp_path, "# logged by a tool\n#   on a day\nt,a,b\n" + rows)
    tb = read_table(p, ["a"], header=True)
    np.testing.assert_array_equal(tb.data[:, 0], 2 * np.arange(5))
    assert tb.first_line == 4
    p = _write(tmp_path, "# logged by a tool\n" + rows)
    np.testing.assert_array_equal(read_table(p, [1, 3]).data, [[i, 3 * i] for i in range(5)])
    with pytest.raises(DataError, match=r"log.csv: line 5, column 2: expected a number, got 'x'"):
        read_table(_write(tmp_path, "# t,a,b\n1,2,3\n4,5,6\n7,8,9\n1,x,3\n"), ["a"], header=True)


def test_a_decimal_comma_is_named_and_read_with_its_setting(tmp_path, reader):
    """A spreadsheet's export in a European locale (semicolons, decimal commas): the refusal says what to change, and
    with ``decimal = ","`` the log reads as the same numbers written with points."""
    p = _write(tmp_path, "1;2,5;3\n4;5,5;6\n")
    with pytest.raises(DataError, match=r"line 1, column 2: expected a number, got '2,5' \(a decimal comma\? give "
                                        r'decimal = "," in the dataset\'s table\)$'):
        read_table(p, [1, 2, 3], delimiter=";")
    with pytest.raises(DataError, match=r"expected a number, got 'x'$"):
        read_table(_write(tmp_path, "1;2;3\n4;x;6\n"), [1, 2, 3], delimiter=";")
    rng = np.random.default_rng(5)
    values = np.column_stack([np.arange(40) * 0.004, rng.normal(size=(40, 3)) * [1.0, 1e-4, 3e5]])
    pointed = _write(tmp_path, "t;a;b;c\n" + "".join(";".join(repr(float(x)) for x in r) + "\n" for r in values), "p.csv")
    comma = _write(tmp_path, pointed.read_text().replace(".", ","), "c.csv")
    read = read_table(comma, ["a", "c", "t"], header=True, delimiter=";", decimal=",", rows=(3, 38)).data
    np.testing.assert_array_equal(read, values[2:38][:, [1, 3, 0]])
    np.testing.assert_array_equal(read, read_table(pointed, ["a", "c", "t"], header=True, delimiter=";", rows=(3, 38)).data)
    if reader == "pyarrow":  # read by pyarrow itself, not handed back to the line reader
        import dynid.io.logs.table_files as tables

        assert tables._arrow_table(comma, ["a"], True, ";", None, rows=(1, None), spool=False, decimal=",") is not None
    with pytest.raises(ValueError, match="decimal: expected '.' or ',' and not the delimiter ','"):
        read_table(comma, [1], decimal=",")


@pytest.mark.parametrize(("separator", "setting"), [(";", 'delimiter = ";"'), ("\t", 'delimiter = "\\t"')])
def test_another_separator_is_named_with_the_setting_that_reads_it(tmp_path, reader, separator, setting):
    """A log whose fields are separated by semicolons or tabs: the refusal names the separator and the setting, written
    as TOML reads it (a tab as "\\t"), and with that setting the same log is read."""
    rows = [[float(i), 2.0 * i, 3.0 * i] for i in range(5)]
    p = _write(tmp_path, "".join(separator.join(str(x) for x in r) + "\n" for r in rows))
    hint = f"(fields separated by {separator!r}? dynid reads ',': give {setting} in the dataset's table)"
    with pytest.raises(DataError, match=re.escape(hint)):
        read_table(p, [1, 2, 3], n_columns=3)
    with pytest.raises(DataError, match=re.escape(f"column 3 requested but the lines have 1 columns {hint}")):
        read_table(p, [1, 2, 3])
    named = _write(tmp_path, separator.join(("t", "a", "b")) + "\n" + p.read_text(), "named.csv")
    found = f"(found t{separator}a{separator}b) "
    with pytest.raises(DataError, match=re.escape(f"no column named 't' in the header {found}{hint}")):
        read_table(named, ["t", "a"], header=True)
    np.testing.assert_array_equal(read_table(p, [1, 2, 3], delimiter=tomllib.loads(setting)["delimiter"]).data, rows)


def test_iso_date_times_in_a_stamps_column_are_posix_seconds_and_nowhere_else(tmp_path):
    """A logger's ISO 8601 time stamps (with or without a zone, 'T' or a space) in the time column read as POSIX
    seconds, as datetime counts them (UTC where no zone is named); the same text in another column is still refused,
    naming the line and column."""
    import datetime

    stamps = ["2026-11-28T01:02:03.250", "2026-11-28 01:02:03.254", "2026-11-28T02:02:03.258+01:00",
              "2026-11-28T01:02:03.262Z"]
    p = _write(tmp_path, "time,q\n" + "".join(f"{s},{k}\n" for k, s in enumerate(stamps)))
    tb = read_table(p, ["time", "q"], header=True, stamps=["time"])
    start = datetime.datetime(2026, 11, 28, 1, 2, 3, 250000, tzinfo=datetime.UTC).timestamp()
    np.testing.assert_allclose(tb.data[:, 0] - start, [0.0, 0.004, 0.008, 0.012], atol=1e-6)
    np.testing.assert_array_equal(tb.data[:, 1], [0, 1, 2, 3])
    with pytest.raises(DataError, match=re.escape(f"{p}: line 2, column 1: expected a number, got '{stamps[0]}'")):
        read_table(p, ["time", "q"], header=True)


@pytest.mark.parametrize("stamps", ["iso", "posix"])
def test_a_log_with_iso_or_posix_time_stamps_identifies_as_the_same_log_in_seconds(tmp_path, stamps):
    """``dynid example ur10e``'s identification log with its time column written as ISO date-times, or as POSIX seconds
    to 17 digits: the first was refused ("expected a number"); the second was resampled, its stamps' last digits
    (0.24 µs) taken for jitter, which moved the fit's figure by 5 %. Both now give the fit of the log in seconds."""
    import datetime
    import json

    from ..cli.refusals import dynid

    assert dynid("example", "ur10e", tmp_path / "try", "-q").returncode == 0
    folder = tmp_path / "try"
    p = dynid("identify", folder / "ur10e.toml", "--out", tmp_path / "seconds", "--no-figures", "-q")
    assert p.returncode == 0, p.stderr
    lines = (folder / "identification.csv").read_text().splitlines()
    start = datetime.datetime(2026, 11, 28, 1, 2, 3, tzinfo=datetime.UTC)

    def stamp(seconds: float) -> str:
        return ((start + datetime.timedelta(seconds=seconds)).isoformat() if stamps == "iso"
                else f"{start.timestamp() + seconds:.17g}")

    dated = [lines[0]] + [",".join([stamp(float(line.split(",")[0])), *line.split(",")[1:]]) for line in lines[1:]]
    (folder / "identification.csv").write_text("\n".join(dated) + "\n")
    p = dynid("identify", folder / "ur10e.toml", "--out", tmp_path / "dated", "--no-figures", "-q")
    assert p.returncode == 0, p.stderr
    error = [json.loads((tmp_path / out / "results.json").read_text())["identification"]["metrics"]["dynid WLS"]
             ["global_relative_error"] for out in ("seconds", "dated")]
    assert error[1] == pytest.approx(error[0], rel=1e-4)


@pytest.mark.parametrize("text", ["t,a\n1.5,2\n3,4\n", "1.5,2\n3,4\n", "# t,a\n1.5,2\n3,4\n"])
def test_a_byte_order_mark_is_not_part_of_the_first_field(tmp_path, reader, text):
    """A spreadsheet's "CSV UTF-8" begins with a byte-order mark: the first column's name or number is read without it."""
    p = tmp_path / "marked.csv"
    p.write_bytes(b"\xef\xbb\xbf" + text.encode())
    header = not text[0].isdigit()
    np.testing.assert_array_equal(read_table(p, ["t", "a"] if header else [1, 2], header=header).data, [[1.5, 2], [3, 4]])


def test_a_spreadsheets_workbook_is_told_to_be_saved_as_csv(tmp_path):
    """An .xlsx (a zip archive) given for a log was "not a UTF-8 text table (a binary file?)": now it says what to do."""
    import zipfile

    book = tmp_path / "log.xlsx"
    with zipfile.ZipFile(book, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("xl/worksheets/sheet1.xml", bytes(range(256)) * 20)
    with pytest.raises(DataError, match=r"log.xlsx: not a UTF-8 text table \(a spreadsheet's workbook\? save the sheet as CSV\)$"):
        read_table(book, [1])

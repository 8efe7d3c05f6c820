"""Result tables: split to a width without losing a cell, the same text for the library and the CLI."""

from dynid.tables import EDGES, PADDING, Line, TextTable, render_text


def _table(n_values=9):
    rows = tuple((f"param{i}", "kg", *(f"{(i + 1) * 1.2345 * 10 ** (j % 4):.4g}" for j in range(n_values))) for i in range(5))
    return TextTable("T", ("name", "unit", *(f"method {j}" for j in range(n_values))), rows, labels=2)


def test_a_wide_table_splits_into_parts_that_fit_and_keep_every_cell():
    t = _table()
    for width in (60, 80, 100):
        parts = t.split(width)
        assert len(parts) > 1
        for part in parts:
            assert sum(w + PADDING for w in part.widths()) + EDGES <= width
            assert part.columns[:2] == ("name", "unit")
        values = [c for part in parts for c in part.columns[2:]]
        assert values == list(t.columns[2:])  # every value column once, in order
        for i, row in enumerate(t.rows):
            assert [c for part in parts for c in part.rows[i][2:]] == list(row[2:])
    assert t.split(10_000) == [t]


def test_plain_text_rendering_holds_every_cell_and_warning():
    t = _table(3)
    text = render_text([Line("title", "title"), t, Line("careful", "warning")], width=200)
    for row in t.rows:
        assert all(cell in text for cell in row)
    assert "warning: careful" in text and text.splitlines()[0] == "title"
    assert all(len(line) <= 60 for line in render_text([_table()], width=60).splitlines())


def test_the_rich_tables_are_as_wide_as_the_split_assumes():
    from rich.console import Console

    from dynid.tables import rich_tables

    console = Console(width=500)
    for part in _table().split(80):
        ((title, table),) = rich_tables(part, 500)
        assert title == part.title
        assert console.measure(table).maximum == sum(w + PADDING for w in part.widths()) + EDGES


def test_the_plain_text_is_what_the_terminal_prints_without_colour():
    """One table renderer (issue "Parts carry their settings, one route", item 5): the library's plain text and the
    CLI's tables are rich's, so a table reads the same in a notebook and a terminal."""
    import io

    from rich.console import Console

    from dynid.report.console import Reporter

    for width in (60, 100):
        buffer = io.StringIO()
        Reporter(out=Console(file=buffer, width=width, color_system=None, force_terminal=False)).blocks([_table()])
        printed = [line.rstrip() for line in buffer.getvalue().splitlines() if line.strip()]
        plain = [line for line in render_text([_table()], width).splitlines() if line.strip()]
        assert printed == plain and any("─" in line for line in plain)


def test_a_long_title_is_a_paragraph_as_wide_as_the_output_not_the_table(monkeypatch):
    """A table's title above a narrow table: one line where the output is not a terminal (a pipe, a log file), wrapped
    at the output's width in plain text, never at the table's width with its padding (issue "Fast where users wait,
    quiet where they read", item 4: `dynid run`'s estimator table broke its title at 64 columns in a pipe)."""
    import io

    from rich.console import Console

    from dynid.report.console import Reporter

    title = ("Estimators: F = eq. 9 on β1 (N·m); evals of eq. 9; wall s (run side by side); Δβ = ‖β̂−β‖/‖β‖ %; mean "
             "over joints of ρ (eq. 18)")
    table = TextTable(title, ("method", "F"), (("OLS", "2.392"), ("ABC", "103.9")))
    def printed(width):
        buffer = io.StringIO()
        Reporter(out=Console(file=buffer, width=width, color_system=None, force_terminal=False)).blocks([table])
        return buffer.getvalue().splitlines()

    monkeypatch.delenv("COLUMNS", raising=False)  # a pipe: one line
    lines = printed(100)
    assert title in lines and all(line == line.rstrip() for line in lines if title in line)
    monkeypatch.setenv("COLUMNS", "100")  # a width asked for: wrapped at it, not at the table's
    lines = printed(100)
    assert " ".join(lines[:2]) == title and len(lines[0]) > 80
    plain = table.render(60).splitlines()
    assert " ".join(plain[:3]) == title and all(len(line) <= 60 for line in plain)
    assert max(len(line) for line in plain[:2]) > 40  # wrapped at the output's 60 columns, not the table's 15

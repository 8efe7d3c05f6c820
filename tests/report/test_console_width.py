"""What a command prints into a pipe or a log file is not wrapped (issue "Fast where users wait, quiet where they
read", item 4: output that is not a terminal was wrapped at about 100 columns, cutting each line of a log file in two);
with COLUMNS set it is wrapped at that width, as a terminal is at its own."""

import io

from rich.console import Console

from dynid.report.console import Reporter
from dynid.tables import Line

LONG = "a finding " + "that goes on " * 30 + "to its end"


def _printed(monkeypatch, columns: str | None) -> list[str]:
    if columns is None:
        monkeypatch.delenv("COLUMNS", raising=False)
    else:
        monkeypatch.setenv("COLUMNS", columns)
    buffer = io.StringIO()
    out = Console(file=buffer, width=100, force_terminal=False)
    rep = Reporter(out=out, err=Console(file=io.StringIO(), force_terminal=False))
    rep.line(LONG)
    rep.blocks([Line(LONG), Line(LONG, "title")])
    return [line for line in buffer.getvalue().splitlines() if line.strip()]


def test_a_pipe_gets_one_line_a_line(monkeypatch):
    assert _printed(monkeypatch, None) == [LONG] * 3


def test_columns_set_wraps_at_that_width(monkeypatch):
    lines = _printed(monkeypatch, "80")
    assert len(lines) > 3 and max(len(line) for line in lines) <= 100

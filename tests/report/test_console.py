"""The console's "wrote" line."""

import io
from pathlib import Path

from rich.console import Console

from dynid.report.console import Reporter


def _wrote(paths) -> str:
    out = io.StringIO()
    Reporter(out=Console(file=out, width=200), err=Console(file=io.StringIO())).wrote([Path(p) for p in paths])
    return out.getvalue().strip()


def test_the_wrote_line_counts_figures_only_where_there_are_some():
    """``dynid payload``, which draws no figure, ended "wrote …/payload.json, payload.urdf, payload.xml and no figures
    in …/", which read as an output gone missing."""
    assert _wrote(["o/payload.json", "o/payload.urdf", "o/payload.xml"]) == "wrote o/payload.json, payload.urdf, payload.xml in o/"
    assert _wrote(["o/results.json", "o/report.html", "o/fit.png"]) == "wrote o/results.json, report.html and 1 figure in o/"
    assert _wrote(["o/results.json", "o/a.png", "o/b.png"]) == "wrote o/results.json and 2 figures in o/"


def test_a_steps_share_done_is_a_bar_with_the_time_left_on_a_terminal():
    """Issue "Fast where users wait", item 3: a step that says its share done ("40 %") shows a bar and the time left
    at its own pace so far; a detail that is no share stays as it is; a pipe still gets one plain line per step."""
    import io

    from rich.console import Console

    from dynid.report.console import Progress, bar

    assert bar("40 %", 6.0) == "████████░░░░░░░░░░░░ 40 %, about 9 s left"
    assert bar("100 %", 6.0) == "████████████████████ 100 %" and bar("best cond = 12", 6.0) == "best cond = 12"
    assert bar("5 %", 0.2) == "█░░░░░░░░░░░░░░░░░░░ 5 %"  # under a second: no estimate yet
    assert bar("0 %", 3.0) == ""  # a step that says only that it started
    terminal = Console(file=io.StringIO(), force_terminal=True, width=120)
    with Progress("dynid identify", terminal) as p:
        p.update("regressor", "0 %")
        p._started["regressor"] -= 10.0  # the step began 10 s ago
        p.update("regressor", "25 %")
        shown = str(p._status.renderable.text if hasattr(p._status.renderable, "text") else p._status.renderable)
        assert "█████░░░░░░░░░░░░░░░ 25 %, about 30 s left" in shown, shown
        p.t0 -= 4.0  # 4 s later (the steps' starts count from t0), no report between: the line drawn again says the
        # time as it is, the time left at the step's pace so far
        later = str(p._status.renderable.text)
    assert "█████░░░░░░░░░░░░░░░ 25 %, about 42 s left  4 s" in later, later
    pipe = io.StringIO()
    with Progress("dynid identify", Console(file=pipe, force_terminal=False)) as p:
        p.update("regressor", "0 %")
        p.update("regressor", "50 %")
    assert pipe.getvalue().count("dynid identify: regressor (at ") == 1

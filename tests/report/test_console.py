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

"""Write a fleet's identification: ``fleet.json``, the fleet table ``fleet.parquet`` (pyarrow) and ``fleet.html``;
each unit's own results go to ``units/<id>/`` from the worker that identified it (:func:`save_unit`)."""

from __future__ import annotations

import html
import math
from pathlib import Path

from ..fleet.identification import FleetResult
from .fleet_summary import fleet_verdict
from .identification_run import save_identification
from .output import staged, write_results

__all__ = ["save_unit", "save_fleet"]


def save_unit(result, folder: Path, robot) -> list[Path]:
    """One unit's results as ``dynid identify --no-figures`` writes them (runs on a Dask worker).

    Parameters
    ----------
    result : IdentificationResult
    folder : Path
    robot : Robot
        The identified robot (exports).

    Returns
    -------
    list of Path
    """
    return save_identification(result, folder, figures_too=False, robot=robot)


HEADERS = {"payload_kg": "payload kg", "validation_error_pct": "error %", "pooled_validation_error_pct": "pooled error %",
           "worst_joint": "worst joint"}
"""Column headers of the HTML table (the Parquet file keeps the column names)."""


def _cell(value) -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "—"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return f"{value:.4g}"
    return html.escape(str(value))


def fleet_html(result: FleetResult) -> str:
    """A self-contained HTML page of the fleet: the verdict, the table with the flagged units' rows and cells marked,
    the flags in words.

    Parameters
    ----------
    result : FleetResult

    Returns
    -------
    str
    """
    table = result.table()
    verdict = fleet_verdict(result)
    flagged = {(o.unit, o.parameter) for o in result.outliers}
    columns = list(table)
    head = "".join(f"<th>{html.escape(HEADERS.get(c, c.replace('_std', ' σ')))}</th>" for c in columns)
    rows = []
    for i, uid in enumerate(table["unit"]):
        cells = []
        for c in columns:
            bad = (uid, c) in flagged or (c == "flags" and table[c][i])
            cells.append(f'<td class="{"bad" if bad else ""}">{_cell(table[c][i])}</td>')
        rows.append(f'<tr class="{"flagged" if table["flags"][i] else ""}">{"".join(cells)}</tr>')
    flags = "".join(f"<li>{html.escape(str(o))}</li>" for o in result.outliers) or "<li>none</li>"
    return f"""<!doctype html>
<html lang="en"><head><meta charset="utf-8"><meta name="viewport" content="width=device-width, initial-scale=1">
<title>dynid fleet — {html.escape(result.manifest.name)}</title>
<style>
body {{ font-family: system-ui, sans-serif; margin: 1.5rem; color: #222; }}
.verdict {{ font-size: 1.1rem; padding: .7rem 1rem; background: #eef4fb; border-left: 4px solid #3b78c3; }}
.wrap {{ overflow-x: auto; }}
table {{ border-collapse: collapse; font-size: .85rem; }}
th, td {{ border: 1px solid #ccc; padding: .25rem .45rem; text-align: right; white-space: nowrap; }}
th {{ background: #f3f3f3; position: sticky; top: 0; }}
td:first-child, th:first-child {{ text-align: left; position: sticky; left: 0; background: #fff; }}
tr.flagged td:first-child {{ background: #fde7e7; font-weight: 600; }}
td.bad {{ background: #f9c9c9; font-weight: 600; }}
</style></head><body>
<h1>Fleet: {html.escape(result.manifest.name)}</h1>
<p class="verdict">{html.escape(verdict)}</p>
<h2>Units that stand out</h2>
<p>z-score of each parameter against the other units, with the unit's own σ: against their median and spread where
they agree within their σ (drive gains, rigid-body parameters), against a prediction interval where they differ by
nature (friction, offsets, a tool). Flagged beyond |z| = {result.threshold:.2f} where the units agree (more where they
differ): a fleet whose units differ only at random has a 1 % chance of any flag.</p>
<ul>{flags}</ul>
<h2>The fleet table</h2>
<p>One row per unit: global validation error [%] of its own estimate and of its pooled estimate (the fleet's shared
rigid-body parameters), friction per joint (Coulomb fc [N·m], viscous fv [N·m·s/rad]) with σ, drive gains K [N·m/A]
when identified. Flagged units and parameters are marked in red. The same table is in <code>fleet.parquet</code>.</p>
<div class="wrap"><table><thead><tr>{head}</tr></thead><tbody>{"".join(rows)}</tbody></table></div>
<p>Ran on {html.escape(result.cluster)} in {result.seconds:.1f} s. Each unit's own results: <code>units/&lt;id&gt;/</code>.</p>
</body></html>
"""


@staged
def save_fleet(result: FleetResult, out: str | Path) -> list[Path]:
    """Write ``fleet.json``, ``fleet.parquet`` and ``fleet.html``.

    Parameters
    ----------
    result : FleetResult
    out : str or Path
        Output folder (the units' folders are beside, in ``units/``).

    """
    import pyarrow as pa
    import pyarrow.parquet as pq

    out = Path(out)
    write_results(out / "fleet.json", result.to_dict(), "fleet")
    pq.write_table(pa.Table.from_pydict(result.table()), out / "fleet.parquet")
    (out / "fleet.html").write_text(fleet_html(result), encoding="utf-8")
    return [out / "fleet.json", out / "fleet.parquet", out / "fleet.html"]

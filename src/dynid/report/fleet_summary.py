"""What the fleet's commands print (``dynid fleet``, ``dynid monitor``), as blocks of :mod:`dynid.tables`;
:func:`dynid.report.summaries.blocks` dispatches to them."""

from __future__ import annotations

import math

from ..tables import Line, TextTable

__all__ = ["fleet_blocks", "fleet_verdict", "monitor_blocks"]


def _cell(value, fmt: str = ".3g") -> str:
    return "—" if value is None or (isinstance(value, float) and not math.isfinite(value)) else format(value, fmt)


def fleet_verdict(result) -> str:
    """How a fleet's identification went, in one sentence: units identified, those that stand out, what pooling did.

    Parameters
    ----------
    result : dynid.fleet.identification.FleetResult

    Returns
    -------
    str
    """
    ok = {s.id: s for s in result.identified}
    flagged = sorted({o.unit for o in result.outliers})
    helped = [u for u, e in result.pooled_errors.items() if e < ok[u].validation_error]
    return (f"{len(ok)} of {len(result.units)} units identified; "
            + (f"{len(flagged)} {'stands' if len(flagged) == 1 else 'stand'} out from the fleet: {', '.join(flagged)}"
               if flagged else "none stands out from the fleet" if math.isfinite(result.threshold)
               else f"none can be told to stand out ({_unflaggable(len(ok))})")
            + (f"; pooling improved {len(helped)} of {len(result.pooled_errors)} units' validation error"
               if result.pooled_errors else (f"; not pooled: {result.pooled_note}" if result.pooled_note else "")))


def fleet_blocks(result) -> list:
    """What ``dynid fleet`` prints: a verdict, then one row per unit (validation error alone and pooled, worst joint,
    consistency, flags) and the flagged parameters.

    Parameters
    ----------
    result : dynid.fleet.identification.FleetResult

    Returns
    -------
    list of Line and TextTable
    """
    table = result.table()
    units = result.units
    out: list = [Line(f"dynid fleet — {result.manifest.name}: {fleet_verdict(result)}", "title")]
    rows = []
    for i, uid in enumerate(table["unit"]):
        rows.append((uid, table["date"][i] or "—", _cell(table["payload_kg"][i]), _cell(table["validation_error_pct"][i]),
                     _cell(table["pooled_validation_error_pct"][i]), table["worst_joint"][i] or "—",
                     {True: "yes", False: "no", None: "—"}[table["consistent"][i]],
                     ", ".join(o.parameter for o in result.flagged(uid)) or ("not identified" if table["error"][i] else "")))
    labels = sorted({s.label for s in result.identified})
    out.append(TextTable("Units: global validation error [%] of each unit's own estimate and of its pooled estimate; worst "
                         f"joint; whether {', '.join(labels) or 'the estimate'} is physically consistent; parameters that "
                         "stand out (z-score against the other units, each unit's stated tool taken out)",
                         ("unit", "date", "payload kg", "error %", "pooled %", "worst", "consistent", "flags"), tuple(rows)))
    inconsistent = [s for s in result.identified if not s.consistency.startswith("yes")]
    if inconsistent:
        why = inconsistent[0].consistency.removeprefix("no").strip(" :")
        out.append(Line(f"consistent: no for {len(inconsistent)} of {len(result.identified)} units: their "
                        f"{inconsistent[0].label} is unconstrained least squares, which no mass distribution need match "
                        f"({inconsistent[0].id}: {why}); list \"sdp\" in the template's [estimation] estimators for a "
                        "physically consistent estimate of each unit"))
    for o in result.outliers[:10]:
        out.append(Line(f"flag: {o}", "warning"))
    if len(result.outliers) > 10:
        out.append(Line(f"… and {len(result.outliers) - 10} more flags (fleet.json)", "warning"))
    for s in units:
        if s.error:
            out.append(Line(f"{s.id}: not identified: {s.error}", "warning"))
        for w in s.warnings:  # each unit's own warnings (a truncated log, gaps filled), named by the unit
            out.append(Line(f"{s.id}: {w}", "warning"))
    flags = (f"flag threshold |z| > {result.threshold:.2f} (1 % chance of any false flag in a fleet whose units differ "
             "only at random)" if math.isfinite(result.threshold) else f"no flags: {_unflaggable(len(result.identified))}")
    out.append(Line(f"ran on {result.cluster} in {result.seconds:.1f} s; {flags}"))
    return out


def _unflaggable(identified: int) -> str:
    """Why no unit of a fleet could be flagged (:func:`dynid.fleet.outliers.fleet_z`: a unit against 3 others or more,
    units of one robot model)."""
    if identified < 4:
        return (f"{identified} units identified: each is compared with at least 3 others, so a fleet of 4 units or more "
                "is needed")
    return "the units' base parameters differ (friction models or robot descriptions): they are not compared"


def monitor_blocks(result) -> list:
    """What ``dynid monitor`` prints: a verdict (alarms or none), each term's reference, the alarms in words.

    Parameters
    ----------
    result : dynid.fleet.monitor.MonitorResult

    Returns
    -------
    list of Line and TextTable
    """
    hours = sum(w.end - w.start for w in result.windows) / 3600
    count = {t: sum(a.term == t for a in result.alarms) for t in result.terms}
    joint = dict(zip(result.terms, result.joints))
    changes = result.changes()
    verdict = (f"{len(changes)} term(s) changed: " + ", ".join(
        f"joint {joint[t]} {t} {c:+.3g} % since the reference" + (f" ({count[t]} alarms)" if count[t] > 1 else "")
        for t, c in changes.items()) if changes else "no change")
    out: list = [Line(f"dynid monitor — {len(result.logs)} logs, {len(result.windows)} windows of {result.settings.window:g} s "
                      f"({hours:.3g} h of logs): {verdict}", "title")]
    rows = tuple((t, f"joint {j}", _cell(float(m), ".4g"), _cell(float(s), ".2g"), _cell(float(x), ".4g"), str(count[t]))
                 for t, j, m, s, x in zip(result.terms, result.joints, result.reference_mean, result.reference_std,
                                          result.latest))
    out.append(TextTable(f"Terms: reference over the first {result.settings.reference_windows} windows (mean, spread), the "
                         f"level now (the windows of the last {result.settings.forgetting_seconds:g} s), alarms",
                         ("term", "joint", "reference", "spread", "now", "alarms"), rows))
    for a in result.alarms:
        out.append(Line(f"alarm: {a}", "warning"))
    for line in result.deferred:
        out.append(Line(line, "warning"))
    if result.resumed:
        out.append(Line(f"went on from an earlier run's state ({result.resumed} logs seen then, "
                        f"{len(result.logs) - result.resumed} new)"))
    out.append(Line(f"CUSUM per term (tuned to shifts of {result.settings.shift:g} reference spreads: k = "
                    f"{result.settings.shift / 2:g}, h = {result.threshold:.3g}): one false alarm per "
                    f"{result.settings.false_alarm_days:g} days of logs on average over all {len(result.terms)} terms"))
    return out

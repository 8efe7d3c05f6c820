"""What the studies print (:mod:`dynid.studies`: the Monte Carlo study, the closed-loop study), as blocks of
:mod:`dynid.tables`; :func:`dynid.report.summaries.blocks` dispatches to them."""

from __future__ import annotations

import numpy as np

from ..estimators.registry import label
from ..tables import Line, TextTable

__all__ = ["closed_loop_study_blocks", "closed_loop_study_rows", "closed_loop_verdict", "montecarlo_blocks"]


def montecarlo_blocks(result) -> list:
    """What ``dynid montecarlo`` prints: spread and bias against the Cramér–Rao bound per noise level and estimator.

    Parameters
    ----------
    result : dynid.studies.montecarlo.MonteCarloResult

    Returns
    -------
    list of Line and TextTable
    """
    cfg, stats = result.config, result.statistics()
    nonzero = np.abs(result.truth) > 1e-9 * np.abs(result.truth).max()
    rows, ends = [], set()
    for li, level in enumerate(cfg.noise_levels):
        for key in cfg.estimators:
            s = stats[key]
            rows.append((f"{level:g}", label(key), *(f"{f(s[k][li]):.3g}" for k, f in (
                ("std_over_crb", np.nanmedian), ("std_over_crb", np.nanmax), ("bias_over_crb", np.nanmedian), ("bias_over_crb", np.nanmax))),
                f"{100 * np.nanmedian(s['rmse'][li][nonzero] / np.abs(result.truth[nonzero])):.3g}",
                str(int(s["failures"][li])), f"{s['seconds_median'][li]:.3g}"))
        ends.add(len(rows) - 1)
    out: list = [Line(f"dynid montecarlo — robot {cfg.robot}, joints 1-{cfg.joints}, {len(result.names)} base parameters, "
                f"{cfg.realisations} realisations × {len(cfg.noise_levels)} noise levels, {cfg.duration:g} s at {cfg.rate:g} Hz; "
                f"ran on {result.cluster} in {result.timings.get('total', float('nan')):.1f} s", "title"),
           TextTable("Spread σ and bias |b| of the base parameters in units of √CRB (Cramér–Rao bound, raw-torque Gaussian "
                     "noise): median and worst over the parameters; median RMSE/|β| %; failed fits; median s per fit",
                     ("noise A", "estimator", "σ med", "σ max", "|b| med", "|b| max", "RMSE %", "fails", "s/fit"),
                     tuple(rows), labels=2, section_ends=frozenset(ends))]
    nearest = []
    for li, level in enumerate(cfg.noise_levels):
        scores = {k: float(np.nanmedian(stats[k]["rmse"][li] / result.crb_std[li])) for k in cfg.estimators}
        best = min(scores, key=lambda k: scores[k])
        nearest.append(f"{level:g} A: {label(best)} ({scores[best]:.3g}× √CRB)")
    out.append(Line("nearest the Cramér–Rao bound (median RMSE over the parameters) — " + "; ".join(nearest), "title"))
    if result.errors:
        out.append(Line(f"{len(result.errors)} fits failed; the first: {result.errors[0]['error']}", "warning"))
    return out


def _percent(x) -> str:
    return "—" if x is None else f"{100 * x:.3g}"


def _ratio(x) -> str:
    return "—" if x is None else f"{x:.3g}"


def closed_loop_study_rows(data: dict) -> tuple[tuple[str, ...], list[tuple[str, ...]], set[int]]:
    """The table of a closed-loop study, one row per cell and estimator, from its ``montecarlo.json`` data.

    Parameters
    ----------
    data : dict
        :meth:`dynid.studies.closed_loop_montecarlo.ClosedLoopStudyResult.to_dict`.

    Returns
    -------
    headers : tuple of str
    rows : list of tuple of str
    ends : set of int
        The last row of each cell.
    """
    n = data["settings"]["realisations"]
    headers: tuple[str, ...] = ("noise", "estimator", "|bias| %", "spread %", "|b|/√CRB", "σ/√CRB", "cover", "fitted", "s/fit")
    rows: list[tuple[str, ...]] = []
    ends: set[int] = set()
    for cell in data["cells"]:
        for est in cell["estimators"].values():
            rows.append((f"{cell['encoder_noise_deg']:g}° {cell['torque_noise_Nm']:g} N·m", str(est["label"]),
                         _percent(est["median_relative_bias"]), _percent(est["median_relative_spread"]),
                         _ratio(est["median_bias_over_crb"]), _ratio(est["median_spread_over_crb"]),
                         "—" if est["coverage_95"] is None else f"{100 * est['coverage_95']:.0f} %",
                         f"{est['converged']}/{n}", _ratio(est["seconds_median"])))
        ends.add(len(rows) - 1)
    return headers, rows, ends


def closed_loop_verdict(data: dict) -> list[str]:
    """The study's verdict in a few lines: per cell, the estimator nearest the Cramér–Rao bound, and how least squares
    fares against IDIM-IV and DIDIM at the highest encoder noise.

    Parameters
    ----------
    data : dict
        :meth:`dynid.studies.closed_loop_montecarlo.ClosedLoopStudyResult.to_dict`.

    Returns
    -------
    list of str
    """
    out = []
    best = [f"{c['encoder_noise_deg']:g}°/{c['torque_noise_Nm']:g} N·m: {label(c['best'])}" for c in data["cells"] if c["best"]]
    if best:
        out.append("smallest RMSE against the Cramér–Rao bound per cell — " + "; ".join(best))
    worst = max(c["encoder_noise_deg"] for c in data["cells"])
    for cell in (c for c in data["cells"] if c["encoder_noise_deg"] == worst):
        ests = cell["estimators"]
        ls = next((k for k in ("ols", "wls") if k in ests and ests[k]["median_relative_bias"] is not None), None)
        closed = [k for k in ("idim-iv", "didim") if k in ests and ests[k]["median_relative_bias"] is not None]
        if ls and closed:
            out.append(f"at {worst:g}° and {cell['torque_noise_Nm']:g} N·m: median |bias| {label(ls)} "
                       f"{_percent(ests[ls]['median_relative_bias'])} %, " + ", ".join(
                           f"{label(k)} {_percent(ests[k]['median_relative_bias'])} %" for k in closed))
    return out


def closed_loop_study_blocks(result) -> list:
    """What ``dynid montecarlo --closed-loop`` prints: bias, spread and coverage per cell of the grid and estimator.

    Parameters
    ----------
    result : dynid.studies.closed_loop_montecarlo.ClosedLoopStudyResult

    Returns
    -------
    list of Line and TextTable
    """
    cfg, data = result.config, result.to_dict()
    headers, rows, ends = closed_loop_study_rows(data)
    band = "derived from each log" if cfg.band is None else f"{cfg.band:g} Hz given"
    out: list = [Line(f"dynid montecarlo, closed loop — robot {cfg.robot}, joints 1-{cfg.joints}, {len(result.names)} base "
                      f"parameters, {cfg.realisations} realisations × {len(cfg.cells)} cells, {cfg.duration:g} s at "
                      f"{cfg.rate:g} Hz under a PID of {cfg.bandwidth:g} Hz, excitation band {band}; ran on {result.cluster} "
                      f"in {result.timings.get('total', float('nan')):.1f} s", "title"),
                 TextTable("Per cell (encoder σ, torque σ) and estimator: medians over the base parameters of |bias|/|β| and "
                           "spread/|β| (%) and in units of √CRB (torque noise, exact motion); share of 95 % intervals "
                           "holding the truth (— : no σ); fits converged; median s per fit",
                           headers, tuple(rows), labels=2, section_ends=frozenset(ends))]
    out += [Line(text) for text in closed_loop_verdict(data)]
    if result.errors:
        out.append(Line(f"{len(result.errors)} fits failed or did not converge; the first: {result.errors[0]['error']}", "warning"))
    return out

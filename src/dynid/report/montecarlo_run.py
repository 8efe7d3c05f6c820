"""Write a Monte Carlo study to a folder: montecarlo.json, every estimate as CSV, and two figures."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from ..estimators.registry import label
from ..io import atomic_write_text
from ..studies.closed_loop_montecarlo import ClosedLoopStudyResult
from ..studies.montecarlo import MonteCarloResult
from . import figures
from .html import write_html_report
from .output import save_figure, staged, write_results

FIGURES = {
    "montecarlo_std_vs_crb.png": "per noise level: standard deviation / Cramér–Rao bound of every base parameter, per method",
    "montecarlo_noise_levels.png": "median over the parameters of std/CRB and |bias|/CRB against the noise level",
}


@staged
def save_montecarlo(result: MonteCarloResult, out: str | Path) -> list[Path]:
    """Write ``montecarlo.json``, ``montecarlo_estimates.csv`` and the figures.

    Parameters
    ----------
    result : MonteCarloResult
    out : str or Path
        Output folder.
    """
    out = Path(out)  # staged passes its staging folder
    stats = result.statistics()
    labels = [label(k) for k in result.config.estimators]
    levels = np.asarray(result.config.noise_levels, dtype=float)
    paths = [out / "montecarlo.json", out / "montecarlo_estimates.csv", *(out / name for name in FIGURES)]
    save_figure(figures.plot_std_over_bound(levels, labels, [stats[k]["std_over_crb"] for k in result.config.estimators]), paths[2])
    save_figure(figures.plot_noise_level_study(levels, labels, [stats[k]["std_over_crb"] for k in result.config.estimators],
                                               [stats[k]["bias_over_crb"] for k in result.config.estimators]), paths[3])
    buf = io.StringIO()
    buf.write(",".join(["noise_level_A", "realisation", "estimator", *result.names]) + "\n")
    for li, level in enumerate(levels):
        for r in range(result.estimates.shape[1]):
            for m, key in enumerate(result.config.estimators):
                buf.write(f"{level:.6g},{r},{key}," + ",".join(f"{v:.10g}" for v in result.estimates[li, r, m]) + "\n")
    atomic_write_text(paths[1], buf.getvalue())
    data = result.to_dict()
    write_results(paths[0], data, "montecarlo")
    write_html_report(out / "report.html", data, "montecarlo", paths[2:], "dynid montecarlo")
    paths.insert(2, out / "report.html")
    return paths


@staged
def save_closed_loop_study(result: ClosedLoopStudyResult, out: str | Path) -> list[Path]:
    """Write ``montecarlo.json``, ``montecarlo_estimates.csv`` (every estimate with its σ) and ``report.html`` of a
    closed-loop study.

    Parameters
    ----------
    result : ClosedLoopStudyResult
    out : str or Path
        Output folder.
    """
    out = Path(out)  # staged passes its staging folder
    paths = [out / "montecarlo.json", out / "montecarlo_estimates.csv", out / "report.html"]
    buf = io.StringIO()
    buf.write(",".join(["encoder_noise_deg", "torque_noise_Nm", "realisation", "estimator", "converged", *result.names,
                        *(f"std_{n}" for n in result.names)]) + "\n")
    for c, (encoder, torque) in enumerate(result.config.cells):
        for r in range(result.estimates.shape[1]):
            for m, key in enumerate(result.config.estimators):
                values = (*result.estimates[c, r, m], *result.std[c, r, m])
                buf.write(f"{encoder:g},{torque:g},{r},{key},{int(result.converged[c, r, m])}," +
                          ",".join(f"{v:.10g}" for v in values) + "\n")
    atomic_write_text(paths[1], buf.getvalue())
    data = result.to_dict()
    write_results(paths[0], data, "montecarlo")
    write_html_report(paths[2], data, "montecarlo_closed_loop", [], "dynid montecarlo --closed-loop")
    return paths

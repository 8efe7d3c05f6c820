"""Write a paper-experiment run to a folder: results.json and the paper's Figures 4-9 as PNG."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

from ..estimators.registry import label
from ..studies import paper_reference as ref
from ..studies.paper import PaperRunResult
from . import figures
from .html import write_html_report
from .output import draw_figures, save_figure, staged, write_results

FIGURES = {
    "fig4_identification_trajectory.png": "joint trajectories of β1",
    "fig5_tool_path.png": "3-D tool path of β1",
    "fig6_abc_convergence.png": "ABC objective per iteration (when the run has ABC)",
    "fig7_torques_identification.png": "measured vs predicted torques on β1",
    "fig8_validation_trajectory.png": "joint trajectories of β2",
    "fig9_torques_validation.png": "measured vs predicted torques on β2",
    "methods_convergence.png": "best objective against evaluations for ABC, ABC×10, DE and PSO (when the run has them)",
    "methods_comparison.png": "validation error per joint and parameter error of every method",
}
TORQUE_PLOT_METHODS = ("abc", "lad", "ols", "sdp")
"""Methods drawn in Figs. 7 and 9 (those the run has), so the curves stay readable."""


def _figure_drawers(result: PaperRunResult) -> dict:
    """Each figure this run has, by file name: a callable that draws it and returns its Figure."""
    ident, valid, lim = result.identification, result.validation, result.robot.limits
    methods = result.estimates
    ident_name = "β1" if result.config.excitation == "paper" else "(optimized)" if result.config.excitation == "optimized" else "(from file)"
    shown = {label(k): methods[k] for k in TORQUE_PLOT_METHODS if k in methods} or {label(k): m for k, m in list(methods.items())[:3]}
    references = {f"{label(k)} F": methods[k].objective for k in ("lad", "ols") if k in methods}
    references[f"paper F = {ref.OBJECTIVE}"] = ref.OBJECTIVE
    figs = {
        "fig4_identification_trajectory.png": lambda: figures.plot_joint_trajectories(
            ident.t, ident.q, lim.q_min, lim.q_max, title=f"Fig. 4 — identification trajectory {ident_name} (dashed: limits)"),
        "fig5_tool_path.png": lambda: figures.plot_tool_path(ident.tool, title=f"Fig. 5 — tool path of {ident_name}"),
        "fig7_torques_identification.png": lambda: figures.plot_torque_comparison(
            ident.t, ident.tau, {k: m.tau_identification for k, m in shown.items()},
            title="Fig. 7 — identification trajectory: measured vs predicted"),
        "fig8_validation_trajectory.png": lambda: figures.plot_joint_trajectories(
            valid.t, valid.q, lim.q_min, lim.q_max, title="Fig. 8 — validation trajectory β2 (dashed: limits)"),
        "fig9_torques_validation.png": lambda: figures.plot_torque_comparison(
            valid.t, valid.tau, {k: m.tau_validation for k, m in shown.items()},
            title="Fig. 9 — validation trajectory: measured vs predicted"),
        "methods_comparison.png": lambda: figures.plot_method_comparison(
            [label(k) for k in methods], [m.metrics["relative_error"]["validation"] for m in methods.values()],
            [100 * np.linalg.norm(m.params - result.truth) / np.linalg.norm(result.truth) for m in methods.values()],
            title="Estimators on the validation trajectory β2 (top) and against the true base parameters (bottom)"),
    }
    if "abc" in methods:
        figs["fig6_abc_convergence.png"] = lambda: figures.plot_convergence(
            methods["abc"].history, reference=references, title="Fig. 6 — ABC convergence (eq. 9)")
    searches = {label(k): m for k, m in methods.items() if m.history is not None}
    if searches:
        figs["methods_convergence.png"] = lambda: figures.plot_convergence(
            {label: (np.linspace(m.n_evaluations / len(m.history), m.n_evaluations, len(m.history)), m.history)
             for label, m in searches.items()},
            reference=references, xlabel="evaluations of eq. 9", title="Box searches on eq. 9 (LAD: the exact minimum in the box)")
    return figs


def _for_figures(result: PaperRunResult) -> PaperRunResult:
    """The result without its observation matrices (25 MB and more), which no figure draws: what is handed
    to the figure process."""
    def light(d):
        return dataclasses.replace(d, w_base=None)

    return dataclasses.replace(result, identification=light(result.identification), validation=light(result.validation))


def _figure_jobs(result: PaperRunResult, paths: list[Path]) -> list:
    """The jobs that write the figures ``paths`` (:func:`dynid.report.output.draw_figures`)."""
    figs = _figure_drawers(result)
    return [lambda p=p: save_figure(figs[p.name](), p) for p in paths]


@staged
def save_paper_run(result: PaperRunResult, out: str | Path, figures_too: bool = True) -> list[Path]:
    """Write ``results.json`` and the figures of ``dynid run``.

    Parameters
    ----------
    result : PaperRunResult
    out : str or Path
        Output folder (created if needed).
    figures_too : bool
        Write the figures.
    """
    out = Path(out)  # staged passes its staging folder
    drawn = _figure_drawers(result) if figures_too else {}
    paths = [out / name for name in FIGURES if name in drawn]
    if paths:
        draw_figures(_figure_jobs, _for_figures(result), paths)
    json_path = out / "results.json"
    data = result.to_dict()
    write_results(json_path, data, "run")
    write_html_report(out / "report.html", data, "run", paths, f"dynid run — {result.robot.name}, joints 1-{result.config.joints}")
    return [json_path, out / "report.html"] + paths

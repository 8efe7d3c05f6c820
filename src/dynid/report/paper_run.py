"""Write a paper-experiment run to a folder: results.json and the paper's Figures 4-9 as PNG."""

from __future__ import annotations

from pathlib import Path

from ..experiment import paper_reference as ref
from ..experiment.paper import PaperRunResult
from ..io import write_json
from . import figures
from .output import output_folder, save_figure

FIGURES = {
    "fig4_identification_trajectory.png": "joint trajectories of β1",
    "fig5_tool_path.png": "3-D tool path of β1",
    "fig6_abc_convergence.png": "ABC objective per iteration",
    "fig7_torques_identification.png": "measured vs predicted torques on β1",
    "fig8_validation_trajectory.png": "joint trajectories of β2",
    "fig9_torques_validation.png": "measured vs predicted torques on β2",
}


def save_paper_run(result: PaperRunResult, out: str | Path) -> list[Path]:
    """Write ``results.json`` and the figures into ``out`` (created if needed); return the paths.

    Raises
    ------
    ConfigError
        If ``out`` exists and is not a folder, or cannot be created.
    """
    out = output_folder(out)
    ident, valid, lim = result.identification, result.validation, result.robot.limits
    abc, lad, ols = result.methods["abc"], result.methods["lad"], result.methods["ols"]
    paths = [out / name for name in FIGURES]
    ident_name = "β1" if result.config.excitation == "paper" else "(optimized)" if result.config.excitation == "optimized" else "(from file)"
    save_figure(figures.plot_joint_trajectories(ident.t, ident.q, lim.q_min, lim.q_max,
                                          title=f"Fig. 4 — identification trajectory {ident_name} (dashed: limits)"), paths[0])
    save_figure(figures.plot_tool_path(ident.tool, title=f"Fig. 5 — tool path of {ident_name}"), paths[1])
    save_figure(figures.plot_convergence(abc.history, reference={"LAD F (exact minimum, same box)": lad.objective, "OLS F": ols.objective,
                                                              f"paper F = {ref.OBJECTIVE}": ref.OBJECTIVE},
                                   title="Fig. 6 — ABC convergence (eq. 9)"), paths[2])
    save_figure(figures.plot_torque_comparison(ident.t, ident.tau, {"ABC": abc.tau_identification, "LAD": lad.tau_identification, "OLS": ols.tau_identification},
                                         title="Fig. 7 — identification trajectory: measured vs predicted"), paths[3])
    save_figure(figures.plot_joint_trajectories(valid.t, valid.q, lim.q_min, lim.q_max,
                                          title="Fig. 8 — validation trajectory β2 (dashed: limits)"), paths[4])
    save_figure(figures.plot_torque_comparison(valid.t, valid.tau, {"ABC": abc.tau_validation, "LAD": lad.tau_validation, "OLS": ols.tau_validation},
                                         title="Fig. 9 — validation trajectory: measured vs predicted"), paths[5])
    json_path = out / "results.json"
    write_json(json_path, result.to_dict())
    return [json_path] + paths

"""Write a paper-experiment run to a folder: results.json and the paper's Figures 4-9 as PNG."""

from __future__ import annotations

import io
from pathlib import Path

from ..exceptions import ConfigError
from ..experiment import paper_reference as ref
from ..experiment.paper import PaperRunResult
from ..io import atomic_write_bytes, write_json
from . import figures

FIGURES = {
    "fig4_identification_trajectory.png": "joint trajectories of β1",
    "fig5_tool_path.png": "3-D tool path of β1",
    "fig6_abc_convergence.png": "ABC objective per iteration",
    "fig7_torques_identification.png": "measured vs predicted torques on β1",
    "fig8_validation_trajectory.png": "joint trajectories of β2",
    "fig9_torques_validation.png": "measured vs predicted torques on β2",
}


def _save(fig_or_axes, path: Path) -> None:
    import matplotlib.pyplot as plt

    fig = fig_or_axes.figure if hasattr(fig_or_axes, "figure") else fig_or_axes.flat[0].figure
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    plt.close(fig)
    atomic_write_bytes(path, buf.getvalue())


def save_paper_run(result: PaperRunResult, out: str | Path) -> list[Path]:
    """Write ``results.json`` and the figures into ``out`` (created if needed); return the paths.

    Raises
    ------
    ConfigError
        If ``out`` exists and is not a folder, or cannot be created.
    """
    import matplotlib

    matplotlib.use("Agg", force=False)
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ConfigError(f"--out {out}: exists and is not a folder")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ConfigError(f"--out {out}: cannot create the folder ({exc.strerror})") from None
    ident, valid, lim = result.identification, result.validation, result.robot.limits
    abc, lad, ols = result.methods["abc"], result.methods["lad"], result.methods["ols"]
    paths = [out / name for name in FIGURES]
    _save(figures.plot_joint_trajectories(ident.t, ident.q, lim.q_min, lim.q_max,
                                          title="Fig. 4 — identification trajectory β1 (dashed: limits)"), paths[0])
    _save(figures.plot_tool_path(ident.tool, title="Fig. 5 — tool path of β1"), paths[1])
    _save(figures.plot_convergence(abc.history, reference={"LAD F (exact minimum, same box)": lad.objective, "OLS F": ols.objective,
                                                              f"paper F = {ref.OBJECTIVE}": ref.OBJECTIVE},
                                   title="Fig. 6 — ABC convergence (eq. 9)"), paths[2])
    _save(figures.plot_torque_comparison(ident.t, ident.tau, {"ABC": abc.tau_identification, "LAD": lad.tau_identification, "OLS": ols.tau_identification},
                                         title="Fig. 7 — identification trajectory: measured vs predicted"), paths[3])
    _save(figures.plot_joint_trajectories(valid.t, valid.q, lim.q_min, lim.q_max,
                                          title="Fig. 8 — validation trajectory β2 (dashed: limits)"), paths[4])
    _save(figures.plot_torque_comparison(valid.t, valid.tau, {"ABC": abc.tau_validation, "LAD": lad.tau_validation, "OLS": ols.tau_validation},
                                         title="Fig. 9 — validation trajectory: measured vs predicted"), paths[5])
    json_path = out / "results.json"
    write_json(json_path, result.to_dict())
    return [json_path] + paths

"""Write an identification or validation run to a folder: results.json and torque figures."""

from __future__ import annotations

import re
from pathlib import Path

from ..experiment.identification import IdentificationResult
from ..validation.torques import TorqueComparison
from . import figures
from .html import write_html_report
from .output import output_folder, save_figure, write_results, staged


def _slug(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9]+", "_", name).strip("_").lower() or "dataset"


def _torque_figure(cmp: TorqueComparison, path: Path, title: str) -> None:
    save_figure(figures.plot_torque_comparison(cmp.t, cmp.measured, cmp.predicted, title=title), path)


def save_comparisons(comparisons, out: Path, prefix: str = "validation") -> list[Path]:
    """One PNG per dataset: measured vs predicted torques of every parameter set."""
    paths = []
    for cmp in comparisons:
        path = out / f"{prefix}_{_slug(cmp.name)}.png"
        _torque_figure(cmp, path, f"{prefix} — {cmp.name}: measured vs predicted torques")
        paths.append(path)
    return paths


@staged
def save_identification(result: IdentificationResult, out: str | Path, figures_too: bool = True, robot=None) -> list[Path]:
    """Write ``results.json``, the identification fit figure and one figure per validation dataset
    (figures unless ``figures_too`` is false), and with ``robot`` (the identified robot) ``robot.urdf`` and
    ``robot.xml`` (MJCF) when the physically consistent estimate passed the consistency check.

    Raises
    ------
    ConfigError
        If ``out`` exists and is not a folder, or cannot be created.
    """
    out = output_folder(out)
    paths = []
    if figures_too:
        paths = [out / "identification_fit.png"]
        _torque_figure(result.fit, paths[0], f"identification — {result.fit.name}: measured vs predicted torques")
        paths += save_comparisons(result.validations, out)
    json_path = out / "results.json"
    data = result.to_dict()
    write_results(json_path, data, "identify")
    write_html_report(out / "report.html", data, "identify", paths, f"dynid identify — {result.robot}")
    paths.insert(0, out / "report.html")
    sdp = data.get("physically_consistent")
    if robot is not None and sdp is not None and data["physically_consistent_verdict"].get(sdp["label"]) == "yes":
        from ..io import atomic_write_text
        from ..io.export import mjcf_from_results, urdf_from_results

        paths[:0] = [out / "robot.urdf", out / "robot.xml"]
        atomic_write_text(paths[0], urdf_from_results(robot, data))
        atomic_write_text(paths[1], mjcf_from_results(robot, data))
    return [json_path] + paths


@staged
def save_validation(comparisons, out: str | Path, warnings=()) -> list[Path]:
    """Write ``validation.json`` (per-joint metrics of every parameter set) and one figure per dataset."""
    out = output_folder(out)
    paths = save_comparisons(comparisons, out)
    json_path = out / "validation.json"
    data = {"validation": [c.to_dict() for c in comparisons], "warnings": list(warnings)}
    write_results(json_path, data, "validate")
    write_html_report(out / "report.html", data, "validate", paths, "dynid validate")
    paths.insert(0, out / "report.html")
    return [json_path] + paths

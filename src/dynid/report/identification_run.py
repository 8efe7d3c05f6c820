"""Write an identification or validation run to a folder: results.json and torque figures."""

from __future__ import annotations

import re
from pathlib import Path

from .._util.keywords import keyword_only_after_data
from ..exceptions import DynIdError
from ..identification.result import IdentificationResult
from ..io import atomic_write_text
from ..io.exported.export import (
    consistent_estimate,
    file_parameters,
    file_terms_entry,
    payload_files,
    withheld_files,
)
from ..io.exported.model_files import written_model
from ..io.exported.replay import ReplayCheck, mjcf_replay, urdf_replay
from ..io.results import stored_standard
from . import figures
from .html import write_html_report
from .output import draw_figures, save_figure, staged, write_results
from .summaries import readiness


def _slug(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9]+", "_", name).strip("_").lower() or "dataset"


def save_comparisons(comparisons, out: Path, prefix: str = "validation", names=None, prismatic=()) -> list[Path]:
    """One PNG per dataset: measured vs predicted torques of every parameter set.

    Drawn on one figure that is redrawn for each dataset.

    Parameters
    ----------
    comparisons : sequence of TorqueComparison
    out : Path
        Folder.
    prefix : str
        Files are ``{prefix}_{dataset}.png`` unless ``names`` says otherwise.
    names : sequence of str, optional
        File name of each comparison.
    prismatic : sequence of bool, optional
        Which joints slide: their axes say force [N].

    Returns
    -------
    list of Path
    """
    paths, titles = [], []
    for i, cmp in enumerate(comparisons):
        kind = prefix if names is None else names[i][0]
        paths.append(out / (f"{prefix}_{_slug(cmp.name)}.png" if names is None else names[i][1]))
        titles.append(f"{kind} — {cmp.name}: measured vs predicted torques")
    if paths:
        draw_figures(_comparison_jobs, list(comparisons), paths, titles, tuple(bool(p) for p in prismatic))
    return paths


def _comparison_jobs(comparisons, paths, titles, prismatic=()) -> list:
    """The jobs that write the comparison figures (:func:`dynid.report.output.draw_figures`)."""
    cache = {}

    def job(cmp, path, title):
        key = (cmp.measured.shape[1], tuple(cmp.predicted))
        if key not in cache:  # one figure per process and layout, redrawn for each dataset
            cache[key] = figures.TorqueFigure(*key, prismatic=prismatic)
        save_figure(cache[key].draw(cmp.t, cmp.measured, cmp.predicted, title), path)

    return [lambda c=c, p=p, t=t: job(c, p, t) for c, p, t in zip(comparisons, paths, titles)]


@staged
@keyword_only_after_data
def save_identification(result: IdentificationResult, out: str | Path, *, figures_too: bool = True, robot=None,
                        urdf: str | Path | None = None, urdf_name: str | None = None,
                        mjcf_model: str | Path | None = None, mjcf_name: str | None = None,
                        mjcf_folder: str | Path | None = None, config=None) -> list[Path]:
    """Write an identification's results and figures.

    ``results.json``, ``report.html``, the identification fit figure and one figure per validation dataset; with
    ``robot`` (the identified robot), when the physically consistent estimate passed the consistency check, the model
    to use: the user's own URDF with the identified values written into it (``urdf``: the same file name, only its
    ``<inertial>`` and ``<dynamics>`` values changed, :func:`dynid.io.exported.urdf_write_back.urdf_written_back`) or, for a
    robot described otherwise, ``dynid-model.urdf`` of dynid's own naming; and the MJCF: the user's own MuJoCo model
    with the identified values written into it (``mjcf_model``, :func:`dynid.io.exported.mjcf_write_back.mjcf_written_back`)
    or ``dynid-model.xml``.

    Parameters
    ----------
    result : IdentificationResult
    out : str or Path
        Output folder.
    figures_too : bool
        Write the figures.
    robot : Robot, optional
        The identified robot, for the exports.
    urdf : str or Path, optional
        The URDF the robot was read from (:attr:`dynid.io.config.identification_config.IdentificationConfig.urdf`).
    urdf_name : str, optional
        The written-back URDF's file name (default the user's; :func:`model_file_name` keeps a user's URDF in the
        output folder from being replaced).
    mjcf_model : str or Path, optional
        The user's own MJCF of the arm (:attr:`dynid.io.config.identification_config.IdentificationConfig.mjcf_model`).
    mjcf_name : str, optional
        The written-back MJCF's file name (default the user's; :func:`model_file_name`).
    mjcf_folder : str or Path, optional
        The folder the MJCF ends up in, from which its relative paths (meshes, includes) are rewritten (default
        ``out``; the command's output folder when ``out`` is a staging folder inside it).
    config : IdentificationConfig, optional
        The config: the written files are read back on its first moving validation log (:func:`taken_away`;
        results.json's ``files_taken_away``), else on random states.
    """
    out = Path(out)  # staged passes its staging folder
    paths = []
    if figures_too:
        names = [("identification", "identification_fit.png")] + [
            ("validation", f"validation_{_slug(v.name)}.png") for v in result.validations]
        paths = save_comparisons((result.fit, *result.validations), out, names=names, prismatic=result.base.prismatic)
    json_path = out / "results.json"
    data = {**result.to_dict(), "readiness": readiness(result).text}  # the first line: the report's box starts with it
    withheld = withheld_files(data)
    if withheld:
        data["files_withheld"] = withheld
    models = [] if withheld else _model_texts(data, out, robot, urdf=urdf, urdf_name=urdf_name, mjcf_model=mjcf_model,
                                              mjcf_name=mjcf_name, mjcf_folder=mjcf_folder)
    if models:
        data["files_taken_away"] = taken_away(models, robot, data, config)
    write_results(json_path, data, "identify")
    write_html_report(out / "report.html", data, "identify", paths, f"dynid identify — {result.robot}")
    paths.insert(0, out / "report.html")
    paths[:0] = [path for path, _ in models]
    for path, text in models:
        atomic_write_text(path, text)
    return [json_path] + paths


def _model_texts(data: dict, out: Path, robot, *, urdf, urdf_name, mjcf_model, mjcf_name, mjcf_folder) -> list:
    """The URDF and the MJCF :func:`save_identification` writes, as ``[(path, text), ...]``: none unless the physically
    consistent estimate passed its check."""
    sdp = stored_standard(data)
    if robot is None or sdp is None or data["physically_consistent_verdict"].get(sdp[0]) != "yes":
        return []
    model = (out / ("dynid-model.urdf" if urdf is None else urdf_name or Path(urdf).name),
             written_model("URDF", robot, data, users_file=urdf)[0])
    mjcf = (out / ("dynid-model.xml" if mjcf_model is None else mjcf_name or Path(mjcf_model).name),
            written_model("MJCF", robot, data, users_file=mjcf_model, out_dir=mjcf_folder or out)[0])
    return [model, mjcf]


def taken_away(models: list, robot, data: dict, config=None) -> dict:
    """The files an identification writes read back by the tools they are for (issue "The model proven where it
    goes", item 1): the URDF by Pinocchio, the MJCF by MuJoCo (:mod:`dynid.io.exported.replay`), on the config's first moving
    validation log where there is one (:func:`dynid.identification.run.moving_validation`), else on random states.

    Parameters
    ----------
    models : list of (Path, str)
        The URDF's and the MJCF's paths and texts.
    robot : Robot
        The identified robot.
    data : dict
        results.json.
    config : IdentificationConfig, optional
        Where the validation logs are.

    Returns
    -------
    dict
        ``log`` (None: random states), and per file its format, the tool, how closely it equals dynid's model, what
        it cannot hold, what the tool computes from it against dynid's whole model per joint (``simulator_gap`` [%],
        :attr:`dynid.io.exported.replay.ReplayCheck.simulator_gap`) and, on a log, its error and dynid's whole model's against
        the measured torques [%].
    """
    from ..identification.run import moving_validation

    fitted, whole = consistent_estimate(robot, data)
    log = None
    if config is not None and config.validation:
        try:
            log = moving_validation(config, data, fitted)
        except DynIdError:  # a log that cannot be read again here: random states
            log = None
    on = {} if log is None else {"states": log[1][1:4], "measured": log[1][4]}
    files = []
    for (path, text), (form, tool, replay) in zip(models, (("URDF", "Pinocchio", urdf_replay),
                                                           ("MJCF", "MuJoCo", mjcf_replay))):
        check: ReplayCheck | str
        try:
            check = replay(text, fitted, file_parameters(fitted, whole, data, form=form)[0], whole=whole, **on)
        except ImportError:
            check = f"{tool} is not installed (pip install 'dynid[mujoco]')"
        except (ValueError, KeyError) as exc:  # a user's model MuJoCo cannot load from its text alone
            check = f"{tool} could not load it from its text ({str(exc).splitlines()[0]})"
        files.append(read_back_entry(path.name, form, check, file_choice(data, form)))
    return {"log": None if log is None else log[0], "files": files}


def file_choice(results: dict, form: str) -> dict:
    """What a written file holds otherwise than dynid's model, as the validation logs chose (results'
    ``diagnostics.file_terms``, :mod:`dynid.identification.file_terms`).

    Parameters
    ----------
    results : dict
        results.json.
    form : {"URDF", "MJCF"}

    Returns
    -------
    dict
        ``friction_folded`` and, for an MJCF, ``offsets_held``: joint numbers, from 1.
    """
    found = file_terms_entry(results)[1]
    found = found if isinstance(found, dict) else {}
    joints = lambda key: [j + 1 for j, f in enumerate(found.get(key) or []) if f is True]  # noqa: E731
    return {"friction_folded": joints("folded"), **({"offsets_held": joints("offset")} if form == "MJCF" else {})}


def read_back_entry(name: str, form: str, check, chosen: dict | None = None) -> dict:
    """One written file read back by its tool, as results.json's ``files_taken_away`` holds it.

    Parameters
    ----------
    name : str
        The file's name.
    form : {"URDF", "MJCF"}
    check : ReplayCheck or str
        :func:`dynid.io.exported.replay.urdf_replay` or :func:`~dynid.io.exported.replay.mjcf_replay`'s check, or why there is none.
    chosen : dict, optional
        What the file holds otherwise than dynid's model (:func:`file_choice`).

    Returns
    -------
    dict
    """
    entry: dict = {"file": name, "format": form, "read_by": "Pinocchio" if form == "URDF" else "MuJoCo"}
    if isinstance(check, str):
        return {**entry, "not_read_back": check}
    return {**entry, "equals_model_to": check.relative_error, "samples": check.n_states,
            "cannot_hold": list(check.missing), "cannot_hold_share": [float(x) for x in check.missing_share],
            "file_vs_measured": check.file_vs_measured, "model_vs_measured": check.model_vs_measured,
            "simulator_gap": [float(x) for x in check.simulator_gap], **(chosen or {}),
            **({"following_joints": list(check.followers)} if check.followers else {})}


def model_file_name(urdf: str | Path, out: str | Path) -> str:
    """A written-back model's name in the output folder ``out``: the user's file name, or ``<stem>-identified<ext>``
    (``arm-identified.urdf``, ``arm-identified.xml``) when the user's file is itself in ``out`` (it is never replaced).

    Parameters
    ----------
    urdf : str or Path
        The user's URDF or MJCF.
    out : str or Path
        The output folder.

    Returns
    -------
    str
    """
    urdf = Path(urdf)
    same = (Path(out) / urdf.name).resolve() == urdf.resolve()
    return f"{urdf.stem}-identified{urdf.suffix}" if same else urdf.name


@staged
def save_validation(comparisons, out: str | Path, warnings=()) -> list[Path]:
    """Write ``validation.json`` (per-joint metrics of every parameter set) and one figure per dataset.

    Parameters
    ----------
    comparisons : sequence of TorqueComparison
    out : str or Path
        Output folder.
    warnings : sequence of str
        Stored in the file.
    """
    out = Path(out)  # staged passes its staging folder
    paths = save_comparisons(comparisons, out)
    json_path = out / "validation.json"
    data = {"validation": [c.to_dict() for c in comparisons], "warnings": list(warnings)}
    write_results(json_path, data, "validate")
    write_html_report(out / "report.html", data, "validate", paths, "dynid validate")
    paths.insert(0, out / "report.html")
    return [json_path] + paths


@staged
def save_payload(payload, out: str | Path, robot=None, parent: str = "", estimate: str = "",
                 link: int | None = None) -> list[Path]:
    """Write ``payload.json``, ``payload.urdf`` (a link on a fixed joint to paste into the arm's URDF) and
    ``payload.xml`` (an MJCF body to put inside the arm's last body) (:func:`dynid.io.exported.export.payload_files`).

    Parameters
    ----------
    payload : Payload
    out : str or Path
        Output folder.
    robot : Robot
        The arm (its tool frame is the flange).
    parent : str
        The URDF link the payload is fixed to.
    estimate : str
        The arm's estimate the payload was taken beyond, stored in the file.
    link : int, optional
        The link carrying it, 0-based (default the last).
    """
    out = Path(out)  # staged passes its staging folder
    urdf, mjcf = payload_files(payload, robot, parent, link)
    write_results(out / "payload.json", {"payload": payload.to_dict(), "arm_estimate": estimate, "urdf_parent": parent},
                  "payload")
    atomic_write_text(out / "payload.urdf", urdf)
    atomic_write_text(out / "payload.xml", mjcf)
    return [out / "payload.json", out / "payload.urdf", out / "payload.xml"]

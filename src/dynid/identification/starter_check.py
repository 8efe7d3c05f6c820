"""What ``dynid init`` checks of the log before it writes the config: the identification log identified as the config
it is about to write would have it (least squares alone), then the robot's mounting and the torques' sign set where
that check finds them otherwise than the robot file says (:func:`dynid.validation.geometry_checks.geometry_findings`'s
gravity, :func:`dynid.validation.diagnostics.sign_findings`), so that the first ``dynid identify`` reads the log
right (issue "Never worse than the description": on the LBR Med7's log the config without the sign scored 20.0 % and
needed a second run). The sign is judged with the mounting set (a ceiling-mounted arm's torques run against an upright
model on some joints, and are not flipped)."""

from __future__ import annotations

import tomllib
from dataclasses import replace
from pathlib import Path

from ..exceptions import DynIdError
from ..io.datasets import load_recording
from ..io.identification_config import config_from_document
from ..io.starter import with_robot_setting, with_torque_setting
from .run import pipeline_of

__all__ = ["checked_against_description"]


def _findings(text: str, path: Path) -> tuple:
    """The identification log's findings with the config ``text`` says, least squares alone."""
    config = config_from_document(tomllib.loads(text), path)
    recording = load_recording(config.identification, config.robot)
    return replace(pipeline_of(config), estimators=("wls",)).fit(recording, held_out=False).findings


def checked_against_description(text: str, path: Path) -> tuple[str, list[str]]:
    """The starter config with the robot's gravity and its identification log's torque sign set where the log's own
    check finds them otherwise (the sign judged again once the gravity is set).

    Parameters
    ----------
    text : str
        The config :func:`dynid.io.starter.starter_config` wrote.
    path : Path
        Where it will be written (its relative paths start from its folder).

    Returns
    -------
    text : str
        As given, or with ``gravity = [...]`` in ``[robot]`` and ``sign = ...`` in ``[identification]``'s torques (or
        currents), each with why beside it.
    notes : list of str
        What was found, a line each (none where the log reads as the robot file says).
    """
    notes: list[str] = []
    try:
        findings = _findings(text, path)
        tilted = next((f for f in findings if f.kind == "gravity" and f.fix is not None), None)
        if tilted is not None and tilted.fix is not None:
            vector = [round(x, 4) for x in tilted.fix["gravity"]]
            text = with_robot_setting(text, "gravity", vector, "m/s² in the base frame: the measured torques fit the "
                                                               "description's model so (dynid init's check)")
            notes.append(f"robot: gravity = {vector} written: {' '.join(tilted.text.split())}")
            findings = _findings(text, path)
    except DynIdError as exc:
        first = " ".join(str(exc).split())
        return text, notes + [f"torque signs not checked against the description ({first}): dynid identify checks them"]
    found = next((f for f in findings if f.kind == "sign" and f.fix is not None and "sign" in f.fix), None)
    if found is None or found.fix is None:
        return text, notes
    sign = found.fix["sign"]
    written = with_torque_setting(text, "sign", sign, "the measured torques run against the description's nominal "
                                                      "model (dynid init's check): remove it if the log's sign is right")
    if written is None:
        return text, notes + [found.text]
    said = "sign = -1" if sign == -1 else f"sign = {sign}"
    return written, notes + [f"torques: {said} written: {' '.join(found.text.split())}"]

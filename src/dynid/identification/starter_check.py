"""What ``dynid init`` checks of the log before it writes the config: the identification log identified as the config
it is about to write would have it (least squares alone), and the torques' sign set where every joint the
description's nominal model can judge runs against it (:func:`dynid.validation.diagnostics.sign_findings`), so that
the first ``dynid identify`` reads the log right (issue "Never worse than the description": on the LBR Med7's log
the config without it scored 20.0 % and needed a second run)."""

from __future__ import annotations

import tomllib
from dataclasses import replace
from pathlib import Path

from ..exceptions import DynIdError
from ..io.datasets import load_recording
from ..io.identification_config import config_from_document
from ..io.starter import with_torque_setting
from .run import pipeline_of

__all__ = ["checked_torque_sign"]


def checked_torque_sign(text: str, path: Path) -> tuple[str, list[str]]:
    """The starter config with its identification log's torque sign set where the log's own check finds it flipped.

    Parameters
    ----------
    text : str
        The config :func:`dynid.io.starter.starter_config` wrote.
    path : Path
        Where it will be written (its relative paths start from its folder).

    Returns
    -------
    text : str
        As given, or with ``sign = ...`` in ``[identification]``'s torques (or currents) and why beside it.
    notes : list of str
        What was found, one line (none where the sign is as logged).
    """
    try:
        config = config_from_document(tomllib.loads(text), path)
        recording = load_recording(config.identification, config.robot)
        result = replace(pipeline_of(config), estimators=("wls",)).fit(recording, held_out=False)
    except DynIdError as exc:
        first = " ".join(str(exc).split())
        return text, [f"torque signs not checked against the description ({first}): dynid identify checks them"]
    found = next((f for f in result.findings if f.kind == "sign" and f.fix is not None and "sign" in f.fix), None)
    if found is None:
        return text, []
    sign = found.fix["sign"]
    written = with_torque_setting(text, "sign", sign, "the measured torques run against the description's nominal "
                                                      "model (dynid init's check): remove it if the log's sign is right")
    if written is None:
        return text, [found.text]
    said = "sign = -1" if sign == -1 else f"sign = {sign}"
    return written, [f"torques: {said} written: {' '.join(found.text.split())}"]

"""What ``dynid init`` checks of the log before it writes the config: the identification log identified as the config
it is about to write would have it, least squares alone on the rule's cutoffs and the description's friction terms
(neither cross-validated: the check finds how the log reads against the robot file, which a few percent of fit do not
change), then the robot's mounting, its joints' zeros and the torques' sign set where that check finds them otherwise
than the robot file says
(:func:`dynid.validation.geometry_checks.geometry_findings`' gravity and turned zeros,
:func:`dynid.validation.diagnostics.sign_findings`), so that the first ``dynid identify`` reads the log right (issue
"Never worse than the description": on the LBR Med7's log the config without the sign scored 20.0 % and needed a
second run). The sign is judged with the geometry set (a ceiling-mounted arm's torques run against an upright model
on some joints, and are not flipped). A reversed joint or swapped columns are left to ``dynid identify``'s finding:
the reader's columns are the user's to check."""

from __future__ import annotations

import tomllib
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from ..exceptions import DataError, DynIdError
from ..io.config.identification_config import config_from_document
from ..io.config.starter import with_joint_setting, with_robot_setting, with_torque_setting
from ..io.logs.datasets import load_recording
from ..model.description import builtin_robots
from .run import pipeline_of

__all__ = ["checked_against_description"]

GEOMETRY_FIXES = 2
"""Geometry settings written one after the other, each checked again: the mounting, then a joint's zero (or the other
way round)."""


CHECKED_SECONDS = 120.0
"""The stretch of a log the check identifies [s]: several periods of any excitation dynid designs (10-20 s each), and
longer than every real log dynid ships configs for, which are checked whole; fitting the whole of an hour-long log
made init take tens of seconds (the figures: benchmarks/README.md)."""

SEARCHED_SECONDS = 300.0
"""The first seconds of a log read for the check [s]: its stretch starts where the arm first moves in them (a second
before), so that a long log that starts at rest is checked on its motion."""

MOVED = 0.01
"""[rad, or m for a sliding joint] How far a joint goes from its first position for the log to move."""


def _findings(text: str, path: Path, progress=None) -> tuple[tuple, int]:
    """The identification log's findings with the config ``text`` says (its first :data:`CHECKED_SECONDS` where no
    stretch is chosen), least squares alone on the rule's cutoffs and the description's friction terms, and the robot's
    joints."""
    config = config_from_document(tomllib.loads(text), path)
    spec = config.identification
    try:  # a log too short for a stretch of it is read whole, refused (if it is) in its own words
        recording = load_recording(_stretch(spec, config.robot), config.robot)
    except DataError:
        recording = load_recording(spec, config.robot)
    if spec.time_range is None and spec.rows is None:
        recording = _moving(recording)
    pipeline = pipeline_of(config)
    fitted = replace(pipeline, estimators=("wls",), preprocessing=replace(pipeline.preprocessing, auto=False),
                     friction="description").fit(recording, held_out=False, progress=progress)
    return fitted.findings, config.robot.n_dof


HEAD_ROWS = 2000
"""The rows read first to know a log's sample step, so that the check's stretch is read without the rest of the file."""


def _stretch(spec, robot):
    """``spec``'s first :data:`SEARCHED_SECONDS` (``spec`` itself where it selects rows or a time range): its rows up to
    that time with a tenth to spare, from the step of its first :data:`HEAD_ROWS` rows, then the time range; a log
    too short for those rows raises DataError (read whole by the caller), so that a long log's other rows are never
    read."""
    if spec.time_range is not None or spec.rows is not None:
        return spec
    if spec.bag is not None:  # a bag is read whole whatever its rows: its time range alone
        return replace(spec, time_range=(0.0, SEARCHED_SECONDS))
    head = load_recording(replace(spec, rows=(1, HEAD_ROWS)), robot)
    step = float(np.median(np.diff(head.t)))
    rows = int(np.ceil(1.1 * SEARCHED_SECONDS / step)) + 1
    return replace(spec, rows=(1, rows), time_range=(0.0, SEARCHED_SECONDS))


def _moving(recording):
    """:data:`CHECKED_SECONDS` of ``recording`` from a second before a joint first moves :data:`MOVED` from its first
    position (the whole of a shorter log, and the stretch ending at its end where the motion starts later)."""
    t = np.asarray(recording.t, dtype=float)
    if t[-1] - t[0] <= CHECKED_SECONDS:
        return recording
    q = np.asarray(recording.q, dtype=float)
    moved = np.flatnonzero(np.any(np.abs(q - q[0]) > MOVED, axis=1))
    start = t[0] if moved.size == 0 else max(t[0], min(t[moved[0]] - 1.0, t[-1] - CHECKED_SECONDS))
    a, b = int(np.searchsorted(t, start)), int(np.searchsorted(t, start + CHECKED_SECONDS, side="right"))
    return replace(recording, t=t[a:b], q=q[a:b], tau=recording.tau[a:b],
                   dq=None if recording.dq is None else recording.dq[a:b])


def _with_geometry(text: str, found, n_dof: int) -> tuple[str, str]:
    """``text`` with the setting a gravity or angles finding names (its ``fix``; ``n_dof`` the robot's joints, the
    ``[[robot.joints]]`` tables made for a zero), and the line that says so."""
    why = "the measured torques fit the description's model so (dynid init's check)"
    said = " ".join(found.text.split()).split(". ")[0]  # what was found; the question and the setting it asks for follow
    if "gravity" in found.fix:
        vector = [round(x, 4) for x in found.fix["gravity"]]
        return (with_robot_setting(text, "gravity", vector, f"m/s² in the base frame: {why}"),
                f"robot: gravity = {vector} written: {said}")
    offsets = found.fix["position_offset"]
    written = with_joint_setting(text, "position_offset", offsets, n_dof,
                                 f"added to the logged angles: {why}; remove it if the encoders' zeros are the file's")
    listed = ", ".join(f'J{j + 1} position_offset = "{v}"' for j, v in sorted(offsets.items()))
    return written, f"robot: {listed} written in [[robot.joints]]: {said}"


def checked_against_description(text: str, path: Path, progress: Callable[[str, float, float], Any] | None = None
                                ) -> tuple[str, list[str]]:
    """The starter config with the robot's gravity, its joints' zeros and its identification log's torque sign set
    where the log's own check finds them otherwise (the sign judged again once the geometry is set).

    Parameters
    ----------
    text : str
        The config :func:`dynid.io.config.starter.starter_config` wrote.
    path : Path
        Where it will be written (its relative paths start from its folder).
    progress : callable, optional
        ``progress(step, done, total)`` of each identification the check runs
        (:meth:`dynid.identification.pipeline.IdentificationPipeline.fit`'s steps).

    Returns
    -------
    text : str
        As given, or with ``gravity = [...]`` in ``[robot]``, ``position_offset = "pi/2"`` (a quarter or half turn)
        in a joint's ``[[robot.joints]]`` table and ``sign = ...`` in ``[identification]``'s torques (or currents),
        each with why beside it.
    notes : list of str
        What was found, a line each (none where the log reads as the robot file says).
    """
    notes: list[str] = []
    try:
        findings, n_dof = _findings(text, path, progress)
        for _ in range(GEOMETRY_FIXES):  # the mounting and a zero can both differ: one found, set and checked again
            found = next((f for f in findings if f.kind in ("gravity", "angles") and f.fix is not None), None)
            if found is None or found.fix is None:
                break
            if tomllib.loads(text).get("robot") in builtin_robots():  # no file of its own to set it in
                notes.append(f"{' '.join(found.text.split())} (a built-in robot: give it in a description file)")
                break
            text, note = _with_geometry(text, found, n_dof)
            notes.append(note)
            findings, _ = _findings(text, path, progress)
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
    return written, notes + [f"torques: sign = {sign} written: {' '.join(found.text.split())}"]

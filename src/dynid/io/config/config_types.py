"""The structure of the configs of ``dynid identify``/``validate`` and ``dynid excite``, typed: each table and field
with its type, its allowed values and a description (what editors show from the JSON Schemas in ``dynid/schema/``).

The parsers (:mod:`dynid.io.config.identification_config`, :mod:`dynid.io.logs.datasets`, :mod:`dynid.io.config.excitation_config`)
convert a document into these structures first (:func:`dynid._util.typed.convert`: one-line messages naming file and
field), then check what depends on the robot (one value per joint) and the files.
"""

from __future__ import annotations

import datetime
import json
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Literal, Union

import msgspec
from msgspec import Meta

from ..._util.typed import Table, json_schema
from ...model.description_types import Angle
from ...model.description_types import RobotDescription as _RobotDescription
from ...preprocessing.bands import MIN_SPEED_FRACTION, PARALLEL_FACTOR, POSITION_FACTOR, REST_FACTOR
from ...preprocessing.settings import MAX_PRESLIDING
from ..logs.dataset_tables import Column, DatasetTable, PositiveHz, SignalTable, TimeTable, _d

if TYPE_CHECKING:  # built at import from the drive terms known then (dynid.model.description_types)
    RobotDescription = Any
else:
    RobotDescription = _RobotDescription

__all__ = ["SignalTable", "TimeTable", "DatasetTable", "PreprocessingTable", "EstimationTable", "ReferenceTable",
           "DriveGainsTable", "ControllerTable", "IdentificationDocument", "ExcitationDocument", "UnitTable",
           "FleetDocument"]

NonNegative = Annotated[float, Meta(ge=0)]
PerJoint = Union[NonNegative, list[NonNegative]]
SmoothingVelocity = Annotated[float, Meta(ge=0, le=10)]
Presliding = Annotated[float, Meta(ge=0, le=MAX_PRESLIDING)]
"""A presliding distance [rad, or m on a sliding joint] (:data:`dynid.preprocessing.settings.MAX_PRESLIDING`)."""


class PreprocessingTable(Table, kw_only=True):
    """``[preprocessing]``: every field optional; by default everything derives from the data
    (:class:`dynid.preprocessing.settings.Preprocessing`)."""

    strategy: Annotated[str, _d("parallel (default), paper, or one registered")] | None = None
    order: Annotated[int, Meta(ge=1, description="order of the Butterworth filters (default 4)")] | None = None
    band: Annotated[PositiveHz, _d("Hz, the excitation band (default: from the positions' spectrum)")] | None = None
    position_cutoff: Annotated[NonNegative, _d(f"Hz, positions (default {POSITION_FACTOR:g}x band); 0: no filter")] | None = None
    velocity_cutoff: Annotated[NonNegative, _d("Hz, measured velocities (default: the position cutoff)")] | None = None
    parallel_cutoff: Annotated[NonNegative, _d(f"Hz, torques and every regressor column (default {PARALLEL_FACTOR:g}x band)")] | None = None
    decimation: Annotated[int, Meta(ge=1, description="parallel decimation (default: down to the parallel band)")] | None = None
    min_speed: Annotated[Union[Literal["auto"], PerJoint], _d(f"rad/s: slower rows left out (default auto: {MIN_SPEED_FRACTION:g} x the RMS speed)")] | None = None
    trim: Annotated[NonNegative, _d("s removed at both ends (default 3 / cutoff)")] | None = None
    chunk: Annotated[int, Meta(ge=1, description="samples per chunk of the regressor")] | None = None
    excitation: Annotated[str, _d("the excitation.json the robot ran: Fourier-fit derivatives")] | None = None
    coulomb_velocity: Annotated[Union[Literal["auto"], SmoothingVelocity, list[SmoothingVelocity]],
                                _d("rad/s: Coulomb term tanh(dq/v); 0: sign; at most 10 (above, the term is a viscous one)")] | None = None
    rest_velocity: Annotated[Union[Literal["auto"], PerJoint], _d(f"rad/s: below it a joint rests (default auto: {REST_FACTOR:g} x its velocity's noise)")] | None = None
    rest_friction: Annotated[Union[Literal["held", "zero"], NonNegative, list[Union[Literal["held", "zero"], NonNegative]]],
                             _d('friction at rest: "held", "zero" or a relaxation time [s], one or one per joint')] | None = None
    presliding: Annotated[Union[Presliding, list[Presliding]], _d(f"rad: Dahl's presliding distance, 0-{MAX_PRESLIDING:g} (default 0)")] | None = None
    torque_delay: Annotated[float, _d("s: how long the torque (current) channel lags the positions (default 0); "
                                      "a logged command held over the control period leads by half of it: -0.5/rate")] | None = None
    smoothing_passes: Annotated[int, Meta(ge=0, description="applications of eq. 17 (strategy paper)")] | None = None
    auto: Annotated[bool, _d("cross-validate the cutoffs when the positions' noise knee allows (default true)")] | None = None


class EstimationTable(Table, kw_only=True):
    """``[estimation]``."""

    estimators: Annotated[list[Union[str, dict[str, Any]]], Meta(
        min_length=1, description="the first is the main estimate: ols, wls, irls, lad, sdp, abc, abc10, de, pso or one "
                                  "registered; an inline table { key = ..., name = value } gives one its class's "
                                  "hyper-parameters")] | None = None
    seed: Annotated[int, Meta(ge=0, description="seeds the box searches (default 0)")] | None = None
    friction: Annotated[Literal["auto", "description"], _d("each joint's friction model by cross-validation, or the "
                                                           "description's terms")] | None = None
    choice: Annotated[Literal["torques", "states"], _d(
        "what chooses the main estimate among the SDP, the drive-only estimate and the description: the validation "
        "logs' torques (default), or their states alone, so that their torques stay an independent test (needs sdp "
        "among the estimators)")] | None = None


class ReferenceTable(Table, kw_only=True):
    """``[[references]]``: a published parameter set (:mod:`dynid.io.config.references`)."""

    name: Annotated[str, _d("the set's name in tables")]
    file: Annotated[str, _d("CSV of the set, relative to the data root")] | None = None
    format: Annotated[Literal["standard", "base", "nominal"], _d("one standard parameter per row, one base parameter "
                                                                "(an expression) per row, or the description's values")] | None = None
    header: Annotated[bool, _d("the first line holds column names")] | None = None
    names: Annotated[Column, _d("column of the names")] | None = None
    values: Annotated[Column, _d("column of the values")] | None = None
    rel_std: Annotated[Column, _d("column of the relative standard deviations [%]")] | None = None


class DriveGainsTable(Table, kw_only=True):
    """``[drive_gains]``: drive gains from a run without and one with a payload of known mass."""

    payload_mass: Annotated[float, Meta(gt=0, le=10_000, description="kg: the known payload (at most 10 t)")]
    unloaded: Annotated[DatasetTable, _d("the run without the payload (currents)")]
    loaded: Annotated[DatasetTable, _d("the same motion with the payload (currents)")]


class ReferenceTrajectoryTable(Table, kw_only=True):
    """``[controller.reference]``: the set-points the controller followed, one row per row of the identification log."""

    file: Annotated[str, _d("CSV of the set-points, relative to the data root")]
    header: Annotated[bool, _d("the first line names the columns")] | None = None
    positions: Annotated[list[Column], _d("one per joint: 1-based numbers or header names")]
    unit: Annotated[Literal["rad", "deg"], _d("of the positions (default rad)")] | None = None
    rows: Annotated[list[Annotated[int, Meta(ge=1)]], Meta(min_length=2, max_length=2,
                                                          description="1-based inclusive data rows")] | None = None


GainValues = Union[Annotated[float, Meta(ge=0)], list[Annotated[float, Meta(ge=0)]]]


class ControllerTable(Table, kw_only=True):
    """``[controller]``: the joint controller that drove the identification run, for the closed-loop estimators
    (IDIM-IV, DIDIM: :mod:`dynid.identification.closed_loop_estimators`)."""

    kp: Annotated[GainValues, _d("N·m/rad: proportional gain, one value or one per joint (per driven joint where joints follow others)")]
    kd: Annotated[GainValues, _d("N·m·s/rad: derivative gain, one value or one per joint (per driven joint where joints follow others)")]
    ki: Annotated[GainValues, _d("N·m/(rad·s): integral gain (default 0: PD)")] | None = None
    rate: Annotated[PositiveHz, _d("Hz: the control rate; the identification log is logged at it")]
    velocity_cutoff: Annotated[NonNegative, _d("Hz: first-order filter of the drive's velocity estimate (0: none)")] | None = None
    feedforward: Annotated[Literal["model", "none"], _d("the description's torque of the reference added to the "
                                                        "loop's (model), or none (default)")] | None = None
    reference: Annotated[ReferenceTrajectoryTable, _d("the reference trajectory: one row per row of the log")]


class IdentificationDocument(Table, kw_only=True):
    """A config of ``dynid identify`` and ``dynid validate`` (:mod:`dynid.io.config.identification_config`)."""

    robot: Annotated[Union[str, RobotDescription], _d("built-in name, description TOML, URDF or MuJoCo MJCF, or a table")]
    mjcf_model: Annotated[str, _d("your own MuJoCo model of the arm (MJCF), relative to this file: identify and export "
                                  "write the identified values into a copy of it")] | None = None
    data_root: Annotated[str, _d("folder of the data files, relative to this file")] | None = None
    name: Annotated[str, _d("the config's name")] | None = None
    notes: Annotated[str, _d("free text")] | None = None
    identification: Annotated[DatasetTable, _d("the log to identify from")]
    validation: Annotated[list[DatasetTable], _d("logs to validate on")] = msgspec.field(default_factory=list)
    preprocessing: Annotated[Union[PreprocessingTable, Literal["auto"]], _d("filters; by default from the data")] | None = None
    estimation: Annotated[EstimationTable, _d("the estimators")] | None = None
    references: Annotated[list[ReferenceTable], _d("published parameter sets scored beside")] = msgspec.field(default_factory=list)
    drive_gains: Annotated[DriveGainsTable, _d("drive gains from a known payload")] | None = None
    controller: Annotated[ControllerTable, _d("the controller of the identification run (IDIM-IV, DIDIM)")] | None = None
    excitation: Annotated[ExcitationTable, _d("what dynid excite designs for this robot (dynid excite CONFIG)")] | None = None


class UnitGainsTable(Table, kw_only=True):
    """A fleet unit's drive-gain runs: the files for the template's ``[drive_gains]`` tables."""

    unloaded: Annotated[str, _d("the run without the payload, relative to the manifest")]
    loaded: Annotated[str, _d("the same motion with the payload, relative to the manifest")]


class UnitTable(Table, kw_only=True):
    """``[[units]]`` of a fleet manifest: one arm, its logs read with the template's column maps (or its own config)."""

    id: Annotated[str, Meta(min_length=1, pattern=r"^[A-Za-z0-9_.-]+$",
                            description="the unit's name: letters, digits, '_', '-', '.' (its output folder)")]
    config: Annotated[str, _d("the unit's own identify config, instead of the template and the files below")] | None = None
    identification: Annotated[str, _d("the log to identify from, relative to the manifest")] | None = None
    validation: Annotated[list[str], _d("logs to validate on, relative to the manifest")] = msgspec.field(default_factory=list)
    drive_gains: Annotated[UnitGainsTable, _d("the drive-gain runs (the template has [drive_gains])")] | None = None
    payload: Annotated[float, Meta(ge=0, le=10_000, description="kg: the tool mounted on this unit (taken out of its "
                                                                "estimate before the fleet compares and pools)")] | None = None
    payload_com: Annotated[list[float], Meta(min_length=3, max_length=3, description="m: the tool's centre of mass in the "
                                                                                      "last link's frame (default: the "
                                                                                      "description's tool frame)")] | None = None
    date: Annotated[datetime.date, _d("when the logs were recorded")] | None = None


class FleetDocument(Table, kw_only=True):
    """A fleet manifest of ``dynid fleet`` (:mod:`dynid.io.config.fleet_manifest`)."""

    name: Annotated[str, _d("the fleet's name")] | None = None
    notes: Annotated[str, _d("free text")] | None = None
    template: Annotated[str, _d("identify config every unit shares (robot, columns, estimators), relative to this "
                                "file")] | None = None
    units: Annotated[list[UnitTable], Meta(min_length=1, description="the arms of the fleet")]


PerJointAngle = Union[Angle, list[Angle]]
PerJointNumber = Union[float, list[float]]


class TrajectoryTable(Table, kw_only=True):
    """``[trajectory]`` of an excitation (eq. 14)."""

    harmonics: Annotated[int, Meta(ge=1, description="N of eq. 14 (default 5)")] | None = None
    frequency: Annotated[float, Meta(gt=0, description="fundamental frequency, Hz (default 0.1 without omega_f)")] | None = None
    omega_f: Annotated[float, Meta(gt=0, description="fundamental pulsation, rad/s")] | None = None
    form: Annotated[Literal["paper", "swevers"], _d("how the coefficients are written: eq. 14 or the Swevers form")] | None = None
    offsets: Annotated[PerJointAngle, _d("fixed q_o [rad]; omit to optimise them")] | None = None
    rest: Annotated[bool, _d("start and end at rest at the offsets")] | None = None


class LimitsTable(Table, kw_only=True):
    """``[limits]``: the robot's limits overridden, one value or one per joint."""

    q_min: Annotated[PerJointAngle, _d("rad")] | None = None
    q_max: Annotated[PerJointAngle, _d("rad")] | None = None
    dq_max: Annotated[PerJointNumber, _d("rad/s")] | None = None
    ddq_max: Annotated[PerJointNumber, _d("rad/s²")] | None = None
    tau_max: Annotated[PerJointNumber, _d("N·m")] | None = None


class ObstacleTable(Table, kw_only=True):
    """``[[workspace.obstacles]]``: one body of the robot's cell, in the base frame [m]."""

    shape: Annotated[Literal["box", "cylinder", "sphere"], _d("the body's shape")]
    size: Annotated[list[float], Meta(min_length=1, max_length=3, description="box: full lengths [x, y, z]; cylinder: "
                                                                         "[radius, length] along its z; sphere: [radius], m")]
    position: Annotated[list[float], Meta(min_length=3, max_length=3, description="its centre [x, y, z], m")]
    rpy: Annotated[list[float], Meta(min_length=3, max_length=3, description="roll, pitch, yaw about the base's fixed "
                                                                        "axes, rad (default 0)")] | None = None
    name: Annotated[str, _d("named in messages (default obstacle 1, 2 …)")] | None = None


class WorkspaceTable(Table, kw_only=True):
    """``[workspace]``: where the tool point may go, base frame [m]."""

    box_min: Annotated[list[float], Meta(min_length=3, max_length=3, description="[x, y, z] m (inf: open)")] | None = None
    box_max: Annotated[list[float], Meta(min_length=3, max_length=3, description="[x, y, z] m (inf: open)")] | None = None
    floor: Annotated[float, _d("height of the floor or table the arm stands over, m: the tool point stays above it and "
                                "every link's shape `clearance` above it")] | None = None
    clearance: Annotated[float, Meta(ge=0.0, description="how far the links' shapes keep off the floor and the cell's "
                                                         "bodies, m (surface to surface); default 0.05")] | None = None
    obstacles: Annotated[list[ObstacleTable], _d("the cell's bodies every link's shape keeps `clearance` off")] | None = None
    geometry: Annotated[Literal["auto", "capsules", "collision"],
                        _d("what the links' shapes are: the robot URDF's own collision shapes or its MJCF's colliding "
                           "geoms (\"collision\"), capsules of `link_radius` about the joint origins (\"capsules\"), "
                           "or the first where the robot's file has them (\"auto\", default)")] | None = None
    link_radius: Annotated[float, Meta(gt=0.0, description="the links' capsule radius, m, without collision shapes; "
                                                           "default: 15 % of the arm's reach, said as an estimate")] | None = None
    srdf: Annotated[str, _d("MoveIt's SRDF of the robot's URDF (path relative to the config): the pairs of links its "
                            "<disable_collisions> name are not kept apart")] | None = None
    avoid_self_collision: Annotated[bool, _d("the design keeps the links off each other: true, by their "
                                             "collision shapes or else their capsules; false, neither (checked and "
                                             "said only); default: the collision shapes yes, the capsules no")] | None = None


class DesignTable(Table, kw_only=True):
    """``[design]``: the optimisation."""

    criterion: Annotated[Literal["cond", "d-optimal"], _d("cond(W_base) (default) or -log det")] | None = None
    starts: Annotated[int, Meta(ge=1, description="optimisation starts (default 6)")] | None = None
    seed: Annotated[int, _d("seeds the random starts")] | None = None
    grid_points: Annotated[int, Meta(ge=1, description="samples per period of the design grid")] | None = None
    safety: Annotated[float, _d("margin kept from each limit, as a fraction (default 0.02)")] | None = None
    maxiter: Annotated[int, Meta(ge=1, description="SLSQP iterations per start (default 150)")] | None = None
    initial: Annotated[str, _d('"paper" (β1) or an excitation JSON')] | None = None


class OutputTable(Table, kw_only=True):
    """``[output]``: the set-points' CSV."""

    rate: Annotated[float, Meta(gt=0, description="controller rate, Hz (default 500)")] | None = None
    periods: Annotated[int, Meta(ge=1, description="periods written (default 1)")] | None = None


class ExcitationTable(Table, kw_only=True):
    """``[excitation]`` of an identification config: what ``dynid excite CONFIG`` designs for the config's robot (every
    table optional; the trajectory defaults to 5 harmonics of 0.1 Hz, starting and ending at rest)."""

    joints: Annotated[int, Meta(ge=1, description="identify the first joints (default all)")] | None = None
    trajectory: Annotated[TrajectoryTable, _d("the Fourier trajectory (eq. 14)")] | None = None
    limits: Annotated[LimitsTable, _d("limits overriding the robot's")] = msgspec.field(default_factory=LimitsTable)
    workspace: Annotated[WorkspaceTable, _d("where the tool may go")] = msgspec.field(default_factory=WorkspaceTable)
    design: Annotated[DesignTable, _d("the optimisation")] = msgspec.field(default_factory=DesignTable)
    output: Annotated[OutputTable, _d("the set-points' CSV")] = msgspec.field(default_factory=OutputTable)


class ExcitationDocument(Table, kw_only=True):
    """A config of ``dynid excite`` (:mod:`dynid.io.config.excitation_config`)."""

    robot: Annotated[Union[str, RobotDescription], _d("built-in name, description TOML, URDF or MuJoCo MJCF, or a table")]
    joints: Annotated[int, Meta(ge=1, description="identify the first joints (default all)")] | None = None
    name: Annotated[str, _d("the config's name")] | None = None
    notes: Annotated[str, _d("free text")] | None = None
    trajectory: Annotated[TrajectoryTable, _d("the Fourier trajectory (eq. 14); without it 5 harmonics of 0.1 Hz, "
                                             "starting and ending at rest")] | None = None
    limits: Annotated[LimitsTable, _d("limits overriding the robot's")] = msgspec.field(default_factory=LimitsTable)
    workspace: Annotated[WorkspaceTable, _d("where the tool may go")] = msgspec.field(default_factory=WorkspaceTable)
    design: Annotated[DesignTable, _d("the optimisation")] = msgspec.field(default_factory=DesignTable)
    output: Annotated[OutputTable, _d("the set-points' CSV")] = msgspec.field(default_factory=OutputTable)


SCHEMAS = {
    "identification": (IdentificationDocument, "dynid identify / validate config",
                       "An identification config of dynid: the robot, its logs, preprocessing, "
                       "estimators, references."),
    "fleet": (FleetDocument, "dynid fleet manifest", "A fleet manifest of dynid: the units of one robot model and "
                                                        "their logs."),
    "excitation": (ExcitationDocument, "dynid excite config", "An excitation design config of dynid."),
    "robot": (RobotDescription, "dynid robot description", "A robot description of dynid: DH table or URDF, limits, drive "
                                                             "gains, drive terms and their nominal values."),
}
"""The JSON Schemas shipped in ``dynid/schema/<name>.schema.json``: (structure, title, description)."""


def write_schemas(folder=None) -> list:
    """Write the JSON Schemas of :data:`SCHEMAS`.

    Parameters
    ----------
    folder : path, optional
        Where (default: the package's ``schema`` folder).

    Returns
    -------
    list of Path
    """
    folder = Path(folder) if folder is not None else Path(__file__).resolve().parents[2] / "schema"
    paths = []
    for name, (kind, title, description) in SCHEMAS.items():
        path = folder / f"{name}.schema.json"
        path.write_text(json.dumps(json_schema(kind, title, description), indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
        paths.append(path)
    return paths


if __name__ == "__main__":  # python -m dynid.io.config.config_types: regenerate the shipped schemas
    for p in write_schemas():
        print(p)

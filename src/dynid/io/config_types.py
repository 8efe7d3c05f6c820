"""The structure of the configs of ``dynid identify``/``validate`` and ``dynid excite``, typed: each table and field
with its type, its allowed values and a description (what editors show from the JSON Schemas in ``dynid/schema/``).

The parsers (:mod:`dynid.io.identification_config`, :mod:`dynid.io.datasets`, :mod:`dynid.io.excitation_config`)
convert a document into these structures first (:func:`dynid.typed.convert`: one-line messages naming file and
field), then check what depends on the robot (one value per joint) and the files.
"""

from __future__ import annotations

from typing import Annotated, Literal, Union

import msgspec
from msgspec import Meta

from typing import TYPE_CHECKING, Any

from ..model.description_types import Angle, RobotDescription as _RobotDescription
from ..typed import Table

if TYPE_CHECKING:  # built at import from the drive terms known then (dynid.model.description_types)
    RobotDescription = Any
else:
    RobotDescription = _RobotDescription

__all__ = ["SignalTable", "TimeTable", "DatasetTable", "PreprocessingTable", "EstimationTable", "ReferenceTable",
           "DriveGainsTable", "IdentificationDocument", "ExcitationDocument"]

Column = Union[Annotated[int, Meta(ge=1)], str]
PositiveHz = Annotated[float, Meta(gt=0, description="Hz")]
NonNegative = Annotated[float, Meta(ge=0)]
PerJoint = Union[NonNegative, list[NonNegative]]
Factor = Union[float, list[float]]


class SignalTable(Table, kw_only=True):
    """Where one signal is: ``{ columns = [2, 3, 4, 5, 6, 7], unit = "rad" }``."""

    columns: Annotated[list[Column], Meta(description="one per joint: 1-based numbers or header names")] | None = None
    file: Annotated[str, Meta(description="default: the dataset's file")] | None = None
    unit: Annotated[str, Meta(description="rad or deg; rad/s or deg/s; A or mA; N*m")] | None = None
    sign: Annotated[Factor, Meta(description="1 or -1, or one per joint: multiplies the signal")] | None = None
    scale: Annotated[Factor, Meta(description="a non-zero factor, or one per joint")] | None = None
    side: Literal["joint", "motor"] | None = None


class TimeTable(Table, kw_only=True):
    """The time stamps' column [s]: ``time = { column = 1 }``."""

    column: Column
    file: str | None = None


class DatasetTable(Table, kw_only=True):
    """A dataset: columns of CSV files, or a ROS 2 bag of sensor_msgs/JointState (:mod:`dynid.io.datasets`)."""

    preset: Annotated[str, Meta(description="ur-rtde, ur-rtde-19, motor-side: fills in the other fields")] | None = None
    name: str | None = None
    file: Annotated[str, Meta(description="default file of every signal, relative to the data root")] | None = None
    header: bool | None = None
    n_columns: Annotated[int, Meta(ge=1)] | None = None
    delimiter: str | None = None
    rows: Annotated[list[Annotated[int, Meta(ge=1)]], Meta(min_length=2, max_length=2,
                                                           description="1-based inclusive data rows")] | None = None
    time_range: Annotated[list[float], Meta(min_length=2, max_length=2, description="s from the first row read")] | None = None
    gaps: Literal["refuse", "interpolate"] | None = None
    max_gap: Annotated[float, Meta(gt=0, description="s: the longest gap interpolated")] | None = None
    held: Literal["interpolate", "keep"] | None = None
    time: TimeTable | None = None
    rate: Annotated[PositiveHz, Meta(description="Hz, when there is no time column")] | None = None
    resample: Annotated[PositiveHz, Meta(description="Hz: uniform grid for jittered time stamps")] | None = None
    side: Literal["joint", "motor"] | None = None
    positions: SignalTable | None = None
    velocities: SignalTable | None = None
    currents: SignalTable | None = None
    torques: SignalTable | None = None
    bag: Annotated[str, Meta(description="a ROS 2 bag's folder, relative to the data root")] | None = None
    topic: str | None = None
    joint_names: list[str] | None = None
    effort: Literal["torques", "currents"] | None = None


class PreprocessingTable(Table, kw_only=True):
    """``[preprocessing]``: every field optional; by default everything derives from the data
    (:class:`dynid.preprocessing.settings.Preprocessing`)."""

    strategy: Annotated[str, Meta(description="parallel (default), paper, or one registered")] | None = None
    order: Annotated[int, Meta(ge=1)] | None = None
    band: Annotated[PositiveHz, Meta(description="Hz, the excitation band")] | None = None
    position_cutoff: Annotated[NonNegative, Meta(description="Hz; 0: no filter")] | None = None
    velocity_cutoff: Annotated[NonNegative, Meta(description="Hz; 0: no filter")] | None = None
    parallel_cutoff: Annotated[NonNegative, Meta(description="Hz, torques and every regressor column")] | None = None
    decimation: Annotated[int, Meta(ge=1)] | None = None
    min_speed: Annotated[Union[Literal["auto"], PerJoint], Meta(description="rad/s")] | None = None
    trim: Annotated[NonNegative, Meta(description="s at both ends")] | None = None
    chunk: Annotated[int, Meta(ge=1)] | None = None
    excitation: Annotated[str, Meta(description="the excitation.json the robot ran: Fourier-fit derivatives")] | None = None
    coulomb_velocity: Annotated[Union[Literal["auto"], PerJoint], Meta(description="rad/s; 0: sign")] | None = None
    rest_velocity: Annotated[Union[Literal["auto"], PerJoint], Meta(description="rad/s")] | None = None
    rest_friction: Annotated[Union[Literal["held", "zero"], NonNegative, list[Union[Literal["held", "zero"], NonNegative]]],
                             Meta(description='"held", "zero" or a relaxation time [s], one or one per joint')] | None = None
    presliding: Annotated[PerJoint, Meta(description="rad")] | None = None
    smoothing_passes: Annotated[int, Meta(ge=0)] | None = None
    auto: bool | None = None


class EstimationTable(Table, kw_only=True):
    """``[estimation]``."""

    estimators: Annotated[list[str], Meta(min_length=1, description="the first is the main estimate: ols, wls, irls, "
                                                                    "lad, sdp, abc, abc10, de, pso or one registered")] | None = None
    seed: Annotated[int, Meta(ge=0)] | None = None
    friction: Literal["auto", "description"] | None = None


class ReferenceTable(Table, kw_only=True):
    """``[[references]]``: a published parameter set (:mod:`dynid.io.references`)."""

    name: str
    file: str | None = None
    format: Literal["standard", "base", "nominal"] | None = None
    header: bool | None = None
    names: Column | None = None
    values: Column | None = None
    rel_std: Column | None = None


class DriveGainsTable(Table, kw_only=True):
    """``[drive_gains]``: drive gains from a run without and one with a payload of known mass."""

    payload_mass: Annotated[float, Meta(gt=0, description="kg")]
    unloaded: DatasetTable
    loaded: DatasetTable


class IdentificationDocument(Table, kw_only=True):
    """A config of ``dynid identify`` and ``dynid validate`` (:mod:`dynid.io.identification_config`)."""

    robot: Annotated[Union[str, RobotDescription], Meta(description="built-in name, description TOML or URDF, or a table")]
    data_root: Annotated[str, Meta(description="folder of the data files, relative to this file")] | None = None
    name: str | None = None
    notes: str | None = None
    identification: DatasetTable
    validation: list[DatasetTable] = msgspec.field(default_factory=list)
    preprocessing: Union[PreprocessingTable, Literal["auto"]] | None = None
    estimation: EstimationTable | None = None
    references: list[ReferenceTable] = msgspec.field(default_factory=list)
    drive_gains: DriveGainsTable | None = None


PerJointAngle = Union[Angle, list[Angle]]
PerJointNumber = Union[float, list[float]]


class TrajectoryTable(Table, kw_only=True):
    """``[trajectory]`` of an excitation (eq. 14)."""

    harmonics: Annotated[int, Meta(ge=1, description="N of eq. 14")]
    frequency: Annotated[float, Meta(gt=0, description="fundamental frequency, Hz")] | None = None
    omega_f: Annotated[float, Meta(gt=0, description="fundamental pulsation, rad/s")] | None = None
    form: Literal["paper", "swevers"] | None = None
    offsets: PerJointAngle | None = None
    rest: bool | None = None


class LimitsTable(Table, kw_only=True):
    """``[limits]``: the robot's limits overridden, one value or one per joint."""

    q_min: PerJointAngle | None = None
    q_max: PerJointAngle | None = None
    dq_max: PerJointNumber | None = None
    ddq_max: PerJointNumber | None = None
    tau_max: PerJointNumber | None = None


class WorkspaceTable(Table, kw_only=True):
    """``[workspace]``: where the tool point may go, base frame [m]."""

    box_min: Annotated[list[float], Meta(min_length=3, max_length=3)] | None = None
    box_max: Annotated[list[float], Meta(min_length=3, max_length=3)] | None = None
    floor: float | None = None


class DesignTable(Table, kw_only=True):
    """``[design]``: the optimisation."""

    criterion: Literal["cond", "d-optimal"] | None = None
    starts: Annotated[int, Meta(ge=1)] | None = None
    seed: int | None = None
    grid_points: Annotated[int, Meta(ge=1)] | None = None
    safety: float | None = None
    maxiter: Annotated[int, Meta(ge=1)] | None = None
    initial: Annotated[str, Meta(description='"paper" (β1) or an excitation JSON')] | None = None


class OutputTable(Table, kw_only=True):
    """``[output]``: the set-points' CSV."""

    rate: Annotated[float, Meta(gt=0, description="controller rate, Hz")] | None = None
    periods: Annotated[int, Meta(ge=1)] | None = None


class ExcitationDocument(Table, kw_only=True):
    """A config of ``dynid excite`` (:mod:`dynid.io.excitation_config`)."""

    robot: Union[str, RobotDescription]
    joints: Annotated[int, Meta(ge=1)] | None = None
    name: str | None = None
    notes: str | None = None
    trajectory: TrajectoryTable
    limits: LimitsTable = msgspec.field(default_factory=LimitsTable)
    workspace: WorkspaceTable = msgspec.field(default_factory=WorkspaceTable)
    design: DesignTable = msgspec.field(default_factory=DesignTable)
    output: OutputTable = msgspec.field(default_factory=OutputTable)


SCHEMAS = {
    "identification": (IdentificationDocument, "dynid identify / validate config",
                       "An identification config of dynid: the robot, its logs, preprocessing, "
                       "estimators, references."),
    "excitation": (ExcitationDocument, "dynid excite config", "An excitation design config of dynid."),
    "robot": (RobotDescription, "dynid robot description", "A robot description of dynid: DH table or URDF, limits, drive "
                                                             "gains, drive terms and their nominal values."),
}
"""The JSON Schemas shipped in ``dynid/schema/<name>.schema.json``: (structure, title, description)."""


def write_schemas(folder=None) -> list:
    """Write the JSON Schemas of :data:`SCHEMAS` (default: into the package's ``schema`` folder).

    Returns
    -------
    list of Path
    """
    import json
    from pathlib import Path

    from ..typed import json_schema

    folder = Path(folder) if folder is not None else Path(__file__).resolve().parents[1] / "schema"
    paths = []
    for name, (kind, title, description) in SCHEMAS.items():
        path = folder / f"{name}.schema.json"
        path.write_text(json.dumps(json_schema(kind, title, description), indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
        paths.append(path)
    return paths


if __name__ == "__main__":  # python -m dynid.io.config_types: regenerate the shipped schemas
    for p in write_schemas():
        print(p)

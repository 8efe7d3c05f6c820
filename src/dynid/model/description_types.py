"""The structure of a robot description (TOML), typed: what :func:`dynid.model.description.robot_from_document`
accepts, checked field by field before any number is used (its JSON Schema: ``dynid/schema/robot.schema.json``).

An angle may be a number [rad] or text like ``"pi/2"``, ``"-2*pi"`` (:func:`dynid.model.description.parse_angle`).
"""

from __future__ import annotations

import functools
from typing import Annotated, Literal, Union

import msgspec
from msgspec import Meta

from .._util.typed import Table
from ..friction import TERMS

__all__ = ["RobotDescription", "JointTable", "ToolTable", "TransmissionTable", "CouplingTable", "PayloadTable", "MimicTable"]

Angle = Annotated[Union[float, str], Meta(description='rad, or text like "pi/2", "-2*pi"')]
Vector3 = Annotated[list[float], Meta(min_length=3, max_length=3)]
Inertia6 = Annotated[list[float], Meta(min_length=6, max_length=6, description="Ixx, Iyy, Izz, Ixy, Ixz, Iyz [kg·m²]")]
Positive = Annotated[float, Meta(gt=0)]


class ToolTable(Table, kw_only=True):
    """``[tool]``: the flange in the last link's frame."""

    translation: Annotated[Vector3, Meta(description="m")] = msgspec.field(default_factory=lambda: [0.0, 0.0, 0.0])


class CouplingTable(Table, kw_only=True):
    """One coupled motor: ``{motor = 6, joint = 5, ratio = 32}`` (motor 6 also turns with joint 5)."""

    motor: Annotated[int, Meta(ge=1, description="1-based motor number (above the joints' own)")]
    joint: Annotated[int, Meta(ge=1, description="1-based joint whose motion the motor also follows")]
    ratio: Annotated[float, Meta(description="motor angle per joint angle of that joint")]


class MimicTable(Table, kw_only=True):
    """A joint that follows another, as a URDF's ``<mimic>``: ``mimic = { joint = "j3", multiplier = -1, offset = 0.1 }``
    (its position ``multiplier · q_j3 + offset``; a palletiser's passive joint, a coupled finger)."""

    joint: Annotated[str, Meta(description="the name of the joint it follows")]
    multiplier: Annotated[float, Meta(description="its position per position of that joint")] = 1.0
    offset: Annotated[float, Meta(description="rad (m if prismatic)")] = 0.0


class TransmissionTable(Table, kw_only=True):
    """``[transmission]``: gear ratios (motor angle = ratio · joint angle) and coupled motors."""

    gear_ratios: Annotated[list[float], Meta(description="motor angle per joint angle, one per joint")] | None = None
    coupling: Annotated[list[CouplingTable], Meta(description="coupled motors")] = msgspec.field(default_factory=list)
    coupled_terms: Annotated[list[Literal["Iam", "fvm", "fcm"]],
                             Meta(description="terms of each coupled motor: rotor inertia, viscous, Coulomb")] | None = None
    coupled_values: Annotated[list[list[float]],
                              Meta(description="nominal values of the coupled terms: one list per coupled motor (in motor "
                                               "order), one value per term of coupled_terms (default 0)")] | None = None


class PayloadTable(Table, kw_only=True):
    """``[payload]``: a load carried by the last link (nominal values, identified with the last link's)."""

    mass: Annotated[float, Meta(gt=0, le=10_000, description="kg")]
    com: Annotated[Vector3, Meta(description="m, in the last link's frame")]
    inertia: Inertia6 = msgspec.field(default_factory=lambda: [0.0] * 6)


_JOINT_FIELDS = [
    ("name", Union[Annotated[str, Meta(description="the joint's name in tables")], None], None),
    ("type", Union[Annotated[Literal["revolute", "prismatic"], Meta(
        description="revolute (theta is the joint variable) or prismatic (d is: a linear track, a SCARA's "
                    "vertical axis); a URDF or MJCF gives its own")], None], None),
    ("parent", Union[Annotated[str, Meta(
        description="modified DH: the name of the joint that carries this one, or \"base\" (a robot with "
                    "branches, Khalil-Kleinfinger's antecedent; default: the joint before it)")], None], None),
    ("gamma", Union[Angle, None], None),
    ("mimic", Union[Annotated[MimicTable, Meta(description="DH tables: this joint follows another (a URDF's <mimic>): no "
                                                           "drive and no log column of its own")], None], None),
    ("b", Union[Annotated[float, Meta(description="m: Khalil-Kleinfinger's offset along the parent's z, with gamma "
                                                  "its rotation about it (modified DH, a branch's first joint)")], None],
     None),
    ("alpha", Union[Angle, None], None),
    ("a", Union[Annotated[float, Meta(description="m")], None], None),
    ("d", Union[Annotated[float, Meta(description="m")], None], None),
    ("theta_offset", Union[Angle, None], None),
    ("q_min", Union[Angle, None], None),
    ("q_max", Union[Angle, None], None),
    ("dq_max", Union[Annotated[float, Meta(description="rad/s (m/s if prismatic)")], None], None),
    ("ddq_max", Union[Annotated[float, Meta(description="rad/s² (m/s² if prismatic)")], None], None),
    ("tau_max", Union[Annotated[float, Meta(description="N·m (N if prismatic)")], None], None),
    ("drive_gain", Union[Annotated[float, Meta(description="N·m/A: joint torque per measured current (eq. 16)")], None], None),
    ("drive_terms", Union[Annotated[list[str], Meta(description="this joint's drive terms (default: the robot's)")], None], None),
    ("counterbalance", Annotated[bool, Meta(description="a spring counterbalance (its terms cbs, cbc, cbsd, cbcd)")], False),
    ("position_offset", Union[Angle, None], None),
    ("mass", Union[Annotated[float, Meta(description="kg")], None], None),
    ("com", Union[Annotated[Vector3, Meta(description="m, link frame")], None], None),
    ("inertia", Union[Inertia6, None], None),
    ("stribeck_velocity", Union[Annotated[Positive, Meta(description="rad/s")], None], None),
]

class DriveValue(Table, kw_only=True):
    """A drive term's nominal value with its uncertainty: ``Ia = { value = 0.3, sigma = 0.05 }`` (a drive's data sheet):
    the estimates that use the description's values are pulled toward ``value`` with a Gaussian prior of standard
    deviation ``sigma`` (:mod:`dynid.identification.drive_only`, the physically consistent SDP)."""

    value: Annotated[float, Meta(description="the nominal value, in the term's unit")]
    sigma: Annotated[Positive, Meta(description="its standard deviation, in the term's unit")]


@functools.cache
def _types(terms: tuple[str, ...]) -> tuple[type, type]:
    joint = msgspec.defstruct("JointTable", _JOINT_FIELDS + [(t, Union[Annotated[float, Meta(description=f"{TERMS[t].unit}: nominal {TERMS[t].description}")],
                                                                    DriveValue, None], None)
                                                for t in terms], bases=(Table,),
                              kw_only=True, module=__name__)
    joint.__doc__ = ("``[[joints]]``: one per joint, base to tip; DH values (or nothing with a URDF), limits, drive gain and "
                     "the nominal value of each drive term (a field per term of :data:`dynid.friction.TERMS`).")
    robot = msgspec.defstruct("RobotDescription", [
        ("name", Union[Annotated[str, Meta(description="the robot's name")], None], None),
        ("convention", Union[Annotated[Literal["modified", "standard", "urdf"],
                                       Meta(description="DH convention of [[joints]] (Khalil's modified by default), or urdf")], None], None),
        ("urdf", Union[Annotated[str, Meta(description="with convention = 'urdf': the URDF file (or a MuJoCo MJCF), relative to this file")], None], None),
        ("held", Union[Annotated[Union[list[str], dict[str, float]], Meta(
            description="joints of the URDF held fixed, not identified (a gripper's fingers, mimic joints): a list of "
                        "names (held at 0) or a table name = position (rad or m); their links count with the link "
                        "they are held to")], None], None),
        ("xacro_args", Union[Annotated[dict[str, Union[str, bool, int, float]], Meta(
            description="with a xacro file: its arguments, name = value (xacro's name:=value; a number or a boolean "
                        "is given as its text, true/false; an argument not given takes the file's default)")], None],
         None),
        ("gravity", Annotated[Vector3, Meta(description="m/s², base frame")], msgspec.field(default_factory=lambda: [0.0, 0.0, -9.81])),
        ("drive_terms", Union[Annotated[list[str], Meta(description="drive/friction terms of every joint, e.g. [\"Ia\", \"fv\", \"fc\", \"off\"] (default: Ia, fc, fv, offset from a URDF or MJCF; fc, fv for a DH table)")], None], None),
        ("notes", Annotated[str, Meta(description="where the values come from")], ""),
        ("tool", Annotated[ToolTable, Meta(description="the flange in the last link's frame")], msgspec.field(default_factory=ToolTable)),
        ("transmission", Annotated[TransmissionTable, Meta(description="gear ratios and coupled motors")],
         msgspec.field(default_factory=TransmissionTable)),
        ("joints", Union[Annotated[list[joint], Meta(description="one table per joint, base to tip")], None], None),  # type: ignore[valid-type]
        ("payload", Union[Annotated[PayloadTable, Meta(description="a load carried by the last link")], None], None),
    ], bases=(Table,), kw_only=True, module=__name__)
    robot.__doc__ = "A robot description (:mod:`dynid.model.description`)."
    return joint, robot


def description_types() -> tuple[type, type]:
    """The typed tables of a robot description for the drive terms :data:`dynid.friction.TERMS` holds now.

    A term added there is a field of every ``[[joints]]`` table.

    Returns
    -------
    JointTable, RobotDescription : type
        msgspec structures.
    """
    return _types(tuple(TERMS))


JointTable, RobotDescription = description_types()

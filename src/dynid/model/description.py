"""Robot descriptions in TOML: DH table (modified or standard) or URDF, plus what a URDF does not say.

Layout (all values SI, angles in radians; an angle may be written ``"pi/2"``, ``"-pi"``, ``"3*pi/4"``)::

    name = "er16"
    convention = "modified"        # "modified" (Khalil/Craig) | "standard" | "urdf"
    urdf = "robot.urdf"            # with convention = "urdf", relative to this file
    gravity = [0.0, 0.0, -9.81]    # m/s², base frame
    drive_terms = ["fc", "fv"]     # identified per joint: names of dynid.friction.TERMS (Ia, fc, fv, offset, fst)
    notes = "where the numbers come from"

    [tool]                         # flange in the last link frame (optional)
    translation = [0.0, 0.0, 0.1]

    [transmission]                 # optional; default: joint-side data, no coupling
    gear_ratios = [32, 32, 45, -48, 45, 32]          # motor angle = ratio · joint angle
    coupling = [{motor = 6, joint = 5, ratio = 32}]  # motor 6 also turns with joint 5 (coupled wrist)
    coupled_terms = ["Iam", "fvm", "fcm"]            # identified per coupled motor
    coupled_values = [[0.0096, 0.62, 1.95]]          # optional: their nominal values, one list per coupled motor

    [[joints]]                     # one table per joint, base to tip
    name = "joint1"
    type = "revolute"              # or "prismatic": d is the joint variable (a linear track, a SCARA's z axis)
    alpha = "pi"                   # DH: alpha (alpha_{i-1} for modified), a, d, theta_offset
    a = 0.0
    d = 0.0                        # a prismatic joint's d at q = 0
    theta_offset = 0.0
    parent = "base"                # optional, modified DH: the joint carrying this one (a robot with branches;
    gamma = 0.0                    # default the joint before it), with Khalil-Kleinfinger's gamma [rad] and b [m]
    b = 0.0                        # (RotZ(gamma) TransZ(b) before RotX(alpha))
    mimic = { joint = "joint0", multiplier = -1.0, offset = 0.0 }  # optional: follows another joint (a <mimic>)
    q_min = -2.9                   # rad (m if prismatic)
    q_max = 2.9
    dq_max = 3.0                   # rad/s (m/s)
    ddq_max = 15.0                 # rad/s² (m/s²)
    tau_max = 800.0                # N·m (N)
    drive_gain = 20.0              # N·m/A, eq. 16: joint torque per measured current
    drive_terms = ["fv"]           # optional: this joint has only these of the robot's drive terms
    counterbalance = true          # optional: a weight counterbalance (spring, hydraulic cylinder) acts on this
                                   # joint: its torque, a smooth function of the angle, is identified too
    position_offset = "-pi/2"      # optional: added to measured angles to get the model's angles
    mass = 60.0                    # kg (with a URDF: mass, com and inertia together replace that link's)
    com = [0.0, 0.0, -0.1]         # m, link frame (standard DH: DH frame i; a URDF: its link's frame)
    inertia = [2.0, 2.0, 1.5, 0.0, 0.0, 0.0]   # about the COM: Ixx, Iyy, Izz, Ixy, Ixz, Iyz
    fc = 8.0                       # one value per drive term
    fv = 5.0
    stribeck_velocity = 0.01       # rad/s, for the Stribeck term fst (default 0.01)

    [payload]                      # optional: a load carried by the last link (nominal values; identified
    mass = 151.0                   # with the last link's parameters), kg
    com = [0.0, 0.0, 0.1]          # m, in the last link's frame (DH conventions: as com)
    inertia = [0, 0, 0, 0, 0, 0]   # kg·m² about its centre of mass: Ixx, Iyy, Izz, Ixy, Ixz, Iyz (default 0)
"""

from __future__ import annotations

import re
import tomllib
from dataclasses import replace
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from .._util.typed import convert
from ..conventions import COUPLING_TERMS, DEFAULT_DRIVE_TERMS
from ..exceptions import ConfigError
from ..friction import COUNTERBALANCE_TERMS, DEFAULT_STRIBECK_VELOCITY, TERMS, check_terms
from .description_types import PayloadTable, TransmissionTable, description_types
from .dh import joints_from_modified_dh, joints_from_standard_dh, standard_dh_link_offset
from .robot import Limits, Robot
from .spatial import inertial_from_physical, physical_problems, transform_inertial
from .transmission import Transmission

_ANGLE = re.compile(r"^\s*([+-]?)\s*(\d*\.?\d*)\s*\*?\s*pi\s*(?:/\s*(\d+\.?\d*))?\s*$")


def builtin_robots() -> list[str]:
    """Names of the robots shipped with dynid.

    Returns
    -------
    list of str
    """
    folder = resources.files("dynid.model") / "robots"
    return sorted(p.name[:-5] for p in folder.iterdir() if p.name.endswith(".toml"))


def load_robot(name_or_path: str | Path, *, held=(), xacro_args: dict | None = None) -> Robot:
    """A built-in robot by name (``"er16"``), a robot description TOML file, a URDF, xacro or MuJoCo (MJCF) file, or
    the robot of an identification config (``dynid init``'s: its ``robot = ...`` or ``[robot]`` table).

    Parameters
    ----------
    name_or_path : str or Path
    held : sequence of str
        Joints of a URDF, xacro or MJCF held fixed at 0 (a gripper's fingers: :func:`dynid.model.urdf.joints_from_urdf`).
    xacro_args : dict of str to str, optional
        A xacro file's arguments (xacro's ``name:=value``); those not given take the file's defaults.

    Returns
    -------
    Robot
        The robot the name or file describes.

    Raises
    ------
    ConfigError
        Unknown robot, unreadable file, or a field with a wrong type or value (the message names the file and the
        field); ``held`` for a robot that is not read from a URDF, xacro or MJCF file; ``xacro_args`` for one that is
        not read from a xacro file.
    """
    text = str(name_or_path)
    path = Path(text)
    from .urdf import expand_xacro, is_mjcf, is_xacro

    _check_xacro_args(xacro_args, path, text)

    if held and not ((path.suffix == ".urdf" or is_mjcf(path) or is_xacro(path)) and path.is_file()):
        raise ConfigError(f"{text}: held = {list(held)!r} needs a URDF, xacro or MJCF file (a description TOML or an "
                          "identification config says held in its [robot] table)")
    if text in builtin_robots():
        res = resources.files("dynid.model") / "robots" / f"{text}.toml"
        return robot_from_toml_text(res.read_text(encoding="utf-8"), source=f"built-in robot {text}", base=Path(str(res)).parent)
    if (path.suffix == ".urdf" or is_mjcf(path)) and path.is_file():
        return robot_from_urdf(path, held=held)
    if is_xacro(path) and path.is_file():
        return robot_from_urdf(expand_xacro(path, xacro_args), source=str(path), name=path.name.split(".")[0],
                               held=held)
    if path.suffix.lower() in (".toml", ".urdf", ".xml", ".xacro", ".mjcf") and not path.is_file():  # a file, missing
        raise ConfigError(f"{text}: no such file (the robot: a built-in robot ({', '.join(builtin_robots())}), or an "
                          "existing .toml description, .urdf, .xacro or MuJoCo .xml file)")
    if not path.suffix == ".toml" or not path.is_file():
        raise ConfigError(f"unknown robot {text!r}: expected a built-in robot ({', '.join(builtin_robots())}), a .toml "
                          "description file, a .urdf, a .xacro or a MuJoCo .xml file")
    body = path.read_text(encoding="utf-8-sig")  # -sig: an editor's byte-order mark
    config = _config_robot(body, path)
    return config if config is not None else robot_from_toml_text(body, source=str(path), base=path.parent)


def _config_robot(text: str, path: Path) -> Robot | None:
    """The robot of an identification config (a TOML with an ``[identification]`` table), as ``dynid identify``
    reads it: ``robot = "..."`` relative to the config's folder, or a ``[robot]`` table; None for any other TOML."""
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError:
        return None  # the description parser says what is wrong
    if "identification" not in doc or "robot" not in doc:
        return None
    ref = doc["robot"]
    if isinstance(ref, dict):
        table = {**ref, "name": ref.get("name", Path(str(ref.get("urdf", path.stem))).stem)}
        return robot_from_document(table, f"{path}: robot", path.parent)
    if isinstance(ref, str):
        local = path.parent / ref
        return load_robot(ref if ref in builtin_robots() or not local.exists() else local)
    raise ConfigError(f"{path}: robot: expected a name, a file or a [robot] table, got {ref!r}")


def parse_angle(value, where: str) -> float:
    """A number, or an angle written like ``"pi/2"``, ``"-pi"``, ``"3*pi/4"``.

    Parameters
    ----------
    value : float or str
    where : str
        The field, named in errors.

    Returns
    -------
    float [rad]

    Raises
    ------
    ConfigError
        Neither a number nor such an expression.
    """
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return float(value)
    if isinstance(value, str):
        m = _ANGLE.match(value)
        if m:
            sign = -1.0 if m.group(1) == "-" else 1.0
            num = float(m.group(2)) if m.group(2) not in ("", ".") else 1.0
            den = float(m.group(3)) if m.group(3) else 1.0
            angle = sign * num * np.pi / den if den != 0 else np.inf
            if np.isfinite(angle):
                return angle
            raise ConfigError(f"{where}: expected a finite angle like 'pi/2', got {value!r}")
    raise ConfigError(f"{where}: expected a number or an angle like 'pi/2', got {value!r}")


URDF_DYNAMICS_NOTE = ("not taken as nominal values, which stay 0 (a robot file's joint friction and armature often "
                      "hold a simulator's setting, not the robot's); to take them, give {keys} in the joints' "
                      "[[robot.joints]] tables (a robot description's [[joints]])")
"""What dynid says of the drive terms a URDF's ``<dynamics>`` or an MJCF's joints state (:func:`robot_from_document`);
``{keys}`` is filled with the terms' fields."""

URDF_DRIVE_TERMS = ("Ia", "fc", "fv", "offset")
"""Drive terms of a robot given by its URDF alone: what a geared arm with current or torque sensing needs."""


def robot_from_toml_text(text: str, source: str, base: Path | None) -> Robot:
    """Parse a robot description (see the module docstring for the layout).

    Parameters
    ----------
    text : str
        TOML text.
    source : str
        The file, named in errors.
    base : Path or None
        Folder that relative paths (a URDF) are resolved against.

    Returns
    -------
    Robot
        The robot the text describes.

    Raises
    ------
    ConfigError
        A field with a wrong type or value.
    """
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{source}: invalid TOML ({exc})") from None
    return robot_from_document(doc, source, base)


def robot_from_urdf(path: str | Path, source: str | None = None, name: str | None = None, held=(),
                    xacro_args: dict | None = None) -> Robot:
    """A robot given by its URDF alone.

    Its chain, inertias and limits; drive terms :data:`URDF_DRIVE_TERMS`, gravity along -z, drive gains 1 (a log of
    joint torques).

    Parameters
    ----------
    path : str or Path
    source : str, optional
        Named in errors (the path by default).
    name : str, optional
        The robot's name (default: the file's stem).
    held : sequence of str
        Joints held fixed at 0 (:func:`dynid.model.urdf.joints_from_urdf`).
    xacro_args : dict of str to str, optional
        A xacro file's arguments (``name:=value``).

    Returns
    -------
    Robot

    Raises
    ------
    ConfigError
        An unreadable URDF or one dynid cannot model; ``xacro_args`` for a file that is not xacro.
    """
    path = Path(path)
    return robot_from_document({"convention": "urdf", "urdf": path.name, "drive_terms": list(URDF_DRIVE_TERMS),
                                "name": name or path.stem, **({"held": list(held)} if held else {}),
                                **({"xacro_args": dict(xacro_args)} if xacro_args else {})},
                               source or str(path), path.parent)  # the URDF relative to its folder


def robot_from_document(doc: dict, source: str, base: Path | None) -> Robot:
    """A robot from a parsed description (the module docstring's layout; a table of a config alike). With
    ``convention = "urdf"`` the ``[[joints]]`` tables are optional: the URDF gives the chain, inertias and limits.

    Parameters
    ----------
    doc : dict
        The parsed TOML (checked against :class:`dynid.model.description_types.RobotDescription`).
    source : str
        Named first in every message (the file).
    base : Path or None
        Folder relative paths (the URDF) start from.

    Returns
    -------
    Robot

    Raises
    ------
    ConfigError
        Names the file (``source``) and the field.
    """
    if not isinstance(doc, dict):
        raise ConfigError(f"{source}: expected a robot description table")
    joint_table, robot_table = description_types()
    d: Any = convert(doc, robot_table, source)
    name = d.name if d.name is not None else Path(source).stem
    convention = d.convention or ("urdf" if d.urdf is not None else "modified")
    # a description read from a URDF fits what the URDF alone (robot = "arm.urdf") fits: moving it into a [robot]
    # table (to hold a gripper, give gains) dropped the rotor inertia and the offset in silence
    default = URDF_DRIVE_TERMS if convention == "urdf" else DEFAULT_DRIVE_TERMS
    try:
        terms = check_terms(d.drive_terms if d.drive_terms is not None else default, f"{source}: drive_terms")
    except ValueError as exc:
        raise ConfigError(str(exc)) from None
    held, upath, urdf_model, rows = _urdf_and_rows(d, convention, base, source, joint_table)
    if not rows:
        raise ConfigError(f"{source}: expected one or more [[joints]] tables")
    n = len(rows)
    where = [f"{source}: joints[{i}]" for i in range(n)]
    for r, w in zip(rows, where):
        bad = sorted(t for t in TERMS if getattr(r, t) is not None and t not in terms)
        if bad:
            raise ConfigError(f"{w}: field(s) {bad} are drive terms the robot does not have (drive_terms = {list(terms)})")
    names = [r.name if r.name is not None else f"joint{i + 1}" for i, r in enumerate(rows)]
    for i, joint in enumerate(names):  # a branch's parent, a log's columns and the tables name joints: one each
        if joint in names[:i]:
            raise ConfigError(f"{where[i]}.name: {joint!r} names joints[{names.index(joint)}] too: expected each joint's "
                              "own name")
    joints, inertial, (tool_r, tool_t), dh, urdf_lim, links = _chain(d, rows, where, names, convention=convention,
                                                                     urdf=(upath, urdf_model), held=held, source=source)
    terms, mask, drive, gains, transmission, stated = _drives(d, rows, where, terms, urdf=(upath, urdf_lim),
                                                              source=source)
    limits = _limits(rows, where, urdf_lim)
    gravity, inertial, stated = _gravity_and_payload(d, doc, inertial, stated, convention=convention, dh=dh,
                                                     urdf=(upath, urdf_lim), source=source)
    link_names = links if convention == "urdf" else names  # a URDF's own link names; a DH table's joint names
    problems = _nominal_problems(inertial, link_names, source)
    return Robot(
        name=str(name), joints=joints, gravity=gravity, inertial=inertial, drive_terms=terms, drive=drive,
        drive_gains=gains, limits=limits, tool_rotation=tool_r, tool_translation=tool_t,
        notes=d.notes, transmission=transmission, drive_mask=mask, nominal_problems=problems,
        stribeck_velocity=np.array([float(_or(r.stribeck_velocity, DEFAULT_STRIBECK_VELOCITY)) for r in rows]),
        prior_sigma=_prior_sigma(rows, terms), held=tuple(held), nominal_notes=stated)


def _urdf_and_rows(d, convention: str, base, source: str, joint_table):
    """:func:`robot_from_document`'s held joints, and for a URDF convention the file read (its path and Pinocchio's
    model), with one joint row per joint of its chain where the table gives none."""
    urdf_model = None
    upath: Any = None
    rows = d.joints
    held = _held(d.held, convention, source, d.xacro_args)
    if convention == "urdf":
        upath, urdf_model = _read_urdf(d.urdf, base, source, held, d.xacro_args)
        if rows is None:
            rows = [joint_table() for _ in urdf_model[0]]
    return held, upath, urdf_model, rows


def _gravity_and_payload(d, doc: dict, inertial: np.ndarray, stated: tuple, *, convention: str, dh, urdf: tuple,
                         source: str) -> tuple[np.ndarray, np.ndarray, tuple]:
    """:func:`robot_from_document`'s gravity (a URDF's MJCF-style gravity option not taken, said) and the last link's
    inertial values with the table's payload added."""
    upath, urdf_lim = urdf
    gravity = np.asarray(d.gravity, dtype=float)
    if urdf_lim is not None and "gravity" in urdf_lim and "gravity" not in doc and not np.allclose(urdf_lim["gravity"], gravity):
        stated += (f"{source}: {upath.name}'s <option gravity> is {_vector(urdf_lim['gravity'])} m/s², not taken: the robot's "
                   f"gravity is {_vector(gravity)} (gravity = [x, y, z] in the [robot] table, or the description, sets it)",)
    if d.payload is not None:
        inertial = inertial.copy()
        inertial[-1] = inertial[-1] + _payload(d.payload, f"{source}: payload", convention, *dh)
    return gravity, inertial, stated


def _chain(d, rows, where: list[str], names: list[str], *, convention: str, urdf: tuple, held: dict, source: str):
    """The joints, their nominal inertial parameters and the tool frame, from the URDF (with its joints' own values:
    limits, friction, gravity) or from a DH table (its α, a, d, which a payload's frame needs).

    Returns ``(joints, inertial, (tool_rotation, tool_translation), (alpha, a, d), urdf_values, link_names)``.
    """
    tool_t = np.asarray(d.tool.translation, dtype=float)
    tool_r = np.eye(3)
    alpha = a = dd = None
    urdf_lim = None
    links: tuple[str, ...] = ()
    if convention == "urdf":
        upath, (joints, inertial, _, links) = urdf
        from .urdf import urdf_joint_values

        urdf_lim = urdf_joint_values(upath, held)
        if len(joints) != len(rows):
            raise ConfigError(f"{source}: {upath} has {len(joints)} revolute joints but {len(rows)} [[joints]] tables are "
                              "given")
        inertial = _merged_inertials(rows, where, inertial, upath)
    else:
        alpha = [parse_angle(_or(r.alpha, 0.0), f"{w}.alpha") for r, w in zip(rows, where)]
        a = [float(_or(r.a, 0.0)) for r in rows]
        dd = [float(_or(r.d, 0.0)) for r in rows]
        off = [parse_angle(_or(r.theta_offset, 0.0), f"{w}.theta_offset") for r, w in zip(rows, where)]
        prismatic = [r.type == "prismatic" for r in rows]
        if convention == "modified":
            joints = joints_from_modified_dh(alpha, a, dd, off, names, prismatic=prismatic, **_branches(rows, where, names))
        else:
            for r, w in zip(rows, where):
                given = [k for k in ("parent", "gamma", "b") if getattr(r, k) is not None]
                if given:
                    raise ConfigError(f"{w}: {', '.join(given)} given, but a branch is placed in modified DH only: "
                                      "write the table with convention = \"modified\" (Khalil-Kleinfinger's gamma, b)")
            joints, tool_r0, tool_t0 = joints_from_standard_dh(alpha, a, dd, off, names, prismatic=prismatic)
            tool_t = tool_t0 + tool_r0 @ tool_t
            tool_r = tool_r0
        inertial = _dh_inertials(rows, where, convention, alpha, a, dd)
        joints = _followers(joints, rows, where, names)
    return joints, inertial, (tool_r, tool_t), (alpha, a, dd), urdf_lim, links


def _followers(joints, rows, where: list[str], names: list[str]) -> tuple:
    """A DH table's joints with their ``mimic = { joint = ..., multiplier = ..., offset = ... }``
    (:attr:`dynid.model.robot.Joint.mimic`), the joint followed named in the table."""
    out = list(joints)
    for i, (r, w) in enumerate(zip(rows, where)):
        if r.mimic is None:
            continue
        if r.mimic.joint not in names or r.mimic.joint == names[i]:
            raise ConfigError(f"{w}.mimic.joint: expected the name of another joint of the table ({', '.join(names)}), "
                              f"got {r.mimic.joint!r}")
        out[i] = replace(out[i], mimic=(names.index(r.mimic.joint), float(r.mimic.multiplier), float(r.mimic.offset)))
    return tuple(out)


def _branches(rows, where: list[str], names: list[str]) -> dict:
    """A modified-DH table's antecedents (``parent``, a joint named before it or ``"base"``) and Khalil-Kleinfinger's
    gamma and b, as :func:`dynid.model.dh.joints_from_modified_dh` takes them."""
    parents: list = []
    for i, (r, w) in enumerate(zip(rows, where)):
        if r.parent is None:
            parents.append(None)
        elif r.parent in names[:i]:
            parents.append(names.index(r.parent))
        elif r.parent == "base":
            parents.append(-1)
        else:
            raise ConfigError(f"{w}.parent: expected \"base\" or the name of a joint before it ({', '.join(names[:i]) or 'none'}"
                              f"), got {r.parent!r}")
    gamma = [parse_angle(_or(r.gamma, 0.0), f"{w}.gamma") for r, w in zip(rows, where)]
    b = [float(_or(r.b, 0.0)) for r in rows]
    for v, w in zip(b, where):
        if not np.isfinite(v):
            raise ConfigError(f"{w}.b: expected a finite offset (m), got {v}")
    return {"parents": parents, "gamma": gamma, "b": b}


def _drives(d, rows, where: list[str], terms: tuple[str, ...], *, urdf: tuple, source: str):
    """Each joint's drive: its friction terms (and those the URDF states), drive gain, transmission with the encoders'
    position offsets.

    Returns ``(terms, mask, drive, gains, transmission, notes)``: the notes say the URDF's friction values taken.
    """
    upath, urdf_lim = urdf
    terms, mask, drive = _drive_terms(rows, where, terms, source)
    stated = () if urdf_lim is None else _urdf_friction(rows, terms, urdf_lim, upath, source)
    offsets = np.array([parse_angle(_or(r.position_offset, 0.0), f"{w}.position_offset") for r, w in zip(rows, where)])
    transmission = _transmission(d.transmission, len(rows), offsets, source)
    gains = np.array([float(_or(r.drive_gain, 1.0)) for r in rows])
    bad = ~(np.isfinite(gains) & (gains > 0))  # NaN compares false: a NaN gain passed and gave "model ready"
    if np.any(bad):
        i = int(np.argmax(bad))
        raise ConfigError(f"{where[i]}.drive_gain: expected a finite, positive gain (N·m/A), got {gains[i]}")
    return terms, mask, drive, gains, transmission, stated


def _nominal_problems(inertial: np.ndarray, link_names, source: str) -> tuple[str, ...]:
    """A line per physical-consistency rule each link's nominal values break; one line for a description without
    inertias (a kinematic URDF), not one a link."""
    if inertial.shape[0] > 1 and not np.any(inertial):
        return (f"{source}: no link has a nominal mass or inertia (a URDF without <inertial>, a kinematic "
                "description): there is no nominal model to compare the estimate with, nor a prior for what the "
                "log does not determine (zero)",)
    return tuple(f"{source}: link {i + 1} ({link_names[i]}): nominal {p}" for i in range(inertial.shape[0])
                 for p in physical_problems(inertial[i]))


def _held(held, convention: str, source: str, xacro_args=None) -> dict:
    """``held`` as joint name -> position (a list holds each at 0); only a URDF has joints to hold (and only a robot
    file has ``xacro_args``)."""
    if xacro_args and convention != "urdf":
        raise ConfigError(f"{source}: xacro_args are a xacro file's arguments, but this description reads no robot file "
                          "(give urdf = \"arm.urdf.xacro\")")
    if held is None:
        return {}
    if convention != "urdf":
        raise ConfigError(f"{source}: held names joints of a URDF to hold fixed, but this description has no URDF "
                          "(leave those joints out of [[joints]])")
    return dict.fromkeys(held, 0.0) if isinstance(held, list) else {str(k): float(v) for k, v in held.items()}


def _read_urdf(urdf: str | None, base: Path | None, source: str, held=None, xacro_args: dict | None = None):
    """The URDF a description names (relative to ``base``; a xacro file expanded with ``xacro_args``) and its chain
    (:func:`dynid.model.urdf.joints_from_urdf`)."""
    from .urdf import expand_xacro, is_xacro, joints_from_urdf

    if urdf is None:
        raise ConfigError(f"{source}: convention 'urdf' needs a field 'urdf' with the file path")
    upath = Path(urdf)
    if not upath.is_absolute() and base is not None:
        upath = base / upath
    _check_xacro_args(xacro_args, upath, f"{source}: xacro_args")
    if is_xacro(upath):
        upath = expand_xacro(upath, xacro_args)
    return upath, joints_from_urdf(upath, held)


def _check_xacro_args(xacro_args: dict | None, path: Path, where: str) -> None:
    """Refuse arguments for a robot file that is not a xacro file (they would be ignored)."""
    from .urdf import is_xacro

    if xacro_args and not is_xacro(path):
        raise ConfigError(f"{where}: xacro arguments {sorted(xacro_args)} given, but {path.name} is not a xacro file "
                          "(.xacro): nothing would read them")


def _dh_inertials(rows, where, convention: str, alpha, a, dd) -> np.ndarray:
    """(n, 10) inertial parameters of a DH table's ``[[joints]]`` (mass, com, inertia each required), in dynid's link
    frames (a standard-DH table gives them in DH frame i)."""
    inertial = np.zeros((len(rows), 10))
    for i, (r, w) in enumerate(zip(rows, where)):
        for key in ("mass", "com", "inertia"):
            if getattr(r, key) is None:
                raise ConfigError(f"{w}: missing field {key!r}")
        mass, com = float(r.mass), np.asarray(r.com, dtype=float)
        ixx, iyy, izz, ixy, ixz, iyz = r.inertia
        inertia = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        if not np.isfinite(mass) or mass < 0:
            raise ConfigError(f"{w}.mass: expected a mass >= 0 (kg), got {mass}")
        phi = inertial_from_physical(mass, com, inertia)
        if convention == "standard":  # given in DH frame i: express in dynid's link frame
            rr, pp = standard_dh_link_offset(alpha[i], a[i], dd[i])
            phi = transform_inertial(phi, rr, pp)
        inertial[i] = phi
    return inertial


def _drive_terms(rows, where, terms: tuple, source: str) -> tuple[tuple, np.ndarray, np.ndarray]:
    """The robot's drive terms (with the counterbalance's where a joint has one), which joint has which (a joint's
    own ``drive_terms``), and their nominal values."""
    n = len(rows)
    balanced = [j for j, r in enumerate(rows) if r.counterbalance]
    if balanced:
        terms = check_terms(tuple(terms) + COUNTERBALANCE_TERMS, source)
    mask = np.ones((n, len(terms)), dtype=bool)
    for j in range(n):  # the counterbalance terms belong to the joints that have one
        mask[j] = [t not in COUNTERBALANCE_TERMS or j in balanced for t in terms]
    for i, (r, w) in enumerate(zip(rows, where)):
        if r.drive_terms is not None:
            if any(t not in terms for t in r.drive_terms):
                raise ConfigError(f"{w}.drive_terms: expected a list drawn from the robot's drive terms {list(terms)}, "
                                  f"got {r.drive_terms!r}")
            mask[i] = [t in r.drive_terms or (t in COUNTERBALANCE_TERMS and i in balanced) for t in terms]
    drive = np.array([[float(_value(getattr(r, t))) for t in terms] for r in rows]).reshape(n, len(terms))
    bad = np.argwhere(~np.isfinite(drive))  # a NaN nominal value became a NaN prior that named no field
    if bad.size:
        i, k = bad[0]
        raise ConfigError(f"{where[i]}.{terms[k]}: expected a finite nominal value, got {drive[i, k]}")
    return terms, mask, drive * mask


def _value(given) -> float:
    """A drive term's nominal value as a ``[[joints]]`` table gives it: a number, ``{ value, sigma }``, or nothing (0)."""
    return 0.0 if given is None else float(getattr(given, "value", given))


def _prior_sigma(rows, terms: tuple) -> tuple[tuple[str, float], ...]:
    """``(parameter name, σ)`` of every drive term a ``[[joints]]`` table gives as ``{ value, sigma }``."""
    return tuple((f"{t}{j + 1}", float(getattr(r, t).sigma)) for j, r in enumerate(rows) for t in terms
                 if hasattr(getattr(r, t, None), "sigma"))


def _vector(v) -> str:
    return "(" + ", ".join(f"{float(x):g}" for x in v) + ")"


def _urdf_friction(rows, terms: tuple, stated: dict, urdf: Path, source: str) -> tuple[str, ...]:
    """A line naming the joints whose URDF ``<dynamics>`` or MJCF joint (``stated``:
    :func:`dynid.model.urdf.urdf_joint_values`) states a rotor inertia, damping or friction that no ``[[joints]]``
    table's ``Ia``/``fv``/``fc`` gives: they are not taken as nominal values (:data:`URDF_DYNAMICS_NOTE`); none where
    the file states only zeros (most vendor files) or the robot has none of those terms."""
    from .urdf import is_mjcf

    mjcf = is_mjcf(urdf)  # the file's root element, not its name: a URDF may be called arm.xml
    parts, keys = [], []
    for term, value, attribute in (("Ia", "armature", "armature"), ("fv", "damping", "damping"),
                                   ("fc", "friction", "frictionloss" if mjcf else "friction")):
        joints = [j for j, r in enumerate(rows) if stated[value][j] != 0 and getattr(r, term) is None]
        if term in terms and joints:
            by_value: dict[float, list[int]] = {}
            for j in joints:
                by_value.setdefault(float(stated[value][j]), []).append(j + 1)
            parts.append(f"{attribute} " + ", ".join(f"{v:g} (J{', J'.join(map(str, js))})" for v, js in by_value.items()))
            keys.append(f"{term} =")
    if not parts:
        return ()
    where = f"{urdf.name}'s joints" if mjcf else f"{urdf.name}'s <dynamics>"
    return (f"{source}: {where} state {'; '.join(parts)}: {URDF_DYNAMICS_NOTE.format(keys=' and '.join(keys))}",)


def _limits(rows, where, urdf_lim) -> Limits:
    """Each joint's limits: its table's, else the URDF's (``urdf_lim``), else none (±inf); checked."""
    inf = np.inf
    default = (lambda k, j, dflt: dflt) if urdf_lim is None else (lambda k, j, dflt: urdf_lim[k][j])  # noqa: E731
    lim = {k: np.array([float(_or(getattr(r, k), default(k, j, dflt))) for j, r in enumerate(rows)])
           for k, dflt in (("dq_max", inf), ("ddq_max", inf), ("tau_max", inf))}
    for k, dflt in (("q_min", -inf), ("q_max", inf)):  # angles may be written like "-2*pi"
        lim[k] = np.array([parse_angle(_or(getattr(r, k), default(k, j, dflt)), f"{w}.{k}") for j, (r, w) in enumerate(zip(rows, where))])
    for i in range(len(rows)):
        if not lim["q_min"][i] < lim["q_max"][i]:
            raise ConfigError(f"{where[i]}: expected q_min < q_max, got {lim['q_min'][i]} >= {lim['q_max'][i]}")
        for k in ("dq_max", "ddq_max", "tau_max"):
            if not lim[k][i] > 0:
                raise ConfigError(f"{where[i]}.{k}: expected a positive limit, got {lim[k][i]}")
    return Limits(**lim)


def _merged_inertials(rows, where, inertial: np.ndarray, urdf: Path) -> np.ndarray:
    """A URDF's link inertials with those the ``[[joints]]`` tables give: a table's ``mass``, ``com`` and ``inertia``
    (all three, in the URDF link's frame, the inertia about the centre of mass, as a URDF writes them) replace that
    link's; the DH geometry fields are refused (the URDF gives the chain)."""
    out = inertial.copy()
    for i, (r, w) in enumerate(zip(rows, where)):
        geometry = [k for k in ("alpha", "a", "d", "theta_offset", "type", "parent", "gamma", "b", "mimic") if getattr(r, k) is not None]
        if geometry:
            raise ConfigError(f"{w}: {', '.join(geometry)} describe a DH chain, but the chain is {urdf.name}'s: leave "
                              "them out (the URDF's joints give the geometry)")
        given = [k for k in ("mass", "com", "inertia") if getattr(r, k) is not None]
        if not given:
            continue
        if len(given) < 3:
            missing = [k for k in ("mass", "com", "inertia") if k not in given]
            raise ConfigError(f"{w}: {', '.join(given)} without {', '.join(missing)}: give mass, com and inertia "
                              f"together to replace {urdf.name}'s inertial of this link")
        mass = float(r.mass)
        if not np.isfinite(mass) or mass < 0:
            raise ConfigError(f"{w}.mass: expected a mass >= 0 (kg), got {mass}")
        for key in ("com", "inertia"):
            if not np.all(np.isfinite(np.asarray(getattr(r, key), dtype=float))):
                raise ConfigError(f"{w}.{key}: expected finite numbers, got {list(getattr(r, key))}")
        ixx, iyy, izz, ixy, ixz, iyz = r.inertia
        out[i] = inertial_from_physical(mass, np.asarray(r.com, dtype=float),
                                        np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]]))
    return out


def _or(value, default):
    """``value`` unless it is None."""
    return default if value is None else value


def _payload(p: PayloadTable, where: str, convention: str, alpha, a, d) -> np.ndarray:
    """The payload's inertial parameters in the last link's frame (eq. 5 order)."""
    com = np.asarray(p.com, dtype=float)
    if not np.all(np.isfinite(com)) or np.abs(com).max() > 10:
        raise ConfigError(f"{where}.com: expected a centre of mass within 10 m of the last link's origin, got {com.tolist()}")
    ixx, iyy, izz, ixy, ixz, iyz = p.inertia
    phi = inertial_from_physical(float(p.mass), com, np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]]))
    if convention == "standard":  # given in DH frame n: in dynid's link frame
        rr, pp = standard_dh_link_offset(alpha[-1], a[-1], d[-1])
        phi = transform_inertial(phi, rr, pp)
    return phi


def _transmission(t: TransmissionTable, n: int, offsets: np.ndarray, source: str) -> Transmission:
    where = f"{source}: transmission"
    ratios = np.ones(n) if t.gear_ratios is None else np.asarray(t.gear_ratios, dtype=float)
    if ratios.shape != (n,):
        raise ConfigError(f"{where}.gear_ratios: expected a list of {n} numbers, got {t.gear_ratios!r}")
    if np.any(ratios == 0):
        raise ConfigError(f"{where}.gear_ratios: expected non-zero ratios, got {ratios.tolist()}")
    r = np.diag(ratios)
    for c, entry in enumerate(t.coupling):
        if not (entry.motor <= n and entry.joint <= n) or entry.motor == entry.joint:
            raise ConfigError(f"{where}.coupling[{c}]: expected two different joint numbers in 1..{n}, got motor {entry.motor}, "
                              f"joint {entry.joint}")
        r[entry.motor - 1, entry.joint - 1] = entry.ratio
    terms = t.coupled_terms if t.coupled_terms is not None else (list(COUPLING_TERMS) if t.coupling else [])
    if t.coupled_values is None:
        return Transmission(r, offsets, tuple(x for x in COUPLING_TERMS if x in terms))
    motors, given = Transmission.coupled_motors_of(r), [list(row) for row in t.coupled_values]
    if len(given) != len(motors) or any(len(row) != len(terms) for row in given) or not np.all(np.isfinite(given)):
        raise ConfigError(f"{where}.coupled_values: expected {len(motors)} list(s) (one per coupled motor) of {len(terms)} "
                          f"finite numbers ({', '.join(terms)}), got {t.coupled_values!r}")
    named = [str(x) for x in terms]
    order = [named.index(x) for x in COUPLING_TERMS if x in named]  # the values in the order dynid keeps the terms
    return Transmission(r, offsets, tuple(x for x in COUPLING_TERMS if x in terms), np.asarray(given, dtype=float)[:, order])

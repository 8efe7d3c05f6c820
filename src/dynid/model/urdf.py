"""Serial chains of revolute and prismatic joints from URDF files, parsed by Pinocchio (a MuJoCo model, MJCF: :mod:`dynid.model.mjcf`)."""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from xml.parsers import expat

import numpy as np

from ..exceptions import ConfigError
from .mjcf import joints_from_mjcf, mjcf_joint_values, mjcf_joints_to_hold
from .robot import Joint
from .robot_files import HELD_HINT, check_xml, is_mjcf, joints_off_arm
from .xacro_expansion import expand_xacro_text

_AXES = {"RX": (1.0, 0.0, 0.0), "RY": (0.0, 1.0, 0.0), "RZ": (0.0, 0.0, 1.0),
         "PX": (1.0, 0.0, 0.0), "PY": (0.0, 1.0, 0.0), "PZ": (0.0, 0.0, 1.0)}
URDF_JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")




_INERTIAL_VALUES = {"mass": ("value",), "inertia": ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"), "origin": ("xyz", "rpy")}
"""The attributes of a link's elements that :func:`check_urdf_text` requires finite (Pinocchio reads a NaN mass as
a massless link)."""



def _said(value, quote: str = "'") -> str:
    """A value read from a file, for a message: quoted, and cut at 40 characters (a value expanded from a xacro
    file may be a whole file's text)."""
    text = str(value)
    return quote + (text if len(text) <= 40 else text[:37] + "...") + quote


def check_urdf_text(path: Path, held=()) -> None:
    """Refuse, with the line number, what Pinocchio's parser (urdfdom) would report without one.

    Malformed XML, joints of unknown type, a joint axis that is no direction (``xyz="0 0 0"``), a ``<mimic>`` without
    the joint it follows or with a multiplier or offset that is no finite number (or a multiplier of 0), and a link's
    mass, inertia or origin that is not finite (NaN was read as a massless link).

    Parameters
    ----------
    path : Path
    held : collection of str
        Joints held fixed (:func:`joints_from_urdf`): their ``<mimic>`` is not read.

    Raises
    ------
    ConfigError
    """
    parser = expat.ParserCreate()
    problems = []
    joint: list = []  # the joint element being read (name, type)
    link: list = []  # the link element being read (name)

    def start(name, attrs):
        if name == "link":
            link[:] = [attrs.get("name", "?")]
        elif link and name in _INERTIAL_VALUES:
            for key in _INERTIAL_VALUES[name]:
                text = attrs.get(key)
                try:
                    finite = text is None or all(np.isfinite([float(v) for v in text.split()]))
                except ValueError:
                    finite = False
                if not finite:
                    problems.append(f"line {parser.CurrentLineNumber}: link {_said(link[0])}: <{name} {key}={_said(text, chr(34))}>, "
                                    "expected finite numbers (a link's inertial values are read, never guessed)")
        if name == "joint" and "type" in attrs:
            joint[:] = [attrs.get("name", "?"), attrs["type"]]
            if attrs["type"] not in URDF_JOINT_TYPES:
                problems.append(f"line {parser.CurrentLineNumber}: joint {_said(attrs.get('name', '?'))} has type {_said(attrs['type'])}, "
                                f"expected one of {', '.join(URDF_JOINT_TYPES)}")
        elif name == "axis" and joint and joint[1] in ("revolute", "continuous", "prismatic"):
            try:
                xyz = [float(v) for v in attrs.get("xyz", "1 0 0").split()]
            except ValueError:
                xyz = []
            if len(xyz) != 3 or not all(np.isfinite(xyz)) or float(np.linalg.norm(xyz)) < 1e-9:
                problems.append(f"line {parser.CurrentLineNumber}: joint {_said(joint[0])} has axis xyz={_said(attrs.get('xyz'), chr(34))}, "
                                "expected three numbers not all zero (the direction it turns about)")
        elif name == "mimic" and joint and joint[1] != "fixed" and joint[0] not in held:
            try:
                values = [float(attrs.get(key, default)) for key, default in (("multiplier", "1"), ("offset", "0"))]
            except ValueError:
                values = []
            if len(values) != 2 or not all(np.isfinite(values)) or values[0] == 0 or "joint" not in attrs:
                given = " ".join(f"{k}={_said(v, chr(34))}" for k, v in attrs.items())
                problems.append(f"line {parser.CurrentLineNumber}: joint {_said(joint[0])} has <mimic {given}>: expected "
                                "the joint it follows (joint=), a finite non-zero multiplier and a finite offset")

    def end(name):
        if name == "joint":
            joint.clear()
        elif name == "link":
            link.clear()

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    check_xml(path, parser)
    if problems:
        raise ConfigError(f"{path}: {problems[0]}")


@contextlib.contextmanager
def _silenced_stderr(lines: list):
    """Keep what C++ code (urdfdom) prints on file descriptor 2 out of the terminal: it goes into ``lines``."""
    sys.stderr.flush()
    saved = os.dup(2)
    with tempfile.TemporaryFile() as tmp:
        os.dup2(tmp.fileno(), 2)
        try:
            yield
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            tmp.seek(0)
            lines.extend(line for line in tmp.read().decode("utf-8", "replace").splitlines() if line.strip())


def inertial_from_pinocchio(inertia) -> np.ndarray:
    """dynid's ten inertial parameters (eq. 5 order) from a ``pinocchio.Inertia``.

    Pinocchio orders them ``[m, mc_x, mc_y, mc_z, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]``.

    Parameters
    ----------
    inertia : pinocchio.Inertia

    Returns
    -------
    (10,) ndarray
    """
    p = np.asarray(inertia.toDynamicParameters()).ravel()
    return np.array([p[4], p[5], p[7], p[6], p[8], p[9], p[1], p[2], p[3], p[0]])


def pinocchio_from_inertial(phi: np.ndarray) -> np.ndarray:
    """Pinocchio's dynamic-parameter order from dynid's ten inertial parameters.

    Parameters
    ----------
    phi : (10,) array
        eq. 5 order.

    Returns
    -------
    (10,) ndarray
    """
    xx, xy, xz, yy, yz, zz, mx, my, mz, m = phi
    return np.array([m, mx, my, mz, xx, xy, yy, xz, yz, zz])


def joints_from_urdf(path: str | Path,
                     held=None) -> tuple[tuple[Joint, ...], np.ndarray, tuple[str, ...], tuple[str, ...]]:
    """Joints and link inertial parameters of a URDF's revolute and prismatic joints: a serial chain, or a tree (two
    arms on a torso), each joint then naming the joint that carries it (:attr:`dynid.model.robot.Joint.parent`).

    Fixed joints are merged by Pinocchio into the parent link, and so are ``held`` joints (a gripper's fingers, mimic
    joints: locked at their position by Pinocchio's ``buildReducedModel``). Continuous joints (unbounded revolute)
    are revolute joints without position limits: dynid's joint angle is their angle.

    Parameters
    ----------
    path : str or Path
    held : dict, optional
        Joint name -> position [rad or m] at which it is held fixed.

    Returns
    -------
    joints : tuple of Joint
    inertial : (n_dof, 10) array
        Inertial parameters of each link in its joint frame (eq. 5 order).
    names : tuple of str
        The joints' names.
    links : tuple of str
        The name of each joint's child link in the URDF (the link its inertial belongs to).

    Raises
    ------
    ConfigError
        If the file cannot be parsed, a held joint is not in it, or a joint is neither revolute nor prismatic.
    """
    import pinocchio as pin

    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"{path}: URDF file not found")
    if is_mjcf(path):  # a MuJoCo model: as MuJoCo compiles it
        return joints_from_mjcf(path, held)
    held = dict(held or {})
    check_urdf_text(path, held)
    model = _pinocchio_model(path, held)
    mimic = mimic_joints(path)
    joints, inertial = [], []
    for j in range(1, model.njoints):
        jm = model.joints[j]
        short = jm.shortname()
        prismatic = short.startswith("JointModelP")
        if short[-2:] in _AXES and short in (f"JointModel{short[-2:]}",):
            axis = np.array(_AXES[short[-2:]])  # revolute or prismatic about/along x, y or z
        elif short.startswith("JointModelRUB") and "R" + short[-1] in _AXES:  # continuous joint about x, y or z
            axis = np.array(_AXES["R" + short[-1]])
        elif short in ("JointModelRevoluteUnaligned", "JointModelPrismaticUnaligned"):
            axis = np.asarray(jm.extract().axis, dtype=float).ravel()
        elif short == "JointModelRevoluteUnboundedUnaligned":  # continuous, unaligned: the axis is its motion subspace
            data = model.createData()
            pin.forwardKinematics(model, data, pin.neutral(model))
            axis = np.asarray(data.joints[j].S, dtype=float).ravel()[3:]
        else:
            raise ConfigError(f"{path}: joint {model.names[j]!r} is {short}, expected a revolute or prismatic joint; "
                              + HELD_HINT.format(names=f'"{model.names[j]}"'))
        placement = model.jointPlacements[j]
        parent = model.parents[j] - 1  # a branch (two arms on a torso): the joint that carries it, -1 the base
        joints.append(Joint(model.names[j], np.array(placement.rotation), np.array(placement.translation), axis,
                            prismatic, None if parent == j - 2 else int(parent),
                            _followed(path, model, model.names[j], mimic.get(model.names[j]), held)))
        inertial.append(inertial_from_pinocchio(model.inertias[j]))
    if not joints:
        raise ConfigError(f"{path}: expected at least one revolute or prismatic joint, found none")
    links = tuple(next((f.name for f in model.frames if f.type == pin.FrameType.BODY and f.parentJoint == j),
                       model.names[j]) for j in range(1, model.njoints))
    return tuple(joints), np.array(inertial), tuple(model.names[1:]), links


def _pinocchio_model(path: Path, held: dict):
    """Pinocchio's model of a URDF, its ``held`` joints locked at their positions (their links merged into the
    parent's)."""
    import pinocchio as pin

    printed: list[str] = []
    try:
        with _silenced_stderr(printed):
            model = pin.buildModelFromUrdf(str(path))
    except Exception as exc:  # pinocchio raises plain RuntimeError/ValueError; urdfdom prints its reason
        reason = printed[0] if printed else (str(exc).splitlines()[0] if str(exc) else type(exc).__name__)
        raise ConfigError(f"{path}: cannot parse URDF ({' '.join(reason.split())})") from None
    if not held:
        return model
    q = pin.neutral(model)
    ids = []
    for name, value in held.items():
        if not model.existJointName(name):
            raise ConfigError(f"{path}: held names joint {name!r}, which the URDF's moving joints do not include "
                              f"({', '.join(model.names[1:])})")
        j = model.getJointId(name)
        i, nq = model.joints[j].idx_q, model.joints[j].nq
        q[i:i + nq] = [np.cos(value), np.sin(value)] if nq == 2 else [value] * nq  # a continuous joint: cos, sin
        ids.append(j)
    return pin.buildReducedModel(model, ids, q)


def joints_to_hold(path: str | Path, logged: Callable[[tuple[str, ...]], set[str]] | None = None) -> tuple[str, ...]:
    """The URDF's moving joints that are not its arm, which ``dynid init`` holds fixed: every joint off the longest
    chain of revolute joints from the base, none mimicking another at its tip (a gripper's fingers, prismatic or on a branch; a
    camera's pan joint on a branch of its own, wherever Pinocchio's depth-first order puts it), or off the chain that
    holds most of the joints the log names (:func:`dynid.model.robot_files.arm_chain`); where the log names joints on
    several branches' chains (both arms of a two-arm robot), every joint but those (the robot is then their tree; a
    gripper's fingers stay held: :func:`dynid.model.robot_files.joints_off_arm`).

    Parameters
    ----------
    path : str or Path
    logged : callable, optional
        ``logged(names)`` -> the names among the file's moving joints that the log names.

    Returns
    -------
    tuple of str
        Joint names (empty for a URDF that is one serial revolute chain).

    Raises
    ------
    ConfigError
        If the file cannot be parsed.
    """
    path = Path(path)
    if is_mjcf(path):
        return mjcf_joints_to_hold(path, logged)
    mimic = mimic_joints(path)
    check_urdf_text(path, held=mimic)
    model = _pinocchio_model(path, {})
    names, parents, revolute, sliding = _tree(model, mimic)
    named = set() if logged is None else logged(tuple(names[k] for k in parents))
    return tuple(names[k] for k in joints_off_arm(parents, revolute, sliding, {k for k in parents if names[k] in named}))


def _tree(model, mimic=frozenset()) -> tuple[dict[int, str], dict[int, int], set[int], set[int]]:
    """Pinocchio's moving joints as :func:`dynid.model.robot_files.arm_chain` reads them (numbered from 0; a
    mimic joint is the arm's only where it carries a joint that mimics none, as a palletiser's passive joint carries
    its wrist, not at a tip, as a gripper's second finger): names, parents, the revolute joints and the prismatic
    ones."""
    names = {j - 1: model.names[j] for j in range(1, model.njoints)}
    parents = {j - 1: model.parents[j] - 1 for j in range(1, model.njoints)}
    carrying = set()  # the joints that carry a joint that mimics none
    for k in parents:
        if names[k] not in mimic:
            j = parents[k]
            while j >= 0:
                carrying.add(j)
                j = parents[j]
    kinds = {j - 1: model.joints[j].shortname() for j in range(1, model.njoints)
             if model.names[j] not in mimic or j - 1 in carrying}
    revolute = {k for k, short in kinds.items() if short.startswith("JointModelR")}
    sliding = {k for k, short in kinds.items() if short.startswith("JointModelP")}
    return names, parents, revolute, sliding


def _followed(path: Path, model, name: str, mimic: tuple | None, held: dict) -> tuple[int, float, float] | None:
    """A joint's :attr:`Joint.mimic` from its ``<mimic>`` (``(joint followed, multiplier, offset)`` as read), the joint
    it follows numbered among the model's moving joints; refused where that joint is held, mimics another, or is
    not a moving joint of the file."""
    if mimic is None:
        return None
    followed, multiplier, offset = mimic
    if followed in held:
        raise ConfigError(f"{path}: joint {name!r} mimics joint {followed!r}, which the config holds fixed: hold "
                          f"{name!r} too (held = [...]) or neither")
    if not model.existJointName(followed) or followed == name:
        raise ConfigError(f"{path}: joint {name!r} mimics joint {followed!r}, which is not another moving joint of the file")
    return model.getJointId(followed) - 1, multiplier, offset


def mimic_joints(path: Path) -> dict[str, tuple[str, float, float]]:
    """A URDF's joints that have a ``<mimic>`` (:attr:`dynid.model.robot.Joint.mimic`).

    Parameters
    ----------
    path : Path
        The URDF (checked to be XML first).

    Returns
    -------
    dict
        Joint name -> (the joint it follows, multiplier, offset) as written; :func:`check_urdf_text` refuses values
        that are no numbers, read here as 1 and 0.

    Raises
    ------
    ConfigError
        A file that is not XML (:func:`check_urdf_text` names the line).
    """
    parser = expat.ParserCreate()
    joint: list[str] = []
    out: dict[str, tuple[str, float, float]] = {}

    def number(text: str | None, default: float) -> float:
        try:
            return float(text) if text is not None else default
        except ValueError:
            return default

    def start(name, attrs):
        if name == "joint" and "type" in attrs:
            joint[:] = [attrs.get("name", "?")]
        elif name == "mimic" and joint:
            out[joint[0]] = (attrs.get("joint", "?"), number(attrs.get("multiplier"), 1.0), number(attrs.get("offset"), 0.0))

    parser.StartElementHandler = start
    try:
        parser.Parse(path.read_bytes(), True)
    except expat.ExpatError:  # check_urdf_text says where
        check_urdf_text(path)
    return out


def urdf_joint_values(path: str | Path, held=None) -> dict:
    """What a URDF states of each revolute joint beside the chain: its limits and its ``<dynamics>`` (Pinocchio's
    reading).

    Parameters
    ----------
    path : str or Path
    held : dict, optional
        Joints held fixed (:func:`joints_from_urdf`): not among the joints.

    Returns
    -------
    dict
        ``q_min, q_max`` [rad], ``dq_max`` [rad/s], ``tau_max`` [N·m], ``ddq_max`` (inf: a URDF has none): a limit
        the URDF leaves out (or 0) is ``±inf``; ``armature`` (rotor inertia, an MJCF's) [kg·m²], ``damping``
        (viscous friction) [N·m·s/rad] and ``friction`` (Coulomb friction: a URDF's ``friction``, an MJCF's
        ``frictionloss``) [N·m]: 0 where the file gives none. Each (n_dof,).
    """
    if is_mjcf(path):
        return mjcf_joint_values(path, held)
    with _silenced_stderr([]):
        model = _pinocchio_model(Path(path), dict(held or {}))
    out: dict[str, list[float]] = {k: [] for k in ("q_min", "q_max", "dq_max", "ddq_max", "tau_max", "armature",
                                                   "damping", "friction")}
    for j in range(1, model.njoints):
        i, nv = model.joints[j].idx_q, model.joints[j].nq
        if nv == 2:  # continuous (cos, sin): no position limit
            lo, hi = -np.inf, np.inf
        else:
            lo, hi = float(model.lowerPositionLimit[i]), float(model.upperPositionLimit[i])
            if not lo < hi or not (np.isfinite(lo) and np.isfinite(hi)) or abs(lo) > 1e10:
                lo, hi = -np.inf, np.inf
        v = model.joints[j].idx_v
        vel, eff = float(model.velocityLimit[v]), float(model.effortLimit[v])
        out["q_min"].append(lo)
        out["q_max"].append(hi)
        out["dq_max"].append(vel if 0 < vel < 1e10 else np.inf)
        out["tau_max"].append(eff if 0 < eff < 1e10 else np.inf)
        out["ddq_max"].append(np.inf)
        out["armature"].append(float(model.armature[v]))
        out["damping"].append(float(model.damping[v]))
        out["friction"].append(float(model.friction[v]))
    return {k: np.array(v) for k, v in out.items()}


def is_xacro(path: str | Path) -> bool:
    """Whether a robot file is a xacro file (``arm.xacro``, ``arm.urdf.xacro``).

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    bool
    """
    return str(path).lower().endswith(".xacro")


def expand_xacro(path: str | Path, mappings: dict | None = None) -> Path:
    """The URDF a xacro file expands to, written once into dynid's cache (``$XDG_CACHE_HOME/dynid/xacro``, by default
    ``~/.cache/dynid/xacro``) in a folder whose name changes with the file's contents and arguments, and reused after.
    The expansion keeps the file's name less ``.xacro`` (``arm.urdf.xacro`` gives ``arm.urdf``), which is the name
    ``dynid identify`` and ``dynid export`` write the identified URDF under.

    dynid expands the file itself (:mod:`dynid.model.xacro_expansion`): macros, properties, arguments, conditionals,
    math and includes by relative path; ``$(find pkg)`` finds the package's folder without ROS
    (:meth:`~dynid.model.xacro_expansion.XacroExpansion.find`), and where it cannot, the file is refused in one line
    naming the package. Mesh paths stay as the file wrote them. Every expression is computed by dynid's interpreter
    (:mod:`dynid.model.xacro_expressions`), never by Python's ``eval``: a description that would run code (files,
    introspection) is refused in one line.

    Parameters
    ----------
    path : str or Path
    mappings : dict, optional
        xacro arguments (``name:=value``).

    Returns
    -------
    Path
        The expanded URDF.

    Raises
    ------
    ConfigError
        The file is unreadable or cannot be expanded (the message names the file).
    """
    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"{path}: xacro file not found")
    text = path.read_bytes()
    key = hashlib.sha256(text + repr(sorted((mappings or {}).items())).encode() + str(path.resolve()).encode()).hexdigest()[:16]
    cache = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "dynid" / "xacro"
    stem = path.name[:-len(".xacro")].removesuffix(".urdf")
    name = Path(f"{stem}-{key}") / f"{stem}.urdf"  # the file keeps the robot's name: export writes "<stem>.urdf"
    for folder in (cache, _fallback_cache()):
        if _cached_and_current(folder / name):
            return folder / name
    urdf, files = expand_xacro_text(path, mappings)
    read = sorted({str(Path(f).resolve()) for f in files})
    out = cache / name
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
    except OSError:  # an unwritable cache: the system's temporary folder instead
        out = _fallback_cache() / name
        out.parent.mkdir(parents=True, exist_ok=True)
    manifest = {f: hashlib.sha256(Path(f).read_bytes()).hexdigest() for f in read if Path(f).is_file()}
    _write_atomically(out.with_suffix(".files.json"), json.dumps(manifest, indent=1))
    _write_atomically(out, urdf)
    return out


def _fallback_cache() -> Path:
    """The xacro cache in the system's temporary folder, where the user's cache folder cannot be written."""
    return Path(tempfile.gettempdir()) / f"dynid-xacro-{os.getuid() if hasattr(os, 'getuid') else 0}"


def _write_atomically(path: Path, text: str) -> None:
    tmp = path.with_suffix(f".{os.getpid()}.tmp")
    tmp.write_text(text, encoding="utf-8")
    os.replace(tmp, path)


def _cached_and_current(out: Path) -> bool:
    """Whether a cached expansion exists and every file it read (the top file, includes, YAML; its ``.files.json``)
    still has the contents it had: an edited included file expands again."""
    try:
        manifest = json.loads(out.with_suffix(".files.json").read_text(encoding="utf-8"))
        return out.is_file() and isinstance(manifest, dict) and all(
            hashlib.sha256(Path(f).read_bytes()).hexdigest() == h for f, h in manifest.items())
    except (OSError, ValueError):
        return False

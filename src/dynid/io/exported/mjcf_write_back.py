"""The user's own MuJoCo model (MJCF) with the identified values written into it, and nothing else changed.

A MuJoCo model of an arm rarely puts its bodies at the frames of the URDF dynid identified with (MuJoCo Menagerie's
UR10e turns its base by π and places each body where its meshes were drawn). The two models are matched where they
must agree, the joint axes at the zero configuration: a rigid transform of the whole arm maps the robot's joint
axes onto the MJCF's (rotation by Kabsch's method on their directions, translation by least squares on the lines),
and each identified link is then expressed in its MJCF body's own frame. MuJoCo (the ``mujoco`` extra) computes the
MJCF's kinematics, so every way MJCF can state a frame (``quat``, ``euler``, ``axisangle``, defaults, ``angle``
units) is read as MuJoCo reads it.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from ...dynamics.kinematics import forward_kinematics
from ...exceptions import ConfigError
from ...model.description_files import (
    _exportable,
    _vec,
    coupled_tendons,
    friction_solref,
    mujoco_inertia,
    offset_actuators,
    position_offset_note,
)
from ...model.mjcf import held_inertials
from ...model.robot import Robot
from ...model.spatial import is_physically_consistent, nearest_consistent, physical_from_inertial, transform_inertial
from ...runtime.extras import require
from .export import _replace, identified_header, moved_far

AXIS_TOLERANCE = 1e-4
"""[rad, m] How far a joint axis of the MJCF may lie from the robot's, once the arms are aligned."""


def _joint_frames(robot: Robot) -> tuple[np.ndarray, np.ndarray]:
    """Rotations (n, 3, 3) and origins (n, 3) of the robot's joint frames at q = 0, in its base frame."""
    rotations, origins = forward_kinematics(robot, np.zeros((1, robot.n_dof)))
    return rotations[0], origins[0]


def _alignment(axes_robot, points_robot, axes_model, points_model) -> tuple[np.ndarray, np.ndarray, float]:
    """``(R, t, misfit)`` mapping the robot's base frame into the MJCF's world: ``R a_robot = a_model`` and each robot
    joint line onto the model's (Kabsch on the directions, then the translation nearest every line)."""
    h = axes_robot.T @ axes_model
    u, s, vt = np.linalg.svd(h)
    if s[1] < 1e-6:  # every axis parallel: the rotation about them is not determined by the axes alone
        raise ValueError("parallel")
    d = np.sign(np.linalg.det(vt.T @ u.T))
    r = vt.T @ np.diag([1.0, 1.0, d]) @ u.T
    projectors = np.eye(3)[None] - axes_model[:, :, None] * axes_model[:, None, :]
    lhs = projectors.sum(axis=0)
    rhs = np.einsum("kij,kj->i", projectors, points_model - points_robot @ r.T)
    t = np.linalg.lstsq(lhs, rhs, rcond=None)[0]
    off_line = np.einsum("kij,kj->ki", projectors, points_robot @ r.T + t - points_model)
    misfit = max(float(np.abs(axes_robot @ r.T - axes_model).max()), float(np.linalg.norm(off_line, axis=1).max()))
    return r, t, misfit


def _rebased(source_dir: Path, out_dir: Path, value: str | None) -> str:
    """A path the original resolves from ``source_dir``, as the written file must say it from ``out_dir``."""
    target = Path(value) if value else Path(".")
    if target.is_absolute():
        return str(target)
    return os.path.relpath(source_dir / target, out_dir)


def _aligned(path: Path, robot: Robot, data, ids) -> tuple:
    """:func:`mjcf_written_back`'s robot joint frames and the rotation and translation that place them on the MJCF's
    joints at q = 0 (``data`` after ``mj_kinematics`` there); a file whose axes are not the robot's is refused."""
    rotations, origins = _joint_frames(robot)
    axes_robot = np.einsum("kij,kj->ki", rotations, np.array([j.axis for j in robot.joints], dtype=float))
    axes_robot /= np.linalg.norm(axes_robot, axis=1, keepdims=True)
    try:
        r, t, misfit = _alignment(axes_robot, origins, data.xaxis[ids], data.xanchor[ids])
    except ValueError:
        raise ConfigError(f"{path}: every joint axis is parallel, so the axes cannot place the arm: write back needs "
                          "two joints that are not parallel") from None
    if misfit > AXIS_TOLERANCE:
        raise ConfigError(f"{path}: its joint axes at q = 0 are not the robot's (off by {misfit:.3g}, in m or rad): "
                          "another robot, another zero position or joints turning the other way")
    return rotations, origins, r, t


def _append_model_terms(root, robot: Robot, fitted, coupled, *, offsets_held: bool) -> None:
    """:func:`mjcf_written_back`'s model-wide terms: the coupled motors' tendons (or a comment with their terms where
    they are not held), the joints' position offsets (a comment), and the offsets' actuators where they are held."""
    if coupled is not None:
        _append_tendons(root, coupled)
    elif robot.transmission.n_coupled_params:
        root.append(ET.Comment(" dynid: coupled motors (not representable in MJCF), add their torques: " + ", ".join(
            f"{n} = {v:.17g}" for n, v in zip(robot.transmission.coupled_parameter_names,
                                              fitted.transmission.coupled_values.ravel())) + " "))
    if note := position_offset_note(robot):
        root.append(ET.Comment(note))
    for attributes in offset_actuators(robot, fitted.standard_parameters()) if offsets_held else []:
        ET.SubElement(_section(root, "actuator"), "general", attributes)


def mjcf_written_back(mjcf: str | Path, robot: Robot, phi: np.ndarray, out_dir: str | Path | None = None,
                      estimate: str = "the physically consistent estimate", *, offsets_held: bool = False
                      ) -> tuple[str, list[str]]:
    """The user's MJCF with each moving body's ``<inertial>`` and each joint's ``armature``, ``damping`` and
    ``frictionloss`` replaced by the identified values; every other element kept (names, frames, geoms, meshes,
    sites, actuators, sensors, defaults, comments).

    Each joint of ``robot`` is found by name among the MJCF's hinges. The link identified in the robot's joint frame
    is expressed in the MJCF body that carries the joint (``transform_inertial``); bodies welded to it (no joint of
    their own, e.g. a flange or a tool) are identified with it, so their inertials become massless (a comment says
    so). Bodies the robot holds fixed (:attr:`Robot.held`: a gripper's fingers, and what rides on them) keep their
    own inertials, and the link they hang on gets the identified values less theirs
    (:func:`dynid.model.mjcf.held_inertials`), so that the full model's mass matrix stays positive definite. A compiler told to take inertias from geoms (``inertiafromgeom="true"``) would ignore the written values: it
    is set to ``"auto"``. Relative file paths (``meshdir``, ``texturedir``, ``assetdir``, ``<include file>``) are
    rewritten for the folder the result is written to. The header comment says what was identified, as in
    :func:`dynid.io.exported.urdf_write_back.urdf_written_back`.

    Parameters
    ----------
    mjcf : str or Path
        The user's MJCF, one file holding the arm's bodies (included files are kept as they are).
    robot : Robot
        The identified robot (its joint names are the MJCF's).
    phi : (n_params,) array
        Standard parameters to write (physically consistent).
    out_dir : str or Path, optional
        Folder the result will be written to (default: the MJCF's own).
    estimate : str
        What the values are, for the header comment.
    offsets_held : bool
        Hold the torque offsets as actuators of constant bias (:func:`dynid.model.description_files.offset_actuators`), added to the
        model's ``<actuator>`` after its own (their indices in ``ctrl`` unchanged), instead of comments.

    Returns
    -------
    text : str
        The MJCF.
    moved : list of str
        Links whose values moved far from the MJCF's own (:data:`dynid.io.exported.export.MOVED_MASS`, ``MOVED_COM``).

    Raises
    ------
    ConfigError
        The MJCF cannot be read or compiled by MuJoCo, lacks a joint of the robot (or has it as another type or in
        an included file), its joint axes at q = 0 are not the robot's (another robot, or another zero), or the
        values are not exportable.
    """
    import mujoco

    path = Path(mjcf)
    fitted = _exportable(robot, phi)
    model, root, ids = read_users_mjcf(path, robot)
    elements = {e.get("name"): e for e in root.iter("joint") if e.get("name")}
    bodies = {e.get("name"): e for e in root.iter("body") if e.get("name")}
    data = mujoco.MjData(model)
    data.qpos[:] = model.qpos0
    data.qpos[model.jnt_qposadr[ids]] = 0.0
    mujoco.mj_kinematics(model, data)
    rotations, origins, r, t = _aligned(path, robot, data, ids)
    moving = set(model.jnt_bodyid[ids])
    moved: list[str] = []
    coupled = coupled_tendons(robot, fitted)
    own = held_inertials(path, dict.fromkeys(robot.held, 0.0)) if robot.held else np.zeros((robot.n_dof, 10))
    for k, (joint, jid) in enumerate(zip(robot.joints, ids)):
        body_id = int(model.jnt_bodyid[jid])
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, body_id)
        body = bodies.get(name)
        if body is None:
            raise ConfigError(f"{path}: the body of joint {joint.name!r} has no name: name it to write into it")
        frame = (r @ rotations[k], r @ origins[k] + t)  # the robot's joint frame in MuJoCo's world
        mass, com, notes = _write_inertial(model, data, (body_id, name, body), bodies, fitted.inertial[k] - own[k],
                                           frame=frame, moving=moving, held=bool(np.any(own[k] != 0)))
        moved += notes
        nominal_mass, nominal_com = float(model.body_mass[body_id]), np.array(model.body_ipos[body_id])
        terms = dict(zip(robot.drive_terms, fitted.drive[k]))
        if coupled is not None:  # the coupled motors' viscous diagonal goes with their tendons
            terms["fv"] = coupled[1][k]
        element = elements[joint.name]
        element.set("armature", f"{terms.get('Ia', 0.0):.17g}")
        element.set("damping", f"{terms.get('fv', 0.0):.17g}")
        element.set("frictionloss", f"{terms.get('fc', 0.0):.17g}")
        dof = int(model.jnt_dofadr[jid])
        if element.get("solreffriction") is None and np.allclose(model.dof_solref[dof], (0.02, 1.0)):  # MuJoCo's default
            element.set("solreffriction", friction_solref(float(model.opt.timestep)))
        extra = {n: v for n, v in terms.items() if n not in ("Ia", "fc", "fv", *(("offset",) if offsets_held else ())) and v != 0}
        if extra:
            body.append(ET.Comment(" dynid: drive terms MJCF cannot hold, add them to the torques: "
                                   + ", ".join(f"{n}{k + 1} = {v:.17g}" for n, v in extra.items()) + " "))
        if robot.coulomb_velocity[k] > 0:
            body.append(ET.Comment(f" dynid: Coulomb term tanh(dq/{robot.coulomb_velocity[k]:.6g}) instead of sign(dq) "))
        far = moved_far(name, mass, com, nominal_mass, nominal_com, "MJCF")
        moved.extend([far] if far else [])
    _append_model_terms(root, robot, fitted, coupled, offsets_held=offsets_held)
    _compiler_for(root, path.parent.resolve(), Path(out_dir).resolve() if out_dir is not None else path.parent.resolve())
    header = identified_header(path.name, "the <inertial> of every body a joint moves and the armature, damping and "
                               "frictionloss of every joint", estimate, moved, "MJCF")
    root.insert(0, ET.Comment(header))
    if root[0].tail is None or not root[0].tail.strip():
        root[0].tail = "\n  "
    return '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n", moved


def _section(root, tag: str):
    """The MJCF's ``<tag>`` section (its first), made at the end where it has none."""
    found = root.find(tag)
    return ET.SubElement(root, tag) if found is None else found


def _append_tendons(root, coupled: tuple) -> None:
    """The coupled motors' tendons (:func:`dynid.model.description_files.coupled_tendons`) added to the MJCF's ``<tendon>``, and
    what they do not hold as a comment."""
    for attributes, joints in coupled[0]:
        tendon = ET.SubElement(_section(root, "tendon"), "fixed", attributes)
        for name, coef in joints:
            ET.SubElement(tendon, "joint", {"joint": name, "coef": f"{coef:.17g}"})
    if coupled[2]:
        root.append(ET.Comment(" dynid: coupled motors' terms MJCF cannot hold, add their torques: "
                               + ", ".join(f"{n} = {v:.17g}" for n, v in coupled[2].items()) + " "))


def _write_inertial(model, data, body: tuple, bodies: dict, alone: np.ndarray, *, frame: tuple, moving: set, held: bool):
    """One moving body's (``(id, name, element)``) ``<inertial>`` replaced by a link's identified values (``alone``: less what the held bodies keep
    of their own, made consistent where that leaves them not), expressed in the body's frame from the robot's joint
    frame ``(rotation, origin)`` in MuJoCo's world; the bodies welded to it made massless, with a comment.

    Returns ``(mass, com, notes)``: the written mass and centre of mass, and a note where the values were made
    consistent.
    """
    import mujoco

    body_id, name, element = body
    notes = []
    if held and not is_physically_consistent(alone):
        alone = nearest_consistent(alone)
        notes.append(f"{name}: its identified values less the held bodies' own are not physically consistent; the "
                     "nearest consistent ones are written (the held bodies keep the file's)")
    body_r = data.xmat[body_id].reshape(3, 3)
    frame_r, frame_p = frame
    in_body = transform_inertial(alone, body_r.T @ frame_r, body_r.T @ (frame_p - data.xpos[body_id]))
    mass, com, inertia = physical_from_inertial(in_body)
    inertia = mujoco_inertia(inertia)
    _replace(element, "inertial", ET.Element("inertial", pos=_vec(com), mass=f"{mass:.17g}", fullinertia=" ".join(
        f"{v:.17g}" for v in (inertia[0, 0], inertia[1, 1], inertia[2, 2], inertia[0, 1], inertia[0, 2], inertia[1, 2]))))
    welded = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b) or f"body {b}" for b in range(model.nbody)
              if b not in moving and _carried_by(model, b, body_id, moving)]
    for other in welded:
        if other in bodies:
            _replace(bodies[other], "inertial", ET.Element("inertial", pos="0 0 0", mass="0", diaginertia="0 0 0"))
    if welded:
        element.insert(0, ET.Comment(f" dynid: {', '.join(welded)} (welded to this body) identified with it: their "
                                     "mass is written here "))
    return mass, com, notes


def read_users_mjcf(path: Path, robot: Robot):
    """The user's MJCF compiled by MuJoCo and parsed as XML (comments kept), with the ids of the robot's joints.

    Parameters
    ----------
    path : Path
    robot : Robot

    Returns
    -------
    model : mujoco.MjModel
    root : xml.etree.ElementTree.Element
    ids : list of int
        MuJoCo's joint id of each of the robot's joints.

    Raises
    ------
    ConfigError
        MuJoCo is not installed (names the extra), the file cannot be read or compiled, a joint of the robot is
        missing, is not a hinge, or is in an included file.
    """
    mujoco = require("mujoco", "mujoco", "writing into an MJCF")
    try:
        model = mujoco.MjModel.from_xml_path(str(path))
        root = ET.parse(path, parser=ET.XMLParser(target=ET.TreeBuilder(insert_comments=True))).getroot()
    except (OSError, ValueError, ET.ParseError) as exc:
        raise ConfigError(f"{path}: cannot read it as MJCF ({' '.join(str(exc).split())})") from None
    named = {e.get("name") for e in root.iter("joint")}
    ids = []
    for joint in robot.joints:
        k = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, joint.name)
        if k < 0:
            raise ConfigError(f"{path}: has no joint {joint.name!r}: the robot identified (joints "
                              f"{', '.join(j.name for j in robot.joints)}) is another than this MJCF's")
        kind = mujoco.mjtJoint.mjJNT_SLIDE if joint.prismatic else mujoco.mjtJoint.mjJNT_HINGE
        if model.jnt_type[k] != kind:
            raise ConfigError(f"{path}: joint {joint.name!r} is not a {'slide' if joint.prismatic else 'hinge'}, the "
                              f"robot's joint is {'prismatic' if joint.prismatic else 'revolute'}")
        if joint.name not in named:
            raise ConfigError(f"{path}: joint {joint.name!r} is in an included file: write back into one file holding the arm")
        ids.append(k)
    return model, root, ids


def _carried_by(model, body: int, owner: int, moving: set) -> bool:
    """``body`` rides on ``owner`` with no joint between them."""
    while body not in (0, owner):
        if model.body_jntnum[body] or body in moving:
            return False
        body = int(model.body_parentid[body])
    return body == owner


def _compiler_for(root, source_dir: Path, out_dir: Path) -> None:
    """Make the written file compile as the original did: inertias written here not overridden by geoms, and file
    references resolved from the folder it is written to."""
    compiler = root.find("compiler")
    if compiler is None:
        compiler = ET.Element("compiler")
        compiler.tail = "\n  "
        root.insert(0, compiler)
    if compiler.get("inertiafromgeom") == "true":
        compiler.set("inertiafromgeom", "auto")
        root.insert(0, ET.Comment(" dynid: inertiafromgeom was \"true\", which would ignore the identified inertials "))
    if out_dir == source_dir:
        return
    for attribute in ("meshdir", "texturedir"):
        if compiler.get(attribute) is not None:
            compiler.set(attribute, _rebased(source_dir, out_dir, compiler.get(attribute)))
    compiler.set("assetdir", _rebased(source_dir, out_dir, compiler.get("assetdir")))
    for include in root.iter("include"):
        if include.get("file"):
            include.set("file", _rebased(source_dir, out_dir, include.get("file")))

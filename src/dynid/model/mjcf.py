"""Serial revolute chains from MuJoCo models (MJCF), as MuJoCo compiles them.

MuJoCo (the ``mujoco`` extra) reads the file, so every way MJCF states a frame (``quat``, ``euler`` in any sequence,
``axisangle`` with an axis of any length, ``xyaxes``, ``zaxis``), angles in degrees or radians, default classes,
includes and inertias computed from geoms mean what they mean to MuJoCo. From the compiled model: each hinge joint
is a revolute joint whose frame is its body's frame moved to the joint's ``pos``; bodies without a joint, and joints
held fixed, count with the link they hang on (as a URDF's fixed joints do); a link's inertial parameters are those
of all its bodies about its joint frame. Pinocchio's own MJCF parser was not used: it takes an ``axisangle`` axis as
given where MuJoCo normalises it (a 60° turn about (1, 0.5, 0) put the torques off by 2.3 times their size).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..exceptions import ConfigError
from ..runtime.extras import require
from .robot import Joint
from .robot_files import HELD_HINT, check_xml, joints_off_arm
from .spatial import inertial_from_physical, rot_axis, transform_inertial


def _compiled(path: Path):
    """MuJoCo's model of the file (one line naming the file where MuJoCo refuses it)."""
    mujoco = require("mujoco", "mujoco", f"reading the MuJoCo model {path.name}")
    check_xml(path)  # with its line and column
    try:
        return mujoco, mujoco.MjModel.from_xml_path(str(path))
    except (OSError, ValueError) as exc:
        raise ConfigError(f"{path}: cannot read it as MJCF ({' '.join(str(exc).split())})") from None


def _quat_matrix(mujoco, quat) -> np.ndarray:
    out = np.zeros(9)
    mujoco.mju_quat2Mat(out, np.asarray(quat, dtype=float))
    return out.reshape(3, 3)


def _chain(path: Path, held: dict):
    """The compiled model, its moving joints (MuJoCo ids, base to tip) and for each body the moving joint it rides
    on (-1: the base)."""
    mujoco, model = _compiled(path)
    names = [model.joint(k).name for k in range(model.njnt)]
    unknown = sorted(set(held) - set(names))
    if unknown:
        raise ConfigError(f"{path}: held names joint {unknown[0]!r}, which the MJCF's joints do not include "
                          f"({', '.join(names)})")
    owner = np.full(model.nbody, -1)  # the moving joint each body rides on
    moving: list[int] = []
    for b in range(1, model.nbody):
        owner[b] = owner[model.body_parentid[b]]
        for k in range(model.body_jntadr[b], model.body_jntadr[b] + model.body_jntnum[b]):
            name = names[k] or f"joint {k + 1}"
            if name in held:
                continue
            kind = int(model.jnt_type[k])
            if kind not in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE):
                what = {0: "a free joint (a floating base)", 1: "a ball joint"}.get(kind, "neither hinge nor slide")
                raise ConfigError(f"{path}: joint {name!r} is {what}, expected a hinge or a slide joint; "
                                  + HELD_HINT.format(names=f'"{name}"'))
            if owner[b] >= 0 and _body(model, owner[b]) == b:
                raise ConfigError(f"{path}: body {model.body(b).name!r} has more than one moving joint ({name!r}): "
                                  "dynid identifies one revolute joint per link; " + HELD_HINT.format(names=f'"{name}"'))
            if abs(model.qpos0[model.jnt_qposadr[k]]) > 0:
                raise ConfigError(f"{path}: joint {name!r} has ref = {model.qpos0[model.jnt_qposadr[k]]:g}: dynid's "
                                  "joint angle is 0 where the body's frame is as written; remove ref (and offset the "
                                  "log's angles by it) or describe the arm in a URDF")
            moving.append(k)
            owner[b] = k
    if not moving:
        raise ConfigError(f"{path}: expected at least one hinge or slide joint, found none")
    return mujoco, model, moving, owner, names


def _body(model, k: int) -> int:
    """The body joint ``k`` moves."""
    return int(model.jnt_bodyid[k])


def _body_in_parent(mujoco, model, b: int, held: dict, names) -> tuple[np.ndarray, np.ndarray]:
    """Body ``b``'s frame in its parent's, with its held joints turned to their positions."""
    rotation, translation = _quat_matrix(mujoco, model.body_quat[b]), np.array(model.body_pos[b], dtype=float)
    for k in range(model.body_jntadr[b], model.body_jntadr[b] + model.body_jntnum[b]):
        if names[k] in held:  # rotate (hinge) or move (slide) the body about the joint at its held position
            axis, anchor, value = np.array(model.jnt_axis[k]), np.array(model.jnt_pos[k]), held[names[k]]
            if model.jnt_type[k] == mujoco.mjtJoint.mjJNT_SLIDE:
                translation = translation + rotation @ (axis * value)
            elif model.jnt_type[k] == mujoco.mjtJoint.mjJNT_HINGE:
                turn = rot_axis(axis / np.linalg.norm(axis), np.array([value]))[0]
                translation = translation + rotation @ (anchor - turn @ anchor)
                rotation = rotation @ turn
    return rotation, translation


def _frames(mujoco, model, moving, held, names):
    """Each body's frame in the frame of the moving joint it rides on (its link's), the base's bodies in the world's."""
    rotations, translations = [np.eye(3)], [np.zeros(3)]
    joint_of_body = {_body(model, k): k for k in moving}
    for b in range(1, model.nbody):
        r, t = _body_in_parent(mujoco, model, b, held, names)
        if b in joint_of_body:  # the link's own frame: the body's, moved to the joint's anchor
            rotations.append(np.eye(3))
            translations.append(-np.array(model.jnt_pos[joint_of_body[b]], dtype=float))
            continue
        p = model.body_parentid[b]
        rotations.append(rotations[p] @ r)
        translations.append(rotations[p] @ t + translations[p])
    return rotations, translations


def joints_from_mjcf(path: str | Path, held=None) -> tuple[tuple[Joint, ...], np.ndarray, tuple[str, ...], tuple[str, ...]]:
    """Joints and link inertial parameters of an MJCF's hinge and slide joints, as MuJoCo compiles the file: a serial
    chain, or a tree (two arms on a torso), each joint then naming the joint that carries it.

    Parameters
    ----------
    path : str or Path
    held : dict, optional
        Joint name -> position [rad or m] at which it is held fixed (its body then counts with its parent's link).

    Returns
    -------
    joints : tuple of Joint
        Placement of each joint frame in the previous link's frame (the base's for the first), its axis in it.
    inertial : (n_dof, 10) array
        Inertial parameters of each link in its joint frame (eq. 5 order).
    names : tuple of str
        The joints' names.
    links : tuple of str
        The name of each joint's body.

    Raises
    ------
    ConfigError
        MuJoCo is not installed (names the extra), the file cannot be compiled, a held joint is not in it, a joint is
        neither hinge nor slide, a body has two moving joints, or a hinge has a reference angle (``ref``).
    """
    path, held = Path(path), dict(held or {})
    mujoco, model, moving, owner, names = _chain(path, held)
    rotations, translations = _frames(mujoco, model, moving, held, names)
    inertial = _lumped(mujoco, model, range(1, model.nbody), moving, owner, (rotations, translations))
    joints = []
    for i, k in enumerate(moving):
        b = _body(model, k)
        parent = model.body_parentid[b]
        r, t = _body_in_parent(mujoco, model, b, held, names)
        r_parent, t_parent = rotations[parent], translations[parent]  # parent body in the previous link's frame
        rotation, translation = r_parent @ r, r_parent @ (t + r @ np.array(model.jnt_pos[k])) + t_parent
        axis = np.array(model.jnt_axis[k], dtype=float)
        carrier = moving.index(owner[parent]) if owner[parent] >= 0 else -1  # a branch: the joint its body rides on
        joints.append(Joint(names[k] or f"joint{i + 1}", rotation, translation, axis / np.linalg.norm(axis),
                            bool(model.jnt_type[k] == mujoco.mjtJoint.mjJNT_SLIDE), None if carrier == i - 1 else carrier,
                            _followed(mujoco, model, path, k, moving, names, held)))
    return (tuple(joints), inertial, tuple(j.name for j in joints),
            tuple(model.body(_body(model, k)).name for k in moving))


def _followed(mujoco, model, path: Path, k: int, moving: list, names, held: dict) -> tuple[int, float, float] | None:
    """A joint's :attr:`Joint.mimic` from the file's joint equality that couples it to another (``<equality><joint
    joint1="it" joint2="other" polycoef="offset multiplier 0 0 0"/>``, dynid's own write-back of a ``<mimic>``): a
    linear coupling to a moving joint; refused where the polynomial is not linear or the other joint is held or
    absent."""
    for e in range(model.neq):
        if model.eq_type[e] != mujoco.mjtEq.mjEQ_JOINT or int(model.eq_obj1id[e]) != k:
            continue
        other, poly = int(model.eq_obj2id[e]), np.asarray(model.eq_data[e][:5], dtype=float)
        said = f"{path}: joint {names[k]!r} has an <equality joint> (polycoef {' '.join(f'{c:g}' for c in poly)})"
        if other < 0 or names[other] in held or other not in moving:
            raise ConfigError(f"{said} couples it to no moving joint of the model dynid identifies (a held or fixed one?): "
                              "hold both, or neither")
        if np.any(poly[2:] != 0) or poly[1] == 0:
            raise ConfigError(f"{said}: expected a linear coupling (polycoef offset multiplier 0 0 0, the multiplier not 0)")
        return moving.index(other), float(poly[1]), float(poly[0])
    return None


def held_inertials(path: str | Path, held=None) -> np.ndarray:
    """Each link's share of the bodies its held joints carry (a gripper's fingers and what rides on them), as
    :func:`joints_from_mjcf` lumps them into the link: their own inertials in the link's joint frame, at the held
    positions. The link alone is :func:`joints_from_mjcf`'s less this.

    Parameters
    ----------
    path : str or Path
    held : dict, optional
        Joint name -> position [rad or m] at which it is held fixed.

    Returns
    -------
    (n_dof, 10) ndarray
        Eq. 5 order; zero rows for links that carry no held joint.
    """
    path, held = Path(path), dict(held or {})
    mujoco, model, moving, owner, names = _chain(path, held)
    rotations, translations = _frames(mujoco, model, moving, held, names)
    bodies = {_body(model, k) for k in moving}
    carried = np.zeros(model.nbody, dtype=bool)  # rides on a held joint below its link's body
    for b in range(1, model.nbody):
        own = any(names[k] in held for k in range(model.body_jntadr[b], model.body_jntadr[b] + model.body_jntnum[b]))
        carried[b] = b not in bodies and (own or carried[model.body_parentid[b]])
    return _lumped(mujoco, model, np.flatnonzero(carried), moving, owner, (rotations, translations))


def _lumped(mujoco, model, bodies, moving, owner, frames) -> np.ndarray:
    """(n_dof, 10): the inertials of ``bodies`` summed into the link each rides on, in its joint frame (``frames``:
    every body's frame in its link's, :func:`_frames`); bodies on the base or without mass count nowhere."""
    rotations, translations = frames
    link_of = {k: i for i, k in enumerate(moving)}
    out = np.zeros((len(moving), 10))
    for b in bodies:
        if owner[b] < 0 or model.body_mass[b] == 0:
            continue
        principal = _quat_matrix(mujoco, model.body_iquat[b])
        phi = inertial_from_physical(float(model.body_mass[b]), np.array(model.body_ipos[b]),
                                     principal @ np.diag(model.body_inertia[b]) @ principal.T)
        out[link_of[owner[b]]] += transform_inertial(phi, rotations[b], translations[b])
    return out


@dataclass(frozen=True)
class CollisionGeom:
    """One collision geom of an MJCF, on the link it rides on (:func:`collision_geoms`).

    Attributes
    ----------
    name : str
        The geom's name (``geom <id>`` where it has none).
    kind : str
        ``"sphere"``, ``"capsule"``, ``"ellipsoid"``, ``"cylinder"``, ``"box"`` or ``"mesh"``.
    size : (3,) array [m]
        MuJoCo's ``geom_size``: a radius; a radius and a half-length; three semi-axes or half-sides.
    vertices : (m, 3) array or None [m]
        A mesh's vertices in the geom's frame (None for the other kinds).
    link : int
        The link (0-based) the geom rides on; -1 for the base.
    placement : (4, 4) array
        The geom's pose in that link's joint frame (the base's: MuJoCo's world frame) [m].
    body : str
        The body it belongs to.
    contype, conaffinity : int
        Its collision bit masks: MuJoCo collides two geoms where one's ``contype`` and the other's ``conaffinity``
        share a bit.
    """

    name: str
    kind: str
    size: np.ndarray
    vertices: np.ndarray | None
    link: int
    placement: np.ndarray
    body: str = ""
    contype: int = 1
    conaffinity: int = 1


GEOM_KINDS = {2: "sphere", 3: "capsule", 4: "ellipsoid", 5: "cylinder", 6: "box", 7: "mesh"}
"""MuJoCo's ``mjtGeom`` values of the shapes a link can carry (planes and height fields are the world's)."""


def collision_geoms(path: str | Path, held=None) -> tuple[CollisionGeom, ...]:
    """The geoms of an MJCF that collide (``contype`` or ``conaffinity`` not 0: not the visual-only ones, group
    whatever), on the links of its chain (:func:`joints_from_mjcf`), as MuJoCo compiles them: a mesh's vertices in its
    geom's frame (MuJoCo collides a mesh by their convex hull). The world body's geoms (a floor, a table) are left out:
    the cell is stated in the excitation config.

    Parameters
    ----------
    path : str or Path
    held : dict, optional
        Joint name -> position at which it is held fixed (its bodies ride on the link it is held to).

    Returns
    -------
    tuple of CollisionGeom

    Raises
    ------
    ConfigError
        As :func:`joints_from_mjcf`.
    """
    path, held = Path(path), dict(held or {})
    mujoco, model, moving, owner, names = _chain(path, held)
    rotations, translations = _frames(mujoco, model, moving, held, names)
    link_of = {k: i for i, k in enumerate(moving)}
    out = []
    for g in range(model.ngeom):
        b, kind = int(model.geom_bodyid[g]), GEOM_KINDS.get(int(model.geom_type[g]))
        if b == 0 or kind is None or not (model.geom_contype[g] or model.geom_conaffinity[g]):
            continue
        pose = np.eye(4)
        pose[:3, :3] = rotations[b] @ _quat_matrix(mujoco, model.geom_quat[g])
        pose[:3, 3] = rotations[b] @ np.array(model.geom_pos[g], dtype=float) + translations[b]
        vertices = None
        if kind == "mesh":
            m = int(model.geom_dataid[g])
            start = int(model.mesh_vertadr[m])
            vertices = np.array(model.mesh_vert[start:start + int(model.mesh_vertnum[m])], dtype=float)
        out.append(CollisionGeom(model.geom(g).name or f"geom {g}", kind, np.array(model.geom_size[g], dtype=float),
                                 vertices, link_of[owner[b]] if owner[b] >= 0 else -1, pose, model.body(b).name,
                                 int(model.geom_contype[g]), int(model.geom_conaffinity[g])))
    return tuple(out)


def excluded_bodies(path: str | Path) -> frozenset[frozenset[str]]:
    """The pairs of bodies an MJCF's ``<contact><exclude body1=... body2=...>`` keeps MuJoCo from colliding.

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    frozenset of frozenset of str
        Body names, two to a pair.

    Raises
    ------
    ConfigError
        MuJoCo is not installed, or the file cannot be compiled.
    """
    _, model = _compiled(Path(path))
    return frozenset(frozenset((model.body(int(sig) >> 16).name, model.body(int(sig) & 0xFFFF).name))
                     for sig in model.exclude_signature)


def mjcf_joint_values(path: str | Path, held=None) -> dict:
    """What an MJCF states of each moving hinge beside the chain: its range and its drive (as MuJoCo compiles them).

    Parameters
    ----------
    path : str or Path
    held : dict, optional
        Joints held fixed (:func:`joints_from_mjcf`): not among the joints.

    Returns
    -------
    dict
        ``q_min, q_max`` [rad] (``±inf`` for a joint without limits), ``dq_max``, ``ddq_max``, ``tau_max`` (inf:
        MJCF states none for a joint), ``armature`` [kg·m²], ``damping`` [N·m·s/rad], ``friction`` (its
        ``frictionloss``) [N·m]; each (n_dof,); and ``gravity`` (3,) [m/s²], its ``<option gravity>``.

    Raises
    ------
    ConfigError
        As :func:`joints_from_mjcf`.
    """
    path, held = Path(path), dict(held or {})
    _, model, moving, _, _ = _chain(path, held)
    limited = np.array([bool(model.jnt_limited[k]) for k in moving])
    ranges = np.array([model.jnt_range[k] for k in moving], dtype=float).reshape(-1, 2)
    dofs = [model.jnt_dofadr[k] for k in moving]
    inf = np.full(len(moving), np.inf)
    return {"q_min": np.where(limited, ranges[:, 0], -np.inf), "q_max": np.where(limited, ranges[:, 1], np.inf),
            "dq_max": inf.copy(), "ddq_max": inf.copy(), "tau_max": inf.copy(),
            "armature": np.array([model.dof_armature[d] for d in dofs], dtype=float),
            "damping": np.array([model.dof_damping[d] for d in dofs], dtype=float),
            "friction": np.array([model.dof_frictionloss[d] for d in dofs], dtype=float),
            "gravity": np.array(model.opt.gravity, dtype=float)}


def mjcf_joints_to_hold(path: str | Path, logged: Callable[[tuple[str, ...]], set[str]] | None = None) -> tuple[str, ...]:
    """The MJCF's joints that are not its arm, which ``dynid init`` holds fixed: every joint off the longest chain of
    hinges from the base (a gripper's fingers, a camera's pan joint on a branch of its own, wherever the file puts it),
    or off the chain that holds most of the joints the log names, or, where the log names joints on several branches'
    chains, every joint but those (:func:`dynid.model.robot_files.joints_off_arm`).

    Parameters
    ----------
    path : str or Path
    logged : callable, optional
        ``logged(names)`` -> the names among the file's moving joints that the log names.

    Returns
    -------
    tuple of str
        Joint names (empty for an MJCF that is one serial chain of hinges).

    Raises
    ------
    ConfigError
        MuJoCo is not installed, or the file cannot be compiled.
    """
    mujoco, model = _compiled(Path(path))
    _, parents, revolute, sliding = _tree(mujoco, model)
    named = set() if logged is None else logged(tuple(model.joint(k).name for k in parents))
    return tuple(model.joint(k).name
                 for k in joints_off_arm(parents, revolute, sliding, {k for k in parents if model.joint(k).name in named}))


def _tree(mujoco, model, held=()) -> tuple[dict[int, str], dict[int, int], set[int], set[int]]:
    """The MJCF's moving joints (not ``held``) as :func:`dynid.model.robot_files.arm_chain` reads them: each riding on
    the last joint of the bodies above it; the hinges are the revolute ones, the slides the prismatic ones."""
    names: dict[int, str] = {}
    parents: dict[int, int] = {}
    owner = np.full(model.nbody, -1)
    for b in range(1, model.nbody):
        owner[b] = owner[model.body_parentid[b]]
        for k in range(model.body_jntadr[b], model.body_jntadr[b] + model.body_jntnum[b]):
            name = model.joint(k).name or f"joint {k + 1}"
            if name not in held:
                names[k], parents[k], owner[b] = name, int(owner[b]), k
    return (names, parents, {k for k in names if model.jnt_type[k] == mujoco.mjtJoint.mjJNT_HINGE},
            {k for k in names if model.jnt_type[k] == mujoco.mjtJoint.mjJNT_SLIDE})

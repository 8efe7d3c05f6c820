"""A robot written as URDF or MuJoCo MJCF text, with given standard parameters (its nominal ones by default).

The files are generated from dynid's own kinematic description (the joint frames every robot has, whether it came
from a DH table or a URDF), so the same writer serves every robot: a chain ``base_link → link1 → … → linkN`` of
revolute or prismatic joints at dynid's joint frames and a fixed ``flange`` link at the tool frame. Each link's
``<inertial>`` holds the mass, the centre of mass and the inertia about it in the link frame
(:func:`dynid.model.spatial.physical_from_inertial`); each joint's ``<dynamics>`` (URDF) or ``damping``,
``frictionloss`` and ``armature`` (MJCF) hold its viscous and Coulomb friction and rotor inertia. What a format has no
field for is written as XML comments on the joint. Only physically consistent parameters are written: a file with a
negative mass or an impossible inertia makes simulators fail or behave wrongly.

These writers know the robot only; a results.json's estimate and the notes on what it holds are
:mod:`dynid.io.exported.export`'s, and a user's own file written back :mod:`dynid.io.exported.urdf_write_back`'s and
:mod:`dynid.io.exported.mjcf_write_back`'s.
"""

from __future__ import annotations

from html import escape
from pathlib import Path

import numpy as np

from .._util.keywords import keyword_only_after_data
from ..conventions import joint_angles_text
from ..exceptions import ConfigError
from .loading import as_robot
from .robot import Robot
from .spatial import (
    CONSISTENCY_TOL,
    is_physically_consistent,
    physical_from_inertial,
    physical_problems,
    within_round_off,
)


def _rpy(rotation: np.ndarray) -> np.ndarray:
    """Roll, pitch, yaw (URDF convention, R = Rz(y)·Ry(p)·Rx(r)) of a rotation matrix (Pinocchio's)."""
    import pinocchio as pin

    return np.asarray(pin.rpy.matrixToRpy(np.asarray(rotation, dtype=float)))


WORLD_JOINT = "world_to_base"
"""The fixed joint by which :func:`urdf_from_robot` turns the base of a robot whose gravity is not along -z of its base,
so that it is along -z of the URDF's root (a URDF has no gravity)."""


def _vec(v) -> str:
    return " ".join(f"{x:.17g}" for x in np.asarray(v, dtype=float))


def _exportable(robot: Robot, phi: np.ndarray | None) -> Robot:
    """The robot with parameters ``phi`` (default nominal), after the checks every export needs: the right
    number of parameters, every link realisable by a mass distribution, friction coefficients ≥ 0.

    Raises
    ------
    ConfigError
        Names the link or joint and the broken rule.
    """
    phi = robot.standard_parameters() if phi is None else np.asarray(phi, dtype=float)
    if phi.shape != (robot.n_params,):
        raise ConfigError(f"export: expected {robot.n_params} standard parameters for robot {robot.name!r}, got {phi.shape}")
    phi = phi.copy()
    names = robot.parameter_names
    for j in range(robot.n_dof):
        found = {term: names.index(f"{term}{j + 1}") for term in ("fc", "fv") if f"{term}{j + 1}" in names}
        if not all(within_round_off(phi[k], phi) for k in found.values()):  # the SDP solver's round-off on its bound
            fc, fv = (phi[found[t]] if t in found else 0.0 for t in ("fc", "fv"))
            raise ConfigError(f"export: joint {j + 1}: negative friction (fc = {fc:.4g}, fv = {fv:.4g}) cannot be exported")
        for k in found.values():
            phi[k] = max(phi[k], 0.0)  # -1e-11 is the solver's 0: written as 0
    fitted = robot.with_parameters(phi)
    for j, joint in enumerate(robot.joints):
        if not is_physically_consistent(fitted.inertial[j], tol=CONSISTENCY_TOL):
            rule = (physical_problems(fitted.inertial[j]) or ["a pseudo-inertia that is not positive semidefinite"])[0]
            raise ConfigError(f"export: link {j + 1} ({joint.name}): {rule}; only physically consistent parameters can be "
                              "exported (the physically consistent estimate of dynid identify is)")
    return fitted


def quoteattr(value: str) -> str:
    """An XML attribute value in double quotes, with &, <, >, " and ' escaped.

    ``html.escape`` produces valid XML entities; ``xml.sax.saxutils`` would import ``urllib`` on the way (70 ms).

    Parameters
    ----------
    value : str

    Returns
    -------
    str
    """
    return f'"{escape(str(value), quote=True)}"'


@keyword_only_after_data
def urdf_from_robot(robot: Robot | str | Path, phi: np.ndarray | None = None, *, name: str | None = None) -> str:
    """URDF text of ``robot`` with the standard parameters ``phi`` (default: its nominal ones).

    Parameters
    ----------
    robot : Robot, str or Path
        A built-in robot's name or a description's path is loaded (:func:`dynid.model.loading.as_robot`).
    phi : (n_params,) array, optional
        Standard parameters (eq. 5 order per link, then the drive terms), e.g. the physically consistent
        estimate of ``dynid identify``.
    name : str, optional
        Robot name in the URDF (default ``robot.name``).

    Returns
    -------
    str

    Raises
    ------
    ConfigError
        A link whose parameters are those of no mass distribution (named with the broken rule), or a
        negative friction coefficient.
    """
    robot = as_robot(robot)
    fitted = _exportable(robot, phi)
    lines = ['<?xml version="1.0"?>', f"<!-- written by dynid from robot {robot.name!r}: identified inertial and friction parameters -->",
             f"<robot name={quoteattr(name or robot.name)}>", '  <link name="base_link"/>']
    turn = _world_from_base(robot.gravity)
    if turn is not None:  # a URDF has no gravity: its users take -z of the root; the base turned so that it is
        lines += ['  <link name="world"/>', f'  <joint name="{WORLD_JOINT}" type="fixed">', '    <parent link="world"/>',
                  '    <child link="base_link"/>', f'    <origin xyz="0 0 0" rpy="{_vec(_rpy(turn))}"/>',
                  f"    <!-- dynid: gravity is {_vec(robot.gravity)} m/s² in the model's base frame: the base is turned so "
                  "that it points along -z of world, as a URDF's users take it -->", "  </joint>"]
    for j, joint in enumerate(robot.joints):
        mass, com, inertia = physical_from_inertial(fitted.inertial[j])
        link = f"link{j + 1}"
        lines += [f'  <link name="{link}">', "    <inertial>", f'      <origin xyz="{_vec(com)}" rpy="0 0 0"/>',
                  f'      <mass value="{mass:.17g}"/>',
                  f'      <inertia ixx="{inertia[0, 0]:.17g}" ixy="{inertia[0, 1]:.17g}" ixz="{inertia[0, 2]:.17g}" iyy="{inertia[1, 1]:.17g}" iyz="{inertia[1, 2]:.17g}" izz="{inertia[2, 2]:.17g}"/>',
                  "    </inertial>", "  </link>"]
        terms = dict(zip(robot.drive_terms, fitted.drive[j]))
        fc, fv = terms.get("fc", 0.0), terms.get("fv", 0.0)
        carrier = int(robot.parents[j])  # the joint before it along a chain; on a tree, the joint its branch rides on
        parent = "base_link" if carrier < 0 else f"link{carrier + 1}"
        kind = "prismatic" if joint.prismatic else "revolute"
        lines += [f"  <joint name={quoteattr(joint.name)} type=\"{kind}\">", f'    <parent link="{parent}"/>', f'    <child link="{link}"/>',
                  f'    <origin xyz="{_vec(joint.translation)}" rpy="{_vec(_rpy(joint.rotation))}"/>',
                  f'    <axis xyz="{_vec(joint.axis)}"/>',
                  '    <limit lower="{:.17g}" upper="{:.17g}" effort="{:.17g}" velocity="{:.17g}"/>'.format(
                      *(_finite(x) for x in (robot.limits.q_min[j], robot.limits.q_max[j], robot.limits.tau_max[j], robot.limits.dq_max[j]))),
                  f'    <dynamics damping="{fv:.17g}" friction="{fc:.17g}"/>']
        if joint.mimic is not None:  # it follows another joint, whose drive supplies its torque
            k, multiplier, offset = joint.mimic
            lines.append(f'    <mimic joint={quoteattr(robot.joints[k].name)} multiplier="{multiplier:.17g}" offset="{offset:.17g}"/>')
        extra = {k: v for k, v in terms.items() if k not in ("fc", "fv") and v != 0}
        if extra:
            lines.append("    <!-- dynid: drive terms URDF cannot hold, add them to the torques: "
                         + ", ".join(f"{k}{j + 1} = {v:.17g}" for k, v in extra.items()) + " -->")
        if robot.coulomb_velocity[j] > 0:
            lines.append(f"    <!-- dynid: Coulomb term tanh(dq/{robot.coulomb_velocity[j]:.6g}) instead of sign(dq) -->")
        lines.append("  </joint>")
    n_coupled = robot.transmission.n_coupled_params
    if n_coupled:
        names = robot.transmission.coupled_parameter_names
        lines.append("  <!-- dynid: coupled motors (not representable in URDF), add their torques: "
                     + ", ".join(f"{n} = {v:.17g}" for n, v in zip(names, fitted.transmission.coupled_values.ravel())) + " -->")
    lines += [f"  <!--{note}-->" for note in (position_offset_note(robot),) if note]
    lines += ['  <link name="flange"/>', '  <joint name="flange_fixed" type="fixed">', f'    <parent link="link{robot.n_dof}"/>',
              '    <child link="flange"/>',
              f'    <origin xyz="{_vec(robot.tool_translation)}" rpy="{_vec(_rpy(robot.tool_rotation))}"/>', "  </joint>", "</robot>", ""]
    return "\n".join(lines)


def _world_from_base(gravity: np.ndarray) -> np.ndarray | None:
    """The rotation world ← base that turns the model's gravity to -z of world (Rodrigues' formula), None where it
    points there already."""
    g = np.asarray(gravity, dtype=float)
    norm = float(np.linalg.norm(g))
    if norm == 0.0:
        return None
    a, b = g / norm, np.array([0.0, 0.0, -1.0])
    if np.allclose(a, b, atol=1e-12):
        return None
    if np.allclose(a, -b, atol=1e-12):  # straight up: half a turn about x
        return np.diag([1.0, -1.0, -1.0])
    axis = np.cross(a, b)
    s, c = float(np.linalg.norm(axis)), float(a @ b)
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]]) / s
    return np.eye(3) + s * k + (1.0 - c) * (k @ k)


COUPLED_TENDON = "dynid_motor_{motor}"
"""The name of the MJCF fixed tendon that holds a coupled motor's friction (:func:`coupled_tendons`)."""


def coupled_tendons(robot: Robot, fitted: Robot) -> tuple[list, np.ndarray, dict] | None:
    """The MJCF fixed tendons that hold the coupled motors' friction (a coupled wrist, :mod:`dynid.model.transmission`):
    per coupled motor ``k`` with ratios ``c``, a tendon of length ``c·q`` with ``damping = fvm_k`` and
    ``frictionloss = fcm_k``. MuJoCo's tendon adds ``fvm·c cᵀ q̇ + fcm·c·sign(c·q̇)``; dynid's viscous column holds the
    off-diagonal part of the first (the diagonal is in the joints' ``fv``), so the joints' damping is written less
    ``fvm·c_j²``. The motor's inertia ``Iam`` stays a comment: its diagonal share is in the joints' ``Ia``, which the
    physically consistent estimate may hold at 0 (a joint's armature would then be negative).

    Parameters
    ----------
    robot : Robot
    fitted : Robot
        ``robot`` with the values to write (:func:`_exportable`).

    Returns
    -------
    (tendons, damping, left) or None
        ``tendons``: per motor its attributes and its ``(joint name, coef)`` pairs; ``damping``: (n_dof,) the joints'
        damping to write; ``left``: the coupled parameters the tendons do not hold, name -> value. None without
        coupled motors, or where a joint's damping would be negative (the coupling then stays a comment).
    """
    tr = robot.transmission
    if not tr.n_coupled_params or not {"fvm", "fcm"} & set(tr.coupled_terms):
        return None
    damping = np.array(dict(zip(robot.drive_terms, fitted.drive.T)).get("fv", np.zeros(robot.n_dof)), dtype=float)
    tendons, left = [], {}
    for k, values in zip(tr.coupled_motors, fitted.transmission.coupled_values):
        c = tr.ratios(k)
        value = dict(zip(tr.coupled_terms, values))
        damping -= value.get("fvm", 0.0) * c**2
        left.update({f"{t}{k + 1}": v for t, v in value.items() if t not in ("fvm", "fcm") and v != 0})
        attributes = {"name": COUPLED_TENDON.format(motor=k + 1), "damping": f"{value.get('fvm', 0.0):.17g}",
                      "frictionloss": f"{value.get('fcm', 0.0):.17g}"}
        tendons.append((attributes, [(robot.joints[j].name, float(c[j])) for j in np.flatnonzero(c)]))
    if np.any(damping < 0):
        return None
    return tendons, damping, left


@keyword_only_after_data
def mjcf_from_robot(robot: Robot | str | Path, phi: np.ndarray | None = None, *, name: str | None = None,
                    offsets_held: bool = False) -> str:
    """MuJoCo MJCF text of a robot with given standard parameters.

    Bodies are nested at dynid's joint frames (a branch's in the body of the joint it rides on); each carries its mass, centre of mass and full inertia about it
    (``<inertial fullinertia>``); each hinge carries ``armature`` (rotor inertia ``Ia``), ``damping`` (viscous ``fv``)
    and ``frictionloss`` (Coulomb ``fc``); a coupled motor's friction is a fixed tendon (:func:`coupled_tendons`). What
    MuJoCo cannot represent is stated in comments: the torque offset (unless ``offsets_held``), the Stribeck term, a
    smooth Coulomb term, and a coupled motor's inertia. MuJoCo's ``frictionloss`` is a dry-friction
    *constraint*: it matches ``fc·sign(q̇)`` while the joint slides, but its force in ``mj_inverse`` comes from the
    constraint solver, so only the other terms reproduce dynid's torques exactly (see the round-trip test); its
    ``solreffriction`` is written as stiff as MuJoCo's default 2 ms step allows (:data:`FRICTION_TIME_STEPS`). Massless
    links and point masses get MuJoCo's smallest mass and inertia (``boundmass``, ``boundinertia`` of 1e-9); a full
    inertia at the limit of a real link (a point mass, a thin rod) is written as MuJoCo loads it
    (:func:`mujoco_inertia`).

    Parameters
    ----------
    robot : Robot, str or Path
        A built-in robot's name or a description's path is loaded (:func:`dynid.model.loading.as_robot`).
    phi : (n_params,) array, optional
        Standard parameters (the robot's nominal ones by default).
    name : str, optional
        The model's name (the robot's by default).
    offsets_held : bool
        Hold the torque offsets as actuators of constant bias (:func:`offset_actuators`) instead of comments.

    Returns
    -------
    str
        An MJCF document.

    Raises
    ------
    ConfigError
        As :func:`urdf_from_robot`.
    """
    robot = as_robot(robot)
    import pinocchio as pin

    fitted = _exportable(robot, phi)
    coupled = coupled_tendons(robot, fitted)
    g = np.asarray(robot.gravity, dtype=float)
    lines = [f"<!-- written by dynid from robot {robot.name!r}: identified inertial and friction parameters -->",
             f"<mujoco model={quoteattr(name or robot.name)}>",
             '  <compiler angle="radian" autolimits="true" boundmass="1e-9" boundinertia="1e-9"/>',
             f'  <option gravity="{_vec(g)}"/>', "  <worldbody>"]
    parents = robot.parents
    depth = [0] * robot.n_dof
    for j in range(robot.n_dof):  # a body's depth in the tree (j along a serial chain)
        depth[j] = 0 if parents[j] < 0 else depth[parents[j]] + 1
    closing: list[tuple[int, str]] = []  # bodies still open: (joint, line), innermost last
    for j, joint in enumerate(robot.joints):
        while closing and closing[-1][0] != parents[j]:  # a branch ends: close up to the body this joint rides on
            lines.append(closing.pop()[1])
        indent = "    " + "  " * depth[j]
        q = pin.Quaternion(np.asarray(joint.rotation, dtype=float))
        mass, com, inertia = physical_from_inertial(fitted.inertial[j])
        inertia = mujoco_inertia(inertia)
        terms = dict(zip(robot.drive_terms, fitted.drive[j]))
        if coupled is not None:  # the coupled motors' viscous diagonal goes with their tendons
            terms["fv"] = coupled[1][j]
        lo, hi = robot.limits.q_min[j], robot.limits.q_max[j]
        limit = f' range="{lo:.17g} {hi:.17g}"' if np.isfinite(lo) and np.isfinite(hi) else ""
        lines += [f'{indent}<body name="link{j + 1}" pos="{_vec(joint.translation)}" quat="{q.w:.17g} {q.x:.17g} {q.y:.17g} {q.z:.17g}">',
                  f'{indent}  <joint name={quoteattr(joint.name)} type="{"slide" if joint.prismatic else "hinge"}" '
                  f'axis="{_vec(joint.axis)}"{limit} '
                  f'armature="{terms.get("Ia", 0.0):.17g}" damping="{terms.get("fv", 0.0):.17g}" '
                  f'frictionloss="{terms.get("fc", 0.0):.17g}" solreffriction="{friction_solref(0.002)}"/>',
                  f'{indent}  <inertial pos="{_vec(com)}" mass="{max(mass, 0.0):.17g}" fullinertia="{inertia[0, 0]:.17g} '
                  f'{inertia[1, 1]:.17g} {inertia[2, 2]:.17g} {inertia[0, 1]:.17g} {inertia[0, 2]:.17g} {inertia[1, 2]:.17g}"/>']
        extra = {k: v for k, v in terms.items() if k not in ("Ia", "fc", "fv", *(("offset",) if offsets_held else ())) and v != 0}
        if extra:
            lines.append(f"{indent}  <!-- dynid: terms MJCF cannot hold, add them to the torques: "
                         + ", ".join(f"{k}{j + 1} = {v:.17g}" for k, v in extra.items()) + " -->")
        if robot.coulomb_velocity[j] > 0:
            lines.append(f"{indent}  <!-- dynid: Coulomb term tanh(dq/{robot.coulomb_velocity[j]:.6g}) instead of sign(dq) -->")
        closing.append((j, f"{indent}</body>"))
    tip = "    " + "  " * (depth[-1] + 1)  # the tool frame rides on the last joint (the last branch's tip)
    q = pin.Quaternion(np.asarray(robot.tool_rotation, dtype=float))
    lines.append(f'{tip}<site name="flange" pos="{_vec(robot.tool_translation)}" quat="{q.w:.17g} {q.x:.17g} {q.y:.17g} {q.z:.17g}"/>')
    lines += [line for _, line in closing[::-1]]
    lines.append("  </worldbody>")
    if robot.followers:  # a joint that follows another: MuJoCo's joint equality q_j = offset + multiplier·q_k
        lines.append("  <equality>")
        for j in robot.followers:
            k, multiplier, offset = robot.joints[j].mimic  # type: ignore[misc]
            lines.append(f"    <joint joint1={quoteattr(robot.joints[j].name)} joint2={quoteattr(robot.joints[k].name)} "
                         f'polycoef="{offset:.17g} {multiplier:.17g} 0 0 0"/>')
        lines.append("  </equality>")
    actuators = offset_actuators(robot, fitted.standard_parameters()) if offsets_held else []
    if actuators:
        lines += ["  <actuator>"] + [f"    <general {' '.join(f'{k}={quoteattr(v)}' for k, v in a.items())}/>" for a in actuators] + ["  </actuator>"]
    if coupled is not None:
        lines.append("  <tendon>")
        for attributes, joints in coupled[0]:
            lines.append(f"    <fixed {' '.join(f'{k}={quoteattr(v)}' for k, v in attributes.items())}>")
            lines += [f'      <joint joint={quoteattr(name)} coef="{coef:.17g}"/>' for name, coef in joints]
            lines.append("    </fixed>")
        lines.append("  </tendon>")
        if coupled[2]:
            lines.append("  <!-- dynid: coupled motors' terms MJCF cannot hold, add their torques: "
                         + ", ".join(f"{n} = {v:.17g}" for n, v in coupled[2].items()) + " -->")
    elif robot.transmission.n_coupled_params:
        lines.append("  <!-- dynid: coupled motors (not representable here), add their torques: "
                     + ", ".join(f"{n} = {v:.17g}" for n, v in zip(robot.transmission.coupled_parameter_names,
                                                                  fitted.transmission.coupled_values.ravel()))
                     + " -->")
    lines += [f"  <!--{note}-->" for note in (position_offset_note(robot),) if note]
    lines += ["</mujoco>", ""]
    return "\n".join(lines)


FRICTION_TIME_STEPS = 2.0
"""The time constant of MuJoCo's dry-friction constraint (``solreffriction``) dynid writes, in the file's timesteps: the
smallest MuJoCo keeps without ``refsafe`` disabled, where its ``frictionloss`` force comes closest to
``frictionloss·sign(q̇)``. On the UR10e example's validation states, MuJoCo's own ``mj_inverse`` of the written file
was 9.9, 0.9, 1.0, 9.1, 11.9, 8.4 % of each joint's RMS torque off dynid's model with MuJoCo's default (0.02 s), and
4.4, 0.3, 0.4, 4.0, 5.3, 3.8 % with 2 steps (0.004 s); stiffer ones with ``refsafe`` disabled closed the gap in
``mj_inverse`` but made a resting wrist jitter at the default 2 ms step (benchmarks/NOTEBOOK.md)."""


def friction_solref(timestep: float) -> str:
    """The ``solreffriction`` dynid writes for a file stepping at ``timestep`` [s] (:data:`FRICTION_TIME_STEPS`).

    Parameters
    ----------
    timestep : float [s]

    Returns
    -------
    str
        ``"timeconst dampratio"``.
    """
    return f"{FRICTION_TIME_STEPS * timestep:.6g} 1"


BOUND_INERTIA = 1e-9
"""The smallest principal moment written to an MJCF ``fullinertia`` [kg·m²], the value of its ``boundinertia``."""


def mujoco_inertia(inertia: np.ndarray) -> np.ndarray:
    """An inertia about the centre of mass as MuJoCo loads it from ``fullinertia``: its principal moments at least
    :data:`BOUND_INERTIA` and each at most the sum of the other two, to 1e-10 relative.

    MuJoCo refuses a ``fullinertia`` that is not positive definite or breaks the triangle inequality (its
    ``boundinertia`` raises only a diagonal one, and ``balanceinertia`` only ``diaginertia``); a physically consistent
    estimate may hold a link at the limit of a real one (a point mass, a thin rod, a flat plate: the TX40's link 6 from
    the SDP, a simulated UR10e's wrist), whose MJCF then did not load. The change is within round-off for any other
    link.

    Parameters
    ----------
    inertia : (3, 3) array [kg·m²]

    Returns
    -------
    (3, 3) ndarray [kg·m²]
    """
    values, vectors = np.linalg.eigh(0.5 * (inertia + inertia.T))
    fixed = np.maximum(values, BOUND_INERTIA)
    fixed[2] = min(fixed[2], (fixed[0] + fixed[1]) * (1.0 - 1e-10))  # eigh sorts them: the largest is the last
    fixed[1] = max(fixed[1], fixed[0])
    if np.array_equal(fixed, values):
        return inertia
    return (vectors * fixed) @ vectors.T


def _finite(x: float) -> float:
    return float(x) if np.isfinite(x) else 1e6


OFFSET_ACTUATOR = "dynid_offset_{joint}"
"""The name of the MJCF actuator that holds a joint's torque offset (:func:`offset_actuators`)."""


def offset_actuators(robot: Robot, phi: np.ndarray) -> list[dict[str, str]]:
    """The MJCF actuators that hold the torque offsets of ``phi``: per joint with a non-zero offset, a ``general``
    actuator of gain 0 and constant bias ``-offset`` (MuJoCo: force = gain·ctrl + bias), so that a torque that includes
    the offset, as the measured torques do, moves the simulated arm as it moves the real one (issue "Every assurance
    checked on what the user meets", item 3). Their ``ctrl`` does nothing; :func:`dynid.io.exported.replay.mjcf_replay` and
    ``mjcf_forward`` subtract their force from the torque the file needs.

    Parameters
    ----------
    robot : Robot
    phi : (n_params,) array
        Standard parameters.

    Returns
    -------
    list of dict
        Each actuator's attributes, in joint order.
    """
    names = list(robot.parameter_names)
    out = []
    for j, joint in enumerate(robot.joints):
        value = float(phi[names.index(f"offset{j + 1}")]) if f"offset{j + 1}" in names else 0.0
        if value != 0.0:
            out.append({"name": OFFSET_ACTUATOR.format(joint=joint.name), "joint": joint.name, "gainprm": "0",
                        "biastype": "affine", "biasprm": f"{-value:.17g} 0 0"})
    return out


def position_offset_note(robot: Robot) -> str:
    """A written description's comment where the robot sets joints' position offsets, else "": its joint angles are
    the description's, a joint's encoder angle plus the offset (as dynid reads a log; a controller's angles take it
    off: :meth:`dynid.model.transmission.Transmission.logged_positions`).

    Parameters
    ----------
    robot : Robot

    Returns
    -------
    str
        The comment's text, spaces about it.
    """
    turned = joint_angles_text(robot.transmission.position_offset)
    return (f" dynid: the joint angles of this file are the description's: a joint's encoder angle (what a log and the "
            f"controller hold) plus its position_offset ({turned}) " if turned else "")

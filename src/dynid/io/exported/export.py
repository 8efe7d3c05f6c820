"""The identified model handed over: URDF (and MuJoCo MJCF) of a robot with its identified inertial and
friction parameters.

The URDF is generated from dynid's own kinematic description (the joint frames every robot has, whether
it came from a DH table or a URDF), so the same writer serves every robot: a chain ``base_link →
link1 → … → linkN`` with revolute joints at dynid's joint frames and a fixed ``flange`` link at the tool
frame. Each link's ``<inertial>`` holds the mass, the centre of mass and the inertia about it in the link
frame (:func:`dynid.model.spatial.physical_from_inertial`); each joint's ``<dynamics>`` holds the
viscous (``damping``) and Coulomb (``friction``) coefficients. URDF has no field for the rotor inertia,
a torque offset, the Stribeck term or a coupled motor: they are written as XML comments on the joint,
and the model's torques then need them added (``τ = RNEA + Ia·q̈ + fc·sign(q̇) + fv·q̇ + offset``).
Visual and collision geometry is not copied: for a robot described by a URDF, the identified values are
written into the user's own file instead (:func:`dynid.io.exported.urdf_write_back.urdf_written_back`).

Only physically consistent parameters are exported: a URDF with a negative mass or an impossible
inertia makes simulators fail or behave wrongly.
"""

from __future__ import annotations

import re
from html import escape
from pathlib import Path
from typing import Any

import numpy as np

from ..._util.keywords import keyword_only_after_data
from ...conventions import joint_angles_text
from ...exceptions import ConfigError
from ...model.friction_model import robot_from_settings
from ...model.loading import as_robot
from ...model.robot import Robot
from ...model.spatial import is_physically_consistent, physical_from_inertial, physical_problems
from ..results import LARGEST_VALUE, stored_standard

CONSISTENCY_TOL = 1e-7
"""Smallest pseudo-inertia eigenvalue tolerated (the SDP solver's accuracy) [kg·m², kg]."""


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
    fitted = robot.with_parameters(phi)
    for j, joint in enumerate(robot.joints):
        if not is_physically_consistent(fitted.inertial[j], tol=CONSISTENCY_TOL):
            rule = (physical_problems(fitted.inertial[j]) or ["a pseudo-inertia that is not positive semidefinite"])[0]
            raise ConfigError(f"export: link {j + 1} ({joint.name}): {rule}; only physically consistent parameters can be "
                              "exported (the physically consistent estimate of dynid identify is)")
        terms = dict(zip(robot.drive_terms, fitted.drive[j]))
        fc, fv = terms.get("fc", 0.0), terms.get("fv", 0.0)
        if fc < 0 or fv < 0:
            raise ConfigError(f"export: joint {j + 1}: negative friction (fc = {fc:.4g}, fv = {fv:.4g}) cannot be exported")
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
        parent = "base_link" if j == 0 else f"link{j}"
        kind = "prismatic" if joint.prismatic else "revolute"
        lines += [f"  <joint name={quoteattr(joint.name)} type=\"{kind}\">", f'    <parent link="{parent}"/>', f'    <child link="{link}"/>',
                  f'    <origin xyz="{_vec(joint.translation)}" rpy="{_vec(_rpy(joint.rotation))}"/>',
                  f'    <axis xyz="{_vec(joint.axis)}"/>',
                  '    <limit lower="{:.17g}" upper="{:.17g}" effort="{:.17g}" velocity="{:.17g}"/>'.format(
                      *(_finite(x) for x in (robot.limits.q_min[j], robot.limits.q_max[j], robot.limits.tau_max[j], robot.limits.dq_max[j]))),
                  f'    <dynamics damping="{fv:.17g}" friction="{fc:.17g}"/>']
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

    Bodies are nested at dynid's joint frames; each carries its mass, centre of mass and full inertia about it
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
    closing = []
    for j, joint in enumerate(robot.joints):
        indent = "    " + "  " * j
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
        closing.append(f"{indent}</body>")
    tip = "    " + "  " * robot.n_dof
    q = pin.Quaternion(np.asarray(robot.tool_rotation, dtype=float))
    lines.append(f'{tip}<site name="flange" pos="{_vec(robot.tool_translation)}" quat="{q.w:.17g} {q.x:.17g} {q.y:.17g} {q.z:.17g}"/>')
    lines += closing[::-1]
    lines.append("  </worldbody>")
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


def consistent_estimate(robot: Robot, results: dict, source: str = "results") -> tuple[Robot, np.ndarray]:
    """The robot and the physically consistent standard parameters stored in a results file.

    The robot carries the Coulomb smoothing it was identified with; the parameters are the ``standard_values`` of the
    results' physically consistent estimate.

    Parameters
    ----------
    robot : Robot
        The robot's description the results were identified for.
    results : dict
        A parsed ``results.json`` of ``dynid identify``.
    source : str
        Where the results come from, named in errors.

    Returns
    -------
    robot : Robot
    phi : (n_params,) ndarray
        Standard parameters, SI units.

    Raises
    ------
    ConfigError
        No physically consistent estimate in the results, results of another robot, or a set that did not pass the
        consistency check (the verdict says why).
    """
    found = stored_standard(results)
    if found is None:
        raise ConfigError(f"{source}: no physically consistent estimate to export; identify with "
                          '[estimation] estimators including "sdp"')
    label, values = found
    verdict = results.get("physically_consistent_verdict", {}).get(label, "yes")
    if verdict != "yes":
        raise ConfigError(f"{source}: the physically consistent estimate did not pass the consistency check ({verdict})")

    try:
        robot = robot_from_settings(robot, results.get("settings", {}))
    except (ValueError, KeyError, TypeError) as exc:
        raise ConfigError(f"{source}: {exc}") from None
    missing = [n for n in robot.parameter_names if n not in values]
    if missing:
        raise ConfigError(f"{source}: its standard parameters are not those of robot {robot.name!r} (missing {', '.join(missing[:4])})")
    for n in robot.parameter_names:
        v = values[n]
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v):
            raise ConfigError(f"{source}: estimates.{label}.standard_values.{n}: expected a finite number, got "
                              f"{'null' if v is None else repr(v)}")
    phi = np.array([float(values[n]) for n in robot.parameter_names])
    for n, v in zip(robot.parameter_names, phi):
        heavy = re.fullmatch(r"M\d+", n) is not None and not 0.0 <= v <= LARGEST_LINK_MASS
        if heavy or abs(v) > LARGEST_VALUE:
            what = (f"a link mass in [0, {LARGEST_LINK_MASS:g}] kg" if heavy else
                    f"a value within ±{LARGEST_VALUE:g} (SI units)")
            raise ConfigError(f"{source}: estimates.{label}.standard_values.{n}: expected {what}, got {float(v)!r}")
    return robot, phi


def file_parameters(robot: Robot, phi: np.ndarray, results: dict, source: str = "results", form: str = "URDF"
                    ) -> tuple[np.ndarray, str]:
    """The standard parameters a written URDF or MJCF holds, as the validation logs chose joint by joint for the estimate
    it is written from (results' ``diagnostics.file_terms``, :mod:`dynid.identification.file_terms`): the joints whose friction is folded hold the
    folded Coulomb and viscous pair and no Stribeck or load-dependent Coulomb term; in an MJCF, the torque offsets not
    held are 0 (those held become actuators' constant bias, :func:`offset_actuators`); a URDF keeps every offset, as
    its comments say.

    Parameters
    ----------
    robot : Robot
        As :func:`consistent_estimate` gives it.
    phi : (n_params,) array
        The physically consistent estimate's standard parameters.
    results : dict
        results.json.
    source : str
        Where the results come from, named in errors.
    form : {"URDF", "MJCF"}

    Returns
    -------
    phi : (n_params,) ndarray
        What the file holds (``phi`` itself where the results chose nothing).
    note : str
        What differs from dynid's model, for a comment in the file ("" where nothing does).

    Raises
    ------
    ConfigError
        A ``file_terms`` entry that is not a ``folded`` and an ``offset`` flag per joint, with a non-negative ``fc`` and
        ``fv`` per joint where a joint is folded.
    """
    out = np.array(phi, dtype=float)
    written, found = file_terms_entry(results)
    if found is None:
        return out, ""
    n = robot.n_dof
    try:
        folded = [j for j, f in enumerate(found["folded"]) if f is True]
        held = [j for j, f in enumerate(found["offset"]) if f is True]
        ok = len(found["folded"]) == len(found["offset"]) == n
        if folded:
            fc, fv = (np.array(found[k], dtype=float) for k in ("fc", "fv"))
            ok = ok and fc.shape == fv.shape == (n,) and bool(np.all(np.isfinite(fc + fv)) and np.all(fc >= 0) and np.all(fv >= 0))
    except (KeyError, TypeError, ValueError):
        ok = False
    if not ok:
        raise ConfigError(f"{source}: diagnostics.file_terms.{written}: expected folded and offset (true or false) for each of "
                          f"the {n} joints, and fc, fv (finite, >= 0) for each where one is folded")
    names = list(robot.parameter_names)
    for j in folded:
        for term in ("fc", "fv", "fst", "fcl"):
            if f"{term}{j + 1}" in names:
                out[names.index(f"{term}{j + 1}")] = {"fc": fc[j], "fv": fv[j]}.get(term, 0.0)
    said = []
    if folded:
        terms = " and ".join(found.get("terms") or ["Stribeck", "load-dependent Coulomb"])
        said.append(f"the friction of {_joints(folded)} holds its {terms} terms folded into the Coulomb and viscous "
                    "pair (the nearest pair on the identification log)")
    if form == "MJCF":
        left = [j for j in range(n) if j not in held and f"offset{j + 1}" in names and out[names.index(f"offset{j + 1}")] != 0]
        for j in left:
            out[names.index(f"offset{j + 1}")] = 0.0
        if held:
            said.append(f"the torque offsets of {_joints(held)} are held by actuators of constant bias "
                        f"({', '.join(OFFSET_ACTUATOR.format(joint=robot.joints[j].name) for j in held)})")
        if left:
            said.append(f"the torque offsets of {_joints(left)} are left out")
    if not said:
        return out, ""
    return out, ("dynid: " + "; ".join(said) + ", where the validation logs say that predicts the joint better; "
                 "dynid's own values are in results.json")


def file_terms_entry(results: dict) -> tuple[str, Any]:
    """The choice results.json holds of what the files hold (``diagnostics.file_terms``,
    :mod:`dynid.identification.file_terms`) for the estimate they are written from (:func:`stored_standard`).

    Parameters
    ----------
    results : dict
        results.json.

    Returns
    -------
    label : str
        The estimate the files are written from ("" where there is none).
    entry : object or None
        Its entry as stored (checked by :func:`file_parameters`); None where the results chose nothing for it.
    """
    chosen = (results.get("diagnostics") or {}).get("file_terms")
    written = stored_standard(results)
    if written is None or not isinstance(chosen, dict):
        return "" if written is None else written[0], None
    return written[0], chosen.get(written[0])


def _joints(indices) -> str:
    return ", ".join(f"J{j + 1}" for j in indices)


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


def with_note(text: str, note: str) -> str:
    """A written URDF or MJCF with ``note`` as a comment after its root element.

    Parameters
    ----------
    text : str
        The file's text.
    note : str
        The comment ("" leaves the text as it is; ``--`` is written ``-``, which an XML comment cannot hold).

    Returns
    -------
    str
    """
    if not note:
        return text
    return text.rstrip("\n") + f"\n<!-- {note.replace('--', '-')} -->\n"


LARGEST_LINK_MASS = 1e5
"""kg: a robot link's mass above this in a results file is no identification (the largest industrial arms' links
weigh a few tonnes); export refuses it rather than write it."""

def nominal_warning(results: dict) -> str | None:
    """One line when the exported (physically consistent) estimate predicted some joints of the validation logs worse
    than the description's nominal model (the gate of ``dynid identify``), naming them; or when it is the robot file's
    own values (``dynid identify`` kept them as the main estimate: its log could not improve them), so that the file
    written is not taken for an identified model; None otherwise.

    Parameters
    ----------
    results : dict
        A parsed ``results.json`` of ``dynid identify``.

    Returns
    -------
    str or None
    """
    found = stored_standard(results)
    nominal = (results.get("diagnostics") or {}).get("nominal_set")
    if found is None or not isinstance(nominal, str):
        return None
    label, worse = found[0], []
    if label == nominal:
        return (f"the estimate written is {nominal}, the robot file's own values: dynid identify kept them as the main "
                "estimate, as its log could not improve them (its verdict says what would)")
    for v in results.get("validation") or []:
        metrics = v.get("metrics") or {}
        if label not in metrics or nominal not in metrics:
            continue
        own, nom = metrics[label].get("relative_error") or [], metrics[nominal].get("relative_error") or []
        meaningful = v.get("relative_error_meaningful") or [True] * len(own)
        for j, (a, b, ok) in enumerate(zip(own, nom, meaningful)):
            if ok and a is not None and b is not None and a > b:
                worse.append(f"J{j + 1} of {v.get('name')} ({a:.3g} % against {b:.3g} %)")
    if not worse:
        return None
    return (f"{label} predicts {', '.join(worse[:4])}{f' and {len(worse) - 4} more' if len(worse) > 4 else ''} worse "
            f"than the description's nominal model ({nominal}): keep the nominal values for those joints, or identify "
            "on a log that excites them")


READINESS_KINDS = ("columns", "sign", "scale", "order", "angles", "gravity", "rate")
"""Findings of ``dynid identify``'s verdict that say the log itself is wrong (the torques' sign, unit or gain, channels
swapped, angles or a mounting that do not match the robot file, its sample rate): a model fitted to it is exported with
a warning."""


def verdict_warnings(results: dict) -> list[str]:
    """One line per finding of ``dynid identify``'s verdict that says the log the model was fitted to is wrong
    (:data:`READINESS_KINDS`), for ``dynid export`` to repeat.

    Parameters
    ----------
    results : dict
        A parsed ``results.json`` of ``dynid identify``.

    Returns
    -------
    list of str
    """
    what = {"angles": "angles", "gravity": "a mounting", "rate": "a sample rate"}
    return [f"the model was fitted to {what.get(str(f.get('kind')), 'torques')} dynid identify doubts: "
            f"{f.get('text')}"
            for f in results.get("findings") or [] if isinstance(f, dict) and f.get("kind") in READINESS_KINDS]


def withheld_files(results: dict) -> str | None:
    """Why ``dynid identify`` writes no URDF or MJCF of a model: the identification log is read otherwise than the robot
    file (a :data:`READINESS_KINDS` finding of its own, not only of a validation log), so the model fitted to it is not
    the robot's; ``dynid export`` still writes it when asked, with the findings as warnings.

    Parameters
    ----------
    results : dict
        A parsed ``results.json`` of ``dynid identify`` (its ``findings``, each ``kind`` and ``text``).

    Returns
    -------
    str or None
        One line, or None where the files are written.
    """
    name = str((results.get("identification") or {}).get("name") or "identification")
    kinds = sorted({str(f.get("kind")) for f in results.get("findings") or [] if isinstance(f, dict)
                    and f.get("kind") in READINESS_KINDS and str(f.get("text", "")).startswith(f"{name}:")})
    if not kinds:
        return None
    what = {"columns": "columns that are not its torques", "sign": "a torque's sign", "scale": "the torques' unit or drive gains", "order": "torque columns swapped",
            "angles": "its angles", "gravity": "the mounting", "rate": "its sample rate"}
    return (f"no URDF or MJCF written: the log {name} is read otherwise than the robot file "
            f"({', '.join(what[k] for k in kinds)}: the verdict names the setting that fixes it), so a model fitted to "
            "it is not the robot's; identify again with that setting (dynid export CONFIG --urdf FILE writes this one "
            "all the same)")


@keyword_only_after_data
def urdf_from_results(robot: Robot | str | Path, results: dict, *, source: str = "results") -> str:
    """URDF of the physically consistent estimate of a ``results.json`` (:func:`consistent_estimate`), its friction as
    the results chose to write it (:func:`file_parameters`).

    Parameters
    ----------
    robot : Robot, str or Path
        The robot's description the results were identified for (a built-in robot's name or a description's path is
        loaded: :func:`dynid.model.loading.as_robot`).
    results : dict
        A parsed ``results.json`` of ``dynid identify``.
    source : str
        Where the results come from, named in errors.

    Returns
    -------
    str
        A URDF document.

    Raises
    ------
    ConfigError
        As :func:`consistent_estimate`.
    """
    fitted, phi = consistent_estimate(as_robot(robot), results, source)
    phi, note = file_parameters(fitted, phi, results, source)
    return with_note(urdf_from_robot(fitted, phi), note)


@keyword_only_after_data
def mjcf_from_results(robot: Robot, results: dict, *, source: str = "results") -> str:
    """MJCF of the physically consistent estimate of a ``results.json`` (:func:`consistent_estimate`), its friction as
    the results chose to write it (:func:`file_parameters`).

    Parameters
    ----------
    robot : Robot
        The robot's description the results were identified for.
    results : dict
        A parsed ``results.json`` of ``dynid identify``.
    source : str
        Where the results come from, named in errors.

    Returns
    -------
    str
        An MJCF document.

    Raises
    ------
    ConfigError
        As :func:`consistent_estimate`.
    """
    fitted, phi = consistent_estimate(robot, results, source)
    phi, note = file_parameters(fitted, phi, results, source, "MJCF")
    return with_note(mjcf_from_robot(fitted, phi, offsets_held=True), note)


MOVED_MASS = 0.5
"""A link whose identified mass differs from its nominal one by more than this fraction is said in the export."""
MOVED_COM = 0.1
"""[m] A link whose identified centre of mass lies this far from its nominal one is said in the export."""


def moved_far(link: str, mass: float, com: np.ndarray, nominal_mass: float, nominal_com: np.ndarray,
              form: str) -> str | None:
    """A line saying that a link's written values are far from its description's own, or None when they are not
    (mass by over :data:`MOVED_MASS`, centre of mass by over :data:`MOVED_COM` m).

    Parameters
    ----------
    link : str
    mass, nominal_mass : float [kg]
    com, nominal_com : (3,) arrays [m]
        Centres of mass, in one frame.
    form : str
        "URDF" or "MJCF", for the line.

    Returns
    -------
    str or None
    """
    if abs(mass - nominal_mass) <= MOVED_MASS * max(nominal_mass, 1e-12) and np.linalg.norm(com - nominal_com) <= MOVED_COM:
        return None
    def point(v):
        return " ".join(f"{x:.3g}" for x in v)

    return (f"{link}: mass {mass:.4g} kg (the {form}'s {nominal_mass:.4g}), centre of mass at ({point(com)}) m "
            f"(the {form}'s ({point(nominal_com)}))")


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


def identified_header(file: str, replaced: str, estimate: str, moved: list[str], form: str) -> str:
    """The header comment of a written-back description: what holds identified values, and what they are.

    Parameters
    ----------
    file : str
        The description's file name.
    replaced : str
        Which elements hold identified values.
    estimate : str
        What the values are.
    moved : list of str
        :func:`moved_far` lines.
    form : str
        "URDF" or "MJCF".

    Returns
    -------
    str
        The comment's text.
    """
    header = [f" written by dynid into {file}: {replaced} hold {estimate}; every other element is the original's.",
              "dynid identifies base parameters: the values written are one physically consistent choice among the many",
              "that predict the same torques (the split between a link and its motor's rotor inertia, and what the",
              "experiment does not excite, are that choice's). Use them to simulate or control the robot, not as each",
              "link's measured mass."]
    if moved:
        header += [f"Far from the {form}'s own values (a choice, as said above, or a description to check):"] + moved
    return "\n     ".join(header) + " "


def _replace(parent, tag: str, new) -> None:
    """Put ``new`` where ``parent``'s ``tag`` child is (or first), keeping the surrounding whitespace."""
    old = parent.find(tag)
    if old is not None:
        index = list(parent).index(old)
        new.tail = old.tail
        parent.remove(old)
        parent.insert(index, new)
    else:
        new.tail = parent.text if parent.text and not parent.text.strip() else "\n    "
        parent.insert(0, new)


def payload_files(payload, robot: Robot, parent: str) -> tuple[str, str]:
    """A payload (:class:`dynid.identification.payload.Payload`) as a URDF link on a fixed joint and as an MJCF body,
    each to paste into the arm's file: the body sits at the flange (the robot's tool frame in its last link), its
    inertial in the flange's frame.

    Parameters
    ----------
    payload : Payload
    robot : Robot
        Its tool frame is the flange.
    parent : str
        The URDF link the payload is fixed to (the arm's last link).

    Returns
    -------
    (str, str)
        The URDF snippet and the MJCF snippet.
    """
    import pinocchio as pin

    inertia = mujoco_inertia(np.asarray(payload.inertia, dtype=float))
    rotation = np.asarray(robot.tool_rotation, dtype=float)
    q = pin.Quaternion(rotation)
    head = (f"identified by dynid payload: {payload.mass:.6g} kg (σ {payload.mass_std:.2g}); "
            f"not determined by the log, kept at a point mass's values: {', '.join(payload.not_determined) or 'none'}")
    urdf = "\n".join([
        f"<!-- {head} -->",
        '<joint name="payload_joint" type="fixed">',
        f"  <parent link={quoteattr(parent)}/>",
        '  <child link="payload"/>',
        f'  <origin xyz="{_vec(robot.tool_translation)}" rpy="{_vec(_rpy(rotation))}"/>',
        "</joint>",
        '<link name="payload">',
        "  <inertial>",
        f'    <origin xyz="{_vec(payload.com)}" rpy="0 0 0"/>',
        f'    <mass value="{payload.mass:.17g}"/>',
        f'    <inertia ixx="{inertia[0, 0]:.17g}" ixy="{inertia[0, 1]:.17g}" ixz="{inertia[0, 2]:.17g}" '
        f'iyy="{inertia[1, 1]:.17g}" iyz="{inertia[1, 2]:.17g}" izz="{inertia[2, 2]:.17g}"/>',
        "  </inertial>",
        "</link>", ""])
    mjcf = "\n".join([
        f"<!-- {head}; put this body inside the arm's last body -->",
        f'<body name="payload" pos="{_vec(robot.tool_translation)}" quat="{q.w:.17g} {q.x:.17g} {q.y:.17g} {q.z:.17g}">',
        f'  <inertial pos="{_vec(payload.com)}" mass="{payload.mass:.17g}" fullinertia="{inertia[0, 0]:.17g} '
        f'{inertia[1, 1]:.17g} {inertia[2, 2]:.17g} {inertia[0, 1]:.17g} {inertia[0, 2]:.17g} {inertia[1, 2]:.17g}"/>',
        "</body>", ""])
    return urdf, mjcf

"""Derivatives of the regressor and of the tool point with respect to the joint state.

Used by the excitation design (:mod:`dynid.excitation.design`): the gradient of cond(W_base) or of the
torques with respect to the Fourier coefficients follows by the chain rule from these per-sample
derivatives, ``dY/dc = Σ_s dY/ds · ds/dc`` with ``s`` ranging over ``q_i, dq_i, ddq_i``, instead of
finite differences of the whole design problem per coefficient.

The regressor is linear in ``ddq`` (difference of step 1, exact) and quadratic in ``dq`` (central
difference, exact up to round-off); in ``q`` it is smooth, and a central difference of step
``1e-6 rad`` has a relative error of about 1e-9. The drive/friction columns take their analytic
derivatives from :mod:`dynid.friction` (``sign(dq)``: 0, its derivative almost everywhere).
"""

from __future__ import annotations

import numpy as np

from .._util.checks import check_states, check_trajectory_array
from ..friction import TERMS, Velocities
from ..model.robot import Robot
from .kinematics import forward_kinematics
from .regressor import regressor

Q_STEP = 1e-6
"""Central-difference step in the joint positions [rad]."""


def coulomb_columns(robot: Robot) -> np.ndarray:
    """Indices of the standard parameters multiplying ``sign`` of a coupled motor's velocity (``fcm#``).

    Parameters
    ----------
    robot : Robot

    Returns
    -------
    (k,) int ndarray
    """
    return np.array([k for k, n in enumerate(robot.parameter_names) if n.startswith("fcm")], dtype=int)


def regressor_state_derivatives(robot: Robot, q, dq, ddq) -> tuple[np.ndarray, np.ndarray]:
    """The regressor and its derivatives with respect to every joint's position, velocity, acceleration.

    Parameters
    ----------
    robot : Robot
    q, dq, ddq : (N, n_dof) arrays [rad, rad/s, rad/s²]

    Returns
    -------
    Y : (N, n_dof, n_params) array
        :func:`dynid.dynamics.regressor.regressor` at the samples.
    dY : (3, n_dof, N, n_dof, n_params) array
        ``dY[0, i]`` = ∂Y/∂q_i, ``dY[1, i]`` = ∂Y/∂dq_i, ``dY[2, i]`` = ∂Y/∂ddq_i (per sample; sample k's
        regressor depends on sample k's state only).

    Raises
    ------
    ShapeError
        If an input is not (N, n_dof) or holds NaN.
    """
    n = robot.n_dof
    q, dq, ddq, n_s = check_states(q, dq, ddq, n)
    eye = np.eye(n)
    # one batched regressor call: base state, q ± h e_i, dq ± e_i, ddq + e_i
    blocks_q = [q] + [q + s * Q_STEP * eye[i] for i in range(n) for s in (1, -1)] + [q] * (3 * n)
    blocks_dq = [dq] + [dq] * (2 * n) + [dq + s * eye[i] for i in range(n) for s in (1, -1)] + [dq] * n
    blocks_ddq = [ddq] + [ddq] * (4 * n) + [ddq + eye[i] for i in range(n)]
    y_all = regressor(robot, np.concatenate(blocks_q), np.concatenate(blocks_dq), np.concatenate(blocks_ddq))
    y_all = y_all.reshape(5 * n + 1, n_s, n, robot.n_params)
    y = y_all[0]
    d = np.empty((3, n, n_s, n, robot.n_params))
    d[0] = (y_all[1:2 * n + 1:2] - y_all[2:2 * n + 1:2]) / (2 * Q_STEP)
    d[1] = (y_all[2 * n + 1:4 * n + 1:2] - y_all[2 * n + 2:4 * n + 1:2]) / 2.0
    d[2] = y_all[4 * n + 1:] - y
    fc = coulomb_columns(robot)
    d[:2, ..., fc] = 0.0
    if robot.drive_terms:  # drive columns: analytic derivatives from the friction table
        d_q, d_dq, d_ddq = drive_column_derivatives(robot.drive_terms, q, dq, robot.friction_velocities)
        npj = robot.n_params_per_joint
        for i in range(n):
            block = slice(i * npj + 10, (i + 1) * npj)
            d[:, :, :, i, block] = 0.0
            d[0, i, :, i, block] = d_q[:, i] * robot.drive_mask[i]
            d[1, i, :, i, block] = d_dq[:, i] * robot.drive_mask[i]
            d[2, i, :, i, block] = d_ddq[:, i] * robot.drive_mask[i]
    return y, d


def drive_column_derivatives(terms, q: np.ndarray, dq: np.ndarray, velocities: Velocities
                             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Derivatives of the drive columns with respect to each joint's own position, velocity and acceleration.

    Parameters
    ----------
    terms : sequence of str
        Drive term names (:data:`dynid.friction.TERMS`).
    q, dq : (N, n_dof) arrays
        [rad], [rad/s].
    velocities : dynid.friction.Velocities

    Returns
    -------
    d_q, d_dq, d_ddq : (N, n_dof, len(terms)) ndarray
        Each column's derivative (the unit of the column per rad, rad/s and rad/s²).
    """
    q, dq = np.asarray(q, dtype=float), np.asarray(dq, dtype=float)
    d_q = np.stack([np.zeros_like(dq) if x.d_q is None else x.d_q(q, dq, velocities) for x in (TERMS[t] for t in terms)], axis=-1)
    d_dq = np.stack([TERMS[t].d_dq(q, dq, velocities) for t in terms], axis=-1)
    d_ddq = np.broadcast_to(np.array([TERMS[t].d_ddq for t in terms]), dq.shape + (len(terms),))
    return d_q, d_dq, d_ddq


def frames_and_axes(robot: Robot, q) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every link frame's rotation and origin in the base frame, and every joint's axis there.

    Parameters
    ----------
    robot : Robot
    q : (N, n_dof) array [rad]

    Returns
    -------
    rots : (N, n_dof, 3, 3) array
    orig : (N, n_dof, 3) array [m]
    axes : (N, 3, n_dof) array
        Unit axes, one column per joint.
    """
    q = check_trajectory_array(q, robot.n_dof, "q")
    rots, orig = forward_kinematics(robot, q)
    return rots, orig, np.stack([rots[:, j] @ robot.joints[j].axis for j in range(robot.n_dof)], axis=2)


def point_motion(robot: Robot, axes: np.ndarray, lever: np.ndarray) -> np.ndarray:
    """How points riding on the arm move with each joint: ``∂p/∂q_j = z_j × (p - o_j)`` about a revolute joint,
    ``z_j`` along a prismatic one (whichever link a point rides on: the caller keeps the joints before it).

    Parameters
    ----------
    robot : Robot
    axes : (N, 3, n_dof) array
        The joints' unit axes in the base frame (:func:`frames_and_axes`).
    lever : (N, m, n_dof, 3) array [m]
        Each point less each joint frame's origin, ``p - o_j``.

    Returns
    -------
    (N, m, n_dof, 3) ndarray [m/rad, or m/m]
    """
    z = np.moveaxis(axes, 1, 2)[:, None]  # (N, 1, n_dof, 3)
    moved = np.cross(z, lever)
    slides = robot.prismatic
    if slides.any():
        moved[:, :, slides] = np.broadcast_to(z[:, :, slides], moved[:, :, slides].shape)
    return moved


def origins_jacobian(robot: Robot, q) -> tuple[np.ndarray, np.ndarray]:
    """Every joint frame's origin and its positional Jacobian ``∂o_k/∂q_j = z_j × (o_k - o_j)`` for the joints ``j``
    before ``k`` (a revolute joint does not move its own frame's origin), ``z_j`` for ``k`` too (a prismatic joint);
    zero for the joints that do not carry ``k`` (:attr:`dynid.model.robot.Robot.carries`: another arm's).

    Parameters
    ----------
    robot : Robot
    q : (N, n_dof) array [rad]

    Returns
    -------
    o : (N, n_dof, 3) array [m]
        Origins in the base frame.
    J : (N, n_dof, 3, n_dof) array [m/rad]
    """
    _, orig, axes = frames_and_axes(robot, q)
    lever = orig[:, :, :, None] - orig.transpose(0, 2, 1)[:, None]  # (N, k, 3, j): o_k - o_j
    jac = np.cross(axes[:, None], lever, axis=2)
    carries = robot.carries
    jac *= (carries & ~np.eye(robot.n_dof, dtype=bool)).T[None, :, None, :]  # only the joints before frame k
    for j in np.flatnonzero(robot.prismatic):  # a prismatic joint moves its own frame and those it carries along z_j
        jac[..., j] = np.where(carries[j][None, :, None], axes[:, None, :, j], jac[..., j])
    return orig, jac


def tool_jacobian(robot: Robot, q) -> tuple[np.ndarray, np.ndarray]:
    """Tool point and its positional Jacobian ``∂p/∂q_j = z_j × (p - o_j)`` (revolute joints), ``z_j`` (prismatic).

    Parameters
    ----------
    robot : Robot
    q : (N, n_dof) array [rad]

    Returns
    -------
    p : (N, 3) array [m]
        Tool (flange) point in the base frame.
    J : (N, 3, n_dof) array [m/rad, or m/m for a prismatic joint]
    """
    rots, orig, axes = frames_and_axes(robot, q)
    p = orig[:, -1] + rots[:, -1] @ robot.tool_translation
    lever = p[:, :, None] - orig.transpose(0, 2, 1)  # (N, 3, n)
    jac = np.cross(axes, lever, axis=1)
    slides = robot.prismatic
    jac[:, :, slides] = axes[:, :, slides]
    if robot.is_tree:  # the tool rides on the last joint: the other branches' joints do not move it
        jac *= robot.carries[:, -1][None, None, :]
    return p, jac


def tips_jacobian(robot: Robot, q) -> tuple[np.ndarray, np.ndarray]:
    """Each branch's tip (:func:`dynid.dynamics.kinematics.tip_positions`) and its positional Jacobian: the tool point's
    (:func:`tool_jacobian`) last, another branch's tip its link origin's (:func:`origins_jacobian`).

    Parameters
    ----------
    robot : Robot
    q : (N, n_dof) array [rad]

    Returns
    -------
    p : (N, n_tips, 3) array [m]
    J : (N, n_tips, 3, n_dof) array [m/rad, or m/m for a prismatic joint]
    """
    tool, jt = tool_jacobian(robot, q)
    if not robot.is_tree:
        return tool[:, None], jt[:, None]
    orig, jo = origins_jacobian(robot, q)
    p, jac = orig[:, robot.tips], jo[:, robot.tips]
    p[:, -1], jac[:, -1] = tool, jt
    return p, jac

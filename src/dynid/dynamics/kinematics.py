"""Batched forward kinematics and Newton–Euler forward recursion (no Python loop over samples)."""

from __future__ import annotations

import numpy as np

from ..model.robot import Robot
from ..model.spatial import rot_axis


def _local_rotations(robot: Robot, q: np.ndarray) -> list[np.ndarray]:
    """``[(N, 3, 3)]``: orientation of link j in link j-1 for every sample."""
    return [jt.rotation @ rot_axis(jt.axis, q[:, j]) for j, jt in enumerate(robot.joints)]


def forward_kinematics(robot: Robot, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Pose of every link frame in the base frame.

    Parameters
    ----------
    robot : Robot
    q : (N, n_dof) array
        Joint positions [rad].

    Returns
    -------
    rotations : (N, n_dof, 3, 3) array
    origins : (N, n_dof, 3) array [m]
    """
    n_s = q.shape[0]
    rots = np.empty((n_s, robot.n_dof, 3, 3))
    orig = np.empty((n_s, robot.n_dof, 3))
    r_prev, p_prev = np.broadcast_to(np.eye(3), (n_s, 3, 3)), np.zeros((n_s, 3))
    for j, rl in enumerate(_local_rotations(robot, q)):
        p_prev = p_prev + r_prev @ robot.joints[j].translation
        r_prev = r_prev @ rl
        rots[:, j], orig[:, j] = r_prev, p_prev
    return rots, orig


def tool_positions(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Tool (flange) point in the base frame, (N, 3) [m]."""
    rots, orig = forward_kinematics(robot, q)
    return orig[:, -1] + rots[:, -1] @ robot.tool_translation


def link_motion(robot: Robot, q: np.ndarray, dq: np.ndarray, ddq: np.ndarray):
    """Newton–Euler forward recursion, batched over samples.

    Returns angular velocity ``w``, angular acceleration ``dw`` and linear acceleration ``a`` of every
    link frame origin (gravity included as a base acceleration ``-g``), in the link's own frame, and the
    link rotations/origins in the base frame.

    Returns
    -------
    w, dw, a : (N, n_dof, 3) arrays [rad/s, rad/s², m/s²]
    rotations : (N, n_dof, 3, 3) array
    origins : (N, n_dof, 3) array
    """
    n_s, n = q.shape
    w = np.zeros((n_s, n, 3))
    dw = np.zeros((n_s, n, 3))
    acc = np.zeros((n_s, n, 3))
    rots = np.empty((n_s, n, 3, 3))
    orig = np.empty((n_s, n, 3))
    w_p, dw_p = np.zeros((n_s, 3)), np.zeros((n_s, 3))
    a_p = np.broadcast_to(-robot.gravity, (n_s, 3))
    r_prev, p_prev = np.broadcast_to(np.eye(3), (n_s, 3, 3)), np.zeros((n_s, 3))
    for j, rl in enumerate(_local_rotations(robot, q)):
        jt = robot.joints[j]
        p = jt.translation
        rt = np.swapaxes(rl, 1, 2)
        a_here = a_p + np.cross(dw_p, p) + np.cross(w_p, np.cross(w_p, p))
        w_in = np.einsum("nij,nj->ni", rt, w_p)
        w_j = w_in + dq[:, j, None] * jt.axis
        dw_j = np.einsum("nij,nj->ni", rt, dw_p) + np.cross(w_in, dq[:, j, None] * jt.axis) + ddq[:, j, None] * jt.axis
        a_j = np.einsum("nij,nj->ni", rt, a_here)
        w[:, j], dw[:, j], acc[:, j] = w_j, dw_j, a_j
        p_prev = p_prev + r_prev @ p
        r_prev = r_prev @ rl
        rots[:, j], orig[:, j] = r_prev, p_prev
        w_p, dw_p, a_p = w_j, dw_j, a_j
    return w, dw, acc, rots, orig

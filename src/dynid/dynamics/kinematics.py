"""Batched forward kinematics (no Python loop over samples)."""

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
    """Tool (flange) point in the base frame.

    Parameters
    ----------
    robot : Robot
    q : (N, n_dof) array [rad]

    Returns
    -------
    (N, 3) ndarray [m]
    """
    rots, orig = forward_kinematics(robot, q)
    return orig[:, -1] + rots[:, -1] @ robot.tool_translation

"""Batched forward kinematics (no Python loop over samples)."""

from __future__ import annotations

import numpy as np

from ..model.robot import Robot


def forward_kinematics(robot: Robot, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Pose of every link frame in the base frame.

    Parameters
    ----------
    robot : Robot
    q : (N, n_dof) array
        Joint positions [rad, or m for a prismatic joint].

    Returns
    -------
    rotations : (N, n_dof, 3, 3) array
    origins : (N, n_dof, 3) array [m]
    """
    n_s = q.shape[0]
    rots = np.empty((n_s, robot.n_dof, 3, 3))
    orig = np.empty((n_s, robot.n_dof, 3))
    base_r, base_p = np.broadcast_to(np.eye(3), (n_s, 3, 3)), np.zeros((n_s, 3))
    for j, (jt, parent) in enumerate(zip(robot.joints, robot.parents)):
        r_prev, p_prev = (base_r, base_p) if parent < 0 else (rots[:, parent], orig[:, parent])
        rl, pl = jt.placement(q[:, j])
        orig[:, j] = p_prev + (np.einsum("nij,nj->ni", r_prev, pl) if jt.prismatic else r_prev @ jt.translation)
        rots[:, j] = r_prev @ rl
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


def tip_positions(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Each branch's tip in the base frame (:attr:`dynid.model.robot.Robot.tips`): the tool point on the last joint's
    link, the link's origin on another branch's (its file states no tool there).

    Parameters
    ----------
    robot : Robot
    q : (N, n_dof) array [rad, or m for a prismatic joint]

    Returns
    -------
    (N, n_tips, 3) ndarray [m]
        The tool point last; ``(N, 1, 3)`` on a serial chain.
    """
    rots, orig = forward_kinematics(robot, q)
    out = orig[:, robot.tips]
    out[:, -1] = orig[:, -1] + rots[:, -1] @ robot.tool_translation
    return out

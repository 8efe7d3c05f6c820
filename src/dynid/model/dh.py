"""Joints from Denavit–Hartenberg tables, modified (Khalil/Craig, the paper's Table 1) or standard.

Modified DH, row ``i``: ``T_{i-1,i} = RotX(alpha_{i-1}) TransX(a_{i-1}) RotZ(theta_i) TransZ(d_i)``, with
``theta_i = q_i + theta_offset_i``. The link frame is DH frame ``i``; inertial parameters are given in it.

Standard DH, row ``i``: ``T_{i-1,i} = RotZ(theta_i) TransZ(d_i) TransX(a_i) RotX(alpha_i)``. Joint ``i``
turns about ``z_{i-1}``; dynid's frame of link ``i`` is DH frame ``i-1`` turned by ``theta_i`` (its origin
on the joint axis), and the fixed part ``TransZ(d_i) TransX(a_i) RotX(alpha_i)`` becomes the placement of
the next joint (or the tool frame after the last one). :func:`standard_dh_link_offset` gives the pose of
DH frame ``i`` in dynid's link frame, to convert inertial data given in DH frame ``i``.
"""

from __future__ import annotations

import numpy as np

from .robot import Joint
from .spatial import rot_x, rot_z


def joints_from_modified_dh(alpha, a, d, theta_offset, names=None) -> tuple[Joint, ...]:
    """Joints of a modified-DH table (Khalil).

    Parameters
    ----------
    alpha, a, d, theta_offset : (n_dof,) arrays
        [rad], [m], [m], [rad].
    names : sequence of str, optional

    Returns
    -------
    tuple of Joint
    """
    n = len(alpha)
    names = names or [f"joint{i + 1}" for i in range(n)]
    joints = []
    for i in range(n):
        r = rot_x(alpha[i]) @ rot_z(theta_offset[i])
        p = rot_x(alpha[i]) @ np.array([a[i], 0.0, 0.0]) + rot_x(alpha[i]) @ np.array([0.0, 0.0, d[i]])
        joints.append(Joint(names[i], r, p))
    return tuple(joints)


def standard_dh_link_offset(alpha_i: float, a_i: float, d_i: float) -> tuple[np.ndarray, np.ndarray]:
    """Pose of standard-DH frame ``i`` in dynid's frame of link ``i`` (``TransZ(d) TransX(a) RotX(alpha)``).

    Parameters
    ----------
    alpha_i : float [rad]
    a_i, d_i : float [m]

    Returns
    -------
    R : (3, 3) ndarray
    p : (3,) ndarray [m]
    """
    return rot_x(alpha_i), np.array([a_i, 0.0, d_i])


def joints_from_standard_dh(alpha, a, d, theta_offset, names=None):
    """Joints and tool pose of a standard-DH table.

    Parameters
    ----------
    alpha, a, d, theta_offset : (n_dof,) arrays
        [rad], [m], [m], [rad].
    names : sequence of str, optional

    Returns
    -------
    joints : tuple of Joint
    tool_rotation, tool_translation : arrays
        DH frame ``n`` in the last link frame (the flange).
    """
    n = len(alpha)
    names = names or [f"joint{i + 1}" for i in range(n)]
    joints = []
    prev_r, prev_p = np.eye(3), np.zeros(3)
    for i in range(n):
        joints.append(Joint(names[i], prev_r @ rot_z(theta_offset[i]), prev_p.copy()))
        prev_r, prev_p = standard_dh_link_offset(alpha[i], a[i], d[i])
    return tuple(joints), prev_r, prev_p

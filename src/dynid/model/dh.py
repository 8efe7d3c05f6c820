"""Joints from Denavit–Hartenberg tables, modified (Khalil/Craig, the paper's Table 1) or standard.

Modified DH, row ``i``: ``T_{i-1,i} = RotX(alpha_{i-1}) TransX(a_{i-1}) RotZ(theta_i) TransZ(d_i)``, with
``theta_i = q_i + theta_offset_i`` (revolute) or ``d_i = q_i + d`` (prismatic, Khalil's sigma = 1). The link frame
is DH frame ``i``; inertial parameters are given in it. A robot with branches (two arms on a torso) takes each joint's
frame from its antecedent's (Khalil & Kleinfinger, "A new geometric notation for open and closed-loop robots", ICRA
1986): ``T = RotZ(gamma) TransZ(b) RotX(alpha) TransX(a) RotZ(theta) TransZ(d)``, gamma = b = 0 on a chain.

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


def joints_from_modified_dh(alpha, a, d, theta_offset, names=None, *, prismatic=None, parents=None, gamma=None,
                            b=None) -> tuple[Joint, ...]:
    """Joints of a modified-DH table (Khalil), a chain or a tree (Khalil-Kleinfinger).

    Parameters
    ----------
    alpha, a, d, theta_offset : (n_dof,) arrays
        [rad], [m], [m], [rad]. A prismatic joint's ``d`` is its offset at ``q = 0``.
    names : sequence of str, optional
    prismatic : (n_dof,) bools, optional
        Which joints slide along their z (default: none).
    parents : (n_dof,) ints or None, optional
        Each joint's antecedent (-1: the base; ``None``: the joint before it); see :attr:`Joint.parent`.
    gamma, b : (n_dof,) arrays, optional
        [rad], [m]: the rotation about and offset along the antecedent's z (default 0).

    Returns
    -------
    tuple of Joint
    """
    n = len(alpha)
    names = names or [f"joint{i + 1}" for i in range(n)]
    prismatic = [False] * n if prismatic is None else prismatic
    parents = [None] * n if parents is None else parents
    gamma = [0.0] * n if gamma is None else gamma
    b = [0.0] * n if b is None else b
    joints = []
    for i in range(n):
        rg = rot_z(gamma[i])
        r = rg @ rot_x(alpha[i]) @ rot_z(theta_offset[i])
        p = np.array([0.0, 0.0, b[i]]) + rg @ rot_x(alpha[i]) @ np.array([a[i], 0.0, d[i]])
        joints.append(Joint(names[i], r, p, prismatic=bool(prismatic[i]), parent=parents[i]))
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


def joints_from_standard_dh(alpha, a, d, theta_offset, names=None, *, prismatic=None):
    """Joints and tool pose of a standard-DH table (a chain).

    Parameters
    ----------
    alpha, a, d, theta_offset : (n_dof,) arrays
        [rad], [m], [m], [rad]. A prismatic joint's ``d`` is its offset at ``q = 0``.
    names : sequence of str, optional
    prismatic : (n_dof,) bools, optional
        Which joints slide along ``z_{i-1}`` (default: none).

    Returns
    -------
    joints : tuple of Joint
    tool_rotation, tool_translation : arrays
        DH frame ``n`` in the last link frame (the flange).
    """
    n = len(alpha)
    names = names or [f"joint{i + 1}" for i in range(n)]
    joints = []
    prismatic = [False] * n if prismatic is None else prismatic
    prev_r, prev_p = np.eye(3), np.zeros(3)
    for i in range(n):
        joints.append(Joint(names[i], prev_r @ rot_z(theta_offset[i]), prev_p.copy(), prismatic=bool(prismatic[i])))
        prev_r, prev_p = standard_dh_link_offset(alpha[i], a[i], d[i])
    return tuple(joints), prev_r, prev_p

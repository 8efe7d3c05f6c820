"""Independent torques from Pinocchio's recursive Newton–Euler algorithm (RNEA).

dynid's own regressor is checked against these, and the simulator uses them, so that simulated
measurements never come from the model being identified.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .._util.checks import check_same_length, check_trajectory_array
from .._util.keywords import keyword_only_after_data
from ..exceptions import ShapeError
from ..model.loading import as_robot
from ..model.robot import Robot
from ..model.urdf import pinocchio_from_inertial
from .regressor import friction_torques


def pinocchio_model(robot: Robot, inertial: np.ndarray | None = None):
    """A ``pinocchio.Model`` of the chain with given inertial parameters.

    Parameters may be physically inconsistent (e.g. a base-parameter embedding); RNEA stays linear.

    Parameters
    ----------
    robot : Robot
    inertial : (n_dof, 10) array, optional
        eq. 5 order (the robot's nominal ones by default).

    Returns
    -------
    pinocchio.Model
    """
    import pinocchio as pin

    inertial = robot.inertial if inertial is None else inertial
    model = pin.Model()
    model.gravity.linear = np.asarray(robot.gravity, dtype=float)
    for j, (jt, parent) in enumerate(zip(robot.joints, robot.parents)):
        placement = pin.SE3(np.asarray(jt.rotation), np.asarray(jt.translation))
        joint = model.addJoint(int(parent) + 1, _joint_model(jt), placement, jt.name)  # Pinocchio's 0 is the base
        model.appendBodyToJoint(joint, pin.Inertia.FromDynamicParameters(pinocchio_from_inertial(inertial[j])), pin.SE3.Identity())
    return model


def _joint_model(joint):
    """Pinocchio's joint model of a joint: about (revolute) or along (prismatic) its axis."""
    import pinocchio as pin

    ax = np.asarray(joint.axis, dtype=float)
    kind = "P" if joint.prismatic else "R"
    for name, unit in (("X", [1, 0, 0]), ("Y", [0, 1, 0]), ("Z", [0, 0, 1])):
        if np.allclose(ax, unit):
            return getattr(pin, f"JointModel{kind}{name}")()
    return pin.JointModelPrismaticUnaligned(ax) if joint.prismatic else pin.JointModelRevoluteUnaligned(ax)


@keyword_only_after_data
def rnea_torques(robot: Robot | str | Path, q, dq, ddq, *, inertial: np.ndarray | None = None, drive: np.ndarray | None = None) -> np.ndarray:
    """Joint torques: Pinocchio's RNEA for the rigid bodies plus the drive terms.

    Parameters
    ----------
    robot : Robot, str or Path
        A built-in robot's name or a description's path is loaded (:func:`dynid.model.loading.as_robot`).
    q, dq, ddq : (N, n_dof) arrays
        [rad], [rad/s], [rad/s²] ([m], [m/s], [m/s²] for a prismatic joint).
    inertial : (n_dof, 10) array, optional
        eq. 5 order (the robot's nominal ones by default).
    drive : (n_dof, n_drive) array, optional
        Drive parameters (the robot's nominal ones by default).

    Returns
    -------
    (N, n_dof) ndarray [N·m] ([N] for a prismatic joint)
        A joint that follows another (:attr:`dynid.model.robot.Joint.mimic`) moves as that joint says, whatever its
        columns hold, and its torque is in the row of the joint it follows (:meth:`dynid.model.robot.Robot.fold`; 0 in
        its own).

    Raises
    ------
    ShapeError
        States of another shape than (N, n_dof) (or of different lengths, or not finite), or ``inertial`` or ``drive``
        of another shape than the robot's.
    """
    robot = as_robot(robot)
    import pinocchio as pin

    q, dq, ddq = (check_trajectory_array(x, robot.n_dof, name) for x, name in ((q, "q"), (dq, "dq"), (ddq, "ddq")))
    check_same_length(q=q, dq=dq, ddq=ddq)
    for name, given, own in (("inertial", inertial, robot.inertial), ("drive", drive, robot.drive)):
        if given is not None and np.shape(given) != np.shape(own):
            raise ShapeError(f"{name}: expected shape {np.shape(own)} ({robot.name}'s), got {np.shape(given)}")
    model = pinocchio_model(robot, inertial)
    data = model.createData()
    q, dq, ddq = (np.ascontiguousarray(x, dtype=float) for x in robot.coupled(q, dq, ddq))
    tau = np.empty_like(q)
    for k in range(q.shape[0]):
        tau[k] = pin.rnea(model, data, q[k], dq[k], ddq[k])
    return robot.fold(tau + friction_torques(robot, dq, ddq, drive, q=q))

"""Serial revolute chains from URDF files, parsed by Pinocchio."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..exceptions import ConfigError
from .robot import Joint

_AXES = {"RX": (1.0, 0.0, 0.0), "RY": (0.0, 1.0, 0.0), "RZ": (0.0, 0.0, 1.0)}


def inertial_from_pinocchio(inertia) -> np.ndarray:
    """dynid's ten inertial parameters (eq. 5 order) from a ``pinocchio.Inertia``.

    Pinocchio orders them ``[m, mc_x, mc_y, mc_z, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]``.
    """
    p = np.asarray(inertia.toDynamicParameters()).ravel()
    return np.array([p[4], p[5], p[7], p[6], p[8], p[9], p[1], p[2], p[3], p[0]])


def pinocchio_from_inertial(phi: np.ndarray) -> np.ndarray:
    """Pinocchio's dynamic-parameter order from dynid's ten inertial parameters."""
    xx, xy, xz, yy, yz, zz, mx, my, mz, m = phi
    return np.array([m, mx, my, mz, xx, xy, yy, xz, yz, zz])


def joints_from_urdf(path: str | Path) -> tuple[tuple[Joint, ...], np.ndarray, tuple[str, ...]]:
    """Joints and link inertial parameters of a URDF serial chain of revolute joints.

    Fixed joints are merged by Pinocchio into the parent link. Continuous joints (unbounded revolute) are
    revolute joints without position limits: dynid's joint angle is their angle.

    Returns
    -------
    joints : tuple of Joint
    inertial : (n_dof, 10) array
        Inertial parameters of each link in its joint frame (eq. 5 order).
    names : tuple of str

    Raises
    ------
    ConfigError
        If the file cannot be parsed, or the chain is not serial or has non-revolute joints.
    """
    import pinocchio as pin

    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"{path}: URDF file not found")
    try:
        model = pin.buildModelFromUrdf(str(path))
    except Exception as exc:  # pinocchio raises plain RuntimeError/ValueError
        raise ConfigError(f"{path}: cannot parse URDF ({str(exc).splitlines()[0] if str(exc) else type(exc).__name__})") from None
    joints, inertial = [], []
    for j in range(1, model.njoints):
        jm = model.joints[j]
        short = jm.shortname()
        if model.parents[j] != j - 1:
            raise ConfigError(f"{path}: joint {model.names[j]!r} does not continue a serial chain")
        if short.startswith("JointModelR") and short[-2:] in _AXES and "Unbounded" not in short:
            axis = np.array(_AXES[short[-2:]])  # revolute, or continuous (RUB: unbounded, same dynamics)
        elif short.startswith("JointModelRUB") and "R" + short[-1] in _AXES:  # continuous joint about x, y or z
            axis = np.array(_AXES["R" + short[-1]])
        elif short == "JointModelRevoluteUnaligned":
            axis = np.asarray(jm.extract().axis, dtype=float).ravel()
        elif short == "JointModelRevoluteUnboundedUnaligned":  # continuous, unaligned: the axis is its motion subspace
            data = model.createData()
            pin.forwardKinematics(model, data, pin.neutral(model))
            axis = np.asarray(data.joints[j].S, dtype=float).ravel()[3:]
        else:
            raise ConfigError(f"{path}: joint {model.names[j]!r} is {short}, expected a revolute joint")
        placement = model.jointPlacements[j]
        joints.append(Joint(model.names[j], np.array(placement.rotation), np.array(placement.translation), axis))
        inertial.append(inertial_from_pinocchio(model.inertias[j]))
    if not joints:
        raise ConfigError(f"{path}: expected at least one revolute joint, found none")
    return tuple(joints), np.array(inertial), tuple(model.names[1:])

"""Robots with branches (issue "Every arm a user has", item 3): two arms on a torso that turns, identified as one
model whose rows are every joint, against Pinocchio's own reading of the same URDF (its regressor, RNEA and
kinematics, not dynid's)."""

import numpy as np
import pinocchio as pin
import pytest

from dynid.dynamics.base_parameters import base_parameters
from dynid.dynamics.regressor import _fill
from dynid.dynamics.rnea import rnea_torques
from dynid.exceptions import ConfigError
from dynid.model.description import load_robot
from dynid.model.urdf import inertial_from_pinocchio

from .test_prismatic_joints import _joint, _link, _urdf, assert_kinematics_follow_pinocchio


def _arm(side: str, y: float, lift: bool = False) -> tuple[list, list]:
    """A three-joint arm on the torso's side ``y`` (its second joint sliding where ``lift``)."""
    s = 1 if y > 0 else -1
    links = [_link(f"{side}_upper", 4.0, f"0 {0.03 * s} 0.12", (0.08, 0.09, 0.02, 0.001, 0.0, 0.004)),
             _link(f"{side}_fore", 2.5, "0.15 0 0.01", (0.01, 0.05, 0.052, 0.0, 0.002, 0.0)),
             _link(f"{side}_hand", 0.9, "0.02 0.01 0.04", (0.003, 0.004, 0.002, 0.0, 0.0, 0.0003))]
    joints = [_joint(f"{side}_j1", "revolute", "torso", f"{side}_upper", f"0.05 {y} 0.5", f"{0.3 * s} 0 0", "0 1 0"),
              _joint(f"{side}_j2", "prismatic" if lift else "revolute", f"{side}_upper", f"{side}_fore", "0 0 0.3",
                     "0 0.2 0", "0 0 1" if lift else "1 0 0", *((-0.1, 0.2) if lift else ()), effort=150 if lift else 500),
              _joint(f"{side}_j3", "revolute", f"{side}_fore", f"{side}_hand", "0.3 0 0", "0 0 0.4", "0.6 0 0.8")]
    return links, joints


def _two_arms() -> str:
    left, right = _arm("left", 0.2), _arm("right", -0.2, lift=True)
    return _urdf([_link("torso", 20.0, "0.01 0 0.3", (1.1, 1.0, 0.4, 0.0, 0.02, 0.0)), *left[0], *right[0]],
                 [_joint("torso_yaw", "revolute", "base", "torso", "0 0 0.8", "0 0 0", "0 0 1"), *left[1], *right[1]])


TWO_ARMS = _two_arms()
"""A torso turning about z, two three-joint arms on it (the right one's second joint sliding): a tree of 7 joints."""


@pytest.fixture
def urdf(tmp_path):
    path = tmp_path / "two_arms.urdf"
    path.write_text(TWO_ARMS)
    return path


def _states(robot, rng, n):
    lo, hi = robot.limits.position_span()
    return rng.uniform(lo, hi, (n, robot.n_dof)), rng.normal(size=(n, robot.n_dof)), rng.normal(size=(n, robot.n_dof)) * 3


def test_every_joint_of_both_arms_is_the_robots_and_each_knows_what_carries_it(urdf):
    robot = load_robot(urdf)
    model = pin.buildModelFromUrdf(str(urdf))
    assert [j.name for j in robot.joints] == list(model.names[1:])
    assert robot.is_tree and robot.parents.tolist() == [p - 1 for p in model.parents[1:]]
    assert robot.parents.tolist() == [-1, 0, 1, 2, 0, 4, 5]  # both arms on the torso's joint


@pytest.mark.parametrize("form", ["numpy", "compiled", "numba"])
def test_the_regressor_and_rnea_equal_pinocchios_on_1000_random_states(urdf, form, rng):
    """Each link's ten columns equal Pinocchio's joint-torque regressor of the URDF (its parameter order mapped to
    eq. 5; a joint feels only the links it carries: the left arm's joints none of the right arm's), Y·φ its RNEA, and
    dynid's own RNEA (Pinocchio on dynid's model) the same, to 1e-10 of the RMS torque."""
    robot = load_robot(urdf)
    model = pin.buildModelFromUrdf(str(urdf))
    data = model.createData()
    q, dq, ddq = _states(robot, rng, 1000)
    y = np.empty((1000, robot.n_dof, robot.n_params))
    _fill(robot, q, dq, ddq, y, np.arange(robot.n_params), form=form)
    pin_y = np.array([pin.computeJointTorqueRegressor(model, data, q[k], dq[k], ddq[k]) for k in range(1000)])
    tau = np.array([pin.rnea(model, data, q[k], dq[k], ddq[k]) for k in range(1000)])
    perm = [4, 5, 7, 6, 8, 9, 1, 2, 3, 0]  # Pinocchio's [m, mc, I] -> eq. 5's order
    npj, n = robot.n_params_per_joint, robot.n_dof
    inertial_columns = y.reshape(1000, n, n, npj)[..., :10].reshape(1000, n, -1)
    expected = pin_y.reshape(1000, n, n, 10)[..., perm].reshape(1000, n, -1)
    assert np.abs(expected[:, 1:4, 4 * 10:]).max() == 0.0  # the left arm's joints feel nothing of the right arm
    assert np.abs(inertial_columns[:, 1:4, 4 * 10:]).max() == 0.0  # nor in dynid's regressor, exactly
    assert np.abs(inertial_columns - expected).max() < 1e-10 * np.sqrt(np.mean(expected ** 2))
    rms = np.sqrt(np.mean(tau ** 2))
    rigid = y[..., [c for c in range(robot.n_params) if c % npj < 10]] @ robot.inertial.ravel()
    assert np.abs(rigid - tau).max() < 1e-10 * rms
    own = rnea_torques(robot.without_drive_terms(robot.drive_terms), q, dq, ddq)
    assert np.abs(own - tau).max() < 1e-10 * rms
    np.testing.assert_allclose(inertial_from_pinocchio(model.inertias[5]), robot.inertial[4], rtol=1e-12)


def test_the_number_of_base_parameters_is_the_rank_of_pinocchios_regressor(urdf, rng):
    robot = load_robot(urdf)
    model = pin.buildModelFromUrdf(str(urdf))
    data = model.createData()
    q, dq, ddq = _states(robot, rng, 300)
    w = np.vstack([pin.computeJointTorqueRegressor(model, data, q[k], dq[k], ddq[k]) for k in range(300)])
    rigid = robot.without_drive_terms(robot.drive_terms)
    assert base_parameters(rigid).n_base == np.linalg.matrix_rank(w)


def test_forward_kinematics_follows_pinocchio(urdf, rng):
    robot = load_robot(urdf)
    assert_kinematics_follow_pinocchio(robot, pin.buildModelFromUrdf(str(urdf)), _states(robot, rng, 20)[0])


def test_a_serial_chains_numbers_and_fingerprint_do_not_change_with_its_parents_stated(urdf, rng):
    """A serial chain stated with each joint's parent is the same robot: the same regressor to the bit, the same
    fingerprint; a tree's fingerprint differs from the same joints read as a chain; a parent after its joint is
    refused in one line."""
    from dataclasses import replace

    robot = load_robot("er16")
    stated = replace(robot, joints=tuple(replace(jt, parent=j - 1) for j, jt in enumerate(robot.joints)))
    q, dq, ddq = _states(robot, rng, 50)
    a, b = (np.empty((50, 6, robot.n_params)) for _ in range(2))
    _fill(robot, q, dq, ddq, a, np.arange(robot.n_params), form="numpy")
    _fill(stated, q, dq, ddq, b, np.arange(robot.n_params), form="numpy")
    assert np.array_equal(a, b) and not stated.is_tree
    assert stated.kinematic_fingerprint() == robot.kinematic_fingerprint()
    tree = load_robot(urdf)
    chain = replace(tree, joints=tuple(replace(jt, parent=None) for jt in tree.joints))
    assert tree.kinematic_fingerprint() != chain.kinematic_fingerprint()
    with pytest.raises(ConfigError, match="carried by joint 3: expected a joint before it"):
        replace(robot, joints=(replace(robot.joints[0], parent=3), *robot.joints[1:]))

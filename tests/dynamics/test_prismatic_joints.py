"""Prismatic joints (issue "Every arm a user has", item 1): a linear track under an arm, a SCARA's vertical axis and a
lift, against Pinocchio's own reading of the same URDF (its regressor and RNEA, not dynid's)."""

import numpy as np
import pinocchio as pin
import pytest

from dynid.conventions import unit_of
from dynid.dynamics.base_parameters import base_parameters
from dynid.dynamics.kinematics import forward_kinematics
from dynid.dynamics.regressor import _fill
from dynid.model.description import load_robot
from dynid.model.urdf import inertial_from_pinocchio, joints_to_hold


def _link(name, mass, com, inertia):
    ixx, iyy, izz, ixy, ixz, iyz = inertia
    return (f'<link name="{name}"><inertial><origin xyz="{com}" rpy="0 0 0"/><mass value="{mass}"/>'
            f'<inertia ixx="{ixx}" ixy="{ixy}" ixz="{ixz}" iyy="{iyy}" iyz="{iyz}" izz="{izz}"/></inertial></link>')


def _joint(name, kind, parent, child, xyz, rpy, axis, lower=-2.0, upper=2.0, mimic="", effort=500):
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{xyz}" rpy="{rpy}"/><axis xyz="{axis}"/>'
            f'<limit lower="{lower}" upper="{upper}" effort="{effort}" velocity="2"/>{mimic}</joint>')


def _urdf(links, joints):
    return '<robot name="r"><link name="base"/>' + "".join(links) + "".join(joints) + "</robot>"


TRACKED = _urdf(
    [_link("carriage", 30.0, "0.05 0.01 0.1", (1.2, 1.5, 1.1, 0.02, -0.01, 0.03)),
     _link("l1", 8.0, "0 0.02 0.15", (0.3, 0.35, 0.2, 0.01, 0.0, -0.02)),
     _link("l2", 6.0, "0.25 0 0.02", (0.05, 0.4, 0.42, 0.0, 0.01, 0.0)),
     _link("l3", 3.0, "0.2 0.01 0", (0.05, 0.15, 0.16, 0.0, 0.0, 0.01)),
     _link("l4", 1.5, "0 0 0.05", (0.01, 0.012, 0.008, 0.0, 0.0, 0.0)),
     _link("l5", 0.7, "0.01 0 0.03", (0.004, 0.005, 0.003, 0.0, 0.0, 0.0))],
    [_joint("track", "prismatic", "base", "carriage", "0.1 -0.2 0.3", "0 0 0.3", "1 0 0", 0.0, 3.0),
     _joint("j1", "revolute", "carriage", "l1", "0 0 0.4", "0 0 0", "0 0 1"),
     _joint("j2", "revolute", "l1", "l2", "0 0.1 0.3", "1.5708 0 0", "0 0 1"),
     _joint("j3", "revolute", "l2", "l3", "0.5 0 0", "0 0 0", "0 0 1"),
     _joint("j4", "prismatic", "l3", "l4", "0.4 0 0", "0.1 0.2 0", "0.3 0.4 0.866", -0.1, 0.2, effort=100),
     _joint("j5", "revolute", "l4", "l5", "0 0 0.1", "0 0 0", "0 0 1", effort=20)])
"""A 3-axis arm on a linear track, then a joint sliding along an unaligned axis and a turning tool."""

SCARA = _urdf(
    [_link("l1", 12.0, "0.2 0 0.05", (0.1, 0.5, 0.55, 0.0, 0.01, 0.0)),
     _link("l2", 8.0, "0.15 0.01 0", (0.05, 0.3, 0.32, 0.01, 0.0, 0.0)),
     _link("quill", 2.0, "0 0 -0.1", (0.02, 0.02, 0.001, 0.0, 0.0, 0.0)),
     _link("tool", 0.8, "0 0.01 -0.02", (0.002, 0.002, 0.001, 0.0, 0.0, 0.0)),
     _link("finger_a", 0.05, "0 0 -0.01", (1e-5, 1e-5, 1e-5, 0.0, 0.0, 0.0)),
     _link("finger_b", 0.05, "0 0 -0.01", (1e-5, 1e-5, 1e-5, 0.0, 0.0, 0.0))],
    [_joint("j1", "revolute", "base", "l1", "0 0 0.4", "0 0 0", "0 0 1"),
     _joint("j2", "revolute", "l1", "l2", "0.4 0 0", "0 0 0", "0 0 1"),
     _joint("j3", "prismatic", "l2", "quill", "0.35 0 0", "0 0 0", "0 0 -1", 0.0, 0.3),
     _joint("j4", "revolute", "quill", "tool", "0 0 -0.2", "0 0 0", "0 0 1"),
     _joint("finger_a_joint", "prismatic", "tool", "finger_a", "0 0.02 -0.05", "0 0 0", "0 1 0", 0.0, 0.02),
     _joint("finger_b_joint", "prismatic", "tool", "finger_b", "0 -0.02 -0.05", "0 0 0", "0 -1 0", 0.0, 0.02,
            '<mimic joint="finger_a_joint"/>')])
"""A SCARA: two revolute axes, a vertical quill sliding down, a revolute tool and a gripper whose fingers slide."""


@pytest.fixture(params=["tracked", "scara"])
def urdf(request, tmp_path):
    path = tmp_path / f"{request.param}.urdf"
    path.write_text(TRACKED if request.param == "tracked" else SCARA)
    return path


def _both(urdf):
    """dynid's robot of the URDF (its fingers held) and Pinocchio's own model of it, the same joints locked at 0."""
    held = joints_to_hold(urdf)
    full = pin.buildModelFromUrdf(str(urdf))
    model = pin.buildReducedModel(full, [full.getJointId(h) for h in held], np.zeros(full.nq))
    return load_robot(urdf, held=held), model, model.createData()


def _states(robot, rng, n):
    lo, hi = robot.limits.position_span()
    return rng.uniform(lo, hi, (n, robot.n_dof)), rng.normal(size=(n, robot.n_dof)), rng.normal(size=(n, robot.n_dof)) * 3


def test_the_arm_is_every_joint_but_a_grippers_fingers(urdf):
    """The track, the quill and the arm's joints are the arm's; the fingers at the tip are held."""
    held = joints_to_hold(urdf)
    robot = load_robot(urdf, held=held)
    if urdf.stem == "tracked":
        assert held == () and robot.prismatic.tolist() == [True, False, False, False, True, False]
    else:
        assert held == ("finger_a_joint", "finger_b_joint")
        assert robot.prismatic.tolist() == [False, False, True, False]


@pytest.mark.parametrize("form", ["numpy", "compiled", "numba"])
def test_the_regressor_equals_pinocchios_on_1000_random_states(urdf, form, rng):
    """Each link's ten columns equal Pinocchio's joint-torque regressor of its own URDF model (its parameter order
    mapped to eq. 5), and Y·φ its RNEA, to 1e-10 of the RMS torque: prismatic joints feel the force along their axis."""
    robot, model, data = _both(urdf)
    q, dq, ddq = _states(robot, rng, 1000)
    y = np.empty((1000, robot.n_dof, robot.n_params))
    _fill(robot, q, dq, ddq, y, np.arange(robot.n_params), form=form)
    pin_y = np.array([pin.computeJointTorqueRegressor(model, data, q[k], dq[k], ddq[k]) for k in range(1000)])
    tau = np.array([pin.rnea(model, data, q[k], dq[k], ddq[k]) for k in range(1000)])
    perm = [4, 5, 7, 6, 8, 9, 1, 2, 3, 0]  # Pinocchio's [m, mc, I(xx xy yy xz yz zz)] -> eq. 5's (XX XY XZ YY YZ ZZ MX MY MZ M)
    np.testing.assert_allclose(inertial_from_pinocchio(pin.Inertia.FromDynamicParameters(np.arange(1.0, 11.0))),
                               np.array(perm) + 1.0, rtol=1e-12)
    npj = robot.n_params_per_joint
    inertial_columns = y.reshape(1000, robot.n_dof, robot.n_dof, npj)[..., :10].reshape(1000, robot.n_dof, -1)
    expected = pin_y.reshape(1000, robot.n_dof, robot.n_dof, 10)[..., perm].reshape(1000, robot.n_dof, -1)
    rms = np.sqrt(np.mean(tau ** 2))
    assert np.abs(inertial_columns - expected).max() < 1e-10 * np.sqrt(np.mean(expected ** 2))
    rigid = y[..., [c for c in range(robot.n_params) if c % npj < 10]] @ robot.inertial.ravel()
    assert np.abs(rigid - tau).max() < 1e-10 * rms


def test_the_number_of_base_parameters_is_the_rank_of_pinocchios_regressor(urdf, rng):
    robot, model, data = _both(urdf)
    q, dq, ddq = _states(robot, rng, 300)
    w = np.vstack([pin.computeJointTorqueRegressor(model, data, q[k], dq[k], ddq[k]) for k in range(300)])
    rigid = robot.without_drive_terms(robot.drive_terms)
    assert base_parameters(rigid).n_base == np.linalg.matrix_rank(w)


def assert_kinematics_follow_pinocchio(robot, model, q):
    """dynid's link frames at ``q`` (N, n_dof) equal Pinocchio's ``oMi`` of ``model`` to 1e-12."""
    data = model.createData()
    rots, origins = forward_kinematics(robot, q)
    for k in range(q.shape[0]):
        pin.forwardKinematics(model, data, q[k])
        for j in range(robot.n_dof):
            np.testing.assert_allclose(origins[k, j], data.oMi[j + 1].translation, atol=1e-12)
            np.testing.assert_allclose(rots[k, j], data.oMi[j + 1].rotation, atol=1e-12)


def test_forward_kinematics_follows_pinocchio(urdf, rng):
    robot, model, _ = _both(urdf)
    assert_kinematics_follow_pinocchio(robot, model, _states(robot, rng, 20)[0])


def test_a_prismatic_joints_drive_terms_are_in_linear_units(urdf):
    robot = load_robot(urdf, held=joints_to_hold(urdf))
    base = base_parameters(robot)
    j = int(np.flatnonzero(robot.prismatic)[0]) + 1
    assert [base.unit(f"{t}{j}") for t in ("fv", "fc", "Ia", "M")] == ["N·s/m", "N", "kg", "kg"]
    assert unit_of(f"fv{j}") == "N·m·s/rad"  # a name alone is a revolute joint's


def test_per_joint_figures_say_their_units_where_joints_slide():
    from dynid.conventions import joint_unit, joints_unit, sliding_note

    sliding = (False, False, True, False)
    assert [joint_unit("N·m", sliding, j) for j in range(4)] == ["N·m", "N·m", "N", "N·m"]
    assert joint_unit("rad/s", sliding, 2) == "m/s" and joint_unit("rad/s", (), 2) == "rad/s"
    assert joints_unit("N·m", sliding) == "N·m/N" and joints_unit("N·m", (True,)) == "N" and joints_unit("N·m", ()) == "N·m"
    assert sliding_note("N·m", sliding) == " (J3 in N)" and sliding_note("N·m", sliding, inside=True) == "; J3 in N"
    assert sliding_note("N·m", (False, False)) == ""


def test_a_residual_finding_on_a_sliding_joint_says_its_position_and_newtons(rng):
    """The verdict's finding on a residual that follows a joint's position (diagnostics' harmonic features): on a
    prismatic joint it says the position and N, not the angle and N·m."""
    from dynid.validation.diagnostics import ResidualSums

    n, m = 2, 4000
    q = np.column_stack([np.linspace(-1.5, 1.5, m), np.linspace(0.0, 1.5, m)])  # a turning joint, a 1.5 m track
    dq = np.ones((m, n))
    y = rng.normal(size=(m, n, 1))
    tau = y[:, :, 0] * 2.0 + 0.5 * np.sin(2 * q) + rng.normal(0, 0.01, (m, n))  # a residual that follows the position
    said = {}
    for sliding in ((False, False), (False, True)):
        stats = ResidualSums(n, 1)
        stats.add(y, tau, q, dq, direction=np.ones((m, n)), low_speed=np.zeros(n), keep=np.ones((m, n), dtype=bool))
        findings, _ = stats.residual_checks(np.array([2.0]), np.sqrt(np.mean(tau**2, axis=0)), prismatic=sliding)
        said[sliding] = {f.joint: f.text for f in findings if f.kind == "position"}
    assert "joint's angle" in said[(False, False)][1] and " N·m over its angles" in said[(False, False)][1]
    assert "joint's position" in said[(False, True)][1] and " N over its positions" in said[(False, True)][1]
    assert said[(False, True)][0] == said[(False, False)][0]  # the revolute joint's line is as it was


def test_a_sliding_joint_is_never_tried_a_quarter_turn_off_and_its_stroke_counts_in_the_reach(urdf):
    """The check of a log read otherwise than the robot file tries each revolute joint's zero a quarter or half turn
    off; a prismatic joint's zero is a length, so it is tried on none (it was shifted by π/2 m as if turned). The reach
    (the capsules' and the workspace's scale) holds each prismatic joint's stroke."""
    from dynid.validation.geometry_checks import candidate_changes

    robot = load_robot(urdf, held=joints_to_hold(urdf))
    shifts = candidate_changes(robot)[0]
    assert np.all(shifts[:, robot.prismatic] == 0.0)
    assert np.any(shifts[:, ~robot.prismatic] != 0.0)
    stroke = np.maximum(np.abs(robot.limits.q_min), np.abs(robot.limits.q_max))[robot.prismatic].sum()
    skeleton = sum(float(np.linalg.norm(j.translation)) for j in robot.joints) + float(np.linalg.norm(robot.tool_translation))
    assert robot.reach == pytest.approx(skeleton + stroke)


def test_a_quarter_turn_on_a_tracked_arms_revolute_joint_is_named_and_the_track_never_turned(tmp_path):
    """The check of a log read otherwise runs on an arm with a prismatic joint: a log whose J3 angles are a quarter turn
    from the URDF's is named so, and the track, which is never tried turned, does not stop the search (it raised
    "zero-size array" there, a traceback through dynid identify on the zoo's tracked arm and TIAGo)."""
    from dynid.dynamics.regressor import nominal_rigid_torque
    from dynid.validation.geometry_checks import geometry_findings

    (tmp_path / "tracked.urdf").write_text(TRACKED)
    robot = load_robot(tmp_path / "tracked.urdf")
    t = np.arange(5000) * 0.004
    omega = 2 * np.pi * np.array([0.1, 0.13, 0.17, 0.21, 0.23, 0.27])
    centre = (robot.limits.q_min + robot.limits.q_max) / 2
    amp = np.minimum(0.8, 0.3 * (robot.limits.q_max - robot.limits.q_min))
    q = centre + amp * np.sin(omega * t[:, None] + np.arange(6))
    dq, ddq = amp * omega * np.cos(omega * t[:, None] + np.arange(6)), -(omega**2) * (q - centre)
    tau = nominal_rigid_torque(robot, q + np.array([0, 0, np.pi / 2, 0, 0, 0]), dq, ddq)
    found, stats = geometry_findings(robot, q, dq, ddq, tau, "log")
    assert [f.kind for f in found] == ["angles"], found
    assert stats["shift"] == pytest.approx([0, 0, np.pi / 2, 0, 0, 0])

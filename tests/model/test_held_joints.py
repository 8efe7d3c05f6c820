"""Joints of a URDF held fixed (a gripper's fingers): the arm identified, the fingers counted with their link."""

import re
import tomllib
from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.exceptions import ConfigError, DataError
from dynid.io.config.starter import starter_config
from dynid.io.exported.urdf_write_back import urdf_written_back
from dynid.model.description import robot_from_document
from dynid.model.urdf import joints_from_urdf, joints_to_hold


def _link(name, mass, xyz):
    return (f'<link name="{name}"><inertial><origin xyz="{xyz}"/><mass value="{mass}"/>'
            f'<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.015"/></inertial></link>')


def _revolute(name, parent, child, xyz, axis):
    return (f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{xyz}"/><axis xyz="{axis}"/><limit lower="-3" upper="3" effort="50" velocity="2"/></joint>')


def _finger(name, xyz, mimic=""):
    return (f'<joint name="{name}" type="prismatic"><parent link="hand"/><child link="{name}_link"/>'
            f'<origin xyz="{xyz}"/><axis xyz="0 1 0"/><limit lower="0" upper="0.04" effort="20" velocity="0.2"/>'
            f'{mimic}</joint>')


ARM = "".join([_link("base", 4.0, "0 0 0.05"), _link("l1", 3.0, "0 0 0.2"), _link("l2", 2.0, "0.2 0 0"),
               _link("hand", 0.7, "0 0 0.05"), _revolute("j1", "base", "l1", "0 0 0.1", "0 0 1"),
               _revolute("j2", "l1", "l2", "0 0 0.4", "0 1 0"),
               '<joint name="hand_joint" type="fixed"><parent link="l2"/><child link="hand"/><origin xyz="0.4 0 0"/>'
               '</joint>'])
FINGERS = (_link("f1_link", 0.1, "0 0.01 0.05") + _link("f2_link", 0.1, "0 -0.01 0.05")
           + _finger("f1", "0 0.02 0.06") + _finger("f2", "0 -0.02 0.06", '<mimic joint="f1" multiplier="-1"/>'))


def _urdf(tmp_path, body, name="arm.urdf"):
    path = tmp_path / name
    path.write_text(f'<?xml version="1.0"?>\n<robot name="arm">{body}</robot>\n')
    return path


def test_a_log_that_names_the_fingers_too_still_has_them_held(tmp_path):
    """A log from ROS's joint_states names a gripper's fingers beside the arm's joints: the fingers (prismatic, one a
    mimic) are on no arm's chain and stay held, and a log of both arms of a robot with a gripper on each takes both arms
    as one model with every finger held (the rule that takes a log's branches as a tree looks at the arms' chains)."""
    urdf = _urdf(tmp_path, ARM + FINGERS)
    assert joints_to_hold(urdf, lambda names: {"j1", "j2", "f1", "f2"}) == ("f1", "f2")
    gripper = ('<link name="{s}hand"/><joint name="{s}hand_joint" type="fixed"><parent link="{s}_link2"/>'
               '<child link="{s}hand"/><origin xyz="0.15 0 0"/></joint>'
               + _link("{s}f_link", 0.1, "0 0.01 0.05")
               + '<joint name="{s}f" type="prismatic"><parent link="{s}hand"/><child link="{s}f_link"/><axis xyz="0 1 0"/>'
               '<limit lower="0" upper="0.04" effort="20" velocity="0.2"/></joint>')
    two = _urdf(tmp_path, _two_arms() + gripper.format(s="l") + gripper.format(s="r"), "two.urdf")
    assert joints_to_hold(two, lambda names: set(names)) == ("lf", "rf")


def test_held_fingers_are_merged_as_fixed_ones_are(tmp_path):
    """The arm with its two prismatic fingers (one mimicking the other) held at 0 has the joints and inertial parameters
    of the same file with the fingers written as fixed joints (Pinocchio merging them either way); without held the
    fingers are joints, the second following the first (a coupled gripper: tests/dynamics/test_mimic_joints.py)."""
    gripper = _urdf(tmp_path, ARM + FINGERS)
    fixed = _urdf(tmp_path, ARM + FINGERS.replace('type="prismatic"', 'type="fixed"'), "fixed.urdf")
    joints = joints_from_urdf(gripper)[0]
    assert [j.name for j in joints] == ["j1", "j2", "f1", "f2"] and joints[3].mimic == (2, -1.0, 0.0)
    held = joints_from_urdf(gripper, {"f1": 0.0, "f2": 0.0})
    plain = joints_from_urdf(fixed)
    assert held[2] == plain[2] == ("j1", "j2")
    np.testing.assert_allclose(held[1], plain[1], rtol=1e-12, atol=1e-15)
    assert held[1][1, 9] == pytest.approx(2.0 + 0.7 + 0.1 + 0.1)  # l2, the hand and both fingers
    assert joints_to_hold(gripper) == ("f1", "f2") and joints_to_hold(fixed) == ()
    robot = robot_from_document({"convention": "urdf", "urdf": "arm.urdf", "held": ["f1", "f2"]}, "arm.toml", tmp_path)
    assert robot.n_dof == 2 and robot.held == ("f1", "f2")
    opened = robot_from_document({"convention": "urdf", "urdf": "arm.urdf", "held": {"f1": 0.03, "f2": 0.03}},
                                 "arm.toml", tmp_path)
    assert not np.allclose(opened.inertial[1], robot.inertial[1])  # the fingers' mass elsewhere: another first moment
    assert opened.inertial[1][9] == pytest.approx(robot.inertial[1][9])


def test_held_is_refused_where_it_cannot_mean_anything(tmp_path):
    _urdf(tmp_path, ARM + FINGERS)
    with pytest.raises(ConfigError, match=r"arm.urdf: held names joint 'f3', which the URDF's moving joints do not "
                                          r"include \(j1, j2, f1, f2\)"):
        robot_from_document({"convention": "urdf", "urdf": "arm.urdf", "held": ["f1", "f2", "f3"]}, "arm.toml",
                            tmp_path)
    with pytest.raises(ConfigError, match=r"arm.toml: held names joints of a URDF to hold fixed, but this description "
                                          r"has no URDF"):
        robot_from_document({"convention": "modified", "held": ["f1"], "joints": [{"mass": 1.0, "com": [0, 0, 0],
                             "inertia": [1, 1, 1, 0, 0, 0]}]}, "arm.toml", tmp_path)


def test_write_back_keeps_the_held_fingers_inertials_and_the_model_loads(tmp_path):
    """issue "Nothing runs, nothing silent": the identified URDF removed the fingers' <inertial> (their mass moved into
    the hand's link) while keeping their prismatic joints, so the full model's mass matrix was singular and forward
    dynamics gave NaN. The fingers now keep their own <inertial>, the link they hang on gets the identified values less
    theirs: read back with the same held joints it gives the values written, and with the fingers free its mass matrix
    is positive definite."""
    import pinocchio as pin

    path = _urdf(tmp_path, ARM + FINGERS)
    robot = robot_from_document({"convention": "urdf", "urdf": "arm.urdf", "held": ["f1", "f2"]}, "arm.toml", tmp_path)
    phi = robot.standard_parameters().copy()
    phi[robot.parameter_names.index("M2")] *= 1.1  # link 2's mass 10 % more: a value to find again
    text, _ = urdf_written_back(path, robot, phi)
    assert len(re.findall(r"<mass value=", text)) == 5  # base, l1, l2 (the hand merged: fixed), both fingers
    assert "the inertials of hand (fixed to this link)" in text
    assert re.search(r'<link name="f1_link"><inertial><origin xyz="0 0.01 0.05"/><mass value="0.1"/>', text)
    assert text.count('type="prismatic"') == 2 and '<mimic joint="f1"' in text
    again = tmp_path / "again.urdf"
    again.write_text(text)
    read = robot_from_document({"convention": "urdf", "urdf": again.name, "held": ["f1", "f2"]}, "again.toml", tmp_path)
    np.testing.assert_allclose(read.inertial, robot.with_parameters(phi).inertial, rtol=1e-9, atol=1e-12)
    assert read.inertial[1, 9] == pytest.approx(1.1 * robot.inertial[1, 9])
    model = pin.buildModelFromUrdf(str(again))  # every joint free, the fingers' too
    data = model.createData()
    for q in (pin.neutral(model), pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))):
        mass = pin.crba(model, data, q)
        assert np.linalg.eigvalsh(0.5 * (mass + mass.T)).min() > 0 and np.isfinite(np.linalg.cond(mass))
        assert np.all(np.isfinite(pin.aba(model, data, q, np.zeros(model.nv), np.zeros(model.nv))))


def test_a_branch_before_the_arm_in_pinocchios_order_is_the_joint_held(tmp_path):
    """A revolute joint on a branch of its own from the base (a camera's pan joint) named so that Pinocchio's
    depth-first order puts it before the arm's first joint: the arm is the longest chain, so the branch is what dynid
    init holds, never the arm; read whole, the file is a tree whose arm rides on the base beside the branch."""
    camera = _link("camera", 0.3, "0 0 0.02") + _revolute("a_camera_pan", "base", "camera", "0.1 0 0.1", "0 0 1")
    urdf = _urdf(tmp_path, ARM + camera)
    import pinocchio as pin

    assert list(pin.buildModelFromUrdf(str(urdf)).names)[1:] == ["a_camera_pan", "j1", "j2"]  # the branch first
    assert joints_to_hold(urdf) == ("a_camera_pan",)
    joints = joints_from_urdf(urdf)[0]  # the whole tree, the arm's first joint on the base beside the branch
    assert [(j.name, j.parent) for j in joints] == [("a_camera_pan", None), ("j1", -1), ("j2", None)]
    assert joints_from_urdf(urdf, {"a_camera_pan": 0.0})[2] == ("j1", "j2")
    assert joints_to_hold(urdf, lambda names: {"a_camera_pan", "j1", "j2"}) == ()  # a log of every joint: the tree
    gripper = _urdf(tmp_path, ARM + camera + FINGERS, "gripper.urdf")
    assert joints_to_hold(gripper) == ("a_camera_pan", "f1", "f2")


def test_init_holds_the_joints_off_the_arm(tmp_path):
    """dynid init on a URDF with a gripper: the config's [robot] table holds the fingers, and it reads as a robot of
    the arm's joints."""
    urdf = _urdf(tmp_path, ARM + FINGERS)
    t = np.arange(200) * 0.01
    (tmp_path / "log.csv").write_text("".join(f"{x},{np.sin(x)},{np.cos(x)},{0.5 * x},{-x}\n" for x in t))
    text, notes = starter_config(urdf, tmp_path / "log.csv", 2, tmp_path / "arm.toml", joints=("j1", "j2"),
                                 held=("f1", "f2"))
    doc = tomllib.loads(text)
    assert doc["robot"] == {"urdf": "arm.urdf", "held": ["f1", "f2"], "drive_terms": ["Ia", "fc", "fv", "offset"]}
    assert any("f1, f2 not on the arm's serial chain" in n for n in notes)
    robot = robot_from_document(doc["robot"], "arm.toml", tmp_path)
    assert robot.n_dof == 2


@pytest.mark.parametrize("header", [True, False])
def test_init_names_the_joints_to_hold_where_the_log_has_fewer(tmp_path, header):
    """A URDF whose chain ends in a revolute gripper joint (the Z1's, the SO-100's) and a log of the arm's two joints:
    init cannot tell the gripper from the arm, and its refusal names the setting that holds it."""
    urdf = _urdf(tmp_path, ARM + _link("jaw", 0.2, "0 0 0.02")
                 + _revolute("gripper", "hand", "jaw", "0 0 0.1", "1 0 0"))
    t = np.arange(100) * 0.01
    rows = "".join(f"{x},{np.sin(x)},{np.cos(x)},{x},{-x}\n" for x in t)
    (tmp_path / "log.csv").write_text(("t,q1,q2,tau1,tau2\n" if header else "") + rows)
    with pytest.raises(DataError, match=r"if the log holds the first 2 of arm.urdf's joints and the rest are a "
                                        r"gripper's, hold them: \[robot\] urdf = \"arm.urdf\", held = \[\"gripper\"\]"):
        starter_config(urdf, tmp_path / "log.csv", 3, tmp_path / "arm.toml", joints=("j1", "j2", "gripper"))


def test_init_offers_no_held_joints_for_a_built_in_robot(tmp_path):
    """``dynid init ur10e`` on a log of one joint: refused as having too few columns, without the hint that holds a
    URDF's gripper joints (it offered ``[robot] urdf = "ur10e", held = [5 of the arm's joints]``: no such file, and
    no gripper on a built-in arm)."""
    (tmp_path / "log.csv").write_text("t,q1,tau1\n0,1,2\n0.1,1.1,2.1\n")
    ur10e = tuple(j.name for j in dynid.load_robot("ur10e").joints)
    with pytest.raises(DataError, match="found 1 positions column") as caught:
        starter_config(Path("ur10e"), tmp_path / "log.csv", 6, tmp_path / "arm.toml", joints=ur10e)
    assert "held = " not in str(caught.value) and "gripper" not in str(caught.value)


def _two_arms():
    """A torso with two arms of two joints each (``l1``, ``l2`` and ``r1``, ``r2``), the left one first in the file."""
    arms = []
    for side, y in (("l", 0.3), ("r", -0.3)):
        arms += [_link(f"{side}_link1", 2.5, "0 0 0.15"), _link(f"{side}_link2", 1.5, "0.15 0 0"),
                 _revolute(f"{side}1", "base", f"{side}_link1", f"0 {y} 0.5", "0 0 1"),
                 _revolute(f"{side}2", f"{side}_link1", f"{side}_link2", "0 0 0.3", "0 1 0")]
    return _link("base", 10.0, "0 0 0.2") + "".join(arms)


def _arm_log(path, robot, columns):
    """A log of ``robot``'s motion and its inverse dynamics, under the given column names."""
    from dynid.dynamics.rnea import rnea_torques

    t = np.arange(2000) / 100.0
    w = 2 * np.pi * np.array([0.1, 0.13])
    q = 0.8 * np.sin(w * t[:, None])
    dq, ddq = 0.8 * w * np.cos(w * t[:, None]), -0.8 * w**2 * np.sin(w * t[:, None])
    tau = rnea_torques(robot, q, dq, ddq)
    np.savetxt(path, np.column_stack([t, q, tau]), delimiter=",", header=",".join(["time", *columns]), comments="")


def test_init_takes_the_arm_the_log_names_and_holds_the_other(tmp_path):
    """A two-arm robot and a log of its right arm: init takes the arm whose joints the log's columns name (it took the
    first arm as long, whose columns the log has not, and refused the log), holds the other; a log of both arms takes
    both as one robot (a tree), and ``--arm`` one of them, saying the other's columns are there."""
    from dynid.io.logs.columns import joints_named

    from ..cli.refusals import assert_refused
    from ..cli.refusals import dynid as run

    urdf = _urdf(tmp_path, _two_arms(), "torso.urdf")
    assert joints_to_hold(urdf) == ("r1", "r2")  # no log: the first of the longest chains, as before
    right = dynid.load_robot(urdf, held=("l1", "l2"))
    _arm_log(tmp_path / "right.csv", right, ["r1_pos", "r2_pos", "r1_effort", "r2_effort"])
    assert joints_named(tmp_path / "right.csv", ("l1", "l2", "r1", "r2")) == {"r1", "r2"}
    assert joints_to_hold(urdf, lambda names: joints_named(tmp_path / "right.csv", names)) == ("l1", "l2")
    p = run("init", urdf, tmp_path / "right.csv", "--out", tmp_path / "right.toml")
    assert p.returncode == 0, p.stderr
    doc = tomllib.loads((tmp_path / "right.toml").read_text())
    assert doc["robot"]["held"] == ["l1", "l2"]
    assert doc["identification"]["positions"]["columns"] == ["r1_pos", "r2_pos"]
    assert "another branch" not in p.stdout
    both = tmp_path / "both.csv"
    _arm_log(both, right, ["l1_pos", "l2_pos", "l1_effort", "l2_effort"])
    lines = both.read_text().splitlines()
    both.write_text("\n".join([lines[0] + ",r1_pos,r2_pos,r1_effort,r2_effort"]
                              + [row + "," + row.split(",", 1)[1] for row in lines[1:]]) + "\n")
    p = run("init", urdf, both, "--out", tmp_path / "both.toml")
    assert p.returncode == 0, p.stderr
    doc = tomllib.loads((tmp_path / "both.toml").read_text())  # both arms as one robot: nothing held
    assert doc["robot"] == "torso.urdf"
    assert doc["identification"]["positions"]["columns"] == ["l1_pos", "l2_pos", "r1_pos", "r2_pos"]
    assert "another branch" not in p.stdout
    p = run("init", urdf, both, "--arm", "r1", "--out", tmp_path / "other.toml")  # one arm, as asked
    assert p.returncode == 0, p.stderr
    doc = tomllib.loads((tmp_path / "other.toml").read_text())
    assert doc["robot"]["held"] == ["l1", "l2"]
    assert doc["identification"]["positions"]["columns"] == ["r1_pos", "r2_pos"]
    said = " ".join(p.stdout.split())
    assert "both.csv also holds columns of l1, l2, on another branch of torso.urdf: held as --arm asks" in said
    assert "dynid init torso.urdf both.csv --arm l1 --out <another config>" in said
    assert_refused(run("init", urdf, both, "--arm", "r3", "--out", tmp_path / "x.toml"),
                   "--arm r3: no moving joint of torso.urdf is named so (it has l1, l2, r1, r2)")
    single = _urdf(tmp_path, ARM, "single.urdf")
    assert_refused(run("init", single, both, "--arm", "j1", "--out", tmp_path / "y.toml"),
                   "--arm j1: single.urdf is one serial chain (no other arm to leave out); leave --arm out")


def test_the_second_arm_identified_on_the_first_arms_written_urdf_holds_both(tmp_path):
    """The docs' two-arm recipe: the right arm identified, then the left arm with the URDF that run wrote as its robot
    file: the file the second run writes holds the first run's right arm and the second run's left arm."""
    from ..cli.refusals import dynid as run

    urdf = _urdf(tmp_path, _two_arms(), "torso.urdf")
    rng = np.random.default_rng(5)
    for side, other in (("r", "l"), ("l", "r")):  # the logs of a robot whose links are 10-40 % off the file's
        truth = dynid.load_robot(urdf, held=(f"{other}1", f"{other}2"))
        phi = truth.standard_parameters() * np.repeat(rng.uniform(0.6, 1.4, truth.n_dof), truth.n_params_per_joint)
        _arm_log(tmp_path / f"{side}.csv", truth.with_parameters(phi), [f"{side}1_pos", f"{side}2_pos", f"{side}1_effort",
                                                                          f"{side}2_effort"])
    assert run("init", urdf, tmp_path / "r.csv", "--out", tmp_path / "r.toml", "-q").returncode == 0
    assert run("identify", tmp_path / "r.toml", "--out", tmp_path / "r_id", "--no-figures", "-q").returncode == 0
    first = tmp_path / "right-identified.urdf"
    first.write_text((tmp_path / "r_id" / "torso.urdf").read_text())
    assert run("init", first, tmp_path / "l.csv", "--out", tmp_path / "l.toml", "-q").returncode == 0
    assert run("identify", tmp_path / "l.toml", "--out", tmp_path / "l_id", "--no-figures", "-q").returncode == 0
    both = tmp_path / "l_id" / "right-identified.urdf"

    def arm(path, side):
        other = "l" if side == "r" else "r"
        return dynid.load_robot(path, held=(f"{other}1", f"{other}2")).inertial

    np.testing.assert_allclose(arm(both, "r"), arm(first, "r"), rtol=1e-12, atol=1e-12)  # the first run's right arm
    assert not np.allclose(arm(first, "r"), arm(urdf, "r"))  # identified by it
    np.testing.assert_allclose(arm(first, "l"), arm(urdf, "l"), rtol=1e-12, atol=1e-12)  # the left as the file had it
    assert not np.allclose(arm(both, "l"), arm(urdf, "l"))  # then identified by the second run


def test_init_on_a_bag_of_one_arm_takes_that_arm_and_names_the_others_joints(tmp_path):
    """ROS bags of a two-arm robot: a bag of the right arm's joints makes it the arm (init took the first arm and the
    bag's read refused the joints it lacks); a bag of both arms takes both as one robot (a tree)."""
    import sys

    from dynid.dynamics.rnea import rnea_torques

    from ..cli.refusals import dynid as run

    sys.path.insert(0, str(Path(__file__).parents[1] / "io"))
    from test_bags import _write_bag

    urdf = _urdf(tmp_path, _two_arms(), "torso.urdf")
    right = dynid.load_robot(urdf, held=("l1", "l2"))
    t = np.arange(2000) / 100.0
    w = 2 * np.pi * np.array([0.1, 0.13])
    q, dq, ddq = 0.8 * np.sin(w * t[:, None]), 0.8 * w * np.cos(w * t[:, None]), -0.8 * w**2 * np.sin(w * t[:, None])
    tau = rnea_torques(right, q, dq, ddq)
    _write_bag(tmp_path / "right_bag", t + 100.0, ["r1", "r2"], q, dq, tau)
    p = run("init", urdf, tmp_path / "right_bag", "--out", tmp_path / "right.toml")
    assert p.returncode == 0, p.stderr
    assert tomllib.loads((tmp_path / "right.toml").read_text())["robot"]["held"] == ["l1", "l2"]
    both = np.hstack([q, q])
    _write_bag(tmp_path / "both_bag", t + 100.0, ["l1", "l2", "r1", "r2"], both, np.hstack([dq, dq]), np.hstack([tau, tau]))
    p = run("init", urdf, tmp_path / "both_bag", "--out", tmp_path / "both.toml")
    assert p.returncode == 0, p.stderr
    assert tomllib.loads((tmp_path / "both.toml").read_text())["robot"] == "torso.urdf"  # both arms, one robot
    assert "another branch" not in p.stdout

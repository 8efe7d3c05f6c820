"""A MuJoCo model (MJCF) as the robot's description: the chain, inertias and limits as MuJoCo compiles them, checked
against MuJoCo's own inverse dynamics (an independent Newton-Euler pass over the same compiled model); what its joints
state of the drives (armature, damping, frictionloss) is said, not taken, as a URDF's <dynamics> is."""

import re
from dataclasses import replace
from importlib import resources

import mujoco
import numpy as np
import pytest

from dynid.dynamics.regressor import regressor
from dynid.exceptions import ConfigError
from dynid.io.config.configs import config_mjcf, config_robot, config_urdf
from dynid.model.description import URDF_DYNAMICS_NOTE, load_robot
from dynid.model.description_files import mjcf_from_robot

ROBOTS = resources.files("dynid.model") / "robots"


HAND_WRITTEN = """<mujoco model="hand">
  <default><joint damping="0.5"/></default>
  <worldbody>
    <body name="l1" pos="0 0 0.1" euler="0 0 30">
      <joint name="j1" axis="0 0 1" range="-90 90"/>
      <inertial pos="0.05 0 0" mass="2" diaginertia="0.01 0.02 0.03" euler="10 20 0"/>
      <body name="l2" pos="0.3 0 0" axisangle="1 0.5 0 60">
        <joint name="j2" axis="0 1 0"/>
        <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03" mass="1.5"/>
        <body name="l3" pos="0.3 0 0" quat="0.9238795 0 0.3826834 0">
          <joint name="j3" axis="1 0 0" pos="0.02 0 0"/>
          <inertial pos="0.1 0.01 0" mass="1" fullinertia="0.01 0.012 0.013 0.001 0 0"/>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>
"""
"""An MJCF as people write them: a default class, angles in degrees (MuJoCo's default unit), euler, axis-angle and
quaternion frames, an inertia from a geom, a joint away from its body's origin."""


def _mujoco_written(tmp_path, name: str) -> str:
    """A robot's model as MuJoCo reads it, saved by MuJoCo as MJCF (its frames, quaternions and inertias as MuJoCo
    writes them): the built-in UR10e's URDF (meshes left out), or dynid's MJCF export of a DH robot; ``"hand"`` is
    :data:`HAND_WRITTEN` as it is."""
    if name == "hand":
        (tmp_path / "arm.xml").write_text(HAND_WRITTEN)
        return str(tmp_path / "arm.xml")
    if (ROBOTS / f"{name}.urdf").is_file():
        text = re.sub(r"<(visual|collision)>.*?</\1>", "", (ROBOTS / f"{name}.urdf").read_text(), flags=re.S)
        source = tmp_path / "arm.urdf"
    else:
        robot = load_robot(name)
        text, source = mjcf_from_robot(robot, robot.standard_parameters()), tmp_path / "dynid.xml"
    source.write_text(text)
    model = mujoco.MjModel.from_xml_path(str(source))
    path = tmp_path / "arm.xml"
    mujoco.mj_saveLastXML(str(path), model)
    return str(path)


def assert_predicts_mujocos_rne(robot, model, rng) -> None:
    """dynid's regressor times the robot's nominal parameters equals MuJoCo's recursive Newton-Euler (``mj_rne``,
    gravity included) of ``model`` at 20 random states, to 1e-9 of the largest torque."""
    data = mujoco.MjData(model)
    q, dq, ddq = (rng.uniform(-1.5, 1.5, (20, robot.n_dof)) for _ in range(3))
    predicted = np.einsum("njp,p->nj", regressor(robot, q, dq, ddq), robot.standard_parameters())
    expected = np.empty_like(predicted)
    for k in range(q.shape[0]):
        data.qpos[:], data.qvel[:] = q[k], dq[k]
        mujoco.mj_forward(model, data)
        data.qacc[:] = ddq[k]
        mujoco.mj_rne(model, data, 1, expected[k])
    np.testing.assert_allclose(predicted, expected, atol=1e-9 * np.abs(expected).max())


@pytest.mark.parametrize("name", ["ur10e", "er16", "hand"])
def test_an_mjcf_robot_predicts_mujocos_inverse_dynamics(tmp_path, rng, name):
    """dynid's regressor times the MJCF robot's nominal parameters equals MuJoCo's recursive Newton-Euler (mj_rne,
    gravity included) on the same file, at random states."""
    path = _mujoco_written(tmp_path, name)
    robot = load_robot(path)
    model = mujoco.MjModel.from_xml_path(path)
    assert robot.n_dof == model.nv
    assert_predicts_mujocos_rne(robot, model, rng)
    assert np.isfinite(robot.limits.q_min[0]) and (name == "hand") != np.all(np.isfinite(robot.limits.q_min))  # ranges
    assert (robot.nominal_notes == ()) == (name == "ur10e")  # the UR10e's URDF states no friction, the others do


def test_what_an_mjcfs_joints_state_of_the_drives_is_said_not_taken(tmp_path):
    """dynid's own MJCF export writes each joint's rotor inertia, viscous and Coulomb friction as armature, damping
    and frictionloss: read back, those are named joint by joint, the nominal values staying 0 as for a URDF."""
    robot = load_robot("ur10e")
    drive = np.zeros_like(robot.drive)
    drive[:, [robot.drive_terms.index(t) for t in ("Ia", "fv", "fc")]] = [[0.5, 2.0, 3.0]] * 3 + [[0.25, 1.0, 1.5]] * 3
    robot = replace(robot, drive=drive)
    path = tmp_path / "ur10e.xml"
    path.write_text(mjcf_from_robot(robot, robot.standard_parameters()))
    back = load_robot(path)
    assert not np.any(back.drive)
    assert back.nominal_notes == (f"{path}: ur10e.xml's joints state armature 0.5 (J1, J2, J3), 0.25 (J4, J5, J6); "
                                  "damping 2 (J1, J2, J3), 1 (J4, J5, J6); frictionloss 3 (J1, J2, J3), 1.5 (J4, J5, J6): "
                                  + URDF_DYNAMICS_NOTE.format(keys="Ia = and fv = and fc ="),)
    np.testing.assert_allclose(back.standard_parameters(), replace(robot, drive=np.zeros_like(drive)).standard_parameters(),
                               atol=1e-12)


def test_a_config_names_an_mjcf_as_its_robot(tmp_path):
    """robot = "arm.xml" in a config, relative to it, as a URDF is, or a [robot] table's file; the identified URDF is
    then written anew, not into the MJCF (identify failed at its end before: "has no joint ..."); a missing file names
    the field and the folders."""
    _mujoco_written(tmp_path, "ur10e")
    for doc in ({"robot": "arm.xml"}, {"robot": {"urdf": "arm.xml", "drive_terms": ["fc", "fv"]}}):
        assert config_robot(doc, tmp_path / "c.toml").n_dof == 6
        assert config_urdf(doc, tmp_path / "c.toml") is None
    assert config_urdf({"robot": {"urdf": "arm.urdf"}}, tmp_path / "c.toml") == tmp_path / "arm.urdf"
    with pytest.raises(ConfigError, match=r"c.toml: robot: file 'nope.xml' not found in"):
        config_robot({"robot": "nope.xml"}, tmp_path / "c.toml")


@pytest.mark.parametrize("body, message", [
    ('<mujoco><worldbody><body name="a"><joint name="j1" type="hinge"/></worldbody></mujoco>',
     r"arm.xml: line 1, column \d+: malformed XML \(mismatched tag\)"),
    ('<mujoco><worldbody><body name="a"><joint name="j1" type="ball"/>'
     '<inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/></body></worldbody></mujoco>',
     r"arm.xml: joint 'j1' is a ball joint, expected a hinge or a slide joint; hold it fixed with held = \[\"j1\"\]"),
])
def test_an_mjcf_dynid_cannot_model_is_one_line(tmp_path, body, message):
    (tmp_path / "arm.xml").write_text(body)
    with pytest.raises(ConfigError, match=message) as caught:
        load_robot(tmp_path / "arm.xml")
    assert "\n" not in str(caught.value)


def test_a_gripper_in_an_mjcf_is_held_and_its_bodies_count_with_the_last_link(tmp_path):
    """Two finger bodies on slide joints after the arm: read whole as a tree's branches, found by dynid init's helper,
    and held fixed through a [robot] table; their masses then belong to the last link (as a URDF's held joints do)."""
    from dynid.model.urdf import joints_to_hold

    fingers = ('<body name="f1" pos="0.2 0 0"><joint name="finger1" type="slide" axis="0 1 0"/>'
               '<inertial pos="0 0 0" mass="0.1" diaginertia="1e-4 1e-4 1e-4"/></body>'
               '<body name="f2" pos="0.2 0 0"><joint name="finger2" type="slide" axis="0 -1 0"/>'
               '<inertial pos="0 0 0" mass="0.1" diaginertia="1e-4 1e-4 1e-4"/></body>')
    text = HAND_WRITTEN.replace('fullinertia="0.01 0.012 0.013 0.001 0 0"/>',
                                'fullinertia="0.01 0.012 0.013 0.001 0 0"/>' + fingers)
    (tmp_path / "arm.xml").write_text(text)
    whole = load_robot(tmp_path / "arm.xml")  # read whole, the fingers are a branch of the last link: a tree
    assert whole.n_dof == 5 and whole.parents.tolist() == [-1, 0, 1, 2, 2]
    assert joints_to_hold(tmp_path / "arm.xml") == ("finger1", "finger2")
    robot = config_robot({"robot": {"urdf": "arm.xml", "held": ["finger1", "finger2"]}}, tmp_path / "c.toml")
    (tmp_path / "bare.xml").write_text(HAND_WRITTEN)
    bare = load_robot(tmp_path / "bare.xml")
    assert robot.n_dof == 3 and robot.inertial[2, 9] == pytest.approx(bare.inertial[2, 9] + 0.2, abs=1e-12)
    assert robot.held == ("finger1", "finger2")


def test_a_hinge_with_a_reference_angle_is_refused_naming_the_joint(tmp_path):
    (tmp_path / "arm.xml").write_text(HAND_WRITTEN.replace('<joint name="j3" axis="1 0 0" pos="0.02 0 0"/>',
                                                           '<joint name="j3" axis="1 0 0" pos="0.02 0 0" ref="10"/>'))
    with pytest.raises(ConfigError, match=r"joint 'j3' has ref = 0.1745"):
        load_robot(tmp_path / "arm.xml")


@pytest.mark.parametrize("change, parents", [
    (('<body name="l3"', '<body name="side" pos="0 0.1 0"><joint name="jb" axis="0 0 1"/>'
      '<inertial pos="0 0 0" mass="0.5" diaginertia="1e-3 1e-3 1e-3"/></body><body name="l3"'), [-1, 0, 1, 1]),
    (('<body name="l1"', '<body name="camera" pos="0 0.2 0.1"><joint name="pan" axis="0 0 1"/>'
      '<inertial pos="0 0 0" mass="0.3" diaginertia="1e-3 1e-3 1e-3"/></body><body name="l1"'), [-1, -1, 1, 2]),
])
def test_an_mjcf_with_a_branch_is_a_tree_that_predicts_mujocos_inverse_dynamics(tmp_path, rng, change, parents):
    """A branch (a side link on the elbow, a camera's pan joint on the base written before the arm) is read whole: each
    joint on the joint its body rides on, and dynid's regressor times the nominal parameters equals MuJoCo's recursive
    Newton-Euler on the file at random states; dynid init holds the branch the log has no columns for (the camera's pan
    joint, written first, is the one held, never the arm)."""
    from dynid.model.urdf import joints_to_hold

    (tmp_path / "arm.xml").write_text(HAND_WRITTEN.replace(*change))
    robot = load_robot(tmp_path / "arm.xml")
    assert robot.parents.tolist() == parents
    assert_predicts_mujocos_rne(robot, mujoco.MjModel.from_xml_path(str(tmp_path / "arm.xml")), rng)
    if "camera" in change[1]:
        assert joints_to_hold(tmp_path / "arm.xml") == ("pan",)
        robot = config_robot({"robot": {"urdf": "arm.xml", "held": ["pan"]}}, tmp_path / "c.toml")
        assert robot.n_dof == 3 and [j.name for j in robot.joints] == ["j1", "j2", "j3"]


def test_an_mjcfs_gravity_other_than_the_robots_is_said(tmp_path):
    """<option gravity> is a simulation's setting: one other than the robot's (a description's gravity, else -9.81 m/s²
    along z) is said with how to set it, not taken; the same gravity, or a description that gives one, says nothing."""
    (tmp_path / "arm.xml").write_text(HAND_WRITTEN.replace("<mujoco model=\"hand\">",
                                                           "<mujoco model=\"hand\"><option gravity=\"0 0 0\"/>"))
    robot = load_robot(tmp_path / "arm.xml")
    assert np.array_equal(robot.gravity, [0.0, 0.0, -9.81])
    assert robot.nominal_notes[-1] == (f"{tmp_path / 'arm.xml'}: arm.xml's <option gravity> is (0, 0, 0) m/s², not taken: "
                                       "the robot's gravity is (0, 0, -9.81) (gravity = [x, y, z] in the [robot] table, "
                                       "or the description, sets it)")
    given = config_robot({"robot": {"urdf": "arm.xml", "gravity": [0.0, 0.0, 0.0]}}, tmp_path / "c.toml")
    assert np.array_equal(given.gravity, [0.0, 0.0, 0.0]) and not any("<option gravity>" in n for n in given.nominal_notes)
    (tmp_path / "same.xml").write_text(HAND_WRITTEN)
    assert not any("<option gravity>" in n for n in load_robot(tmp_path / "same.xml").nominal_notes)


def test_identify_writes_into_a_copy_of_the_mjcf_the_robot_was_read_from(tmp_path):
    """As a URDF the robot comes from gets the identified values written into a copy of it, so does an MJCF: the
    config's mjcf_model defaults to it (given, the given one); a robot holding joints fixed gets a new MJCF instead
    (writing into the file would count the held bodies twice)."""
    from dynid.io.config.identification_config import load_identification_config

    path = _mujoco_written(tmp_path, "ur10e")
    (tmp_path / "log.csv").write_text("".join(f"{k * 0.01}" + ",0" * 12 + "\n" for k in range(50)))
    table = ('[identification]\nfile = "log.csv"\ntime = { column = 1 }\npositions = { columns = [2, 3, 4, 5, 6, 7] }\n'
             'torques = { columns = [8, 9, 10, 11, 12, 13] }\n')
    (tmp_path / "c.toml").write_text('robot = "arm.xml"\n' + table)
    assert config_mjcf({"robot": "arm.xml"}, tmp_path / "c.toml") == tmp_path / "arm.xml"
    assert load_identification_config(tmp_path / "c.toml").mjcf_model == tmp_path / "arm.xml"
    (tmp_path / "other.xml").write_text(open(path).read())
    (tmp_path / "given.toml").write_text('robot = "arm.xml"\nmjcf_model = "other.xml"\n' + table)
    assert load_identification_config(tmp_path / "given.toml").mjcf_model == tmp_path / "other.xml"
    (tmp_path / "held.toml").write_text('[robot]\nurdf = "arm.xml"\nheld = ["wrist_3_joint"]\n'
                                        + table.replace("2, 3, 4, 5, 6, 7", "2, 3, 4, 5, 6").replace("8, 9, 10, 11, 12, 13", "7, 8, 9, 10, 11"))
    held = load_identification_config(tmp_path / "held.toml")
    assert held.mjcf_model is None and held.robot.n_dof == 5
    six = load_robot(path)  # the held wrist's link counts with the fifth: its mass there, its first moments about it
    assert held.robot.inertial[4, 9] == pytest.approx(six.inertial[4, 9] + six.inertial[5, 9], rel=1e-12)
    assert config_mjcf({"robot": "ur10e"}, tmp_path / "c.toml") is None


def test_a_hinge_held_at_an_angle_is_the_arm_with_that_joint_at_that_angle(tmp_path, rng):
    """held = {wrist_2_joint = 0.7}: the five-joint robot's torques are the six-joint robot's with q5 = 0.7 (the wrist
    turned, at rest), on the first four joints and the sixth: the held body is turned about its joint, not left."""
    path = _mujoco_written(tmp_path, "ur10e")
    full = load_robot(path)
    held = config_robot({"robot": {"urdf": "arm.xml", "held": {"wrist_2_joint": 0.7}}}, tmp_path / "c.toml")
    q, dq, ddq = (rng.uniform(-1, 1, (10, 5)) for _ in range(3))
    widen = lambda x, v: np.insert(x, 4, v, axis=1)  # noqa: E731 - the held joint's column
    expected = np.einsum("njp,p->nj", regressor(full, widen(q, 0.7), widen(dq, 0.0), widen(ddq, 0.0)),
                         full.standard_parameters())
    got = np.einsum("njp,p->nj", regressor(held, q, dq, ddq), held.standard_parameters())
    np.testing.assert_allclose(got, np.delete(expected, 4, axis=1), atol=1e-10 * np.abs(expected).max())


def test_init_holds_an_mjcfs_gripper_and_writes_a_config_that_loads(tmp_path):
    """dynid init on an MJCF with two fingers after the arm writes held = [...] (it refused before: "joint 'finger1'
    is a slide joint"), and the config it writes reads the three-joint arm."""
    from dynid.io.config.identification_config import load_identification_config

    from ..cli.refusals import dynid as run

    fingers = ('<body name="f1" pos="0.2 0 0"><joint name="finger1" type="slide" axis="0 1 0"/>'
               '<inertial pos="0 0 0" mass="0.1" diaginertia="1e-4 1e-4 1e-4"/></body>'
               '<body name="f2" pos="0.2 0 0"><joint name="finger2" type="slide" axis="0 -1 0"/>'
               '<inertial pos="0 0 0" mass="0.1" diaginertia="1e-4 1e-4 1e-4"/></body>')
    (tmp_path / "arm.xml").write_text(HAND_WRITTEN.replace('fullinertia="0.01 0.012 0.013 0.001 0 0"/>',
                                                           'fullinertia="0.01 0.012 0.013 0.001 0 0"/>' + fingers))
    t = np.arange(500) * 0.002
    np.savetxt(tmp_path / "log.csv", np.column_stack([t, np.sin(np.outer(t, [1, 2, 3])), np.cos(np.outer(t, [1, 2, 3]))]),
               delimiter=",")
    p = run("init", str(tmp_path / "arm.xml"), str(tmp_path / "log.csv"), "--out", str(tmp_path / "arm.toml"))
    assert p.returncode == 0, p.stderr
    assert 'held = ["finger1", "finger2"]' in (tmp_path / "arm.toml").read_text()
    config = load_identification_config(tmp_path / "arm.toml")
    assert config.robot.n_dof == 3 and config.robot.held == ("finger1", "finger2") and config.mjcf_model is None


def test_an_mjcf_with_two_arms_holds_the_arm_the_log_does_not_name(tmp_path):
    """Two arms on one body: without a log the first is the arm (the other held); a log whose columns name the second
    arm's joints makes it the arm; a log of both arms, both (read whole, the file is a tree of both)."""
    from dynid.io.logs.columns import joints_named
    from dynid.model.mjcf import mjcf_joints_to_hold

    def arm(side, y):
        return (f'<body name="{side}_link1" pos="0 {y} 0.5"><joint name="{side}1" type="hinge" axis="0 0 1" range="-3 3"/>'
                f'<inertial pos="0 0 0.15" mass="2.5" diaginertia="0.01 0.02 0.015"/>'
                f'<body name="{side}_link2" pos="0 0 0.3"><joint name="{side}2" type="hinge" axis="0 1 0" range="-3 3"/>'
                f'<inertial pos="0.15 0 0" mass="1.5" diaginertia="0.01 0.02 0.015"/></body></body>')

    path = tmp_path / "two.xml"
    path.write_text(f'<mujoco model="two"><worldbody><body name="base"><inertial pos="0 0 0.2" mass="10" '
                    f'diaginertia="0.1 0.1 0.1"/>{arm("l", 0.3)}{arm("r", -0.3)}</body></worldbody></mujoco>')
    (tmp_path / "r.csv").write_text("time,r1_pos,r2_pos,r1_effort,r2_effort\n0,0,0,0,0\n0.01,0,0,0,0\n")
    assert mjcf_joints_to_hold(path) == ("r1", "r2")
    assert mjcf_joints_to_hold(path, lambda names: joints_named(tmp_path / "r.csv", names)) == ("l1", "l2")
    (tmp_path / "both.csv").write_text("time,l1_pos,l2_pos,r1_pos,r2_pos,l1_effort,l2_effort,r1_effort,r2_effort\n"
                                       "0,0,0,0,0,0,0,0,0\n0.01,0,0,0,0,0,0,0,0\n")
    assert mjcf_joints_to_hold(path, lambda names: joints_named(tmp_path / "both.csv", names)) == ()  # the tree
    assert load_robot(path).parents.tolist() == [-1, 0, -1, 2]

"""The identified values written into the user's own URDF as a text edit: a ``diff`` against the user's file shows only
the ``<inertial>`` and ``<dynamics>`` values and dynid's comments (issue "A user's first hour", item 5)."""

import difflib
import re

import numpy as np
import pytest

import dynid
from dynid.exceptions import ConfigError
from dynid.io.exported.urdf_write_back import urdf_written_back

# A URDF as vendors write them: a declaration and comments before <robot> (one with a non-ASCII letter, so byte and
# character offsets differ), " />" and "/>" mixed, an inertial spread over lines with <mass> first, a moving link with
# no inertial, a joint with no <dynamics>, a tool link fixed to the last one, meshes, a transmission naming a joint,
# tabs in one link.
USERS = """<?xml version="1.0" encoding="utf-8"?>
<!-- Généré par le fabricant: do not edit by hand -->
<!-- second comment -->
<robot name="arm3"   xmlns:xacro="http://www.ros.org/wiki/xacro">
  <link name="base_link">
    <visual><geometry><mesh filename="package://arm3/meshes/base.dae" scale="0.001 0.001 0.001"/></geometry></visual>
  </link>
  <joint name="shoulder" type="revolute">
    <parent link="base_link"/>
    <child link="upper"/>
    <origin xyz="0 0 0.3" rpy="0 0 0" />
    <axis xyz="0 0 1"/>
    <limit effort="100" velocity="2" lower="-3" upper="3"/>
    <dynamics damping="0.0"   friction="0.0" />
  </joint>
  <link name="upper">
    <inertial>
      <mass value="4.0"/>
      <origin xyz="0.0 0.0 0.1" rpy="0 0 0"/>
      <inertia ixx="0.05" ixy="0" ixz="0"
               iyy="0.05" iyz="0" izz="0.02"/>
    </inertial>
    <visual>
      <!-- the shell -->
      <geometry><mesh filename="package://arm3/meshes/upper.stl"/></geometry>
    </visual>
  </link>
  <joint name="elbow" type="revolute">
    <parent link="upper"/>
    <child link="fore"/>
    <origin xyz="0 0 0.4" rpy="1.5707963267948966 0 0"/>
    <axis xyz="0 0 1"/>
    <limit effort="50" velocity="2" lower="-3" upper="3"/>
  </joint>
  <link name="fore">
\t<collision><geometry><cylinder radius="0.05" length="0.3"/></geometry></collision>
  </link>
  <joint name="wrist" type="continuous">
    <parent link="fore"/>
    <child link="hand"/>
    <origin xyz="0.3 0 0" rpy="0 0 0"/>
    <axis xyz="1 0 0"/>
    <dynamics damping="0.1"/>
  </joint>
  <link name="hand">
    <inertial>
      <origin xyz="0.02 0 0" rpy="0 0 0"/>
      <mass value="0.5"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.002"/>
    </inertial>
  </link>
  <joint name="tool_joint" type="fixed">
    <parent link="hand"/>
    <child link="tool0"/>
    <origin xyz="0.05 0 0" rpy="0 0 0"/>
  </joint>
  <link name="tool0">
    <inertial>
      <origin xyz="0 0 0" rpy="0 0 0"/>
      <mass value="0.2"/>
      <inertia ixx="0.0001" ixy="0" ixz="0" iyy="0.0001" iyz="0" izz="0.0001"/>
    </inertial>
  </link>
  <transmission name="t1">
    <type>transmission_interface/SimpleTransmission</type>
    <joint name="shoulder"><hardwareInterface>EffortJointInterface</hardwareInterface></joint>
    <actuator name="m1"><mechanicalReduction>100</mechanicalReduction></actuator>
  </transmission>
</robot>
<!-- trailing comment -->
"""


def _identified_lines(lines):
    """Indices of the lines a write-back may change: inside an <inertial> block, a <dynamics> tag, a dynid comment."""
    keep, inside = [], None
    for k, line in enumerate(lines):
        if inside is None and re.search(r"<inertial\b|<dynamics\b|<!-- (dynid|written by dynid)", line):
            inside = {"<inertial": "</inertial>", "<dynamics": "/>"}.get(
                re.search(r"<inertial|<dynamics|<!--", line).group(0), "-->")
        if inside is not None:
            keep.append(k)
            if inside in line:
                inside = None
    return set(keep)


def _scaled(robot, rng):
    phi = robot.standard_parameters().copy()
    names = list(robot.parameter_names)
    for j in range(robot.n_dof):
        scale = rng.uniform(0.7, 1.3)
        for term in ("XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M"):
            phi[names.index(f"{term}{j + 1}")] *= scale
        phi[names.index(f"fv{j + 1}")] = 0.25 * (j + 1)
        phi[names.index(f"fc{j + 1}")] = 1.5 * (j + 1)
    return phi


def test_a_diff_against_the_users_urdf_shows_only_the_identified_values(tmp_path):
    users = tmp_path / "arm3.urdf"
    users.write_text(USERS, encoding="utf-8")
    robot = dynid.load_robot(users)
    assert [j.name for j in robot.joints] == ["shoulder", "elbow", "wrist"]
    robot = robot.with_parameters(robot.standard_parameters())  # the tool's mass is in the hand's link for dynid too
    phi = _scaled(robot, np.random.default_rng(3))
    text, moved = urdf_written_back(users, robot, phi)
    back = tmp_path / "back.urdf"
    back.write_text(text, encoding="utf-8")
    before, after = USERS.splitlines(), text.splitlines()
    # every line outside the identified elements is the user's, byte for byte and in order (declaration, comments
    # before and after <robot>, the root's attributes, meshes, tabs, the transmission's <joint>)
    a_free, b_free = _identified_lines(before), _identified_lines(after)
    assert [x for k, x in enumerate(before) if k not in a_free] == [x for k, x in enumerate(after) if k not in b_free]
    changed = [ln for ln in difflib.unified_diff(before, after, lineterm="", n=0)
               if ln[:1] in "+-" and not ln.startswith(("+++", "---"))]
    assert changed and all(re.search(r"inertial|<origin|<mass|<inertia|i[xyz]{2}=|<dynamics|dynid|^\+\s+\S", c)
                           for c in changed)
    assert text.startswith('<?xml version="1.0" encoding="utf-8"?>\n<!-- Généré par le fabricant')
    assert text.endswith("</robot>\n<!-- trailing comment -->\n")
    # read back (dynid's reader, Pinocchio's parser): the values are those written, names kept
    import pinocchio as pin

    again = dynid.load_robot(back)
    np.testing.assert_allclose(again.inertial, robot.with_parameters(phi).inertial, rtol=1e-12, atol=1e-14)
    model = pin.buildModelFromUrdf(str(back))
    assert list(model.names)[1:] == ["shoulder", "elbow", "wrist"]
    np.testing.assert_allclose(model.damping, [0.25, 0.5, 0.75])
    np.testing.assert_allclose(model.friction, [1.5, 3.0, 4.5])
    # the tool's inertial moved into the hand's, said in a comment; the link without one got one
    assert len(re.findall(r"^\s*<inertial>", text, flags=re.M)) == 3 and "the inertials of tool0 (fixed to this link)" in text
    assert 'damping="0.75" friction="4.5"' in text  # an attribute the joint lacked is added, in the file's style
    assert moved == [] or all(m.split(":")[0] in ("upper", "fore", "hand") for m in moved)


def test_a_users_urdf_that_is_not_xml_is_refused_in_one_line(tmp_path):
    bad = tmp_path / "bad.urdf"
    bad.write_text(USERS.replace("</robot>", "</robt>"), encoding="utf-8")
    good = tmp_path / "good.urdf"
    good.write_text(USERS, encoding="utf-8")
    robot = dynid.load_robot(good)
    with pytest.raises(ConfigError, match=r"bad\.urdf: cannot read it as URDF \(mismatched tag"):
        urdf_written_back(bad, robot, robot.standard_parameters())


def test_a_robot_mounted_otherwise_keeps_its_gravity_in_a_comment_and_is_read_back_with_it(tmp_path):
    """A config's gravity (a wall or a tilted mount) is not the URDF's -z: the written-back URDF said nothing of it, and
    its read-back by Pinocchio with -z differed from dynid's model by 29 % of its RMS on a tilted UR10e's log. The
    header comment gives the gravity, and the read-back uses it: the file equals the model to round-off. A robot along
    -z gets no such comment."""
    from dataclasses import replace

    from dynid.io.exported.replay import urdf_replay

    users = tmp_path / "arm3.urdf"
    users.write_text(USERS, encoding="utf-8")
    upright = dynid.load_robot(users)
    upright = upright.with_parameters(upright.standard_parameters())
    phi = _scaled(upright, np.random.default_rng(3))
    tilted = replace(upright, gravity=np.array([-4.18, 0.0, -8.88]))
    text, _ = urdf_written_back(users, tilted, phi)
    assert "dynid: gravity is -4.18 0 -8.88 m/s² in this robot's base frame" in text
    assert "dynid: gravity is" not in urdf_written_back(users, upright, phi)[0]
    assert urdf_replay(text, tilted, phi).relative_error < 1e-9
    assert urdf_replay(text, upright, phi).relative_error < 1e-9

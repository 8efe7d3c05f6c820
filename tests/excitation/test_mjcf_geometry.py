"""An MJCF robot's own collision geoms against the cell (issue "An excitation safe to run on the real robot", items 1
and 2: the design's distances and the MuJoCo check use the robot's own geometry). A hand-written MJCF arm carries
every kind of colliding geom, visual-only geoms and a held finger; the shapes dynid reads must sit where MuJoCo puts
the file's geoms and measure the distances MuJoCo measures on the file itself."""

from pathlib import Path

import mujoco
import numpy as np
import pytest

from dynid.exceptions import ConfigError
from dynid.excitation.cell_replay import cell_contacts
from dynid.excitation.constraints import Workspace
from dynid.excitation.link_geometry import FAR, link_geometry_from_mjcf, self_pairs
from dynid.excitation.obstacles import Obstacle
from dynid.io.config.excitation_config import load_excitation_config
from dynid.model.description import load_robot

ARM = """<mujoco model="cell-arm">
  <compiler angle="radian"/>
  <asset>
    <mesh name="wedge" vertex="0 0 0  0.08 0 0  0 0.06 0  0 0 0.1  0.05 0.05 0.05  0.02 0.01 0.09"/>
  </asset>
  <default><default class="visual"><geom contype="0" conaffinity="0" group="2"/></default></default>
  <worldbody>
    <geom name="floor" type="plane" size="2 2 0.1"/>
    <body name="base" pos="0.1 0 0.05">
      <geom name="pedestal" type="cylinder" size="0.08 0.05"/>
      <body name="upper" pos="0 0 0.1" euler="0 0 0.4">
        <joint name="j1" axis="0 0 1"/>
        <inertial pos="0 0 0.1" mass="2" diaginertia="0.02 0.02 0.01"/>
        <geom name="shoulder" type="sphere" size="0.07" pos="0 0 0.05"/>
        <geom name="shoulder_look" class="visual" type="sphere" size="0.2"/>
        <body name="fore" pos="0 0 0.2" quat="0.9238795 0.3826834 0 0">
          <joint name="j2" axis="0 1 0" pos="0 0 0.01"/>
          <inertial pos="0.15 0 0" mass="1.5" diaginertia="0.01 0.02 0.02"/>
          <geom name="upper_arm" type="capsule" fromto="0 0 0 0.3 0 0" size="0.04"/>
          <geom name="elbow_box" type="box" size="0.03 0.05 0.02" pos="0.3 0 0" euler="0.2 0.1 0.3"/>
          <body name="wrist" pos="0.3 0 0">
            <joint name="j3" axis="1 0 0"/>
            <inertial pos="0.05 0 0" mass="0.8" diaginertia="0.002 0.003 0.003"/>
            <geom name="wrist_egg" type="ellipsoid" size="0.05 0.03 0.02" pos="0.05 0 0"/>
            <geom name="wrist_mesh" type="mesh" mesh="wedge" pos="0.08 0.02 0" euler="0.3 0 0.5"/>
            <body name="flange" pos="0.12 0 0">
              <geom name="flange_disc" type="cylinder" size="0.03 0.01" euler="0 1.5707963 0"/>
              <body name="finger" pos="0.02 0 0">
                <joint name="finger_joint" type="slide" axis="0 1 0"/>
                <inertial pos="0 0 0" mass="0.05" diaginertia="1e-5 1e-5 1e-5"/>
                <geom name="finger_pad" type="box" size="0.01 0.01 0.02"/>
              </body>
            </body>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>
"""
"""Colliding geoms of every kind MuJoCo has for a link (sphere, capsule, box, ellipsoid, mesh, cylinder), a
visual-only geom of a default class, a geom on a body without a joint (rides on the wrist), a held slide joint's
finger, one on the base and the world's floor."""

COLLIDING = ("pedestal", "shoulder", "upper_arm", "elbow_box", "wrist_egg", "wrist_mesh", "flange_disc", "finger_pad")


@pytest.fixture(scope="module")
def arm(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("mjcf") / "arm.xml"
    path.write_text(ARM)
    return path


def _robot(arm):
    return load_robot(arm, held=("finger_joint",))


def test_the_shapes_are_the_colliding_geoms_where_mujoco_places_them(arm, rng):
    robot = _robot(arm)
    geometry = link_geometry_from_mjcf(robot, arm)
    assert geometry is not None and set(geometry.names) == set(COLLIDING)  # not the visual one, not the floor
    assert dict(zip(geometry.names, geometry.link.tolist())) == {
        "pedestal": -1, "shoulder": 0, "upper_arm": 1, "elbow_box": 1, "wrist_egg": 2, "wrist_mesh": 2,
        "flange_disc": 2, "finger_pad": 2}
    model = mujoco.MjModel.from_xml_path(str(arm))
    data = mujoco.MjData(model)
    q = rng.uniform(-2.5, 2.5, (6, robot.n_dof))
    rotation, position = geometry.poses(robot, q)
    for n in range(q.shape[0]):
        data.qpos[:robot.n_dof] = q[n]
        mujoco.mj_kinematics(model, data)
        for s, name in enumerate(geometry.names):
            g = model.geom(name).id
            np.testing.assert_allclose(position[n, s], data.geom_xpos[g], atol=1e-12)
            np.testing.assert_allclose(rotation[n, s], data.geom_xmat[g].reshape(3, 3), atol=1e-12)


def test_each_shape_measures_the_distance_mujoco_measures_on_the_file(arm, rng):
    """A ball added to the file's world: MuJoCo's own distance from it to each of the file's geoms (mj_geomDistance)
    equals coal's from the ball to dynid's shape of that geom (the clearance 0), at random poses and a ball moved
    about; pairs whose bounding spheres are :data:`FAR` apart stand by that lower bound."""
    robot = _robot(arm)
    geometry = link_geometry_from_mjcf(robot, arm)
    radius = 0.06
    compared = 0
    for centre in rng.uniform([-0.3, -0.3, 0.1], [0.4, 0.4, 0.6], (6, 3)):
        compared += _against_a_ball(arm, robot, geometry, centre, radius, rng.uniform(-2.5, 2.5, (8, robot.n_dof)))
    assert compared >= 20


def _against_a_ball(arm, robot, geometry, centre, radius, q) -> int:
    """The pairs of :func:`test_each_shape_measures_the_distance_mujoco_measures_on_the_file` compared exactly."""
    text = ARM.replace("  </worldbody>", f'    <geom name="ball" type="sphere" size="{radius}" pos="{" ".join(map(str, centre))}" '
                       'contype="0" conaffinity="0"/>\n  </worldbody>')
    model = mujoco.MjModel.from_xml_string(text)
    data = mujoco.MjData(model)
    ws = Workspace(clearance=0.0, obstacles=(Obstacle("sphere", np.array([radius]), centre, name="ball"),),
                   geometry=geometry)
    found = ws.cell_distances(robot, q)
    moving = [s for s, k in enumerate(geometry.link) if k >= 0]
    compared = 0
    for n in range(q.shape[0]):
        data.qpos[:robot.n_dof] = q[n]
        mujoco.mj_forward(model, data)
        for column, s in enumerate(moving):
            truth = mujoco.mj_geomDistance(model, data, model.geom(geometry.names[s]).id, model.geom("ball").id, 10.0, None)
            assert found.distance[n, column] <= truth + 1e-6
            if found.distance[n, column] < FAR:
                np.testing.assert_allclose(found.distance[n, column], truth, atol=1e-4)
                compared += 1
    return compared


def test_mujocos_check_collides_the_files_own_geoms(arm):
    """A box over the elbow at q = 0: MuJoCo's check of the cell finds the elbow's link (2) touching it; moved away, none."""
    robot = _robot(arm)
    geometry = link_geometry_from_mjcf(robot, arm)
    rotation, position = geometry.poses(robot, np.zeros((1, robot.n_dof)))
    elbow = position[0, geometry.names.index("elbow_box")]
    for offset, touching in ((np.zeros(3), True), (np.array([0.0, 0.0, 1.5]), False)):
        crate = Obstacle("box", np.array([0.04, 0.04, 0.04]), elbow + offset, name="crate")
        found = cell_contacts(robot, np.zeros(1), np.zeros((1, robot.n_dof)),
                              Workspace(clearance=0.01, obstacles=(crate,), geometry=geometry))
        assert (found.touching > 0) == touching
        if touching:
            assert found.first["body"] == "crate" and found.first["link"] == 2


def _config(tmp_path: Path, arm: Path, geometry: str | None) -> Path:
    cfg = tmp_path / f"excite-{geometry}.toml"
    cfg.write_text(f'[robot]\nurdf = "{arm}"\nheld = ["finger_joint"]\n[trajectory]\nharmonics = 2\nfrequency = 0.1\n'
                   '[workspace]\n' + (f'geometry = "{geometry}"\n' if geometry else "")
                   + '[[workspace.obstacles]]\nshape = "box"\nsize = [0.2, 0.2, 0.2]\nposition = [0.6, 0.4, 0.3]\n')
    return cfg


def test_the_config_takes_the_mjcfs_geoms_and_says_when_there_are_none(arm, tmp_path):
    found = load_excitation_config(_config(tmp_path, arm, None)).problem.workspace.geometry
    assert found is not None and set(found.names) == set(COLLIDING) and found.source == str(arm)
    assert load_excitation_config(_config(tmp_path, arm, "capsules")).problem.workspace.geometry is None
    bare = tmp_path / "visual_only.xml"
    bare.write_text(ARM.replace('<default><default class="visual">', '<default><geom contype="0" conaffinity="0"/>'
                                '<default class="visual">'))
    assert load_excitation_config(_config(tmp_path, bare, None)).problem.workspace.geometry is None
    with pytest.raises(ConfigError, match=r"visual_only\.xml has no colliding geom \(contype or conaffinity not 0\) on a "
                                          "moving link"):
        load_excitation_config(_config(tmp_path, bare, "collision"))


def test_the_pairs_the_file_keeps_mujoco_from_colliding_are_not_kept_apart(arm, tmp_path):
    """An ``<exclude>`` of two bodies and a geom whose bit masks meet no other's: their pairs, read off the file by
    MuJoCo's rules (contype of one and conaffinity of the other share no bit), are excluded and left out of the self
    pairs."""
    text = (ARM.replace('<geom name="finger_pad" type="box"', '<geom name="finger_pad" contype="2" conaffinity="2" type="box"')
            .replace("</worldbody>", '</worldbody>\n  <contact><exclude body1="base" body2="wrist"/></contact>'))
    path = tmp_path / "excluding.xml"
    path.write_text(text)
    robot = load_robot(path, held=("finger_joint",))
    geometry = link_geometry_from_mjcf(robot, path)
    named = {frozenset((geometry.names[g], geometry.names[h])) for g, h in geometry.excluded}
    expected = ({frozenset(("pedestal", w)) for w in ("wrist_egg", "wrist_mesh")}
                | {frozenset(("finger_pad", other)) for other in COLLIDING if other != "finger_pad"})
    assert named == expected
    assert not set(self_pairs(robot, geometry)) & geometry.excluded
    assert set(self_pairs(robot, link_geometry_from_mjcf(robot, arm))) & geometry.excluded  # the plain file checks some

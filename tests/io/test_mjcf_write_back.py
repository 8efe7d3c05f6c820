"""Write-back into the user's own MJCF: MuJoCo's inverse dynamics of the written model equals dynid's prediction,
though the MJCF's bodies sit at frames of their own, and everything but the identified values is kept."""

import xml.etree.ElementTree as ET
from importlib import resources
from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.dynamics.base_parameters import base_parameters
from dynid.dynamics.kinematics import forward_kinematics
from dynid.dynamics.regressor import regressor
from dynid.exceptions import ConfigError
from dynid.io.exported.mjcf_write_back import mjcf_written_back

from .test_export import _with_friction

mujoco = pytest.importorskip("mujoco")
pin = pytest.importorskip("pinocchio")

TETRAHEDRON = "v 0 0 0\nv 0.05 0 0\nv 0 0.05 0\nv 0 0 0.05\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"


def _quat(rotation):
    q = pin.Quaternion(rotation)
    return f"{q.w:.17g} {q.x:.17g} {q.y:.17g} {q.z:.17g}"


def _vec(v):
    return " ".join(f"{x:.17g}" for x in v)


def _users_mjcf(robot, rng, inertiafromgeom="true"):
    """An MJCF of the robot as a user would have it, built independently of dynid's exporter: the base turned by π
    and moved, every body at a random frame of its own (so joints have a pos and an axis in it), a mesh geom and a
    wrong inertial in each body, a welded tool with a mass of its own on the last body, a site and an actuator."""
    rotations, origins = forward_kinematics(robot, np.zeros((1, robot.n_dof)))
    world = pin.SE3(pin.utils.rotate("z", np.pi), np.array([0.1, -0.2, 0.3]))
    frames = [world * pin.SE3(rotations[0, j], origins[0, j]) * pin.SE3(pin.utils.rpyToMatrix(*rng.uniform(-np.pi, np.pi, 3)),
                                                                       rng.uniform(-0.1, 0.1, 3)) for j in range(robot.n_dof)]
    lines = ["<mujoco model='users_arm'>", f"  <compiler angle='radian' meshdir='meshes' inertiafromgeom='{inertiafromgeom}'/>",
             "  <asset><mesh name='piece' file='piece.obj'/></asset>", "  <worldbody>",
             f"    <body name='base' pos='{_vec(world.translation)}' quat='{_quat(world.rotation)}'>",
             "      <geom type='box' size='.1 .1 .1'/>"]
    parent = world
    for j, joint in enumerate(robot.joints):
        local = parent.actInv(frames[j])
        axis = frames[j].rotation.T @ (world.rotation @ rotations[0, j] @ np.asarray(joint.axis, dtype=float))
        anchor = frames[j].actInv(world.act(origins[0, j]))
        lines += [f"{'  ' * (j + 3)}<body name='body_{joint.name}' pos='{_vec(local.translation)}' quat='{_quat(local.rotation)}'>",
                  f"{'  ' * (j + 4)}<joint name='{joint.name}' pos='{_vec(anchor)}' axis='{_vec(axis)}' damping='9'/>",
                  f"{'  ' * (j + 4)}<inertial pos='0.01 0.02 0.03' mass='{1.5 + j}' diaginertia='0.1 0.2 0.25'/>",
                  f"{'  ' * (j + 4)}<geom type='mesh' mesh='piece'/>"]
        parent = frames[j]
    tip = "  " * (robot.n_dof + 3)
    lines += [f"{tip}<body name='tool' pos='0 0 0.1'><inertial pos='0 0 0.02' mass='0.7' diaginertia='1e-3 1e-3 1e-3'/>"
              "<site name='tcp'/></body>"]
    lines += ["  " * (j + 3) + "</body>" for j in range(robot.n_dof, -1, -1)]
    lines += ["  </worldbody>", f"  <actuator><motor name='m1' joint='{robot.joints[0].name}'/></actuator>", "</mujoco>", ""]
    return "\n".join(lines)


@pytest.fixture
def ur10e():
    return dynid.load_robot(Path(str(resources.files("dynid.model") / "robots" / "ur10e.urdf")))


@pytest.mark.parametrize("inertiafromgeom", ["true", "auto"])
def test_mujoco_inverse_dynamics_of_the_written_back_mjcf_equals_dynid(tmp_path, rng, ur10e, inertiafromgeom):
    """mj_inverse on random states of the written-back model (read from another folder than the original's, meshes
    found) equals dynid's prediction β = Kφ with the values written, less the Coulomb term (MuJoCo's frictionloss is a
    constraint force, as in the exporter's own test); the welded tool's mass is identified with the last link."""
    robot = _with_friction(ur10e, rng)
    phi = robot.standard_parameters()
    (tmp_path / "model" / "meshes").mkdir(parents=True)
    (tmp_path / "model" / "meshes" / "piece.obj").write_text(TETRAHEDRON)
    source = tmp_path / "model" / "arm.xml"
    source.write_text(_users_mjcf(robot, rng, inertiafromgeom))
    (tmp_path / "out").mkdir()
    text, moved = mjcf_written_back(source, robot, phi, out_dir=tmp_path / "out")
    written = tmp_path / "out" / "arm_identified.xml"
    written.write_text(text)
    model = mujoco.MjModel.from_xml_path(str(written))
    data = mujoco.MjData(model)
    terms = dict(zip(robot.drive_terms, robot.drive.T))
    np.testing.assert_allclose(model.dof_damping, terms.get("fv", 0.0))
    np.testing.assert_allclose(model.dof_armature, terms.get("Ia", 0.0))
    assert model.body_mass[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "tool")] == 0.0
    base = base_parameters(robot, rng=0)
    beta = base.base_from_standard(phi)
    for _ in range(10):
        q, ddq = rng.uniform(-1.5, 1.5, (2, robot.n_dof))
        dq = rng.choice([-1.0, 1.0], robot.n_dof) * rng.uniform(0.05, 1.5, robot.n_dof)
        data.qpos[:], data.qvel[:], data.qacc[:] = q, dq, ddq
        mujoco.mj_inverse(model, data)
        tau = data.qfrc_inverse + data.qfrc_constraint + terms.get("fc", 0.0) * np.sign(dq) + terms.get("offset", 0.0)
        predicted = base.base_observation(regressor(robot, q[None], dq[None], ddq[None]))[0] @ beta
        np.testing.assert_allclose(tau, predicted, atol=1e-8 * max(1.0, np.abs(predicted).max()))
    original, back = ET.parse(source).getroot(), ET.fromstring(text.split("\n", 1)[1])
    assert [(e.tag, e.get("name")) for e in original.iter() if e.tag is not ET.Comment] == \
        [(e.tag, e.get("name")) for e in back.iter() if e.tag is not ET.Comment]
    assert "one physically consistent choice among the many" in text and len(moved) == robot.n_dof  # all far from the dummies


def test_an_mjcf_of_another_robot_or_zero_is_refused(tmp_path, rng, ur10e):
    robot = ur10e
    good = _users_mjcf(robot, rng, "auto")
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "piece.obj").write_text(TETRAHEDRON)
    other = tmp_path / "other.xml"
    other.write_text(good.replace(f"name='{robot.joints[2].name}'", "name='elbow'"))
    with pytest.raises(ConfigError, match=rf"other.xml: has no joint '{robot.joints[2].name}'"):
        mjcf_written_back(other, robot, robot.standard_parameters())
    shifted = tmp_path / "shifted.xml"  # joint 2 at another zero: its child bodies turned
    elements = ET.fromstring(good)
    body = next(b for b in elements.iter("body") if b.get("name") == f"body_{robot.joints[2].name}")
    body.set("pos", " ".join(str(float(x) + 0.05) for x in body.get("pos").split()))
    shifted.write_text(ET.tostring(elements, encoding="unicode"))
    with pytest.raises(ConfigError, match=r"shifted.xml: its joint axes at q = 0 are not the robot's"):
        mjcf_written_back(shifted, robot, robot.standard_parameters())
    broken = tmp_path / "broken.xml"
    broken.write_text(good.replace("</worldbody>", ""))
    with pytest.raises(ConfigError, match=r"broken.xml: cannot read it as MJCF"):
        mjcf_written_back(broken, robot, robot.standard_parameters())

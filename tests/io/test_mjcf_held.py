"""Write-back into a user's MJCF whose arm holds a gripper (issue "Nothing runs, nothing silent", item 4): the held
fingers keep their own inertials, the last link gets the identified values less theirs, and the written model loads
in MuJoCo with a positive definite mass matrix and MuJoCo's torques equal to dynid's model of the estimate."""

from __future__ import annotations

import numpy as np

ARM = """<mujoco model="arm">
  <compiler angle="radian" autolimits="true"/>
  <worldbody>
    <body name="l1" pos="0 0 0.1">
      <joint name="j1" type="hinge" axis="0 0 1" range="-3 3"/>
      <geom type="capsule" size="0.04" fromto="0 0 0 0 0 0.2"/>
      <inertial pos="0 0 0.1" mass="3" diaginertia="0.02 0.02 0.01"/>
      <body name="l2" pos="0 0 0.2">
        <joint name="j2" type="hinge" axis="0 1 0" range="-2 2"/>
        <inertial pos="0.15 0 0" mass="2" diaginertia="0.005 0.02 0.02"/>
        <body name="l3" pos="0.3 0 0">
          <joint name="j3" type="hinge" axis="1 0 0" range="-3 3"/>
          <inertial pos="0.05 0.01 0" mass="1" diaginertia="0.002 0.003 0.003"/>
          <body name="hand" pos="0.1 0 0">
            <inertial pos="0.02 0 0" mass="0.5" diaginertia="0.001 0.001 0.001"/>
            <body name="finger_left" pos="0.05 0.01 0">
              <joint name="f1" type="slide" axis="0 1 0" range="0 0.04"/>
              <inertial pos="0.01 0 0" mass="0.05" diaginertia="1e-5 1e-5 1e-5"/>
            </body>
            <body name="finger_right" pos="0.05 -0.01 0">
              <joint name="f2" type="slide" axis="0 -1 0" range="0 0.04"/>
              <inertial pos="0.01 0 0" mass="0.05" diaginertia="1e-5 1e-5 1e-5"/>
            </body>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


def test_the_write_back_into_an_mjcf_with_a_held_gripper_loads_and_reproduces_the_model(tmp_path):
    import mujoco

    from dynid.dynamics.regressor import regressor
    from dynid.io.exported.mjcf_write_back import mjcf_written_back
    from dynid.model.description import load_robot

    path = tmp_path / "arm.xml"
    path.write_text(ARM)
    robot = load_robot(path, held=("f1", "f2"))
    assert robot.n_dof == 3 and robot.held == ("f1", "f2")
    phi = robot.standard_parameters().copy()
    phi[:30] *= 1.2  # the links 20 % heavier than the file's: what an identification hands on
    text, _ = mjcf_written_back(path, robot, phi)  # refused ("held") before
    model = mujoco.MjModel.from_xml_string(text)
    assert abs(model.body("finger_left").mass[0] - 0.05) < 1e-12 and abs(model.body("finger_right").mass[0] - 0.05) < 1e-12
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    full = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, full)
    eig = np.linalg.eigvalsh(full)
    assert eig.min() > 0 and eig.max() / eig.min() < 1e8  # the 5-joint model, fingers included
    rng = np.random.default_rng(3)
    q, dq, ddq = (rng.uniform(-1, 1, (50, 3)) for _ in range(3))
    arm = [model.joint(n).dofadr[0] for n in ("j1", "j2", "j3")]
    ours = regressor(robot, q, dq, ddq) @ phi
    theirs = np.empty_like(ours)
    for k in range(q.shape[0]):
        data.qpos[:], data.qvel[:], data.qacc[:] = 0.0, 0.0, 0.0
        data.qpos[arm], data.qvel[arm], data.qacc[arm] = q[k], dq[k], ddq[k]
        mujoco.mj_inverse(model, data)
        theirs[k] = data.qfrc_inverse[arm]
    np.testing.assert_allclose(theirs, ours, rtol=1e-7, atol=1e-7 * np.abs(ours).max())

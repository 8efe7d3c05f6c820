"""MJCF export: MuJoCo's inverse dynamics of the exported model reproduces dynid's torques."""

import numpy as np
import pytest

from dynid.dynamics.base_parameters import base_parameters
from dynid.dynamics.regressor import regressor
from dynid.exceptions import ConfigError
from dynid.model.description import load_robot
from dynid.model.description_files import mjcf_from_robot

from .test_export import _with_friction

mujoco = pytest.importorskip("mujoco")


@pytest.mark.parametrize("name", ["ur10e", "tx40", "er16"])
def test_mujoco_inverse_dynamics_of_the_exported_model_equals_dynid(rng, name):
    """mj_inverse on random states: MuJoCo's torques without its dry-friction constraint force (rigid bodies,
    armature = rotor inertia, damping = viscous, the TX40's coupled motor's viscous friction as a fixed tendon's damping)
    plus the terms stated in comments (offset, the coupled motor's inertia) and the dry friction the constraints hold
    (the joints' and the tendon's) equal dynid's prediction with the base parameters β = Kφ, less its Coulomb term fc·sign(q̇).
    MuJoCo's ``frictionloss`` (= fc, checked) is a soft constraint: in inverse dynamics its force is what
    the constraint solver finds, up to fc, so it is not compared. Tolerance 1e-8 relative; the TX40's
    point-mass link 6 gets MuJoCo's smallest inertia (1e-9)."""
    robot = _with_friction(load_robot(name), rng)
    phi = robot.standard_parameters()
    base = base_parameters(robot, rng=0)
    model = mujoco.MjModel.from_xml_string(mjcf_from_robot(robot, phi))
    data = mujoco.MjData(model)
    assert model.nv == robot.n_dof
    terms = dict(zip(robot.drive_terms, robot.drive.T))
    tr = robot.transmission
    coupled = dict(zip(tr.coupled_parameter_names, tr.coupled_values.ravel()))
    # a coupled motor's viscous and dry friction are a fixed tendon (c·q): the joints' damping less its diagonal share
    tendon_diagonal = sum((coupled[f"fvm{k + 1}"] * tr.ratios(k) ** 2 for k in tr.coupled_motors), np.zeros(robot.n_dof))
    np.testing.assert_allclose(model.dof_frictionloss, terms.get("fc", 0.0))
    np.testing.assert_allclose(model.dof_damping, terms.get("fv", 0.0) - tendon_diagonal)
    assert model.ntendon == len(tr.coupled_motors)
    np.testing.assert_allclose(model.dof_armature, terms.get("Ia", 0.0))
    for _ in range(20):
        q, ddq = rng.uniform(-1.5, 1.5, (2, robot.n_dof))
        dq = rng.choice([-1.0, 1.0], robot.n_dof) * rng.uniform(0.05, 1.5, robot.n_dof)
        data.qpos[:], data.qvel[:], data.qacc[:] = q, dq, ddq
        mujoco.mj_inverse(model, data)
        tau = data.qfrc_inverse + data.qfrc_constraint + terms.get("fc", 0.0) * np.sign(dq) + terms.get("offset", 0.0)
        if tr.n_coupled_params:  # the motor's inertia (a comment) and its dry friction (the tendon's constraint, taken out)
            held = np.array([not n.startswith("fvm") for n in tr.coupled_parameter_names])
            tau = tau + tr.coupling_columns(dq[None], ddq[None])[0] @ np.where(held, tr.coupled_values.ravel(), 0.0)
        predicted = base.base_observation(regressor(robot, q[None], dq[None], ddq[None]))[0] @ base.base_from_standard(phi)
        np.testing.assert_allclose(tau, predicted, atol=1e-8 * max(1.0, np.abs(predicted).max()))


def test_mjcf_refuses_inconsistent_parameters():
    robot = load_robot("er16")
    phi = robot.standard_parameters().copy()
    phi[robot.parameter_names.index("M3")] = -1.0
    with pytest.raises(ConfigError, match=r"export: link 3 \(joint3\): mass -1 kg is not positive"):
        mjcf_from_robot(robot, phi)


def test_the_tx40s_coupled_motor_friction_is_read_back_as_held_and_its_inertia_as_missing(rng):
    """The TX40's motor 6 turns with joints 5 and 6: its viscous and dry friction are a fixed tendon of the MJCF, read
    back by MuJoCo as part of the model the file holds (to round-off); its inertia is not held and is said."""
    from dynid.io.exported.replay import mjcf_replay

    robot = _with_friction(load_robot("tx40"), rng)
    phi = robot.standard_parameters()
    check = mjcf_replay(mjcf_from_robot(robot, phi), robot, phi, n_states=50, rng=1)
    assert check.relative_error < 1e-8
    assert "Iam" in check.missing and "fvm" not in check.missing and "fcm" not in check.missing


def test_a_users_mjcf_written_back_holds_the_coupled_motor_as_dynids_own_does(rng, tmp_path):
    """The TX40's coupled motor's friction written into a user's own MJCF: the same tendon, the joints' damping less its
    diagonal share: MuJoCo's viscous torques of the two files equal."""
    from dynid.io.exported.mjcf_write_back import mjcf_written_back

    from .test_mjcf_write_back import TETRAHEDRON, _users_mjcf

    robot = _with_friction(load_robot("tx40"), rng)
    phi = robot.standard_parameters()
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "piece.obj").write_text(TETRAHEDRON)
    (tmp_path / "arm.xml").write_text(_users_mjcf(robot, np.random.default_rng(3)))
    text, _ = mjcf_written_back(tmp_path / "arm.xml", robot, phi)
    (tmp_path / "written.xml").write_text(text)
    theirs = mujoco.MjModel.from_xml_path(str(tmp_path / "written.xml"))
    ours = mujoco.MjModel.from_xml_string(mjcf_from_robot(robot, phi))
    assert theirs.ntendon == ours.ntendon == 1
    np.testing.assert_allclose(theirs.tendon_damping, ours.tendon_damping)
    np.testing.assert_allclose(theirs.tendon_frictionloss, ours.tendon_frictionloss)
    ids = [theirs.joint(j.name).dofadr[0] for j in robot.joints]
    np.testing.assert_allclose(theirs.dof_damping[ids], ours.dof_damping)
    # the viscous torque each file's joints and tendon give at the same velocities (MuJoCo's passive forces)
    a, b = mujoco.MjData(theirs), mujoco.MjData(ours)
    for _ in range(5):
        dq = rng.uniform(-1.5, 1.5, robot.n_dof)
        a.qvel[:], b.qvel[:] = 0.0, dq
        a.qvel[ids] = dq
        mujoco.mj_forward(theirs, a)
        mujoco.mj_forward(ours, b)
        np.testing.assert_allclose(a.qfrc_passive[ids], b.qfrc_passive, rtol=1e-12, atol=1e-12)

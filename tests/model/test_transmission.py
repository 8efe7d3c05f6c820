import numpy as np
import pytest

from dynid.dynamics.base_parameters import base_parameters
from dynid.dynamics.regressor import regressor
from dynid.exceptions import ConfigError
from dynid.model.description import load_robot, robot_from_toml_text
from dynid.model.transmission import Transmission

from ..conftest import random_states

_WRIST = """
name = "coupled"
convention = "modified"
drive_terms = ["Ia", "fc", "fv", "offset"]
[transmission]
gear_ratios = [30, -40, 25]
coupling = [{motor = 3, joint = 2, ratio = 12.5}]
[[joints]]
mass = 2.0
com = [0.1, 0.0, 0.0]
inertia = [0.1, 0.1, 0.1, 0.0, 0.0, 0.0]
[[joints]]
alpha = "-pi/2"
mass = 1.0
com = [0.0, 0.1, 0.0]
inertia = [0.05, 0.05, 0.05, 0.0, 0.0, 0.0]
position_offset = "-pi/2"
[[joints]]
alpha = "pi/2"
a = 0.3
mass = 0.5
com = [0.0, 0.0, 0.05]
inertia = [0.01, 0.01, 0.01, 0.0, 0.0, 0.0]
drive_terms = ["fv"]
"""


def test_coupling_columns_match_motor_side_physics(rng):
    """A motor that turns with two joints: tau = R[k]ᵀ (J·R[k]·ddq + Fv·R[k]·dq + Fc·sign(R[k]·dq)) is
    reproduced by the joint Ia/fv terms plus Iam, fvm, fcm (module docstring of transmission)."""
    robot = robot_from_toml_text(_WRIST.replace('drive_terms = ["fv"]', ""), "w.toml", None)
    assert robot.parameter_names[-3:] == ("Iam3", "fvm3", "fcm3")
    r = robot.transmission.motor_from_joint
    q, dq, ddq = random_states(rng, 50, 3)
    j_m, fv_m, fc_m = 2e-4, 3e-3, 0.02
    rk = r[2]
    tau_motor = rk * (j_m * (ddq @ rk) + fv_m * (dq @ rk) + fc_m * np.sign(dq @ rk))[:, None]
    y = regressor(robot, q, dq, ddq)
    names = robot.parameter_names
    phi = np.zeros(robot.n_params)
    for j, coef in ((1, rk[1] ** 2), (2, rk[2] ** 2)):  # diagonal parts go to the joints' own terms
        phi[names.index(f"Ia{j + 1}")] = j_m * coef
        phi[names.index(f"fv{j + 1}")] = fv_m * coef
    phi[names.index("Iam3")] = j_m * rk[2] ** 2
    phi[names.index("fvm3")] = fv_m * rk[2] ** 2
    phi[names.index("fcm3")] = fc_m * abs(rk[2])
    np.testing.assert_allclose(y @ phi, tau_motor, atol=1e-12)


def test_joint_without_a_term_has_zero_column_and_no_base_parameter(rng):
    robot = robot_from_toml_text(_WRIST, "w.toml", None)
    q, dq, ddq = random_states(rng, 20, 3)
    y = regressor(robot, q, dq, ddq)
    for name in ("Ia3", "fc3", "offset3"):
        assert not np.any(y[:, :, robot.parameter_names.index(name)])
    base = base_parameters(robot, rng=1)
    assert "fv3" in base.names and not {"fc3", "offset3"} & set(base.names)
    assert {"Iam3", "fvm3", "fcm3"} <= set(base.names)


def test_motor_side_conversions_invert_the_transmission(rng):
    robot = robot_from_toml_text(_WRIST, "w.toml", None)
    tr = robot.transmission
    q = rng.normal(size=(10, 3))
    theta_m = (q - tr.position_offset) @ tr.motor_from_joint.T
    np.testing.assert_allclose(tr.joint_positions(theta_m), q, atol=1e-12)
    np.testing.assert_allclose(tr.position_offset, [0.0, -np.pi / 2, 0.0])
    # virtual work: motor power equals joint power
    dq = rng.normal(size=(10, 3))
    tau_m = rng.normal(size=(10, 3))
    tau = tr.joint_torques(tau_m)
    np.testing.assert_allclose((tau * dq).sum(1), (tau_m * (dq @ tr.motor_from_joint.T)).sum(1), atol=1e-10)


def test_transmission_errors():
    with pytest.raises(ConfigError, match="gear ratio"):
        Transmission(np.diag([1.0, 0.0]), np.zeros(2))
    with pytest.raises(ConfigError, match="singular"):
        Transmission(np.array([[1.0, 1.0], [1.0, 1.0]]), np.zeros(2))
    bad = _WRIST.replace("{motor = 3, joint = 2, ratio = 12.5}", "{motor = 3, joint = 3, ratio = 12.5}")
    with pytest.raises(ConfigError, match=r"w.toml: transmission.coupling\[0\]: expected two different joint numbers"):
        robot_from_toml_text(bad, "w.toml", None)
    bad = _WRIST.replace('drive_terms = ["fv"]', 'drive_terms = ["Iam"]')
    with pytest.raises(ConfigError, match=r"joints\[2\].drive_terms"):
        robot_from_toml_text(bad, "w.toml", None)
    bad = _WRIST.replace("gear_ratios = [30, -40, 25]", "gear_ratios = [30, 0, 25]")
    with pytest.raises(ConfigError, match="gear_ratios: expected non-zero"):
        robot_from_toml_text(bad, "w.toml", None)


def test_submodel_refuses_to_cut_a_coupling():
    robot = robot_from_toml_text(_WRIST, "w.toml", None)
    with pytest.raises(ConfigError, match="couples joints"):
        robot.submodel(2)
    assert load_robot("er16").submodel(3).transmission.n_dof == 3


def test_coupled_values_are_nominal_values_in_dynids_order_and_enter_the_mass_matrix():
    """``coupled_values``: the coupled motor's nominal terms, given in the order of ``coupled_terms`` and kept in
    dynid's (Iam, fvm, fcm). Independent truth: motor 3 turns by ``12.5 q2 + 25 q3``; its rotor inertia ``J`` adds
    ``J R[k]ᵀ R[k]`` to the mass matrix, whose off-diagonal part in joint units (``Iam = J R[k, k]²``) is
    ``Iam · c2 · c3 = Iam · 0.5`` at (2, 3), and nothing else (Pinocchio's CRBA plus the drive terms)."""
    from dynid.simulation.closed_loop import JointDynamics

    given = _WRIST.replace("coupling = [", 'coupled_terms = ["fcm", "Iam"]\ncoupled_values = [[1.5, 0.02]]\ncoupling = [')
    robot = robot_from_toml_text(given, "w.toml", None)
    assert robot.transmission.coupled_terms == ("Iam", "fcm")
    np.testing.assert_array_equal(robot.transmission.coupled_values, [[0.02, 1.5]])
    plain = robot_from_toml_text(_WRIST.replace("coupling = [", 'coupled_terms = ["fcm", "Iam"]\ncoupling = ['), "w.toml", None)
    q = np.array([0.3, -0.4, 0.5])
    difference = JointDynamics(robot).mass_and_bias(q, np.zeros(3))[0] - JointDynamics(plain).mass_and_bias(q, np.zeros(3))[0]
    expected = np.zeros((3, 3))
    expected[1, 2] = expected[2, 1] = 0.02 * (12.5 / 25) * 1.0
    np.testing.assert_allclose(difference, expected, atol=1e-12)


@pytest.mark.parametrize("values", ["[[0.02]]", "[[0.02, 1.5], [0.0, 0.0]]", "[[nan, 1.5]]"])
def test_coupled_values_of_the_wrong_shape_are_named(values):
    bad = _WRIST.replace("coupling = [", f'coupled_terms = ["fcm", "Iam"]\ncoupled_values = {values}\ncoupling = [')
    with pytest.raises(ConfigError, match=r"w.toml: transmission.coupled_values: expected 1 list\(s\) .* of 2 finite numbers"):
        robot_from_toml_text(bad, "w.toml", None)


def test_the_tx40_simulation_truth_can_be_controlled_where_the_built_in_cannot():
    """The built-in TX40 has no inertia about joint 6's axis, so no gain follows from its mass matrix; the simulation
    truth of ``configs/robots/tx40_simulation.toml`` (FIGAROH's drive values) has, and a positive definite one."""
    from pathlib import Path

    from dynid.simulation.closed_loop import Controller, JointDynamics

    with pytest.raises(ConfigError, match="joint 6 has no inertia"):
        Controller.for_robot(load_robot("tx40"))
    truth = load_robot(str(Path(__file__).parents[2] / "configs" / "robots" / "tx40_simulation.toml"))
    np.testing.assert_array_equal(truth.transmission.coupled_values, [[0.00964, 0.616, 1.95]])
    assert np.linalg.eigvalsh(JointDynamics(truth).mass_and_bias(np.zeros(6), np.zeros(6))[0]).min() > 0
    assert np.all(Controller.for_robot(truth).kp > 0)

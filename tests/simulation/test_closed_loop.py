"""The closed-loop simulator against Pinocchio's inverse dynamics, and its controller's checks."""

import numpy as np
import pytest

import dynid
from dynid.dynamics.rnea import rnea_torques
from dynid.exceptions import ConfigError, ShapeError
from dynid.simulation.closed_loop import ClosedLoopNoise, Controller, simulate_closed_loop


def _reference(robot, seconds, rate, rng):
    t = np.arange(int(seconds * rate)) / rate
    w = 2 * np.pi * rng.uniform(0.2, 0.6, robot.n_dof)
    a = rng.uniform(0.2, 0.5, robot.n_dof)
    return t, a * np.sin(w * t[:, None]), a * w * np.cos(w * t[:, None]), -a * w**2 * np.sin(w * t[:, None])


@pytest.mark.parametrize("name", ["er16", "tx40"])
def test_the_torques_applied_are_the_inverse_dynamics_of_the_simulated_motion(name, rng):
    """Pinocchio's RNEA plus dynid's drive terms (a separately built model) on the simulated states gives the
    torque the controller applied at each step, with noisy positions in the loop. ER-16: ABA with the rotor
    inertia as armature; TX40 (coupled wrist motor, rotor inertias given): the CRBA path."""
    from dynid.simulation.closed_loop import JointDynamics

    robot = dynid.load_robot(name)
    if name == "tx40":  # give every joint a rotor inertia and friction, and the coupled motor its terms
        phi = robot.standard_parameters().copy()
        names = list(robot.parameter_names)
        for j in range(robot.n_dof - 1):  # Ia6 is the coupled motor's (Iam6 off the diagonal)
            phi[names.index(f"Ia{j + 1}")] = 0.05
        for term in ("XX6", "YY6", "ZZ6"):  # the point-mass link 6 gets an inertia about its axis
            phi[names.index(term)] = 0.01
        for j in range(robot.n_dof):
            phi[names.index(f"fc{j + 1}")], phi[names.index(f"fv{j + 1}")] = 1.0, 0.5
        phi[robot.n_dof * robot.n_params_per_joint:] = 0.02
        robot = robot.with_parameters(phi)
    assert JointDynamics(robot)._aba == (name == "er16")
    t, q, dq, ddq = _reference(robot, 2.0, 1000.0, rng)
    controller = Controller.for_robot(robot)
    run = simulate_closed_loop(robot, t, q, dq, controller, ClosedLoopNoise(np.deg2rad(1e-2), np.deg2rad(1e-3), 0.1), rng=rng,
                               feedforward=rnea_torques(robot, q, dq, ddq))
    expected = rnea_torques(robot, run.q_true, run.dq_true, run.ddq_true)
    np.testing.assert_allclose(run.tau_applied, expected, atol=1e-9 * np.abs(expected).max())
    assert np.abs(run.q_true - q).max() < 0.01  # the loop tracks its reference
    assert 0.05 < np.std(run.tau - run.tau_applied) < 0.15  # the logged torques carry their noise
    assert np.all(np.abs(np.round(run.q / np.deg2rad(1e-3)) * np.deg2rad(1e-3) - run.q) < 1e-12)  # quantised


def test_the_loop_sees_the_noisy_positions(rng):
    """Position noise reaches the applied torque through the controller (the closed loop's point)."""
    robot = dynid.load_robot("er16").submodel(3)
    t, q, dq, _ = _reference(robot, 1.0, 1000.0, rng)
    controller = Controller.for_robot(robot)
    quiet = simulate_closed_loop(robot, t, q, dq, controller)
    noisy = simulate_closed_loop(robot, t, q, dq, controller, ClosedLoopNoise(position_std=np.deg2rad(1e-2)), rng=rng)
    assert np.abs(noisy.tau_applied - quiet.tau_applied).max() > 1.0


def test_controller_and_simulation_refusals(rng):
    robot = dynid.load_robot("er16").submodel(3)
    with pytest.raises(ConfigError, match=r"controller.kp: expected one value per joint \(3\)"):
        Controller.of(3, kp=[1.0, 2.0], kd=1.0)
    with pytest.raises(ConfigError, match="controller.kd: expected positive"):
        Controller.of(3, kp=1.0, kd=0.0)
    with pytest.raises(ConfigError, match="controller.velocity_cutoff"):
        Controller.of(3, kp=1.0, kd=1.0, rate=100.0, velocity_cutoff=60.0)
    t, q, dq, _ = _reference(robot, 1.0, 1000.0, rng)
    controller = Controller.for_robot(robot)
    with pytest.raises(ShapeError, match=r"q_ref: expected shape \(1000, 3\)"):
        simulate_closed_loop(robot, t, q[:, :2], dq, controller)
    with pytest.raises(ConfigError, match="needs an rng"):
        simulate_closed_loop(robot, t, q, dq, controller, ClosedLoopNoise(torque_std=0.1))
    with pytest.raises(ConfigError, match="diverged"):
        simulate_closed_loop(robot, t, q, dq, Controller.of(3, kp=1e9, kd=1e7))


def test_the_compiled_stages_run_as_the_dynamics_own_accelerations(rng, monkeypatch):
    """The simulator's compiled stages add the drive terms (Coulomb, viscous, offset) themselves before Pinocchio's
    ABA; the same run through the dynamics' own accelerations (their NumPy drive torques) is the same to the bit."""
    from dynid.simulation.closed_loop import JointDynamics

    robot = dynid.load_robot("ur10e")
    phi = robot.standard_parameters().copy()
    names = list(robot.parameter_names)
    for j in range(robot.n_dof):  # every term the stages add, non-zero, and the rotor inertia (ABA's armature)
        for term, value in (("Ia", 0.05), ("fc", 2.0), ("fv", 0.7), ("offset", 0.3)):
            phi[names.index(f"{term}{j + 1}")] = value
    robot = robot.with_parameters(phi)
    assert JointDynamics(robot).simple_drive_terms() is not None
    t, q, dq, _ = _reference(robot, 1.0, 1000.0, rng)
    noise = ClosedLoopNoise(np.deg2rad(1e-2), np.deg2rad(1e-3), 0.1)
    seed = int(rng.integers(1 << 30))
    compiled = simulate_closed_loop(robot, t, q, dq, Controller.for_robot(robot), noise, rng=np.random.default_rng(seed))
    monkeypatch.setattr(JointDynamics, "simple_drive_terms", lambda self: None)
    general = simulate_closed_loop(robot, t, q, dq, Controller.for_robot(robot), noise, rng=np.random.default_rng(seed))
    for key in ("q", "tau", "q_true", "dq_true", "ddq_true", "tau_applied"):
        np.testing.assert_array_equal(getattr(compiled, key), getattr(general, key), err_msg=key)

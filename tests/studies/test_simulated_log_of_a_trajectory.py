"""dynid.simulated_log of a given excitation (a designed one, eq. 15), so that design, simulation and identification
chain in the API: checked against the trajectory itself and dynid's regressor times the description's parameters
(Pinocchio's RNEA simulates the log)."""

import numpy as np
import pytest

import dynid
from dynid.exceptions import ConfigError
from dynid.excitation.fourier import FourierTrajectory
from dynid.simulation.measurements import NoiseModel


def test_a_log_runs_the_trajectory_given_and_its_torques_are_the_models():
    robot = dynid.load_robot("er16")
    rng = np.random.default_rng(3)
    k = robot.n_dof
    motion = FourierTrajectory(2 * np.pi * 0.1, rng.uniform(-0.3, 0.3, k), rng.uniform(-0.05, 0.05, (k, 5)),
                               rng.uniform(-0.05, 0.05, (k, 5)))
    log = dynid.simulated_log(robot, seconds=10.0, rate=100.0, trajectory=motion, noise=NoiseModel(0.0, 0.0))
    q, dq, ddq = motion.evaluate(np.arange(1000) / 100.0)
    np.testing.assert_array_equal(log.q, q)
    torque = dynid.regressor(robot, q, dq, ddq) @ robot.standard_parameters()
    np.testing.assert_allclose(log.tau, torque, rtol=0, atol=1e-9 * np.abs(torque).max())
    noisy = dynid.simulated_log(robot, seconds=10.0, rate=100.0, trajectory=motion, rng=1)
    assert np.abs(noisy.q - q).max() <= np.pi / 2**20 + 1e-15  # the default 20-bit encoders' rounding, no other motion
    with pytest.raises(ConfigError, match=r"^simulated_log: the trajectory moves 2 joints, er16 has 6 \(its first 2 joints: the robot's submodel\(2\)\)$"):
        dynid.simulated_log(robot, trajectory=FourierTrajectory(1.0, np.zeros(2), np.zeros((2, 5)), np.zeros((2, 5))))
    two = dynid.simulated_log(robot.submodel(2), seconds=1.0, trajectory=FourierTrajectory(1.0, np.zeros(2), np.zeros((2, 5)),
                                                                                           np.zeros((2, 5))))
    assert two.q.shape[1] == 2 and two.tau.shape == two.q.shape  # what the message says to do works

import numpy as np
import pytest

from dynid.dynamics.regressor import regressor
from dynid.exceptions import ConfigError
from dynid.model.description import load_robot
from dynid.simulation import NoiseModel, simulate_measurements
from dynid.simulation.measurements import torques_from_currents


def test_currents_follow_eq16_with_the_declared_noise(rng):
    robot = load_robot("er16").submodel(3)
    n = 4000
    q, dq, ddq = (rng.uniform(-1, 1, (n, 3)) for _ in range(3))
    meas = simulate_measurements(robot, np.arange(n) * 1e-3, q, dq, ddq, NoiseModel(0.2, 1e-3), rng)
    tau = regressor(robot, q, dq, ddq) @ robot.standard_parameters()
    np.testing.assert_allclose(meas.tau_true, tau, atol=1e-9)
    err = meas.current - tau / robot.drive_gains
    assert abs(err.std() - 0.2) < 0.01 and abs(err.mean()) < 0.01
    np.testing.assert_allclose(torques_from_currents(meas.current, robot.drive_gains), meas.current * robot.drive_gains)
    assert np.all(np.abs(meas.q - q) <= 0.5e-3 + 1e-15)
    assert np.allclose(meas.q / 1e-3, np.round(meas.q / 1e-3))


def test_same_seed_same_data():
    robot = load_robot("er16").submodel(2)
    q = np.zeros((10, 2))
    a = simulate_measurements(robot, np.arange(10.0), q, q, q, NoiseModel(), np.random.default_rng(3))
    b = simulate_measurements(robot, np.arange(10.0), q, q, q, NoiseModel(), np.random.default_rng(3))
    np.testing.assert_array_equal(a.current, b.current)


def test_bad_noise():
    with pytest.raises(ConfigError, match="current noise"):
        NoiseModel(current_std=-1)
    with pytest.raises(ConfigError, match="encoder"):
        NoiseModel(encoder_resolution=float("nan"))

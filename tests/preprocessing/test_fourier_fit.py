import numpy as np
import pytest

from dynid.exceptions import ConfigError
from dynid.excitation import paper_identification_trajectory
from dynid.preprocessing import fourier_fit_derivatives


def test_recovers_derivatives_from_noisy_quantised_positions(rng):
    traj = paper_identification_trajectory()
    t = np.arange(0, 25, 1e-3)
    q, dq, ddq = traj.evaluate(t)
    step = 1e-4
    q_meas = np.round((q + rng.normal(0, 1e-4, q.shape)) / step) * step
    q_f, dq_f, ddq_f, fit = fourier_fit_derivatives(t, q_meas, traj.omega_f, traj.n_harmonics)
    assert np.abs(dq_f - dq).max() < 1e-4
    assert np.abs(ddq_f - ddq).max() < 1e-3
    np.testing.assert_allclose(fit.to_rows(), traj.to_rows(), atol=1e-5)


def test_exact_without_noise():
    traj = paper_identification_trajectory()
    t = np.arange(0, 25, 1e-2)
    q, dq, ddq = traj.evaluate(t)
    _, dq_f, ddq_f, _ = fourier_fit_derivatives(t, q, traj.omega_f, 5)
    np.testing.assert_allclose(dq_f, dq, atol=1e-10)
    np.testing.assert_allclose(ddq_f, ddq, atol=1e-10)


def test_errors():
    with pytest.raises(ConfigError, match="harmonics"):
        fourier_fit_derivatives(np.arange(10.0), np.zeros((10, 1)), 1.0, 0)
    with pytest.raises(ConfigError, match="at least 11"):
        fourier_fit_derivatives(np.arange(5.0), np.zeros((5, 1)), 1.0, 5)

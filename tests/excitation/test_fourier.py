import numpy as np
import pytest

from dynid.exceptions import ConfigError
from dynid.excitation import FourierTrajectory, paper_identification_trajectory, paper_validation_trajectory
from dynid.excitation.fourier import sample_times


def test_paper_trajectories_layout():
    b1, b2 = paper_identification_trajectory(), paper_validation_trajectory()
    assert (b1.n_dof, b1.n_harmonics, b2.n_harmonics) == (3, 5, 3)
    assert b1.q0[2] == 0.0  # lost in the source
    assert b1.a[0, 0] == -0.1911 and b1.b[0, 4] == 0.0730
    assert b2.q0[1] == -0.5026 and b2.b[2, 2] == 0.1524
    assert np.isclose(b1.period, 20.0)


def test_derivatives_match_finite_differences():
    traj = paper_validation_trajectory()
    t = np.linspace(0, 20, 20001)
    q, dq, ddq = traj.evaluate(t)
    h = t[1] - t[0]
    np.testing.assert_allclose(np.gradient(q, h, axis=0)[1:-1], dq[1:-1], atol=1e-5)
    np.testing.assert_allclose(np.gradient(dq, h, axis=0)[1:-1], ddq[1:-1], atol=1e-5)
    np.testing.assert_allclose(q[0], traj.q0 + traj.b.sum(axis=1))  # eq. 14 at t = 0


def test_errors():
    with pytest.raises(ConfigError, match="pulsation"):
        FourierTrajectory.from_rows(np.zeros((1, 3)), -1.0)
    with pytest.raises(ConfigError, match="2N\\+1"):
        FourierTrajectory.from_rows(np.zeros((1, 4)), 1.0)
    with pytest.raises(ConfigError, match="sampling rate"):
        sample_times(25.0, -5.0)
    with pytest.raises(ConfigError, match="duration"):
        sample_times(0.0, 100.0)
    assert sample_times(25.0, 1000.0).size == 25000

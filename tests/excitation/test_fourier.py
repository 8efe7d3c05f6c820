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


def test_swevers_form_is_the_same_trajectory_and_dicts_round_trip():
    import numpy as np
    import pytest

    from dynid.exceptions import ConfigError
    from dynid.excitation.fourier import FourierTrajectory, trajectory_from_dict

    rng = np.random.default_rng(7)
    q0, a, b = rng.normal(size=2), rng.normal(size=(2, 3)), rng.normal(size=(2, 3))
    w = 0.7
    sw = FourierTrajectory.from_swevers(q0, a, b, w)
    t = np.linspace(0, 9, 50)
    k = np.arange(1, 4)
    # Swevers et al. 1997: q = q0 + Σ a_l/(l w) sin(l w t) - b_l/(l w) cos(l w t)
    expected = q0 + np.sin(np.outer(t, k * w)) @ (a / (k * w)).T - np.cos(np.outer(t, k * w)) @ (b / (k * w)).T
    np.testing.assert_allclose(sw.evaluate(t)[0], expected, atol=1e-12)
    for form in ("paper", "swevers"):
        back = trajectory_from_dict(sw.to_dict(form=form))
        np.testing.assert_allclose(back.evaluate(t)[1], sw.evaluate(t)[1], atol=1e-12)
    with pytest.raises(ConfigError, match="x.json: expected a and b of shape"):
        trajectory_from_dict({"omega_f": 1.0, "q0": [0, 0], "a": [[1.0]], "b": [[1.0]]}, "x.json")
    with pytest.raises(ConfigError, match="form must be one of paper, swevers"):
        trajectory_from_dict({"form": "cheb", "omega_f": 1.0, "q0": [0], "a": [[1.0]], "b": [[1.0]]})

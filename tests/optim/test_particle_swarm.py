import numpy as np
import pytest

from dynid.exceptions import ConfigError
from dynid.optim.particle_swarm import minimize_particle_swarm


def sphere(x):  # x (D, K)
    return np.sum((x - 0.3) ** 2, axis=0)


def test_minimises_a_shifted_sphere():
    res = minimize_particle_swarm(sphere, [(-5, 5)] * 4, maxiter=200, rng=0)
    np.testing.assert_allclose(res.x, 0.3, atol=1e-3)
    assert res.nfev == 30 * 201


def test_history_is_monotone_stays_in_bounds_and_is_seeded():
    seen = []

    def f(x):
        seen.append(x.copy())
        return sphere(x) + np.sin(5 * x).sum(axis=0)

    bounds = [(-1, 0.2), (0, 2), (-3, -1)]
    a = minimize_particle_swarm(f, bounds, maxiter=40, rng=7)
    pts = np.concatenate(seen, axis=1)
    lo, hi = np.array(bounds).T
    assert np.all(pts >= lo[:, None]) and np.all(pts <= hi[:, None])
    assert np.all(np.diff(a.history) <= 0)
    b = minimize_particle_swarm(f, bounds, maxiter=40, rng=7)
    np.testing.assert_array_equal(a.x, b.x)


@pytest.mark.parametrize("kwargs", [{"swarm_size": 1}, {"maxiter": 0}, {"bounds": [(1, 0)]}])
def test_bad_settings(kwargs):
    args = {"bounds": [(0, 1)], **kwargs}
    with pytest.raises(ConfigError):
        minimize_particle_swarm(sphere, **args)

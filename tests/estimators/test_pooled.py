"""The fleet's pooled estimate against a hierarchical Gaussian model whose truth is known."""

import numpy as np
import pytest

from dynid.estimators.pooled import pooled_estimate, shared_parameters
from dynid.exceptions import ShapeError


def _fleet(rng, units=8, p=6, tau=(0.0, 0.0, 0.0, 0.0, 5.0, 5.0), sigma=1.0):
    mu = rng.normal(0, 10, p)
    beta = mu + rng.normal(size=(units, p)) * np.asarray(tau)
    cov = np.array([np.diag(rng.uniform(0.5, 2.0, p) * sigma ** 2) for _ in range(units)])
    b = np.array([rng.multivariate_normal(beta[u], cov[u]) for u in range(units)])
    return mu, beta, b, cov


def test_pooling_units_that_share_parameters_brings_each_closer_to_its_truth():
    rng = np.random.default_rng(0)
    own_err, pooled_err = [], []
    for _ in range(40):
        mu, beta, b, cov = _fleet(rng)
        est = pooled_estimate(b, cov)
        own_err.append((b - beta)[:, :4] ** 2)
        pooled_err.append((est.params - beta)[:, :4] ** 2)
    # four shared parameters of 8 units: the pooled error is about 1/8 of each unit's own
    assert np.mean(pooled_err) < 0.3 * np.mean(own_err)


def test_a_parameter_that_varies_between_units_is_hardly_pooled():
    rng = np.random.default_rng(1)
    ratios = []
    for _ in range(40):
        mu, beta, b, cov = _fleet(rng, tau=(0, 0, 0, 0, 30.0, 30.0))
        est = pooled_estimate(b, cov)
        ratios.append(np.mean((est.params - beta)[:, 4:] ** 2) / np.mean((b - beta)[:, 4:] ** 2))
        assert np.all(est.spread[4:] > 10)  # τ found large
    assert np.mean(ratios) < 1.05  # no worse than alone (the truth varies 30 σ between units)


def test_a_unit_whose_log_says_nothing_of_a_shared_parameter_takes_the_fleets():
    rng = np.random.default_rng(2)
    mu, beta, b, cov = _fleet(rng, tau=(0, 0, 0, 0, 0, 0))
    cov[0, 2, 2] = 1e12  # unit 0 did not excite parameter 2
    est = pooled_estimate(b, cov)
    others = np.mean(est.params[1:, 2])
    assert est.params[0, 2] == pytest.approx(others, abs=1e-3 * (1 + abs(others)))


def test_unshared_parameters_are_each_units_own_estimate():
    rng = np.random.default_rng(4)
    mu, beta, b, cov = _fleet(rng)
    names = ("ZZ1R", "MX2", "XX2R", "fc1", "fv1", "offset1")
    est = pooled_estimate(b, cov, shared_parameters(names))
    np.testing.assert_allclose(est.params[:, 3:], b[:, 3:], rtol=1e-9, atol=1e-9)  # diagonal covariances: untouched
    assert list(shared_parameters(names)) == [True, True, True, False, False, False]


def test_shapes_are_checked():
    with pytest.raises(ShapeError):
        pooled_estimate(np.zeros((1, 3)), np.zeros((1, 3, 3)))
    with pytest.raises(ShapeError, match="positive definite"):
        pooled_estimate(np.zeros((2, 2)), np.zeros((2, 2, 2)))

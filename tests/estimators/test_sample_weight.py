"""``fit(W, tau, sample_weight=None)``, scikit-learn's contract (issue "Re-zone the top floors", item 6): a weight of 2
is the row given twice and 0 the row left out, for the squared loss (OLS) and eq. 9's absolute one (LAD); chunked
``partial_fit`` with weights equals ``fit``; bad weights are refused in one line."""

import numpy as np
import pytest

from dynid.estimators.least_absolute import LeastAbsoluteDeviations
from dynid.estimators.least_squares import OrdinaryLeastSquares, WeightedLeastSquares
from dynid.estimators.problem import FitData
from dynid.exceptions import ShapeError

N_DOF, P = 2, 5
JOINTS = FitData(n_dof=N_DOF)


def _problem(rng, samples=120):
    w = rng.standard_normal((samples * N_DOF, P)) * np.geomspace(1.0, 10.0, P)
    tau = w @ rng.uniform(-2, 2, P) + 0.05 * rng.standard_normal(samples * N_DOF)
    return w, tau


@pytest.mark.parametrize("cls", [OrdinaryLeastSquares, LeastAbsoluteDeviations])
def test_integer_weights_are_repeated_samples_and_zero_leaves_a_sample_out(cls, rng):
    w, tau = _problem(rng)
    per_sample = rng.integers(0, 4, w.shape[0] // N_DOF)  # 0 to 3 copies of each sample (both joints' rows)
    weights = np.repeat(per_sample, N_DOF)
    rows = np.repeat(np.arange(w.shape[0]).reshape(-1, N_DOF), per_sample, axis=0).reshape(-1)
    weighted = cls().fit(w, tau, sample_weight=weights, problem=JOINTS).params_
    repeated = cls().fit(w[rows], tau[rows], problem=JOINTS).params_
    np.testing.assert_allclose(weighted, repeated, rtol=1e-7, atol=1e-9)
    plain = cls().fit(w, tau, problem=JOINTS).params_
    assert np.abs(weighted - plain).max() > 1e-6  # the weights changed the estimate


def test_weights_shaped_as_the_torques_and_chunked_partial_fit_agree(rng):
    w, tau = _problem(rng)
    weights = rng.uniform(0.2, 3.0, w.shape[0])
    whole = WeightedLeastSquares().fit(w, tau.reshape(-1, N_DOF), sample_weight=weights.reshape(-1, N_DOF))
    chunked = WeightedLeastSquares()
    for part in np.array_split(np.arange(w.shape[0] // N_DOF), 3):
        rows = (part[:, None] * N_DOF + np.arange(N_DOF)).reshape(-1)
        chunked.partial_fit(w[rows], tau[rows], sample_weight=weights[rows], problem=JOINTS)
    np.testing.assert_allclose(chunked.solve().params_, whole.params_, rtol=1e-10, atol=1e-12)
    ones = WeightedLeastSquares().fit(w, tau, sample_weight=np.ones(w.shape[0]), problem=JOINTS)
    np.testing.assert_allclose(ones.params_, WeightedLeastSquares().fit(w, tau, problem=JOINTS).params_, rtol=1e-12)


@pytest.mark.parametrize("weights, said", [
    (lambda m: -np.ones(m), "sample_weight: expected finite weights >= 0"),
    (lambda m: np.full(m, np.nan), "sample_weight: expected finite weights >= 0"),
    (lambda m: np.ones(m - 1), r"sample_weight: expected one weight per row of W, shape \(240,\)"),
])
def test_bad_weights_are_refused_in_one_line(weights, said, rng):
    w, tau = _problem(rng)
    for est in (OrdinaryLeastSquares(), LeastAbsoluteDeviations()):
        with pytest.raises(ShapeError, match=said):
            est.fit(w, tau, sample_weight=weights(w.shape[0]), problem=JOINTS)


def test_wls_is_ols_with_weights_of_one_over_each_joints_residual_variance(rng):
    """Gautier & Poignet's WLS: OLS with sample_weight 1/σ_j² on joint j's rows, σ_j of the OLS residuals."""
    w, tau = _problem(rng)
    tau = tau + np.tile([0.0, 1.0], w.shape[0] // N_DOF) * 0.5 * rng.standard_normal(w.shape[0])  # joint 2 noisier
    wls = WeightedLeastSquares().fit(w, tau, problem=JOINTS)
    residual = (tau - w @ OrdinaryLeastSquares().fit(w, tau, problem=JOINTS).params_).reshape(-1, N_DOF)
    sigma = np.sqrt((residual**2).sum(axis=0) / (residual.shape[0] - P / N_DOF))
    np.testing.assert_allclose(sigma, wls.joint_std_, rtol=1e-8)  # dynid's σ_j: RSS_j / (N - p / n_dof)
    ols = OrdinaryLeastSquares().fit(w, tau, sample_weight=np.tile(1.0 / sigma**2, w.shape[0] // N_DOF), problem=JOINTS)
    np.testing.assert_allclose(ols.params_, wls.params_, rtol=1e-9, atol=1e-12)
    assert np.abs(wls.params_ - OrdinaryLeastSquares().fit(w, tau, problem=JOINTS).params_).max() > 1e-4

import numpy as np
import pytest

from dynid.exceptions import ShapeError
from dynid.validation import correlation_coefficient, relative_error, rmse


def test_eq18_equals_pearson(rng):
    m = rng.normal(size=(500, 3))
    p = m + rng.normal(0, 0.3, m.shape)
    rho = correlation_coefficient(m, p)
    for j in range(3):
        assert rho[j] == pytest.approx(np.corrcoef(m[:, j], p[:, j])[0, 1], abs=1e-12)
    np.testing.assert_allclose(correlation_coefficient(m, 2 * m + 1), 1.0)


def test_rmse_and_relative_error():
    m = np.array([[3.0], [4.0]])
    p = np.array([[3.0], [3.0]])
    assert rmse(m, p)[0] == pytest.approx(np.sqrt(0.5))
    assert relative_error(m, p)[0] == pytest.approx(100 * 1 / 5)
    with pytest.raises(ShapeError, match="differ in shape"):
        rmse(m, p[:1])


def test_global_relative_error_weighs_every_sample_and_joint():
    from dynid.validation import global_relative_error

    m = np.array([[3.0, 0.1], [4.0, 0.0]])
    p = np.array([[3.0, 0.0], [4.0, 0.1]])
    assert global_relative_error(m, p) == pytest.approx(100 * np.sqrt(0.02) / np.sqrt(25.01))


def test_a_prediction_that_does_not_vary_has_no_correlation(rng):
    m = rng.normal(size=(200, 2))
    p = np.column_stack([m[:, 0], np.full(200, 75.0) + 1e-14 * rng.normal(size=200)])  # a held pose's rounding
    rho = correlation_coefficient(m, p)
    assert rho[0] == pytest.approx(1.0) and np.isnan(rho[1])
    assert np.isfinite(correlation_coefficient(m, m + 1e-6 * rng.normal(size=m.shape))).all()

import numpy as np
import pytest

from dynid.exceptions import ConfigError
from dynid.preprocessing import five_point_cubic_smoothing


def eq17(y):
    """Paper eq. 17, written out term by term."""
    m = len(y)
    s = np.empty(m)
    s[0] = (69 * y[0] + 4 * (y[1] + y[3]) - 6 * y[2] - y[4]) / 70
    s[1] = (2 * (y[0] + y[4]) + 27 * y[1] + 12 * y[2] - 8 * y[3]) / 35
    for i in range(2, m - 2):
        s[i] = (-3 * (y[i - 2] + y[i + 2]) + 12 * (y[i - 1] + y[i + 1]) + 17 * y[i]) / 35
    s[m - 2] = (2 * (y[m - 5] + y[m - 1]) - 8 * y[m - 4] + 12 * y[m - 3] + 27 * y[m - 2]) / 35
    s[m - 1] = (-y[m - 5] + 4 * (y[m - 4] + y[m - 2]) - 6 * y[m - 3] + 69 * y[m - 1]) / 70
    return s


def test_equals_eq17(rng):
    y = rng.normal(size=(200, 3))
    got = five_point_cubic_smoothing(y, passes=1)
    want = np.stack([eq17(y[:, j]) for j in range(3)], axis=1)
    np.testing.assert_allclose(got, want, atol=1e-12)


def test_repeated_passes_and_identity(rng):
    y = rng.normal(size=50)
    np.testing.assert_allclose(five_point_cubic_smoothing(y, 2), eq17(eq17(y)), atol=1e-12)
    np.testing.assert_array_equal(five_point_cubic_smoothing(y, 0), y)


def test_cubic_is_preserved():
    t = np.linspace(-1, 1, 40)
    y = 1 + 2 * t - t**2 + 0.5 * t**3
    np.testing.assert_allclose(five_point_cubic_smoothing(y, 3), y, atol=1e-12)


def test_errors():
    with pytest.raises(ConfigError, match=">= 0"):
        five_point_cubic_smoothing(np.zeros(10), -1)
    with pytest.raises(ConfigError, match="at least 5"):
        five_point_cubic_smoothing(np.zeros(4), 1)

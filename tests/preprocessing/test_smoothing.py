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


def test_eq17_is_scipys_savitzky_golay_to_rounding():
    """Independent truth: eq. 17 is the 5-point cubic Savitzky–Golay filter with polynomial ends (SciPy's
    ``savgol_filter(y, 5, 3, mode="interp")``), which dynid called before it applied the paper's formulas itself."""
    from scipy.signal import savgol_filter

    rng = np.random.default_rng(3)
    for shape in [(5,), (6, 3), (1000, 4)]:
        y = rng.normal(size=shape)
        np.testing.assert_allclose(five_point_cubic_smoothing(y, 1), savgol_filter(y, 5, 3, mode="interp", axis=0),
                                   rtol=0, atol=1e-13)


def test_the_paper_strategy_needs_no_scipy_signal():
    """dynid run's strategy (eq. 17 and the Fourier fit) prepares a log without importing scipy.signal, whose import
    cost a whole run about 0.5-1.5 s (SciPy 1.17 parses every docstring of the module); a Butterworth filter imports it."""
    import subprocess
    import sys

    code = ("import sys, numpy as np, dynid\n"
            "from dynid.preprocessing.preparation import Preprocessing, prepare\n"
            "robot = dynid.load_robot('er16').submodel(3)\n"
            "log = dynid.simulated_log(robot, seconds=10, seed=1)\n"
            "prepare(log, Preprocessing(strategy='paper', fourier=(0.1 * np.pi, 5)))\n"
            "print('scipy.signal' in sys.modules)\n"
            "from dynid.preprocessing.filters import butterworth_filtfilt\n"
            "butterworth_filtfilt(np.ones((100, 1)), 100.0, 10.0)\n"
            "print('scipy.signal' in sys.modules)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["False", "True"]

"""Five-point cubic smoothing (paper eq. 17).

Eq. 17 is the least-squares cubic fitted on a sliding five-sample window, evaluated at the window's
centre inside the signal and at the end samples of the first and last windows — SciPy's Savitzky–Golay filter
``savgol_filter(y, 5, 3, mode="interp")`` to rounding. Its five formulas are applied here as the paper writes them
(weights over 35 and 70): importing ``scipy.signal`` for them cost ``dynid run`` 1.5 s of its 5.
"""

from __future__ import annotations

import numpy as np

from ..exceptions import ConfigError

_INTERIOR = np.array([-3.0, 12.0, 17.0, 12.0, -3.0]) / 35.0
"""``ȳ_i`` from ``y_{i−2} … y_{i+2}`` (eq. 17, i = 3 … m − 2)."""
_FIRST = np.array([[69.0, 4.0, -6.0, 4.0, -1.0], [4.0, 54.0, 24.0, -16.0, 4.0]]) / 70.0
"""``ȳ_1`` and ``ȳ_2`` from ``y_1 … y_5``; the last two samples mirror them."""


def _smooth_once(y: np.ndarray) -> np.ndarray:
    """One application of eq. 17 along axis 0."""
    out = np.empty_like(y)
    m = y.shape[0]
    out[2: m - 2] = sum(_INTERIOR[k] * y[k: m - 4 + k] for k in range(5))
    out[:2] = np.tensordot(_FIRST, y[:5], axes=1)
    out[m - 2:] = np.tensordot(_FIRST[::-1, ::-1], y[m - 5:], axes=1)
    return out


def five_point_cubic_smoothing(y: np.ndarray, passes: int = 1) -> np.ndarray:
    """Apply eq. 17 ``passes`` times along axis 0 (time).

    Parameters
    ----------
    y : (N,) or (N, n) array, N >= 5
    passes : int >= 0
        The paper notes that more passes smooth more but bias the identification.

    Returns
    -------
    ndarray
        Same shape as ``y``.

    Raises
    ------
    ConfigError
        If ``passes`` is negative or there are fewer than 5 samples.
    """
    if passes < 0:
        raise ConfigError(f"smoothing passes must be >= 0, got {passes}")
    y = np.asarray(y, dtype=float)
    if passes and y.shape[0] < 5:
        raise ConfigError(f"eq. 17 smoothing needs at least 5 samples, got {y.shape[0]}")
    for _ in range(passes):
        y = _smooth_once(y)
    return y

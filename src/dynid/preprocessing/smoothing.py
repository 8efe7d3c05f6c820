"""Five-point cubic smoothing (paper eq. 17).

Eq. 17 is the least-squares cubic fitted on a sliding five-sample window, evaluated at the window's
centre inside the signal and at the end samples of the first and last windows: exactly SciPy's
Savitzky–Golay filter ``savgol_filter(y, 5, 3, mode="interp")``.
"""

from __future__ import annotations

import numpy as np
from scipy.signal import savgol_filter

from ..exceptions import ConfigError


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
        y = savgol_filter(y, 5, 3, mode="interp", axis=0)
    return y

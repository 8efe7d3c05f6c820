"""Search boxes of the optimisers."""

from __future__ import annotations

import numpy as np

from ..exceptions import ConfigError


def check_box(bounds, what: str) -> np.ndarray:
    """``bounds`` as a (D, 2) float array of lower < upper.

    Raises
    ------
    ConfigError
        Wrong shape or a lower bound not below its upper bound (``what`` names the optimiser).
    """
    bounds = np.asarray(bounds, dtype=float)
    if bounds.ndim != 2 or bounds.shape[1] != 2 or not np.all(bounds[:, 0] < bounds[:, 1]):
        raise ConfigError(f"{what} bounds must be (D, 2) with lower < upper, got shape {bounds.shape}")
    return bounds

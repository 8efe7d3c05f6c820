"""Search boxes of the optimisers."""

from __future__ import annotations

import numpy as np

from ..exceptions import ConfigError


def check_box(bounds, what: str) -> np.ndarray:
    """A search box as a (D, 2) float array of lower < upper.

    Parameters
    ----------
    bounds : (D, 2) array_like
    what : str
        The optimiser, named in the error.

    Returns
    -------
    (D, 2) ndarray

    Raises
    ------
    ConfigError
        Wrong shape or a lower bound not below its upper bound.
    """
    bounds = np.asarray(bounds, dtype=float)
    if bounds.ndim != 2 or bounds.shape[1] != 2 or not np.all(bounds[:, 0] < bounds[:, 1]):
        raise ConfigError(f"{what} bounds must be (D, 2) with lower < upper, got shape {bounds.shape}")
    return bounds

"""Bootstrap confidence intervals of estimated parameters (moving-block bootstrap over samples).

Torque residuals of a recording are correlated in time (smoothing, derivative estimation, unmodelled
dynamics), so resampling single rows would understate the spread. The moving-block bootstrap draws
blocks of ``L`` consecutive samples (all joints of a sample together) with replacement until the
original length is reached, refits the estimator on each resample and reports percentile intervals.
Ref.: H. R. Künsch, "The jackknife and the bootstrap for general stationary observations", Ann. Statist.
17(3), 1989; B. Efron & R. Tibshirani, "An Introduction to the Bootstrap", 1993, ch. 13 (percentile).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..exceptions import ConfigError
from .base import Estimator, check_observations


@dataclass(frozen=True)
class BootstrapIntervals:
    """Bootstrap distribution of the parameters.

    Attributes
    ----------
    samples : (B, p) array
        Parameters refitted on each resample.
    lower, upper : (p,) arrays
        Percentile interval at ``level``.
    std : (p,) array
        Bootstrap standard deviation.
    level : float
    block_length : int
        Samples per block.
    """

    samples: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    std: np.ndarray
    level: float
    block_length: int


def bootstrap_intervals(make_estimator: Callable[[], Estimator], w, tau, n_dof: int, *, n_resamples: int = 200,
                        block_length: int | None = None, level: float = 0.95,
                        rng: np.random.Generator | int | None = None) -> BootstrapIntervals:
    """Moving-block bootstrap of an estimator's parameters.

    Parameters
    ----------
    make_estimator : callable
        Returns a fresh, unfitted estimator (``fit(W, tau)`` sets ``params_``).
    w : (N·n_dof, p) array
        Observation matrix, rows sample-major.
    tau : (N·n_dof,) or (N, n_dof) array
    n_dof : int
    n_resamples : int
        ``B`` (>= 2).
    block_length : int, optional
        Samples per block (default ``round(N^(1/3))``).
    level : float
        Confidence level in (0, 1).
    rng : Generator or seed

    Returns
    -------
    BootstrapIntervals

    Raises
    ------
    ConfigError
        Invalid ``n_resamples``, ``block_length`` or ``level``.
    ShapeError
        Inconsistent ``W`` and ``tau``.
    """
    w, tau = check_observations(w, tau, n_dof)
    n = w.shape[0] // n_dof
    if n_resamples < 2:
        raise ConfigError(f"bootstrap needs at least 2 resamples, got {n_resamples}")
    if not 0 < level < 1:
        raise ConfigError(f"bootstrap confidence level must be in (0, 1), got {level}")
    length = max(1, round(n ** (1 / 3))) if block_length is None else int(block_length)
    if not 1 <= length <= n:
        raise ConfigError(f"bootstrap block length must be between 1 and {n} samples, got {block_length}")
    rng = np.random.default_rng(rng)
    n_blocks = -(-n // length)
    w3, tau2 = w.reshape(n, n_dof, -1), tau.reshape(n, n_dof)
    samples = []
    for _ in range(n_resamples):
        starts = rng.integers(0, n - length + 1, n_blocks)
        idx = (starts[:, None] + np.arange(length)).ravel()[:n]
        est = make_estimator().fit(w3[idx].reshape(n * n_dof, -1), tau2[idx].ravel())
        samples.append(est.params_)
    samples = np.array(samples)
    alpha = 100 * (1 - level) / 2
    lower, upper = np.percentile(samples, [alpha, 100 - alpha], axis=0)
    return BootstrapIntervals(samples, lower, upper, samples.std(axis=0, ddof=1), level, length)

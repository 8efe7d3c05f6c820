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
from .accumulate import LeastSquaresAccumulator
from .base import Estimator, check_observations
from .least_squares import OrdinaryLeastSquares, WeightedLeastSquares

GRAM_CHUNK = 4096
"""Samples per step when the per-sample Gram matrices are weighted by the resample counts."""


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
    resamples = []
    for _ in range(n_resamples):
        starts = rng.integers(0, n - length + 1, n_blocks)
        resamples.append((starts[:, None] + np.arange(length)).ravel()[:n])
    template = make_estimator()
    if type(template) in (OrdinaryLeastSquares, WeightedLeastSquares):
        samples = _least_squares_resamples(template, w3, tau2, resamples)
    else:
        samples = np.array([make_estimator().fit(w3[idx].reshape(n * n_dof, -1), tau2[idx].ravel()).params_
                            for idx in resamples])
    alpha = 100 * (1 - level) / 2
    lower, upper = np.percentile(samples, [alpha, 100 - alpha], axis=0)
    return BootstrapIntervals(samples, lower, upper, samples.std(axis=0, ddof=1), level, length)


def _least_squares_resamples(template, w3: np.ndarray, tau2: np.ndarray, resamples) -> np.ndarray:
    """OLS/WLS refits of every resample without refactorising it: a resample repeats sample ``s`` ``c_s``
    times, so each joint's Gram matrix of ``[W | τ]`` is ``Σ_s c_s G_s``; all resamples at once are one
    matrix product of the counts (B, N) with the per-sample Grams (N, ·), chunk by chunk. Its Cholesky
    factor is the triangular factor the incremental QR would reach (:class:`LeastSquaresAccumulator`),
    so the solve, its rank check and the WLS weights are those of the estimator itself (to round-off)."""
    n, n_dof, p = w3.shape
    counts = np.array([np.bincount(idx, minlength=n) for idx in resamples], dtype=float)  # (B, N)
    aug = np.concatenate([w3, tau2[..., None]], axis=2)  # (N, n_dof, p+1)
    grams = np.zeros((len(resamples), n_dof * (p + 1) ** 2))
    for a in range(0, n, GRAM_CHUNK):
        block = aug[a:a + GRAM_CHUNK]
        per_sample = np.einsum("sjp,sjq->sjpq", block, block).reshape(block.shape[0], -1)
        grams += counts[:, a:a + GRAM_CHUNK] @ per_sample
    grams = grams.reshape(len(resamples), n_dof, p + 1, p + 1)
    out = []
    for g, idx in zip(grams, resamples):
        acc = LeastSquaresAccumulator(p, n_dof)
        try:
            acc.factors[:] = [np.linalg.cholesky(gj).T for gj in g]
        except np.linalg.LinAlgError:  # a residual of exactly zero: refactorise this resample
            est = template.clone().fit(w3[idx].reshape(n * n_dof, -1), tau2[idx].ravel())
            out.append(est.params_)
            continue
        acc.rows[:] = n
        ols = acc.solve(rcond=template.rcond)
        if isinstance(template, WeightedLeastSquares):
            std = acc.joint_residual_std(ols.params)
            ols = acc.solve(1.0 / np.where(std > 0, std, 1.0), rcond=template.rcond)
        out.append(ols.params)
    return np.array(out)

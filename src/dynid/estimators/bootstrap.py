"""Bootstrap confidence intervals of estimated parameters (moving-block bootstrap over samples).

Torque residuals of a recording are correlated in time (smoothing, derivative estimation, unmodelled
dynamics), so resampling single rows would understate the spread. The moving-block bootstrap draws
blocks of ``L`` consecutive samples (all joints of a sample together) with replacement until the
original length is reached, refits the estimator on each resample and reports percentile intervals.
Ref.: H. R. Künsch, "The jackknife and the bootstrap for general stationary observations", Ann. Statist.
17(3), 1989; B. Efron & R. Tibshirani, "An Introduction to the Bootstrap", 1993, ch. 13 (percentile).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .._util.reprs import short_repr
from ..exceptions import ConfigError
from .base import Estimator, check_observations
from .least_squares import OrdinaryLeastSquares, WeightedLeastSquares
from .problem import FitData, with_problem

GRAM_CHUNK = 4096
"""Samples per step when the per-sample Gram matrices are formed."""


@short_repr
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
                        rng: np.random.Generator | int | None = None, problem: FitData | None = None) -> BootstrapIntervals:
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
    problem : FitData, optional
        What each refit sees of the problem (its ``fit``'s ``problem=``); default ``FitData(n_dof=n_dof)``.

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
    problem = FitData(n_dof=n_dof) if problem is None else problem

    def refit(est, idx):
        return est.fit(w3[idx].reshape(n * n_dof, -1), tau2[idx].ravel(), **with_problem(est.fit, problem)).params_

    if type(template) in (OrdinaryLeastSquares, WeightedLeastSquares):
        samples = _least_squares_resamples(template, w3, tau2, resamples, length, lambda idx: refit(template.clone(), idx))
    else:
        samples = np.array([refit(make_estimator(), idx) for idx in resamples])
    alpha = 100 * (1 - level) / 2
    lower, upper = np.percentile(samples, [alpha, 100 - alpha], axis=0)
    return BootstrapIntervals(samples, lower, upper, samples.std(axis=0, ddof=1), level, length)


def _least_squares_resamples(template, w3: np.ndarray, tau2: np.ndarray, resamples, length: int, refit) -> np.ndarray:
    """OLS/WLS refits of every resample without refactorising it. A resample is a sequence of blocks of
    consecutive samples, so each joint's Gram matrix of ``[W | τ]`` is a sum of block Grams, and a block
    Gram is the difference of two prefix sums of the per-sample Grams: ``P[s + L] − P[s]``. Each resample
    then costs one gather of ``2·N/L`` rows instead of a QR of all of its rows. The Cholesky factor of the
    Gram gives the least-squares solution, and the joints' residual sums of squares (the quadratic form of
    each joint's Gram) give the WLS weights as :class:`WeightedLeastSquares` computes them (to round-off). A resample
    whose Gram is not numerically positive definite is refitted by ``refit(idx)``."""
    n, n_dof, p = w3.shape
    iu = np.triu_indices(p + 1)
    aug = np.concatenate([w3, tau2[..., None]], axis=2)  # (N, n_dof, p+1)
    prefix = np.zeros((n + 1, n_dof, iu[0].size))
    for a in range(0, n, GRAM_CHUNK):
        block = aug[a:a + GRAM_CHUNK]
        prefix[a + 1:a + 1 + block.shape[0]] = block[:, :, iu[0]] * block[:, :, iu[1]]
    np.cumsum(prefix, axis=0, out=prefix)
    out = []
    for idx in resamples:
        starts = idx[::length]
        ends = np.minimum(starts + length, starts + (n - np.arange(starts.size) * length))
        packed = prefix[ends].sum(axis=0) - prefix[starts].sum(axis=0)  # (n_dof, T)
        g = np.zeros((n_dof, p + 1, p + 1))
        g[:, iu[0], iu[1]] = packed
        g = g + np.triu(g, 1).transpose(0, 2, 1)
        try:
            theta = _gram_solve(g.sum(axis=0), p)
            if isinstance(template, WeightedLeastSquares):  # as WeightedLeastSquares.fit: 1/σ_j of the OLS residual
                x = np.append(theta, -1.0)
                ss = np.maximum(np.einsum("i,jik,k->j", x, g, x), 0.0)  # round-off may make an exact fit negative
                std = np.sqrt(ss / np.maximum(n - p / n_dof, 1.0))
                wts = 1.0 / np.where(std > 0, std, 1.0)
                theta = _gram_solve(np.tensordot(wts**2, g, axes=1), p)
        except np.linalg.LinAlgError:  # not numerically positive definite: refactorise this resample
            theta = refit(idx)
        out.append(theta)
    return np.array(out)


def _gram_solve(g: np.ndarray, p: int) -> np.ndarray:
    """Least-squares parameters from the Gram matrix of ``[W | τ]`` (Cholesky; LinAlgError if singular)."""
    c = np.linalg.cholesky(g[:p, :p])
    return np.linalg.solve(c.T, np.linalg.solve(c, g[:p, p]))

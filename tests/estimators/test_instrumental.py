"""Instrumental variables and the long-run covariance of scores correlated in time."""

import numpy as np
import pytest

from dynid.estimators import instrumental
from dynid.estimators.instrumental import (
    instrumental_variables,
    long_run_covariance,
    newey_west_lags,
    parzen_lags,
    weighted_least_squares,
)
from dynid.exceptions import ShapeError


def test_the_long_run_variance_of_a_moving_average():
    """Independent truth: scores ``u_k + θ u_{k−1}`` of white ``u`` have the long-run variance ``T (1 + θ)²`` (their
    spectrum at frequency 0); the white-noise formula would give ``T (1 + θ²)``."""
    rng = np.random.default_rng(4)
    theta, t = 0.8, 200_000
    u = rng.normal(size=t + 1)
    g = (u[1:] + theta * u[:-1])[:, None]
    s = long_run_covariance(g, np.arange(t), lags=40)
    assert s[0, 0] / t == pytest.approx((1 + theta) ** 2, rel=0.05)
    assert not s[0, 0] / t == pytest.approx(1 + theta**2, rel=0.2)


def test_rows_of_one_instant_are_summed_before_the_lags():
    """Two joints with opposite noise at each instant: their scores cancel within the instant."""
    rng = np.random.default_rng(5)
    e = rng.normal(size=1000)
    scores = np.column_stack([e, -e]).reshape(-1, 1)  # instant k: rows 2k (joint 1) and 2k+1 (joint 2)
    instants = np.repeat(np.arange(1000), 2)
    assert long_run_covariance(scores, instants, lags=3)[0, 0] == pytest.approx(0.0, abs=1e-9)
    assert long_run_covariance(scores, np.arange(2000), lags=0)[0, 0] == pytest.approx(2 * e @ e)


def test_instrumental_intervals_hold_the_truth_with_correlated_errors():
    """A Monte Carlo against the estimates' own spread: errors-in-variables in W and an error correlated in time
    (moving average over 5 samples). The sandwich's σ matches the spread of the estimates (within 20 %); the
    white-noise formula's does not."""
    rng = np.random.default_rng(6)
    m, beta = 600, np.array([1.0, -2.0])
    x = np.column_stack([np.sin(np.arange(m) / 15.0), np.cos(np.arange(m) / 40.0)])  # smooth, noise-free rows
    estimates, sandwich, textbook = [], [], []
    for _ in range(400):
        v = np.convolve(rng.normal(size=m + 4), np.ones(5) / np.sqrt(5), mode="valid")
        w = x + 0.3 * rng.normal(size=x.shape)
        tau = x @ beta + v
        sol = instrumental_variables(w, tau, x, np.arange(m))
        estimates.append(sol.params)
        sandwich.append(sol.params_std)
        textbook.append(instrumental_variables(w, tau, x).params_std)
    spread = np.std(estimates, axis=0, ddof=1)
    np.testing.assert_allclose(np.mean(sandwich, axis=0) / spread, 1.0, atol=0.2)
    assert np.all(np.mean(textbook, axis=0) / spread < 0.75)
    assert abs(np.mean(estimates, axis=0) - beta).max() < 3 * spread.max() / np.sqrt(400) + 1e-3


def test_shapes_are_checked_and_the_lags_follow_the_rule():
    with pytest.raises(ShapeError, match="instant"):
        long_run_covariance(np.ones((4, 2)), np.arange(3))
    assert newey_west_lags(100) == 4 and newey_west_lags(1) == 1 and newey_west_lags(176) == 4


def test_parzen_lags_see_the_cancellation_of_blue_noise():
    """Independent truth: a residual that is differenced, smoothed white noise plus a little white noise (blue, as a
    log filtered above its excitation band leaves it) has the autocovariance ``γ_l`` of its taps, so the variance of
    ``Σ z_k r_k`` for fixed, slow instruments is ``Σ_l γ_l Σ_k z_{k+l} z_kᵀ`` exactly. Averaged over draws the Parzen
    estimate with :func:`parzen_lags` is within 25 % of it; Newey–West's Bartlett rule counts the noise the lags cancel
    (measured 3.2-3.3 times; the closed-loop study's σ was 2.7-3.3 times the spread with 30 Hz cutoffs)."""
    rng = np.random.default_rng(7)
    t = 2000
    k = np.arange(t)
    z = np.column_stack([np.sin(2 * np.pi * k / 400), np.cos(2 * np.pi * k / 170) + 0.5])
    taps = np.convolve([1.0, -1.0], [0.25, 0.5, 0.25])
    white = 0.2
    gamma = np.correlate(taps, taps, "full")[taps.size - 1:]
    gamma[0] += white**2
    exact = sum((1 if lag == 0 else 2) * gamma[lag] * 0.5 * (z[lag:].T @ z[: t - lag] + z[: t - lag].T @ z[lag:])
                for lag in range(gamma.size))
    parzen, bartlett = [], []
    for _ in range(100):
        r = np.convolve(rng.normal(size=t + taps.size - 1), taps, "valid") + white * rng.normal(size=t)
        parzen.append(np.diag(long_run_covariance(z * r[:, None], k, kernel="parzen")))
        bartlett.append(np.diag(long_run_covariance(z * r[:, None], k)))
    ratio = np.mean(parzen, axis=0) / np.diag(exact)
    assert np.all((ratio > 0.9) & (ratio < 1.25)), ratio
    assert np.all(np.mean(bartlett, axis=0) / np.diag(exact) > 2.5)
    assert parzen_lags(t) == 40 and parzen_lags(161) == 2 * newey_west_lags(161) == 8


def test_long_lag_windows_are_summed_by_fft_to_the_same_sum(monkeypatch):
    """The FFT path against the direct sum over lags (both kernels, missing instants, lags beyond the log)."""
    rng = np.random.default_rng(8)
    g = rng.normal(size=(3000, 4))
    instants = np.sort(rng.integers(0, 2500, 3000))
    fast = [long_run_covariance(g, instants, lags=lags, kernel=kernel)
            for kernel in ("parzen", "bartlett") for lags in (200, 5000)]
    monkeypatch.setattr(instrumental, "_FFT_ABOVE", 10**9)
    direct = [long_run_covariance(g, instants, lags=lags, kernel=kernel)
              for kernel in ("parzen", "bartlett") for lags in (200, 5000)]
    for a, b in zip(fast, direct):
        np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-9 * np.abs(b).max())
    np.testing.assert_allclose(fast[0], fast[0].T)
    assert np.linalg.eigvalsh(fast[0]).min() > -1e-9 * np.abs(fast[0]).max()
    with pytest.raises(ValueError, match="kernel"):
        long_run_covariance(g, instants, kernel="tukey")


def test_the_covariance_is_the_estimators_own_with_instruments_far_from_the_regressors():
    """The IV estimate is ``A τ`` with ``A = (ZᵀW)⁻¹Zᵀ``: with independent noise of variance σ² its covariance is
    exactly ``σ² A Aᵀ``. With instruments Z = W R (R not symmetric) ZᵀW is far from symmetric, so a sandwich that lost
    a transpose (``(ZᵀW)⁻¹ S (ZᵀW)⁻¹``) differs from it; the simulated instruments of the closed-loop tests are close
    to W and did not show it."""
    rng = np.random.default_rng(11)
    m, p, sigma = 4000, 4, 0.3
    w = rng.normal(size=(m, p))
    r = np.eye(p) + np.triu(rng.normal(size=(p, p)), 1) * 2.0
    z = w @ r
    tau = w @ np.arange(1.0, p + 1) + sigma * rng.normal(size=m)
    sol = instrumental_variables(w, tau, z)
    zw = z.T @ w
    assert np.linalg.norm(zw - zw.T) > 0.5 * np.linalg.norm(zw)  # far from symmetric
    a = np.linalg.solve(zw, z.T)
    truth = sol.residual_std**2 * a @ a.T  # the same σ̂², the estimator's own linear map
    np.testing.assert_allclose(sol.covariance, truth, rtol=1e-8, atol=1e-12)


def test_weighted_least_squares_is_least_squares_on_the_scaled_rows_and_its_sandwich_the_spread():
    """The estimate is NumPy's least squares on the rows divided by their σ (a row of infinite σ left out); its σ
    without instants is the textbook ``s² (AᵀA)⁻¹`` of those rows; with an error correlated in time (a moving average over 5
    samples) the sandwich's σ matches the Monte Carlo spread of the estimates (within 20 %), the textbook's does not."""
    rng = np.random.default_rng(3)
    m, beta = 600, np.array([1.0, -2.0])
    x = np.column_stack([np.sin(np.arange(m) / 15.0), np.cos(np.arange(m) / 40.0)])
    sigma = np.where(np.arange(m) % 2 == 0, 0.5, 2.0)
    tau = x @ beta + sigma * rng.normal(size=m)
    sigma_out = sigma.copy()
    sigma_out[:10] = np.inf
    a, b = x[10:] / sigma[10:, None], tau[10:] / sigma[10:]
    np.testing.assert_allclose(weighted_least_squares(x, tau, sigma_out)[0], np.linalg.lstsq(a, b, rcond=None)[0], rtol=1e-10)
    params, std = weighted_least_squares(x, tau, sigma)
    a, b = x / sigma[:, None], tau / sigma
    np.testing.assert_allclose(params, np.linalg.lstsq(a, b, rcond=None)[0], rtol=1e-10)
    s2 = np.sum((b - a @ params) ** 2) / (m - 2)
    np.testing.assert_allclose(std, np.sqrt(np.diag(s2 * np.linalg.inv(a.T @ a))), rtol=1e-8)
    estimates, sandwich, textbook = [], [], []
    for _ in range(400):
        v = np.convolve(rng.normal(size=m + 4), np.ones(5) / np.sqrt(5), mode="valid")
        tau = x @ beta + v
        p, s = weighted_least_squares(x, tau, np.ones(m), np.arange(m))
        estimates.append(p)
        sandwich.append(s)
        textbook.append(weighted_least_squares(x, tau, np.ones(m))[1])
    spread = np.std(estimates, axis=0, ddof=1)
    np.testing.assert_allclose(np.mean(sandwich, axis=0) / spread, 1.0, atol=0.2)
    assert np.all(np.mean(textbook, axis=0) / spread < 0.75)

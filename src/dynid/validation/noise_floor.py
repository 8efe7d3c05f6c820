"""The noise floor of a scored log: what a perfect model would score on the same samples.

The measured torques carry noise (sensor, current, quantisation) that no model predicts. Its level is estimated from
the log itself: the second difference ``τ[k+1] - 2τ[k] + τ[k-1]`` of a sampled motion is almost only noise at the
rates robots log (the motion's own second difference is ``τ̈·Δt²``), with variance ``6σ²`` for white noise, and its
median absolute deviation is robust to the few steps of friction at reversals: ``σ = 1.4826·MAD / √6``. The scored
samples keep the part of it the parallel (or anti-aliasing) zero-phase Butterworth filter passes: a white noise of
variance ``σ²`` over ``[0, rate/2]`` keeps ``σ²·f_c·I_n / (rate/2)``, with ``I_n = ∫₀^∞ (1 + x^{2n})^{-2} dx`` the
noise bandwidth of the forward-backward filter of order ``n`` in units of its cutoff (Gautier's parallel filtering,
the paper's eq. 17 preprocessing; Donoho & Johnstone 1994 for the MAD estimate of a noise level).

The floor of a joint is that filtered σ [N·m], as an RMSE, and ``100·σ / RMS τ`` as a relative error; over all joints
``100·sqrt(Σσ²) / sqrt(Σ RMS τ²)``. A set whose error is near its floor is as good as the samples allow.

A log filtered before dynid read it keeps almost no sample-to-sample noise: its floor would read near 0 and say
nothing of the sensor. Such a log is recognised (:func:`looks_filtered`) and its floor is unknown.
"""

from __future__ import annotations

import numpy as np

from ..preprocessing.bands import decimation_cutoff

__all__ = ["AT_FLOOR", "SMOOTH", "looks_filtered", "torque_noise", "scored_bandwidth", "noise_floor"]

AT_FLOOR = 1.5
"""An error at most this many times the floor is "at the noise floor"."""


SMOOTH = 0.1
"""[%] A log whose torques' sample-to-sample noise (:func:`torque_noise`) is below this share of their RMS on the
median joint was low-pass filtered before dynid read it, or simulated without noise. Measured (2026-11-26): the raw
logs of ../shared/data show medians of 2.4-4.3 % (single joints 0.28-12 %); the UR10e's log filtered at 3 Hz 0.019 %,
a simulated ER-16 log filtered at 3 Hz 0.034 %; the issue's ROS 2 bag of filtered currents reported 0.002 %. What is
left in such a log is the motion's own second difference, not the sensor's noise: its noise floor cannot be read
from it."""


def looks_filtered(tau, noise: np.ndarray | None = None) -> bool:
    """Whether a log's torques carry no measurable sample-to-sample noise (:data:`SMOOTH`).

    Parameters
    ----------
    tau : (N, n_dof) array or StoredColumns [N·m]
        Raw measured torques, as read.
    noise : (n_dof,) array [N·m], optional
        Their :func:`torque_noise`, where the caller has it (computed here otherwise).

    Returns
    -------
    bool
        False for a log of fewer than 3 samples or with no joint that carries torque.
    """
    noise = torque_noise(tau) if noise is None else noise
    rms = np.array([float(np.sqrt(np.mean(np.square(np.asarray(tau.column(j) if hasattr(tau, "column") else tau[:, j],
                                                                 dtype=float))))) for j in range(tau.shape[1])])
    live = rms > 0
    return bool(live.any() and tau.shape[0] >= 3 and np.median(100.0 * noise[live] / rms[live]) < SMOOTH)


def torque_noise(tau) -> np.ndarray:
    """Each joint's white-noise level in a log's raw torques, from the MAD of their second differences.

    Parameters
    ----------
    tau : (N, n_dof) array or StoredColumns [N·m]
        Raw (unfiltered) measured torques.

    Returns
    -------
    (n_dof,) ndarray [N·m]
        0 for a log of fewer than 3 samples.
    """
    n = tau.shape[1]
    out = np.zeros(n)
    for j in range(n):
        column = np.asarray(tau.column(j) if hasattr(tau, "column") else tau[:, j], dtype=float)
        if column.size >= 3:
            d2 = column[2:] - 2 * column[1:-1] + column[:-2]
            out[j] = 1.4826 * float(np.median(np.abs(d2 - np.median(d2)))) / np.sqrt(6.0)
    return out


def _noise_bandwidth(order: int) -> float:
    """``∫₀^∞ (1 + x^{2n})^{-2} dx`` of a forward-backward Butterworth low-pass of order n (x: frequency / cutoff)."""
    x, dx = np.linspace(0.0, 20.0, 200_001, retstep=True)
    f = (1.0 + x ** (2 * order)) ** -2
    return float((f.sum() - 0.5 * (f[0] + f[-1])) * dx)


def scored_bandwidth(settings, rate: float) -> float:
    """The share of a white noise's variance the scored samples keep after the parallel or anti-aliasing filter.

    Parameters
    ----------
    settings : Preprocessing
        Resolved (its ``parallel_cutoff``, ``decimation`` and ``order``).
    rate : float [Hz]

    Returns
    -------
    float
        In (0, 1]: 1 when nothing filters the torques.
    """
    cutoff = float(settings.parallel_cutoff or 0.0)
    dec = int(settings.decimation or 1)
    if cutoff <= 0 and dec > 1:
        cutoff = decimation_cutoff(rate, dec)
    if cutoff <= 0:
        return 1.0
    return float(min(1.0, cutoff * _noise_bandwidth(int(settings.order)) / (rate / 2)))


def noise_floor(data) -> np.ndarray | None:
    """Each joint's noise floor on the samples a prepared log is scored on (module docstring).

    Parameters
    ----------
    data : PreparedData

    Returns
    -------
    (n_dof,) ndarray [N·m] or None
        The RMSE a perfect model would have there; None (unknown) for torques without measurable noise
        (:func:`looks_filtered`: filtered before dynid read them, the floor is not in them any more).
    """
    noise = torque_noise(data.tau)
    if looks_filtered(data.tau, noise):
        return None
    return noise * np.sqrt(scored_bandwidth(data.settings, data.rate))

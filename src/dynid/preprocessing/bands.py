"""Preprocessing defaults derived from the data: the excitation band and the cutoffs that follow from it.

A user should never have to choose a cutoff. The rules below follow Gautier's identification practice
(M. Gautier, "Dynamic identification of robots with power model", ICRA 1997; Khalil & Dombre,
"Modeling, Identification and Control of Robots", 2002, §12.5.2):

* the **excitation band** ``f_exc`` is where the motion lives: the frequency below which 99 % of the
  energy of the joint velocities lies, estimated from the spectrum of the measured positions (every
  joint together, each weighted by its own energy), or ``n_harmonics·ω_f/2π`` of a known Fourier
  excitation (eq. 14);
* positions (and measured velocities) are low-passed at ``f_q = 10·f_exc`` (Gautier: ω_fq ≥ 10·ω_dyn),
  so the filter leaves the motion untouched (a 4th-order zero-phase Butterworth changes a component at
  ``f_q/5`` by less than 0.01 %) while removing the noise that differentiation amplifies;
* the **parallel filter** (the same zero-phase low-pass on the torques and on every column of the
  observation matrix, so measured and modelled torque stay comparable, sign(q̇) included) has its
  cutoff at ``f_p = 5·f_exc``: every column keeps its in-band content while the torque noise above
  it, which carries no information on the parameters, is removed;
* the **decimation** keeps the largest factor whose anti-aliasing cutoff ``0.8·f_s/(2·d)`` stays at or
  above ``f_p`` (Khalil & Dombre: decimate after the parallel filter down to about twice its band).

* rows of joint ``j`` slower than ``min_speed_j = 0.05 × its RMS speed`` are left out of the estimation
  (not of the validation): near rest the measured velocity's sign, and so the Coulomb column, is
  unreliable (filter ringing, encoder noise, static friction), and those few rows bias every parameter.

All cutoffs are capped at 0.8 × the Nyquist frequency.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..column_store import StoredColumns

ENERGY_FRACTION = 0.99
"""Fraction of the velocity energy that defines the excitation band."""

POSITION_FACTOR = 10.0
"""Position/velocity filter cutoff over the excitation band (Gautier: ω_fq ≥ 10·ω_dyn)."""

PARALLEL_FACTOR = 10.0
"""Parallel filter cutoff over the excitation band."""

MIN_SPEED_FRACTION = 0.05
"""Rows slower than this fraction of the joint's RMS speed are left out of the estimation."""

NYQUIST_CAP = 0.8
"""No cutoff above this fraction of the Nyquist frequency."""


def decimation_cutoff(rate: float, factor: int) -> float:
    """Cutoff of the anti-aliasing filter of a decimation by ``factor``: 0.8 × the new Nyquist [Hz]."""
    return 0.8 * rate / (2 * factor)


def excitation_band(q: np.ndarray, rate: float, fraction: float = ENERGY_FRACTION) -> float:
    """Frequency below which ``fraction`` of the joint velocities' energy lies, from the positions.

    The positions are detrended (a straight line through the ends, so the record is continuous at its
    wrap-around) and windowed (Hann); the velocity spectrum is ``(2πf)²·|Q(f)|²`` summed over the joints.

    Parameters
    ----------
    q : (N, n_dof) array [rad], or StoredColumns
        Measured positions on a uniform grid (read one joint at a time).
    rate : float [Hz]
    fraction : float in (0, 1)

    Returns
    -------
    float [Hz]
        At least two frequency bins (``2·rate/N``), at most the Nyquist frequency.
    """
    if not isinstance(q, StoredColumns):
        q = np.asarray(q, dtype=float)
        q = q.reshape(q.shape[0], -1)
    n = q.shape[0]
    ramp = np.linspace(0.0, 1.0, n)
    window = np.hanning(n)
    f = np.fft.rfftfreq(n, 1.0 / rate)
    f2 = f**2
    energy = np.zeros(f.size)
    for j in range(q.shape[1]):  # one joint at a time: the spectrum's temporaries are one column long
        column = q[:, j]
        x = (column - column[0] - ramp * (column[-1] - column[0])) * window
        energy += f2 * np.abs(np.fft.rfft(x)) ** 2
    total = energy.sum()
    if not total > 0:
        return float(rate / 2)
    k = int(np.searchsorted(np.cumsum(energy) / total, fraction))
    return float(min(max(f[min(k, f.size - 1)], 2.0 * rate / n), rate / 2))


@dataclass(frozen=True)
class DerivedCutoffs:
    """Cutoffs and decimation derived from an excitation band (module docstring).

    Attributes
    ----------
    band : float [Hz]
    position_cutoff, parallel_cutoff : float [Hz]
    decimation : int
    """

    band: float
    position_cutoff: float
    parallel_cutoff: float
    decimation: int


def decimation_for(rate: float, cutoff: float) -> int:
    """The largest decimation whose anti-aliasing cutoff (:func:`decimation_cutoff`) is at or above ``cutoff``."""
    return max(1, int(np.floor(0.8 * rate / (2 * cutoff))))


def capped(cutoff: float, rate: float) -> float:
    """``cutoff`` [Hz], at most :data:`NYQUIST_CAP` × the Nyquist frequency of ``rate``."""
    return min(cutoff, NYQUIST_CAP * rate / 2)


def cutoffs_from_band(band: float, rate: float) -> DerivedCutoffs:
    """The rules of the module docstring for a band ``band`` [Hz] at sampling rate ``rate`` [Hz]."""
    f_p = capped(PARALLEL_FACTOR * band, rate)
    return DerivedCutoffs(float(band), float(capped(POSITION_FACTOR * band, rate)), float(f_p), decimation_for(rate, f_p))

"""Preprocessing defaults derived from the data: the excitation band and the cutoffs that follow from it.

A user should never have to choose a cutoff. The rules below follow Gautier's identification practice
(M. Gautier, "Dynamic identification of robots with power model", ICRA 1997; Khalil & Dombre,
"Modeling, Identification and Control of Robots", 2002, §12.5.2):

* the **excitation band** ``f_exc`` is where the motion lives: the frequency below which 99 % of the
  energy of the joint velocities lies, estimated from the spectrum of the measured positions above
  its noise floor (every joint together, each weighted by its own energy; :func:`estimate_band`), or
  ``n_harmonics·ω_f/2π`` of a known Fourier excitation (eq. 14);
* positions (and measured velocities) are low-passed at ``f_q =`` :data:`POSITION_FACTOR` ``· f_exc`` (Gautier: ω_fq ≥ 10·ω_dyn),
  so the filter leaves the motion untouched (a 4th-order zero-phase Butterworth changes a component at
  ``f_q/5`` by less than 0.01 %) while removing the noise that differentiation amplifies;
* the **parallel filter** (the same zero-phase low-pass on the torques and on every column of the
  observation matrix, so measured and modelled torque stay comparable, sign(q̇) included) has its
  cutoff at ``f_p =`` :data:`PARALLEL_FACTOR` ``· f_exc``: every column keeps its in-band content while the torque noise above
  it, which carries no information on the parameters, is removed;
* the **decimation** keeps the largest factor whose anti-aliasing cutoff ``0.8·f_s/(2·d)`` stays at or
  above ``f_p`` (Khalil & Dombre: decimate after the parallel filter down to about twice its band).

* rows of joint ``j`` slower than ``min_speed_j =`` :data:`MIN_SPEED_FRACTION` ``× its RMS speed`` are left out of the estimation
  (not of the validation): near rest the measured velocity's sign, and so the Coulomb column, is
  unreliable (filter ringing, encoder noise, static friction), and those few rows bias every parameter.

All cutoffs are capped at :data:`NYQUIST_CAP` × the Nyquist frequency.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._util.column_store import StoredColumns

ENERGY_FRACTION = 0.99
"""Fraction of the velocity energy that defines the excitation band."""

POSITION_FACTOR = 10.0
"""Position/velocity filter cutoff over the excitation band (Gautier: ω_fq ≥ 10·ω_dyn)."""

PARALLEL_FACTOR = 10.0
"""Parallel filter cutoff over the excitation band."""

REST_FACTOR = 3.0
"""A joint rests where its filtered velocity is below this many standard deviations of the velocity's noise
(:func:`dynid.preprocessing.filters.velocity_noise_std`): the sign of a slower velocity is noise."""

MIN_SPEED_FRACTION = 0.05
"""Rows slower than this fraction of the joint's RMS speed are left out of the estimation."""

NYQUIST_CAP = 0.8
"""No cutoff above this fraction of the Nyquist frequency."""


def decimation_cutoff(rate: float, factor: int) -> float:
    """Cutoff of the anti-aliasing filter of a decimation: 0.8 × the new Nyquist frequency.

    Parameters
    ----------
    rate : float [Hz]
        Sampling rate before decimating.
    factor : int
        Decimation factor.

    Returns
    -------
    float [Hz]
    """
    return 0.8 * rate / (2 * factor)


NOISE_BIN_FACTOR = 20.0
"""A periodogram bin counts as motion when it exceeds the noise floor this many times (white noise exceeds it
with probability e⁻²⁰ ≈ 2·10⁻⁹ per bin)."""

NOISE_SMOOTH_FACTOR = 5.0
"""… or when the mean of its 9 nearest bins exceeds the floor this many times (a continuous spectrum)."""

IMPLAUSIBLE_BAND = 0.25
"""A band above this fraction of the Nyquist frequency is implausible for a robot's motion (a warning)."""


@dataclass(frozen=True)
class BandEstimate:
    """The excitation band found in a log's positions, and what the noise holds.

    Attributes
    ----------
    band : float [Hz]
        Frequency below which :data:`ENERGY_FRACTION` of the motion's velocity energy lies (noise excluded).
    noise_share : float in [0, 1]
        Share of the positions' velocity-weighted spectral energy that is broadband noise (the floor).
    rate : float [Hz]
    motion_found : bool
        False when no bin rose above the noise floor (the band is then the plain 99 % rule's).
    knee : float or None [Hz]
        Median over the joints of the first frequency above the band where the positions' spectrum falls to twice
        the noise floor (where the noise takes over).
    """

    band: float
    noise_share: float
    rate: float
    motion_found: bool = True
    knee: float | None = None
    """Frequency [Hz] above the band where the motion's spectrum meets the noise floor (the median over the joints
    of the first 1/6-octave band above ``band`` whose mean power is below twice the floor): above it, noise dominates
    positions, velocities and accelerations alike; below it, the motion does."""

    def warnings(self, name: str) -> tuple[str, ...]:
        """One line per implausible finding, naming the dataset and the setting that fixes it.

        Parameters
        ----------
        name : str
            The dataset.

        Returns
        -------
        tuple of str
        """
        nyquist = self.rate / 2
        out = []
        if not self.motion_found:
            out.append(f"{name}: no motion stands out of the positions' noise floor; the excitation band "
                       f"{self.band:.3g} Hz is a guess: give preprocessing.band (Hz)")
        elif self.band > IMPLAUSIBLE_BAND * nyquist:
            out.append(f"{name}: the excitation band found, {self.band:.3g} Hz, is close to the Nyquist frequency "
                       f"{nyquist:.4g} Hz, so filtering removes little: an undersampled log or positions that are mostly "
                       "noise? Give preprocessing.band (Hz) if the excitation is known")
        return tuple(out)


def _detrended(column: np.ndarray, ramp: np.ndarray) -> np.ndarray:
    """``column`` less its least-squares straight line (``ramp``: 0 to 1 over the samples). A line through the end
    samples would carry their noise into a ramp whose low-frequency energy looks like motion; the Hann window
    tapers what remains at the ends."""
    centred = ramp - 0.5
    slope = float(centred @ (column - column.mean()) / (centred @ centred))
    return column - column.mean() - slope * centred


def _noise_floor(power: np.ndarray, f: np.ndarray, nyquist: float) -> float:
    """Mean periodogram level of broadband noise: the lowest median over octaves of the upper spectrum, divided
    by ln 2 (the median of an exponential variable is ln 2 × its mean). Octaves, because motion raises the
    lower ones and the resampling of jittered time stamps lowers the very top (hence nothing above 0.7 f_N)."""
    medians = []
    hi = 0.7 * nyquist
    while hi > nyquist / 64:
        a, b = np.searchsorted(f, [hi / 2, hi], side="right")  # f ascending: the bins hi/2 < f <= hi
        if b - a >= 16:
            medians.append(np.median(power[a:b]))
        hi /= 2
    if not medians:
        sel = f > nyquist / 4
        medians = [np.median(power[sel])] if sel.any() else [0.0]
    return float(min(medians) / np.log(2))


def estimate_band(q: np.ndarray, rate: float, fraction: float = ENERGY_FRACTION) -> BandEstimate:
    """The excitation band of the motion, found above the positions' noise floor.

    Per joint, the positions are detrended (:func:`_detrended`) and windowed (Hann), and their periodogram ``P(f)`` is compared with its noise
    floor ``N`` (:func:`_noise_floor`, broadband encoder or sensor noise). A bin is motion when ``P``
    exceeds ``20·N`` or its 9-bin mean exceeds ``5·N``; the motion's velocity energy is ``(2πf)²·(P − N)``
    on those bins, summed over the joints (each weighted by its own energy), and the band is where it
    reaches ``fraction``. Without the floor, a few percent of noise energy, which the velocity weighting
    ``f²`` puts at the top of the spectrum, moves the 99 % point to the noise (hundreds of Hz on a 1 kHz
    log whose motion lies below 1 Hz).

    Parameters
    ----------
    q : (N, n_dof) array [rad], or StoredColumns
        Measured positions on a uniform grid (read one joint at a time).
    rate : float [Hz]
    fraction : float in (0, 1)

    Returns
    -------
    BandEstimate
        ``band`` is at least two frequency bins (``2·rate/N``) and at most the Nyquist frequency.

    References
    ----------
    Welch-free periodogram statistics: Percival & Walden, *Spectral Analysis for Physical Applications*
    (1993), §6.4 (the χ²₂ distribution of periodogram ordinates).
    """
    if not isinstance(q, StoredColumns):
        q = np.asarray(q, dtype=float)
        q = q.reshape(q.shape[0], -1)
    n = q.shape[0]
    ramp = np.linspace(0.0, 1.0, n)
    window = np.hanning(n)
    f = np.fft.rfftfreq(n, 1.0 / rate)
    f2 = f**2
    total = np.zeros(f.size)
    motion = np.zeros(f.size)
    noise = 0.0
    kernel = np.ones(9) / 9
    floors, powers = [], []
    grid = np.unique(np.searchsorted(f, np.geomspace(max(f[1], 1e-12), f[-1], 400)))  # 400 points, ~ 1/40 octave
    bounds = _octave_bounds(f)  # the same for every joint
    for j in range(q.shape[1]):  # one joint at a time: the spectrum's temporaries are one column long
        x = _detrended(np.asarray(q[:, j], dtype=float), ramp) * window
        power = np.abs(np.fft.rfft(x)) ** 2
        floor = _noise_floor(power, f, rate / 2)
        floors.append(floor)
        octaves = _octave_smoothed(power, bounds)
        powers.append(octaves[grid])  # on a log-spaced grid: a long log's spectrum is not kept
        total += f2 * power
        if floor > 0:
            smooth = np.convolve(power, kernel, mode="same")
            above = (power > NOISE_BIN_FACTOR * floor) | (smooth > NOISE_SMOOTH_FACTOR * floor)
            above &= f < _first_gap(octaves, f, floor)
            motion += np.where(above, f2 * np.maximum(power - floor, 0.0), 0.0)
            noise += float(f2.sum() * floor)
        else:
            motion += f2 * power
    lo, hi = 2.0 * rate / n, rate / 2
    found = motion.sum() > 0
    energy = motion if found else total
    if not energy.sum() > 0:
        return BandEstimate(float(hi), 0.0, float(rate), False)
    k = int(np.searchsorted(np.cumsum(energy) / energy.sum(), fraction))
    band = float(min(max(f[min(k, f.size - 1)], lo), hi))
    share = float(min(noise / total.sum(), 1.0)) if total.sum() > 0 else 0.0
    knees = []
    for floor, smooth in zip(floors, powers):
        below = np.flatnonzero((f[grid] > band) & (smooth < 2 * floor))
        knees.append(f[grid][below[0]] if below.size and floor > 0 else hi)
    return BandEstimate(band, share, float(rate), bool(found), float(np.median(knees)))


GAP_OCTAVES = 1.0
"""The excitation's motion is the spectrum up to its first stretch of this many octaves at the noise floor (below
twice it, sixth-octave means): what rises above the floor beyond such a gap is not the excitation. In closed loop the
controller shapes the encoder's noise (the sensitivity function: suppressed within the loop's bandwidth, raised
around its crossover), so the floor measured where the loop suppresses it is below the white noise at the top of
the spectrum, which would otherwise count as motion and, weighted by f², put the band near the Nyquist frequency."""


def _first_gap(smoothed: np.ndarray, f: np.ndarray, floor: float) -> float:
    """The frequency [Hz] where the first :data:`GAP_OCTAVES` stretch at the floor starts (inf when there is none)."""
    quiet = np.concatenate([[0], (smoothed[1:] < 2 * floor).astype(np.int8), [0]])
    edges = np.diff(quiet)
    starts, last = np.flatnonzero(edges == 1) + 1, np.flatnonzero(edges == -1)  # runs [start, last] of quiet bins
    wide = f[last] >= f[starts] * 2**GAP_OCTAVES
    return float(f[starts[wide][0]]) if wide.any() else np.inf


def _octave_bounds(f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each frequency of ``f`` (ascending), the first and one past the last bin within a twelfth of an octave
    either side of it (:func:`_octave_smoothed`)."""
    return np.searchsorted(f, f / 2 ** (1 / 12)), np.searchsorted(f, f * 2 ** (1 / 12), side="right")


def _octave_smoothed(power: np.ndarray, bounds: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
    """The mean of ``power`` over a sixth of an octave around each frequency (a running sum: O(N); ``bounds``:
    :func:`_octave_bounds` of the frequencies)."""
    lo, hi = bounds
    c = np.concatenate([[0.0], np.cumsum(power)])
    return (c[hi] - c[lo]) / np.maximum(hi - lo, 1)


def white_noise_std(x, rate: float) -> np.ndarray:
    """Standard deviation of the broadband (white) noise in each column of ``x``, from its periodogram's noise
    floor (:func:`_noise_floor`): ``σ² = N / Σw²`` for the Hann window ``w``.

    Parameters
    ----------
    x : (N, k) array or StoredColumns
        Positions [rad] or velocities [rad/s] on a uniform grid.
    rate : float [Hz]

    Returns
    -------
    (k,) array, in the unit of ``x``.
    """
    n = x.shape[0]
    ramp = np.linspace(0.0, 1.0, n)
    window = np.hanning(n)
    f = np.fft.rfftfreq(n, 1.0 / rate)
    out = np.zeros(x.shape[1])
    for j in range(x.shape[1]):
        y = _detrended(np.asarray(x[:, j], dtype=float), ramp) * window
        out[j] = np.sqrt(_noise_floor(np.abs(np.fft.rfft(y)) ** 2, f, rate / 2) / float((window**2).sum()))
    return out


def difference_noise_std(x) -> np.ndarray:
    """Standard deviation of the white noise in each column of ``x`` from its second differences, robustly:
    ``1.4826 · MAD(Δ²x) / √6`` (white noise's second difference has variance 6σ²; a smooth signal's is small, and the
    median ignores the isolated jumps Coulomb friction puts in a current or torque, which inflate a spectrum's noise
    floor).

    Parameters
    ----------
    x : (N, k) array or StoredColumns
        On a uniform grid, N >= 3.

    Returns
    -------
    (k,) array, in the unit of ``x``.
    """
    out = np.zeros(x.shape[1])
    for j in range(x.shape[1]):
        c = np.asarray(x[:, j], dtype=float)
        d2 = c[2:] - 2 * c[1:-1] + c[:-2]
        out[j] = 1.4826 * float(np.median(np.abs(d2 - np.median(d2)))) / np.sqrt(6.0)
    return out


def excitation_band(q: np.ndarray, rate: float, fraction: float = ENERGY_FRACTION) -> float:
    """The excitation band of :func:`estimate_band`.

    Parameters
    ----------
    q : (N, n_dof) array [rad]
        Positions on a uniform grid.
    rate : float [Hz]
    fraction : float
        Share of the motion's velocity energy below the band.

    Returns
    -------
    float [Hz]
    """
    return estimate_band(q, rate, fraction).band


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
    """The largest decimation whose anti-aliasing cutoff (:func:`decimation_cutoff`) is at or above a cutoff.

    Parameters
    ----------
    rate : float [Hz]
    cutoff : float [Hz]

    Returns
    -------
    int
        At least 1.
    """
    return max(1, int(np.floor(0.8 * rate / (2 * cutoff))))


def capped(cutoff: float, rate: float) -> float:
    """A cutoff at most :data:`NYQUIST_CAP` × the Nyquist frequency of a rate.

    Parameters
    ----------
    cutoff : float [Hz]
    rate : float [Hz]

    Returns
    -------
    float [Hz]
    """
    return min(cutoff, NYQUIST_CAP * rate / 2)


def cutoffs_from_band(band: float, rate: float) -> DerivedCutoffs:
    """The cutoffs and decimation the module's rules derive from an excitation band.

    Parameters
    ----------
    band : float [Hz]
        Excitation band.
    rate : float [Hz]
        Sampling rate.

    Returns
    -------
    DerivedCutoffs
    """
    f_p = capped(PARALLEL_FACTOR * band, rate)
    return DerivedCutoffs(float(band), float(capped(POSITION_FACTOR * band, rate)), float(f_p), decimation_for(rate, f_p))

"""Zero-phase filtering, differentiation and parallel decimation of logs that are not one known
Fourier trajectory (Gautier's identification practice; SciPy's ``butter`` and ``sosfiltfilt``).

References: M. Gautier, "Dynamic identification of robots with power model", ICRA 1997 (parallel
decimation of the observation matrix and the torques); Khalil & Dombre 2002, §12.5.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from .._util.column_store import by_column
from ..exceptions import ConfigError
from ..runtime.threads import cores
from ._filter_kernel import gaussian_nearest, gaussian_weights, zero_phase
from .bands import decimation_cutoff


def _signal():
    """``scipy.signal``, imported when a filter is designed: its import costs about 1.5 s (SciPy 1.17), which a run
    that filters nothing (the paper's eq. 17 and Fourier-fit strategy) does not pay."""
    from scipy import signal

    return signal


def _check_cutoff(rate: float, cutoff: float, what: str) -> None:
    if not (rate > 0 and 0 < cutoff < rate / 2):
        raise ConfigError(f"{what}: expected 0 < cutoff < rate/2 = {rate / 2:g} Hz, got cutoff {cutoff:g} Hz at {rate:g} Hz")


def butterworth_filtfilt(x: np.ndarray, rate: float, cutoff: float, order: int = 4) -> np.ndarray:
    """Zero-phase low-pass Butterworth filter along time (axis 0).

    Parameters
    ----------
    x : (N, ...) array, or StoredColumns (:mod:`dynid._util.column_store`: the result is stored too)
        Filtered one column at a time: the same numbers as the whole-array call along axis 0.
    rate : float
        Sampling rate [Hz].
    cutoff : float
        -3 dB frequency of the single pass [Hz] (the forward-backward pass squares the gain).
    order : int

    Returns
    -------
    (N, ...) array or StoredColumns
        The filtered samples.

    Raises
    ------
    ConfigError
        If ``cutoff`` is not in (0, rate/2).
    """
    _check_cutoff(rate, cutoff, "Butterworth filter")
    signal = _signal()
    sos = signal.butter(order, cutoff, btype="low", fs=rate, output="sos")
    if isinstance(x, np.ndarray) and 0 < x.size <= WHOLE_ARRAY_VALUES:  # one call: its set-up paid once, not per column
        return signal.sosfiltfilt(sos, np.asarray(x, dtype=float), axis=0)
    return by_column(x, lambda column, j: signal.sosfiltfilt(sos, column))


def even_filtfilt(signal, sos: np.ndarray, x: np.ndarray, padlen: int, zi: np.ndarray, *,
                  carry: tuple | None = None) -> np.ndarray:
    """``scipy.signal.sosfiltfilt(sos, x, axis=0, padtype="even", padlen=padlen)``, bit for bit, with the filter's
    initial state ``zi`` computed once by the caller: SciPy's own steps (the even extension, ``sosfilt`` forward from
    ``zi`` times the first sample, backward from ``zi`` times the last output) without its per-call checks and
    ``sosfilt_zi``, which cost as much as filtering a block of two columns of a few thousand samples.

    With ``carry``, ``x`` is a block of a longer signal whose forward pass goes on from the block before: exact, as one
    pass over the whole signal (:func:`parallel_decimation`).

    Parameters
    ----------
    signal : module
        ``scipy.signal`` (:func:`_signal`).
    sos : (n_sections, 6) array
    x : (n, c) array
        Signals along axis 0; ``n > padlen``.
    padlen : int
        Samples of even extension at each end (0: none).
    zi : (n_sections, 2) array
        ``signal.sosfilt_zi(sos)``.
    carry : tuple ``(state, split, state_out)``, optional
        ``state`` (n_sections, 2, c): the forward pass's state at ``x``'s first row, which is then not padded (None:
        padded and started as SciPy does); ``split``: a row of ``x`` whose forward state ``state_out`` (n_sections, 2,
        c) receives (None: none).

    Returns
    -------
    (n, c) ndarray
    """
    initial, split, state_out = (None, None, None) if carry is None else carry
    left = padlen if initial is None else 0
    ext = np.concatenate([x[left:0:-1], x, x[-2:-(padlen + 2):-1]]) if padlen else x
    state = zi.reshape(zi.shape[0], 2, 1)
    z = state * ext[:1] if initial is None else initial
    if split is None:
        y, _ = signal.sosfilt(sos, ext, axis=0, zi=z)
    else:  # forward to the split, its state kept, then on: the same operations as one pass
        head, state_out[...] = signal.sosfilt(sos, ext[:left + split], axis=0, zi=z)
        y = np.concatenate([head, signal.sosfilt(sos, ext[left + split:], axis=0, zi=state_out)[0]])
    y, _ = signal.sosfilt(sos, y[::-1], axis=0, zi=state * y[-1:])
    y = y[::-1]
    return y[left:y.shape[0] - padlen] if padlen else y


WHOLE_ARRAY_VALUES = 500_000
"""Up to this many values, :func:`butterworth_filtfilt` filters an array in one call along its first axis (the same
numbers as column by column; SciPy computes the filter's initial state and pads once per call, not once per column);
above it, a column at a time, so that SciPy's copies stay one column's."""


def differentiate(x: np.ndarray, rate: float) -> np.ndarray:
    """Time derivative by central differences (one-sided at the ends), one column at a time.

    Parameters
    ----------
    x : (N, ...) array or StoredColumns
    rate : float
        Sampling rate [Hz].

    Returns
    -------
    (N, ...) array or StoredColumns
        In the unit of ``x`` per second.
    """
    return by_column(x, lambda column, j: np.gradient(column, 1.0 / rate))


GAUSS_CUTOFF = np.sqrt(np.log(2) / 2) / np.pi
"""A Gaussian kernel of standard deviation ``σ_t`` [s] halves the power at ``GAUSS_CUTOFF / σ_t`` [Hz] (0.1325/σ_t)."""


def gaussian_smooth(x, rate: float, cutoff: float):
    """Gaussian smoothing along time, column by column (stored columns stay stored).

    Unlike a Butterworth filter its step response does not overshoot, so a velocity smoothed by it never changes sign
    where the joint stops abruptly.

    Parameters
    ----------
    x : (N, ...) array or StoredColumns
    rate : float
        Sampling rate [Hz].
    cutoff : float
        Half-power frequency [Hz]; 0: no smoothing.

    Returns
    -------
    (N, ...) array or StoredColumns
    """
    from scipy.ndimage import gaussian_filter1d

    if not 0 < cutoff < rate / 2:
        return x
    sigma = GAUSS_CUTOFF / cutoff * rate
    if x.shape[0] * int(np.prod(x.shape[1:])) * 8 * sigma >= COMPILED_GAUSSIAN_WORK:
        weights, workers = gaussian_weights(sigma), cores()
        return by_column(x, lambda column, j: gaussian_nearest(column, weights, workers))
    return by_column(x, lambda column, j: gaussian_filter1d(column, sigma, mode="nearest"))


COMPILED_GAUSSIAN_WORK = 2_000_000_000
"""From this many products (samples × columns × the kernel's 8σ + 1 weights) on, :func:`gaussian_smooth` runs the
compiled correlation (:func:`dynid.preprocessing._filter_kernel.gaussian_nearest`, SciPy's numbers bit for bit, on the
process's cores): about a second of SciPy's ``gaussian_filter1d``; an hour of six joints at 1 kHz smoothed at 4 Hz is
5.7·10⁹. Below it SciPy's, and the process never loads numba."""


def velocity_noise_std(sigma: np.ndarray, rate: float, cutoff: float, order: int, differentiated: bool,
                       gaussian: bool = False) -> np.ndarray:
    """Standard deviation of the noise left in a velocity after this module's filters.

    White noise of standard deviation ``sigma`` (per joint) on the positions (``differentiated``: the velocity is
    their central difference after the low-pass) or on measured velocities, through :func:`butterworth_filtfilt`
    at ``cutoff`` (0: none), or with ``gaussian`` through :func:`gaussian_smooth`:
    ``σ_v² = ∫ (2σ²/f_s)·|H(f)|²·|D(f)|² df`` over ``[0, f_s/2]``, where ``|H|²`` is the zero-phase filter's
    power gain (``|B(f)|⁴`` for the forward-backward Butterworth ``B``, ``exp(-(2πfσ_t)²)`` for the Gaussian) and
    ``|D(f)| = f_s·sin(2πf/f_s)`` for the central difference (``|D| = 1`` otherwise).

    Parameters
    ----------
    sigma : (n_dof,) array [rad or rad/s]
    rate, cutoff : float [Hz]
    order : int
    differentiated, gaussian : bool

    Returns
    -------
    (n_dof,) array [rad/s]
    """
    f = np.linspace(0.0, rate / 2, 4097)
    gain = np.ones_like(f)
    if 0 < cutoff < rate / 2 and gaussian:
        gain = np.exp(-((2 * np.pi * f * GAUSS_CUTOFF / cutoff) ** 2))
    elif 0 < cutoff < rate / 2:
        signal = _signal()
        sos = signal.butter(order, cutoff, btype="low", fs=rate, output="sos")
        gain = np.abs(signal.sosfreqz(sos, worN=f, fs=rate)[1]) ** 4
    if differentiated:
        gain = gain * (rate * np.sin(2 * np.pi * f / rate)) ** 2
    integral = float(np.sum((gain[1:] + gain[:-1]) / 2) * (f[1] - f[0]))
    return np.asarray(sigma, dtype=float) * np.sqrt(2.0 / rate * integral)


COLUMN_BLOCK = 2
"""The fewest columns filtered at once by :func:`parallel_decimation` (more for a short block: :data:`BLOCK_VALUES`),
one block per core at a time (bounds the filter's temporary copies: 16 rather than 64 took 33 MB off the TX40
identification's peak, 8 rather than 16 another 4 MB; on two cores' threads blocks of 2 keep the peak 3 MB above one
thread's blocks of 8, blocks of 4 7 MB). Each column is filtered on its own, so the numbers do not depend on the
blocks or the cores."""

BLOCK_VALUES = 60_000
"""A block of a short signal takes more columns than :data:`COLUMN_BLOCK`, up to this many values (rows × columns) in
all: SciPy's set-up per call costs as much as filtering two columns of a few thousand samples, and a block of this
size holds its copies in about 3 MB."""

COMPILED_FILTER_VALUES = 50_000_000
"""From this many values (the log's samples × the columns of every signal filtered together) on,
:func:`parallel_decimation` filters with the compiled filter (:mod:`dynid.preprocessing._filter_kernel`, SciPy's numbers bit for bit): an hour at 1 kHz. Below it,
SciPy's ``sosfiltfilt``, and the process never loads numba."""

COMPILED_COLUMN_BLOCK = 16
"""Columns the compiled filter takes at once (it runs along a row's columns, so more than :data:`COLUMN_BLOCK`)."""

PARALLEL_VALUES = 200_000
"""From this many values (samples × columns to filter) on, :func:`parallel_decimation` filters its column blocks on
the process's cores (SciPy's filter releases the GIL): a TX40 block of 28,000 samples × 522 columns in 0.23 s on two
threads in blocks of 2 against 0.61 s on one in blocks of 8."""


class FractionalShift:
    """Signals read a fraction of a sample later or earlier: a band-limited shift.

    A Lanczos-windowed sinc of ``2·taps`` coefficients, ``h_m = sinc(m − δ) sinc((m − δ)/taps)`` normalised to a unit
    sum, ``δ`` the fractional part of the shift (Laakso et al., "Splitting the unit delay", IEEE Signal Processing
    Magazine 13(1), 1996): flat and linear-phase over most of the band, local (the ends mirrored over ``taps``
    samples), and unlike linear interpolation it keeps the noise's power at every shift (interpolating half-way
    averages two samples and halves white noise's variance, which pulls a delay estimate to half samples). Half-way
    between samples it keeps 95 % of white noise's variance; SciPy's spline shift (``scipy.ndimage.shift``, orders 3
    and 5) keeps 75 % and 83 %, linear interpolation 50 % (measured on 20 000 samples).

    Parameters
    ----------
    x : (N,) or (N, m) array
        Samples on a uniform grid, time first.
    taps : int
        Coefficients on each side.
    """

    def __init__(self, x, taps: int = 16):
        self.x = np.asarray(x, dtype=float)
        self.n = self.x.shape[0]
        self.taps = int(taps)
        self._pad, self._mirrored = -1, self.x  # the mirrored signal, made for the largest shift read so far

    def _mirrored_by(self, pad: int) -> tuple[int, np.ndarray]:
        """The signal with at least ``pad`` mirrored samples at each end, and how many it has."""
        if pad > self._pad:
            self._pad = max(pad, 2 * self._pad)
            self._mirrored = np.pad(self.x, [(self._pad, self._pad)] + [(0, 0)] * (self.x.ndim - 1), mode="symmetric")
        return self._pad, self._mirrored

    def read(self, samples: float, at: np.ndarray | None = None) -> np.ndarray:
        """The signal ``samples`` later: ``y[k] = x(k + samples)``.

        Parameters
        ----------
        samples : float
            Negative: earlier.
        at : (M,) int array, optional
            Only these samples ``k`` (the same values as ``read(samples)[at]``, computed at them alone).

        Returns
        -------
        array, the shape of ``x`` (of ``x[at]``)
            At the ends the mirror image stands for the samples the log does not hold.
        """
        whole = int(np.floor(samples))
        frac = float(samples) - whole
        if frac < 1e-12:
            offsets, weights = np.array([0]), np.array([1.0])
        else:
            offsets = np.arange(-self.taps + 1, self.taps + 1)
            weights = np.sinc(offsets - frac) * np.sinc((offsets - frac) / self.taps)
            weights /= weights.sum()
        pad, mirrored = self._mirrored_by(abs(whole) + self.taps + 1)
        out = np.zeros_like(self.x if at is None else self.x[at])
        for offset, weight in zip(offsets, weights):
            start = pad + whole + int(offset)
            out += weight * (mirrored[start:start + self.n] if at is None else mirrored[start + np.asarray(at)])
        return out


def edge_padding(rate: float, cutoff: float, order: int) -> int:
    """Samples the parallel filter pads each end of a log with, by even (mirror) extension: about the filter's
    settling time, ``order / (2 · cutoff)`` seconds.

    A mirror extension of that length makes the filter's start average the samples near the edge. SciPy's default
    odd extension of a few samples pivots on the edge sample itself and starts the filter from twice its value: a
    noisy torque log (a robot in closed loop carries the loop's torque noise) then left one sample's whole noise in
    the first and last decimated rows (measured: edge spread 102 against 6.9 inside, for white noise through a
    2.8 Hz filter at 1 kHz). Torques and observation matrix are padded alike, so ``τ = Wβ`` holds on the padded
    rows as on the others.

    Parameters
    ----------
    rate, cutoff : float [Hz]
    order : int

    Returns
    -------
    int
    """
    return int(np.ceil(order * rate / (2.0 * cutoff)))


def _on_cores(task: Callable, items: list, parallel: bool) -> None:
    """``task(item)`` for every item, on the process's cores when ``parallel`` (threads: the tasks release the GIL)."""
    workers = min(cores(), len(items)) if parallel else 1
    if workers <= 1:
        for item in items:
            task(item)
        return

    with ThreadPoolExecutor(max_workers=workers) as pool:
        list(pool.map(task, items))


def _live_columns(flat: np.ndarray) -> np.ndarray:
    """The columns of ``flat`` (n, m) that are not zero throughout: ``np.any`` (which casts by buffers, no temporary),
    a block of rows per core where it is large (:data:`PARALLEL_VALUES`; benchmarks/NOTEBOOK.md, stop 114). The same
    columns either way."""
    workers = min(cores(), flat.shape[0]) if flat.size >= PARALLEL_VALUES else 1
    if workers <= 1:
        return np.flatnonzero(np.any(flat, axis=0))
    bounds = np.linspace(0, flat.shape[0], workers + 1).astype(int)
    with ThreadPoolExecutor(max_workers=workers) as pool:
        parts = list(pool.map(lambda k: np.any(flat[bounds[k]:bounds[k + 1]], axis=0), range(workers)))
    return np.flatnonzero(np.logical_or.reduce(parts))


def parallel_decimation(block: Callable[[int, int], np.ndarray], n_samples: int, rate: float, factor: int,
                        *, order: int = 4, chunk: int = 20_000,
                        cutoff: float | None = None) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """Low-pass filter and down-sample a signal that is computed chunk by chunk.

    Used for the observation matrix and the torques together (Gautier's parallel decimation): both
    go through the same zero-phase low-pass filter, then every ``factor``-th sample is kept. Memory stays
    bounded by ``chunk`` samples whatever the log's length: the forward pass goes on from one chunk to the
    next (its state carried, exact), and the backward pass starts a margin after each chunk's end, so the
    result matches filtering the whole signal at once to the decay of the filter's transient over that
    margin. The log's ends are padded by mirror extension (:func:`edge_padding`).

    Parameters
    ----------
    block : callable ``(start, stop) -> (stop - start, ...) array``, or a tuple of such arrays
        Computes samples ``start .. stop-1`` of the signal (a tuple: several signals filtered alike, without
        first copying them into one array).
    n_samples : int
    rate : float [Hz]
    factor : int
        Decimation factor.
    order : int
        Order of the zero-phase Butterworth low-pass.
    cutoff : float or None [Hz]
        Its cutoff; default :func:`decimation_cutoff` (``factor`` 1 and no cutoff: no filtering, just
        chunks). A cutoff above the decimation's own would alias.
    chunk : int
        Samples computed per step (before the margins).

    Yields
    ------
    index : (M,) int array
        Indices of the kept samples in the original signal.
    values : (M, ...) array, or a tuple of them
        Filtered signal at those samples.
    """
    if factor < 1:
        raise ConfigError(f"decimation factor: expected an integer >= 1, got {factor}")
    chunk = max(chunk - chunk % factor, factor)
    if factor == 1 and cutoff is None:
        for start in range(0, n_samples, chunk):
            stop = min(start + chunk, n_samples)
            yield np.arange(start, stop), block(start, stop)
        return
    cutoff = decimation_cutoff(rate, factor) if cutoff is None else cutoff
    if cutoff > decimation_cutoff(rate, factor) * (1 + 1e-9):
        raise ConfigError(f"parallel filter: a cutoff of {cutoff:g} Hz aliases when decimating by {factor} "
                          f"(at most {decimation_cutoff(rate, factor):g} Hz)")
    _check_cutoff(rate, cutoff, "parallel filter")
    signal = _signal()
    sos = signal.butter(order, cutoff, btype="low", fs=rate, output="sos")
    zi = signal.sosfilt_zi(sos)
    margin = int(np.ceil(10 * order * 0.4 * rate / cutoff))  # the filter's transient, as 10·factor·order at the decimation's cutoff
    states = None  # each signal's forward state at the chunk's start: none at the log's start (padded there)
    for start in range(0, n_samples, chunk):
        stop = min(start + chunk, n_samples)
        hi = min(n_samples, stop + margin)
        values = block(start, hi)
        index = np.arange(start, stop)
        index = index[index % factor == 0]
        padlen = min(edge_padding(rate, cutoff, order), hi - start - 1)
        split = stop - start if stop < n_samples else None

        def filtered(flat, live, fast, state):
            out = np.zeros((index.size, flat.shape[1]))
            after = None if split is None else np.zeros((sos.shape[0], 2, flat.shape[1]))
            width = COMPILED_COLUMN_BLOCK if fast else max(COLUMN_BLOCK, BLOCK_VALUES // flat.shape[0])

            def one(cols):  # a column block: the filter's copies stay small; blocks write disjoint columns of out
                carry = (None if state is None else state[:, :, cols], split,
                         None if after is None else np.empty((sos.shape[0], 2, cols.size)))
                out[:, cols] = (zero_phase(sos, flat, padlen, zi, cols, index - start, carry=carry) if fast else
                                even_filtfilt(signal, sos, flat[:, cols], padlen, zi, carry=carry)[index - start])
                if after is not None:
                    after[:, :, cols] = carry[2]

            _on_cores(one, [live[c:c + width] for c in range(0, live.size, width)],
                      flat.shape[0] * live.size >= PARALLEL_VALUES)
            return out, after

        signals = values if isinstance(values, tuple) else (values,)
        flats = [v.reshape(v.shape[0], -1) for v in signals]
        states = states or [None] * len(flats)
        # Columns that are zero throughout the block and whose forward state is zero stay zero (the filter of zeros is
        # exactly zero): a regressor has many (joint i does not see the links before it), so only the others are
        # filtered.
        lives = [_live_columns(flat) if state is None else
                 np.union1d(_live_columns(flat), np.flatnonzero(np.any(state, axis=(0, 1))))
                 for flat, state in zip(flats, states)]
        # a long log's signals through the compiled filter (the same numbers as SciPy's, bit for bit), all of them
        # alike: the torques beside a regressor cost SciPy more set-up per call than filtering
        fast = n_samples * sum(live.size for live in lives) >= COMPILED_FILTER_VALUES
        done = [filtered(flat, live, fast, state) for flat, live, state in zip(flats, lives, states)]
        states = [after for _, after in done]
        out = tuple(y.reshape((index.size,) + v.shape[1:]) for v, (y, _) in zip(signals, done))
        yield index, (out if isinstance(values, tuple) else out[0])
        del values, signals, flats, done

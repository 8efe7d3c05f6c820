"""The zero-phase filters of long logs, compiled (numba): the parallel decimation's Butterworth filter and the
direction of motion's Gaussian smoothing.

:func:`dynid.preprocessing.filters.parallel_decimation` filters every live column of the base regressor at the log's
rate; on an hour at 1 kHz that is about 10⁹ values, which SciPy's ``sosfiltfilt`` takes one column block at a time with
several copies of each. :func:`zero_phase` computes what ``scipy.signal.sosfiltfilt(sos, x, axis=0, padtype="even",
padlen=padlen)`` computes, with the same operations in the same order (each section's transposed direct form II as
SciPy's ``_sosfilt`` runs it, its initial state ``sosfilt_zi(sos)`` times the first value, no fast-math): the same
numbers to the last bit (tests/preprocessing/test_filter_kernel.py). It runs along the columns of one row at a time,
which the compiler vectorises.

:func:`gaussian_nearest` computes what ``scipy.ndimage.gaussian_filter1d(x, sigma, mode="nearest")`` computes, for
SciPy's own weights: each output sums the same products in the same order as SciPy's correlation of a symmetric kernel
(the centre's product, then the pairs of samples ``k`` either side from the outermost in), so the numbers are SciPy's
to the last bit; the outputs go a block at a time, which the compiler vectorises, and the column's halves on two
threads.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np

__all__ = ["compiled", "gaussian_nearest", "gaussian_weights", "zero_phase"]


def _sections(sos, x, z0, z1, reverse):  # pragma: no cover - compiled
    """One pass of the second-order sections ``sos`` (n_sections, 6) over the rows of ``x`` (n, c), forward or
    backward, in place; ``z0``, ``z1`` (n_sections, c) the sections' states, updated."""
    n, c = x.shape
    for k in range(n):
        row = x[n - 1 - k] if reverse else x[k]
        for s in range(sos.shape[0]):
            b0, b1, b2, a1, a2 = sos[s, 0], sos[s, 1], sos[s, 2], sos[s, 4], sos[s, 5]
            w0 = z0[s]
            w1 = z1[s]
            for j in range(c):
                xc = row[j]
                xn = b0 * xc + w0[j]
                w0[j] = b1 * xc - a1 * xn + w1[j]
                w1[j] = b2 * xc - a2 * xn
                row[j] = xn


def _extended(x, cols, left, right, ext):  # pragma: no cover - compiled
    """``ext`` (left + n + right, len(cols)) filled with the columns ``cols`` of ``x`` (n, ·) and their even extension
    at the start by ``left`` rows and at the end by ``right`` (SciPy's ``even_ext``: ``x[left:0:-1]``, ``x``,
    ``x[-2:-(right + 2):-1]``), in one pass."""
    n = x.shape[0]
    for i in range(left + n + right):
        src = left - i if i < left else i - left if i < left + n else 2 * n + left - 2 - i
        row = x[src]
        out = ext[i]
        for j in range(cols.shape[0]):
            out[j] = row[cols[j]]


GAUSSIAN_BLOCK = 1024
"""Outputs :func:`gaussian_nearest` sums at once (8 kB of partial sums, beside the 2·radius + 1024 samples they read)."""


def _symmetric(x, w, out, start, stop):  # pragma: no cover - compiled
    """``out[i]`` for ``start <= i < stop``: the correlation of ``x`` (padded by the radius ``r`` at both ends) with
    the symmetric weights ``w`` (2r + 1), in SciPy's order: ``x[i]·w[r]``, then ``+ (x[i-k] + x[i+k])·w[r-k]`` for
    ``k = r … 1``."""
    r = (w.shape[0] - 1) // 2
    acc = np.empty(GAUSSIAN_BLOCK)
    for a in range(start, stop, GAUSSIAN_BLOCK):
        m = min(GAUSSIAN_BLOCK, stop - a)
        centre = x[a + r:a + r + m]
        for i in range(m):
            acc[i] = centre[i] * w[r]
        for k in range(r, 0, -1):
            wk = w[r - k]
            left = x[a + r - k:a + r - k + m]
            right = x[a + r + k:a + r + k + m]
            for i in range(m):
                acc[i] += (left[i] + right[i]) * wk
        for i in range(m):
            out[a + i] = acc[i]


sections = extended = symmetric = None
_kernels = None  # the three, set at once: two threads may ask for them together


def compiled():
    """The section pass, the extension and the symmetric correlation, compiled on first use into numba's on-disk cache
    (:mod:`dynid.warm_up` compiles them at installation).

    Returns
    -------
    tuple
        ``(sections, extended, symmetric)``: ``sections(sos, x, z0, z1, reverse)``, ``extended(x, cols, left, right,
        ext)``, ``symmetric(x, w, out, start, stop)``.
    """
    global sections, extended, symmetric, _kernels
    if _kernels is None:
        import numba

        jit = numba.njit(cache=True, nogil=True)
        three = (jit(_sections), jit(_extended), jit(_symmetric))
        sections, extended, symmetric = three
        _kernels = three
    return _kernels


def gaussian_weights(sigma: float) -> np.ndarray:
    """The weights of ``scipy.ndimage.gaussian_filter1d`` at standard deviation ``sigma`` [samples]: its response to a
    unit impulse, over its support (SciPy's own numbers, whatever radius and normalisation it uses).

    Parameters
    ----------
    sigma : float
        Standard deviation [samples], > 0.

    Returns
    -------
    (2r + 1,) ndarray
        Symmetric weights summing to 1.
    """
    from scipy.ndimage import gaussian_filter1d

    reach = int(5 * sigma) + 10  # beyond SciPy's radius of 4 σ
    impulse = np.zeros(2 * reach + 1)
    impulse[reach] = 1.0
    response = gaussian_filter1d(impulse, sigma, mode="constant")
    r = reach - int(np.flatnonzero(response)[0])
    return response[reach - r:reach + r + 1].copy()


def gaussian_nearest(x: np.ndarray, weights: np.ndarray, workers: int = 1) -> np.ndarray:
    """``scipy.ndimage.gaussian_filter1d(x, sigma, mode="nearest")`` for ``weights = gaussian_weights(sigma)``, bit for
    bit.

    Parameters
    ----------
    x : (N,) array
        One signal.
    weights : (2r + 1,) array
        Symmetric weights (:func:`gaussian_weights`).
    workers : int
        Threads, each computing a contiguous part of the outputs (the numbers do not depend on it).

    Returns
    -------
    (N,) ndarray
    """
    correlate = compiled()[2]
    x = np.asarray(x, dtype=float).reshape(-1)
    r = (weights.shape[0] - 1) // 2
    padded = np.concatenate([np.full(r, x[0]), x, np.full(r, x[-1])]) if x.size else x
    out = np.empty(x.size)
    w = np.ascontiguousarray(weights, dtype=float)
    bounds = np.linspace(0, x.size, max(1, min(workers, x.size // GAUSSIAN_BLOCK)) + 1).astype(int)
    if bounds.size <= 2:
        correlate(padded, w, out, 0, x.size)
        return out
    with ThreadPoolExecutor(max_workers=bounds.size - 1) as pool:
        list(pool.map(lambda ab: correlate(padded, w, out, ab[0], ab[1]), zip(bounds[:-1], bounds[1:])))
    return out


def zero_phase(sos: np.ndarray, x: np.ndarray, padlen: int, zi: np.ndarray, cols: np.ndarray | None = None,
               rows: np.ndarray | None = None, *, carry: tuple | None = None) -> np.ndarray:
    """``scipy.signal.sosfiltfilt(sos, x[:, cols], axis=0, padtype="even", padlen=padlen)[rows]``, bit for bit; with
    ``carry``, a block of a longer signal whose forward pass goes on from the block before (as
    :func:`dynid.preprocessing.filters.even_filtfilt`, the same numbers).

    Parameters
    ----------
    sos : (n_sections, 6) array
        Second-order sections with ``a0 = 1`` (``scipy.signal.butter(..., output="sos")``).
    x : (n, m) array
        Signals along axis 0, C-ordered; ``n > padlen``.
    padlen : int
        Samples of even extension at each end (0: none).
    zi : (n_sections, 2) array
        ``scipy.signal.sosfilt_zi(sos)``.
    cols : (c,) int array, optional
        The columns of ``x`` to filter (default all), read in place (no gathered copy).
    rows : (r,) int array, optional
        The rows of the result to return (default all).
    carry : tuple ``(state, split, state_out)``, optional
        ``state`` (n_sections, 2, c): the forward pass's state at ``x``'s first row, which is then not padded (None:
        padded and started as SciPy does); ``split``: a row of ``x`` whose forward state ``state_out`` (n_sections, 2,
        c) receives (None: none).

    Returns
    -------
    (r, c) ndarray
        The filtered signals.
    """
    run, extend = compiled()[:2]
    state, split, state_out = (None, None, None) if carry is None else carry
    x = np.ascontiguousarray(x, dtype=float)
    cols = np.arange(x.shape[1]) if cols is None else np.asarray(cols, dtype=np.int64)
    left = padlen if state is None else 0
    ext = np.empty((x.shape[0] + left + padlen, cols.size))
    extend(x, cols, left, padlen, ext)
    sos = np.ascontiguousarray(sos, dtype=float)
    for reverse in (False, True):
        edge = ext[-1] if reverse else ext[0]  # the backward pass starts from the forward pass's last value
        if reverse or state is None:
            z0 = np.ascontiguousarray(zi[:, 0, None] * edge[None, :])
            z1 = np.ascontiguousarray(zi[:, 1, None] * edge[None, :])
        else:
            z0, z1 = np.ascontiguousarray(state[:, 0]), np.ascontiguousarray(state[:, 1])
        if reverse or split is None:
            run(sos, ext, z0, z1, reverse)
        else:  # forward to the split, its state kept, then on
            run(sos, ext[:left + split], z0, z1, False)
            state_out[:, 0], state_out[:, 1] = z0, z1
            run(sos, ext[left + split:], z0, z1, False)
    return ext[left:ext.shape[0] - padlen] if rows is None else ext[left + np.asarray(rows)]

"""The zero-phase Butterworth filter of the parallel decimation, compiled (numba) for long logs.

:func:`dynid.preprocessing.filters.parallel_decimation` filters every live column of the base regressor at the log's
rate; on an hour at 1 kHz that is about 10⁹ values, which SciPy's ``sosfiltfilt`` takes one column block at a time with
several copies of each. :func:`zero_phase` computes what ``scipy.signal.sosfiltfilt(sos, x, axis=0, padtype="even",
padlen=padlen)`` computes, with the same operations in the same order (each section's transposed direct form II as
SciPy's ``_sosfilt`` runs it, its initial state ``sosfilt_zi(sos)`` times the first value, no fast-math): the same
numbers to the last bit (tests/preprocessing/test_filter_kernel.py). It runs along the columns of one row at a time,
which the compiler vectorises.
"""

from __future__ import annotations

import numpy as np

__all__ = ["compiled", "zero_phase"]


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


def _extended(x, cols, padlen, ext):  # pragma: no cover - compiled
    """``ext`` (n + 2·padlen, len(cols)) filled with the columns ``cols`` of ``x`` (n, ·) and their even extension at
    both ends (SciPy's ``even_ext``: ``x[padlen:0:-1]``, ``x``, ``x[-2:-(padlen + 2):-1]``), in one pass."""
    n = x.shape[0]
    for i in range(n + 2 * padlen):
        src = padlen - i if i < padlen else i - padlen if i < padlen + n else 2 * n + padlen - 2 - i
        row = x[src]
        out = ext[i]
        for j in range(cols.shape[0]):
            out[j] = row[cols[j]]


sections = extended = None
_kernels = None  # the pair, set at once: two threads may ask for it together


def compiled():
    """The section pass and the extension, compiled on first use into numba's on-disk cache (:mod:`dynid.warm_up`
    compiles them at installation).

    Returns
    -------
    tuple
        ``(sections, extended)``: ``sections(sos, x, z0, z1, reverse)``, ``extended(x, cols, padlen, ext)``.
    """
    global sections, extended, _kernels
    if _kernels is None:
        import numba

        jit = numba.njit(cache=True, nogil=True)
        pair = (jit(_sections), jit(_extended))
        sections, extended = pair
        _kernels = pair
    return _kernels


def zero_phase(sos: np.ndarray, x: np.ndarray, padlen: int, zi: np.ndarray, cols: np.ndarray | None = None,
               rows: np.ndarray | None = None) -> np.ndarray:
    """``scipy.signal.sosfiltfilt(sos, x[:, cols], axis=0, padtype="even", padlen=padlen)[rows]``, bit for bit.

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

    Returns
    -------
    (r, c) ndarray
        The filtered signals.
    """
    run, extend = compiled()
    x = np.ascontiguousarray(x, dtype=float)
    cols = np.arange(x.shape[1]) if cols is None else np.asarray(cols, dtype=np.int64)
    ext = np.empty((x.shape[0] + 2 * padlen, cols.size))
    extend(x, cols, padlen, ext)
    sos = np.ascontiguousarray(sos, dtype=float)
    for reverse in (False, True):
        edge = ext[-1] if reverse else ext[0]  # the backward pass starts from the forward pass's last value
        z0 = np.ascontiguousarray(zi[:, 0, None] * edge[None, :])
        z1 = np.ascontiguousarray(zi[:, 1, None] * edge[None, :])
        run(sos, ext, z0, z1, reverse)
    return ext[padlen:ext.shape[0] - padlen] if rows is None else ext[padlen + np.asarray(rows)]

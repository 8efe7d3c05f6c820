"""Choices among equal scores made the same on every CPU: NumPy's OpenBLAS picks its kernels by the CPU, which moves a
score's last digits, so an ``argmin`` among scores that are equal but for those digits would choose by the CPU
(benchmarks/NOTEBOOK.md, stop 119)."""

from __future__ import annotations

import numpy as np

EQUAL = 1e-9
"""Two scores within this share of the least (relative) are equal: far above the 1e-15 to 1e-8 that another CPU's
kernels move them, far below any difference a choice is made on."""


def first_least(values, axis: int = 0):
    """The index of the first value within :data:`EQUAL` of the least along ``axis`` (NaN never the least).

    Parameters
    ----------
    values : array_like
    axis : int

    Returns
    -------
    int or ndarray of int
        ``np.argmin``'s result where no two values are equal to that share; the first of equals otherwise.
    """
    v = np.asarray(values, dtype=float)
    least = np.fmin.reduce(v, axis=axis, keepdims=True)
    found = np.argmax(v <= least + EQUAL * np.abs(least), axis=axis)
    return int(found) if np.ndim(found) == 0 else found

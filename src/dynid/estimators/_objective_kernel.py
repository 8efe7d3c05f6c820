"""Compiled inner loop of eq. 9 under a one-coordinate move (see :class:`dynid.estimators.base.LinearAbsoluteObjective`)."""

from __future__ import annotations

import numba as nb


@nb.njit(cache=True, fastmath=False, nogil=True)
def shifted_absolute_sum(r, column, delta, row_weights, out):
    """``out = r - delta·column`` and ``Σ row_weights·|out|`` in one pass."""
    s = 0.0
    for i in range(r.shape[0]):
        v = r[i] - column[i] * delta
        out[i] = v
        s += row_weights[i] * abs(v)
    return s

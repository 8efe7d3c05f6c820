"""Compiled inner loop of eq. 9 under a one-coordinate move (see :class:`dynid.estimators.base.LinearAbsoluteObjective`)."""

from __future__ import annotations

import numba as nb


@nb.njit(cache=True, fastmath=False, nogil=True)
def shifted_absolute_total(r, column, delta, row_weights):
    """``Σ row_weights·|r - delta·column|`` in one pass, without writing the shifted residual (:func:`shifted` writes
    it, with the same operations, when it is needed)."""
    s = 0.0
    for i in range(r.shape[0]):
        v = r[i] - column[i] * delta
        s += row_weights[i] * abs(v)
    return s


@nb.njit(cache=True, fastmath=False, nogil=True)
def shifted(r, column, delta, out):
    """``out = r - delta·column``."""
    for i in range(r.shape[0]):
        out[i] = r[i] - column[i] * delta


@nb.njit(cache=True, fastmath=False, nogil=True)
def add_absolute_residual_sums(tau, predicted, row_weights, out):
    """``out[k] += Σ_i row_weights[i]·|tau[i] - predicted[i, k]|`` for a block of rows ``i`` and a population
    ``k``, in one pass over the block (rows in order, so the sums do not depend on how the rows are blocked)."""
    for i in range(predicted.shape[0]):
        t = tau[i]
        wi = row_weights[i]
        for k in range(predicted.shape[1]):
            out[k] += wi * abs(t - predicted[i, k])

"""Recursive least squares with exponential forgetting, one small problem per joint side by side: the friction and
drive terms of every joint re-identified sample by sample while the rigid-body part stays that of the last full
identification (Ljung, *System Identification*, 2nd ed., §11.2: RLS with forgetting factor λ).

For joint ``j``, with regressor row ``φ`` (its friction columns: Coulomb, viscous, offset, …) and measurement ``y``
(its torque minus the rigid-body prediction)::

    k = P φ / (λ + φᵀ P φ)
    θ ← θ + k (y - φᵀ θ)
    P ← (P - k φᵀ P) / λ

The memory of the estimate is about ``1 / (1 - λ)`` samples. The updates of a block of samples run in a compiled
loop (numba), the joints side by side.
"""

from __future__ import annotations

import numpy as np

from ..exceptions import ShapeError

__all__ = ["RecursiveLeastSquares"]


def _update_block(theta, p, phi, y, keep, lam):  # pragma: no cover - compiled
    m, n, q = phi.shape
    pphi = np.empty(q)
    for i in range(m):
        for j in range(n):
            if not keep[i, j]:
                continue
            denom = lam
            for a in range(q):
                s = 0.0
                for b in range(q):
                    s += p[j, a, b] * phi[i, j, b]
                pphi[a] = s
                denom += phi[i, j, a] * s
            err = y[i, j]
            for a in range(q):
                err -= phi[i, j, a] * theta[j, a]
            for a in range(q):
                theta[j, a] += pphi[a] / denom * err
            for a in range(q):
                for b in range(q):
                    p[j, a, b] = (p[j, a, b] - pphi[a] * pphi[b] / denom) / lam


_kernel = None


def _compiled():
    global _kernel
    if _kernel is None:
        import numba

        _kernel = numba.njit(cache=True, nogil=True)(_update_block)
    return _kernel


class RecursiveLeastSquares:
    """RLS with forgetting for ``n`` independent problems of ``q`` parameters each (module docstring).

    Parameters
    ----------
    theta : (n, q) array
        Starting estimates (e.g. the last full identification's friction terms).
    covariance : (n, q, q) array or float
        Starting ``P`` (a float: that times the identity): how far the estimates may move at first.
    forgetting : float
        λ in (0, 1].

    Raises
    ------
    ShapeError
        Inconsistent shapes, or λ outside (0, 1].
    """

    def __init__(self, theta, covariance=1e3, forgetting: float = 0.999):
        self.theta = np.array(theta, dtype=float, copy=True)
        if self.theta.ndim != 2:
            raise ShapeError(f"theta: expected (n, q), got shape {self.theta.shape}")
        n, q = self.theta.shape
        p = np.asarray(covariance, dtype=float)
        self.p = np.broadcast_to(np.eye(q) * p, (n, q, q)).copy() if p.ndim == 0 else p.copy()
        if self.p.shape != (n, q, q):
            raise ShapeError(f"covariance: expected a number or shape {(n, q, q)}, got {self.p.shape}")
        if not 0 < forgetting <= 1:
            raise ShapeError(f"forgetting: expected a factor in (0, 1], got {forgetting}")
        self.forgetting = float(forgetting)

    def update(self, phi, y, keep=None) -> np.ndarray:
        """Take in a block of samples, one after the other.

        Parameters
        ----------
        phi : (m, n, q) array
            Regressor rows, time-first.
        y : (m, n) array
            Measurements.
        keep : (m, n) bool array, optional
            Samples to use (default all).

        Returns
        -------
        (n, q) ndarray
            The estimates after the block (also :attr:`theta`).

        Raises
        ------
        ShapeError
            Shapes that do not match the problems.
        """
        phi = np.ascontiguousarray(phi, dtype=float)
        y = np.ascontiguousarray(y, dtype=float)
        n, q = self.theta.shape
        if phi.ndim != 3 or phi.shape[1:] != (n, q) or y.shape != phi.shape[:2]:
            raise ShapeError(f"expected phi (m, {n}, {q}) and y (m, {n}), got {phi.shape} and {y.shape}")
        keep = np.ones(y.shape, dtype=bool) if keep is None else np.ascontiguousarray(keep, dtype=bool)
        _compiled()(self.theta, self.p, phi, y, keep, self.forgetting)
        return self.theta.copy()

"""Ordinary least squares with parameter standard deviations (Gautier & Khalil)."""

from __future__ import annotations

import numpy as np

from ..exceptions import IdentifiabilityError
from .base import Estimator, check_observations


class OrdinaryLeastSquares(Estimator):
    """OLS: ``params_ = argmin ||tau - W p||²``.

    Learned attributes
    ------------------
    params_ : (p,) array
    covariance_ : (p, p) array
        ``sigma² (WᵀW)⁻¹`` with ``sigma² = ||r||² / (M - p)``.
    params_std_ : (p,) array
    relative_std_ : (p,) array
        ``100 · std / |param|`` [%].
    condition_number_ : float
        cond(W).

    Raises
    ------
    IdentifiabilityError
        If ``W`` is rank-deficient (the data do not excite every parameter).
    """

    def __init__(self, *, rcond: float | None = None):
        self.rcond = rcond

    def fit(self, w, tau) -> "OrdinaryLeastSquares":
        w, tau = check_observations(w, tau)
        m, p = w.shape
        if m <= p:
            raise IdentifiabilityError(f"OLS needs more equations than parameters, got {m} rows for {p} parameters")
        q, r = np.linalg.qr(w)
        sv = np.linalg.svd(r, compute_uv=False)
        rcond = self.rcond if self.rcond is not None else max(m, p) * np.finfo(float).eps
        if sv[-1] <= rcond * sv[0]:
            raise IdentifiabilityError(f"observation matrix is rank-deficient (cond = {sv[0] / max(sv[-1], 1e-300):.3g}): use base parameters or a richer excitation")
        self.params_ = np.linalg.solve(r, q.T @ tau)
        res = tau - w @ self.params_
        sigma2 = float(res @ res) / (m - p)
        rinv = np.linalg.inv(r)
        self.covariance_ = sigma2 * (rinv @ rinv.T)
        self.params_std_ = np.sqrt(np.diag(self.covariance_))
        with np.errstate(divide="ignore", invalid="ignore"):
            self.relative_std_ = 100.0 * self.params_std_ / np.abs(self.params_)
        self.condition_number_ = float(sv[0] / sv[-1])
        self.residual_std_ = float(np.sqrt(sigma2))
        return self

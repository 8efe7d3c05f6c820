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


class WeightedLeastSquares(Estimator):
    """WLS with one weight per joint: each joint's rows are divided by that joint's residual standard
    deviation from a first OLS fit (Gautier & Poignet 2001, the paper's ref. [6]).

    Parameters
    ----------
    n_dof : int
        Joints per sample in ``W``'s rows (row ``k·n_dof + j`` is joint ``j``).

    Learned attributes
    ------------------
    params_, covariance_, params_std_, relative_std_, condition_number_ (of the weighted W),
    joint_std_ : (n_dof,) residual standard deviation of each joint [N·m].
    """

    def __init__(self, *, n_dof: int, rcond: float | None = None):
        self.n_dof = n_dof
        self.rcond = rcond

    def fit(self, w, tau) -> "WeightedLeastSquares":
        w, tau = check_observations(w, tau, self.n_dof)
        m, p = w.shape
        ols = OrdinaryLeastSquares(rcond=self.rcond).fit(w, tau)
        res = (tau - w @ ols.params_).reshape(-1, self.n_dof)
        n_s = res.shape[0]
        dof_per_joint = max(n_s - p / self.n_dof, 1.0)
        std = np.sqrt((res**2).sum(axis=0) / dof_per_joint)
        std = np.where(std > 0, std, 1.0)
        scale = np.tile(1.0 / std, n_s)
        weighted = OrdinaryLeastSquares(rcond=self.rcond).fit(w * scale[:, None], tau * scale)
        self.params_ = weighted.params_
        self.covariance_ = weighted.covariance_
        self.params_std_ = weighted.params_std_
        self.relative_std_ = weighted.relative_std_
        self.condition_number_ = weighted.condition_number_
        self.joint_std_ = std
        return self

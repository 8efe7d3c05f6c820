"""Ordinary least squares with parameter standard deviations (Gautier & Khalil)."""

from __future__ import annotations

import numpy as np

from .accumulate import LeastSquaresAccumulator
from .base import Estimator, check_observations, infer_n_dof


class OrdinaryLeastSquares(Estimator):
    """OLS: ``params_ = argmin ||tau - W p||²``.

    Learned attributes
    ------------------
    params_ : (p,) array
    covariance_ : (p, p) array
        ``sigma² (WᵀW)⁻¹`` with ``sigma² = ||r||² / (M - p)``.
    residual_std_ : float
        ``sigma``.
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
        acc = LeastSquaresAccumulator(w.shape[1])
        acc.add(w, tau)
        _set_solution(self, acc.solve(rcond=self.rcond))
        return self


def _set_solution(est, sol) -> None:
    est.params_ = sol.params
    est.covariance_ = sol.covariance
    est.params_std_ = sol.params_std
    est.relative_std_ = sol.relative_std
    est.condition_number_ = sol.condition_number
    est.residual_std_ = sol.residual_std


class WeightedLeastSquares(Estimator):
    """WLS with one weight per joint: each joint's rows are divided by that joint's residual standard
    deviation from a first OLS fit (Gautier & Poignet 2001, the paper's ref. [6]).

    Parameters
    ----------
    n_dof : int or None
        Joints per sample in ``W``'s rows (row ``k·n_dof + j`` is joint ``j``); None: inferred from tau
        given as (N, n_dof).

    Learned attributes
    ------------------
    params_, covariance_, params_std_, relative_std_, condition_number_ (of the weighted W),
    joint_std_ : (n_dof,) residual standard deviation of each joint [N·m].
    """

    def __init__(self, *, n_dof: int | None = None, rcond: float | None = None):
        self.n_dof = n_dof
        self.rcond = rcond

    def fit(self, w, tau) -> "WeightedLeastSquares":
        self.n_dof_ = infer_n_dof(self.n_dof, tau)
        w, tau = check_observations(w, tau, self.n_dof_)
        acc = LeastSquaresAccumulator(w.shape[1], self.n_dof_)
        acc.add(w, tau)
        ols = acc.solve(rcond=self.rcond)
        std = acc.joint_residual_std(ols.params)
        std = np.where(std > 0, std, 1.0)
        _set_solution(self, acc.solve(1.0 / std, rcond=self.rcond))
        self.joint_std_ = std
        return self

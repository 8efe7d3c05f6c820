"""Least absolute deviations: the exact minimiser of the paper's objective (eq. 9) as a linear program."""

from __future__ import annotations

import numpy as np
from scipy.optimize import linprog

from ..exceptions import DynIdError, ShapeError
from .base import Estimator, check_observations, infer_n_dof, paper_objective


class LeastAbsoluteDeviations(Estimator):
    """LAD: ``params_ = argmin sum_k delta_j(k) |tau_k - W_k p|``, i.e. eq. 9 without a search box.

    The primal LP ``min delta·(u + v)`` s.t. ``W p + u - v = tau``, ``u, v >= 0`` has as many
    constraints as rows of ``W``; dynid solves its dual, which has one equality constraint per
    parameter, with SciPy's HiGHS interior point, and reads the parameters from the dual's
    multipliers (Barrodale & Roberts, SIAM J. Numer. Anal. 10(5), 1973). Optional ``bounds`` (p, 2)
    restrict the parameters like the ABC's search box, so both minimise the same problem.

    Parameters
    ----------
    n_dof : int or None
        Joints per sample; None: inferred from tau given as (N, n_dof).
        Joints per sample in ``W``'s rows.
    weights : (n_dof,) array, optional
        ``delta`` of eq. 9 (default 1).
    bounds : (p, 2) array, optional

    Learned attributes
    ------------------
    params_, objective_ (eq. 9), result_ (SciPy's OptimizeResult).

    Raises
    ------
    DynIdError
        If HiGHS reports the problem infeasible or fails.
    """

    def __init__(self, *, n_dof: int | None = None, weights=None, bounds=None):
        self.n_dof = n_dof
        self.weights = weights
        self.bounds = bounds

    def fit(self, w, tau) -> "LeastAbsoluteDeviations":
        self.n_dof_ = infer_n_dof(self.n_dof, tau)
        w, tau = check_observations(w, tau, self.n_dof_)
        m, p = w.shape
        delta = np.ones(self.n_dof_) if self.weights is None else np.asarray(self.weights, dtype=float)
        row_w = np.tile(delta, m // self.n_dof_) / (m // self.n_dof_)
        if self.bounds is None:
            lo, hi = np.full(p, -np.inf), np.full(p, np.inf)
        else:
            b = np.asarray(self.bounds, dtype=float)
            if b.shape != (p, 2):
                raise ShapeError(f"expected LAD bounds of shape ({p}, 2), got {b.shape}")
            lo, hi = b[:, 0], b[:, 1]
        # Dual LP (p equality constraints instead of M): max tau·y - hi·g+ + lo·g-
        # s.t. W^T y - g+ + g- = 0, |y_i| <= row_w_i, g+- >= 0 (fixed at 0 where the bound is infinite).
        # The parameters are minus the multipliers of the equality constraints.
        c = np.concatenate([-tau, np.where(np.isfinite(hi), hi, 0.0), -np.where(np.isfinite(lo), lo, 0.0)])
        a_eq = np.hstack([w.T, -np.eye(p), np.eye(p)])
        var_bounds = np.concatenate([
            np.stack([-row_w, row_w], 1),
            np.stack([np.zeros(p), np.where(np.isfinite(hi), np.inf, 0.0)], 1),
            np.stack([np.zeros(p), np.where(np.isfinite(lo), np.inf, 0.0)], 1),
        ])
        res = linprog(c, A_eq=a_eq, b_eq=np.zeros(p), bounds=var_bounds, method="highs-ipm")
        if res.status != 0:
            raise DynIdError(f"LAD linear program failed: {res.message}")
        self.params_ = np.clip(-res.eqlin.marginals, lo, hi)
        self.objective_ = float(paper_objective(tau - w @ self.params_, self.n_dof_, delta))
        self.result_ = res
        return self

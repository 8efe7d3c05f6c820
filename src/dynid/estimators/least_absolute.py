"""Least absolute deviations: the exact minimiser of the paper's objective (eq. 9) as a linear program."""

from __future__ import annotations

import numpy as np
from scipy.optimize import linprog

from ..exceptions import DynIdError, ShapeError
from .base import Estimator, check_observations, infer_n_dof, paper_objective, weighted_rows


class LeastAbsoluteDeviations(Estimator):
    """LAD: ``params_ = argmin sum_k delta_j(k) |tau_k - W_k p|``, i.e. eq. 9 without a search box.

    The primal LP ``min delta·(u + v)`` s.t. ``W p + u - v = tau``, ``u, v >= 0`` has as many
    constraints as rows of ``W``; dynid solves its dual, which has one equality constraint per
    parameter, with SciPy's HiGHS interior point, and reads the parameters from the dual's
    multipliers (Barrodale & Roberts, SIAM J. Numer. Anal. 10(5), 1973). Optional ``bounds`` (p, 2)
    restrict the parameters like the ABC's search box, so both minimise the same problem.

    Long problems are solved exactly on a fraction of the rows (Portnoy & Koenker, Statistical Science
    12(4), 1997, "globbing"): a pilot fit (LAD on evenly spaced rows, or least squares in the box,
    whichever fits every row better) predicts which rows lie far above or below the optimum; their dual
    variables are fixed at ±delta (their sign), so only the rows near the fit remain in the LP. The
    solution is then checked on every fixed row: a sign that disagrees moves the rows back into the LP and
    it is solved again, so the result is the exact minimiser of the whole problem (the KKT conditions hold
    on every row).

    It has no hyper-parameters: the joints per sample, eq. 9's ``delta`` (default 1) and the box (default none) come
    to ``fit`` as ``problem=FitData(n_dof=..., weights=..., bounds=...)``.

    Attributes
    ----------
    params_, objective_ (eq. 9), result_ (SciPy's OptimizeResult).

    Raises
    ------
    DynIdError
        If HiGHS reports the problem infeasible or fails.
    """

    loss_power = 1.0  # eq. 9: sample_weight multiplies each absolute residual
    PROBLEM_FIELDS = ("n_dof", "weights", "bounds")

    def fit(self, w, tau, sample_weight=None, *, problem=None) -> LeastAbsoluteDeviations:
        """Minimise the weighted sum of absolute residuals (eq. 9) as a linear programme, within the box if given.

        Parameters
        ----------
        w : (M, p) array
            Observation matrix, row ``k·n_dof + j`` = sample ``k``, joint ``j``.
        tau : (M,) or (N, n_dof) array [N·m]
        sample_weight : (M,) or (N, n_dof) array, optional
            One weight ≥ 0 per row of the absolute residual (eq. 9) (:func:`dynid.estimators.base.weighted_rows`).
        problem : FitData, optional
            Its ``n_dof``, ``weights`` (eq. 9's ``delta``) and ``bounds`` (the box, (p, 2)).

        Returns
        -------
        self

        Raises
        ------
        ShapeError
            Wrong shapes, or bounds that are not (p, 2).
        """
        w, tau = weighted_rows(w, tau, sample_weight, self.loss_power)
        problem = self.take_problem(problem)
        self.n_dof_ = infer_n_dof(problem.n_dof, tau)
        w, tau = check_observations(w, tau, self.n_dof_)
        m, p = w.shape
        delta = np.ones(self.n_dof_) if problem.weights is None else np.asarray(problem.weights, dtype=float)
        row_w = np.tile(delta, m // self.n_dof_) / (m // self.n_dof_)
        if problem.bounds is None:
            lo, hi = np.full(p, -np.inf), np.full(p, np.inf)
        else:
            b = np.asarray(problem.bounds, dtype=float)
            if b.shape != (p, 2):
                raise ShapeError(f"expected LAD bounds of shape ({p}, 2), got {b.shape}")
            lo, hi = b[:, 0], b[:, 1]
        beta, res = _lad_by_globbing(w, tau, row_w, lo, hi)
        self.params_ = beta
        self.objective_ = float(paper_objective(tau - w @ self.params_, self.n_dof_, delta))
        self.result_ = res
        return self


PILOT_FRACTION = 25
"""The pilot fit uses every 25th row (at least 50 per parameter)."""
BAND = 3
"""Rows kept in the LP: 3× the pilot's, those of smallest residual at the pilot's fit."""


def _dual_lp(w, tau, row_w, lo, hi, *, rows, fixed, fixed_y):
    """The dual LP on ``rows`` with the dual variables of ``fixed`` rows set to ``fixed_y``: the parameters
    (minus the equality multipliers, clipped to the box) and SciPy's result.

    Dual of eq. 9 in the box: max tau·y - hi·g+ + lo·g- s.t. W^T y - g+ + g- = 0, |y_i| <= row_w_i, g± >= 0
    (g± fixed at 0 where the bound is infinite); fixed rows move to the right-hand side.
    """
    p = w.shape[1]
    c = np.concatenate([-tau[rows], np.where(np.isfinite(hi), hi, 0.0), -np.where(np.isfinite(lo), lo, 0.0)])
    a_eq = np.hstack([w[rows].T, -np.eye(p), np.eye(p)])
    b_eq = -(w[fixed].T @ fixed_y) if fixed.size else np.zeros(p)
    var_bounds = np.concatenate([
        np.stack([-row_w[rows], row_w[rows]], 1),
        np.stack([np.zeros(p), np.where(np.isfinite(hi), np.inf, 0.0)], 1),
        np.stack([np.zeros(p), np.where(np.isfinite(lo), np.inf, 0.0)], 1),
    ])
    res = linprog(c, A_eq=a_eq, b_eq=b_eq, bounds=var_bounds, method="highs-ipm")
    if res.status != 0:
        raise DynIdError(f"LAD linear program failed: {res.message}")
    return np.clip(-res.eqlin.marginals, lo, hi), res


def _pilot(w, tau, row_w, lo, hi, n_pilot):
    """The fit whose residuals choose the band: LAD on ``n_pilot`` evenly spaced rows, or least squares on
    every row clipped to the box, whichever has the smaller eq. 9 on every row. The subsample's LAD can be
    far off when the rows are poorly conditioned and no bound is active; least squares is then close to
    LAD (symmetric noise), but clipping it is no fit when bounds are active (a box that misses the truth)."""
    none = np.array([], dtype=int)
    lad, _ = _dual_lp(w, tau, row_w, lo, hi, rows=np.linspace(0, w.shape[0] - 1, n_pilot).astype(int), fixed=none, fixed_y=none)
    sw = np.sqrt(row_w)
    ls = np.clip(np.linalg.lstsq(w * sw[:, None], tau * sw, rcond=None)[0], lo, hi)
    return min((lad, ls), key=lambda b: float(row_w @ np.abs(tau - w @ b)))


def _lad_by_globbing(w, tau, row_w, lo, hi):
    """Exact LAD in the box, on a band of rows around a pilot fit (class docstring); small problems directly."""
    m, p = w.shape
    none = np.array([], dtype=int)
    n_pilot = max(50 * p, m // PILOT_FRACTION)
    keep = BAND * n_pilot
    if keep >= m // 2:
        return _dual_lp(w, tau, row_w, lo, hi, rows=np.arange(m), fixed=none, fixed_y=none)
    r = tau - w @ _pilot(w, tau, row_w, lo, hi, n_pilot)
    while keep < m // 2:
        band = np.zeros(m, dtype=bool)
        band[np.argpartition(np.abs(r), keep)[:keep]] = True
        fixed = np.flatnonzero(~band)
        fixed_y = np.where(r[fixed] > 0, row_w[fixed], -row_w[fixed])
        beta, res = _dual_lp(w, tau, row_w, lo, hi, rows=np.flatnonzero(band), fixed=fixed, fixed_y=fixed_y)
        r = tau - w @ beta
        if np.all(r[fixed] * fixed_y >= 0):  # complementary slackness on every fixed row: optimal
            return beta, res
        keep *= 2  # a fixed row crossed the fit: a wider band around the new fit
    return _dual_lp(w, tau, row_w, lo, hi, rows=np.arange(m), fixed=none, fixed_y=none)

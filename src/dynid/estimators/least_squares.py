"""Ordinary and weighted least squares with parameter standard deviations (Gautier & Khalil), on all rows at once
(``fit``) or chunk by chunk (``partial_fit``: memory independent of the log's length)."""

from __future__ import annotations

import numpy as np

from ..conventions import split_name
from ..exceptions import ShapeError
from .base import AccumulatingEstimator


def coulomb_offset_pairs(names) -> tuple[tuple[int, int], ...]:
    """``(fc_j, offset_j)`` index pairs of the parameters ``names`` (none without names).

    A joint that moves one way only has its Coulomb friction and torque offset in one term; where the log determines
    that term, the offset keeps the description's value and the term is taken as Coulomb friction (symmetric: the same
    friction in the direction the log never moved), :meth:`dynid.estimators.accumulate.LeastSquaresAccumulator.solve`.

    Parameters
    ----------
    names : sequence of str or None
        (p,) base parameters' names.

    Returns
    -------
    tuple of (int, int)
    """
    if names is None:
        return ()
    where = {split_name(n): i for i, n in enumerate(names) if n[-1:].isdigit()}
    return tuple((i, where[("offset", j)]) for (term, j), i in where.items() if term == "fc" and ("offset", j) in where)


class _LeastSquares(AccumulatingEstimator):
    """What OLS and WLS share: their hyper-parameter ``rcond``, and what they read of the problem (the joints per
    sample, the prior of the directions the rows leave open and the stated σ of some parameters)."""

    PROBLEM_FIELDS = ("n_dof", "base_prior", "base_prior_std")

    def __init__(self, *, rcond: float | None = None):
        self.rcond = rcond


class OrdinaryLeastSquares(_LeastSquares):
    """OLS: ``params_ = argmin ||tau - W p||²``.

    What it reads of the problem (``fit(..., problem=FitData(...))``, or ``partial_fit``'s):

    - ``n_dof``: joints per sample in ``W``'s rows (row ``k·n_dof + j`` is joint ``j``); None: inferred from tau given
      as (N, n_dof), else 1 (then :attr:`joint_std_` is the residual's standard deviation over all rows);
    - ``base_prior``, (p,): values kept along the directions the rows do not determine (the description's nominal
      base parameters); without it a rank-deficient ``W`` is refused. A full-rank ``W`` is solved as without it. With
      the parameters' names given (``partial_fit(..., names=)``), a joint's Coulomb friction takes the one term it
      shares with its offset where only that term is determined (:func:`coulomb_offset_pairs`);
    - ``base_prior_std``, (p,): each parameter's prior standard deviation, NaN where none (a drive's data sheet,
      ``Ia = { value = 0.3, sigma = 0.05 }``): such a parameter is pulled toward ``base_prior`` as a Gaussian prior,
      rows ``(s/σ_i)·(p_i - prior_i)`` beside the data's, ``s`` the fit's residual σ (the maximum a posteriori
      estimate; :meth:`dynid.estimators.accumulate.LeastSquaresAccumulator.solve`'s ``gaussian``).

    Parameters
    ----------
    rcond : float or None
        Singular values below ``rcond`` × the largest count as zero (rank deficiency); default
        ``max(M, p) · eps``.

    Attributes
    ----------
    params_ : (p,) array
    covariance_ : (p, p) array
        ``sigma² (WᵀW)⁻¹`` with ``sigma² = ||r||² / (M - p)``.
    residual_std_ : float
        ``sigma`` [N·m].
    params_std_ : (p,) array
    relative_std_ : (p,) array
        ``100 · std / |param|`` [%].
    condition_number_ : float
        cond(W).
    joint_std_ : (n_dof,) array
        Residual standard deviation of each joint [N·m].
    solution_ : dynid.estimators.accumulate.LeastSquaresSolution
        All of the above as one object (its ``from_prior``: the parameters left at ``base_prior``).

    Raises
    ------
    IdentifiabilityError
        If ``W`` is rank-deficient (the data do not excite every parameter) and no ``base_prior`` is given.

    Notes
    -----
    Ref.: M. Gautier, W. Khalil, "Exciting trajectories for the identification of base inertial parameters of
    robots", IJRR 11(4), 1992 (σ of the estimates).
    """

    def _solve(self, acc) -> None:
        names = self.__dict__.get("names_in_")
        sol = acc.solve(rcond=self.rcond, names=names, prior=self.problem_.base_prior, pairs=coulomb_offset_pairs(names),
                        gaussian=_gaussian(self))
        _set_solution(self, sol)
        self.ols_params_ = sol.params
        self.joint_std_ = acc.joint_residual_std(sol.params)


def _gaussian(est) -> tuple | None:
    """``(values, sigmas)`` of an estimator's Gaussian prior (its problem's ``base_prior`` with ``base_prior_std``), or
    None."""
    problem = est.problem_
    if problem.base_prior_std is None:
        return None
    sigmas = np.asarray(problem.base_prior_std, dtype=float)
    if not np.any(np.isfinite(sigmas)):
        return None
    if problem.base_prior is None:
        raise ShapeError("base_prior_std: a prior standard deviation needs base_prior, the values it is about")
    values = np.asarray(problem.base_prior, dtype=float)
    if sigmas.shape != values.shape:
        raise ShapeError(f"expected a base_prior_std of shape {values.shape}, got {sigmas.shape}")
    return values, sigmas


def _set_solution(est, sol) -> None:
    est.solution_ = sol
    est.params_ = sol.params
    est.covariance_ = sol.covariance
    est.params_std_ = sol.params_std
    est.relative_std_ = sol.relative_std
    est.condition_number_ = sol.condition_number
    est.residual_std_ = sol.residual_std


class WeightedLeastSquares(_LeastSquares):
    """WLS with one weight per joint: each joint's rows are divided by that joint's residual standard
    deviation from a first OLS fit.

    It reads the problem's ``n_dof`` (required unless tau is given as (N, n_dof)), ``base_prior`` and
    ``base_prior_std`` as :class:`OrdinaryLeastSquares` does (the Gaussian prior on the weighted problem: the rows of
    the stated parameters weigh ``1/σ_i²`` against the weighted residuals' unit variance).

    Parameters
    ----------
    rcond : float or None
        As :class:`OrdinaryLeastSquares`.

    Attributes
    ----------
    params_, covariance_, params_std_, relative_std_, residual_std_, condition_number_, solution_
        As :class:`OrdinaryLeastSquares`, of the weighted problem.
    ols_params_ : (p,) array
        The first (OLS) fit.
    joint_std_ : (n_dof,) array
        Residual standard deviation of each joint in the OLS fit [N·m]; the weights are their inverses
        (1 where a joint's is 0).

    Raises
    ------
    IdentifiabilityError
        If ``W`` is rank-deficient and no ``base_prior`` is given.

    Notes
    -----
    Ref.: M. Gautier, P. Poignet, "Extended Kalman filtering and weighted least squares dynamic identification of
    robot", Control Engineering Practice 9(12), 2001 (the paper's ref. [6]).
    """

    needs_joints = True

    def _solve(self, acc) -> None:
        names = self.__dict__.get("names_in_")
        pairs = coulomb_offset_pairs(names)
        prior = self.problem_.base_prior
        ols = acc.solve(rcond=self.rcond, names=names, prior=prior, pairs=pairs)
        std = acc.joint_residual_std(ols.params)
        _set_solution(self, acc.solve(1.0 / np.where(std > 0, std, 1.0), rcond=self.rcond, prior=prior,
                                      pairs=pairs, gaussian=_gaussian(self)))
        self.ols_params_ = ols.params
        self.joint_std_ = std

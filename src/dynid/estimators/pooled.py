"""Pooled identification of a fleet: units of one model share their rigid-body base parameters up to small
deviations, while friction, offsets (and whatever the data say varies, like a tool) are their own.

Each unit ``u`` brings its own estimate ``b_u`` with covariance ``C_u`` (weighted least squares on its log: the
information of its log, ``C_u⁻¹``, is what pooling weighs). The hierarchical model (a normal random-effects model,
e.g. Gelman et al., *Bayesian Data Analysis*, ch. 5)::

    b_u ~ N(β_u, C_u)
    β_u,k = μ_k + δ_u,k,   δ_u,k ~ N(0, τ_k²)   for the shared parameters k; no prior on the others

gives each unit the estimate ``β̂_u = (C_u⁻¹ + D)⁻¹ (C_u⁻¹ b_u + D μ)``, ``D = diag(1/τ_k²)`` on the shared
parameters: a unit whose log says little about a parameter borrows it from the fleet, one whose log determines it
keeps its own. The fleet's ``μ`` and the unit-to-unit variances ``τ²`` are estimated from the units by
expectation-maximisation (empirical Bayes): a parameter that really varies between units (a tool's mass) gets a
large ``τ²`` and is hardly pooled.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from .._util.reprs import short_repr
from ..exceptions import ShapeError

__all__ = ["PooledEstimate", "pooled_estimate", "shared_parameters", "own_term"]

OWN_TERMS = frozenset({"fc", "fv", "fst", "fca", "fcl", "offset"})
"""Drive terms (:data:`dynid.friction.TERMS`) that are each unit's own (friction, current offsets), never pooled."""


def own_term(name: str) -> bool:
    """Whether a base parameter is a unit's own friction or offset term (``fc3``, ``offset1``; not ``ZZ1R``, ``Ia2``).

    Parameters
    ----------
    name : str

    Returns
    -------
    bool
    """
    m = re.fullmatch(r"([a-z]+)\d+", str(name))
    return m is not None and m.group(1) in OWN_TERMS


def shared_parameters(names) -> np.ndarray:
    """Which base parameters units of one model share up to small deviations: the rigid-body ones.

    Parameters
    ----------
    names : sequence of str
        Base parameter names (``ZZ1R``, ``fc1``, ``offset3``, …).

    Returns
    -------
    (n,) bool ndarray
    """
    return np.array([not own_term(n) for n in names])


@short_repr
@dataclass(frozen=True)
class PooledEstimate:
    """Every unit's estimate with the fleet's help.

    Attributes
    ----------
    params : (n_units, n_params) array
        Each unit's pooled estimate β̂_u.
    covariance : (n_units, n_params, n_params) array
        Its posterior covariance (given μ and τ²).
    fleet : (n_params,) array
        μ on the shared parameters (NaN elsewhere).
    spread : (n_params,) array
        τ, the unit-to-unit standard deviation of the shared parameters (NaN elsewhere).
    shared : (n_params,) bool array
    iterations : int
        Expectation-maximisation steps.
    """

    params: np.ndarray
    covariance: np.ndarray
    fleet: np.ndarray
    spread: np.ndarray
    shared: np.ndarray
    iterations: int

    @property
    def std(self) -> np.ndarray:
        """(n_units, n_params) standard deviations of the pooled estimates."""
        return np.sqrt(np.maximum(np.diagonal(self.covariance, axis1=1, axis2=2), 0.0))


def pooled_estimate(params, covariance, shared=None, max_iterations: int = 500, tol: float = 1e-10) -> PooledEstimate:
    """Pool the units' estimates (module docstring).

    Parameters
    ----------
    params : (n_units, n_params) array
        Each unit's own estimate b_u (e.g. WLS).
    covariance : (n_units, n_params, n_params) array
        Their covariances C_u (positive definite).
    shared : (n_params,) bool array, optional
        The parameters pooled (default: all; :func:`shared_parameters` picks the rigid-body ones by name).
    max_iterations : int
    tol : float
        Convergence: relative change of τ² and μ.

    Returns
    -------
    PooledEstimate

    Raises
    ------
    ShapeError
        Inconsistent shapes, fewer than 2 units, or a covariance that is not positive definite.
    """
    b = np.asarray(params, dtype=float)
    c = np.asarray(covariance, dtype=float)
    if b.ndim != 2 or b.shape[0] < 2 or c.shape != (b.shape[0], b.shape[1], b.shape[1]):
        raise ShapeError(f"expected params (n_units >= 2, n_params) and covariances (n_units, n_params, n_params), got "
                         f"{b.shape} and {c.shape}")
    n_units, p = b.shape
    s = np.ones(p, dtype=bool) if shared is None else np.asarray(shared, dtype=bool)
    try:
        info = np.linalg.inv(c)
        np.linalg.cholesky(info)
    except np.linalg.LinAlgError:
        raise ShapeError("covariance: expected positive definite covariances of every unit's estimate") from None
    rhs = np.einsum("uij,uj->ui", info, b)
    own_var = np.diagonal(c, axis1=1, axis2=2)
    mu = np.median(b, axis=0)
    tau2 = np.maximum(np.var(b, axis=0) - own_var.mean(axis=0), 1e-6 * own_var.mean(axis=0)) + 1e-300
    it = 0
    for it in range(1, max_iterations + 1):  # noqa: B007 - the count is returned
        d = np.where(s, 1.0 / tau2, 0.0)
        post_info = info + d[None, :] * np.eye(p)[None]
        post_cov = np.linalg.inv(post_info)
        mean = np.einsum("uij,uj->ui", post_cov, rhs + (d * mu)[None, :])
        new_mu = mean.mean(axis=0)
        new_tau2 = np.mean((mean - new_mu) ** 2 + np.diagonal(post_cov, axis1=1, axis2=2), axis=0)
        new_tau2 = np.maximum(new_tau2, 1e-12 * own_var.mean(axis=0)) + 1e-300
        change = max(np.max(np.abs(new_tau2 - tau2)[s] / tau2[s], initial=0.0),
                     np.max(np.abs(new_mu - mu)[s] / np.sqrt(tau2[s] + own_var.mean(axis=0)[s]), initial=0.0))
        mu, tau2 = new_mu, new_tau2
        if change < tol:
            break
    d = np.where(s, 1.0 / tau2, 0.0)
    post_cov = np.linalg.inv(info + d[None, :] * np.eye(p)[None])
    mean = np.einsum("uij,uj->ui", post_cov, rhs + (d * mu)[None, :])
    return PooledEstimate(mean, post_cov, np.where(s, mu, np.nan), np.where(s, np.sqrt(tau2), np.nan), s, it)

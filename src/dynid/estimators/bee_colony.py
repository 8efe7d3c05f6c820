"""Artificial bee colony estimator: minimises the paper's objective eq. 9 over a search box (§3.1)."""

from __future__ import annotations

from collections.abc import Callable

from ..optim.bee_colony import minimize_bee_colony
from .base import BoxSearchEstimator


class BeeColonyEstimator(BoxSearchEstimator):
    """ABC identification (paper §3.1, eqs. 7-13), defaults from §4.1.

    Parameters
    ----------
    bounds : (p, 2) array
        Search box of the parameters (the paper's Table 3); required to fit (the identification pipeline builds it
        around the least-squares estimate).
    n_dof : int or None
        Joints per sample; None: inferred from tau given as (N, n_dof).
        Joints per sample in ``W``'s rows, for eq. 9.
    weights : (n_dof,) array, optional
        ``delta`` of eq. 9 (default 1).
    colony_size, limit, maxiter : int
        ``Ns = 30``, ``limit = 15``, ``Tmax = 50``.
    rng : Generator or seed
    callback : callable, optional
        ``callback(iteration, best_objective)``.

    Attributes
    ----------
    params_, objective_ (eq. 9), history_ (best objective per iteration), n_evaluations_, result_.
    """

    def __init__(self, *, bounds=None, n_dof: int | None = None, weights=None, colony_size: int = 30, limit: int = 15,
                 maxiter: int = 50, rng=None, callback: Callable[[int, float], None] | None = None):
        self.bounds = bounds
        self.n_dof = n_dof
        self.weights = weights
        self.colony_size = colony_size
        self.limit = limit
        self.maxiter = maxiter
        self.rng = rng
        self.callback = callback

    def _search(self, objective, bounds):
        """The artificial bee colony's search of the box (§3.1)."""
        return minimize_bee_colony(objective, bounds, colony_size=self.colony_size, limit=self.limit,
                                   maxiter=self.maxiter, rng=self.rng, callback=self.callback)

"""Artificial bee colony estimator: minimises the paper's objective eq. 9 over a search box (§3.1)."""

from __future__ import annotations

from collections.abc import Callable

from ..optim.bee_colony import minimize_bee_colony
from .base import BoxSearchEstimator


class BeeColonyEstimator(BoxSearchEstimator):
    """ABC identification (paper §3.1, eqs. 7-13), defaults from §4.1.

    The search box of the parameters (the paper's Table 3), the joints per sample and eq. 9's ``delta`` come to ``fit``
    as ``problem=FitData(bounds=..., n_dof=..., weights=...)`` (the identification pipeline builds the box around the
    least-squares estimate).

    Parameters
    ----------
    colony_size, limit, maxiter : int
        ``Ns = 30``, ``limit = 15``, ``Tmax = 50``.
    rng : Generator or seed
    callback : callable, optional
        ``callback(iteration, best_objective)``.

    Attributes
    ----------
    params_, objective_ (eq. 9), history_ (best objective per iteration), n_evaluations_, result_.
    """

    CONSTRAINTS = {"colony_size": ("int", 2, 100_000), "limit": ("int", 1, None), "maxiter": ("int", 1, 1_000_000)}

    def __init__(self, *, colony_size: int = 30, limit: int = 15,
                 maxiter: int = 50, rng=None, callback: Callable[[int, float], None] | None = None):
        self.colony_size = colony_size
        self.limit = limit
        self.maxiter = maxiter
        self.rng = rng
        self.callback = callback

    def _search(self, objective, bounds):
        """The artificial bee colony's search of the box (§3.1)."""
        return minimize_bee_colony(objective, bounds, colony_size=self.colony_size, limit=self.limit,
                                   maxiter=self.maxiter, rng=self.rng, callback=self.callback)

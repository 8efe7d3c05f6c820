"""Differential evolution and particle swarm on the paper's objective (eq. 9), for comparison with the ABC.

Both minimise the same ``F`` over the same search box as :class:`~dynid.estimators.BeeColonyEstimator`, and
report the same learned attributes (``params_``, ``objective_``, ``history_``, ``n_evaluations_``).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.optimize import differential_evolution

from ..optim.particle_swarm import minimize_particle_swarm
from .base import BoxSearchEstimator


class DifferentialEvolutionEstimator(BoxSearchEstimator):
    """SciPy's differential evolution (Storn & Price 1997, ``best1bin``) on eq. 9 over a box.

    The search box (the ABC's), the joints per sample and eq. 9's ``delta`` come to ``fit`` as ``problem=``
    (:class:`~dynid.estimators.base.BoxSearchEstimator`).

    Parameters
    ----------
    popsize : int
        Population size as a multiple of ``p`` (SciPy's convention).
    maxiter : int
        Generations; at most ``popsize · p · (maxiter + 1)`` evaluations.
    tol : float
        SciPy's relative convergence tolerance on the population's objective spread.
    polish : bool
        Finish with L-BFGS-B (off by default: eq. 9 is not differentiable).
    rng : Generator or seed
    callback : callable, optional
        ``callback(generation, best_objective)``.

    Attributes
    ----------
    params_, objective_ (eq. 9), history_ (best objective per generation), n_evaluations_, result_.
    """

    CONSTRAINTS = {"popsize": ("int", 1, 10_000), "maxiter": ("int", 1, 1_000_000), "tol": ("real", 0.0, None)}

    def __init__(self, *, popsize: int = 15, maxiter: int = 1000, tol: float = 1e-8,
                 polish: bool = False, rng=None, callback: Callable[[int, float], None] | None = None):
        self.popsize = popsize
        self.maxiter = maxiter
        self.tol = tol
        self.polish = polish
        self.rng = rng
        self.callback = callback

    def _search(self, objective, bounds):
        """SciPy's differential evolution over the box, its evaluations counted point by point."""
        history = []
        evaluations = 0

        def counted(x):  # SciPy's nfev counts calls of the vectorised objective, not points
            nonlocal evaluations
            evaluations += x.shape[1] if x.ndim == 2 else 1
            return objective(x)

        def record(intermediate_result):
            history.append(float(intermediate_result.fun))
            if self.callback is not None:
                self.callback(len(history), history[-1])

        res = differential_evolution(counted, bounds, popsize=self.popsize, maxiter=self.maxiter, tol=self.tol,
                                     polish=self.polish, vectorized=True, updating="deferred",
                                     rng=np.random.default_rng(self.rng), callback=record)
        res.history = np.array(history)
        res.nfev = evaluations
        return res


class ParticleSwarmEstimator(BoxSearchEstimator):
    """Global-best particle swarm with Clerc's constriction (:func:`dynid.optim.particle_swarm.minimize_particle_swarm`)
    on eq. 9 over a box.

    The search box, the joints per sample and eq. 9's ``delta`` come to ``fit`` as ``problem=``
    (:class:`~dynid.estimators.base.BoxSearchEstimator`).

    Parameters
    ----------
    swarm_size : int
        Particles (default 30, the ABC's colony size).
    maxiter : int
        Iterations; ``swarm_size · (maxiter + 1)`` evaluations.
    rng : Generator or seed
    callback : callable, optional
        ``callback(iteration, best_objective)``.

    Attributes
    ----------
    params_, objective_ (eq. 9), history_, n_evaluations_, result_.
    """

    CONSTRAINTS = {"swarm_size": ("int", 2, 100_000), "maxiter": ("int", 1, 1_000_000)}

    def __init__(self, *, swarm_size: int = 30, maxiter: int = 50, rng=None,
                 callback: Callable[[int, float], None] | None = None):
        self.swarm_size = swarm_size
        self.maxiter = maxiter
        self.rng = rng
        self.callback = callback

    def _search(self, objective, bounds):
        """The particle swarm's search of the box."""
        return minimize_particle_swarm(objective, bounds, swarm_size=self.swarm_size, maxiter=self.maxiter,
                                       rng=self.rng, callback=self.callback)

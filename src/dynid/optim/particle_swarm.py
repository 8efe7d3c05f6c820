"""Particle swarm optimisation (PSO) over a box, the global-best form with Clerc's constriction.

Reference: M. Clerc & J. Kennedy, "The particle swarm — explosion, stability, and convergence in a
multidimensional complex space", IEEE Trans. Evol. Comput. 6(1), 2002; the constriction values
``chi = 0.7298``, ``c1 = c2 = 2.05`` (inertia ``w = chi``, acceleration ``chi·c = 1.4962``) are theirs.

Each iteration, every particle ``i`` moves by
``v_i ← w v_i + a1 r1 ⊙ (p_i - x_i) + a2 r2 ⊙ (g - x_i)``, ``x_i ← x_i + v_i`` with ``r1, r2 ~ U(0, 1)``
per dimension, ``p_i`` its best position so far and ``g`` the swarm's. Velocities are limited to the box
width and positions clipped to the box (the velocity component that hit a wall is set to zero).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.optimize import OptimizeResult

from ..exceptions import ConfigError
from .box import check_box

INERTIA = 0.7298
ACCELERATION = 0.7298 * 2.05


def minimize_particle_swarm(fun: Callable[[np.ndarray], np.ndarray], bounds, *, swarm_size: int = 30,
                            maxiter: int = 50, rng: np.random.Generator | int | None = None,
                            inertia: float = INERTIA, cognitive: float = ACCELERATION, social: float = ACCELERATION,
                            callback: Callable[[int, float], None] | None = None) -> OptimizeResult:
    """Minimise ``fun`` over a box with a global-best particle swarm.

    Parameters
    ----------
    fun : callable
        Vectorised objective: ``fun(X)`` with ``X`` of shape (D, K) returns (K,) values, one per column.
    bounds : (D, 2) array
        Lower and upper bound of every dimension.
    swarm_size : int
        Number of particles (>= 2).
    maxiter : int
        Iterations; the objective is evaluated ``swarm_size · (maxiter + 1)`` times.
    rng : Generator or seed
    inertia, cognitive, social : float
        ``w``, ``a1``, ``a2`` (default: Clerc & Kennedy's constriction).
    callback : callable, optional
        ``callback(iteration, best_objective)`` after every iteration.

    Returns
    -------
    OptimizeResult
        ``x``, ``fun``, ``nit``, ``nfev``, ``success``, ``message``, ``history`` (best objective after each
        iteration, length ``maxiter``).

    Raises
    ------
    ConfigError
        If the settings or bounds are invalid.
    """
    bounds = check_box(bounds, "PSO")
    if swarm_size < 2:
        raise ConfigError(f"PSO swarm size must be >= 2, got {swarm_size}")
    if maxiter < 1:
        raise ConfigError(f"PSO iterations must be >= 1, got {maxiter}")
    rng = np.random.default_rng(rng)
    lo, hi = bounds[:, 0], bounds[:, 1]
    width = hi - lo
    dim = lo.size

    def evaluate(x):
        return np.asarray(fun(x.T), dtype=float).reshape(swarm_size)

    x = lo + rng.random((swarm_size, dim)) * width
    v = (rng.random((swarm_size, dim)) - 0.5) * width
    f = evaluate(x)
    p_best, p_f = x.copy(), f.copy()
    g = int(np.argmin(p_f))
    g_best, g_f = p_best[g].copy(), float(p_f[g])
    history = np.empty(maxiter)
    for it in range(maxiter):
        r1, r2 = rng.random((2, swarm_size, dim))
        v = inertia * v + cognitive * r1 * (p_best - x) + social * r2 * (g_best - x)
        v = np.clip(v, -width, width)
        x = x + v
        hit = (x < lo) | (x > hi)
        x = np.clip(x, lo, hi)
        v[hit] = 0.0
        f = evaluate(x)
        better = f < p_f
        p_best[better], p_f[better] = x[better], f[better]
        g = int(np.argmin(p_f))
        if p_f[g] < g_f:
            g_best, g_f = p_best[g].copy(), float(p_f[g])
        history[it] = g_f
        if callback is not None:
            callback(it + 1, g_f)
    return OptimizeResult(x=g_best, fun=g_f, nit=maxiter, nfev=swarm_size * (maxiter + 1), success=True,
                          message=f"{maxiter} iterations reached", history=history)

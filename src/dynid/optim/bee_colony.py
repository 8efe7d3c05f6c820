"""Artificial bee colony (ABC) optimiser, as described in §3.1 of the ER-16 paper (eqs. 7-13).

Reference: D. Karaboga, "An idea based on honey bee swarm for numerical optimization", TR06, Erciyes
University, 2005; the paper's Steps 1-7:

1. ``Ns`` random solutions in the search box (eq. 7).
2. Fitness ``fit = 1 / (1 + F)`` (eq. 8); the best ``Ne = Ns/2`` become the food sources of the
   employed bees.
3. Each employed bee tries ``v^j = x_i^j + lambda (x_i^j - x_k^j)`` on one random dimension ``j``,
   with a random other source ``k != i`` and ``lambda ~ U(-1, 1)`` (eq. 10); greedy selection (eq. 11).
4. Each of the ``Nu = Ns/2`` onlooker (following) bees picks a source with probability
   ``p_i = fit_i / sum fit`` (eq. 12) and
5. searches its neighbourhood the same way, with greedy selection.
6. A source not improved for more than ``limit`` trials is replaced by a random one (scout, eq. 13).
7. The best solution so far is kept; repeat from 3 for ``Tmax`` iterations.

Details the paper leaves open follow Karaboga's reference implementation: candidates are clipped to
the search box, and the trial counter of a source resets when it improves.

Every candidate differs from its source in one coordinate. When ``fun`` also offers ``start(x) -> (F,
state)`` and ``move(state, j, delta) -> (F, state)`` (e.g. eq. 9, whose residual changes by one column
times ``delta``: :class:`dynid.estimators.base.LinearAbsoluteObjective`), each candidate costs one column
instead of the whole product; the candidates and the random draws are the same.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.optimize import OptimizeResult

from ..exceptions import ConfigError
from .box import check_box


def minimize_bee_colony(fun: Callable[[np.ndarray], float], bounds, *, colony_size: int = 30, limit: int = 15,
                        maxiter: int = 50, rng: np.random.Generator | int | None = None,
                        callback: Callable[[int, float], None] | None = None) -> OptimizeResult:
    """Minimise ``fun`` over a box with the artificial bee colony (paper §3.1).

    Parameters
    ----------
    fun : callable
        Objective ``F(x) >= 0`` (eq. 9), ``x`` of shape (D,).
    bounds : (D, 2) array
        Lower and upper bound of every dimension (the paper's Table 3).
    colony_size : int
        ``Ns`` (even, >= 4); ``Ne = Nu = Ns / 2`` (paper: 30).
    limit : int
        Trials without improvement before a scout replaces the source (paper: 15).
    maxiter : int
        ``Tmax``, number of iterations (paper: 50).
    rng : Generator or seed
    callback : callable, optional
        ``callback(iteration, best_objective)`` after every iteration.

    Returns
    -------
    OptimizeResult
        ``x``, ``fun``, ``nit``, ``nfev``, ``success``, ``message`` and ``history`` (best objective
        after each iteration, length ``maxiter``).

    Raises
    ------
    ConfigError
        If the settings or bounds are invalid.
    """
    bounds = check_box(bounds, "ABC")
    if colony_size < 4 or colony_size % 2:
        raise ConfigError(f"ABC colony size must be an even number >= 4, got {colony_size}")
    if limit < 1:
        raise ConfigError(f"ABC limit must be >= 1, got {limit}")
    if maxiter < 1:
        raise ConfigError(f"ABC iterations must be >= 1, got {maxiter}")
    rng = np.random.default_rng(rng)
    lo, hi = bounds[:, 0], bounds[:, 1]
    dim = lo.size
    n_food = colony_size // 2
    nfev = 0

    incremental = hasattr(fun, "start") and hasattr(fun, "move")

    def evaluate(x):
        """F(x) and the state a coordinate move starts from (None without the incremental interface)."""
        nonlocal nfev
        nfev += 1
        if incremental:
            f, state = fun.start(x)
            return float(f), state
        return float(fun(x)), None

    # Steps 1-2: Ns random solutions (eq. 7), keep the Ne best as food sources
    init = lo + rng.random((colony_size, dim)) * (hi - lo)
    evaluated = [evaluate(x) for x in init]
    init_f = np.array([f for f, _ in evaluated])
    order = np.argsort(init_f, kind="stable")[:n_food]
    foods, obj = init[order].copy(), init_f[order].copy()
    states = [evaluated[k][1] for k in order]
    trials = np.zeros(n_food, dtype=int)
    best = int(np.argmin(obj))
    best_x, best_f = foods[best].copy(), obj[best]
    history = np.empty(maxiter)

    def fitness(f):
        return 1.0 / (1.0 + f) if f >= 0 else 1.0 + abs(f)  # eq. 8 (Karaboga's branch for F < 0)

    def neighbour_search(i):
        j = rng.integers(dim)
        k = rng.integers(n_food - 1)
        k = k + 1 if k >= i else k  # k != i
        nonlocal nfev
        v = foods[i].copy()
        v[j] = np.clip(foods[i, j] + rng.uniform(-1.0, 1.0) * (foods[i, j] - foods[k, j]), lo[j], hi[j])  # eq. 10
        if incremental:
            nfev += 1
            fv, sv = fun.move(states[i], j, v[j] - foods[i, j])
        else:
            fv, sv = evaluate(v)
        if fitness(fv) > fitness(obj[i]):  # eq. 11, greedy selection
            foods[i], obj[i], trials[i], states[i] = v, fv, 0, sv
        else:
            trials[i] += 1

    for it in range(maxiter):
        for i in range(n_food):  # Step 3: employed bees
            neighbour_search(i)
        fit = np.array([fitness(f) for f in obj])
        prob = fit / fit.sum()  # eq. 12
        for _ in range(n_food):  # Steps 4-5: onlooker bees
            neighbour_search(int(rng.choice(n_food, p=prob)))
        cur = int(np.argmin(obj))
        if obj[cur] < best_f:  # Step 7: memorise the best
            best_x, best_f = foods[cur].copy(), obj[cur]
        for scout in np.flatnonzero(trials > limit):  # Step 6: scouts (eq. 13)
            foods[scout] = lo + rng.random(dim) * (hi - lo)
            obj[scout], states[scout] = evaluate(foods[scout])
            trials[scout] = 0
            if obj[scout] < best_f:
                best_x, best_f = foods[scout].copy(), obj[scout]
        history[it] = best_f
        if callback is not None:
            callback(it + 1, best_f)
    return OptimizeResult(x=best_x, fun=best_f, nit=maxiter, nfev=nfev, success=True,
                          message=f"Tmax = {maxiter} iterations reached", history=history)

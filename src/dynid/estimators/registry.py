"""The one registry of estimators used by ``dynid run``, ``identify``, ``validate`` and ``montecarlo``.

Each method has a short key, a label for tables and one way to be built from a :class:`FitData`:

- ``ols``, ``wls``, ``irls``: least squares, per-joint weighted least squares, Huber IRLS;
- ``lad``: the exact minimiser of eq. 9 over the search box (a linear program);
- ``sdp``: physically consistent least squares over the standard parameters, reported as base parameters;
- ``abc``: the artificial bee colony at the paper's budget (Ns = 30, limit = 15, Tmax = 50);
- ``abc10``: the same with 10× the iterations;
- ``de``, ``pso``: differential evolution and particle swarm on eq. 9 over the same box, each given the
  evaluation budget of ``abc10`` (``10 · Ns · Tmax``).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..dynamics.base_parameters import BaseParameters
from .base import Estimator
from ..exceptions import ConfigError
from .names import BOOTSTRAPPED, BOX_SEARCHES, DESCRIPTIONS, LABELS, METHODS, parse_methods

__all__ = ["BOOTSTRAPPED", "BOX_SEARCHES", "DESCRIPTIONS", "LABELS", "METHODS", "parse_methods", "SearchBudget", "FitData",
           "Fitted", "make_estimator", "fit_method"]

@dataclass(frozen=True)
class SearchBudget:
    """ABC settings of §4.1; DE and PSO get ``10 · colony_size · maxiter`` evaluations."""

    colony_size: int = 30
    limit: int = 15
    maxiter: int = 50

    @property
    def evaluations(self) -> int:
        return 10 * self.colony_size * self.maxiter


@dataclass
class FitData:
    """What the estimators see of one identification recording.

    Attributes
    ----------
    w_base : (N·n_dof, n_base) array
        Base observation matrix, rows sample-major.
    tau : (N·n_dof,) array
        Measured torques [N·m].
    n_dof : int
    bounds : (n_base, 2) array
        Search box of the box searches and LAD.
    base : BaseParameters
    w_standard : (N·n_dof, p) array, optional
        Standard observation matrix (needed by ``sdp`` only).
    layout : tuple, optional
        ``(links, nonnegative)`` of :func:`dynid.dynamics.layout.consistency_layout` (``sdp``).
    prior : (p,) array, optional
        Standard parameters the SDP pulls unidentifiable directions towards.
    weights : (n_dof,) array, optional
        ``delta`` of eq. 9.
    """

    w_base: np.ndarray
    tau: np.ndarray
    n_dof: int
    bounds: np.ndarray
    base: BaseParameters
    w_standard: np.ndarray | None = None
    layout: tuple | None = None
    prior: np.ndarray | None = None
    weights: np.ndarray | None = None


@dataclass
class Fitted:
    """One method's fit: base parameters, the fitted estimator, wall time and evaluations of eq. 9."""

    key: str
    params: np.ndarray
    estimator: Estimator
    seconds: float
    n_evaluations: int | None


def make_estimator(key: str, data: FitData, budget: SearchBudget, rng: np.random.Generator,
                   callback: Callable[[int, float], None] | None = None) -> Estimator:
    """An unfitted estimator of method ``key`` for ``data`` (``rng`` seeds the box searches)."""
    n, wts, box = data.n_dof, data.weights, data.bounds
    if key in ("ols", "wls"):  # each estimator's module (and its solver) is imported on first use
        from .least_squares import OrdinaryLeastSquares, WeightedLeastSquares

        return OrdinaryLeastSquares() if key == "ols" else WeightedLeastSquares(n_dof=n)
    if key == "irls":
        from .robust import IterativelyReweightedLeastSquares

        return IterativelyReweightedLeastSquares(n_dof=n)
    if key == "lad":
        from .least_absolute import LeastAbsoluteDeviations

        return LeastAbsoluteDeviations(n_dof=n, weights=wts, bounds=box)
    if key == "sdp":
        from .physically_consistent import PhysicallyConsistentLeastSquares

        if data.w_standard is None or data.layout is None:
            raise ConfigError("method sdp needs the standard observation matrix and the parameter layout")
        links, nonneg = data.layout
        return PhysicallyConsistentLeastSquares(links=links, nonnegative=nonneg, prior=data.prior)
    if key in ("abc", "abc10"):
        from .bee_colony import BeeColonyEstimator

        iters = budget.maxiter * (10 if key == "abc10" else 1)
        return BeeColonyEstimator(bounds=box, n_dof=n, weights=wts, colony_size=budget.colony_size, limit=budget.limit,
                                  maxiter=iters, rng=rng, callback=callback)
    from .global_search import DifferentialEvolutionEstimator, ParticleSwarmEstimator

    if key == "pso":
        return ParticleSwarmEstimator(bounds=box, n_dof=n, weights=wts, swarm_size=budget.colony_size,
                                      maxiter=max(1, budget.evaluations // budget.colony_size - 1), rng=rng, callback=callback)
    if key == "de":
        p = box.shape[0]
        popsize = max(1, math.ceil(budget.colony_size / p))
        return DifferentialEvolutionEstimator(bounds=box, n_dof=n, weights=wts, popsize=popsize,
                                              maxiter=max(1, budget.evaluations // (popsize * p) - 1), rng=rng, callback=callback)
    raise ConfigError(f"unknown method {key!r}; expected one of {', '.join(METHODS)}")


def fit_method(key: str, data: FitData, budget: SearchBudget, rng: np.random.Generator,
               callback: Callable[[int, float], None] | None = None) -> Fitted:
    """Fit method ``key`` and return its base parameters (the SDP's standard set mapped to the base).

    Raises
    ------
    ConfigError
        ``sdp`` without ``w_standard`` and ``layout``, or an unknown key.
    DynIdError
        From the estimator (rank deficiency, solver failure).
    """
    est = make_estimator(key, data, budget, rng, callback)
    t0 = time.perf_counter()
    if key == "sdp":
        est.fit(data.w_standard, data.tau)
        params = data.base.base_from_standard(est.params_)
    else:
        est.fit(data.w_base, data.tau)
        params = est.params_
    seconds = time.perf_counter() - t0
    return Fitted(key, np.asarray(params, dtype=float), est, seconds, getattr(est, "n_evaluations_", None))


COST_ORDER = ("de", "pso", "abc10", "lad", "sdp", "irls", "abc", "ols", "wls")
"""Methods from the longest to the shortest fit (measured on dynid run): the pool starts the long ones first,
so that two cores finish together."""


def fit_methods(keys, data: FitData, budget: SearchBudget, rngs: dict, progress: Callable[[str, int, float], None] | None = None,
                workers: int | None = None, extra: dict | None = None) -> dict:
    """Fit every method of ``keys``, side by side on the cores (threads: the work is in BLAS, LAPACK, HiGHS
    and numba, which release the GIL).

    Each method draws from its own generator ``rngs[key]``, so the results depend neither on the order nor
    on the number of workers; each ``seconds`` is that method's wall time while the others ran.
    ``progress(key, iteration, best)`` reports the box searches (and ``(key, None, None)`` as a method starts).
    ``extra`` (name -> callable without arguments) adds independent tasks to the same pool, started after
    the three longest fits (their results are returned under their names).
    Returns key -> :class:`Fitted` in the order of ``keys``, then the extra tasks' results.

    When a fit fails, or this thread is interrupted (Ctrl-C), the box searches stop at their next iteration,
    the fits not started are cancelled, and the error is raised once the running ones have ended.
    """
    import threading
    from concurrent.futures import FIRST_EXCEPTION, ThreadPoolExecutor, wait

    from ..threads import cores

    stop = threading.Event()  # set when this thread is interrupted (Ctrl-C): the searches end at their next iteration

    def fit(key):
        if stop.is_set():
            raise _Stopped
        if progress is not None:
            progress(key, None, None)

        def callback(i, f, key=key):
            if stop.is_set():
                raise _Stopped
            if progress is not None:
                progress(key, i, f)

        return fit_method(key, data, budget, rngs[key], callback)

    extra = extra or {}
    rank = {k: i for i, k in enumerate(COST_ORDER)}
    tasks = [(rank[k], k, lambda k=k: fit(k)) for k in keys] + [(2.5, name, f) for name, f in extra.items()]
    tasks.sort(key=lambda task: task[0])
    pool = ThreadPoolExecutor(max_workers=max(1, min(workers or cores(), len(tasks))))
    try:
        futures = {name: pool.submit(f) for _, name, f in tasks}
        pending = set(futures.values())
        while pending:  # woken ten times a second: blocked on a lock, this thread would see Ctrl-C only at the end
            finished, pending = wait(pending, timeout=0.1, return_when=FIRST_EXCEPTION)
            for fut in finished:
                if fut.exception() is not None:
                    fut.result()  # raises the fit's error now; the other fits stop below
        done = {name: fut.result() for name, fut in futures.items()}
    except BaseException:
        stop.set()  # a box search would otherwise run to its end (seconds) before the interrupt is seen
        pool.shutdown(wait=True, cancel_futures=True)
        raise
    pool.shutdown()
    return {**{key: done[key] for key in keys}, **{name: done[name] for name in extra}}


class _Stopped(Exception):
    """Ends a fit of :func:`fit_methods` whose caller was interrupted (never seen by the caller)."""

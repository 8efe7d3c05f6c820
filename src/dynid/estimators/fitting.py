"""Fitting the registered estimators (:mod:`dynid.estimators.registry`) on a problem (:class:`FitData`): one, or all
side by side on the cores, each reported as base parameters with its wall time."""

from __future__ import annotations

import copy
import threading
import time
from collections.abc import Callable, Iterable
from concurrent.futures import FIRST_EXCEPTION, ThreadPoolExecutor, wait
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..exceptions import ConfigError, DynIdError
from ..runtime.threads import cores
from .problem import FitData, SearchBudget, with_problem
from .registry import PROBLEM_FILLED, _named, is_plugin, spec

if TYPE_CHECKING:
    from .base import Estimator

__all__ = ["Fitted", "make_estimator", "finish", "fit_method", "fit_methods"]


@dataclass
class Fitted:
    """One estimator's fit.

    Attributes
    ----------
    key : str
    params : (n_base,) array
        Base parameters (a standard-space estimator's mapped through the base-parameter map).
    estimator : Estimator
        The fitted estimator (its learned attributes: ``params_std_``, ``history_``, …).
    seconds : float
        Wall time of the fit [s].
    n_evaluations : int or None
        Evaluations of eq. 9 (box searches only).
    """

    key: str
    params: np.ndarray
    estimator: Estimator
    seconds: float
    n_evaluations: int | None


def make_estimator(key: str, data: FitData, budget: SearchBudget = SearchBudget(), rng=None,
                   callback: Callable[[int, float], None] | None = None, template: Estimator | None = None) -> Estimator:
    """An unfitted estimator for a problem: the registry's for ``key``, or a clone of the object given.

    Parameters
    ----------
    key : str
        A registered estimator (case-insensitive).
    data : FitData
    budget : SearchBudget
        The box searches' budget (of the registry's estimators: an object given carries its own).
    rng : numpy.random.Generator, optional
        Seeds the box searches.
    callback : callable, optional
        ``callback(iteration, best)`` of the box searches.
    template : Estimator, optional
        An unfitted estimator given in place of ``key`` (:func:`dynid.estimators.registry.estimator_choices`): its
        clone is returned, of its class and with its hyper-parameters (scikit-learn's ``clone``), the seeded generator,
        the callback and what the problem fills for a plugin class (:data:`dynid.estimators.registry.PROBLEM_FILLED`)
        set on it.

    Returns
    -------
    Estimator

    Raises
    ------
    ConfigError
        Unknown key, or ``sdp`` without the parameter layout.
    """
    entry = spec(key)
    built = entry.builder()(data, budget, rng, callback)
    if template is None:
        return built
    params = template.get_params()
    filled = built.get_params() if hasattr(built, "get_params") else {}
    own = copy.deepcopy({k: v for k, v in params.items() if k not in PROBLEM_FILLED})
    return type(template)(**own, **{k: filled[k] for k in PROBLEM_FILLED if k in params and k in filled})


def finish(key: str, est: Estimator, data: FitData, seconds: float) -> Fitted:
    """A fitted estimator as :class:`Fitted`: its parameters in the base (a standard-space estimator's mapped).

    Parameters
    ----------
    key : str
    est : Estimator
        Fitted.
    data : FitData
        The problem (its base map).
    seconds : float
        Wall time of the fit [s].

    Returns
    -------
    Fitted

    Raises
    ------
    ConfigError
        A standard-space estimator without a base map.
    """
    try:
        params = np.asarray(est.params_, dtype=float)
    except (AttributeError, TypeError, ValueError) as exc:
        raise ConfigError(f"{_named(key)}: after fit, expected params_ as an array of numbers "
                          f"({type(exc).__name__}: {exc})") from None
    w = data.w_standard if spec(key).space == "standard" else data.w_base
    expected = w.shape[1] if w is not None else (len(data.base.names) if data.base is not None and spec(key).space == "base"
                                                 else params.size)
    if params.shape != (expected,):
        raise ConfigError(f"{_named(key)}: returned parameters of shape {params.shape}, expected ({expected},): one per "
                          "column of the observation matrix it was given")
    if not np.all(np.isfinite(params)):
        bad = int(np.sum(~np.isfinite(params)))
        raise ConfigError(f"{_named(key)}: returned {bad} NaN or infinite parameter(s) of {params.size}: no estimate")
    if spec(key).space == "standard":
        if data.base is None:
            raise ConfigError(f"estimator {key} estimates standard parameters: the base-parameter map is needed")
        params = data.base.base_from_standard(params)
    return Fitted(spec(key).key, np.asarray(params, dtype=float), est, seconds, getattr(est, "n_evaluations_", None))


def fit_method(key: str, data: FitData, budget: SearchBudget = SearchBudget(), rng=None,
               callback: Callable[[int, float], None] | None = None, estimator: Estimator | None = None,
               template: Estimator | None = None) -> Fitted:
    """Fit estimator ``key`` on ``data`` and return its base parameters.

    Parameters
    ----------
    key : str
        A registered estimator.
    data : FitData
    budget : SearchBudget
        The box searches' budget.
    rng : numpy.random.Generator, optional
        Seeds the box searches.
    callback : callable, optional
        ``callback(iteration, best)`` of the box searches.
    estimator : Estimator, optional
        One built and fed already (rows streamed by ``partial_fit``): only its solution is computed here.
    template : Estimator, optional
        The object given in place of ``key``: a clone of it is fitted (:func:`make_estimator`).

    Returns
    -------
    Fitted

    Raises
    ------
    ConfigError
        Unknown key, or a standard-space estimator without ``w_standard`` (or a base map).
    DynIdError
        From the estimator (rank deficiency, solver failure).
    """
    entry = spec(key)
    t0 = time.perf_counter()
    try:
        if estimator is not None:
            est = estimator.solve(**with_problem(estimator.solve, data)) if hasattr(estimator, "solve") else estimator
        else:
            est = make_estimator(key, data, budget, rng, callback, template)
            w = data.w_standard if entry.space == "standard" else data.w_base
            if w is None:
                raise ConfigError(f"estimator {entry.key} needs the {entry.space} observation matrix")
            est.fit(w, data.tau, **with_problem(est.fit, data))
    except (DynIdError, _Stopped):
        raise
    except Exception as exc:  # a plugin's own error, said in one line naming it (a built-in's is a bug: raised as is)
        if not is_plugin(key):
            raise
        text = " ".join(str(exc).split()) or "no message"
        raise ConfigError(f"{_named(key)}: its fit raised {type(exc).__name__}: {text[:200]}") from None
    return finish(key, est, data, time.perf_counter() - t0)


def fit_methods(keys_: Iterable[str], data: FitData, budget: SearchBudget, rngs: dict, *, progress=None,
                workers: int | None = None, extra: dict | None = None, fed: dict | None = None,
                given: dict | None = None) -> dict:
    """Fit every estimator of ``keys_``, side by side on the cores (threads: the work is in BLAS, LAPACK, HiGHS
    and numba, which release the GIL).

    Parameters
    ----------
    keys_ : sequence of str
    data : FitData
    budget : SearchBudget
    rngs : dict
        key -> generator of that estimator: the results depend neither on the order nor on the number of workers.
    progress : callable, optional
        ``progress(key, iteration, best)`` reports the box searches (and ``(key, None, None)`` as a fit starts).
    workers : int, optional
        Threads (default: the cores).
    extra : dict, optional
        name -> callable without arguments: independent tasks run in the same pool, after the three longest fits.
    fed : dict, optional
        key -> estimator already fed by ``partial_fit``: only solved.
    given : dict, optional
        key -> the estimator object given in place of the key: a clone of it is fitted (:func:`make_estimator`).

    Returns
    -------
    dict
        key -> :class:`Fitted` in the order of ``keys_``, then the extra tasks' results under their names.
        Each ``seconds`` is that fit's wall time while the others ran.

    Notes
    -----
    When a fit fails, or this thread is interrupted (Ctrl-C), the box searches stop at their next iteration,
    the fits not started are cancelled, and the error is raised once the running ones have ended.
    """
    keys_ = tuple(keys_)
    fed, given = fed or {}, given or {}
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

        return fit_method(key, data, budget, rngs.get(key), callback, fed.get(key), given.get(key))

    extra = extra or {}
    tasks = [(-spec(k).cost, k, lambda k=k: fit(k)) for k in keys_] + [(-6.5, name, f) for name, f in extra.items()]
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
    return {**{key: done[key] for key in keys_}, **{name: done[name] for name in extra}}


class _Stopped(Exception):
    """Ends a fit of :func:`fit_methods` whose caller was interrupted (never seen by the caller)."""

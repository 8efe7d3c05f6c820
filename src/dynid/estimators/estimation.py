"""Every estimator of one identification fed from the same rows, block by block, then fitted side by side.

Blocks of rows ``(y, tau, keep)`` come from a preprocessing strategy (:mod:`dynid.preprocessing.strategies`). The
estimators that accumulate (:class:`~dynid.estimators.base.AccumulatingEstimator`: OLS, WLS, the SDP) take each
block by ``partial_fit``, so their memory does not grow with the log; the rows are stacked in memory only for those
that need them all at once (IRLS, LAD, the box searches) or when the caller asks. One least-squares estimate is
always there, the *reference*: its residuals give each joint's noise (and the WLS weights), its σ the search box of
the box searches. It is the first of OLS/WLS in the list, else WLS.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import replace
from typing import Any

import numpy as np

from ..exceptions import ConfigError
from .base import AccumulatingEstimator
from .fitting import Fitted, fit_methods, make_estimator
from .problem import FitData, SearchBudget, with_problem
from .registry import LEAST_SQUARES, _named, parse_estimators, seed_index, spec

__all__ = ["Estimation", "stream_rows"]


class Estimation:
    """The estimators ``keys`` of one identification, fed from the same blocks of rows.

    Parameters
    ----------
    keys : sequence of str
        Estimators of :mod:`dynid.estimators.registry` (case-insensitive); the first is the main estimate.
    problem : FitData
        What is known before any row: ``n_dof``, ``base``, ``layout``, ``prior``, ``weights`` (rows and box unset).
    names : sequence of str, optional
        Base parameters' names (said when the data do not excite some of them).
    keep_rows : bool
        Keep every block's base rows in memory even when no estimator needs them (:meth:`rows`).
    given : dict, optional
        key -> the estimator object given in place of the key: a clone of it is what is fed and fitted
        (:func:`dynid.estimators.fitting.make_estimator`).

    Attributes
    ----------
    keys : tuple of str
    reference : AccumulatingEstimator
        The least-squares reference (module docstring), solved by :meth:`solve_reference`.
    reference_key : str
        "ols" or "wls".
    streamed : dict
        key -> the estimators fed block by block.

    Raises
    ------
    ConfigError
        An unknown or repeated estimator.
    """

    def __init__(self, keys: Iterable[str], problem: FitData, names=None, keep_rows: bool = False,
                 given: dict | None = None):
        self.keys = parse_estimators(tuple(keys))
        self.problem = problem
        self.given = dict(given or {})
        self.names = None if names is None else tuple(names)
        self.reference_key = next((k for k in self.keys if k in LEAST_SQUARES), "wls")
        self.streamed: dict[str, AccumulatingEstimator] = {}
        for key in self.keys:
            if spec(key).needs_box:
                continue
            est = make_estimator(key, problem, template=self.given.get(key))
            if isinstance(est, AccumulatingEstimator):
                self.streamed[key] = est
        ref = self.streamed.get(self.reference_key)
        self.reference: Any = ref if ref is not None else make_estimator(self.reference_key, problem,
                                                                         template=self.given.get(self.reference_key))
        if not isinstance(self.reference, AccumulatingEstimator):
            raise ConfigError(f"{_named(self.reference_key)}: replaces the least-squares reference of every "
                              "identification, which takes the rows block by block (partial_fit) and gives σ; register "
                              "it under a key of its own, or subclass dynid.estimators.AccumulatingEstimator")
        fed = [self.reference, *self.streamed.values()]  # which take the problem with their rows (a plugin may not)
        self._takes_problem = {id(est): bool(with_problem(est.partial_fit, problem)) for est in fed}
        self.standard = any(spec(k).space == "standard" for k in self.keys)
        in_memory = [k for k in self.keys if k not in self.streamed]
        self._stack_base = keep_rows or any(spec(k).space == "base" for k in in_memory)
        self._stack_standard = any(spec(k).space == "standard" for k in in_memory)
        self._w: list[np.ndarray] = []
        self._ws: list[np.ndarray] = []
        self._tau: list[np.ndarray] = []

    def add(self, y: np.ndarray, tau: np.ndarray, keep: np.ndarray | None = None, y_standard: np.ndarray | None = None) -> None:
        """Feed one block of rows to every estimator.

        Parameters
        ----------
        y : (M, n_dof, n_base) array
            Base regressor of the block.
        tau : (M, n_dof) array [N·m]
        keep : (M, n_dof) bool array, optional
            Rows used (the others count for no estimator: left out of the accumulated ones, zeroed in the stacked ones).
        y_standard : (M, n_dof, p) array, optional
            Standard regressor (needed when an estimator of the standard space is listed).
        """
        nb = y.shape[-1]
        w = y.reshape(-1, nb)
        t = np.asarray(tau).reshape(-1)
        k = None if keep is None else np.asarray(keep).reshape(-1)
        ws = None if y_standard is None else y_standard.reshape(-1, y_standard.shape[-1])
        given = {"problem": self.problem}
        if self.reference_key not in self.streamed:
            self.reference.partial_fit(w, t, k, names=self.names, **(given if self._takes_problem[id(self.reference)] else {}))
        for key, est in self.streamed.items():
            with_it = given if self._takes_problem[id(est)] else {}
            if spec(key).space == "standard":
                if ws is None:
                    raise ValueError(f"estimator {key} estimates standard parameters: pass y_standard")
                est.partial_fit(ws, t, k, **with_it)
            else:
                est.partial_fit(w, t, k, names=self.names, **with_it)
        if self._stack_base or self._stack_standard:
            kk = np.ones(t.shape, dtype=bool) if k is None else k
            self._tau.append(t * kk)
            if self._stack_base:
                self._w.append(w * kk[:, None])
            if self._stack_standard and ws is not None:
                self._ws.append(ws * kk[:, None])

    def rows(self) -> tuple[np.ndarray | None, np.ndarray | None]:
        """The stacked base rows and torques kept for the estimators that need every row.

        Returns
        -------
        w : (M, n_base) ndarray or None
        tau : (M,) ndarray [N·m] or None
            None when none were kept.
        """
        if not self._w:
            return None, None
        return np.concatenate(self._w), np.concatenate(self._tau)

    def solve_reference(self) -> AccumulatingEstimator:
        """The least-squares reference, solved (its ``solution_``, ``ols_params_``, ``joint_std_``).

        Returns
        -------
        AccumulatingEstimator

        Raises
        ------
        IdentifiabilityError
            Too few rows, or the rows do not excite every base parameter.
        """
        return self.reference.solve()

    @property
    def needs_box(self) -> bool:
        """Whether an estimator searches a box (:meth:`fit` needs ``box``).

        Returns
        -------
        bool
        """
        return any(spec(k).needs_box for k in self.keys)

    def fit(self, box: np.ndarray | None = None, rngs: dict | None = None, *, rng: int | tuple[int, ...] | None = None,
            budget: SearchBudget = SearchBudget(), joint_weights: np.ndarray | None = None, progress=None,
            keys: Iterable[str] | None = None, workers: int | None = None, extra: dict | None = None) -> dict[str, Fitted]:
        """Fit the estimators side by side (:func:`dynid.estimators.fitting.fit_methods`).

        Parameters
        ----------
        box : (n_base, 2) array, optional
            Search box of the estimators that need one.
        rngs : dict, optional
            key -> generator of that estimator.
        rng : int or tuple of int, optional
            A seed, without ``rngs``: each estimator's generator is ``numpy.random.default_rng([*rng, its registry
            index])`` (:func:`dynid.estimators.registry.seed_index`), whichever others are fitted beside it.
        budget : SearchBudget
        joint_weights : (n_dof,) array, optional
            Row weights of the estimators that take them (``sdp``: the reference's WLS weights).
        progress : callable, optional
            ``progress(key, iteration, best)``.
        keys : sequence of str, optional
            A subset of :attr:`keys` (default all).
        workers : int, optional
            Threads (default: the cores).
        extra : dict, optional
            Other tasks run in the same pool (name -> callable).

        Returns
        -------
        dict
            key -> :class:`~dynid.estimators.fitting.Fitted`, then the extra tasks' results.

        Raises
        ------
        ConfigError
            A box search without a box.
        TypeError
            Both ``rng`` and ``rngs``.
        DynIdError
            From an estimator.
        """
        w, tau = self.rows()
        ws = np.concatenate(self._ws) if self._ws else None
        data = replace(self.problem, w_base=w, tau=tau, bounds=box, w_standard=ws,
                       joint_weights=self.problem.joint_weights if joint_weights is None else joint_weights)
        chosen = self.keys if keys is None else tuple(keys)
        if rngs is not None and rng is not None:
            raise TypeError("Estimation.fit: give rng (a seed) or rngs (a generator per estimator), not both")
        if rng is not None:
            seed = tuple(int(x) for x in np.atleast_1d(rng))
            rngs = {key: np.random.default_rng([*seed, seed_index(key)]) for key in chosen}
        for key in chosen:
            if spec(key).needs_box and box is None:
                raise ConfigError(f"estimator {key} searches a box: none was given")
        fed = {key: self.streamed[key] for key in chosen if key in self.streamed}  # solved on ``data``, joint weights included
        return fit_methods(chosen, data, budget, rngs or {}, progress=progress, workers=workers, extra=extra, fed=fed,
                           given=self.given)


def stream_rows(chunks, estimation: Estimation, base, observer: Callable | None = None, standard: bool | None = None) -> None:
    """Feed the blocks of a strategy's ``chunks`` to ``estimation``, calling ``observer`` on each block too.

    Parameters
    ----------
    chunks : iterable of (index, y, tau, keep)
        From :meth:`dynid.preprocessing.strategies.Strategy.chunks`; standard regressors when ``standard``.
    estimation : Estimation
    base : BaseParameters
        Maps a standard regressor block to the base one.
    observer : callable, optional
        ``observer(index, y, tau, keep, y_standard)`` with the block's base regressor (``y_standard`` None unless
        ``standard``).
    standard : bool, optional
        Whether the blocks hold standard regressors (default: whether ``estimation`` needs them).
    """
    standard = estimation.standard if standard is None else standard
    for index, y, tau, keep in chunks:
        y_standard = None
        if standard:
            y_standard, y = y, base.base_observation(y)
        estimation.add(y, tau, keep, y_standard if estimation.standard else None)
        if observer is not None:
            observer(index, y, tau, keep, y_standard)

"""``check_estimator(key_or_class)``: the checks an estimator passes before dynid trusts it, for a plugin's author
(before registering it, or after) and for dynid's own tests (issue "Re-zone the top floors", item 6; scikit-learn's
``check_estimator`` is the model).

The estimator is built and fitted the way the pipeline does (:func:`dynid.estimators.fitting.fit_method`, the
plugin guard included) on a small synthetic problem whose parameters are known: an observation matrix of two joints
and six base parameters with correlated, unequally scaled columns, torques with 0.1 % noise, and a search box that
holds the truth off its centre. What is checked:

* it builds from the registry and fits: ``params_`` one finite number per column;
* it estimates: least-squares-like estimators within 5 σ of the truth (σ from the problem's own covariance); box
  searches (``needs_box``) end inside the box, with eq. 9 below its value at the box's centre;
* the same ``rng`` gives the same parameters (dynid's results are reproducible);
* it leaves ``W`` and ``τ`` as they were;
* ``get_params`` returns the constructor's parameters (:meth:`dynid.estimators.base.Estimator.get_params`);
* ``fit(W, tau, sample_weight=None)`` (scikit-learn's contract): weights of one give the estimate without weights.

Estimators of the standard parameters (``space = "standard"``, e.g. ``sdp``) need a robot's parameter layout, which
the estimators do not see: they are checked by dynid's tests on a robot, not here.
"""

from __future__ import annotations

import inspect

import numpy as np

from .._util.keywords import seed_of
from ..exceptions import DynIdError
from .base import BoxSearchEstimator, Estimator, paper_objective
from .fitting import fit_method
from .problem import FitData, SearchBudget, with_problem
from .registry import _REGISTRY, register, spec

__all__ = ["EstimatorCheckError", "check_estimator"]

N_DOF = 2
N_PARAMS = 6
N_SAMPLES = 400
NOISE = 1e-3
"""Torque noise, a fraction of the torques' RMS."""


class EstimatorCheckError(DynIdError):
    """An estimator failed :func:`check_estimator`: the message names it and lists every failed check.

    Parameters
    ----------
    message : str
        The estimator's key, then the failed checks separated by "; ".
    field : str, optional
        Unused (the base class's).
    """


def _problem(seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float]:
    """``(W, tau, truth, bounds, sigma)``: the synthetic problem (module docstring)."""
    rng = np.random.default_rng([seed, 7])
    m = N_SAMPLES * N_DOF
    mixing = np.eye(N_PARAMS) + 0.4 * rng.standard_normal((N_PARAMS, N_PARAMS))
    w = (rng.standard_normal((m, N_PARAMS)) @ mixing) * np.geomspace(1.0, 30.0, N_PARAMS)
    truth = rng.uniform(-2.0, 2.0, N_PARAMS)
    clean = w @ truth
    sigma = NOISE * float(np.sqrt(np.mean(clean**2)))
    tau = clean + sigma * rng.standard_normal(m)
    half = 0.5 + np.abs(truth)
    bounds = np.column_stack([truth - 0.6 * half, truth + 1.4 * half])  # the truth inside, off the centre
    return w, tau, truth, bounds, sigma


def check_estimator(estimator, rng=0) -> None:
    """Check an estimator (module docstring), registered or not.

    Parameters
    ----------
    estimator : str or Estimator subclass
        A registry key (a plugin registers its estimator with :func:`dynid.estimators.register`), or the class itself,
        checked before it is registered, as registered with its defaults (a :class:`BoxSearchEstimator` as a box
        search); the registry is as it was afterwards.
    rng : int or numpy.random.Generator
        Seeds the synthetic problem and the estimator's ``rng`` (a generator gives one draw as the seed).

    Raises
    ------
    ConfigError
        A key that is not registered.
    TypeError
        Neither a key nor an :class:`~dynid.estimators.base.Estimator` subclass.
    EstimatorCheckError
        Every failed check, in one line.
    """
    seed = seed_of(rng)
    if isinstance(estimator, str):
        _check(spec(estimator), seed)
        return
    if not (isinstance(estimator, type) and issubclass(estimator, Estimator)):
        raise TypeError(f"check_estimator: expected a registry key or an Estimator subclass, got {estimator!r}")
    key = "check_" + "".join(c if c.isalnum() else "_" for c in estimator.__name__.lower())
    before = _REGISTRY.get(key)
    entry = register(key, estimator, label=estimator.__name__, needs_box=issubclass(estimator, BoxSearchEstimator),
                     replace=True)
    try:
        _check(entry, seed, estimator.__name__)
    finally:
        if before is None:
            _REGISTRY.pop(key, None)
        else:
            _REGISTRY[key] = before


def _check(entry, seed: int, name: str | None = None) -> None:
    """The checks of :func:`check_estimator` on a registry entry; ``name`` in messages (default its key)."""
    said = name or entry.key
    if entry.space != "base":
        raise EstimatorCheckError(f"{said}: estimates {entry.space} parameters, which need a robot's layout: "
                                  "check_estimator checks base-space estimators")
    w, tau, truth, bounds, sigma = _problem(seed)
    w0, tau0 = w.copy(), tau.copy()
    data = FitData(w, tau, N_DOF, bounds, None)
    budget = SearchBudget()
    failures: list[str] = []
    try:
        first = fit_method(entry.key, data, budget, np.random.default_rng([seed, 11]))
        again = fit_method(entry.key, data, budget, np.random.default_rng([seed, 11]))
    except DynIdError as exc:
        raise EstimatorCheckError(f"{said}: fit failed on a well-posed problem: {exc}") from None
    params = first.params
    if not (np.array_equal(w, w0) and np.array_equal(tau, tau0)):
        failures.append("fit changed the W or tau it was given")
    if not np.array_equal(params, again.params):
        failures.append("the same rng gave other parameters: results must be reproducible (draw from the rng given)")
    if entry.needs_box:
        inside = np.all((params >= bounds[:, 0] - 1e-9) & (params <= bounds[:, 1] + 1e-9))
        centre = bounds.mean(axis=1)
        if not inside:
            failures.append("a box search ended outside its box")
        if not paper_objective(tau - w @ params, N_DOF) < paper_objective(tau - w @ centre, N_DOF):
            failures.append("the box search did not improve eq. 9 on the box's centre")
    else:
        cov = sigma**2 * np.linalg.inv(w.T @ w)
        z = np.abs(params - truth) / np.sqrt(np.diag(cov))
        if np.any(z > 5):
            failures.append(f"estimates {int(np.sum(z > 5))} parameter(s) more than 5 σ from the truth "
                            f"(worst {z.max():.3g} σ) on a well-conditioned problem with 0.1 % noise")
    try:
        params_given = first.estimator.get_params()
    except Exception as exc:  # noqa: BLE001  any failure is the check's finding
        failures.append(f"get_params failed: {type(exc).__name__}: {exc}")
    else:
        if not isinstance(params_given, dict):
            failures.append("get_params did not return a dict")
    failures += _sample_weight_failures(first.estimator, w, tau, seed, data)
    if failures:
        raise EstimatorCheckError(f"{said}: " + "; ".join(failures))


def _sample_weight_failures(fitted, w: np.ndarray, tau: np.ndarray, seed: int, data: FitData) -> list[str]:
    """Refit a clone of ``fitted`` on the problem ``data`` without weights and with weights of one (the same ``rng``
    seed, if it has one): the same parameters, or the failure in words."""
    if "sample_weight" not in inspect.signature(fitted.fit).parameters:
        return ["fit takes no sample_weight: the contract is fit(W, tau, sample_weight=None) (one weight >= 0 per row)"]
    fits = []
    for weights in (None, np.ones(tau.shape[0])):
        est = fitted.clone()
        if "rng" in est.get_params():
            est.set_params(rng=np.random.default_rng([seed, 13]))
        try:
            fits.append(np.asarray(est.fit(w, tau, sample_weight=weights, **with_problem(est.fit, data)).params_, dtype=float))
        except Exception as exc:  # noqa: BLE001  any failure is the check's finding
            return [f"fit(W, tau, sample_weight=...) failed: {type(exc).__name__}: {exc}"]
    if not np.allclose(fits[0], fits[1], rtol=1e-9, atol=1e-12 * (1.0 + np.abs(fits[0]).max())):
        return ["sample_weight of ones gave other parameters than no sample_weight"]
    return []

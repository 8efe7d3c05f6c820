"""The one registry of estimators, used by ``dynid run``, ``identify``, ``validate``, ``montecarlo`` and the API.

Each estimator has a key (case-insensitive), a label for tables, a description, and is built from a
:class:`~dynid.estimators.problem.FitData` (what it sees of the problem: the observation rows, the joints, the search box, the eq. 9
weights, the SDP's prior and layout). Built in:

- ``ols``, ``wls``, ``irls``: least squares, per-joint weighted least squares, Huber IRLS;
- ``lad``: the exact minimiser of eq. 9 over the search box (a linear program);
- ``sdp``: physically consistent least squares over the standard parameters, reported as base parameters;
- ``abc``: the artificial bee colony of §3.1 at the paper's budget (Ns = 30, limit = 15, Tmax = 50);
- ``abc10``: the same with 10× the iterations;
- ``de``, ``pso``: differential evolution and particle swarm on eq. 9 over the same box, each given the
  evaluation budget of ``abc10`` (``10 · Ns · Tmax``).

A new estimator is one file that subclasses :class:`dynid.estimators.base.Estimator` and calls :func:`register`;
every command and :class:`dynid.Identifier` can then use its key. Reading the keys (a config check) imports
no solver: the built-in classes load when first built. The problem an estimator sees is
:mod:`dynid.estimators.problem`'s; fitting them is :mod:`dynid.estimators.fitting`'s.
"""

from __future__ import annotations

import dataclasses
import importlib
import importlib.util
import inspect
import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from ..exceptions import ConfigError
from ..plugins import Registry, load_plugins, origin
from .problem import MOVED_TO_PROBLEM, FitData, SearchBudget

if TYPE_CHECKING:
    import numpy as np

    from .base import Estimator

__all__ = ["DEFAULT_ESTIMATORS", "EstimatorSpec", "SearchBudget", "FitData", "register", "unregister", "spec", "keys",
           "label", "parse_estimators", "estimator_choices", "configured_estimator"]

DEFAULT_ESTIMATORS = ("wls", "sdp")
"""The estimators an identification runs where none are listed: weighted least squares (the main estimate) and the
physically consistent SDP, pulled toward the description's values made consistent where they are not
(:meth:`dynid.model.robot.Robot.physical_prior`), so that a consistent estimate competes in the verdict on every arm
(issue "The better model wins", item 2). Until 0.2 the default was least squares alone."""


Builder = Callable[["FitData", SearchBudget, "np.random.Generator | None", "Callable[[int, float], None] | None"], "Estimator"]


@dataclass(frozen=True)
class EstimatorSpec:
    """How the registry knows an estimator.

    Attributes
    ----------
    key : str
        Lower-case name used in configs, on the command line and in :class:`dynid.Identifier`.
    label : str
        Shown in tables and figures (``"dynid <label>"`` names its estimate).
    description : str
        One line for reports.
    build : callable or str
        ``build(data, budget, rng, callback) -> Estimator``, or an :class:`~dynid.estimators.base.Estimator`
        subclass (its keyword hyper-parameters ``rng`` and ``callback`` are filled by the identification; the problem
        comes to its ``fit`` as ``problem=``: :class:`FitData`), or ``"module:attribute"`` of either (imported when
        first built). A plugin class written before ``fit`` took the problem, whose constructor names ``n_dof``,
        ``bounds``, ``weights``, ``prior``, ``links``, ``nonnegative``, ``joint_weights``, ``base_prior`` or
        ``base_prior_std``, still gets them there (:data:`PROBLEM_FILLED`).
    space : {"base", "standard"}
        The parameters it estimates: base parameters, or standard ones (mapped to the base by the pipeline).
    cost : float
        Relative fitting time: the longest start first, so that two cores finish together.
    needs_box : bool
        It searches the box :attr:`FitData.bounds` (the pipeline builds one around the least-squares estimate).
    bootstrapped : bool
        Cheap enough to refit on every bootstrap resample.
    options : dict
        Fixed hyper-parameters passed to the class.
    makes : str
        ``"module:attribute"`` of the class a function :attr:`build` makes: an object of that class given in place of
        a key is this estimator (:func:`estimator_choices`).
    """

    key: str
    label: str
    description: str
    build: Any
    space: str = "base"
    cost: float = 1.0
    needs_box: bool = False
    bootstrapped: bool = False
    options: dict = dataclasses.field(default_factory=dict)
    makes: str = ""

    def builder(self) -> Builder:
        """The callable that builds an unfitted estimator from :class:`FitData`.

        Returns
        -------
        callable
            ``build(data, budget, rng, callback) -> Estimator`` (a class given as :attr:`build` is wrapped so that the
            problem's matching keyword hyper-parameters are passed).
        """
        target = self.build
        if isinstance(target, str):
            module, _, attr = target.partition(":")
            target = getattr(importlib.import_module(module, __package__), attr)
        if isinstance(target, type):
            return _from_class(target, self.options)
        return target


PROBLEM_FILLED = MOVED_TO_PROBLEM | {"rng", "callback"}
"""Constructor parameters the identification fills (the seeded generator, the progress callback; and, for a plugin
class whose constructor still names them, the problem's layout, search box, weights and prior): never taken from an
estimator object given as a choice."""


def _from_class(cls: type, options: dict) -> Builder:
    """A builder that passes the problem's matching keyword hyper-parameters to ``cls`` (see :class:`EstimatorSpec`)."""
    accepted = set(inspect.signature(cls).parameters)

    def build(data: FitData, budget: SearchBudget, rng, callback):
        values = {"n_dof": data.n_dof, "bounds": data.bounds, "weights": data.weights, "prior": data.prior,
                  "joint_weights": data.joint_weights, "rng": rng, "callback": callback, "base_prior": data.base_prior,
                  "base_prior_std": data.base_prior_std}
        if data.layout is not None:
            values.update(links=data.layout[0], nonnegative=data.layout[1])
        kwargs = {k: v for k, v in values.items() if k in accepted}
        return cls(**{**kwargs, **options})

    return build


def _box_search(kind: str, iterations: int = 1) -> Builder:
    """Builder of a box search at the budget of :class:`SearchBudget` (ABC: ``iterations`` × Tmax; DE and PSO:
    :attr:`SearchBudget.evaluations`)."""

    def build(data: FitData, budget: SearchBudget, rng, callback):
        if kind == "abc":
            from .bee_colony import BeeColonyEstimator

            return BeeColonyEstimator(colony_size=budget.colony_size, limit=budget.limit,
                                      maxiter=budget.maxiter * iterations, rng=rng, callback=callback)
        from .global_search import DifferentialEvolutionEstimator, ParticleSwarmEstimator

        if kind == "pso":
            return ParticleSwarmEstimator(swarm_size=budget.colony_size,
                                          maxiter=max(1, budget.evaluations // budget.colony_size - 1), rng=rng, callback=callback)
        p = len(data.bounds)  # DE's population is a multiple of the box's dimension (SciPy's convention)
        popsize = max(1, math.ceil(budget.colony_size / p))
        return DifferentialEvolutionEstimator(popsize=popsize, maxiter=max(1, budget.evaluations // (popsize * p) - 1),
                                              rng=rng, callback=callback)

    return build


def _sdp(data: FitData, budget: SearchBudget, rng, callback) -> Estimator:
    from .physically_consistent import PhysicallyConsistentLeastSquares

    if data.layout is None:
        raise ConfigError("estimator sdp needs the parameter layout of the robot (links and non-negative columns)")
    return PhysicallyConsistentLeastSquares()


_ESTIMATORS = Registry("estimator", builder=lambda entry: entry.build)
_REGISTRY: dict[str, EstimatorSpec] = _ESTIMATORS.entries


def register(key: str, build, *, label: str | None = None, description: str = "", space: str = "base",
             cost: float = 1.0, needs_box: bool = False, bootstrapped: bool = False, replace: bool = False,
             makes: str = "", **options) -> EstimatorSpec:
    """Make an estimator known to every command and to :class:`dynid.Identifier` under ``key``.

    Parameters
    ----------
    key : str
        Its name (case-insensitive: stored in lower case); letters, digits and ``_``.
    build : Estimator subclass, callable or "module:attribute"
        See :attr:`EstimatorSpec.build`.
    label, description, space, cost, needs_box, bootstrapped
        See :class:`EstimatorSpec` (``label`` defaults to ``key`` in upper case).
    replace : bool
        Replace an estimator registered under the same key (else a ``ValueError``, unless it is the same class of the
        same module: a plugin imported again).
    makes : str
        See :attr:`EstimatorSpec.makes` (a function ``build`` only).
    **options
        Fixed hyper-parameters of the class.

    Returns
    -------
    EstimatorSpec

    Raises
    ------
    ValueError
        A malformed key, an unknown ``space``, or a key already registered (without ``replace``).

    Examples
    --------
    >>> from dynid.estimators import Estimator, register
    >>> class Ridge(Estimator):
    ...     def __init__(self, *, alpha=1e-3):
    ...         self.alpha = alpha
    ...     def fit(self, w, tau, sample_weight=None):
    ...         import numpy as np
    ...         from dynid.estimators import weighted_rows
    ...         w, tau = weighted_rows(w, tau, sample_weight, 0.5)
    ...         self.params_ = np.linalg.solve(w.T @ w + self.alpha * np.eye(w.shape[1]), w.T @ tau)
    ...         return self
    >>> spec = register("ridge", Ridge, description="ridge regression")
    """
    k = str(key).strip().lower()
    if not k or not k.replace("_", "").isalnum():
        raise ValueError(f"estimator key: expected letters, digits and _, got {key!r}")
    if space not in ("base", "standard"):
        raise ValueError(f"estimator {k}: space must be 'base' or 'standard', got {space!r}")
    entry = EstimatorSpec(k, label or k.upper(), description, build, space, cost, needs_box, bootstrapped, dict(options),
                          makes)
    _ESTIMATORS.add(k, entry, replace=replace)
    return entry


def unregister(key: str) -> None:
    """Forget a registered estimator.

    Parameters
    ----------
    key : str

    Raises
    ------
    KeyError
        An unknown key.
    """
    _ESTIMATORS.remove(key)


register("ols", ".least_squares:OrdinaryLeastSquares", label="OLS", description="ordinary least squares", cost=0.2,
         bootstrapped=True)
register("wls", ".least_squares:WeightedLeastSquares", label="WLS", description="weighted least squares, one weight per joint",
         cost=0.1, bootstrapped=True)
register("irls", ".robust:IterativelyReweightedLeastSquares", label="IRLS",
         description="iteratively reweighted least squares (Huber)", cost=0.4)
register("lad", ".least_absolute:LeastAbsoluteDeviations", label="LAD",
         description="least absolute deviations: exact minimum of eq. 9 in the search box (HiGHS)", cost=6, needs_box=True)
register("sdp", _sdp, label="SDP", space="standard", cost=5, makes=".physically_consistent:PhysicallyConsistentLeastSquares",
         description="physically consistent least squares (SDP, cvxpy + Clarabel), prior: nominal parameters × U(0.7, 1.3)")
register("abc", _box_search("abc"), label="ABC", description="artificial bee colony, the paper's budget", cost=0.3,
         needs_box=True, makes=".bee_colony:BeeColonyEstimator")
register("abc10", _box_search("abc", 10), label="ABC×10", description="artificial bee colony, 10× the paper's iterations",
         cost=7, needs_box=True)
register("de", _box_search("de"), label="DE", description="differential evolution (SciPy), the budget of ABC×10", cost=9,
         needs_box=True, makes=".global_search:DifferentialEvolutionEstimator")
register("pso", _box_search("pso"), label="PSO", description="particle swarm (constriction), the budget of ABC×10", cost=8,
         needs_box=True, makes=".global_search:ParticleSwarmEstimator")

BUILT_IN = _ESTIMATORS.seal()
"""The estimators dynid comes with (the others were registered by the user)."""


def is_plugin(key: str) -> bool:
    """Whether estimator ``key`` is the user's (registered by a plugin, or a built-in key replaced by one).

    Parameters
    ----------
    key : str

    Returns
    -------
    bool
    """
    return _ESTIMATORS.is_plugin(key)


def _named(key: str) -> str:
    """``estimator KEY`` and, for a plugin's, where it comes from."""
    k = str(key).strip().lower()
    return f"estimator {k} (plugin {origin(_REGISTRY[k].build)})" if is_plugin(k) else f"estimator {k}"

LEAST_SQUARES = ("ols", "wls")
"""The least-squares estimates that carry σ; one of them is the reference of every identification (the first of
these in the list of estimators, else WLS): its residuals give each joint's noise, its σ the search box."""


def registered_by_user(keys_: Iterable[str]) -> dict:
    """The estimators among ``keys_`` that are not built in: what another process (a Dask worker) must register to
    fit them (:func:`ensure_registered`).

    Parameters
    ----------
    keys_ : sequence of str

    Returns
    -------
    dict
        key -> :class:`EstimatorSpec`.
    """
    return _ESTIMATORS.by_user([spec(k).key for k in keys_])


def ensure_registered(specs: dict) -> None:
    """Register the estimators of ``specs`` that this process does not know (a Dask worker).

    Parameters
    ----------
    specs : dict
        key -> :class:`EstimatorSpec` (:func:`registered_by_user` in the process that had them).
    """
    _ESTIMATORS.ensure(specs)


def spec(key: str) -> EstimatorSpec:
    """The registered estimator ``key`` (case-insensitive).

    Parameters
    ----------
    key : str

    Returns
    -------
    EstimatorSpec

    Raises
    ------
    ConfigError
        An unknown key (the message lists the known ones).
    """
    entry = _ESTIMATORS.find(key)  # the user's own estimators too (dynid.plugins)
    if entry is None:
        raise ConfigError(f"unknown estimator {key!r}; expected one of {', '.join(_REGISTRY)}", field="estimators")
    return entry


def keys() -> tuple[str, ...]:
    """Every registered estimator.

    Returns
    -------
    tuple of str
        The built-in ones first, in registration order.
    """
    return tuple(_REGISTRY)


OTHER_LABELS = {"idim-iv": "IDIM-IV", "didim": "DIDIM", "didim-sdp": "DIDIM-SDP"}
"""Labels of estimators that run outside the registry (the closed-loop ones, :mod:`dynid.identification.closed_loop_estimators`)."""


def label(key: str) -> str:
    """The table label of an estimator.

    Parameters
    ----------
    key : str

    Returns
    -------
    str
        ``"WLS"``, ``"ABC×10"``; anything not registered as it is.
    """
    entry = _REGISTRY.get(str(key).strip().lower())
    return entry.label if entry is not None else OTHER_LABELS.get(str(key).strip().lower(), str(key))


def estimate_label(key: str) -> str:
    """How dynid's estimate by ``key`` is labelled in tables, figures and JSON: ``"dynid WLS"``, ``"dynid ABC×10"``.

    Parameters
    ----------
    key : str
        A registered estimator.

    Returns
    -------
    str
    """
    return f"dynid {label(key)}"


def parse_estimators(text: str | Iterable[str] | None, default: tuple[str, ...] | None = None) -> tuple[str, ...]:
    """Estimator keys from text or a sequence, case-insensitive.

    Parameters
    ----------
    text : str, sequence of str, or None
        ``"ols,abc"``, ``["OLS", "abc"]``; ``"all"``: every registered key.
    default : tuple of str, optional
        What None gives (default: the built-in estimators).

    Returns
    -------
    tuple of str

    Raises
    ------
    ConfigError
        Unknown, repeated or no estimator (field ``estimators``).
    """
    if text is None:
        return default if default is not None else BUILT_IN
    if isinstance(text, str) and text.strip().lower() == "all":
        return keys()
    items = text.split(",") if isinstance(text, str) else list(text)
    if not all(isinstance(k, str) for k in items):
        objects = [type(k).__name__ for k in items if hasattr(k, "get_params")]
        if objects:
            raise ConfigError(f"estimators: here only names of estimators (an estimator object, {objects[0]}, goes to "
                              "the identification: dynid.Identifier, identify_from_arrays or IdentificationPipeline)",
                              field="estimators")
        raise ConfigError(f"estimators: expected names of estimators, got {text!r}", field="estimators")
    found = [k.strip().lower() for k in items]
    if any(k not in _REGISTRY for k in found):
        load_plugins()  # the user's own estimators (dynid.plugins)
    unknown = [k for k in found if k not in _REGISTRY]
    if unknown or not found:
        raise ConfigError(f"estimators: expected a comma-separated subset of {', '.join(_REGISTRY)} (or all), got {text!r}",
                          field="estimators")
    if len(set(found)) != len(found):
        raise ConfigError(f"estimators: each estimator once, got {text!r}", field="estimators")
    return tuple(found)


def estimator_choices(items, where: str = "estimators") -> tuple[tuple[str, ...], dict]:
    """The estimators of a list of keys and estimator objects: their keys, and the objects by key (scikit-learn's
    rule: an object holds its hyper-parameters, the problem comes to ``fit``; a clone of each object is what is fitted,
    :func:`dynid.estimators.fitting.make_estimator`).

    Parameters
    ----------
    items : str, or sequence of str and Estimator
        Keys (as :func:`parse_estimators` takes them) and unfitted estimators of registered classes, e.g.
        ``["wls", PhysicallyConsistentLeastSquares(...)]``; the first is the main estimate.
    where : str
        Where the list was given, for the messages.

    Returns
    -------
    keys : tuple of str
    given : dict
        key -> the estimator object given for it (keys given as names are not in it).

    Raises
    ------
    ConfigError
        An unknown key, an object of a class not registered, repeated or no estimator.
    """
    if items is None or isinstance(items, str):
        return parse_estimators(items), {}
    items = list(items)
    objects = {i: _key_of(item, where) for i, item in enumerate(items) if not isinstance(item, str)}
    keys_ = parse_estimators([objects.get(i, item) for i, item in enumerate(items)])
    return keys_, {objects[i]: items[i] for i in objects}


def configured_estimator(key: str, given: dict, where: str):
    """An unfitted estimator of a registered key carrying hyper-parameters given by name (a config's
    ``{ key = "abc", colony_size = 60 }``): each name one of its class's constructor parameters that the problem does
    not fill (:data:`PROBLEM_FILLED`), each value among the class's ``PARAMETER_CHOICES`` where it lists them.

    Parameters
    ----------
    key : str
        A registered estimator key (lower case).
    given : dict
        Parameter name -> value.
    where : str
        Where they were given, for the messages.

    Returns
    -------
    Estimator
        Unfitted; the problem comes to its ``fit``.

    Raises
    ------
    ConfigError
        An unknown key or parameter name, a value outside the class's choices, a value its constructor refuses, or
        an estimator built by a function that names no class.
    """
    cls = _estimator_class(spec(key))
    settable = [p.name for p in inspect.signature(cls).parameters.values()
                if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY) and p.name not in PROBLEM_FILLED]
    for name, value in given.items():
        if name not in settable:
            filled = " (dynid fills it: the config's seed, the log)" if name in PROBLEM_FILLED else ""
            raise ConfigError(f"{where}: {key} has no hyper-parameter {name!r}{filled}; expected some of "
                              f"{', '.join(settable) or 'none'}", field="estimators")
        choices = getattr(cls, "PARAMETER_CHOICES", {}).get(name)
        if choices is not None and value not in choices:
            raise ConfigError(f"{where}: {key}'s {name}: expected one of {', '.join(map(str, choices))}, got {value!r}",
                              field="estimators")
    try:
        return cls(**given)
    except (TypeError, ValueError) as exc:
        raise ConfigError(f"{where}: {key}: {exc}", field="estimators") from None


def _estimator_class(entry: EstimatorSpec) -> type:
    """The class of a registered estimator (its :attr:`EstimatorSpec.build`, or what its function :attr:`~EstimatorSpec.makes`)."""
    target = entry.build if isinstance(entry.build, (type, str)) else entry.makes
    if isinstance(target, type):
        return target
    if not target:
        raise ConfigError(f"estimator {entry.key}: its builder names no class to carry hyper-parameters", field="estimators")
    module, attr = _class_name(target)
    return getattr(importlib.import_module(module), attr)


def _key_of(item, where: str) -> str:
    """The registered key whose estimator is of ``item``'s class (exactly)."""
    if not hasattr(item, "get_params"):
        raise ConfigError(f"{where}: expected names of estimators or estimator objects, got {item!r}", field="estimators")
    cls = type(item)
    for key, entry in _REGISTRY.items():
        target = entry.build if isinstance(entry.build, type) else entry.makes or entry.build
        if target is cls or isinstance(target, str) and _class_name(target) == (cls.__module__, cls.__qualname__):
            return key
    raise ConfigError(f"{where}: {cls.__name__} is not a registered estimator: dynid.estimators.register(key, "
                      f"{cls.__name__}) first, then give the object or its key", field="estimators")


def _class_name(target: str) -> tuple[str, str]:
    """``(module, attribute)`` of a ``"module:attribute"`` (a module relative to this package resolved)."""
    module, _, attr = target.partition(":")
    return importlib.util.resolve_name(module, __package__), attr


def seed_index(key: str) -> int:
    """Position of an estimator in the registry: with the run's seed it seeds the estimator's own generator, so
    that adding estimators to a run leaves the others' results as they were.

    Parameters
    ----------
    key : str

    Returns
    -------
    int
    """
    return keys().index(spec(key).key)



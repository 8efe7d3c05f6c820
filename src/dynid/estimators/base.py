"""Shared estimator contract (scikit-learn style: parameters by name, as its ``BaseEstimator`` has them) and the paper's
objective (eq. 9)."""

from __future__ import annotations

import functools
import inspect
import math
import numbers
from typing import Self

import numpy as np

from .._util.reprs import short_value
from ..exceptions import ConfigError, NotFittedError, ShapeError
from .accumulate import LeastSquaresAccumulator
from .problem import MOVED_TO_PROBLEM, FitData


def check_observations(w, tau, n_dof: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Validate an observation matrix and torques at the public boundary.

    Parameters
    ----------
    w : (M, p) array
    tau : (M,) or (N, n_dof) array with N·n_dof = M [N·m]
    n_dof : int, optional
        With it, also check that ``M`` is a whole number of samples.

    Returns
    -------
    w : (M, p) float64 array
    tau : (M,) float64 array

    Raises
    ------
    ShapeError
        Wrong shapes, rows not matching, or NaN/inf values.
    """
    w = np.asarray(w, dtype=np.float64)
    tau = np.asarray(tau, dtype=np.float64).reshape(-1)
    if w.ndim != 2:
        raise ShapeError(f"expected W with shape (N*n_dof, n_params), got {w.shape}")
    if w.shape[0] != tau.shape[0]:
        raise ShapeError(f"W has {w.shape[0]} rows but tau has {tau.shape[0]} values")
    if not (np.all(np.isfinite(w)) and np.all(np.isfinite(tau))):
        raise ShapeError("W or tau holds NaN or infinite values")
    if n_dof is not None and w.shape[0] % n_dof:
        raise ShapeError(f"W has {w.shape[0]} rows, not a multiple of n_dof = {n_dof}")
    return w, tau


def weighted_rows(w, tau, sample_weight, power: float):
    """The rows of ``(W, tau)`` scaled for a fit with sample weights (scikit-learn's ``sample_weight``).

    A least-squares fit of the scaled rows minimises ``Σ s_i r_i²`` when each row is scaled by ``√s_i`` (``power``
    0.5); a fit of the sum of absolute residuals (eq. 9) minimises ``Σ s_i |r_i|`` when it is scaled by ``s_i``
    (``power`` 1). A weight of 2 is then the row given twice, 0 the row left out (its zero row stays).

    Parameters
    ----------
    w : (M, p) array
    tau : (M,) or (N, n_dof) array [N·m]
    sample_weight : (M,) or (N, n_dof) array, or None
        One weight ≥ 0 per row of ``W`` (or per torque, shaped as ``tau``); None: ``w, tau`` returned as given.
    power : float
        0.5 for a squared loss, 1 for an absolute one.

    Returns
    -------
    w : (M, p) array
    tau : array shaped as given

    Raises
    ------
    ShapeError
        Weights of another shape than one per row, or weights that are negative, NaN or infinite.
    """
    if sample_weight is None:
        return w, tau
    w = np.asarray(w, dtype=np.float64)
    tau = np.asarray(tau, dtype=np.float64)
    s = np.asarray(sample_weight, dtype=np.float64)
    if w.ndim != 2 or s.size != w.shape[0] or s.shape not in ((w.shape[0],), tau.shape):
        raise ShapeError(f"sample_weight: expected one weight per row of W, shape ({w.shape[0] if w.ndim == 2 else '?'},) "
                         f"or {tau.shape} as tau, got {s.shape}")
    s = s.reshape(-1)
    if not np.all(np.isfinite(s)) or np.any(s < 0):
        raise ShapeError("sample_weight: expected finite weights >= 0, got negative, NaN or infinite ones")
    factor = np.sqrt(s) if power == 0.5 else s**power
    return w * factor[:, None], (tau.reshape(-1) * factor).reshape(tau.shape)


def paper_objective(residual: np.ndarray, n_dof: int, weights: np.ndarray | None = None) -> np.ndarray:
    """Objective ``F`` of eq. 9: ``(1/N) sum_i sum_j delta_j |tau_ji - tau_pji|``.

    Parameters
    ----------
    residual : (N*n_dof,) or (N*n_dof, K) array
        Measured minus predicted torques, rows ordered sample-major (row ``k·n_dof + j``).
    n_dof : int
    weights : (n_dof,) array, optional
        ``delta_j`` in [0, 1] (default 1).

    Returns
    -------
    float or (K,) array [N·m]
    """
    r = np.abs(np.asarray(residual, dtype=float))
    n_s = r.shape[0] // n_dof
    r = r.reshape((n_s, n_dof) + r.shape[1:])
    d = np.ones(n_dof) if weights is None else np.asarray(weights, dtype=float)
    return np.tensordot(d, r.sum(axis=0), axes=(0, 0)) / n_s


def infer_n_dof(n_dof: int | None, tau) -> int:
    """Joints per sample: ``n_dof`` when given, else the second axis of ``tau`` given as (N, n_dof).

    Parameters
    ----------
    n_dof : int or None
    tau : array

    Returns
    -------
    int

    Raises
    ------
    ShapeError
        Neither says it.
    """
    if n_dof is not None:
        return int(n_dof)
    shape = np.shape(tau)
    if len(shape) == 2:
        return int(shape[1])
    raise ShapeError(f"cannot tell the joints of tau with shape {shape}: pass tau as (N, n_dof) or set n_dof")


class LinearAbsoluteObjective:
    """Eq. 9 on ``(W, tau)`` as a function of the parameters, ``F(x)`` for ``x`` (p,) or (p, K), with the
    coordinate-move interface of :func:`dynid.optim.bee_colony.minimize_bee_colony`: the residual of a candidate that
    differs in coordinate ``j`` by ``delta`` is ``r - delta·W[:, j]``, one fused pass (numba) instead of the product
    with all of ``W``.

    Parameters
    ----------
    w : (M, p) array
        Observation matrix.
    tau : (M,) array [N·m]
    n_dof : int
        Joints per sample.
    weights : (n_dof,) array, optional
        ``delta_j`` of eq. 9 (default 1).
    """

    def __init__(self, w: np.ndarray, tau: np.ndarray, n_dof: int, weights=None):
        self.w = w
        self.columns = np.asfortranarray(w)
        self.tau = tau
        self.n_dof = n_dof
        self.weights = weights
        d = np.ones(n_dof) if weights is None else np.asarray(weights, dtype=float)
        self.row_weights = np.tile(d, w.shape[0] // n_dof) / (w.shape[0] // n_dof)

    BLOCK = 1024
    """Rows per block of a population's evaluation: the block's residuals (BLOCK × K) stay in cache."""

    def __call__(self, x):
        x = np.asarray(x, dtype=float)
        if x.ndim == 1:
            return paper_objective(self.tau - self.w @ x, self.n_dof, self.weights)
        # A population (p, K): one pass over W in row blocks; each block's predictions (BLAS) are turned into
        # weighted absolute residuals and summed in one compiled pass while they are in cache, instead of an
        # (M, K) residual matrix written and read again three times (DE, PSO).
        from ._objective_kernel import add_absolute_residual_sums

        m, k = self.w.shape[0], x.shape[1]
        x = np.ascontiguousarray(x)
        out = np.zeros(k)
        buf = np.empty((min(self.BLOCK, m), k))
        for start in range(0, m, self.BLOCK):
            stop = min(start + self.BLOCK, m)
            b = buf[:stop - start]
            np.matmul(self.w[start:stop], x, out=b)
            add_absolute_residual_sums(self.tau[start:stop], b, self.row_weights[start:stop], out)
        return out

    def start(self, x) -> tuple[float, np.ndarray]:
        """F and the residual of a starting point.

        Parameters
        ----------
        x : (p,) array

        Returns
        -------
        f : float [N·m]
        r : (M,) array
            ``tau - W x``.
        """
        r = self.tau - self.w @ np.asarray(x, dtype=float)
        return float(self.row_weights @ np.abs(r)), r

    def move(self, r, j: int, delta: float) -> tuple[float, ShiftedResidual]:
        """F and the residual of a candidate that differs from the one of residual ``r`` in coordinate ``j`` by
        ``delta``. F is summed without writing the new residual: a search keeps most candidates' residuals never
        (a greedy selection rejects them), so it is written only when a move starts from it
        (:class:`ShiftedResidual`); the numbers are those of writing it first.

        Parameters
        ----------
        r : (M,) array or ShiftedResidual
            The current candidate's residual.
        j : int
        delta : float

        Returns
        -------
        f : float [N·m]
        r_new : ShiftedResidual
        """
        from ._objective_kernel import shifted_absolute_total

        base = r.array() if isinstance(r, ShiftedResidual) else r
        column = self.columns[:, j]
        return float(shifted_absolute_total(base, column, float(delta), self.row_weights)), ShiftedResidual(base, column, float(delta))


class ShiftedResidual:
    """``r - delta·column``, written on first use (:meth:`LinearAbsoluteObjective.move`).

    Parameters
    ----------
    r : (M,) array
    column : (M,) array
    delta : float
    """

    __slots__ = ("_r", "_column", "_delta", "_array")

    def __init__(self, r: np.ndarray, column: np.ndarray, delta: float):
        self._r: np.ndarray | None = r
        self._column: np.ndarray | None = column
        self._delta = delta
        self._array: np.ndarray | None = None

    def array(self) -> np.ndarray:
        """The residual (written once, then kept).

        Returns
        -------
        (M,) array
        """
        if self._array is None:
            from ._objective_kernel import shifted

            assert self._r is not None and self._column is not None
            out = np.empty_like(self._r)
            shifted(self._r, self._column, self._delta, out)
            self._array, self._r, self._column = out, None, None  # the candidate's own residual: the inputs let go
        return self._array


class HyperParameters:
    """Mixin: ``get_params`` / ``set_params`` over the constructor's parameters (scikit-learn's contract).

    A class stores each constructor parameter under its own name. ``PARAMETER_KINDS`` says which of its
    constructor's parameters count (:class:`inspect.Parameter` kinds); by default every named one.
    """

    PARAMETER_KINDS = frozenset({inspect.Parameter.POSITIONAL_OR_KEYWORD, inspect.Parameter.KEYWORD_ONLY})

    CONSTRAINTS: dict[str, tuple[str, float | None, float | None]] = {}
    """Name -> ``(kind, low, high)`` (scikit-learn's ``_parameter_constraints``): ``"int"`` an integer (not a bool, not a
    float like 6.0), ``"real"`` a finite number, within ``[low, high]`` (None: unbounded). Checked where the object is
    built and by :meth:`set_params`; a parameter whose default is None may be None."""

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        init = cls.__dict__.get("__init__")
        if init is None:
            return

        @functools.wraps(init)
        def checked(self, *args, **kw):
            init(self, *args, **kw)
            self.check_params()

        cls.__init__ = checked  # type: ignore[method-assign]

    def check_params(self) -> None:
        """Refuse a parameter outside :attr:`CONSTRAINTS` in one line naming the class, the parameter and what was
        expected.

        Raises
        ------
        ConfigError
            ``field`` the parameter's name.
        """
        defaults = {p.name: p.default for p in inspect.signature(type(self).__init__).parameters.values()}
        for name, (kind, low, high) in self.CONSTRAINTS.items():
            if not hasattr(self, name) or (getattr(self, name) is None and defaults.get(name) is None):
                continue
            value = getattr(self, name)
            number = isinstance(value, numbers.Real) and not isinstance(value, bool)
            ok = number and (isinstance(value, numbers.Integral) if kind == "int" else math.isfinite(value))
            if ok and (low is None or value >= low) and (high is None or value <= high):
                continue
            what = "an integer" if kind == "int" else "a finite number"
            span = (f" from {low:g} to {high:g}" if low is not None and high is not None else
                    f" of at least {low:g}" if low is not None else f" of at most {high:g}" if high is not None else "")
            raise ConfigError(f"{type(self).__name__}: {name}: expected {what}{span}, got {value!r}", field=name)

    def get_params(self, deep: bool = True) -> dict:
        """The constructor's parameters and their values.

        Parameters
        ----------
        deep : bool
            Unused (no nested estimators); scikit-learn's signature.

        Returns
        -------
        dict
            Name -> value, in the constructor's order.
        """
        parameters = list(inspect.signature(type(self).__init__).parameters.values())[1:]  # not ``self``
        return {p.name: getattr(self, p.name) for p in parameters if p.kind in self.PARAMETER_KINDS}

    def set_params(self, **params) -> Self:
        """Set constructor parameters by name.

        Parameters
        ----------
        **params
            Name -> value.

        Returns
        -------
        self

        Raises
        ------
        ValueError
            An unknown name (the message names the class and the known names).
        """
        known = self.get_params()
        for name, value in params.items():
            if name not in known:
                raise ValueError(f"{type(self).__name__} has no parameter {name!r}; expected one of {sorted(known)}")
            setattr(self, name, value)
        self.check_params()
        return self

    def __repr__(self) -> str:
        """scikit-learn's: the class and the parameters that differ from the constructor's defaults, an array by its
        shape (``BeeColonyEstimator(colony_size=60)``).

        Returns
        -------
        str
        """
        defaults = {p.name: p.default for p in inspect.signature(type(self).__init__).parameters.values()}
        shown = [f"{name}={short_value(value)}" for name, value in self.get_params().items()
                 if not _is_default(value, defaults.get(name, inspect.Parameter.empty))]
        return f"{type(self).__name__}({', '.join(shown)})"


def _is_default(value, default) -> bool:
    """Whether a parameter's value is its default (an array never is, unless it is the default object)."""
    if value is default:
        return True
    if hasattr(value, "shape") or hasattr(default, "shape"):
        return False
    try:
        return bool(value == default)
    except (TypeError, ValueError):
        return False


class Estimator(HyperParameters):
    """Base class (scikit-learn contract): ``fit(W, tau, sample_weight=None, *, problem=None)`` sets ``params_`` and
    returns self; ``predict(W)``; ``score``; ``get_params``, ``set_params`` and ``clone``.

    Subclasses store only keyword hyper-parameters in ``__init__`` (budgets, the prior's kind and weight, ``rng``) and
    set learned attributes ending in ``_``. What depends on the data comes to ``fit`` as ``problem``
    (:class:`~dynid.estimators.problem.FitData`: the joints per sample, the search box, eq. 9's weights, the prior, the
    parameter layout); each subclass names the fields it reads in :attr:`PROBLEM_FIELDS` and keeps them as
    ``problem_``. The joints per sample are inferred from ``tau`` given as (N, n_dof) when the problem does not state
    them (attribute ``n_dof_``).
    """

    params_: np.ndarray
    PARAMETER_KINDS = frozenset({inspect.Parameter.KEYWORD_ONLY})
    """Only the keyword hyper-parameters are parameters (a plugin's positional arguments are not)."""
    PROBLEM_FIELDS: tuple[str, ...] = ()
    """The fields of :class:`~dynid.estimators.problem.FitData` this estimator reads in ``fit`` (``problem=``)."""

    def __init_subclass__(cls, **kwargs):
        """A subclass's constructor given what is the problem's since 0.2.0 (``n_dof``, ``bounds``, ``prior``, …) says
        in one line where it goes, unless the subclass takes it (a plugin written before)."""
        super().__init_subclass__(**kwargs)
        init = cls.__dict__.get("__init__")
        if init is None:
            return
        parameters = inspect.signature(init).parameters.values()
        if any(p.kind is inspect.Parameter.VAR_KEYWORD for p in parameters):
            return  # a plugin's constructor that takes any keyword takes these too
        taken = {p.name for p in parameters}

        @functools.wraps(init)
        def checked(self, *args, **given):
            moved = sorted(given.keys() & MOVED_TO_PROBLEM - taken)
            if moved:
                name = "layout" if moved[0] in ("links", "nonnegative") else moved[0]
                raise TypeError(f"{type(self).__name__}({moved[0]}=...): what depends on the data comes to fit now, "
                                f"fit(W, tau, problem=dynid.estimators.FitData({name}=...))")
            init(self, *args, **given)

        cls.__init__ = checked  # type: ignore[method-assign]

    def take_problem(self, problem) -> FitData:
        """Keep the fields of ``problem`` this estimator reads (:attr:`PROBLEM_FIELDS`) as ``problem_`` and return it.

        Parameters
        ----------
        problem : FitData or None
            None: nothing stated (every field None).

        Returns
        -------
        FitData

        Raises
        ------
        TypeError
            ``problem`` is not a FitData.
        """
        if problem is not None and not isinstance(problem, FitData):
            raise TypeError(f"{type(self).__name__}.fit: problem is a dynid.estimators.FitData (the joints, search "
                            f"box, weights, prior and layout), got {type(problem).__name__}")
        kept = {} if problem is None else {name: getattr(problem, name) for name in self.PROBLEM_FIELDS}
        self.problem_ = FitData(**kept)
        return self.problem_

    def clone(self) -> Estimator:
        """An unfitted estimator with the same hyper-parameters.

        Returns
        -------
        Estimator
        """
        return type(self)(**self.get_params())

    loss_power = 0.5
    """How ``sample_weight`` scales the rows (:func:`weighted_rows`): 0.5 for a squared loss, 1 for eq. 9's absolute one."""

    def fit(self, w, tau, sample_weight=None, *, problem=None):  # pragma: no cover - abstract
        """Fit the parameters to an observation matrix and torques (each estimator's own method).

        Parameters
        ----------
        w : (M, p) array
            Observation matrix, row ``k·n_dof + j`` = sample ``k``, joint ``j``.
        tau : (M,) or (N, n_dof) array [N·m]
        sample_weight : (M,) or (N, n_dof) array, optional
            One weight ≥ 0 per row (:func:`weighted_rows`): 2 counts a row twice, 0 leaves it out.
        problem : FitData, optional
            What the estimator sees of the problem beside the rows (its :attr:`PROBLEM_FIELDS`; kept as ``problem_``).

        Returns
        -------
        self
        """
        raise NotImplementedError

    def predict(self, w) -> np.ndarray:
        """Predicted torques ``W @ params_``.

        Parameters
        ----------
        w : (M, p) array

        Returns
        -------
        (M,) array [N·m]

        Raises
        ------
        NotFittedError
            Not fitted yet (an ``AttributeError`` and a ``ValueError``, as scikit-learn's).
        """
        if not hasattr(self, "params_"):
            raise NotFittedError(f"{type(self).__name__} is not fitted yet: call fit(W, tau) first")
        return np.asarray(w, dtype=float) @ self.params_

    def summary(self) -> str:
        """The estimator and what it learned: its repr (the hyper-parameters that differ from the defaults), then one
        line per learned attribute (those ending in ``_``: an array by its shape and range, a sequence by its length,
        the problem by the fields it read).

        Returns
        -------
        str
            Ends "not fitted yet" before :meth:`fit`.
        """
        learned = {k: v for k, v in vars(self).items() if k.endswith("_") and not k.startswith("_")}
        lines = [repr(self)] + [f"  {k}: {_described(v)}" for k, v in learned.items()]
        return "\n".join(lines if learned else lines + ["  not fitted yet: call fit(W, tau)"])

    def score(self, w, tau) -> float:
        """Coefficient of determination R² of the prediction (1: perfect).

        Parameters
        ----------
        w : (M, p) array
        tau : (M,) or (N, n_dof) array [N·m]

        Returns
        -------
        float
        """
        w, tau = check_observations(w, tau)
        res = tau - self.predict(w)
        return 1.0 - float(res @ res) / float(((tau - tau.mean()) ** 2).sum())


def _described(value) -> str:
    """A learned attribute in :meth:`Estimator.summary`: an array of numbers by its shape and range, a number, a string
    or a sequence as a record's repr shows it (:func:`dynid._util.reprs.short_value`), anything else by its type."""
    if isinstance(value, np.ndarray) and value.dtype.kind in "fiu":
        finite = value[np.isfinite(value)]
        return f"array {value.shape}" + (f" from {finite.min():.4g} to {finite.max():.4g}" if finite.size else "")
    if value is None or isinstance(value, (bool, int, float, np.number, str, list, tuple, np.ndarray)):
        return short_value(value)
    if isinstance(value, FitData):  # the problem it was fitted on: the fields it read
        return repr(value)
    return type(value).__name__


class AccumulatingEstimator(Estimator):
    """Base of the estimators that can learn from rows given chunk by chunk (``partial_fit``), so that memory does
    not grow with the log: the rows of each joint are folded into a triangular factor
    (:class:`dynid.estimators.accumulate.LeastSquaresAccumulator`), and the solution is computed from the factors
    when a learned attribute is first read (or :meth:`solve` is called) after the last ``partial_fit``.

    Subclasses implement ``_solve(accumulator)``, which sets the learned attributes from the rows and ``problem_``
    (the problem given to the first ``partial_fit``, or to :meth:`solve` when it changed after the rows). The joints per
    sample are the problem's ``n_dof``, else inferred from ``tau`` given as (N, n_dof), else 1.
    """

    PROBLEM_FIELDS: tuple[str, ...] = ("n_dof",)
    needs_joints = False
    """Whether the estimator weighs the joints' rows apart (then ``n_dof`` or ``tau`` as (N, n_dof) is required)."""

    def partial_fit(self, w, tau, mask=None, *, names=None, sample_weight=None, problem=None) -> AccumulatingEstimator:
        """Fold rows into the estimate.

        Parameters
        ----------
        w : (M, p) array
            Observation rows, row ``k·n_dof + j`` = sample ``k``, joint ``j``.
        tau : (M,) or (N, n_dof) array
            Torques [N·m].
        mask : (M,) bool array, optional
            Rows to use (e.g. those fast enough).
        names : sequence of str, optional
            The parameters' names (said when the data do not excite some of them).
        sample_weight : (M,) or (N, n_dof) array, optional
            One weight ≥ 0 per row of the squared loss (:func:`weighted_rows`).
        problem : FitData, optional
            What the estimator reads of the problem (:attr:`PROBLEM_FIELDS`), kept from the first call that gives it.

        Returns
        -------
        self

        Raises
        ------
        ShapeError
            Wrong shapes, a number of parameters that changed between calls, or non-finite values.
        """
        w, tau = weighted_rows(w, tau, sample_weight, self.loss_power)
        w = np.asarray(w, dtype=np.float64)
        if w.ndim != 2:
            raise ShapeError(f"expected W with shape (N*n_dof, n_params), got {w.shape}")
        if problem is not None or "problem_" not in self.__dict__:
            self.take_problem(problem)
        acc = self.__dict__.get("accumulator_")
        if acc is None:
            shape, stated = np.shape(tau), self.problem_.n_dof
            if stated is not None or len(shape) == 2 or not self.needs_joints:
                n = stated if stated is not None else (shape[1] if len(shape) == 2 else 1)
            else:
                n = infer_n_dof(None, tau)  # raises: the rows' joints are needed
            acc = LeastSquaresAccumulator(w.shape[1], n)
            self.accumulator_ = acc
            self.n_dof_ = int(n)
        self._forget()
        if names is not None:
            self.names_in_ = tuple(names)
        acc.add(w, tau, mask)
        return self

    def fit(self, w, tau, sample_weight=None, *, problem=None):
        """Fit on all rows at once: ``partial_fit`` on a fresh accumulator, then :meth:`solve`.

        Parameters
        ----------
        w : (M, p) array
        tau : (M,) or (N, n_dof) array [N·m]
        sample_weight : (M,) or (N, n_dof) array, optional
            One weight ≥ 0 per row of the squared loss (:func:`weighted_rows`).
        problem : FitData, optional
            What the estimator reads of the problem (:attr:`PROBLEM_FIELDS`).

        Returns
        -------
        self
        """
        w, tau = weighted_rows(w, tau, sample_weight, self.loss_power)
        problem = self.take_problem(problem)
        w, tau_flat = check_observations(w, tau, problem.n_dof)
        self.__dict__.pop("accumulator_", None)
        self.partial_fit(w, tau if np.ndim(tau) == 2 else tau_flat, problem=problem)
        return self.solve()

    def solve(self, *, problem=None) -> AccumulatingEstimator:
        """Compute the learned attributes from the rows folded in so far.

        Parameters
        ----------
        problem : FitData, optional
            The problem as it stands after the rows (e.g. the joint weights of the least-squares reference), in place of
            the one the rows came with.

        Returns
        -------
        self

        Raises
        ------
        AttributeError
            No rows were given yet.
        """
        acc = self.__dict__.get("accumulator_")
        if acc is None:
            raise AttributeError(f"{type(self).__name__} has no rows yet: call fit or partial_fit first")
        if problem is not None:
            self.take_problem(problem)
        self._solve(acc)
        self.__dict__["_solved"] = True
        return self

    def _solve(self, acc) -> None:  # pragma: no cover - abstract
        raise NotImplementedError

    def _forget(self) -> None:
        """Drop the learned attributes of an earlier solution (new rows came)."""
        keep = {"accumulator_", "n_dof_", "names_in_", "problem_"}
        for name in [k for k in self.__dict__ if k.endswith("_") and not k.startswith("_") and k not in keep]:
            del self.__dict__[name]
        self.__dict__["_solved"] = False

    def __getattr__(self, name: str):
        # a learned attribute read after partial_fit: solve once, then it is an ordinary attribute
        if name.endswith("_") and not name.startswith("_") and not self.__dict__.get("_solved", True) \
                and "accumulator_" in self.__dict__:
            self.solve()
            if name in self.__dict__:
                return self.__dict__[name]
        raise AttributeError(f"{type(self).__name__!s} has no attribute {name!r}")


class BoxSearchEstimator(Estimator):
    """Base of the estimators that search a box for the minimum of eq. 9 (ABC, DE, PSO).

    The problem gives the box (``bounds``, (p, 2)), the joints per sample (``n_dof``, or None: inferred) and eq. 9's
    ``weights``; subclasses implement ``_search(objective, bounds)``: the minimum of eq. 9's ``F`` over the box as an
    ``OptimizeResult`` (``x``, ``fun``, ``nfev``, ``history``).
    """

    PROBLEM_FIELDS = ("n_dof", "bounds", "weights")
    loss_power = 1.0  # eq. 9: sample_weight multiplies each absolute residual

    def fit(self, w, tau, sample_weight=None, *, problem=None):
        """Search the box for the minimum of eq. 9 (each subclass's search).

        Parameters
        ----------
        w : (M, p) array
            Observation matrix, row ``k·n_dof + j`` = sample ``k``, joint ``j``.
        tau : (M,) or (N, n_dof) array [N·m]
        sample_weight : (M,) or (N, n_dof) array, optional
            One weight ≥ 0 per row of the absolute residual (eq. 9) (:func:`weighted_rows`).
        problem : FitData
            Its ``bounds`` (the search box, required), ``n_dof`` and ``weights`` (eq. 9's ``delta``, default 1).

        Returns
        -------
        self

        Raises
        ------
        ShapeError
            Wrong shapes, no box, or a box that is not (p, 2).
        """
        w, tau = weighted_rows(w, tau, sample_weight, self.loss_power)
        self.take_problem(problem)
        bounds, objective = self._objectives(w, tau)
        self._set_search_result(self._search(objective, bounds))
        return self

    def _search(self, objective, bounds):  # pragma: no cover - abstract
        raise NotImplementedError

    def _objectives(self, w, tau):
        """Checked ``bounds`` (p, 2) and eq. 9 on ``(W, tau)`` as ``F(x)`` for ``x`` (p,) or (p, K) → float or (K,)."""
        problem = self.problem_
        self.n_dof_ = infer_n_dof(problem.n_dof, tau)
        w, tau = check_observations(w, tau, self.n_dof_)
        if problem.bounds is None:
            raise ShapeError(f"{type(self).__name__}: the search box (problem=FitData(bounds=...), of shape "
                             f"({w.shape[1]}, 2)) is needed to fit (the identification pipeline builds it around the "
                             "least-squares estimate)")
        bounds = np.asarray(problem.bounds, dtype=float)
        if bounds.shape != (w.shape[1], 2):
            raise ShapeError(f"expected {type(self).__name__} bounds of shape ({w.shape[1]}, 2), got {bounds.shape}")

        return bounds, LinearAbsoluteObjective(w, tau, self.n_dof_, problem.weights)

    def _set_search_result(self, res) -> None:
        self.params_ = np.asarray(res.x, dtype=float)
        self.objective_ = float(res.fun)
        self.history_ = getattr(res, "history", None)
        self.n_evaluations_ = int(res.nfev)
        self.result_ = res

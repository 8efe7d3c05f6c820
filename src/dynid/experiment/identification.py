"""Identification of a real robot from its logs, and validation on other logs.

Recording (CSV, :mod:`dynid.io.datasets`) → zero-phase Butterworth filtering of positions, velocities
and torques → derivatives by central differences → base regressor and torques, low-pass filtered and
decimated together (Gautier's parallel decimation), chunk by chunk → optional removal of the rows of
joints moving slower than a threshold (Coulomb friction is undefined at rest) → OLS/WLS accumulated by
incremental QR (memory independent of the log's length) → validation: relative error, RMSE and
correlation coefficient (eq. 18) per joint, for dynid's parameters and each reference set.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Callable

import numpy as np

from ..conventions import unit_of
from ..dynamics.base_parameters import BaseParameters
from ..dynamics.regressor import regressor
from ..dynamics.layout import consistency_layout
from ..estimators.accumulate import LeastSquaresAccumulator, LeastSquaresSolution
from ..estimators.physically_consistent import PhysicallyConsistentLeastSquares, consistency_margin
from ..exceptions import ConfigError, DataError
from ..io.datasets import Recording
from ..io.references import ReferenceSet
from ..model.robot import Robot
from ..preprocessing.filters import butterworth_filtfilt, differentiate, parallel_decimation
from ..preprocessing.fourier_fit import fourier_fit_derivatives
from ..validation import correlation_coefficient, relative_error, rmse

METHODS = ("ols", "wls")


@dataclass(frozen=True)
class Preprocessing:
    """Preprocessing settings; ``None`` means the default for the sampling rate (:meth:`resolved`).

    Attributes
    ----------
    order : int
        Order of the Butterworth filters.
    position_cutoff, velocity_cutoff, torque_cutoff : float or None [Hz]
        Zero-phase low-pass cutoffs; 0 switches a filter off. Defaults: ``min(0.15·f_N, 20 Hz)`` for
        positions and velocities, ``min(0.2·f_N, 25 Hz)`` for torques (``f_N`` = Nyquist frequency).
    decimation : int or None
        Parallel decimation factor. Default: ``max(1, rate // (10·velocity_cutoff))``.
    min_speed : float or tuple [rad/s]
        Rows of joint ``j`` where ``|dq_j| < min_speed_j`` are left out of the estimation (0: keep all).
    trim : float or None [s]
        Removed at both ends after filtering, where the filters' edge effects corrupt the derivatives.
        Default: ``3 / cutoff`` of the slowest filter the derivatives go through (positions, and
        velocities when they are measured), 0 when those filters are off.
    chunk : int
        Samples per chunk of the regressor.
    fourier : (omega_f, n_harmonics) or None
        When the robot ran a known periodic excitation (eq. 14, e.g. from ``dynid excite``): positions,
        velocities and accelerations come from a least-squares fit of the measured positions on its
        harmonics (paper §3.3; :func:`dynid.preprocessing.fourier_fit_derivatives`) instead of filtering
        and differentiating; torques are still low-pass filtered.
    """

    order: int = 4
    position_cutoff: float | None = None
    velocity_cutoff: float | None = None
    torque_cutoff: float | None = None
    decimation: int | None = None
    min_speed: float | tuple = 0.0
    trim: float | None = None
    chunk: int = 20_000
    fourier: tuple[float, int] | None = None

    def resolved(self, rate: float, measured_velocity: bool = True) -> "Preprocessing":
        nyq = rate / 2
        vel = self.velocity_cutoff if self.velocity_cutoff is not None else min(0.15 * nyq, 20.0)
        pos = self.position_cutoff if self.position_cutoff is not None else vel
        tq = self.torque_cutoff if self.torque_cutoff is not None else min(0.2 * nyq, 25.0)
        dec = self.decimation if self.decimation is not None else max(1, int(rate // (10 * vel)) if vel > 0 else 1)
        on = [c for c in ((pos, vel) if measured_velocity else (pos,)) if c > 0]
        trim = self.trim if self.trim is not None else (3.0 / min(on) if on else 0.0)
        return replace(self, position_cutoff=float(pos), velocity_cutoff=float(vel), torque_cutoff=float(tq),
                       decimation=int(dec), trim=float(trim))

    def to_dict(self) -> dict:
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in self.__dict__.items()}


@dataclass(frozen=True)
class PreparedData:
    """Filtered joint signals on a uniform grid, ready for the regressor (N, n_dof) each."""

    name: str
    t: np.ndarray
    q: np.ndarray
    dq: np.ndarray
    ddq: np.ndarray
    tau: np.ndarray
    rate: float
    settings: Preprocessing
    warnings: tuple[str, ...] = ()


def prepare(recording: Recording, settings: Preprocessing) -> PreparedData:
    """Filter and differentiate a recording (positions, velocities: measured or from positions;
    accelerations: derivative of the filtered velocities).

    Raises
    ------
    ConfigError
        A cutoff at or above the Nyquist frequency.
    DataError
        Too few samples left after trimming.
    """
    s = settings.resolved(recording.rate, recording.dq is not None)
    rate = recording.rate

    def lowpass(x, cutoff, what):
        if cutoff <= 0:
            return x
        try:
            return butterworth_filtfilt(x, rate, cutoff, s.order)
        except ConfigError as exc:
            raise ConfigError(f"preprocessing.{what}_cutoff: {exc}") from None

    if recording.n_samples < 3 * (2 * s.order + 1) + 1:
        raise DataError(f"{recording.name}: {recording.n_samples} samples are too few to filter")
    if s.fourier is not None:
        q, dq, ddq, _ = fourier_fit_derivatives(recording.t, recording.q, *s.fourier)
    else:
        q = lowpass(recording.q, s.position_cutoff, "position")
        dq = lowpass(recording.dq, s.velocity_cutoff, "velocity") if recording.dq is not None else differentiate(q, rate)
        ddq = differentiate(dq, rate)
    tau = lowpass(recording.tau, s.torque_cutoff, "torque")
    t = recording.t
    cut = int(round(s.trim * rate))
    if cut:
        if 2 * cut >= t.shape[0] - 2:
            raise DataError(f"{recording.name}: trim = {s.trim} s leaves no samples of the {t[-1]:.3f} s recording")
        t, q, dq, ddq, tau = (x[cut:-cut] for x in (t, q, dq, ddq, tau))
    return PreparedData(recording.name, t, q, dq, ddq, tau, rate, s, recording.warnings)


def _min_speed(settings: Preprocessing, n: int) -> np.ndarray:
    v = np.asarray(settings.min_speed, dtype=float)
    if v.ndim == 0:
        v = np.full(n, float(v))
    if v.shape != (n,) or np.any(v < 0):
        raise ConfigError(f"preprocessing.min_speed: expected a non-negative number or {n} of them, got {settings.min_speed!r}")
    return v


def base_chunks(robot: Robot, base: BaseParameters, data: PreparedData,
                progress: Callable[[int, int], None] | None = None, standard: bool = False):
    """Parallel-decimated base (or standard) regressor and torques, chunk by chunk.

    Yields
    ------
    index : (M,) int array
        Sample indices kept (every ``decimation``-th).
    y : (M, n_dof, n_base) array, or (M, n_dof, n_params) with ``standard``
        (the base regressor is then ``base.base_observation(y)``: decimation commutes with selecting columns).
    tau : (M, n_dof) array [N·m]
    keep : (M, n_dof) bool array
        Rows fast enough for the estimation (``|dq_j| >= min_speed_j``).
    """
    n = robot.n_dof
    nb = robot.n_params if standard else base.n_base
    s = data.settings
    vmin = _min_speed(s, n)
    n_s = data.t.shape[0]

    def block(a, b):
        y = regressor(robot, data.q[a:b], data.dq[a:b], data.ddq[a:b])
        y = y if standard else base.base_observation(y)
        return np.concatenate([y.reshape(b - a, n * nb), data.tau[a:b]], axis=1)

    for index, values in parallel_decimation(block, n_s, data.rate, s.decimation, s.order, s.chunk):
        y = values[:, : n * nb].reshape(-1, n, nb)
        keep = np.abs(data.dq[index]) >= vmin
        if progress is not None:
            progress(int(index[-1]) + 1, n_s)
        yield index, y, values[:, n * nb:].copy(), keep  # a copy: a view would keep the whole block alive


@dataclass(frozen=True)
class TorqueComparison:
    """Measured and predicted torques of one dataset (decimated), with per-joint metrics.

    Attributes
    ----------
    name : str
    t : (M,) array [s]
    measured : (M, n_dof) array [N·m]
    predicted : dict label -> (M, n_dof) array
    """

    name: str
    t: np.ndarray
    measured: np.ndarray
    predicted: dict

    def metrics(self) -> dict:
        """label -> {relative_error [%], rmse [N·m], correlation (eq. 18)}, each (n_dof,)."""
        return {label: {"relative_error": relative_error(self.measured, p), "rmse": rmse(self.measured, p),
                        "correlation": correlation_coefficient(self.measured, p)}
                for label, p in self.predicted.items()}

    def to_dict(self) -> dict:
        return {"name": self.name, "n_samples": int(self.t.shape[0]),
                "rms_torque": np.sqrt((self.measured**2).mean(axis=0)), "metrics": self.metrics()}


def compare_torques(robot: Robot, base: BaseParameters, data: PreparedData, parameter_sets: dict,
                    progress=None) -> TorqueComparison:
    """Predict the torques of ``data`` with each base parameter vector of ``parameter_sets`` (label ->
    (n_base,)), on the same parallel-decimated samples as the estimation."""
    ts, meas, preds = [], [], {k: [] for k in parameter_sets}
    for index, y, tau, _ in base_chunks(robot, base, data, progress):
        ts.append(data.t[index])
        meas.append(tau)
        for label, beta in parameter_sets.items():
            preds[label].append(y @ beta)
    return TorqueComparison(data.name, np.concatenate(ts), np.concatenate(meas),
                            {k: np.concatenate(v) for k, v in preds.items()})


def estimate_label(method: str) -> str:
    """How dynid's estimate is labelled in tables, figures and JSON: ``"dynid WLS"``."""
    return f"dynid {method.upper()}"


SDP_LABEL = "dynid SDP"
"""Label of the physically consistent estimate."""


def parameter_sets(method: str, params: np.ndarray, references=(), consistent: np.ndarray | None = None) -> dict:
    """label -> base parameter vector: dynid's estimate, its physically consistent estimate if any, then each
    reference set."""
    sdp = {} if consistent is None else {SDP_LABEL: consistent}
    return {estimate_label(method): params, **sdp, **{r.name: r.beta for r in references}}


@dataclass(frozen=True)
class ConsistentEstimate:
    """Physically consistent least squares on a real log (same row weights as the OLS/WLS estimate).

    Attributes
    ----------
    standard : (n_params,) array
        Standard parameters (each link's pseudo-inertia ⪰ 0, friction and rotor inertias ≥ 0).
    base : (n_base,) array
    pseudo_inertia_min_eig : (n_dof,) array
    prior : str
        What the unidentifiable directions were pulled towards.
    """

    standard: np.ndarray
    base: np.ndarray
    pseudo_inertia_min_eig: np.ndarray
    prior: str = "the robot model's nominal parameters"


@dataclass(frozen=True)
class IdentificationResult:
    """Identified base parameters with their uncertainty, fit, validations and reference sets.

    Attributes
    ----------
    robot : str
    base : BaseParameters
    method : str
        "ols" or "wls".
    solution : LeastSquaresSolution
        Parameters, covariance, std, relative std [%], condition number of the (weighted) base
        observation matrix.
    joint_std : (n_dof,) array [N·m]
        Residual standard deviation of each joint (OLS residuals; the WLS weights are their inverses).
    references : tuple of ReferenceSet
    fit : TorqueComparison
        On the identification data.
    validations : tuple of TorqueComparison
    n_rows : int
        Equations used (after decimation and the speed threshold).
    settings : dict
    warnings : tuple of str
    consistent : ConsistentEstimate or None
        The physically consistent estimate, when asked for.
    consistency : dict
        label -> consistency margin of each parameter set (``>= 0``: some mass distribution with non-negative
        friction and rotor inertias has these base parameters; :func:`dynid.estimators.consistency_margin`).
    """

    robot: str
    base: BaseParameters
    method: str
    solution: LeastSquaresSolution
    joint_std: np.ndarray
    references: tuple[ReferenceSet, ...]
    fit: TorqueComparison
    validations: tuple[TorqueComparison, ...] = ()
    n_rows: int = 0
    settings: dict = field(default_factory=dict)
    warnings: tuple[str, ...] = ()
    consistent: ConsistentEstimate | None = None
    consistency: dict = field(default_factory=dict)

    @property
    def label(self) -> str:
        return estimate_label(self.method)

    def parameter_sets(self) -> dict:
        """label -> base parameter vector: dynid's estimate(s), then each reference set."""
        return parameter_sets(self.method, self.solution.params, self.references,
                              None if self.consistent is None else self.consistent.base)

    def reference_agreement(self, ref: ReferenceSet) -> dict:
        """Differences to a reference that states relative standard deviations: ``z = |Δ| / σ_ref``."""
        sigma = np.abs(ref.beta) * ref.relative_std / 100.0
        diff = self.solution.params - ref.beta
        with np.errstate(divide="ignore", invalid="ignore"):
            z = np.abs(diff) / sigma
        ok = np.isfinite(z)
        return {"z": z, "within_1_sigma": int(np.sum(z[ok] <= 1)), "within_2_sigma": int(np.sum(z[ok] <= 2)),
                "within_3_sigma": int(np.sum(z[ok] <= 3)), "compared": int(ok.sum())}

    def to_dict(self) -> dict:
        sol = self.solution
        params = [{"name": n, "value": float(v), "std": float(s), "relative_std_percent": float(r), "unit": unit_of(n),
                   "expression": e.split(" = ", 1)[1]}
                  for n, v, s, r, e in zip(self.base.names, sol.params, sol.params_std, sol.relative_std, self.base.expressions)]
        refs = []
        for r in self.references:
            entry = {"name": r.name, "source": r.source, "values": dict(zip(self.base.names, r.beta.tolist()))}
            if r.relative_std is not None:
                agree = self.reference_agreement(r)
                entry["agreement"] = {k: v for k, v in agree.items() if k != "z"}
                entry["z"] = dict(zip(self.base.names, agree["z"].tolist()))
            refs.append(entry)
        return {
            "robot": self.robot, "method": self.method, "base_parameters": params,
            "condition_number": sol.condition_number, "residual_std": sol.residual_std,
            "joint_residual_std": self.joint_std, "n_rows": self.n_rows, "settings": self.settings,
            "identification": self.fit.to_dict(), "validation": [v.to_dict() for v in self.validations],
            "references": refs, "warnings": list(self.warnings),
            "consistency_margin": self.consistency,
            **({} if self.consistent is None else {"physically_consistent": {
                "label": SDP_LABEL, "prior": self.consistent.prior,
                "values": dict(zip(self.base.names, self.consistent.base.tolist())),
                "standard_values": dict(zip(self.base.standard_names, self.consistent.standard.tolist())),
                "pseudo_inertia_min_eig": self.consistent.pseudo_inertia_min_eig.tolist()}}),
        }


def identify(robot: Robot, base: BaseParameters, data: PreparedData, method: str = "wls",
             references: tuple[ReferenceSet, ...] = (), progress=None, physically_consistent: bool = False) -> IdentificationResult:
    """Estimate the base parameters from one prepared recording by OLS or WLS (chunked), and with
    ``physically_consistent`` also by physically consistent least squares over the standard parameters
    (same row weights; prior: the robot model's nominal parameters). Every parameter set gets its
    consistency margin.

    Raises
    ------
    ConfigError
        Unknown method.
    IdentifiabilityError
        Too few rows or a rank-deficient base observation matrix (the log does not excite every
        base parameter).
    """
    if method not in METHODS:
        raise ConfigError(f"estimation.method: expected one of {', '.join(METHODS)}, got {method!r}")
    n = robot.n_dof
    acc = LeastSquaresAccumulator(base.n_base, n)
    acc_std = LeastSquaresAccumulator(robot.n_params, n) if physically_consistent else None
    for _, y, tau, keep in base_chunks(robot, base, data, progress, standard=physically_consistent):
        if acc_std is not None:
            acc_std.add(y.reshape(-1, robot.n_params), tau.reshape(-1), keep.reshape(-1))
            y = base.base_observation(y)
        acc.add(y.reshape(-1, base.n_base), tau.reshape(-1), keep.reshape(-1))
    ols = acc.solve()
    joint_std = acc.joint_residual_std(ols.params)
    row_weights = None if method == "ols" else 1.0 / np.where(joint_std > 0, joint_std, 1.0)
    sol = ols if method == "ols" else acc.solve(row_weights)
    consistent = None if acc_std is None else _consistent_estimate(robot, base, acc_std, row_weights)
    warnings = list(data.warnings)
    dropped = 1.0 - acc.rows.sum() / (n * len(range(0, data.t.shape[0], data.settings.decimation)))
    if dropped > 0.5:
        warnings.append(f"{data.name}: {100 * dropped:.0f}% of the rows are below preprocessing.min_speed and were left out")
    for r in references:
        warnings.extend(r.warnings)
    sets = parameter_sets(method, sol.params, references, None if consistent is None else consistent.base)
    links, nonneg = consistency_layout(robot)
    margins = {label: consistency_margin(base.regrouping, beta, links, nonneg) for label, beta in sets.items()}
    fit = compare_torques(robot, base, data, sets)
    return IdentificationResult(robot.name, base, method, sol, joint_std, tuple(references), fit, n_rows=int(acc.rows.sum()),
                                settings={"preprocessing": data.settings.to_dict(), "rate": data.rate}, warnings=tuple(warnings),
                                consistent=consistent, consistency=margins)


def _consistent_estimate(robot: Robot, base: BaseParameters, acc: LeastSquaresAccumulator, row_weights) -> ConsistentEstimate:
    """The SDP on the accumulated triangular factor of the standard problem (weighted like the estimate)."""
    p = robot.n_params
    reduced = acc.reduced(row_weights)
    links, nonneg = consistency_layout(robot)
    est = PhysicallyConsistentLeastSquares(links=links, nonnegative=nonneg, prior=robot.standard_parameters())
    est.fit(reduced[:, :p], reduced[:, p])
    return ConsistentEstimate(est.params_, base.base_from_standard(est.params_), est.pseudo_inertia_min_eig_)

"""Monte Carlo study of the estimators in closed loop, on the noise grid of Leboutet et al. (2021).

For every cell of the grid (encoder noise × torque noise) and realisation, the robot is simulated under its own
controller (:func:`dynid.simulation.closed_loop.simulate_closed_loop`: a PID tuned on the mass matrix with the
nominal model's feed-forward, :meth:`~dynid.simulation.closed_loop.Controller.for_robot`), the loop seeing the noisy
positions; the log (measured positions, commanded torques plus noise) is prepared as ``dynid identify`` prepares a
real one, given the one thing known of its drives: each command is held over the control period, so the logged
torques lead the motion by half a period (:func:`zero_order_hold_delay`, the ``torque_delay`` setting); and every
estimator is fitted on it by :class:`dynid.identification.pipeline.IdentificationPipeline`, as ``dynid identify`` fits
them: the open-loop ones (OLS, WLS, IRLS, LAD, SDP, ABC, …) on the prepared log, then IDIM-IV and DIDIM
(:class:`dynid.identification.closed_loop_estimators.ClosedLoopEstimator` parts given the controller and the set-points) on the
same rows, simulating the run. Per cell and estimator the study reports the bias and
spread of each base parameter, against |β| and against the Cramér–Rao bound, and the coverage of the estimator's
95 % intervals (``|β̂ − β| ≤ 1.96 σ̂``) where it gives σ.

Cramér–Rao bound: torque noise of standard deviation ``σ_τ`` on every joint with the motion known exactly gives
``cov ⪰ σ_τ² (Σ_k W_kᵀ W_k)⁻¹``, ``W_k`` the base observation rows at the true states of the noise-free closed-loop
run (Kay 1993, §3.8). Noisy positions carry less information than exact ones, so this stays a lower bound; it
ignores the position noise, which only raises the true bound.

Ref.: Q. Leboutet, J. Roux, A. Janot, J. R. Guadarrama-Olvera, G. Cheng, "Inertial parameter identification in
robotics: a survey", Applied Sciences 11(9), 2021 (BIRDy's benchmark: encoder noise 1e-4°, 1e-3°, 1e-2°;
torque noise 0.05 and 0.1 N·m); S. M. Kay, "Fundamentals of Statistical Signal Processing: Estimation Theory", 1993.

Each task seeds its generators from ``(seed, cell, realisation)``: results do not depend on where or in which order
the tasks run.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from .._util.reprs import short_repr
from ..dynamics.base_parameters import base_parameters
from ..dynamics.regressor import observation_matrix
from ..dynamics.rnea import rnea_torques
from ..estimators.instrumental import CLOSED_LOOP_METHODS
from ..estimators.registry import label, parse_estimators
from ..exceptions import ConfigError, DynIdError
from ..excitation.fourier import sample_times
from ..excitation.paper_trajectories import PAPER_OMEGA_F
from ..identification.closed_loop_estimators import ClosedLoopEstimator, ClosedLoopExperiment, ClosedLoopSetup
from ..identification.pipeline import IdentificationPipeline
from ..io.logs.datasets import Recording
from ..model.description import load_robot
from ..model.robot import Robot
from ..preprocessing.preparation import Preprocessing
from ..runtime.cluster import realisations_on_grid
from ..runtime.threads import with_single_blas_thread
from ..simulation.closed_loop import ClosedLoopNoise, Controller, simulate_closed_loop
from .paper import PaperExperimentConfig, StudyResult, StudySetup, identification_trajectory, study_header

__all__ = ["ENCODER_NOISE_DEG", "TORQUE_NOISE", "CLOSED_LOOP_ESTIMATORS", "ClosedLoopStudyConfig", "ClosedLoopStudyResult",
           "run_closed_loop_study", "simulate_realisation", "zero_order_hold_delay"]

ENCODER_NOISE_DEG = (1e-4, 1e-3, 1e-2)
"""Encoder noise of the grid [°] (Leboutet et al. 2021)."""
TORQUE_NOISE = (0.05, 0.1)
"""Torque noise of the grid [N·m] (Leboutet et al. 2021)."""
CLOSED_LOOP_ESTIMATORS = ("ols", "wls", "irls", "lad", "sdp", "abc", "idim-iv", "didim")
"""Every estimator side by side by default."""


def _noise_levels(values, name: str, unit: str, example: str, zero: bool) -> tuple[float, ...]:
    v = np.asarray(values, dtype=float)
    low = np.any(v < 0) if zero else np.any(v <= 0)
    if v.ndim != 1 or v.size == 0 or not np.all(np.isfinite(v)) or low:
        kind = "non-negative" if zero else "positive"
        raise ConfigError(f"{name}: expected {kind} noise levels in {unit} like {example}, got {list(np.atleast_1d(values))}",
                          field=name)
    return tuple(float(x) for x in v)


@dataclass(frozen=True)
class ClosedLoopStudyConfig:
    """Settings of :func:`run_closed_loop_study`.

    Attributes
    ----------
    robot : str
        Built-in robot name or description (TOML, URDF).
    joints : int
        Joints identified (the first ones).
    encoder_noise : tuple of float [°]
        Standard deviations of the encoder noise, one row of the grid each.
    torque_noise : tuple of float [N·m]
        Standard deviations of the logged torques' noise (> 0: the bound divides by it).
    realisations : int
        Realisations per cell (>= 2).
    estimators : tuple of str
        Open-loop estimators of :mod:`dynid.estimators.registry` and the closed-loop ones (``idim-iv``, ``didim``).
    seed : int
    duration : float [s]
    rate : float [Hz]
        Control rate, also the log's.
    bandwidth : float [Hz]
        The PID's bandwidth (:meth:`dynid.simulation.closed_loop.Controller.for_robot`).
    band : float or None [Hz]
        The excitation band given to the preprocessing (its cutoffs follow it); None: derived from each log, as
        ``dynid identify`` does.
    excitation : str
        "paper" (β1), "optimized" or an ``excitation.json``, as in ``dynid run``.
    omega_f : float [rad/s]
        Fundamental pulsation of the excitation.
    """

    robot: str = "er16"
    joints: int = 3
    encoder_noise: tuple[float, ...] = ENCODER_NOISE_DEG
    torque_noise: tuple[float, ...] = TORQUE_NOISE
    realisations: int = 100
    estimators: tuple[str, ...] = CLOSED_LOOP_ESTIMATORS
    seed: int = 0
    duration: float = 25.0
    rate: float = 1000.0
    bandwidth: float = 5.0
    band: float | None = None
    excitation: str = "paper"
    omega_f: float = PAPER_OMEGA_F

    @property
    def cells(self) -> list[tuple[float, float]]:
        """The grid: (encoder noise [°], torque noise [N·m]) per cell."""
        return [(e, s) for e in self.encoder_noise for s in self.torque_noise]

    @property
    def open_loop(self) -> tuple[str, ...]:
        """The estimators fitted on the log alone (WLS when none is asked: IDIM-IV and DIDIM start from it)."""
        return tuple(k for k in self.estimators if k not in CLOSED_LOOP_METHODS) or ("wls",)

    def validate(self) -> Robot:
        """Check every setting.

        Returns
        -------
        Robot
            The robot of the study (its first ``joints`` joints).

        Raises
        ------
        ConfigError
            One line naming the first invalid setting.
        """
        _noise_levels(self.encoder_noise, "encoder_noise", "degrees", "1e-4,1e-3,1e-2", zero=True)
        _noise_levels(self.torque_noise, "torque_noise", "N·m", "0.05,0.1", zero=False)
        if self.realisations < 2:
            raise ConfigError(f"realisations must be at least 2, got {self.realisations}", field="realisations")
        keys = [str(k).strip().lower() for k in self.estimators]
        try:
            parse_estimators([k for k in keys if k not in CLOSED_LOOP_METHODS] or ["wls"])
        except ConfigError as exc:
            raise ConfigError(f"{exc}; in closed loop also {', '.join(CLOSED_LOOP_METHODS)}", field="estimators") from None
        if len(set(keys)) != len(keys) or keys != list(self.estimators):
            raise ConfigError(f"estimators: each estimator once, in lower case, got {list(self.estimators)}", field="estimators")
        for name, value in (("duration", self.duration), ("rate", self.rate), ("bandwidth", self.bandwidth)):
            if not (np.isfinite(value) and value > 0):
                raise ConfigError(f"{name}: expected a positive number, got {value!r}", field=name)
        if self.band is not None and not (np.isfinite(self.band) and 0 < self.band < self.rate / 2):
            raise ConfigError(f"band: expected an excitation band in Hz below half the rate ({self.rate / 2:g} Hz), "
                              f"got {self.band!r}", field="band")
        if self.bandwidth * 20 > self.rate:
            raise ConfigError(f"bandwidth: a PID of {self.bandwidth:g} Hz needs a control rate of at least 20 times it, "
                              f"got {self.rate:g} Hz", field="bandwidth")
        full = load_robot(self.robot)
        if not 1 <= self.joints <= full.n_dof:
            raise ConfigError(f"joints: expected 1 to {full.n_dof} for robot {self.robot}, got {self.joints}", field="joints")
        robot = full.submodel(self.joints) if self.joints < full.n_dof else full
        robot.require_physical_nominal("the simulation truth of the closed-loop study")
        return robot

    def paper_config(self) -> PaperExperimentConfig:
        """The excitation settings as a paper-experiment configuration (:func:`identification_trajectory`).

        Returns
        -------
        PaperExperimentConfig
        """
        return PaperExperimentConfig(robot=self.robot, joints=self.joints, seed=self.seed, duration=self.duration,
                                     rate=self.rate, omega_f=self.omega_f, excitation=self.excitation)


@dataclass
class _Setup(StudySetup):
    """:class:`StudySetup` (``unit_crb`` for σ_τ = 1 N·m) and the set-points the controller follows."""

    experiment: ClosedLoopExperiment


def _prepare(config: ClosedLoopStudyConfig) -> _Setup:
    robot = config.validate()
    base = base_parameters(robot, rng=np.random.default_rng([config.seed, 1]))
    traj, _ = identification_trajectory(config.paper_config(), robot, base)
    t = sample_times(config.duration, config.rate)
    q, dq, ddq = traj.evaluate(t)
    controller = Controller.for_robot(robot, bandwidth=config.bandwidth, rate=config.rate)
    experiment = ClosedLoopExperiment(controller, q, dq, rnea_torques(robot, q, dq, ddq))
    clean = simulate_closed_loop(robot, t, q, dq, controller, feedforward=experiment.feedforward)
    w = base.base_observation(observation_matrix(robot, clean.q_true, clean.dq_true, clean.ddq_true)).reshape(-1, base.n_base)
    return _Setup(config, robot, base, base.base_from_standard(robot.standard_parameters()), t, np.linalg.inv(w.T @ w),
                  experiment)


@with_single_blas_thread
def simulate_realisation(setup: _Setup, cell: int, realisation: int) -> dict:
    """Simulate one closed-loop log of one cell of the grid and fit every estimator on it.

    Parameters
    ----------
    setup : _Setup
        What every realisation shares.
    cell : int
        Index in :attr:`ClosedLoopStudyConfig.cells`.
    realisation : int

    Returns
    -------
    dict
        ``params``, ``std`` (n_methods, n_base) with NaN rows for estimators that failed (``std`` NaN also where an
        estimator gives no σ), ``converged`` (n_methods,) bool, ``seconds`` (n_methods,), ``errors`` {key: message}.
    """
    cfg = setup.config
    encoder, torque = cfg.cells[cell]
    keys = tuple(cfg.estimators)
    rng = np.random.default_rng([cfg.seed, 20, cell, realisation])
    noise = ClosedLoopNoise(position_std=float(np.deg2rad(encoder)), torque_std=torque)
    exp = setup.experiment
    run = simulate_closed_loop(setup.robot, setup.t, exp.q_ref, exp.dq_ref, exp.controller, noise, rng=rng,
                               feedforward=exp.feedforward)
    log = Recording(f"closed loop {cell}.{realisation}", setup.t, run.q, None, run.tau, cfg.rate)
    settings = Preprocessing(band=cfg.band, torque_delay=zero_order_hold_delay(cfg.rate))
    n_base = setup.base.n_base
    params, std = np.full((len(keys), n_base), np.nan), np.full((len(keys), n_base), np.nan)
    converged, seconds = np.zeros(len(keys), dtype=bool), np.zeros(len(keys))
    errors: dict[str, str] = {}

    seed = int(np.random.default_rng([cfg.seed, 21, cell, realisation]).integers(2**31))
    reference = ClosedLoopSetup(exp.controller, exp.q_ref, feedforward=exp.feedforward is not None)
    try:  # dynid identify's route: the closed-loop parts on the rows the others fitted, the settings as given
        pipeline = IdentificationPipeline(setup.robot, preprocessing=replace(settings, auto=False), friction="description",
                                          estimators=(*cfg.open_loop, *(ClosedLoopEstimator(k, reference) for k in keys
                                                                        if k in CLOSED_LOOP_METHODS)), rng=seed)
        result = pipeline.fit(log, held_out=False)
    except DynIdError as exc:
        errors.update({k: str(exc) for k in keys})
    else:
        by_key = {e.key: e for e in result.estimates.values()}
        for i, key in enumerate(keys):
            e = by_key.get(key)
            if e is None:  # not estimated: its row stays NaN
                continue
            stopped = key in CLOSED_LOOP_METHODS and bool(e.note)  # a closed-loop estimator stopped before converging
            params[i], converged[i], seconds[i] = e.params, not stopped, e.seconds
            if e.std is not None:
                std[i] = e.std
            if stopped:
                errors[key] = e.note
    return {"params": params, "std": std, "converged": converged, "seconds": seconds, "errors": errors}


def zero_order_hold_delay(rate: float) -> float:
    """The torque channel's delay of a log of commanded torques, each held over its control period [s].

    The command logged at ``t_k`` acts over ``[t_k, t_k + 1/rate)``, on average half a period later: the motion at
    ``t_k`` answers the torques of ``t_k ± 1/(2·rate)`` alike, so the log's torques lead it by half a period
    (:attr:`dynid.preprocessing.settings.Preprocessing.torque_delay` ``= −0.5/rate``). Left as logged, the half period
    biases every estimator alike: on the ER-16 study's noise-free run, least squares was 0.147 % off (median over the
    base parameters), 0.004 % with the delay given.

    Parameters
    ----------
    rate : float [Hz]
        The control rate.

    Returns
    -------
    float [s]
    """
    return -0.5 / rate


def _number(x) -> float | None:
    x = float(x)
    return x if np.isfinite(x) else None


@short_repr
@dataclass
class ClosedLoopStudyResult(StudyResult):
    """Estimates of every (cell, realisation, estimator) and their statistics (:class:`StudyResult`);
    :meth:`to_dict` is ``montecarlo.json``.

    Attributes
    ----------
    std : (n_cells, n_realisations, n_methods, n_base) array
        The estimates' σ: NaN where an estimator failed or gives none.
    converged : (n_cells, n_realisations, n_methods) bool array
    """

    std: np.ndarray = field(kw_only=True)
    converged: np.ndarray = field(kw_only=True)

    def statistics(self) -> dict:
        """Statistics of each estimator per cell, over the realisations it fitted.

        Returns
        -------
        dict
            key -> (n_cells, n_base) arrays ``bias``, ``spread`` (sample standard deviation), ``rmse`` [parameter
            units], ``bias_over_crb``, ``spread_over_crb``; and (n_cells,) arrays ``median_relative_bias``,
            ``median_relative_spread`` (medians over the parameters of |bias|/|β| and spread/|β|, over the parameters
            with |β| above 1e-6 of the largest), ``coverage`` (share of (realisation, parameter) pairs with
            ``|β̂ − β| ≤ 1.96 σ̂``, NaN without σ), ``fitted``, ``converged`` and ``seconds_median``.
        """
        n_cells = len(self.config.cells)
        big = np.abs(self.truth) > 1e-6 * np.abs(self.truth).max()
        out = {}
        for m, key in enumerate(self.config.estimators):
            stats: dict = {k: np.full((n_cells, self.truth.size), np.nan) for k in ("bias", "spread", "rmse")}
            rel_bias, rel_spread, coverage, seconds = (np.full(n_cells, np.nan) for _ in range(4))
            fitted, converged = np.zeros(n_cells, dtype=int), np.zeros(n_cells, dtype=int)
            for c in range(n_cells):
                est, sd = self.estimates[c, :, m], self.std[c, :, m]
                ok = np.all(np.isfinite(est), axis=1)
                fitted[c], converged[c] = ok.sum(), (ok & self.converged[c, :, m]).sum()
                if ok.sum():
                    seconds[c] = float(np.median(self.seconds[c, ok, m]))
                if ok.sum() < 2:
                    continue
                e = est[ok]
                stats["bias"][c] = e.mean(axis=0) - self.truth
                stats["spread"][c] = e.std(axis=0, ddof=1)
                stats["rmse"][c] = np.sqrt(np.mean((e - self.truth) ** 2, axis=0))
                rel_bias[c] = np.median(np.abs(stats["bias"][c][big]) / np.abs(self.truth[big]))
                rel_spread[c] = np.median(stats["spread"][c][big] / np.abs(self.truth[big]))
                if np.all(np.isfinite(sd[ok])):
                    coverage[c] = float(np.mean(np.abs(e - self.truth) <= 1.96 * sd[ok]))
            stats.update(bias_over_crb=np.abs(stats["bias"]) / self.crb_std, spread_over_crb=stats["spread"] / self.crb_std,
                         median_relative_bias=rel_bias, median_relative_spread=rel_spread, coverage=coverage,
                         fitted=fitted, converged=converged, seconds_median=seconds)
            out[key] = stats
        return out

    def best(self, cell: int, stats: dict | None = None) -> str | None:
        """The estimator of the smallest median RMSE/√CRB in a cell, among those that fitted every realisation.

        Parameters
        ----------
        cell : int
        stats : dict, optional
            :meth:`statistics`, when already computed.

        Returns
        -------
        str or None
        """
        stats = self.statistics() if stats is None else stats
        n = self.estimates.shape[1]
        scores = {k: float(np.nanmedian(s["rmse"][cell] / self.crb_std[cell])) for k, s in stats.items() if s["fitted"][cell] == n}
        return min(scores, key=lambda k: scores[k]) if scores else None

    def to_dict(self) -> dict:
        """The study as ``montecarlo.json``.

        Returns
        -------
        dict
        """
        stats = self.statistics()
        names = list(self.names)

        def estimator(st: dict, c: int) -> dict:
            enough = st["fitted"][c] > 1
            return {"fitted": int(st["fitted"][c]), "converged": int(st["converged"][c]),
                    "seconds_median": _number(st["seconds_median"][c]),
                    "median_relative_bias": _number(st["median_relative_bias"][c]),
                    "median_relative_spread": _number(st["median_relative_spread"][c]),
                    "median_bias_over_crb": _number(np.nanmedian(st["bias_over_crb"][c])) if enough else None,
                    "median_spread_over_crb": _number(np.nanmedian(st["spread_over_crb"][c])) if enough else None,
                    "coverage_95": _number(st["coverage"][c]),
                    **{k: dict(zip(names, map(_number, st[k][c]))) for k in ("bias", "spread", "rmse")}}

        return {
            "study": "closed loop",
            **study_header(self.config, names, self.truth),
            "cluster": self.cluster,
            "cells": [{"encoder_noise_deg": e, "torque_noise_Nm": s, "best": self.best(c, stats),
                       "cramer_rao_std": dict(zip(names, self.crb_std[c].tolist())),
                       "estimators": {key: {"label": label(key), **estimator(st, c)} for key, st in stats.items()}}
                      for c, (e, s) in enumerate(self.config.cells)],
            "errors": self.errors,
            "timings": self.timings,
        }


def run_closed_loop_study(config: ClosedLoopStudyConfig = ClosedLoopStudyConfig(), *, scheduler: str | None = None,
                          workers: int | None = None, progress: Callable[[int, int], None] | None = None) -> ClosedLoopStudyResult:
    """Run the closed-loop study on a Dask cluster (a LocalCluster of the local cores by default).

    Parameters
    ----------
    config : ClosedLoopStudyConfig
    scheduler : str, optional
        Address of a running Dask scheduler; its workers need dynid installed.
    workers : int, optional
        Worker processes of the LocalCluster (default: the number of cores).
    progress : callable, optional
        ``progress(done, total)`` as realisations finish.

    Returns
    -------
    ClosedLoopStudyResult

    Raises
    ------
    ConfigError
        Invalid settings, an unreachable scheduler, or Dask not installed.
    """
    cells, n_methods = config.cells, len(config.estimators)
    setup, arrays, errors, cluster, seconds = realisations_on_grid(
        _prepare, simulate_realisation, config, len(cells),
        lambda setup: {"params": ((n_methods, setup.base.n_base), np.nan), "std": ((n_methods, setup.base.n_base), np.nan),
                       "converged": ((n_methods,), False), "seconds": ((n_methods,), 0.0)},
        lambda c, r, k, msg: {"encoder_noise_deg": cells[c][0], "torque_noise_Nm": cells[c][1], "realisation": r,
                              "estimator": k, "error": msg},
        what="dynid montecarlo --closed-loop", scheduler=scheduler, workers=workers, progress=progress)
    crb_std = np.sqrt(np.outer(np.array([s for _, s in cells]) ** 2, np.diag(setup.unit_crb)))
    return ClosedLoopStudyResult(config, tuple(setup.base.names), setup.truth, arrays["params"], arrays["seconds"], crb_std,
                                 errors, {"total": seconds}, cluster, std=arrays["std"], converged=arrays["converged"])

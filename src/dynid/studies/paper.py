"""The paper's identification experiment, end to end (§3-4), on a simulated robot.

Model → base parameters → excitation β1 (eq. 14) → simulated currents (eq. 16) → the pipeline every command
shares: the preprocessing strategy "paper" (eq. 17 smoothing and Fourier-fit derivatives,
:mod:`dynid.preprocessing.paper_smoothing`) → the estimators of :mod:`dynid.estimators.registry` fed from its rows
(:class:`dynid.estimators.estimation.Estimation`: ABC of eqs. 7-13 at the paper's budget and 10× it, DE and PSO on
the same objective and box, LAD = the exact minimiser of eq. 9 in that box, OLS, WLS, IRLS, physically consistent
least squares) → correlation coefficient (eq. 18), RMSE and relative error on β1 and on the validation trajectory
β2, parameter error against the truth, bootstrap intervals.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from .._util.keywords import keyword_only_after_data
from .._util.reprs import short_repr
from ..conventions import unit_of
from ..dynamics.base_parameters import BaseParameters, base_parameters
from ..dynamics.kinematics import tool_positions
from ..dynamics.layout import consistency_layout
from ..estimators import OrdinaryLeastSquares, bootstrap_intervals, consistency_margin, paper_objective
from ..estimators.estimation import Estimation
from ..estimators.fitting import make_estimator
from ..estimators.physically_consistent import consistency_verdict, margin_is_consistent
from ..estimators.problem import FitData, SearchBudget
from ..estimators.registry import parse_estimators, seed_index, spec
from ..exceptions import ConfigError
from ..excitation.design import ExcitationProblem, base_condition_number, design_excitation
from ..excitation.fourier import sample_times
from ..excitation.paper_trajectories import (
    PAPER_DURATION,
    PAPER_OMEGA_F,
    PAPER_RATE,
    paper_identification_trajectory,
    paper_validation_trajectory,
)
from ..identification.pipeline import IdentificationPipeline
from ..io.logs.datasets import Recording
from ..io.logs.trajectories import load_trajectory
from ..model.description import load_robot
from ..model.robot import Robot
from ..preprocessing.preparation import prepared_rows
from ..preprocessing.settings import Preprocessing
from ..preprocessing.strategies import check_strategy
from ..runtime.threads import with_single_blas_thread
from ..simulation.measurements import NoiseModel, simulate_measurements, torques_from_currents
from ..validation import correlation_coefficient, relative_error, rmse
from . import paper_reference as ref

PLANTS = ("assumed", "paper")
BOUNDS = ("auto", "table3", "scaled")


@dataclass(frozen=True)
class PaperExperimentConfig:
    """Settings of :func:`run_paper_experiment` (defaults: the paper's experiment).

    Attributes
    ----------
    robot : str
        Built-in robot name or description TOML.
    joints : int
        Number of joints identified (the first ones; the others held at 0, their mass carried by
        the last identified link). The paper: 3.
    plant : {"assumed", "paper"}
        Simulation truth: the robot file's (assumed) parameters, or the paper's Table 2 as base
        and friction parameters (er16, 3 joints only).
    seed : int
    duration, rate : float
        Recording length [s] and sampling rate [Hz] (paper: 25 s, 1 kHz).
    omega_f : float
        Fundamental pulsation [rad/s] (paper: 2π·0.05).
    current_noise : float
        Motor current noise standard deviation [A].
    encoder_resolution : float
        Position quantisation step [rad].
    smoothing_passes : int
        Applications of eq. 17 to the torques.
    colony_size, limit, maxiter : int
        ABC settings (paper: 30, 15, 50).
    weights : tuple of float or None
        ``delta`` of eq. 9 per joint (default 1).
    abc_bounds : {"auto", "table3", "scaled"}
        Search box: the paper's Table 3, or ``±(2|β_OLS| + 1)`` around zero ("scaled"); "auto"
        takes Table 3 for the paper's own plant (``plant = "paper"``) and "scaled" otherwise (:func:`box_kind`).
    excitation : str
        Identification trajectory: "paper" (β1, eq. A.1), "optimized" (designed for this run by
        :func:`dynid.excitation.design.design_excitation`: 5 harmonics at ``omega_f``, β1's offsets, the
        robot's limits, starting from β1) or the path of an ``excitation.json`` written by ``dynid excite``.
    estimators : tuple of str
        Estimators compared (keys of :mod:`dynid.estimators.registry`; default the built-in ones).
    bootstrap : int
        Moving-block bootstrap resamples for the least-squares methods (0: none).
    strategy : str
        Preprocessing strategy of the simulated recordings (:mod:`dynid.preprocessing.strategies`; default the
        paper's: eq. 17 and the Fourier fit); it is given the trajectory's harmonics and ``smoothing_passes``.
    """

    robot: str = "er16"
    joints: int = 3
    plant: str = "assumed"
    seed: int = 0
    duration: float = PAPER_DURATION
    rate: float = PAPER_RATE
    omega_f: float = PAPER_OMEGA_F
    current_noise: float = 0.05
    encoder_resolution: float = 2 * np.pi / 2**20
    smoothing_passes: int = 1
    colony_size: int = 30
    limit: int = 15
    maxiter: int = 50
    weights: tuple[float, ...] | None = None
    abc_bounds: str = "auto"
    excitation: str = "paper"
    estimators: tuple[str, ...] | None = None
    bootstrap: int = 100
    strategy: str = "paper"

    def validate(self, robot: Robot) -> None:
        """Check every setting against the robot.

        Parameters
        ----------
        robot : Robot
            The robot of the run.

        Raises
        ------
        ConfigError
            One line naming the first invalid setting.
        """
        if self.seed < 0:
            raise ConfigError(field="seed", message=f"seed must be a non-negative integer, got {self.seed}")
        if not 1 <= self.joints <= robot.n_dof:
            raise ConfigError(field="joints", message=f"joints must be between 1 and {robot.n_dof} for robot {robot.name!r}, got {self.joints}")
        if self.plant not in PLANTS:
            raise ConfigError(field="plant", message=f"plant must be one of {', '.join(PLANTS)}, got {self.plant!r}")
        if self.abc_bounds not in BOUNDS:
            raise ConfigError(field="abc_bounds", message=f"abc_bounds must be one of {', '.join(BOUNDS)}, got {self.abc_bounds!r}")
        if self.plant == "paper" and (robot.name != "er16" or self.joints != 3):
            raise ConfigError("plant 'paper' uses Table 2, which exists only for robot er16 with 3 joints", field="plant")
        for name in ("duration", "rate", "omega_f"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise ConfigError(f"{name} must be positive, got {v}", field=name)
        if 1 <= self.joints <= robot.n_dof:  # the truth of the simulation: the description's nominal values
            simulated = robot.submodel(self.joints) if self.joints < robot.n_dof else robot
            phi, names = simulated.standard_parameters(), list(simulated.parameter_names)
            masses = np.array([phi[names.index(f"M{j + 1}")] for j in range(simulated.n_dof)])
            for j in np.flatnonzero(~(masses > 0)):
                raise ConfigError(f"robot: {self.robot}: link {j + 1} ({robot.joints[j].name}) has a nominal mass of "
                                  f"{masses[j]:g} kg (a URDF link without <inertial>?); dynid run simulates the robot with "
                                  "its nominal values: give the link its mass and inertia", field="robot")
        n = int(round(self.duration * self.rate))
        if n < MIN_SAMPLES:
            raise ConfigError(f"rate: duration × rate gives {n} samples, expected at least {MIN_SAMPLES}: raise the rate "
                              "or the duration", field="rate")
        if self.colony_size < 4 or self.colony_size % 2:
            raise ConfigError(f"colony_size must be an even number >= 4 (half employed, half onlooker bees), got "
                              f"{self.colony_size}", field="colony_size")
        for name in ("limit", "maxiter"):
            if getattr(self, name) < 1:
                raise ConfigError(f"{name} must be >= 1, got {getattr(self, name)}", field=name)
        if not self.current_noise >= 0:
            raise ConfigError(f"current_noise must be >= 0 (A), got {self.current_noise}", field="current_noise")
        if not self.encoder_resolution >= 0:
            raise ConfigError(f"encoder_resolution must be >= 0 (rad), got {self.encoder_resolution}", field="encoder_resolution")
        if self.smoothing_passes < 0:
            raise ConfigError(field="smoothing_passes", message=f"smoothing_passes must be >= 0, got {self.smoothing_passes}")
        parse_estimators(self.estimators)

        check_strategy(self.strategy)
        if self.bootstrap != 0 and self.bootstrap < 2:
            raise ConfigError(field="bootstrap", message=f"bootstrap must be 0 (none) or at least 2 resamples, got {self.bootstrap}")
        if self.weights is not None:
            w = np.asarray(self.weights, dtype=float)
            if w.shape != (self.joints,) or np.any(w < 0) or np.any(w > 1):
                raise ConfigError(field="weights", message=f"weights needs {self.joints} values in [0, 1], got {list(self.weights)}")


MIN_SAMPLES = 10
"""Samples a simulated recording needs at least (:func:`dynid.excitation.fourier.sample_times`)."""


@short_repr
@dataclass
class Dataset:
    """One preprocessed recording and its observation matrix.

    Attributes
    ----------
    t : (N,) array [s]
    q, dq, ddq : (N, n) arrays [rad, rad/s, rad/s²]
        Joint motion after the preprocessing (Fourier-fit derivatives).
    tau : (N, n) array [N·m]
        Measured torques after eq. 16 and eq. 17.
    tau_true : (N, n) array [N·m]
        Noise-free torques.
    w_base : (N·n, n_base) array
        Base observation matrix, filtered like ``tau``.
    tool : (N, 3) array [m]
        Tool position, for the workspace figure.
    """

    t: np.ndarray
    q: np.ndarray
    dq: np.ndarray
    ddq: np.ndarray
    tau: np.ndarray          # measured torques after eq. 16 and eq. 17, (N, n)
    tau_true: np.ndarray     # noise-free torques, (N, n)
    w_base: np.ndarray       # (N*n, n_base)
    tool: np.ndarray         # (N, 3)


@short_repr
@dataclass
class PaperEstimate:
    """What one estimator gave.

    Attributes
    ----------
    params : (n_base,) array
        Base parameters in SI units.
    objective : float
        Eq. 9 at ``params``.
    seconds : float
        Wall time of the estimator [s].
    n_evaluations : int or None
        Evaluations of eq. 9 (None for the solvers).
    tau_identification, tau_validation : (N, n) arrays [N·m]
        Predicted torques on both recordings.
    metrics : dict
        dataset -> metric -> (n,) values (eq. 18, RMSE, relative error).
    params_std : (n_base,) array or None
        σ of ``params`` where the estimator gives one.
    history : array or None
        Best objective per iteration of a search.
    bootstrap : dict or None
        Block-bootstrap intervals (``lower``, ``upper``, ``std``, ``level``, ``resamples``, ``block_length``).
    pseudo_inertia_min_eig : (n_links,) array or None
        Smallest eigenvalue of each link's pseudo-inertia (physical consistency).
    consistency_margin : float or None
        Smallest such eigenvalue over the links.
    """

    params: np.ndarray
    objective: float
    seconds: float
    n_evaluations: int | None
    tau_identification: np.ndarray
    tau_validation: np.ndarray
    metrics: dict
    params_std: np.ndarray | None = None
    history: np.ndarray | None = None
    bootstrap: dict | None = None
    pseudo_inertia_min_eig: np.ndarray | None = None
    consistency_margin: float | None = None


@short_repr
@dataclass
class PaperRunResult:
    """Everything :func:`run_paper_experiment` measured; :meth:`to_dict` is ``results.json``.

    Attributes
    ----------
    config : PaperExperimentConfig
    robot : Robot
    base : BaseParameters
        The base-parameter map of the identified joints.
    truth : (n_base,) array
        The simulated plant's base parameters.
    bounds : (n_base, 2) array
        The ABC's search box.
    identification, validation : Dataset
        The two recordings.
    trajectories : dict
        What is known of the excitation trajectories (labels, condition numbers).
    estimates : dict
        estimator key -> :class:`PaperEstimate`.
    timings : dict
        Step -> wall time [s].
    warnings : list of str
    truth_consistency_margin : float or None
        Physical-consistency margin of the truth.
    truth_consistency : str
        The margin in words (:func:`dynid.estimators.physically_consistent.consistency_verdict`): "yes", or "no" and
        why (the paper's Table 2 has ``fc1 = -0.0448 < 0``).
    """

    config: PaperExperimentConfig
    robot: Robot
    base: BaseParameters
    truth: np.ndarray
    bounds: np.ndarray
    identification: Dataset
    validation: Dataset
    trajectories: dict
    estimates: dict = field(default_factory=dict)
    timings: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)
    truth_consistency_margin: float | None = None
    truth_consistency: str = ""

    def to_dict(self) -> dict:
        """The run as ``results.json``.

        Returns
        -------
        dict
            JSON-ready: settings, truth, every estimate with its metrics and errors against the truth, the paper's figures.
        """
        names = list(self.base.names)
        out: dict[str, Any] = {
            "robot": self.robot.name,
            "joints": self.config.joints,
            "plant": self.config.plant,
            "seed": self.config.seed,
            "settings": {**settings_of(self.config), "estimators": list(parse_estimators(self.config.estimators))},
            "parameters": names,
            "units": {n: unit_of(n) for n in names},
            "paper_symbols": {n: ref.paper_symbol(n) for n in names},
            "regrouping": list(self.base.expressions),
            "truth": dict(zip(names, self.truth.tolist())),
            "truth_consistency_margin": self.truth_consistency_margin,
            "truth_consistency": self.truth_consistency,
            "abc_bounds": {n: b.tolist() for n, b in zip(names, self.bounds)},
            "search_box": box_kind(self.config, self.robot, self.base),
            "trajectories": self.trajectories,
            "estimates": {},
            "paper": {"objective": ref.OBJECTIVE,
                      "correlation": {"identification": list(ref.CORRELATION_IDENTIFICATION),
                                      "validation": list(ref.CORRELATION_VALIDATION)},
                      "table2": ref.TABLE2},
            "timings": self.timings,
            "warnings": self.warnings,
        }
        for key, m in self.estimates.items():
            d = {"label": spec(key).label, "description": spec(key).description,
                 "params": dict(zip(names, m.params.tolist())), "objective": m.objective, "seconds": m.seconds,
                 "n_evaluations": m.n_evaluations,
                 "parameter_error_percent": dict(zip(names, _percent_error(m.params, self.truth).tolist())),
                 "parameter_error_norm_percent": float(100 * np.linalg.norm(m.params - self.truth) / np.linalg.norm(self.truth))}
            d.update({k: {s: v.tolist() for s, v in val.items()} for k, val in m.metrics.items()})
            if m.params_std is not None:
                d["params_std"] = dict(zip(names, m.params_std.tolist()))
            if m.history is not None:
                d["history"] = m.history.tolist()
            if m.bootstrap is not None:
                b = m.bootstrap
                d["bootstrap"] = {"resamples": b["resamples"], "block_length_samples": b["block_length"], "level": b["level"],
                                  **{k: dict(zip(names, b[k].tolist())) for k in ("lower", "upper", "std")}}
            if m.pseudo_inertia_min_eig is not None:
                d["pseudo_inertia_min_eig"] = m.pseudo_inertia_min_eig.tolist()
            if m.consistency_margin is not None:
                d["consistency_margin"] = m.consistency_margin
                d["physically_consistent"] = margin_is_consistent(m.consistency_margin, m.params)
            out["estimates"][key] = d
        return out

def _percent_error(est: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """Relative error [%] of each parameter; NaN where the truth is 0, or rounding of 0 (a regrouped parameter whose
    terms cancel: 8e-17 kg·m² gave 1.3e13 %)."""
    zero = np.abs(truth) <= 1e-12 * np.abs(truth).max()
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(zero, np.nan, 100.0 * np.abs(est - truth) / np.abs(truth))


def identification_trajectory(config: PaperExperimentConfig, robot: Robot, base: BaseParameters):
    """The identification trajectory of ``config.excitation`` and what is known of it.

    Parameters
    ----------
    config : PaperExperimentConfig
    robot : Robot
    base : BaseParameters

    Returns
    -------
    traj : FourierTrajectory
    info : dict
        ``trajectory`` (label), ``cond_base_regressor`` (cond(W_base) on 100 samples of a period) and the same for the
        paper's β1.

    Raises
    ------
    ConfigError
        A trajectory file whose joint count is not the run's.
    """
    k = config.joints
    beta1 = paper_identification_trajectory(config.omega_f, k)
    if config.excitation == "paper":
        traj, label = beta1, "paper β1 (eq. A.1)"
    elif config.excitation == "optimized":
        problem = ExcitationProblem(robot, config.omega_f, beta1.n_harmonics, offsets=beta1.q0, base=base)
        design = design_excitation(problem, n_starts=4, rng=np.random.default_rng([config.seed, 3]), initial=beta1)
        traj, label = design.trajectory, "optimized (min cond(W_base) under the robot's limits; 4 starts: β1 and random)"
    else:
        traj, label = load_trajectory(config.excitation), config.excitation
        if traj.n_dof != k:
            raise ConfigError(field="excitation", message=f"excitation {config.excitation}: the trajectory has {traj.n_dof} joints, the run identifies {k}")
    cond_beta1 = base_condition_number(robot, base, beta1)
    info = {"trajectory": label, "cond_base_regressor": cond_beta1 if traj is beta1 else base_condition_number(robot, base, traj),
            "cond_base_regressor_beta1": cond_beta1,
            "grid": "100 samples over one period"}
    return traj, info


def _limit_warnings(robot: Robot, label: str, q, dq, ddq, tau) -> list[str]:
    """Which limits the commanded motion (and the torques it needs) exceeds."""
    lim = robot.limits
    out = []
    if np.any(q < lim.q_min) or np.any(q > lim.q_max) or np.any(np.abs(dq) > lim.dq_max) or np.any(np.abs(ddq) > lim.ddq_max):
        out.append(f"the {label} trajectory leaves the joint limits of {robot.name}")
    over = np.flatnonzero(np.abs(tau).max(axis=0) > lim.tau_max)
    if over.size:
        out.append(f"the {label} trajectory needs more than tau_max on joint(s) {', '.join(str(j + 1) for j in over)}")
    return out


def simulate_recording(robot: Robot, traj, t: np.ndarray, noise: NoiseModel, rng, phi_true: np.ndarray, label: str,
                       warnings: list) -> tuple[Recording, np.ndarray, np.ndarray]:
    """Simulate one recording of ``traj``: quantised positions and torques from noisy currents (eq. 16).

    Parameters
    ----------
    robot : Robot
    traj : FourierTrajectory
        The commanded motion.
    t : (N,) array [s]
    noise : NoiseModel
    rng : numpy.random.Generator
    phi_true : (n_params,) array
        The simulation truth (standard parameters).
    label : str
        The recording's name; limit violations of the commanded motion are appended to ``warnings`` with it.
    warnings : list of str

    Returns
    -------
    recording : Recording
        Positions (no velocities) and torques ``K·I`` as a robot would log them.
    tau_true : (N, n_dof) array [N·m]
        The noise-free torques.
    tool : (N, 3) array [m]
        The tool path.
    """
    q, dq, ddq = traj.evaluate(t)
    meas = simulate_measurements(robot.with_parameters(phi_true), t, q, dq, ddq, noise, rng)  # coupled motors' terms too
    warnings.extend(_limit_warnings(robot, label, q, dq, ddq, meas.tau_true))
    tau = torques_from_currents(meas.current, robot.drive_gains)
    rate = 1.0 / float(t[1] - t[0]) if t.size > 1 else 1.0
    return Recording(label, t, meas.q, None, tau, rate), meas.tau_true, tool_positions(robot, q)


def paper_preprocessing(traj, passes: int, strategy: str = "paper") -> Preprocessing:
    """The preprocessing of a recording of a Fourier trajectory: by default the paper's (§3.3).

    Parameters
    ----------
    traj : FourierTrajectory
        Its harmonics drive the Fourier-fit derivatives.
    passes : int
        Applications of eq. 17.
    strategy : str
        A registered preprocessing strategy: its rule, never cross-validated cutoffs (``auto`` false).

    Returns
    -------
    Preprocessing
    """
    return Preprocessing(strategy=strategy, fourier=(traj.omega_f, traj.n_harmonics), smoothing_passes=passes, auto=False)


def simulate_dataset(robot, base, traj, t, noise, rng, phi_true, passes, label, warnings, problem: FitData | None = None,
                     strategy: str = "paper", *, estimators: tuple = ("ols",)) -> tuple[Dataset, Estimation | None]:
    """Simulate one recording of a trajectory (currents with noise, eq. 16) and prepare it by a strategy, through the
    identification pipeline (:class:`dynid.identification.pipeline.IdentificationPipeline`).

    By default the strategy "paper": the Fourier fit for the derivatives, eq. 17 ``passes`` times on the torques **and
    every column of the observation matrix** (parallel filtering: smoothing the torques alone makes measured and
    modelled torque differ at each velocity reversal, where the Coulomb column steps).

    Parameters
    ----------
    robot : Robot
    base : BaseParameters
    traj : FourierTrajectory
    t : (N,) array
        Sample times [s].
    noise : float
        Current noise σ [A].
    rng : numpy.random.Generator
    phi_true : (n_std,) array
        The plant's standard parameters.
    passes : int
        Applications of eq. 17.
    label : str
        The recording's name, prefixing warnings.
    warnings : list of str
        Limit violations of the commanded motion are appended.
    problem : FitData, optional
        With it, ``estimators`` are fed the recording's rows
        (:meth:`~dynid.identification.pipeline.IdentificationPipeline.estimation`).
    strategy : str
        A registered preprocessing strategy.
    estimators : tuple of str
        Keys of :mod:`dynid.estimators.registry`.

    Returns
    -------
    Dataset
    Estimation or None
        The estimators fed, unfitted; None without ``problem``.
    """
    recording, tau_true, tool = simulate_recording(robot, traj, t, noise, rng, phi_true, label, warnings)
    pipeline = IdentificationPipeline(robot, paper_preprocessing(traj, passes, strategy), estimators=estimators,
                                      friction="description")  # the paper's model: the description's friction terms
    prepared = pipeline.prepare(recording, base)
    estimation = None if problem is None else pipeline.estimation(prepared, problem, keep_rows=True)
    w, tau = estimation.rows() if estimation is not None else _zeroed(*prepared_rows(robot, base, prepared.data))
    assert w is not None and tau is not None  # kept rows: keep_rows=True
    data = prepared.data
    return Dataset(t, data.q, data.dq, data.ddq, tau.reshape(-1, robot.n_dof), tau_true, w, tool), estimation


def _zeroed(w: np.ndarray, tau: np.ndarray, keep: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The rows the estimation does not use zeroed, as :meth:`Estimation.rows` keeps them."""
    return w * keep[:, None], tau * keep


def settings_of(config) -> dict:
    """A study's settings as its JSON holds them: the config's fields, tuples as lists.

    Parameters
    ----------
    config : dataclass
        A study's config (:class:`PaperExperimentConfig`, the Monte Carlo's, the closed-loop study's).

    Returns
    -------
    dict
    """
    return {k: (list(v) if isinstance(v, tuple) else v) for k, v in asdict(config).items()}


@short_repr
@dataclass
class StudySetup:
    """What every realisation of a simulated study shares (computed once, sent to the workers once).

    Attributes
    ----------
    config : dataclass
        The study's settings.
    robot : Robot
    base : BaseParameters
    truth : (n_base,) array
        The true base parameters.
    t : (N,) array [s]
        The sample times.
    unit_crb : (n_base, n_base) array
        The Cramér–Rao covariance for a unit noise σ.
    """

    config: Any
    robot: Robot
    base: BaseParameters
    truth: np.ndarray
    t: np.ndarray
    unit_crb: np.ndarray


@short_repr
@dataclass
class StudyResult:
    """A simulated study's estimates, in the order of its grid's cells, its realisations and its estimators.

    Attributes
    ----------
    config : dataclass
        The study's settings.
    names : tuple of str
        Base parameter names.
    truth : (n_base,) array
    estimates : (n_cells, n_realisations, n_methods, n_base) array
        NaN where an estimator failed.
    seconds : (n_cells, n_realisations, n_methods) array [s]
    crb_std : (n_cells, n_base) array
        Square roots of the Cramér–Rao bound's diagonal.
    errors : list
        What failed, with the message.
    timings : dict
        Step -> wall time [s].
    cluster : str
        The Dask cluster the study ran on.
    """

    config: Any
    names: tuple
    truth: np.ndarray
    estimates: np.ndarray
    seconds: np.ndarray
    crb_std: np.ndarray
    errors: list = field(default_factory=list)
    timings: dict = field(default_factory=dict)
    cluster: str = ""


def study_header(config, names: list[str], truth: np.ndarray) -> dict:
    """What a simulated study's JSON opens with: its settings, the base parameters' names and the truth.

    Parameters
    ----------
    config : dataclass
    names : list of str
        Base parameter names.
    truth : (n_base,) array

    Returns
    -------
    dict
        ``settings``, ``parameters``, ``truth`` (by name).
    """
    return {"settings": settings_of(config), "parameters": names, "truth": dict(zip(names, truth.tolist()))}


def _metrics(tau: np.ndarray, pred: np.ndarray) -> dict:
    return {"correlation": correlation_coefficient(tau, pred), "rmse": rmse(tau, pred),
            "relative_error": relative_error(tau, pred)}


@with_single_blas_thread
@keyword_only_after_data
def run_paper_experiment(config: PaperExperimentConfig = PaperExperimentConfig(), *,
                         progress: Callable[[str, int | None, float | None], None] | None = None) -> PaperRunResult:
    """Run the paper's experiment (§4) on a simulated robot and compare the estimators of ``config.estimators``.

    Parameters
    ----------
    config : PaperExperimentConfig
    progress : callable, optional
        ``progress(step, iteration, best_objective)``: each step as it starts with ``(step, None, None)``
        (``"simulation"``, a method key, ``"bootstrap"``), and the box searches' iterations (ABC, DE, PSO).

    Returns
    -------
    PaperRunResult

    Raises
    ------
    ConfigError
        Unknown robot or invalid settings.
    """
    t0 = time.perf_counter()
    full = load_robot(config.robot)
    config.validate(full)
    keys = parse_estimators(config.estimators)
    robot = full.submodel(config.joints) if config.joints < full.n_dof else full
    base = base_parameters(robot, rng=np.random.default_rng([config.seed, 1]))
    warnings: list[str] = []

    truth, phi_true = _plant(config, robot, base)
    ident, valid, estimation, trajectories, seconds = _simulated_datasets(config, robot, base, keys, phi_true, warnings,
                                                                          progress)
    timings = {"simulation_and_preprocessing": seconds}

    data, budget = _search_problem(config, robot, base, ident, estimation.problem, truth=truth, keys=keys, warnings=warnings)
    bounds = data.bounds
    layout = consistency_layout(robot)

    result = PaperRunResult(config, robot, base, truth, bounds, ident, valid, trajectories, warnings=warnings)
    boots = _bootstrap_tasks(config, keys, data, budget, progress)
    fits: dict[str, Any] = estimation.fit(bounds, rng=(config.seed, 2), budget=budget, progress=progress, extra=boots)
    for key in keys:
        timings[key] = fits[key].seconds
        boot = None
        if f"{key}_bootstrap" in fits:
            bs, timings[f"{key}_bootstrap"] = fits[f"{key}_bootstrap"]
            boot = {"resamples": config.bootstrap, "block_length": bs.block_length, "level": bs.level,
                    "lower": bs.lower, "upper": bs.upper, "std": bs.std}
        result.estimates[key] = _paper_estimate(fits[key], ident, valid, config, base, layout, boot)
    result.truth_consistency_margin, result.truth_consistency = _truth_verdict(base, truth, layout)
    timings["total"] = time.perf_counter() - t0
    result.timings = timings
    return result


def _search_problem(config: PaperExperimentConfig, robot: Robot, base: BaseParameters, ident: Dataset, fed: FitData, *,
                    truth: np.ndarray, keys: tuple[str, ...], warnings: list[str]) -> tuple[FitData, SearchBudget]:
    """The identification rows with the run's search box (:func:`paper_search_box`; a warning where the truth lies
    outside it and a box search runs) and the box searches' budget."""
    y = ident.tau.ravel()
    bounds = paper_search_box(config, robot, base, ident.w_base, y)
    outside = [n for n, v, (lo, hi) in zip(base.names, truth, bounds) if not lo <= v <= hi]
    if outside and any(spec(m).needs_box for m in keys):  # only the box searches and LAD use it
        warnings.append("truth outside the ABC search box for " + ", ".join(outside))
    data = FitData(ident.w_base, y, config.joints, bounds, base, None, fed.layout, fed.prior, config.weights)
    return data, SearchBudget(config.colony_size, config.limit, config.maxiter)


def _simulated_datasets(config: PaperExperimentConfig, robot: Robot, base: BaseParameters, keys: tuple[str, ...],
                        phi_true: np.ndarray, warnings: list[str], progress):
    """The identification (β1) and validation (β2) recordings simulated with one generator and prepared, the
    estimators fed the first's rows; the trajectories as results.json holds them.

    Returns ``(identification, validation, estimation, trajectories, seconds)``: the seconds of the simulation and
    preprocessing (an excitation designed for the run not counted).
    """
    rng = np.random.default_rng(config.seed)
    t = sample_times(config.duration, config.rate)
    noise = NoiseModel(config.current_noise, config.encoder_resolution)
    traj_id, excitation_info = identification_trajectory(config, robot, base)
    traj_val = paper_validation_trajectory(config.omega_f, config.joints)
    t_sim = time.perf_counter()
    if progress is not None:
        progress("simulation and preprocessing", None, None)
    ident, estimation = simulate_dataset(robot, base, traj_id, t, noise, rng, phi_true, config.smoothing_passes,
                                         "identification (β1)", warnings, problem(config, robot, base), config.strategy,
                                         estimators=keys)
    assert estimation is not None  # fed: a problem was given
    valid, _ = simulate_dataset(robot, base, traj_val, t, noise, rng, phi_true, config.smoothing_passes, "validation (β2)",
                                warnings, strategy=config.strategy)
    seconds = time.perf_counter() - t_sim
    trajectories = {"identification": traj_id.to_dict(), "validation": traj_val.to_dict(), "excitation": excitation_info}
    return ident, valid, estimation, trajectories, seconds


def _bootstrap_tasks(config: PaperExperimentConfig, keys: tuple[str, ...], data: FitData, budget: SearchBudget,
                     progress) -> dict:
    """The bootstrap of each bootstrapped estimator as a task of the estimators' pool (independent of the fit: it refits
    on resamples of ``data``'s rows), each seeded by ``(seed, 5, its registry index)``."""
    def bootstrap(key):
        if progress is not None:
            progress(f"bootstrap of {spec(key).label}", None, None)
        t_b = time.perf_counter()
        bs = bootstrap_intervals(lambda: make_estimator(key, data, budget, None), data.w_base, data.tau, config.joints,
                                 problem=data, n_resamples=config.bootstrap,
                                 rng=np.random.default_rng([config.seed, 5, seed_index(key)]))
        return bs, time.perf_counter() - t_b

    return {f"{key}_bootstrap": (lambda key=key: bootstrap(key)) for key in keys if spec(key).bootstrapped and config.bootstrap}


def _truth_verdict(base: BaseParameters, truth: np.ndarray, layout) -> tuple[float, str]:
    """The true parameters' physical-consistency margin and its verdict in words (the paper's Table 2 is not consistent)."""
    margin = consistency_margin(base.regrouping, truth, *layout)
    return margin, consistency_verdict(margin, base.regrouping, truth, base.names, layout[1])


def _plant(config: PaperExperimentConfig, robot: Robot, base: BaseParameters) -> tuple[np.ndarray, np.ndarray]:
    """The simulated plant's base and standard parameters: the paper's Table 2 (``plant = "paper"``) or the robot's
    description."""
    if config.plant == "paper":
        missing = [n for n in base.names if ref.paper_symbol(n) not in ref.TABLE2]
        if missing:
            raise ConfigError(field="plant", message=f"plant 'paper': no Table 2 value for {', '.join(missing)}")
        truth = np.array([ref.TABLE2[ref.paper_symbol(n)] for n in base.names])
        return truth, base.standard_from_base(truth, reference=robot.standard_parameters())
    robot.require_physical_nominal("the simulation truth of dynid run")
    phi_true = robot.standard_parameters()
    return base.base_from_standard(phi_true), phi_true


def _paper_estimate(fit, ident, valid, config: PaperExperimentConfig, base: BaseParameters, layout, boot) -> PaperEstimate:
    """One estimator's :class:`PaperEstimate`: its predictions and metrics on β1 and β2, eq. 9's objective, σ and
    history where it has them, its consistency margin, the bootstrap's intervals (``boot``)."""
    k = config.joints
    p_id = (ident.w_base @ fit.params).reshape(-1, k)
    p_val = (valid.w_base @ fit.params).reshape(-1, k)
    metrics: dict[str, dict] = {}
    for name, tau, pred in (("identification", ident.tau, p_id), ("validation", valid.tau, p_val)):
        for mk, mv in _metrics(tau, pred).items():
            metrics.setdefault(mk, {})[name] = mv
    est = fit.estimator
    return PaperEstimate(
        params=fit.params, objective=float(paper_objective(ident.tau.ravel() - p_id.ravel(), k, config.weights)),
        seconds=fit.seconds, n_evaluations=fit.n_evaluations, tau_identification=p_id, tau_validation=p_val,
        metrics=metrics, params_std=getattr(est, "params_std_", None), history=getattr(est, "history_", None),
        bootstrap=boot, pseudo_inertia_min_eig=getattr(est, "pseudo_inertia_min_eig_", None),
        consistency_margin=consistency_margin(base.regrouping, fit.params, *layout))


def problem(config: PaperExperimentConfig, robot: Robot, base: BaseParameters) -> FitData:
    """What the estimators know of the problem before any row.

    The joints, the base map, the parameter layout and the eq. 9 weights; for ``sdp`` a rough CAD guess as prior
    (nominal parameters × U(0.7, 1.3), seeded by the run).

    Parameters
    ----------
    config : PaperExperimentConfig
    robot : Robot
    base : BaseParameters

    Returns
    -------
    FitData
    """
    keys = parse_estimators(config.estimators)
    prior = None
    if "sdp" in keys:
        prior = robot.standard_parameters() * np.random.default_rng([config.seed, 4]).uniform(0.7, 1.3, robot.n_params)
    return FitData(None, None, config.joints, None, base, None, consistency_layout(robot), prior, config.weights)


def box_kind(config, robot: Robot, base: BaseParameters) -> str:
    """Which search box a run's box searches get: the paper's Table 3 where the plant is the paper's own (its Table 2,
    inside that box), else one derived from the data that holds the truth (``±(2|β_OLS| + 1)``): every estimator is
    judged on a problem it can solve. The assumed ER-16 plant lies outside Table 3 (ZZ2R, MX2R, MY3).

    Parameters
    ----------
    config : PaperExperimentConfig
        ``abc_bounds``: "auto" chooses as above; "table3" and "scaled" force a box.
    robot : Robot
    base : BaseParameters

    Returns
    -------
    str
        "table3" or "scaled".

    Raises
    ------
    ConfigError
        "table3" asked for a model whose base parameters are not the paper's.
    """
    has_table3 = all(ref.paper_symbol(n) in ref.TABLE3 for n in base.names)
    if config.abc_bounds == "table3" and not has_table3:
        raise ConfigError("abc_bounds 'table3' needs the paper's 21 parameters (er16, 3 joints); use 'scaled'", field="abc_bounds")
    if config.abc_bounds == "table3" or (config.abc_bounds == "auto" and has_table3 and robot.name == "er16"
                                         and config.joints == 3 and config.plant == "paper"):
        return "table3"
    return "scaled"


def paper_search_box(config, robot: Robot, base: BaseParameters, w_base: np.ndarray, y: np.ndarray) -> np.ndarray:
    """The ABC's search box: the paper's Table 3 (amended where it misses the paper's own Table 2,
    :data:`dynid.studies.paper_reference.TABLE3_AMENDED`), or ``±(2|β_OLS| + 1)``.

    Parameters
    ----------
    config : PaperExperimentConfig
        ``abc_bounds`` chooses.
    robot : Robot
    base : BaseParameters
    w_base : (N·n, n_base) array
        Identification observation matrix.
    y : (N·n,) array [N·m]
        Identification torques.

    Returns
    -------
    (n_base, 2) ndarray
        Lower and upper bound per base parameter.

    Raises
    ------
    ConfigError
        "table3" asked for a model whose base parameters are not the paper's.
    """
    if box_kind(config, robot, base) == "table3":
        return np.array([ref.search_scope(ref.paper_symbol(n)) for n in base.names], dtype=float)
    half = 2.0 * np.abs(OrdinaryLeastSquares().fit(w_base, y).params_) + 1.0
    return np.stack([-half, half], axis=1)

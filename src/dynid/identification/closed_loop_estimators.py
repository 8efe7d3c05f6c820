"""Identification of a robot run in closed loop: IDIM-IV and DIDIM beside least squares.

Both estimators simulate the robot's closed loop (:mod:`dynid.simulation.closed_loop`: the same controller, reference
and feed-forward as the experiment) with the current estimate, and prepare the simulated positions exactly as the
measured ones (the same resolved preprocessing settings, the same parallel filter and decimation), so the rows of
the simulated observation matrix ``W_s`` match the measured ``W`` and ``τ``:

- **IDIM-IV** (Janot, Vandanjon & Gautier, IEEE TCST 22(1), 2014): ``W_s`` as instruments,
  ``β_{k+1} = (W_sᵀ W)⁻¹ W_sᵀ τ``; ``W_s`` is noise-free and so uncorrelated with the loop's noise in ``W``.
- **DIDIM** (Gautier, Janot & Vandanjon, IEEE TCST 21(2), 2013): closed-loop output error on the torques, by
  Gauss–Newton with the Jacobian ``∂τ_s/∂β`` taken as ``W_s`` re-linearised at each step: ``β_{k+1} = W_s⁺ τ``.
- **DIDIM-SDP**: DIDIM whose every step is the physically consistent least squares
  (:class:`dynid.estimators.physically_consistent.PhysicallyConsistentLeastSquares`: each link's pseudo-inertia
  positive semidefinite, friction and rotor inertias non-negative, the description's values as the prior) on the
  *standard* simulated observation matrix; the iterate is a standard parameter vector, simulated as it is, so every
  simulation runs a physically consistent model. The SDP gives no σ.

Their σ is the sandwich ``A⁻¹ S A⁻ᵀ`` (``A = W_sᵀ W`` for IDIM-IV, ``W_sᵀ W_s`` for DIDIM) with ``S`` the long-run
covariance of the scores over the log's instants (:func:`dynid.estimators.instrumental.long_run_covariance`, the
Parzen kernel over :func:`~dynid.estimators.instrumental.parzen_lags`): the residuals of a filtered, decimated
closed-loop log are correlated in time and between joints, and the white-noise formula ``σ² A⁻¹`` put the 95 %
intervals around the truth in 78-80 % of the ER-16 study's realisations at 1e-2°. With cutoffs above the excitation
band the residual is blue (differentiated encoder noise up to the cutoff), its correlations cancel over several
samples, and Newey–West's few Bartlett lags made σ 2.7-3.3 times the estimates' spread (100 % coverage); the Parzen
window over a fiftieth of the log sees the cancellation.

Both start from the weighted least-squares estimate on the measured rows (IDIM-WLS) — or from the description's
values when that estimate is too biased to be simulated (unstable) — weight every joint's rows by
the inverse of its residual σ, and stop when the simulated torques change by less than ``tol`` (relative) between
iterations. A base-parameter estimate is simulated through the standard vector nearest the description's nominal
values with the same base parameters (:meth:`dynid.dynamics.base_parameters.BaseParameters.standard_from_base`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np

from .._util.reprs import short_repr
from ..dynamics.base_parameters import BaseParameters
from ..dynamics.layout import consistency_layout
from ..dynamics.rnea import rnea_torques
from ..estimators.instrumental import CLOSED_LOOP_METHODS, instrumental_variables, weighted_least_squares
from ..estimators.physically_consistent import PhysicallyConsistentLeastSquares
from ..estimators.problem import FitData
from ..exceptions import ConfigError, DataError, ShapeError
from ..io.logs.datasets import Recording
from ..model.robot import Robot
from ..preprocessing.preparation import Preprocessing, prepare, prepared_rows
from ..preprocessing.prepared import PreparedData
from ..simulation.closed_loop import ClosedLoopNoise, ClosedLoopSetup, Controller, simulate_closed_loop
from .estimation_pass import Estimate, consistency_checks

__all__ = ["ClosedLoopExperiment", "ClosedLoopEstimate", "ClosedLoopEstimator", "ClosedLoopSetup", "closed_loop_identify",
           "CLOSED_LOOP_METHODS"]


LABELS = {"wls": "IDIM-WLS", "idim-iv": "IDIM-IV", "didim": "DIDIM", "didim-sdp": "DIDIM-SDP"}

STALLED = 1e-3
"""A relative change of the simulated torques below which iterations whose changes no longer fall (three in a row, none
10 % below the smaller of the two before) have converged: they wobble at the resolution of the closed-loop simulation
(measured: DIDIM on a 10 s, 6-joint ER-16 log settles into changes of 2.4e-4 at every iteration, above ``tol``)."""


@short_repr
@dataclass(frozen=True)
class ClosedLoopExperiment:
    """What the closed-loop estimators must know of an experiment to simulate it.

    Attributes
    ----------
    controller : Controller
    q_ref, dq_ref : (N, n_dof) arrays
        The reference at the log's instants [rad, rad/s].
    feedforward : (N, n_dof) array or None
        Feed-forward torques the controller added [N·m].
    """

    controller: Controller
    q_ref: np.ndarray
    dq_ref: np.ndarray
    feedforward: np.ndarray | None = None


@short_repr
@dataclass(frozen=True)
class ClosedLoopEstimate:
    """One estimate of the base parameters.

    Attributes
    ----------
    method : str
        "IDIM-WLS", "IDIM-IV", "DIDIM" or "DIDIM-SDP".
    params, params_std : (n_base,) arrays
        ``params_std`` NaN where the estimator gives no σ (DIDIM-SDP).
    iterations : int
        Closed-loop simulations run.
    converged : bool
    changes : tuple of float
        Relative change of the simulated torques at each iteration.
    message : str
        Why it stopped.
    """

    method: str
    params: np.ndarray
    params_std: np.ndarray
    iterations: int = 0
    converged: bool = True
    changes: tuple[float, ...] = field(default=())
    message: str = ""

    def to_dict(self, names=None) -> dict:
        """JSON-ready, parameters by name when ``names`` are given.

        Parameters
        ----------
        names : sequence of str, optional

        Returns
        -------
        dict
        """
        names = list(names) if names is not None else [f"beta{k + 1}" for k in range(self.params.size)]
        return {"method": self.method, "iterations": self.iterations, "converged": self.converged, "message": self.message,
                "changes": list(self.changes),
                "parameters": [{"name": n, "value": float(v), "std": float(s) if np.isfinite(s) else None}
                               for n, v, s in zip(names, self.params, self.params_std)]}


def closed_loop_identify(robot: Robot, base: BaseParameters, recording: Recording, experiment: ClosedLoopExperiment,
                         *, methods=("idim-iv", "didim"), preprocessing: Preprocessing | None = None, max_iter: int = 10,
                         tol: float = 1e-4, data: PreparedData | None = None) -> dict[str, ClosedLoopEstimate]:
    """IDIM-WLS, then each closed-loop estimator of ``methods`` (module docstring).

    Parameters
    ----------
    robot : Robot
        The model identified (its friction terms), and the nominal values a base estimate is simulated through.
    base : BaseParameters
    recording : Recording
        The closed-loop log: measured positions and torques at the controller's instants.
    experiment : ClosedLoopExperiment
    methods : sequence of str
        Among :data:`CLOSED_LOOP_METHODS` (IDIM-IV and DIDIM by default; DIDIM-SDP on request).
    preprocessing : Preprocessing, optional
        Default: every setting derived from the log (the settings resolved on it prepare the simulations too).
    max_iter : int
        Closed-loop simulations per estimator at most.
    tol : float
        Relative change of the simulated torques that ends the iterations.
    data : PreparedData, optional
        ``recording`` as an identification prepared it already (:meth:`IdentificationPipeline.prepare
        <dynid.identification.pipeline.IdentificationPipeline.prepare>`: its cross-validated cutoffs, rest model and
        speeds): the measured rows are these, and the simulated logs are prepared with its settings. Default:
        ``recording`` prepared here with ``preprocessing``.

    Returns
    -------
    dict
        ``{"wls": ..., "idim-iv": ..., "didim": ..., "didim-sdp": ...}`` (those asked for), :class:`ClosedLoopEstimate`
        each.

    Raises
    ------
    ConfigError
        An unknown method.
    ShapeError
        A reference or feed-forward whose length is not the log's, or a log not at the controller's rate.
    """
    keys = [str(m).lower() for m in methods]
    unknown = [m for m in keys if m not in CLOSED_LOOP_METHODS]
    if unknown:
        raise ConfigError(f"closed-loop estimator {unknown[0]!r}: expected one of {', '.join(CLOSED_LOOP_METHODS)}")
    n_s = recording.t.size
    for name, x in (("reference q", experiment.q_ref), ("reference dq", experiment.dq_ref), ("feed-forward", experiment.feedforward)):
        if x is not None and np.shape(x) != (n_s, robot.n_dof):
            raise ShapeError(f"{name}: expected ({n_s}, {robot.n_dof}) samples, one per sample of {recording.name}, got {np.shape(x)}")
    if abs(recording.rate - experiment.controller.rate) > 1e-6 * experiment.controller.rate:
        raise ShapeError(f"{recording.name}: logged at {recording.rate:.6g} Hz, the controller runs at {experiment.controller.rate:.6g} Hz: "
                         "the closed-loop estimators need the log at the control rate")
    data = data if data is not None else prepare(recording, preprocessing or Preprocessing())
    w, tau, keep = prepared_rows(robot, base, data)
    n = robot.n_dof
    w, tau = w[keep], tau[keep]
    joint = np.tile(np.arange(n), keep.size // n)[keep]
    instants = np.repeat(np.arange(keep.size // n), n)[keep]
    params, _ = weighted_least_squares(w, tau, np.ones(tau.size))
    residual = tau - w @ params
    sigma = np.array([np.sqrt(np.mean(residual[joint == j] ** 2)) if np.any(joint == j) else 1.0 for j in range(n)])
    row_sigma = np.maximum(sigma, 1e-12)[joint]
    start, start_std = weighted_least_squares(w, tau, row_sigma)
    out = {"wls": ClosedLoopEstimate(LABELS["wls"], start, start_std, message="least squares on the measured rows")}
    nominal = robot.standard_parameters()
    simulated: dict = {}  # the estimators all start from the same estimate: its closed loop is simulated once

    def simulated_rows(x, standard=False):
        """The simulated rows at the measured rows kept, and whether the simulated joint moves there."""
        key = (np.asarray(x, dtype=float).tobytes(), standard)
        if key not in simulated:
            try:
                simulated[key] = _simulated_rows(x, standard)
            except ConfigError as exc:  # a closed loop that cannot be simulated: said again without simulating it again
                simulated[key] = exc
        if isinstance(simulated[key], ConfigError):
            raise simulated[key]
        return simulated[key]

    def _simulated_rows(x, standard):
        phi = x if standard else base.standard_from_base(x, reference=nominal)
        run = simulate_closed_loop(robot, recording.t, experiment.q_ref, experiment.dq_ref, experiment.controller,
                                   ClosedLoopNoise(), phi=phi, feedforward=experiment.feedforward)
        sim = Recording(f"{recording.name} (simulated)", recording.t, run.q, None, run.tau_applied, recording.rate,
                        followers=robot.followers)
        ws, _, moving = prepared_rows(robot, base, prepare(sim, data.settings, strict=False), standard)
        if ws.shape[0] != keep.size:
            raise DataError(f"{recording.name}: the simulated log prepares to {ws.shape[0] // n} samples, the measured one to "
                            f"{keep.size // n}")
        return ws[keep], moving[keep]

    for key in keys:
        if key == "didim-sdp":
            out[key] = _didim_sdp(robot, base, simulated_rows, prepared_rows(robot, base, data, standard=True)[0][keep], tau,
                                  row_sigma, max_iter=max_iter, tol=tol)
            continue

        def step(rows, key=key):
            ws, moving = rows
            if key == "idim-iv":
                sol = instrumental_variables(w / row_sigma[:, None], tau / row_sigma, ws / row_sigma[:, None], instants,
                                             kernel="parzen")
                return sol.params, sol.params_std, w @ sol.params
            # a row where the simulated joint is slower than min_speed fits nothing, as a measured one does not
            beta, std = weighted_least_squares(ws, tau, np.where(moving, row_sigma, np.inf), instants)
            return beta, std, ws @ beta

        run = _iterate(simulated_rows, step, start, base.base_from_standard(nominal), w @ start, max_iter=max_iter, tol=tol,
                       start_words="the least-squares estimate")
        out[key] = ClosedLoopEstimate(LABELS[key], run.x, start_std if run.std is None else run.std, len(run.changes),
                                      run.converged, run.changes, run.message)
    return out


@dataclass(frozen=True)
class _Iterations:
    """How the closed-loop iterations ended: the estimate ``x`` and its ``std`` (None: the start's), the relative
    changes, whether they converged, and why they stopped."""

    x: np.ndarray
    std: np.ndarray | None
    changes: tuple[float, ...]
    converged: bool
    message: str


def _iterate(simulate, step, start, fallback, previous, *, max_iter: int, tol: float, start_words: str) -> _Iterations:
    """The iterations IDIM-IV, DIDIM and DIDIM-SDP share: simulate the closed loop with the current estimate, take a
    step on the simulated rows, until the modelled torques change by less than ``tol`` (or stall below
    :data:`STALLED`).

    An estimate whose closed loop cannot be simulated (unstable, a massless link) is replaced: the start by
    ``fallback`` (the description's values: instruments need only be uncorrelated with the noise, and the iterations
    take them to the estimate), a later step by halving it towards the last estimate that simulated, up to 6 times
    (a Gauss–Newton step too long for the closed loop). When no halving can be simulated either, the iterations stop
    and give the last estimate whose own closed loop could be simulated.

    Parameters
    ----------
    simulate : callable
        ``simulate(x)`` -> simulated rows; raises ConfigError when ``x`` cannot be simulated.
    step : callable
        ``step(rows)`` -> ``(x, std, torque)``, the next estimate, its σ and its modelled torques.
    start, fallback : (p,) arrays
    previous : (M,) array
        The start's modelled torques [N·m].
    max_iter : int
    tol : float
    start_words : str
        What the start is, for the message.

    Returns
    -------
    _Iterations
    """
    x, std, message, converged, note = start.copy(), None, "", False, ""
    changes: list[float] = []
    good = None  # the last estimate that simulated, halved steps included
    kept = (x, std)  # the last estimate (and σ) of the iterations whose own closed loop simulated
    for _ in range(max_iter):
        try:
            rows = simulate(x)
            kept = (x, std)
        except ConfigError as exc:
            trials = ([(fallback, f"{start_words} cannot be simulated ({exc}); started from the description's values; ")]
                      if good is None else
                      [(good + 0.5**h * (x - good), f"a step halved {h} time(s) to keep the closed loop stable; ")
                       for h in range(1, 7)])
            last = exc
            for trial, words in trials:
                try:
                    rows = simulate(trial)
                except ConfigError as again:
                    last = again
                    continue
                x, note = trial, note + words
                break
            else:
                message = (f"stopped: {exc}; the estimate is the last one whose closed loop could be simulated"
                           if good is not None else
                           f"stopped: neither {start_words} nor the description can be simulated ({last})")
                x, std = kept
                break
        good = x.copy()
        x, std, torque = step(rows)
        change = float(np.linalg.norm(torque - previous)) / max(float(np.linalg.norm(previous)), 1e-300)
        changes.append(change)
        previous = torque
        if change < tol:
            converged, message = True, f"converged: the simulated torques changed by {change:.2g} (relative)"
            break
        if len(changes) >= 3 and change < STALLED and change >= 0.9 * min(changes[-3:-1]):
            converged, message = True, (f"converged: the simulated torques change by {change:.2g} (relative) at each "
                                        "iteration and no longer fall (the closed-loop simulation's own resolution)")
            break
    else:
        message = f"not converged after {max_iter} simulations (last change {changes[-1]:.2g})"
    return _Iterations(x, std, tuple(changes), converged, note + message)


def _didim_sdp(robot: Robot, base: BaseParameters, simulated_rows, w_standard, tau, row_sigma, *, max_iter: int,
               tol: float) -> ClosedLoopEstimate:
    """DIDIM with the physically consistent least squares at each step (module docstring), by :func:`_iterate` on
    standard parameter vectors, from the physically consistent least squares on the measured rows ``w_standard``
    (IDIM-SDP); a mean of consistent models is consistent, so the halved steps stay physical."""
    nominal = robot.standard_parameters()
    problem = FitData(layout=consistency_layout(robot), prior=nominal)

    def fit(w, weight=None):
        sdp = PhysicallyConsistentLeastSquares()
        return sdp.fit(w / row_sigma[:, None], tau / row_sigma, sample_weight=weight, problem=problem).params_

    def step(rows):
        ws, moving = rows
        phi = fit(ws, moving.astype(float))  # a row where the simulated joint is slower than min_speed fits nothing
        return phi, None, ws @ phi

    phi = fit(w_standard)
    run = _iterate(lambda x: simulated_rows(x, standard=True), step, phi, nominal, w_standard @ phi, max_iter=max_iter, tol=tol,
                   start_words="the IDIM-SDP estimate")
    beta = base.base_from_standard(run.x)
    return ClosedLoopEstimate(LABELS["didim-sdp"], beta, np.full(beta.size, np.nan), len(run.changes), run.converged,
                              run.changes, run.message)


@dataclass(frozen=True)
class ClosedLoopEstimator:
    """One closed-loop estimator as a part of the identification pipeline
    (:class:`dynid.identification.pipeline.IdentificationPipeline`): its method and how the log was recorded, which it
    carries as an open-loop estimator carries its prior.

    Attributes
    ----------
    method : str
        Among :data:`CLOSED_LOOP_METHODS`.
    setup : ClosedLoopSetup
        The controller, the set-points and whether the controller added the model's torques.
    max_iter : int
        Closed-loop simulations at most (:func:`closed_loop_identify`).
    tol : float
        Relative change of the simulated torques that ends the iterations.

    Raises
    ------
    ConfigError
        An unknown method.
    """

    method: str
    setup: ClosedLoopSetup
    max_iter: int = 10
    tol: float = 1e-4

    def __post_init__(self):
        if self.method not in CLOSED_LOOP_METHODS:
            raise ConfigError(f"closed_loop: {self.method!r} is not a closed-loop estimator (expected "
                              f"{', '.join(CLOSED_LOOP_METHODS)})", field="closed_loop")

    def experiment(self, robot: Robot, recording: Recording) -> ClosedLoopExperiment:
        """The experiment to simulate: the set-points, their derivatives and the feed-forward along them.

        Parameters
        ----------
        robot : Robot
            The model whose torques the controller added along the reference (with ``setup.feedforward``).
        recording : Recording
            The log as read (one set-point per sample).

        Returns
        -------
        ClosedLoopExperiment

        Raises
        ------
        DataError
            A reference without one set-point per sample of the log.
        """
        controller = self.setup.controller
        q_ref = self.setup.reference_positions()
        if q_ref.ndim == 2 and q_ref.shape[1] != robot.n_dof:  # the driven joints' set-points, as a log holds them
            q_ref = robot.coupled(robot.widened(q_ref))[0]
        if q_ref.shape[0] != recording.t.size:
            where = getattr(self.setup.reference, "file", "the reference")
            raise DataError(f"{where}: {q_ref.shape[0]} rows of set-points, the identification log has "
                            f"{recording.t.size} samples: give one set-point per row of the log (and the same rows)")
        dt = 1.0 / controller.rate
        dq_ref = np.gradient(q_ref, dt, axis=0)
        ff = rnea_torques(robot, q_ref, dq_ref, np.gradient(dq_ref, dt, axis=0)) if self.setup.feedforward else None
        return ClosedLoopExperiment(controller, q_ref, dq_ref, ff)

    def added_to(self, result, robot: Robot, base: BaseParameters, recording: Recording, preprocessing: Preprocessing, *,
                 experiment: ClosedLoopExperiment | None = None, data: PreparedData | None = None):
        """An identification's result with this estimate beside its others, on its log as read, at the control rate.

        Parameters
        ----------
        result : dynid.identification.result.IdentificationResult
            The estimates so far.
        robot, base : Robot, BaseParameters
            The model as identified (with the choices the data made) and its base-parameter map.
        recording : Recording
            The identification log as read (the estimator prepares its simulations as it was prepared).
        preprocessing : Preprocessing
            The settings as given (the simulated logs derive theirs as the measured one did).
        experiment : ClosedLoopExperiment, optional
            :meth:`experiment` when the caller has it already (estimators sharing a setup read its set-points once).
        data : PreparedData, optional
            The log as the identification prepared it (:func:`closed_loop_identify`): not prepared again.

        Returns
        -------
        IdentificationResult
            ``result`` with the estimate added (a stop before convergence: the estimate's note and a warning) and its
            consistency checked.

        Raises
        ------
        DataError
            A reference without one set-point per sample of the log.
        """
        t0 = time.perf_counter()
        experiment = experiment if experiment is not None else self.experiment(robot, recording)
        out = closed_loop_identify(robot, base, recording, experiment, methods=(self.method,),
                                   preprocessing=preprocessing, max_iter=self.max_iter, tol=self.tol,
                                   data=data)[self.method]
        std = out.params_std if np.all(np.isfinite(out.params_std)) else None  # DIDIM-SDP: no σ
        estimate = Estimate(self.method, out.params, std, time.perf_counter() - t0, note="" if out.converged else out.message)
        margins, verdicts = consistency_checks(robot, base, {estimate.label: estimate.params})
        return replace(result, estimates={**result.estimates, estimate.label: estimate},
                       warnings=result.warnings + (() if out.converged else (f"{estimate.label}: {out.message}",)),
                       consistency={**result.consistency, **margins},
                       consistency_verdicts={**result.consistency_verdicts, **verdicts})

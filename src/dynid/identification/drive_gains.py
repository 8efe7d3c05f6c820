"""Drive gains and payloads identified from logs of motor currents (eq. 16, τ = K·I).

**Drive gains** (Gautier & Briot, "Global identification of joint drive gains and dynamic parameters of
parallel robots", Multibody System Dynamics 33, 2015). Currents alone fix the model only up to one
scale per joint: ``K_j I_j = W_j β`` holds for ``(c_j K_j, c_j β)`` too. A second run with a payload of
known mass ``m_L`` on the last link breaks the ambiguity. The payload adds ``Δφ`` to the last link's ten
standard parameters: its mass ``m_L`` is known, its first moments and inertia are not. Stacking both
runs, every row of joint ``j`` reads

    K_j·I_j − W_j·β − [loaded]·Y_j,last·Δφ' = [loaded]·Y_j,M·m_L

with unknowns ``K`` (n_dof), the base parameters ``β`` and the identifiable combinations of the
payload's unknown parameters ``Δφ'``; the right-hand side is the known mass's torque. A joint whose
torque the payload's mass never reaches (e.g. the last joint: a mass at its own axis exerts no torque
about it) keeps ``K`` unobservable; its σ is then infinite and the estimate is left out.

**Payload** of a loaded run, given the robot's base parameters and gains: ``K·I − W·β = Y_last·Δφ``,
least squares over the identifiable combinations of the payload's ten parameters (link frame of the
last link, about its origin, eq. 5 order).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg

from .._util.reprs import short_repr
from ..conventions import INERTIAL_TERMS
from ..dynamics.base_parameters import BaseParameters
from ..dynamics.regressor import regressor
from ..estimators.accumulate import LeastSquaresAccumulator, LeastSquaresSolution
from ..exceptions import IdentifiabilityError
from ..model.robot import Robot
from ..preprocessing.bands import difference_noise_std
from ..preprocessing.filters import decimation_cutoff, velocity_noise_std
from ..preprocessing.preparation import base_chunks
from ..preprocessing.prepared import PreparedData


def _link_columns(robot: Robot, link: int | None = None) -> np.ndarray:
    """Indices of link ``link``'s (0-based; default the last) ten inertial parameters in the standard vector."""
    start = (robot.n_dof - 1 if link is None else link) * robot.n_params_per_joint
    return np.arange(start, start + 10)


def _independent(columns: np.ndarray, rng: np.random.Generator, robot: Robot, tol: float = 1e-8) -> np.ndarray:
    """The subset of ``columns`` (standard indices) whose regressor columns are linearly independent on random
    states (QR with column pivoting; Gautier's numerical base-parameter rule)."""
    q, dq, ddq = (rng.uniform(-np.pi, np.pi, (200, robot.n_dof)) for _ in range(3))
    y = regressor(robot, q, dq, ddq)[:, :, columns].reshape(-1, columns.size)
    _, r, piv = scipy.linalg.qr(y, mode="economic", pivoting=True)
    d = np.abs(np.diag(r))
    rank = int(np.sum(d > tol * d[0]))
    return np.sort(columns[piv[:rank]])


MIN_SIGNAL_TO_NOISE = 3.0
"""The known mass's torque on a joint (RMS) must be this many times the joint's residual σ for its gain to count as
determined: below, model error, not the payload, sets the value (Gautier & Briot's method needs the payload to
change each joint's torque well above the noise)."""


@short_repr
@dataclass(frozen=True)
class DriveGainEstimate:
    """Drive gains from a run without and one with a payload of known mass.

    Attributes
    ----------
    gains : (n_dof,) array [N·m/A]
        NaN where not observable.
    gains_std : (n_dof,) array [N·m/A]
        inf where not observable.
    base : (n_base,) array
        Base parameters of the unloaded robot identified with them.
    payload_mass : float [kg]
    n_rows : int
    condition_number : float
    payload_torque : (n_dof,) array [N·m] or None
        RMS over the loaded run of the torque the known mass adds to each joint.
    residual_std : (n_dof,) array [N·m] or None
        Each joint's residual σ in the stacked fit. A gain is not observable where ``payload_torque`` is below
        :data:`MIN_SIGNAL_TO_NOISE` times it and the other joints' equations do not set it.
    undetermined : (n_dof,) array [N·m/A] or None
        What the fit gave for the gains it does not determine (NaN elsewhere), for the record.
    without_own : (n_dof,) array [N·m/A] or None
        The estimate without the joint's own payload torque, for the joints whose payload torque is weak (NaN
        elsewhere): a move beyond 3σ says the weak torque set the value.
    """

    gains: np.ndarray
    gains_std: np.ndarray
    base: np.ndarray
    payload_mass: float
    n_rows: int
    condition_number: float
    payload_torque: np.ndarray | None = None
    residual_std: np.ndarray | None = None
    undetermined: np.ndarray | None = None
    without_own: np.ndarray | None = None

    def why_not_observable(self, j: int) -> str:
        """Why joint ``j``'s gain is not observable ("" when it is).

        Parameters
        ----------
        j : int
            0-based joint.

        Returns
        -------
        str
        """
        if np.isfinite(self.gains[j]):
            return ""
        if self.payload_torque is None or self.residual_std is None:
            return "the payload does not reach this joint"
        ratio = self.payload_torque[j] / max(float(self.residual_std[j]), 1e-300)
        text = (f"the payload adds RMS {self.payload_torque[j]:.3g} N·m to this joint, {ratio:.2g}× its residual σ "
                f"(at least {MIN_SIGNAL_TO_NOISE:g}× needed)")
        if self.undetermined is not None and self.without_own is not None and np.isfinite(self.without_own[j]):
            text += (f"; the fit's {self.undetermined[j]:.4g} N·m/A moves to {self.without_own[j]:.4g} without that "
                     "torque")
        return text

    def to_dict(self) -> dict:
        """JSON-ready estimate.

        Returns
        -------
        dict
            ``gains`` (None where not observable), ``gains_std``, ``payload_mass`` [kg], ``n_rows``,
            ``condition_number``, ``not_observable`` (gain -> why), ``payload_torque_rms`` and ``residual_std`` [N·m].
        """
        out = {"gains": self.gains.tolist(), "gains_std": self.gains_std.tolist(), "payload_mass": self.payload_mass,
               "n_rows": self.n_rows, "condition_number": self.condition_number,
               "not_observable": {f"K{j + 1}": self.why_not_observable(j) for j in range(self.gains.size)
                                  if not np.isfinite(self.gains[j])}}
        if self.payload_torque is not None and self.residual_std is not None:
            out["payload_torque_rms"] = self.payload_torque.tolist()
            out["residual_std"] = self.residual_std.tolist()
        return out


@short_repr
@dataclass(frozen=True)
class PayloadEstimate:
    """Inertial parameters of a payload on the last link (its link frame, about its origin, eq. 5 order).

    Attributes
    ----------
    names : tuple of str
        The identifiable ones (e.g. ``("XX", "XY", …, "M")``; others do not act on the joints).
    values, std : arrays, same length
    """

    names: tuple[str, ...]
    values: np.ndarray
    std: np.ndarray

    @property
    def mass(self) -> float:
        """The payload's mass [kg] (NaN when not identifiable)."""
        return float(self.values[self.names.index("M")]) if "M" in self.names else float("nan")

    @property
    def not_determined(self) -> tuple[str, ...]:
        """The parameters the loaded run does not determine: σ at least their value (the noise sets them)."""
        return tuple(n for n, v, s in zip(self.names, self.values, self.std) if not s < abs(v))

    def to_dict(self) -> dict:
        """JSON-ready payload parameters.

        Returns
        -------
        dict
            name -> {"value", "std", "determined"} in SI units; a parameter whose σ is at least its value is not
            determined by the loaded run.
        """
        lost = set(self.not_determined)
        return {n: {"value": float(v), "std": float(s), "determined": n not in lost}
                for n, v, s in zip(self.names, self.values, self.std)}


def identify_drive_gains(robot: Robot, base: BaseParameters, unloaded: PreparedData, loaded: PreparedData,
                         payload_mass: float, rng=0) -> DriveGainEstimate:
    """Drive gains by the stacked formulation of Gautier & Briot (module docstring).

    Parameters
    ----------
    robot : Robot
    base : BaseParameters
    unloaded, loaded : PreparedData
        The two runs with their ``tau`` holding motor currents [A] (joint side), e.g. loaded through a robot with
        unit drive gains.
    payload_mass : float [kg]
    rng : int
        Seed of the random states that find the payload's identifiable parameters.

    Returns
    -------
    DriveGainEstimate

    Raises
    ------
    IdentifiabilityError
        Too few rows, or nothing makes the gains observable.
    """
    n = robot.n_dof
    last = _independent(_link_columns(robot)[:9], np.random.default_rng(rng), robot)
    mass_col = _link_columns(robot)[9]
    nb, nl = base.n_base, last.size
    p = n + nb + nl
    acc = LeastSquaresAccumulator(p, n)
    noise_sumsq = np.zeros(n)  # Σ over the rows kept of the filtered currents' noise variance, per joint
    known_sumsq, known_rows = np.zeros(n), np.zeros(n)  # the known mass's torque on each joint, on the rows kept
    by_joint = np.zeros((p, n))  # Aᵀb from each joint's rows alone (for the test below)
    for data, is_loaded in ((unloaded, False), (loaded, True)):
        variance = filtered_current_noise(data)
        for _, y, current, keep in base_chunks(robot, base, data, standard=True):
            noise_sumsq += variance * keep.sum(axis=0)
            m = y.shape[0]
            a = np.zeros((m, n, p))
            a[:, np.arange(n), np.arange(n)] = current
            a[:, :, n:n + nb] = -base.base_observation(y)
            rhs = np.zeros((m, n))
            if is_loaded:
                a[:, :, n + nb:] = -y[:, :, last]
                rhs = y[:, :, mass_col] * payload_mass
                known_sumsq += np.sum(np.where(keep, rhs, 0.0) ** 2, axis=0)
                known_rows += keep.sum(axis=0)
            by_joint += np.einsum("mjp,mj->pj", a * keep[:, :, None], rhs)
            acc.add(a.reshape(-1, p), rhs.reshape(-1), keep.reshape(-1))
    sol = _compensated(acc.solve(rcond=1e-12), acc, noise_sumsq)
    gains, std = sol.params[:n].copy(), sol.params_std[:n].copy()
    known = np.sqrt(known_sumsq / np.maximum(known_rows, 1))
    residual = acc.joint_residual_std(sol.params)
    signal_to_noise = known / np.maximum(residual, 1e-300)
    # A gain is determined where the known mass changes the joint's torque well above the residual; elsewhere the
    # covariance's σ, computed as if the model were exact, says nothing of the error (UR10e J1: σ 2 %, the value
    # 26 % off the description's, the payload's torque 1.8× the residual).
    weak = ~(std < 0.5 * np.abs(gains))
    without_own = np.full(n, np.nan)
    r = acc.reduced()[:p, :p]
    for j in np.flatnonzero(~(signal_to_noise >= MIN_SIGNAL_TO_NOISE) & ~weak):
        # A gain whose own payload torque is weak may still be set by the other joints' equations (a wrist joint
        # shares its link's parameters with the joints below it): it is determined if it stays where it is without
        # that torque; if it moves by more than 3σ, the weak torque set it and the σ understates its error.
        # the solution moves by (AᵀA)⁻¹ Aᵀb_j = R⁻¹ R⁻ᵀ Aᵀb_j, R the accumulator's triangular factor
        shift = scipy.linalg.solve_triangular(r, scipy.linalg.solve_triangular(r, by_joint[:, j], trans="T"))
        without_own[j] = sol.params[j] - shift[j]
        weak[j] = not abs(without_own[j] - gains[j]) <= 3 * std[j]
    if np.all(weak):
        raise IdentifiabilityError("drive_gains: the payload's mass makes no joint's gain observable")
    estimate = DriveGainEstimate(gains, std, sol.params[n:n + nb], float(payload_mass), sol.n_rows,
                                 sol.condition_number, known, residual, np.where(weak, gains, np.nan), without_own)
    estimate.gains[weak], estimate.gains_std[weak] = np.nan, np.inf
    return estimate


def filtered_current_noise(data: PreparedData) -> np.ndarray:
    """Variance of the noise left in each joint's current rows after the parallel filter.

    The raw currents' white noise (:func:`dynid.preprocessing.bands.difference_noise_std`, robust to the jumps of
    Coulomb friction) through the zero-phase Butterworth filter the parallel decimation applies
    (:func:`dynid.preprocessing.filters.velocity_noise_std` without differentiation); zero for a strategy that does
    not keep the currents raw until that filter (the paper's eq. 17 smoothing).

    Parameters
    ----------
    data : PreparedData
        Its ``tau`` the raw motor currents [A].

    Returns
    -------
    (n_dof,) ndarray [A²]
    """
    s = data.settings
    n = data.q.shape[1]
    if s.strategy != "parallel":
        return np.zeros(n)
    cutoff = s.parallel_cutoff if s.parallel_cutoff else decimation_cutoff(data.rate, int(s.decimation or 1))
    sigma = difference_noise_std(data.tau)
    return velocity_noise_std(sigma, data.rate, float(cutoff), int(s.order), False) ** 2


def _compensated(sol, acc: LeastSquaresAccumulator, noise_sumsq: np.ndarray):
    """The stacked least squares with the currents' noise taken out of the normal equations (bias-compensated least
    squares, Söderström, "Errors-in-variables methods in system identification", Automatica 43, 2007, §5): a
    current column carries noise of known variance, which adds ``Σ σ²`` to its diagonal of ``AᵀA`` and pulls every
    gain towards zero (on a simulated UR10e at 0.01 A, its wrist gain K5 by 0.9 % on average); subtracting it removes that bias. Falls back
    to plain least squares where the compensated matrix is not positive definite."""
    n, p = noise_sumsq.size, sol.params.size
    r_all = acc.reduced()
    r, z = r_all[:p, :p], r_all[:p, p]
    normal = r.T @ r
    normal[np.arange(n), np.arange(n)] -= noise_sumsq
    try:
        np.linalg.cholesky(normal)
    except np.linalg.LinAlgError:
        return sol
    params = np.linalg.solve(normal, r.T @ z)
    m = sol.n_rows
    sigma2 = float(np.sum(acc.joint_residual_sumsq(params))) / max(m - p, 1)
    cov = sigma2 * np.linalg.inv(normal)
    std = np.sqrt(np.maximum(np.diag(cov), 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = 100.0 * std / np.abs(params)
    return LeastSquaresSolution(params, cov, std, rel, sol.condition_number, float(np.sqrt(sigma2)), m)


def identify_payload(robot: Robot, base: BaseParameters, beta: np.ndarray, loaded: PreparedData, rng=0,
                     gain_ratio=None, link: int | None = None) -> PayloadEstimate:
    """A payload's identifiable inertial parameters from a loaded run.

    Parameters
    ----------
    robot : Robot
    base : BaseParameters
    beta : (n_base,) array
        The unloaded robot's base parameters.
    loaded : PreparedData
        The loaded run, its ``tau`` in N·m.
    rng : int
        Seed of the random states that find the identifiable parameters.
    gain_ratio : (n_dof,) array, optional
        Each joint's torque beyond ``beta`` multiplied by it (identified drive gains over those the torques were read
        with; default 1).
    link : int, optional
        The link carrying the payload, 0-based (the one its joint moves; default the last: on a robot with branches,
        another arm's hand).

    Returns
    -------
    PayloadEstimate
        About that link's frame.

    Raises
    ------
    IdentifiabilityError
        Too few rows or a rank-deficient problem.
    """
    own = _link_columns(robot, link)
    cols = _independent(own, np.random.default_rng(rng), robot)
    acc = LeastSquaresAccumulator(cols.size, robot.n_dof)
    for _, y, tau, keep in base_chunks(robot, base, loaded, standard=True):
        extra = tau - base.base_observation(y) @ beta
        if gain_ratio is not None:
            extra = extra * np.asarray(gain_ratio, dtype=float)
        acc.add(y[:, :, cols].reshape(-1, cols.size), extra.reshape(-1), keep.reshape(-1))
    sol = acc.solve()
    names = tuple(INERTIAL_TERMS[i - own[0]] for i in cols)
    return PayloadEstimate(names, sol.params, sol.params_std)


@short_repr
@dataclass(frozen=True)
class GainsAndPayload:
    """What ``[drive_gains]`` of an identification config gives.

    Attributes
    ----------
    gains : DriveGainEstimate
    payload : PayloadEstimate
    description_gains : tuple of float
        The gains the robot description states, for comparison.
    """

    gains: DriveGainEstimate
    payload: PayloadEstimate
    description_gains: tuple[float, ...]

    def to_dict(self) -> dict:
        """JSON-ready gains, payload and the description's gains.

        Returns
        -------
        dict
        """
        return {**self.gains.to_dict(), "description_gains": list(self.description_gains),
                "payload": self.payload.to_dict(), "payload_frame": "last link's frame, about its origin (eq. 5 order)"}

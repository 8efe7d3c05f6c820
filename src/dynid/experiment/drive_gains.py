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


from dataclasses import dataclass, replace

import numpy as np

import scipy.linalg

from ..conventions import INERTIAL_TERMS
from ..dynamics.base_parameters import BaseParameters
from ..dynamics.regressor import regressor
from ..estimators.accumulate import LeastSquaresAccumulator
from ..exceptions import IdentifiabilityError
from ..model.robot import Robot
from ..preprocessing.pipeline import PreparedData, base_chunks


def _last_link_columns(robot: Robot) -> np.ndarray:
    """Indices of the last link's ten inertial parameters in the standard vector."""
    start = (robot.n_dof - 1) * robot.n_params_per_joint
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
    """

    gains: np.ndarray
    gains_std: np.ndarray
    base: np.ndarray
    payload_mass: float
    n_rows: int
    condition_number: float

    def to_dict(self) -> dict:
        """JSON-ready estimate.

        Returns
        -------
        dict
            ``gains``, ``gains_std``, ``payload_mass`` [kg], ``n_rows``, ``condition_number``.
        """
        return {"gains": self.gains.tolist(), "gains_std": self.gains_std.tolist(), "payload_mass": self.payload_mass,
                "n_rows": self.n_rows, "condition_number": self.condition_number}


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

    def to_dict(self) -> dict:
        """JSON-ready payload parameters.

        Returns
        -------
        dict
            name -> {"value", "std"} in SI units.
        """
        return {n: {"value": float(v), "std": float(s)} for n, v, s in zip(self.names, self.values, self.std)}


def _current_robot(robot: Robot) -> Robot:
    """The same robot with unit gains, so that its datasets' "torques" are the currents."""
    return replace(robot, drive_gains=np.ones(robot.n_dof))


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
    last = _independent(_last_link_columns(robot)[:9], np.random.default_rng(rng), robot)
    mass_col = _last_link_columns(robot)[9]
    nb, nl = base.n_base, last.size
    p = n + nb + nl
    acc = LeastSquaresAccumulator(p, n)
    for data, is_loaded in ((unloaded, False), (loaded, True)):
        for _, y, current, keep in base_chunks(robot, base, data, standard=True):
            m = y.shape[0]
            a = np.zeros((m, n, p))
            a[:, np.arange(n), np.arange(n)] = current
            a[:, :, n:n + nb] = -base.base_observation(y)
            rhs = np.zeros((m, n))
            if is_loaded:
                a[:, :, n + nb:] = -y[:, :, last]
                rhs = y[:, :, mass_col] * payload_mass
            acc.add(a.reshape(-1, p), rhs.reshape(-1), keep.reshape(-1))
    sol = acc.solve(rcond=1e-12)
    gains, std = sol.params[:n].copy(), sol.params_std[:n].copy()
    weak = ~(std < 0.5 * np.abs(gains))  # σ beyond half the value: the payload does not reach that joint
    gains[weak], std[weak] = np.nan, np.inf
    if np.all(weak):
        raise IdentifiabilityError("drive_gains: the payload's mass makes no joint's gain observable")
    return DriveGainEstimate(gains, std, sol.params[n:n + nb], float(payload_mass), sol.n_rows, sol.condition_number)


def identify_payload(robot: Robot, base: BaseParameters, beta: np.ndarray, loaded: PreparedData, rng=0) -> PayloadEstimate:
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

    Returns
    -------
    PayloadEstimate

    Raises
    ------
    IdentifiabilityError
        Too few rows or a rank-deficient problem.
    """
    cols = _independent(_last_link_columns(robot), np.random.default_rng(rng), robot)
    acc = LeastSquaresAccumulator(cols.size, robot.n_dof)
    for _, y, tau, keep in base_chunks(robot, base, loaded, standard=True):
        extra = tau - base.base_observation(y) @ beta
        acc.add(y[:, :, cols].reshape(-1, cols.size), extra.reshape(-1), keep.reshape(-1))
    sol = acc.solve()
    names = tuple(INERTIAL_TERMS[i - _last_link_columns(robot)[0]] for i in cols)
    return PayloadEstimate(names, sol.params, sol.params_std)


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

"""Simulated identification experiments.

Torques come from Pinocchio's RNEA with the truth parameters plus the drive terms (never from dynid's
own regressor). The controller logs motor currents ``I = tau / K`` (eq. 16) with Gaussian noise and
encoder-quantised positions; velocities and accelerations are not measured.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._util.checks import check_vector
from .._util.reprs import short_repr
from ..dynamics.rnea import rnea_torques
from ..exceptions import ConfigError
from ..model.robot import Robot


@dataclass(frozen=True)
class NoiseModel:
    """Measurement imperfections.

    Attributes
    ----------
    current_std : float
        Standard deviation of the motor current noise [A] (same for every joint).
    encoder_resolution : float
        Quantisation step of the joint positions [rad]; 0 disables quantisation.
    """

    current_std: float = 0.05
    encoder_resolution: float = 2 * np.pi / 2**20

    def __post_init__(self) -> None:
        if not (np.isfinite(self.current_std) and self.current_std >= 0):
            raise ConfigError(f"current noise must be a non-negative standard deviation (A), got {self.current_std}")
        if not (np.isfinite(self.encoder_resolution) and self.encoder_resolution >= 0):
            raise ConfigError(f"encoder resolution must be non-negative (rad), got {self.encoder_resolution}")


@short_repr
@dataclass(frozen=True)
class Measurements:
    """One simulated recording. All arrays time-first, (N, n_dof) unless noted.

    Attributes
    ----------
    t : (N,) array [s]
    q : measured (quantised) positions [rad]
    current : measured motor currents [A]
    q_true, dq_true, ddq_true : the commanded motion [rad, rad/s, rad/s²]
    tau_true : noise-free joint torques [N·m]
    """

    t: np.ndarray
    q: np.ndarray
    current: np.ndarray
    q_true: np.ndarray
    dq_true: np.ndarray
    ddq_true: np.ndarray
    tau_true: np.ndarray


def simulate_measurements(robot: Robot, t: np.ndarray, q: np.ndarray, dq: np.ndarray, ddq: np.ndarray,
                          noise: NoiseModel, rng: np.random.Generator,
                          inertial: np.ndarray | None = None, drive: np.ndarray | None = None) -> Measurements:
    """Simulate the recording of a motion sampled at given times.

    Parameters
    ----------
    robot : Robot
        Its drive gains ``K`` convert torques to currents (eq. 16).
    t : (N,) array [s]
    q, dq, ddq : (N, n_dof) arrays
        [rad], [rad/s], [rad/s²].
    noise : NoiseModel
    rng : numpy.random.Generator
    inertial : (n_dof, 10) array, optional
        Truth inertial parameters (the robot's nominal ones by default).
    drive : (n_dof, n_drive_terms) array, optional
        Truth drive parameters (the robot's nominal ones by default).

    Returns
    -------
    Measurements
        Noisy positions and currents with the noise-free torques.
    """
    gains = check_vector(robot.drive_gains, robot.n_dof, "drive gains")
    tau = rnea_torques(robot, q, dq, ddq, inertial=inertial, drive=drive)
    current = tau / gains + rng.normal(0.0, noise.current_std, tau.shape) if noise.current_std > 0 else tau / gains
    if noise.encoder_resolution > 0:
        q_meas = np.round(q / noise.encoder_resolution) * noise.encoder_resolution
    else:
        q_meas = q.copy()
    return Measurements(t=t, q=q_meas, current=current, q_true=q, dq_true=dq, ddq_true=ddq, tau_true=tau)


def torques_from_currents(current: np.ndarray, gains: np.ndarray) -> np.ndarray:
    """Joint torques ``tau = K·I`` (eq. 16).

    Parameters
    ----------
    current : (N, n_dof) array [A]
    gains : (n_dof,) array [N·m/A]

    Returns
    -------
    (N, n_dof) ndarray [N·m]
    """
    return np.asarray(current, dtype=float) * np.asarray(gains, dtype=float)

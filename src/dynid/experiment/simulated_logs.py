"""Logs of a simulated robot, as a controller writes them: to try dynid without a robot, and for examples.

A random Fourier excitation (eq. 14: 5 harmonics of 0.1 Hz, 60 % of each joint's range, within its speed limit),
quantised positions and torques from noisy motor currents through the drive gains (eq. 16), simulated by
:func:`dynid.simulation.measurements.simulate_measurements` with the robot description's own parameters.
"""

from __future__ import annotations

import numpy as np

from ..excitation.fourier import FourierTrajectory
from ..io.datasets import Recording
from ..model.robot import Robot
from ..simulation.measurements import NoiseModel, simulate_measurements, torques_from_currents

__all__ = ["simulated_log"]


def simulated_log(robot: Robot, seconds: float = 30.0, rate: float = 250.0, seed: int = 0,
                  noise: NoiseModel = NoiseModel()) -> Recording:
    """A log of ``robot`` running a random Fourier excitation.

    Parameters
    ----------
    robot : Robot
        The simulation truth is its description's parameters (``robot.standard_parameters()``).
    seconds : float
        Length [s].
    rate : float
        Sampling rate [Hz].
    seed : int
        Seeds the trajectory and the noise.
    noise : NoiseModel
        Current noise [A] and encoder resolution [rad] (default 0.05 A, 20-bit encoders).

    Returns
    -------
    Recording
        ``t`` (N,) [s], ``q`` (N, n_dof) [rad], ``tau`` (N, n_dof) [N·m] (``dq`` None: not logged).

    Raises
    ------
    ConfigError
        A description without physical nominal parameters.
    """
    robot.require_physical_nominal("a simulated log (its truth is the description's parameters)")
    rng = np.random.default_rng(seed)
    n, harmonics, omega = robot.n_dof, 5, 2 * np.pi * 0.1
    lo, hi = np.maximum(robot.limits.q_min, -np.pi), np.minimum(robot.limits.q_max, np.pi)
    k = np.arange(1, harmonics + 1)
    a, b = rng.normal(size=(n, harmonics)) / k, rng.normal(size=(n, harmonics)) / k
    amplitude = np.abs(a).sum(axis=1) + np.abs(b).sum(axis=1)
    speed = omega * (np.abs(a) * k + np.abs(b) * k).sum(axis=1)
    scale = np.minimum(0.6 * (hi - lo) / 2 / amplitude, 0.8 * np.minimum(robot.limits.dq_max, 3.0) / speed)
    trajectory = FourierTrajectory(omega, (lo + hi) / 2, a * scale[:, None], b * scale[:, None])
    t = np.arange(int(round(seconds * rate))) / rate
    q, dq, ddq = trajectory.evaluate(t)
    meas = simulate_measurements(robot, t, q, dq, ddq, noise, rng)
    return Recording(f"simulated {robot.name}, seed {seed}", t, meas.q, None, torques_from_currents(meas.current, robot.drive_gains),
                     float(rate))

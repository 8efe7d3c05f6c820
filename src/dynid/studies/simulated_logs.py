"""Logs of a simulated robot, as a controller writes them: to try dynid without a robot, and for examples.

A random Fourier excitation (eq. 14: 5 harmonics of 0.1 Hz, 60 % of each joint's range, within its speed limit) or a
given one (a designed excitation: eq. 15),
quantised positions and torques from noisy motor currents through the drive gains (eq. 16), simulated by
:func:`dynid.simulation.measurements.simulate_measurements` with the robot description's own parameters.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .._util.keywords import keyword_only_after_data, renamed_keyword, seed_of
from ..exceptions import ConfigError
from ..excitation.fourier import FourierTrajectory
from ..io.logs.datasets import Recording
from ..model.loading import as_robot
from ..model.robot import Robot
from ..simulation.measurements import NoiseModel, simulate_measurements, torques_from_currents
from .simulated_fleet import random_excitation

__all__ = ["simulated_log"]


@renamed_keyword("seed", "rng")
@keyword_only_after_data
def simulated_log(robot: Robot | str | Path, *, seconds: float = 30.0, rate: float = 250.0, rng: int | np.random.Generator = 0,
                  noise: NoiseModel = NoiseModel(), trajectory: FourierTrajectory | None = None) -> Recording:
    """A log of ``robot`` running a Fourier excitation (eq. 14): a random one, or ``trajectory``.

    Parameters
    ----------
    robot : Robot, str or Path
        The simulation truth is its description's parameters (``robot.standard_parameters()``).
        A built-in robot's name or a description's path is loaded (:func:`dynid.model.loading.as_robot`).
    seconds : float
        Length [s].
    rate : float
        Sampling rate [Hz].
    rng : int or numpy.random.Generator
        Seeds the trajectory and the noise (an int: the same log for the same int). Was ``seed`` (still taken, with a
        FutureWarning).
    noise : NoiseModel
        Current noise [A] and encoder resolution [rad] (default 0.05 A, 20-bit encoders).
    trajectory : FourierTrajectory, optional
        The motion, e.g. :func:`dynid.design_excitation`'s ``trajectory`` (eq. 15), from ``t = 0`` (``rng`` then
        draws the noise alone); default a random excitation drawn from ``rng``.

    Returns
    -------
    Recording
        ``t`` (N,) [s], ``q`` (N, n_dof) [rad], ``tau`` (N, n_dof) [N·m] (``dq`` None: not logged); ``q`` the
        description's angles, as :func:`dynid.load_recording` gives a log's (the encoders' angles a CSV of it holds:
        :meth:`dynid.model.transmission.Transmission.logged_positions`).

    Raises
    ------
    ConfigError
        A description without physical nominal parameters, a trajectory of another number of joints, a length or rate
        that is not positive (or gives fewer than two samples), or a negative seed.
    """
    if not (np.isfinite(seconds) and np.isfinite(rate) and seconds > 0 and rate > 0 and round(seconds * rate) >= 2):
        raise ConfigError(f"simulated_log: expected a positive length and rate giving two samples or more, got seconds = "
                          f"{seconds!r} and rate = {rate!r}")
    if isinstance(rng, (int, np.integer)) and not isinstance(rng, bool):
        seed_of(rng)  # a negative seed refused in one line (NumPy's error does not name it)
    robot = as_robot(robot)
    robot.require_physical_nominal("a simulated log (its truth is the description's parameters)")
    generator = np.random.default_rng(rng)
    if trajectory is None:
        trajectory = random_excitation(robot, generator)
    elif np.shape(trajectory.q0) != (robot.n_dof,):
        moved = np.size(trajectory.q0)
        first = f" (its first {moved} joints: the robot's submodel({moved}))" if moved < robot.n_dof else ""
        raise ConfigError(f"simulated_log: the trajectory moves {moved} joints, {robot.name} has {robot.n_dof}{first}")
    t = np.arange(int(round(seconds * rate))) / rate
    q, dq, ddq = robot.coupled(*trajectory.evaluate(t))  # a joint that follows another (<mimic>) moves as it says
    meas = simulate_measurements(robot, t, q, dq, ddq, noise, generator)
    seeded = f", seed {int(rng)}" if isinstance(rng, (int, np.integer)) else ""
    tau = torques_from_currents(meas.current, robot.drive_gains)
    if robot.followers:  # no drive, no sensor: its column reads 0, as a log read for the robot gives it
        tau[:, list(robot.followers)] = 0.0
    return Recording(f"simulated {robot.name}{seeded}", t, meas.q, None, tau, float(rate),
                     prismatic=tuple(robot.prismatic.tolist()), followers=robot.followers)

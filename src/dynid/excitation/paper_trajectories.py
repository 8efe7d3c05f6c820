"""The paper's excitation (β1, eq. A.1) and validation (β2, eq. A.2) trajectories, joints 1-3.

Each row is read as ``[q_o, a_1..a_N, b_1..b_N]`` (eq. 14). The source lost the first number of β1's
third row (only ten numbers survive): dynid uses ``q_o = 0`` for joint 3 there. The paper's fundamental
frequency is 0.05 Hz, ``omega_f = 2 pi · 0.05 rad/s`` (period 20 s; the paper records 25 s).
"""

from __future__ import annotations

import numpy as np

from .fourier import FourierTrajectory

PAPER_OMEGA_F: float = 2.0 * np.pi * 0.05
"""Fundamental pulsation of the paper's trajectories [rad/s] (0.05 Hz)."""

PAPER_DURATION: float = 25.0
"""Recording length of the paper's experiment [s]."""

PAPER_RATE: float = 1000.0
"""Sampling rate of the paper's experiment [Hz]."""

BETA1_ROWS = np.array([
    [-0.3857, -0.1911, -0.2842, -0.2289, -0.2455, -0.5705, 0.3359, 0.4129, 0.5744, 0.4842, 0.0730],
    [0.0011, 0.3597, -0.0179, -0.0117, 0.0443, 0.4355, 0.2551, 0.0386, 0.0411, 0.0057, -0.0065],
    [0.0, -0.1638, 0.5347, -0.1448, 0.1029, 0.0826, 0.4426, 0.3359, 0.6126, -0.6714, -0.5792],  # q_o lost in the source: 0
])
"""Appendix A, eq. A.1: five-harmonic identification trajectory."""

BETA2_ROWS = np.array([
    [0.3016, 0.4006, 0.6921, -0.4210, -0.0423, 0.6066, -0.9719],
    [-0.5026, -0.0051, 0.0492, 0.8074, 0.4578, -0.2521, 0.6288],
    [-0.1276, -0.0624, 0.3805, 0.4006, 0.3016, 0.3531, 0.1524],
])
"""Appendix A, eq. A.2: three-harmonic validation trajectory."""


def paper_identification_trajectory(omega_f: float = PAPER_OMEGA_F, n_dof: int = 3) -> FourierTrajectory:
    """β1 (eq. A.1), five harmonics; joints beyond three reuse rows 1-3 (the paper gives no wrist trajectory).

    Parameters
    ----------
    omega_f : float [rad/s]
        Fundamental pulsation.
    n_dof : int

    Returns
    -------
    FourierTrajectory
    """
    return FourierTrajectory.from_rows(BETA1_ROWS[[j % 3 for j in range(n_dof)]], omega_f)


def paper_validation_trajectory(omega_f: float = PAPER_OMEGA_F, n_dof: int = 3) -> FourierTrajectory:
    """β2 (eq. A.2), three harmonics; joints beyond three reuse rows 1-3.

    Parameters
    ----------
    omega_f : float [rad/s]
        Fundamental pulsation.
    n_dof : int

    Returns
    -------
    FourierTrajectory
    """
    return FourierTrajectory.from_rows(BETA2_ROWS[[j % 3 for j in range(n_dof)]], omega_f)

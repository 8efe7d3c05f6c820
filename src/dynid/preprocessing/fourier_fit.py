"""Velocities and accelerations from a least-squares Fourier fit of the positions (paper §3.3, ref. [19]).

When the robot tracks a known periodic excitation (eq. 14), its positions are fitted by linear least
squares on the known harmonics ``1, sin(k w_f t), cos(k w_f t)``; the derivatives of the fitted series
give noise-free velocities and accelerations (Swevers et al., IEEE TRA 13(5), 1997).
"""

from __future__ import annotations

import numpy as np

from ..exceptions import ConfigError
from ..excitation.fourier import FourierTrajectory


def fourier_fit_derivatives(t: np.ndarray, q: np.ndarray, omega_f: float, n_harmonics: int):
    """Fit ``q`` on ``n_harmonics`` harmonics of ``omega_f`` and differentiate.

    Parameters
    ----------
    t : (N,) array [s]
    q : (N, n_dof) array [rad]
    omega_f : float [rad/s]
    n_harmonics : int >= 1

    Returns
    -------
    q_fit, dq, ddq : (N, n_dof) arrays
    trajectory : FourierTrajectory
        The fitted coefficients.

    Raises
    ------
    ConfigError
        If there are too few samples for the number of coefficients.
    """
    if n_harmonics < 1:
        raise ConfigError(f"number of harmonics must be >= 1, got {n_harmonics}")
    t = np.asarray(t, dtype=float)
    q = np.asarray(q, dtype=float)
    if t.shape[0] < 2 * n_harmonics + 1:
        raise ConfigError(f"Fourier fit with {n_harmonics} harmonics needs at least {2 * n_harmonics + 1} samples, got {t.shape[0]}")
    wk = omega_f * np.arange(1, n_harmonics + 1)
    basis = np.concatenate([np.ones((t.size, 1)), np.sin(np.outer(t, wk)), np.cos(np.outer(t, wk))], axis=1)
    coef = np.linalg.lstsq(basis, q, rcond=None)[0]  # (2N+1, n_dof)
    traj = FourierTrajectory.from_rows(coef.T, omega_f)
    q_fit, dq, ddq = traj.evaluate(t)
    return q_fit, dq, ddq, traj

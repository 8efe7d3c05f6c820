"""Finite Fourier series excitation trajectories (paper eq. 14)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..exceptions import ConfigError


@dataclass(frozen=True)
class FourierTrajectory:
    """``q_i(t) = q_io + sum_k a_ik sin(k w_f t) + b_ik cos(k w_f t)`` (paper eq. 14).

    Attributes
    ----------
    omega_f : float
        Fundamental pulsation w_f [rad/s]; the period is ``2 pi / omega_f``.
    q0 : (n_dof,) array
        Offsets q_io [rad].
    a, b : (n_dof, n_harmonics) arrays
        Sine and cosine amplitudes [rad].
    """

    omega_f: float
    q0: np.ndarray
    a: np.ndarray
    b: np.ndarray

    def __post_init__(self) -> None:
        if not (np.isfinite(self.omega_f) and self.omega_f > 0):
            raise ConfigError(f"fundamental pulsation must be positive (rad/s), got {self.omega_f}")
        if self.a.shape != self.b.shape or self.a.shape[0] != self.q0.shape[0]:
            raise ConfigError(f"Fourier coefficients disagree: q0 {self.q0.shape}, a {self.a.shape}, b {self.b.shape}")

    @property
    def n_dof(self) -> int:
        return self.q0.shape[0]

    @property
    def n_harmonics(self) -> int:
        return self.a.shape[1]

    @property
    def period(self) -> float:
        return 2.0 * np.pi / self.omega_f

    @classmethod
    def from_rows(cls, rows, omega_f: float) -> "FourierTrajectory":
        """From the paper's layout: one row per joint, ``[q_o, a_1..a_N, b_1..b_N]`` (Appendix A)."""
        rows = np.atleast_2d(np.asarray(rows, dtype=float))
        if rows.shape[1] % 2 != 1:
            raise ConfigError(f"expected rows of 2N+1 coefficients [q_o, a_1..a_N, b_1..b_N], got {rows.shape[1]}")
        nh = (rows.shape[1] - 1) // 2
        return cls(float(omega_f), rows[:, 0].copy(), rows[:, 1:1 + nh].copy(), rows[:, 1 + nh:].copy())

    def to_rows(self) -> np.ndarray:
        """Inverse of :meth:`from_rows`: (n_dof, 2N+1)."""
        return np.concatenate([self.q0[:, None], self.a, self.b], axis=1)

    def evaluate(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Positions, velocities and accelerations at times ``t`` (N,), each of shape (N, n_dof)."""
        t = np.asarray(t, dtype=float)
        k = np.arange(1, self.n_harmonics + 1)
        wk = k * self.omega_f
        s, c = np.sin(np.outer(t, wk)), np.cos(np.outer(t, wk))  # (N, nh)
        q = self.q0 + s @ self.a.T + c @ self.b.T
        dq = (c * wk) @ self.a.T - (s * wk) @ self.b.T
        ddq = -(s * wk**2) @ self.a.T - (c * wk**2) @ self.b.T
        return q, dq, ddq

    def to_dict(self) -> dict:
        return {"form": "paper eq. 14", "omega_f": self.omega_f, "q0": self.q0.tolist(),
                "a": self.a.tolist(), "b": self.b.tolist()}


def sample_times(duration: float, rate: float) -> np.ndarray:
    """Uniform sample times ``0, 1/rate, ...`` covering ``duration`` seconds (N = round(duration*rate)).

    Raises
    ------
    ConfigError
        If the duration or the rate is not positive.
    """
    if not (np.isfinite(duration) and duration > 0):
        raise ConfigError(f"duration must be positive (s), got {duration}")
    if not (np.isfinite(rate) and rate > 0):
        raise ConfigError(f"sampling rate must be positive (Hz), got {rate}")
    n = int(round(duration * rate))
    if n < 10:
        raise ConfigError(f"duration × rate gives {n} samples, expected at least 10")
    return np.arange(n) / rate

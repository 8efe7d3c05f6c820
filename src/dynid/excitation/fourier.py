"""Finite Fourier series excitation trajectories (paper eq. 14)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._util.keywords import keyword_only_after_data
from .._util.reprs import short_repr
from ..exceptions import ConfigError


@short_repr
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
        """Number of joints."""
        return self.q0.shape[0]

    @property
    def n_harmonics(self) -> int:
        """Number of harmonics N of each joint's series."""
        return self.a.shape[1]

    @property
    def period(self) -> float:
        """Period ``2π / ω_f`` of the trajectory [s]."""
        return 2.0 * np.pi / self.omega_f

    @classmethod
    def from_rows(cls, rows, omega_f: float) -> FourierTrajectory:
        """A trajectory from the paper's layout (Appendix A).

        Parameters
        ----------
        rows : (n_dof, 2N+1) array_like
            One row per joint, ``[q_o, a_1..a_N, b_1..b_N]`` [rad] (eq. 14).
        omega_f : float
            Fundamental pulsation ω_f [rad/s].

        Returns
        -------
        FourierTrajectory
        """
        rows = np.atleast_2d(np.asarray(rows, dtype=float))
        if rows.shape[1] % 2 != 1:
            raise ConfigError(f"expected rows of 2N+1 coefficients [q_o, a_1..a_N, b_1..b_N], got {rows.shape[1]}")
        nh = (rows.shape[1] - 1) // 2
        return cls(float(omega_f), rows[:, 0].copy(), rows[:, 1:1 + nh].copy(), rows[:, 1 + nh:].copy())

    def to_rows(self) -> np.ndarray:
        """Inverse of :meth:`from_rows`.

        Returns
        -------
        (n_dof, 2N+1) ndarray
            ``[q_o, a_1..a_N, b_1..b_N]`` per joint [rad].
        """
        return np.concatenate([self.q0[:, None], self.a, self.b], axis=1)

    def evaluate(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Positions, velocities and accelerations of eq. 14 and its derivatives.

        Parameters
        ----------
        t : (N,) array_like
            Times [s].

        Returns
        -------
        q, dq, ddq : (N, n_dof) ndarray
            [rad], [rad/s], [rad/s²].
        """
        t = np.asarray(t, dtype=float)
        k = np.arange(1, self.n_harmonics + 1)
        wk = k * self.omega_f
        s, c = np.sin(np.outer(t, wk)), np.cos(np.outer(t, wk))  # (N, nh)
        q = self.q0 + s @ self.a.T + c @ self.b.T
        dq = (c * wk) @ self.a.T - (s * wk) @ self.b.T
        ddq = -(s * wk**2) @ self.a.T - (c * wk**2) @ self.b.T
        return q, dq, ddq

    @classmethod
    def from_swevers(cls, q0, a, b, omega_f: float) -> FourierTrajectory:
        """A trajectory from the Swevers form.

        ``q_i = q_i0 + Σ_l a_il/(l ω_f) sin(l ω_f t) - b_il/(l ω_f) cos(l ω_f t)`` (Swevers, Ganseman, Tükel,
        de Schutter, Van Brussel, IEEE TRA 13(5), 1997).

        Parameters
        ----------
        q0 : (n_dof,) array_like
            Offsets [rad].
        a, b : (n_dof, N) array_like
            Velocity amplitudes [rad/s].
        omega_f : float
            Fundamental pulsation ω_f [rad/s].

        Returns
        -------
        FourierTrajectory
        """
        a, b = np.atleast_2d(np.asarray(a, dtype=float)), np.atleast_2d(np.asarray(b, dtype=float))
        lw = omega_f * np.arange(1, a.shape[1] + 1)
        return cls(float(omega_f), np.asarray(q0, dtype=float).copy(), a / lw, -b / lw)

    def to_swevers(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Inverse of :meth:`from_swevers`.

        Returns
        -------
        q0 : (n_dof,) ndarray
            Offsets [rad].
        a, b : (n_dof, N) ndarray
            Velocity amplitudes [rad/s].
        """
        lw = self.omega_f * np.arange(1, self.n_harmonics + 1)
        return self.q0.copy(), self.a * lw, -self.b * lw

    @keyword_only_after_data
    def to_dict(self, *, form: str = "paper") -> dict:
        """JSON-ready coefficients; read back by :func:`trajectory_from_dict`.

        Parameters
        ----------
        form : {"paper", "swevers"}
            The paper's form (eq. 14) or the Swevers form.

        Returns
        -------
        dict
            ``form``, ``omega_f`` [rad/s] and the coefficients per joint.
        """
        if form == "swevers":
            q0, a, b = self.to_swevers()
            return {"form": "swevers", "omega_f": self.omega_f, "q0": q0.tolist(), "a": a.tolist(), "b": b.tolist()}
        if form != "paper":
            raise ConfigError(f"trajectory form must be 'paper' or 'swevers', got {form!r}")
        return {"form": "paper", "omega_f": self.omega_f, "q0": self.q0.tolist(),
                "a": self.a.tolist(), "b": self.b.tolist()}


FORMS = ("paper", "swevers")


def trajectory_from_dict(d: dict, source: str = "trajectory") -> FourierTrajectory:
    """A trajectory from :meth:`FourierTrajectory.to_dict` output.

    Parameters
    ----------
    d : dict
        ``form`` ("paper", eq. 14, or "swevers"), ``omega_f`` and the coefficients.
    source : str
        Where ``d`` comes from, named in error messages.

    Returns
    -------
    FourierTrajectory

    Raises
    ------
    ConfigError
        A missing or malformed field, named with ``source``.
    """
    if not isinstance(d, dict):
        raise ConfigError(f"{source}: expected an object with form, omega_f, q0, a, b")
    form = d.get("form", "paper")
    if form == "paper eq. 14":  # results.json of earlier `dynid run`s
        form = "paper"
    if form not in FORMS:
        raise ConfigError(f"{source}: form must be one of {', '.join(FORMS)}, got {form!r}")
    for key in ("omega_f", "q0", "a", "b"):
        if key not in d:
            raise ConfigError(f"{source}: missing field {key!r}")
    try:
        omega_f = float(d["omega_f"])
        q0 = np.asarray(d["q0"], dtype=float).reshape(-1)
        a, b = (np.asarray(d[k], dtype=float) for k in ("a", "b"))
    except (TypeError, ValueError):
        raise ConfigError(f"{source}: omega_f, q0, a and b must be numbers (a, b: one list per joint)") from None
    if a.ndim != 2 or a.shape != b.shape or a.shape[0] != q0.size or a.shape[1] < 1:
        raise ConfigError(f"{source}: expected a and b of shape (n_dof, n_harmonics) with n_dof = {q0.size} "
                          f"(the length of q0), got {a.shape} and {b.shape}")
    if not all(np.all(np.isfinite(x)) for x in (q0, a, b)):
        raise ConfigError(f"{source}: coefficients must be finite")
    if form == "swevers":
        return FourierTrajectory.from_swevers(q0, a, b, omega_f)
    return FourierTrajectory(omega_f, q0, a, b)


def sample_times(duration: float, rate: float) -> np.ndarray:
    """Uniform sample times ``0, 1/rate, ...`` covering ``duration`` seconds.

    Parameters
    ----------
    duration : float
        [s], > 0.
    rate : float
        Sample rate [Hz], > 0.

    Returns
    -------
    (N,) ndarray
        Times [s], N = round(duration·rate).

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

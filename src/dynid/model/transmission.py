"""Transmissions: gear ratios, coupled joints (e.g. a coupled wrist) and encoder zeros.

Motor angles follow the joint angles through a constant matrix ``R`` (``theta_m = R q``, with the
gear ratios on its diagonal); by the principle of virtual work the joint torques follow the motor
torques through its transpose (``tau = Rᵀ tau_m``). A motor ``k`` whose row of ``R`` has entries
off the diagonal turns with several joints (the Stäubli TX40's motor 6 turns with joints 5 and 6),
so its inertia and friction couple the joints' equations. With ``c = R[k] / R[k, k]`` (``c_k = 1``)
those coupling parameters have the regressor columns (time-first, one row per joint)::

    Iam_k :  (c cᵀ - diag(c²)) @ ddq      inertia of motor k, off-diagonal part
    fvm_k :  (c cᵀ - diag(c²)) @ dq       viscous friction of motor k, off-diagonal part
    fcm_k :  c · sign(c · dq)             Coulomb friction of motor k

The diagonal parts of the first two are collinear with the joints' own ``Ia`` and ``fv`` columns and
are absorbed by them. For the TX40 this is FIGAROH's parameterisation (joint-5 row
``[ddq6, dq6, sign(dq5 + dq6)]``, joint-6 row ``[ddq5, dq5, sign(dq5 + dq6)]``), all in joint units.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from .._util.reprs import short_repr
from ..conventions import COUPLING_TERMS
from ..exceptions import ConfigError


@short_repr
@dataclass(frozen=True)
class Transmission:
    """Joint-to-motor transmission of an n-joint robot.

    Attributes
    ----------
    motor_from_joint : (n, n) array
        ``R`` with ``theta_m = R q`` (motor angles from joint angles); gear ratios on the diagonal.
    position_offset : (n,) array
        Added to measured joint angles to get the model's joint angles [rad] (encoder zero vs model zero).
    coupled_terms : tuple of str
        Coupling parameters identified for every coupled motor, a subset of ``COUPLING_TERMS``.
    coupled_values : (n_coupled, len(coupled_terms)) array
        Their nominal values (joint units).
    """

    motor_from_joint: np.ndarray
    position_offset: np.ndarray
    coupled_terms: tuple[str, ...] = ()
    coupled_values: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))

    def __post_init__(self) -> None:
        r = np.asarray(self.motor_from_joint, dtype=float)
        n = r.shape[0]
        if r.shape != (n, n) or n == 0:
            raise ConfigError(f"transmission: expected a square motor_from_joint matrix, got shape {r.shape}")
        if np.any(np.diag(r) == 0) or not np.all(np.isfinite(r)):
            raise ConfigError("transmission: every gear ratio (diagonal of motor_from_joint) must be finite and non-zero")
        if abs(np.linalg.det(r)) < 1e-12 * max(1.0, np.abs(r).max()) ** n:
            raise ConfigError("transmission: motor_from_joint is singular, joint angles cannot be recovered from motor angles")
        bad = [t for t in self.coupled_terms if t not in COUPLING_TERMS]
        if bad:
            raise ConfigError(f"transmission: unknown coupled term(s) {bad}, expected a subset of {list(COUPLING_TERMS)}")
        values = np.asarray(self.coupled_values, dtype=float)
        if values.size == 0:
            values = np.zeros((len(self.coupled_motors_of(r)), len(self.coupled_terms)))
        if values.shape != (len(self.coupled_motors_of(r)), len(self.coupled_terms)):
            raise ConfigError(f"transmission: expected coupled values of shape {(len(self.coupled_motors_of(r)), len(self.coupled_terms))}, got {values.shape}")
        offset = np.asarray(self.position_offset, dtype=float)
        if offset.shape != (n,):
            raise ConfigError(f"transmission: expected {n} position offsets, got shape {offset.shape}")
        object.__setattr__(self, "motor_from_joint", r)
        object.__setattr__(self, "position_offset", offset)
        object.__setattr__(self, "coupled_values", values)
        for a in (r, offset, values):
            a.setflags(write=False)

    @staticmethod
    def coupled_motors_of(r: np.ndarray) -> tuple[int, ...]:
        """The motors that also turn with other joints (a coupled wrist).

        Parameters
        ----------
        r : (n, n) array
            Motor-from-joint matrix.

        Returns
        -------
        tuple of int
            0-based motor indices.
        """
        off = np.asarray(r) - np.diag(np.diag(r))
        return tuple(int(k) for k in np.flatnonzero(np.any(off != 0, axis=1)))

    @classmethod
    def identity(cls, n: int) -> Transmission:
        """Direct drive on the joint side: ``R = I``, no offsets, no coupling.

        Parameters
        ----------
        n : int
            Joints.

        Returns
        -------
        Transmission
        """
        return cls(np.eye(n), np.zeros(n))

    @property
    def n_dof(self) -> int:
        """Joints (and motors)."""
        return self.motor_from_joint.shape[0]

    @cached_property
    def coupled_motors(self) -> tuple[int, ...]:
        """0-based indices of the motors that turn with more than one joint."""
        return self.coupled_motors_of(self.motor_from_joint)

    @cached_property
    def _coupling(self) -> tuple[tuple[np.ndarray, np.ndarray], ...]:
        """Per coupled motor, ``c`` and ``c cᵀ - diag(c²)`` (module docstring), computed once: a closed-loop
        simulation asks for the coupling columns four times a control period."""
        return tuple((self.ratios(k), np.outer(self.ratios(k), self.ratios(k)) - np.diag(self.ratios(k) ** 2))
                     for k in self.coupled_motors)

    @property
    def n_coupled_params(self) -> int:
        """Parameters of the coupled motors (coupled motors × coupled terms)."""
        return len(self.coupled_motors) * len(self.coupled_terms)

    @property
    def coupled_parameter_names(self) -> tuple[str, ...]:
        """``Iam6, fvm6, fcm6`` …: coupled motor by motor (1-based motor number), terms in order."""
        return tuple(f"{t}{k + 1}" for k in self.coupled_motors for t in self.coupled_terms)

    def ratios(self, k: int) -> np.ndarray:
        """The ratios ``c = R[k] / R[k, k]`` of motor ``k``.

        Parameters
        ----------
        k : int
            0-based motor.

        Returns
        -------
        (n,) array
        """
        r = self.motor_from_joint
        return r[k] / r[k, k]

    def coupling_columns(self, dq: np.ndarray, ddq: np.ndarray) -> np.ndarray:
        """Regressor columns of the coupling parameters (module docstring).

        Parameters
        ----------
        dq, ddq : (N, n_dof) arrays [rad/s, rad/s²]

        Returns
        -------
        (N, n_dof, n_coupled_params) array
        """
        n_s = dq.shape[0]
        out = np.zeros((n_s, self.n_dof, self.n_coupled_params))
        col = 0
        for c, off in self._coupling:
            for term in self.coupled_terms:
                if term == "Iam":
                    out[:, :, col] = ddq @ off.T
                elif term == "fvm":
                    out[:, :, col] = dq @ off.T
                else:  # fcm
                    out[:, :, col] = np.sign(dq @ c)[:, None] * c
                col += 1
        return out

    def joint_positions(self, theta_m: np.ndarray) -> np.ndarray:
        """Model joint angles from motor angles: ``R⁻¹ theta_m + offset``.

        Parameters
        ----------
        theta_m : (N, n) array [rad]

        Returns
        -------
        (N, n) array [rad]
        """
        return np.linalg.solve(self.motor_from_joint, np.asarray(theta_m, dtype=float).T).T + self.position_offset

    def logged_positions(self, q: np.ndarray) -> np.ndarray:
        """The angles the joints' encoders (and their controller) read at model joint angles ``q``: ``q - offset``,
        what a log holds and a reader adds ``position_offset`` back to (:func:`dynid.io.logs.datasets.load_recording`).

        Parameters
        ----------
        q : (N, n) array [rad]

        Returns
        -------
        (N, n) array [rad]
        """
        return np.asarray(q, dtype=float) - self.position_offset

    def joint_velocities(self, dtheta_m: np.ndarray) -> np.ndarray:
        """Joint velocities (or accelerations) from motor ones: ``R⁻¹ dtheta_m``.

        Parameters
        ----------
        dtheta_m : (N, n) array [rad/s or rad/s²]

        Returns
        -------
        (N, n) array
        """
        return np.linalg.solve(self.motor_from_joint, np.asarray(dtheta_m, dtype=float).T).T

    def joint_torques(self, tau_m: np.ndarray) -> np.ndarray:
        """Joint torques from motor torques: ``tau = Rᵀ tau_m``.

        Parameters
        ----------
        tau_m : (N, n) array [N·m]

        Returns
        -------
        (N, n) array [N·m]
        """
        return np.asarray(tau_m, dtype=float) @ self.motor_from_joint

    def subset(self, k: int) -> Transmission:
        """The transmission of the first ``k`` joints.

        Parameters
        ----------
        k : int

        Returns
        -------
        Transmission

        Raises
        ------
        ConfigError
            A coupling links them to the others.
        """
        r = self.motor_from_joint
        if np.any(r[:k, k:] != 0) or np.any(r[k:, :k] != 0):
            raise ConfigError(f"transmission couples joints 1-{k} with joints beyond {k}: cannot hold the latter still")
        keep = [i for i, m in enumerate(self.coupled_motors) if m < k]
        return Transmission(r[:k, :k].copy(), self.position_offset[:k].copy(), self.coupled_terms,
                            self.coupled_values[keep].copy())

"""Drive and friction terms of a joint (paper eq. 3 and its usual extensions): one table, stated once.

Every term is linear in its coefficient, so the joint torque stays linear in the parameters
(τ = Φ·θ). Each :class:`FrictionTerm` says its name, unit, sign constraint, other spellings found in
published sets, its regressor column as a function of the joint state, and that column's derivative
with respect to the velocity (for the excitation design's chain rule). The regressor, the simulator,
the sensitivities, the constrained estimators' layout, the description parser and the name/unit
conventions all read this table: **adding a term is one entry in** :data:`TERMS`.

The smooth Coulomb and Stribeck columns use per-joint velocities that the robot carries
(:attr:`dynid.model.robot.Robot.coulomb_velocity`, :attr:`~dynid.model.robot.Robot.stribeck_velocity`).

This module sits at the bottom layer (beside :mod:`dynid.conventions`) because the robot description
(model layer) and the conventions read it, and lower layers never import higher ones.

References: Armstrong-Hélouvry, Dupont & Canudas de Wit, "A survey of models, analysis tools and
compensation methods for the control of machines with friction", Automatica 30(7), 1994 (Coulomb,
viscous, Stribeck); Olsson, Åström et al., Eur. J. Control 4(3), 1998 (smooth Coulomb approximations).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np


def coulomb_column(dq: np.ndarray, velocity) -> np.ndarray:
    """``sign(dq)``, or ``tanh(dq / v_s)`` for the joints with ``v_s > 0``.

    Parameters
    ----------
    dq : (N, n_dof) array [rad/s]
    velocity : (n_dof,) array or float [rad/s]
        Smoothing velocity ``v_s`` per joint (0: sign).

    Returns
    -------
    (N, n_dof) array, in [-1, 1].
    """
    dq = np.asarray(dq, dtype=float)
    vs = np.broadcast_to(np.asarray(velocity, dtype=float), dq.shape[-1:])
    smooth = vs > 0
    out = np.sign(dq)
    if smooth.any():
        out[..., smooth] = np.tanh(dq[..., smooth] / vs[smooth])
    return out


def _coulomb_dq(dq, v):
    """d/d(dq) of :func:`coulomb_column`: 0 for sign (almost everywhere), (1 - tanh²)/v_s for tanh."""
    vs = np.broadcast_to(np.asarray(v.coulomb, dtype=float), dq.shape[-1:])
    safe = np.where(vs > 0, vs, 1.0)
    return np.where(vs > 0, (1.0 - np.tanh(dq / safe) ** 2) / safe, 0.0)


def _stribeck(dq, v):
    return np.sign(dq) * np.exp(-(dq / v.stribeck) ** 2)


def _stribeck_dq(dq, v):
    return -2.0 * np.abs(dq) / v.stribeck**2 * np.exp(-(dq / v.stribeck) ** 2)


@dataclass(frozen=True)
class Velocities:
    """Per-joint velocities some columns need: Coulomb smoothing and Stribeck velocities [rad/s] (n_dof,)."""

    coulomb: np.ndarray
    stribeck: np.ndarray


@dataclass(frozen=True)
class FrictionTerm:
    """One drive/friction term of a joint.

    Attributes
    ----------
    name : str
        Parameter stem (``"fc"`` → ``fc1``, ``fc2`` …).
    unit : str
        Unit of the coefficient.
    nonnegative : bool
        Physically ≥ 0 (constrained estimators and the consistency check impose it).
    column : callable ``(dq, ddq, velocities) -> (N, n_dof)``
        Regressor column of each joint (the torque is ``coefficient × column``).
    d_dq : callable ``(dq, velocities) -> (N, n_dof)``
        Derivative of the column with respect to the joint's own velocity.
    d_ddq : float
        Derivative with respect to the joint's own acceleration (constant: the columns are linear in ddq).
    aliases : tuple of str
        Other spellings in published sets (FIGAROH, MATLAB toolboxes).
    description : str
    """

    name: str
    unit: str
    nonnegative: bool
    column: Callable
    d_dq: Callable
    d_ddq: float
    aliases: tuple[str, ...]
    description: str


TERMS: dict[str, FrictionTerm] = {t.name: t for t in (
    FrictionTerm("Ia", "kg·m²", True, lambda dq, ddq, v: ddq, lambda dq, v: np.zeros_like(dq), 1.0, ("Jm",),
                 "rotor (reflected motor) inertia, Ia·ddq"),
    FrictionTerm("fc", "N·m", True, lambda dq, ddq, v: coulomb_column(dq, v.coulomb), _coulomb_dq, 0.0, ("fs", "Fc"),
                 "Coulomb friction, fc·sign(dq) (eq. 3), or fc·tanh(dq/v_s) with a smoothing velocity"),
    FrictionTerm("fv", "N·m·s/rad", True, lambda dq, ddq, v: dq, lambda dq, v: np.ones_like(dq), 0.0, ("Fv",),
                 "viscous friction, fv·dq (eq. 3)"),
    FrictionTerm("offset", "N·m", False, lambda dq, ddq, v: np.ones_like(dq), lambda dq, v: np.zeros_like(dq), 0.0,
                 ("f0", "off"), "constant torque offset (current sensor offset, asymmetric Coulomb friction)"),
    FrictionTerm("fst", "N·m", True, lambda dq, ddq, v: _stribeck(dq, v), _stribeck_dq, 0.0, (),
                 "Stribeck friction, fst·sign(dq)·exp(-(dq/v_st)²) with a given Stribeck velocity v_st"),
)}
"""The table: every drive/friction term dynid knows, in the order of the parameter vector."""

DEFAULT_TERMS: tuple[str, ...] = ("fc", "fv")
"""The paper's friction model (eq. 3): Coulomb and viscous friction."""

DEFAULT_STRIBECK_VELOCITY = 0.01
"""Stribeck velocity [rad/s] when a description uses ``fst`` without giving one."""


def term_names() -> tuple[str, ...]:
    """Names of the terms of :data:`TERMS`, in table order."""
    return tuple(TERMS)


def check_terms(terms, where: str) -> tuple[str, ...]:
    """Terms in table order; an unknown name is a ``ValueError`` naming ``where`` (never an offset)."""
    bad = [t for t in terms if t not in TERMS]
    if bad:
        raise ValueError(f"{where}: unknown drive term(s) {bad}, expected a subset of {list(TERMS)}")
    return tuple(t for t in TERMS if t in terms)


def drive_columns(terms, dq: np.ndarray, ddq: np.ndarray, velocities: Velocities) -> np.ndarray:
    """Columns of ``terms`` for every joint: (N, n_dof, len(terms))."""
    dq, ddq = np.asarray(dq, dtype=float), np.asarray(ddq, dtype=float)
    if not terms:
        return np.zeros(dq.shape + (0,))
    return np.stack([TERMS[t].column(dq, ddq, velocities) for t in terms], axis=-1)


def drive_column_derivatives(terms, dq: np.ndarray, velocities: Velocities) -> tuple[np.ndarray, np.ndarray]:
    """Derivatives of the columns of ``terms`` with respect to the joint's own velocity and acceleration,
    each (N, n_dof, len(terms))."""
    dq = np.asarray(dq, dtype=float)
    d_dq = np.stack([TERMS[t].d_dq(dq, velocities) for t in terms], axis=-1)
    d_ddq = np.broadcast_to(np.array([TERMS[t].d_ddq for t in terms]), dq.shape + (len(terms),))
    return d_dq, d_ddq


def nonnegative_terms() -> tuple[str, ...]:
    return tuple(t.name for t in TERMS.values() if t.nonnegative)

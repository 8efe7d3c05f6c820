"""Conventions stated once: axis order, units, parameter order and names.

Arrays are time-first: ``t (N,)``, ``q, dq, ddq, tau (N, n_dof)``; the per-sample regressor is
``Y (N, n_dof, n_params)`` and the observation matrix ``W = Y.reshape(-1, n_params)`` (row
``k * n_dof + j`` is sample ``k``, joint ``j``). SI units and radians everywhere inside the package.

Standard parameters of joint ``j`` (1-based in names) come in one block: the ten inertial parameters
of link ``j`` in the paper's order (eq. 5), about the link frame origin and in link frame axes,
followed by the drive terms the robot declares (a subset of ``DRIVE_TERMS``, in that order).
"""

from __future__ import annotations

INERTIAL_TERMS: tuple[str, ...] = ("XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M")
"""Inertial parameters of one link, paper eq. 5 order (inertia about the link origin, first moments, mass)."""

DRIVE_TERMS: tuple[str, ...] = ("Ia", "fc", "fv", "offset")
"""Per-joint drive terms: rotor inertia, Coulomb friction, viscous friction, torque offset (eq. 3)."""

DEFAULT_DRIVE_TERMS: tuple[str, ...] = ("fc", "fv")
"""The paper's friction model (eq. 3): Coulomb and viscous friction."""

UNITS: dict[str, str] = {
    "XX": "kg·m²", "XY": "kg·m²", "XZ": "kg·m²", "YY": "kg·m²", "YZ": "kg·m²", "ZZ": "kg·m²",
    "MX": "kg·m", "MY": "kg·m", "MZ": "kg·m", "M": "kg",
    "Ia": "kg·m²", "fc": "N·m", "fv": "N·m·s/rad", "offset": "N·m",
}


def parameter_name(term: str, joint: int) -> str:
    """Name of a standard parameter, e.g. ``parameter_name("ZZ", 0) == "ZZ1"`` (joint is 0-based)."""
    return f"{term}{joint + 1}"


def split_name(name: str) -> tuple[str, int]:
    """Inverse of :func:`parameter_name`: ``"MX3" -> ("MX", 2)``; a trailing ``R`` is ignored."""
    stem = name[:-1] if name.endswith("R") and not name[-2:-1].isalpha() else name
    i = len(stem)
    while i > 0 and stem[i - 1].isdigit():
        i -= 1
    return stem[:i], int(stem[i:]) - 1


def unit_of(name: str) -> str:
    """Unit of a (standard or base) parameter from its leading term, e.g. ``"ZZ1R" -> "kg·m²"``."""
    term, _ = split_name(name)
    return UNITS.get(term, "")

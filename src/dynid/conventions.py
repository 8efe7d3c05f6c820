"""Conventions stated once: axis order, units, parameter order and names.

Arrays are time-first: ``t (N,)``, ``q, dq, ddq, tau (N, n_dof)``; the per-sample regressor is
``Y (N, n_dof, n_params)`` and the observation matrix ``W = Y.reshape(-1, n_params)`` (row
``k * n_dof + j`` is sample ``k``, joint ``j``). SI units and radians everywhere inside the package.

Standard parameters of joint ``j`` (1-based in names) come in one block: the ten inertial parameters
of link ``j`` in the paper's order (eq. 5), about the link frame origin and in link frame axes,
followed by the drive terms the robot declares (a subset of ``DRIVE_TERMS``, in that order).
"""

from __future__ import annotations

import math

from . import friction

INERTIAL_TERMS: tuple[str, ...] = ("XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M")
"""Inertial parameters of one link, paper eq. 5 order (inertia about the link origin, first moments, mass)."""

DRIVE_TERMS: tuple[str, ...] = friction.term_names()
"""Per-joint drive terms (:data:`dynid.friction.TERMS`): rotor inertia, Coulomb, viscous, offset, Stribeck."""

COUPLING_TERMS: tuple[str, ...] = ("Iam", "fvm", "fcm")
"""Parameters of a motor that turns with several joints (coupled wrist): inertia, viscous and Coulomb
friction, in joint units (see :mod:`dynid.model.transmission`). Named after the motor: ``Iam6``."""

DEFAULT_DRIVE_TERMS: tuple[str, ...] = friction.DEFAULT_TERMS
"""The paper's friction model (eq. 3): Coulomb and viscous friction."""

UNITS: dict[str, str] = {
    "XX": "kg·m²", "XY": "kg·m²", "XZ": "kg·m²", "YY": "kg·m²", "YZ": "kg·m²", "ZZ": "kg·m²",
    "MX": "kg·m", "MY": "kg·m", "MZ": "kg·m", "M": "kg",
    "Iam": "kg·m²", "fvm": "N·m·s/rad", "fcm": "N·m",
}
"""Units of the inertial and coupled-motor terms; drive terms take theirs from :data:`dynid.friction.TERMS`."""

ALIASES: dict[str, str] = {
    "Ixx": "XX", "Ixy": "XY", "Ixz": "XZ", "Iyy": "YY", "Iyz": "YZ", "Izz": "ZZ",
    "mx": "MX", "my": "MY", "mz": "MZ", "m": "M", "fsm": "fcm",
}
"""Other spellings of the inertial and coupled-motor terms; drive terms' come from :data:`dynid.friction.TERMS`."""


def _alias(term: str) -> str:
    for t in friction.TERMS.values():
        if term in t.aliases:
            return t.name
    return ALIASES.get(term, term)
"""Other spellings of the terms found in published parameter sets (FIGAROH, MATLAB toolboxes)."""


def parameter_name(term: str, joint: int) -> str:
    """Name of a standard parameter, e.g. ``parameter_name("ZZ", 0) == "ZZ1"``.

    Parameters
    ----------
    term : str
        Inertial or drive term (``"ZZ"``, ``"fv"``…).
    joint : int
        0-based.

    Returns
    -------
    str
    """
    return f"{term}{joint + 1}"


def split_name(name: str) -> tuple[str, int]:
    """Inverse of :func:`parameter_name`: ``"MX3" -> ("MX", 2)``; a trailing ``R`` is ignored.

    Parameters
    ----------
    name : str

    Returns
    -------
    term : str
    joint : int
        0-based.
    """
    stem = name[:-1] if name.endswith("R") and not name[-2:-1].isalpha() else name
    i = len(stem)
    while i > 0 and stem[i - 1].isdigit():
        i -= 1
    return stem[:i], int(stem[i:]) - 1


def canonical_name(name: str) -> str:
    """dynid's name of a parameter written in another common spelling.

    ``"Ixx2" -> "XX2"``, ``"m3" -> "M3"``, ``"fs1" -> "fc1"``, ``"off4"``/``"f04" -> "offset4"``; dynid names pass
    unchanged.

    Parameters
    ----------
    name : str
        A parameter name in any common spelling, e.g. ``"Ixx2"``.

    Returns
    -------
    str

    Raises
    ------
    ValueError
        If ``name`` is not a term followed by a 1-based joint number.
    """
    text = name.strip()
    i = len(text)
    while i > 0 and text[i - 1].isdigit():
        i -= 1
    if i == len(text) or i == 0:
        raise ValueError(f"expected a parameter name like 'XX1' or 'Ixx1', got {name!r}")
    term, joint = text[:i], text[i:]
    if term == "f" and joint.startswith("0"):
        return f"offset{int(joint[1:])}"
    term = _alias(term)
    known = set(INERTIAL_TERMS) | set(friction.TERMS) | set(COUPLING_TERMS)
    if term not in known:
        raise ValueError(f"unknown parameter term {text[:i]!r} in {name!r}")
    return f"{term}{int(joint)}"


LINEAR_UNITS: dict[str, str] = {"kg·m²": "kg", "N·m": "N", "N·m·s/rad": "N·s/m", "rad": "m", "rad/s": "m/s",
                                 "rad/s²": "m/s²", "N·m/A": "N/A"}
"""A quantity's unit on a prismatic joint, where its revolute unit differs: the rotor inertia reflected as a mass,
forces for torques, per metre for per radian, positions and their derivatives in metres."""


def joint_unit(unit: str, prismatic, j: int) -> str:
    """The unit of joint ``j``'s quantity whose unit on a revolute joint is ``unit``: its linear unit
    (:data:`LINEAR_UNITS`) where the joint slides.

    Parameters
    ----------
    unit : str
        E.g. ``"N·m"`` for a torque, ``"rad/s"`` for a velocity.
    prismatic : sequence of bool
        Which joints slide (:attr:`dynid.model.robot.Robot.prismatic`); empty: none.
    j : int
        The joint, 0-based.

    Returns
    -------
    str
    """
    return LINEAR_UNITS.get(unit, unit) if 0 <= j < len(prismatic) and prismatic[j] else unit


def joints_unit(unit: str, prismatic) -> str:
    """The unit of a figure over all joints (an RMS over them) whose unit on revolute joints is ``unit``: ``"N·m/N"``
    where some joints slide and others turn, the linear unit where all slide.

    Parameters
    ----------
    unit : str
    prismatic : sequence of bool

    Returns
    -------
    str
    """
    linear = LINEAR_UNITS.get(unit, unit)
    if not any(prismatic) or linear == unit:
        return unit
    return linear if all(prismatic) else f"{unit}/{linear}"


def sliding_note(unit: str, prismatic, *, inside: bool = False) -> str:
    """What a list or table of per-joint figures in ``unit`` adds where some joints slide, e.g. ``" (J3 in N)"``, or
    ``"; J3 in N"`` ``inside`` parentheses that name the unit; ``""`` on a robot of revolute joints.

    Parameters
    ----------
    unit : str
        The figures' unit on a revolute joint.
    prismatic : sequence of bool
    inside : bool

    Returns
    -------
    str
    """
    joints = [f"J{j + 1}" for j, p in enumerate(prismatic) if p]
    if not joints:
        return ""
    said = f"{', '.join(joints)} in {LINEAR_UNITS.get(unit, unit)}"
    return f"; {said}" if inside else f" ({said})"


def unit_of(name: str, prismatic=()) -> str:
    """Unit of a (standard or base) parameter from its leading term, e.g. ``"ZZ1R" -> "kg·m²"``.

    Parameters
    ----------
    name : str
        A standard or base parameter's name.
    prismatic : sequence of bool, optional
        Which joints slide (:attr:`dynid.model.robot.Robot.prismatic`): a drive term of such a joint has its linear
        unit (:data:`LINEAR_UNITS`; ``"fv1" -> "N·s/m"``).

    Returns
    -------
    str
    """
    term, joint = split_name(name)
    if term not in friction.TERMS:
        return UNITS.get(term, "")
    return joint_unit(friction.TERMS[term].unit, prismatic, joint)


MOVING_SPAN = 0.05
"""[rad] A joint whose positions span more than this in a log moves: its measured velocities must follow them."""

TIME_UNITS: dict[str, float] = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9}
"""Units of a log's time column (``time = { column = ..., unit = "ns" }``), in seconds."""

CONTROLLER_STEPS: tuple[float, float] = (1e-4, 0.2)
"""[s] The time steps robot controllers log at (10 kHz to 5 Hz)."""


def time_unit_of(step: float) -> str | None:
    """The unit of time stamps whose median step, read as seconds, is ``step``: the one that makes it a controller's
    step (:data:`CONTROLLER_STEPS`), or None where seconds do or no unit does.

    Parameters
    ----------
    step : float
        Median step of the time stamps as read.

    Returns
    -------
    str or None
        A key of :data:`TIME_UNITS` other than "s".
    """
    low, high = CONTROLLER_STEPS
    if low <= step <= high:
        return None
    return next((u for u, f in TIME_UNITS.items() if f < 1.0 and low <= step * f <= high), None)



def joint_angles_text(angles) -> str:
    """The joints whose angle is not zero, in degrees (``"J2 -90°, J3 +90°"``): how a description's position offsets
    are said wherever dynid writes angles that hold them or not (excitation.csv, a written URDF or MJCF).

    Parameters
    ----------
    angles : sequence of float
        One per joint [rad].

    Returns
    -------
    str
        Empty where every angle is zero.
    """
    return ", ".join(f"J{j + 1} {math.degrees(v):+.4g}°" for j, v in enumerate(angles) if v)

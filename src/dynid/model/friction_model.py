"""A joint's friction model: which Coulomb-like terms it has, their velocities and their state at rest.

:class:`JointFriction` names a model of the family :mod:`dynid.identification.friction_models` chooses from;
:func:`robot_with` gives the robot whose regressor has those terms. The state at rest is a property of the
logs' preprocessing (``Preprocessing.rest_friction``), the rest of the robot.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..friction import TERMS
from .robot import Robot

__all__ = ["COULOMB_LIKE", "KINDS", "JointFriction", "robot_from_settings", "robot_with"]

COULOMB_LIKE = ("fc", "fst", "fca", "fcl")
"""Terms whose columns a friction model sets; every other drive term of the description stays in each model."""

KINDS = ("coulomb", "asymmetric", "stribeck", "smooth", "load")

@dataclass(frozen=True)
class JointFriction:
    """One joint's friction model.

    Attributes
    ----------
    kind : str
        "coulomb", "asymmetric", "stribeck", "smooth" or "load".
    velocity : float [rad/s]
        Stribeck velocity ("stribeck") or smoothing velocity ("smooth"), else 0.
    rest : "held", "zero" or float [s]
        State of the Coulomb-like terms at rest (:func:`dynid.friction.held_direction`).
    """

    kind: str = "coulomb"
    velocity: float = 0.0
    rest: str | float = "held"

    @property
    def label(self) -> str:
        """E.g. "Stribeck (v 0.05 rad/s), held at rest"."""
        names = {"coulomb": "Coulomb + viscous", "asymmetric": "asymmetric Coulomb", "stribeck": "Stribeck",
                 "smooth": "smooth Coulomb", "load": "load-dependent Coulomb"}
        v = f" (v {self.velocity:.2g} rad/s)" if self.kind in ("stribeck", "smooth") else ""
        if self.kind == "smooth":
            return names[self.kind] + v
        rest = {"held": "held at rest", "zero": "none at rest"}.get(self.rest) if isinstance(self.rest, str) else \
            f"relaxing in {self.rest:g} s at rest"
        return f"{names[self.kind]}{v}, {rest}"

    def to_dict(self) -> dict:
        """JSON-ready model.

        Returns
        -------
        dict
            ``kind``, ``velocity``, ``rest`` and ``label``.
        """
        return {"kind": self.kind, "velocity": self.velocity, "rest": self.rest, "label": self.label}

    @classmethod
    def from_dict(cls, d: dict) -> JointFriction:
        """Inverse of :meth:`to_dict`.

        Parameters
        ----------
        d : dict

        Returns
        -------
        JointFriction

        Raises
        ------
        ValueError
            An unknown kind, a negative velocity or an unknown state at rest.
        """
        kind, velocity, rest = d["kind"], float(d["velocity"]), d["rest"]
        if kind not in KINDS or not velocity >= 0 or not (rest in ("held", "zero") or (isinstance(rest, (int, float))
                                                                                     and not isinstance(rest, bool) and rest >= 0)):
            raise ValueError(f"expected a friction model {{kind in {KINDS}, velocity >= 0, rest}}, got {d!r}")
        if kind in ("stribeck", "smooth") and not velocity > 0:
            raise ValueError(f"a {kind} friction model needs a positive velocity, got {velocity}")
        return cls(kind, velocity, rest)


def robot_with(robot: Robot, models) -> Robot:
    """A robot with each joint's friction model.

    The description's terms, the Coulomb-like ones per model (:data:`COULOMB_LIKE`), in the table's order; a joint's
    mask has only its model's terms.

    Parameters
    ----------
    robot : Robot
    models : sequence of JointFriction
        One per joint.

    Returns
    -------
    Robot
    """
    base_terms = [t for t in robot.drive_terms if t not in COULOMB_LIKE]
    wanted = set(base_terms) | {"fc"}
    for m in models:
        wanted |= set(_model_terms(m.kind, robot))
    terms = tuple(t for t in TERMS if t in wanted)
    n = robot.n_dof
    old = {t: i for i, t in enumerate(robot.drive_terms)}
    mask = np.zeros((n, len(terms)), dtype=bool)
    drive = np.zeros((n, len(terms)))
    for j, m in enumerate(models):
        own = set(_model_terms(m.kind, robot)) | {t for t in base_terms if robot.drive_mask[j, old[t]]}
        for c, t in enumerate(terms):
            mask[j, c] = t in own
            if mask[j, c] and t in old:
                drive[j, c] = robot.drive[j, old[t]]
    smooth = smoothing_velocities(models)
    stribeck = np.array([m.velocity if m.kind == "stribeck" else robot.stribeck_velocity[j] for j, m in enumerate(models)])
    return replace(robot, drive_terms=terms, drive=drive, drive_mask=mask, coulomb_velocity=smooth, stribeck_velocity=stribeck)


def smoothing_velocities(models) -> np.ndarray:
    """Each joint's Coulomb smoothing velocity under its friction model: a smooth Coulomb's, 0 (``sign(q̇)``) for the
    other models.

    Parameters
    ----------
    models : sequence of JointFriction
        One per joint.

    Returns
    -------
    (n_dof,) array [rad/s]
    """
    return np.array([m.velocity if m.kind == "smooth" else 0.0 for m in models])


def _model_terms(kind: str, robot: Robot) -> tuple[str, ...]:
    return {"coulomb": ("fc",), "asymmetric": ("fc", "fca"), "stribeck": ("fc", "fst"), "smooth": ("fc",),
            "load": ("fc", "fcl")}[kind]


def robot_from_settings(robot: Robot, settings: dict) -> Robot:
    """A robot as a results.json's ``settings`` say it was identified.

    Without the description's drive terms the identification left out (``drive_terms``: a joint torque sensor's log
    holds no rotor inertia ``Ia``), with each joint's friction model (``friction_models``) or, in results of older
    versions, the Coulomb smoothing velocities.

    Parameters
    ----------
    robot : Robot
        The robot's description.
    settings : dict
        The results' ``settings``.

    Returns
    -------
    Robot

    Raises
    ------
    ValueError
        Stored models that are not one per joint of this robot, or malformed.
    """
    if not isinstance(settings, dict):
        return robot
    terms = settings.get("drive_terms")  # the description's drive terms that the identification left out (Ia, where a
    if isinstance(terms, list):          # joint torque sensor measured the log) are left out again
        robot = robot.without_drive_terms([t for t in robot.drive_terms if t not in terms])
    stored = settings.get("friction_models")
    if isinstance(stored, dict):
        models = stored.get("models")
        if not isinstance(models, list) or len(models) != robot.n_dof:
            raise ValueError(f"settings.friction_models.models: expected {robot.n_dof} joint models, got {models!r}")
        return robot_with(robot, [JointFriction.from_dict(m) for m in models])
    vs = settings.get("coulomb_velocity")
    if vs is not None:
        return replace(robot, coulomb_velocity=np.asarray(vs, dtype=float))
    return robot

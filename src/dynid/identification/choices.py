"""What the data chose for the model, kept beside the robot's description rather than written into it.

The description says what the robot is. An identification chooses on its log what the description leaves open:
the filters (``preprocessing = "auto"``, :func:`dynid.identification.cross_validation.choose_preprocessing`), each
joint's Coulomb smoothing velocity (``coulomb_velocity = "auto"``,
:func:`dynid.identification.cross_validation.choose_coulomb_velocity`) and, with ``friction = "auto"``, each joint's
friction model and its state at rest (:func:`dynid.identification.friction_models.choose_friction`).
:class:`ModelChoices` is these choices as one value of the result, as Pinocchio keeps a ``Data`` beside its
``Model``: the model that is identified is :meth:`ModelChoices.model` of the description, which stays as it was read.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .._util.reprs import short_repr
from ..model.friction_model import smoothing_velocities
from ..model.robot import Robot
from .cross_validation import CoulombChoice, PreprocessingChoice
from .friction_models import FrictionChoice

__all__ = ["ModelChoices"]


@short_repr
@dataclass(frozen=True)
class ModelChoices:
    """The settings an identification chose on its log (module docstring).

    Attributes
    ----------
    coulomb_velocity : (n_dof,) array [rad/s]
        Each joint's Coulomb smoothing velocity (0: ``sign(q̇)``) as the settings gave it or :attr:`coulomb` chose it;
        where :attr:`friction` is made, each joint's friction model sets its own (:meth:`smoothing_velocity`).
    preprocessing : PreprocessingChoice or None
        The filters' cross-validation, when there were candidates to choose among.
    coulomb : CoulombChoice or None
        The smoothing velocities' cross-validation (``coulomb_velocity = "auto"``).
    friction : FrictionChoice or None
        Each joint's friction model and state at rest (``friction = "auto"``).
    """

    coulomb_velocity: np.ndarray
    preprocessing: PreprocessingChoice | None = None
    coulomb: CoulombChoice | None = None
    friction: FrictionChoice | None = None

    def model(self, description: Robot) -> Robot:
        """The robot as it is identified: ``description`` with these choices.

        Parameters
        ----------
        description : Robot
            The robot's description, as read.

        Returns
        -------
        Robot
            A new robot: the description's links, the chosen smoothing velocities and, where made, the chosen friction
            models (drive terms, masks, Stribeck and smoothing velocities).
        """
        robot = replace(description, coulomb_velocity=np.asarray(self.coulomb_velocity, dtype=float))
        return robot if self.friction is None else self.friction.robot(robot)

    def smoothing_velocity(self) -> np.ndarray:
        """Each joint's Coulomb smoothing velocity in the identified model.

        Returns
        -------
        (n_dof,) array [rad/s]
            :attr:`coulomb_velocity`, or where friction models were chosen, theirs
            (:func:`dynid.model.friction_model.smoothing_velocities`: a smooth Coulomb's, 0 for the others).
        """
        if self.friction is None:
            return np.asarray(self.coulomb_velocity, dtype=float)
        return smoothing_velocities(self.friction.models)

    def to_dict(self) -> dict:
        """The choices as results.json's ``settings`` stores them.

        Returns
        -------
        dict
            ``coulomb_velocity`` [rad/s] per joint (:meth:`smoothing_velocity`), and when made
            ``preprocessing_cross_validation``,
            ``coulomb_cross_validation`` and ``friction_models``.
        """
        out: dict = {"coulomb_velocity": self.smoothing_velocity().tolist()}
        if self.preprocessing is not None:
            out["preprocessing_cross_validation"] = self.preprocessing.to_dict()
        if self.coulomb is not None:
            out["coulomb_cross_validation"] = self.coulomb.to_dict()
        if self.friction is not None:
            out["friction_models"] = self.friction.to_dict()
        return out

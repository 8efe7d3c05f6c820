"""Where each kind of standard parameter sits in a robot's parameter vector (for constrained estimators)."""

from __future__ import annotations

import numpy as np

from ..friction import nonnegative_terms
from ..model.robot import Robot

COUPLED_NONNEGATIVE = ("Iam", "fcm", "fvm")
"""Coupled-motor terms that are physically non-negative (the drive terms' flags are in dynid.friction)."""


def consistency_layout(robot: Robot) -> tuple[np.ndarray, np.ndarray]:
    """Columns of each link's ten inertial parameters, and of the non-negative drive terms.

    Parameters
    ----------
    robot : Robot

    Returns
    -------
    links : (n_dof, 10) int array
    nonnegative : (k,) int array
        Columns of the non-negative drive terms (:func:`dynid.friction.nonnegative_terms`) that the joint has, and of
        the coupled motors' (:data:`COUPLED_NONNEGATIVE`).
    """
    npj = robot.n_params_per_joint
    links = np.array([np.arange(10) + j * npj for j in range(robot.n_dof)], dtype=int)
    names = robot.parameter_names
    nonneg = []
    for k, name in enumerate(names):
        term = name.rstrip("0123456789")
        if term in nonnegative_terms() or term in COUPLED_NONNEGATIVE:
            j = int(name[len(term):]) - 1
            if k >= robot.n_dof * npj or robot.drive_mask[j, robot.drive_terms.index(term)]:
                nonneg.append(k)
    return links, np.array(nonneg, dtype=int)

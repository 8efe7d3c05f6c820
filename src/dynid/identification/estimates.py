"""An identification's estimates as every later step sees them: one estimate whichever estimator made it, the
labels of the two that are not an estimator's key alone (the SDP's, the drive-only one's), and each set's physical
consistency check (Sousa & Cortesão 2014; :func:`dynid.estimators.consistency_margin`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from .._util.reprs import short_repr
from ..dynamics.layout import consistency_layout
from ..estimators.registry import estimate_label
from ..exceptions import DynIdError
from ..model.robot import Robot

if TYPE_CHECKING:  # the verdict reads these without the regressor or SciPy: a config's run imports them first
    from ..dynamics.base_parameters import BaseParameters

__all__ = ["Estimate", "consistency_checks", "SDP_LABEL", "DRIVE_ONLY_KEY", "DRIVE_ONLY_LABEL", "HELD_OUT_FOLDS"]

DRIVE_ONLY_KEY = "drive-only"
"""Key of the description's rigid body with the drive terms fitted (:mod:`dynid.identification.drive_only`)."""

SDP_LABEL = estimate_label("sdp")
"""Label of the physically consistent estimate."""

DRIVE_ONLY_LABEL = estimate_label(DRIVE_ONLY_KEY)
"""Label of the description's rigid body with the drive terms fitted (:mod:`dynid.identification.drive_only`)."""

@short_repr
@dataclass(frozen=True)
class Estimate:
    """One estimate of the base parameters, whichever estimator made it.

    Attributes
    ----------
    key : str
        The estimator (:mod:`dynid.estimators.registry`).
    params : (n_base,) array
        Base parameters (units of :func:`dynid.conventions.unit_of`).
    std : (n_base,) array or None
        Standard deviations (least squares: from the covariance; None when the estimator gives none).
    seconds : float
        Wall time of the fit [s].
    n_evaluations : int or None
        Evaluations of eq. 9 (box searches).
    standard : (n_params,) array or None
        Standard parameters, for an estimator of the standard space (the SDP).
    pseudo_inertia_min_eig : (n_links,) array or None
        Smallest eigenvalue of each link's pseudo-inertia (the SDP).
    note : str
        What to know about it (a solver that ended inaccurately).
    estimator : Estimator or None
        The fitted estimator, with its learned attributes (the bee colony's ``history_``, the SDP's ``status_``, a
        plugin's own); None for the estimates no estimator object makes (the description's nominal model, the
        drive-only candidate, a closed-loop estimate). Not written to results.json.
    """

    key: str
    params: np.ndarray
    std: np.ndarray | None = None
    seconds: float = 0.0
    n_evaluations: int | None = None
    standard: np.ndarray | None = None
    pseudo_inertia_min_eig: np.ndarray | None = None
    note: str = ""
    estimator: object = field(default=None, repr=False, compare=False)

    @property
    def label(self) -> str:
        """``"dynid <LABEL>"``."""
        return estimate_label(self.key)

    def to_dict(self, base: BaseParameters) -> dict:
        """The estimate as results.json stores it (values and σ by base parameter name).

        Parameters
        ----------
        base : BaseParameters

        Returns
        -------
        dict
        """
        out = {"key": self.key, "values": dict(zip(base.names, self.params.tolist())), "seconds": self.seconds,
               "n_evaluations": self.n_evaluations}
        if self.std is not None:
            out["std"] = dict(zip(base.names, self.std.tolist()))
        if self.standard is not None:
            out["standard_values"] = dict(zip(base.standard_names, self.standard.tolist()))
        if self.pseudo_inertia_min_eig is not None:
            out["pseudo_inertia_min_eig"] = self.pseudo_inertia_min_eig.tolist()
        if self.key == "sdp":
            out["prior"] = "the robot model's nominal parameters"
        if self.note:
            out["note"] = self.note
        return out


def consistency_checks(robot: Robot, base: BaseParameters, sets: dict) -> tuple[dict, dict]:
    """Each parameter set's consistency margin and verdict (:func:`dynid.estimators.consistency_margin`).

    Parameters
    ----------
    robot : Robot
    base : BaseParameters
    sets : dict
        label -> base parameters (n_base,).

    Returns
    -------
    tuple of dict
        label -> margin (NaN when the check failed), label -> verdict (one line).
    """
    from ..estimators.physically_consistent import consistency_margin, consistency_verdict

    links, nonneg = consistency_layout(robot)
    margins, verdicts = {}, {}
    for label, beta in sets.items():
        try:
            margins[label] = consistency_margin(base.regrouping, beta, links, nonneg)
            verdicts[label] = consistency_verdict(margins[label], base.regrouping, beta, base.names, nonneg)
        except DynIdError as exc:  # a failed check never stops the identification
            margins[label], verdicts[label] = float("nan"), f"not checked: {exc}"
    return margins, verdicts


NOMINAL_LABEL = "description (nominal)"
"""The set of the description's own nominal values, scored on the validation logs beside the estimates when no
reference set of the config is that."""

CONSISTENT_NOMINAL_LABEL = "description (nominal, made consistent)"
"""The description's nominal values with each physically impossible link replaced by its nearest consistent one
(:meth:`dynid.model.robot.Robot.physical_prior`): the nominal candidate where the robot file's values are not
physically consistent."""

HELD_OUT_FOLDS = 5
"""Contiguous blocks of the identification log that compare the estimates when no validation log does."""

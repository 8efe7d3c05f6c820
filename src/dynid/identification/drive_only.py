"""The description's rigid body with only the drive terms identified: the model a short or poor log can still improve
on the description with (issue "Honest on any log", item 1).

A log of a few seconds determines the drive terms (Coulomb and viscous friction, offsets, rotor inertia) of the
joints it moves far better than the links' inertial parameters, which a short log's fit bends to whatever the log
shows: on windows of 3-6 s of the UR10e's identification log the full estimate predicted the validation logs worse
than the description on five of six (5.5-22.2 % against 3.4-4.5 %), the description's rigid body with the drive terms
fitted better than both (2.1-3.5 %), and on the sixth better than the full estimate (1.68 % against 1.78 %).
Nothing in the identification log alone says which of the two predicts other motions better (a blocked
cross-validation, a stronger prior and an F test of the restriction were measured and rejected:
benchmarks/README.md), so :func:`dynid.identification.run.run_identification` scores this estimate beside the others
on the validation logs and makes it the main one where the identified rigid body is doubtful there (the nominal model
predicts them better, or the least-squares estimate extrapolates) and this one predicts them better than the main
estimate does.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..dynamics.base_parameters import BaseParameters
from ..dynamics.layout import consistency_layout
from ..estimators.accumulate import LeastSquaresAccumulator
from ..estimators.least_squares import coulomb_offset_pairs
from ..model.robot import Robot

__all__ = ["DRIVE_ONLY_KEY", "DriveOnly", "drive_only"]

DRIVE_ONLY_KEY = "drive-only"
"""The estimate's key (label ``"dynid drive-only"``)."""


@dataclass(frozen=True)
class DriveOnly:
    """The description's rigid body with the drive terms fitted, ready to be made the main estimate.

    Attributes
    ----------
    params : (n_base,) array
        Base parameters.
    std : (n_base,) array
        Their standard deviations (0 for what the description fixes).
    standard : (n_params,) array
        Standard parameters: the description's (physically consistent) links, the fitted drive terms.
    fit : TorqueComparison
        The identification log's comparison with every set of the result and this one (label ``"dynid drive-only"``).
    """

    params: np.ndarray
    std: np.ndarray
    standard: np.ndarray
    fit: object


def drive_only(robot: Robot, base: BaseParameters, accumulator: LeastSquaresAccumulator, joint_weights=None,
               prior: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Least squares of the drive terms with the links' inertial parameters at the description's values.

    ``φ = φ_nominal + B x``: ``B`` selects the standard drive terms (every term of :attr:`Robot.drive_terms` and the
    coupled motors' parameters), ``x`` is fitted on the base rows of ``accumulator`` (``β = regrouping · φ``), its
    undetermined directions left at the description's values and a one-way joint's Coulomb + offset term taken as
    Coulomb friction as in :meth:`LeastSquaresAccumulator.solve`. The terms that are physically non-negative (rotor
    inertia, Coulomb, viscous and Stribeck friction: :func:`dynid.dynamics.layout.consistency_layout`) are bounded by
    0: a term the unbounded fit makes negative is held at 0 with the bounded fit's other terms at bound (SciPy's BVLS),
    the rest refitted, so that the estimate is physically consistent wherever the description is.

    Parameters
    ----------
    robot : Robot
        With nominal inertial parameters.
    base : BaseParameters
        The base-parameter map of the rows of ``accumulator``.
    accumulator : LeastSquaresAccumulator
        The identification's base rows.
    joint_weights : (n_dof,) array, optional
        WLS weights, as the least-squares estimate's.
    prior : (n_params,) array, optional
        The description's standard parameters (default :meth:`Robot.physical_prior`: impossible links replaced by
        their nearest consistent ones).

    Returns
    -------
    (params, std, standard) or None
        ``(n_base,)`` base parameters and σ, ``(n_params,)`` standard parameters; None for a description without
        inertial parameters or a robot without drive terms.
    """
    if not np.any(robot.inertial != 0):
        return None
    phi0 = robot.physical_prior()[0] if prior is None else np.asarray(prior, dtype=float)
    names = robot.parameter_names
    links, nonnegative = consistency_layout(robot)
    drive = np.setdiff1d(np.arange(len(names)), links.ravel())
    if drive.size == 0:
        return None
    lower = np.where(np.isin(drive, nonnegative), 0.0, -np.inf)
    rigid = phi0.copy()
    rigid[drive] = 0.0
    basis, offset = base.regrouping[:, drive], base.regrouping @ rigid
    active = np.zeros(drive.size, dtype=bool)  # non-negative drive terms held at 0
    x = np.zeros(drive.size)
    for _ in range(drive.size + 1):
        free = np.flatnonzero(~active)
        pairs = coulomb_offset_pairs([names[i] for i in drive[free]])
        params, cov, sol = accumulator.solve_affine(basis[:, free], offset, joint_weights, prior=phi0[drive[free]],
                                                    pairs=pairs)
        x = np.zeros(drive.size)
        x[free] = sol.params
        below = ~active & (x < lower)
        if not below.any():
            break
        # the bounded least squares' active set first (the step that frees a bound is SciPy's), then any term the
        # prior's directions push below its bound; a one-way joint's offset that the fit kept at the description's
        # value stays there, so that the bounded fit does not split that joint's one term otherwise
        kept = free[[fixed for coulomb, fixed in pairs if coulomb in sol.anchored]]
        active |= below if active.any() else _at_bound(accumulator, basis, offset, lower, joint_weights,
                                                        kept, phi0[drive[kept]]) | below
    standard = phi0.copy()
    standard[drive] = x
    return params, np.sqrt(np.maximum(np.diag(cov), 0.0)), standard


def _at_bound(accumulator: LeastSquaresAccumulator, basis: np.ndarray, offset: np.ndarray, lower: np.ndarray,
              joint_weights, fixed=(), values=()) -> np.ndarray:
    """The terms at their lower bound in the bounded least squares ``min ||D(τ - W(offset + basis x))||², x ≥ lower``
    (SciPy's BVLS on the column-scaled triangular factor; Stark & Parker 1995), the terms ``fixed`` held at
    ``values`` (never at bound): (d,) bool."""
    from scipy.optimize import lsq_linear

    p, d = basis.shape
    held = np.zeros(d, dtype=bool)
    held[np.asarray(fixed, dtype=int)] = True
    offset = offset + basis[:, held] @ np.asarray(values, dtype=float)
    red = accumulator.reduced(joint_weights)
    a = red[:p, :p] @ basis[:, ~held]
    scale = np.linalg.norm(a, axis=0)
    scale = np.where(scale > 0, scale, 1.0)
    fit = lsq_linear(a / scale, red[:p, p] - red[:p, :p] @ offset, bounds=(lower[~held] * scale, np.inf), method="bvls")
    x = np.zeros(d)
    x[~held] = fit.x / scale
    return ~held & np.isfinite(lower) & (x <= lower + 1e-9 * np.maximum(1.0, np.abs(x)))

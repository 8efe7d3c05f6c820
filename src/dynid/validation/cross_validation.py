"""Blocked time-series cross-validation of preprocessing and model choices on one log.

Samples of a log are correlated in time (and more so after filtering), so random folds would score a
model on samples almost identical to those it was fitted on. The folds here are contiguous blocks of
the log (Bergmeir & Benítez, "On the use of cross-validation for time series predictor evaluation",
Information Sciences 191, 2012): the parameters are fitted on all blocks but one, by least squares
accumulated per block (:class:`dynid.estimators.accumulate.LeastSquaresAccumulator`), and the torque
error is measured on the block left out, joint by joint.

Used to choose each joint's Coulomb smoothing velocity ``v_s`` (:mod:`dynid.friction`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..dynamics.base_parameters import BaseParameters
from ..estimators.accumulate import LeastSquaresAccumulator
from ..exceptions import IdentifiabilityError
from ..model.robot import Robot
from ..preprocessing.pipeline import PreparedData, base_chunks

COULOMB_GRID = (0.0, 0.003, 0.01, 0.03, 0.1)
"""Candidate smoothing velocities, as fractions of each joint's RMS speed (0: sign)."""

FOLDS = 5


@dataclass(frozen=True)
class CoulombChoice:
    """Per-joint Coulomb smoothing velocity chosen by blocked cross-validation.

    Attributes
    ----------
    velocity : (n_dof,) array [rad/s]
        Chosen ``v_s`` (0: sign).
    candidates : (n_candidates, n_dof) array [rad/s]
        The grid tried, per joint (``COULOMB_GRID`` × the joint's RMS speed).
    error : (n_candidates, n_dof) array [N·m]
        Out-of-fold RMS torque error of each candidate, per joint.
    folds : int
    """

    velocity: np.ndarray
    candidates: np.ndarray
    error: np.ndarray
    folds: int

    def to_dict(self) -> dict:
        return {"velocity": self.velocity, "candidates": self.candidates, "out_of_fold_rms_error": self.error,
                "folds": self.folds, "grid_fraction_of_rms_speed": list(COULOMB_GRID)}


def out_of_fold_error(accumulators: list[LeastSquaresAccumulator]) -> np.ndarray:
    """RMS residual of each joint on each block when fitted (OLS) on all the other blocks, pooled over
    the blocks, (n_dof,) [N·m].

    Raises
    ------
    IdentifiabilityError
        When the blocks but one do not identify the parameters.
    """
    n = accumulators[0].n_dof
    sumsq, rows = np.zeros(n), np.zeros(n)
    for k, held in enumerate(accumulators):
        rest = LeastSquaresAccumulator.merged([a for i, a in enumerate(accumulators) if i != k])
        params = rest.solve().params
        sumsq += held.joint_residual_sumsq(params)
        rows += held.rows
    return np.sqrt(sumsq / np.maximum(rows, 1))


def choose_coulomb_velocity(robot: Robot, base: BaseParameters, data: PreparedData, folds: int = FOLDS,
                            grid=COULOMB_GRID) -> CoulombChoice:
    """Choose each joint's Coulomb smoothing velocity by blocked cross-validation.

    Every candidate of ``grid`` (× each joint's RMS speed) is applied to all joints at once; each joint
    keeps the candidate with its smallest out-of-fold torque error (ties: the smaller velocity).

    Parameters
    ----------
    robot : Robot
    base : BaseParameters
    data : PreparedData
        The identification log after :func:`dynid.preprocessing.prepare`.
    folds : int
        Contiguous blocks (at least 2).
    grid : sequence of float
        Fractions of the RMS speed; 0 keeps ``sign``.

    Returns
    -------
    CoulombChoice
    """
    n = robot.n_dof
    speed = np.sqrt(np.mean(data.dq**2, axis=0))
    candidates = np.outer(np.asarray(grid, dtype=float), speed)
    n_s = data.t.shape[0]
    error = np.full((len(grid), n), np.inf)
    for c, vs in enumerate(candidates):
        accs = [LeastSquaresAccumulator(base.n_base, n) for _ in range(folds)]
        for index, y, tau, keep in base_chunks(replace(robot, coulomb_velocity=vs), base, data):
            fold = index * folds // n_s
            for k in np.unique(fold):
                sel = fold == k
                accs[k].add(y[sel].reshape(-1, base.n_base), tau[sel].reshape(-1), keep[sel].reshape(-1))
        try:
            error[c] = out_of_fold_error(accs)
        except IdentifiabilityError:
            continue
    best = np.argmin(error, axis=0)  # argmin keeps the first (smallest velocity) of equal errors
    if not np.all(np.isfinite(error[best, np.arange(n)])):
        return CoulombChoice(np.zeros(n), candidates, error, folds)
    return CoulombChoice(candidates[best, np.arange(n)], candidates, error, folds)

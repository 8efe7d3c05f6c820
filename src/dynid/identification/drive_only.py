"""The description's rigid body with only the drive terms identified: the model a short or poor log can still improve
on the description with (issue "Honest on any log", item 1).

A log of a few seconds determines the drive terms (Coulomb and viscous friction, offsets, rotor inertia) of the
joints it moves far better than the links' inertial parameters, which a short log's fit bends to whatever the log
shows: on windows of 3-6 s of the UR10e's identification log the full estimate predicted the validation logs worse
than the description on five of six (5.5-22.2 % against 3.4-4.5 %), the description's rigid body with the drive terms
fitted better than both (2.1-3.5 %), and on the sixth better than the full estimate (1.68 % against 1.78 %).
Nothing in the identification log alone says which of the two predicts other motions better (a blocked
cross-validation, a stronger prior and an F test of the restriction were measured and rejected:
benchmarks/NOTEBOOK.md), so :func:`dynid.identification.run.run_identification` scores this estimate beside the others
on the validation logs and makes it the main one where the identified rigid body is doubtful there (the nominal model
predicts them better, or the least-squares estimate extrapolates) and this one predicts them better than the main
estimate does.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from .._util.reprs import short_repr
from ..conventions import split_name
from ..dynamics.base_parameters import BaseParameters
from ..dynamics.layout import consistency_layout
from ..estimators.accumulate import LeastSquaresAccumulator
from ..estimators.least_squares import coulomb_offset_pairs
from ..model.robot import Robot
from ..preprocessing.bands import capped
from ..preprocessing.preparation import Preprocessing, base_chunks, prepare
from ..preprocessing.prepared import PreparedData
from .estimates import DRIVE_ONLY_KEY, DRIVE_ONLY_LABEL, NOMINAL_LABEL

__all__ = ["CUTOFF_FACTORS", "DRIVE_ONLY_KEY", "DriveOnly", "drive_only", "prepared_variant", "preprocessing_variants", "variants_judge"]


@short_repr
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
    fit : TorqueComparison or None
        The identification log's comparison with every set of the result and this one (label ``"dynid drive-only"``);
        None as :func:`drive_only` returns it.
    held : dict
        The drive terms held at the description's value because the preprocessing variants moved them (or, for an
        offset, its joint's Coulomb friction) by their own value or more (:func:`drive_only`): name -> the estimates
        at ``held["cutoff_factors"]`` × the log's cutoffs; empty when none.
    undetermined : dict
        The same for the terms the variants moved as much that keep this log's value, as the description gives none
        (a rotor inertia a URDF cannot hold): the log does not determine them.
    """

    params: np.ndarray
    std: np.ndarray
    standard: np.ndarray
    fit: object = None
    held: dict = field(default_factory=dict)
    undetermined: dict = field(default_factory=dict)


CUTOFF_FACTORS = (0.5, 2.0)
"""The other preparations of a log that :func:`drive_only` compares: every cutoff at these multiples of the log's own."""


def preprocessing_variants(robot: Robot, base: BaseParameters, recording, data: PreparedData, given: Preprocessing,
                           one_way=()) -> tuple:
    """The base rows of the log prepared again at :data:`CUTOFF_FACTORS` × its position, velocity and parallel cutoffs,
    for :func:`drive_only`'s judgement of the one-way joints' drive terms; none where no joint moved one way, the
    description has no inertias or the robot no drive terms, or the log was not prepared by parallel filtering (the
    paper's eq. 17, Fourier-fit derivatives).

    Parameters
    ----------
    robot, base
        The model as identified (the chosen friction models) and its base-parameter map.
    recording : dynid.io.logs.datasets.Recording
        The log as read.
    data : PreparedData
        The log as prepared for the estimation (its resolved settings and rest model).
    given : Preprocessing
        The settings as given (a given decimation or trim stays).
    one_way : sequence of int
        The joints that moved one way only.

    Returns
    -------
    tuple of (float, LeastSquaresAccumulator)
        Each factor with the rows its preparation gives, in ``base``'s layout.
    """
    if not variants_judge(robot, data, one_way):
        return ()
    out = []
    for f in CUTOFF_FACTORS:
        acc = LeastSquaresAccumulator(base.n_base, robot.n_dof)
        for _, y, tau, keep in base_chunks(robot, base, prepared_variant(recording, data, given, f)):
            acc.add(y.reshape(-1, base.n_base), tau.reshape(-1), keep.reshape(-1))
        out.append((f, acc))
    return tuple(out)


def variants_judge(robot: Robot, data: PreparedData, one_way) -> bool:
    """Whether the preprocessing variants judge this log's drive terms (:func:`preprocessing_variants`): some joint moved
    one way, the description has inertias and the robot drive terms, and the log was prepared by parallel filtering.

    Parameters
    ----------
    robot : Robot
    data : PreparedData
    one_way : sequence of int

    Returns
    -------
    bool
    """
    s = data.settings
    return bool(len(one_way) and robot.drive_terms and np.any(robot.inertial != 0) and s.strategy == "parallel"
                and s.fourier is None)


def prepared_variant(recording, data: PreparedData, given: Preprocessing, factor: float) -> PreparedData:
    """The log prepared again with its position, velocity and parallel cutoffs at ``factor`` × its own (capped below
    Nyquist), its other resolved settings and rest model kept (:func:`preprocessing_variants`).

    Parameters
    ----------
    recording : dynid.io.logs.datasets.Recording
        The log as read.
    data : PreparedData
        The log as prepared (its resolved settings).
    given : Preprocessing
        The settings as given.
    factor : float

    Returns
    -------
    PreparedData
    """
    s = data.settings
    position, velocity, parallel = (None if c is None else capped(factor * c, data.rate)
                                    for c in (s.position_cutoff, s.velocity_cutoff, s.parallel_cutoff))
    settings = replace(given, band=s.band, position_cutoff=position, velocity_cutoff=velocity, parallel_cutoff=parallel,
                       min_speed=s.min_speed, rest_velocity=s.rest_velocity, coulomb_velocity=s.coulomb_velocity)
    return prepare(recording, settings).with_rest_model(s.rest_friction, s.presliding)


def drive_only(robot: Robot, base: BaseParameters, accumulator: LeastSquaresAccumulator, *, joint_weights=None,
               prior: np.ndarray | None = None, variants: tuple = (), one_way=()) -> DriveOnly | None:
    """Least squares of the drive terms with the links' inertial parameters at the description's values.

    ``φ = φ_nominal + B x``: ``B`` selects the standard drive terms (every term of :attr:`Robot.drive_terms` and the
    coupled motors' parameters), ``x`` is fitted on the base rows of ``accumulator`` (``β = regrouping · φ``), its
    undetermined directions left at the description's values and a one-way joint's Coulomb + offset term taken as
    Coulomb friction as in :meth:`LeastSquaresAccumulator.solve`. The terms that are physically non-negative (rotor
    inertia, Coulomb, viscous and Stribeck friction: :func:`dynid.dynamics.layout.consistency_layout`) are bounded by
    0: a term the unbounded fit makes negative is held at 0 with the bounded fit's other terms at bound (SciPy's BVLS),
    the rest refitted, so that the estimate is physically consistent wherever the description is.

    With ``variants``, the same fit on the same log prepared with other cutoffs (:func:`preprocessing_variants`): a
    drive term of a joint of ``one_way`` whose estimate moves across the variants by as much as its own value (max -
    min ≥ |x|, the spread read as a σ of 100 % or more, the threshold at which dynid calls a parameter not
    determined) is not determined by the log, whatever its covariance says. A joint that crawls one way barely
    accelerates, so its rotor inertia (and the split of its Coulomb friction and offset) is set by the filters' shaping
    of a tiny acceleration, not by the robot: on the zoo's 5 s logs (benchmarks/NOTEBOOK.md) a shoulder's rotor inertia
    fitted outside dynid with the TRUE links came out at 0.48, 0.18 and -0.23 kg·m² at 5, 10 and 20 Hz (truth 0.025,
    covariance σ 0.04). Such a term is held at the description's value where the description gives one; a one-way
    joint's unstable Coulomb friction or offset holds the offset at the description's value, so that their sum stays
    Coulomb friction; any other keeps the log's value and is said (:attr:`DriveOnly.undetermined`): a description
    without the term (a URDF has no rotor inertia) is no knowledge of it, and holding such terms at 0 made the zoo's
    short logs better in 14 cells and worse in 9 (benchmarks/NOTEBOOK.md). A term the description states with a σ
    (``Ia = { value = 0.3, sigma = 0.05 }``, :attr:`Robot.prior_sigma`) is pulled toward its value with that Gaussian
    prior (:meth:`LeastSquaresAccumulator.solve_affine`'s ``gaussian``).

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
    variants : tuple of (float, LeastSquaresAccumulator)
        The cutoff factor and the base rows of each other preparation of the log (:func:`preprocessing_variants`).
    one_way : sequence of int
        The joints (0-based) that moved one way only, whose drive terms the variants judge.

    Returns
    -------
    DriveOnly or None
        Without its ``fit``; None for a description without inertial parameters or a robot without drive terms.
    """
    if not np.any(robot.inertial != 0):
        return None
    phi0 = robot.physical_prior()[0] if prior is None else np.asarray(prior, dtype=float)
    names = robot.parameter_names
    links, nonnegative = consistency_layout(robot)
    drive = np.setdiff1d(np.arange(len(names)), links.ravel())
    if drive.size == 0:
        return None
    problem = _DriveProblem(names, drive, np.where(np.isin(drive, nonnegative), 0.0, -np.inf), phi0, regrouping=base.regrouping,
                            joint_weights=joint_weights, sigmas=robot.prior_sigmas()[drive])
    x, params, cov = problem.fit(accumulator)
    moved_one_way = set(one_way)
    # a term no base parameter holds (another joint's friction term, a counterbalance elsewhere) is not in the model
    in_base = np.any(base.regrouping[:, drive] != 0, axis=0)
    judged = [i for i, k in enumerate(drive) if split_name(names[k])[1] in moved_one_way and in_base[i]]
    held: dict[str, tuple[float, ...]] = {}
    loose: dict[str, tuple[float, ...]] = {}
    if variants and judged:
        fitted = {1.0: x, **{f: problem.fit(acc)[0] for f, acc in variants}}
        factors = sorted(fitted)
        runs = np.array([fitted[f] for f in factors])
        spread = runs.max(axis=0) - runs.min(axis=0)
        unstable = [i for i in judged if spread[i] > 0 and spread[i] >= abs(x[i])]
        pinned = _pinned(unstable, [names[k] for k in drive], phi0[drive])
        said = lambda i: tuple(float(v) for v in runs[:, i])  # noqa: E731
        held = {names[drive[i]]: said(i) for i in pinned}
        loose = {names[drive[i]]: said(i) for i in unstable
                 if i not in pinned and split_name(names[drive[i]])[0] not in ("fc", "offset")}
        if pinned:
            x, params, cov = problem.fit(accumulator, np.asarray(pinned, dtype=int))
        held = {"cutoff_factors": tuple(factors), **held} if held else {}
        loose = {"cutoff_factors": tuple(factors), **loose} if loose else {}
    standard = phi0.copy()
    standard[drive] = x
    return DriveOnly(params, np.sqrt(np.maximum(np.diag(cov), 0.0)), standard, held=held, undetermined=loose)


def _pinned(unstable: list, names: list, prior: np.ndarray) -> list:
    """The drive terms (indices into ``names``) that :func:`drive_only` holds at the description's values, of the
    ``unstable`` ones: a one-way joint's offset where its Coulomb friction or offset is unstable (the two act as one
    term there: the sum stays Coulomb friction, as :meth:`LeastSquaresAccumulator.solve` takes it), and any other
    term the description gives a value for (non-zero: a URDF has no rotor inertia, and 0 is no knowledge of one)."""
    out: set[int] = set()
    for i in unstable:
        term, j = split_name(names[i])
        if term in ("fc", "offset"):
            out.update(k for k, n in enumerate(names) if n == f"offset{j + 1}")
        elif prior[i] != 0:
            out.add(i)
    return sorted(out)


def held_out_errors(robot: Robot, folds, joint_weights=None) -> dict[str, float]:
    """The description's candidates on held-out blocks of the identification log: the RMS torque error [N·m] of the
    description's rigid body with its drive terms fitted on all blocks but one (as :func:`drive_only` fits them, the
    one-way joints' terms not judged), and of the description's nominal values (made physically consistent where they
    are not, as :func:`dynid.identification.evidence.nominal_set`'s), each on the block left out, over all
    blocks (issue "The better model wins", item 3).

    Parameters
    ----------
    robot : Robot
        With nominal inertial parameters.
    folds : sequence of LeastSquaresAccumulator
        The log's contiguous blocks of standard rows
        (:class:`dynid.identification.estimation_pass.BlockScoring`'s ``folds``).
    joint_weights : (n_dof,) array, optional
        WLS weights, as the least-squares estimate's.

    Returns
    -------
    dict
        :data:`~dynid.identification.estimates.DRIVE_ONLY_LABEL` and
        :data:`~dynid.identification.estimates.NOMINAL_LABEL` -> RMS error [N·m]; empty for a description without
        inertial parameters.
    """
    if not np.any(robot.inertial != 0) or not folds:
        return {}
    names, phi0 = robot.parameter_names, robot.physical_prior()[0]
    links, nonnegative = consistency_layout(robot)
    drive = np.setdiff1d(np.arange(len(names)), links.ravel())
    problem = _DriveProblem(names, drive, np.where(np.isin(drive, nonnegative), 0.0, -np.inf), phi0,
                            regrouping=np.eye(len(names)), joint_weights=joint_weights, sigmas=robot.prior_sigmas()[drive])
    nominal = phi0  # the nominal candidate: the file's values, made consistent where they are not (nominal_set)
    sse, rows = np.zeros(2), 0
    for k, held in enumerate(folds):
        phi = phi0.copy()
        if drive.size:
            phi[drive] = problem.fit(LeastSquaresAccumulator.merged([a for i, a in enumerate(folds) if i != k]))[0]
        sse += [held.joint_residual_sumsq(phi).sum(), held.joint_residual_sumsq(nominal).sum()]
        rows += int(held.rows.sum())
    rms = np.sqrt(sse / max(rows, 1))
    return {DRIVE_ONLY_LABEL: float(rms[0]), NOMINAL_LABEL: float(rms[1])}


class _DriveProblem:
    """The bounded fit of :func:`drive_only` on any accumulator of the rows ``regrouping`` maps the standard parameters
    to (the base map's; the identity for standard rows), some terms held at the description's values."""

    def __init__(self, names, drive: np.ndarray, lower: np.ndarray, phi0: np.ndarray, *, regrouping: np.ndarray,
                 joint_weights, sigmas: np.ndarray | None = None) -> None:
        self.names, self.drive, self.lower, self.phi0, self.joint_weights = names, drive, lower, phi0, joint_weights
        self.sigmas = np.full(drive.size, np.nan) if sigmas is None else np.asarray(sigmas, dtype=float)
        rigid = phi0.copy()
        rigid[drive] = 0.0
        self.basis, self.offset = regrouping[:, drive], regrouping @ rigid

    def fit(self, accumulator: LeastSquaresAccumulator, fixed=()) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(x, params, covariance)``: the drive terms (``fixed`` ones at the description's values), the base
        parameters and their covariance."""
        d, phi0, drive = self.drive.size, self.phi0, self.drive
        fixed = np.asarray(fixed, dtype=int)
        pinned = np.zeros(d, dtype=bool)
        pinned[fixed] = True
        offset = self.offset + self.basis[:, pinned] @ phi0[drive[pinned]]
        active = np.zeros(d, dtype=bool)  # non-negative drive terms held at 0
        x = np.where(pinned, phi0[drive], 0.0)
        for _ in range(d + 1):
            free = np.flatnonzero(~active & ~pinned)
            pairs = coulomb_offset_pairs([self.names[i] for i in drive[free]])
            params, cov, sol = accumulator.solve_affine(self.basis[:, free], offset, self.joint_weights,
                                                        prior=phi0[drive[free]], pairs=pairs,
                                                        gaussian=(phi0[drive[free]], self.sigmas[free]))
            x = np.where(pinned, phi0[drive], 0.0)
            x[free] = sol.params
            below = ~active & ~pinned & (x < self.lower)
            if not below.any():
                break
            # the bounded least squares' active set first (the step that frees a bound is SciPy's), then any term the
            # prior's directions push below its bound; a one-way joint's offset that the fit kept at the description's
            # value stays there, so that the bounded fit does not split that joint's one term otherwise
            kept = np.concatenate([free[[fixed_ for coulomb, fixed_ in pairs if coulomb in sol.anchored]], fixed])
            active |= below if active.any() else _at_bound(accumulator, self.basis, self.offset, self.lower,
                                                            joint_weights=self.joint_weights, fixed=kept, values=phi0[drive[kept]]) | below
        return x, params, cov


def _at_bound(accumulator: LeastSquaresAccumulator, basis: np.ndarray, offset: np.ndarray, lower: np.ndarray,
              *, joint_weights, fixed=(), values=()) -> np.ndarray:
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

"""Identification of a real robot from its logs: one pass over the prepared recording feeds every estimator
(:class:`dynid.estimators.estimation.Estimation`) and the verdict's statistics.

Prepared recording (:mod:`dynid.preprocessing`) → the strategy's blocks of base (and standard) regressor rows and
torques → the estimators of ``estimators`` (the first is the main estimate; OLS/WLS and the SDP accumulate block by
block, so memory does not depend on the log's length) → fit metrics, the consistency of every estimate, the verdict
on the model (:mod:`dynid.validation.diagnostics`), gathered into an
:class:`~dynid.identification.result.IdentificationResult`. Validation on other logs is
:mod:`dynid.identification.run`'s.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .._util.column_store import root_mean_square
from .._util.keywords import keyword_only_after_data
from ..dynamics.base_parameters import BaseParameters
from ..dynamics.layout import consistency_layout
from ..estimators import paper_objective
from ..estimators.accumulate import LeastSquaresAccumulator
from ..estimators.estimation import Estimation, stream_rows
from ..estimators.physically_consistent import PhysicallyConsistentLeastSquares
from ..estimators.registry import (
    DEFAULT_ESTIMATORS,
    LEAST_SQUARES,
    PROBLEM_FILLED,
    FitData,
    estimate_label,
    estimator_choices,
    spec,
)
from ..estimators.registry import label as estimator_label
from ..exceptions import DynIdError, IdentifiabilityError
from ..io.config.references import ReferenceSet
from ..io.exported.export import READINESS_KINDS
from ..model.robot import Robot
from ..preprocessing.preparation import base_chunks
from ..preprocessing.prepared import PreparedData
from ..validation.diagnostics import (
    SCALE_MISFIT,
    BlockGrams,
    OrderSums,
    ResidualSums,
    bootstrap_finding,
    excitation_findings,
    prior_findings,
    scale_findings,
    sign_findings,
    state_columns,
    unexplained_finding,
    unlike_nominal_findings,
)
from ..validation.geometry_checks import geometry_findings
from ..validation.torques import TorqueSums, resting_rows
from .drive_only import drive_only, held_out_errors
from .estimates import DRIVE_ONLY_LABEL, HELD_OUT_FOLDS, SDP_LABEL, Estimate, consistency_checks
from .flipped_joints import flipped_joint_findings
from .geared_friction import beyond_hysteresis, hysteresis_explains, hysteresis_finding
from .result import IdentificationResult, search_box

__all__ = ["BlockScoring", "Estimate", "IdentificationResult", "identify"]


@keyword_only_after_data
def identify(robot: Robot, base: BaseParameters, data: PreparedData, estimators=DEFAULT_ESTIMATORS, *,
             references: tuple[ReferenceSet, ...] = (), progress=None, rng: int = 0, held_out: bool = False,
             jackknife: bool = False, observers: tuple = (), variants: tuple = ()) -> IdentificationResult:
    """Estimate the base parameters from one prepared recording with every estimator of ``estimators``, in one pass
    over its rows; check every estimate's physical consistency and gather what the log itself says for the verdict
    (its findings, held-out blocks, the drive-only candidate, the SDP's refits). The main estimate is the first listed
    until :func:`dynid.identification.verdict.decide` chooses
    (:meth:`dynid.identification.pipeline.IdentificationPipeline.fit`).

    Parameters
    ----------
    robot : Robot
        The model (its drive terms: the friction model identified).
    base : BaseParameters
        The base-parameter map of ``robot``.
    data : PreparedData
        From :func:`dynid.preprocessing.preparation.prepare`.
    estimators : sequence of str and Estimator, or str
        Keys of :mod:`dynid.estimators.registry` (case-insensitive; a text: comma-separated, ``"wls,sdp"``) or unfitted
        estimators of registered classes carrying their hyper-parameters
        (:func:`dynid.estimators.registry.estimator_choices`; e.g. ``sdp`` with the geometric prior of Lee, Wensing &
        Park 2020); the first is the main
        estimate. A least-squares
        estimate is always computed (the first of OLS/WLS listed, else WLS): it gives σ, each joint's noise (and
        the SDP's row weights) and the box of LAD and the box searches (:func:`search_box`).
    references : tuple of ReferenceSet
        Published parameter sets scored beside.
    progress : callable, optional
        ``progress(step, done, total)``.
    rng : int
        Seeds the box searches (each estimator draws from ``(rng, its registry index)``) and the bootstrap.
    held_out : bool
        With ``sdp`` listed, when no validation log will say which estimate to trust: the least-squares and the
        physically consistent estimates' errors on held-out contiguous blocks (:data:`HELD_OUT_FOLDS`-fold blocked
        cross-validation), which the main estimate's finding gives (the consistent one is the main estimate where
        least squares is not consistent: :func:`dynid.identification.verdict.choose_main_estimate`).
    jackknife : bool
        With ``sdp`` listed: refit the physically consistent estimate on every :data:`HELD_OUT_FOLDS` − 1 of the
        contiguous blocks (:attr:`IdentificationResult.sdp_refits`), whose spread on the validation logs' states the
        torque-free verdict weighs (:func:`dynid.identification.verdict.state_evidence`).
    observers : tuple of callable
        ``observer(index, y, tau, keep)`` called with every block of base rows of the one pass (what else needs them,
        e.g. the delay check of :mod:`dynid.identification.pipeline`).
    variants : tuple of (float, LeastSquaresAccumulator)
        The log's base rows at other cutoffs (:func:`dynid.identification.drive_only.preprocessing_variants`), by
        which the drive-only estimate judges the drive terms of the joints that moved one way.

    Returns
    -------
    IdentificationResult

    Raises
    ------
    ConfigError
        Unknown estimator, or ``sdp`` with a robot description without physical nominal parameters.
    IdentifiabilityError
        Too few rows or a rank-deficient base observation matrix (the log does not excite every base parameter).
    """
    keys, given = estimator_choices(estimators)
    problem, prior_notes, not_carried = _fit_problem(robot, base, keys)
    ls_key = next((k for k in keys if k in LEAST_SQUARES), "wls")
    scored = any(k not in (ls_key, "sdp") for k in keys)  # F of eq. 9 for every set: the rows in memory
    estimation, scoring = _one_pass(robot, base, data, Estimation(keys, problem, base.names, keep_rows=scored, given=given),
                                    held_out=(held_out or jackknife) and "sdp" in keys, observers=observers,
                                    progress=progress)
    reference = _solved_reference(robot, base, estimation, data)
    row_weights = None if ls_key == "ols" else 1.0 / np.where(reference.joint_std_ > 0, reference.joint_std_, 1.0)
    estimates, box = _fitted_estimates(estimation, reference, keys, ls_key, row_weights, rng=rng, progress=progress,
                                       data=data)
    warnings = _log_warnings(robot, data, estimates, reference, references, prior_notes=prior_notes, not_carried=not_carried)
    sets = {**{label: e.params for label, e in estimates.items()}, **{r.name: r.beta for r in references}}
    objective = {}
    if scored:
        w_all, tau_all = estimation.rows()
        objective = {label: float(paper_objective(tau_all - w_all @ beta, robot.n_dof)) for label, beta in sets.items()}
    evidence = _log_evidence(robot, base, data, scoring, reference, estimates, sets, row_weights, rng=rng,
                             ls_label=estimate_label(ls_key), held_out=held_out, jackknife=jackknife,
                             variants=variants, progress=progress)
    return IdentificationResult(
        robot.name, base, keys, ls_key, reference.solution_, reference.joint_std_, estimates, tuple(references),
        n_rows=int(reference.accumulator_.rows.sum()), settings={"preprocessing": data.settings.to_dict(), "rate": data.rate,
                                                                  **_given_settings(given)},
        warnings=tuple(warnings), objective=objective, box=box, model=robot, main=estimate_label(keys[0]), **evidence)


def _fit_problem(robot: Robot, base: BaseParameters, keys) -> tuple[FitData, tuple[str, ...], tuple[str, ...]]:
    """:func:`identify`'s problem for the estimators ``keys``: the description's prior (the documented prior of every
    estimator that asks for one, said wherever the description has inertial values: the nominal candidate takes them
    too), the consistency layout where an estimate is checked link by link, the stated σ; with the prior's notes and
    the names of the σ least squares cannot carry."""
    sdp = "sdp" in keys
    prior = None
    prior_notes: tuple[str, ...] = ()
    if sdp or np.any(robot.inertial != 0):
        try:
            prior, prior_notes = robot.physical_prior()
        except DynIdError:
            if sdp:
                raise
    base_std, not_carried = base.base_std(robot.prior_sigmas()) if robot.prior_sigma else (None, ())
    problem = FitData(None, None, robot.n_dof, None, base,
                      layout=consistency_layout(robot) if sdp or any(spec(k).space == "standard" for k in keys) else None,
                      prior=prior, base_prior=base.base_from_standard(robot.standard_parameters()),
                      prior_std=robot.prior_sigmas() if robot.prior_sigma else None, base_prior_std=base_std)
    return problem, prior_notes, not_carried


def _one_pass(robot: Robot, base: BaseParameters, data: PreparedData, estimation: Estimation, *, held_out: bool,
              observers: tuple, progress) -> tuple[Estimation, BlockScoring]:
    """:func:`identify`'s one pass over the log's rows: every block of base (and, where an estimator or the held-out
    blocks need them, standard) rows into the estimators and the verdict's sums."""
    scoring = BlockScoring(robot, base, data, held_out=held_out, observers=observers)
    standard = estimation.standard or bool(scoring.folds)
    chunks = base_chunks(robot, base, data, _step(progress, f"regressor, {data.name}"), standard=standard)
    stream_rows(chunks, estimation, base, scoring.add, standard=standard)
    return estimation, scoring


def _solved_reference(robot: Robot, base: BaseParameters, estimation: Estimation, data: PreparedData):
    """The least-squares reference of the pass (its error names the joints that barely move); the SDP's prior then
    splits Coulomb friction and offset as least squares did where it anchored them."""
    try:
        reference = estimation.solve_reference()
    except IdentifiabilityError as exc:
        speed = root_mean_square(data.dq)
        still = [f"J{j + 1}" for j in np.flatnonzero(speed < 1e-3 * max(speed.max(), 1e-12))]
        hint = f"; joint(s) {', '.join(still)} barely move" if still else ""
        raise IdentifiabilityError(f"{data.name}: {exc}{hint}") from None
    sol = reference.solution_
    if sol.anchored and "sdp" in estimation.streamed:
        estimation.problem = replace(estimation.problem, prior=_anchored_prior(estimation.problem.prior, robot, base, sol))
    return reference


def _fitted_estimates(estimation: Estimation, reference, keys, ls_key: str, row_weights, *, rng: int,
                      progress, data: PreparedData) -> tuple[dict, np.ndarray | None]:
    """Every estimator's estimate by label (least squares' the reference's own), and the box the box searches drew
    from (:func:`search_box`; None where no estimator needs one). An estimator that finds nothing refuses, naming the
    torque columns of ``data`` that are the joints' velocities or positions (:func:`_named_states`)."""
    sol = reference.solution_
    box = search_box(sol.params, sol.params_std) if estimation.needs_box else None
    report = None if progress is None else (lambda key, i, f: progress(f"estimators: {estimator_label(key)}", 0 if i is None else i, 0))
    try:
        fitted = estimation.fit(box, rng=int(rng), joint_weights=row_weights, progress=report)  # (seed, estimator's index)
    except DynIdError as exc:
        raise _named_states(exc, data) from None
    estimates = {estimate_label(key): _estimate(key, fitted.get(key), reference if key == ls_key else None)
                 for key in (*keys, *(() if ls_key in keys else (ls_key,)))}
    return estimates, box


def _named_states(exc: DynIdError, data: PreparedData) -> DynIdError:
    """An estimator's refusal (a plain :class:`DynIdError`: no parameters for these torques) with the torque columns of
    ``data`` that equal a joint's velocity or position named (:func:`dynid.validation.diagnostics.state_columns`);
    ``exc`` itself where none does."""
    named = state_columns(data.q, data.dq, data.tau, range(data.tau.shape[1])) if type(exc) is DynIdError else []
    if not named:
        return exc
    return DynIdError(f"{data.name}: no estimate for these torques ({str(exc).split(':')[0]} found none), and "
                      f"{', '.join(named)}: its torques (or currents) columns read another signal; check them in the "
                      "config")


def _log_warnings(robot: Robot, data: PreparedData, estimates: dict, reference, references, *,
                  prior_notes: tuple[str, ...], not_carried: tuple[str, ...]) -> list[str]:
    """:func:`identify`'s warnings, in this order: the description's, the prior's, the log's, the estimators', the σ
    least squares cannot carry, rows mostly left out as too slow, and the reference sets'."""
    warnings = list(robot.nominal_problems) + list(robot.nominal_notes) + list(prior_notes) + list(data.warnings) + \
        [e.note for e in estimates.values() if e.note] + _not_carried_note(not_carried)
    n = robot.n_dof
    dropped = 1.0 - reference.accumulator_.rows.sum() / (n * len(range(0, data.t.shape[0], data.settings.decimation or 1)))
    if dropped > 0.5:
        warnings.append(f"{data.name}: {100 * dropped:.0f}% of the rows are below preprocessing.min_speed and were left out")
    for r in references:
        warnings.extend(r.warnings)
    return warnings


def _log_evidence(robot: Robot, base: BaseParameters, data: PreparedData, scoring: BlockScoring, reference,
                  estimates: dict, sets: dict, row_weights, *, rng: int, ls_label: str, held_out: bool, jackknife: bool,
                  variants: tuple, progress) -> dict:
    """What the log itself says for the verdict (:func:`identify`'s fields of the result): every set's consistency
    and fit, the drive-only candidate, the findings (the model's, a swapped pair's, a flipped joint's where the log is
    read right) and the held-out blocks' refits."""
    sums, joint_std = scoring.sums, reference.joint_std_
    if progress is not None:
        progress("consistency checks", 0, 1)
    margins, verdicts = consistency_checks(robot, base, sets)
    sliding = tuple(robot.prismatic.tolist())
    fit = replace(sums.comparison(data.name, sets), noise=joint_std, speed=root_mean_square(data.dq), prismatic=sliding,
                  followers=robot.followers)
    found = None if scoring.nominal is None else drive_only(robot, base, reference.accumulator_, joint_weights=row_weights,
                                                            variants=variants, one_way=one_way_joints(data))
    alternative = None if found is None else replace(found, fit=replace(
        sums.comparison(data.name, {**sets, DRIVE_ONLY_LABEL: found.params}), noise=joint_std, speed=fit.speed,
        prismatic=sliding, followers=robot.followers))
    findings, stats = _verdict(robot, base, reference.solution_, reference.ols_params_, row_weights, scoring=scoring,
                               fit=fit, rng=rng, consistent=SDP_LABEL in estimates)
    if scoring.nominal is not None:  # a swapped pair fits badly, so "varies beyond the fit's residual" cannot judge it
        findings += scoring.order.findings(fit.varies(beyond="floor"), data.name)
    if SDP_LABEL in estimates and not any(f.kind in READINESS_KINDS for f in findings):  # the log read right first
        findings += flipped_joint_findings(estimates[SDP_LABEL].estimator, reference, data.name, prismatic=sliding)
    inconsistent = not str(verdicts.get(ls_label, "yes")).startswith("yes")
    refits = _held_out_evidence(robot, base, scoring.folds, row_weights, stats, ls_label, held_out=held_out and inconsistent,
                                jackknife=jackknife, progress=progress, span=float(data.t[-1] - data.t[0]))
    return {"fit": fit, "consistency": margins, "consistency_verdicts": verdicts, "findings": tuple(findings),
            "diagnostics": stats, "drive_only": alternative, "sdp_refits": refits}


def _not_carried_note(names: tuple[str, ...]) -> list[str]:
    """The warning for stated σ that least squares cannot use (:meth:`BaseParameters.base_std`)."""
    if not names:
        return []
    return [f"{', '.join(names)}: the σ stated for {'it' if len(names) == 1 else 'them'} is used by the SDP and the "
            "drive-only estimate, not by least squares, whose base parameters hold "
            f"{'it' if len(names) == 1 else 'each'} regrouped with other terms"]


def _given_settings(given: dict) -> dict:
    """results.json's ``settings.estimator_hyperparameters``: those of the estimator objects given (none: no key), but
    what the identification fills (:data:`dynid.estimators.registry.PROBLEM_FILLED`), each value a JSON scalar or its
    ``repr``."""
    if not given:
        return {}
    plain = (str, int, float, bool, type(None))
    return {"estimator_hyperparameters": {key: {name: value if isinstance(value, plain) else repr(value)
                                                for name, value in est.get_params().items() if name not in PROBLEM_FILLED}
                                          for key, est in given.items()}}


class BlockScoring:
    """What the one pass over the identification log feeds besides the estimators, fed once per block of base rows
    (:func:`dynid.estimators.estimation.stream_rows`' observer): the fit's metrics (:class:`TorqueSums`), the verdict's
    residual statistics (:class:`ResidualSums`) and block Gram matrices for the bootstrap (:class:`BlockGrams`), the
    held-out folds of the least-squares/SDP comparison, and any further ``observers``.

    Parameters
    ----------
    robot : Robot
    base : BaseParameters
    data : PreparedData
        The log the blocks come from.
    held_out : bool
        Keep :data:`HELD_OUT_FOLDS` contiguous folds of the standard rows (the SDP's held-out comparison).
    observers : tuple of callable
        ``observer(index, y, tau, keep)``, each called with every block.
    """

    def __init__(self, robot: Robot, base: BaseParameters, data: PreparedData, held_out: bool = False,
                 observers: tuple = ()):
        n = robot.n_dof
        self.robot, self.data, self.observers = robot, data, tuple(observers)
        self.sums = TorqueSums.for_data(data, base.n_base)
        self.residuals = ResidualSums(n, base.n_base)
        self.blocks = BlockGrams(n, base.n_base, data.t.shape[0])
        self.near_reversal = 5 * np.broadcast_to(np.asarray(data.settings.min_speed, dtype=float), (n,))
        self.folds = [LeastSquaresAccumulator(robot.n_params, n) for _ in range(HELD_OUT_FOLDS)] if held_out else []
        # the description's nominal model (base parameters), where it has one: the verdict checks the torques against it
        self.nominal = base.base_from_standard(robot.standard_parameters()) if np.any(robot.inertial != 0) else None
        self.order = OrderSums(n)

    def add(self, index, y, tau, keep, y_standard) -> None:
        """Feed one block of base rows to every accumulator.

        Parameters
        ----------
        index : (M,) int array
            Sample indices of the block.
        y : (M, n_dof, n_base) array
            Base rows.
        tau : (M, n_dof) array [N·m]
            Torques.
        keep : (M, n_dof) bool array
            Rows kept for the estimation.
        y_standard : (M, n_dof, n_params) array or None
            Standard rows (used with held-out folds).
        """
        data, n_s = self.data, self.data.t.shape[0]
        for k in np.unique(index * HELD_OUT_FOLDS // n_s) if self.folds else ():
            sel = index * HELD_OUT_FOLDS // n_s == k
            self.folds[k].add(y_standard[sel].reshape(-1, self.robot.n_params), tau[sel].reshape(-1), keep[sel].reshape(-1))
        scored = data.scored(index)
        if scored.all():
            self.sums.add(data.t[index], y, tau, resting_rows(data, index))
        elif scored.any():  # a clipped torque's samples count in no metric
            self.sums.add(data.t[index[scored]], y[scored], tau[scored], resting_rows(data, index[scored]))
        direction = np.asarray(data.direction[index]) if data.direction is not None else np.sign(np.asarray(data.dq[index]))
        self.residuals.add(y, tau, np.asarray(data.q[index]), np.asarray(data.dq[index]), direction=direction,
                           low_speed=self.near_reversal, keep=keep)
        if self.nominal is not None:
            self.order.add(y @ self.nominal, direction, np.asarray(data.dq[index]), tau)
        self.blocks.add(index, y, tau, keep)
        for observer in self.observers:
            observer(index, y, tau, keep)


def _estimate(key: str, fitted, reference) -> Estimate:
    """The :class:`Estimate` of a fit (the least-squares reference's own when ``fitted`` is None)."""
    if fitted is None:
        sol = reference.solution_
        return Estimate(key, sol.params, sol.params_std, estimator=reference)
    est = fitted.estimator
    std = getattr(est, "params_std_", None)
    standard = est.params_ if spec(key).space == "standard" else None
    status = getattr(est, "status_", "optimal")
    note = ""
    if status != "optimal":
        note = (f"physically consistent least squares: the SDP solver (Clarabel) ended with status {status}: its estimate "
                "may be slightly off the optimum (a poorly excited log or badly scaled parameters)" if key == "sdp" else
                f"{estimate_label(key)}: the solver ended with status {status}")
    return Estimate(key, fitted.params, None if std is None or standard is not None else np.asarray(std), fitted.seconds,
                    fitted.n_evaluations, None if standard is None else np.asarray(standard),
                    getattr(est, "pseudo_inertia_min_eig_", None), note, est)


FRICTION_TERMS = ("fc", "fv", "offset", "fst", "fca", "fcl")
"""Drive terms that are friction (not the rotor inertia, not a counterbalance): the sign check looks beyond them."""


def _nominal_checks(base, scoring: BlockScoring, fit, stats: dict, *, unfitted: bool) -> list:
    """The torques against the description's nominal model (``scoring.nominal``): a flipped sign and a scale (unit or
    gain) (:mod:`dynid.validation.diagnostics`), a log whose geometry does not match the robot file's
    (:mod:`dynid.validation.geometry_checks`); their statistics go into ``stats`` (``unfitted``: no fit follows the
    torques either)."""
    nominal, sums, data = scoring.nominal, scoring.sums, scoring.data
    assert nominal is not None  # called only where the description has a nominal model
    corr = sums.comparison(data.name, {"nominal": nominal}).metrics()["nominal"]["correlation"]
    stats["nominal_correlation"] = corr
    # the friction the nominal model may lack can run against it over a short log: judge the rest of the torque
    friction = {j: [k for k, name in enumerate(base.names) for term in FRICTION_TERMS if name == f"{term}{j + 1}"]
                for j in range(scoring.robot.n_dof)}
    beyond, slope = sums.beyond(nominal, friction)
    stats["nominal_correlation_beyond_friction"] = beyond
    stats["nominal_slope_beyond_friction"] = slope
    # the scale is judged beyond the rotor inertia too: descriptions rarely give it (a URDF has no armature), and on a
    # short slow log the torque it takes can be most of what varies beyond friction (the UR10e: 6.7× "the nominal")
    rotor = _rotor_columns(scoring.robot, base)
    drive = {j: cols + rotor.get(j, []) for j, cols in friction.items()}
    beyond_drive, slope_drive = sums.beyond(nominal, drive)
    stats["nominal_correlation_beyond_drive"] = beyond_drive
    stats["nominal_slope_beyond_drive"] = slope_drive
    # the correlation beyond friction judges where it is known, both ways: friction the nominal model lacks can run
    # against it (a short log: plain ρ -0.87, beyond -0.09) or hide a flipped sign (the UR10e's J1: -0.36, beyond -0.98).
    # One joint's flipped sign or scale fits badly, so its torque is judged against the noise floor, not the fit's
    # residual
    geometry, stats["geometry"] = geometry_findings(scoring.robot, data.q, data.dq, data.ddq, data.tau, data.name)
    varies = fit.varies(beyond="floor")
    floor = fit.floor_metrics()  # one channel's own scale is one the fit cannot follow
    misfit = None if floor is None else (np.min([m["rmse"] for m in fit.metrics().values()], axis=0)
                                         > SCALE_MISFIT * np.asarray(floor["rmse"]))
    def unlike(rho):
        return unlike_nominal_findings(np.where(np.isfinite(rho), rho, corr), varies, data.name, q=data.q, dq=data.dq,
                                       tau=data.tau, explained=bool(geometry), unfitted=unfitted)

    said = unlike(beyond)
    geared = None if not said else beyond_hysteresis(
        scoring.robot, base, data, nominal, friction, drive,
        lambda rho: not unlike(rho) and hysteresis_explains(rho, beyond, varies))
    if said and geared is None:  # not torques: no sign, scale or geometry of them can be judged
        return said
    note = []
    if geared is not None:  # torques with a geared drive's hysteresis: judged beyond its friction
        note = [hysteresis_finding(geared, beyond, varies, data.name)]
        beyond, slope, beyond_drive, slope_drive = geared.beyond, geared.slope, geared.beyond_drive, geared.slope_drive
        stats["nominal_correlation_beyond_hysteresis"] = beyond
    return (sign_findings(np.where(np.isfinite(beyond), beyond, corr), varies, data.name,
                          slope=np.where(np.isfinite(beyond), slope, np.nan))
            + scale_findings(beyond_drive, slope_drive, varies, data.name,
                             gains=data.drive_gains if data.drive_gains is not None else np.ones(scoring.robot.n_dof),
                             misfit=misfit, mass=float(np.sum(scoring.robot.inertial[:, 9])),
                             described=scoring.robot.drive_gains) + geometry + note)


def _rotor_columns(robot: Robot, base: BaseParameters) -> dict:
    """Joint (0-based) -> the base columns that hold its rotor inertia ``Ia`` (its own, or the inertial one it is
    regrouped into), from the base map's regrouping."""
    names = list(robot.parameter_names)
    out: dict = {}
    for j in range(robot.n_dof):
        if f"Ia{j + 1}" in names:
            column = np.asarray(base.regrouping)[:, names.index(f"Ia{j + 1}")]
            out[j] = [int(k) for k in np.flatnonzero(np.abs(column) > 0)]
    return out


def _verdict(robot, base, sol, ols_params, row_weights, *, scoring: BlockScoring, fit, rng, consistent: bool):
    """The verdict's findings on the identification log (:mod:`dynid.validation.diagnostics`) and their statistics
    (``consistent``: the physically consistent estimate is among the estimates)."""
    n = robot.n_dof
    rms = fit.rms_torque
    sums, residuals, blocks, data = scoring.sums, scoring.residuals, scoring.blocks, scoring.data
    findings: list = []
    stats: dict = {}
    unexplained = unexplained_finding(fit, data.name)
    if scoring.nominal is not None:  # the description's nominal model: does the data run against it?
        findings += _nominal_checks(base, scoring, fit, stats, unfitted=bool(unexplained))
    findings += unexplained
    fc = np.array([sol.params[base.names.index(f"fc{j + 1}")] if f"fc{j + 1}" in base.names else 0.0 for j in range(n)])
    more, res_stats = residuals.residual_checks(ols_params, rms, fc, prismatic=robot.prismatic)
    findings += more
    stats.update(res_stats)
    boot = blocks.bootstrap_std(row_weights, rng=rng)
    more, ratio = bootstrap_finding(sol.params_std, boot)
    findings += more
    stats.update({"bootstrap_std": dict(zip(base.names, boot.tolist())), "bootstrap_over_covariance_std": ratio})
    raw = sums.m2 + sums.count * np.einsum("jc,jd->jcd", sums.mean, sums.mean)  # Σ z zᵀ per joint
    col_rms = np.sqrt(np.max(np.diagonal(raw, axis1=1, axis2=2)[:, :-1], axis=0) / max(sums.count, 1))
    rms_all = float(np.sqrt(np.mean(rms**2)))
    findings += excitation_findings(base.names, sol.params, sol.params_std, col_rms, rms_all, consistent=consistent)
    joint_col_rms = np.sqrt(np.diagonal(raw, axis1=1, axis2=2)[:, :-1] / max(sums.count, 1))  # (n_dof, p)
    with np.errstate(invalid="ignore"):  # σ NaN where the prior keeps a direction
        share = 100.0 * np.max(np.asarray(sol.params_std, dtype=float) * joint_col_rms
                               / np.maximum(rms, 1e-300)[:, None], axis=0)  # on the joint it matters most to
    stats["sigma_torque_percent"] = {n: (float(x) if np.isfinite(x) else None) for n, x in zip(base.names, share)}
    if sol.from_prior:
        stats["from_prior"] = [base.names[i] for i in sol.from_prior]
        findings += prior_findings(base.names, sol.from_prior, one_way_joints(data), data.name, dead=data.dead_said, still=data.still,
                                   anchored=sol.anchored)
    if sol.anchored:
        stats["coulomb_from_one_term"] = [base.names[i] for i in sol.anchored]
    # the prediction's spread from the parameters' covariance: Σ diag(y C yᵀ) = trace(C Σ y yᵀ)
    spread = np.sqrt(np.maximum(np.einsum("cd,jdc->j", sol.covariance, raw[:, :-1, :-1]) / max(sums.count, 1), 0.0))
    stats["prediction_spread"] = spread
    return findings, stats


def _anchored_prior(prior, robot: Robot, base: BaseParameters, sol) -> np.ndarray:
    """The physically consistent estimate's prior with the Coulomb friction of the joints whose Coulomb + offset term
    least squares gave to Coulomb friction (:attr:`LeastSquaresSolution.anchored`) at that value, so that its pull
    toward the prior splits the term as least squares did (offset at the description's value) rather than half and
    half."""
    prior = np.array(prior, dtype=float)
    names = robot.parameter_names
    for i in sol.anchored:
        prior[names.index(base.names[i])] = sol.params[i]
    return prior


def one_way_joints(data: PreparedData) -> list[int]:
    """The joints that moved in one direction only (at least 99 % of their moving samples one way; a joint that never
    moved is not one of them, :attr:`PreparedData.still`).

    Parameters
    ----------
    data : PreparedData
        Its velocities and ``settings.min_speed`` (a joint's moving samples).

    Returns
    -------
    list of int
        The joints, 0-based.
    """
    n = data.dq.shape[1]
    speed = np.broadcast_to(np.asarray(data.settings.min_speed, dtype=float), (n,))
    out = []
    for j in (j for j in range(n) if j not in data.still):  # a column at a time: a long log's are stored
        column = np.asarray(data.dq[:, j], dtype=float)
        moved = column[np.abs(column) > speed[j]]
        if moved.size and min(np.count_nonzero(moved > 0), np.count_nonzero(moved < 0)) / moved.size < 0.01:
            out.append(j)
    return out


def _held_out_evidence(robot: Robot, base: BaseParameters, folds, row_weights, stats: dict, ls_label: str, *,
                       held_out: bool, jackknife: bool, progress=None, span: float = 0.0) -> tuple:
    """What the held-out blocks say: with ``held_out``, the least-squares and SDP estimates' errors on them and the
    description's candidates' (:func:`dynid.identification.drive_only.held_out_errors`; ``stats["held_out_rms_error"]``,
    and ``stats["held_out_block_seconds"]``, each block's length: ``span`` over the blocks); with ``jackknife``, the SDP refitted on all blocks
    but one (returned, base parameters; empty otherwise)."""
    if not folds or not (held_out or jackknife):
        return ()
    if progress is not None:
        progress("physically consistent SDP, held-out blocks", 0, 1)
    own, held, refitted = _held_out_errors(robot, folds, row_weights)
    if held_out:
        stats["held_out_rms_error"] = {ls_label: own, **({} if held is None else {SDP_LABEL: held}),
                                       **held_out_errors(robot, folds, row_weights)}
        stats["held_out_block_seconds"] = span / HELD_OUT_FOLDS  # the log's span [s] over the blocks
    return tuple(base.base_from_standard(phi) for phi in refitted) if jackknife else ()


def _held_out_errors(robot: Robot, folds, row_weights) -> tuple[float, float | None, list]:
    """RMS torque error on the held-out blocks of the unconstrained (OLS/WLS, minimum-norm over the standard
    parameters: the base estimate's predictions) and the physically consistent estimates, each fitted on the others;
    and the physically consistent estimate of each fold (standard parameters). Where the SDP has no solution on some
    blocks (torques far off in size or not the robot's: the findings on the whole log say which), it has no held-out
    figure and no refits (None, []): the blocks are evidence, and their solver's failure is not the user's error."""
    p = robot.n_params
    links, nonneg = consistency_layout(robot)
    sse = np.zeros(2)
    rows = 0
    fitted: list | None = []
    for k, held in enumerate(folds):
        rest = LeastSquaresAccumulator.merged([a for i, a in enumerate(folds) if i != k])
        reduced = rest.reduced(row_weights)
        phi = np.linalg.lstsq(reduced[:p, :p], reduced[:p, p], rcond=1e-10)[0]
        sse[0] += held.joint_residual_sumsq(phi).sum()
        rows += int(held.rows.sum())
        if fitted is not None:
            try:
                est = PhysicallyConsistentLeastSquares().fit(reduced[:, :p], reduced[:, p], problem=FitData(
                    layout=(links, nonneg), prior=robot.standard_parameters()))
            except DynIdError:
                fitted = None
                continue
            sse[1] += held.joint_residual_sumsq(est.params_).sum()
            fitted.append(est.params_)
    own, sdp = np.sqrt(sse / max(rows, 1))
    return float(own), None if fitted is None else float(sdp), fitted or []


def _step(progress, label: str):
    """``progress(label, done, total)`` as a ``(done, total)`` callback (None stays None)."""
    return None if progress is None else (lambda done, total: progress(label, done, total))

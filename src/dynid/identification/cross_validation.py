"""Blocked time-series cross-validation of preprocessing and model choices on one log.

Samples of a log are correlated in time (and more so after filtering), so random folds would score a
model on samples almost identical to those it was fitted on. The folds here are contiguous blocks of
the log (Bergmeir & Benítez, "On the use of cross-validation for time series predictor evaluation",
Information Sciences 191, 2012): the parameters are fitted on all blocks but one, by least squares
accumulated per block (:class:`dynid.estimators.accumulate.LeastSquaresAccumulator`), and the torque
error is measured on the block left out, joint by joint.

Used to choose each joint's Coulomb smoothing velocity ``v_s`` (:mod:`dynid.friction`), and with
``preprocessing = "auto"`` the filters: candidates that filter differently are fitted on the same
blocks and scored on the same held-out samples, preprocessed by the default rules, so that a candidate
cannot look better by filtering its own test samples more.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from .._util.column_store import root_mean_square
from .._util.reprs import short_repr
from ..dynamics.base_parameters import BaseParameters
from ..estimators.accumulate import LeastSquaresAccumulator
from ..exceptions import IdentifiabilityError
from ..model.robot import Robot
from ..preprocessing.bands import POSITION_FACTOR, capped
from ..preprocessing.preparation import Preprocessing, base_chunks, prepare
from ..preprocessing.prepared import PreparedData
from ..runtime.processes import ForkedCall

COULOMB_GRID = (0.0, 0.003, 0.01, 0.03, 0.1)
"""Candidate smoothing velocities, as fractions of each joint's RMS speed (0: sign)."""

FOLDS = 5

PREPARING = "preprocessing"
"""The stage :func:`choose_preprocessing` reports while it prepares the log by the default rule."""

CROSS_VALIDATING = "preprocessing: cross-validation of the cutoffs"
"""The stage it reports while it cross-validates the cutoffs (only where there is a choice to make)."""


@short_repr
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
        """JSON-ready choice.

        Returns
        -------
        dict
            The velocities chosen, the candidates and their out-of-fold errors.
        """
        return {"velocity": self.velocity, "candidates": self.candidates, "out_of_fold_rms_error": self.error,
                "folds": self.folds, "grid_fraction_of_rms_speed": list(COULOMB_GRID)}


def out_of_fold_error(accumulators: list[LeastSquaresAccumulator]) -> np.ndarray:
    """RMS residual of each joint on each block when fitted (OLS) on all the other blocks, pooled over the blocks.

    Parameters
    ----------
    accumulators : list of LeastSquaresAccumulator
        One per block.

    Returns
    -------
    (n_dof,) ndarray [N·m]

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
    speed = root_mean_square(data.dq)
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


MAX_SAMPLES = 60_000
"""A longer log has its cutoffs chosen on its middle ``MAX_SAMPLES`` samples (a minute of a 1 kHz log)."""


def _middle(recording, n: int):
    """The recording's middle ``n`` samples (the recording itself when it is not longer)."""
    if recording.n_samples <= n:
        return recording
    a = (recording.n_samples - n) // 2
    cut = lambda x: None if x is None else x[a:a + n]  # noqa: E731 - stored columns slice as views
    return replace(recording, t=recording.t[a:a + n] - recording.t[a], q=cut(recording.q), dq=cut(recording.dq),
                   tau=cut(recording.tau))


KNEE_MARGIN = 3.0
"""The cutoffs are cross-validated when the noise knee lies at least this many times above the 10×-band rule."""

SCORE_MARGIN = 0.1
"""A cutoff other than the rule's must lower the cross-validation score by this fraction to be chosen."""


@short_repr
@dataclass(frozen=True)
class PreprocessingChoice:
    """Filters chosen by blocked cross-validation (``preprocessing = "auto"``).

    Attributes
    ----------
    settings : Preprocessing
        The chosen candidate (resolved on the data).
    candidates : tuple of Preprocessing
    error : (n_candidates, n_dof) array [N·m]
        Out-of-fold RMS torque error of each candidate on the common held-out samples.
    score : (n_candidates,) array
        Mean over joints of (error / RMS torque)²: the criterion (joints weigh alike).
    note : str
        What was chosen, in words.
    data : PreparedData
        The identification log prepared with the chosen settings.
    """

    settings: Preprocessing
    candidates: tuple
    error: np.ndarray
    score: np.ndarray
    note: str = ""
    data: PreparedData | None = None

    @property
    def chose(self) -> bool:
        """Whether there was a choice to make (several candidates)."""
        return len(self.candidates) > 1

    def to_dict(self) -> dict:
        """JSON-ready choice.

        Returns
        -------
        dict
            The candidate chosen, the candidates and their out-of-fold errors and scores.
        """
        chosen = next(i for i, c in enumerate(self.candidates) if c.position_cutoff == self.settings.position_cutoff)
        return {"chosen": chosen, "note": self.note,
                "candidates": [{"position_cutoff": c.position_cutoff, "parallel_cutoff": c.parallel_cutoff,
                                "decimation": c.decimation} for c in self.candidates],
                "out_of_fold_rms_error": self.error, "score": self.score}


def _candidate(robot, base, recording, settings: Preprocessing, evaluation: list, prior: np.ndarray, duration: float,
               folds: int) -> tuple[PreparedData, np.ndarray]:
    """One candidate of :func:`choose_preprocessing`: the log prepared with ``settings``, and each joint's RMS error
    over the folds of the parameters fitted on the other folds (:func:`_out_of_fold_error`)."""
    data = prepare(recording, settings)
    fitted, _ = _fold_accumulators(robot, base, data, duration, folds)
    return data, _out_of_fold_error(robot, fitted, evaluation, prior, folds)


def _out_of_fold_error(robot, fitted: list, evaluation: list, prior: np.ndarray, folds: int) -> np.ndarray:
    """Each joint's RMS error over the folds of the parameters fitted on the other folds of ``fitted``, scored on
    ``evaluation``'s rows (``inf`` where a fold's complement does not determine them)."""
    sumsq, rows = np.zeros(robot.n_dof), np.zeros(robot.n_dof)
    try:
        for k in range(folds):
            params = LeastSquaresAccumulator.merged([a for i, a in enumerate(fitted) if i != k]).solve(prior=prior).params
            sumsq += evaluation[k].joint_residual_sumsq(params)
            rows += evaluation[k].rows
    except IdentifiabilityError:
        return np.full(robot.n_dof, np.inf)
    return np.sqrt(sumsq / np.maximum(rows, 1))


def _fold_accumulators(robot, base, data: PreparedData, duration: float, folds: int):
    """One accumulator per block of ``duration / folds`` seconds (blocks by time, so that candidates trimmed
    differently share their block boundaries), and each joint's RMS torque."""
    accs = [LeastSquaresAccumulator(base.n_base, robot.n_dof) for _ in range(folds)]
    sumsq = np.zeros(robot.n_dof)
    count = 0
    for index, y, tau, keep in base_chunks(robot, base, data):
        fold = np.minimum((data.t[index] / duration * folds).astype(int), folds - 1)
        sumsq += (tau**2).sum(axis=0)
        count += tau.shape[0]
        for k in np.unique(fold):
            sel = fold == k
            accs[k].add(y[sel].reshape(-1, base.n_base), tau[sel].reshape(-1), keep[sel].reshape(-1))
    return accs, np.sqrt(sumsq / max(count, 1))


def choose_preprocessing(robot: Robot, base: BaseParameters, recording, given: Preprocessing, folds: int = FOLDS,
                         progress: Callable[[str, float, float], None] | None = None) -> PreprocessingChoice:
    """Choose the position/velocity and parallel cutoffs (hence the decimation) by blocked cross-validation, when
    there is a choice to make.

    The default rule filters at :data:`~dynid.preprocessing.bands.POSITION_FACTOR` × the excitation band; on a slow motion logged
    with little noise, the positions' spectrum stays above the noise floor far beyond that (the knee,
    :attr:`dynid.preprocessing.bands.BandEstimate.knee`), and the content there (what the accelerations of the
    robot's own dynamics hold) is worth keeping. When the knee lies :data:`KNEE_MARGIN` times above the rule and the
    config gives no cutoff, the candidates are the rule's cutoff, the knee and their geometric mean. Each candidate's
    parameters are fitted on all blocks but one of its own preprocessed rows and scored on the held-out block of the
    **default** preprocessing's rows, the same for every candidate.

    Parameters
    ----------
    robot, base
    recording : dynid.io.logs.datasets.Recording
        The raw identification log.
    given : Preprocessing
        The config's settings (``None`` fields are chosen).
    folds : int
    progress : callable, optional
        ``progress(stage, done, total)``: :data:`PREPARING` the log by the default rule (its share done), then, where
        there is a choice, :data:`CROSS_VALIDATING` in preparations of the log (on a long log its middle's by the rule,
        each candidate, and the chosen one's of the whole log).

    Returns
    -------
    PreprocessingChoice
        With one candidate (the default rule's) when there was nothing to choose.
    """
    said = progress if progress is not None else (lambda stage, done, total: None)
    reference = prepare(recording, given, progress=lambda share: said(PREPARING, share, 1))
    rs = reference.settings
    band, knee = rs.band, rs.knee
    default = POSITION_FACTOR * (band or 0.0)
    if (given.position_cutoff is not None or given.parallel_cutoff is not None or rs.fourier is not None or knee is None
            or knee < KNEE_MARGIN * default):
        return PreprocessingChoice(rs, (rs,), np.zeros((1, robot.n_dof)), np.zeros(1), "", reference)
    full, recording = recording, _middle(recording, MAX_SAMPLES)  # a long log: its middle minute decides
    cutoffs = (default, float(np.sqrt(default * knee)), knee)
    first = int(recording is not full)  # a long log: its middle by the rule first, and the chosen one's whole log last
    steps = len(cutoffs) + 2 * first
    said(CROSS_VALIDATING, 0, steps)
    if recording is not full:
        reference = prepare(recording, replace(given, band=band))
        said(CROSS_VALIDATING, 1, steps)
    duration = float(recording.t[-1] - recording.t[0]) + 1.0 / recording.rate
    evaluation, rms = _fold_accumulators(robot, base, reference, duration, folds)
    prior = base.base_from_standard(robot.standard_parameters())  # as the estimate: undetermined directions kept there
    settings = [replace(given, position_cutoff=given.position_cutoff if given.position_cutoff is not None else cutoff,
                        parallel_cutoff=given.parallel_cutoff if given.parallel_cutoff is not None else cutoff)
                for cutoff in (capped(f, recording.rate) for f in cutoffs)]
    # the rule's candidate is the reference itself (the same arrays: only its derivation says "10× band") where the
    # reference resolved the same cutoffs: its folds are the evaluation's, and it needs no pass of its own
    rs = reference.settings
    same = rs.position_cutoff == settings[0].position_cutoff and rs.parallel_cutoff == settings[0].parallel_cutoff
    # the other candidates on the cores (forked children) where the log is in memory; the same numbers
    stored = any(x is not None and not isinstance(x, np.ndarray) for x in (recording.q, recording.dq, recording.tau))
    beside = [None if stored or (k == 0 and not same) else
              ForkedCall(_candidate, robot, base, recording, s, evaluation, prior, duration, folds)
              for k, s in enumerate(settings) if k > 0 or not same]
    candidates, errors, prepared = [], [], []
    with contextlib.ExitStack() as stack:
        for call in beside:
            if call is not None:
                stack.enter_context(call)
        calls = iter(beside)
        for k, s in enumerate(settings):
            if k == 0 and same:
                data, error = reference, _out_of_fold_error(robot, evaluation, evaluation, prior, folds)
            else:
                call = next(calls)
                data, error = (_candidate(robot, base, recording, s, evaluation, prior, duration, folds) if call is None
                               else call.result())
            candidates.append(data.settings)
            prepared.append(data)
            errors.append(error)
            said(CROSS_VALIDATING, first + len(prepared), steps)
    error = np.array(errors)
    score = np.mean((error / np.where(rms > 0, rms, 1.0)) ** 2, axis=1)
    scored = bool(np.all(np.isfinite(score)))
    best = int(np.argmin(score)) if scored else 0  # a candidate not scored: the rule's cutoff, said so
    if scored and score[best] > (1 - SCORE_MARGIN) * score[0]:  # the rule's cutoff unless another is clearly better
        best = 0
    among = f"{', '.join(f'{f:.3g}' for f in cutoffs)} Hz ({POSITION_FACTOR:g}× the band, the noise knee and their geometric mean)"
    note = (f"cutoffs {cutoffs[best]:.3g} Hz, chosen by {folds}-fold blocked cross-validation among {among}"
            if scored else
            f"cutoffs {cutoffs[0]:.3g} Hz ({POSITION_FACTOR:g}× the band): not cross-validated among {among}, as a fold "
            f"of {duration / folds:.3g} s holds too few rows to fit the {base.n_base} base parameters on the others")
    note += "" if recording is full else f" on the log's middle {recording.n_samples} samples"
    data = prepared[best]
    if recording is not full:
        chosen = candidates[best]
        data = prepare(full, replace(given, band=band, position_cutoff=chosen.position_cutoff,
                                     parallel_cutoff=chosen.parallel_cutoff),
                       progress=lambda share: said(CROSS_VALIDATING, steps - 1 + share, steps))
    data = replace(data, settings=replace(data.settings, derivation=f"{data.settings.derivation}; {note}"))
    return PreprocessingChoice(data.settings, tuple(candidates), error, score, note, data)

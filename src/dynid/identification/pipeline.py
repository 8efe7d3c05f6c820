"""The identification pipeline, assembled from its parts: a robot model, a preprocessing strategy with the choices it
derives from the data, the base-parameter map, the estimators, the evidence and the verdict.

One recording goes through it the same way whoever calls it (``dynid identify`` from a config,
:func:`dynid.identify_from_arrays` and :class:`dynid.Identifier` from arrays, the studies)::

    pipeline = IdentificationPipeline(robot, preprocessing, estimators=("wls", "sdp"), friction="auto")
    result = pipeline.fit(recording, validation=(log_b, log_c))

:meth:`~IdentificationPipeline.fit` calls its four parts once each, in order (pysindy's ``SINDy.fit``):

1. **preparation**, :meth:`~IdentificationPipeline.prepare` (Gautier's parallel filtering and decimation, or the
   paper's eq. 17 with Fourier-fit derivatives, :mod:`dynid.preprocessing.strategies`): the filters (the strategy's
   rule on the excitation band, or cutoffs chosen by blocked cross-validation where the positions' noise knee lies far
   above it, :func:`dynid.identification.cross_validation.choose_preprocessing`), the Coulomb smoothing velocity
   (``preprocessing.coulomb_velocity``: given, or "auto" by cross-validation), and each joint's friction model and
   its state at rest (``friction = "auto"``, :func:`dynid.identification.friction_models.choose_friction`), which
   may change the base-parameter map;
2. **estimation**, :meth:`~IdentificationPipeline.estimate`: every estimator in one pass over the rows
   (:func:`dynid.identification.estimation_pass.identify`), the consistency checks and what the log itself says (held-out
   blocks, the drive-only candidate, the SDP's refits, the torque delay), then the closed-loop estimators (IDIM-IV,
   DIDIM, DIDIM-SDP: :class:`dynid.identification.closed_loop_estimators.ClosedLoopEstimator`);
3. **evidence**, :func:`dynid.identification.evidence.gather_evidence`: every candidate scored on the validation logs
   given, as prepared and on the one yardstick;
4. **verdict**, :func:`dynid.identification.verdict.decide`: the main estimate, chosen once.

The result's ``settings`` say every choice and why. Reading logs and configs and the drive gains' runs are the
callers' (:mod:`dynid.identification.run`). An experiment that sets its own search box and seeds (the paper's,
:mod:`dynid.studies.paper`) takes the estimators fed and unfitted from :meth:`~IdentificationPipeline.estimation`.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from .._util.keywords import seed_of
from .._util.reprs import short_repr
from ..dynamics.base_parameters import BaseParameters, base_parameters
from ..dynamics.regressor import expect_samples
from ..estimators.estimation import Estimation, stream_rows
from ..estimators.registry import DEFAULT_ESTIMATORS, FitData, estimator_choices
from ..exceptions import ConfigError, DataError, DynIdError
from ..io.config.identification_config import split_estimators
from ..model.loading import as_robot
from ..model.robot import Robot
from ..preprocessing.preparation import base_chunks, prepare
from ..preprocessing.prepared import PreparedData, dead_channels, min_speeds
from ..preprocessing.settings import Preprocessing
from ..preprocessing.strategies import strategy_for
from ..runtime.processes import ForkedCall
from ..validation.diagnostics import DELAY_ADVICE, delay_findings
from .choices import ModelChoices
from .closed_loop_estimators import ClosedLoopEstimator
from .cross_validation import choose_coulomb_velocity, choose_preprocessing
from .delay import delay_from_rows
from .drive_only import preprocessing_variants
from .estimation_pass import identify, one_way_joints
from .evidence import filtered_finding, gather_evidence, weighed_means, yardstick_reference
from .friction_models import SMOOTH_FIT_FACTOR, choose_friction
from .geared_friction import delay_beyond_hysteresis, hysteresis_delay_finding, hysteresis_weighed
from .verdict import SAME_FIGURE, decide

__all__ = ["IdentificationPipeline", "PreparedIdentification", "FRICTION_CHOICES"]

REGRESSOR_PASSES = 10
"""Times an identification computes the regressor over its log's samples at least (the reference preparation, the
cutoffs' candidates, the friction models' folds, the estimation, the delay check; with the validation logs 10.5-86× on
the shipped configs and the example, benchmarks/NOTEBOOK.md): where that is beyond the NumPy form's budget, the
compiled regressor computes from the first sample (:func:`dynid.dynamics.regressor.expect_samples`)."""

FRICTION_CHOICES = ("auto", "description")
"""``friction``: each joint's model chosen by cross-validation, or the description's terms."""


@short_repr
@dataclass(frozen=True)
class PreparedIdentification:
    """A recording prepared for the estimators, with the model the data chose.

    Attributes
    ----------
    robot : Robot
        The model as it will be identified: ``choices.model(description)`` (the description itself is never
        modified).
    base : BaseParameters
        The base-parameter map of :attr:`robot`.
    data : PreparedData
        The filtered signals (their resolved settings in ``data.settings``).
    choices : ModelChoices
        What the data chose (:class:`dynid.identification.choices.ModelChoices`; results.json's ``settings`` hold its
        :meth:`~dynid.identification.choices.ModelChoices.to_dict`).
    variants : tuple of (float, LeastSquaresAccumulator)
        Where a joint moved one way only: the base rows of the log prepared at other cutoffs
        (:func:`dynid.identification.drive_only.preprocessing_variants`).
    """

    robot: Robot
    base: BaseParameters
    data: PreparedData
    choices: ModelChoices
    variants: tuple = ()


@short_repr
@dataclass(frozen=True)
class IdentificationPipeline:
    """Identification of one robot from one recording (module docstring).

    Parameters
    ----------
    robot : Robot
        The robot's description (a built-in robot's name or a description's path is loaded:
        :func:`dynid.model.loading.as_robot`).
    preprocessing : Preprocessing
        The settings as given (``None`` fields: derived from the data).
    estimators : tuple of str, Estimator and ClosedLoopEstimator
        Keys of :mod:`dynid.estimators.registry`, or unfitted estimators of registered classes carrying their
        hyper-parameters (:func:`dynid.estimators.registry.estimator_choices`); the first is the main estimate. The
        closed-loop ones (IDIM-IV, DIDIM, DIDIM-SDP: :data:`dynid.estimators.instrumental.CLOSED_LOOP_METHODS` keys, with
        ``controller``, or :class:`dynid.identification.closed_loop_estimators.ClosedLoopEstimator` parts) run after the others,
        on the log as read, in order, as a config's ``[estimation] estimators`` lists them.
    friction : {"description", "auto"} or None
        The description's friction terms, or each joint's model chosen by cross-validation; None (default): as a
        config without the setting (:attr:`dynid.preprocessing.settings.Preprocessing.friction_default`: "auto" unless a
        Coulomb smoothing velocity is given), whichever route fits.
    rng : int
        Seeds the box searches and the bootstrap (a config's ``seed``).
    source : str
        Where the robot's description comes from (results.json's ``robot_source``: a built-in name, a path), so that
        :func:`dynid.load_results` finds it.
    controller : ClosedLoopSetup or None
        How the log was recorded in closed loop (:class:`dynid.simulation.closed_loop.ClosedLoopSetup`); needed
        with closed-loop keys among ``estimators``.
    choice : {"torques", "states"}
        What the verdict weighs on the validation logs: their torques, or (with ``sdp``) the SDP's refits' spread on
        their states (a config's ``[estimation] choice``).
    torque_sensor : str or None
        "joint" for a log of joint torque sensors: the states' fallback is then the description, not the drive-only
        estimate (a config's ``torque_sensor``).

    Attributes
    ----------
    open_loop : tuple
        The open-loop estimators of ``estimators`` (keys and objects), fitted on the prepared log.
    closed_loop_estimators : tuple of ClosedLoopEstimator
        The closed-loop parts of ``estimators`` (a key's made with ``controller``), run by :meth:`estimate` in order.
    closed_loop : tuple of str
        Their methods.

    Raises
    ------
    ConfigError
        An unknown ``friction`` or estimator, a closed-loop estimator first or without ``controller`` (when built), or
        an unknown preprocessing strategy (when preparing).
    """

    robot: Robot
    preprocessing: Preprocessing = field(default_factory=Preprocessing)
    estimators: tuple = DEFAULT_ESTIMATORS
    friction: str | None = None
    rng: int = 0
    source: str = ""
    controller: Any = None
    choice: str = "torques"
    torque_sensor: str | None = None
    open_loop: tuple = field(init=False, repr=False, compare=False)
    closed_loop_estimators: tuple[ClosedLoopEstimator, ...] = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        object.__setattr__(self, "robot", as_robot(self.robot))
        object.__setattr__(self, "rng", seed_of(self.rng))  # a negative seed refused here, not deep in an estimator
        if self.friction is None:
            object.__setattr__(self, "friction", self.preprocessing.friction_default)
        if self.friction not in FRICTION_CHOICES:
            raise ConfigError(f'friction: expected "description" or "auto", got {self.friction!r}', field="friction")
        items = (self.estimators,) if isinstance(self.estimators, str) else tuple(self.estimators)
        if items and isinstance(items[0], ClosedLoopEstimator):
            raise ConfigError(f"estimators: the first is the main estimate and starts the closed-loop ones: list ols or "
                              f"wls before {items[0].method!r}", field="estimators")
        open_loop, keys = split_estimators([e for e in items if not isinstance(e, ClosedLoopEstimator)], "estimators")
        if keys and self.controller is None:
            raise ConfigError(f"estimators: {keys[0]} simulates the run in closed loop and needs its "
                              "controller (a ClosedLoopSetup: the controller, the set-points, the feed-forward)",
                              field="controller")
        parts = tuple(e if isinstance(e, ClosedLoopEstimator) else ClosedLoopEstimator(e.strip().lower(), self.controller)
                      for e in items if isinstance(e, ClosedLoopEstimator) or isinstance(e, str) and e.strip().lower() in keys)
        object.__setattr__(self, "open_loop", open_loop)
        object.__setattr__(self, "closed_loop_estimators", parts)

    @property
    def closed_loop(self) -> tuple[str, ...]:
        """The closed-loop estimators' methods, in the order they run.

        Returns
        -------
        tuple of str
        """
        return tuple(part.method for part in self.closed_loop_estimators)

    def prepare(self, recording, base: BaseParameters | None = None, step: Callable[[str], Any] | None = None,
                progress: Callable[[str, int, int], Any] | None = None) -> PreparedIdentification:
        """Filter a recording and make the choices that depend on it (module docstring, steps 1-3).

        Parameters
        ----------
        recording : dynid.io.logs.datasets.Recording
            Anything with ``name, label, t, q, dq (or None), tau, rate, n_samples, warnings``; ``tau`` [N·m] with the
            drive gains applied (eq. 16).
        base : BaseParameters, optional
            The description's base-parameter map, when the caller has it already.
        step : callable, optional
            ``step(label)`` before each step that takes time.
        progress : callable, optional
            ``progress(label, done, total)``: each step as it starts (``0, 1``), and the cross-validations' share done
            as they go.

        Returns
        -------
        PreparedIdentification

        Raises
        ------
        ConfigError
            Settings that do not fit the recording (a cutoff above its Nyquist frequency, an unknown strategy).
        DataError
            A recording the strategy cannot prepare, or whose every torque channel is dead.
        IdentifiabilityError
            Too little motion to cross-validate a choice on.
        ShapeError
            A recording not one row per time stamp and one column per joint, or holding NaN
            (:meth:`dynid.io.logs.datasets.Recording.check`).
        """
        def say(label: str) -> Callable[[int, int], None] | None:
            if step is not None:
                step(label)
            if progress is None:
                return None
            progress(label, 0, 1)
            return lambda done, total: progress(label, done, total)

        recording.check(self.robot.n_dof)
        expect_samples(REGRESSOR_PASSES * recording.n_samples)  # the compiled regressor from the first sample
        dead, _ = dead_channels(recording.tau, recording.label)
        if len(dead) == recording.tau.shape[1]:
            raise DataError(f"{recording.label}: every joint's torque reads one value throughout (dead channels, or "
                            "not the torque or current columns?): nothing can be identified from this log")
        settings = self.preprocessing
        base = base if base is not None else base_parameters(self.robot, rng=0)
        auto = settings.auto and strategy_for(settings).chooses_cutoffs
        shares: dict = {}

        def stage(label: str, done: float, total: float) -> None:  # each stage said once as it starts, then its share
            if label not in shares:
                shares[label] = say(label)
            if shares[label] is not None:
                shares[label](done, total)

        filters = choose_preprocessing(self.robot, base, recording, settings, progress=stage) if auto else None
        if filters is not None:
            assert filters.data is not None  # the chosen candidate's prepared data
            data = filters.data
        else:
            data = prepare(recording, settings, progress=lambda share: stage("preprocessing", share, 1))
        vs = settings.coulomb_velocity
        coulomb = None
        if vs == "auto":
            say("Coulomb smoothing velocity (cross-validation)")
            coulomb = choose_coulomb_velocity(self.robot, base, data)
        choices = ModelChoices(coulomb.velocity if coulomb is not None
                               else np.broadcast_to(np.asarray(vs, dtype=float), (self.robot.n_dof,)),
                               filters if filters is not None and filters.chose else None, coulomb)
        if self.friction == "auto":
            data, choices = _friction_chosen(choices, self.robot, data, given=self.preprocessing.min_speed != "auto",
                                             progress=say("friction model of each joint (cross-validation)"))
        robot = choices.model(self.robot)
        if choices.friction is not None:
            base = base_parameters(robot, rng=0)
        variants = preprocessing_variants(robot, base, recording, data, settings, one_way_joints(data))
        return PreparedIdentification(robot, base, data, choices, variants)

    def estimate(self, prepared: PreparedIdentification, references: tuple = (), progress=None,
                 held_out: bool = False, recording=None, *, jackknife: bool = False, delay: bool = True):
        """Every estimator on the prepared data, the consistency checks and the verdict
        (:func:`dynid.identification.estimation_pass.identify`), then the closed-loop estimators.

        Parameters
        ----------
        prepared : PreparedIdentification
            From :meth:`prepare`.
        references : tuple of ReferenceSet
            Published parameter sets scored beside, in :attr:`PreparedIdentification.base`'s layout.
        progress : callable, optional
            ``progress(step, done, total)``.
        held_out : bool
            With ``sdp`` listed and no validation log to come: score the least-squares and SDP estimates on held-out
            blocks (said in the main estimate's finding; :func:`dynid.identification.estimation_pass.identify`).
        recording : dynid.io.logs.datasets.Recording, optional
            The log as read, which the closed-loop estimators simulate (needed with :attr:`closed_loop`).
        jackknife : bool
            Refit the SDP on all blocks of the log but one, for the torque-free verdict
            (:func:`dynid.identification.estimation_pass.identify`).
        delay : bool
            Check the log for a delay between its torque and position channels (default true).

        Returns
        -------
        dynid.identification.result.IdentificationResult
            Its ``settings`` hold the resolved preprocessing, the preprocessing as given (``given_preprocessing``: what
            another log's preparation starts from, :func:`dynid.preprocessing.strategies.carried_over`),
            :attr:`PreparedIdentification.choices`,
            ``robot_source``, ``robot_fingerprint`` (:meth:`dynid.model.robot.Robot.kinematic_fingerprint`) and
            ``drive_terms`` (the robot's before the friction models: a joint torque sensor's log drops ``Ia``).

        Raises
        ------
        ConfigError
            An unknown estimator, ``sdp`` with a description without physical nominal parameters, or closed-loop
            estimators without ``recording``.
        DataError
            Set-points that are not one per sample of ``recording``.
        IdentifiabilityError
            A log that does not excite every base parameter.
        """
        blocks: list = []  # the delay check's rows, from the identification's own pass
        check = _delay_checked(prepared.data) if delay else "not estimated: asked not to"
        result = identify(prepared.robot, prepared.base, prepared.data, self.open_loop, references=references,
                          progress=progress, rng=self.rng,
                          held_out=held_out, jackknife=jackknife,
                          observers=(lambda *block: blocks.append(block),) if check is None else (),
                          variants=prepared.variants)
        findings, checked = _delay_check(prepared, blocks) if check is None else ([], {"note": check})
        result = replace(result, settings={**result.settings, "given_preprocessing": self.preprocessing.to_dict(),
                                           "robot_source": self.source,
                                           "robot_fingerprint": prepared.robot.kinematic_fingerprint(),
                                           "drive_terms": list(self.robot.drive_terms),
                                           **prepared.choices.to_dict()},
                         findings=result.findings + tuple(findings), diagnostics={**result.diagnostics, "torque_delay": checked},
                         choices=prepared.choices)
        if not self.closed_loop:
            return result
        if recording is None:
            raise ConfigError(f"{self.closed_loop[0]} simulates the log as read: IdentificationPipeline.estimate(..., "
                              "recording=...), or fit(recording)", field="closed_loop")

        if progress is not None:
            progress("closed-loop estimators (" + ", ".join(self.closed_loop) + ")", 0, 1)
        experiment = self.closed_loop_estimators[0].experiment(prepared.robot, recording)  # one reading for all
        for part in self.closed_loop_estimators:  # on the rows the other estimators fitted: the log is not prepared again
            result = part.added_to(result, prepared.robot, prepared.base, recording, self.preprocessing,
                                   experiment=experiment, data=prepared.data)
        return result

    def estimation(self, prepared: PreparedIdentification, problem: FitData, *, keep_rows: bool = False) -> Estimation:
        """The open-loop estimators fed every block of the prepared log's base rows in one pass, not yet fitted: for an
        experiment that sets its own search box and seeds (the paper's Table 3 box and per-estimator seeds,
        :func:`dynid.studies.paper.run_paper_experiment`), where :meth:`estimate` gives the verdict's.

        Parameters
        ----------
        prepared : PreparedIdentification
            From :meth:`prepare`.
        problem : FitData
            What the estimators know before any row (joints, base map, layout, prior, eq. 9 weights); the estimator
            objects given are cloned and fitted on it.
        keep_rows : bool
            Keep the stacked base rows (:meth:`dynid.estimators.estimation.Estimation.rows`).

        Returns
        -------
        dynid.estimators.estimation.Estimation
            Fit it with a box and generators (:meth:`~dynid.estimators.estimation.Estimation.fit`).

        Raises
        ------
        ConfigError
            An estimator that cannot take the rows block by block as the least-squares reference.
        """
        keys, given = estimator_choices(self.open_loop)
        estimation = Estimation(keys, problem, prepared.base.names, keep_rows=keep_rows, given=given)
        chunks = base_chunks(prepared.robot, prepared.base, prepared.data, standard=estimation.standard)
        stream_rows(chunks, estimation, prepared.base)
        return estimation

    def fit(self, recording, *, validation: tuple = (), references: Callable[[Robot, BaseParameters], tuple] | None = None,
            progress=None, held_out: bool | None = None,
            drive_gains: Callable[[Robot, BaseParameters], Any] | None = None, weigh_delay: bool = True,
            file_variants: bool = True):
        """Identify: the four parts, once each (module docstring).

        Parameters
        ----------
        recording : dynid.io.logs.datasets.Recording
            The identification log, as read.
        validation : tuple of Recording
            Logs of other motions, read: the verdict's evidence.
        references : callable, optional
            ``references(robot, base)`` -> the reference sets in the prepared model's layout.
        progress : callable, optional
            ``progress(step, done, total)``.
        held_out : bool, optional
            Score the least-squares and SDP estimates on held-out blocks of the log (default: without validation logs,
            where they are the evidence).
        drive_gains : callable, optional
            ``drive_gains(robot, base)`` for the prepared model, computed on the second core while the estimators run,
            its value the result's ``drive_gains``.
        weigh_delay : bool
            With validation logs, weigh a delay finding on them (:func:`_delay_weighed`: the log identified again with
            the delay); default true.
        file_variants : bool
            With validation logs, choose what the written files hold of each estimate
            (:mod:`dynid.identification.file_terms`); default true (the delay's second identification writes none).

        Returns
        -------
        dynid.identification.result.IdentificationResult

        Raises
        ------
        DynIdError
            As :meth:`prepare`, :meth:`estimate` and the validation logs' scoring.
        """
        step = None if progress is None else (lambda label: progress(label, 0, 1))
        validation = tuple(validation)
        prepared = self.prepare(recording, progress=progress)
        refs = () if references is None else references(prepared.robot, prepared.base)
        reference = yardstick_reference(recording) if validation else None
        smooth = filtered_finding([recording.name, *(log.name for log in validation)], [recording, *validation])
        beside = None if drive_gains is None else ForkedCall(drive_gains, prepared.robot, prepared.base)
        with beside or contextlib.nullcontext():
            result = self.estimate(prepared, refs, progress, held_out=not validation if held_out is None else held_out,
                                   recording=recording if self.closed_loop else None,
                                   jackknife=bool(validation) and self.choice == "states", delay=weigh_delay)
            if beside is not None:
                if step is not None:
                    step("drive gains and payload")
                result = replace(result, drive_gains=beside.result())
        # a delay finding is weighed by identifying the log again with it (:func:`_delay_weighed`), on the second core
        # while this one gathers the first identification's evidence; the verdict never adds or removes the finding
        weigh = bool(validation) and weigh_delay and any(f.kind == "delay" for f in result.findings)
        again = ForkedCall(self._identified_again, result, prepared, recording, validation) if weigh else None
        with again or contextlib.nullcontext():
            evidence = (gather_evidence(self, prepared, result, validation, reference=reference, progress=progress,
                                        file_variants=file_variants) if validation else None)
            result = decide(result, evidence)
            if again is not None:
                if step is not None:
                    step("the delay found, weighed on the validation logs")
                result = _delay_weighed(result, again.result())
        return replace(result, findings=tuple(result.findings) + smooth)

    def _identified_again(self, result, prepared, recording, validation: tuple) -> tuple[tuple[float, str], ...]:
        """The log identified again with its torques read at the delay ``result`` found (every validation log's too)
        and, where the finding names a geared drive's hysteresis as well, apart with that presliding distance: for
        each, the main estimate's mean error over the validation logs that move on the one yardstick, and its name.

        The second identification keeps the first's choices (its cutoffs, the friction model of each joint: the
        prepared robot as the description), so that the setting alone differs, and checks no delay of its own."""
        delay, s = result.diagnostics["torque_delay"], prepared.data.settings
        kept = {"auto": False, "position_cutoff": s.position_cutoff, "velocity_cutoff": s.velocity_cutoff,
                "parallel_cutoff": s.parallel_cutoff, "decimation": s.decimation}
        changes = [{"torque_delay": self.preprocessing.torque_delay + delay["seconds"]}]
        if "hysteresis" in delay:
            changes.append({"presliding": delay["hysteresis"]["presliding"]})
        answers = []
        for change in changes:
            again = replace(self, robot=prepared.robot, friction="description",
                            preprocessing=replace(self.preprocessing, **kept, **change))
            other = again.fit(recording, validation=validation, weigh_delay=False, file_variants=False)
            answers.append((_yardstick_mean(other), other.main))
        return tuple(answers)


def _yardstick_mean(result) -> float:
    """The main estimate's mean error over the validation logs that move, on the one yardstick [%]."""
    return float(weighed_means(result.diagnostics["yardstick"])[result.main])


def _delay_weighed(result, answers: tuple):
    """The delay finding kept where the validation logs agree, withdrawn otherwise: the main estimate's mean error on
    the one yardstick with the delay (``answers[0]``, :meth:`IdentificationPipeline._identified_again`) and without,
    better by more than :data:`~dynid.identification.verdict.SAME_FIGURE` to keep it (issue "Every assurance checked on
    what the user meets", item 5): held-out blocks of the log favoured the delays the real UR10e's and LBR Med7's logs
    show, which their validation logs do not (the figures: the changelog, benchmarks/NOTEBOOK.md). Where the finding
    names a geared drive's hysteresis too (``answers[1]``, with its presliding distance), the setting the validation
    logs agree with better is kept (:func:`dynid.identification.geared_friction.hysteresis_weighed`). The figures are
    in ``diagnostics["torque_delay"]``."""
    delay = result.diagnostics["torque_delay"]
    (with_delay, main_with), *presliding = answers
    figures: dict[str, Any] = {"without": _yardstick_mean(result), "with": with_delay, "main_with": main_with}
    if presliding:
        figures["presliding"] = {"with": presliding[0][0], "main_with": presliding[0][1]}
    findings = []
    for f in result.findings:
        text = _weighed_text(f.text, delay, figures) if f.kind == "delay" else f.text
        if text is not None:
            findings.append(replace(f, text=text))
    return replace(result, findings=tuple(findings),
                   diagnostics={**result.diagnostics, "torque_delay": {**delay, "validation": figures}})


def _weighed_text(text: str, delay: dict, figures: dict) -> str | None:
    """The delay finding's text with the validation logs' answer (:func:`_delay_weighed`'s ``figures``), None where it
    is withdrawn."""
    if "presliding" in figures:
        return hysteresis_weighed(text, figures, delay["seconds"], delay["hysteresis"]["presliding"])
    with_delay, without = figures["with"], figures["without"]
    if not with_delay * SAME_FIGURE < without:
        return None
    return text.replace(DELAY_ADVICE, f"identify again with it: the validation logs agree (the main estimate so, "
                                      f"{figures['main_with']}, predicts them {with_delay:.3g} % against {without:.3g} %, "
                                      "on one yardstick)")


def _friction_chosen(choices: ModelChoices, robot: Robot, data: PreparedData, *, given: bool,
                     progress: Callable[[int, int], None] | None = None) -> tuple[PreparedData, ModelChoices]:
    """:meth:`IdentificationPipeline.prepare`'s friction model of each joint, chosen by cross-validation on ``data``
    (:func:`dynid.identification.friction_models.choose_friction`); ``data`` then takes the chosen rest model and the
    slowest speeds its smooth Coulomb terms are fitted at (:func:`_fitted_speeds`; ``given``: the user set
    ``min_speed``). Returns ``data`` and ``choices`` with the friction chosen."""
    friction = choose_friction(choices.model(robot), data, progress=progress)
    data = data.with_rest_model(friction.rest_friction(), data.settings.presliding)
    return _fitted_speeds(data, friction, given=given), replace(choices, friction=friction)


def _fitted_speeds(data: PreparedData, friction, given: bool) -> PreparedData:
    """``data`` with each joint's slowest fitted speed raised where its chosen smooth Coulomb term needs it
    (:meth:`dynid.identification.friction_models.FrictionChoice.fit_speeds`), said in the settings' derivation, and in
    a warning where the user gave ``min_speed``."""
    vmin = min_speeds(data.settings, len(friction.models))
    fit = friction.fit_speeds(vmin)
    raised = [j for j in range(fit.size) if fit[j] > vmin[j]]
    if not raised:
        return data
    said = ", ".join(f"J{j + 1} {fit[j]:.3g} rad/s" for j in raised)
    data = data.with_min_speed(fit, f"; rows of a joint with a smooth Coulomb term slower than {SMOOTH_FIT_FACTOR:g}× "
                                    f"its velocity left out ({said})")
    if given:
        data = replace(data, warnings=(*data.warnings, f"preprocessing.min_speed raised where friction = \"auto\" chose "
                                       f"smooth Coulomb friction, which is fitted only on rows at least "
                                       f"{SMOOTH_FIT_FACTOR:g}× its velocity fast: {said}"))
    return data


DELAY_MAX_SAMPLES = 60_000
"""The delay check of :func:`_delay_check` holds the log's rows in memory: a longer log is not checked (said so)."""


def _delay_checked(data: PreparedData) -> str | None:
    """Why the delay check does not run on ``data`` (None: it runs)."""
    if data.settings.strategy != "parallel":
        return f"not estimated: the {data.settings.strategy!r} strategy"
    if data.t.shape[0] > DELAY_MAX_SAMPLES:
        return f"not estimated: {data.t.shape[0]} samples (at most {DELAY_MAX_SAMPLES}); estimate_delay on a part"
    return None


def _delay_check(prepared: PreparedIdentification, blocks: list) -> tuple[list, dict]:
    """The delay between the torque and position channels the identification log shows on top of the one given
    (:func:`dynid.identification.delay.delay_from_rows`, on the identification's own rows), and the finding when it
    matters (:func:`dynid.validation.diagnostics.delay_findings`); a lag found is weighed against a geared drive's
    hysteresis (:func:`dynid.identification.geared_friction.delay_beyond_hysteresis`): where that predicts held-out
    blocks of the log as well, the finding names both settings, and validation logs weigh each apart."""
    data = prepared.data
    try:
        d = delay_from_rows(data, blocks)
    except DynIdError as exc:
        return [], {"note": f"not estimated: {exc}"}
    found = delay_findings(d.samples, d.std, d.determined, data.rate, data.settings.torque_delay, data.name, d.held_out)
    checked: dict[str, Any] = {"samples": d.samples, "std": d.std, "seconds": d.seconds, "determined": d.determined,
                               "at_bound": d.at_bound, "held_out_ratio": d.held_out}
    turned = delay_beyond_hysteresis(prepared.robot, prepared.base, data, d) if found else None
    if turned is not None:
        found = [hysteresis_delay_finding(found[0], *turned)]
        checked = {**checked, "hysteresis": {"presliding": turned[0], "held_out_ratio": turned[1]}}
    return found, checked

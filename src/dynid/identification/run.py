"""The runs ``dynid identify`` and ``dynid validate`` describe: identification from a parsed config
(:mod:`dynid.io.identification_config`) or from arrays, then validation on other logs beside the reference sets."""

from __future__ import annotations

import contextlib
from dataclasses import fields, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .._util.checks import check_trajectory_array
from .._util.keywords import keyword_only_after_data, seed_of
from ..estimators.registry import with_hyperparameters
from ..exceptions import ConfigError, DataError, DynIdError, ShapeError
from ..io.dataset_specs import DatasetSpec
from ..io.datasets import Recording, load_recording
from ..io.identification_config import IdentificationConfig, stored_preprocessing
from ..io.log_repairs import (
    GAP_FACTOR,
    check_clock_unit,
    check_position_steps,
    limit_warnings,
    logged_velocities,
    position_ranges,
    repeated_share,
    resampled,
    uniform_rate,
    unwrapped_positions,
)
from ..io.results import stored_estimates, stored_residual_level
from ..model.description import builtin_robots
from ..model.loading import as_robot
from ..model.robot import Robot
from ..preprocessing.settings import Preprocessing
from ..preprocessing.strategies import carried_over, yardstick_settings
from ..runtime.processes import ForkedCall
from ..runtime.threads import with_single_blas_thread
from ..validation.diagnostics import Finding
from ..validation.noise_floor import SMOOTH, looks_filtered
from .estimates import DRIVE_ONLY_LABEL, SDP_LABEL
from .verdict import choose_main_estimate, nominal_set, state_evidence

if TYPE_CHECKING:  # the pipeline imports SciPy: a config is checked before it is imported
    from .pipeline import IdentificationPipeline


def _references(config: IdentificationConfig, base):
    from ..io.references import load_reference

    nominal = config.robot.standard_parameters()
    return tuple(load_reference(r, config.data_root, f"{config.path}: references[{i}]", base, nominal)
                 for i, r in enumerate(config.references))


def _gains_and_payload(config: IdentificationConfig, robot, base):
    """Drive gains from the two runs, then the payload from the loaded run with those gains."""
    from ..preprocessing.pipeline import prepare
    from .drive_gains import GainsAndPayload, identify_drive_gains, identify_payload

    runs = config.drive_gains
    assert runs is not None  # called only when the config has [drive_gains]
    unit = replace(robot, drive_gains=np.ones(robot.n_dof))  # so that the recordings' "torques" are the currents
    files = [str(s.file) for spec in (runs.unloaded, runs.loaded) for s in list(spec.signals.values())[:1]]
    try:
        pre_u = prepare(load_recording(runs.unloaded, unit, spool=False), config.preprocessing)  # in memory: scaled below
        pre_l = prepare(load_recording(runs.loaded, unit, spool=False), config.preprocessing)
        gains = identify_drive_gains(robot, base, pre_u, pre_l, runs.payload_mass, rng=config.estimation.seed)
        k = np.where(np.isfinite(gains.gains), gains.gains, robot.drive_gains)
        payload = identify_payload(robot, base, gains.base, replace(pre_l, tau=pre_l.tau * k))
    except DynIdError as exc:  # said with the runs it comes from, when the message names neither
        text = str(exc)
        if any(f in text for f in files) or not files:
            raise
        raise type(exc)(f"[drive_gains] ({' and '.join(files)}): {text}") from None
    return GainsAndPayload(gains, payload, tuple(robot.drive_gains.tolist()))


def validate_sets(config: IdentificationConfig, base, parameter_sets: dict, recordings, *,
                  progress=None, resolved: Preprocessing | None = None, noise=None, covariance=None,
                  yardstick: Preprocessing | None = None, fitted: tuple[str, np.ndarray] | None = None,
                  geometry: bool = True, nominal: str | None = None) -> tuple[tuple, tuple[str, ...]]:
    """Score parameter sets on logs: their predicted torques against the measured ones.

    Parameters
    ----------
    config : IdentificationConfig
        Its robot (as identified: friction terms, Coulomb smoothing) and preprocessing.
    base : BaseParameters
    parameter_sets : dict
        label -> (n_base,) base parameters.
    recordings : iterable of Recording
        The logs, read (:func:`dynid.io.datasets.load_recording`); a generator's are read one at a time, as each is
        scored.
    progress : callable, optional
        ``progress(step, done, total)``.
    resolved : Preprocessing, optional
        The identification's resolved preprocessing, carried over to these logs.
    noise : (n_dof,) array [N·m], optional
        Each joint's residual σ (for the prediction bands).
    covariance : dict, optional
        label -> covariance of that set.
    yardstick : Preprocessing, optional
        Prepare each log by the one yardstick instead of the identification's settings carried over: the
        identification log's settings resolved by dynid's default rules
        (:func:`dynid.preprocessing.strategies.yardstick_settings`).
    fitted : (str, (n_dof,) array), optional
        The estimate fitted to the identification log and its correlation with each joint's torque there: a log
        whose torque channels run against it, swapped or scaled is said (:mod:`dynid.validation.channel_checks`).
    geometry : bool
        Check each log's geometry against the robot file's: not where the identification log's does not match it
        either (its finding's setting is for every dataset, and the logs agree with each other).
    nominal : str, optional
        The description's nominal model among ``parameter_sets``: a log's scale is judged against it too.

    Returns
    -------
    comparisons : tuple of TorqueComparison
        A log read otherwise than the identification log has its ``misread`` set.
    warnings : tuple of str
        Besides the logs' own, a log read otherwise: its torque channels flipped or swapped against the fitted estimate
        (``fitted``), or its geometry not the robot file's (:mod:`dynid.validation.geometry_checks`: a joint's zero,
        two columns swapped, gravity).

    Raises
    ------
    DataError
        A log that cannot be prepared.
    TypeError
        A log not read (a ``DatasetSpec``: :func:`dynid.io.datasets.load_recording` reads it).
    """
    from ..preprocessing.pipeline import prepare
    from ..validation.channel_checks import channel_findings
    from ..validation.geometry_checks import geometry_findings
    from ..validation.torques import compare_torques

    out: list = []
    warnings: list[str] = []
    settings = (carried_over(resolved, config.preprocessing) if yardstick is None else
                yardstick_settings(resolved, config.preprocessing, yardstick))
    for recording in recordings:
        if not isinstance(recording, Recording):
            raise TypeError(f"validate_sets: expected read logs (dynid.load_recording(spec, robot)), got {type(recording).__name__}")
        if progress is not None:  # one step per log: filtering and predicting it
            progress(f"validation, {recording.name}", 0, 1)
        data = prepare(recording, settings, strict=False)
        scored = compare_torques(config.robot, base, data, parameter_sets,
                                 progress=None if progress is None else (lambda d, t, s=recording.name: progress(f"validation, {s}", d, t)),
                                 noise=noise, covariance=covariance)
        # a log recorded otherwise than the fitted one: its torque channels, else its geometry
        found = [] if yardstick is not None or fitted is None else channel_findings(scored, *fitted, nominal=nominal)
        if not found and geometry and yardstick is None and np.any(config.robot.inertial != 0):
            found, _ = geometry_findings(config.robot, data.q, data.dq, data.ddq, data.tau, recording.name, fitted=False)
        warnings.extend(f.text for f in found)
        out.append(replace(scored, misread=found[0].text) if found else scored)
        warnings.extend(data.warnings)
    return tuple(out), tuple(warnings)


@with_single_blas_thread
@keyword_only_after_data
def run_identification(config: IdentificationConfig, *, progress=None, validate: bool = True):
    """Identify the base parameters from a config's identification dataset, then validate them.

    Validation on each validation dataset beside the reference sets.

    Parameters
    ----------
    config : IdentificationConfig
    progress : callable, optional
        ``progress(step, done, total)`` reports each step.
    validate : bool
        Validate on the config's ``[[validation]]`` datasets.

    Returns
    -------
    IdentificationResult

    Raises
    ------
    DynIdError
        Bad data (:class:`DataError`), settings (:class:`ConfigError`) or a problem the data do not identify
        (:class:`IdentifiabilityError`), each one line.
    """
    from ..dynamics.base_parameters import base_parameters

    def step(label):
        if progress is not None:
            progress(label, 0, 1)

    step("base parameters and references")
    base = base_parameters(config.robot, rng=0)
    refs = _references(config, base)  # read here to report a bad reference file before any computation
    step(f"reading {config.identification.name}")
    recording = load_recording(config.identification, config.robot)
    # every dataset is read (its gaps, rates and ranges checked) before any computation
    checked = []
    for spec in config.validation if validate else ():
        step(f"reading {spec.name}")
        checked.append(load_recording(spec, config.robot))
    config, checked, repeated = _distinct_validation(config, recording, checked)
    pipeline = pipeline_of(config)
    prepared = pipeline.prepare(recording, base, step)
    raw = recording if pipeline.closed_loop else None  # the closed-loop estimators simulate the log as read
    reference = yardstick_reference(recording) if validate and config.validation else None
    smooth = filtered_finding([config.identification.name, *(spec.name for spec in config.validation if validate)],
                              [recording, *checked])
    del recording  # the raw positions and velocities: only the filtered ones are used from here
    if prepared.base is not base:  # the friction models chosen changed the map: the references follow it
        refs = _references(replace(config, robot=prepared.robot), prepared.base)
    robot, base = prepared.robot, prepared.base
    # the drive gains need neither the identification nor its data: the second core computes them meanwhile
    gains = None if config.drive_gains is None else ForkedCall(_gains_and_payload, config, robot, base)
    with gains or contextlib.nullcontext():
        result = pipeline.estimate(prepared, refs, progress, held_out=validate and not config.validation, recording=raw,
                                   jackknife=validate and bool(config.validation) and config.estimation.choice == "states")
        if gains is not None:
            step("drive gains and payload")
            result = replace(result, drive_gains=gains.result())
    result = replace(result, warnings=result.warnings + repeated)
    if not validate or not config.validation:
        return replace(result, findings=tuple(result.findings) + smooth)
    sets = result.parameter_sets()
    nominal = nominal_set(robot, base, result.references)
    if nominal is not None and nominal[0] not in sets:  # scored beside, for the gate against the nominal model
        sets[nominal[0]] = nominal[1]

    alt = result.drive_only if nominal is not None else None
    if alt is not None:  # a candidate scored in the same pass, kept only where the verdict chooses it
        sets[DRIVE_ONLY_LABEL] = alt.params
    scored_all, warnings = validate_sets(replace(config, robot=robot), base, sets, tuple(checked), progress=progress,
                                         resolved=prepared.data.settings, noise=result.joint_std,
                                         covariance={result.label: result.solution.covariance},
                                         fitted=(result.label, result.fit.metrics()[result.label]["correlation"]),
                                         geometry=not any(f.kind in ("angles", "gravity") for f in result.findings),
                                         nominal=None if nominal is None else nominal[0])
    validations = scored_all if alt is None else tuple(v.without(DRIVE_ONLY_LABEL) for v in scored_all)
    result = replace(result, validations=validations, warnings=result.warnings + warnings)
    refits = {f"{SDP_LABEL} refit {k + 1}": beta for k, beta in enumerate(result.sdp_refits)} if nominal else {}
    yardstick = yardstick_scores(replace(config, robot=robot), base, {**sets, **refits}, tuple(checked),
                                 resolved=prepared.data.settings, reference=reference, progress=progress)
    states = None
    if refits:  # [estimation] choice = "states": the verdict reads the validation logs' states, not their torques
        assert nominal is not None
        fallback = DRIVE_ONLY_LABEL if alt is not None and config.torque_sensor != "joint" else nominal[0]
        misread = {v.name for v in scored_all if v.misread}  # the verdict weighs no log read otherwise
        trusted = tuple(v for v in yardstick if v.name not in misread)
        states = state_evidence(trusted, SDP_LABEL, fallback, tuple(refits), nominal[0]) if trusted else None
        for label in refits:
            yardstick = tuple(v.without(label) for v in yardstick)
    result = with_yardstick(choose_main_estimate(result, nominal, scored_all, yardstick, states=states), yardstick)
    return replace(result, findings=tuple(result.findings) + smooth)


def _distinct_validation(config: IdentificationConfig, recording, checked: list) -> tuple:
    """The config and validation logs without those that repeat the identification log's samples
    (:func:`dynid.io.log_repairs.repeated_share`), and a warning for each left out: their figures would be the fit's,
    and the verdict would weigh them as a test of other motions."""
    kept, said = [], []
    for k, (spec, log) in enumerate(zip(config.validation, checked)):
        share = repeated_share(recording, log)
        if share >= 0.5:
            said.append(f"{spec.name}: {100 * share:.0f} % of its sampled positions are samples of the identification "
                        "log: left out of the validation, whose figures would be the fit's; give a log of other motions "
                        "(or other rows of the log: rows, time_range)")
        else:
            kept.append(k)
    if not said:
        return config, checked, ()
    return (replace(config, validation=tuple(config.validation[k] for k in kept)), [checked[k] for k in kept],
            tuple(said))


def filtered_finding(names: list, recordings: list) -> tuple:
    """A finding naming the logs whose torques carry no measurable sample-to-sample noise
    (:func:`dynid.validation.noise_floor.looks_filtered`: filtered before dynid read them, or simulated without
    noise): their noise floor is unknown, and a fit near zero error there says little (issue "Never worse than the
    description", item 5).

    Parameters
    ----------
    names : list of str
    recordings : list of Recording
        As read, raw.

    Returns
    -------
    tuple of Finding
        Empty where every log carries noise.
    """
    smooth = [name for name, rec in zip(names, recordings) if looks_filtered(rec.tau)]
    if not smooth:
        return ()
    return (Finding("filtered", f"{', '.join(smooth)}: the torques carry no measurable sample-to-sample noise (below "
                                f"{SMOOTH:g} % of their RMS on the median joint; raw sensor logs show 2-4 %): they were "
                                "low-pass filtered before dynid read them, or simulated without noise. Their noise floor "
                                "is unknown, the errors measure the fit to an already smoothed torque, and the rest "
                                "thresholds read from the same logs may be too low: log the raw torques (and positions) "
                                "if the controller can, or give [preprocessing] rest_velocity for a joint that creeps"),)


YARDSTICK = ("each validation log prepared by dynid's default rules (filters, samples kept, rest threshold), carried "
             "over from the identification log prepared by the same rules, whatever the identification's settings")
"""What the one yardstick is, as results.json and the terminal say it (:func:`with_yardstick`)."""


def yardstick_reference(recording) -> Preprocessing | None:
    """The identification log's settings resolved by dynid's default rules: what the one yardstick carries over to the
    validation logs (:func:`dynid.preprocessing.strategies.yardstick_settings`).

    Parameters
    ----------
    recording : dynid.io.datasets.Recording
        The identification log, as read.

    Returns
    -------
    Preprocessing or None
        None where the default rules cannot prepare the log (the validation logs then take them alone).
    """
    from ..preprocessing.pipeline import prepare

    try:
        return prepare(recording, Preprocessing(), strict=False).settings
    except DynIdError:
        return None


def yardstick_scores(config: IdentificationConfig, base, sets: dict, recordings, *, resolved=None, reference=None,
                     progress=None) -> tuple:
    """Every set scored on the validation logs by the one yardstick (issue "Never worse than the description", item 5):
    each log prepared by dynid's default rules, whatever the identification's settings
    (:func:`dynid.preprocessing.strategies.yardstick_settings`).

    Parameters
    ----------
    config : IdentificationConfig
        As identified (its robot's friction model).
    base : BaseParameters
    sets : dict
        label -> (n_base,) base parameters.
    recordings : iterable of Recording
        The validation logs, read.
    resolved : Preprocessing, optional
        The identification's resolved settings (only what describes the model is kept from them).
    reference : Preprocessing, optional
        The identification log's settings resolved by the default rules (:func:`yardstick_reference`).
    progress : callable, optional

    Returns
    -------
    tuple of TorqueComparison
    """
    step = None if progress is None else (lambda label, done, total: progress(f"one yardstick: {label}", done, total))
    return validate_sets(config, base, sets, recordings, progress=step, resolved=resolved,
                         yardstick=reference or Preprocessing())[0]


def with_yardstick(result, scored: tuple):
    """``result`` with the sets' errors on the one yardstick in its diagnostics (``"yardstick"``: the global relative
    error [%] of each set on each log and their mean over the logs), beside the figures on the identification's own
    settings.

    Parameters
    ----------
    result : IdentificationResult
    scored : tuple of TorqueComparison
        From :func:`yardstick_scores`.

    Returns
    -------
    IdentificationResult
        Where some logs rest throughout and others move, ``"mean_over_logs_that_move"`` gives the mean over those
        that move (``"logs"`` names them): a log at rest scores the distance to the static-friction band about its
        gravity torque (:func:`dynid.validation.torques.rests_throughout`), another unit than a motion's error, and
        ten of them at 0 would make the mean a tenth of the motion's.
    """
    from ..validation.torques import rests_throughout

    logs = {c.name: {label: float(m["global_relative_error"]) for label, m in c.metrics().items()} for c in scored}
    labels = [label for label in (scored[0].metrics() if scored else {})]

    def mean(names) -> dict:
        return {label: float(np.mean([logs[name][label] for name in names])) for label in labels}

    figures = {"settings": YARDSTICK, "global_relative_error": logs, "mean_global_relative_error": mean(logs)}
    moving = [c.name for c in scored if not rests_throughout(c.rest_share)]
    if moving and len(moving) < len(scored):  # a log at rest throughout scores the distance to the static-friction band
        figures["mean_over_logs_that_move"] = {"logs": moving, **mean(moving)}
    return replace(result, diagnostics={**result.diagnostics, "yardstick": figures})


def pipeline_of(config: IdentificationConfig) -> IdentificationPipeline:
    """The identification pipeline a config describes: its robot, preprocessing, estimators (the closed-loop ones with
    the ``[controller]``), friction choice, seed.

    Parameters
    ----------
    config : IdentificationConfig

    Returns
    -------
    IdentificationPipeline
    """
    from .pipeline import IdentificationPipeline

    e = config.estimation
    return IdentificationPipeline(config.robot, config.preprocessing, with_hyperparameters(e.estimators, e.hyperparameters),
                                  e.friction, e.seed, config.robot_source, config.controller if e.closed_loop else None)


@keyword_only_after_data
def run_validation(config: IdentificationConfig, identified: dict, *, datasets: tuple[DatasetSpec | Recording, ...] | None = None,
                   progress=None, source: str = "results", yardstick: bool = False) -> tuple[tuple, tuple[str, ...]]:
    """Validate identified base parameters and the config's reference sets on the config's validation datasets (or on
    ``datasets``).

    Parameters
    ----------
    config : IdentificationConfig
    identified : dict
        The results.json of ``dynid identify`` (every estimate in it is scored).
    datasets : tuple of DatasetSpec or Recording, optional
        Logs to validate on instead of the config's ``[[validation]]`` ones (each read as it is scored), or logs read
        already (:func:`dynid.io.datasets.load_recording`).
    progress : callable, optional
        ``progress(step, done, total)``.
    source : str
        Where the results come from (their file), named in errors.
    yardstick : bool
        Prepare every log by the one yardstick (dynid's default rules, carried over from the config's identification
        log prepared by them: :func:`dynid.preprocessing.strategies.yardstick_settings`) instead of the results'
        settings, so that results identified with other settings, or another tool's model, are scored on the same
        samples treated the same way.

    Returns
    -------
    comparisons : tuple of TorqueComparison
    warnings : tuple of str

    Raises
    ------
    DataError
        Results that do not belong to this robot (different base parameters), or malformed.
    ConfigError
        No log to validate on.
    """
    config, base, estimates = _identified_model(config, identified, source)
    refs = _references(config, base)
    sets = {**estimates, **{r.name: r.beta for r in refs}}
    datasets = config.validation if datasets is None else datasets
    if not datasets:
        raise ConfigError(f"{config.path}: no [[validation]] datasets to validate on (give one, or another log)")
    reference = yardstick_reference(load_recording(config.identification, config.robot)) or Preprocessing() if yardstick else None
    label, beta = nominal_set(config.robot, base, refs) or (None, None)
    beside = label is not None and label not in sets  # scored for the channel checks' scale, not shown
    logs = _read_as_scored(datasets, config.robot, progress)
    comparisons, warnings = validate_sets(config, base, {**sets, label: beta} if beside else sets, logs,
                                          progress=progress, resolved=stored_preprocessing(identified),
                                          noise=stored_residual_level(identified, config.robot.n_dof),
                                          yardstick=reference, fitted=_fitted_correlation(identified, sets, config.robot.n_dof),
                                          nominal=label)
    if beside:
        comparisons = tuple(v.without(str(label)) for v in comparisons)
    return comparisons, tuple(w for r in refs for w in r.warnings) + warnings


def _read_as_scored(datasets, robot, progress):
    """Each log read as :func:`validate_sets` reaches it (one in memory at a time), its step said before the read; a
    log read already passes as it is."""
    for spec in datasets:
        if progress is not None:
            progress(f"validation, {spec.name}", 0, 1)
        yield spec if isinstance(spec, Recording) else load_recording(spec, robot)


def _fitted_correlation(identified: dict, sets: dict, n_dof: int) -> tuple[str, np.ndarray] | None:
    """The main estimate of a results.json and its correlation with each joint's torque on the identification log
    (where the results hold them), for :func:`validate_sets`' check of a log's torque channels."""
    main = identified.get("main_estimate")
    metrics: Any = ((identified.get("identification") or {}).get("metrics") or {}).get(main)
    try:
        corr = np.asarray(metrics["correlation"], dtype=np.float64)
    except (KeyError, TypeError, ValueError):
        return None
    return (str(main), corr) if main in sets and corr.shape == (n_dof,) else None


def _identified_model(config: IdentificationConfig, identified: dict, source: str):
    """``(config, base, estimates)``: the config with its robot as the results identified it (their friction model),
    the base-parameter map, and every estimate of results.json (label -> base parameters)."""
    from ..dynamics.base_parameters import base_parameters
    from ..model.friction_model import robot_from_settings

    try:
        config = replace(config, robot=robot_from_settings(config.robot, identified.get("settings", {})))
    except (TypeError, ValueError, KeyError, AttributeError, ConfigError) as exc:
        raise DataError(f"{source}: settings: {exc}") from None
    base = base_parameters(config.robot, rng=0)
    return config, base, stored_estimates(identified, base.names, source, config.robot.name)


@with_single_blas_thread
def run_payload(config: IdentificationConfig, identified: dict, dataset: DatasetSpec, *, source: str = "results"):
    """A tool's payload from a log with it, the arm's model taken from an identification's results (issue "The model
    proven where it goes", item 4; :func:`dynid.identification.payload.payload_from_log`).

    The log is prepared as the validation logs are (the identification's settings carried over); its torques less
    the main estimate's are the payload's.

    Parameters
    ----------
    config : IdentificationConfig
    identified : dict
        The results.json of ``dynid identify``: its main estimate is the arm without the payload (the description's
        nominal model where that is the main one).
    dataset : DatasetSpec
        The log with the payload (:func:`dynid.io.identification_config.dataset_for_file`).
    source : str
        Where the results come from, named in errors.

    Returns
    -------
    (Payload, str, ndarray or None)
        The payload, the label of the estimate taken for the arm, and the identified drive gains' ratio to those the
        torques were read with, where the results identified them (:func:`identified_gain_ratio`), which the
        payload's torques are scaled by.

    Raises
    ------
    DataError
        Results of another robot, or a log that cannot be read.
    IdentifiabilityError
        A log whose motion determines none of the payload's parameters.
    """
    from ..preprocessing.pipeline import prepare
    from .payload import payload_from_log

    config, base, estimates = _identified_model(config, identified, source)
    label = identified.get("main_estimate")
    if label not in estimates:  # older results, or the description's values: the first estimate
        label = next(iter(estimates))
    recording = load_recording(dataset, config.robot)
    data = prepare(recording, carried_over(stored_preprocessing(identified), config.preprocessing), strict=False)
    ratio = identified_gain_ratio(identified, config.robot.n_dof)
    found = payload_from_log(config.robot, base, estimates[label], data, rng=config.estimation.seed, gain_ratio=ratio)
    return found, label, ratio


def forward_check(config: IdentificationConfig, identified: dict, mjcf_text: str, *, source: str = "results"):
    """An exported MJCF simulated along the config's first moving validation log (issue "The model proven where it
    goes", item 3; :func:`dynid.io.replay.mjcf_forward`): the log prepared as ``dynid validate`` prepares it, without
    decimation, so the simulation follows every sample.

    Parameters
    ----------
    config : IdentificationConfig
    identified : dict
        results.json of ``dynid identify``: the physically consistent estimate the MJCF holds.
    mjcf_text : str
        The MJCF as written.
    source : str
        Where the results come from, named in errors.

    Returns
    -------
    (str, ForwardCheck) or None
        The log's name and the check; None without a validation log that moves.

    Raises
    ------
    DataError
        A log that cannot be read, or results of another robot.
    ValueError
        MuJoCo cannot load the text.
    """
    from ..io.export import consistent_estimate
    from ..io.replay import mjcf_forward

    robot, phi = consistent_estimate(config.robot, identified, source)
    found = moving_validation(config, identified, robot)
    if found is None:
        return None
    name, (t, q, dq, ddq, tau) = found
    return name, mjcf_forward(mjcf_text, robot, phi, t, q, dq, ddq, tau)


def moving_validation(config: IdentificationConfig, identified: dict, robot=None):
    """The config's first validation log that moves, prepared as ``dynid validate`` prepares it but without
    decimation (every sample: a simulation or a replay follows them all).

    Parameters
    ----------
    config : IdentificationConfig
    identified : dict
        results.json: the preparation it was identified with, carried over.
    robot : Robot, optional
        The model the log is read for (default the config's).

    Returns
    -------
    (str, (t, q, dq, ddq, tau)) or None
        The log's name and its arrays [s, rad, rad/s, rad/s², N·m]; None without a validation log that moves.

    Raises
    ------
    DataError
        A log that cannot be read.
    """
    from ..preprocessing.pipeline import prepare

    robot = config.robot if robot is None else robot
    settings = replace(carried_over(stored_preprocessing(identified), config.preprocessing), decimation=1,
                       parallel_cutoff=0.0)  # every sample, as the simulation runs them
    for spec in config.validation:
        data = prepare(load_recording(spec, robot), settings, strict=False)
        if data.resting is not None and float(np.mean(data.resting)) >= 0.5:  # a log at rest shows no motion to follow
            continue
        return spec.name, tuple(np.asarray(x, dtype=float) for x in (data.t, data.q, data.dq, data.ddq, data.tau))
    return None


def identified_gain_ratio(identified: dict, n_dof: int) -> np.ndarray | None:
    """Each joint's drive gain identified by the results' ``[drive_gains]`` run over the gain its torques were read
    with (1 where a gain was not determined); None without identified gains.

    Parameters
    ----------
    identified : dict
        results.json.
    n_dof : int

    Returns
    -------
    (n_dof,) ndarray or None
    """
    found = identified.get("drive_gains")
    if not isinstance(found, dict):
        return None
    try:
        gains = np.array([np.nan if g is None else float(g) for g in found.get("gains", [])], dtype=float)
        read = np.asarray(found.get("description_gains", []), dtype=float)
    except (TypeError, ValueError):
        return None
    if gains.shape != (n_dof,) or read.shape != (n_dof,):
        return None
    return np.where(np.isfinite(gains) & (read > 0), gains / np.where(read > 0, read, 1.0), 1.0)


@with_single_blas_thread
def identify_from_arrays(robot: Robot | str | Path, t, q=None, tau=None, dq=None, *, name: str = "arrays", **settings):
    """Identify a robot from arrays, without a config file or a CSV: the pipeline of ``dynid identify``
    (:class:`~dynid.identification.pipeline.IdentificationPipeline`: data-derived preprocessing and the choices
    cross-validated on the data, the estimators, the verdict), on arrays resampled as the log readers resample.

    Parameters
    ----------
    robot : Robot, str or Path
        E.g. :func:`dynid.load_robot`; a built-in robot's name or a description's path is loaded
        (:func:`dynid.model.loading.as_robot`).
    t : (N,) array [s], or a recording
        Increasing time stamps; jittered ones are interpolated onto a uniform grid at one over their median step,
        as the log readers do (with a warning). Or a log as :func:`dynid.load_recording` or
        :func:`dynid.simulated_log` give it, identified as it is (its name and warnings kept; no arrays beside it).
    q : (N, n_dof) array [rad]
        Joint positions (with time stamps).
    tau : (N, n_dof) array [N·m]
        Joint torques (e.g. drive gain × motor current, eq. 16; with time stamps).
    dq : (N, n_dof) array [rad/s], optional
        Measured velocities (default: differentiated from the filtered positions).
    name : str
        The dataset's name in tables and messages (arrays only).
    **settings
        The pipeline's settings, as :class:`~dynid.identification.pipeline.IdentificationPipeline` takes them:
        ``preprocessing`` (default: every setting derived from the data), ``estimators`` (keys or objects, as a
        config's ``[estimation] estimators``; the closed-loop ones with ``controller``), ``friction``
        ({"description", "auto"}, default "description"), ``rng`` (default 0; an int or a generator), ``controller``
        (:class:`dynid.simulation.closed_loop.ClosedLoopSetup`, as a config's ``[controller]`` gives it).

    Returns
    -------
    dynid.identification.identify.IdentificationResult

    Raises
    ------
    ShapeError
        Arrays of inconsistent shapes, not time-first, or not finite.
    DataError
        Time stamps that do not increase, a gap longer than 5 median steps, or set-points that are not one per sample.
    ConfigError
        An unknown estimator, setting or ``friction``, closed-loop estimators without ``controller``, time stamps
        without positions and torques, or arrays beside a recording.
    """
    robot = as_robot(robot)
    recording = _given_log(robot, t, q, tau, dq, name)
    from .pipeline import IdentificationPipeline

    known = {f.name for f in fields(IdentificationPipeline) if f.init} - {"robot", "source"}
    unknown = sorted(set(settings) - known)
    if unknown:
        raise ConfigError(f"identify_from_arrays: unknown setting {unknown[0]!r}; expected one of {', '.join(sorted(known))}",
                          field=unknown[0])
    given = {"rng": seed_of(settings.get("rng")), "preprocessing": settings.get("preprocessing") or Preprocessing()}
    pipeline = IdentificationPipeline(robot, **{**settings, **given},
                                      source=robot.name if robot.name in builtin_robots() else "")
    return pipeline.fit(recording)


def _given_log(robot: Robot, t, q, tau, dq, name: str) -> Recording:
    """A recording given as one (nothing beside it), or made of arrays (:func:`recording_from_arrays`)."""
    if isinstance(t, Recording):
        if not (q is None and tau is None and dq is None):
            raise ConfigError(f"{t.name}: a recording holds its positions, velocities and torques: give it alone, "
                              "or give the arrays t, q, tau")
        return t
    if q is None or tau is None:
        raise ConfigError("positions q and torques tau are needed with the time stamps t (or give a recording, as "
                          "dynid.load_recording reads one)")
    recording = recording_from_arrays(robot, t, q, tau, dq, name)
    if not np.any(np.ptp(recording.q, axis=0) > 0):  # to identify from (a pose's torques are predicted alright)
        raise DataError(f"{name}: no joint's position ever changes: a robot at rest throughout, or the wrong array?")
    return recording


def recording_from_arrays(robot: Robot, t, q, tau, dq=None, name: str = "arrays"):
    """A recording of arrays, checked and on a uniform grid as the log readers give one.

    Parameters
    ----------
    robot : Robot
        Its number of joints is the arrays' width.
    t : (N,) array [s]
        Increasing time stamps; jittered ones are interpolated onto a uniform grid at one over their median step.
    q : (N, n_dof) array [rad]
        The description's angles (a log's plus the description's ``position_offset``: nothing is added here).
    tau : (N, n_dof) array [N·m]
    dq : (N, n_dof) array [rad/s], optional
    name : str
        The dataset's name in messages.

    Returns
    -------
    dynid.io.datasets.Recording
        Starting at t = 0; a warning when the time stamps were interpolated.

    Raises
    ------
    ShapeError
        Arrays of inconsistent shapes, not time-first, or not finite.
    DataError
        Time stamps that do not increase or are slower than any controller logs (another unit:
        :func:`dynid.io.log_repairs.check_clock_unit`), a gap longer than 5 median steps, a position step no motion
        makes (:func:`dynid.io.log_repairs.check_position_steps`), or positions beyond 4π rad (degrees:
        :func:`dynid.io.log_repairs.position_ranges`, which also says the positions outside the joint limits).
    """

    t = np.asarray(t, dtype=float).reshape(-1)
    q = check_trajectory_array(q, robot.n_dof, "q")
    tau = check_trajectory_array(tau, robot.n_dof, "tau")
    dq = None if dq is None else check_trajectory_array(dq, robot.n_dof, "dq")
    if not (q.shape[0] == tau.shape[0] == t.shape[0] and (dq is None or dq.shape[0] == t.shape[0])):
        raise ShapeError(f"expected t, q, tau (and dq) with the same number of samples, got {t.shape[0]}, {q.shape[0]}, {tau.shape[0]}")
    steps = np.diff(t)
    if t.size < 2 or not np.all(np.isfinite(t)) or np.any(steps <= 0):
        raise DataError("t: expected finite, increasing time stamps")
    median = float(np.median(steps))
    check_clock_unit(median, "t", None)
    if np.any(steps > GAP_FACTOR * median):
        k = int(np.argmax(steps))
        raise DataError(f"t: a gap of {steps[k]:.3g} s after {t[k] - t[0]:.3f} s (median step {median:.3g} s): give the parts "
                        "on each side of it separately")
    said: list[str] = []
    q = unwrapped_positions(q, name, said)
    check_position_steps(q, t - t[0], robot, name)
    said += limit_warnings(robot, t - t[0], position_ranges(robot, t, q, name, degrees="numpy.radians(q)"), name,
                           degrees="numpy.radians(q)")
    dq = logged_velocities(q, dq, name, said)
    warnings: tuple[str, ...] = tuple(said)
    rate = uniform_rate(t)
    if np.ptp(steps) > 1e-6 * median:
        signals = {"q": q, "tau": tau, **({} if dq is None else {"dq": dq})}
        t, signals = resampled(t, signals, rate)
        q, tau, dq = signals["q"], signals["tau"], signals.get("dq")
        warnings += (f"{name}: time stamps jitter by up to {np.ptp(steps) / median:.2g} median steps: interpolated "
                     f"onto a uniform grid at {rate:.6g} Hz",)
    else:
        rate = 1.0 / median
    return Recording(name, t - t[0], q, dq, tau, rate, warnings)

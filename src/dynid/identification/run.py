"""The runs ``dynid identify`` and ``dynid validate`` describe: identification from a parsed config
(:mod:`dynid.io.config.identification_config`) or from arrays, then validation on other logs beside the reference sets."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import fields, replace
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .._util.keywords import keyword_only_after_data, seed_of
from ..exceptions import ConfigError, DataError, DynIdError
from ..io.config.identification_config import IdentificationConfig, stored_preprocessing
from ..io.logs.dataset_specs import DatasetSpec
from ..io.logs.datasets import Recording, given_recording, load_recording
from ..io.logs.log_repairs import (
    repeated_share,
)
from ..io.results import stored_estimates, stored_residual_level
from ..model.description import builtin_robots
from ..model.loading import as_robot
from ..model.robot import Robot
from ..preprocessing.settings import Preprocessing
from ..preprocessing.strategies import carried_over
from ..runtime.threads import with_single_blas_thread
from .evidence import nominal_set, validate_sets, yardstick_reference, yardstick_scores

if TYPE_CHECKING:  # the pipeline imports SciPy: a config is checked before it is imported
    from .pipeline import IdentificationPipeline


def _references(config: IdentificationConfig, base):
    from ..io.config.references import load_reference

    nominal = config.robot.standard_parameters()
    return tuple(load_reference(r, config.data_root, f"{config.path}: references[{i}]", base, nominal)
                 for i, r in enumerate(config.references))


def _gains_and_payload(config: IdentificationConfig, robot, base):
    """Drive gains from the two runs, then the payload from the loaded run with those gains."""
    from ..preprocessing.preparation import prepare
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
    def reading(spec):  # a step of its own, its share read said as it goes
        label = f"reading {spec.name}"
        if progress is None:
            return load_recording(spec, config.robot)
        progress(label, 0, 1)
        return load_recording(spec, config.robot, progress=lambda done, total: progress(label, done, total))

    if config.references:  # a bad reference file is said before any computation
        from ..dynamics.base_parameters import base_parameters

        _references(config, base_parameters(config.robot, rng=0))
    recording = reading(config.identification)
    # every dataset is read (its gaps, rates and ranges checked) before any computation
    checked = [reading(spec) for spec in (config.validation if validate else ())]
    config, checked, repeated = _distinct_validation(config, recording, checked)
    gains = None if config.drive_gains is None else partial(_gains_and_payload, config)
    result = pipeline_of(config).fit(recording, validation=tuple(checked), progress=progress, drive_gains=gains,
                                     references=lambda robot, base: _references(replace(config, robot=robot), base),
                                     held_out=validate and not config.validation)
    return replace(result, warnings=result.warnings + repeated)


def _distinct_validation(config: IdentificationConfig, recording, checked: list) -> tuple:
    """The config and validation logs without those that repeat the identification log's samples
    (:func:`dynid.io.logs.log_repairs.repeated_share`), and a warning for each left out: their figures would be the fit's,
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
    return IdentificationPipeline(config.robot, config.preprocessing, e.estimators, e.friction, e.seed, config.robot_source,
                                  config.controller if e.closed_loop else None, e.choice, config.torque_sensor)


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
        already (:func:`dynid.io.logs.datasets.load_recording`).
    progress : callable, optional
        ``progress(step, done, total)``.
    source : str
        Where the results come from (their file), named in errors.
    yardstick : bool
        Score every log by the one yardstick (its torques as measured, its states filtered by dynid's default rules
        carried over from the config's identification log: :func:`dynid.identification.evidence.yardstick_scores`,
        the first state filter) instead of the results' settings, so that results identified with other settings, or
        another tool's model, are scored on the same samples treated the same way.

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
    repeated: dict[str, str] = {}
    fitted = _identification_log(config)
    logs = _fit_repeats_said(fitted, _read_as_scored(datasets, config.robot, progress), repeated)

    def marked(comparisons):  # a log that repeats the fit's samples, marked so (the next step then says so)
        return tuple(replace(c, repeats_fit=True) if c.name in repeated else c for c in comparisons)

    if yardstick:
        return (marked(_on_the_yardstick(config, base, sets, logs, fitted, identified)),
                tuple(w for r in refs for w in r.warnings) + tuple(repeated.values()))
    label, beta = nominal_set(config.robot, base, refs) or (None, None)
    beside = label is not None and label not in sets  # scored for the channel checks' scale, not shown
    comparisons, warnings = validate_sets(config, base, {**sets, label: beta} if beside else sets, logs,
                                          progress=progress, resolved=stored_preprocessing(identified),
                                          noise=stored_residual_level(identified, config.robot.n_dof),
                                          fitted=_fitted_correlation(identified, sets, config.robot.n_dof),
                                          nominal=label)
    if beside:
        comparisons = tuple(v.without(str(label)) for v in comparisons)
    return marked(comparisons), tuple(w for r in refs for w in r.warnings) + warnings + tuple(repeated.values())


def _on_the_yardstick(config: IdentificationConfig, base, sets: dict, logs, fitted: Recording | None,
                      identified: dict) -> tuple:
    """:func:`run_validation`'s comparisons on the one yardstick: every log's torques as measured, its states filtered
    by the default rules carried over from the identification log (``fitted``, read again where it was not given;
    :func:`dynid.identification.evidence.yardstick_scores`, its first state filter)."""
    reference = yardstick_reference(fitted if fitted is not None else load_recording(config.identification, config.robot))
    return yardstick_scores(config, base, sets, logs, resolved=stored_preprocessing(identified), reference=reference)[0]


def _identification_log(config: IdentificationConfig) -> Recording | None:
    """The config's identification log as read, or None where it cannot be read now (moved, renamed)."""
    try:
        return load_recording(config.identification, config.robot)
    except DynIdError:
        return None


def _fit_repeats_said(fitted: Recording | None, logs, said: dict[str, str]):
    """The logs as they come, and into ``said`` (log name -> warning) a warning for each that repeats the samples of
    ``fitted``, the identification log (:func:`dynid.io.logs.log_repairs.repeated_share`): scored as asked, but its
    figures are the fit's, not a test on other motions. Without it (None) the logs go unchecked."""
    for log in logs:
        share = 0.0 if fitted is None else repeated_share(fitted, log)
        if share >= 0.5:
            said[log.name] = (f"{log.name}: {100 * share:.0f} % of its sampled positions are samples of the "
                              "identification log the model was fitted on: its figures are the fit's, not a validation "
                              "on other motions")
        yield log


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
def run_payload(config: IdentificationConfig, identified: dict, dataset: DatasetSpec, *, source: str = "results",
                link: int | None = None):
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
        The log with the payload (:func:`dynid.io.config.identification_config.dataset_for_file`).
    source : str
        Where the results come from, named in errors.
    link : int, optional
        The link carrying the tool, 0-based (default the last; on a robot with branches, another arm's hand).

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
    from ..preprocessing.preparation import prepare
    from .payload import payload_from_log

    config, base, estimates = _identified_model(config, identified, source)
    label = identified.get("main_estimate")
    if label not in estimates:  # older results, or the description's values: the first estimate
        label = next(iter(estimates))
    recording = load_recording(dataset, config.robot)
    data = prepare(recording, carried_over(stored_preprocessing(identified), config.preprocessing), strict=False)
    ratio = identified_gain_ratio(identified, config.robot.n_dof)
    found = payload_from_log(config.robot, base, estimates[label], data, rng=config.estimation.seed, gain_ratio=ratio,
                             residual=stored_residual_level(identified, config.robot.n_dof), link=link)
    return found, label, ratio


def forward_check(config: IdentificationConfig, identified: dict, mjcf_text: str, *, source: str = "results",
                  progress: Callable[[int, int], None] | None = None):
    """An exported MJCF simulated along the config's first moving validation log (issue "The model proven where it
    goes", item 3; :func:`dynid.io.exported.replay.mjcf_forward`): the log prepared as ``dynid validate`` prepares it, without
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
    progress : callable, optional
        ``progress(done, total)`` in samples simulated.

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
    from ..io.exported.export import consistent_estimate
    from ..io.exported.replay import mjcf_forward

    robot, phi = consistent_estimate(config.robot, identified, source)
    found = moving_validation(config, identified, robot)
    if found is None:
        return None
    name, (t, q, dq, ddq, tau) = found
    return name, mjcf_forward(mjcf_text, robot, phi, t, q, dq, ddq, tau, progress=progress)


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
    from ..preprocessing.preparation import prepare

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
        Joint positions (with time stamps); on a robot whose joints follow others (``<mimic>``), the driven joints'
        columns alone may be given, as a log holds them (:attr:`dynid.model.robot.Robot.independent`).
    tau : (N, n_dof) array [N·m]
        Joint torques (e.g. drive gain × motor current, eq. 16; with time stamps), the same columns as ``q``.
    dq : (N, n_dof) array [rad/s], optional
        Measured velocities (default: differentiated from the filtered positions).
    name : str
        The dataset's name in tables and messages (arrays only).
    **settings
        The pipeline's settings, as :class:`~dynid.identification.pipeline.IdentificationPipeline` takes them:
        ``preprocessing`` (default: every setting derived from the data), ``estimators`` (keys or objects, as a
        config's ``[estimation] estimators``; the closed-loop ones with ``controller``), ``friction``
        ({"description", "auto"}, default as a config's: "auto" unless a Coulomb smoothing velocity is given), ``rng`` (default 0; an int or a generator), ``controller``
        (:class:`dynid.simulation.closed_loop.ClosedLoopSetup`, as a config's ``[controller]`` gives it).

    Returns
    -------
    dynid.identification.result.IdentificationResult

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
    recording = given_recording(robot, t, q, tau, dq, name)
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

"""Experiment configs of ``dynid identify`` / ``dynid validate`` (TOML), and the runs they describe.

Layout (paths relative to the config file; data paths relative to ``data_root``)::

    robot = "ur10e"                      # built-in robot name or description TOML
    data_root = "../../shared/data/ur10e_mamedov2020"   # overridden by --data-root / DYNID_DATA_ROOT

    [identification]                     # a dataset table (dynid.io.datasets)
    preset = "ur-rtde"
    file = "identification_data/ur-20_02_10-30sec_12harm.csv"
    rows = [635, 3510]

    [preprocessing]                      # dynid.preprocessing.Preprocessing; all optional: by default every
                                         # cutoff derives from the excitation band found in the data
    order = 4
    band = 0.5                           # Hz, the excitation band (default: from the positions' spectrum)
    position_cutoff = 5.0                # Hz, positions and measured velocities (default 10× band)
    parallel_cutoff = 2.5                # Hz, torques AND every regressor column (default 5× band)
    decimation = 16                      # default: down to the parallel band
    min_speed = 0.0                      # rad/s, one value or one per joint; "auto" (default): 5 % of
                                         # each joint's RMS speed
    coulomb_velocity = 0.0               # rad/s, Coulomb term tanh(dq/v) per joint; 0 (default): sign(dq);
                                         # "auto": chosen per joint by blocked cross-validation
    excitation = "excitation.json"       # the robot ran this trajectory of dynid excite: derivatives
                                         # by a Fourier fit on its harmonics instead of filters

    [estimation]
    method = "wls"                       # "ols" or "wls": the estimate with σ
    physically_consistent = true         # also physically consistent least squares (SDP), default false
    methods = ["wls", "sdp", "lad", "abc", "de", "pso", "irls"]   # optional: every estimator side by side
    seed = 0                             # seeds the box searches (ABC, ABC×10, DE, PSO)

    [drive_gains]                        # optional: drive gains K (eq. 16) from a run without and one with a
    payload_mass = 2.805                 # payload of known mass [kg] on the last link (Gautier & Briot), and
    [drive_gains.unloaded]               # the payload's inertial parameters; both dataset tables hold currents
    preset = "ur-rtde"
    file = "identification_data/ur-20_02_19_14harm50sec.csv"
    rows = [195, 4966]
    [drive_gains.loaded]
    preset = "ur-rtde"
    file = "identification_data/ur-20_02_19_14harm50secLoad.csv"
    rows = [308, 5071]

    [[validation]]                       # dataset tables, each with a name
    name = "ptp_10_points"
    preset = "ur-rtde"
    file = "validation_data/ur-20_01_17-ptp_10_points.csv"
    rows = [700, 4200]

    [[references]]                       # published parameter sets (dynid.io.references)
    name = "Mamedov & Mikhel 2020"
    file = "ur10e_reference_parameters.csv"
    header = true
    names = "name"
    values = "value"
"""

from __future__ import annotations

import os
from dataclasses import dataclass, fields, replace
from pathlib import Path

import numpy as np

from ..exceptions import ConfigError, DataError
from ..io.configs import config_robot, read_config
from ..io.datasets import DatasetSpec, SignalSpec, dataset_spec, load_recording
from ..io.trajectories import load_trajectory
from ..model.robot import Robot
from ..preprocessing.settings import Preprocessing
from .method_names import parse_methods
from ..threads import with_single_blas_thread

# Parsing a config imports nothing heavy (no SciPy, compiled kernels or solvers), so that a mistake in it
# is reported at once; the identification itself imports them when it runs.

METHODS = ("ols", "wls")
"""The least-squares estimate that carries σ (``[estimation] method``)."""

DATA_ROOT_ENV = "DYNID_DATA_ROOT"


@dataclass(frozen=True)
class IdentificationConfig:
    """A parsed identification config (module docstring)."""

    path: Path
    robot: Robot
    identification: DatasetSpec
    validation: tuple[DatasetSpec, ...]
    preprocessing: Preprocessing
    method: str
    references: tuple[dict, ...]
    data_root: Path
    physically_consistent: bool = False
    methods: tuple[str, ...] = ()
    seed: int = 0
    drive_gains: tuple | None = None  # (payload_mass, unloaded DatasetSpec, loaded DatasetSpec)


_PRE_KEYS = {"order": int, "position_cutoff": float, "velocity_cutoff": float, "parallel_cutoff": float, "band": float,
             "decimation": int, "min_speed": None, "trim": float, "chunk": int, "excitation": None,
             "coulomb_velocity": None, "auto": None}


def _preprocessing(table, where: str, n: int, here: Path = Path(".")) -> Preprocessing:
    if not isinstance(table, dict):
        raise ConfigError(f"{where}: expected a table")
    if "torque_cutoff" in table:
        raise ConfigError(f"{where}.torque_cutoff: no longer exists, because a filter on the torques alone biases the "
                          "estimate near velocity reversals; use parallel_cutoff (torques and every regressor column), "
                          "or leave it out for the data-derived default")
    unknown = sorted(set(table) - set(_PRE_KEYS))
    if unknown:
        raise ConfigError(f"{where}: unknown field(s) {unknown}, expected some of {sorted(_PRE_KEYS)}")
    values = {}
    for key, kind in _PRE_KEYS.items():
        if key not in table:
            continue
        v = table[key]
        if key == "excitation":
            if not isinstance(v, str):
                raise ConfigError(f"{where}.excitation: expected the excitation.json of dynid excite, got {v!r}")
            try:
                traj = load_trajectory(here / v)
            except ConfigError as exc:
                raise ConfigError(f"{where}.excitation: {exc}") from None
            if traj.n_dof != n:
                raise ConfigError(f"{where}.excitation: the trajectory has {traj.n_dof} joints, the robot {n}")
            values["fourier"] = (traj.omega_f, traj.n_harmonics)
            continue
        if key == "auto":
            if not isinstance(v, bool):
                raise ConfigError(f"{where}.auto: expected true or false, got {v!r}")
            values[key] = v
            continue
        if key in ("min_speed", "coulomb_velocity"):
            if v == "auto":
                values[key] = v
                continue
            ok = (isinstance(v, (int, float)) and not isinstance(v, bool) and v >= 0) or (
                isinstance(v, list) and len(v) == n and all(isinstance(x, (int, float)) and not isinstance(x, bool) and x >= 0 for x in v))
            if not ok:
                auto = '"auto", '
                raise ConfigError(f"{where}.{key}: expected {auto}a non-negative number or a list of {n} (rad/s), got {v!r}")
            values[key] = tuple(float(x) for x in v) if isinstance(v, list) else float(v)
            continue
        if isinstance(v, bool) or not isinstance(v, (int, float)) or (kind is int and v != int(v)) or v < 0:
            raise ConfigError(f"{where}.{key}: expected a non-negative {'integer' if kind is int else 'number'}, got {v!r}")
        if key in ("order", "decimation", "chunk") and v < 1:
            raise ConfigError(f"{where}.{key}: expected an integer >= 1, got {v!r}")
        if key == "band" and v <= 0:
            raise ConfigError(f"{where}.band: expected a positive frequency in Hz, got {v!r}")
        values[key] = kind(v)
    return Preprocessing(**values)


def load_identification_config(path: str | Path, data_root: str | Path | None = None) -> IdentificationConfig:
    """Parse an identification config.

    Parameters
    ----------
    path : path of the TOML file
    data_root : path, optional
        Folder the data paths are relative to; default: the environment variable ``DYNID_DATA_ROOT``,
        else the config's ``data_root`` (relative to the config file), else the config's folder.

    Raises
    ------
    ConfigError
        Unreadable file, invalid TOML, unknown or malformed fields (the message names file and field).
    """
    path = Path(path)
    doc = read_config(path, {"robot", "data_root", "identification", "validation", "preprocessing", "estimation",
                             "references", "name", "notes", "drive_gains"})
    here = path.parent
    robot = config_robot(doc, path)
    override = data_root or os.environ.get(DATA_ROOT_ENV)
    if override is None and not isinstance(doc.get("data_root", "."), str):
        raise ConfigError(f"{path}: data_root: expected a folder path, got {doc['data_root']!r}")
    root = Path(override) if override else here / doc.get("data_root", ".")  # an absolute path stays as is
    if not root.is_dir():
        raise ConfigError(f"{path}: data_root {root} is not a folder (set data_root, --data-root or {DATA_ROOT_ENV})")
    n = robot.n_dof
    if "identification" not in doc:
        raise ConfigError(f"{path}: expected an [identification] table describing the identification dataset")
    ident = dataset_spec(doc["identification"], root, f"{path}: identification", "identification", n)
    vals = doc.get("validation", [])
    if not isinstance(vals, list):
        raise ConfigError(f"{path}: validation: expected [[validation]] tables")
    validation = tuple(dataset_spec(v, root, f"{path}: validation[{i}]", f"validation {i + 1}", n) for i, v in enumerate(vals))
    names = [v.name for v in validation]
    if len(set(names)) != len(names):
        raise ConfigError(f"{path}: validation: dataset names must be unique, got {names}")
    table = doc.get("preprocessing", {})
    if table == "auto":
        table = {"auto": True, "coulomb_velocity": "auto"}
    pre = _preprocessing(table, f"{path}: preprocessing", n, here)
    est = doc.get("estimation", {})
    if not isinstance(est, dict):
        raise ConfigError(f"{path}: estimation: expected a table")
    unknown = sorted(set(est) - {"method", "physically_consistent", "methods", "seed"})
    if unknown:
        raise ConfigError(f"{path}: estimation: unknown field(s) {', '.join(unknown)}; expected method, methods, "
                          "physically_consistent, seed")
    methods = est.get("methods", [])
    if not isinstance(methods, list) or not all(isinstance(m, str) for m in methods):
        raise ConfigError(f"{path}: estimation.methods: expected a list of method names, got {methods!r}")
    try:
        methods = parse_methods(methods) if methods else ()
    except ConfigError as exc:
        raise ConfigError(f"{path}: estimation.methods: {str(exc).split(': ', 1)[1]}") from None
    primary = next((m for m in methods if m in METHODS), "wls")
    method = est.get("method", primary)
    if method not in METHODS:
        raise ConfigError(f"{path}: estimation.method: expected one of {', '.join(METHODS)}, got {method!r}")
    consistent = est.get("physically_consistent", "sdp" in methods)
    if not isinstance(consistent, bool):
        raise ConfigError(f"{path}: estimation.physically_consistent: expected true or false, got {consistent!r}")
    seed = est.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise ConfigError(f"{path}: estimation.seed: expected a non-negative integer, got {seed!r}")
    refs = doc.get("references", [])
    if not isinstance(refs, list) or not all(isinstance(r, dict) for r in refs):
        raise ConfigError(f"{path}: references: expected [[references]] tables")
    gains = _drive_gains(doc.get("drive_gains"), root, f"{path}: drive_gains", n)
    return IdentificationConfig(path, robot, ident, validation, pre, method, tuple(refs), root, consistent or "sdp" in methods,
                                methods, seed, gains)


def _drive_gains(table, root: Path, where: str, n: int):
    if table is None:
        return None
    if not isinstance(table, dict):
        raise ConfigError(f"{where}: expected a table with payload_mass, [unloaded] and [loaded]")
    unknown = sorted(set(table) - {"payload_mass", "unloaded", "loaded"})
    missing = sorted({"payload_mass", "unloaded", "loaded"} - set(table))
    if unknown or missing:
        raise ConfigError(f"{where}: expected payload_mass, unloaded and loaded; "
                          + (f"unknown {', '.join(unknown)}" if unknown else f"missing {', '.join(missing)}"))
    mass = table["payload_mass"]
    if isinstance(mass, bool) or not isinstance(mass, (int, float)) or not mass > 0:
        raise ConfigError(f"{where}.payload_mass: expected a positive mass in kg, got {mass!r}")
    specs = []
    for key in ("unloaded", "loaded"):
        spec = dataset_spec(table[key], root, f"{where}.{key}", key, n)
        if "currents" not in spec.signals:
            raise ConfigError(f"{where}.{key}: expected motor currents (a currents column map or a preset with currents)")
        specs.append(spec)
    return float(mass), specs[0], specs[1]


def _stored_preprocessing(identified: dict) -> Preprocessing | None:
    """The identification's resolved preprocessing as results.json stores it (None if absent)."""
    stored = identified.get("settings", {}).get("preprocessing") if isinstance(identified.get("settings"), dict) else None
    if not isinstance(stored, dict):
        return None
    known = {f.name for f in fields(Preprocessing)}
    try:
        values = {k: (tuple(v) if isinstance(v, list) else v) for k, v in stored.items() if k in known}
        return Preprocessing(**values)
    except TypeError:
        return None


def _references(config: IdentificationConfig, base):
    from ..io.references import load_reference

    nominal = config.robot.standard_parameters()
    return tuple(load_reference(r, config.data_root, f"{config.path}: references[{i}]", base, nominal)
                 for i, r in enumerate(config.references))


def _gains_and_payload(config: IdentificationConfig, robot, base):
    """Drive gains from the two runs, then the payload from the loaded run with those gains."""
    from ..preprocessing.pipeline import prepare
    from .drive_gains import GainsAndPayload, identify_drive_gains, identify_payload

    mass, unloaded, loaded = config.drive_gains
    unit = replace(robot, drive_gains=np.ones(robot.n_dof))  # so that the recordings' "torques" are the currents
    pre_u = prepare(load_recording(unloaded, unit), config.preprocessing)
    pre_l = prepare(load_recording(loaded, unit), config.preprocessing)
    gains = identify_drive_gains(robot, base, pre_u, pre_l, mass, rng=config.seed)
    k = np.where(np.isfinite(gains.gains), gains.gains, robot.drive_gains)
    payload = identify_payload(robot, base, gains.base, replace(pre_l, tau=pre_l.tau * k))
    return GainsAndPayload(gains, payload, tuple(robot.drive_gains.tolist()))


def validation_settings(given: Preprocessing, resolved: Preprocessing | None) -> Preprocessing:
    """Preprocessing of validation logs: the identification's filters (in Hz, resolved on its data) so
    both are scored through the same filters; decimation and trim derived again for each log (its rate
    may differ), and no Fourier fit (the excitation's harmonics fit only its own log)."""
    if resolved is None:
        return replace(given, fourier=None)
    return replace(resolved, fourier=None, decimation=given.decimation, trim=given.trim, derivation="")


def _validate(config: IdentificationConfig, base, parameter_sets: dict, datasets: tuple[DatasetSpec, ...],
              progress=None, resolved: Preprocessing | None = None) -> tuple[tuple, tuple[str, ...]]:
    from ..preprocessing.pipeline import prepare
    from .identification import compare_torques

    out, warnings = [], []
    settings = validation_settings(config.preprocessing, resolved)
    for spec in datasets:
        data = prepare(load_recording(spec, config.robot), settings)
        out.append(compare_torques(config.robot, base, data, parameter_sets, progress))
        warnings.extend(data.warnings)
    return tuple(out), tuple(warnings)


def dataset_for_file(config: IdentificationConfig, file: Path, rows=None) -> DatasetSpec:
    """The identification dataset's column map applied to another log ``file`` (optional ``rows``).

    Raises
    ------
    DataError
        If the identification dataset reads several files (add a [[validation]] table instead).
    """
    spec = config.identification
    files = {s.file for s in spec.signals.values()} | ({spec.time.file} if spec.time else set())
    if len(files) > 1:
        raise DataError("--file: the identification dataset reads several files; add a [[validation]] table to the config instead")
    signals = {k: SignalSpec(Path(file), s.columns, s.scale) for k, s in spec.signals.items()}
    time = SignalSpec(Path(file), spec.time.columns, 1.0) if spec.time else None
    return replace(spec, name=Path(file).name, signals=signals, time=time,
                   rows=None if rows is None else tuple(rows))


@with_single_blas_thread
def run_identification(config: IdentificationConfig, progress=None, validate: bool = True):
    """Identify the base parameters from the config's identification dataset, then validate them on
    each validation dataset beside the reference sets.

    Returns
    -------
    dynid.experiment.identification.IdentificationResult
    """
    from ..dynamics.base_parameters import base_parameters
    from ..preprocessing.pipeline import prepare
    from ..validation.cross_validation import choose_coulomb_velocity
    from .identification import identify

    base = base_parameters(config.robot, rng=0)
    refs = _references(config, base)
    recording = load_recording(config.identification, config.robot)
    filters = None
    if config.preprocessing.auto:
        from ..validation.cross_validation import choose_preprocessing

        filters = choose_preprocessing(config.robot, base, recording, config.preprocessing)
        data = filters.data
    else:
        data = prepare(recording, config.preprocessing)
    vs = config.preprocessing.coulomb_velocity
    choice = choose_coulomb_velocity(config.robot, base, data) if vs == "auto" else None
    robot = replace(config.robot, coulomb_velocity=choice.velocity if choice is not None else np.broadcast_to(vs, (config.robot.n_dof,)))
    result = identify(robot, base, data, config.method, refs, progress, config.physically_consistent, config.methods, config.seed)
    result = replace(result, settings={**result.settings, "coulomb_velocity": robot.coulomb_velocity.tolist(),
                                       **({} if choice is None else {"coulomb_cross_validation": choice.to_dict()}),
                                       **({} if filters is None else {"preprocessing_cross_validation": filters.to_dict()})})
    if config.drive_gains is not None:
        result = replace(result, drive_gains=_gains_and_payload(config, robot, base))
    if not validate or not config.validation:
        return result
    validations, warnings = _validate(replace(config, robot=robot), base, result.parameter_sets(), config.validation, progress,
                                      data.settings)
    return replace(result, validations=validations, warnings=result.warnings + warnings)


def run_validation(config: IdentificationConfig, identified: dict, datasets: tuple[DatasetSpec, ...] | None = None,
                   progress=None) -> tuple[tuple, tuple[str, ...]]:
    """Validate identified base parameters (``identified``: results.json of ``dynid identify``) and the
    config's reference sets on the config's validation datasets (or on ``datasets``).

    Raises
    ------
    DataError
        The results do not belong to this robot (different base parameters).
    """
    from ..dynamics.base_parameters import base_parameters
    from .identification import parameter_sets

    base = base_parameters(config.robot, rng=0)
    try:
        names = [p["name"] for p in identified["base_parameters"]]
        values = np.array([float(p["value"]) for p in identified["base_parameters"]])
        method = str(identified.get("method", "ls"))
    except (KeyError, TypeError, ValueError):
        raise DataError("results: expected the results.json of dynid identify (a list base_parameters of {name, value})") from None
    if tuple(names) != base.names:
        raise DataError(f"results: its base parameters ({len(names)}) are not those of robot {config.robot.name!r} ({base.n_base}); was it identified with this config?")
    refs = _references(config, base)
    consistent = identified.get("physically_consistent")
    try:
        sdp = None if consistent is None else np.array([float(consistent["values"][n]) for n in base.names])
    except (KeyError, TypeError, ValueError):
        raise DataError("results: physically_consistent.values must give every base parameter") from None
    stored = identified.get("methods", {})
    try:
        others = {str(label): np.array([float(m["values"][n]) for n in base.names]) for label, m in stored.items()}
    except (KeyError, TypeError, ValueError, AttributeError):
        raise DataError("results: methods.*.values must give every base parameter") from None
    sets = parameter_sets(method, values, refs, sdp, others)
    datasets = config.validation if datasets is None else datasets
    if not datasets:
        raise ConfigError(f"{config.path}: no [[validation]] datasets to validate on (or give --file)")
    stored_vs = identified.get("settings", {}).get("coulomb_velocity") if isinstance(identified.get("settings"), dict) else None
    if stored_vs is not None:
        try:
            config = replace(config, robot=replace(config.robot, coulomb_velocity=np.asarray(stored_vs, dtype=float)))
        except (TypeError, ValueError, ConfigError):
            raise DataError("results: settings.coulomb_velocity must give one non-negative velocity per joint") from None
    comparisons, warnings = _validate(config, base, sets, datasets, progress, _stored_preprocessing(identified))
    return comparisons, tuple(w for r in refs for w in r.warnings) + warnings


@with_single_blas_thread
def identify_from_arrays(robot: Robot, t, q, tau, dq=None, *, preprocessing: Preprocessing | None = None,
                         method: str = "wls", physically_consistent: bool = False, methods: tuple[str, ...] = (),
                         name: str = "arrays"):
    """Identify a robot from arrays, without a config file or a CSV: the same pipeline as ``dynid identify``
    (data-derived preprocessing, parallel filtering, OLS/WLS with σ, optionally the SDP and other estimators).

    Parameters
    ----------
    robot : Robot
        E.g. :func:`dynid.load_robot`.
    t : (N,) array [s]
        Uniformly sampled time stamps.
    q : (N, n_dof) array [rad]
        Joint positions.
    tau : (N, n_dof) array [N·m]
        Joint torques (e.g. drive gain × motor current, eq. 16).
    dq : (N, n_dof) array [rad/s], optional
        Measured velocities (default: differentiated from the filtered positions).
    preprocessing : Preprocessing, optional
        Default: every setting derived from the data.
    method, physically_consistent, methods
        As ``[estimation]`` of a config.

    Returns
    -------
    dynid.experiment.identification.IdentificationResult

    Raises
    ------
    ShapeError
        Arrays of inconsistent shapes, not time-first, or not finite.
    DataError
        Time stamps that are not uniform and increasing.
    """
    from ..checks import check_trajectory_array
    from ..dynamics.base_parameters import base_parameters
    from ..exceptions import ShapeError
    from ..io.datasets import Recording
    from ..preprocessing.pipeline import prepare
    from .identification import identify

    t = np.asarray(t, dtype=float).reshape(-1)
    q = check_trajectory_array(q, robot.n_dof, "q")
    tau = check_trajectory_array(tau, robot.n_dof, "tau")
    dq = None if dq is None else check_trajectory_array(dq, robot.n_dof, "dq")
    if not (q.shape[0] == tau.shape[0] == t.shape[0] and (dq is None or dq.shape[0] == t.shape[0])):
        raise ShapeError(f"expected t, q, tau (and dq) with the same number of samples, got {t.shape[0]}, {q.shape[0]}, {tau.shape[0]}")
    steps = np.diff(t)
    if t.size < 2 or np.any(steps <= 0) or np.ptp(steps) > 1e-6 * np.median(steps):
        raise DataError("t: expected uniformly spaced, increasing time stamps (resample the data first)")
    rate = 1.0 / float(np.median(steps))
    data = prepare(Recording(name, t - t[0], q, dq, tau, rate), preprocessing or Preprocessing())
    base = base_parameters(robot, rng=0)
    return identify(robot, base, data, method, (), None, physically_consistent or "sdp" in methods, tuple(methods))

"""Configs of ``dynid identify`` / ``dynid validate`` (TOML): parsing only; :mod:`dynid.experiment.identification_run` runs them.

Layout (paths relative to the config file; data paths relative to ``data_root``)::

    robot = "ur10e"                      # built-in robot name or description TOML
    data_root = "../../shared/data/ur10e_mamedov2020"   # overridden by DYNID_DATA_ROOT (dynid: --data-root)

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
    rest_velocity = "auto"               # rad/s: below it a joint rests (no Coulomb friction predicted);
                                         # "auto" (default): 3x its velocity's noise, for each log
    rest_friction = "held"               # at rest: the friction of the last motion ("held", default) or
                                         # none ("zero"); one value or one per joint
    excitation = "excitation.json"       # the robot ran this trajectory of dynid excite: derivatives
                                         # by a Fourier fit on its harmonics instead of filters

    [estimation]
    estimators = ["wls", "sdp"]          # the first is the main estimate (default ["wls"]); any of ols, wls, irls,
                                         # lad, sdp (physically consistent), abc, abc10, de, pso, or one registered
    seed = 0                             # seeds the box searches (ABC, ABC×10, DE, PSO)
    friction = "auto"                    # each joint's friction model and its state at rest chosen by
                                         # cross-validation (default); "description": the description's terms

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

from ..exceptions import ConfigError, DataError
from .configs import config_robot, read_config, robot_source
from .datasets import DatasetSpec, SignalSpec, dataset_spec
from .trajectories import load_trajectory
from ..model.robot import Robot
from ..preprocessing.settings import Preprocessing
from ..estimators.registry import parse_estimators

# Parsing a config imports nothing heavy (no SciPy, compiled kernels or solvers), so that a mistake in it
# is reported at once; the identification itself imports them when it runs.

DATA_ROOT_ENV = "DYNID_DATA_ROOT"


@dataclass(frozen=True)
class IdentificationConfig:
    """A parsed identification config (module docstring)."""

    path: Path
    robot: Robot
    identification: DatasetSpec
    validation: tuple[DatasetSpec, ...]
    preprocessing: Preprocessing
    references: tuple[dict, ...]
    data_root: Path
    estimators: tuple[str, ...] = ("wls",)
    seed: int = 0
    drive_gains: tuple | None = None  # (payload_mass, unloaded DatasetSpec, loaded DatasetSpec)
    robot_source: str = ""  # a built-in name, a description's path or "config:<path>" (dynid.io.configs.robot_source)
    friction: str = "auto"  # "auto": each joint's friction model by cross-validation; "description": as described


_PRE_KEYS = {"order": int, "position_cutoff": float, "velocity_cutoff": float, "parallel_cutoff": float, "band": float,
             "decimation": int, "min_speed": None, "trim": float, "chunk": int, "excitation": None,
             "coulomb_velocity": None, "rest_velocity": None, "rest_friction": None, "presliding": None,
             "auto": None, "strategy": None, "smoothing_passes": int}


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
        if key == "rest_friction":
            one = lambda x: x in ("held", "zero") or (isinstance(x, (int, float)) and not isinstance(x, bool) and x >= 0)  # noqa: E731
            ok = one(v) or (isinstance(v, list) and len(v) == n and all(one(x) for x in v))
            if not ok:
                raise ConfigError(f'{where}.rest_friction: expected "held", "zero", a relaxation time in seconds, or a list '
                                  f"of {n} of them, got {v!r}")
            values[key] = tuple(v) if isinstance(v, list) else v
            continue
        if key == "strategy":
            from ..preprocessing.strategies import check_strategy

            try:
                values[key] = check_strategy(v) if isinstance(v, str) else check_strategy(repr(v))
            except ConfigError as exc:
                raise ConfigError(f"{where}.strategy: {str(exc).split(': ', 1)[1]}") from None
            continue
        if key == "auto":
            if not isinstance(v, bool):
                raise ConfigError(f"{where}.auto: expected true or false, got {v!r}")
            values[key] = v
            continue
        if key in ("min_speed", "coulomb_velocity", "rest_velocity", "presliding"):
            if v == "auto" and key != "presliding":
                values[key] = v
                continue
            ok = (isinstance(v, (int, float)) and not isinstance(v, bool) and v >= 0) or (
                isinstance(v, list) and len(v) == n and all(isinstance(x, (int, float)) and not isinstance(x, bool) and x >= 0 for x in v))
            if not ok:
                auto = '"auto", ' if key != "presliding" else ""
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
    override = data_root or os.environ.get(DATA_ROOT_ENV)
    if override is None and not isinstance(doc.get("data_root", "."), str):
        raise ConfigError(f"{path}: data_root: expected a folder path, got {doc['data_root']!r}")
    root = Path(override) if override else here / doc.get("data_root", ".")  # an absolute path stays as is
    if not root.is_dir():
        raise ConfigError(f"{path}: data_root {root} is not a folder (set data_root in the config, or {DATA_ROOT_ENV})", field="data_root")
    robot = config_robot(doc, path, root)
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
    old = [k for k in ("method", "physically_consistent", "methods") if k in est]
    if old:
        raise ConfigError(f"{path}: estimation.{old[0]}: no longer exists; list the estimators, the main one first: "
                          f"estimators = {_estimators_from_old(est)}")
    unknown = sorted(set(est) - {"estimators", "seed", "friction"})
    if unknown:
        raise ConfigError(f"{path}: estimation: unknown field(s) {', '.join(unknown)}; expected estimators, friction, seed")
    friction = est.get("friction", "description" if pre.coulomb_velocity != 0.0 else "auto")
    if friction not in ("auto", "description"):
        raise ConfigError(f'{path}: estimation.friction: expected "auto" (each joint\'s friction model chosen by '
                          f'cross-validation) or "description" (the robot description\'s terms), got {friction!r}')
    listed = est.get("estimators", ["wls"])
    if not isinstance(listed, list) or not all(isinstance(m, str) for m in listed):
        raise ConfigError(f"{path}: estimation.estimators: expected a list of estimator names like [\"wls\", \"sdp\"], got {listed!r}")
    try:
        estimators = parse_estimators(listed)
    except ConfigError as exc:
        raise ConfigError(f"{path}: estimation.estimators: {str(exc).split(': ', 1)[1]}") from None
    seed = est.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise ConfigError(f"{path}: estimation.seed: expected a non-negative integer, got {seed!r}")
    refs = doc.get("references", [])
    if not isinstance(refs, list) or not all(isinstance(r, dict) for r in refs):
        raise ConfigError(f"{path}: references: expected [[references]] tables")
    gains = _drive_gains(doc.get("drive_gains"), root, f"{path}: drive_gains", n)
    return IdentificationConfig(path, robot, ident, validation, pre, tuple(refs), root, estimators=estimators, seed=seed,
                                drive_gains=gains, friction=friction, robot_source=robot_source(doc, path, root))


def _estimators_from_old(est: dict) -> str:
    """The ``estimators`` list that says what the old keys ``method``, ``physically_consistent`` and ``methods`` said."""
    methods = [str(m).lower() for m in est.get("methods", [])] if isinstance(est.get("methods"), list) else []
    first = est.get("method") if isinstance(est.get("method"), str) else next((m for m in methods if m in ("ols", "wls")), "wls")
    keys = [first.lower()] + (["sdp"] if est.get("physically_consistent") is True or "sdp" in methods else [])
    keys += [m for m in methods if m not in keys]
    return "[" + ", ".join(f'"{k}"' for k in keys) + "]"


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


def stored_preprocessing(identified: dict) -> Preprocessing | None:
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
        raise DataError("file: the identification dataset reads several files; add a [[validation]] table to the config instead", field="file")
    signals = {k: SignalSpec(Path(file), s.columns, s.scale, s.side) for k, s in spec.signals.items()}
    time = SignalSpec(Path(file), spec.time.columns, 1.0) if spec.time else None
    return replace(spec, name=Path(file).name, signals=signals, time=time,
                   rows=None if rows is None else tuple(rows))

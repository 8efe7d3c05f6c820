"""Configs of ``dynid identify`` / ``dynid validate`` (TOML): parsing only; :mod:`dynid.identification.run` runs them.

Layout (paths relative to the config file; data paths relative to ``data_root``)::

    robot = "ur10e"                      # built-in robot name or description TOML
    data_root = "../../shared/data/ur10e_mamedov2020"   # overridden by DYNID_DATA_ROOT (dynid: --data-root)

    [identification]                     # a dataset table (dynid.io.logs.datasets)
    preset = "ur-rtde"
    file = "identification_data/ur-20_02_10-30sec_12harm.csv"
    rows = [635, 3510]

    [preprocessing]                      # dynid.preprocessing.Preprocessing; all optional: by default every
                                         # cutoff derives from the excitation band found in the data
                                         # (the factors: dynid.preprocessing.bands)
    order = 4
    band = 0.5                           # Hz, the excitation band (default: from the positions' spectrum)
    position_cutoff = 5.0                # Hz, positions and measured velocities (default: POSITION_FACTOR × band)
    parallel_cutoff = 2.5                # Hz, torques AND every regressor column (default: PARALLEL_FACTOR × band)
    decimation = 16                      # default: down to the parallel band
    min_speed = 0.0                      # rad/s, one value or one per joint; "auto" (default):
                                         # MIN_SPEED_FRACTION × each joint's RMS speed
    coulomb_velocity = 0.0               # rad/s, Coulomb term tanh(dq/v) per joint; 0 (default): sign(dq);
                                         # "auto": chosen per joint by blocked cross-validation
    rest_velocity = "auto"               # rad/s: below it a joint rests (no Coulomb friction predicted);
                                         # "auto" (default): REST_FACTOR × its velocity's noise, each log
    rest_friction = "held"               # at rest: the friction of the last motion ("held", default) or
                                         # none ("zero"); one value or one per joint
    excitation = "excitation.json"       # the robot ran this trajectory of dynid excite: derivatives
                                         # by a Fourier fit on its harmonics instead of filters

    [estimation]
    estimators = ["wls", "sdp"]          # the first is the main estimate (default ["wls", "sdp"]); any of ols, wls, irls,
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

    [[references]]                       # published parameter sets (dynid.io.config.references)
    name = "Mamedov & Mikhel 2020"
    file = "ur10e_reference_parameters.csv"
    header = true
    names = "name"
    values = "value"
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field, fields, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import msgspec
import numpy as np

from ..._util.keywords import keyword_only_after_data
from ..._util.reprs import short_repr
from ..._util.typed import convert
from ...estimators.registry import DEFAULT_ESTIMATORS, configured_estimator, estimate_label, estimator_choices, keys
from ...exceptions import ConfigError, DataError
from ...model.robot import Robot
from ...preprocessing.settings import Preprocessing
from ...preprocessing.strategies import check_strategy
from ..logs.bags import is_bag
from ..logs.dataset_specs import DatasetSpec, SignalSpec, dataset_spec
from ..logs.table_files import read_table
from ..logs.trajectories import load_trajectory
from .config_types import EstimationTable, IdentificationDocument, PreprocessingTable
from .configs import config_mjcf, config_robot, config_urdf, read_config, robot_source

if TYPE_CHECKING:
    from ...simulation.closed_loop import ClosedLoopSetup

# Parsing a config imports nothing heavy (no SciPy, compiled kernels or solvers), so that a mistake in it
# is reported at once; the identification itself imports them when it runs.

DATA_ROOT_ENV = "DYNID_DATA_ROOT"


@dataclass(frozen=True)
class EstimationSettings:
    """What a config's ``[estimation]`` table asks for (:class:`dynid.io.config.config_types.EstimationTable`), its defaults
    filled in.

    Attributes
    ----------
    estimators : tuple of str and Estimator
        Estimator keys (lower case) or unfitted estimators (a config's entry with settings, ``{ key = "abc",
        colony_size = 60 }``: the estimator carrying them), the first the main estimate, the closed-loop ones (IDIM-IV,
        DIDIM: :attr:`closed_loop`) after the others.
    seed : int
        Seeds the box searches and the bootstrap.
    friction : str
        "auto": each joint's friction model by cross-validation; "description": as described.
    choice : str
        "torques": the main estimate chosen on the validation logs' torques; "states": on their states alone
        (:func:`dynid.identification.verdict.choose_main_estimate`).
    """

    estimators: tuple = DEFAULT_ESTIMATORS
    seed: int = 0
    friction: str = "auto"
    choice: str = "torques"

    @property
    def closed_loop(self) -> tuple[str, ...]:
        """The closed-loop estimators among :attr:`estimators` (IDIM-IV, DIDIM), in the order they run.

        Returns
        -------
        tuple of str
        """
        return split_estimators(self.estimators, "[estimation] estimators")[1]


@short_repr
@dataclass(frozen=True)
class DriveGainsSettings:
    """What a config's ``[drive_gains]`` table asks for: drive gains K (eq. 16) from a run without and one with a
    known payload (:func:`dynid.identification.drive_gains.identify_drive_gains`).

    Attributes
    ----------
    payload_mass : float [kg]
    unloaded, loaded : DatasetSpec
        The runs without and with the payload; both hold motor currents.
    """

    payload_mass: float
    unloaded: DatasetSpec
    loaded: DatasetSpec


@short_repr
@dataclass(frozen=True)
class IdentificationConfig:
    """A parsed identification config (module docstring).

    Attributes
    ----------
    path : Path
        The config file.
    robot : Robot
    identification : DatasetSpec
    validation : tuple of DatasetSpec
    preprocessing : Preprocessing
        As given (``None``: derived from the data).
    references : tuple of dict
        Reference parameter sets' tables.
    data_root : Path
        Folder the data files are relative to.
    estimation : EstimationSettings
        What ``[estimation]`` asks for: the estimators, the seed, the friction models, the choice.
    drive_gains : DriveGainsSettings or None
        ``[drive_gains]``: the payload's mass and the runs without and with it.
    robot_source : str
        A built-in name, a description's path or ``"config:<path>"`` (:func:`dynid.io.config.configs.robot_source`).
    urdf : Path or None
        The URDF the robot comes from, if it does (:func:`dynid.io.config.configs.config_urdf`): ``dynid export`` writes the
        identified values back into it.
    mjcf_model : Path or None
        ``mjcf_model``: the user's own MuJoCo model of the arm, checked against the robot's joints
        (:func:`dynid.io.exported.mjcf_write_back.read_users_mjcf`); ``dynid identify`` and ``dynid export`` write the identified
        values into a copy of it. Not given, the MJCF the robot was read from, if it was and holds no joint fixed.
    controller : dynid.simulation.closed_loop.ClosedLoopSetup or None
        ``[controller]``: the controller, the set-points' :class:`ReferenceTrajectory` and whether the model's torque
        was fed forward.
    torque_sensor : str
        The identification log's ``torques.sensor``: "joint" (a joint torque sensor on the link side) or "drive".
    """

    path: Path
    robot: Robot
    identification: DatasetSpec
    validation: tuple[DatasetSpec, ...]
    preprocessing: Preprocessing
    references: tuple[dict, ...]
    data_root: Path
    estimation: EstimationSettings = field(default_factory=EstimationSettings)
    drive_gains: DriveGainsSettings | None = None
    robot_source: str = ""  # a built-in name, a description's path or "config:<path>" (dynid.io.config.configs.robot_source)
    urdf: Path | None = None  # the URDF the robot comes from (dynid.io.config.configs.config_urdf): export writes into it
    mjcf_model: Path | None = None  # the user's own MJCF: identify and export write the values into a copy of it
    controller: ClosedLoopSetup | None = None
    torque_sensor: str = "drive"  # the identification log's torques.sensor: "joint" or "drive"

    @property
    def description_files(self) -> tuple[Path, ...]:
        """The robot's description files this config reads: the description it names (URDF, xacro, MJCF or robot
        table), the URDF it comes from, the user's MJCF model.

        Returns
        -------
        tuple of Path
        """
        named = Path(self.robot_source) if self.robot_source and not self.robot_source.startswith("config:") else None
        return tuple(dict.fromkeys(p for p in (named, self.urdf, self.mjcf_model) if p is not None and p.is_file()))

    @property
    def files_read(self) -> tuple[Path, ...]:
        """Every file this config reads: itself, :attr:`description_files` and the logs (a file dynid writes must be
        none of them).

        Returns
        -------
        tuple of Path
        """
        found = [self.path, *self.description_files]
        gains = () if self.drive_gains is None else (self.drive_gains.unloaded, self.drive_gains.loaded)
        for spec in (self.identification, *self.validation, *gains):
            found.extend(spec.files)
        return tuple(dict.fromkeys(found))


REMOVED = {
    ("preprocessing", "torque_cutoff"): "no longer exists, because a filter on the torques alone biases the estimate near "
                                        "velocity reversals; use parallel_cutoff (torques and every regressor column), or "
                                        "leave it out for the data-derived default (dynid migrate {path} rewrites it)",
    ("estimation", "sdp_prior"): "no longer exists (a key of an unreleased 0.2.0 draft): the SDP's prior is given in its "
                                 'entry of the estimators list, { key = "sdp", prior_kind = "geometric" } in place of "sdp"',
}
"""Fields that no longer exist, and what to write instead (said before the typed check, which would only call them
unknown); ``[estimation] method``, ``methods`` and ``physically_consistent`` are said by :func:`_estimators_from_old`."""


def _per_joint(value, n: int, where: str):
    """A per-joint setting as :class:`Preprocessing` holds it: the value, or a tuple of ``n``."""
    if isinstance(value, list):
        if len(value) != n:
            raise ConfigError(f"{where}: expected one value or a list of {n} (one per joint), got {value!r}")
        return tuple(float(x) if not isinstance(x, str) else x for x in value)
    return value if isinstance(value, str) else float(value)


def _preprocessing(table: PreprocessingTable, where: str, n: int, here: Path = Path(".")) -> Preprocessing:
    """:class:`Preprocessing` of a typed ``[preprocessing]`` table: what depends on the robot (one value per joint),
    the strategy's name and the excitation file checked here."""
    values: dict[str, Any] = {}
    for f in msgspec.structs.fields(table):
        v = getattr(table, f.name)
        if v is None:
            continue
        w = f"{where}.{f.name}"
        if f.name == "excitation":
            try:
                traj = load_trajectory(here / v)
            except ConfigError as exc:
                raise ConfigError(f"{w}: {exc}") from None
            if traj.n_dof != n:
                raise ConfigError(f"{w}: the trajectory has {traj.n_dof} joints, the robot {n}")
            values["fourier"] = (traj.omega_f, traj.n_harmonics)
        elif f.name == "strategy":
            try:
                values["strategy"] = check_strategy(v)
            except ConfigError as exc:
                raise ConfigError(f"{w}: {str(exc).split(': ', 1)[1]}") from None
        elif f.name in ("min_speed", "coulomb_velocity", "rest_velocity", "presliding", "rest_friction"):
            values[f.name] = _per_joint(v, n, w)
        elif f.name in ("order", "decimation", "chunk", "smoothing_passes"):
            values[f.name] = int(v)
        elif f.name == "auto":
            values[f.name] = bool(v)
        else:
            values[f.name] = float(v)
    return Preprocessing(**values)


@keyword_only_after_data
def load_identification_config(path: str | Path, *, data_root: str | Path | None = None) -> IdentificationConfig:
    """Parse an identification config.

    Parameters
    ----------
    path : path of the TOML file
    data_root : path, optional
        Folder the data paths are relative to; default: the environment variable ``DYNID_DATA_ROOT``,
        else the config's ``data_root`` (relative to the config file), else the config's folder.

    Returns
    -------
    IdentificationConfig

    Raises
    ------
    ConfigError
        Unreadable file, invalid TOML, unknown or malformed fields (the message names file and field;
        the structure: :class:`dynid.io.config.config_types.IdentificationDocument`).
    """
    path = Path(path)
    return config_from_document(read_config(path, None), path, data_root)


def split_estimators(asked, where: str) -> tuple[tuple, tuple[str, ...]]:
    """The open-loop estimators (:func:`dynid.estimators.registry.parse_estimators`) and the closed-loop ones
    (IDIM-IV, DIDIM, DIDIM-SDP: :data:`dynid.estimators.instrumental.CLOSED_LOOP_METHODS`) of an estimator list, as a
    config's ``[estimation] estimators`` and :class:`dynid.identification.identifier.Identifier` take it.

    Parameters
    ----------
    asked : sequence of str and Estimator
        Estimator keys, or estimator objects (:func:`dynid.estimators.registry.estimator_choices`); the first is the
        main estimate.
    where : str
        Where the list was given, for the messages.

    Returns
    -------
    estimators : tuple
        The parsed open-loop estimators: keys in lower case, the objects as given.
    closed_loop : tuple of str
        The closed-loop keys, lower case.

    Raises
    ------
    ConfigError
        An unknown key, or a closed-loop estimator first (it starts from the first's estimate).
    """
    from ...estimators.instrumental import CLOSED_LOOP_METHODS

    asked = [k.strip().lower() if isinstance(k, str) else k for k in asked]  # estimator objects stay as they are
    closed_loop = tuple(k for k in asked if isinstance(k, str) and k in CLOSED_LOOP_METHODS)
    if asked and isinstance(asked[0], str) and asked[0] in CLOSED_LOOP_METHODS:
        raise ConfigError(f"{where}: the first is the main estimate and starts the closed-loop ones: list ols or wls "
                          f"before {asked[0]!r}")
    open_loop = [k for k in asked if not (isinstance(k, str) and k in CLOSED_LOOP_METHODS)]
    try:
        keys_ = estimator_choices(open_loop, where)[0]
        estimators = tuple(k if isinstance(o, str) else o for k, o in zip(keys_, open_loop))
    except ConfigError as exc:
        text = str(exc)
        if text.startswith("plugin "):  # a plugin that cannot be imported names itself and where it was named
            raise ConfigError(f"{where}: {text}") from None
        names = "(or all), or in closed loop " + ", ".join(CLOSED_LOOP_METHODS)  # the closed-loop ones are taken here too
        raise ConfigError(f"{where}: {text.split(': ', 1)[1].replace('(or all)', names)}") from None
    return estimators, closed_loop


def config_from_document(doc: dict, path: Path, data_root: str | Path | None = None) -> IdentificationConfig:
    """Parse an identification config already read (e.g. a fleet's unit: its template with the unit's files).

    Parameters
    ----------
    doc : dict
        The TOML document.
    path : Path
        The file it stands for: messages name it, relative paths start from its folder.
    data_root : path, optional
        As :func:`load_identification_config`.

    Returns
    -------
    IdentificationConfig

    Raises
    ------
    ConfigError
        As :func:`load_identification_config`.
    """
    doc = _current_document(doc, path)
    # the robot table is checked by the description's own parser (its drive terms are those registered now)
    typed = convert({**doc, "robot": "-"} if isinstance(doc.get("robot"), dict) else doc, IdentificationDocument, str(path))
    here = path.parent
    override = data_root or os.environ.get(DATA_ROOT_ENV)
    root = Path(override) if override else here / (typed.data_root or ".")  # an absolute path stays as is
    if not root.is_dir():
        raise ConfigError(f"{path}: data_root {root} is not a folder (set data_root in the config, or {DATA_ROOT_ENV})", field="data_root")
    robot = _robot_of(doc, path, root)
    n = robot.n_dof
    ident, validation = _datasets(doc, path, root, robot)
    pre = _preprocessing_of(typed.preprocessing, path, n)
    controller = _controller(doc.get("controller"), root, f"{path}: controller", robot)
    estimation = _estimation_settings(typed.estimation, pre, path, controller is not None)
    refs = doc.get("references", [])
    _check_reference_names(refs, path)
    gains = _drive_gains(doc.get("drive_gains"), root, f"{path}: drive_gains", n)
    source, urdf, mjcf = _robot_files(doc, typed, path, root, robot)
    return IdentificationConfig(path, robot, ident, validation, pre, tuple(refs), root, estimation, drive_gains=gains,
                                robot_source=source, urdf=urdf, controller=controller, torque_sensor=_torque_sensor(doc),
                                mjcf_model=mjcf)


def _robot_of(doc: dict, path: Path, root: Path):
    """:func:`config_from_document`'s robot: its table or file (:func:`config_robot`), with the drive terms a joint
    torque sensor does not see (:func:`_sensed_terms`)."""
    return _sensed_terms(config_robot(doc, path, root), doc, path)


def _branches_hint(robot) -> str:
    """For a robot with branches, what a refusal of a column list of the wrong length adds: its joints, and the
    ``held`` that keeps its longest chain (:func:`dynid.model.robot_files.joints_off_arm`: a gripper's fingers, another arm
    the log has no columns for)."""
    if not robot.is_tree:
        return ""
    from ...model.robot_files import joints_off_arm

    parents = {k: int(p) for k, p in enumerate(robot.parents)}
    off = ", ".join(f'"{robot.joints[k].name}"' for k in joints_off_arm(
        parents, set(np.flatnonzero(~robot.prismatic).tolist()), set(np.flatnonzero(robot.prismatic).tolist())))
    return (f" ({robot.name} has branches, {robot.n_dof} joints: {', '.join(j.name for j in robot.joints)}; hold those "
            f"the log has no columns for in the config's [robot] table, held = [{off}] for its longest chain, or let "
            "dynid init write the config)")


def _logged_joints(table, robot) -> tuple[int, np.ndarray]:
    """The number of joints a dataset's columns hold and which of them slide: the robot's coordinates (a joint that
    follows another, ``<mimic>``, has no column), or every joint where its positions list one column per joint (a
    config written before such joints were read; the followers' columns then read and not used, said so)."""
    kept = robot.independent
    listed = table.get("positions", {}).get("columns") if isinstance(table, dict) and isinstance(table.get("positions"), dict) else None
    if not robot.followers or (isinstance(listed, list) and len(listed) == robot.n_dof):
        return robot.n_dof, robot.prismatic
    return int(kept.sum()), robot.prismatic[kept]


def _datasets(doc: dict, path: Path, root: Path, robot) -> tuple:
    """:func:`config_from_document`'s identification dataset and validation datasets (their names unique)."""
    joints = _branches_hint(robot)
    ident = dataset_spec(doc["identification"], root, f"{path}: identification", "identification",
                         *_logged_joints(doc["identification"], robot), joints)
    validation = tuple(dataset_spec(v, root, f"{path}: validation[{i}]", f"validation {i + 1}", *_logged_joints(v, robot),
                                    joints)
                       for i, v in enumerate(doc.get("validation", [])))
    names = [v.name for v in validation]
    if len(set(names)) != len(names):
        raise ConfigError(f"{path}: validation: dataset names must be unique, got {names}")
    return ident, validation


def _preprocessing_of(given, path: Path, n: int):
    """:func:`config_from_document`'s preprocessing: the table given, ``"auto"`` (every choice made on the data), or
    the defaults."""
    table = PreprocessingTable(auto=True, coulomb_velocity="auto") if given == "auto" else given or PreprocessingTable()
    return _preprocessing(table, f"{path}: preprocessing", n, path.parent)


def _current_document(doc: dict, path: Path) -> dict:
    """A config's document as read today: the layout a validation table inherits filled in, a removed key refused
    (saying what replaced it)."""
    doc = with_inherited_layout(doc)
    for (section, key), why in REMOVED.items():
        if isinstance(doc.get(section), dict) and key in doc[section]:
            raise ConfigError(f"{path}: {section}.{key}: {why.replace('{path}', str(path))}")
    est = doc.get("estimation")
    old = [k for k in ("method", "physically_consistent", "methods") if isinstance(est, dict) and k in est]
    if old and isinstance(est, dict):
        raise ConfigError(f"{path}: estimation.{old[0]}: no longer exists; list the estimators, the main one first: "
                          f"estimators = {_estimators_from_old(est)} (dynid migrate {path} rewrites it)")
    return doc


def _estimation_settings(e, pre, path: Path, controlled: bool) -> EstimationSettings:
    """The ``[estimation]`` table as settings: the estimators (closed-loop ones only with a controller; an entry with
    hyper-parameters as the estimator object carrying them), the friction (each joint's model chosen unless a Coulomb
    smoothing velocity is given), the seed,
    the choice of the main estimate (``e`` None: the table left out)."""
    e = e or EstimationTable()
    friction = e.friction or pre.friction_default
    asked, configured = _estimator_entries(e.estimators or list(DEFAULT_ESTIMATORS), f"{path}: estimation.estimators")
    estimators, closed_loop = split_estimators(asked, f"{path}: estimation.estimators")
    if closed_loop and not controlled:
        raise ConfigError(f"{path}: estimation.estimators: {closed_loop[0]} simulates the run in closed loop and needs its "
                          "controller: add a [controller] table (kp, kd, rate, the reference trajectory), or leave it out "
                          "(without the controller only the open-loop estimators can run)")
    if e.choice == "states" and "sdp" not in estimators:
        raise ConfigError(f"{path}: estimation.choice = \"states\" weighs the SDP's spread on the validation logs' "
                          "states: add sdp to estimation.estimators, or leave choice out")
    return EstimationSettings(tuple(configured.get(k, k) if isinstance(k, str) else k for k in (*estimators, *closed_loop)),
                              e.seed or 0, friction, e.choice or "torques")


def _robot_files(doc: dict, typed, path: Path, root: Path, robot):
    """Where the robot's description comes from (results.json's ``robot_source``), its URDF and its MuJoCo model
    (``mjcf_model``, else the description's own MJCF), as the config names them.

    Returns ``(source, urdf, mjcf_model)``.
    """
    urdf = config_urdf(doc, path, root)
    mjcf = _mjcf_model(typed.mjcf_model, path.parent, robot, urdf, path) or _robots_mjcf(doc, path, root, robot)
    return robot_source(doc, path, root), urdf, mjcf


def _estimator_entries(entries: list, where: str) -> tuple[list[str], dict]:
    """The estimators list's keys (lower case), and for each key its inline tables give settings, the unfitted
    estimator carrying them (:func:`dynid.estimators.registry.configured_estimator`, which checks them against the
    estimator's class): key -> estimator."""
    asked: list[str] = []
    settings: dict[str, dict] = {}
    for i, entry in enumerate(entries):
        if not isinstance(entry, dict):
            asked.append(str(entry).strip().lower())
            continue
        key = entry.get("key")
        if not isinstance(key, str):
            raise ConfigError(f'{where}[{i}]: a table in the list names its estimator, {{ key = "sdp", prior_kind = '
                              f'"geometric" }}, got {entry!r}')
        key = key.strip().lower()
        asked.append(key)
        settings[key] = {**settings.get(key, {}), **{k: v for k, v in entry.items() if k != "key"}}
    return asked, {key: configured_estimator(key, given, f"{where}[{asked.index(key)}]") for key, given in settings.items()
                   if given}


def _torque_sensor(doc: dict) -> str:
    """The identification log's ``torques.sensor`` ("drive" where not said)."""
    table = doc.get("identification")
    torques = table.get("torques") if isinstance(table, dict) else None
    return "joint" if isinstance(torques, dict) and torques.get("sensor") == "joint" else "drive"


JOINT_SENSOR_NOTE = ("a joint torque sensor on the link side of the gear (torques.sensor = \"joint\") measures no "
                     "rotor inertia")


def _sensed_terms(robot: Robot, doc: dict, path: Path) -> Robot:
    """The robot's drive terms as the identification log's torque sensor measures them: with ``torques.sensor =
    "joint"`` (a joint torque sensor on the link side, e.g. a KUKA LBR's or a Franka's) no rotor inertia ``Ia``
    unless the config lists it in ``drive_terms`` itself, where it is said: the log's torque holds none, and a rotor
    inertia fitted to it takes up whatever else the log shows (issue "Never worse than the description", item 3)."""
    if _torque_sensor(doc) != "joint" or "Ia" not in robot.drive_terms:
        return robot
    own = doc.get("robot")
    given = isinstance(own, dict) and own.get("drive_terms") is not None
    if given:
        return robot.without_drive_terms((), note=f"{path}: robot.drive_terms lists Ia, but {JOINT_SENSOR_NOTE}: the "
                                              "rotor inertia fitted to this log is not the drive's (leave Ia out)")
    return robot.without_drive_terms(("Ia",))


def _mjcf_model(given: str | None, here: Path, robot, urdf: Path | None, path: Path) -> Path | None:
    """``mjcf_model``, relative to the config's folder, checked now against the robot's joints (one line: no such
    file, not MJCF, a joint missing or not a hinge, MuJoCo not installed)."""
    if given is None:
        return None
    file = here / given  # an absolute path stays as is
    if not file.is_file():
        raise ConfigError(f"{path}: mjcf_model: no such file {file}", field="mjcf_model")
    if urdf is not None and urdf.name == file.name:
        raise ConfigError(f"{path}: mjcf_model: {file.name} is also the URDF's file name, and identify writes both into "
                          "one folder: give the MJCF another name", field="mjcf_model")
    from ..exported.mjcf_write_back import read_users_mjcf

    try:
        read_users_mjcf(file, robot)
    except ConfigError as exc:
        raise ConfigError(f"{path}: mjcf_model: {exc}", field="mjcf_model") from None
    return file


def _robots_mjcf(doc: dict, path: Path, root: Path, robot) -> Path | None:
    """The MJCF the robot was read from, where no ``mjcf_model`` is given: identify and export write the values into a
    copy of it, as into a URDF the robot was read from; none for a robot with held joints (:func:`_mjcf_model`'s
    check refuses those: their bodies would count twice), whose MJCF is written anew."""
    mjcf = config_mjcf(doc, path, root)
    return None if mjcf is None or robot.held else _mjcf_model(str(mjcf), path.parent, robot, None, path)


def _controller(table, root: Path, where: str, robot):
    """The :class:`~dynid.simulation.closed_loop.ClosedLoopSetup` of a ``[controller]`` table (typed already), or None;
    the set-points are read as the logs' angles are, the robot's position offsets added. A robot whose joints follow
    others (``<mimic>``) has its gains and set-points given for the driven joints, as its logs hold them (a follower has
    no drive: it is given its master's gains, which act on nothing)."""
    if table is None:
        return None
    from ...simulation.closed_loop import ClosedLoopSetup, Controller

    n, driven = robot.n_dof, np.flatnonzero(robot.independent)
    try:
        kp, kd, ki = (_every_joint(table.get(k, 0.0), robot) for k in ("kp", "kd", "ki"))
        controller = Controller.of(n, kp, kd, ki, float(table["rate"]), float(table.get("velocity_cutoff", 0.0)))
    except ConfigError as exc:
        raise ConfigError(f"{where}: {str(exc).removeprefix('controller.')}") from None
    ref = table["reference"]
    offset = robot.transmission.position_offset
    if robot.followers and len(ref["positions"]) == driven.size:
        offset = None if offset is None else np.asarray(offset)[driven]
    elif len(ref["positions"]) != n:
        joints = f"{driven.size} columns (one per driven joint)" if robot.followers else f"{n} columns (one per joint)"
        raise ConfigError(f"{where}.reference.positions: expected {joints}, got {ref['positions']!r}")
    reference = ReferenceTrajectory(root / ref["file"], tuple(ref["positions"]), bool(ref.get("header", False)),
                                    np.pi / 180 if ref.get("unit") == "deg" else 1.0,
                                    None if ref.get("rows") is None else (int(ref["rows"][0]), int(ref["rows"][1])),
                                    None if offset is None else tuple(float(x) for x in offset))
    return ClosedLoopSetup(controller, reference, feedforward=table.get("feedforward", "none") == "model")


def _every_joint(gain, robot):
    """A gain given per driven joint of a robot with followers, one per joint: a follower takes its master's."""
    wide = robot.widened(gain) if np.ndim(gain) == 1 else gain
    if np.shape(wide) != np.shape(gain):  # widened: a follower takes its master's gain
        for j in robot.followers:
            wide[j] = wide[robot.joints[j].mimic[0]]
    return wide


@dataclass(frozen=True)
class ReferenceTrajectory:
    """Where the reference of ``[controller]`` is.

    Attributes
    ----------
    file : Path
    positions : tuple of int or str
        Columns, 1-based or header names.
    header : bool
    scale : float
        To radians.
    rows : (first, last) or None
    offset : tuple of float or None
        The robot's position offsets [rad], added as to a log's angles (the controller's set-points are its encoders'
        angles: :func:`dynid.io.logs.datasets.load_recording`).
    """

    file: Path
    positions: tuple
    header: bool = False
    scale: float = 1.0
    rows: tuple[int, int] | None = None
    offset: tuple[float, ...] | None = None

    def read(self) -> np.ndarray:
        """The set-points.

        Returns
        -------
        (N, n_dof) ndarray [rad]

        Raises
        ------
        DataError
            A missing or malformed file (named, with the line).
        """
        table = read_table(self.file, list(self.positions), header=self.header, rows=self.rows)
        q = np.asarray(table.data, dtype=float) * self.scale
        return q if self.offset is None else q + np.asarray(self.offset)


def _check_reference_names(refs: list, path: Path) -> None:
    """Reference sets are told apart by name in every table: one name per set, none of dynid's estimates' labels."""
    labels = {estimate_label(k) for k in keys()}
    seen: dict[str, int] = {}
    for i, r in enumerate(refs):
        name = str(r.get("name", "")) if isinstance(r, dict) else ""
        if name in labels:
            raise ConfigError(f"{path}: references[{i}].name: {name!r} is the name of dynid's own estimate; name the set "
                              "after its source")
        if name in seen:
            raise ConfigError(f"{path}: references[{i}].name: {name!r} names two reference sets (references[{seen[name]}] "
                              "too); give each its own name")
        seen[name] = i


LAYOUT_KEYS = ("preset", "header", "n_columns", "delimiter", "decimal", "gaps", "max_gap", "held", "time", "rate", "resample", "side",
               "positions", "velocities", "currents", "torques")
"""The keys of a dataset table that say how its file is laid out (the rest say which file and which part of it)."""


def with_inherited_layout(doc: dict) -> dict:
    """The config with each ``[[validation]]`` table that states no positions of its own (no ``positions``, ``preset`` or
    ``bag``) given the identification's column layout (:data:`LAYOUT_KEYS`); its own keys (``file``, ``rows``,
    ``time_range``, ``name``, and ``torques`` or ``currents``, e.g. to flip a sign: then neither of the
    identification's) stay. The identification's signals must then read its default ``file`` (none of them naming a
    file of its own). A table that names no file but ``rows`` or ``time_range`` is another stretch of the
    identification's log: it takes its file (or its signals' own files) too. Where the identification log is a ROS 2
    bag, a validation table that names no CSV file takes the bag's reader settings it does not state
    (:data:`BAG_READER_KEYS`).

    Parameters
    ----------
    doc : dict
        The parsed config.

    Returns
    -------
    dict
        A new document (``doc`` is not modified).
    """
    ident = doc.get("identification")
    validation = doc.get("validation")
    if not isinstance(ident, dict) or not isinstance(validation, list):
        return doc
    own_files = any(isinstance(ident.get(k), dict) and "file" in ident[k] for k in ("time", "positions", "velocities",
                                                                                     "currents", "torques"))
    layout = {k: ident[k] for k in LAYOUT_KEYS if k in ident}
    reader = {k: ident[k] for k in BAG_READER_KEYS if k in ident} if "bag" in ident else {}
    merged = []
    for v in validation:
        if reader and isinstance(v, dict) and not any(k in v for k in ("file", "positions", "preset")):
            merged.append({**reader, **v})  # a bag's table: the identification's bag, topic, joint names, effort
            continue
        states_its_own = not isinstance(v, dict) or any(k in v for k in ("positions", "preset", "bag"))
        if states_its_own or "bag" in ident:
            merged.append(v)
            continue
        stretch = "file" not in v and any(k in v for k in ("rows", "time_range"))  # another stretch of the same log
        if own_files and not stretch:
            merged.append(v)
            continue
        torque = ("torques", "currents") if any(k in v for k in ("torques", "currents")) else ()  # its own: both left
        file = {"file": ident["file"]} if stretch and "file" in ident else {}  # the identification's file(s) too
        merged.append({**{k: x for k, x in layout.items() if k not in torque}, **file, **v})
    return {**doc, "validation": merged}


BAG_READER_KEYS = ("bag", "topic", "joint_names", "effort")
"""What a ``[[validation]]`` table of a config whose identification log is a ROS 2 bag inherits from it where it does
not state them (a table naming only ``time_range`` scores another stretch of the same bag; one naming another ``bag``
reads it with the identification's topic, joint names and effort)."""


def _estimators_from_old(est: dict) -> str:
    """The ``estimators`` list that says what the old keys ``method``, ``physically_consistent`` and ``methods`` said."""
    methods = [str(m).lower() for m in est.get("methods", [])] if isinstance(est.get("methods"), list) else []
    method = est.get("method")
    first = method if isinstance(method, str) else next((m for m in methods if m in ("ols", "wls")), "wls")
    keys = [first.lower()] + (["sdp"] if est.get("physically_consistent") is True or "sdp" in methods else [])
    keys += [m for m in methods if m not in keys]
    return "[" + ", ".join(f'"{k}"' for k in keys) + "]"


def _drive_gains(table, root: Path, where: str, n: int):
    """The :class:`DriveGainsSettings` of a ``[drive_gains]`` table (typed already), or None."""
    if table is None:
        return None
    specs = []
    for key in ("unloaded", "loaded"):
        spec = dataset_spec(table[key], root, f"{where}.{key}", key, n)
        if "currents" not in spec.signals:
            raise ConfigError(f"{where}.{key}: expected motor currents (a currents column map or a preset with currents)")
        specs.append(spec)
    return DriveGainsSettings(float(table["payload_mass"]), specs[0], specs[1])


def stored_preprocessing(identified: dict, key: str = "preprocessing") -> Preprocessing | None:
    """The identification's resolved preprocessing as results.json stores it.

    Parameters
    ----------
    identified : dict
        The results' ``identification`` section.
    key : str
        ``"preprocessing"`` (the resolved settings) or ``"given_preprocessing"`` (the settings as the config or the
        call gave them, before anything was derived from the log).

    Returns
    -------
    Preprocessing or None
        None if absent.
    """
    stored = identified.get("settings", {}).get(key) if isinstance(identified.get("settings"), dict) else None
    if not isinstance(stored, dict):
        return None
    known = {f.name for f in fields(Preprocessing)}
    try:
        values: dict[str, Any] = {k: (tuple(v) if isinstance(v, list) else v) for k, v in stored.items() if k in known}
        return Preprocessing(**values)
    except TypeError:
        return None


def dataset_for_file(config: IdentificationConfig, file: Path, rows=None) -> DatasetSpec:
    """The identification dataset's column map applied to another log, the whole of it (or ``rows``): the part of the
    identification log its ``rows`` or ``time_range`` select is not carried over.

    Parameters
    ----------
    config : IdentificationConfig
    file : Path
    rows : (first, last), optional
        1-based inclusive rows.

    Returns
    -------
    DatasetSpec

    Raises
    ------
    DataError
        A file that does not exist; a CSV log given for a bag's config or a bag for a CSV's (the reader of the
        identification log reads it: one line, never the identification log under its name); or an identification
        dataset that reads several files (add a [[validation]] table instead).
    """
    spec = config.identification
    file = Path(file)
    if not file.exists():
        raise DataError(f"--file {file}: no such file or bag", field="file")
    if spec.bag is not None:  # read with the identification's bag reader: its topic, joint names, effort
        if not is_bag(file):
            raise DataError(f"--file {file}: the config's logs are ROS bags (bag = ...); expected a bag's folder or its "
                            ".mcap/.db3 file or a ROS 1 .bag, or add a [[validation]] table for a CSV log", field="file")
        return replace(spec, name=file.name, bag=replace(spec.bag, path=file),
                       rows=None if rows is None else tuple(rows), time_range=None)
    if is_bag(file):
        raise DataError(f"--file {file}: a ROS bag, but the config's logs are CSV files; add a [[validation]] table "
                        "with bag = ... for it", field="file")
    files = {s.file for s in spec.signals.values()} | ({spec.time.file} if spec.time else set())
    if len(files) > 1:
        raise DataError("file: the identification dataset reads several files; add a [[validation]] table to the config instead", field="file")
    signals = {k: SignalSpec(file, s.columns, s.scale, s.side) for k, s in spec.signals.items()}
    time = SignalSpec(file, spec.time.columns, spec.time.scale) if spec.time else None  # its unit too
    return replace(spec, name=file.name, signals=signals, time=time,  # the identification's part is not its
                   rows=None if rows is None else tuple(rows), time_range=None)

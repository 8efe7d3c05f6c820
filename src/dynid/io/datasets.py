"""Measured datasets: which columns of which CSV files hold time, positions, velocities, currents or
torques, on which side of the transmission and in which units — and their conversion to SI joint
quantities on a uniform time grid.

A dataset is described by a table of the experiment config (TOML)::

    preset = "ur-rtde"               # optional: fills in the fields below (see PRESETS)
    file = "log.csv"                 # default file of every signal, relative to the data root
    header = false                   # first line holds column names
    rows = [635, 3510]               # 1-based inclusive data rows (header excluded)
    time_range = [6.3, 35.1]         # seconds from the first row read (after rows), inclusive
    gaps = "auto"                    # a time step over 5x the median: "auto" (default: fill up to 20 samples),
                                     # "refuse" or "interpolate" (up to max_gap); empty or NaN
                                     # fields of a signal are filled or refused alike
    time = { column = 1 }            # time stamps [s] (unit = "ms", "us" or "ns" otherwise) …
    rate = 5000.0                    # … or a sampling rate [Hz] when there is no time column
    resample = 100.0                 # Hz: uniform grid for jittered time stamps (default: 1/median step)
    side = "joint"                   # "joint" or "motor" (motor-side values go through the transmission)
    positions = { columns = [2, 3, 4, 5, 6, 7], unit = "rad" }         # or "deg"
    velocities = { columns = [8, 9, 10, 11, 12, 13], unit = "rad/s" }  # optional
    currents = { columns = [14, 15, 16, 17, 18, 19] }  # A; torque = drive gain · current (eq. 16)
    torques = { file = "tau.csv", columns = ["Joint_1", …] }           # N·m, instead of currents
    torques = { columns = [...], sign = -1, scale = [1, 1, 2], side = "motor" }   # as the robot gives them:
                                     # sign and scale (one value or one per joint) multiply the signal;
                                     # side overrides the dataset's for this signal (motor-side torques
                                     # of a log whose positions are joint side go through the gear ratios)
    max_gap = 0.1                    # s: gaps = "interpolate" fills gaps up to this long (default 0.1 s)
    held = "interpolate"             # rows that repeat the previous one exactly (a logger faster than its
                                     # source): replaced by interpolation (default) or "keep"

or a ROS 2 bag of ``sensor_msgs/JointState`` (:mod:`dynid.io.bags`)::

    bag = "run_01"                   # the bag's folder, relative to the data root
    topic = "/joint_states"          # default
    joint_names = ["j1", …]          # default: the robot's joint names
    effort = "torques"               # or "currents" (through the drive gains, eq. 16)

Columns are 1-based numbers or header names. Drive gains multiply currents on the side where they
are measured.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path

import numpy as np

from ..column_store import SPOOL_BYTES, StoredColumns, by_column, select_rows
from ..conventions import MOVING_SPAN, TIME_UNITS, time_unit_of
from ..exceptions import ConfigError, DataError
from ..keywords import keyword_only_after_data
from ..model.robot import Robot
from .columns import csv_table
from .tables import read_table

PRESETS: dict[str, dict] = {
    "ur-rtde": {
        "header": False, "n_columns": 31, "time": {"column": 1}, "side": "joint",
        "positions": {"columns": [2, 3, 4, 5, 6, 7]}, "velocities": {"columns": [8, 9, 10, 11, 12, 13]},
        "currents": {"columns": [14, 15, 16, 17, 18, 19]},
    },
    "ur-rtde-19": {
        "header": False, "n_columns": 19, "time": {"column": 1}, "side": "joint",
        "positions": {"columns": [2, 3, 4, 5, 6, 7]}, "velocities": {"columns": [8, 9, 10, 11, 12, 13]},
        "currents": {"columns": [14, 15, 16, 17, 18, 19]},
    },
    "motor-side": {
        "header": True, "side": "motor",
        "positions": {"columns": ["Joint_1", "Joint_2", "Joint_3", "Joint_4", "Joint_5", "Joint_6"]},
        "torques": {"columns": ["Joint_1", "Joint_2", "Joint_3", "Joint_4", "Joint_5", "Joint_6"]},
    },
}
"""Column maps of common logs: Universal Robots RTDE logs (31 columns: t, q, qd, i, i_target,
tau_target; or the 19-column variant), and motor-side logs with one file per signal and a header
``Joint_1..Joint_6`` but no time column (e.g. the Stäubli TX40 recordings of FIGAROH; give ``rate``)."""

_UNITS = {
    "positions": {"rad": 1.0, "deg": np.pi / 180},
    "velocities": {"rad/s": 1.0, "deg/s": np.pi / 180},
    "currents": {"A": 1.0, "mA": 1e-3},
    "torques": {"N*m": 1.0, "N·m": 1.0, "Nm": 1.0},
}
_SIGNALS = tuple(_UNITS)


@dataclass(frozen=True)
class SignalSpec:
    """Where a signal is and how it converts.

    Attributes
    ----------
    file : Path
    columns : tuple
        Column names or 1-based indices, one per joint.
    scale : float or (n_dof,) array
        The unit's factor times the config's ``sign`` and ``scale``.
    side : str or None
        "joint", "motor", or None: the dataset's.
    """

    file: Path
    columns: tuple
    scale: float | tuple = 1.0
    side: str | None = None


@dataclass(frozen=True)
class DatasetSpec:
    """Where a dataset's signals are and how to read them (see the module docstring).

    Attributes
    ----------
    name : str
    signals : dict
        Signal name (positions, velocities, torques, currents…) -> :class:`SignalSpec`.
    time : SignalSpec or None
        The time stamps' column.
    rate : float or None [Hz]
        When there is no time column.
    resample : float or None [Hz]
        Uniform grid for jittered time stamps (default 1 / median step).
    side : str
        "joint" or "motor" side of the transmission.
    header : bool
        The first line holds column names.
    n_columns : int or None
        Columns every line has.
    rows : (first, last) or None
        1-based inclusive data rows.
    delimiter : str
    time_range : (start, stop) or None [s]
        From the first row read.
    gaps : str
        A time step over 5× the median: "auto" (filled when at most :data:`AUTO_GAP_SAMPLES` samples and
        ``max_gap`` long, refused otherwise), "refuse" or "interpolate" (up to ``max_gap``); missing values (empty
        or NaN fields) are filled or refused alike (:func:`_filled`).
    bag : BagSpec or None
        A ROS 2 bag instead of columns.
    table : str
        The config table it comes from, for messages: ``[identification]``, ``[[validation]] "p3"``.
    max_gap : float [s]
        The longest gap interpolated.
    held : str
        Rows repeating the previous one exactly: "interpolate" or "keep".
    """

    name: str
    signals: dict
    time: SignalSpec | None = None
    rate: float | None = None
    resample: float | None = None
    side: str = "joint"
    header: bool = False
    n_columns: int | None = None
    rows: tuple[int, int] | None = None
    delimiter: str = ","
    time_range: tuple[float, float] | None = None
    gaps: str = "auto"
    bag: BagSpec | None = None
    table: str = ""
    """The config table it comes from, for messages: ``[identification]``, ``[[validation]] "p3"``."""
    max_gap: float = 0.1
    held: str = "interpolate"


@dataclass(frozen=True)
class BagSpec:
    """A ROS 2 bag of ``sensor_msgs/JointState`` messages (read with the rosbags library).

    Attributes
    ----------
    path : Path
        The bag's folder (with metadata.yaml) or its storage file.
    topic : str
    joint_names : tuple of str or None
        The bag's joint names, in the robot's joint order (default: the robot's joint names).
    effort : "torques" or "currents"
        What the messages' ``effort`` holds (currents go through the drive gains, eq. 16).
    """

    path: Path
    topic: str = "/joint_states"
    joint_names: tuple[str, ...] | None = None
    effort: str = "torques"


@dataclass(frozen=True)
class Recording:
    """A measured dataset in SI joint quantities on a uniform time grid. The (N, n_dof) signals are arrays,
    or for a spooled long log :class:`dynid.column_store.StoredColumns` (``t`` is always an array).

    Attributes
    ----------
    name : str
    t : (N,) array [s], uniform
    q : (N, n_dof) [rad], model joint angles (transmission and encoder zeros applied)
    dq : (N, n_dof) [rad/s] or None when not measured
    tau : (N, n_dof) [N·m], joint torques (from currents through the drive gains, eq. 16)
    rate : float [Hz]
    warnings : tuple of str
    source : str
        The files (or bag) it was read from.
    """

    name: str
    t: np.ndarray
    q: np.ndarray
    dq: np.ndarray | None
    tau: np.ndarray
    rate: float
    warnings: tuple[str, ...] = field(default=())
    source: str = ""

    @property
    def n_samples(self) -> int:
        """Number of samples N."""
        return self.t.shape[0]

    @property
    def label(self) -> str:
        """The dataset's name and the files it was read from, for messages: ``"identification (log.csv)"``."""
        return f"{self.name} ({self.source})" if self.source else self.name


def _rows(value, where: str):
    if value is None:
        return None
    if value[1] < value[0]:
        raise ConfigError(f"{where}.rows: expected [first, last] 1-based data rows with first <= last, got {value!r}")
    return (value[0], value[1])


def _time_range(value, where: str):
    if value is None:
        return None
    if not all(np.isfinite(v) for v in value) or value[0] < 0 or value[1] <= value[0]:
        raise ConfigError(f"{where}.time_range: expected [start, stop] in seconds with 0 <= start < stop, got {value!r}")
    return (float(value[0]), float(value[1]))


GAP_FACTOR = 5.0
"""A time step longer than this many median steps is a gap in the log (a lost connection, a pause)."""

AUTO_GAP_SAMPLES = 20
"""With ``gaps = "auto"`` (the default), gaps of at most this many samples are filled by interpolation (a logger
that dropped a few packets), with a warning; a longer one is refused, naming the setting that fills it."""

RESTART_STEPS = 100
"""A time stamp this many typical steps before the one above it starts a second recording, not a glitch of the clock:
the refusal says how to read each (:func:`_increasing`)."""

STALL_STEPS = (0.75, 1.5)
"""Rows that share a time stamp while their values change are taken as evenly spaced up to the next stamp when that
makes their steps this share of the log's mean step (a stalled clock); otherwise the repeat is refused."""

HELD_SHARE = 0.05
"""A log whose rows repeat the previous one exactly this often holds stale samples (a logger faster than its source)."""

SPIKE_SPREADS = 10.0
"""A torque or current sample more than this many times its channel's standard deviation from the median of the five
samples around it is an isolated spike (a logging or bus glitch: no drive applies such a torque and takes it back
within two samples); it is replaced by that median (Hampel's identifier; Pearson 2002). The real logs' largest such
departure is 4.3 channel deviations (the UR10e's resting p2)."""

MIN_RATE = 5.0
"""Hz: a log whose time stamps step slower than this holds them in another unit (milliseconds read as seconds)."""

MIN_SELECTED = 50
"""Samples a ``time_range`` or ``rows`` must select: fewer cannot be filtered and identify nothing."""

STEP_SPEED = 2.0
"""A position step between two samples faster than this many times the joint's velocity limit is a jump of the
encoder, not motion (:func:`_position_step`)."""

STEP_SHARE = 20.0
"""... and than this many times the 99th percentile of the joint's own steps in the log."""

SPIKE_SAMPLES = 5
"""A jump the positions come back from within this many samples is a spike, which the filters pass over; one they stay
at (this many samples before and after it differ by more than the joint can move) is a step (:func:`_position_step`)."""

IMPLAUSIBLE_EFFORT = 1e6
"""|torque| [N·m] or |current| [A] above which a log's value is refused: no robot joint comes near it (the largest
industrial arms' joints carry about 1e5 N·m)."""


def _plausibility(spec: DatasetSpec, robot: Robot, t, q, tau, *, source: str, tau_source: str, warnings: list[str]) -> None:
    """Refuse positions that cannot be radians and implausible efforts, warn about positions outside the joint limits,
    naming joint and time range (a current or torque held at its extreme is found where the log is prepared:
    :func:`dynid.preprocessing.prepared.clipped_samples`)."""
    lim = robot.limits
    worst, outside, still = np.zeros(q.shape[1]), [], []
    for j in range(q.shape[1]):  # one joint at a time, each read once: q may be stored
        column = q[:, j]
        _position_step(column, t, float(lim.dq_max[j]), j, source)
        worst[j] = np.abs(column).max()
        still.append(bool(column.max() == column.min()))
        k = np.flatnonzero((column < lim.q_min[j] - 0.05) | (column > lim.q_max[j] + 0.05))
        outside.append((k.size, k[0] if k.size else 0))
    if np.any(worst > 4 * np.pi):
        j = int(np.argmax(worst))
        raise DataError(f"{source}: joint {j + 1} reaches {worst[j]:.4g} rad, implausible for radians: are the "
                        f"positions in degrees (positions = {{ ..., unit = \"deg\" }})?")
    if all(still):
        raise DataError(f"{source}: no joint's position ever changes ({spec.table or spec.name}): a frozen log, or the "
                        "wrong columns or rows?")
    for j in (j for j, s in enumerate(still) if s and spec.table == "[identification]"):
        warnings.append(f"{source}: joint {j + 1}'s position never changes in [identification] (a joint held still, or "
                        "the wrong column?): what only its motion shows keeps the description's values")
    for j, (count, first) in enumerate(outside):
        if count:
            warnings.append(f"{source}: joint {j + 1} leaves its limits [{lim.q_min[j]:.3g}, {lim.q_max[j]:.3g}] rad "
                            f"during {count} samples from t = {t[first]:.3f} s (units, encoder zero, position_offset?)")
    kind = "currents" if "currents" in spec.signals or (spec.bag is not None and spec.bag.effort == "currents") else "torques"
    for j in range(tau.shape[1]):
        x = tau[:, j]
        peak = np.abs(x).max()
        if peak > IMPLAUSIBLE_EFFORT:
            top = int(np.argmax(np.abs(x)))
            raise DataError(f"{tau_source}: joint {j + 1}'s {kind} reach {x[top]:.4g} at t = {t[top]:.3f} s, implausible for "
                            f"any robot joint (above {IMPLAUSIBLE_EFFORT:.0e}): check the column, its unit and scale")


def check_position_steps(q, t, robot: Robot, source: str) -> None:
    """Refuse a step of a joint's positions that no motion makes and that the positions stay at (an encoder homed
    again, two recordings joined): faster than :data:`STEP_SPEED` times the joint's velocity limit and
    :data:`STEP_SHARE` times its 99th-percentile step in the log, and not undone within :data:`SPIKE_SAMPLES` samples.

    Parameters
    ----------
    q : (N, n_dof) array or StoredColumns [rad]
    t : (N,) array [s]
    robot : Robot
        Its velocity limits (a joint without one is not checked).
    source : str
        The file or dataset, for the message.

    Raises
    ------
    DataError
        Naming the joint, the step and its time, and what to select.
    """
    for j in range(q.shape[1]):
        _position_step(np.asarray(q[:, j], dtype=float), t, float(robot.limits.dq_max[j]), j, source)


def _position_step(column: np.ndarray, t: np.ndarray, limit: float, j: int, source: str) -> None:
    """Refuse a step of a joint's positions that no motion makes and that the positions stay at (an encoder homed
    again, two recordings joined): faster than :data:`STEP_SPEED` times the velocity limit and :data:`STEP_SHARE` times
    the joint's 99th-percentile step, and not undone within :data:`SPIKE_SAMPLES` samples. Its filtered derivative
    would be a torque-sized spike, and the positions on one side of it are off by the step."""
    if not np.isfinite(limit) or limit <= 0 or column.shape[0] < 2 * SPIKE_SAMPLES + 2:
        return
    steps = np.abs(np.diff(column))
    quick = steps > STEP_SPEED * limit * np.diff(t)
    for k in np.flatnonzero(quick & (steps > STEP_SHARE * np.percentile(steps, 99))):
        before, after = max(int(k) - SPIKE_SAMPLES, 0), min(int(k) + 1 + SPIKE_SAMPLES, column.shape[0] - 1)
        if abs(column[after] - column[before]) > STEP_SPEED * limit * (t[after] - t[before]):
            end = int(k) + 1  # the step's samples: a resampled log spreads it over two
            while end < quick.shape[0] and quick[end]:
                end += 1
            raise DataError(f"{source}: joint {j + 1}'s position steps by {column[end] - column[k]:.4g} rad at t = "
                            f"{t[k + 1]:.3f} s and stays there, faster than the joint moves (limit {limit:.3g} rad/s): "
                            "an encoder homed again, or two recordings joined? select rows or time_range on one side "
                            "of it")


def _detected(log: Path, robot: Robot) -> DatasetSpec:
    """The dataset of a CSV log, its columns found as ``dynid init`` finds them (:func:`dynid.io.columns.csv_table`)."""
    if not log.is_file():
        raise DataError(f"{log}: no such log")
    table, _ = csv_table(Path("robot.urdf"), log, robot.n_dof, tuple(j.name for j in robot.joints))
    return dataset_spec(tomllib.loads("\n".join(table)), log.parent, str(log), log.stem, robot.n_dof)


def dataset_spec(table: dict, base: Path, where: str, name: str, n_dof: int) -> DatasetSpec:
    """Parse a dataset table of a config (module docstring; its structure:
    :class:`dynid.io.config_types.DatasetTable`); paths are relative to ``base``.

    Parameters
    ----------
    table : dict
        The table as the TOML gave it.
    base : Path
        The data root.
    where : str
        ``"<config file>: <table>"``, for the messages.
    name : str
        The dataset's name when the table gives none.
    n_dof : int
        The robot's joints (one column each).

    Returns
    -------
    DatasetSpec

    Raises
    ------
    ConfigError
        Unknown preset, unit or side, a missing signal or file, a column list of the wrong length;
        the message names the config field.
    """
    from ..typed import convert
    from .config_types import DatasetTable

    source, _, inside = where.rpartition(": ")
    if not isinstance(table, dict):
        convert(table, DatasetTable, source or where, inside if source else "")  # says what was expected
    preset = table.get("preset")
    merged: dict = {}
    if isinstance(preset, str):  # the preset's fields first, the table's on top (the merged table is checked below)
        if preset not in PRESETS:
            raise ConfigError(f"{where}.preset: unknown preset {preset!r}, expected one of {', '.join(PRESETS)}")
        merged.update({k: (dict(v) if isinstance(v, dict) else v) for k, v in PRESETS[preset].items()})
    for k, v in table.items():
        if isinstance(v, dict) and isinstance(merged.get(k), dict):
            merged[k] = {**merged[k], **v}
        else:
            merged[k] = v
    t = convert(merged, DatasetTable, source or where, inside if source else "")
    if t.bag is not None:
        return _bag_spec(t, base, where, name, n_dof)
    for key in ("topic", "joint_names", "effort"):
        if getattr(t, key) is not None:
            raise ConfigError(f"{where}.{key}: only for a dataset read from a ROS 2 bag (bag = \"folder\")")

    def path_of(f: str | None, w: str) -> Path:
        f = f if f is not None else t.file
        if not f:
            raise ConfigError(f"{w}: expected a 'file' (here or for the whole dataset)")
        p = Path(f)
        return p if p.is_absolute() else base / p

    signals = {}
    for kind in _SIGNALS:
        sig = getattr(t, kind)
        if sig is None or sig is False:  # velocities = false: none (a preset's left out)
            continue
        w = f"{where}.{kind}"
        if sig is True:
            raise ConfigError(f"{w}: expected a table with 'columns', or false for none (derived from the positions)")
        if sig.columns is None:
            raise ConfigError(f"{w}: expected a table with 'columns' (1-based numbers or header names)")
        if sig.sensor is not None and kind != "torques":
            raise ConfigError(f"{w}.sensor: only the torques have a sensor (joint or drive), got it on the {kind}")
        if len(sig.columns) != n_dof:
            raise ConfigError(f"{w}.columns: expected {n_dof} columns (one per joint), got {sig.columns!r}")
        units = _UNITS[kind]
        unit = sig.unit if sig.unit is not None else next(iter(units))
        if unit not in units:
            raise ConfigError(f"{w}.unit: expected one of {', '.join(units)}, got {unit!r}")
        factor = np.full(n_dof, units[unit])
        for key in ("sign", "scale"):
            v = getattr(sig, key)
            if v is None:
                continue
            many = isinstance(v, list)
            values = v if many else [v]
            ok = all(np.isfinite(x) and x != 0 for x in values) and (key != "sign" or all(x in (1, -1) for x in values))
            if not ok or (many and len(v) != n_dof):
                what = "1 or -1" if key == "sign" else "a non-zero number"
                raise ConfigError(f"{w}.{key}: expected {what} or a list of {n_dof} of them (one per joint), got {v!r}")
            factor = factor * np.asarray(values, dtype=float)
        scale = float(factor[0]) if np.all(factor == factor[0]) else tuple(float(x) for x in factor)
        signals[kind] = SignalSpec(path_of(sig.file, w), tuple(sig.columns), scale, sig.side)
    if "positions" not in signals:
        raise ConfigError(f"{where}: expected 'positions' (columns of the joint or motor angles)")
    if ("currents" in signals) == ("torques" in signals):
        raise ConfigError(f"{where}: expected exactly one of 'currents' (with drive gains) or 'torques'")
    time = None if t.time is None else SignalSpec(
        path_of(t.time.file, f"{where}.time"), (t.time.column,) + (() if t.time.nanoseconds is None else (t.time.nanoseconds,)),
        TIME_UNITS[t.time.unit or "s"] if t.time.nanoseconds is None else (TIME_UNITS[t.time.unit or "s"], 1e-9))
    if (time is None) == (t.rate is None):
        raise ConfigError(f"{where}: expected either a 'time' column or a sampling 'rate' [Hz]")
    return DatasetSpec(
        name=str(t.name if t.name is not None else name), signals=signals, time=time,
        rate=None if t.rate is None else float(t.rate), resample=None if t.resample is None else float(t.resample),
        side=t.side or "joint", header=bool(t.header), n_columns=t.n_columns,
        rows=_rows(t.rows, where), delimiter=t.delimiter if t.delimiter is not None else ",",
        time_range=_time_range(t.time_range, where), gaps=t.gaps or "auto",
        table=_table_name(where), max_gap=float(t.max_gap) if t.max_gap is not None else 0.1, held=t.held or "interpolate")


def _table_name(where: str) -> str:
    """The config table of a dataset, from the ``where`` of its messages (``"c.toml: validation[2]"``)."""
    part = where.split(": ")[-1]
    if part.startswith("validation["):
        return f"[[validation]] {int(part[11:-1]) + 1}"
    if part.startswith("drive_gains."):
        return f"[{part}]"
    return f"[{part}]"


def _bag_spec(t, base: Path, where: str, name: str, n_dof: int) -> DatasetSpec:
    """A dataset read from a ROS 2 bag: ``bag = "folder"``, optional ``topic``, ``joint_names``, ``effort``."""
    extra = [k for k in ("file", "header", "n_columns", "delimiter", "rows", "time", "rate", "max_gap", "held", *_SIGNALS)
             if getattr(t, k) is not None]
    if extra:
        raise ConfigError(f"{where}: field(s) {extra} do not apply to a ROS 2 bag; expected some of bag, topic, joint_names, "
                          "effort, side, resample, time_range, gaps, name")
    path = Path(t.bag) if Path(t.bag).is_absolute() else base / t.bag
    if t.joint_names is not None and len(t.joint_names) != n_dof:
        raise ConfigError(f"{where}.joint_names: expected {n_dof} joint names, got {t.joint_names!r}")
    return DatasetSpec(name=str(t.name if t.name is not None else name), signals={}, side=t.side or "joint",
                       resample=None if t.resample is None else float(t.resample),
                       time_range=_time_range(t.time_range, where), gaps=t.gaps or "auto",
                       bag=BagSpec(path, t.topic or "/joint_states", None if t.joint_names is None else tuple(t.joint_names),
                                   t.effort or "torques"))


@keyword_only_after_data
def load_recording(spec: DatasetSpec | str | Path, robot: Robot, *, spool: bool | None = None) -> Recording:
    """Read a dataset and convert it to SI joint quantities on a uniform time grid.

    Steps: read the columns (:func:`dynid.io.tables.read_table`) or the ROS 2 bag's JointState messages, scale
    units, check the time stamps, resample jittered time stamps linearly onto a uniform grid, convert motor-side
    signals through the transmission (``q = R⁻¹ theta_m + offset``, ``tau = Rᵀ tau_m``), currents to torques with the
    drive gains (eq. 16).

    Parameters
    ----------
    spec : DatasetSpec, or a log's path
        A dataset of a config; or a CSV log whose columns are found as ``dynid init`` finds them (a header naming
        time, positions and torques or currents).
    robot : Robot
    spool : bool, optional
        Hold the signals in temporary files (:mod:`dynid.column_store`) rather than in memory; by default when the
        files hold more than :data:`dynid.column_store.SPOOL_BYTES` (an hour-long log). The numbers are the same
        either way.

    Returns
    -------
    Recording

    Raises
    ------
    DataError
        Unreadable or damaged files, non-increasing time stamps (names file and line), files of different lengths,
        implausible values, a log whose columns cannot be told.
    TypeError
        Neither a dataset nor a path (one line saying what was given).
    """
    if isinstance(spec, (str, Path)):
        spec = _detected(Path(spec), robot)
    elif not isinstance(spec, DatasetSpec):
        raise TypeError(f"load_recording: expected a log's path or a DatasetSpec (a config's dataset), got "
                        f"{type(spec).__name__}")
    warnings: list[str] = []
    if spec.bag is not None:
        from .bags import read_joint_states

        t, raw, where = read_joint_states(spec.bag, robot, spec.name, warnings)
        return _assemble(spec, robot, t, raw, where, timed=True, q_source=str(spec.bag.path),
                         tau_source=str(spec.bag.path), warnings=warnings)
    requests: dict[Path, list] = {}
    for s in list(spec.signals.values()) + ([spec.time] if spec.time else []):
        requests.setdefault(s.file, [])
        for c in s.columns:
            if c not in requests[s.file]:
                requests[s.file].append(c)
    if spool is None:
        spool = sum(p.stat().st_size for p in requests if p.is_file()) > SPOOL_BYTES
    tables = {}
    for path, cols in requests.items():
        table = read_table(path, cols, header=spec.header, delimiter=spec.delimiter, n_columns=spec.n_columns, rows=spec.rows,
                           spool=spool, missing=True)
        tables[path] = (table, cols)
        warnings.extend(table.warnings)
    del table
    lengths = {p: tb.data.shape[0] for p, (tb, _) in tables.items()}
    n_s = min(lengths.values())
    if len(set(lengths.values())) > 1:
        if not warnings:  # only a skipped truncated line may make the files differ
            raise DataError(f"{spec.name}: files have different numbers of rows: " + ", ".join(f"{p} {n}" for p, n in lengths.items()))
        warnings.append(f"{spec.name}: the files are cut to the shortest one ({n_s} rows)")

    def get(s: SignalSpec) -> np.ndarray | StoredColumns:
        tb, cols = tables[s.file]
        scale = np.broadcast_to(np.asarray(s.scale, dtype=float), (len(s.columns),))
        if isinstance(tb.data, StoredColumns):  # a view of the stored columns; scaled into new ones
            x = tb.data.select([cols.index(c) for c in s.columns], n_s)
            return x if np.all(scale == 1.0) else x.map_columns(lambda column, j: column * scale[j])
        block = tb.data[:n_s, [cols.index(c) for c in s.columns]]  # a copy of its own: scaled in place
        if np.any(scale != 1.0):
            block *= scale
        return block

    if spec.time is not None:
        stamps = np.asarray(get(spec.time), dtype=float)
        # seconds and nanoseconds in two columns: summed from the first second on (float64 keeps the nanoseconds)
        t = stamps[:, 0] if stamps.shape[1] == 1 else (stamps[:, 0] - stamps[0, 0]) + stamps[:, 1]
        first_line = tables[spec.time.file][0].first_line
        where = lambda k: f"{spec.time.file}: line {first_line + k}"  # noqa: E731 - sample k's place in the file
        if np.isnan(t).any():
            raise DataError(f"{where(int(np.argmax(np.isnan(t))))}: the time stamp is missing (an empty or NaN field)")
    else:
        t = np.arange(n_s) / spec.rate
        where = None
    raw = {kind: get(s) for kind, s in spec.signals.items()}
    tables.clear()  # the files' columns are in t and raw now: a long log is not held twice
    tau_kind = "currents" if "currents" in spec.signals else "torques"
    return _assemble(spec, robot, t, raw, where, timed=spec.time is not None, q_source=str(spec.signals["positions"].file),
                     tau_source=str(spec.signals[tau_kind].file), warnings=warnings)


def _increasing(spec: DatasetSpec, t, raw: dict, where, warnings: list[str]):
    """Time stamps that increase: a row that repeats the previous one, time stamp and every value, is a sample written
    twice and dropped (said); any other time stamp that does not increase is refused, naming its place."""
    steps = np.diff(t)
    if not np.any(steps <= 0):
        return t, raw, where
    k = np.flatnonzero(steps == 0)
    twice = k[np.all([np.all(np.asarray(select_rows(x, k + 1)) == np.asarray(select_rows(x, k)), axis=1)
                      for x in raw.values()], axis=0)] + 1
    if twice.size:
        keep = np.ones(t.shape[0], dtype=bool)
        keep[twice] = False
        t, raw = t[keep], {kind: select_rows(x, keep) for kind, x in raw.items()}
        where = (lambda w, rows: (lambda i: w(int(rows[i]))))(where, np.flatnonzero(keep))
        warnings.append(f"{spec.name}: {twice.size} row(s) repeat the previous one, time stamp and every value (a "
                        "sample written twice): dropped")
        steps = np.diff(t)
    if np.any(steps == 0) and not np.any(steps < 0):
        t = _stalled_clock(spec, t, steps, warnings)
        steps = np.diff(t)
    if np.any(steps <= 0):
        i = int(np.argmax(steps <= 0))
        what = "a repeated time stamp" if t[i + 1] == t[i] else "time going back"
        typical = float(np.median(steps[steps > 0])) if np.any(steps > 0) else 0.0
        again = (t[i] - t[i + 1] > RESTART_STEPS * typical
                 and "; two recordings one after the other? give each its own file, or select one with rows")
        raise DataError(f"{where(i + 1)}: time stamps must increase, got {what}: {float(t[i + 1]):.9g} s after "
                        f"{float(t[i]):.9g} s{again or ''}")
    return t, raw, where


def _stalled_clock(spec: DatasetSpec, t, steps, warnings: list[str]):
    """Runs of rows whose time stamp repeats while their values change (a clock that stalled, or stamps written
    coarser than the samples) spread evenly from their stamp to the next one, when that puts their steps within
    :data:`STALL_STEPS` of the log's mean step; otherwise ``t`` is returned unchanged and the caller refuses the first
    repeat, naming its line."""
    n = t.shape[0]
    same = steps == 0
    a = np.flatnonzero(same & ~np.r_[False, same[:-1]])  # each run's first row
    b = np.flatnonzero(same & ~np.r_[same[1:], False]) + 1  # ... and its last
    k = b - a + 1
    typical = float(t[-1] - t[0]) / (n - 1)
    after = np.where(b + 1 < n, t[np.minimum(b + 1, n - 1)], t[a] + k * typical)  # the last run: the mean step
    step = (after - t[a]) / k
    low, high = STALL_STEPS
    if typical <= 0 or np.any((step < low * typical) | (step > high * typical)):
        return t
    place = np.arange(int(k.sum())) - np.repeat(np.cumsum(k) - k, k)
    t = np.array(t, dtype=float)
    t[np.repeat(a, k) + place] = np.repeat(t[a], k) + place * np.repeat(step, k)
    warnings.append(f"{spec.name}: {int((k - 1).sum())} time stamp(s) in {a.size} run(s) repeat the one before while "
                    "the values change (a stalled or coarse clock): spread evenly to the next time stamp")
    return t


def _filled(spec: DatasetSpec, t, raw: dict, where, warnings: list[str]):
    """Missing values (empty or NaN fields: signals logged at other times than the rows, as a log merging topics has
    them) filled by interpolation in time between the column's own values, as ``spec.gaps`` fills gaps in time: "auto"
    up to :data:`AUTO_GAP_SAMPLES` missing in a row, "interpolate" up to ``max_gap`` seconds, "refuse" none. Rows before
    every signal has started or after one has stopped are dropped; the warning says how many of each."""
    holes = {kind: [j for j in range(x.shape[1]) if np.isnan(x[:, j]).any()] for kind, x in raw.items()}
    if not any(holes.values()):
        return t, raw, where
    table = spec.table or spec.name
    n, a, b = t.shape[0], 0, t.shape[0]  # from the row where every signal has started to the one after the first stops
    for kind, columns in holes.items():
        for j in columns:
            held = np.flatnonzero(~np.isnan(raw[kind][:, j]))
            if held.size < 2:
                raise DataError(f"{spec.name}: joint {j + 1}'s {kind} hold {held.size} value(s), the rest empty or NaN: "
                                "are the columns right?")
            a, b = max(a, int(held[0])), min(b, int(held[-1]) + 1)
    if b - a < 2:
        raise DataError(f"{spec.name}: the signals' values do not overlap in time (empty or NaN fields elsewhere): are "
                        "the columns right?")
    count = 0
    for kind, columns in holes.items():
        for j in columns:
            gone = np.isnan(raw[kind][:, j])
            gone[:a], gone[b:] = False, False  # rows dropped: not filled
            count += int(gone.sum())
            _check_missing(spec, t, gone, f"joint {j + 1}'s {kind}", where, table)

    def fill(column: np.ndarray, j: int, kind: str) -> np.ndarray:
        if j not in holes[kind]:
            return column
        gone = np.isnan(column)
        return np.where(gone, np.interp(t, t[~gone], column[~gone]), column)

    raw = {kind: by_column(x, partial(fill, kind=kind)) if holes[kind] else x
           for kind, x in raw.items()}  # between the values either side, then the rows kept
    if a or b < n:
        t, raw = t[a:b], {kind: x[a:b] for kind, x in raw.items()}
        where = where if where is None or not a else (lambda w, f: (lambda k: w(k + f)))(where, a)
    named = "; ".join(f"{kind} of joint{'s' if len(c) > 1 else ''} {', '.join(str(j + 1) for j in c)}"
                      for kind, c in holes.items() if c)
    after = n - b
    dropped = f"; {a} row(s) before every signal started and {after} after one stopped dropped" if a or after else ""
    warnings.append(f"{spec.name}: {count} missing value(s) (empty or NaN fields) in {named}: filled by interpolation "
                    f"in time between each column's own values (gaps = \"{spec.gaps}\" in {table}; \"refuse\" refuses "
                    f"them){dropped}")
    return t, raw, where


def _check_missing(spec: DatasetSpec, t, gone: np.ndarray, what: str, where, table: str) -> None:
    """Refuse a column's missing values where ``spec.gaps`` does not fill them (:func:`_filled`), naming the longest
    run."""
    if not gone.any():
        return
    edges = np.diff(np.concatenate([[0], gone.astype(np.int8), [0]]))
    starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    i = int(np.argmax(stops - starts))
    k, n = int(starts[i]), int(stops[i] - starts[i])
    span = float(t[min(k + n, t.shape[0] - 1)] - t[max(k - 1, 0)])
    place = where(k) if where is not None else f"{spec.name}: sample {k + 1}"
    if spec.gaps == "refuse":
        raise DataError(f"{place}: {what} are missing (an empty or NaN field); gaps = \"refuse\" in {table} refuses "
                        f"filling it; \"auto\" fills up to {AUTO_GAP_SAMPLES} in a row by interpolation")
    if spec.gaps == "auto" and n > AUTO_GAP_SAMPLES:
        raise DataError(f"{place}: {what} are missing for {n} rows in a row ({span:.3g} s), more than the "
                        f"{AUTO_GAP_SAMPLES} dynid fills by itself; set gaps = \"interpolate\" in {table} to fill up "
                        f"to max_gap = {spec.max_gap:g} s, or select rows without it")
    if spec.gaps == "interpolate" and span > spec.max_gap:
        raise DataError(f"{place}: {what} are missing for {span:.3g} s ({n} rows), longer than max_gap = "
                        f"{spec.max_gap:g} s in {table}; select rows without it, or raise max_gap")


def _in_time_range(spec: DatasetSpec, t, raw: dict, where, warnings: list[str]):
    """The samples in ``spec.time_range`` (seconds from the first sample), checked."""
    assert spec.time_range is not None
    start, stop = spec.time_range
    inside = (t - t[0] >= start - 1e-9) & (t - t[0] <= stop + 1e-9)
    if inside.sum() < 2:
        raise DataError(f"{spec.name}: time_range [{start:g}, {stop:g}] s holds fewer than 2 samples of the "
                        f"{t[-1] - t[0]:.3f} s recording")
    if stop > t[-1] - t[0] + 1.0 / (spec.rate or 1.0 / float(np.median(np.diff(t)))):
        warnings.append(f"{spec.name}: time_range ends at {stop:g} s, after the recording's end at "
                        f"{t[-1] - t[0]:.3f} s")
    first = int(np.argmax(inside))
    t, raw = t[inside], {kind: select_rows(x, inside) for kind, x in raw.items()}
    if where is not None:
        where = (lambda w, f: (lambda k: w(k + f)))(where, first)
    return t, raw, where


def _check_clock_unit(step: float, source: str, table: str) -> None:
    """Refuse time stamps ``step`` seconds apart when that is slower than any robot controller logs
    (:data:`MIN_RATE`): they hold another unit, which the message guesses."""
    if 1.0 / step >= MIN_RATE:
        return
    unit = time_unit_of(step)
    guess = f"they look like {unit} (time = {{ ..., unit = \"{unit}\" }})" if unit else "another unit?"
    raise DataError(f"{source}: the time stamps step by {step:.4g} s ({1.0 / step:.4g} Hz), slower than any robot "
                    f"controller logs (at least {MIN_RATE:g} Hz): {guess}; dynid reads seconds unless the time "
                    f"column's unit says otherwise, or give rate (Hz) in {table} instead of the time column")


def _assemble(spec: DatasetSpec, robot: Robot, t, raw: dict, where, *, timed: bool, q_source: str, tau_source: str,
              warnings: list[str]) -> Recording:
    """Time checks, selection, gaps, resampling, transmission, drive gains and plausibility, shared by every
    kind of dataset; ``where(k)`` names sample k's place in the source (file and line, bag and message)."""
    n_s = t.shape[0]
    if n_s < 2:
        raise DataError(f"{spec.name}: expected at least 2 samples, got {n_s}")
    if timed:
        t, raw, where = _increasing(spec, t, raw, where, warnings)
    if spec.time_range is not None:
        t, raw, where = _in_time_range(spec, t, raw, where, warnings)
    t, raw, where = _filled(spec, t, raw, where, warnings)
    side = lambda kind: (spec.signals[kind].side if kind in spec.signals else None) or spec.side  # noqa: E731
    if "positions" in raw and side("positions") != "motor":  # a motor may turn near a whole turn between samples
        raw["positions"] = unwrapped_positions(raw["positions"], spec.name, warnings)
    raw = _held_rows(spec, t, raw, warnings)
    raw = _despiked(spec, raw, warnings)
    if (spec.time_range is not None or spec.rows is not None) and t.size < MIN_SELECTED:
        which, value = ("time_range", list(spec.time_range)) if spec.time_range is not None else ("rows", list(spec.rows or ()))
        raise DataError(f"{spec.table or spec.name}: {which} = {value} selects {t.size} samples; at least {MIN_SELECTED} "
                        f"are needed: widen it")
    median = float(np.median(np.diff(t)))
    table = spec.table or spec.name
    if timed and spec.resample is None:  # before the gaps: a log in milliseconds has its gaps in seconds
        _check_clock_unit(median, q_source, table)
    if timed:
        steps = np.diff(t)
        gaps = np.flatnonzero(steps > GAP_FACTOR * median)
        if gaps.size and spec.gaps == "auto" and float(steps[gaps].max()) > AUTO_GAP_SAMPLES * median:
            k = int(gaps[np.argmax(steps[gaps])])
            raise DataError(f"{where(k + 1)}: a gap of {steps[k]:.3g} s in the time stamps (median step {median:.3g} s, "
                            f"{steps[k] / median:.0f} samples) after the time stamp {float(t[k]):.6g} s ({t[k] - t[0]:.3f} s "
                            f"into the selected rows), longer than the {AUTO_GAP_SAMPLES} samples dynid fills by itself; set "
                            f"gaps = \"interpolate\" in {table} to fill gaps up to max_gap = {spec.max_gap:g} s, or select "
                            "rows on one side of it")
        if gaps.size and spec.gaps == "refuse":
            k = int(gaps[0])
            raise DataError(f"{where(k + 1)}: a gap of {steps[k]:.3g} s in the time stamps (median step {median:.3g} s) after "
                            f"the time stamp {float(t[k]):.6g} s ({t[k] - t[0]:.3f} s into the selected rows); set gaps = "
                            f"\"interpolate\" in {table} to fill gaps up to max_gap = {spec.max_gap:g} s, or select rows "
                            "on one side of it")
        if gaps.size:
            k = int(gaps[np.argmax(steps[gaps])])
            if steps[k] > spec.max_gap:
                raise DataError(f"{where(k + 1)}: a gap of {steps[k]:.3g} s in the time stamps after {t[k] - t[0]:.3f} s of "
                                f"the selected rows is longer than max_gap = {spec.max_gap:g} s, the most gaps = \"interpolate\" "
                                f"fills with invented samples; select rows on one side of it, or raise max_gap in {table}")
            warnings.append(f"{spec.name}: {gaps.size} gap(s) in the time stamps filled by interpolation, the longest "
                            f"{steps[k]:.3g} s after {t[k] - t[0]:.3f} s (gaps = \"{spec.gaps}\" in {table}; \"refuse\" "
                            "refuses them)")
    uniform = not timed or np.ptp(np.diff(t)) <= 1e-6 * median
    rate = float(spec.rate or 0.0) if not timed else (spec.resample or uniform_rate(t))
    if timed and spec.resample is None:
        _check_clock_unit(1.0 / rate, q_source, table)
    if timed and (not uniform or spec.resample is not None):
        t, raw = resampled(t, raw, rate)
    tr = robot.transmission
    if side("positions") == "motor":  # popped: each raw signal is released as soon as its joint-side one exists
        q = _row_wise(tr.joint_positions, raw.pop("positions"))
    else:
        q = _per_joint(np.add, raw.pop("positions"), tr.position_offset)
    if "velocities" in raw and side("velocities") == "motor":
        dq = _row_wise(tr.joint_velocities, raw.pop("velocities"))
    else:
        dq = raw.pop("velocities", None)
    dq = logged_velocities(q, dq, spec.name, warnings)
    kind = "currents" if "currents" in raw else "torques"
    if kind == "currents":
        motor_or_joint = _per_joint(np.multiply, raw["currents"], robot.drive_gains)
    else:
        motor_or_joint = raw["torques"]
    tau = _row_wise(tr.joint_torques, motor_or_joint) if side(kind) == "motor" else motor_or_joint
    _plausibility(spec, robot, t - t[0], q, raw["currents"] if "currents" in raw else raw["torques"], source=q_source,
                  tau_source=tau_source, warnings=warnings)
    source = str(spec.bag.path) if spec.bag is not None else ", ".join(sorted({str(s.file) for s in spec.signals.values()}))
    return Recording(spec.name, t - t[0], q, dq, tau, float(rate), tuple(warnings), source)


def logged_velocities(q, dq, name: str, warnings: list[str]):
    """The measured velocities, or None where a joint's hold one value throughout while its positions span more than
    :data:`MOVING_SPAN` (a logger writing 0 for a field it does not fill): a model fitted with them would have
    that joint's velocity-dependent terms wrong, so every joint's are left out and derived from the positions, said.

    Parameters
    ----------
    q : (N, n_dof) array or StoredColumns [rad]
    dq : (N, n_dof) array or StoredColumns [rad/s], or None
    name : str
        The dataset, for the warning.
    warnings : list of str
        Gets one line naming the joints, if any.

    Returns
    -------
    (N, n_dof) array or StoredColumns [rad/s], or None
        ``dq`` itself, or None where it is left out.
    """
    if dq is None:
        return None
    dead, values, spans = [], set(), []
    for j in range(q.shape[1]):  # one joint at a time: the columns may be stored
        v = dq[:, j]
        if v.max() == v.min():
            x = q[:, j]
            span = float(x.max() - x.min())
            if span > MOVING_SPAN:
                dead.append(j + 1)
                values.add(f"{float(v[0]):.4g}")
                spans.append(span)
    if not dead:
        return dq
    who = f"joint {dead[0]}'s" if len(dead) == 1 else f"joints {', '.join(map(str, dead))}'"
    warnings.append(f"{name}: {who} measured velocities read {' or '.join(sorted(values))} rad/s throughout while "
                    f"the positions span up to {max(spans):.3g} rad (a velocity channel not logged?): every joint's "
                    "velocities are left out and derived from the positions")
    return None


def uniform_rate(t: np.ndarray) -> float:
    """The rate of a uniform grid for time stamps: one over their median step, to 6 digits.

    Parameters
    ----------
    t : (N,) array [s]

    Returns
    -------
    float [Hz]
    """
    return float(f"{1.0 / float(np.median(np.diff(t))):.6g}")


def resampled(t: np.ndarray, signals: dict, rate: float) -> tuple[np.ndarray, dict]:
    """Signals at jittered time stamps linearly interpolated onto a uniform grid from ``t[0]`` at ``rate``.

    Parameters
    ----------
    t : (N,) array [s]
        Increasing time stamps.
    signals : dict
        name -> (N, n) array (or stored columns).
    rate : float [Hz]

    Returns
    -------
    grid : (M,) array [s]
    signals : dict
        name -> (M, n) array.
    """
    grid = t[0] + np.arange(int(np.floor((t[-1] - t[0]) * rate + 1e-9)) + 1) / rate
    return grid, {kind: by_column(x, lambda column, j: np.interp(grid, t, column)) for kind, x in signals.items()}


WRAP_TOLERANCE = 0.5
"""[rad] A step between two samples of a joint's position within this of a whole turn (2π) is the angle wrapped to one
turn (a continuous joint logged in [-π, π)), not a motion: no joint turns that far in one sample."""


def unwrapped_positions(x, name: str, warnings: list[str]):
    """Positions with every step of a whole turn (:data:`WRAP_TOLERANCE`) taken back: an angle logged within one turn
    (a continuous joint in [-π, π)) runs on. The dynamics of a revolute joint repeat every turn; filtering,
    resampling and differentiation do not.

    Parameters
    ----------
    x : (N, n_dof) array or StoredColumns [rad]
    name : str
        The dataset, for the warning.
    warnings : list of str
        Gets one line naming each joint taken back and how often, if any.

    Returns
    -------
    (N, n_dof) array or StoredColumns [rad]
        ``x`` itself where no step is a whole turn.
    """
    if not any(_turns(np.asarray(x[:, j], dtype=float)).any() for j in range(x.shape[1])):
        return x  # stored columns are read, not written again
    said = []

    def unwrap(column: np.ndarray, j: int) -> np.ndarray:
        turns = _turns(column)
        if not turns.any():
            return column
        jumps = np.count_nonzero(turns)
        said.append(f"joint {j + 1}: {jumps} jump{'s' if jumps > 1 else ''}")
        return column - 2 * np.pi * np.concatenate([[0.0], np.cumsum(turns)])

    out = by_column(x, unwrap)
    warnings.append(f"{name}: positions jump by a whole turn (2π) between two samples, an angle logged within one "
                    f"turn: taken back so that they run on ({'; '.join(said)})")
    return out


def _turns(column: np.ndarray) -> np.ndarray:
    """The whole turns each step of a position column wraps by (0 for a step that is not a whole turn)."""
    steps = np.diff(column)
    turns = np.round(steps / (2 * np.pi))
    return np.where(np.abs(steps - 2 * np.pi * turns) <= WRAP_TOLERANCE, turns, 0.0)


def _despiked(spec: DatasetSpec, raw: dict, warnings: list[str]) -> dict:
    """The torques or currents with their isolated spikes (:data:`SPIKE_SPREADS`) replaced by the median of the five
    samples around each, and a warning per channel that had any: the dataset, the joint, how many and the largest.
    Only a log with spikes is copied (a long log's stored columns are read once, not written again)."""
    kind = "currents" if "currents" in raw else "torques"
    if kind not in raw:
        return raw
    x = raw[kind]
    found = {j: hit for j in range(x.shape[1]) if (hit := _spikes(np.asarray(x[:, j], dtype=float))) is not None}
    if not found:
        return raw

    def mended(values: np.ndarray, j: int) -> np.ndarray:
        if j not in found:
            return values
        out = np.array(values, dtype=float)
        out[found[j][0]] = found[j][1]
        return out

    fixed = by_column(x, mended)
    unit = "A" if kind == "currents" else "N·m"
    for j, (where, _, largest) in sorted(found.items()):
        warnings.append(f"{spec.name}: J{j + 1}'s {kind[:-1]} has {where.size} isolated spike(s), up to {largest:.4g} "
                        f"{unit} from the samples around them (over {SPIKE_SPREADS:g}× the channel's standard deviation): "
                        "each replaced by the median of the five samples around it")
    return {**raw, kind: fixed}


def _spikes(x: np.ndarray) -> tuple[np.ndarray, np.ndarray, float] | None:
    """A channel's isolated spikes (:data:`SPIKE_SPREADS`): their indices, the medians that replace them and the largest
    departure; None where there are none."""
    if x.size < 5 or np.mean(x == np.median(x)) >= 0.5:
        return None  # mostly one value (dead, at a limit, a quantised rest): its deviation says nothing of a spike
    with np.errstate(over="ignore", invalid="ignore"):  # a value of 1e300 is refused later, by the plausibility check
        limit = SPIKE_SPREADS * float(np.std(x))
    if not 0 < limit < np.inf:
        return None
    # a sample that far from the median of its five has a neighbour that far from it: check those only
    step = np.abs(np.diff(x)) > limit
    near = np.flatnonzero(np.concatenate([[False], step]) | np.concatenate([step, [False]]))
    near = near[(near >= 2) & (near < x.size - 2)]
    if near.size == 0:
        return None
    median = np.median(np.stack([x[near + k] for k in range(-2, 3)]), axis=0)
    departure = np.abs(x[near] - median)
    spikes = departure > limit
    if not spikes.any():
        return None
    return near[spikes], median[spikes], float(departure[spikes].max())


def _held_rows(spec: DatasetSpec, t, raw: dict, warnings: list[str]) -> dict:
    """Rows whose every signal repeats the previous row exactly are stale samples (a logger that ran faster than its
    source): with ``held = "interpolate"``, when they are at least :data:`HELD_SHARE` of the rows, they are replaced
    by linear interpolation in time between the fresh rows around them; the warning says how many."""
    signals = [x for x in raw.values()]
    n = t.shape[0]
    if n < 3 or any(isinstance(x, StoredColumns) for x in signals):
        return raw
    same = np.ones(n - 1, dtype=bool)
    for x in signals:
        same &= np.all(x[1:] == x[:-1], axis=1)
    held = np.concatenate([[False], same])
    share = held.mean()
    if share < HELD_SHARE or share > 0.5:  # a log mostly of repeated rows is frozen, not stale now and then
        return raw
    table = spec.table or spec.name
    if spec.held == "keep":
        warnings.append(f"{spec.name}: {held.sum()} rows ({100 * share:.0f} %) repeat the previous one exactly (stale samples "
                        f"of a logger faster than its source), kept as they are (held = \"keep\" in {table})")
        return raw
    fresh = ~held
    warnings.append(f"{spec.name}: {held.sum()} rows ({100 * share:.0f} %) repeat the previous one exactly (stale samples of a "
                    f"logger faster than its source): replaced by interpolation between the fresh rows (held = \"keep\" in "
                    f"{table} keeps them)")
    return {kind: np.column_stack([np.interp(t, t[fresh], x[fresh, j]) for j in range(x.shape[1])]) for kind, x in raw.items()}


def _row_wise(f, x):
    """``f(x)`` for a map that treats each sample alone (a transmission), chunk by chunk on stored columns."""
    return x.map_rows(f) if isinstance(x, StoredColumns) else f(x)


def _per_joint(op, x, values):
    """``op(x, values)`` with one value per joint (an offset, a gain), column by column on stored columns."""
    values = np.broadcast_to(np.asarray(values, dtype=float), (x.shape[1],))
    return x.map_columns(lambda column, j: op(column, values[j])) if isinstance(x, StoredColumns) else op(x, values)

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

or a ROS 2 bag of ``sensor_msgs/JointState`` (:mod:`dynid.io.logs.bags`)::

    bag = "run_01"                   # the bag's folder, relative to the data root
    topic = "/joint_states"          # default
    joint_names = ["j1", …]          # default: the robot's joint names
    effort = "torques"               # or "currents" (through the drive gains, eq. 16)

Columns are 1-based numbers or header names. Drive gains multiply currents on the side where they
are measured. The table is converted into a :class:`DatasetSpec` here (:func:`dataset_spec`), beside the log readers that take the
spec, through its typed structure (:mod:`dynid.io.logs.dataset_tables`); the configs (:mod:`dynid.io.config`) decode
their tables into them.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...conventions import TIME_UNITS
from ...exceptions import ConfigError

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
    decimal : str
        The numbers' decimal separator, "." or "," (:func:`dynid.io.logs.table_files.read_table`).
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
    decimal: str = "."
    time_range: tuple[float, float] | None = None
    gaps: str = "auto"
    bag: BagSpec | None = None
    table: str = ""
    """The config table it comes from, for messages: ``[identification]``, ``[[validation]] "p3"``."""
    max_gap: float = 0.1
    held: str = "interpolate"

    @property
    def files(self) -> tuple[Path, ...]:
        """The files (or the bag) the dataset is read from.

        Returns
        -------
        tuple of Path
        """
        found = [s.file for s in (self.time, *self.signals.values()) if s is not None]
        return tuple(dict.fromkeys(found + ([self.bag.path] if self.bag is not None else [])))


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


def _factor(sig, kind: str, w: str, n_dof: int, sliding) -> np.ndarray:
    """(n_dof,): a signal's unit's factor (an angle's, not on a prismatic joint's metres) times its sign and scale."""
    units = _UNITS[kind]
    unit = sig.unit if sig.unit is not None else next(iter(units))
    if unit not in units:
        raise ConfigError(f"{w}.unit: expected one of {', '.join(units)}, got {unit!r}")
    factor = np.full(n_dof, units[unit])
    if kind in ("positions", "velocities") and len(sliding) == n_dof:
        factor[np.asarray(sliding, dtype=bool)] = 1.0  # a prismatic joint's metres are no angle
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
    return factor


def dataset_spec(table: dict, base: Path, where: str, name: str, n_dof: int, sliding=(), joints: str = "") -> DatasetSpec:
    """Parse a dataset table of a config (module docstring; its structure:
    :class:`dynid.io.config.config_types.DatasetTable`); paths are relative to ``base``.

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
    sliding : sequence of bool, optional
        Which joints are prismatic: a position unit in degrees leaves their metres as they are.
    joints : str
        Added to the refusal of a column list of the wrong length (a robot with branches: its joints and what to hold).

    Returns
    -------
    DatasetSpec

    Raises
    ------
    ConfigError
        Unknown preset, unit or side, a missing signal or file, a column list of the wrong length;
        the message names the config field.
    """
    from ..._util.typed import convert
    from .dataset_tables import DatasetTable

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
            raise ConfigError(f"{w}.columns: expected {n_dof} columns (one per joint), got {sig.columns!r}{joints}")
        factor = _factor(sig, kind, w, n_dof, sliding)
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
    delimiter, decimal = _separators(t, where)
    return DatasetSpec(
        name=str(t.name if t.name is not None else name), signals=signals, time=time,
        rate=None if t.rate is None else float(t.rate), resample=None if t.resample is None else float(t.resample),
        side=t.side or "joint", header=bool(t.header), n_columns=t.n_columns,
        rows=_rows(t.rows, where), delimiter=delimiter, decimal=decimal,
        time_range=_time_range(t.time_range, where), gaps=t.gaps or "auto",
        table=_table_name(where), max_gap=float(t.max_gap) if t.max_gap is not None else 0.1, held=t.held or "interpolate")


def _separators(t, where: str) -> tuple[str, str]:
    """A dataset table's delimiter and decimal separator (a comma and a point by default), refused where they are one."""
    delimiter, decimal = t.delimiter if t.delimiter is not None else ",", t.decimal or "."
    if decimal == delimiter:
        raise ConfigError(f"{where}.decimal: the numbers' decimal separator cannot be the delimiter {delimiter!r}: give "
                          "the delimiter that separates the fields (delimiter = \";\" in a European spreadsheet's export)")
    return delimiter, decimal


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
    extra = [k for k in ("file", "header", "n_columns", "delimiter", "decimal", "rows", "time", "rate", "max_gap", "held", *_SIGNALS)
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

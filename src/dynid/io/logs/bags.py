"""ROS bags of ``sensor_msgs/JointState`` as datasets: ROS 2 bags (SQLite or MCAP) and ROS 1 ``.bag`` files (the rosbags
library: no ROS installation needed).

Each message gives one sample: its header stamp (seconds), and for the robot's joints, found by name,
``position`` [rad], ``velocity`` [rad/s] when every message has it, and ``effort`` (joint torques in N·m,
or motor currents in A with ``effort = "currents"``).
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np

from ...exceptions import DataError
from ...runtime.extras import require

BAG_SUFFIXES = (".mcap", ".db3", ".bag")
"""A ROS 2 bag's storage files (MCAP, SQLite) and a ROS 1 bag's file."""


def is_bag(path: Path) -> bool:
    """Whether a log is a ROS bag: a folder holding a ROS 2 bag (its ``metadata.yaml``, or a ``.db3`` or ``.mcap``
    file), or a file of :data:`BAG_SUFFIXES`. An empty folder, or one of CSV logs, is none.

    Parameters
    ----------
    path : Path

    Returns
    -------
    bool
    """
    if path.is_dir():
        return (path / "metadata.yaml").is_file() or any(f.suffix.lower() in (".db3", ".mcap") for f in path.iterdir())
    return path.suffix.lower() in BAG_SUFFIXES


def read_joint_states(spec, robot, name: str, warnings: list[str] | None = None):
    """Time stamps and raw signals of a ROS bag's JointState messages (ROS 2, or a ROS 1 ``.bag``).

    Parameters
    ----------
    spec : DatasetSpec
        Its ``bag`` says the file, topic and joints.
    robot : Robot
    name : str
        The dataset, for errors.
    warnings : list of str, optional
        Gets a line where the velocities are left out for NaN values.

    Returns
    -------
    t : (N,) ndarray [s]
    signals : dict
        positions, velocities (if present), torques or currents: (N, n_dof) arrays in the bag's units.
    where : callable
        ``where(k)`` names sample k's place in the bag (for errors).

    Raises
    ------
    DataError
        A missing or unreadable bag, no such topic, a topic of another type, joints missing from the messages, or
        messages without positions or efforts.
    """
    path = spec.path
    require("rosbags.highlevel", "ros", f"{path}: reading a ROS bag")
    from rosbags.highlevel import AnyReader

    if not path.exists():
        raise DataError(f"{path}: ROS bag not found")
    wanted = list(spec.joint_names or [j.name for j in robot.joints if j.mimic is None])  # a <mimic> joint: no drive
    stamps, pos, vel, eff = [], [], [], []
    try:
        typestore = _typestore_for(path, AnyReader)
        if typestore is not None and warnings is not None:
            warnings.append(f"{name}: {path.name} holds no message definitions (recorded by ROS 2 Humble or earlier): "
                            "its messages are read with ROS 2 Humble's standard types")
        with AnyReader([path], default_typestore=typestore) as reader:
            connections = [c for c in reader.connections if c.topic == spec.topic]
            if not connections:
                topics = sorted({c.topic for c in reader.connections})
                raise DataError(f"{path}: no topic {spec.topic!r} in the bag (it has {', '.join(topics) or 'none'})")
            if any(c.msgtype != "sensor_msgs/msg/JointState" for c in connections):
                raise DataError(f"{path}: topic {spec.topic!r} holds {connections[0].msgtype}, expected sensor_msgs/msg/JointState")
            for k, (conn, _, raw) in enumerate(reader.messages(connections=connections)):
                msg: Any = reader.deserialize(raw, conn.msgtype)
                names = list(msg.name)
                missing = [n for n in wanted if n not in names]
                if missing:
                    raise DataError(f"{path}: message {k + 1} on {spec.topic} lacks joint(s) {', '.join(missing)} "
                                    f"(it has {', '.join(names)}); set joint_names")
                idx = [names.index(n) for n in wanted]
                if len(msg.position) != len(names) or len(msg.effort) != len(names):
                    raise DataError(f"{path}: message {k + 1} on {spec.topic}: expected a position and an effort per joint")
                stamps.append(msg.header.stamp.sec + 1e-9 * msg.header.stamp.nanosec)
                pos.append(np.asarray(msg.position, dtype=float)[idx])
                eff.append(np.asarray(msg.effort, dtype=float)[idx])
                vel.append(np.asarray(msg.velocity, dtype=float)[idx] if len(msg.velocity) == len(names) else None)
    except DataError:
        raise
    except Exception as exc:  # rosbags' own errors: a damaged or foreign file
        raise DataError(f"{path}: cannot read it as a ROS bag ({_one_line(str(exc))})") from None
    if len(stamps) < 2:
        raise DataError(f"{path}: {len(stamps)} JointState message(s) on {spec.topic}, expected at least 2")
    signals: dict[str, np.ndarray] = {"positions": np.array(pos), ("currents" if spec.effort == "currents" else "torques"): np.array(eff)}
    given = [v for v in vel if v is not None]
    if len(given) == len(vel):  # optional: else derived from the positions
        finite = [bool(np.all(np.isfinite(v))) for v in given]
        if all(finite):
            signals["velocities"] = np.array(given)
        elif warnings is not None:
            k = finite.index(False)
            warnings.append(f"{name}: message {k + 1} on {spec.topic} has NaN or infinite velocities: the bag's "
                            "velocities are left out and derived from the positions")
    for kind, x in signals.items():  # NaN: a missing value, filled or refused as the dataset's gaps say
        if np.isinf(x).any():
            k = int(np.argwhere(np.isinf(x))[0, 0])
            raise DataError(f"{path}: message {k + 1} on {spec.topic}: infinite {kind}")
    return np.array(stamps), signals, lambda k: f"{path}: message {k + 1} on {spec.topic}"


def joint_state_names(path: Path, topic: str = "/joint_states") -> list[str]:
    """The joint names of a ROS bag's first JointState message on ``topic`` (``dynid init``'s choice of the arm among
    a robot file's branches); empty where the bag cannot be read so (reading it as a dataset then says why).

    Parameters
    ----------
    path : Path
        A ROS 2 bag (its folder, or its ``.mcap``/``.db3`` file) or a ROS 1 ``.bag`` file.
    topic : str

    Returns
    -------
    list of str
    """
    try:
        require("rosbags.highlevel", "ros", f"{path}: reading a ROS bag")
        from rosbags.highlevel import AnyReader

        with AnyReader([path], default_typestore=_typestore_for(path, AnyReader)) as reader:
            connections = [c for c in reader.connections if c.topic == topic and c.msgtype == "sensor_msgs/msg/JointState"]
            for conn, _, raw in reader.messages(connections=connections):
                msg: Any = reader.deserialize(raw, conn.msgtype)
                return list(msg.name)
    except Exception:  # noqa: BLE001 - a bag read otherwise says what is wrong with it
        return []
    return []


def _typestore_for(path: Path, reader_class):
    """None for a bag that carries its message definitions (every bag since ROS 2 Iron), ROS 2 Humble's standard
    typestore for one that does not (rosbags would refuse it: "Bag contains no type definitions")."""
    from rosbags.highlevel import AnyReaderError
    from rosbags.typesys import Stores, get_typestore

    try:
        with reader_class([path]):
            return None
    except AnyReaderError as exc:
        if "no type definitions" not in str(exc):
            raise
    return get_typestore(Stores.ROS2_HUMBLE)


def _one_line(message: str) -> str:
    """A library's multi-line message (a YAML parser's, with the text it quotes and a caret under it) as one line:
    what it says and where (line and column)."""
    parts, quoted = [], False
    for line in (x.strip() for x in message.splitlines()):
        where = re.fullmatch(r'in "<[^>]*>", (line \d+, column \d+):?', line)
        if where:
            parts.append(f"at {where.group(1)};")
            quoted = True  # the parser quotes the text next, then a caret under it
        elif quoted or not line or line.startswith("^"):
            quoted = False
        else:
            parts.append(line)
    return " ".join(parts).rstrip(";")

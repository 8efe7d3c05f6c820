"""``dynid init``: a starter identification config for a robot's URDF and a log, with the columns it detected.

The log's columns are matched by their header names (time: ``t``, ``time``, ``timestamp``, PlotJuggler's ``__time``;
positions: ``q``, ``pos``, ``position``, ``angle``; velocities: ``dq``, ``qd``, ``vel``; torques: ``tau``, ``torque``,
``effort``; currents: ``i``, ``current``). A header naming the URDF's joints — ROS-style
``/joint_states/<joint>/position|velocity|effort`` (PlotJuggler's CSV export), ``<joint>_pos``, ``<joint>.effort`` —
is taken in the URDF's joint order, whatever the log's (ROS drivers often publish joints alphabetically); other names
in the order they appear (``q1``…, ``/joint_states/position[0]``…). Without a header, by their count (a time column first, then one
block of ``n_dof`` columns per signal: positions and torques, or positions, velocities and torques) or a known
logger's layout (Universal Robots' RTDE: ``preset = "ur-rtde"``). What was detected is written as comments in the
config, to check before identifying.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import tomlkit
from tomlkit.items import Table

from ...exceptions import ConfigError, DataError
from ...model.description import URDF_DRIVE_TERMS, builtin_robots, load_robot
from ..logs.bags import is_bag
from ..logs.columns import csv_table, joints_named, signal_files
from ..logs.dataset_specs import PRESETS
from ..logs.datasets import dataset_spec, load_recording
from ..logs.table_files import read_table


def starter_config(urdf: Path, log: Path, n_dof: int, out: Path, validation: tuple[Path, ...] = (),
                   joints: tuple[str, ...] = (), held: tuple[str, ...] = (), robot=None, *,
                   rate: float | None = None, xacro_args: dict | None = None) -> tuple[str, list[str]]:
    """A starter config for a URDF and a log.

    Parameters
    ----------
    urdf : Path
        The robot's URDF.
    log : Path
        A CSV log (comma, semicolon, tab or space separated), or a ROS bag: a ROS 2 bag (its folder, or its
        ``.mcap``/``.db3`` file) or a ROS 1 ``.bag`` file.
    n_dof : int
        The robot's joints.
    out : Path
        Where the config will be: the URDF and the log's folder are written relative to its folder.
    validation : tuple of Path
        Other logs of the same layout: each a ``[[validation]]`` entry (it takes the identification's columns).
    joints : tuple of str
        The URDF's joint names, in the chain's order (columns naming them are taken in this order).
    held : tuple of str
        The URDF's joints held fixed (:func:`dynid.model.urdf.joints_to_hold`): written as the ``[robot]`` table's
        ``held``, and said.
    robot : Robot, optional
        The robot read from ``urdf``: a bag is then opened and read as identify reads it (its joint names against the
        robot's, its rate, length and effort range said), and where its nominal values are physically consistent the
        config lists ``estimators = ["wls", "sdp"]`` (its values made consistent for the SDP's prior where they are
        not; without the robot, the SDP is suggested in a comment that says why it is not listed).
    rate : float, optional
        The logs' sample rate [Hz], for a CSV log with a header and no time column (``rate =`` in the config; the
        validation tables take it with the identification's columns).
    xacro_args : dict of str to str, optional
        A xacro robot file's arguments: written as the ``[robot]`` table's ``xacro_args``.

    Returns
    -------
    text : str
        The config (TOML), with what was detected in comments.
    notes : list of str
        What was detected, one line each.

    Raises
    ------
    DataError
        An unreadable log, or columns from which no layout can be told (the message says which columns were seen).
    """
    for given in (log, *validation):  # a FIFO blocks its reader forever; a device never ends
        if given.exists() and not (given.is_file() or given.is_dir()):
            raise DataError(f"{given}: not a regular file (a device, a FIFO or a socket): give the log's file")
    if log.is_dir() and not (log / "metadata.yaml").is_file():
        raise DataError(f"{log}: a folder without metadata.yaml, not a ROS 2 bag: give a CSV log, or a bag's folder or "
                        "its .mcap/.db3 file")
    bags = [v for v in validation if is_bag(v)]
    if is_bag(log) and len(bags) != len(validation) or not is_bag(log) and bags:
        raise DataError(f"{(set(validation) - set(bags) or set(bags)).pop()}: the validation logs and {log.name} must be "
                        "of one kind (all ROS bags or all CSV logs): they share the identification's reader")
    without = _without_sdp(robot)
    if is_bag(log):
        return _bag_config(urdf, log, out, validation, held, robot, xacro_args=xacro_args, without_sdp=without)
    pair = signal_files(log, validation[0], n_dof, rate) if validation else None
    if pair is not None:  # one signal per file: the second log is the first's other signal
        (table, notes), validation = pair, validation[1:]
        notes += _motor_side(table, log.parent, robot)
    else:
        table, notes = csv_table(urdf, log, n_dof, joints, rate=rate)
    readers = tuple(_own_reader(table, v, urdf, n_dof, joints, rate) for v in validation)
    gains = _builtin_gains(table, robot)
    notes += _robot_notes(urdf, log, table, held, robot, gains, without)
    notes += [f"{v.name}: another layout than {log.name}'s, read by its own columns" for v, r in zip(validation, readers) if r]
    return _config(urdf, log, out, validation, table, notes, held=held, xacro_args=xacro_args, without_sdp=without,
                   gains=gains, readers=readers), notes


def _sliding_note(robot) -> list[str]:
    """The line naming the prismatic joints and their units (nothing for a revolute arm)."""
    if robot is None or not robot.prismatic.any():
        return []
    names = ", ".join(j.name for j in robot.joints if j.prismatic)
    return [f"prismatic: {names}: positions in m, velocities in m/s, forces in N (a column in mm: scale = 0.001 for it "
            "in positions' scale list)"]


MOTOR_ANGLES = 2.0
"""Logged angles beyond this many times a joint's largest limit are taken as its motor's (before the gear)."""


def _motor_side(table: Table, folder: Path, robot) -> list[str]:
    """``side = "motor"`` on a dataset table whose angles reach :data:`MOTOR_ANGLES` times a joint's limits where the
    robot has gear ratios (FIGAROH's TX40 files: 50.3 rad = 32 · π/2), said; nothing otherwise."""
    positions = table["positions"]
    assert isinstance(positions, dict)  # written by signal_files
    if robot is None or np.allclose(np.abs(np.diag(robot.transmission.motor_from_joint)), 1.0):
        return []
    delimiter = str(table.get("delimiter", ","))
    q = np.asarray(read_table(folder / str(positions["file"]), list(positions["columns"]), header=True,
                              delimiter=delimiter, decimal=str(table.get("decimal", "."))).data)
    reach = np.abs(q).max(axis=0) / np.maximum(np.abs(robot.limits.q_min), np.abs(robot.limits.q_max))
    if not np.any(reach > MOTOR_ANGLES):
        return []
    table.add("side", "motor")
    j = int(np.argmax(reach))
    return [f"side = \"motor\": the angles reach {reach[j]:.3g}× J{j + 1}'s limit: the motors' (through the description's "
            "gear ratios)"]


def _own_reader(table: Table, log: Path, urdf: Path, n_dof: int, joints: tuple[str, ...], rate: float | None) -> Table | None:
    """A validation log's dataset table where its layout differs from the identification log's ``table`` (a UR's
    19-column RTDE log validated on a 31-column one), else None (it takes the identification's reader); None too
    where its columns cannot be told: identify then says what it cannot read."""
    try:
        own, _ = csv_table(urdf, log, n_dof, joints, rate=rate)
    except DataError:
        return None
    same = {k: v for k, v in own.items() if k != "file"} == {k: v for k, v in table.items() if k != "file"}
    return None if same else own


def _estimators_note(without_sdp: str | None, robot=None) -> str:
    if without_sdp is None:
        made = ("" if robot is None or not robot.physical_prior()[1] else
                "; the description's inertial values are not physically consistent: the SDP's prior and the nominal "
                "candidate are the nearest consistent ones (identify names the links)")
        return ("estimators: WLS and the physically consistent SDP (what dynid export writes); dynid identify chooses "
                "the main estimate among them, the description's values and its drive terms" + made)
    return f"estimators: WLS; the physically consistent SDP is not listed ({without_sdp})"


def _without_sdp(robot) -> str | None:
    """Why the config cannot list the physically consistent estimate (``sdp``); None where it can: the robot was read
    (the SDP's prior is its nominal values, made physically consistent where they are not:
    :meth:`dynid.model.robot.Robot.physical_prior`)."""
    return "the robot was not read" if robot is None else None


def xacro_arguments(given: list[str]) -> dict[str, str]:
    """``--xacro-arg name:=value`` options as a dict (xacro's own spelling; ``name=value`` too).

    Parameters
    ----------
    given : list of str

    Returns
    -------
    dict of str to str

    Raises
    ------
    ConfigError
        An option without a name and a value, or a name given twice.
    """
    out: dict[str, str] = {}
    for text in given:
        name, sep, value = text.partition(":=") if ":=" in text else text.partition("=")
        if not sep or not name.strip().isidentifier():
            raise ConfigError(f"--xacro-arg {text}: expected name:=value (a xacro argument's name, then its value)")
        if name.strip() in out:
            raise ConfigError(f"--xacro-arg {text}: {name.strip()} is given twice")
        out[name.strip()] = value
    return out


def _robot_notes(urdf: Path, log: Path, table, held: tuple[str, ...], robot, gains, without_sdp: str | None) -> list[str]:
    """:func:`starter_config`'s lines on the robot for a CSV log: its prismatic joints, the joints held, the drive gains
    and the estimators listed."""
    followers = [robot.followers_said()] if robot is not None and robot.followers else []
    return [*_sliding_note(robot), *followers, *_held_notes(urdf, held, log, robot), *_gain_notes(table, urdf, robot, gains),
            _estimators_note(without_sdp, robot)]


def _bag_config(urdf: Path, log: Path, out: Path, validation: tuple[Path, ...], held: tuple[str, ...], robot, *,
                xacro_args: dict | None, without_sdp: str | None) -> tuple[str, list[str]]:
    """:func:`starter_config` for a ROS bag: the joints taken by the robot file's names, each bag read as identify reads
    it where the robot is given."""
    table = tomlkit.table()
    table.add("bag", log.name)
    table["bag"].comment("a ROS bag: sensor_msgs/JointState on /joint_states")
    table.add(tomlkit.comment('topic = "/joint_states"'))
    table.add(tomlkit.comment('effort = "torques"               # or "currents" (through the drive gains)'))
    kind = "a ROS 1 bag" if log.suffix.lower() == ".bag" else "a ROS 2 bag (rosbag2, SQLite or MCAP)"
    said = [f"{log.name}: {kind}: the joints are taken by the URDF's joint names",
            *([] if robot is None else [_bag_read(b, robot) for b in (log, *validation)]), *_held_notes(urdf, held, log, robot)]
    said.append(_estimators_note(without_sdp, robot))
    return _config(urdf, log, out, validation, table, said, held=held, xacro_args=xacro_args,
                   without_sdp=without_sdp), said


def _held_notes(urdf: Path, held: tuple[str, ...], log: Path | None = None, robot=None) -> list[str]:
    """The lines of the joints held: which, and those of them the log holds columns of (another arm of a two-arm
    robot that ``--arm`` left out), which a config of their own identifies."""
    tree = robot is not None and robot.is_tree
    notes = [f"{urdf.name}: the log's joints are on several branches: one model of its {robot.n_dof} joints (a tree, "
             "each joint feeling the links it carries)"] if tree else []
    if not held:
        return notes
    where = "no columns in the log (a gripper, a head)" if tree else "not on the arm's serial chain (a gripper, a head, another arm)"
    notes.append(f"{urdf.name}: {', '.join(held)} {where}: held fixed at 0, their links counted with the link they hang "
                 "on (held in [robot])")
    logged = sorted(joints_named(log, held), key=held.index) if log is not None else []
    if log is not None and logged:  # --arm chose one arm of a log of several
        notes.append(f"{log.name} also holds columns of {', '.join(logged)}, on another branch of {urdf.name}: held as "
                     f"--arm asks; their config: dynid init {urdf.name} {log.name} --arm {logged[0]} --out <another "
                     "config>, or without --arm every branch the log names as one robot")
    return notes


def _reads_currents(table) -> bool:
    """Whether the dataset table reads motor currents (its own ``currents`` or its preset's)."""
    return "currents" in table or "currents" in PRESETS.get(str(table.get("preset")), {})


def _builtin_gains(table, robot) -> tuple[float, ...] | None:
    """The drive gains of the built-in robot of the description's name (a UR10e's URDF: the built-in ``ur10e``'s),
    where the log holds motor currents and the description states none (a URDF cannot); else None."""
    if robot is None or not _reads_currents(table) or np.any(robot.drive_gains != 1.0) \
            or robot.name not in builtin_robots():
        return None
    gains = np.asarray(load_robot(robot.name).drive_gains, dtype=float)
    return tuple(float(g) for g in gains) if gains.shape == (robot.n_dof,) and np.any(gains != 1.0) else None


def _gain_notes(table, urdf: Path, robot, gains: tuple[float, ...] | None) -> list[str]:
    """A log of motor currents with a description that states no drive gains (a URDF cannot: each is 1 N·m/A): said,
    with the built-in robot's gains written in their place (``gains``), or where the gains go (eq. 16, τ = K·I)."""
    if robot is None or not _reads_currents(table) or np.any(robot.drive_gains != 1.0):
        return []
    if gains is not None:
        return [f"motor currents, and {urdf.name} states no drive gains: the built-in robot \"{robot.name}\"'s are "
                f"written in [[robot.joints]] ({', '.join(f'{g:.6g}' for g in gains)} N·m/A, eq. 16, τ = K·I); check "
                "them against your controller's. Read as 1 N·m/A, each joint's current scales its rows differently "
                "and no rigid body fits them all"]
    return [f"motor currents, and {urdf.name} states no drive gains: each joint's current is read as its torque in "
            "N·m (1 N·m/A) until a [robot] table gives each joint's drive_gain (torque per ampere at the joint, eq. "
            "16; [[robot.joints]]); dynid identify's verdict estimates them from the description's nominal model"]


def _bag_read(bag: Path, robot) -> str:
    """A bag read as ``dynid identify`` reads it (its JointState messages' joints by the robot's joint names): one
    line with its samples, duration, rate and effort range; a bag that cannot be read is refused in one line."""
    spec = dataset_spec({"bag": bag.name}, bag.parent, f"{bag}", bag.name, int(robot.independent.sum()))
    rec = load_recording(spec, robot, spool=False)
    t, tau = np.asarray(rec.t), np.asarray(rec.tau)
    line = (f"{bag.name}: read as identify reads it: {t.size} samples over {t[-1] - t[0]:.3g} s ({rec.rate:.4g} Hz), "
            f"every joint of the robot by name; effort from {tau.min():.3g} to {tau.max():.3g}")
    if not np.any(np.abs(tau) > 0):
        line += " (all 0: the bag logs no effort; identify needs torques or currents)"
    return line


def _config(urdf: Path, log: Path, out: Path, validation: tuple[Path, ...], table: Table, notes: list[str], *,
            held: tuple[str, ...] = (), xacro_args: dict | None = None, without_sdp: str | None = None,
            gains: tuple[float, ...] | None = None, readers: tuple = ()) -> str:
    """The config's text, written by tomlkit (every string escaped, whatever the paths and columns hold): what was
    detected in comments, the robot (a table where joints are held, a xacro file takes arguments or ``gains`` give
    each joint's drive gain in ``[[robot.joints]]``), the dataset table, the validation logs, and the estimators: WLS
    and the SDP, or, ``without_sdp`` saying why not, the SDP suggested in a comment."""
    doc = tomlkit.document()
    for line in ("dynid identification config, written by dynid init: check the columns and units below, then",
                 "  dynid identify THIS_FILE", *notes):
        doc.add(tomlkit.comment(" ".join(line.splitlines())))
    as_table = bool(held or xacro_args or gains)
    if not as_table:  # keys before the first table
        doc.add("robot", tomlkit.item(_robot_ref(urdf, out.parent)))
    doc.add("data_root", tomlkit.item(_relative(log.parent, out.parent)))
    doc.add(tomlkit.nl())
    if as_table:
        robot = _robot_table(_robot_ref(urdf, out.parent))
        if held:
            robot.add("held", list(held))
            robot["held"].comment("not the arm's joints: held fixed at 0")
        if xacro_args:
            arguments = tomlkit.inline_table()
            arguments.update({str(k): str(v) for k, v in xacro_args.items()})
            arguments.comment("the xacro file's arguments (name:=value)")
            robot.add("xacro_args", arguments)
        if gains:
            joints = tomlkit.aot()
            for j, g in enumerate(gains):
                entry = tomlkit.table()
                entry.add("drive_gain", tomlkit.item(g))
                if j == 0:
                    entry["drive_gain"].comment("N·m/A at the joint (eq. 16): the built-in robot's")
                joints.append(entry)
            robot.add("joints", joints)
        robot.add(tomlkit.nl())
        doc.add("robot", robot)
    table.add(tomlkit.nl())
    doc.add("identification", table)
    if validation:
        tables = tomlkit.aot()
        for v, reader in zip(validation, readers or (None,) * len(validation)):
            entry = tomlkit.table()
            entry.comment("the identification's reader" if reader is None else "its own reader: another layout")
            entry.add("name", v.stem)
            entry.add("bag" if is_bag(v) else "file", _relative(v, log.parent))
            for key, value in ({} if reader is None else reader).items():
                if key != "file":  # the file is the entry's own, relative to the data root
                    entry.add(key, value)
            tables.append(entry)
        doc.add("validation", tables)
    else:
        for line in ("[[validation]]                  # other logs, same layout, to check the model where it was not "
                     "fitted", 'name = "second_run"', 'file = "second_run.csv"'):
            table.add(tomlkit.comment(line))
    last = tables[-1] if validation else table
    if without_sdp is None:  # both candidates of the verdict; the SDP is what dynid export writes
        estimation = tomlkit.table()
        estimation.add("estimators", ["wls", "sdp"])
        estimation["estimators"].comment("sdp: physically consistent, what dynid export writes; the verdict chooses "
                                         "the main estimate")
        doc.add("estimation", estimation)
    else:
        last.add(tomlkit.nl())
        last.add(tomlkit.comment("[estimation]"))
        last.add(tomlkit.comment('estimators = ["wls", "sdp"]     # add sdp for a physically consistent estimate to export'))
        last.add(tomlkit.comment(f"not listed: {' '.join(without_sdp.split())}"))
    return tomlkit.dumps(doc)


def with_torque_setting(text: str, name: str, value, why: str) -> str | None:
    """A starter config's text with ``name = value`` in its identification log's torques (or currents) table, and in
    those of the validation logs read by their own columns (:func:`starter_config`: a log of another layout, from the
    same drives), with ``why`` beside it (tomlkit keeps the rest as written).

    Parameters
    ----------
    text : str
        The config :func:`starter_config` wrote.
    name : str
        The setting (``sign``).
    value : int, float or list
    why : str
        A comment on the line.

    Returns
    -------
    str or None
        None where the log's torques are no table of their own (a bag's efforts).
    """
    doc = tomlkit.parse(text)
    ident = doc.get("identification")
    if ident is None or _with_signal_setting(ident, name, value, why) is None:
        return None
    for entry in doc.get("validation", []):
        _with_signal_setting(entry, name, value, why)
    return tomlkit.dumps(doc)


def _with_signal_setting(dataset, name: str, value, why: str):
    """``name = value`` in a dataset table's own torques (or currents) table, written afresh (the new key spaced as
    the others) with ``why`` beside it; None where it has none of its own."""
    key = next((k for k in ("torques", "currents") if k in dataset), None)
    if key is None or not isinstance(dataset[key], dict):
        return None
    table = tomlkit.inline_table()
    table.update({**dict(dataset[key]), name: value})
    table.comment(" ".join(why.split()))
    dataset[key] = table
    return table


def with_robot_setting(text: str, name: str, value, why: str) -> str:
    """A starter config's text with ``name = value`` in its ``[robot]`` table (a ``robot = "..."`` key made that table,
    its file as ``urdf``) and ``why`` beside it.

    Parameters
    ----------
    text : str
        What dynid init is about to write.
    name, value : str, list
        The robot's setting and its value: ``gravity`` and three numbers [m/s²] in the base frame.
    why : str
        The comment written beside it.

    Returns
    -------
    str
    """
    doc = tomlkit.parse(text)
    robot = _robot_of(doc)
    robot[name] = value
    robot[name].comment(" ".join(why.split()))
    return tomlkit.dumps(doc)


def with_joint_setting(text: str, name: str, values: dict, n_dof: int, why: str) -> str:
    """A starter config's text with ``name = value`` in some joints' ``[[robot.joints]]`` tables (made, one per joint,
    where the config has none; the ``[robot]`` table made as :func:`with_robot_setting` makes it) and ``why`` beside
    the first.

    Parameters
    ----------
    text : str
        What dynid init is about to write.
    name : str
        A joint's setting: ``position_offset``.
    values : dict of int to value
        0-based joint -> its value (an angle as ``"pi/2"``).
    n_dof : int
        The robot's joints (the tables made).
    why : str
        The comment written beside the first value.

    Returns
    -------
    str
    """
    doc = tomlkit.parse(text)
    robot = _robot_of(doc)
    if "joints" not in robot:
        tables = tomlkit.aot()
        for _ in range(n_dof):
            tables.append(tomlkit.table())
        robot.add("joints", tables)
    for k, (j, value) in enumerate(sorted(values.items())):
        robot["joints"][j][name] = value
        if k == 0:
            robot["joints"][j][name].comment(" ".join(why.split()))
    return tomlkit.dumps(doc)


def _robot_of(doc):
    """A starter config's ``[robot]`` table, made from its ``robot = "file"`` key where it has none."""
    robot = doc.get("robot")
    if isinstance(robot, str):
        doc.remove("robot")
        doc.add("robot", _robot_table(robot))
        robot = doc["robot"]
    assert isinstance(robot, dict)  # a table dynid init wrote
    return robot


def _robot_table(urdf: str):
    """A ``[robot]`` table for a robot file: its path and the drive terms ``robot = "file"`` gives it
    (:data:`dynid.model.description.URDF_DRIVE_TERMS`; a table without them would have the paper's two)."""
    table = tomlkit.table()
    table.add("urdf", urdf)
    table.add("drive_terms", list(URDF_DRIVE_TERMS))
    return table


def _robot_ref(urdf: Path, folder: Path) -> str:
    """How the config names the robot: a built-in robot's name as given (``tx40``), a file relative to ``folder``."""
    return str(urdf) if str(urdf) in builtin_robots() and not urdf.exists() else _relative(urdf, folder)


def _relative(path: Path, folder: Path) -> str:
    return Path(os.path.relpath(path.resolve(), folder.resolve())).as_posix()


def check_target(path: Path, force: bool, read: tuple[Path, ...] = ()) -> None:
    """Refuse to overwrite a config unless asked, and a file the run reads always.

    Parameters
    ----------
    path : Path
    force : bool
    read : tuple of Path
        The files the run reads (the robot file, the logs).

    Raises
    ------
    ConfigError
        ``path`` exists and ``force`` is false, or ``path`` is one of ``read``.
    """
    if path.exists() and any(path.resolve() == Path(r).resolve() for r in read):
        raise ConfigError(f"--out {path}: a file this init reads (the robot file or a log), which --force would replace "
                          "by the config; give the config another name, e.g. arm.toml")
    if path.exists() and not force:
        raise ConfigError(f"--out {path}: exists; give another name, or --force to overwrite it")

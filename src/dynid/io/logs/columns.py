"""Which column of a CSV log is which signal, as ``dynid init`` and :func:`dynid.load_recording` find them (module
docstring of :mod:`dynid.io.config.starter`): header names, a URDF's joint names, a count of columns without a header, or a
known logger's layout."""

from __future__ import annotations

import itertools
import json
import re
from pathlib import Path

import numpy as np
import tomlkit
from tomlkit.items import InlineTable, Table

from ...conventions import time_unit_of
from ...exceptions import DataError
from ..files import text_encoding_hint
from .bags import is_bag, joint_state_names
from .table_files import decimal_commas, is_data_line, read_table


def csv_table(urdf: Path, log: Path, n_dof: int, joints: tuple[str, ...] = (), *,
              rate: float | None = None, rate_hint: str = "dynid init ... --rate HZ") -> tuple[Table, list[str]]:
    """A CSV log's dataset table with its columns detected, and what was detected.

    Parameters
    ----------
    urdf : Path
        The robot's URDF (its name, in hints and the torque sensor's inference; need not exist).
    log : Path
        A CSV log (comma, semicolon, tab or space separated).
    n_dof : int
    joints : tuple of str
        The URDF's joint names, in the chain's order (columns naming them are taken in this order).
    rate : float, optional
        The log's sample rate [Hz] where it has no time column.
    rate_hint : str
        How the caller's user gives that rate, for the message of a log without time stamps.

    Returns
    -------
    table : tomlkit.items.Table
        The ``[identification]`` table, with comments (tomlkit writes its strings escaped, whatever the log's file
        and column names hold).
    notes : list of str
        What was detected, one line each.

    Raises
    ------
    DataError
        An unreadable log, or columns from which no layout can be told (the message says which columns were seen).
    """
    lines, delimiter, decimal = _first_lines(log)
    first = _fields(lines[0], delimiter)
    header = not all(_number(c) for c in first)
    notes: list[str] = [f"{log.name}: {len(first)} columns separated by {_named(delimiter)}, "
                        + ("a header line" if header else "no header line")
                        + (", decimal commas" if decimal == "," else "")]
    table = tomlkit.table()
    table.add("file", log.name)
    _add_separators(table, delimiter, decimal)
    if header:
        return table, notes + _header_entries(table, urdf, log, (first, lines), delimiter, n_dof=n_dof, joints=joints,
                                              rate=rate, rate_hint=rate_hint)
    return _headerless_table(table, notes, urdf, log, len(first), n_dof=n_dof, joints=joints, rate=rate)


def _header_entries(table, urdf: Path, log: Path, read: tuple, delimiter: str, *, n_dof: int, joints: tuple[str, ...],
                    rate: float | None, rate_hint: str) -> list[str]:
    """A log with a header line (``read``: its header's fields and its first lines): its columns found and checked,
    their entries added to ``table``, what was found."""
    def split(line: str) -> list[str]:
        return _fields(line, delimiter)

    first, lines = read
    found, order_notes = _found_columns(first, split(lines[1]) if len(lines) > 1 else [], joints, n_dof)
    group_notes, passed = _one_group_each(found, log, (delimiter, str(table.get("decimal", "."))), n_dof)
    _check_one_signal(log, first, found, n_dof)
    if "time" not in found and rate is None:
        raise DataError(f"{log}: no time column among {_shown(first)}; accepted: {ACCEPTED}; for a log without time "
                        f"stamps give its sample rate: {rate_hint}")
    effort = "torques" if len(found.get("torques", [])) >= n_dof else "currents"
    missing = [k for k in ("positions", effort) if len(found.get(k, [])) < n_dof]
    if missing:
        count = len(found.get(missing[0], []))
        raise DataError(f"{log}: found {count} {missing[0]} column(s) of the {n_dof} the robot needs among "
                        f"{_shown(first)}; accepted: {ACCEPTED}" + _hold_hint(urdf, joints, count))
    table.add("header", True)
    time_notes, taken = (_time_entry(table, first, found["time"][0], [split(line) for line in lines[1:]])
                         if "time" in found else _rate_entry(table, float(rate or 0.0)))
    time_notes += _rate_unused(rate, found["time"][0]) if "time" in found else []
    signal_notes, signals, assumed = _signal_entries(table, found, ("positions", "velocities", effort), urdf, n_dof)
    notes = order_notes + group_notes + time_notes + signal_notes
    notes += _unread_notes([c for c in first if c not in taken + signals], passed, effort, urdf, n_dof)
    return notes + ([_assumed_units(assumed)] if assumed else [])


def _unread_notes(left: list[str], passed, effort: str, urdf: Path, n_dof: int) -> list[str]:
    """:func:`_header_entries`' note on the columns ``left`` unread: a ``<mimic>`` joint's, more joint columns than
    the robot has joints (``passed``: those already said as a group passed over), or any others."""
    extra = [c for c in left if _kind(c) in ("positions", effort) and c not in passed]
    followed = _mimic_columns(urdf, extra)
    if extra and len(followed) == len(extra):
        return [f"not read: {', '.join(left)} — the columns of joints that follow others in {urdf.name} (<mimic>: "
                f"{', '.join(sorted(set(followed.values())))}): their motion is computed from the joints they follow, "
                "and their torque is those joints'"]
    if extra:
        return [f"not read: {', '.join(left)} — the log has more joint columns than the robot's {n_dof} joints "
                f"({', '.join(extra)}): is {urdf.name} the whole arm, and are the first {n_dof} its joints?"]
    return [f"not read: {', '.join(left)}"] if left else []


def _mimic_columns(urdf: Path, columns: list[str]) -> dict[str, str]:
    """The columns among ``columns`` that name a joint of the URDF that follows another (``<mimic>``) -> that joint."""
    from ...model.urdf import mimic_joints  # here: the robot file's reader is loaded where a log has columns to spare

    if not columns or urdf.suffix.lower() != ".urdf" or not urdf.is_file():
        return {}
    names = mimic_joints(urdf)
    out = {}
    for column in columns:
        named = [n for n in names if re.search(rf"(^|[^A-Za-z0-9]){re.escape(n)}([^A-Za-z0-9]|$)", column)]
        if named:
            out[column] = max(named, key=len)
    return out


def _signal_entries(table, found: dict, kinds: tuple[str, ...], urdf: Path, n_dof: int) -> tuple[list[str], list[str], list[str]]:
    """Each signal found for every joint as its entry of ``table`` (columns, the unit their names say, the gear's side):
    what was found, the columns taken, the signals whose units are assumed."""
    notes: list[str] = []
    taken: list[str] = []
    assumed: list[str] = []
    for kind in kinds:
        if len(found.get(kind, [])) >= n_dof:
            unit = _named_unit(found[kind][:n_dof])
            assumed += [] if unit or _kind_and_unit(found[kind][0])[1] else [kind]
            motor = bool(_qualifiers(found[kind][0]) & MOTOR_SIDE)
            side = {"side": "motor"} if motor and kind == "torques" else {}
            table.add(kind, _inline(columns=found[kind][:n_dof], **({"unit": unit} if unit else {}), **side))
            notes.append(f"{kind}: " + ", ".join(found[kind][:n_dof]) + (f" (in {unit}, as their names say)" if unit else "")
                         + _side_note(kind, motor))
            taken += found[kind][:n_dof]
            if kind == "torques" and not motor:  # a log cannot tell which side of the gear measured them: the arm may
                notes += _torque_sensor(table, urdf)
    return notes, taken, assumed


def _headerless_table(table, notes: list[str], urdf: Path, log: Path, n_columns: int, *, n_dof: int,
                      joints: tuple[str, ...], rate: float | None = None):
    """A log without a header line: a layout told by its number of columns (an RTDE preset, or time then blocks of
    ``n_dof`` columns per signal; the blocks alone with ``rate``, a log without time stamps)."""
    if rate is not None and n_columns in (2 * n_dof, 3 * n_dof):
        blocks = ["positions", "torques"] if n_columns == 2 * n_dof else ["positions", "velocities", "torques"]
        rate_notes, _ = _rate_entry(table, rate)
        for b, kind in enumerate(blocks):
            table.add(kind, _inline(columns=[1 + b * n_dof + j for j in range(n_dof)]))
        return table, notes + rate_notes + [f"no header: {', '.join(blocks)} in blocks of {n_dof}",
                                            _assumed_units(blocks)] + _torque_sensor(table, urdf)
    if n_columns == 31 and n_dof == 6:
        return _preset_table("ur-rtde", log), notes + [
            "31 columns: Universal Robots' RTDE layout (time, q, qd, currents, …): preset = \"ur-rtde\" (its units: s, "
            "rad, rad/s, A)"]
    order, said = _velocity_block(log, table, n_dof) if n_columns == 1 + 3 * n_dof else ([], "")
    swapped = order[1:2] == ["torques"]  # the third block is the velocities: no preset of (t, q, q̇, …) fits
    if n_columns == 19 and n_dof == 6 and not swapped and UNIVERSAL_ROBOTS.search(_robot_name(urdf) or urdf.stem):
        return _preset_table("ur-rtde-19", log), notes + [
            "19 columns and a Universal Robots arm: its RTDE layout without targets (time, q, qd, motor currents): "
            "preset = \"ur-rtde-19\" (its units: s, rad, rad/s, A); if the last six are torques in N·m, give time, "
            "positions, velocities and torques in blocks of 6 columns instead"]
    if n_columns in (1 + 2 * n_dof, 1 + 3 * n_dof):
        # which block is the velocities: the one that follows the positions' derivative (_velocity_block)
        blocks = ["positions", "torques"] if n_columns == 1 + 2 * n_dof else order
        table.add("time", _inline(column=1))
        for b, kind in enumerate(blocks):
            table.add(kind, _inline(columns=[2 + b * n_dof + j for j in range(n_dof)]))
        notes.append(f"no header: column 1 taken as time, then {', '.join(blocks)} in blocks of {n_dof}{said}")
        notes.append(_assumed_units(blocks, time=True))
        return table, notes + _rate_unused(rate, "column 1") + _torque_sensor(table, urdf)
    fewer = next((k for k in range(n_dof - 1, 0, -1) if n_columns in (1 + 2 * k, 1 + 3 * k)), 0)
    raise DataError(f"{log}: {n_columns} columns without a header: expected a time column and {n_dof} columns per "
                    f"signal, or those alone with --rate HZ (or name the columns in a header line: t, q1…, tau1…)"
                    + _hold_hint(urdf, joints, fewer))


VELOCITY_LIKE = 0.95
"""A block of a headerless log whose columns correlate with the positions' derivative this much or more (median over
the joints that move) is the velocities (:func:`_velocity_block`)."""

VELOCITY_ROWS = 20_000
"""Rows :func:`_velocity_block` reads: a few seconds of any log, never the whole of an hour-long one."""


def _velocity_block(log: Path, table, n_dof: int) -> tuple[list[str], str]:
    """The order of a headerless log's two blocks after the positions (issue "Every assurance checked on what the user
    meets", item 2): the one whose columns follow the positions' derivative is the velocities, the other the torques.
    Returns the blocks' names and the note's words on that guess and its confidence (a log written t, q, τ, q̇ was
    read as t, q, q̇, τ, and its velocities fitted as torques)."""
    delimiter = table.get("delimiter", ",")
    try:
        with log.open(encoding="utf-8-sig") as fh:
            rows = [_fields(line.rstrip("\r\n").replace(",", ".") if table.get("decimal") == "," else line.rstrip("\r\n"),
                            delimiter) for line in itertools.islice(fh, VELOCITY_ROWS) if line.strip()
                    and not line.lstrip().startswith("#")]
        data = np.array([[float(x) for x in r] for r in rows if len(r) == 1 + 3 * n_dof], dtype=float)
    except (OSError, UnicodeDecodeError, ValueError):
        data = np.empty((0, 1 + 3 * n_dof))
    order = ["positions", "velocities", "torques"]
    if data.shape[0] < 20 or not np.all(np.isfinite(data)):
        return order, " (the second block taken as velocities by its place: too few rows to tell)"
    t, q = data[:, 0], data[:, 1:1 + n_dof]
    with np.errstate(invalid="ignore", divide="ignore"):
        derivative = np.gradient(q, t, axis=0) if np.all(np.diff(t) > 0) else np.gradient(q, axis=0)
    moving = [j for j in range(n_dof) if np.std(derivative[:, j]) > 0]

    def follows(block: int) -> float:
        cols = data[:, 1 + block * n_dof:1 + (block + 1) * n_dof]
        rho = [np.corrcoef(derivative[:, j], cols[:, j])[0, 1] for j in moving if np.std(cols[:, j]) > 0]
        return float(np.median(rho)) if rho else float("nan")

    second, third = follows(1), follows(2)
    if third >= VELOCITY_LIKE and not second >= VELOCITY_LIKE:
        return (["positions", "torques", "velocities"],
                f" (the third block follows the positions' derivative, correlation {third:.3f}, the second "
                f"{second:.2f}: the velocities are the third)")
    if second >= VELOCITY_LIKE:
        return order, f" (the second block follows the positions' derivative: correlation {second:.3f})"
    return order, (f" (a guess by place: neither block follows the positions' derivative, correlations {second:.2f} "
                   f"and {third:.2f}: check which is which)")


PATTERNS = {
    "time": r"[_%]*(t|time|times?tamp|stamp|sec|seconds)",
    "positions": r"(joint_?)?(q|pos|position|positions|angle)|actual_q",
    "velocities": r"(joint_?)?(dq|qd|qdot|vel|velocity|velocities)|actual_qd",
    "torques": r"(joint_?)?(tau|torque|torques|effort|moment)|target_moment",
    "currents": r"(i|cur|current|currents|actual_current)",
}
"""Header-name stems of each signal (case-insensitive, followed by an optional separator and joint number)."""


ACCEPTED = ("t, time, timestamp, __time or %time for the time; q1…/pos1…/position[0]…, dq1…/vel1…, tau1…/effort[0]… "
            "or i1…, each with a unit beside it or not (t_s, q1_deg, tau1_Nm) and a side of the gear or a variant or not "
            "(q_link_1, tau_mot_abs_Nm1), the joint first or not (A1_pos, axis1_torque, JointPosition1); or the URDF's joint names: "
            "/joint_states/<joint>/position|velocity|effort, <joint>_pos, <joint>.effort")
"""The header patterns init accepts, named in its refusals."""


_SEPARATORS = r"[\s/._\-\[\]()]"


def _seconds_and_nanoseconds(header: list[str]) -> tuple[str, str] | None:
    """The columns of a time stamp split into whole seconds and nanoseconds (ROS 2 ``header.stamp.sec`` and
    ``header.stamp.nanosec``, ROS 1 ``secs`` and ``nsecs``), or None."""
    low = {c.strip().lower(): c for c in header}
    for c, name in low.items():
        for sec, nsec in ((".sec", ".nanosec"), ("/sec", "/nanosec"), (".secs", ".nsecs"), ("/secs", "/nsecs"),
                          ("_sec", "_nanosec")):
            if c.endswith(sec) and c[:-len(sec)] + nsec in low:
                return name, low[c[:-len(sec)] + nsec]
    return None


UNITS = {"s": "s", "sec": "s", "ms": "ms", "us": "us", "ns": "ns", "rad": "rad", "deg": "deg", "degrees": "deg",
         "rad/s": "rad/s", "rads": "rad/s", "rad_s": "rad/s", "radps": "rad/s", "deg/s": "deg/s", "degps": "deg/s",
         "deg_s": "deg/s", "dps": "deg/s", "nm": "N*m", "n_m": "N*m", "n*m": "N*m", "a": "A", "ma": "mA"}
"""Unit words a column's name may carry beside its signal and joint (``t_s``, ``q1_deg``, ``pos [rad]``,
``tau_Nm3``): the unit the config's signal table takes."""

_UNIT = r"[\s_\-\[\(]*(" + "|".join(sorted((re.escape(u) for u in UNITS), key=len, reverse=True)) + r")[\]\)]?$"
_JOINT = r"[\s_\-\[\(]*(j(oint)?)?_?\d+[\]\)]?$"
_LEADING_JOINT = r"^(a|axis|j|joint)[\s_\-]?\d+[\s_\-]+"
"""A joint named before the signal: ``A1_pos`` (KUKA's axes A1…A7), ``axis1_torque``, ``J1 position``."""


DEFAULT_UNITS = ("rad", "rad/s", "N*m", "A")
"""The units a signal table takes without ``unit``."""


def _named_unit(columns: list[str]) -> str | None:
    """The unit every one of a signal's columns names (:func:`_kind_and_unit`), where it is not the table's default."""
    units = {_kind_and_unit(c)[1] for c in columns}
    unit = units.pop() if len(units) == 1 else None
    return unit if unit not in (None, *DEFAULT_UNITS) else None


def _kind(name: str) -> str | None:
    """The signal a column's name says, by its last path component (``/joint_states/position[0]`` → positions)."""
    return _kind_and_unit(name)[0]


def _kind_and_unit(name: str) -> tuple[str | None, str | None]:
    """The signal a column's name says and the unit it names (:data:`UNITS`), if any: ``q_deg1`` and ``q1_deg`` are
    positions in degrees."""
    last = [part for part in re.split(r"[/.]", name.strip().lower()) if part] or [""]
    if len(last) > 1 and last[-1].isdigit():  # ROS-style position/0 and position.0: the index is a part of its own
        last = last[:-1]
    last[-1] = re.sub(_LEADING_JOINT, "", last[-1])
    stem = re.sub(_JOINT, "", last[-1])
    for kind, pattern in PATTERNS.items():
        if re.fullmatch(pattern, stem):
            return kind, None
    qualified = _qualified(stem)  # q_meas: a qualifier, not a unit (s) at its end
    unit = None if qualified else re.search(_UNIT, stem) or re.search(_UNIT, last[-1])
    if unit is None:
        return qualified, None
    bare = re.sub(_JOINT, "", re.sub(_UNIT, "", re.sub(_JOINT, "", last[-1])))
    signal = next((k for k, pattern in PATTERNS.items() if re.fullmatch(pattern, bare)), None) or _qualified(bare)
    return (signal, UNITS[unit.group(1)]) if signal else (None, None)


MOTOR_SIDE = frozenset({"mot", "motor", "rotor"})
"""Words of a column's name that say the motor side of the gear (``tau_mot_Nm1``)."""
LINK_SIDE = frozenset({"se", "link", "load", "output", "secondary"})
"""Words that say the link side (``q_se_deg1``: a secondary, link-side encoder)."""
QUALIFIERS = MOTOR_SIDE | LINK_SIDE | frozenset({"abs", "rel", "meas", "measured", "msr", "act", "actual", "fb",
                                                 "feedback", "raw"})
"""Words a signal's stem may carry beside it (``q_se_deg1``, ``tau_mot_abs_Nm1``, ``q_meas_1``): its side of the gear
or a variant; columns of one signal that differ by them are groups of their own (:func:`_one_group_each`)."""


def _one_group_each(found: dict, log: Path, separators: tuple[str, str], n_dof: int) -> tuple[list[str], list[str]]:
    """Where a signal's columns make several groups of one column per joint that differ by their names'
    :data:`QUALIFIERS` (a KR 300's ``q_se_deg1…`` and ``q_mot_deg1…``), one group taken (``found`` changed in place),
    and said: a group with a channel that reads one value throughout the log is passed over, then the link side is
    taken before an unnamed side and the motor side, then the header's order; the notes, and the columns passed over."""
    notes: list[str] = []
    passed: list[str] = []
    for kind, columns in found.items():
        groups: dict[frozenset, list[str]] = {}
        for c in columns:
            groups.setdefault(_qualifiers(c), []).append(c)
        if kind == "time" or len(groups) < 2 or any(len(g) != n_dof for g in groups.values()):
            continue
        complete = list(groups.values())
        dead = _constant_columns(log, separators, [c for g in complete for c in g])

        def rank(g: list[str]) -> tuple:
            words = _qualifiers(g[0])
            return any(c in dead for c in g), 0 if words & LINK_SIDE else 2 if words & MOTOR_SIDE else 1, complete.index(g)

        chosen = min(complete, key=rank)
        found[kind] = chosen
        left = [f"{g[0]}…{g[-1]}" + (f" ({', '.join(c for c in g if c in dead)} read one value throughout)"
                                     if any(c in dead for c in g) else "") for g in complete if g is not chosen]
        notes.append(f"{kind} also in the log, not read: {'; '.join(left)} (give their columns to take them)")
        passed += [c for g in complete if g is not chosen for c in g]
    return notes, passed


def _constant_columns(log: Path, separators: tuple[str, str], columns: list[str]) -> set[str]:
    """The columns of a log that read one value throughout (none where the log cannot be read: its reader says why);
    ``separators``: the delimiter and the decimal separator."""
    try:
        data = np.asarray(read_table(log, columns, header=True, delimiter=separators[0], decimal=separators[1]).data)
    except DataError:
        return set()
    return {c for c, x in zip(columns, data.T) if np.ptp(x) == 0}


def _side_note(kind: str, motor: bool) -> str:
    """What a signal's columns named for the motor side are taken as: torques through the gear ratios, angles and
    speeds as the joint's (a drive's motor angle divided by its ratio), with how to say otherwise."""
    if not motor:
        return ""
    if kind == "torques":
        return ' (named for the motor side: side = "motor", taken through the description\'s gear ratios)'
    return (' (named for the motor side, taken as the joint\'s: the motor\'s divided by its gear ratio; if they are '
            'the motor\'s own, add side = "motor")')


def _qualified(stem: str) -> str | None:
    """The signal of a stem written as a signal's word and :data:`QUALIFIERS` (``q_se``, ``tau_mot_abs``), or None."""
    words = [w for w in re.split(r"[\s_\-]+", stem) if w]
    if len(words) < 2 or not set(words[1:]) <= QUALIFIERS:
        return None
    return next((kind for kind, pattern in PATTERNS.items() if kind != "time" and re.fullmatch(pattern, words[0])), None)


def _qualifiers(name: str) -> frozenset:
    """The :data:`QUALIFIERS` among the words of a column name's last path component (``tau_mot_abs_Nm1``; not a
    topic's or a joint's name before it: ``/motor_states/elbow/effort`` has none)."""
    last = [part for part in re.split(r"[/.]", name.strip().lower()) if part and not part.isdigit()] or [""]
    return frozenset(re.split(r"[^a-z]+", last[-1])) & QUALIFIERS


def _named_joint(name: str, joints: tuple[str, ...]) -> tuple[str, int] | None:
    """``(signal, joint index)`` of a column that names one of the URDF's joints and a signal beside it
    (``/joint_states/elbow_joint/position``, ``elbow_joint_pos``, ``elbow_joint.effort``); the longest joint name wins
    (``joint_1`` against ``joint_10``)."""
    low = name.strip().lower()
    for j in sorted(range(len(joints)), key=lambda j: -len(joints[j])):
        joint = joints[j].lower()
        match = re.search(rf"(^|{_SEPARATORS}){re.escape(joint)}($|{_SEPARATORS})", low)
        if not joint or match is None:
            continue
        rest = [part for part in re.split(rf"{_SEPARATORS}+", low[:match.start()] + " " + low[match.end():]) if part]
        kinds = [k for k in (_kind(part) for part in reversed(rest)) if k not in (None, "time")]
        if kinds:
            return kinds[0], j
    return None


def named_out_of_order(columns, joints: tuple[str, ...]) -> list[int] | None:
    """The robot's joint each of a signal's configured columns names, where they name every joint once but not in the
    robot's order (``elbow_joint_position, shoulder_lift_joint_position, shoulder_pan_joint_position, ...``: a ROS
    driver's alphabetical JointState order); else None.

    Parameters
    ----------
    columns : sequence of str or int
        A signal's columns as configured, one per joint (numbers name no joint: None).
    joints : tuple of str
        The description's joint names, in the chain's order.

    Returns
    -------
    list of int or None
        The 0-based joint each column names, in the columns' order.
    """
    if len(columns) != len(joints) or not all(isinstance(c, str) for c in columns):
        return None
    hits = [_named_joint(c, joints) for c in columns]
    order = [hit[1] for hit in hits if hit is not None]
    if len(order) != len(joints) or sorted(order) != list(range(len(joints))) or order == sorted(order):
        return None
    return order


def _in_named_order(found: dict[str, list[str]], first: list[str], row: list[str],
                    joints: tuple[str, ...]) -> list[str]:
    """Where the log names its joints in columns of their own (``rostopic echo -p``'s ``field.name0``…, a JointState's
    names in every row, often alphabetical), each signal's numbered columns reordered into the URDF's joint order, said;
    ``found`` is changed in place."""
    names = {int(m.group(1)): row[i] for i, c in enumerate(first) if i < len(row)
             and (m := re.fullmatch(r".*name[\[_]?(\d+)\]?", c.strip().lower())) is not None}
    order = [names[k] for k in sorted(names)]
    if not set(joints) <= set(order) or order[:len(joints)] == list(joints):
        return []
    taken = [order.index(j) for j in joints]  # the log may name more joints (a gripper's): the URDF's are taken
    moved = [kind for kind, columns in found.items() if kind != "time" and len(columns) == len(order)]
    for kind in moved:
        found[kind] = [found[kind][k] for k in taken]
    return [f"{', '.join(moved)}: the log names its joints in {', '.join(f for f in first if 'name' in f.lower())} "
            f"({', '.join(order)}): taken in the URDF's joint order ({', '.join(joints)})"] if moved else []


COMMANDED = frozenset({"cmd", "command", "commanded", "commands", "desired", "des", "target", "targets", "setpoint",
                       "setpoints", "sp", "ref", "reference", "goal", "demand", "demanded", "ff", "feedforward"})
"""Words of a column name that make it a commanded signal (a controller's set-point or feed-forward), never a measured
one."""


def commanded(name: str, joints: tuple[str, ...] = ()) -> bool:
    """Whether a column holds a commanded signal (:data:`COMMANDED` among its words, the joint names left out):
    ``q_cmd1``, ``/joint_trajectory_controller/state/desired/positions/0``, ``elbow_joint/position_setpoint``.

    Parameters
    ----------
    name : str
    joints : tuple of str
        The URDF's joint names (a word of one of them is no marker).

    Returns
    -------
    bool
    """
    low = name.strip().lower()
    for joint in sorted(joints, key=len, reverse=True):
        low = low.replace(joint.lower(), " ") if joint else low
    return bool(COMMANDED & set(re.split(r"[^a-z]+", low)))


def joints_named(log: Path, joints: tuple[str, ...]) -> set[str]:
    """The joints of ``joints`` that a CSV log's header names beside a signal (``right_s0_pos``,
    ``/joint_states/elbow/effort``; commanded columns left out), for ``dynid init`` to take the arm the log holds
    among a robot file's branches.

    Parameters
    ----------
    log : Path
        A CSV log, or a ROS bag (its first JointState message's names); a headerless log names no joint.
    joints : tuple of str
        The robot file's moving joints.

    Returns
    -------
    set of str

    Raises
    ------
    DataError
        A text log that cannot be read.
    """
    if is_bag(log):  # the names of its first JointState message
        return set(joints) & set(joint_state_names(log))
    if not log.is_file():
        return set()
    lines, delimiter, _ = _first_lines(log)
    first = _fields(lines[0], delimiter)
    if all(_number(c) for c in first):
        return set()
    hits = (None if commanded(c, joints) else _named_joint(c, joints) for c in first)
    return {joints[hit[1]] for hit in hits if hit is not None}


def _by_joint_names(first: list[str], joints: tuple[str, ...]) -> tuple[dict[str, list[str]], list[str]]:
    """Columns naming every joint of the URDF, per signal in the URDF's joint order, and a note per signal whose log
    order differs; a commanded column (:func:`commanded`) is never taken."""
    named: dict[str, dict[int, str]] = {}
    twice: list[str] = []
    for column in first:
        hit = None if commanded(column, joints) else _named_joint(column, joints)
        if hit is not None:
            if hit[1] in named.get(hit[0], {}):
                twice.append(f"{column} (J{hit[1] + 1} {hit[0]} again: {named[hit[0]][hit[1]]} taken)")
            named.setdefault(hit[0], {}).setdefault(hit[1], column)
    found, notes = {}, [f"a joint named twice: {', '.join(twice)}"] if twice else []
    for kind, columns in named.items():
        if len(columns) == len(joints):
            found[kind] = [columns[j] for j in range(len(joints))]
            if found[kind] != [c for c in first if c in found[kind]]:
                notes.append(f"{kind}: taken in the URDF's joint order ({', '.join(joints)}), not the log's")
    return found, notes


def _inline(**entries) -> InlineTable:
    """A TOML inline table of the entries (``{ columns = [...] }``)."""
    table = tomlkit.inline_table()
    table.update(entries)
    return table


ASSUMED_UNITS = {"positions": "rad", "velocities": "rad/s", "torques": "N·m", "currents": "A (through the drive gains)"}
"""The unit each signal's table takes where neither the config nor the column's name gives one."""


def _assumed_units(kinds: list[str], time: bool = False) -> str:
    """The note on the units taken for signals whose columns name none (and for the time, ``time``)."""
    return ("units assumed: " + ("s, " if time else "") + ", ".join(f"{kind} in {ASSUMED_UNITS[kind]}" for kind in kinds)
            + ("; add unit = \"deg\" to positions for degrees" if "positions" in kinds else ""))


SIGNAL_FILE_WORDS = {"positions": frozenset({"pos", "position", "positions", "angle", "angles", "encoder", "q"}),
                     "torques": frozenset({"tau", "torque", "torques", "effort", "efforts", "moment"}),
                     "currents": frozenset({"curr", "current", "currents", "amp", "amps"})}
"""Words of a file's name that say the one signal it holds (FIGAROH's ``pos_read_data.csv`` and ``curr_data.csv``)."""


def signal_files(log: Path, other: Path, n_dof: int, rate: float | None) -> tuple[Table, list[str]] | None:
    """A dataset table for a log split into one file per signal, where ``log`` and ``other`` are such a pair: each a
    column per joint under the same header that names no signal (``Joint_1`` … ``Joint_6``), as many rows, and file
    names that say which holds the angles and which the torques or currents; else None.

    Parameters
    ----------
    log, other : Path
        The logs given first and second.
    n_dof : int
    rate : float or None
        Their sample rate [Hz] (``--rate``): such files have no time column.

    Returns
    -------
    (table, notes) or None

    Raises
    ------
    DataError
        Such a pair without ``rate``, or of different lengths.
    """
    heads = []
    for path in (log, other):
        lines, delimiter, decimal = _first_lines(path)
        header = _fields(lines[0], delimiter)
        if len(header) != n_dof or any(_number(c) or _kind(c) is not None for c in header):
            return None
        heads.append((header, delimiter, decimal))
    kinds = [next((k for k, words in SIGNAL_FILE_WORDS.items() if set(re.split(r"[^a-z]+", p.stem.lower())) & words),
                  None) for p in (log, other)]
    if heads[0] != heads[1] or sorted(map(str, kinds)) not in (["positions", "torques"], ["currents", "positions"]):
        return None
    rows = _row_count(log) - 1, _row_count(other) - 1  # under the header
    if rows[0] != rows[1]:
        raise DataError(f"{log} and {other}: one signal per file, read row by row, but {rows[0]} rows against "
                        f"{rows[1]} under the header: expected the two signals of the same samples (one file cut short?)")
    if rate is None:
        raise DataError(f"{log} and {other}: one signal per file without time stamps: give their sample rate, "
                        "dynid init ... --rate HZ")
    (header, delimiter, decimal), table = heads[0], tomlkit.table()
    table.add("header", True)
    _add_separators(table, delimiter, decimal)
    table.add("rate", float(rate))
    table["rate"].comment("Hz: no time column (--rate)")
    for kind, path in sorted(zip(map(str, kinds), (log, other)), key=lambda kp: kp[0] != "positions"):
        table.add(kind, _inline(file=path.name, columns=header))
    effort = kinds[1] if kinds[0] == "positions" else kinds[0]
    return table, [f"{log.name} and {other.name}: one signal per file ({', '.join(header)}): the positions and the "
                   f"{effort} by the files' names, row by row at {rate:g} Hz"]


def _fields(line: str, delimiter: str) -> list[str]:
    """A line's fields: split at runs of spaces for a space-separated log, else at the delimiter, stripped of spaces
    and of the double quotes a spreadsheet puts around a name (as the reader's header, :func:`read_table`)."""
    return line.split() if delimiter == " " else [c.strip().strip('"') for c in line.split(delimiter)]


def _preset_table(preset: str, log: Path) -> Table:
    """A dataset table that reads ``log`` by one of :data:`dynid.io.logs.dataset_specs.PRESETS`."""
    table = tomlkit.table()
    table.add("preset", preset)
    table.add("file", log.name)
    return table


def _row_count(path: Path) -> int:
    """A text log's lines with something on them."""
    with open(path, encoding="utf-8-sig", errors="replace") as f:
        return sum(1 for line in f if line.strip())


def _rate_unused(rate: float | None, column: str) -> list[str]:
    """The note that ``--rate`` is not used where the log has a time column (none without ``--rate``)."""
    return [] if rate is None else [f"--rate {rate:g} not used: the log's time column ({column}) gives its times"]


def _rate_entry(table: Table, rate: float) -> tuple[list[str], list[str]]:
    """``rate`` added to a dataset's table for a log without a time column at ``--rate``; the notes and the columns
    taken."""
    table.add("rate", rate)
    table["rate"].comment("Hz: no time column (--rate)")
    return [f"no time column: one sample every 1/{rate:g} s (--rate)"], []


def _check_one_signal(log: Path, first: list[str], found: dict, n_dof: int) -> None:
    """A log whose header names one column per joint and no signal (FIGAROH's ``Joint_1`` … ``Joint_6``, one file of
    positions and one of currents) given without its other signal's file (:func:`signal_files`): refused with how
    ``dynid init`` takes the pair and how a config reads one file per signal (it was told "found 0 positions
    column(s)", of a file of positions)."""
    signals = [k for k in found if k != "time"]
    if signals or len(first) - len(found.get("time", [])) != n_dof:
        return
    raise DataError(f"{log}: its {n_dof} columns ({_shown(first)}) name the joints, not a signal: a file of one signal "
                    "(positions, or torques or currents)? Give its other signal's file second, named for its signal "
                    "(dynid init ROBOT pos_data.csv curr_data.csv --rate HZ), or write the [identification] table by "
                    "hand, each signal with its file: positions = { file = "
                    f'"{log.name}", columns = [...] }}, torques = {{ file = "...", columns = [...] }} (or currents), '
                    "header = true, rate = HZ without a time column (docs: configuration, dataset tables)")


def _hold_hint(urdf: Path, joints: tuple[str, ...], count: int) -> str:
    """Where the log has the signals of fewer joints than the URDF: the URDF's last joints held (a gripper's), said;
    nothing for a built-in robot (no file whose joints a config could hold)."""
    if not 0 < count < len(joints) or not urdf.is_file():
        return ""
    rest = ", ".join(json.dumps(j) for j in joints[count:])
    return (f"; if the log holds the first {count} of {urdf.name}'s joints and the rest are a gripper's, hold them: "
            f"[robot] urdf = \"{urdf.name}\", held = [{rest}] (docs: Your robot from a URDF)")


SENSOR_HINT = ('# torques from joint torque sensors on the link side (a KUKA LBR, a Franka)? add sensor = "joint" to '
               "the torques table: no rotor inertia is then fitted")
"""The line under a config's torques that asks what a log cannot say: which side of the gear measured them."""


UNIVERSAL_ROBOTS = re.compile(r"(^|[^a-z0-9])ur(3|5|7|8|10|12|15|16|18|20|30)e?($|[^a-z0-9])", re.IGNORECASE)
"""A description's robot name of a Universal Robots arm (``ur10e``, ``ur5``, ``ur20``), whose RTDE logs have a layout
of their own."""

JOINT_SENSED = re.compile(r"lbr|iiwa|med7|med14|panda|fr3|franka|gen3(?![_\-]?lite)", re.IGNORECASE)
"""Names of arms whose joint torques come from torque sensors on the link side of every gear: KUKA's LBR iiwa and
LBR Med, Franka Emika's Panda and FR3, Kinova's Gen3 (in a URDF's robot name or its file's name). Not Kinova's other
arms: the Gen3 lite has no joint torque sensors, and a Jaco's logs are usually its motor currents."""


def _torque_sensor(table: Table, urdf: Path) -> list[str]:
    """``sensor = "joint"`` added to a dataset's torques where the URDF names an arm of :data:`JOINT_SENSED`, with the
    comment that says so and how to undo it, else :data:`SENSOR_HINT` under them; the note for the header."""
    named = next((n for n in (_robot_name(urdf), urdf.stem) if n and JOINT_SENSED.search(n)), None)
    if named is None:
        table.add(tomlkit.comment(SENSOR_HINT[2:]))
        return []
    why = (f'sensor = "joint" inferred from the name "{named}" in {urdf.name}: an arm with joint torque sensors on the '
           "link side of its gears, whose torques hold no rotor inertia")
    torques = table["torques"]
    assert isinstance(torques, InlineTable)  # added by csv_table
    torques["sensor"] = "joint"
    table.add(tomlkit.comment(f'{why}; write sensor = "drive" if these are motor currents or a motor-side torque'))
    return [why]


def _robot_name(urdf: Path) -> str | None:
    """The ``name`` of a URDF's (or xacro file's) ``<robot>`` element, read as text (nothing of it runs), or None."""
    try:
        head = urdf.read_text(errors="replace")[:20000]
    except OSError:
        return None
    found = re.search(r"<robot\b[^>]*?\bname\s*=\s*[\"']([^\"']*)[\"']", head)
    return found.group(1) if found else None


def _found_columns(first: list[str], row: list[str], joints: tuple[str, ...], n_dof: int) -> tuple[dict, list[str]]:
    """Each signal's columns in a header (by the URDF's joint names first, else by their names' stems), a commanded
    column never taken (:func:`commanded`), and what was noticed."""
    by_name, notes = _by_joint_names(first, joints) if len(joints) == n_dof else ({}, [])
    named = {c for columns in by_name.values() for c in columns}
    skipped = [name for name in first if commanded(name, joints)]
    found: dict[str, list[str]] = {}
    for name in first:
        kind = _kind(name)
        if kind and name not in named and name not in skipped:
            found.setdefault(kind, []).append(name)
    if skipped:
        notes.append(f"commanded, never taken for a measured signal: {', '.join(skipped[:6])}"
                     + (f" and {len(skipped) - 6} more" if len(skipped) > 6 else ""))
    found.update(by_name)
    return found, notes + _in_named_order(found, first, row, joints)


def _time_entry(table: Table, first: list[str], column: str, rows: list[list[str]]) -> tuple[list[str], list[str]]:
    """``time`` added to a dataset's table; what was detected, and the columns taken: a time stamp split into whole
    seconds and nanoseconds (ROS's ``header.stamp.sec`` and ``.nanosec``) is one time of two columns; a single column's
    unit is told from its steps."""
    split_stamp = _seconds_and_nanoseconds(first)
    if split_stamp is not None:
        seconds, nanoseconds = split_stamp
        table.add("time", _inline(column=seconds, nanoseconds=nanoseconds))
        return [f"time stamps: {seconds} + {nanoseconds} (whole seconds and nanoseconds, summed)"], [seconds, nanoseconds]
    unit = _time_unit(rows, first.index(column))
    table.add("time", _inline(column=column, **({"unit": unit} if unit else {})))
    return [f"time stamps: {column} steps as a controller's in {unit}: unit = \"{unit}\""] if unit else [], [column]


def _first_lines(log: Path) -> tuple[list[str], str, str]:
    """A text log's first non-blank lines from its header (or first data line) on, its delimiter and its decimal
    separator: comment lines (``#`` first) left out, a header written as one (NumPy's ``# t,q1,…``) taken as the
    header, data lines written with decimal commas given decimal points."""
    try:
        with log.open(encoding="utf-8-sig") as fh:  # the first lines only (an hour-long log is half a gigabyte); -sig: a BOM
            lines = [line.rstrip("\r\n") for line in itertools.islice(fh, 50) if line.strip()]
    except UnicodeDecodeError:
        raise DataError(f"{log}: not a UTF-8 text table{text_encoding_hint(log)}") from None
    except OSError as exc:
        raise DataError(f"{log}: cannot read it ({exc.strerror or exc})") from None
    comments = next((k for k, line in enumerate(lines) if not line.lstrip().startswith("#")), len(lines))
    if len(lines) - comments < 2:
        raise DataError(f"{log}: fewer than two lines: not a log")
    # the separator that splits the first two lines alike: a header's names hold no decimal comma, which a
    # spreadsheet's export in a European locale puts in every number beside its semicolons
    first, second = lines[comments], lines[comments + 1]
    delimiter = next((d for d in (";", "\t", " ") if len(_fields(second, d)) > 1 and decimal_commas(_fields(second, d))),
                     None)
    decimal = "." if delimiter is None else ","
    if delimiter is None:
        delimiter = max((",", ";", "\t", " "), key=lambda d: (min(first.count(d), second.count(d)), second.count(d)))
    else:
        lines = [line.replace(",", ".") if is_data_line(line.replace(",", "."), delimiter) else line for line in lines]
    if comments and is_data_line(lines[comments], delimiter):
        comments -= 1
        lines[comments] = lines[comments].lstrip()[1:].strip()
    return lines[comments:], delimiter, decimal


def _add_separators(table, delimiter: str, decimal: str) -> None:
    """A dataset table's ``delimiter`` and ``decimal`` where they are not the defaults (a comma, a point)."""
    if delimiter != ",":
        table.add("delimiter", delimiter)
    if decimal != ".":
        table.add("decimal", decimal)


def _time_unit(rows: list[list[str]], column: int) -> str | None:
    """The unit of a log's time column from its first rows (:func:`dynid.conventions.time_unit_of`)."""
    values = []
    for fields in rows:
        try:
            values.append(float(fields[column]))
        except (ValueError, IndexError):
            continue
    steps = sorted(b - a for a, b in zip(values, values[1:]) if b > a)
    return time_unit_of(steps[len(steps) // 2]) if steps else None


def _shown(columns: list[str], most: int = 12) -> str:
    """The header's first columns, for a message."""
    return str(columns[:most])[:-1] + (f", … {len(columns) - most} more]" if len(columns) > most else "]")


def _number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _named(delimiter: str) -> str:
    return {",": "commas", ";": "semicolons", "\t": "tabs", " ": "spaces"}[delimiter]

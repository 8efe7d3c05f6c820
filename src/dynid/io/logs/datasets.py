"""Measured datasets read: a log's columns (:mod:`dynid.io.logs.dataset_specs` says which hold what, and in which units)
converted to SI joint quantities on a uniform time grid, the checks and repairs of :mod:`dynid.io.logs.log_repairs`
applied on the way (:func:`load_recording`)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from numbers import Real
from pathlib import Path

import numpy as np

from ..._util.checks import check_trajectory_array
from ..._util.column_store import SPOOL_BYTES, StoredColumns
from ..._util.keywords import keyword_only_after_data
from ..._util.reprs import short_repr
from ...exceptions import ConfigError, DataError, ShapeError
from ...model.loading import as_robot
from ...model.robot import Robot
from .bags import read_joint_states
from .columns import csv_table, named_out_of_order
from .dataset_specs import DatasetSpec, SignalSpec, dataset_spec
from .log_repairs import (
    AUTO_GAP_SAMPLES,
    GAP_FACTOR,
    MIN_SELECTED,
    _despiked,
    _filled,
    _held_rows,
    _in_time_range,
    _increasing,
    _per_joint,
    _plausibility,
    _row_wise,
    check_clock_unit,
    check_position_steps,
    limit_warnings,
    logged_velocities,
    position_ranges,
    resampled,
    uniform_rate,
    unwrapped_positions,
)
from .table_files import read_table


@short_repr
@dataclass(frozen=True)
class Recording:
    """A measured dataset in SI joint quantities on a uniform time grid. The (N, n_dof) signals are arrays,
    or for a spooled long log :class:`dynid._util.column_store.StoredColumns` (``t`` is always an array).

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
    drive_gains : (n_dof,) array or None
        The drive gains ``tau`` was read through [N·m/A] (motor currents times these, eq. 16); None where it was
        logged or given as torques.
    prismatic : tuple of bool
        Which joints slide (positions [m], forces [N]), as the robot it was read for says; empty: none or not known.
    followers : tuple of int
        The joints that follow another (a URDF's ``<mimic>``: :attr:`dynid.model.robot.Joint.mimic`): the log holds no
        column of theirs; their positions follow that joint's, their torque columns are 0 (that joint's drive
        supplies it).
    """

    name: str
    t: np.ndarray
    q: np.ndarray
    dq: np.ndarray | None
    tau: np.ndarray
    rate: float
    warnings: tuple[str, ...] = field(default=())
    source: str = ""
    drive_gains: np.ndarray | None = None
    prismatic: tuple[bool, ...] = ()
    followers: tuple[int, ...] = ()

    @property
    def n_samples(self) -> int:
        """Number of samples N."""
        return self.t.shape[0]

    @property
    def label(self) -> str:
        """The dataset's name and the files it was read from, for messages: ``"identification (log.csv)"``."""
        return f"{self.name} ({self.source})" if self.source else self.name

    def check(self, n_dof: int) -> None:
        """Refuse a recording that is not one row per time stamp and one column per joint (a recording made by hand:
        the readers' are), or whose arrays hold NaN.

        Parameters
        ----------
        n_dof : int
            The robot's number of joints.

        Raises
        ------
        ShapeError
            Naming the recording, the signal, its shape and the one expected.
        """
        n = np.shape(self.t)[0] if np.ndim(self.t) == 1 else -1
        if n < 0:
            raise ShapeError(f"{self.label}: t has shape {np.shape(self.t)}, expected (N,): one time stamp a sample")
        for name, x in (("q", self.q), ("tau", self.tau), ("dq", self.dq)):
            if x is None and name == "dq":
                continue
            shape = None if x is None else tuple(x.shape)
            if shape != (n, n_dof):
                raise ShapeError(f"{self.label}: {name} has shape {shape}, expected ({n}, {n_dof}): one row per time "
                                 "stamp, one column per joint")
            if isinstance(x, np.ndarray) and not np.all(np.isfinite(x)):
                raise ShapeError(f"{self.label}: {name} holds a NaN or infinite value")


def _detected(log: Path, robot: Robot, rate: float | None = None) -> DatasetSpec:
    """The dataset of a CSV log, its columns found as ``dynid init`` finds them (:func:`dynid.io.logs.columns.csv_table`)."""
    if not log.is_file():
        raise DataError(f"{log}: no such log")
    kept = robot.independent  # the robot's coordinates: a joint that follows another has no column
    table, _ = csv_table(Path("robot.urdf"), log, int(kept.sum()), tuple(j.name for j in robot.joints if j.mimic is None),
                         rate=rate, rate_hint="load_recording(..., rate=HZ)")
    return dataset_spec(table.unwrap(), log.parent, str(log), log.stem, int(kept.sum()), robot.prismatic[kept])


@keyword_only_after_data
def load_recording(spec: DatasetSpec | str | Path, robot: Robot | str | Path, *, spool: bool | None = None,
                   rate: float | None = None, progress: Callable[[float, float], None] | None = None) -> Recording:
    """Read a dataset and convert it to SI joint quantities on a uniform time grid.

    Steps: read the columns (:func:`dynid.io.logs.table_files.read_table`) or the ROS 2 bag's JointState messages, scale
    units, check the time stamps, resample jittered time stamps linearly onto a uniform grid, convert motor-side
    signals through the transmission (``q = R⁻¹ theta_m + offset``, ``tau = Rᵀ tau_m``), currents to torques with the
    drive gains (eq. 16).

    Parameters
    ----------
    spec : DatasetSpec, or a log's path
        A dataset of a config; or a CSV log whose columns are found as ``dynid init`` finds them (a header naming
        time, positions and torques or currents).
    robot : Robot, str or Path
        A built-in robot's name or a description's path is loaded (:func:`dynid.model.loading.as_robot`).
    spool : bool, optional
        Hold the signals in temporary files (:mod:`dynid._util.column_store`) rather than in memory; by default when the
        files hold more than :data:`dynid._util.column_store.SPOOL_BYTES` (an hour-long log). The numbers are the same
        either way.
    rate : float, optional
        [Hz] The sample rate of a CSV log given by its path that has no time column (as ``dynid init --rate``); a
        dataset of a config states its own.
    progress : callable, optional
        ``progress(done, total)``: the files' bytes read, weighed as :data:`READ_SHARE` of the whole (their checks and
        repairs the rest), then ``(total, total)`` when the recording is ready.

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
    ConfigError
        A rate beside a config's dataset, or one that is not a positive number.
    """
    robot = as_robot(robot)
    if rate is not None and not (isinstance(rate, Real) and not isinstance(rate, bool) and np.isfinite(rate) and rate > 0):
        raise ConfigError(f"load_recording: rate: expected a sample rate in Hz above 0, got {rate!r}", field="rate")
    if isinstance(spec, (str, Path)):
        spec = _detected(Path(spec), robot, rate)
    elif not isinstance(spec, DatasetSpec):
        raise TypeError(f"load_recording: expected a log's path or a DatasetSpec (a config's dataset), got "
                        f"{type(spec).__name__}")
    elif rate is not None:
        raise ConfigError(f"load_recording: rate is for a log given by its path; the dataset {spec.name!r} states its "
                          "own (its rate or time column)", field="rate")
    _check_named_order(spec, robot)
    warnings: list[str] = []
    if spec.bag is not None:
        t, raw, where = read_joint_states(spec.bag, robot, spec.name, warnings)
        return _assemble(spec, robot, t, raw, where, timed=True, q_source=str(spec.bag.path),
                         tau_source=str(spec.bag.path), warnings=warnings)
    requests: dict[Path, list] = {}
    for s in list(spec.signals.values()) + ([spec.time] if spec.time else []):
        requests.setdefault(s.file, [])
        for c in s.columns:
            if c not in requests[s.file]:
                requests[s.file].append(c)
    sizes = {p: p.stat().st_size if p.is_file() else 0 for p in requests}
    if spool is None:
        spool = sum(sizes.values()) > SPOOL_BYTES
    tables, total, before = {}, max(sum(sizes.values()), 1), 0
    for path, cols in requests.items():
        dated = spec.time.columns if spec.time is not None and spec.time.file == path and len(spec.time.columns) == 1 else ()
        said = None if progress is None else (lambda done, _, before=before: progress(READ_SHARE * (before + done), total))
        table = read_table(path, cols, header=spec.header, delimiter=spec.delimiter, n_columns=spec.n_columns, rows=spec.rows,
                           spool=spool, missing=True, stamps=dated, decimal=spec.decimal, progress=said)
        tables[path] = (table, cols)
        warnings.extend(table.warnings)
        before += sizes[path]
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
    checks = (lambda share: None) if progress is None else (
        lambda share: progress((READ_SHARE + (1 - READ_SHARE) * share) * total, total))
    recording = _assemble(spec, robot, t, raw, where, timed=spec.time is not None,
                          q_source=str(spec.signals["positions"].file), tau_source=str(spec.signals[tau_kind].file),
                          warnings=warnings, progress=checks)
    checks(1.0)
    return recording


READ_SHARE = 0.6
"""The share of :func:`load_recording`'s time its progress gives the files' reading (the hour-long log of
benchmarks/long_log.py: 3.6 of 6.1 s reading the text, the rest checking, mending and converting the signals)."""


def _check_named_order(spec: DatasetSpec, robot: Robot) -> None:
    """Refuse a signal whose columns name the description's joints in another order than its chain's
    (:func:`dynid.io.logs.columns.named_out_of_order`): read as listed, every joint would get another joint's signal."""
    joints = tuple(j.name for j in robot.joints if j.mimic is None)  # the columns of the robot's coordinates
    for kind, signal in spec.signals.items():
        order = named_out_of_order(signal.columns, joints)
        if order is None:
            continue
        listed = ", ".join(f"{c} is J{j + 1}'s" for k, (c, j) in enumerate(zip(signal.columns, order)) if j != k)
        right = ", ".join(f'"{signal.columns[order.index(j)]}"' for j in range(len(joints)))
        raise ConfigError(f"{spec.table or spec.name}: the {kind}' columns name the robot description's joints in another "
                          f"order than its chain's ({listed}): each joint would be given another's signal; "
                          f"list them in the chain's order, {kind} = {{ columns = [{right}] }} (column numbers are "
                          "taken as listed)", field=f"{kind}.columns")


def _assemble(spec: DatasetSpec, robot: Robot, t, raw: dict, where, *, timed: bool, q_source: str, tau_source: str,
              warnings: list[str], progress: Callable[[float], None] = lambda share: None) -> Recording:
    """Time checks, selection, gaps, resampling, transmission, drive gains and plausibility, shared by every
    kind of dataset; ``where(k)`` names sample k's place in the source (file and line, bag and message);
    ``progress(share)`` as its share of the work goes (about a third each: mending, converting, checking)."""
    n_s = t.shape[0]
    if n_s < 2:
        raise DataError(f"{spec.name}: expected at least 2 samples, got {n_s}")
    if timed:
        t, raw, where = _increasing(spec, t, raw, where, warnings)
    if spec.time_range is not None:
        t, raw, where = _in_time_range(spec, t, raw, where, warnings)
    t, raw, where = _filled(spec, t, raw, where, warnings)
    side = lambda kind: (spec.signals[kind].side if kind in spec.signals else None) or spec.side  # noqa: E731
    raw = _cleaned(spec, t, raw, side("positions") != "motor", warnings)
    progress(1 / 3)
    if (spec.time_range is not None or spec.rows is not None) and t.size < MIN_SELECTED:
        which, value = ("time_range", list(spec.time_range)) if spec.time_range is not None else ("rows", list(spec.rows or ()))
        raise DataError(f"{spec.table or spec.name}: {which} = {value} selects {t.size} samples; at least {MIN_SELECTED} "
                        f"are needed: widen it")
    t, raw, rate = _on_uniform_grid(spec, t, raw, where, timed=timed, q_source=q_source, warnings=warnings)
    raw = _coordinates_widened(robot, raw, spec.table or spec.name, warnings)
    q, dq, tau, kind = _followers_filled(robot, *_joint_side(spec, robot, raw, side, warnings))
    progress(2 / 3)
    _plausibility(spec, robot, t - t[0], q, raw["currents"] if "currents" in raw else raw["torques"], source=q_source,
                  tau_source=tau_source, warnings=warnings)
    source = str(spec.bag.path) if spec.bag is not None else ", ".join(sorted({str(s.file) for s in spec.signals.values()}))
    return Recording(spec.name, t - t[0], q, dq, tau, float(rate), tuple(warnings), source,
                     robot.drive_gains.copy() if kind == "currents" else None, tuple(robot.prismatic.tolist()),
                     robot.followers)


def _on_uniform_grid(spec: DatasetSpec, t, raw: dict, where, *, timed: bool, q_source: str,
                     warnings: list[str]) -> tuple[np.ndarray, dict, float]:
    """:func:`_assemble`'s clock: the time stamps' unit checked, the gaps said, and the samples on a uniform grid at
    the log's rate (a grid whose stamps' digits ran out put back on it; an uneven one, or ``resample``, resampled).
    Returns the time stamps [s], the signals and the rate [Hz] (``spec.rate`` for a log without time stamps)."""
    median = float(np.median(np.diff(t)))
    table = spec.table or spec.name
    if timed and spec.resample is None:  # before the gaps: a log in milliseconds has its gaps in seconds
        check_clock_unit(median, q_source, table)
    if timed:
        _check_gaps(spec, t, where, median, warnings)
    uniform = not timed or np.ptp(np.diff(t)) <= 1e-6 * median
    if timed and not uniform and np.ptp(np.diff(t)) <= 1e-6 * median + 4 * float(np.spacing(np.abs(t).max())):
        # a uniform grid whose stamps' digits run out (POSIX seconds, a date and time: 0.24 µs at 2026's): put back on it
        t, uniform = t[0] + np.arange(t.size) * float(f"{(t[-1] - t[0]) / (t.size - 1):.6g}"), True
    rate = float(spec.rate or 0.0) if not timed else (spec.resample or uniform_rate(t))
    if timed and spec.resample is None:
        check_clock_unit(1.0 / rate, q_source, table)
    if timed and (not uniform or spec.resample is not None):
        t, raw = resampled(t, raw, rate)
    return t, raw, float(rate)


def _coordinates_widened(robot: Robot, raw: dict, name: str = "", warnings: list[str] | None = None) -> dict:
    """Raw signals of the robot's coordinates (a column for each joint that follows none: a log holds no drive of a
    ``<mimic>`` joint) as one column per joint, a joint that follows another given zeros (:func:`_followers_filled`
    sets it); signals with a column for every joint are kept, the followers' columns said unused in ``warnings``."""
    if not robot.followers:
        return raw
    if warnings is not None and np.shape(raw.get("positions", ()))[1:] == (robot.n_dof,):  # every joint's columns
        names = ", ".join(robot.joints[j].name for j in robot.followers)
        warnings.append(f"{name}: the columns of {names} (<mimic>: a joint that follows another) are read and not used: "
                        "their motion is computed from the joints they follow, their torque is those joints'; list the "
                        "other joints' columns alone to leave them out")
    for key, x in raw.items():
        if np.ndim(x) == 2:
            raw[key] = robot.widened(x)
    return raw


def _followers_filled(robot: Robot, q, dq, tau, kind: str):
    """:func:`_joint_side`'s signals with each joint that follows another moving as that joint says, its torque 0
    (the joint it follows supplies it: :meth:`dynid.model.robot.Robot.fold`)."""
    if not robot.followers:
        return q, dq, tau, kind
    q, dq, _ = robot.coupled(q, dq)
    tau = np.array(tau, dtype=float)
    tau[:, list(robot.followers)] = 0.0
    return q, dq, tau, kind


def _cleaned(spec: DatasetSpec, t: np.ndarray, raw: dict, joint_side: bool, warnings: list[str]) -> dict:
    """:func:`_assemble`'s raw signals with joint-side positions unwrapped (a motor may turn near a whole turn between
    samples: not those), rows a logger held repaired and spikes removed, each said in ``warnings``."""
    if "positions" in raw and joint_side:
        raw["positions"] = unwrapped_positions(raw["positions"], spec.name, warnings)
    raw = _held_rows(spec, t, raw, warnings)
    return _despiked(spec, raw, warnings)


def _check_gaps(spec: DatasetSpec, t: np.ndarray, where, median: float, warnings: list[str]) -> None:
    """:func:`_assemble`'s gaps in the time stamps: refused where the spec's ``gaps`` asks, or longer than dynid fills
    by itself or than ``max_gap``; else said (they are filled by the resampling)."""
    table = spec.table or spec.name
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


def _joint_side(spec: DatasetSpec, robot: Robot, raw: dict, side, warnings: list[str]):
    """:func:`_assemble`'s joint-side positions, velocities and torques (motor-side signals through the transmission,
    currents through the drive gains; each raw signal popped as soon as its joint-side one exists), and whether the
    log gave currents or torques."""
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
    return q, dq, tau, kind


def given_recording(robot: Robot, t, q, tau, dq, name: str) -> Recording:
    """A recording given as one (nothing beside it), or made of arrays (:func:`recording_from_arrays`).

    Parameters
    ----------
    robot : Robot
    t : (N,) array [s], or a Recording
    q, tau, dq : (N, n_dof) arrays or None
    name : str

    Returns
    -------
    Recording

    Raises
    ------
    ConfigError
        Arrays beside a recording, or time stamps without positions and torques.
    DataError
        No joint's position ever changes.
    """
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
        Its number of joints is the arrays' width (or its coordinates', where joints follow others: ``<mimic>``).
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
    dynid.io.logs.datasets.Recording
        Starting at t = 0; a warning when the time stamps were interpolated.

    Raises
    ------
    ShapeError
        Arrays of inconsistent shapes, not time-first, or not finite.
    DataError
        Time stamps that do not increase or are slower than any controller logs (another unit:
        :func:`dynid.io.logs.log_repairs.check_clock_unit`), a gap longer than 5 median steps, a position step no motion
        makes (:func:`dynid.io.logs.log_repairs.check_position_steps`), or positions beyond 4π rad (degrees:
        :func:`dynid.io.logs.log_repairs.position_ranges`, which also says the positions outside the joint limits).
    """

    t = np.asarray(t, dtype=float).reshape(-1)
    if robot.followers and np.ndim(q) == 2 and np.shape(q)[1] == int(robot.independent.sum()):  # the coordinates alone
        raw = _coordinates_widened(robot, {"q": q, "tau": tau, **({} if dq is None else {"dq": dq})})
        q, tau, dq = raw["q"], raw["tau"], raw.get("dq")
    q = check_trajectory_array(q, robot.n_dof, "q")
    tau = check_trajectory_array(tau, robot.n_dof, "tau")
    dq = None if dq is None else check_trajectory_array(dq, robot.n_dof, "dq")
    q, dq, tau, _ = _followers_filled(robot, q, dq, tau, "torques")
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
    return Recording(name, t - t[0], q, dq, tau, rate, warnings, prismatic=tuple(robot.prismatic.tolist()),
                     followers=robot.followers)

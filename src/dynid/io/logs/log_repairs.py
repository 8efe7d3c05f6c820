"""The checks and repairs of a log as it is read (:func:`dynid.io.logs.datasets.load_recording`): a clock that restarts or
stalls, gaps and empty fields, rows a faster logger repeated, spikes, wrapped angles, position steps, implausible
efforts, logged velocities that disagree with the positions, jittered time stamps put on a uniform grid. Each says
what it did in the recording's warnings, or refuses the log in one line naming it."""

from __future__ import annotations

from functools import partial

import numpy as np

from ..._util.column_store import StoredColumns, by_column, select_rows
from ...conventions import MOVING_SPAN, TIME_UNITS, time_unit_of
from ...exceptions import DataError
from ...model.robot import Robot
from .dataset_specs import DatasetSpec

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


DEGREE_SPEED = 3.0
"""A joint whose positions move faster than this many times its velocity limit (the 75th percentile of its speed over
:data:`SPEED_SPAN`: a drive's chatter lifts the top percentiles, not this one) and within that limit read as degrees is
logged in degrees: a joint that moves less than 4π degrees is not refused by its range (:func:`position_ranges`). The
real logs' joints move at up to 0.71× their limits so (the TX40's; 1.0× at the 99th percentile), a simulated xArm7
whose drives chatter at 1.8× (20× at the 99th), a joint in degrees 57× its own speed."""


SPEED_SPAN = 0.02
"""s: the span a joint's speed is measured over (not sample to sample, which the encoder's noise and resolution
dominate at a high rate)."""


IMPLAUSIBLE_EFFORT = 1e6
"""|torque| [N·m] or |current| [A] above which a log's value is refused: no robot joint comes near it (the largest
industrial arms' joints carry about 1e5 N·m)."""


def _plausibility(spec: DatasetSpec, robot: Robot, t, q, tau, *, source: str, tau_source: str, warnings: list[str]) -> None:
    """Refuse positions that cannot be radians and implausible efforts, warn about positions outside the joint limits,
    naming joint and time range (a current or torque held at its extreme is found where the log is prepared:
    :func:`dynid.preprocessing.prepared.clipped_samples`)."""
    ranges = position_ranges(robot, t, q, source, steps=True)
    still = ranges[0]
    if all(still):
        raise DataError(f"{source}: no joint's position ever changes ({spec.table or spec.name}): a frozen log, or the "
                        "wrong columns or rows?")
    for j in (j for j, s in enumerate(still) if s and spec.table == "[identification]"):
        warnings.append(f"{source}: joint {j + 1}'s position never changes in [identification] (a joint held still, or "
                        "the wrong column?): what only its motion shows keeps the description's values")
    warnings += limit_warnings(robot, t, ranges, source)
    kind = "currents" if "currents" in spec.signals or (spec.bag is not None and spec.bag.effort == "currents") else "torques"
    for j in range(tau.shape[1]):
        x = tau[:, j]
        peak = np.abs(x).max()
        if peak > IMPLAUSIBLE_EFFORT:
            top = int(np.argmax(np.abs(x)))
            raise DataError(f"{tau_source}: joint {j + 1}'s {kind} reach {x[top]:.4g} at t = {t[top]:.3f} s, implausible for "
                            f"any robot joint (above {IMPLAUSIBLE_EFFORT:.0e}): check the column, its unit and scale")


MAX_STROKE = 100.0
"""[m] A prismatic joint's positions beyond this (or ten times its limits) are refused as millimetres read as metres."""


def position_ranges(robot: Robot, t, q, source: str, *, steps: bool = False,
                    degrees: str = 'positions = { ..., unit = "deg" }'
                    ) -> tuple[list[bool], list[tuple[int, int]], dict[int, float]]:
    """Refuse positions that cannot be radians; say which joints never move and which leave their limits.

    Parameters
    ----------
    robot : Robot
        Its position limits (and with ``steps`` its velocity limits).
    t : (N,) array [s]
    q : (N, n_dof) array or StoredColumns [rad]
        Read one joint at a time.
    source : str
        The file or dataset, for the message.
    steps : bool
        Also refuse a step no motion makes (a reader's check, before the log is unwrapped).
    degrees : str
        How to give degrees, in the message (a config's unit; ``numpy.radians`` for arrays).

    Returns
    -------
    still : list of bool
        Per joint, whether its position never changes.
    outside : list of (int, int)
        Per joint, how many samples leave its limits (by more than 0.05 rad) and the first of them.
    fast : dict
        Joint (0-based) -> its speed [rad/s] where it moves as if its positions were degrees (:data:`DEGREE_SPEED`).

    Raises
    ------
    DataError
        A revolute joint beyond 4π rad: degrees read as radians; a prismatic one beyond ten times its limits (or
        :data:`MAX_STROKE`): millimetres read as metres.
    """
    lim = robot.limits
    t = np.asarray(t, dtype=float)
    span = max(1, int(round(SPEED_SPAN / float(np.median(np.diff(t)))))) if t.size > 1 else 1
    worst, outside, still, fast = np.zeros(q.shape[1]), [], [], {}
    for j in range(q.shape[1]):  # one joint at a time, each read once: q may be stored
        column = np.asarray(q[:, j], dtype=float)
        if steps:
            _position_step(column, t, float(lim.dq_max[j]), j, source)
        worst[j] = np.abs(column).max()
        still.append(bool(column.max() == column.min()))
        k = np.flatnonzero((column < lim.q_min[j] - 0.05) | (column > lim.q_max[j] + 0.05))
        outside.append((k.size, k[0] if k.size else 0))
        if 0 < lim.dq_max[j] < np.inf and t.size > span and not robot.joints[j].prismatic:
            speed = float(np.percentile(np.abs(column[span:] - column[:-span]) / (t[span:] - t[:-span]), 75))
            if speed > DEGREE_SPEED * lim.dq_max[j] and np.radians(speed) <= lim.dq_max[j]:
                fast[j] = speed
    slides = robot.prismatic
    reach = np.maximum(np.abs(lim.q_min), np.abs(lim.q_max))
    metres = np.minimum(MAX_STROKE, np.maximum(1.0, 10 * np.where(np.isfinite(reach), reach, np.inf)))
    if np.any(slides & (worst > metres)):
        j = int(np.argmax(slides & (worst > metres)))
        factors = ", ".join("0.001" if k == j else "1" for k in range(q.shape[1]))
        raise DataError(f"{source}: joint {j + 1} (prismatic) reaches {worst[j]:.4g} m, implausible for metres (its "
                        f"limits reach {reach[j]:.3g} m): are its positions in millimetres (positions = {{ ..., scale = "
                        f"[{factors}] }})?")
    worst[slides] = 0.0  # metres: no angle
    if np.any(worst > 4 * np.pi):
        j = int(np.argmax(worst))
        raise DataError(f"{source}: joint {j + 1} reaches {worst[j]:.4g} rad, implausible for radians: are the "
                        f"positions in degrees ({_degrees_setting(np.flatnonzero(worst > 4 * np.pi), q.shape[1], degrees)})? "
                        "Or a motor's angle, before its gear (side = \"motor\" in the dataset's table, with the gear "
                        "ratios in the robot description's [transmission] gear_ratios)?")
    return still, outside, fast


def _degrees_setting(joints, n_dof: int, degrees: str) -> str:
    """How to read ``joints``' positions as degrees: ``degrees`` (every joint's), and for some joints alone a config's
    per-joint ``scale`` where ``degrees`` is a config's unit."""
    if len(joints) == n_dof or "unit" not in degrees:
        return degrees
    factors = ", ".join(f"{np.pi / 180:.6g}" if j in joints else "1" for j in range(n_dof))
    return f"{degrees}; for {'this joint' if len(joints) == 1 else 'these joints'} alone positions = {{ ..., scale = [{factors}] }}"


def limit_warnings(robot: Robot, t, ranges: tuple, source: str, *,
                   degrees: str = 'positions = { ..., unit = "deg" }') -> list[str]:
    """One warning per joint that leaves its position limits, and per joint that moves faster than its velocity limit
    as if its positions were degrees (:func:`position_ranges`' ``outside`` and ``fast``).

    Parameters
    ----------
    robot : Robot
    t : (N,) array [s]
    ranges : tuple
        :func:`position_ranges`' result.
    source : str
    degrees : str
        How to give degrees, in the message.

    Returns
    -------
    list of str
    """
    lim, (_, outside, fast) = robot.limits, ranges
    setting = _degrees_setting(list(fast), len(outside), degrees)
    return [f"{source}: joint {j + 1} leaves its limits [{lim.q_min[j]:.3g}, {lim.q_max[j]:.3g}] "
            f"{'m' if robot.joints[j].prismatic else 'rad'} during {count} "
            f"samples from t = {t[first]:.3f} s (units, encoder zero, position_offset?)"
            for j, (count, first) in enumerate(outside) if count] + [
        f"{source}: joint {j + 1} moves at {v:.3g} rad/s, {v / lim.dq_max[j]:.0f}× its velocity limit "
        f"({lim.dq_max[j]:.3g} rad/s) and within it read as degrees: are its positions in degrees ({setting})? Read as "
        "radians, its inertia and friction come out scaled" for j, v in fast.items()]


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


def check_clock_unit(step: float, source: str, table: str | None) -> None:
    """Refuse time stamps ``step`` seconds apart when that is slower than any robot controller logs
    (:data:`MIN_RATE`): they hold another unit, which the message guesses.

    Parameters
    ----------
    step : float
        The time stamps' median step, read as seconds.
    source : str
        The file or dataset, for the message.
    table : str or None
        The config table whose time column or rate to fix; None for arrays given to the library (which reads seconds).

    Raises
    ------
    DataError
        Time stamps slower than :data:`MIN_RATE`, with the unit they look like.
    """
    if 1.0 / step >= MIN_RATE:
        return
    unit = time_unit_of(step)
    if table is None:  # arrays: the library reads seconds
        fix, then = f"give t × {TIME_UNITS.get(unit or 's', 1.0):g}, in seconds", ""
    else:
        fix = f'time = {{ ..., unit = "{unit}" }}'
        then = (f"; dynid reads seconds unless the time column's unit says otherwise, or give rate (Hz) in {table} "
                "instead of the time column")
    guess = f"they look like {unit} ({fix})" if unit else "another unit?"
    raise DataError(f"{source}: the time stamps step by {step:.4g} s ({1.0 / step:.4g} Hz), slower than any robot "
                    f"controller logs (at least {MIN_RATE:g} Hz): {guess}{then}")


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


REPEATED_ROWS = 20
"""A validation log repeats the identification log where this many of its sampled positions (distinct rows, of
:data:`REPEAT_SAMPLES`), and at least half of them, are rows of the identification log exactly: the same samples,
whose figures would be the fit's (a log at rest has too few distinct rows to be judged)."""


REPEAT_SAMPLES = 200
"""The evenly spaced rows of a validation log :func:`repeated_share` looks up."""


def repeated_share(reference, other) -> float:
    """The share of ``other``'s sampled positions that are rows of ``reference``'s exactly (0 where fewer than
    :data:`REPEATED_ROWS` of them are distinct).

    Parameters
    ----------
    reference, other : Recording
        Read logs (their positions arrays, or a spooled log's stored columns: one column of ``reference`` is read
        whole, the rest at the candidate rows).

    Returns
    -------
    float
        In [0, 1].
    """
    n = len(other.q)
    rows = np.unique(np.asarray(other.q[np.linspace(0, n - 1, min(n, REPEAT_SAMPLES)).astype(int)], dtype=float),
                     axis=0)
    if len(rows) < REPEATED_ROWS or other.q.shape[1] != reference.q.shape[1]:
        return 0.0
    first = np.asarray(reference.q[:, 0], dtype=float)
    candidates = np.flatnonzero(np.isin(first, rows[:, 0]))
    if candidates.size == 0:
        return 0.0
    found = {tuple(r) for r in np.asarray(reference.q[candidates], dtype=float)}
    return sum(tuple(r) in found for r in rows) / len(rows)

"""A log whose geometry does not match the robot file: a joint's zero a quarter or half turn off, a joint counted the
other way round (its encoder's axis opposite to the robot file's), two position columns swapped (or two joints'
positions and torques), gravity along another axis of the base (a robot mounted on a wall or a ceiling) or along any
direction (mounted tilted).

Encoders, drivers and robot files often count a joint's angle from different zeros: the Stäubli TX40's logged angles
need -π/2 on J2 and +π/2 on J3 to match its URDF. A log's columns need not come in the chain's order, and a URDF
says nothing of how its robot is mounted. A fit cannot tell: the base parameters absorb much of a rotated gravity
load, and what they cannot absorb looks like misfit. The description's nominal model can: with the wrong geometry it
explains little of the torque that gravity and inertia carry, with the right one most of it.

Each joint's measured torque is regressed on the nominal model's torque of that joint beside nuisance columns that
the nominal model does not hold (the joint's direction of motion, velocity and acceleration, a constant, and the
sin/cos of its angle and twice its angle where it has a counterbalance: friction, rotor inertia, an offset and a
counterbalance, whatever their size). What the nominal torque leaves unexplained of what the nuisance columns leave,
summed over the joints, is compared for the logged angles and for the logged angles with one or two joints turned by
±π/2 or π, two joints' position columns swapped (their nuisance columns swapped too; every figure over what the logged
angles' nuisance columns leave, so that all are on one scale), their position and torque columns swapped (a driver's
alphabetical joint order), one joint's states negated, gravity along each axis of the base either way, or along the
direction that explains most (:func:`tilted_gravity`) where it is tilted from every axis. Beside them, the motion
faster or slower than logged (:func:`time_scale`: a log's sample rate or time unit misread scales its velocities and
accelerations, not its angles), named only where it leaves less than every change of geometry.
A change is named where it leaves at most :data:`CHANGE_GAIN` of what the log and the description as they are leave
(Frisch-Waugh: the nominal column is regressed out of the nuisance columns' residual).
"""

from __future__ import annotations

import itertools
from dataclasses import replace

import numpy as np

from .._util.ties import first_least
from ..dynamics.regressor import nominal_rigid_torque
from ..friction import COUNTERBALANCE_TERMS
from ..model.robot import Robot
from .diagnostics import Finding

CANDIDATE_TURNS = (0.5 * np.pi, -0.5 * np.pi, np.pi)
"""The offsets tried on each joint [rad]: zeros that differ by a quarter or a half turn (other conventions, a joint
mounted the other way round)."""

UNEXPLAINED_FROM = 0.05
"""The search runs where the nominal model leaves at least this share of the torque beyond the nuisance columns
unexplained (the right angles leave 0.2-0.4 % on the UR10e's and the LBR Med7's real logs, up to 8.8 % on windows of
3-6 s of the UR10e's, 41 % and 55 % on the TX40's and the KR 300's, whose nominal values are rough guesses; the
Med7's J1 and J3 positions and torques swapped leave 6.7 %: its J1 and J3 carry no gravity torque)."""

MOVED = 0.01
"""The search runs where the nominal model's torque, as logged, varies beyond the nuisance columns by at least this
share of what the measured torque does there: a log at rest says nothing of its geometry (the UR10e's static holds:
1e-7, where every change leaves all unexplained; the cases named in benchmarks/geometry_checks.py: 0.13 or more)."""

CHANGE_GAIN = 0.6
"""A change is named where the nominal model leaves at most this share of what it leaves with the logged angles (the
TX40's log without its offsets: 0.46; the four real logs and 36 windows of them as configured: 0.87 or more)."""

PAIRED_JOINTS = 3
"""Two joints are turned together only among the this many joints whose own turns leave least (the TX40's J2 and J3:
J2's turn alone leaves 0.57 of what the log leaves, with J3's 0.46)."""

SIMPLER = 0.8
"""Two joints changed are named rather than one where they leave less than this share of what the best single turn
leaves."""

TWIN = 1.1
"""Two changes whose nominal torques run with the measured ones and leave within this ratio of each other are twins
the log cannot tell apart: a turn is named before a reversal, with the other beside it."""

TILT_DIRECTIONS = 20_000
"""Gravity directions searched for a tilted mount (:func:`tilted_gravity`): a Fibonacci lattice on the sphere, its
neighbours about 1.4° apart."""

TILTED = (2.0, 10.0)
"""Degrees from the description's gravity, and from every other axis of the base, beyond which the best gravity
direction is a candidate of its own (a robot mounted tilted); nearer another axis, that axis's candidate names it."""

ROUND_SCALES = np.array([2.0, 3.0, 4.0, 5.0, 10.0, 20.0, 50.0, 60.0, 100.0, 1000.0])
"""Time scales a misread rate or unit makes (half or twice the rate, 100 Hz read as 1 kHz, ms as s, minutes):
preferred among those that fit as well."""

TIME_SCALES = np.unique(np.concatenate([10.0 ** np.linspace(-3.0, 3.0, 61), ROUND_SCALES, 1 / ROUND_SCALES]))
"""The time scales :func:`time_scale` tries: from 1000× faster to 1000× slower than logged, 10^0.1 apart, and
:data:`ROUND_SCALES` both ways."""

TIME_SCALE_TIE = 1.25
"""Scales that leave within this ratio of the least are as good (the slowest log's inertial torques are small)."""

RATE_FACTOR = 1.5
"""A time scale is named where the motion is at least this many times slower or faster than logged."""

SAMPLES = (100, 5)
"""The samples of the log the search reads: this many stretches of this many rows each, evenly spaced."""


def unexplained_share(robot: Robot, q, dq, ddq, tau, shifts, *, orders=None, gravities=None, directions=None,
                      channels=None, signed: bool = False) -> np.ndarray:
    """What each change of the logged angles leaves of the torque, as a share of what the nuisance columns of the
    logged angles leave (module docstring).

    Parameters
    ----------
    robot : Robot
        With its nominal inertial parameters.
    q, dq, ddq : (N, n_dof) arrays
        Logged states [rad], [rad/s], [rad/s²].
    tau : (N, n_dof) array
        Measured joint torques [N·m].
    shifts : (S, n_dof) array
        Offsets added to the logged angles [rad].
    orders : (S, n_dof) int array, optional
        For each change, the logged column each joint's states are read from (after the shift); the logged order by
        default.
    gravities : (S, 3) array, optional
        For each change, the gravity vector in the base frame [m/s²]; the description's by default.
    directions : (S, n_dof) array of ±1, optional
        For each change, the factor each joint's logged states are read with: -1 for a joint counted the other way
        round (its encoder's axis opposite to the robot file's); 1 by default.
    channels : (S,) bool array, optional
        For each change, whether the torque columns are read in ``orders`` too (a joint's whole channels swapped with
        another's, a driver's alphabetical joint order); the states alone by default.
    signed : bool
        Count a joint's nominal torque as explaining nothing where it runs against the measured torque (a negative
        slope): tells apart two changes a half turn apart on a joint whose torques that half turn only flips.

    Returns
    -------
    (S,) ndarray
        Σ_j (residual sum of squares of joint j's torque on its nominal torque and nuisance columns, with the change)
        / Σ_j (that on the nuisance columns of the logged angles alone).
    """
    q, dq, ddq, tau = (np.asarray(x, dtype=float) for x in (q, dq, ddq, tau))
    n = robot.n_dof
    shifts = np.asarray(shifts, dtype=float)
    orders = np.tile(np.arange(n), (len(shifts), 1)) if orders is None else np.asarray(orders, dtype=int)
    gravities = (np.tile(np.asarray(robot.gravity, dtype=float), (len(shifts), 1)) if gravities is None
                 else np.asarray(gravities, dtype=float))
    directions = np.ones((len(shifts), n)) if directions is None else np.asarray(directions, dtype=float)
    channels = np.zeros(len(shifts), dtype=bool) if channels is None else np.asarray(channels, dtype=bool)
    reference = _sums(robot, q, dq, ddq, tau, None)[0]
    out = np.empty(len(shifts))
    for i, (shift, order, gravity, way, channel) in enumerate(zip(shifts, orders, gravities, directions, channels)):
        qi, dqi, ddqi = way * (q + shift)[:, order], way * dq[:, order], way * ddq[:, order]
        taui = tau[:, order] if channel else tau
        mounted = robot if np.array_equal(gravity, robot.gravity) else replace(robot, gravity=gravity)
        # a joint counted the other way round may have its torque reversed with it: its slope's sign is free
        left = _sums(robot, qi, dqi, ddqi, taui, nominal_rigid_torque(mounted, qi, dqi, ddqi), signed=signed,
                     free=set(np.flatnonzero(way < 0).tolist()))[0]
        out[i] = left / reference if reference > 0 else 0.0
    return out


def _sums(robot: Robot, q, dq, ddq, tau, nominal, *, signed: bool = False, free: frozenset | set = frozenset()
          ) -> tuple[float, float]:
    """Σ_j the residual sum of squares of joint j's torque on its nuisance columns (and its nominal torque, where
    given: with ``signed``, only where it runs with the measured torque, but on the joints ``free``), and Σ_j the
    nominal torque's own sum of squares beyond the nuisance columns."""
    balanced = _counterbalanced(robot)
    left = variation = 0.0
    for j in range(robot.n_dof):
        basis = _nuisance(q, dq, ddq, j, j in balanced)
        r = tau[:, j] - basis @ (basis.T @ tau[:, j])
        left += float(r @ r)
        if nominal is not None:
            p = nominal[:, j] - basis @ (basis.T @ nominal[:, j])
            pp, pr = float(p @ p), float(p @ r)
            variation += pp
            left -= pr**2 / pp if pp > 1e-12 * max(float(r @ r), 1e-300) and (pr > 0 or not signed or j in free) else 0.0
    return left, variation


def _nuisance(q, dq, ddq, j: int, balanced: bool) -> np.ndarray:
    """An orthonormal basis of joint j's nuisance columns (module docstring): its direction of motion, velocity,
    acceleration and a constant, and with a counterbalance the sin/cos of its angle and twice its angle (they span the
    same space for any offset of the angle)."""
    nuisance = [np.sign(dq[:, j]), dq[:, j], ddq[:, j], np.ones(len(q))]
    if balanced:
        nuisance += [np.sin(q[:, j]), np.cos(q[:, j]), np.sin(2 * q[:, j]), np.cos(2 * q[:, j])]
    return np.linalg.svd(np.column_stack(nuisance), full_matrices=False)[0]


def tilted_gravity(robot: Robot, q, dq, ddq, tau) -> np.ndarray:
    """The gravity vector, of the description's magnitude and along any direction of the base, with which the nominal
    model's torque runs with the measured one and leaves least of it beyond the nuisance columns (a robot mounted
    tilted: on a slanted pedestal, a wall at an angle).

    The gravity torque is linear in the gravity vector, so each direction's torque is the inertial torque plus a
    combination of the torques of gravity along the three axes: :data:`TILT_DIRECTIONS` directions cost four nominal
    torques and each joint's 4×4 Gram matrix.

    Parameters
    ----------
    robot, q, dq, ddq, tau
        The description with its nominal inertial parameters, the logged states [rad], [rad/s], [rad/s²] and the
        measured joint torques [N·m], (N, n_dof) arrays: as :func:`unexplained_share` takes them.

    Returns
    -------
    (3,) ndarray [m/s²]
        In the base frame.
    """
    g = float(np.linalg.norm(robot.gravity))
    still = np.zeros_like(q)
    columns = [nominal_rigid_torque(replace(robot, gravity=np.zeros(3)), q, dq, ddq)]
    columns += [nominal_rigid_torque(replace(robot, gravity=g * axis), q, still, still) for axis in np.eye(3)]
    k = np.arange(TILT_DIRECTIONS) + 0.5  # a Fibonacci lattice: evenly spread directions
    z, turn = 1 - 2 * k / TILT_DIRECTIONS, np.pi * (1 + 5**0.5) * k
    directions = np.column_stack([np.sqrt(1 - z**2) * np.cos(turn), np.sqrt(1 - z**2) * np.sin(turn), z])
    weights = np.column_stack([np.ones(len(directions)), directions])  # the inertial torque, then gravity's
    balanced = _counterbalanced(robot)
    explained = np.zeros(len(directions))
    for j in range(robot.n_dof):
        basis = _nuisance(q, dq, ddq, j, j in balanced)
        r = tau[:, j] - basis @ (basis.T @ tau[:, j])
        b = np.column_stack([c[:, j] for c in columns])
        b -= basis @ (basis.T @ b)
        pp, pr = np.einsum("di,ij,dj->d", weights, b.T @ b, weights), weights @ (b.T @ r)
        explained += np.where((pr > 0) & (pp > 1e-12 * max(float(r @ r), 1e-300)), pr**2 / np.maximum(pp, 1e-300), 0.0)
    return g * directions[int(np.argmax(explained))]


def _with_tilt(robot: Robot, changes: tuple, log: tuple) -> tuple:
    """``changes`` with :func:`tilted_gravity` on ``log`` as one more, where it lies beyond :data:`TILTED` degrees
    from the description's gravity and from every other axis of the base."""
    g = tilted_gravity(robot, *log)
    described = np.asarray(robot.gravity, dtype=float)
    axes = np.concatenate([np.eye(3), -np.eye(3)]) * np.linalg.norm(described)
    degrees = lambda a: np.degrees(np.arccos(np.clip(a @ g / np.linalg.norm(g) ** 2, -1, 1)))  # noqa: E731
    nearest = axes[int(np.argmin(degrees(axes)))]
    if degrees(described) <= TILTED[0] or (degrees(nearest) <= TILTED[1] and not np.allclose(nearest, described)):
        return changes
    n = robot.n_dof
    added = (np.zeros(n), np.arange(n), g, np.ones(n), np.array(False))
    return tuple(np.concatenate([x, a[None]]) for x, a in zip(changes, added))


def candidate_changes(robot: Robot) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """No change; every joint and every pair of joints turned by each of :data:`CANDIDATE_TURNS`; every pair of joints'
    position columns swapped, and their position and torque columns swapped; every joint counted the other way round;
    gravity along each axis of the base either way (those other than the description's).

    Parameters
    ----------
    robot : Robot

    Returns
    -------
    shifts : (S, n_dof) ndarray [rad]
        S = 1 + 3 r + 9 r (r - 1) / 2 + n (n - 1) + n + the gravities, r the revolute joints (a prismatic joint's zero
        is not turned).
    orders : (S, n_dof) int ndarray
        The logged column each joint is read from.
    gravities : (S, 3) ndarray [m/s²]
    directions : (S, n_dof) ndarray of ±1
        The factor each joint's logged states are read with.
    channels : (S,) bool ndarray
        Whether the torque columns are read in ``orders`` too.
    """
    n, g = robot.n_dof, np.asarray(robot.gravity, dtype=float)
    identity = np.arange(n)
    shifts, orders = [np.zeros(n)], [identity]
    turning = [j for j in range(n) if not robot.joints[j].prismatic]  # a sliding joint's zero is no turn
    for size in (1, 2):
        for joints in itertools.combinations(turning, size):
            for turns in itertools.product(CANDIDATE_TURNS, repeat=size):
                row = np.zeros(n)
                row[list(joints)] = turns
                shifts.append(row)
                orders.append(identity)
    channels = [False] * len(shifts)
    for channel, (a, b) in itertools.product((False, True), itertools.combinations(range(n), 2)):
        order = identity.copy()
        order[[a, b]] = b, a
        shifts.append(np.zeros(n))
        orders.append(order)
        channels.append(channel)
    directions = [np.ones(n)] * len(shifts)
    for j in range(n):
        shifts.append(np.zeros(n))
        orders.append(identity)
        directions.append(np.where(identity == j, -1.0, 1.0))
    gravities = [g] * len(shifts)
    for axis, sign in itertools.product(range(3), (1.0, -1.0)):
        other = np.zeros(3)
        other[axis] = sign * np.linalg.norm(g)
        if not np.allclose(other, g):
            shifts.append(np.zeros(n))
            orders.append(identity)
            gravities.append(other)
            directions.append(np.ones(n))
    channels += [False] * (len(shifts) - len(channels))
    return np.array(shifts), np.array(orders), np.array(gravities), np.array(directions), np.array(channels)


def geometry_findings(robot: Robot, q, dq, ddq, tau, dataset: str, *, fitted: bool = True
                      ) -> tuple[list[Finding], dict]:
    """A joint's zero a quarter or half turn from the robot file's, a joint counted the other way round, two joints'
    columns swapped, or gravity along another axis of the base (module docstring).

    Parameters
    ----------
    robot : Robot
        With its nominal inertial parameters.
    q, dq, ddq : (N, n_dof) samples
        The identification log's prepared states [rad], [rad/s], [rad/s²] (arrays, or a spooled log's stored
        columns).
    tau : (N, n_dof) samples
        Its measured joint torques [N·m].
    dataset : str
        The log, named in the finding.
    fitted : bool
        The log the model is fitted to (the finding gives the setting that fixes the description), or a validation log
        (it asks whether the log was recorded otherwise than the identification's, which the robot file fits).

    Returns
    -------
    findings : list of Finding
        One "angles" finding (a zero, a reversal or a swap) or "gravity" finding naming the change and the setting
        (and a twin the log cannot tell from it), or none.
    stats : dict
        ``unexplained`` (the share left with the log and the description as they are), ``nominal_variation`` (how much
        of the torque beyond the nuisance columns the nominal model varies: :data:`MOVED`) and, where the search ran,
        the closest change's ``shift`` [rad], ``order``, ``gravity`` [m/s²], ``direction`` (±1 per joint),
        ``channels`` (the torque columns in ``order`` too) and ``unexplained_changed``, and its ``twin`` (the same keys) where there is one (:func:`_tie_break`).
    """
    raw = (q, dq, ddq, tau)
    q, dq, ddq, tau = (_spread(x) for x in raw)
    reference = _sums(robot, q, dq, ddq, tau, None)[0]
    left, variation = _sums(robot, q, dq, ddq, tau, nominal_rigid_torque(robot, q, dq, ddq))
    logged = left / reference if reference > 0 else 0.0
    stats: dict = {"unexplained": logged, "nominal_variation": variation / reference if reference > 0 else 0.0}
    if logged < UNEXPLAINED_FROM or stats["nominal_variation"] < MOVED:
        return [], stats
    log = (q, dq, ddq, tau)
    changes = _with_tilt(robot, tuple(x[1:] for x in candidate_changes(robot)), log)
    shifts, orders, gravities, ways, channels = changes
    # two joints turned only among the joints whose own turns explain most: the pairs are most of the candidates
    paired = np.count_nonzero(shifts, axis=1) == 2
    scores = np.full(len(shifts), np.inf)
    scores[~paired] = _scored(robot, log, changes, ~paired)
    turned = (np.count_nonzero(shifts, axis=1) == 1) & ~paired
    best_turn = [scores[turned & (shifts[:, j] != 0)].min(initial=np.inf) for j in range(robot.n_dof)]  # a sliding
    # joint is never turned: it ranks last
    top = np.argsort(best_turn, kind="stable")[:PAIRED_JOINTS]
    among = paired & np.all((shifts == 0) | np.isin(np.arange(robot.n_dof), top), axis=1)
    scores[among] = _scored(robot, log, changes, among)
    # one change, unless two joints changed leave clearly less
    single = (np.count_nonzero(shifts, axis=1) + np.count_nonzero(orders != np.arange(robot.n_dof), axis=1)
              + np.count_nonzero(ways < 0, axis=1) + np.any(gravities != np.asarray(robot.gravity, dtype=float), axis=1)) == 1
    one, two = (int(np.flatnonzero(m)[np.argmin(scores[m])]) for m in (single, ~single))  # ties: _tie_break
    pick, twin = _tie_break(robot, log, changes, scores, logged, two if scores[two] < SIMPLER * scores[one] else one,
                            single=single)
    stats.update(shift=shifts[pick].tolist(), order=orders[pick].tolist(), gravity=gravities[pick].tolist(),
                 direction=ways[pick].tolist(), channels=bool(channels[pick]), unexplained_changed=float(scores[pick]))
    if twin is not None:
        stats["twin"] = {"shift": shifts[twin].tolist(), "order": orders[twin].tolist(),
                         "gravity": gravities[twin].tolist(), "direction": ways[twin].tolist(),
                         "channels": bool(channels[twin])}
    rate = _rate_finding(robot, (log, raw), logged, float(scores[pick]), dataset, stats)
    if rate or scores[pick] > CHANGE_GAIN * logged or not _replicated(robot, raw, changes, pick):
        return rate, stats
    share = (f"of the torque that friction, rotor inertia and an offset leave, it explains all but "
             f"{100 * scores[pick]:.2g} % so, all but {100 * logged:.2g} % as it is")
    kind, text, joint = _text_of(robot, log, changes, pick)
    what = text[0] if twin is None else f"{text[0]} (as well on this arm: {_text_of(robot, log, changes, twin)[1][0]})"
    fix = (f"{text[1]}, and identify again" if fitted else "Was this log recorded with other zeros, another column "
           "order or another mounting than the identification log? Its scores say little until it is read as that one")
    return [Finding(kind, f"{dataset}: the description's nominal model fits the torques far better with {what}: "
                          f"{share}. {fix}", joint, fix=_setting(robot, changes, pick) if fitted and twin is None else None
                    )], stats


def _setting(robot: Robot, changes: tuple, pick: int) -> dict | None:
    """The setting that makes the description read the log as change ``pick`` does, where one setting does it:
    ``{"gravity": [gx, gy, gz]}`` (the mounting) or ``{"position_offset": {joint: "pi/2", ...}}`` (zeros turned,
    nothing else changed); None for a reversal or a swap (the columns' order and direction are the reader's)."""
    shifts, orders, gravities, ways, channels = (x[pick] for x in changes)
    if np.any(orders != np.arange(robot.n_dof)) or np.any(ways < 0) or channels:
        return None
    if shifts.any():
        same_mount = np.array_equal(gravities, np.asarray(robot.gravity, dtype=float))
        return {"position_offset": {int(j): _pi_text(shifts[j]) for j in np.flatnonzero(shifts)}} if same_mount else None
    return {"gravity": [float(x) for x in gravities]}


def time_scale(robot: Robot, q, dq, ddq, tau) -> tuple[float, float]:
    """The time scale ``c`` of the log that the description's nominal model explains best: its torque with the motion
    ``c`` times slower than logged is the gravity torque plus the rest divided by ``c²`` (velocities and accelerations
    are derivatives in time), scored as the geometry's candidates are (module docstring), over ``c`` from 1/1000 to
    1000 (:data:`TIME_SCALES`).

    Parameters
    ----------
    robot : Robot
    q, dq, ddq, tau : (N, n_dof) arrays
        The log's states [rad, rad/s, rad/s²] and torques [N·m].

    Returns
    -------
    c : float
        The scale nearest 1 that leaves within :data:`TIME_SCALE_TIE` of the least any scale leaves (a slow log whose
        inertial torques are small fits any slower motion as well: the least slowing that does), 1 or a round one
        (:data:`ROUND_SCALES`) where one does.
    share : float
        What the nominal model leaves at ``c``, of what the nuisance columns leave.
    """
    left = _time_scaled_shares(robot, (q, dq, ddq, tau), TIME_SCALES)
    near = np.flatnonzero(left <= TIME_SCALE_TIE * left.min())
    rounded = [k for k in near if np.any(np.isclose(TIME_SCALES[k], np.concatenate([[1.0], ROUND_SCALES, 1 / ROUND_SCALES])))]
    near = np.asarray(rounded or near)
    k = int(near[np.argmin(np.abs(np.log(TIME_SCALES[near])))])
    return float(TIME_SCALES[k]), float(left[k])


def _time_scaled_shares(robot: Robot, log: tuple, scales) -> np.ndarray:
    """What the nominal model leaves of the torque beyond the nuisance columns with the motion of ``log`` (q, dq, ddq,
    tau) each of ``scales`` times slower (:func:`time_scale`)."""
    q, dq, ddq, tau = log
    reference = _sums(robot, q, dq, ddq, tau, None)[0]
    still = np.zeros_like(dq)
    gravity = nominal_rigid_torque(robot, q, still, still)
    moving = nominal_rigid_torque(robot, q, dq, ddq) - gravity
    return np.array([_sums(robot, q, dq, ddq, tau, gravity + moving / c**2)[0] for c in scales]) / max(reference, 1e-300)


def _rate_finding(robot: Robot, logs: tuple, logged: float, changed: float, dataset: str, stats: dict) -> list:
    """A "rate" finding where the nominal model explains the torques far better with the motion at another speed
    (:func:`time_scale`) than as logged and than the closest change of geometry (``changed``), on the samples searched
    and on another set of them (:func:`_replicated`'s): the log's sample rate or its time column's unit misread."""
    log, raw = logs
    c, share = time_scale(robot, *log)
    stats.update(time_scale=c, unexplained_time_scaled=share)
    if share > CHANGE_GAIN * logged or share >= changed or abs(np.log(c)) < np.log(RATE_FACTOR):
        return []
    if len(raw[0]) > SAMPLES[0] * SAMPLES[1]:
        again = _time_scaled_shares(robot, tuple(_spread(x, 0.5) for x in raw), (1.0, c))
        if again[1] > CHANGE_GAIN * again[0]:
            return []
    way = "slower" if c > 1 else "faster"
    factor = c if c > 1 else 1 / c
    return [Finding("rate", f"{dataset}: the description's nominal model fits the torques far better with the motion "
                            f"about {factor:.3g}× {way} than logged ({100 * share:.2g} % of the torque beyond friction, "
                            f"rotor inertia and an offset left so, {100 * logged:.2g} % as logged): is the log's sample "
                            f"rate (rate = ...) or its time column's unit right? Read at {1 / c:.3g}× the rate it is "
                            "read at now, its velocities and accelerations are the robot's")]


def _replicated(robot: Robot, raw: tuple, changes: tuple, pick: int) -> bool:
    """Whether change ``pick`` leaves at most :data:`CHANGE_GAIN` of what the log as it is leaves on another set of
    samples too (:func:`_spread` at phase 0.5): a change named by the samples' chance is not (a simulated xArm7 whose
    drives chatter: J1 and J2 swapped left 0.59 of it on the samples searched, 0.79-4.3 on others, while a real zero a
    quarter turn off leaves 0.00-0.02 on any)."""
    if len(raw[0]) <= SAMPLES[0] * SAMPLES[1]:
        return True  # the search read every sample
    n = robot.n_dof
    unchanged = (np.zeros(n), np.arange(n), np.asarray(robot.gravity, dtype=float), np.ones(n), np.array(False))
    left = unexplained_share(robot, *(_spread(x, 0.5) for x in raw),
                             **_named(np.stack([a, x[pick]]) for a, x in zip(unchanged, changes)))
    return bool(left[1] <= CHANGE_GAIN * left[0])


def _tie_break(robot: Robot, log: tuple, changes: tuple, scores: np.ndarray, logged: float, pick: int, *, single
               ) -> tuple[int, int | None]:
    """The change named, and a twin as good that the log cannot tell from it (or None). A half turn of a joint, or
    gravity reversed, may only flip torques, which each joint's free slope takes up: of the changes within 5 % of the
    gain, the one whose nominal torques run with the measured ones (a joint counted the other way round may run
    against them: its torque may be reversed with it). Another kind of change as good by that too (to :data:`TWIN`) is
    the twin (the LBR Med7's J2 counted the other way round with its torque, and its J3 turned by 180°: its links nearly
    symmetric)."""
    twins = np.flatnonzero((scores <= scores[pick] + 0.05 * (logged - scores[pick]) + 1e-12) & (single == single[pick]))
    if len(twins) < 2:
        return pick, None
    signed = _scored(robot, log, changes, twins, signed=True)
    reversal = np.any(changes[3][twins] < 0, axis=1)
    tied = [k for k in range(len(twins)) if signed[k] <= TWIN * signed.min() + 1e-12]
    turns = [k for k in tied if not reversal[k]] or tied  # a turn before a reversal as good
    best = turns[first_least(signed[turns])]  # of equals the first (a vertical axis turned by any angle), not the CPU's
    other = [k for k in tied if reversal[k] != reversal[best]]
    return int(twins[best]), (int(twins[other[first_least(signed[other])]]) if other else None)


def _text_of(robot: Robot, log: tuple, changes: tuple, k: int) -> tuple[str, tuple, int | None]:
    """:func:`_change_text` or :func:`_reversed_text` of change ``k``."""
    shifts, orders, gravities, ways, channels = changes
    if np.any(ways[k] < 0):
        q, dq, ddq, tau = log
        return _reversed_text(robot, q, dq, ddq, tau, ways[k])
    return _change_text(robot, shifts[k], orders[k], gravities[k], bool(channels[k]))


def _scored(robot: Robot, log: tuple, changes: tuple, which, *, signed: bool = False) -> np.ndarray:
    """:func:`unexplained_share` of the changes ``which`` (a mask or indices) of ``changes``
    (:func:`candidate_changes`' arrays) on ``log`` (q, dq, ddq, tau)."""
    return unexplained_share(robot, *log, **_named(x[which] for x in changes), signed=signed)


def _named(changes) -> dict:
    """:func:`candidate_changes`' five arrays (or rows of them) as :func:`unexplained_share`'s keywords."""
    return dict(zip(("shifts", "orders", "gravities", "directions", "channels"), changes, strict=True))


def _change_text(robot: Robot, shift: np.ndarray, order: np.ndarray, gravity: np.ndarray, channels: bool = False
                 ) -> tuple[str, tuple, int | None]:
    """The finding's kind, (what was changed, the question and the setting that fixes it), and its joint."""
    if shift.any():
        turned = np.flatnonzero(shift)
        settings = " and ".join(f'position_offset = "{_pi_text(shift[j])}" to J{j + 1}' for j in turned)
        return "angles", (f"the logged angles of {' and '.join(f'J{j + 1}' for j in turned)} turned by "
                          f"{' and '.join(f'{np.degrees(shift[j]):+.0f}°' for j in turned)}",
                          f"Is each encoder's zero where the robot file's is? If not, give {settings} (added to the "
                          "logged angles: in a robot description's [[joints]] tables, or the config's [robot] table "
                          "with one [[robot.joints]] table per joint)"), int(turned[0])
    swapped = np.flatnonzero(order != np.arange(robot.n_dof))
    if swapped.size:
        pair, own = (" and ".join(f"J{j + 1}{mark}" for j in swapped) for mark in ("", "'s"))
        if channels:
            return "angles", (f"the columns of {pair} swapped, positions and torques alike",
                              "Are the columns in the order of the robot's joints (a ROS driver may publish its joint "
                              f"states in alphabetical order)? If not, swap {own} in every signal's columns = [...] "
                              "(positions, torques or currents, velocities) of every dataset"), int(swapped[0])
        return "angles", (f"the logged angles of {pair} swapped",
                          f"Are the positions' columns in the order of the robot's joints? If not, swap {own} in "
                          "positions = { columns = [...] } (and velocities', if given) of every dataset"), int(swapped[0])
    axis = int(np.argmax(np.abs(gravity)))
    tilt = float(np.degrees(np.arccos(min(1.0, abs(gravity[axis]) / np.linalg.norm(gravity)))))
    if tilt > 1.0:
        vector = "[" + ", ".join(f"{x:.2f}" for x in gravity) + "]"
        return "gravity", (f"gravity along {vector} m/s² of the base frame ({tilt:.0f}° from "
                           f"{'+' if gravity[axis] > 0 else '-'}{'xyz'[axis]}), not "
                           "[" + ", ".join(f"{x:g}" for x in robot.gravity) + "] m/s²",
                           "Is the robot mounted tilted (a slanted pedestal, a wall at an angle)? If so, give gravity = "
                           f"{vector} in the config's [robot] table (or the robot description), or the mount's exact "
                           "angle"), None
    vector = "[" + ", ".join(f"{x:g}" for x in gravity) + "]"
    return "gravity", (f"gravity along {'+' if gravity[axis] > 0 else '-'}{'xyz'[axis]} of the base frame, not "
                       "[" + ", ".join(f"{x:g}" for x in robot.gravity) + "] m/s²",
                       "Is the robot mounted otherwise than the description says (on a wall, a ceiling)? If so, "
                       f"give gravity = {vector} in the config's [robot] table (or the robot description)"), None


def _reversed_text(robot: Robot, q, dq, ddq, tau, way: np.ndarray) -> tuple[str, tuple, int]:
    """The finding's kind, (what was changed, the question and the setting), and the joint, for a joint counted the
    other way round: its positions' sign, and its torque's where the nominal torque so runs against the measured one
    (a drive whose whole convention is reversed)."""
    j = int(np.flatnonzero(way < 0)[0])
    signs = ", ".join("-1" if k == j else "1" for k in range(robot.n_dof))
    nominal = nominal_rigid_torque(robot, way * q, way * dq, way * ddq)[:, j]
    runs_against = _sums(robot, q, dq, ddq, tau, nominal[:, None] * (np.arange(robot.n_dof) == j), signed=True)[0] \
        > _sums(robot, q, dq, ddq, tau, -nominal[:, None] * (np.arange(robot.n_dof) == j), signed=True)[0]
    torques = f" and torques = {{ ..., sign = [{signs}] }} (its torque runs the other way too)" if runs_against else ""
    return "angles", (f"the logged angles of J{j + 1} counted the other way round",
                      f"Does J{j + 1}'s encoder count against the robot file's axis? If so, give positions = {{ ..., "
                      f"sign = [{signs}] }}{torques} in every dataset (and velocities', if given)"), j


def _counterbalanced(robot: Robot) -> set[int]:
    """The joints (0-based) with a counterbalance among their drive terms: its torque, a function of the joint's own
    angle whose columns span the same space for any offset of that angle, is a nuisance column too."""
    terms = [k for k, t in enumerate(robot.drive_terms) if t in COUNTERBALANCE_TERMS]
    mask = np.asarray(robot.drive_mask, dtype=bool)
    return {j for j in range(robot.n_dof) if terms and mask[j, terms].any()}


def _spread(x, phase: float = 0.0) -> np.ndarray:
    """:data:`SAMPLES` of an (N, n_dof) signal (an array, or a spooled log's stored columns: only those rows are
    read), the stretches ``phase`` of their spacing from the evenly spaced ones (another set of samples at 0.5)."""
    count, length = SAMPLES
    n = len(x)
    if n <= count * length:
        return np.asarray(x, dtype=float)
    starts = np.linspace(0, n - length, count).astype(int)
    starts = np.minimum(starts + int(phase * (n - length) / max(count - 1, 1)), n - length)
    return np.concatenate([np.asarray(x[a:a + length], dtype=float) for a in starts])


def _pi_text(angle: float) -> str:
    """``"pi/2"``, ``"-pi/2"`` or ``"pi"``: an angle of :data:`CANDIDATE_TURNS` as a description TOML writes it."""
    return {0.5: "pi/2", -0.5: "-pi/2", 1.0: "pi"}[round(angle / np.pi, 1)]

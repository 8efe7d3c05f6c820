"""Logged angles that do not match the robot file: a joint's zero a quarter or half turn off, two columns swapped.

Encoders, drivers and robot files often count a joint's angle from different zeros: the Stäubli TX40's logged angles
need -π/2 on J2 and +π/2 on J3 to match its URDF. And a log's columns need not come in the chain's order. A fit cannot
tell: the base parameters absorb much of a rotated gravity load, and what they cannot absorb looks like misfit. The
description's nominal model can: with the logged angles it explains little of the torque that gravity and inertia
carry, with the right ones most of it.

Each joint's measured torque is regressed on the nominal model's torque of that joint beside nuisance columns that
the nominal model does not hold (the joint's direction of motion, velocity and acceleration, a constant, and the
sin/cos of its angle and twice its angle where it has a counterbalance: friction, rotor inertia, an offset and a
counterbalance, whatever their size). What the nominal torque leaves unexplained of what the nuisance columns leave,
summed over the joints, is compared for the logged angles and for the logged angles with one or two joints turned by
±π/2 or π, or two joints' columns swapped (their nuisance columns swapped too; every figure over what the logged
angles' nuisance columns leave, so that all are on one scale). A change is named where it leaves at most :data:`CHANGE_GAIN` of what the
logged angles leave (Frisch-Waugh: the nominal column is regressed out of the nuisance columns' residual).
"""

from __future__ import annotations

import itertools

import numpy as np

from ..dynamics.regressor import nominal_rigid_torque
from ..friction import COUNTERBALANCE_TERMS
from ..model.robot import Robot
from .diagnostics import Finding

CANDIDATE_TURNS = (0.5 * np.pi, -0.5 * np.pi, np.pi)
"""The offsets tried on each joint [rad]: zeros that differ by a quarter or a half turn (other conventions, a joint
mounted the other way round)."""

UNEXPLAINED_FROM = 0.1
"""The search runs where the nominal model leaves at least this share of the torque beyond the nuisance columns
unexplained (the right angles leave 0.2-0.4 % on the UR10e's and the LBR Med7's real logs, 41 % and 55 % on the
TX40's and the KR 300's, whose nominal values are rough guesses)."""

CHANGE_GAIN = 0.6
"""A change is named where the nominal model leaves at most this share of what it leaves with the logged angles (the
TX40's log without its offsets: 0.46; the four real logs and 36 windows of them as configured: 0.87 or more)."""

SIMPLER = 0.8
"""Two joints changed are named rather than one where they leave less than this share of what the best single turn
leaves."""

SAMPLES = (200, 5)
"""The samples of the log the search reads: this many stretches of this many rows each, evenly spaced."""


def unexplained_share(robot: Robot, q, dq, ddq, tau, shifts, orders=None, *, signed: bool = False) -> np.ndarray:
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
    balanced = _counterbalanced(robot)

    def left(qi, dqi, ddqi, nominal) -> float:
        """Σ_j the residual sum of squares of joint j's torque on its nuisance columns (and its nominal torque)."""
        total = 0.0
        for j in range(n):
            nuisance = [np.sign(dqi[:, j]), dqi[:, j], ddqi[:, j], np.ones(len(q))]
            if j in balanced:  # spans the same space for any offset of the joint's angle
                nuisance += [np.sin(qi[:, j]), np.cos(qi[:, j]), np.sin(2 * qi[:, j]), np.cos(2 * qi[:, j])]
            basis = np.linalg.svd(np.column_stack(nuisance), full_matrices=False)[0]
            r = tau[:, j] - basis @ (basis.T @ tau[:, j])
            total += float(r @ r)
            if nominal is not None:
                p = nominal[:, j] - basis @ (basis.T @ nominal[:, j])
                pp, pr = float(p @ p), float(p @ r)
                total -= pr**2 / pp if pp > 1e-12 * max(float(r @ r), 1e-300) and (pr > 0 or not signed) else 0.0
        return total

    reference = left(q, dq, ddq, None)
    out = np.empty(len(shifts))
    for i, (shift, order) in enumerate(zip(shifts, orders)):
        qi, dqi, ddqi = (q + shift)[:, order], dq[:, order], ddq[:, order]
        out[i] = left(qi, dqi, ddqi, nominal_rigid_torque(robot, qi, dqi, ddqi)) / reference if reference > 0 else 0.0
    return out


def candidate_changes(n_dof: int) -> tuple[np.ndarray, np.ndarray]:
    """No change; every joint and every pair of joints turned by each of :data:`CANDIDATE_TURNS`; every pair of joints'
    columns swapped.

    Parameters
    ----------
    n_dof : int

    Returns
    -------
    shifts : (1 + 3 n + 9 n (n - 1) / 2 + n (n - 1) / 2, n_dof) ndarray [rad]
    orders : the same shape, int
        The logged column each joint is read from.
    """
    identity = np.arange(n_dof)
    shifts, orders = [np.zeros(n_dof)], [identity]
    for size in (1, 2):
        for joints in itertools.combinations(range(n_dof), size):
            for turns in itertools.product(CANDIDATE_TURNS, repeat=size):
                row = np.zeros(n_dof)
                row[list(joints)] = turns
                shifts.append(row)
                orders.append(identity)
    for a, b in itertools.combinations(range(n_dof), 2):
        order = identity.copy()
        order[[a, b]] = b, a
        shifts.append(np.zeros(n_dof))
        orders.append(order)
    return np.array(shifts), np.array(orders)


def logged_angle_findings(robot: Robot, q, dq, ddq, tau, dataset: str) -> tuple[list[Finding], dict]:
    """A joint's zero a quarter or half turn from the robot file's, or two joints' columns swapped (module docstring).

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

    Returns
    -------
    findings : list of Finding
        One "angles" finding naming the joints, the change and the setting, or none.
    stats : dict
        ``unexplained`` (the share left with the logged angles) and, where the search ran, the closest change's
        ``shift`` [rad], ``order`` and ``unexplained_changed``.
    """
    q, dq, ddq, tau = (_spread(x) for x in (q, dq, ddq, tau))
    logged = float(unexplained_share(robot, q, dq, ddq, tau, np.zeros((1, robot.n_dof)))[0])
    stats: dict = {"unexplained": logged}
    if logged < UNEXPLAINED_FROM:
        return [], stats
    shifts, orders = (x[1:] for x in candidate_changes(robot.n_dof))
    scores = unexplained_share(robot, q, dq, ddq, tau, shifts, orders)
    # one joint turned, unless two joints changed leave clearly less (a half turn of a joint whose torque only changes
    # sign, which each joint's free slope takes up, is no evidence)
    single = np.count_nonzero(shifts, axis=1) + np.count_nonzero(orders != np.arange(robot.n_dof), axis=1) == 1
    one, two = (int(np.flatnonzero(m)[np.argmin(scores[m])]) for m in (single, ~single))
    pick = two if scores[two] < SIMPLER * scores[one] else one
    # a joint whose torques a half turn only flips leaves two changes a half turn apart about as good (within 5 % of the
    # gain): the one whose nominal torques run with the measured ones, not against them
    twins = np.flatnonzero((scores <= scores[pick] + 0.05 * (logged - scores[pick]) + 1e-12) & (single == single[pick]))
    if len(twins) > 1:
        pick = int(twins[np.argmin(unexplained_share(robot, q, dq, ddq, tau, shifts[twins], orders[twins], signed=True))])
    stats.update(shift=shifts[pick].tolist(), order=orders[pick].tolist(), unexplained_changed=float(scores[pick]))
    if scores[pick] > CHANGE_GAIN * logged:
        return [], stats
    share = (f"of the torque that friction, rotor inertia and an offset leave, it explains all but "
             f"{100 * scores[pick]:.2g} % so, all but {100 * logged:.2g} % as logged")
    if shifts[pick].any():
        turned = np.flatnonzero(shifts[pick])
        settings = " and ".join(f'position_offset = "{_pi_text(shifts[pick][j])}" to J{j + 1}' for j in turned)
        text = (f"the description's nominal model fits the torques far better with the logged angles of "
                f"{' and '.join(f'J{j + 1}' for j in turned)} turned by "
                f"{' and '.join(f'{np.degrees(shifts[pick][j]):+.0f}°' for j in turned)}: {share}. Is each "
                f"encoder's zero where the robot file's is? If not, give {settings} (added to the logged angles: in "
                "a robot description's [[joints]] tables, or the config's [robot] table with one [[robot.joints]] "
                "table per joint) and identify again")
    else:
        turned = np.flatnonzero(orders[pick] != np.arange(robot.n_dof))
        pair = " and ".join(f"J{j + 1}" for j in turned)
        text = (f"the description's nominal model fits the torques far better with the logged angles of {pair} "
                f"swapped: {share}. Are the positions' columns in the order of the robot's joints? If not, swap "
                f"{pair}'s in positions = {{ columns = [...] }} (and velocities', if given) of every dataset, and "
                "identify again")
    return [Finding("angles", f"{dataset}: {text}", int(turned[0]))], stats


def _counterbalanced(robot: Robot) -> set[int]:
    """The joints (0-based) with a counterbalance among their drive terms: its torque, a function of the joint's own
    angle whose columns span the same space for any offset of that angle, is a nuisance column too."""
    terms = [k for k, t in enumerate(robot.drive_terms) if t in COUNTERBALANCE_TERMS]
    mask = np.asarray(robot.drive_mask, dtype=bool)
    return {j for j in range(robot.n_dof) if terms and mask[j, terms].any()}


def _spread(x) -> np.ndarray:
    """:data:`SAMPLES` of an (N, n_dof) signal (an array, or a spooled log's stored columns: only those rows are
    read)."""
    count, length = SAMPLES
    n = len(x)
    if n <= count * length:
        return np.asarray(x, dtype=float)
    starts = np.linspace(0, n - length, count).astype(int)
    return np.concatenate([np.asarray(x[a:a + length], dtype=float) for a in starts])


def _pi_text(angle: float) -> str:
    """``"pi/2"``, ``"-pi/2"`` or ``"pi"``: an angle of :data:`CANDIDATE_TURNS` as a description TOML writes it."""
    return {0.5: "pi/2", -0.5: "-pi/2", 1.0: "pi"}[round(angle / np.pi, 1)]

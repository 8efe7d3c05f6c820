"""A log prepared for the estimators, whichever strategy prepared it (:mod:`dynid.preprocessing.strategies`): its
filtered signals on a uniform grid, its resolved settings, and where and in which direction each joint moves — the
friction state at rest that every Coulomb-like regressor column uses (:func:`dynid.friction.held_direction`)."""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from .._util.column_store import by_column
from .._util.reprs import short_repr
from ..conventions import MOVING_SPAN
from ..exceptions import ConfigError, DataError
from ..friction import Velocities, held_direction
from ..model.robot import Robot
from .settings import Preprocessing

__all__ = ["check_velocities", "clipped_samples", "dead_channels", "PreparedData", "Samples", "direction_of_motion",
           "min_speeds", "rest_decay", "rest_velocities"]

Samples = Any
"""An (N, n_dof) signal: an array, or for a spooled long log :class:`dynid._util.column_store.StoredColumns`."""


@short_repr
@dataclass(frozen=True)
class PreparedData:
    """Filtered joint signals on a uniform grid, ready for the regressor.

    Signals are arrays, or for a spooled long log :class:`dynid._util.column_store.StoredColumns` (``t`` is always an array).

    Attributes
    ----------
    name : str
        The dataset.
    t : (N,) array [s]
    q, dq, ddq : (N, n_dof) samples [rad, rad/s, rad/s²]
    tau : (N, n_dof) samples [N·m]
        Joint torques (drive gains applied).
    rate : float [Hz]
        Rate of the grid (after decimation).
    settings : Preprocessing
        Resolved settings.
    warnings : tuple of str
    direction : (N, n_dof) array or None
        Direction of motion the Coulomb-like columns use (:func:`dynid.friction.held_direction`).
    motion : (N, n_dof) array or None
        The velocity [rad/s] that says where a joint moves (no overshoot where it stops).
    resting : (N, n_dof) bool array or None
        Where each joint rests (:func:`dynid.friction.moving_joints`).
    dead : tuple of int
        Joints whose measured torque is constant over the log (:func:`dead_channels`) or saturated throughout
        (:func:`clipped_samples`).
    still : tuple of int
        Joints whose position never changes in the log.
    clipped : (N, n_dof) bool array or None
        Samples where a joint's measured torque is held at its extreme (:func:`clipped_samples`).
    drive_gains : (n_dof,) array or None
        The drive gains the torques were read through (the recording's: motor currents times these, eq. 16); None
        where they were logged or given as torques.
    followers : tuple of int
        Joints that follow another (``<mimic>``): among ``dead``, no dead channel to speak of.
    """

    name: str
    t: np.ndarray
    q: Samples
    dq: Samples
    ddq: Samples
    tau: Samples
    rate: float
    settings: Preprocessing
    warnings: tuple[str, ...] = ()
    direction: np.ndarray | None = None
    """(N, n_dof) direction of motion the Coulomb-like columns use (:func:`dynid.friction.held_direction`)."""
    motion: np.ndarray | None = None
    """(N, n_dof) the velocity [rad/s] that says where a joint moves (no overshoot where it stops)."""
    resting: np.ndarray | None = None
    """(N, n_dof) bool: where each joint rests (:func:`dynid.friction.moving_joints`)."""
    dead: tuple[int, ...] = ()
    """Joints (0-based) whose measured torque is constant over the whole log (:func:`dead_channels`), or at its limit
    so long that it is taken as saturated throughout (:func:`clipped_samples`): their rows are used by no estimate and
    no metric."""
    still: tuple[int, ...] = ()
    """Joints (0-based) whose position never changes in the log (a joint held still): their rows are used by no
    estimate (their friction at rest is anywhere in its static band, and their drive terms appear in no other row)."""
    clipped: np.ndarray | None = None
    """(N, n_dof) bool, or None where nothing is: samples where a joint's measured torque is held at its extreme
    (:func:`clipped_samples`): that joint's rows there are used by no estimate, and those samples by no metric."""
    drive_gains: np.ndarray | None = None
    """(n_dof,) the drive gains the torques were read through (eq. 16), or None: logged or given as torques."""
    followers: tuple[int, ...] = ()
    """Joints that follow another (``<mimic>``): among :attr:`dead` (their rows are folded into that joint's and hold
    nothing: :meth:`dynid.model.robot.Robot.fold`), but no dead channel to speak of (:attr:`dead_said`)."""

    @property
    def dead_said(self) -> tuple[int, ...]:
        """The dead or saturated channels a line names: :attr:`dead` less the joints that follow another."""
        return tuple(j for j in self.dead if j not in self.followers)

    def kept(self, index: np.ndarray, vmin: np.ndarray) -> np.ndarray:
        """The rows an estimate uses: joints moving at least ``vmin``, none of a dead channel or of a joint held still,
        none where a joint's torque is clipped.

        Parameters
        ----------
        index : (M,) int array
            Sample indices.
        vmin : (n_dof,) array [rad/s]
            Minimum speed of each joint.

        Returns
        -------
        (M, n_dof) bool array
        """
        keep = np.abs(np.asarray(self.dq[index])) >= vmin
        if self.dead or self.still:
            keep[:, list(self.dead) + list(self.still)] = False
        if self.clipped is not None:
            keep &= ~self.clipped[index]
        return keep

    def scored(self, index: np.ndarray) -> np.ndarray:
        """The samples the metrics score: all but those where some joint's torque is clipped.

        Parameters
        ----------
        index : (M,) int array
            Sample indices.

        Returns
        -------
        (M,) bool array
        """
        if self.clipped is None:
            return np.ones(len(index), dtype=bool)
        return ~self.clipped[index].any(axis=1)

    def with_rest_model(self, rest_friction, presliding) -> PreparedData:
        """The same samples with another rest model and presliding distance.

        The direction of motion is computed anew where the rest model or a presliding distance changes; the settings
        say so either way.

        Parameters
        ----------
        rest_friction : str, float or tuple
            "held", "zero", a relaxation time [s], or one per joint.
        presliding : float or tuple
            Presliding distance [rad], or one per joint.

        Returns
        -------
        PreparedData
        """
        s = replace(self.settings, rest_friction=rest_friction, presliding=presliding)
        if self.direction is not None and _same_rest_model(self.settings, s, self.dq.shape[1]):
            return replace(self, settings=s)  # the same direction, not computed again
        return replace(self, settings=s, direction=direction_of_motion(self.dq, self.motion, s, self.rate))

    def with_min_speed(self, min_speed, note: str = "") -> PreparedData:
        """The same samples with other slowest speeds that the estimation fits.

        Parameters
        ----------
        min_speed : (n_dof,) array [rad/s]
            Each joint's slowest speed fitted (:meth:`kept`).
        note : str
            Why, appended to the settings' ``derivation``.

        Returns
        -------
        PreparedData
        """
        s = replace(self.settings, min_speed=tuple(float(v) for v in min_speed),
                    derivation=self.settings.derivation + note)
        return replace(self, settings=s)


def _per_joint(value, n: int, where: str, allowed=None) -> np.ndarray:
    v = np.asarray(value)
    v = np.full(n, v.item()) if v.ndim == 0 else v
    if v.shape != (n,) or (allowed is not None and not set(v.tolist()) <= allowed):
        raise ConfigError(f"preprocessing.{where}: expected one value or {n} of them"
                          + (f" among {sorted(allowed)}" if allowed else "") + f", got {value!r}")
    return v


def _same_rest_model(a: Preprocessing, b: Preprocessing, n: int) -> bool:
    """Whether two settings give every joint the same rest model and presliding distance (the direction of motion's
    settings that :meth:`PreparedData.with_rest_model` changes)."""
    return (np.array_equal(rest_decay(a.rest_friction, n), rest_decay(b.rest_friction, n))
            and np.array_equal(_per_joint(a.presliding, n, "presliding").astype(float),
                               _per_joint(b.presliding, n, "presliding").astype(float)))


def direction_of_motion(dq, guide, s: Preprocessing, rate: float):
    """Each joint's direction of motion, column by column (stored columns stay stored).

    :func:`dynid.friction.held_direction` with the log's rest velocities, rest model and presliding distances.

    Parameters
    ----------
    dq : (N, n_dof) samples [rad/s]
        Velocities.
    guide : (N, n_dof) samples [rad/s]
        Velocity that says where a joint moves.
    s : Preprocessing
        Resolved settings.
    rate : float [Hz]

    Returns
    -------
    (N, n_dof) array or StoredColumns
        In [-1, 1].
    """
    n = dq.shape[1]
    guide = dq if guide is None else guide
    rest = _per_joint(0.0 if s.rest_velocity == "auto" else s.rest_velocity, n, "rest_velocity").astype(float)
    decay = rest_decay(s.rest_friction, n)
    x0 = _per_joint(s.presliding, n, "presliding").astype(float)
    cutoff = s.band if s.fourier is not None else (s.velocity_cutoff or s.position_cutoff or rate / 4)
    travel = rest / cutoff  # a blip of the rest velocity's size lasts about 1/cutoff
    return by_column(dq, lambda column, j: held_direction(column[:, None], rest[j], decay[j], presliding=x0[j], rate=rate,
                                                          guide=np.asarray(guide[:, j])[:, None], min_travel=travel[j])[:, 0])


def rest_decay(value, n: int) -> np.ndarray:
    """``rest_friction`` as relaxation times.

    Parameters
    ----------
    value : str, float or tuple
        "held", "zero", seconds, or one per joint.
    n : int
        Number of joints.

    Returns
    -------
    (n,) ndarray [s]
        inf: held; 0: zero.
    """
    v = _per_joint(value, n, "rest_friction")
    try:
        return np.array([np.inf if x == "held" else 0.0 if x == "zero" else float(x) for x in v.tolist()])
    except (TypeError, ValueError):
        raise ConfigError(f'preprocessing.rest_friction: expected "held", "zero" or a relaxation time in seconds, '
                          f"got {value!r}") from None


def rest_velocities(data: PreparedData, robot: Robot) -> Velocities:
    """The friction columns' velocities for a log: the robot's, with the log's rest velocity and direction.

    Parameters
    ----------
    data : PreparedData
    robot : Robot

    Returns
    -------
    Velocities
    """
    v = robot.friction_velocities
    rest = data.settings.rest_velocity
    return Velocities(v.coulomb, v.stribeck, np.broadcast_to(np.asarray(0.0 if rest == "auto" else rest, dtype=float),
                                                               (robot.n_dof,)), None)


def min_speeds(settings: Preprocessing, n: int) -> np.ndarray:
    """``min_speed`` per joint, checked.

    Parameters
    ----------
    settings : Preprocessing
        Resolved (a number or one per joint, not "auto").
    n : int
        Number of joints.

    Returns
    -------
    (n,) ndarray [rad/s]

    Raises
    ------
    ConfigError
        A negative speed, or not one per joint.
    """
    v = np.asarray(settings.min_speed, dtype=float)
    if v.ndim == 0:
        v = np.full(n, float(v))
    if v.shape != (n,) or np.any(v < 0):
        raise ConfigError(f"preprocessing.min_speed: expected a non-negative number or {n} of them, got {settings.min_speed!r}")
    return v


VELOCITY_SHAPE = 0.9
"""Correlation from which measured velocities and the positions' derivative have the same shape
(:func:`check_velocities`)."""

VELOCITY_UNLIKE = 0.5
"""Correlation below which measured velocities do not follow the positions' derivative at all, on a joint whose
positions span more than :data:`dynid.conventions.MOVING_SPAN` (:func:`check_velocities`)."""

VELOCITY_RATIO = 2.0
"""Measured velocities more than this many times the positions' derivative, or less than its inverse, or of the
opposite sign, are in another unit, sign or side than the positions (:func:`check_velocities`)."""


def check_velocities(dq, from_positions, label: str, *, positions=None) -> None:
    """Refuse measured velocities that are not the derivative of the positions: where a joint's two have the same
    shape (correlation at least :data:`VELOCITY_SHAPE` in magnitude), their ratio must lie within a factor
    :data:`VELOCITY_RATIO` of 1 (deg/s read as rad/s gives 57.3, a motor-side velocity the gear ratio, a flipped
    sign -1): a model fitted with them has every velocity-dependent term wrong. Where the joint moves (its
    ``positions`` span more than :data:`dynid.conventions.MOVING_SPAN`), they must have its shape at all
    (correlation at least :data:`VELOCITY_UNLIKE`): another joint's column, or currents read as velocities (which a
    viscous term then fits as the torque, below the noise floor), are refused.

    Parameters
    ----------
    dq : (N, n_dof) array or StoredColumns [rad/s]
        The measured velocities, filtered.
    from_positions : (N, n_dof) array or StoredColumns [rad/s]
        The derivative of the filtered positions.
    label : str
        The dataset, for the message.
    positions : (N, n_dof) array or StoredColumns [rad], optional
        The filtered positions, whose span says which joints move (without them, no joint is required to).

    Raises
    ------
    DataError
        Naming the dataset, the joint, the ratio or correlation and the settings to check.
    """
    for j in range(dq.shape[1]):
        v = np.asarray(dq.column(j) if hasattr(dq, "column") else dq[:, j], dtype=float)
        d = np.asarray(from_positions.column(j) if hasattr(from_positions, "column") else from_positions[:, j],
                       dtype=float)
        vv, dd, vd = float(v @ v), float(d @ d), float(v @ d)
        if positions is not None and vv > 0 and dd > 0 and abs(vd) < VELOCITY_UNLIKE * np.sqrt(vv * dd):
            x = np.asarray(positions.column(j) if hasattr(positions, "column") else positions[:, j], dtype=float)
            span = float(np.ptp(x))
            if span > MOVING_SPAN:
                raise DataError(f"{label}: joint {j + 1}'s measured velocities do not follow the derivative of its "
                                f"positions (correlation {vd / np.sqrt(vv * dd):.2f} over a motion of {span:.3g} rad): "
                                "another joint's column, or not velocities? check the velocities' columns, or leave "
                                "them out (velocities = false) to derive them from the positions")
        if vv <= 0 or dd <= 0 or abs(vd) < VELOCITY_SHAPE * np.sqrt(vv * dd):
            continue
        ratio = vd / dd
        if 1 / VELOCITY_RATIO <= ratio <= VELOCITY_RATIO:
            continue
        hint = (" (deg/s read as rad/s?)" if abs(ratio / (180 / np.pi) - 1) < 0.1 else
                " (time stamps in milliseconds?)" if abs(ratio / 1000 - 1) < 0.1 else
                " (positions in degrees?)" if abs(ratio / (np.pi / 180) - 1) < 0.1 else
                " (a flipped sign?)" if abs(ratio + 1) < 0.1 else "")
        raise DataError(f"{label}: joint {j + 1}'s measured velocities are {ratio:.4g}× the derivative of its "
                        f"positions{hint}: check their unit, sign and side (velocities = {{ ..., unit = \"deg/s\" }}, "
                        "sign = -1 or side = \"motor\"), or leave them out (velocities = false) to derive them "
                        "from the positions")


SATURATION_SAMPLES = 20
"""Consecutive samples at a joint's extreme value that count as saturation (a clipped current or torque)."""
QUANTISED_SHARE = 0.05
"""A channel with at least this share of consecutive samples reading the same value (away from its extremes) is
quantised (logged in steps, e.g. 0.1 N·m): a smooth peak then also reads one value for many samples, and a run at the
extreme counts as saturation only where the torque on both sides of it heads beyond it (:func:`_heads_beyond`)."""
FLANK_STEPS = 3
"""The flanks of a run in a quantised channel: the samples next to it within this many steps (:func:`_quantum`) of
its value."""
BEYOND_STEPS = 1.0
"""A run in a quantised channel is saturation where its flanks' parabola exceeds it by more than this many steps."""
SCORED_SHARE = 0.5
"""The share of a log's samples the metrics keep at least where torques are clipped (:func:`clipped_samples`)."""


def clipped_samples(tau, t: np.ndarray, label: str,
                    reach: int = 0) -> tuple[np.ndarray | None, tuple[str, ...], tuple[int, ...]]:
    """The samples where a joint's measured torque is held at its largest or smallest value for at least
    :data:`SATURATION_SAMPLES` samples in a row (a drive's current or torque limit, on either side: a limit may clip
    one direction only), and the warning that says so. Such a sample says only that the torque was at least that
    much; it is left out of the estimation (that joint's rows) and of the metrics (the whole sample). In a quantised
    channel (:data:`QUANTISED_SHARE`) a run counts only where the torque on both sides heads beyond it.

    Where that would leave the metrics less than :data:`SCORED_SHARE` of the samples, the joints clipped the longest
    are taken as saturated throughout instead, one at a time until it does not: their rows are left out of the
    estimation and of the metrics, as a dead channel's, and the other joints keep their samples (issue "Honest on any
    log": refuse only where nothing can be estimated).

    Parameters
    ----------
    tau : (N, n_dof) array or StoredColumns [N·m]
        The measured torques (a constant channel is a dead one, :func:`dead_channels`, not a clipped one).
    t : (N,) array [s]
        Time stamps, for the warning.
    label : str
        The dataset, for the warning.
    reach : int
        Samples marked on each side of a clipped run as well: the reach of the filter the torques go through.

    Returns
    -------
    clipped : (N, n_dof) bool array or None
        None where no joint is clipped but those saturated throughout.
    warnings : tuple of str
        One line per clipped joint: the dataset, the joint, its longest run and how many samples are left out.
    saturated : tuple of int
        The joints (0-based) saturated throughout, whose rows are all left out.
    """
    n = tau.shape[0]
    mask, words, extremes = None, {}, {}  # words and extremes by joint
    for j in range(tau.shape[1]):
        x = np.asarray(tau.column(j) if hasattr(tau, "column") else tau[:, j], dtype=float)
        peak = float(np.abs(x).max()) if x.size else 0.0
        if peak == 0 or float(np.ptp(x)) <= 1e-12 * max(1.0, peak):
            continue
        runs, step = [], _quantum(x, peak)
        for extreme, side in ((float(x.max()), 1.0), (float(x.min()), -1.0)):
            at = np.abs(x - extreme) <= 1e-9 * peak
            edges = np.diff(np.concatenate([[0], at.astype(np.int8), [0]]))
            runs += [(int(a), int(b)) for a, b in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1))
                     if b - a >= SATURATION_SAMPLES and (step == 0 or _heads_beyond(x, int(a), int(b), side, step))]
        if not runs:
            continue
        mask = np.zeros((n, tau.shape[1]), dtype=bool) if mask is None else mask
        for a, b in runs:
            mask[max(a - reach, 0):min(b + reach, n), j] = True
        a, b = max(runs, key=lambda r: r[1] - r[0])
        extremes[j] = x[a]
        words[j] = (f"{label}: J{j + 1}'s torque stays at its extreme {x[a]:.4g} N·m for {b - a} samples "
                    f"(t = {t[a]:.3f}-{t[b - 1]:.3f} s): saturated? its {int(mask[:, j].sum())} samples there and "
                    "within the filter's reach are left out of the estimation and of the metrics")
    if mask is None:
        return None, (), ()
    saturated: list[int] = []
    while mask.any(axis=1).mean() > 1.0 - SCORED_SHARE:
        j = int(np.argmax(mask.sum(axis=0)))
        share = float(mask[:, j].mean())
        words[j] = (
            f"{label}: J{j + 1}'s torque is at its extreme {extremes[j]:.4g} N·m in {100 * share:.3g} % of the samples "
            "(with the filter's reach): saturated throughout? its rows are left out of the estimation and of the "
            "metrics, as a dead channel's, so that the other joints keep their samples")
        saturated.append(j)
        mask[:, j] = False
    return (mask if mask.any() else None), tuple(words[j] for j in sorted(words)), tuple(sorted(saturated))


def _quantum(x: np.ndarray, peak: float) -> float:
    """The step of a quantised channel (:data:`QUANTISED_SHARE`): the median change between consecutive samples that
    differ, away from the channel's extremes (a clip's own runs do not make a channel quantised); 0 if not quantised."""
    tol = 1e-9 * peak
    inner = x[(np.abs(x - x.max()) > tol) & (np.abs(x - x.min()) > tol)]
    moves = np.abs(np.diff(inner))
    changed = moves[moves > tol]
    if changed.size == 0 or changed.size > (1 - QUANTISED_SHARE) * moves.size:
        return 0.0
    return float(np.median(changed))


def _heads_beyond(x: np.ndarray, a: int, b: int, side: float, step: float) -> bool:
    """Whether the torque on both sides of the run ``x[a:b]`` (at the channel's maximum, ``side`` 1, or minimum, -1)
    heads beyond it.

    The flanks are the samples next to the run, outwards, while they stay within :data:`FLANK_STEPS` steps ``step`` of
    the run's value (at most ten times the run's length on each side). A parabola in the sample index fitted to both
    (a line to one, where the run touches an end of the log) goes beyond the run's value inside the run by more than
    :data:`BEYOND_STEPS` steps: a clipped torque was heading further; a smooth peak read in steps stays within about a
    step of its top value."""
    level, m = x[a], 10 * (b - a)

    def flank(index: np.ndarray) -> np.ndarray:  # judged on the samples within the flank's reach only
        off = np.flatnonzero(np.abs(x[index] - level) > FLANK_STEPS * step * (1 + 1e-9))
        return index[:off[0]] if off.size else index

    before, after = flank(np.arange(a - 1, max(a - m, 0) - 1, -1)), flank(np.arange(b, min(b + m, x.shape[0])))
    if before.size < 3 and after.size < 3:
        return True  # nothing to judge by: the run is kept as saturation, as in a channel that is not quantised
    index = np.concatenate([before[::-1], after])
    fit = np.polynomial.Polynomial.fit(index, x[index], 2 if before.size >= 3 and after.size >= 3 else 1)
    return float(np.max(side * (fit(np.arange(a, b, dtype=float)) - level))) > BEYOND_STEPS * step


def dead_channels(tau, label: str, followers=()) -> tuple[tuple[int, ...], tuple[str, ...]]:
    """The joints whose measured torque never changes in a log (a dead sensor, a disconnected drive, a column that is
    not this joint's torque), and the warning that says so.

    Parameters
    ----------
    tau : (N, n_dof) array or StoredColumns [N·m]
        The measured torques.
    label : str
        The dataset, for the warning.
    followers : tuple of int
        Joints that follow another (``<mimic>``): their torque column is 0 by construction, among the dead without a
        warning.

    Returns
    -------
    dead : tuple of int
        0-based joints.
    warnings : tuple of str
        One line per dead joint, naming the dataset and the joint.
    """
    dead, words = [], []
    for j in range(tau.shape[1]):
        column = np.asarray(tau.column(j) if hasattr(tau, "column") else tau[:, j], dtype=float)
        if j in followers:
            dead.append(j)
        elif column.size and float(np.ptp(column)) <= 1e-12 * max(1.0, float(np.abs(column).max())):
            dead.append(j)
            words.append(f"{label}: J{j + 1}'s torque reads {column[0]:.4g} N·m throughout (a dead sensor, or a column that "
                         "is not this joint's torque?): its rows are left out of the estimation and of the metrics")
    return tuple(dead), tuple(words)

"""The preprocessing of logs: :func:`prepare` and :func:`base_chunks` by the strategy the settings name
(:mod:`dynid.preprocessing.strategies`), and the default strategy, :class:`ParallelFiltering`, where every filter is
chosen and applied:

Recording → zero-phase low-pass of positions (and measured velocities) → derivatives by central
differences (or a Fourier fit on a known excitation's harmonics) → base regressor and torques computed
chunk by chunk, then **filtered in parallel** (the same zero-phase low-pass on τ and on every column of
the observation matrix, Gautier's parallel filtering) and decimated together → optional removal of the
rows of joints slower than a threshold.

Nothing filters the torques alone: a filter on τ that the regressor columns do not go through (in
particular the step of sign(q̇) in the Coulomb column) makes measured and modelled torque differ near
every velocity reversal, whatever the parameters. Every cutoff left unset derives from the excitation
band of the data (:mod:`dynid.preprocessing.bands`), and :attr:`Preprocessing.derivation` says how.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from .._util.column_store import StoredColumns, by_column, root_mean_square
from ..conventions import sliding_note
from ..dynamics.base_parameters import BaseParameters
from ..dynamics.regressor import regressor
from ..exceptions import ConfigError, DataError
from ..friction import moving_joints
from ..model.robot import Robot
from .bands import MIN_SPEED_FRACTION, REST_FACTOR, white_noise_std
from .filters import (
    FractionalShift,
    butterworth_filtfilt,
    differentiate,
    gaussian_smooth,
    parallel_decimation,
    velocity_noise_std,
)
from .fourier_fit import fourier_fit_derivatives
from .prepared import (
    PreparedData,
    check_velocities,
    clipped_samples,
    dead_channels,
    direction_of_motion,
    min_speeds,
    rest_velocities,
)
from .settings import Preprocessing
from .strategies import Strategy, strategy_for

__all__ = ["PreparedData", "Preprocessing", "ParallelFiltering", "base_chunks", "prepare", "prepared_rows", "torque_delayed"]

def prepare(recording, settings: Preprocessing, strict: bool = True,
            progress: Callable[[float], None] | None = None) -> PreparedData:
    """Filtered joint signals of a recording, by the strategy ``settings.strategy`` names
    (:mod:`dynid.preprocessing.strategies`; default :class:`ParallelFiltering`).

    Parameters
    ----------
    recording : dynid.io.logs.datasets.Recording
        Anything with ``name, label, t, q, dq (or None), tau, rate, n_samples, warnings``.
    settings : Preprocessing
        Unset values are derived from this recording (:meth:`Preprocessing.resolved`).
    strict : bool
        Refuse settings that do not fit this recording rather than adapt them (with a warning).
    progress : callable, optional
        ``progress(share)``, the share of the preparation done (0 to 1), as it goes (:class:`ParallelFiltering`'s own
        preparation; another strategy's, or a subclass's own ``prepare``, once at its end).

    Returns
    -------
    PreparedData

    Raises
    ------
    ConfigError
        An unknown strategy, or settings the recording cannot take.
    DataError
        Too few samples.
    """
    if settings.torque_delay:
        recording = torque_delayed(recording, settings.torque_delay)
    strategy = strategy_for(settings)
    if progress is not None and type(strategy).prepare is ParallelFiltering.prepare:  # not a plugin's own prepare
        return _parallel_prepare(recording, settings, strict, progress)
    data = strategy.prepare(recording, settings, strict)
    if progress is not None:
        progress(1.0)
    return data


def torque_delayed(recording, delay: float):
    """The recording with its torques read ``delay`` seconds later, on the same grid (:attr:`Preprocessing.torque_delay`).

    Parameters
    ----------
    recording : dynid.io.logs.datasets.Recording
    delay : float [s]
        The torque channel's lag behind the positions (negative: it leads).

    Returns
    -------
    dynid.io.logs.datasets.Recording
        ``tau(t + delay)`` by a band-limited shift (:class:`dynid.preprocessing.filters.FractionalShift`); at the ends,
        where the log holds no torque that late (or early), its mirror image. Stored columns stay stored.

    Raises
    ------
    ConfigError
        A delay that is not finite, or not shorter than a tenth of the recording.
    """
    t = np.asarray(recording.t, dtype=float)
    span = float(t[-1] - t[0]) if t.size > 1 else 0.0
    if not np.isfinite(delay) or abs(delay) >= 0.1 * span:
        raise ConfigError(f"preprocessing.torque_delay: expected a delay in seconds shorter than a tenth of "
                          f"{recording.label} ({0.1 * span:.3g} s), got {delay!r}")
    samples = float(delay) * recording.rate
    return replace(recording, tau=by_column(recording.tau, lambda x, _: FractionalShift(x).read(samples)))


def base_chunks(robot: Robot, base: BaseParameters, data: PreparedData,
                progress: Callable[[int, int], None] | None = None, standard: bool = False):
    """The rows of ``data`` for the estimators, block by block, by the strategy that prepared it
    (:meth:`dynid.preprocessing.strategies.Strategy.chunks`).

    Parameters
    ----------
    robot : Robot
    base : BaseParameters
    data : PreparedData
    progress : callable, optional
        ``progress(done, total)`` in samples.
    standard : bool
        Yield the standard regressor instead of the base one.

    Returns
    -------
    iterator of tuple
        ``(index, y, tau, keep)`` blocks: sample indices (M,), regressor (M, n_dof, n_base) (n_params with
        ``standard``), torques (M, n_dof) [N·m], rows used by the estimation (M, n_dof) bool.
    """
    return strategy_for(data.settings).chunks(robot, base, data, progress, standard)


def prepared_rows(robot: Robot, base: BaseParameters, data: PreparedData,
                  standard: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every row of ``data`` for the estimators in memory, one per joint and sample (:func:`base_chunks` stacked).

    Parameters
    ----------
    robot : Robot
    base : BaseParameters
    data : PreparedData
    standard : bool
        The standard regressor's rows instead of the base one's.

    Returns
    -------
    w : (M, n_base) array
        (M, n_params) with ``standard``.
    tau : (M,) array [N·m]
    keep : (M,) bool array
        The rows the estimation uses.
    """
    ws, taus, keeps = [], [], []
    for _, y, tau, keep in base_chunks(robot, base, data, standard=standard):
        ws.append(y.reshape(-1, y.shape[-1]))
        taus.append(np.asarray(tau).reshape(-1))
        keeps.append(np.asarray(keep).reshape(-1))
    return np.concatenate(ws), np.concatenate(taus), np.concatenate(keeps)


class ParallelFiltering(Strategy):
    """The default strategy: every filter chosen from the data and applied to the torques and the regressor alike
    (module docstring); long logs are streamed chunk by chunk."""

    name = "parallel"
    chooses_cutoffs = True

    def prepare(self, recording, settings: Preprocessing, strict: bool = True) -> PreparedData:
        """Filter and differentiate a recording (positions, velocities: measured or from positions; accelerations:
        derivative of the filtered velocities), find where each joint rests and its direction of motion. The torques
        are not filtered here: they go through the parallel filter with the regressor (:meth:`chunks`).

        Parameters
        ----------
        recording : dynid.io.logs.datasets.Recording
        settings : Preprocessing
        strict : bool
            Refuse given cutoffs at or above this recording's Nyquist frequency (else lower them, with a warning).

        Returns
        -------
        PreparedData

        Raises
        ------
        ConfigError
            A cutoff at or above the Nyquist frequency.
        DataError
            Too few samples to filter, or none left after trimming.
        """
        return _parallel_prepare(recording, settings, strict)

    def chunks(self, robot, base, data, progress=None, standard=False):
        """Parallel-filtered, decimated regressor and torques, chunk by chunk.

        Rows of joints slower than ``min_speed`` are not kept (see :meth:`Strategy.chunks`).

        Parameters
        ----------
        robot : Robot
        base : BaseParameters
        data : PreparedData
            From :meth:`prepare`.
        progress : callable, optional
            ``progress(done, total)`` in samples.
        standard : bool
            Give the standard regressor instead of the base one.

        Returns
        -------
        iterator of tuple
            ``(index, y, tau, keep)`` as :meth:`Strategy.chunks`.
        """
        return _parallel_chunks(robot, base, data, progress, standard)


def _parallel_prepare(recording, settings: Preprocessing, strict: bool = True,
                      progress: Callable[[float], None] = lambda share: None) -> PreparedData:
    """:meth:`ParallelFiltering.prepare`; ``progress(share)`` after each step, weighed by its share of the time on
    benchmarks/long_log.py's hour-long log (the bands 17 %, the filters 33 %, the rest velocities 16 %, ...)."""
    rate = recording.rate
    if recording.n_samples < 3 * (2 * settings.order + 1) + 1:
        raise DataError(f"{recording.label}: {recording.n_samples} samples are too few to filter "
                        f"(at least {3 * (2 * settings.order + 1) + 1} for preprocessing.order = {settings.order})")
    s = settings.resolved(rate, recording.q, measured_velocity=recording.dq is not None, name=recording.label, strict=strict)
    progress(0.17)
    q, dq, ddq = _filtered_states(recording, s)
    progress(0.5)
    tau = recording.tau if isinstance(recording.tau, StoredColumns) else np.asarray(recording.tau, dtype=float)
    moving = _direction_velocity(recording, s, dq)
    s, rest = _rest_and_speed(recording, s, dq, strict)
    progress(0.66)
    if ddq is None:
        ddq = differentiate(dq, rate)
    t = recording.t
    cut = int(round(s.trim * rate))
    if cut:
        if 2 * cut >= t.shape[0] - 2:
            raise DataError(f"{recording.label}: preprocessing.trim = {s.trim:.3g} s at both ends leaves no samples of "
                            f"the {t[-1] - t[0]:.3f} s recording")
        t, q, dq, ddq, tau, moving = (x[cut:-cut] for x in (t, q, dq, ddq, tau, moving))
    resting = np.empty(dq.shape, dtype=bool)  # one byte a sample and joint, whatever the log's length
    for j in range(dq.shape[1]):
        resting[:, j] = ~moving_joints(np.asarray(dq[:, j])[:, None], np.asarray(moving[:, j])[:, None], rest[j])[:, 0]
    followers = tuple(getattr(recording, "followers", ()))
    progress(0.76)
    dead, clipped, channel_words = _channel_checks(tau, t, recording.label, s, rate, followers)
    positions = recording.q[cut:-cut] if cut else recording.q
    still = tuple(j for j in range(q.shape[1])  # positions read one value throughout: a joint held still
                  if float(np.ptp(positions.column(j) if hasattr(positions, "column") else positions[:, j])) == 0.0)
    progress(0.84)
    data = PreparedData(recording.name, t, q, dq, ddq, tau, rate, replace(s, warnings=()),
                        tuple(recording.warnings) + s.warnings + channel_words,
                        direction_of_motion(dq, moving, s, rate), moving, resting, dead, still, clipped,
                        getattr(recording, "drive_gains", None), followers)
    progress(1.0)
    return data


def _filtered_states(recording, s: Preprocessing):
    """:func:`_parallel_prepare`'s positions and velocities, low-passed (the measured velocities checked against the
    positions' derivative) or from the Fourier fit with their accelerations (None: differentiated later)."""
    rate = recording.rate

    def lowpass(x, cutoff, what):
        if cutoff <= 0:
            return x
        try:
            return butterworth_filtfilt(x, rate, cutoff, s.order)
        except ConfigError as exc:
            raise ConfigError(f"preprocessing.{what}_cutoff: {exc}") from None

    if s.fourier is not None:
        q, dq, ddq, _ = fourier_fit_derivatives(recording.t, recording.q, *s.fourier)
        return q, dq, ddq
    q = lowpass(recording.q, s.position_cutoff, "position")
    dq = lowpass(recording.dq, s.velocity_cutoff, "velocity") if recording.dq is not None else differentiate(q, rate)
    if recording.dq is not None:
        check_velocities(dq, differentiate(q, rate), recording.label, positions=q)
    return q, dq, None


def _rest_and_speed(recording, s: Preprocessing, dq, strict: bool) -> tuple[Preprocessing, np.ndarray]:
    """:func:`_parallel_prepare`'s rest velocity and minimum speed, derived where "auto" (said in the derivation), a
    given minimum speed above every speed of a joint refused where ``strict``; with each joint's rest velocity."""
    if s.rest_velocity == "auto":
        rest = np.maximum(REST_FACTOR * _velocity_noise(recording, s), np.asarray(s.rest_floor, dtype=float))
        s = replace(s, rest_velocity=tuple(float(v) for v in rest),
                    derivation=s.derivation + f"; a joint rests below {REST_FACTOR:g}σ of its velocity's noise ("
                    + ", ".join(f"{v:.2g}" for v in rest) + " rad/s"
                    + sliding_note("rad/s", getattr(recording, "prismatic", ()), inside=True) + "), "
                    + _rest_words(s.rest_friction))
    rest = np.broadcast_to(np.asarray(s.rest_velocity, dtype=float), (recording.q.shape[1],))
    if s.min_speed == "auto":  # before the accelerations exist: its temporary square adds to a smaller peak
        vmin = np.maximum(MIN_SPEED_FRACTION * root_mean_square(dq), 2 * rest)
        s = replace(s, min_speed=tuple(float(v) for v in vmin),
                    derivation=s.derivation + f"; rows slower than {100 * MIN_SPEED_FRACTION:g} % of the joint's RMS speed "
                    "(or than twice its rest velocity) left out of the estimation")
    elif strict:  # a given minimum speed above every speed of a joint leaves it no row
        vmin = min_speeds(s, recording.q.shape[1])
        peak = np.abs(dq).max(axis=0) if isinstance(dq, np.ndarray) else np.array(
            [np.abs(dq.column(j)).max() for j in range(dq.shape[1])])
        slow = np.flatnonzero(vmin > peak)
        if slow.size:
            j = int(slow[0])
            raise ConfigError(f"preprocessing.min_speed: {vmin[j]:.4g} rad/s is above every speed of joint {j + 1} in "
                              f"{recording.label} (at most {peak[j]:.4g} rad/s), which leaves it no row; lower it, or "
                              f"leave it out ({100 * MIN_SPEED_FRACTION:g} % of each joint's RMS speed)")
    return s, rest


def _channel_checks(tau, t, label: str, s: Preprocessing, rate: float, followers=()) -> tuple[tuple, np.ndarray | None, tuple]:
    """:func:`_parallel_prepare`'s dead, saturated and clipped torque channels (a joint at its limit throughout is
    left out as a dead one; every joint so is refused), and their words; a joint that follows another is among the
    dead without words."""
    dead, dead_words = dead_channels(tau, label, followers)
    reach = int(np.ceil(2 * rate / s.parallel_cutoff)) if s.parallel_cutoff else 0  # the parallel filter's reach
    clipped, clipped_words, saturated = clipped_samples(tau, t, label, reach)
    dead = tuple(sorted(set(dead) | set(saturated)))  # a joint at its limit throughout is left out as a dead one
    if saturated and len(dead) == tau.shape[1]:  # (torques all dead, e.g. none given to predict: refused upstream)
        raise DataError(f"{label}: every joint's torque reads one value or its limit throughout (dead or "
                        "saturated channels): nothing can be identified from this log; a log where the drives are "
                        "within their limits is needed")
    return dead, clipped, dead_words + clipped_words


def _direction_velocity(recording, s: Preprocessing, dq):
    """The velocity that says where a joint moves and in which direction (:func:`dynid.friction.held_direction`'s
    guide): measured velocities, or the positions' central difference, smoothed by a Gaussian at the velocity's
    cutoff (:func:`dynid.preprocessing.filters.gaussian_smooth`: no overshoot, so no false reversal where a joint
    stops abruptly, as a Butterworth filter's ringing gives); a Fourier fit's velocity as it is."""
    if s.fourier is not None:
        return dq
    if recording.dq is not None:
        return gaussian_smooth(recording.dq, recording.rate, _hz(s.velocity_cutoff))
    return differentiate(gaussian_smooth(recording.q, recording.rate, _hz(s.position_cutoff)), recording.rate)


def _hz(cutoff: float | None) -> float:
    """A resolved cutoff [Hz] (never None once :meth:`Preprocessing.resolved` has run; 0: no filter)."""
    return 0.0 if cutoff is None else float(cutoff)


def _velocity_noise(recording, s: Preprocessing) -> np.ndarray:
    """Standard deviation of the noise in :func:`_direction_velocity` (rad/s, per joint), from the noise floor of the
    measured velocities or positions (:func:`dynid.preprocessing.bands.white_noise_std`)."""
    if recording.dq is not None and s.fourier is None:
        sigma = white_noise_std(recording.dq, recording.rate)
        return velocity_noise_std(sigma, recording.rate, _hz(s.velocity_cutoff), s.order, False, gaussian=True)
    sigma = white_noise_std(recording.q, recording.rate)
    if s.fourier is not None:
        return velocity_noise_std(sigma, recording.rate, _hz(s.band), s.order, True)
    return velocity_noise_std(sigma, recording.rate, _hz(s.position_cutoff), s.order, True, gaussian=True)


def _rest_words(value) -> str:
    if value == "held":
        return "where it keeps the friction of its last motion"
    if value == "zero":
        return "where no friction is predicted"
    if isinstance(value, (int, float)):
        return f"where the friction of its last motion relaxes with a time constant of {value:g} s"
    return "where the friction of its last motion relaxes with time constants " + ", ".join(
        "∞" if x == "held" else "0" if x == "zero" else f"{x:g}" for x in value) + " s"


def _parallel_chunks(robot: Robot, base: BaseParameters, data: PreparedData,
                     progress: Callable[[int, int], None] | None = None, standard: bool = False):
    """:meth:`ParallelFiltering.chunks`: parallel-filtered, decimated base (or standard) regressor and torques.

    Yields
    ------
    index : (M,) int array
        Sample indices kept (every ``decimation``-th).
    y : (M, n_dof, n_base) array, or (M, n_dof, n_params) with ``standard``
        (the base regressor is then ``base.base_observation(y)``: filtering and decimation commute with
        selecting columns).
    tau : (M, n_dof) array [N·m]
    keep : (M, n_dof) bool array
        Rows fast enough for the estimation (``|dq_j| >= min_speed_j``).
    """
    n = robot.n_dof
    s = data.settings
    vmin = min_speeds(s, n)
    n_s = data.t.shape[0]
    velocities = rest_velocities(data, robot)

    cutoff = s.parallel_cutoff if s.parallel_cutoff else None
    filtered = (s.decimation or 1) > 1 or cutoff is not None  # the chunks are filtered into new arrays: one buffer
    columns = None if standard else base.independent  # the base regressor directly: no full array, no copy
    held = None  # serves every chunk's regressor (a new one per chunk is memory the system clears again)

    def block(a, b):  # the regressor and the torques, filtered alike but never copied into one array
        nonlocal held
        q, dq, ddq, tau = (np.asarray(x[a:b]) for x in (data.q, data.dq, data.ddq, data.tau))  # stored columns: read here
        v = velocities if data.direction is None else replace(velocities, direction=np.asarray(data.direction[a:b]))
        shape = (b - a, n, robot.n_params if columns is None else columns.size)
        if filtered and (held is None or held.shape != shape):
            held = np.empty(shape)
        return regressor(robot, q, dq, ddq, columns=columns, velocities=v, out=held if filtered else None), tau

    for index, (y, tau) in parallel_decimation(block, n_s, data.rate, s.decimation or 1, order=s.order, chunk=s.chunk, cutoff=cutoff):
        keep = data.kept(index, vmin)
        if progress is not None:
            progress(int(index[-1]) + 1, n_s)
        yield index, y, tau, keep

"""The preprocessing pipeline of logs: one place where every filter is chosen and applied.

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

from dataclasses import dataclass, replace
from typing import Callable

import numpy as np

from ..column_store import StoredColumns, root_mean_square
from ..dynamics.base_parameters import BaseParameters
from ..dynamics.regressor import regressor
from ..exceptions import ConfigError, DataError
from ..model.robot import Robot
from .bands import MIN_SPEED_FRACTION
from .filters import butterworth_filtfilt, differentiate, parallel_decimation
from .fourier_fit import fourier_fit_derivatives
from .settings import Preprocessing

__all__ = ["PreparedData", "Preprocessing", "base_chunks", "prepare"]


@dataclass(frozen=True)
class PreparedData:
    """Filtered joint signals on a uniform grid, ready for the regressor (N, n_dof) each: arrays, or for a
    spooled long log :class:`dynid.column_store.StoredColumns` (``t`` is always an array)."""

    name: str
    t: np.ndarray
    q: np.ndarray
    dq: np.ndarray
    ddq: np.ndarray
    tau: np.ndarray
    rate: float
    settings: Preprocessing
    warnings: tuple[str, ...] = ()


def prepare(recording, settings: Preprocessing) -> PreparedData:
    """Filter and differentiate a recording (positions, velocities: measured or from positions;
    accelerations: derivative of the filtered velocities). The torques are not filtered here: they go
    through the parallel filter with the regressor (:func:`base_chunks`).

    Parameters
    ----------
    recording : dynid.io.datasets.Recording
        Anything with ``name, t, q, dq (or None), tau, rate, n_samples, warnings``.
    settings : Preprocessing
        Unset values are derived from this recording (:meth:`Preprocessing.resolved`).

    Raises
    ------
    ConfigError
        A cutoff at or above the Nyquist frequency.
    DataError
        Too few samples to filter, or none left after trimming.
    """
    rate = recording.rate
    if recording.n_samples < 3 * (2 * settings.order + 1) + 1:
        raise DataError(f"{recording.label}: {recording.n_samples} samples are too few to filter "
                        f"(at least {3 * (2 * settings.order + 1) + 1} for preprocessing.order = {settings.order})")
    s = settings.resolved(rate, recording.q, recording.dq is not None)

    def lowpass(x, cutoff, what):
        if cutoff <= 0:
            return x
        try:
            return butterworth_filtfilt(x, rate, cutoff, s.order)
        except ConfigError as exc:
            raise ConfigError(f"preprocessing.{what}_cutoff: {exc}") from None

    ddq = None
    if s.fourier is not None:
        q, dq, ddq, _ = fourier_fit_derivatives(recording.t, recording.q, *s.fourier)
    else:
        q = lowpass(recording.q, s.position_cutoff, "position")
        dq = lowpass(recording.dq, s.velocity_cutoff, "velocity") if recording.dq is not None else differentiate(q, rate)
    tau = recording.tau if isinstance(recording.tau, StoredColumns) else np.asarray(recording.tau, dtype=float)
    if s.min_speed == "auto":  # before the accelerations exist: its temporary square adds to a smaller peak
        vmin = MIN_SPEED_FRACTION * root_mean_square(dq)
        s = replace(s, min_speed=tuple(float(v) for v in vmin),
                    derivation=s.derivation + f"; rows slower than {100 * MIN_SPEED_FRACTION:g} % of the joint's RMS speed "
                    "left out of the estimation")
    if ddq is None:
        ddq = differentiate(dq, rate)
    t = recording.t
    cut = int(round(s.trim * rate))
    if cut:
        if 2 * cut >= t.shape[0] - 2:
            raise DataError(f"{recording.label}: preprocessing.trim = {s.trim:.3g} s at both ends leaves no samples of "
                            f"the {t[-1] - t[0]:.3f} s recording")
        t, q, dq, ddq, tau = (x[cut:-cut] for x in (t, q, dq, ddq, tau))
    return PreparedData(recording.name, t, q, dq, ddq, tau, rate, s, tuple(recording.warnings))


def _min_speed(settings: Preprocessing, n: int) -> np.ndarray:
    v = np.asarray(settings.min_speed, dtype=float)
    if v.ndim == 0:
        v = np.full(n, float(v))
    if v.shape != (n,) or np.any(v < 0):
        raise ConfigError(f"preprocessing.min_speed: expected a non-negative number or {n} of them, got {settings.min_speed!r}")
    return v


def base_chunks(robot: Robot, base: BaseParameters, data: PreparedData,
                progress: Callable[[int, int], None] | None = None, standard: bool = False):
    """Parallel-filtered, decimated base (or standard) regressor and torques, chunk by chunk.

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
    vmin = _min_speed(s, n)
    n_s = data.t.shape[0]

    def block(a, b):  # the regressor and the torques, filtered alike but never copied into one array
        columns = None if standard else base.independent  # the base regressor directly: no full array, no copy
        q, dq, ddq, tau = (np.asarray(x[a:b]) for x in (data.q, data.dq, data.ddq, data.tau))  # stored columns: read here
        return regressor(robot, q, dq, ddq, columns), tau

    cutoff = s.parallel_cutoff if s.parallel_cutoff else None
    for index, (y, tau) in parallel_decimation(block, n_s, data.rate, s.decimation, s.order, s.chunk, cutoff):
        keep = np.abs(data.dq[index]) >= vmin
        if progress is not None:
            progress(int(index[-1]) + 1, n_s)
        yield index, y, tau, keep

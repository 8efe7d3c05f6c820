"""A transport delay between a log's torque (current) channel and its position channel, estimated from the data.

Drives often log currents a few samples after the positions they were computed from (a bus cycle, a filter's
group delay). A delay ``d`` makes the measured torque at ``t`` the model's torque at ``t − d``, which the regressor
cannot absorb. The delay minimises the least-squares residual of the identification: with the observation matrix
``W`` of the positions fixed (computed once), the parallel-filtered torques are read at ``t_k + d`` (interpolated
on the full-rate grid, so ``d`` is found to a fraction of a sample) and ``RSS(d) = ‖(I − P_W) τ(t + d)‖²`` is
minimised over ``|d| ≤ max_samples``, the torques shifted by a band-limited fractional delay
(:class:`dynid.preprocessing.filters.FractionalShift`: linear interpolation would average neighbouring samples, lower
the noise at half-sample delays and pull the minimum there). Its σ is the Gauss–Newton one, ``σ_d² = S / (JᵀJ)²`` with ``J = ∂r/∂d`` and ``S`` the long-run variance of
the scores ``J_i r_i`` over the log's instants (:func:`dynid.estimators.instrumental.long_run_covariance`), since the
residual of a real log is correlated in time (MuJoCo's system identification fits the same measurement parameter, as a sensor delay).
Current offsets need no step of their own: they are the ``offset`` drive term, identified with σ like the others.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..dynamics.base_parameters import BaseParameters, base_parameters
from ..estimators.instrumental import long_run_covariance
from ..exceptions import ConfigError, IdentifiabilityError
from ..io.logs.datasets import Recording
from ..model.robot import Robot
from ..preprocessing.filters import FractionalShift, butterworth_filtfilt
from ..preprocessing.preparation import Preprocessing, base_chunks, prepare
from ..preprocessing.prepared import PreparedData

__all__ = ["DelayEstimate", "estimate_delay", "delay_from_rows", "held_out_sum", "delayed"]

DELAY_FOLDS = 5
"""Contiguous blocks of the log on which a delay's held-out residual is measured (:attr:`DelayEstimate.held_out`)."""

DETERMINED_STD = 0.5
"""[samples] A delay estimate with a larger σ is not determined by the log."""


@dataclass(frozen=True)
class DelayEstimate:
    """The torque channel's delay behind the positions.

    Attributes
    ----------
    samples : float
        Delay in samples of the log (positive: the torques come late).
    std : float
        Its σ, in samples.
    seconds : float [s]
    at_bound : bool
        The minimum lies at ``±max_samples``: the delay may be larger (give a larger bound).
    held_out : float
        The residual on held-out blocks of the log with the torques read at this delay, over that with them read as
        given (:data:`DELAY_FOLDS` contiguous blocks, each predicted by least squares on the others): below 1 where the
        delay improves what the model predicts of motion it was not fitted on (issue "Every assurance checked on what
        the user meets", item 5); NaN where not measured.
    held_out_sums : tuple of float [(N·m)²]
        The two held-out squared residuals whose ratio is ``held_out``: with the torques read as given, and at this
        delay (what :func:`dynid.identification.geared_friction.delay_beyond_hysteresis` compares across friction
        models).
    """

    samples: float
    std: float
    seconds: float
    at_bound: bool = False
    held_out: float = float("nan")
    held_out_sums: tuple[float, float] = (float("nan"), float("nan"))

    @property
    def determined(self) -> bool:
        """The log determines the delay: the minimum lies inside the bound and σ is below :data:`DETERMINED_STD`
        samples (a slow excitation on a fast log changes the residual too little for a delay of a few samples).

        A local criterion: on a short log whose motion barely excites the parameters, the delay trades off against
        them, the residual has several near-equal minima and one of them can pass. Measured on the UR10e's
        point-to-point logs: over ±20 samples the residual changes by 1-5 % (p1-p5; 21 times on its excitation log),
        and in seven of p1-p10 delays of -18 to +18 samples pass with σ of 0.008-0.5. Estimate the delay on an
        excitation log."""
        return not self.at_bound and self.std < DETERMINED_STD


def estimate_delay(robot: Robot, recording: Recording, base: BaseParameters | None = None,
                   preprocessing: Preprocessing | None = None, max_samples: float = 20.0) -> DelayEstimate:
    """The delay of the torque channel behind the positions (module docstring).

    Parameters
    ----------
    robot : Robot
    recording : Recording
        ``t`` (N,) [s], ``q`` and ``tau`` (N, n_dof) on a uniform grid.
    base : BaseParameters, optional
        Default: computed from ``robot``.
    preprocessing : Preprocessing, optional
        Default: every setting derived from the log.
    max_samples : float
        Largest delay searched, either way [samples].

    Returns
    -------
    DelayEstimate

    Raises
    ------
    ConfigError
        ``max_samples`` not positive.
    IdentifiabilityError
        Fewer rows than parameters, or a residual that does not change with the delay (no motion).
    """
    if not (np.isfinite(max_samples) and max_samples > 0):
        raise ConfigError(f"max_samples: expected a positive number of samples, got {max_samples!r}")
    base = base if base is not None else base_parameters(robot, rng=0)
    data = prepare(recording, preprocessing or Preprocessing())
    return delay_from_rows(data, base_chunks(robot, base, data), max_samples)


SCAN_BLOCK = 16
"""Delays of the coarse scan whose torques :func:`delay_from_rows` projects at once: one pass over the orthogonal
factor for all of them, and the kept rows' copies bounded to this many."""


def delay_from_rows(data: PreparedData, blocks, max_samples: float = 20.0) -> DelayEstimate:
    """:func:`estimate_delay` on a log prepared already (by the default strategy, ``"parallel"``), from its blocks of
    base rows: the identification's own pass gives them, so the check needs no second pass.

    Parameters
    ----------
    data : PreparedData
        From :func:`dynid.preprocessing.preparation.prepare` (its torques at the log's rate, not yet filtered).
    blocks : iterable of tuple
        ``(index, y, tau, keep)`` as :func:`dynid.preprocessing.preparation.base_chunks` yields them (``tau`` unused).
    max_samples : float
        Largest delay searched, either way [samples].

    Returns
    -------
    DelayEstimate

    Raises
    ------
    IdentifiabilityError
        Fewer rows than parameters, or a residual that does not change with the delay (no motion).
    """
    from scipy.optimize import minimize_scalar

    w, keep, instants, read = _gathered(data, blocks)
    q_factor, _ = np.linalg.qr(w[keep])

    def residual(d: float) -> np.ndarray:
        shifted = read(d)
        return shifted - q_factor @ (q_factor.T @ shifted)

    def rss(d: float) -> float:  # |s|² - |Qᵀs|²: one product with Q, not two (the residual at the noise floor is
        shifted = read(d)  # 1e-4 of |s|² or more: 12 digits are left)
        projected = q_factor.T @ shifted
        return float(shifted @ shifted - projected @ projected)

    bound = float(max_samples)
    grid = np.linspace(-bound, bound, int(4 * bound) + 1)  # a coarse scan first: RSS need not be convex far away
    values = np.empty(grid.size)
    for k in range(0, grid.size, SCAN_BLOCK):  # a block of the scan's reads projected in one product (one pass over Q)
        scan = np.column_stack([read(d) for d in grid[k:k + SCAN_BLOCK]])
        projected = q_factor.T @ scan
        values[k:k + SCAN_BLOCK] = np.einsum("ij,ij->j", scan, scan) - np.einsum("ij,ij->j", projected, projected)
    k = int(np.argmin(values))
    lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]
    best = minimize_scalar(rss, bounds=(lo, hi), method="bounded", options={"xatol": 1e-4})
    d = float(best.x)
    h = 0.25
    slope = (residual(d + h) - residual(d - h)) / (2 * h)  # ∂r/∂d, samples⁻¹
    information = float(slope @ slope)
    if not information > 0:
        raise IdentifiabilityError(f"{data.name}: the residual does not change with the delay (does the robot move?)")
    # Gauss–Newton σ with the scores' long-run covariance: a residual correlated in time (model error on a short
    # point-to-point log) determines the delay far less than white noise of the same size would
    spread = float(long_run_covariance((slope * residual(d))[:, None], instants)[0, 0])
    std = float(np.sqrt(max(spread, 0.0)) / information)
    sums = _held_out_sums(w, keep, np.column_stack([read(x) for x in (0.0, d)]), instants)
    held = float(sums[1] / sums[0]) if sums[0] > 0 else float("nan")
    return DelayEstimate(d, std, d / data.rate, bool(abs(d) > bound - 0.5), held, (float(sums[0]), float(sums[1])))


def held_out_sum(data: PreparedData, blocks) -> float:
    """The least-squares squared residual of held-out blocks of the log with its torques read as given: the
    denominator of :attr:`DelayEstimate.held_out`, for rows of another friction model on the same samples
    (:func:`dynid.identification.geared_friction.delay_beyond_hysteresis`).

    Parameters
    ----------
    data : PreparedData
    blocks : iterable of tuple
        As :func:`delay_from_rows` takes them.

    Returns
    -------
    float [(N·m)²]
        NaN where a block of :data:`DELAY_FOLDS` holds no kept row.

    Raises
    ------
    IdentifiabilityError
        Fewer rows than parameters.
    """
    w, keep, instants, read = _gathered(data, blocks)
    return float(_held_out_sums(w, keep, read(0.0)[:, None], instants)[0])


def _gathered(data: PreparedData, blocks):
    """The kept rows' regressor ``w`` (every row), the kept mask, each kept row's sample and ``read(d)``: the kept
    rows' torques, filtered as the regressor's columns are, read ``d`` samples later (module docstring)."""
    s = data.settings
    rows, times, keeps = [], [], []
    for index, y, _, keep in blocks:
        rows.append(y.reshape(-1, y.shape[-1]))
        times.append(np.asarray(data.t)[index])
        keeps.append(np.asarray(keep).reshape(-1))
    w, t_rows, keep = np.concatenate(rows), np.concatenate(times), np.concatenate(keeps)
    n = w.shape[0] // t_rows.size  # rows per instant: the joints
    if keep.sum() <= w.shape[1]:
        raise IdentifiabilityError(f"{data.name}: {int(keep.sum())} rows for {w.shape[1]} base parameters")
    del rows
    tau = np.asarray(data.tau, dtype=float)
    if s.parallel_cutoff is not None:  # the torques as the regressor's columns are filtered
        tau = np.asarray(butterworth_filtfilt(tau, data.rate, s.parallel_cutoff, s.order))
    t_full = np.asarray(data.t, dtype=float)
    # band-limited (module docstring): linear interpolation pulled the minimum to x.5 samples on noisy logs
    shift = FractionalShift(tau)
    rows_index = np.rint((t_rows - t_full[0]) * data.rate).astype(int)
    instants = np.repeat(np.arange(keep.size // n), n)[keep]
    return w, keep, instants, lambda d: shift.read(d, at=rows_index).reshape(-1)[keep]


def _held_out_sums(w: np.ndarray, keep: np.ndarray, y: np.ndarray, instants: np.ndarray) -> np.ndarray:
    """The least-squares squared residuals on :data:`DELAY_FOLDS` contiguous blocks of the kept rows (``instants``:
    each kept row's sample, in time order), each predicted by the fit on the others, of each column of ``y`` (the
    torques read as given, and at the delay); NaN where a block is empty. Each block's rows enter once, as the triangular
    factor of ``[W | y]``: the fit on the other blocks solves their stacked factors, and the block's residual is its
    own factor times ``[β; -1]`` (the orthogonal factor keeps the norms)."""
    folds = instants * DELAY_FOLDS // (int(instants.max()) + 1)
    p = w.shape[1]
    rows = w[keep]
    factors = []
    for k in range(DELAY_FOLDS):
        held = folds == k
        if not held.any():
            return np.full(y.shape[1], np.nan)
        factors.append(np.linalg.qr(np.column_stack([rows[held], y[held]]), mode="r"))
    sse = np.zeros(y.shape[1])
    for k in range(DELAY_FOLDS):
        rest = np.vstack([f for i, f in enumerate(factors) if i != k])
        beta = np.linalg.lstsq(rest[:, :p], rest[:, p:], rcond=None)[0]
        sse += np.sum((factors[k] @ np.vstack([beta, -np.eye(y.shape[1])])) ** 2, axis=0)
    return sse


def delayed(recording: Recording, samples: float) -> Recording:
    """The recording with its torques read ``samples`` later (the delay undone), on the same grid.

    Parameters
    ----------
    recording : Recording
    samples : float
        A :class:`DelayEstimate`'s ``samples``.

    Returns
    -------
    Recording
        The last ``ceil(samples)`` samples (or first, for a negative delay) are dropped: their torques were not logged.
    """
    t = np.asarray(recording.t, dtype=float)
    tau = np.asarray(recording.tau, dtype=float)
    shifted = FractionalShift(tau).read(samples)
    cut = int(np.ceil(abs(samples)))
    keep = slice(0, t.size - cut) if samples >= 0 else slice(cut, t.size)
    q = np.asarray(recording.q)[keep]
    dq = None if recording.dq is None else np.asarray(recording.dq)[keep]
    return replace(recording, t=t[keep] - t[keep][0], q=q, dq=dq, tau=shifted[keep])

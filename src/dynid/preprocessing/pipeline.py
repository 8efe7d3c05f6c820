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

from dataclasses import dataclass, fields, replace
from typing import Callable

import numpy as np

from ..dynamics.base_parameters import BaseParameters
from ..dynamics.regressor import regressor
from ..exceptions import ConfigError, DataError
from ..model.robot import Robot
from .bands import MIN_SPEED_FRACTION, cutoffs_from_band, excitation_band
from .filters import butterworth_filtfilt, decimation_cutoff, differentiate, parallel_decimation
from .fourier_fit import fourier_fit_derivatives


@dataclass(frozen=True)
class Preprocessing:
    """Preprocessing settings; ``None`` means "derived from the data" (:meth:`resolved`).

    Attributes
    ----------
    order : int
        Order of the Butterworth filters.
    position_cutoff, velocity_cutoff : float or None [Hz]
        Zero-phase low-pass cutoffs of the positions and of measured velocities; 0 switches a filter
        off. Default: ``10·band`` (velocities: the position cutoff).
    parallel_cutoff : float or None [Hz]
        Cutoff of the zero-phase low-pass applied to the torques **and** to every regressor column
        (parallel filtering); 0: only the decimation's anti-aliasing filter. Default: ``5·band``, or
        the decimation's own cutoff when only ``decimation`` is given.
    decimation : int or None
        Parallel decimation factor. Default: the largest whose anti-aliasing cutoff is at or above
        ``parallel_cutoff``.
    band : float or None [Hz]
        Excitation band. Default: from the positions' spectrum (:func:`dynid.preprocessing.bands.excitation_band`),
        or the harmonics of ``fourier``.
    min_speed : "auto", float or tuple [rad/s]
        Rows of joint ``j`` where ``|dq_j| < min_speed_j`` are left out of the estimation (0: keep all).
        "auto": 5 % of each joint's RMS speed (:data:`dynid.preprocessing.bands.MIN_SPEED_FRACTION`).
    trim : float or None [s]
        Removed at both ends after filtering, where the filters' edge effects corrupt the derivatives.
        Default: ``3 / cutoff`` of the slowest filter the derivatives go through, 0 when those are off.
    chunk : int
        Samples per chunk of the regressor.
    fourier : (omega_f, n_harmonics) or None
        When the robot ran a known periodic excitation (eq. 14, e.g. from ``dynid excite``): positions,
        velocities and accelerations come from a least-squares fit of the measured positions on its
        harmonics (paper §3.3) instead of filtering and differentiating.
    coulomb_velocity : "auto", float or tuple [rad/s]
        Smoothing velocity of the Coulomb term per joint (:mod:`dynid.dynamics.friction`); 0 (default):
        sign. "auto": chosen per joint by blocked cross-validation on the identification log
        (:func:`dynid.validation.cross_validation.choose_coulomb_velocity`). Not the default: on the
        UR10e logs the choice made on the excitation log raised the point-to-point validation errors.
    derivation : str
        Filled by :meth:`resolved`: what was derived from the data, and why.
    """

    order: int = 4
    position_cutoff: float | None = None
    velocity_cutoff: float | None = None
    parallel_cutoff: float | None = None
    decimation: int | None = None
    band: float | None = None
    min_speed: str | float | tuple = "auto"
    trim: float | None = None
    chunk: int = 20_000
    fourier: tuple[float, int] | None = None
    coulomb_velocity: str | float | tuple = 0.0
    derivation: str = ""

    def resolved(self, rate: float, q: np.ndarray | None = None, measured_velocity: bool = True) -> "Preprocessing":
        """Every ``None`` replaced by its data-derived value (module :mod:`dynid.preprocessing.bands`).

        Parameters
        ----------
        rate : float [Hz]
        q : (N, n_dof) array, optional
            Measured positions, for the excitation band when neither ``band`` nor ``fourier`` gives it.
        measured_velocity : bool
            Whether the log has velocities (then filtered at ``velocity_cutoff``).

        Raises
        ------
        ConfigError
            A cutoff at or above the Nyquist frequency, or no way to find the band.
        """
        nyq = rate / 2
        for name in ("position_cutoff", "velocity_cutoff", "parallel_cutoff", "band"):
            v = getattr(self, name)
            if v is not None and v >= nyq:
                raise ConfigError(f"preprocessing.{name}: expected below the Nyquist frequency {nyq:g} Hz of the "
                                  f"{rate:g} Hz log, got {v:g} Hz")
        band, source = self.band, "given by preprocessing.band"
        if band is None and self.fourier is not None:
            band, source = self.fourier[0] * self.fourier[1] / (2 * np.pi), "the excitation's highest harmonic"
        if band is None:
            if q is None:
                raise ConfigError("preprocessing.band: needed when no positions are given to estimate it")
            band, source = excitation_band(q, rate), "99 % of the velocity energy in the positions' spectrum"
        derived = cutoffs_from_band(band, rate, source)
        pos = self.position_cutoff if self.position_cutoff is not None else derived.position_cutoff
        vel = self.velocity_cutoff if self.velocity_cutoff is not None else pos
        if self.parallel_cutoff:
            par = self.parallel_cutoff
        elif self.decimation is not None or self.parallel_cutoff == 0:
            par = decimation_cutoff(rate, self.decimation) if (self.decimation or 1) > 1 else 0.0
        else:
            par = derived.parallel_cutoff
        if self.decimation is not None:
            dec = self.decimation
        elif par > 0:
            dec = max(1, int(np.floor(0.8 * rate / (2 * par))))
        else:
            dec = 1
        if self.fourier is not None:
            on = []
        else:
            on = [c for c in ((pos, vel) if measured_velocity else (pos,)) if c > 0]
        trim = self.trim if self.trim is not None else (3.0 / min(on) if on else 0.0)
        chosen = [f"excitation band {band:.3g} Hz ({source})"]
        if self.fourier is None:
            chosen.append(f"positions low-passed at {pos:.3g} Hz" + ("" if self.position_cutoff is not None else " (10× band)"))
        else:
            chosen.append("positions, velocities and accelerations from the Fourier fit")
        chosen.append(f"torques and every regressor column low-passed in parallel at {par:.3g} Hz"
                      + ("" if self.parallel_cutoff is not None or self.decimation is not None else " (10× band)")
                      if par > 0 else "no parallel filter")
        chosen.append(f"decimation by {dec}" + ("" if self.decimation is not None else " (down to the parallel band)"))
        return replace(self, position_cutoff=float(pos), velocity_cutoff=float(vel), parallel_cutoff=float(par),
                       decimation=int(dec), band=float(band), trim=float(trim), derivation="; ".join(chosen))

    def to_dict(self) -> dict:
        return {f.name: (list(getattr(self, f.name)) if isinstance(getattr(self, f.name), tuple) else getattr(self, f.name))
                for f in fields(self)}


@dataclass(frozen=True)
class PreparedData:
    """Filtered joint signals on a uniform grid, ready for the regressor (N, n_dof) each."""

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
        raise DataError(f"{recording.name}: {recording.n_samples} samples are too few to filter "
                        f"(at least {3 * (2 * settings.order + 1) + 1} for preprocessing.order = {settings.order})")
    s = settings.resolved(rate, recording.q, recording.dq is not None)

    def lowpass(x, cutoff, what):
        if cutoff <= 0:
            return x
        try:
            return butterworth_filtfilt(x, rate, cutoff, s.order)
        except ConfigError as exc:
            raise ConfigError(f"preprocessing.{what}_cutoff: {exc}") from None

    if s.fourier is not None:
        q, dq, ddq, _ = fourier_fit_derivatives(recording.t, recording.q, *s.fourier)
    else:
        q = lowpass(recording.q, s.position_cutoff, "position")
        dq = lowpass(recording.dq, s.velocity_cutoff, "velocity") if recording.dq is not None else differentiate(q, rate)
        ddq = differentiate(dq, rate)
    tau = np.asarray(recording.tau, dtype=float)
    if s.min_speed == "auto":
        vmin = MIN_SPEED_FRACTION * np.sqrt(np.mean(dq**2, axis=0))
        s = replace(s, min_speed=tuple(float(v) for v in vmin),
                    derivation=s.derivation + f"; rows slower than {100 * MIN_SPEED_FRACTION:g} % of the joint's RMS speed "
                    "left out of the estimation")
    t = recording.t
    cut = int(round(s.trim * rate))
    if cut:
        if 2 * cut >= t.shape[0] - 2:
            raise DataError(f"{recording.name}: preprocessing.trim = {s.trim:.3g} s at both ends leaves no samples of "
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
    nb = robot.n_params if standard else base.n_base
    s = data.settings
    vmin = _min_speed(s, n)
    n_s = data.t.shape[0]

    def block(a, b):
        y = regressor(robot, data.q[a:b], data.dq[a:b], data.ddq[a:b])
        y = y if standard else base.base_observation(y)
        return np.concatenate([y.reshape(b - a, n * nb), data.tau[a:b]], axis=1)

    cutoff = s.parallel_cutoff if s.parallel_cutoff else None
    for index, values in parallel_decimation(block, n_s, data.rate, s.decimation, s.order, s.chunk, cutoff):
        y = values[:, : n * nb].reshape(-1, n, nb)
        keep = np.abs(data.dq[index]) >= vmin
        if progress is not None:
            progress(int(index[-1]) + 1, n_s)
        yield index, y, values[:, n * nb:].copy(), keep  # a copy: a view would keep the whole block alive

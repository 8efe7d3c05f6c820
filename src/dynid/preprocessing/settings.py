"""Preprocessing settings (light: no SciPy, no compiled kernels, so that a config is checked before any
heavy import); the pipeline that applies them is :mod:`dynid.preprocessing.pipeline`."""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np

from ..exceptions import ConfigError
from .bands import PARALLEL_FACTOR, POSITION_FACTOR, cutoffs_from_band, decimation_cutoff, decimation_for, excitation_band


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
        Smoothing velocity of the Coulomb term per joint (:mod:`dynid.friction`); 0 (default):
        sign. "auto": chosen per joint by blocked cross-validation on the identification log
        (:func:`dynid.validation.cross_validation.choose_coulomb_velocity`). Not the default: on the
        UR10e logs the choice made on the excitation log raised the point-to-point validation errors.
    auto : bool
        ``preprocessing = "auto"``: the position and parallel cutoffs (hence the decimation) are chosen
        by blocked cross-validation (:func:`dynid.validation.cross_validation.choose_preprocessing`), and
        the Coulomb smoothing velocity too unless given.
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
    auto: bool = False
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
        derived = cutoffs_from_band(band, rate)
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
            dec = decimation_for(rate, par)
        else:
            dec = 1
        if self.fourier is not None:
            on = []
        else:
            on = [c for c in ((pos, vel) if measured_velocity else (pos,)) if c > 0]
        trim = self.trim if self.trim is not None else (3.0 / min(on) if on else 0.0)
        chosen = [f"excitation band {band:.3g} Hz ({source})"]
        if self.fourier is None:
            chosen.append(f"positions low-passed at {pos:.3g} Hz" + ("" if self.position_cutoff is not None else f" ({POSITION_FACTOR:g}× band)"))
        else:
            chosen.append("positions, velocities and accelerations from the Fourier fit")
        chosen.append(f"torques and every regressor column low-passed in parallel at {par:.3g} Hz"
                      + ("" if self.parallel_cutoff is not None or self.decimation is not None else f" ({PARALLEL_FACTOR:g}× band)")
                      if par > 0 else "no parallel filter")
        chosen.append(f"decimation by {dec}" + ("" if self.decimation is not None else " (down to the parallel band)"))
        return replace(self, position_cutoff=float(pos), velocity_cutoff=float(vel), parallel_cutoff=float(par),
                       decimation=int(dec), band=float(band), trim=float(trim), derivation="; ".join(chosen))

    def to_dict(self) -> dict:
        return {f.name: (list(getattr(self, f.name)) if isinstance(getattr(self, f.name), tuple) else getattr(self, f.name))
                for f in fields(self)}

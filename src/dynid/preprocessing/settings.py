"""Preprocessing settings (light: no SciPy, no compiled kernels, so that a config is checked before any
heavy import); the pipeline that applies them is :mod:`dynid.preprocessing.preparation`."""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np

from .._util.keywords import keyword_only_after_data
from ..exceptions import ConfigError
from .bands import (
    PARALLEL_FACTOR,
    POSITION_FACTOR,
    capped,
    cutoffs_from_band,
    decimation_cutoff,
    decimation_for,
    estimate_band,
)

MAX_PRESLIDING = 1.0
"""[rad, or m on a sliding joint] The largest presliding distance a setting may give: far beyond any drive's lost motion
(1-10 mrad on geared drives); a larger one keeps the dry friction from ever turning, and the fit would then blame the log
for not determining it."""

_RANGES = (("order", 1, True, False), ("band", 0.0, False, True), ("position_cutoff", 0.0, False, False),
           ("velocity_cutoff", 0.0, False, False), ("parallel_cutoff", 0.0, False, False), ("decimation", 1, True, False),
           ("trim", 0.0, False, False), ("chunk", 1, True, False), ("smoothing_passes", 0, True, False))
"""Settings checked where they are made (:meth:`Preprocessing.__post_init__`): (field, least value, integer, the least
value itself refused)."""


def _in_range(value, low: float, whole: bool, above: bool = False) -> bool:
    """Whether ``value`` is a number (an integer where ``whole``) of at least ``low`` (above it where ``above``), not
    NaN."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        return False
    return bool(value > low if above else value >= low) and (not whole or float(value).is_integer())


_PER_JOINT = (("min_speed", True), ("rest_velocity", True), ("coulomb_velocity", True), ("rest_floor", False))
"""Speeds [rad/s, or m/s on a sliding joint] checked where they are made: (field, "auto" allowed); each a number >= 0,
not NaN, or one per joint."""


def _speeds(value, auto: bool) -> bool:
    """Whether ``value`` is "auto" (where ``auto``) or a speed >= 0, or a non-empty sequence of them, none NaN."""
    if isinstance(value, str):
        return auto and value == "auto"
    values = np.atleast_1d(np.asarray(value, dtype=object))
    return values.ndim == 1 and values.size > 0 and all(_in_range(x, 0.0, False) for x in values.tolist())


MIN_SAMPLES_KEPT = 200
"""A log whose settings come from another dataset is decimated by at most ``N // MIN_SAMPLES_KEPT``."""


@dataclass(frozen=True)
class Preprocessing:
    """Preprocessing settings; ``None`` means "derived from the data" (:meth:`resolved`).

    Attributes
    ----------
    order : int
        Order of the Butterworth filters.
    position_cutoff, velocity_cutoff : float or None [Hz]
        Zero-phase low-pass cutoffs of the positions and of measured velocities; 0 switches a filter
        off. Default: :data:`~dynid.preprocessing.bands.POSITION_FACTOR` × ``band`` (velocities: the position cutoff).
    parallel_cutoff : float or None [Hz]
        Cutoff of the zero-phase low-pass applied to the torques **and** to every regressor column
        (parallel filtering); 0: only the decimation's anti-aliasing filter. Default:
        :data:`~dynid.preprocessing.bands.PARALLEL_FACTOR` × ``band``, lowered to the decimation's own cutoff when a
        given ``decimation`` needs it (said in :attr:`derivation`).
    decimation : int or None
        Parallel decimation factor. Default: the largest whose anti-aliasing cutoff is at or above
        ``parallel_cutoff``.
    band : float or None [Hz]
        Excitation band. Default: from the positions' spectrum (:func:`dynid.preprocessing.bands.excitation_band`),
        or the harmonics of ``fourier``.
    min_speed : "auto", float or tuple [rad/s]
        Rows of joint ``j`` where ``|dq_j| < min_speed_j`` are left out of the estimation (0: keep all).
        "auto": :data:`~dynid.preprocessing.bands.MIN_SPEED_FRACTION` × each joint's RMS speed.
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
        (:func:`dynid.identification.cross_validation.choose_coulomb_velocity`). Not the default: on the
        UR10e logs the choice made on the excitation log raised the point-to-point validation errors.
    rest_velocity : "auto", float or tuple [rad/s]
        Per joint, the velocity below which the joint counts as resting: its Coulomb (and Stribeck, asymmetric
        Coulomb) column is 0 there, with a ramp to ±1 at twice it (:func:`dynid.friction.moving_sign`), since
        below it the velocity's sign is noise and the friction of a resting joint is whatever holds it. "auto"
        (default): :data:`dynid.preprocessing.bands.REST_FACTOR` × the standard deviation of the noise the
        filtered velocity carries (:func:`dynid.preprocessing.filters.velocity_noise_std`), for each log
        anew; 0: plain sign.
    band_floor : float [Hz]
        Lower bound of a band estimated from the data: a log scored with another log's parameters is filtered for
        the faster of the two motions.
    rest_floor : float or tuple [rad/s]
        Lower bound of the "auto" rest velocity: a log scored with another log's parameters takes that log's rest
        velocities as the floor (the same sensors; a log that barely moves shows too little noise to measure it).
    rest_friction : "held", "zero", float [s], or a tuple of them
        Per joint, the friction predicted while it rests: "held" (default), that of its last motion (the static
        friction holds the link while the controller keeps the torque it had when the joint stopped); a time in
        seconds: that, relaxing to 0 with this time constant; "zero": none (:func:`dynid.friction.held_direction`).
    presliding : float or tuple [rad]
        Per joint, Dahl's presliding distance over which the friction reverses with the direction of motion
        (:func:`dynid.friction.held_direction`); 0 (default): at once. At most :data:`MAX_PRESLIDING`.
    torque_delay : float [s]
        How long the torque (current) channel lags the positions: the torque logged at ``t`` is the model's torque at
        ``t − torque_delay``, so the torques are read ``torque_delay`` later (a band-limited shift on the log's grid,
        :class:`dynid.preprocessing.filters.FractionalShift`) before any filter. Default 0. A drive that holds each commanded torque over its control period
        and logs the command leads the motion by half a period: ``−0.5 / rate`` (the closed-loop study's logs).
        :func:`dynid.identification.delay.estimate_delay` estimates it from a log.
    strategy : str
        The preprocessing strategy (:mod:`dynid.preprocessing.strategies`): "parallel" (default: the filters
        described here) or "paper" (the paper's §3.3: a Fourier fit on ``fourier``'s harmonics and eq. 17 on the
        torques and every regressor column, ``smoothing_passes`` times), or one registered by the user.
    smoothing_passes : int
        Applications of eq. 17 by the "paper" strategy (default 1).
    auto : bool
        Default true: when neither cutoff is given and the positions' noise knee lies well above
        :data:`~dynid.preprocessing.bands.POSITION_FACTOR` × the band (a slow motion on a quiet log: the rule
        would filter away content the data hold), the position and parallel cutoffs (hence the decimation) are
        chosen by blocked cross-validation among the rule's cutoff, the knee and their geometric mean
        (:func:`dynid.identification.cross_validation.choose_preprocessing`); false: the rule.
    derivation : str
        Filled by :meth:`resolved`: what was derived from the data, and why.
    noise_share : float or None
        Filled by :meth:`resolved` when the band comes from the positions: the share of their velocity-weighted
        spectral energy that is broadband noise (:class:`dynid.preprocessing.bands.BandEstimate`).
    knee : float or None [Hz]
        Filled by :meth:`resolved` like ``noise_share``: where the positions' spectrum meets the noise floor.
    warnings : tuple of str
        Filled by :meth:`resolved`: an implausible band, a capped cutoff (one line each, naming the dataset).
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
    rest_velocity: str | float | tuple = "auto"
    rest_floor: float | tuple = 0.0
    band_floor: float = 0.0
    knee: float | None = None
    rest_friction: str | float | tuple = "held"
    presliding: float | tuple = 0.0
    torque_delay: float = 0.0
    strategy: str = "parallel"
    smoothing_passes: int = 1
    auto: bool = True
    derivation: str = ""
    noise_share: float | None = None
    warnings: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        """Refuse a setting no log can mean, in one line naming the field (a ``ConfigError``), as a config's
        ``[preprocessing]`` table is checked (:data:`_RANGES`, the speeds of :data:`_PER_JOINT`, ``rest_friction``,
        ``presliding`` up to :data:`MAX_PRESLIDING`): the same settings through the API and through a file."""
        for name, low, whole, above in _RANGES:
            value = getattr(self, name)
            if value is not None and not _in_range(value, low, whole, above):
                raise ConfigError(f"preprocessing.{name}: expected {'an integer' if whole else 'a number'} "
                                  f"{'>' if above else '>='} {low:g}, got {value!r}")
        for name, auto in _PER_JOINT:
            if not _speeds(getattr(self, name), auto):
                said = '"auto", ' if auto else ""
                raise ConfigError(f"preprocessing.{name}: expected {said}a speed >= 0 (rad/s, or m/s on a sliding "
                                  f"joint), or one per joint, got {getattr(self, name)!r}")
        rest = np.atleast_1d(np.asarray(self.rest_friction, dtype=object))
        if rest.ndim > 1 or not all(x in ("held", "zero") or _in_range(x, 0.0, False) for x in rest.tolist()):
            raise ConfigError(f'preprocessing.rest_friction: expected "held", "zero" or a relaxation time >= 0 s, or one '
                              f"per joint, got {self.rest_friction!r}")
        try:
            x0 = np.asarray(self.presliding, dtype=float)
        except (TypeError, ValueError):
            x0 = np.array(np.nan)
        if x0.ndim > 1 or not np.all((x0 >= 0) & (x0 <= MAX_PRESLIDING)):
            raise ConfigError(f"preprocessing.presliding: expected a distance from 0 to {MAX_PRESLIDING:g} (rad, or m on a "
                              f"sliding joint), or one per joint, got {self.presliding!r}")

    @keyword_only_after_data
    def resolved(self, rate: float, q: np.ndarray | None = None, *, measured_velocity: bool = True,
                 name: str = "data", strict: bool = True) -> Preprocessing:
        """Every ``None`` replaced by its data-derived value (module :mod:`dynid.preprocessing.bands`).

        Cutoffs given in Hz stay what the user wrote; a cutoff at or above :data:`~dynid.preprocessing.bands.NYQUIST_CAP`
        of this log's Nyquist frequency (another dataset's rate) is lowered to it, and a parallel cutoff above a
        given decimation's anti-aliasing cutoff is lowered to that, each with a line in :attr:`warnings`.

        Parameters
        ----------
        rate : float [Hz]
        q : (N, n_dof) array, optional
            Measured positions, for the excitation band when neither ``band`` nor ``fourier`` gives it.
        measured_velocity : bool
            Whether the log has velocities (then filtered at ``velocity_cutoff``).
        name : str
            The dataset, for the warnings.
        strict : bool
            Refuse a given cutoff at or above this log's Nyquist frequency (the config's own log: a mistake) rather
            than lowering it (settings carried over to a log of another rate).

        Returns
        -------
        Preprocessing
            No ``None`` left; :attr:`derivation` says what was derived and why.

        Raises
        ------
        ConfigError
            A band (or with ``strict`` a given cutoff) at or above the Nyquist frequency, or no way to find the band.
        """
        nyq = rate / 2
        for key in (("position_cutoff", "velocity_cutoff", "parallel_cutoff", "band") if strict else ("band",)):
            v = getattr(self, key)
            if v is not None and v >= nyq:
                raise ConfigError(f"preprocessing.{key}: expected below the Nyquist frequency {nyq:g} Hz of {name} "
                                  f"({rate:.6g} Hz), got {v:g} Hz")
        warnings = list(self.warnings)
        band, source, share, knee = self._band(rate, q, name, warnings)
        derived = cutoffs_from_band(band, rate)

        def given(key: str, value: float | None) -> float | None:  # a cutoff in Hz, capped for this log's rate
            if value is None or value <= 0:
                return value
            cap = capped(value, rate)
            if cap < value:
                warnings.append(f"{name}: preprocessing.{key} = {value:g} Hz lies above {100 * cap / nyq:.0f} % of this "
                                f"log's Nyquist frequency ({rate:.6g} Hz): filtered at {cap:.4g} Hz")
            return cap

        pos = given("position_cutoff", self.position_cutoff)
        pos = derived.position_cutoff if pos is None else pos
        vel = given("velocity_cutoff", self.velocity_cutoff)
        vel = pos if vel is None else vel
        par = given("parallel_cutoff", self.parallel_cutoff)
        lowered = False
        if par is None:
            par = derived.parallel_cutoff
        if strict and self.decimation is not None and self.decimation > 1 and decimation_cutoff(rate, self.decimation) < band:
            raise ConfigError(f"preprocessing.decimation: {self.decimation} keeps {rate / self.decimation:.4g} Hz of {name} "
                              f"({rate:.6g} Hz), whose anti-aliasing filter ({decimation_cutoff(rate, self.decimation):.3g} Hz) "
                              f"would remove the motion ({source}: {band:.3g} Hz); at most "
                              f"{decimation_for(rate, band)}, or leave it out")
        if self.decimation is not None and self.decimation > 1 and par > decimation_cutoff(rate, self.decimation):
            limit = decimation_cutoff(rate, self.decimation)
            if self.parallel_cutoff:  # both given and they contradict: say so
                warnings.append(f"{name}: preprocessing.parallel_cutoff = {par:.4g} Hz would alias when decimating by "
                                f"{self.decimation} (at most {limit:.4g} Hz): filtered at {limit:.4g} Hz")
            par, lowered = limit, True
        if self.decimation is not None:
            dec = self.decimation
        elif par > 0:
            dec = decimation_for(rate, par)
        else:
            dec = 1
        if not strict and self.decimation is None and q is not None:  # a short log keeps enough samples to judge it
            dec = max(1, min(dec, q.shape[0] // MIN_SAMPLES_KEPT))
        if self.fourier is not None:
            on = []
        else:
            on = [c for c in ((pos, vel) if measured_velocity else (pos,)) if c > 0]
        trim = self.trim if self.trim is not None else (3.0 / min(on) if on else 0.0)
        if self.trim is None and q is not None:  # at most a tenth of the log at each end
            trim = min(trim, 0.1 * q.shape[0] / rate)
        return replace(self, position_cutoff=float(pos), velocity_cutoff=float(vel), parallel_cutoff=float(par),  # noqa: E501
                       decimation=int(dec), band=float(band), trim=float(trim),
                       derivation=self._derivation(band, source, pos, par, dec, lowered),
                       noise_share=share, knee=knee, warnings=tuple(dict.fromkeys(warnings)))

    def _band(self, rate: float, q, name: str, warnings: list) -> tuple[float, str, float | None, float | None]:
        """:meth:`resolved`'s excitation band: given, the Fourier fit's highest harmonic, or estimated from ``q``
        (no lower than ``band_floor``); with where it comes from, the noise share and the knee. Appends the
        estimate's warnings."""
        band, source, share, knee = self.band, "given by preprocessing.band", self.noise_share, self.knee
        if band is None and self.fourier is not None:
            band, source = self.fourier[0] * self.fourier[1] / (2 * np.pi), "the excitation's highest harmonic"
        if band is None:
            if q is None:
                raise ConfigError("preprocessing.band: needed when no positions are given to estimate it")
            found = estimate_band(q, rate)
            band, share, knee = found.band, found.noise_share, found.knee
            source = (f"99 % of the motion's velocity energy, above a noise floor holding {100 * share:.2g} % of the "
                      "positions' spectrum" if found.motion_found else "99 % of the velocity energy: no motion above the noise")
            if self.band_floor > 0 and found.warnings(name):  # a log that barely moves: the identification's band
                band, source = self.band_floor, "the identification log's: this log's own is implausible"
            else:
                warnings.extend(found.warnings(name))
            if band < self.band_floor:
                band, source = self.band_floor, "the identification log's, wider than this log's"
        return band, source, share, knee

    def _derivation(self, band: float, source: str, pos: float, par: float, dec: int, lowered: bool) -> str:
        """:meth:`resolved`'s account of what it chose and why (:attr:`derivation`)."""
        chosen = [f"excitation band {band:.3g} Hz ({source})"]
        if self.torque_delay:
            chosen.append(f"torques read {1e3 * abs(self.torque_delay):.3g} ms {'later' if self.torque_delay > 0 else 'earlier'} "
                          "than logged (torque_delay)")
        if self.fourier is None:
            chosen.append(f"positions low-passed at {pos:.3g} Hz" + ("" if self.position_cutoff is not None else f" ({POSITION_FACTOR:g}× band)"))
        else:
            chosen.append("positions, velocities and accelerations from the Fourier fit")
        if par > 0:
            why = (f" (the anti-aliasing cutoff of decimation = {dec})" if lowered else
                   "" if self.parallel_cutoff is not None else f" ({PARALLEL_FACTOR:g}× band)")
            chosen.append(f"torques and every regressor column low-passed in parallel at {par:.3g} Hz{why}")
        else:
            chosen.append("no parallel filter")
        chosen.append(f"decimation by {dec}" + ("" if self.decimation is not None else " (down to the parallel band)"))
        return "; ".join(chosen)

    @property
    def friction_default(self) -> str:
        """The friction setting every route takes where none is given: "auto" (each joint's model chosen by
        cross-validation), or "description" where a Coulomb smoothing velocity is given (its terms are the user's).

        Returns
        -------
        str
        """
        return "description" if self.coulomb_velocity != 0.0 else "auto"

    def to_dict(self) -> dict:
        """The settings as results.json stores them (``warnings`` go to the result's own warnings).

        Returns
        -------
        dict
            field -> value (tuples as lists).
        """
        return {f.name: (list(getattr(self, f.name)) if isinstance(getattr(self, f.name), tuple) else getattr(self, f.name))
                for f in fields(self) if f.name != "warnings"}

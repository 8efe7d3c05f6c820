"""Change detection on a stream of standardised estimates: Page's two-sided CUSUM (Page 1954; Montgomery,
*Introduction to Statistical Quality Control*, §9.1), one pair of charts per monitored term.

Each new value ``z`` (an estimate minus its reference mean, over its reference standard deviation) updates::

    S⁺ ← max(0, S⁺ + z - k),   S⁻ ← max(0, S⁻ - z - k)

and an alarm is raised when either exceeds ``h``. With ``k = ½`` the chart is tuned to shifts of one standard
deviation and more. ``h`` follows from the in-control average run length (the mean number of values between false
alarms) by Siegmund's approximation, ``ARL₀ ≈ (e^{2kb} - 2kb - 1) / (2k²)``, ``b = h + 1.166``, for the whole family
of charts (their false alarms add up). When the alarm comes, the change is dated by maximum likelihood among the
values since the chart last stood at zero (the split ``τ`` that maximises ``(Σ_{i≥τ} z_i)² / (n - τ)``, the
generalised likelihood ratio of a mean shift), and its size is the mean of ``z`` since then.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..exceptions import ShapeError

__all__ = ["Cusum", "CusumAlarm", "cusum_threshold"]

K_REFERENCE = 0.5
"""The chart's reference value k (half the smallest shift, in standard deviations, it is tuned to)."""


def _arl(h: float, k: float) -> float:
    b = h + 1.166
    return (math.exp(2 * k * b) - 2 * k * b - 1) / (2 * k * k)


def cusum_threshold(arl0: float, charts: int = 1, k: float = K_REFERENCE) -> float:
    """The decision interval ``h`` that gives a family of ``charts`` one-sided charts a false alarm every ``arl0``
    values on average (Siegmund's approximation, module docstring).

    Parameters
    ----------
    arl0 : float
        In-control average run length of the family [values].
    charts : int
        One-sided charts in the family (two per monitored term).
    k : float

    Returns
    -------
    float

    Raises
    ------
    ValueError
        ``arl0`` not above 1, or ``charts`` < 1.
    """
    if not arl0 > 1 or charts < 1:
        raise ValueError(f"expected arl0 > 1 and charts >= 1, got {arl0} and {charts}")
    target = arl0 * charts
    lo, hi = 0.0, 100.0
    for _ in range(200):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if _arl(mid, k) < target else (lo, mid)
    return hi


@dataclass(frozen=True)
class CusumAlarm:
    """An alarm of a chart.

    Attributes
    ----------
    channel : int
        Which monitored term.
    index : int
        The value that raised it (0-based over the stream).
    start : int
        The first value of the change (after the chart last stood at zero).
    direction : int
        +1 a rise, -1 a fall.
    shift : float
        Mean of ``z`` from ``start`` to ``index`` [reference standard deviations].
    """

    channel: int
    index: int
    start: int
    direction: int
    shift: float


class Cusum:
    """Two-sided CUSUM charts for ``channels`` terms (module docstring).

    Parameters
    ----------
    channels : int
    threshold : float
        ``h`` (:func:`cusum_threshold`).
    k : float

    Attributes
    ----------
    alarms : list of CusumAlarm
        Every alarm so far; a channel that alarmed restarts from zero.
    """

    def __init__(self, channels: int, threshold: float, k: float = K_REFERENCE):
        self.h, self.k = float(threshold), float(k)
        self.up, self.down = np.zeros(channels), np.zeros(channels)
        self.start_up = np.zeros(channels, dtype=int)
        self.start_down = np.zeros(channels, dtype=int)
        self.count = 0
        self.history: list[np.ndarray] = []
        self.alarms: list[CusumAlarm] = []

    def update(self, z) -> list[CusumAlarm]:
        """Take in one value per channel.

        Parameters
        ----------
        z : (channels,) array
            Standardised values; NaN leaves a channel as it was.

        Returns
        -------
        list of CusumAlarm
            The alarms this value raised.

        Raises
        ------
        ShapeError
            Not one value per channel.
        """
        z = np.asarray(z, dtype=float)
        if z.shape != self.up.shape:
            raise ShapeError(f"z: expected {self.up.shape[0]} values, got shape {z.shape}")
        i, new = self.count, []
        ok = np.isfinite(z)
        zz = np.where(ok, z, 0.0)
        self.history.append(np.where(ok, z, np.nan))
        for side, sign, starts in ((self.up, 1.0, self.start_up), (self.down, -1.0, self.start_down)):
            starts[ok & (side == 0)] = i
            side[:] = np.where(ok, np.maximum(0.0, side + sign * zz - self.k), side)
            for c in np.nonzero(side > self.h)[0]:
                since = self._change_point(int(c), int(starts[c]), i)
                seen = np.array([h[c] for h in self.history[since:i + 1]])
                new.append(CusumAlarm(int(c), i, since, int(sign), float(np.nanmean(seen))))
                side[c] = 0.0
                starts[c] = i + 1
        self.count += 1
        self.alarms.extend(new)
        return new

    def _change_point(self, channel: int, first: int, last: int) -> int:
        """The most likely start of a mean shift among values ``first..last`` of a channel (module docstring)."""
        z = np.nan_to_num(np.array([h[channel] for h in self.history[first:last + 1]]))
        tail = np.cumsum(z[::-1])[::-1]  # Σ_{i≥τ} z_i
        stat = tail ** 2 / np.arange(z.size, 0, -1)
        return first + int(np.argmax(stat))

"""Units that stand out from their fleet: z-scores of each identified parameter against the other units.

For unit ``u`` and parameter ``k``, the other ``m`` units are the reference (leaving the unit out keeps an odd unit
from widening its own reference). Two cases: a parameter that units of one model share (a drive gain, a rigid-body
parameter) and on which the others agree within their standard deviations σ (their sample variance below the 99 %
quantile of σ²·χ²_{m-1}/(m-1)); and a parameter that may differ from unit to unit (friction, current offsets: said
beforehand, since a few units that happen to agree would otherwise make a normal one look odd) or on which they do
not agree:

- **they agree**: the fleet's value is their median, its spread
  the larger of 1.4826 × their median absolute deviation and their median σ, and
  ``z = (x_uk - median) / sqrt(spread² + σ_uk²)`` is compared with the normal quantile;
- **they differ** (friction, a tool): ``z = (x_uk - mean) / sqrt(s²·(1 + 1/m) + σ_uk²)`` with their sample
  standard deviation ``s``, a prediction interval for a new unit, compared with Student's t with ``m - 1`` degrees of
  freedom (a spread estimated from few units has heavy tails: in a small fleet only a large difference is flagged).

Thresholds are Bonferroni's for a family-wise false-flag probability ``alpha`` over every unit and parameter. The
unit's own σ enters every z, so a parameter its log determines poorly is not flagged for that.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..exceptions import ShapeError

__all__ = ["MAD_TO_STD", "FALSE_FLAG_RATE", "Outlier", "fleet_z", "fleet_outliers"]

MAD_TO_STD = 1.4826
"""The median absolute deviation of normal data × this is their standard deviation."""

FALSE_FLAG_RATE = 0.01
"""Probability that a fleet of units that differ only at random has any flag (over all units and parameters)."""


def fleet_z(values, std=None, alpha: float = FALSE_FLAG_RATE, may_differ=None) -> tuple[np.ndarray, np.ndarray]:
    """Leave-one-out z-scores and their flag thresholds (module docstring).

    Parameters
    ----------
    values : (n_units, n_params) array
        NaN where a unit has no value (not identified, not observable): its z is NaN.
    std : (n_units, n_params) array, optional
        Each value's standard deviation (default 0: the others agree only if they are equal).
    alpha : float
        Family-wise false-flag probability.
    may_differ : (n_params,) bool array, optional
        Parameters expected to differ between units (default: none).

    Returns
    -------
    z : (n_units, n_params) ndarray
        NaN where fewer than 3 other units have a value.
    threshold : (n_units, n_params) ndarray
        The |z| beyond which each is flagged.

    Raises
    ------
    ShapeError
        Not 2-D, or ``std`` of another shape.
    """
    from scipy.stats import chi2, norm, t

    x = np.asarray(values, dtype=float)
    if x.ndim != 2:
        raise ShapeError(f"values: expected (n_units, n_params), got shape {x.shape}")
    s = np.zeros_like(x) if std is None else np.asarray(std, dtype=float)
    if s.shape != x.shape:
        raise ShapeError(f"std: expected shape {x.shape}, got {s.shape}")
    s = np.where(np.isfinite(s), s, np.inf)
    differ = np.zeros(x.shape[1], dtype=bool) if may_differ is None else np.asarray(may_differ, dtype=bool)
    z, limit = np.full_like(x, np.nan), np.full_like(x, np.inf)
    tests = max(int(np.sum(np.isfinite(x))), 1)
    p = alpha / (2 * tests)
    normal = float(norm.isf(p))
    agree = {m: float(chi2.ppf(0.99, m - 1) / (m - 1)) for m in range(3, x.shape[0] + 1)}
    student = {m: float(t.isf(p, m - 1)) for m in range(3, x.shape[0] + 1)}
    for u in range(x.shape[0]):
        for k in range(x.shape[1]):
            ok = np.isfinite(x[:, k]) & np.isfinite(s[:, k])
            ok[u] = False
            m = int(ok.sum())
            if m < 3 or not np.isfinite(x[u, k]):
                continue
            others, sigma = x[ok, k], s[ok, k]
            variance = float(np.var(others, ddof=1))
            if not differ[k] and variance <= agree[m] * float(np.mean(sigma ** 2)):
                med = float(np.median(others))
                spread = max(MAD_TO_STD * float(np.median(np.abs(others - med))), float(np.median(sigma)))
                scale, centre, limit[u, k] = np.hypot(spread, s[u, k]), med, normal
            else:
                scale = np.sqrt(variance * (1 + 1 / m) + s[u, k] ** 2)
                centre, limit[u, k] = float(np.mean(others)), student[m]
            if scale > 0:
                z[u, k] = (x[u, k] - centre) / scale
    return z, limit


@dataclass(frozen=True)
class Outlier:
    """A unit's parameter that stands out.

    Attributes
    ----------
    unit : str
    parameter : str
    value : float
    fleet : float
        The other units' median.
    z : float
    """

    unit: str
    parameter: str
    value: float
    fleet: float
    z: float

    def to_dict(self) -> dict:
        """JSON-ready.

        Returns
        -------
        dict
        """
        return {"unit": self.unit, "parameter": self.parameter, "value": self.value, "fleet_median": self.fleet, "z": self.z}

    def __str__(self) -> str:
        return (f"{self.unit}: {self.parameter} = {self.value:.4g}, the other units {self.fleet:.4g} "
                f"(z {self.z:+.1f})")


def fleet_outliers(units, names, values, std=None, alpha: float = FALSE_FLAG_RATE,
                   may_differ=None) -> tuple[tuple[Outlier, ...], float]:
    """The parameters of units that stand out from the fleet, largest ``|z|`` first.

    Parameters
    ----------
    units : sequence of str
    names : sequence of str
        The parameters (columns of ``values``).
    values, std : (n_units, n_params) arrays
        As :func:`fleet_z`.
    alpha : float
        Family-wise false-flag probability.
    may_differ : (n_params,) bool array, optional
        As :func:`fleet_z`.

    Returns
    -------
    outliers : tuple of Outlier
    threshold : float
        The lowest ``|z|`` beyond which a parameter was flagged (that of the parameters on which the other units agree
        within their σ; inf for fleets of fewer than 4 units: none is flagged).

    Raises
    ------
    ShapeError
        ``values`` not (len(units), len(names)).
    """
    x = np.asarray(values, dtype=float)
    if x.shape != (len(units), len(names)):
        raise ShapeError(f"values: expected shape ({len(units)}, {len(names)}), got {x.shape}")
    if len(units) < 4:
        return (), float("inf")
    z, limits = fleet_z(x, std, alpha, may_differ)
    found = []
    for u, k in zip(*np.nonzero(np.abs(np.nan_to_num(z)) > limits)):
        others = np.delete(x[:, k], u)
        found.append(Outlier(str(units[u]), str(names[k]), float(x[u, k]), float(np.nanmedian(others)), float(z[u, k])))
    found.sort(key=lambda o: -abs(o.z))
    return tuple(found), float(np.min(limits)) if limits.size else float("inf")

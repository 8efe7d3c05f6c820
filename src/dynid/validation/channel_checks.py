"""A validation log whose torque channels are read otherwise than the identification log's: one joint's sign flipped,
two joints' columns swapped, torques in another unit or through other drive gains.

The estimate fitted to the identification log predicts each of its joints (its correlation coefficient, eq. 18, near
1). On another log read the same way its predictions run with the measured torques; a flipped channel runs against
its prediction at about its size, and two swapped channels each fit the other's prediction far better than their own.
The check the identification log gets (:func:`dynid.validation.diagnostics.sign_findings`,
:class:`dynid.validation.diagnostics.OrderSums`) judges
against the description's nominal model, since nothing is fitted yet; here the fitted estimate is the sharper yardstick
(the description's nominal J2 and J3 torques of the UR10e correlate at 0.9 and more). A scale is the log's, not the
fit's, only where the description's nominal model sees it too: a joint whose identification log is in another unit
has its estimate off by that scale, and the description predicts the validation log at its size.
"""

from __future__ import annotations

import numpy as np

from .diagnostics import ORDER_GAIN, SCALE_LIMIT, Finding, scale_text

__all__ = ["FITTED", "channel_findings"]

FITTED = 0.9
"""A joint is judged where the estimate's correlation with its measured torque on the identification log is at least
this: the estimate predicts it."""

AGAINST = -0.8
"""A joint whose measured torque correlates with the estimate's prediction below this, at its size (within
:data:`dynid.validation.diagnostics.SCALE_LIMIT`), runs against it: its sign is flipped."""


NOMINAL_FOLLOWS = 0.5
"""A joint's measured torque on a validation log correlates with the description's nominal prediction at least this much
for the nominal model's slope to say whether the log or the fit has another scale (a CAD description 10-60 % off
correlates at 0.65-0.9 on the UR10e example's validation log)."""


def _others_predicted(rho: np.ndarray, judged, joints) -> bool:
    """Whether the estimate predicts the log's judged joints other than ``joints`` (their median correlation at least
    :data:`FITTED`): a channel is judged only on a log whose other joints the estimate predicts, not one it extrapolates
    to or whose torques barely vary (the UR10e's static holds, where an estimate fitted to a 1.5 s window misses every
    joint)."""
    rest = [j for j in judged if j not in joints]
    return bool(rest) and float(np.median(np.asarray(rho)[rest])) >= FITTED


def _centred(x) -> np.ndarray:
    """An (N, n_dof) signal about each joint's mean."""
    x = np.asarray(x, dtype=float)
    return x - x.mean(axis=0)


def _fit(m: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each joint's slope of the measured torque ``m`` on the predicted one ``p`` and their correlation (both
    :func:`_centred`)."""
    power = np.maximum((p**2).sum(axis=0), 1e-300)
    # a joint with no torque of its own (one that follows another, <mimic>) has m = p = 0: correlation 0, not 0/0
    return (m * p).sum(axis=0) / power, (m * p).sum(axis=0) / np.sqrt(np.maximum((m**2).sum(axis=0) * power, 1e-300))


def channel_findings(comparison, label: str, fitted: np.ndarray, nominal: str | None = None) -> list[Finding]:
    """A validation log's flipped, swapped or scaled torque channels (module docstring).

    Parameters
    ----------
    comparison : TorqueComparison
        The validation log scored with ``label`` among its sets.
    label : str
        The estimate fitted to the identification log.
    fitted : (n_dof,) array
        Its correlation coefficient (eq. 18) with each joint's measured torque on the identification log.
    nominal : str, optional
        The description's nominal model among the log's sets: a scale is judged only with it.

    Returns
    -------
    list of Finding
        At most one, of kind ``"misread"``, naming the joints and the setting of the table that reads the log.
    """
    measured = np.asarray(comparison.measured, dtype=float)
    predicted = np.asarray(comparison.predicted[label], dtype=float)
    judged = np.flatnonzero(comparison.varies(beyond="floor") & (np.asarray(fitted, dtype=float) >= FITTED)
                            & np.all(np.isfinite(predicted), axis=0))
    m, p = _centred(measured), _centred(predicted)
    slope, rho = _fit(m, p)
    own = ((m - p) ** 2).sum(axis=0)  # about each channel's mean: an offset the estimate misses is no swap
    for a, b in ((a, b) for i, a in enumerate(judged) for b in judged[i + 1:]):
        cross = (((m[:, a] - p[:, b]) ** 2).sum(), ((m[:, b] - p[:, a]) ** 2).sum())
        if (cross[0] <= ORDER_GAIN * own[a] and cross[1] <= ORDER_GAIN * own[b]
                and _others_predicted(rho, judged, (a, b))):
            return [Finding("misread", f"{comparison.name}: J{a + 1}'s and J{b + 1}'s measured torques fit each other's "
                                       f"prediction by {label} far better than their own (residual "
                                       f"{np.sqrt(cross[0] / own[a]):.2g}× and {np.sqrt(cross[1] / own[b]):.2g}×): are "
                                       "their columns swapped in this log? If so, swap them in torques = { columns = "
                                       "[...] } of the table that reads it", int(a))]
    flipped = [j for j in judged if rho[j] < AGAINST and 1 / SCALE_LIMIT <= abs(slope[j]) <= SCALE_LIMIT]
    n = measured.shape[1]
    if flipped and _others_predicted(rho, judged, flipped):  # after the swaps: two swapped channels may run against
        joints = " and ".join(f"J{j + 1}" for j in flipped)
        fix = ", ".join("-1" if j in flipped else "1" for j in range(n))
        return [Finding("misread", f"{comparison.name}: {joints}'s measured torque runs against {label}'s prediction "
                                   f"(ρ = {', '.join(f'{rho[j]:.3f}' for j in flipped)}), which fits "
                                   f"{'it' if len(flipped) == 1 else 'them'} on the identification log: is the sign "
                                   f"flipped in this log? If so, torques = {{ ..., sign = [{fix}] }} in the "
                                   "table that reads it", int(flipped[0]))]
    return _scale_findings(comparison, label, slope, rho, judged, nominal)


def _scale_findings(comparison, label: str, slope: np.ndarray, rho: np.ndarray, judged, nominal: str | None
                    ) -> list[Finding]:
    """Joints whose measured torque runs with the estimate's prediction (ρ ≥ :data:`FITTED`) at beyond
    :data:`dynid.validation.diagnostics.SCALE_LIMIT` times or under its inverse (every joint it so runs with, or some
    where the estimate predicts the others), where the description's nominal model sees that scale too: on each of those joints
    it follows (ρ ≥ :data:`NOMINAL_FOLLOWS`), its slope is nearer the estimate's than 1 (the UR10e example's validation
    torques at 0.1×: the estimate's slopes 0.100, the nominal model's 0.086-0.108 where it follows)."""
    if nominal is None or nominal not in comparison.predicted:
        return []
    followed = [j for j in judged if rho[j] >= FITTED]
    scaled = [j for j in followed if not 1 / SCALE_LIMIT <= slope[j] <= SCALE_LIMIT]
    if not scaled or not (len(scaled) == len(followed) >= 2 or _others_predicted(rho, judged, scaled)):
        return []
    k, r = _fit(_centred(comparison.measured), _centred(comparison.predicted[nominal]))
    seen = [j for j in scaled if r[j] >= NOMINAL_FOLLOWS and k[j] > 0]
    if not seen or any(abs(np.log10(k[j] / slope[j])) >= abs(np.log10(k[j])) for j in seen):
        return []  # the description predicts this log at its size: the fit, not the log, is off
    n = slope.size
    common = np.ptp(np.log10(slope[scaled])) < 0.1 and len(scaled) == len(followed)
    fix = scale_text(float(np.median(slope[scaled]))) if common else \
        "[" + ", ".join(scale_text(float(slope[j])) if j in scaled else "1" for j in range(n)) + "]"
    joints = ", ".join(f"J{j + 1} ({slope[j]:.3g}×)" for j in scaled)
    return [Finding("misread", f"{comparison.name}: the measured torques of {joints} are that many times "
                               f"{label}'s prediction (ρ ≥ {FITTED:g}), which fits them on the identification log, "
                               "and about as many times the description's nominal model's: is this log in another unit "
                               "or through other drive gains than the identification log? If so, torques = { ..., "
                               f"scale = {fix} }} in the table that reads it", int(scaled[0]))]

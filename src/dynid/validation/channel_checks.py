"""A validation log whose torque channels are read otherwise than the identification log's: one joint's sign flipped,
two joints' columns swapped.

The estimate fitted to the identification log predicts each of its joints (its correlation coefficient, eq. 18, near
1). On another log read the same way its predictions run with the measured torques; a flipped channel runs against
its prediction at about its size, and two swapped channels each fit the other's prediction far better than their own.
The check the identification log gets (:func:`dynid.validation.diagnostics.sign_findings`,
:class:`dynid.validation.diagnostics.OrderSums`) judges
against the description's nominal model, since nothing is fitted yet; here the fitted estimate is the sharper yardstick
(the description's nominal J2 and J3 torques of the UR10e correlate at 0.9 and more).
"""

from __future__ import annotations

import numpy as np

from .diagnostics import ORDER_GAIN, SCALE_LIMIT, Finding

__all__ = ["FITTED", "channel_findings"]

FITTED = 0.9
"""A joint is judged where the estimate's correlation with its measured torque on the identification log is at least
this: the estimate predicts it."""

AGAINST = -0.8
"""A joint whose measured torque correlates with the estimate's prediction below this, at its size (within
:data:`dynid.validation.diagnostics.SCALE_LIMIT`), runs against it: its sign is flipped."""


def _others_predicted(rho: np.ndarray, judged, joints) -> bool:
    """Whether the estimate predicts the log's judged joints other than ``joints`` (their median correlation at least
    :data:`FITTED`): a channel is judged only on a log whose other joints the estimate predicts, not one it extrapolates
    to or whose torques barely vary (the UR10e's static holds, where an estimate fitted to a 1.5 s window misses every
    joint)."""
    rest = [j for j in judged if j not in joints]
    return bool(rest) and float(np.median(np.asarray(rho)[rest])) >= FITTED


def channel_findings(comparison, label: str, fitted: np.ndarray) -> list[Finding]:
    """A validation log's flipped or swapped torque channels (module docstring).

    Parameters
    ----------
    comparison : TorqueComparison
        The validation log scored with ``label`` among its sets.
    label : str
        The estimate fitted to the identification log.
    fitted : (n_dof,) array
        Its correlation coefficient (eq. 18) with each joint's measured torque on the identification log.

    Returns
    -------
    list of Finding
        At most one, of kind ``"misread"``, naming the joints and the setting of the table that reads the log.
    """
    measured = np.asarray(comparison.measured, dtype=float)
    predicted = np.asarray(comparison.predicted[label], dtype=float)
    judged = np.flatnonzero(comparison.varies(beyond="floor") & (np.asarray(fitted, dtype=float) >= FITTED)
                            & np.all(np.isfinite(predicted), axis=0))
    m, p = measured - measured.mean(axis=0), predicted - predicted.mean(axis=0)
    power = np.maximum((p**2).sum(axis=0), 1e-300)
    slope = (m * p).sum(axis=0) / power
    rho = (m * p).sum(axis=0) / np.sqrt(np.maximum((m**2).sum(axis=0), 1e-300) * power)
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
    return []

"""A joint's torque read with the wrong sign where the description's nominal model cannot tell: the physically
consistent estimate cannot follow it, and follows it with the sign flipped.

The nominal model judges a torque's sign where it predicts the joint's torque (gravity, the links' inertia:
:func:`dynid.validation.diagnostics.sign_findings`). A joint whose torque it barely predicts (the first axis of an
upright arm, a flange's rotation) is not judged there. Least squares fits such a joint with either sign (its inertia
and friction come out negative), the SDP cannot (pseudo-inertias positive semidefinite, friction ≥ 0): where the SDP
leaves :data:`MISFIT` times least squares' residual on one joint, it is refitted with that joint's torque negated,
and the joint is named where the refit leaves at most :data:`FLIPPED_FITS` of its residual there and less over all
joints. Measured on the LBR Med7's log read with J7's sign flipped: the SDP fitted J7 to 96 % against least squares'
27 % (1.0-1.2× on every joint of the four real logs read right), and predicted the validation log 20.0 % against
8.8 % read right.
"""

from __future__ import annotations

import copy

import numpy as np

from ..conventions import joint_unit
from ..exceptions import DynIdError
from ..validation.diagnostics import Finding

__all__ = ["FLIPPED_FITS", "MISFIT", "flipped_joint_findings"]

MISFIT = 2.0
"""The SDP's RMS residual on a joint, over least squares' on the same rows, from which the joint's sign is tried."""

FLIPPED_FITS = 0.5
"""The SDP refitted with the joint's torque negated leaves at most this share of its RMS residual on that joint."""


def flipped_joint_findings(sdp, reference, dataset: str, table: str = "[identification]", *, prismatic=()) -> list[Finding]:
    """The joints whose measured torque the SDP follows only with its sign flipped (module docstring).

    Parameters
    ----------
    sdp : PhysicallyConsistentLeastSquares or None
        The fitted SDP with its accumulated rows (``accumulator_``, ``problem_``); None: nothing to judge.
    reference : AccumulatingEstimator
        The least-squares reference, fitted on the same rows (its ``accumulator_`` and ``params_``).
    dataset : str
        The log, named in the finding.
    table : str
        The config table whose ``torques`` sign the finding names.
    prismatic : sequence of bool
        Which joints slide (their forces said in N).

    Returns
    -------
    list of Finding
        At most one, kind ``sign``.
    """
    acc = None if sdp is None else sdp.__dict__.get("accumulator_")
    ls_acc = reference.__dict__.get("accumulator_")
    if acc is None or ls_acc is None or not np.array_equal(acc.rows, ls_acc.rows):
        return []
    own = acc.joint_residual_sumsq(sdp.params_)
    least = ls_acc.joint_residual_sumsq(reference.params_)
    weights = sdp.problem_.joint_weights
    w2 = np.ones(acc.n_dof) if weights is None else np.asarray(weights, dtype=float) ** 2
    flipped, shares = [], []
    for j in np.flatnonzero(own > MISFIT**2 * np.maximum(least, 1e-300)):
        try:
            left = _refit_negated(sdp, acc, int(j))
        except DynIdError:  # no consistent solution with it negated: its sign is not judged (a check never refuses)
            continue
        if left[j] <= FLIPPED_FITS**2 * own[j] and w2 @ left < w2 @ own:
            flipped.append(int(j))
            shares.append((np.sqrt(own[j] / ls_acc.rows[j]), np.sqrt(left[j] / ls_acc.rows[j])))
    if not flipped:
        return []
    joints = ", ".join(f"J{j + 1}" for j in flipped)
    rms = "; ".join(f"J{j + 1} {a:.3g} {joint_unit('N·m', prismatic, j)} RMS as read, {b:.3g} flipped"
                    for j, (a, b) in zip(flipped, shares))
    return [Finding("sign", f"{dataset}: {joints}: the physically consistent estimate cannot follow the measured torque "
                            f"and follows it with its sign flipped ({rms}), where the nominal model barely predicts "
                            f"it: is its sign flipped? Negate {'its entry' if len(flipped) == 1 else 'their entries'} "
                            f"of torques = {{ ..., sign = [...] }} in {table} and the other datasets")]


def _refit_negated(sdp, acc, j: int) -> np.ndarray:
    """Each joint's residual sum of squares of the SDP refitted on ``acc`` with joint ``j``'s torque negated."""
    negated = copy.deepcopy(acc)
    negated.factors[j][:, -1] *= -1.0  # the QR factor of [W_j | -tau_j]: the torque's column negated
    refit = sdp.clone()
    refit.take_problem(sdp.problem_)
    refit.__dict__["accumulator_"] = negated
    refit.solve()
    return negated.joint_residual_sumsq(refit.params_)

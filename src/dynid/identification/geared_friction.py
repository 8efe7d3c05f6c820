"""Torques that follow the description once the friction turns over a presliding distance: a geared drive's
hysteresis, told from a log read wrongly.

The check of a log read as torques (:func:`dynid.validation.diagnostics.unlike_nominal_findings`) judges each joint's
measured torque against the description's nominal model once the friction columns (Coulomb, viscous, offset) are
regressed out of both. On a light arm with geared drives the dry friction does not turn at once at a reversal but over
a presliding distance (Dahl's model), and that hysteresis, which Coulomb's ``sign(q̇)`` column does not span, can be
most of what varies beyond friction: the zoo's SO-100 with a 2 mrad presliding distance correlates 0.46 at best with
its description beyond friction (0.98 without the hysteresis). Before the log is called misread, the correlation is
judged again with the Coulomb columns of Dahl's model (:func:`dynid.friction.held_direction` with a presliding distance)
at :data:`PRESLIDING_DISTANCES`; a distance at which a joint follows the description says the log holds torques.
It costs one pass over the log's rows per distance, only where the log would otherwise be called misread.

The same hysteresis looks like a late torque channel: after a reversal the friction turns over the presliding
distance, as a delayed ``sign(q̇)`` would. Where the delay check (:mod:`dynid.identification.delay`) finds a lag, the
log's held-out blocks are predicted again with Dahl's columns and no delay (:func:`delay_beyond_hysteresis`); where
a distance predicts them at least as well as the lag, the finding says the log cannot tell the two apart
(:func:`hysteresis_delay_finding`), and validation logs weigh the two settings apart (:func:`hysteresis_weighed`).
The delay and the distance trade off along a shallow valley of the held-out residual, so the delay left beside the
best distance is not reported (benchmarks/NOTEBOOK.md, stop 116).

Reference: Dahl, "Solid friction damping of mechanical vibrations", AIAA Journal 14(12), 1976; Canudas de Wit et al.,
"A new model for control of systems with friction", IEEE TAC 40(3), 1995, §2.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..dynamics.base_parameters import BaseParameters
from ..exceptions import DynIdError
from ..model.robot import Robot
from ..preprocessing.preparation import base_chunks
from ..preprocessing.prepared import PreparedData
from ..validation.diagnostics import Finding
from ..validation.torques import TorqueSums
from .delay import DelayEstimate, held_out_sum
from .verdict import SAME_FIGURE

__all__ = ["EXPLAINED", "PRESLIDING_DISTANCES", "HYSTERESIS_SCAN", "Hysteresis", "beyond_hysteresis", "hysteresis_explains",
           "hysteresis_finding", "delay_beyond_hysteresis", "hysteresis_delay_finding", "hysteresis_weighed"]

EXPLAINED = 0.25
"""The share of what friction turning at once leaves unexplained beyond it (``1 − ρ²`` of a joint's correlation with the
nominal model) that Dahl's friction must explain on one joint that varies (``1 − (1 − ρ_Dahl²) / (1 − ρ²)``, a partial
R²) for the log to be called a geared drive's hysteresis: a correlation nudged across the misread check's bound is not
one. Measured (benchmarks/NOTEBOOK.md, stop 118): simulated UR10e logs with Dahl friction of 1-8 mrad at 10-30× the
rigid-body RMS torque 0.42-1.0, the zoo's SO-100 0.93; a log of chatter at 10× its RMS whose J4 went from 0.47 to 0.52
with 10 mrad, 0.05."""

PRESLIDING_DISTANCES = (0.001, 0.003, 0.01)
"""Presliding distances [rad] tried, smallest first: 1-10 mrad (3.4-34 arcmin) spans the lost motion of the geared
drives of industrial and hobby arms."""


@dataclass(frozen=True)
class Hysteresis:
    """The torques against the nominal model beyond friction whose Coulomb terms turn over a presliding distance.

    Attributes
    ----------
    presliding : float [rad]
        The distance.
    beyond, slope : (n_dof,) arrays
        Each joint's partial correlation with the nominal model, and the torque's slope on it, beyond friction.
    beyond_drive, slope_drive : (n_dof,) arrays
        The same beyond friction and the rotor inertia.
    """

    presliding: float
    beyond: np.ndarray
    slope: np.ndarray
    beyond_drive: np.ndarray
    slope_drive: np.ndarray


def beyond_hysteresis(robot: Robot, base: BaseParameters, data: PreparedData, nominal: np.ndarray, friction: dict,
                      drive: dict, follows) -> Hysteresis | None:
    """The presliding distance of :data:`PRESLIDING_DISTANCES` at which the torques follow the nominal model best
    (the largest correlation of a joint), where they follow it at one.

    Parameters
    ----------
    robot : Robot
    base : BaseParameters
    data : PreparedData
        The identification log as prepared (its rest model kept; its presliding distance replaced).
    nominal : (n_base,) array
        The description's nominal base parameters.
    friction, drive : dict
        Joint (0-based) -> the base columns of its friction terms, and of its friction and rotor inertia
        (:meth:`dynid.validation.torques.TorqueSums.beyond`).
    follows : callable
        ``follows(beyond) -> bool``: whether correlations beyond friction say the log holds torques.

    Returns
    -------
    Hysteresis or None
        None where no distance makes them follow it (or the log already has a presliding distance).
    """
    if np.any(np.asarray(data.settings.presliding, dtype=float) != 0):
        return None
    found = []
    for distance in PRESLIDING_DISTANCES:
        turned = data.with_rest_model(data.settings.rest_friction, distance)
        sums = TorqueSums.for_data(turned, base.n_base)
        for index, y, tau, _ in base_chunks(robot, base, turned):
            scored = turned.scored(index)
            sums.add(turned.t[index[scored]], y[scored], tau[scored])
        beyond, slope = sums.beyond(nominal, friction)
        if follows(beyond):
            found.append(Hysteresis(distance, beyond, slope, *sums.beyond(nominal, drive)))
    return max(found, key=lambda h: float(np.nanmax(np.abs(h.beyond)))) if found else None


def hysteresis_explains(turned: np.ndarray, plain: np.ndarray, varies: np.ndarray) -> bool:
    """Whether Dahl's friction explains :data:`EXPLAINED` of what friction that turns at once leaves unexplained, on a
    joint that varies.

    Parameters
    ----------
    turned, plain : (n_dof,) arrays
        Each joint's correlation with the nominal model beyond Dahl's friction and beyond friction that turns at once
        (NaN where unknown).
    varies : (n_dof,) bool array
        The joints judged.

    Returns
    -------
    bool
    """
    turned, plain = np.asarray(turned, dtype=float), np.asarray(plain, dtype=float)
    left = 1.0 - np.where(np.isfinite(plain), plain, 0.0) ** 2
    with np.errstate(invalid="ignore", divide="ignore"):
        share = 1.0 - (1.0 - turned**2) / np.maximum(left, 1e-12)
    return bool(np.any(np.asarray(varies, dtype=bool) & np.isfinite(share) & (share >= EXPLAINED)))


def hysteresis_finding(found: Hysteresis, plain: np.ndarray, varies: np.ndarray, dataset: str) -> Finding:
    """The verdict's line where the torques follow the description only beyond a geared drive's hysteresis.

    Parameters
    ----------
    found : Hysteresis
        From :func:`beyond_hysteresis`.
    plain : (n_dof,) array
        The correlations beyond friction that turns at once (Coulomb's ``sign(q̇)``).
    varies : (n_dof,) bool array
        Joints whose measured torque varies beyond its noise (the joints judged).
    dataset : str

    Returns
    -------
    Finding
        Of kind "friction", naming the distance, the joint that follows best with it and without it.
    """
    judged = [j for j in range(found.beyond.size) if varies[j] and np.isfinite(found.beyond[j])]
    best = max(judged, key=lambda j: abs(found.beyond[j]))
    before = max((abs(plain[j]) for j in judged if np.isfinite(plain[j])), default=float("nan"))
    return Finding("friction", f"{dataset}: the measured torques follow the description's nominal model only with dry "
                               f"friction that turns over {1000 * found.presliding:g} mrad after each reversal (Dahl's "
                               f"presliding distance: J{best + 1} correlates {abs(found.beyond[best]):.2f} with it beyond "
                               f"friction, the joints {before:.2f} at most with friction that turns at once): a geared "
                               "drive's hysteresis, not torque columns read wrongly; [preprocessing] presliding = "
                               f"{found.presliding:g} models it in the fit (check it on a validation log)")


HYSTERESIS_SCAN = (0.0005, 0.001, 0.002, 0.004, 0.008, 0.016)
"""Presliding distances [rad] the delay check scans, a factor 2 apart, before it refines the best between its
neighbours (:func:`delay_beyond_hysteresis`)."""


def delay_beyond_hysteresis(robot: Robot, base: BaseParameters, data: PreparedData,
                            found: DelayEstimate) -> tuple[float, float] | None:
    """The presliding distance whose Dahl columns, with the torques read as given, predict held-out blocks of the log
    at least as well as the lag ``found`` does with friction that turns at once (module docstring).

    Each friction model is scored by the held-out squared residual (:func:`dynid.identification.delay.held_out_sum`,
    :attr:`DelayEstimate.held_out_sums`) on the same kept rows and torques. The distance minimises it over
    :data:`HYSTERESIS_SCAN`, refined between the best one's neighbours (Brent's method on its logarithm). Only a lag
    is weighed: the friction that turns after a reversal makes the torques look late, never early.

    Parameters
    ----------
    robot : Robot
    base : BaseParameters
    data : PreparedData
        The identification log as prepared (the ``"parallel"`` strategy, as the delay check needs).
    found : DelayEstimate
        The delay found with the log's own friction columns.

    Returns
    -------
    tuple of (float [rad], float) or None
        The distance and its held-out squared residual over that with friction that turns at once and no delay (the
        denominator of :attr:`DelayEstimate.held_out`); None where the lag predicts better, the delay found is a lead,
        or the log already has a presliding distance.
    """
    from scipy.optimize import minimize_scalar

    if found.samples <= 0 or np.any(np.asarray(data.settings.presliding, dtype=float) != 0):
        return None

    def score(log_distance: float) -> float:
        turned = data.with_rest_model(data.settings.rest_friction, float(np.exp(log_distance)))
        try:
            return held_out_sum(turned, base_chunks(robot, base, turned))
        except DynIdError:
            return float("inf")

    scan = np.log(HYSTERESIS_SCAN)
    values = np.array([score(x) for x in scan])
    k = int(np.argmin(values))
    lo, hi = scan[max(k - 1, 0)], scan[min(k + 1, scan.size - 1)]
    best = minimize_scalar(score, bounds=(lo, hi), method="bounded", options={"xatol": 0.05})
    distance, total = (float(np.exp(best.x)), float(best.fun)) if best.fun < values[k] else (HYSTERESIS_SCAN[k], values[k])
    return (distance, total / found.held_out_sums[0]) if total <= found.held_out_sums[1] else None


def hysteresis_delay_finding(delay: Finding, distance: float, ratio: float) -> Finding:
    """The delay finding where Dahl's columns without a delay predict the log as well as the lag
    (:func:`delay_beyond_hysteresis`): the log cannot tell a late torque channel from a geared drive's hysteresis.

    Parameters
    ----------
    delay : Finding
        The delay finding (:func:`dynid.validation.diagnostics.delay_findings`).
    distance : float [rad]
        The presliding distance.
    ratio : float
        Its held-out squared residual over that with friction that turns at once and no delay.

    Returns
    -------
    Finding
        Of kind "delay", ending with the same advice (the validation logs' answer replaces it), both settings named.
    """
    head, advice = delay.text.split(": if the drive logs them so, ", 1)
    gain = 100 * (1 - ratio)
    return Finding("delay", f"{head}; but with dry friction that turns over {1000 * distance:.2g} mrad after each "
                            f"reversal (Dahl's presliding distance, a geared drive's hysteresis) and no delay it is "
                            f"{gain:.2g} % smaller, so this log cannot tell a late torque channel from "
                            f"that hysteresis{HYSTERESIS_ADVICE}{distance:.2g} (radians) or, if the drive "
                            f"logs them so, {advice}")


HYSTERESIS_ADVICE = ": try [preprocessing] presliding = "
"""Where :func:`hysteresis_delay_finding`'s advice starts, which :func:`hysteresis_weighed` replaces with the validation
logs' answer."""


def hysteresis_weighed(text: str, figures: dict, delay_seconds: float, distance: float) -> str | None:
    """:func:`hysteresis_delay_finding`'s text with the validation logs' answer: the log identified again with the
    presliding distance and, apart, with the delay (:meth:`dynid.identification.pipeline.IdentificationPipeline.fit`).

    Parameters
    ----------
    text : str
        The finding's text.
    figures : dict
        ``without``, ``with`` and ``main_with`` (the delay), and ``presliding``: ``{"with", "main_with"}``; the main
        estimate's mean error over the validation logs on the one yardstick [%] and its name.
    delay_seconds : float [s]
        The ``torque_delay`` the finding names.
    distance : float [rad]
        The presliding distance it names.

    Returns
    -------
    str or None
        The setting the validation logs agree with (the better where both: better than without by more than
        :data:`~dynid.identification.verdict.SAME_FIGURE`), the other's figure beside it; None where they agree with
        neither (the finding is withdrawn).
    """
    without, pre = figures["without"], figures["presliding"]
    agreed = [(figures["with"], figures["main_with"], f"torque_delay = {delay_seconds:.4g} (seconds)", "the delay"),
              (pre["with"], pre["main_with"], f"presliding = {distance:.2g} (radians)", "the presliding distance")]
    agreed.sort(key=lambda a: a[0])
    if not agreed[0][0] * SAME_FIGURE < without:
        return None
    (best, main, setting, what), (other, _, other_setting, _) = agreed
    head = text.split(HYSTERESIS_ADVICE, 1)[0]
    return (f"{head}: identified again with [preprocessing] {setting}, the validation logs agree (the main estimate "
            f"so, {main}, predicts them {best:.3g} % against {without:.3g} %, on one yardstick; with {other_setting} "
            f"instead, {other:.3g} %): keep {what}")

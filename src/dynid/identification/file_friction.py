"""The friction the written URDF and MJCF hold (issue "Every assurance checked on what the user meets", item 3).

A URDF's ``<dynamics friction damping>`` and an MJCF's ``frictionloss`` and ``damping`` hold a constant Coulomb and a
viscous coefficient per joint; dynid's model may also hold Stribeck friction (``fst``) and load-dependent Coulomb friction
(``fcl``), which no format holds. Written as they are, the files leave those terms out: on the real UR10e's validation
log that is 3.4 % of the torque (8.4 % against 5.0 % for dynid's whole model). Folded into the two coefficients the
formats hold (the nearest Coulomb and viscous pair, by non-negative least squares, to the joint's whole friction on the
identification log's motion), the files come closer on that log; but a load-dependent term's nearest constant depends
on the load the motion carries, and on the LBR Med7's faster validation run it would make joint 3's torque worse.
So the fold is a candidate, not a rule: each joint's pair is written folded only where the validation logs that move
say it predicts that joint better than the pair as identified (both scored as the identification prepared the logs);
without validation logs the files hold the pair as identified. The figures: the changelog, benchmarks/README.md.
"""

from __future__ import annotations

import numpy as np

__all__ = ["FOLDED_TERMS", "FILE_AS_IDENTIFIED", "FILE_FOLDED", "file_candidates", "file_friction", "folded_parameters"]

FOLDED_TERMS = ("fst", "fcl")
"""dynid's friction terms no URDF or MJCF holds, folded into the Coulomb and viscous pair they do."""

FILE_AS_IDENTIFIED = "the files' friction as identified"
FILE_FOLDED = "the files' friction folded"

LARGEST_SAMPLES = 20_000
"""The identification log's samples the fold is fitted on, evenly spread (every sample of a shorter log)."""


def _index(robot, term: str, j: int) -> int | None:
    names = robot.parameter_names
    name = f"{term}{j + 1}"
    return names.index(name) if name in names else None


def folded_parameters(robot, phi: np.ndarray, q, dq, ddq) -> np.ndarray | None:
    """``phi`` with each joint's Stribeck and load-dependent Coulomb friction folded into its Coulomb and viscous terms.

    Per joint, the pair ``(fc', fv') ≥ 0`` nearest (least squares) to the joint's whole friction torque on the states:
    ``fc·… + fv·q̇ + fst·… + fcl·…`` against ``fc'·sign(q̇) + fv'·q̇`` (the Coulomb term as the formats hold it);
    ``fst`` and ``fcl`` are then 0. Only moving samples weigh: a joint at rest has ``sign(0) = 0`` either way.

    Parameters
    ----------
    robot : Robot
        The model ``phi`` is of.
    phi : (n_params,) array
        Standard parameters.
    q, dq, ddq : (N, n_dof) arrays [rad, rad/s, rad/s²]
        The states the fold is fitted on (the identification log's).

    Returns
    -------
    (n_params,) ndarray or None
        None where nothing is to fold (no ``fst`` or ``fcl`` term, or no ``fc`` and ``fv`` to hold it).
    """
    from scipy.optimize import nnls  # SciPy's optimisers and the regressor's kernels load only where a fold is fitted

    from ..dynamics.regressor import regressor

    phi = np.asarray(phi, dtype=float)
    folded_terms = [t for t in FOLDED_TERMS if t in robot.drive_terms]
    if not {"fc", "fv"} <= set(robot.drive_terms) or not folded_terms:
        return None
    friction = np.array([n.rstrip("0123456789") in ("fc", "fv", *folded_terms) and n not in robot.transmission.coupled_parameter_names
                         for n in robot.parameter_names])
    whole = regressor(robot, q, dq, ddq) @ np.where(friction, phi, 0.0)
    out = phi.copy()
    for j in range(robot.n_dof):
        fc, fv = _index(robot, "fc", j), _index(robot, "fv", j)
        assert fc is not None and fv is not None
        columns = np.stack([np.sign(dq[:, j]), dq[:, j]], axis=1)
        out[[fc, fv]] = nnls(columns, whole[:, j])[0]
        for term in folded_terms:
            k = _index(robot, term, j)
            if k is not None:
                out[k] = 0.0
    return out


def file_candidates(robot, base, phi: np.ndarray, data) -> dict:
    """The physically consistent estimate as the files would hold its friction, both ways, as base parameter sets to
    score on the validation logs: as identified (``fst`` and ``fcl`` left out) and folded (:func:`folded_parameters` on
    the identification log's states).

    Parameters
    ----------
    robot : Robot
        The prepared model (its parameter names are ``base.standard_names``).
    base : BaseParameters
    phi : (n_params,) array
        The physically consistent estimate's standard parameters.
    data : PreparedData
        The identification log as prepared.

    Returns
    -------
    dict
        ``{FILE_AS_IDENTIFIED: beta, FILE_FOLDED: beta}``, or empty where nothing is to fold; plus the folded standard
        set under ``"standard"``.
    """
    n = len(data.t)
    step = max(1, n // LARGEST_SAMPLES)
    q, dq, ddq = (np.asarray(x[::step], dtype=float) for x in (data.q, data.dq, data.ddq))
    folded = folded_parameters(robot, phi, q, dq, ddq)
    if folded is None:
        return {}
    dropped = np.array([n.rstrip("0123456789") in FOLDED_TERMS for n in robot.parameter_names])
    return {FILE_AS_IDENTIFIED: base.base_from_standard(np.where(dropped, 0.0, phi)),
            FILE_FOLDED: base.base_from_standard(folded), "standard": folded}


def file_friction(robot, folded: np.ndarray, scored: tuple) -> dict:
    """Which joints the files hold folded: where the validation logs that move say the folded pair predicts the joint
    better (its mean relative error over the logs lower).

    Parameters
    ----------
    robot : Robot
        The prepared model.
    folded : (n_params,) array
        :func:`folded_parameters`.
    scored : tuple of TorqueComparison
        The validation logs that move, with :data:`FILE_AS_IDENTIFIED` and :data:`FILE_FOLDED` among their sets.

    Returns
    -------
    dict
        results.json's ``diagnostics["file_friction"]``: ``fc``, ``fv`` (the folded pair per joint [N·m, N·m·s/rad]),
        ``folded`` (bool per joint), ``error_as_identified`` and ``error_folded`` (each joint's mean relative error over
        the logs [%]), ``terms`` (what is folded), ``logs`` (their names).
    """
    now = np.mean([np.asarray(c.metrics()[FILE_AS_IDENTIFIED]["relative_error"], dtype=float) for c in scored], axis=0)
    fold = np.mean([np.asarray(c.metrics()[FILE_FOLDED]["relative_error"], dtype=float) for c in scored], axis=0)
    chosen = fold < now
    terms = [t for t in FOLDED_TERMS if t in robot.drive_terms]
    return {"fc": [float(folded[_index(robot, "fc", j)]) for j in range(robot.n_dof)],
            "fv": [float(folded[_index(robot, "fv", j)]) for j in range(robot.n_dof)],
            "folded": [bool(x) for x in chosen], "error_as_identified": [float(x) for x in now],
            "error_folded": [float(x) for x in fold], "terms": terms, "logs": [c.name for c in scored]}

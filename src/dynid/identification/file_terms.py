"""What the written URDF and MJCF hold of dynid's drive terms (issue "Every assurance checked on what the user meets",
item 3): friction the formats cannot hold folded into what they can, and the MJCF's torque offsets, each joint's
choice made by the validation logs.

A URDF's ``<dynamics friction damping>`` and an MJCF's ``frictionloss`` and ``damping`` hold a constant Coulomb and a
viscous coefficient per joint; dynid's model may also hold Stribeck friction (``fst``) and load-dependent Coulomb friction
(``fcl``), which no format holds, and a torque offset, which an MJCF can hold as an actuator's constant bias
(:func:`dynid.model.description_files.offset_actuators`) and a URDF cannot. Written as identified, the files leave those terms out.
Folded into the two coefficients the formats hold (the nearest Coulomb and viscous pair, by non-negative least
squares, to the joint's whole friction on the identification log's motion) and with the offsets held, the files come
closer to the measured torques on some logs; but a load-dependent term's nearest constant depends on the load the
motion carries, and a torque offset does not predict every log better. So each is a candidate, not a rule:
each estimate the files may be written from (the physically consistent one, the drive-only candidate) is scored on the
validation logs that move as the files would hold it, friction as identified or folded, offset left out or held (four
sets each, scored as the identification prepared the logs), and each joint is written as the set that predicts it best (the first, as identified without the offset, on a tie). Without validation
logs the files hold the terms as identified and no offset. The figures: the changelog, benchmarks/README.md and
NOTEBOOK.md.
"""

from __future__ import annotations

import itertools

import numpy as np

from .._util.ties import first_least

__all__ = ["FOLDED_TERMS", "file_candidates", "file_terms", "folded_parameters", "variant_label"]

FOLDED_TERMS = ("fst", "fcl")
"""dynid's friction terms no URDF or MJCF holds, folded into the Coulomb and viscous pair they do."""

LARGEST_SAMPLES = 20_000
"""The identification log's samples the fold is fitted on, evenly spread (every sample of a shorter log)."""


def variant_label(folded: bool, offset: bool, estimate: str = "") -> str:
    """The label of an estimate as the files would hold it (scored beside the candidates, never kept).

    Parameters
    ----------
    folded : bool
        Its Stribeck and load-dependent Coulomb friction folded into the Coulomb and viscous pair.
    offset : bool
        Its torque offsets held.
    estimate : str
        The estimate's label (each estimate the files may be written from has its own variants).

    Returns
    -------
    str
    """
    said = f"the files' terms: friction {'folded' if folded else 'as identified'}, offset {'held' if offset else 'left out'}"
    return f"{estimate}: {said}" if estimate else said


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


def file_candidates(robot, base, phi: np.ndarray, data, estimate: str = "") -> tuple[dict, np.ndarray | None]:
    """An estimate the files may be written from, as they would hold it, every way (module docstring), as base
    parameter sets to score on the validation logs.

    Parameters
    ----------
    robot : Robot
        The prepared model (its parameter names are ``base.standard_names``).
    base : BaseParameters
    phi : (n_params,) array
        The physically consistent estimate's standard parameters.
    data : PreparedData
        The identification log as prepared.
    estimate : str
        Its label (:func:`variant_label`).

    Returns
    -------
    sets : dict
        ``{variant_label(folded, offset, estimate): beta}``, empty where there is no choice (no Stribeck, load-dependent
        Coulomb or offset term).
    folded : (n_params,) ndarray or None
        :func:`folded_parameters` on the identification log's states, None where nothing is folded.
    """
    n = len(data.t)
    step = max(1, n // LARGEST_SAMPLES)
    q, dq, ddq = (np.asarray(x[::step], dtype=float) for x in (data.q, data.dq, data.ddq))
    folded = folded_parameters(robot, phi, q, dq, ddq)
    stems = np.array([n.rstrip("0123456789") for n in robot.parameter_names])
    offsets = stems == "offset"
    if folded is None and not np.any(phi[offsets]):
        return {}, None
    sets = {}
    for fold, offset in itertools.product((False, True) if folded is not None else (False,),
                                          (False, True) if np.any(phi[offsets]) else (False,)):
        values = np.where(np.isin(stems, FOLDED_TERMS), 0.0, folded if fold and folded is not None else phi)
        sets[variant_label(fold, offset, estimate)] = base.base_from_standard(np.where(offsets & (not offset), 0.0, values))
    return sets, folded


def file_terms(robot, folded: np.ndarray | None, labels, scored: tuple) -> dict:
    """Each joint written as the variant the validation logs that move say predicts it best (its mean relative error
    over the logs; the first variant, as identified without the offset, on a tie).

    Parameters
    ----------
    robot : Robot
        The prepared model.
    folded : (n_params,) array or None
        :func:`folded_parameters`.
    labels : sequence of str
        The variants scored (:func:`file_candidates`' keys, the first as identified without the offset).
    scored : tuple of TorqueComparison
        The validation logs that move, with the variants among their sets.

    Returns
    -------
    dict
        An estimate's entry in results.json's ``diagnostics["file_terms"]``: ``folded`` and ``offset`` (per joint: friction folded, torque
        offset held in the MJCF), ``fc``, ``fv`` (the folded pair per joint [N·m, N·m·s/rad]; with a fold only),
        ``errors`` (each variant's mean relative error per joint over the logs [%]), ``terms`` (what is folded),
        ``logs`` (their names).
    """
    labels = list(labels)
    errors = np.array([np.mean([np.asarray(c.metrics()[k]["relative_error"], dtype=float) for c in scored], axis=0)
                       for k in labels])
    best = first_least(errors, axis=0)  # the first of equals: as identified, offset left out
    out = {"folded": ["friction folded" in labels[b] for b in best],
           "offset": ["offset held" in labels[b] for b in best],
           "errors": {k: [float(x) for x in e] for k, e in zip(labels, errors)},
           "terms": [t for t in FOLDED_TERMS if t in robot.drive_terms], "logs": [c.name for c in scored]}
    if folded is not None:
        out["fc"] = [float(folded[_index(robot, "fc", j)]) for j in range(robot.n_dof)]
        out["fv"] = [float(folded[_index(robot, "fv", j)]) for j in range(robot.n_dof)]
    return out

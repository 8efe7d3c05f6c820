"""The evidence the verdict weighs (issue "One route, four named parts"): every candidate parameter set scored on the
validation logs, as the identification prepared them and on the one yardstick, the logs read otherwise than the
identification log, and the SDP's refits' spread on the validation states. The third of
:meth:`dynid.identification.pipeline.IdentificationPipeline.fit`'s parts: it scores, it does not choose
(:mod:`dynid.identification.verdict` does, once).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .._util.reprs import short_repr
from ..exceptions import DynIdError
from ..io.logs.datasets import Recording
from ..preprocessing.settings import Preprocessing
from ..preprocessing.strategies import YARDSTICK_FILTERS, carried_over, yardstick_filters, yardstick_settings
from ..validation.diagnostics import Finding
from ..validation.noise_floor import SMOOTH, looks_filtered
from .estimates import CONSISTENT_NOMINAL_LABEL, DRIVE_ONLY_LABEL, NOMINAL_LABEL, SDP_LABEL
from .file_terms import file_candidates, file_terms

__all__ = ["CONSISTENT_NOMINAL_LABEL", "NOMINAL_LABEL", "YARDSTICK", "Evidence", "filtered_finding", "gather_evidence", "moving_logs", "nominal_set",
           "state_evidence", "validate_sets", "weighed_means", "with_yardstick",
           "yardstick_reference", "yardstick_scores"]


@short_repr
@dataclass(frozen=True)
class Evidence:
    """What the validation logs say of the candidates (module docstring).

    Attributes
    ----------
    nominal : (str, (n_base,) array) or None
        The description's nominal model, scored beside the estimates (:func:`nominal_set`).
    scored : tuple of TorqueComparison
        Every candidate on each validation log as the identification prepared it (the drive-only one included).
    validations : tuple of TorqueComparison
        The same without the drive-only candidate: what results.json shows.
    filters : tuple of tuple of TorqueComparison
        Every candidate on the one yardstick (:func:`yardstick_scores`) under each state filter of
        :data:`dynid.preprocessing.strategies.YARDSTICK_FILTERS` (the first: the default rules' cutoffs), the SDP's
        refits left out: the verdict weighs their mean.
    best : tuple of str
        The candidate (estimate, the description's nominal model, the drive-only estimate) with the lowest mean error
        under each filter, over the logs read as the identification log: where they differ, the ranking depends on the
        filter, and the verdict says so.
    states : dict or None
        With ``choice = "states"``: the SDP's refits' spread on the validation states
        (:func:`state_evidence`).
    warnings : tuple of str
        The logs' own and those of a log read otherwise.
    file_terms : dict or None
        Per estimate the files may be written from, how they hold each joint's drive terms: friction folded or not, the
        MJCF's torque offset held or not (:func:`dynid.identification.file_terms.file_terms`); None where there is no
        choice or no validation log moves.
    """

    nominal: tuple | None
    scored: tuple
    validations: tuple
    filters: tuple
    best: tuple[str, ...]
    states: dict | None
    warnings: tuple[str, ...]
    file_terms: dict | None = None


def gather_evidence(pipeline, prepared, result, validation: tuple, *, reference: Preprocessing | None = None,
                    progress=None, file_variants: bool = True) -> Evidence:
    """Score the identification's candidates on the validation logs (module docstring).

    Parameters
    ----------
    pipeline : IdentificationPipeline
        Its preprocessing as given, ``choice`` and ``torque_sensor``.
    prepared : PreparedIdentification
        The identification log as prepared: the model identified, its base map and resolved settings.
    result : IdentificationResult
        The estimates (:meth:`dynid.identification.pipeline.IdentificationPipeline.estimate`).
    validation : tuple of Recording
        The validation logs, read.
    reference : Preprocessing, optional
        The identification log's settings by dynid's default rules (:func:`yardstick_reference`).
    progress : callable, optional
        ``progress(step, done, total)``.
    file_variants : bool
        Score the estimates as the written files would hold them (:mod:`dynid.identification.file_terms`).

    Returns
    -------
    Evidence
    """
    setup = replace(pipeline, robot=prepared.robot)
    robot, base = prepared.robot, prepared.base
    sets = result.parameter_sets()
    nominal = nominal_set(robot, base, result.references)
    if nominal is not None and nominal[0] not in sets:  # scored beside, for the gate against the nominal model
        sets[nominal[0]] = nominal[1]
    alt = result.drive_only if nominal is not None else None
    if alt is not None:  # a candidate scored in the same pass, kept only where the verdict chooses it
        sets[DRIVE_ONLY_LABEL] = alt.params
    standards = {k: e.standard for k, e in result.estimates.items() if e.standard is not None}
    if alt is not None and alt.standard is not None:
        standards[DRIVE_ONLY_LABEL] = alt.standard
    variants = {k: file_candidates(robot, base, phi, prepared.data, estimate=k) for k, phi in standards.items()} if file_variants else {}
    files = {label: beta for found, _ in variants.values() for label, beta in found.items()}
    scored, warnings = validate_sets(setup, base, sets, validation, progress=progress, resolved=prepared.data.settings,
                                     noise=result.joint_std, covariance={result.label: result.solution.covariance},
                                     fitted=(result.label, result.fit.metrics()[result.label]["correlation"]),
                                     geometry=not any(f.kind in ("angles", "gravity") for f in result.findings),
                                     nominal=None if nominal is None else nominal[0], beside=files)
    file_choice = None
    if files:  # scored beside, for what the files hold alone (dynid.identification.file_terms)
        from ..validation.torques import rests_throughout

        moving = tuple(v for v in scored if not v.misread and not rests_throughout(v.rest_share)
                       and all(k in v.metrics() for k in files))
        file_choice = {k: file_terms(robot, folded, list(found), moving) for k, (found, folded) in variants.items()
                       if found} if moving else None
        scored = tuple(v.without(*files) for v in scored)
    validations = scored if alt is None else tuple(v.without(DRIVE_ONLY_LABEL) for v in scored)
    refits = {f"{SDP_LABEL} refit {k + 1}": beta for k, beta in enumerate(result.sdp_refits)} if nominal else {}
    filters = yardstick_scores(setup, base, {**sets, **refits}, validation, resolved=prepared.data.settings,
                               reference=reference, progress=progress)
    yardstick = filters[0]
    misread = {v.name for v in scored if v.misread}  # the verdict weighs no log read otherwise
    candidates = [k for k in sets if k in result.estimates or k in (DRIVE_ONLY_LABEL, None if nominal is None else nominal[0])]
    best = tuple(_best(tuple(v for v in one if v.name not in misread), candidates) for one in filters)
    states = None
    if refits:  # [estimation] choice = "states": the verdict reads the validation logs' states, not their torques
        assert nominal is not None
        fallback = DRIVE_ONLY_LABEL if alt is not None and pipeline.torque_sensor != "joint" else nominal[0]
        trusted = tuple(v for v in yardstick if v.name not in misread)
        states = state_evidence(trusted, SDP_LABEL, fallback, tuple(refits), nominal[0]) if trusted else None
        filters = tuple(tuple(v.without(*refits) for v in one) for one in filters)
    return Evidence(nominal, scored, validations, filters, best, states, tuple(warnings), file_choice)


def _best(comparisons: tuple, candidates: list) -> str:
    """The candidate with the lowest mean global error over ``comparisons`` ("" where there is none)."""
    if not comparisons or not candidates:
        return ""
    moving = moving_logs(comparisons)
    return min(candidates, key=lambda k: float(np.mean([v.metrics()[k]["global_relative_error"] for v in moving])))


def validate_sets(setup, base, parameter_sets: dict, recordings, *,
                  progress=None, resolved: Preprocessing | None = None, noise=None, covariance=None,
                  fitted: tuple[str, np.ndarray] | None = None,
                  geometry: bool = True, nominal: str | None = None, beside: dict | None = None) -> tuple[tuple, tuple[str, ...]]:
    """Score parameter sets on logs: their predicted torques against the measured ones.

    Parameters
    ----------
    setup : IdentificationConfig or IdentificationPipeline
        Its ``robot`` (as identified: friction terms, Coulomb smoothing) and ``preprocessing`` (as given).
    base : BaseParameters
    parameter_sets : dict
        label -> (n_base,) base parameters.
    recordings : iterable of Recording
        The logs, read (:func:`dynid.io.logs.datasets.load_recording`); a generator's are read one at a time, as each is
        scored.
    progress : callable, optional
        ``progress(step, done, total)``.
    resolved : Preprocessing, optional
        The identification's resolved preprocessing, carried over to these logs.
    noise : (n_dof,) array [N·m], optional
        Each joint's residual σ (for the prediction bands).
    covariance : dict, optional
        label -> covariance of that set.
    fitted : (str, (n_dof,) array), optional
        The estimate fitted to the identification log and its correlation with each joint's torque there: a log
        whose torque channels run against it, swapped or scaled is said (:mod:`dynid.validation.channel_checks`).
    geometry : bool
        Check each log's geometry against the robot file's: not where the identification log's does not match it
        either (its finding's setting is for every dataset, and the logs agree with each other).
    nominal : str, optional
        The description's nominal model among ``parameter_sets``: a log's scale is judged against it too.
    beside : dict, optional
        More sets, scored on the logs that move only (every joint at rest in less than
        :data:`~dynid.validation.torques.AT_REST_SHARE` of the prepared samples; the written files' variants,
        :mod:`dynid.identification.file_terms`).

    Returns
    -------
    comparisons : tuple of TorqueComparison
        A log read otherwise than the identification log has its ``misread`` set.
    warnings : tuple of str
        Besides the logs' own, a log read otherwise: its torque channels flipped or swapped against the fitted estimate
        (``fitted``), or its geometry not the robot file's (:mod:`dynid.validation.geometry_checks`: a joint's zero,
        two columns swapped, gravity).

    Raises
    ------
    DataError
        A log that cannot be prepared.
    TypeError
        A log not read (a ``DatasetSpec``: :func:`dynid.io.logs.datasets.load_recording` reads it).
    """
    from ..preprocessing.preparation import prepare
    from ..validation.channel_checks import channel_findings
    from ..validation.geometry_checks import geometry_findings
    from ..validation.torques import compare_torques, rests_throughout

    out: list = []
    warnings: list[str] = []
    settings = carried_over(resolved, setup.preprocessing)
    for recording in recordings:
        if not isinstance(recording, Recording):
            raise TypeError(f"validate_sets: expected read logs (dynid.load_recording(spec, robot)), got {type(recording).__name__}")
        if progress is not None:  # one step per log: filtering and predicting it
            progress(f"validation, {recording.name}", 0, 1)
        data = prepare(recording, settings, strict=False)
        resting = None if data.resting is None else np.mean(np.asarray(data.resting, dtype=float).reshape(len(data.t), -1), axis=0)
        sets = parameter_sets if not beside or rests_throughout(resting) else {**parameter_sets, **beside}
        scored = compare_torques(setup.robot, base, data, sets,
                                 progress=None if progress is None else (lambda d, t, s=recording.name: progress(f"validation, {s}", d, t)),
                                 noise=noise, covariance=covariance)
        # a log recorded otherwise than the fitted one: its torque channels, else its geometry
        found = [] if fitted is None else channel_findings(scored, *fitted, nominal=nominal)
        if not found and geometry and np.any(setup.robot.inertial != 0):
            found, _ = geometry_findings(setup.robot, data.q, data.dq, data.ddq, data.tau, recording.name, fitted=False)
        warnings.extend(f.text for f in found)
        out.append(replace(scored, misread=found[0].text) if found else scored)
        warnings.extend(data.warnings)
    return tuple(out), tuple(warnings)


def filtered_finding(names: list, recordings: list) -> tuple:
    """A finding naming the logs whose torques carry no measurable sample-to-sample noise
    (:func:`dynid.validation.noise_floor.looks_filtered`: filtered before dynid read them, or simulated without
    noise): their noise floor is unknown, and a fit near zero error there says little (issue "Never worse than the
    description", item 5).

    Parameters
    ----------
    names : list of str
    recordings : list of Recording
        As read, raw.

    Returns
    -------
    tuple of Finding
        Empty where every log carries noise.
    """
    smooth = [name for name, rec in zip(names, recordings) if looks_filtered(rec.tau)]
    if not smooth:
        return ()
    return (Finding("filtered", f"{', '.join(smooth)}: the torques carry no measurable sample-to-sample noise (below "
                                f"{SMOOTH:g} % of their RMS on the median joint; raw sensor logs show 2-4 %): they were "
                                "low-pass filtered before dynid read them, or simulated without noise. Their noise floor "
                                "is unknown, the errors measure the fit to an already smoothed torque, and the rest "
                                "thresholds read from the same logs may be too low: log the raw torques (and positions) "
                                "if the controller can, or give [preprocessing] rest_velocity for a joint that creeps"),)


YARDSTICK = ("each validation log's torques as measured (no filter), its states filtered by dynid's default rules "
             "carried over from the identification log, whatever the identification's settings; the candidates ranked "
             "with the states filtered at half and twice those cutoffs too")
"""What the one yardstick is, as results.json and the terminal say it (:func:`with_yardstick`)."""


def yardstick_reference(recording) -> Preprocessing | None:
    """The identification log's settings resolved by dynid's default rules: what the one yardstick carries over to the
    validation logs (:func:`dynid.preprocessing.strategies.yardstick_settings`).

    Parameters
    ----------
    recording : dynid.io.logs.datasets.Recording
        The identification log, as read.

    Returns
    -------
    Preprocessing or None
        None where the default rules cannot prepare the log (the validation logs then take them alone).
    """
    from ..preprocessing.preparation import prepare

    try:
        return prepare(recording, Preprocessing(), strict=False).settings
    except DynIdError:
        return None


def yardstick_scores(setup, base, sets: dict, recordings, *, resolved=None, reference=None,
                     progress=None) -> tuple[tuple, ...]:
    """Every set scored on the validation logs by the one yardstick (issues "Never worse than the description", item 5,
    and "The better model wins", item 1): each log's torques as measured, its states prepared by dynid's default
    rules whatever the identification's settings, under each state filter of
    :data:`dynid.preprocessing.strategies.YARDSTICK_FILTERS`
    (:func:`dynid.preprocessing.strategies.yardstick_filters`), on the same samples and rest threshold for every
    filter and set.

    Why it is fair: every set is scored on the same samples against the same measured torque, which no filter of
    the yardstick's touches, so the torque's noise adds the same to every set's squared error and no set gains by a
    filter that smooths the measured torque alongside its own predictions; the accelerations' noise, which a set with
    larger inertial terms turns into more predicted noise, is what the state filter sets, and a ranking that holds
    under half and twice the rule's cutoff does not hang on it.

    Parameters
    ----------
    setup : IdentificationConfig or IdentificationPipeline
        As identified (its robot's friction model) and its preprocessing as given.
    base : BaseParameters
    sets : dict
        label -> (n_base,) base parameters.
    recordings : iterable of Recording
        The validation logs, read.
    resolved : Preprocessing, optional
        The identification's resolved settings (only what describes the model is kept from them).
    reference : Preprocessing, optional
        The identification log's settings resolved by the default rules (:func:`yardstick_reference`).
    progress : callable, optional

    Returns
    -------
    tuple of tuple of TorqueComparison
        One tuple (a comparison per log) per state filter, in the order of
        :data:`~dynid.preprocessing.strategies.YARDSTICK_FILTERS`.
    """
    from ..preprocessing.preparation import prepare
    from ..validation.torques import compare_torques

    treated = yardstick_settings(resolved, setup.preprocessing, reference or Preprocessing())
    out: list[list] = [[] for _ in YARDSTICK_FILTERS]
    for recording in recordings:
        if progress is not None:
            progress(f"one yardstick: {recording.name}", 0, 1)
        rest = None
        for k, settings in enumerate(yardstick_filters(treated, recording)):
            data = prepare(recording, settings if rest is None else replace(settings, rest_velocity=rest), strict=False)
            rest = data.settings.rest_velocity  # the first filter's rest threshold for every filter: the same samples
            out[k].append(compare_torques(setup.robot, base, data, sets))
    return tuple(tuple(one) for one in out)


def with_yardstick(result, filters: tuple, best: tuple[str, ...] = ()):
    """``result`` with the sets' errors on the one yardstick in its diagnostics (``"yardstick"``: the global relative
    error [%] of each set on each log and their mean over the logs, with the states filtered by the default rules;
    ``"noise_floor"``: what a perfect model scores on the same samples, from the measured torques' own noise
    (:mod:`dynid.validation.noise_floor`), mean over the logs that move;
    ``"filters"``: each state filter's multiple of those cutoffs, the sets' mean errors under it and the best
    candidate), beside the figures on the identification's own settings.

    Parameters
    ----------
    result : IdentificationResult
    filters : tuple of tuple of TorqueComparison
        From :func:`yardstick_scores`.
    best : tuple of str
        :attr:`Evidence.best`.

    Returns
    -------
    IdentificationResult
        Where some logs rest throughout and others move, ``"mean_over_logs_that_move"`` gives the mean over those
        that move (``"logs"`` names them): a log at rest scores the distance to the static-friction band about its
        gravity torque (:func:`dynid.validation.torques.rests_throughout`), another unit than a motion's error, and
        ten of them at 0 would make the mean a tenth of the motion's.
    """
    from ..validation.torques import rests_throughout

    scored = filters[0] if filters else ()
    logs = {c.name: {label: float(m["global_relative_error"]) for label, m in c.metrics().items()} for c in scored}
    labels = [label for label in (scored[0].metrics() if scored else {})]

    def mean(names) -> dict:
        return {label: float(np.mean([logs[name][label] for name in names])) for label in labels}

    figures: dict = {"settings": YARDSTICK, "global_relative_error": logs, "mean_global_relative_error": mean(logs)}
    moving = [c.name for c in scored if not rests_throughout(c.rest_share)]
    if moving and len(moving) < len(scored):  # a log at rest throughout scores the distance to the static-friction band
        figures["mean_over_logs_that_move"] = {"logs": moving, **mean(moving)}
    floors = [(c.floor_metrics() or {}).get("global_relative_error", np.nan) for c in moving_logs(scored)]
    if floors and np.all(np.isfinite(floors)):  # what a perfect model scores on the same samples: the torques' noise
        figures["noise_floor"] = float(np.mean(floors))
    if len(filters) > 1:
        figures["filters"] = [{"cutoff_factor": f, "mean_global_relative_error": {
            label: float(np.mean([c.metrics()[label]["global_relative_error"] for c in moving_logs(one)])) for label in labels},
            **({"best": b} if b else {})} for f, one, b in zip(YARDSTICK_FILTERS, filters, best or ("",) * len(filters))]
    return replace(result, diagnostics={**result.diagnostics, "yardstick": figures})


def weighed_means(yardstick: dict) -> dict:
    """The one yardstick's mean error of each set over the logs that move, as the verdict weighs them (over every log
    where none rests throughout, or every one does), from results' ``diagnostics["yardstick"]``
    (:func:`with_yardstick`).

    Parameters
    ----------
    yardstick : dict

    Returns
    -------
    dict
        label -> mean global relative error [%] (``"logs"`` names the logs where some rest).
    """
    return yardstick.get("mean_over_logs_that_move") or yardstick["mean_global_relative_error"]


def moving_logs(comparisons: tuple) -> tuple:
    """The logs that move, where some rest throughout: those score the distance to the static-friction band about
    their gravity torque (:func:`dynid.validation.torques.rests_throughout`), another unit than a motion's error.

    Parameters
    ----------
    comparisons : tuple of TorqueComparison

    Returns
    -------
    tuple of TorqueComparison
        All of them where none moves.
    """
    from ..validation.torques import rests_throughout

    moving = tuple(c for c in comparisons if not rests_throughout(c.rest_share))
    return moving or comparisons


def state_evidence(comparisons, sdp: str, fallback: str, refits: tuple[str, ...], scale: str) -> dict:
    """What the validation logs' states alone say of the SDP against a fallback (``[estimation] choice = "states"``):
    the RMS difference of their predictions there, and the SDP's block-jackknife spread there (its refits on all blocks
    of the identification log but one: ``sqrt((K-1)/K · Σ_k mean((P_k - P̄)²))``, the delete-one-block jackknife's
    standard error; Efron & Tibshirani, *An Introduction to the Bootstrap*, 1993, §11), both in % of the ``scale``
    set's RMS prediction, averaged over the logs by their samples. At rest, each prediction without its Coulomb-like
    terms (what the one yardstick scores there is the distance to the static-friction band about it). No measured
    torque is read.

    Parameters
    ----------
    comparisons : sequence of TorqueComparison
        The validation logs with ``sdp``, ``fallback``, ``refits`` and ``scale`` among their sets.
    sdp, fallback : str
        The two candidates' labels.
    refits : tuple of str
        The SDP refits' labels.
    scale : str
        The set whose RMS prediction is 100 % (the description's nominal model).

    Returns
    -------
    dict
        ``apart`` and ``spread`` [%], ``fallback``.
    """
    apart, spread, weight = [], [], []
    for v in comparisons:
        def pred(label):
            centre = v.predicted[label] if v.centre is None else v.centre.get(label, v.predicted[label])
            return v.predicted[label] if v.resting is None else np.where(v.resting, centre, v.predicted[label])

        unit = 100.0 / max(float(np.sqrt(np.mean(pred(scale) ** 2))), 1e-12)
        parts = np.array([pred(r) for r in refits])
        k = len(refits)
        spread.append(unit * np.sqrt((k - 1) / k * np.sum(np.mean((parts - parts.mean(axis=0)) ** 2, axis=(1, 2)))))
        apart.append(unit * np.sqrt(np.mean((pred(sdp) - pred(fallback)) ** 2)))
        weight.append(v.predicted[sdp].size)
    return {"apart": float(np.average(apart, weights=weight)), "spread": float(np.average(spread, weights=weight)),
            "fallback": fallback}


def nominal_set(robot, base, references) -> tuple[str, np.ndarray] | None:
    """The description's nominal model as a base-parameter set: a reference set of the config that is it, else
    :data:`NOMINAL_LABEL`.

    Parameters
    ----------
    robot : Robot
    base : BaseParameters
    references : sequence of ReferenceSet

    Returns
    -------
    (str, (n_base,) ndarray) or None
        Its label and base parameters; None for a description without inertias. Where a link's nominal values are
        those of no mass distribution, the nearest physically consistent ones (:meth:`Robot.physical_prior`, said in
        its notes), labelled :data:`CONSISTENT_NOMINAL_LABEL` (issue "The better model wins", item 2).
    """
    if not np.any(robot.inertial != 0):
        return None
    phi, made = robot.physical_prior()
    beta = base.base_from_standard(phi)
    same = next((r.name for r in references if r.beta.shape == beta.shape and
                 np.allclose(r.beta, beta, rtol=1e-9, atol=1e-12)), None)
    return (same or (CONSISTENT_NOMINAL_LABEL if made else NOMINAL_LABEL)), beta

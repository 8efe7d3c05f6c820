"""The one verdict: which estimate is the main one, the description's nominal model among the candidates (issue "Never
worse than the description", item 1).

:func:`choose_main_estimate` is the only function that chooses, and :func:`decide` its one caller, the last part of
:meth:`dynid.identification.pipeline.IdentificationPipeline.fit`, once the evidence is gathered
(:mod:`dynid.identification.evidence`). The candidates, in the order they are weighed:

1. the first estimator listed;
2. the physically consistent SDP (where listed), where the first is least squares and is not physically consistent,
   and the SDP predicts the validation logs as well (to :data:`SAME_FIGURE`, mean global error) or better; without
   validation logs, wherever it passed its own consistency check (what ``dynid export`` writes), the held-out
   contiguous blocks of the identification log (:data:`dynid.identification.estimation_pass.HELD_OUT_FOLDS`-fold blocked
   cross-validation) said in its finding but not deciding: they kept least squares on five real logs and windows
   where it predicted the validation logs 5-30× worse;
3. the description's rigid body with the drive terms fitted (:mod:`dynid.identification.drive_only`), where the
   estimate so far is doubtful on the validation logs (the description's nominal model predicts them better, or least
   squares' predictions leave the range the identification log supports) and it predicts them better; or where least
   squares, not physically consistent, stays the main estimate against the SDP (so the SDP would be what ``dynid
   export`` writes) and the drive-only set is physically consistent, predicts them as well as least squares (to
   :data:`SAME_FIGURE`) and better than the SDP (benchmarks/README.md: what the written files hold, on the zoo);
4. the description's nominal model itself, where it predicts the validation logs better than every estimate: the
   main estimate is then the robot file's values, and the first finding says to keep them.

A validation log read otherwise than the identification log (``misread``: its torque channels flipped or swapped
against the fitted estimate, :mod:`dynid.validation.channel_checks`; its geometry not the robot file's,
:mod:`dynid.validation.geometry_checks`) is not weighed: the choice is made on the other logs, or on the
identification log alone (the SDP where least squares is not physically consistent: what ``dynid export`` writes).

The validation figures it weighs are the one yardstick's (:func:`dynid.identification.evidence.yardstick_scores`: every
validation log's torques as measured, its states filtered by dynid's default rules whatever the identification's
settings, the mean over three state filters: half, once and twice those cutoffs), so a setting that filters the
validation logs differently does not move the choice (issue "Never worse than the description", item 5), and a
ranking that changes with the state filter is said (issue "The better model wins", item 1). The
choice reads the validation logs' torques, and says so: where a candidate was chosen on them, their figures for it
are not an independent test. The alternatives measured and rejected are in benchmarks/NOTEBOOK.md.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..conventions import joints_unit
from ..estimators.registry import estimate_label
from ..validation.diagnostics import Finding, nominal_gate, validation_findings
from .estimates import (
    DRIVE_ONLY_KEY,
    DRIVE_ONLY_LABEL,
    HELD_OUT_FOLDS,
    NOMINAL_LABEL,
    SDP_LABEL,
    Estimate,
    consistency_checks,
)
from .evidence import moving_logs, with_yardstick
from .plausibility import drive_term_findings

__all__ = ["NOMINAL_KEY", "STATE_SIGMAS", "choose_main_estimate", "decide", "held_out_best"]

NOMINAL_KEY = "description"
"""The key of the description's nominal model's estimate when it is the main one."""

SAME_FIGURE = 1.02
"""Two mean validation errors within this ratio are the same figure for the choice: the physically consistent
estimate (what ``dynid export`` writes) stays the main one where an inconsistent least-squares estimate predicts no
better than this, so that the first line, the main estimate and the file exported name one estimate."""


STATE_SIGMAS = 3.0
"""With ``[estimation] choice = "states"``: the SDP is the main estimate where its predictions on the validation logs'
states differ from the fallback's by more than this many times their own spread over refits on parts of the log
(:func:`dynid.identification.evidence.state_evidence`). Measured on the 4 real logs and 18 real windows (``benchmarks/torque_free.py``): any value
from 2.3 to 3.7 keeps every main estimate within 2 % of the description or better; 3 is the usual 3σ. On simulated
short logs whose description's links are exact the SDP's refits share its bias, and ratios of 3.3-6.8 kept a wrong
SDP (benchmarks/NOTEBOOK.md): no threshold serves both, which is why this choice is an option, not the default."""


def decide(result, evidence=None):
    """The verdict of :meth:`dynid.identification.pipeline.IdentificationPipeline.fit`: the main estimate chosen once,
    on the evidence gathered (:func:`choose_main_estimate`), the one yardstick's figures added.

    Parameters
    ----------
    result : IdentificationResult
        The estimates, as :meth:`~dynid.identification.pipeline.IdentificationPipeline.estimate` gives them.
    evidence : Evidence, optional
        The validation logs' (:func:`dynid.identification.evidence.gather_evidence`); None without validation logs
        (the identification log's own held-out blocks are then the evidence).

    Returns
    -------
    IdentificationResult
    """
    if evidence is None:
        return choose_main_estimate(result)
    result = replace(result, validations=evidence.validations, warnings=result.warnings + evidence.warnings)
    if evidence.file_terms is not None:  # what the written files hold: results.json, for identify's and export's writers
        result = replace(result, diagnostics={**result.diagnostics, "file_terms": evidence.file_terms})
    # every log that moves (a log at rest throughout scores the distance to the static-friction band, another unit)
    # under every state filter: their mean
    judged = tuple(c for one in evidence.filters for c in moving_logs(one))
    chosen = choose_main_estimate(result, evidence.nominal, evidence.scored, judged, states=evidence.states)
    chosen = with_yardstick(chosen, evidence.filters, evidence.best)
    filters = chosen.diagnostics["yardstick"].get("filters", [])
    return replace(chosen, findings=tuple(chosen.findings) + _ranking_finding(filters, chosen.main))


def _ranking_finding(filters: list, main: str) -> tuple:
    """A finding where, with the validation logs' states filtered at another cutoff
    (:func:`dynid.identification.evidence.with_yardstick`'s ``"filters"``), another candidate predicts them better than
    the main estimate by more than :data:`SAME_FIGURE`: the choice rests on the mean over the filters, not on one, and
    the logs do not settle it (candidates within it of each other that rank differently are not said). Where one
    candidate beats the main estimate so under every filter, the logs agree and the main estimate stays by the
    verdict's rule: said so (the description's rigid body with the drive terms fitted is taken only where the
    identified rigid body is doubtful on the validation logs)."""
    beaten = [(f["cutoff_factor"], f["best"], f["mean_global_relative_error"]) for f in filters
              if f.get("best") and f["best"] != main and main in f["mean_global_relative_error"]
              and f["mean_global_relative_error"][main] > SAME_FIGURE * f["mean_global_relative_error"][f["best"]]]
    if not beaten:
        return ()
    said = "; ".join(f"at {k:g}× the cutoffs {b} {_apart(e[b], e[main])} for {main}" for k, b, e in beaten)
    better = {b for _, b, _ in beaten}
    if len(beaten) == len(filters) and len(better) == 1:  # one candidate better under every filter: the logs agree
        (best,) = better
        if best == DRIVE_ONLY_LABEL:
            why = (f"{best} is taken only where the identified rigid body is doubtful on the validation logs (the "
                   "description's nominal model predicts them better, or its predictions leave the range the "
                   "identification log supports), and it is not here")
        elif best == SDP_LABEL:
            why = f"it is physically consistent, and the verdict weighs {best} against it only where it is not"
        else:
            why = "the verdict's rules kept it (docs/real-logs.md, \"What happens to a log\")"
        return (Finding("yardstick", f"{best} predicts the validation logs better than {main} with their states "
                                     f"filtered at every cutoff ({said}): {main} stays the main estimate, as {why}"),)
    return (Finding("yardstick", f"the validation logs rank the candidates differently with their states filtered at "
                                 f"another cutoff ({said}): {main} was chosen on the mean over half, once and twice "
                                 "dynid's cutoffs, and the logs do not settle it; a longer or faster validation log, "
                                 "whose motion stands above the accelerations' noise, would"),)


def _mean_error(validations, label: str) -> float:
    """The mean over ``validations`` of ``label``'s global relative error [%]."""
    return float(np.mean([v.metrics()[label]["global_relative_error"] for v in validations]))


def choose_main_estimate(result, nominal: tuple[str, np.ndarray] | None = None, scored: tuple | None = None,
                         judged: tuple | None = None, states: dict | None = None):
    """The main estimate of an identification and, with validation logs, the verdict's findings on them (module
    docstring).

    Parameters
    ----------
    result : IdentificationResult
        Its estimates, fit, diagnostics (``held_out_rms_error``) and validations (scored without the drive-only set).
    nominal : (str, (n_base,) array), optional
        The description's nominal model: its label among the scored sets and its base parameters.
    scored : tuple of TorqueComparison, optional
        The validation logs with every set scored, the drive-only one (:attr:`IdentificationResult.drive_only`)
        included.
    judged : tuple of TorqueComparison, optional
        The same sets scored on the one yardstick (:func:`dynid.identification.evidence.yardstick_scores`): where given,
        the choice weighs these figures, so that it does not depend on how the identification's settings filter the
        validation logs; default ``scored`` (and ``result.validations``).
    states : dict, optional
        :func:`state_evidence`: where given (``[estimation] choice = "states"``), the choice reads no validation torque:
        the SDP where it stands :data:`STATE_SIGMAS` times its spread apart from the fallback, else the fallback.

    Returns
    -------
    IdentificationResult
        With ``main`` and ``findings`` set (and, with validation logs, ``diagnostics``), and the drive-only or nominal
        estimate among its estimates where it is the main one.
    """

    if any(v.misread for v in result.validations):
        return _without_misread(result, nominal, scored, judged, states)
    findings = [f for f in result.findings if f.kind not in ("main", "drive", "misread")]  # an earlier call's again
    ls, main = result.label, estimate_label(result.estimators[0])
    inconsistent = not str(result.consistency_verdicts.get(ls, "yes")).startswith("yes")
    rigid = main == ls and SDP_LABEL in result.estimates and inconsistent
    if not result.validations:
        main, text = _held_out_choice(result, main, inconsistent)
        if text:
            findings.insert(0, Finding("main", text))
        return replace(result, main=main, findings=tuple(findings + _drive_findings(result, main)))
    if states is not None and nominal is not None and scored is not None:
        result, chosen = _state_choice(result, nominal, scored, states)
    else:
        result, chosen = _torque_choice(result, main, rigid, nominal, scored, judged)
    main = main if chosen is None else chosen[0]
    if chosen is not None:
        findings = [Finding("main", chosen[1])]
    return _with_validation_findings(replace(result, main=main), findings, nominal)


def _without_misread(result, nominal, scored, judged, states):
    """:func:`choose_main_estimate` on the validation logs read as the identification log alone (on the identification
    log alone where none is), with a finding naming the others: a log recorded with other zeros, its columns in another
    order, another mounting or a torque channel flipped scores every estimate by that, not by how it predicts (a UR10e's
    validation log with J2 a quarter turn off took the choice from the SDP, 0.2 % on the log as recorded, to the
    description's links with the drive terms fitted, the one candidate that does not move its links: 108 % against
    108.2 % on the misread log)."""
    misread = [v for v in result.validations if v.misread]
    names = {v.name for v in misread}

    def kept(comparisons):
        return None if comparisons is None else tuple(v for v in comparisons if v.name not in names)

    trusted = kept(result.validations)
    diagnostics = {**result.diagnostics, "misread": sorted(names)}  # without validation logs, held_out_choice reads it
    chosen = choose_main_estimate(replace(result, validations=trusted, diagnostics=diagnostics), nominal, kept(scored),
                                  kept(judged), states if trusted else None)
    on = "the other validation logs" if trusted else "the identification log alone"
    if not trusted and chosen.main == SDP_LABEL != result.label:
        on += f": {SDP_LABEL}, physically consistent where {result.label} is not, and what dynid export writes"
    text = (f"the verdict leaves out {', '.join(sorted(names))}: read otherwise than the identification log (its "
            "angles, mounting, torque channels, units or rate: the warning says how), its figures score every estimate by that, "
            f"not by how it predicts; the main estimate is chosen on {on}: read the log as the warning says and "
            "identify again for a test on it")
    findings = list(chosen.findings)
    at = 1 if findings and findings[0].kind == "main" else 0
    return replace(chosen, validations=result.validations, findings=tuple(findings[:at] + [Finding("misread", text)]
                                                                           + findings[at:]))


def _held_out_choice(result, main: str, inconsistent: bool) -> tuple[str, str]:
    """Without validation logs (:func:`choose_main_estimate`'s candidate 2): the SDP where least squares is not
    physically consistent, and the finding that says what held-out blocks of the log showed of every candidate ("" where
    the first estimator listed stays): which predicted them best, over how much held-out time, and that this is weaker
    evidence than a validation log (issue "The better model wins", item 3).

    The blocks do not choose. Where least squares predicts them better, the physically consistent SDP is still the main
    estimate when it passed its own check: it is what ``dynid export`` writes, and blocks of one excitation do not tell
    which estimate extrapolates. Measured (benchmarks/NOTEBOOK.md, "without validation logs"): on the five real logs
    and windows where held-out blocks kept least squares, it predicted the validation logs 5-30× worse than the SDP
    (the KR 300's full log 55.4 % against 11.8 %, the Med7's 50-55 s 661 % against 22.4 %); choosing among the SDP,
    the drive-only estimate and the description's values on them made more of the 36 real windows worse than better
    (``benchmarks/short_windows.py --blocks``; the figures in benchmarks/NOTEBOOK.md)."""
    ls = result.label
    held = result.diagnostics.get("held_out_rms_error") or {}
    if result.diagnostics.get("misread") and SDP_LABEL not in held:  # every validation log left out: what export writes
        return _exported_instead(result, main), ""
    if not inconsistent or SDP_LABEL not in held:
        return main, ""
    sdp, own = held[SDP_LABEL], held[ls]
    if sdp <= SAME_FIGURE * own:
        text = f"main estimate: {SDP_LABEL}, physically consistent, where {ls} is not" + (
            "" if sdp < own else "; it is what dynid export writes")
    elif _exported_instead(result, main) == main:
        return main, ""  # another estimator listed first keeps its place, as with validation logs
    else:
        text = f"main estimate: {SDP_LABEL}, physically consistent, where {ls} is not; it is what dynid export writes"
    return SDP_LABEL, text + _held_out_words(held, result.diagnostics.get("held_out_block_seconds"), SDP_LABEL,
                                             joints_unit("N·m", result.fit.prismatic))


def _held_out_words(held: dict, seconds: float | None, main: str, unit: str) -> str:
    """The held-out blocks' figures of every candidate, best first, as :func:`_held_out_choice`'s finding says them."""
    ranked = sorted(held.items(), key=lambda kv: kv[1])
    names = {NOMINAL_LABEL: "the description's values"}
    best = held_out_best(held, main)
    length = f" of {seconds:.3g} s" if seconds else ""
    out = (f"; held out: {HELD_OUT_FOLDS} blocks{length} of this log, each predicted by a fit on the other "
           f"{HELD_OUT_FOLDS - 1} (weaker evidence than a validation log of another motion), "
           + (f"{main} predicted them as well as any, to {100 * (SAME_FIGURE - 1):g} %: " if best == main else
              f"{names.get(best, best)} predicted them best: ")
           + ", ".join(f"{names.get(k, k)} {v}" for (k, _), v in zip(ranked, _distinct_figures([v for _, v in ranked])))
           + f" {unit} RMS")
    if best != main:
        out += (f"; {main} is kept: blocks of one excitation do not tell which model predicts other motions (on 36 "
                "real windows, choosing on them handed on a worse model more often than a better one); a validation "
                "log ([[validation]]) would")
    return out


def held_out_best(held: dict, main: str) -> str:
    """The candidate that predicts the held-out blocks best (``held``: label -> RMS error), ``main`` where it does
    within :data:`SAME_FIGURE`.

    Parameters
    ----------
    held : dict
        ``diagnostics["held_out_rms_error"]``.
    main : str

    Returns
    -------
    str
    """
    best = min(held, key=lambda k: held[k])
    return main if main in held and held[main] <= SAME_FIGURE * held[best] else best


def _exported_instead(result, main: str) -> str:
    """The SDP where ``main`` is least squares, not physically consistent, and the SDP passed its own check (what
    ``dynid export`` writes); else ``main``."""
    verdicts = result.consistency_verdicts
    if (main == result.label and not str(verdicts.get(main, "yes")).startswith("yes")
            and str(verdicts.get(SDP_LABEL, "")).startswith("yes")):
        return SDP_LABEL
    return main


def _torque_choice(result, main: str, rigid: bool, nominal, scored, judged):
    """The verdict on the validation logs' torques (:func:`choose_main_estimate`'s candidates 2-4): ``result`` (with
    the drive-only or the nominal estimate among its estimates where chosen) and (label, finding), or None where the
    first estimator listed stays."""
    ls = result.label
    chosen: tuple[str, str] | None = None
    weighed = judged or result.validations
    avg = " on average, on one yardstick" if judged else " on average"  # the figures the choice weighed
    sdp, own = (_mean_error(weighed, SDP_LABEL), _mean_error(weighed, ls)) if rigid else (0, 0)
    if rigid and sdp <= SAME_FIGURE * own:  # what export writes, unless the log says it predicts worse
        main, chosen = SDP_LABEL, (SDP_LABEL, f"main estimate: {SDP_LABEL}, physically consistent, where {ls} is not "
                                              + (f"and predicts the validation logs worse ({_apart(sdp, own)}{avg})"
                                                 if sdp < own else f"and predicts the validation logs as well, to "
                                                 f"{100 * (SAME_FIGURE - 1):g} % ({_apart(sdp, own)}{avg}); it is "
                                                 "what dynid export writes"))
    if nominal is not None and scored is not None and result.drive_only is not None:
        preferred = _drive_only_preferred(result, main, nominal[0], scored, judged or scored, avg,
                                          consistent_instead=rigid and main == ls)
        if preferred is not None:
            result, chosen = preferred
            main = chosen[0]
    if nominal is not None and scored is not None:
        weighed = judged or scored
        described, own = _mean_error(weighed, nominal[0]), _mean_error(weighed, main)
        if described < own and all(described < _mean_error(weighed, k) for k in result.estimates):
            result = _with_nominal(result, nominal)
            chosen = (nominal[0], (
                f"main estimate: {nominal[0]}: keep your robot file's values, this log cannot improve them: the "
                f"description's nominal model predicts the validation logs better than every estimate "
                f"({_apart(described, own).replace(' against ', f' against {main} ')}{avg}); chosen on the "
                "validation logs, so their "
                "figures for it are not an independent test; what would improve it: a longer, richer excitation "
                "(dynid excite) over the motions the robot will make"))
    return result, chosen


def _state_choice(result, nominal: tuple[str, np.ndarray], scored: tuple, states: dict):
    """The torque-free verdict (``choose_main_estimate(states=...)``): ``result`` (with the chosen fallback among its
    estimates, the evidence in its diagnostics) and (label, finding): the SDP, or the fallback (the description's
    rigid body with the drive terms fitted on a motor-side log, the description itself on a joint torque sensor's)."""
    apart, spread, fallback = states["apart"], states["spread"], states["fallback"]
    ratio = apart / max(spread, 1e-12)
    how = (f"chosen on the validation logs' states alone (estimation.choice = \"states\"), so their figures are an "
           f"independent test: the SDP's predictions there differ from {fallback}'s by {apart:.3g} %, {ratio:.2g}× their "
           f"own spread over refits on parts of this log ({spread:.3g} %")
    if ratio > STATE_SIGMAS:
        main, text = SDP_LABEL, (f"main estimate: {SDP_LABEL}, {how}; over {STATE_SIGMAS:g}×: the links this log found "
                                 "are not the description's, beyond what it can tell)")
    elif fallback == DRIVE_ONLY_LABEL and result.drive_only is not None:
        alt = result.drive_only
        margins, verdicts = consistency_checks(result.model, result.base, {DRIVE_ONLY_LABEL: alt.params})
        result = replace(result, estimates={**result.estimates, DRIVE_ONLY_LABEL: Estimate(
            DRIVE_ONLY_KEY, alt.params, alt.std, standard=alt.standard)}, fit=alt.fit, validations=scored,
            consistency={**result.consistency, **margins}, consistency_verdicts={**result.consistency_verdicts, **verdicts})
        main, text = DRIVE_ONLY_LABEL, (f"main estimate: {DRIVE_ONLY_LABEL}, the description's rigid body with the drive "
                                        f"terms fitted to this log, {how}; within {STATE_SIGMAS:g}×: this log does not "
                                        f"tell its links from the description's there){_held_note(alt.held, alt.undetermined)}")
    else:
        result = _with_nominal(result, nominal)
        main, text = nominal[0], (f"main estimate: {nominal[0]}: keep your robot file's values, this log cannot improve "
                                  f"them: {how}; within {STATE_SIGMAS:g}×: this log does not tell the links from the "
                                  "description's there); what would improve them: a longer, richer excitation (dynid "
                                  "excite) over the motions the robot will make")
    evidence = {"apart_percent": apart, "spread_percent": spread, "ratio": ratio, "fallback": fallback,
                "threshold": STATE_SIGMAS}
    return replace(result, diagnostics={**result.diagnostics, "state_evidence": evidence}), (main, text)


def _with_nominal(result, nominal: tuple[str, np.ndarray]):
    """``result`` with the description's nominal model among its estimates, under the label its set is scored with:
    its standard values are the robot file's (made physically consistent where they are not), which export writes."""

    estimate = Estimate(NOMINAL_KEY, np.asarray(nominal[1], dtype=float), np.zeros_like(nominal[1]),
                        standard=result.model.physical_prior()[0])
    margins, verdicts = consistency_checks(result.model, result.base, {nominal[0]: estimate.params})
    return replace(result, estimates={**result.estimates, nominal[0]: estimate},
                   consistency={**result.consistency, **margins},
                   consistency_verdicts={**result.consistency_verdicts, **verdicts})


def _with_validation_findings(result, chosen: list, nominal: tuple[str, np.ndarray] | None):
    """The findings: the choice's first, the identification's, then least squares' on each validation log
    (extrapolation, an error far above the fit's) and the main estimate against the description's nominal model, joint
    by joint (:func:`dynid.validation.diagnostics.nominal_gate`)."""
    findings = [f for f in chosen if f.kind == "main"] + [f for f in result.findings
                                                          if f.kind not in ("main", "drive", "misread")]
    findings += _drive_findings(result, result.main) + _validation_findings(result)
    diagnostics = dict(result.diagnostics)
    if nominal is not None:
        gate, stats = nominal_gate(result.validations, result.main, nominal[0])
        findings += gate if result.main != nominal[0] else []  # the description against itself says nothing
        diagnostics.update({"nominal_set": nominal[0], "versus_nominal": stats})
    return replace(result, findings=tuple(findings), diagnostics=diagnostics)


def _drive_findings(result, main: str) -> list:
    """The main estimate's implausible drive terms (:func:`dynid.identification.plausibility.drive_term_findings`):
    its standard parameters where it has them, else its base parameters."""
    estimate = result.estimates.get(main)
    if estimate is None or getattr(estimate, "key", "") == NOMINAL_KEY:  # the robot file's own values: not fitted
        return []
    if estimate.standard is not None:
        return drive_term_findings(main, result.model.parameter_names, estimate.standard)
    return drive_term_findings(main, result.base.names, estimate.params)


def _validation_findings(result) -> list:
    """Least squares' findings on each validation log: extrapolation, an error far above the fit's
    (:func:`dynid.validation.diagnostics.validation_findings`)."""
    label = result.label
    fit_err = result.fit.metrics()[label]["global_relative_error"]
    fit_spread = result.diagnostics.get("prediction_spread")
    out: list = []
    for v in result.validations:
        err = v.metrics()[label]["global_relative_error"]
        moving = v.rest_share is None or float(np.mean(v.rest_share)) < 0.5  # a log mostly at rest: friction unknown
        floor = (v.floor_metrics() or {}).get("global_relative_error", np.nan)
        out += validation_findings(v.name, err if moving else np.nan, fit_err, prediction_spread=(v.spread or {}).get(label),
                                   fit_spread=fit_spread, label=label, floor=floor)
    return out


def _drive_only_preferred(result, main: str, nominal: str, scored: tuple, weighed: tuple, avg: str = " on average", *,
                          consistent_instead: bool = False):
    """``result`` with :attr:`IdentificationResult.drive_only` among its estimates and ``scored`` as its validations,
    and (label, finding), where the identified rigid body is doubtful on the validation logs and the description's
    rigid body with the drive terms fitted predicts them better than the main estimate ``main`` (mean global error), or,
    with ``consistent_instead`` (``main`` is least squares, not physically consistent, and stays the main estimate
    against the SDP), where the drive-only set is physically consistent, predicts them as well as ``main`` (to
    :data:`SAME_FIGURE`) and better than the SDP: then it, not the SDP, is what ``dynid export`` writes, as the SDP
    is where it predicts as well; None otherwise.

    Doubtful: the description's nominal model predicts the validation logs better than ``main``, or the least-squares
    estimate's predictions there leave the range the identification log supports (its prediction σ from the
    parameters' covariance over 5× that on the identification log), so the log does not determine the directions those
    motions need. ``weighed``: the figures the choice weighs (the one yardstick's, else ``scored``)."""

    alt = result.drive_only
    own, described = _mean_error(weighed, main), _mean_error(weighed, nominal)
    far = [f for f in _validation_findings(result) if f.kind == "extrapolation"]
    better = _mean_error(weighed, DRIVE_ONLY_LABEL)
    doubtful = (described < own or far) and better < own
    sdp = _mean_error(weighed, SDP_LABEL) if consistent_instead else np.inf
    instead = consistent_instead and better <= SAME_FIGURE * own and better < sdp
    if not (doubtful or instead):
        return None
    margins, verdicts = consistency_checks(result.model, result.base, {DRIVE_ONLY_LABEL: alt.params})
    if not doubtful and not str(verdicts.get(DRIVE_ONLY_LABEL, "")).startswith("yes"):
        return None
    estimate = Estimate(DRIVE_ONLY_KEY, alt.params, alt.std, standard=alt.standard)
    result = replace(result, estimates={**result.estimates, DRIVE_ONLY_LABEL: estimate}, fit=alt.fit,
                     validations=scored, consistency={**result.consistency, **margins},
                     consistency_verdicts={**result.consistency_verdicts, **verdicts})
    why = (f"the description's nominal model predicts the validation logs better than {main} "
           f"({_apart(described, own)}{avg})" if described < own else
           f"{result.label}'s predictions leave the range the identification log supports on "
           f"{len(far)} of {len(scored)} validation logs")
    how = (f"because {why} and {DRIVE_ONLY_LABEL} predicts them better than {main} ({_apart(better, own)}{avg}; the "
           f"description's nominal model {described:.3g} %)" if doubtful else
           f"physically consistent where {main} is not, because it predicts the validation logs as well as {main}, to "
           f"{100 * (SAME_FIGURE - 1):g} % ({_apart(better, own)}{avg}), and better than {SDP_LABEL} "
           f"({sdp:.3g} %); it is what dynid export writes")
    finding = (f"main estimate: {DRIVE_ONLY_LABEL}, the description's rigid body with the drive terms (friction, offsets, "
               f"rotor inertia) fitted to this log, {how}; chosen on "
               f"the validation logs, so their figures for it are not an independent test{_held_note(alt.held, alt.undetermined)}")
    if alt.held or alt.undetermined:
        result = replace(result, diagnostics={**result.diagnostics, "drive_only_held": alt.held,
                                              "drive_only_undetermined": alt.undetermined})
    return result, (DRIVE_ONLY_LABEL, finding)


def _apart(better: float, worse: float) -> str:
    """"a % against b %" with as many significant digits (3 to 6) as it takes for the two to read differently: the
    main-estimate finding said "worse (1.11 % against 1.11 % on average)" on a zoo log."""
    a, b = _apart_figures(better, worse)
    return f"{a} % against {b} %"


def _distinct_figures(values: list[float]) -> list[str]:
    """``values`` written with as many significant digits (3 to 6) as it takes for each to read differently from its
    neighbours (sorted values), as :func:`_apart_figures` does for two."""
    for digits in range(3, 7):
        form = f".{digits}g" if digits == 3 else f"#.{digits}g"
        out = [f"{v:{form}}" for v in values]
        if all(a != b for a, b, x, y in zip(out, out[1:], values, values[1:]) if x != y):
            return out
    return out


def _apart_figures(better: float, worse: float) -> tuple[str, str]:
    """The two figures of :func:`_apart`, written (the held-out blocks' finding said "worse (0.208 against 0.208 N·m
    RMS)")."""
    digits = next((d for d in range(3, 7) if f"{better:.{d}g}" != f"{worse:.{d}g}"), 6)
    form = f".{digits}g" if digits == 3 else f"#.{digits}g"  # past three digits, trailing zeros too: 1.110 against 1.114
    return f"{better:{form}}", f"{worse:{form}}"


def _held_note(held: dict, undetermined: dict) -> str:
    """The main-estimate finding's words on the drive terms the log does not determine
    (:attr:`dynid.identification.drive_only.DriveOnly.held` and ``undetermined``)."""
    def listed(runs: dict) -> str:
        return ", ".join(f"{name} ({', '.join(f'{v:.3g}' for v in r)})" for name, r in runs.items() if name != "cutoff_factors")

    if not held and not undetermined:
        return ""
    factors = (held or undetermined)["cutoff_factors"]
    out = (f"; the log does not determine some drive terms of the joints that moved one way (their estimates with the "
           f"cutoffs at {', '.join(f'{f:g}' for f in factors)}× the log's move by their own size or more: such a "
           "joint barely accelerates, and its Coulomb friction and offset act as one term)")
    if held:
        out += f": kept at the description's values: {listed(held)}"
    if undetermined:
        sheet = any(k.startswith("Ia") for k in undetermined)
        out += (f"{';' if held else ':'} kept at this log's values, as the description gives none: {listed(undetermined)}"
                + (" (a rotor inertia from the drive's data sheet, Ia = ... in [[robot.joints]], would be kept instead)"
                   if sheet else ""))
    return out

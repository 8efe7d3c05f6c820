"""What the commands print, as blocks of :mod:`dynid.tables` (lines and tables), built from the result objects:
the results hold numbers, this module their text. :func:`summary` renders any result as plain text; this module
holds an identification's and its validation's blocks, and :func:`blocks` dispatches the others' to their modules
(:mod:`~dynid.report.choice_tables`, :mod:`~dynid.report.study_summaries`, :mod:`~dynid.report.excitation_summary`,
:mod:`~dynid.report.fleet_summary`, :mod:`~dynid.report.paper_summary`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._util.keywords import keyword_only_after_data
from ..conventions import INERTIAL_TERMS, joints_unit, sliding_note, split_name
from ..estimators.registry import OTHER_LABELS, label
from ..exceptions import NotFittedError
from ..friction import COUNTERBALANCE_TERMS, TERMS
from ..identification.drive_only import DRIVE_ONLY_KEY
from ..identification.estimates import HELD_OUT_FOLDS, NOMINAL_LABEL
from ..identification.estimation_pass import DRIVE_ONLY_LABEL
from ..identification.fitted_model import IdentifiedModel
from ..identification.identifier import Identifier
from ..identification.result import BOX_FRACTION, BOX_SIGMAS, IdentificationResult
from ..identification.verdict import NOMINAL_KEY, held_out_best
from ..tables import Line, TextTable, render_text
from ..validation.diagnostics import UNFITTED, nominal_gate
from ..validation.noise_floor import AT_FLOOR
from ..validation.torques import TorqueComparison, rests_throughout
from .choice_tables import coulomb_choice_table, drive_gains_blocks, filter_choice_table, friction_choice_table
from .excitation_summary import design_blocks, excitation_blocks
from .fleet_summary import fleet_blocks, monitor_blocks
from .paper_summary import run_summary_blocks
from .study_summaries import closed_loop_study_blocks, montecarlo_blocks

SIGMA_WORDS = (" from the covariance and from a moving-block bootstrap over the log; σ % from the larger. Both are "
               "the spread from the noise, not a model's bias")
"""How the base-parameter tables' σ columns read (a :func:`larger_relative_std` table)."""

BAD_RELATIVE_STD = 100.0
"""[%] A base parameter whose σ reaches its value is not determined by the data: highlighted."""

NEGLIGIBLE_TORQUE = 1.0
"""[%] A torque offset whose σ is below this share of its joint's RMS torque is determined to be about 0 (0.01 ± 0.02
N·m), which "not determined" would misstate: its column is 1 on every log, so its ±σ is the same torque on any
motion. Another term under it is said "about 0 on this log's motion" (:func:`undetermined`), apart from the
undetermined ones: its ±σ torque on the identification log says nothing of a faster motion."""


def larger_relative_std(name: str, value: float, relative_std: float | None, bootstrap_std: dict) -> float | None:
    """A base parameter's σ over |value| [%], from the larger of the covariance's σ and the moving-block bootstrap's
    (results.json ``diagnostics.bootstrap_std``): the covariance assumes white residuals and understates the spread
    of a log whose residuals are correlated (9× on the LBR Med7's), so neither alone is shown as the σ to trust.

    Parameters
    ----------
    name : str
    value : float
        The estimate.
    relative_std : float or None
        The covariance's σ over |value| [%] (None: kept at the prior).
    bootstrap_std : dict
        name -> the bootstrap's σ, in the parameter's unit; a missing name: the covariance's alone.

    Returns
    -------
    float or None
    """
    boot = bootstrap_std.get(name)
    if relative_std is None or boot is None or not math.isfinite(boot) or value == 0:
        return relative_std
    return max(float(relative_std), 100.0 * float(boot) / abs(float(value)))


def not_determined(name: str, relative_std: float | None, sigma_torque_percent: dict) -> bool:
    """Whether a base parameter is not determined by the log: σ of :data:`BAD_RELATIVE_STD` of its value or more,
    except a torque offset whose ±σ is under :data:`NEGLIGIBLE_TORQUE` of its joint's torque (determined: about 0).

    Parameters
    ----------
    name : str
    relative_std : float or None
        σ over |value| [%] (None: kept at the prior, no σ).
    sigma_torque_percent : dict
        results.json ``diagnostics.sigma_torque_percent``: each parameter's ±σ torque over its joint's RMS torque [%].

    Returns
    -------
    bool
    """
    if relative_std is None or relative_std < BAD_RELATIVE_STD:  # NaN (no value to compare with) falls through
        return False
    share = sigma_torque_percent.get(name)
    return not (name.startswith("offset") and share is not None and share < NEGLIGIBLE_TORQUE)


__all__ = ["blocks", "summary", "comparison_table", "identification_blocks", "identification_brief"]


REST_ROWS = 0.05
"""Tables show the moving and resting figures apart where some joint rests on at least this share of samples."""


def comparison_table(cmp: TorqueComparison) -> TextTable:
    """Relative error, RMSE and correlation coefficient (eq. 18) per joint for every parameter set of ``cmp``.

    One label row per set, then one row per metric (narrow enough for 80 columns with six joints). A joint whose
    relative error is not meaningful (:meth:`TorqueComparison.meaningful`) shows "n/m" there, and one whose torque does
    not vary beyond its noise (:meth:`TorqueComparison.varies`), or whose prediction does not vary, "n/m" as its
    correlation; where joints rest, the error
    on the moving samples and the RMSE at rest follow.

    Parameters
    ----------
    cmp : dynid.validation.torques.TorqueComparison

    Returns
    -------
    TextTable
    """
    rms = cmp.rms_torque
    n = cmp.measured.shape[1]
    ok = cmp.meaningful()
    share = np.zeros(n) if cmp.rest_share is None else np.asarray(cmp.rest_share)
    split = cmp.rest_share is not None and np.any(share >= REST_ROWS) and np.any(share <= 1 - REST_ROWS)
    rows, ends = [], set()
    for name, m in cmp.metrics().items():
        rows.append((name,) + ("",) * (n + 1))
        rows.append(("  error %", *(f"{x:.1f}" if k else "n/m" for x, k in zip(m["relative_error"], ok)),
                     f"{m['global_relative_error']:.2f}"))
        rows.append(("  RMSE N·m", *(f"{x:.3g}" for x in m["rmse"]), ""))
        rows.append(("  ρ (eq. 18)", *(f"{x:.4f}" if v and np.isfinite(x) else "n/m" for x, v in zip(m["correlation"], cmp.varies())), ""))
        if split and "moving_relative_error" in m:
            rows.append(("  moving error %", *(f"{x:.1f}" if k and np.isfinite(x) else "n/m"
                                               for x, k in zip(m["moving_relative_error"], ok)), ""))
            rows.append(("  at rest RMSE N·m", *(f"{x:.3g}" if s >= REST_ROWS else "" for x, s in zip(m["rest_rmse"], share)), ""))
        ends.add(len(rows) - 1)
    floor = cmp.floor_metrics()
    if floor is not None:  # what a perfect model scores on the same samples
        rows.append(("noise floor (a perfect model)",) + ("",) * (n + 1))
        rows.append(("  error %", *(f"{x:.2g}" if k and np.isfinite(x) else "n/m" for x, k in zip(floor["relative_error"], ok)),
                     f"{floor['global_relative_error']:.2g}"))
        rows.append(("  RMSE N·m", *(f"{x:.3g}" for x in floor["rmse"]), ""))
        ends.add(len(rows) - 1)
    rest = "" if not np.any(share > 0) else ("; at rest " + ", ".join(f"{100 * x:.0f}" for x in share) + " % of the "
                                             "samples, scored as the distance to the static-friction band ±f_s")
    return TextTable(f"{cmp.name}: {cmp.n_samples} samples; RMS torque " + ", ".join(f"{x:.3g}" for x in rms)
                     + f" N·m{sliding_note('N·m', cmp.prismatic)}{rest}",
                     ("parameters", *(f"J{j + 1}" for j in range(n)), "all"), tuple(rows), section_ends=frozenset(ends))


@keyword_only_after_data
def summary(result, *, width: int = 100) -> str:
    """Plain-text summary of a result of dynid (identification, paper run, Monte Carlo study, excitation design).

    Parameters
    ----------
    result : IdentificationResult, PaperRunResult, MonteCarloResult, ExcitationRun, ExcitationDesign, TorqueComparison
        or a list of TorqueComparison, or a fitted ``Identifier`` (its result's) or ``IdentifiedModel``
        (:func:`blocks`).
    width : int
        Characters per line the tables are fitted to.

    Returns
    -------
    str
    """
    return render_text(blocks(result, library=True), width)


def blocks(result, *, library: bool = False) -> list:
    """The blocks of :func:`summary` (the terminal renders them with colours, :mod:`dynid.report.console`).

    Parameters
    ----------
    result : object
        Any result of dynid (identification, validation: one ``TorqueComparison`` or a list of them, drive gains,
        Monte Carlo, excitation, paper run), or a fitted object: a :class:`~dynid.identification.identifier.Identifier`
        (its identification's result, as ``dynid identify`` prints it) or an
        :class:`~dynid.identification.fitted_model.IdentifiedModel` (its :meth:`summary
        <dynid.identification.fitted_model.IdentifiedModel.summary>`, one read back from results.json included).

    library : bool
        Said to a library user (:func:`summary`): the first line names the fitted model's methods where the terminal's
        names ``dynid identify``'s output folder (:func:`readiness`).

    Returns
    -------
    list of Line or TextTable

    Raises
    ------
    TypeError
        Not a result of dynid.
    NotFittedError
        An ``Identifier`` not fitted yet.
    """
    from ..excitation.design import ExcitationDesign
    from ..fleet.identification import FleetResult
    from ..fleet.monitor import MonitorResult
    from ..identification.excite import ExcitationRun
    from ..studies.closed_loop_montecarlo import ClosedLoopStudyResult
    from ..studies.montecarlo import MonteCarloResult
    from ..studies.paper import PaperRunResult

    if isinstance(result, Identifier):
        if not hasattr(result, "result_"):
            raise NotFittedError("dynid.summary: this Identifier is not fitted yet: call its fit(...) first")
        result = result.result_
    if isinstance(result, IdentifiedModel):
        return [Line(text) for text in result.summary().splitlines()]
    if isinstance(result, TorqueComparison) or (isinstance(result, (list, tuple)) and result
                                                and all(isinstance(c, TorqueComparison) for c in result)):
        return validation_blocks(result if isinstance(result, (list, tuple)) else [result])
    if isinstance(result, IdentificationResult):
        return identification_blocks(result, library=library)
    for kind, make in ((PaperRunResult, run_summary_blocks),
                       (MonteCarloResult, montecarlo_blocks), (ClosedLoopStudyResult, closed_loop_study_blocks),
                       (ExcitationRun, excitation_blocks), (ExcitationDesign, design_blocks),
                       (FleetResult, fleet_blocks), (MonitorResult, monitor_blocks)):
        if isinstance(result, kind):
            return make(result)
    raise TypeError(f"expected a result of dynid, got {type(result).__name__}")


def identification_blocks(result, *, library: bool = False) -> list:
    """What ``dynid identify`` prints: how the data were prepared, the base parameters with σ beside the references,
    the estimators, the drive gains, the fit and validation tables and the verdict.

    Parameters
    ----------
    result : dynid.identification.result.IdentificationResult
    library : bool
        Its first line as said to a library user (:func:`readiness`).

    Returns
    -------
    list of Line and TextTable
    """
    r = result
    out: list = [readiness(r, library=library), _identification_title(r), *_followers_line(r)]
    out.extend(in_short(r))  # how it went and what to do next, first; the details follow
    out.extend(_preparation_blocks(r))
    out.append(_base_table(r))
    for ref in r.references:
        if ref.relative_std is not None:
            a = r.reference_agreement(ref)
            out.append(Line(f"{ref.name}: dynid's values lie within 1σ / 2σ / 3σ of its stated standard deviations for "
                            f"{a['within_1_sigma']} / {a['within_2_sigma']} / {a['within_3_sigma']} of {a['compared']} base parameters"))
    out.append(Line(f"residual σ per joint (N·m{sliding_note('N·m', r.fit.prismatic, inside=True)}): "
                    + ", ".join(f"{x:.3g}" for x in r.joint_std)))
    for name, e in r.estimates.items():
        if e.pseudo_inertia_min_eig is not None:
            out.append(Line(f"{name}: physically consistent least squares, prior: the robot model's nominal parameters; smallest "
                            "pseudo-inertia eigenvalue per link " + ", ".join(f"{x:.3g}" for x in e.pseudo_inertia_min_eig)))
    if r.consistency_verdicts:
        out.append(Line("physically consistent (some mass distribution with friction and rotor inertias ≥ 0 has these base "
                        "parameters)? " + "; ".join(f"{name}: {v}" for name, v in r.consistency_verdicts.items())))
    if r.objective:
        rows = tuple((name, f"{f:.4f}",
                      "" if name not in r.estimates else (str(r.estimates[name].n_evaluations) if r.estimates[name].n_evaluations else "solve"),
                      "" if name not in r.estimates else f"{r.estimates[name].seconds:.2f}") for name, f in r.objective.items())
        out.append(TextTable(f"Estimators on {r.fit.name} (the validation tables follow)",
                             ("parameters", "F eq. 9 (N·m)", "evaluations", "time (s)"), rows))
        if r.box is not None:
            out.append(Line(f"LAD, ABC, DE and PSO search the box {r.label} ± ({BOX_SIGMAS:g}·σ + {BOX_FRACTION:g}·|value|); "
                            "ABC at the paper's budget (Ns = 30, limit = 15, Tmax = 50), ABC×10, DE and PSO at 10× its evaluations"))
    if r.drive_gains is not None:
        out.extend(drive_gains_blocks(r.drive_gains, r.fit.prismatic))
    for c in (r.fit, *r.validations):
        out.append(comparison_table(c))
        out.extend(Line(f) for f in c.flags())
    out.extend(_verdict(r))
    out.extend(Line(w, "warning") for w in r.warnings)
    return out


def _preparation_blocks(r) -> list:
    """:func:`identification_blocks`' lines on how the data were prepared and the tables of the choices made on them
    (cutoffs, the Coulomb smoothing, the friction models)."""
    out: list = []
    pre = r.settings.get("preprocessing", {})
    if pre.get("derivation"):
        out.append(Line("preprocessing: " + pre["derivation"]))
    if r.settings.get("preprocessing_cross_validation") is not None:
        out.append(filter_choice_table(r.settings["preprocessing_cross_validation"], r.fit.prismatic))
    if r.settings.get("coulomb_cross_validation") is not None:
        out.append(coulomb_choice_table(r.settings["coulomb_cross_validation"], r.fit.prismatic))
    if r.settings.get("friction_models") is not None:
        out.append(friction_choice_table(r.settings["friction_models"], r.fit.prismatic))
    return out


def _base_table(r) -> TextTable:
    """:func:`identification_blocks`' table of the base parameters: least squares' values and σ (bootstrap's beside),
    the closed-loop, drive-only and other main estimates, and the reference sets."""
    sol, base = r.solution, r.base
    # IDIM-IV, DIDIM, the drive-only estimate and any other main estimate (the SDP): beside least squares
    main = r.main_estimate
    closed = [e for e in r.estimates.values() if e.key in OTHER_LABELS or e.key == DRIVE_ONLY_KEY
              or (e is main and e.key != r.least_squares)]
    kept = set(sol.from_prior)  # directions the log did not determine: the prior's (finding "prior")
    boot = (r.diagnostics or {}).get("bootstrap_std") or {}
    rows = tuple((n, base.unit(n), f"{sol.params[i]:.4g}", "prior" if i in kept else f"{sol.params_std[i]:.2g}",
                  *(("prior" if i in kept else f"{boot.get(n, math.nan):.2g}",) if boot else ()),
                  "—" if i in kept else f"{larger_relative_std(n, sol.params[i], sol.relative_std[i], boot):.1f}",
                  *(f"{e.params[i]:.4g}" for e in closed), *(f"{ref.beta[i]:.4g}" for ref in r.references))
                 for i, n in enumerate(base.names))
    return TextTable(f"Base parameters, {r.label} (σ: standard deviation{SIGMA_WORDS if boot else ''}; "
                     + ("closed-loop estimates and " if any(e.key in OTHER_LABELS for e in closed) else
                        "the main estimate and " if closed else "") + "reference values beside)",
                     ("name", "unit", "value", "σ", *(("σ boot.",) if boot else ()), "σ %",
                      *(label(e.key) + (" (main)" if e is main else "") for e in closed),
                      *(ref.name for ref in r.references)),
                     rows, labels=2)


def _followers_line(r) -> list:
    """The line on the joints that follow another (:meth:`dynid.model.robot.Robot.followers_said`), where the model
    has any."""
    said = r.model.followers_said() if getattr(r, "model", None) is not None else ""
    return [Line(said)] if said else []


def _identification_title(r) -> Line:
    return Line(f"dynid identify — robot {r.robot}, {r.least_squares.upper()} on {r.fit.name}: {r.base.n_base} base "
                f"parameters from {r.n_rows} equations, cond = {r.solution.condition_number:.4g}", "title")


def _verdict(r, brief: bool = False) -> list:
    """The verdict's title and findings; ``brief``: the verdict's choice and :data:`BRIEF_FINDINGS` more (those that
    ask something first), the rest counted by kind."""
    title = Line("Verdict on the model: " + ("no finding: the residuals show no structure the checks look for"
                                            if not r.findings else f"{len(r.findings)} finding(s)"), "title")
    shown = list(r.findings)
    if brief:
        first = [f for f in shown if f.kind == "main" or f.kind in NOT_READY_KINDS]  # what the first line points to
        asks = [f for f in shown if _asks(r, f) and f not in first]
        rest = [f for f in shown if f not in first and f not in asks]
        picked = (asks + rest)[:BRIEF_FINDINGS]
        shown = [f for f in shown if f in first or f in picked]  # the verdict's order
        left = [f.kind for f in r.findings if f not in shown]
        if left:
            kinds = ", ".join(f"{k} ({left.count(k)})" if left.count(k) > 1 else k for k in dict.fromkeys(left))
            return [title, *(Line(f.text) for f in shown),
                    Line(f"and {len(left)} more ({kinds}): --verbose, or report.html")]
    return [title, *(Line(f.text) for f in shown)]


def _held_out_clause(r, label: str) -> str:
    """The first line's words on held-out blocks of the identification log, where they were scored (without
    validation logs): how ``label`` predicts them against the best candidate, and over how much time."""
    held = (getattr(r, "diagnostics", None) or {}).get("held_out_rms_error") or {}
    if label not in held:
        return ""
    seconds = r.diagnostics.get("held_out_block_seconds")
    blocks = f"{HELD_OUT_FOLDS} × {seconds:.3g} s" if seconds else f"{HELD_OUT_FOLDS} blocks"
    best = held_out_best(held, label)
    unit = joints_unit("N·m", r.fit.prismatic)
    said = (f"it predicts them as well as any candidate ({held[label]:.3g} {unit} RMS)" if best == label else
            f"{'the description' if best == NOMINAL_LABEL else best} predicts them better ({held[best]:.3g} against "
            f"{held[label]:.3g} {unit} RMS)")
    return f"; on held-out blocks of this log ({blocks}, weaker evidence than another motion) {said}"


def _exportable(r) -> list[str]:
    """The estimates ``dynid export`` can write: standard parameters that passed the consistency check (the SDP's, the
    drive-only one's), the main estimate first as export takes it (:func:`dynid.io.results.stored_standard`)."""
    ordered = sorted(r.estimates.items(), key=lambda item: item[0] != getattr(r, "main", ""))
    return [n for n, e in ordered if getattr(e, "standard", None) is not None
            and str(r.consistency_verdicts.get(n, "")).startswith("yes")]


def readiness(result, *, library: bool = False) -> Line:
    """The first line of ``dynid identify``: whether the model is ready to use, and the one thing to do next.

    Ready: a physically consistent estimate (what ``dynid export`` writes), no torque running against the model, and
    on the validation logs no joint the description's nominal model predicts better (the publish gate). Otherwise the
    first reason, with what would help.

    Parameters
    ----------
    result : dynid.identification.result.IdentificationResult
    library : bool
        Said to a library user (:func:`summary`): the model's URDF and MJCF are
        :meth:`~dynid.identification.fitted_model.IdentifiedModel.urdf` and ``mjcf()`` (an Identifier's ``model_``), and
        the check on other motions ``validate(log)``, not ``dynid identify``'s output folder and a config's
        ``[[validation]]`` logs.

    Returns
    -------
    Line
    """
    r = result
    kinds = {f.kind for f in r.findings}
    exportable = _exportable(r)
    worse = {log: s.get("worse_joints", []) for log, s in (r.diagnostics.get("versus_nominal") or {}).items()}
    nominal = r.diagnostics.get("nominal_set")
    if exportable and nominal is not None and any(s.get("estimate") != exportable[0]
                                                  for s in (r.diagnostics.get("versus_nominal") or {}).values()):
        # the gate judged the main estimate; what is ready is what export writes (it warns on these joints)

        trusted = [v for v in r.validations if not v.misread]  # the verdict weighed these alone
        worse = {log: s["worse_joints"] for log, s in nominal_gate(trusted, exportable[0], nominal)[1].items()}
    worse = {log: j for log, j in worse.items() if j}
    if "sign" in kinds:
        return Line("not ready: the measured torques run against the model on some joint (a flipped sign?): the "
                    "verdict at the end names it and the setting that fixes it", "warning")
    if any(f.kind == "columns" and UNFITTED in f.text for f in r.findings):
        return Line("not ready: the torque columns do not follow the robot file's model on any joint and no fit follows "
                    "them (another signal read as torques, or torques that no model of the arm follows: a controller "
                    "or a simulation oscillating?): the verdict at the end says what they look like", "warning")
    if "columns" in kinds:
        return Line("not ready: the torque columns do not follow the robot file's model on any joint (velocities, "
                    "positions or another signal read as torques?): the verdict at the end says what they look like",
                    "warning")
    if "spikes" in kinds:
        return Line("not ready: the measured torques are mostly spikes (a controller or simulation chattering, or "
                    "glitches) and follow the robot file's model on no joint: the verdict at the end names the joints",
                    "warning")
    if "order" in kinds:
        return Line("not ready: the torques of some joints look swapped: the verdict at the end names them", "warning")
    if "angles" in kinds:
        return Line("not ready: the logged angles do not match the robot file (a joint's zero a quarter or half turn "
                    "off, a joint counted the other way round, or two columns swapped?): the verdict at the end names "
                    "them and the setting that fixes it", "warning")
    if "rate" in kinds:
        return Line("not ready: the torques fit the description far better with the motion faster or slower than logged "
                    "(the log's sample rate or time unit?): the verdict at the end says how much", "warning")
    if "gravity" in kinds:
        return Line("not ready: the torques fit the description far better with gravity along another direction (a "
                    "robot mounted on a wall, a ceiling or tilted?): the verdict at the end names it and the setting that "
                    "fixes it", "warning")
    if "scale" in kinds:
        return Line("not ready: the measured torques are far from the description's size (a unit, or the drive "
                    "gains?): the verdict at the end says how far and the setting that fixes it", "warning")
    if "unexplained" in kinds:
        return Line("not ready: the best fit to this log misses most of its torque, beyond the torques' noise: "
                    "something the arm's model cannot express carries them; the verdict at the end says how much and "
                    "on which joints", "warning")
    misread = [v.name for v in r.validations if v.misread]
    if misread:
        return Line(f"not ready: {', '.join(misread)} {'is' if len(misread) == 1 else 'are'} read otherwise than the "
                    "identification log (angles, mounting, torque channels, units or rate), so the model has no fair test on other "
                    "motions: the warning says how to read it; then identify again", "warning")
    if getattr(r.estimates.get(getattr(r, "main", "")), "key", "") == NOMINAL_KEY:
        return Line(f"keep your robot file's values ({r.main}): this log cannot improve them; the verdict at the end "
                    "says why and what would", "title")
    if not exportable:
        why = ('add "sdp" to [estimation] estimators for a physically consistent estimate' if "sdp" not in r.estimators
               else "no estimate passed the consistency check (the verdict says why)")
        return Line(f"not ready to export: {why}", "warning")
    if worse:
        log, joints = next(iter(worse.items()))
        return Line(f"not ready: the description's nominal model predicts {', '.join(f'J{j}' for j in joints)} of {log} "
                    f"better than {exportable[0]} (what dynid export writes); identify on a log that excites them "
                    "(dynid excite), or keep the nominal values there", "warning")
    files = ("its URDF and MJCF: IdentifiedModel.urdf() and .mjcf(), an Identifier's model_" if library else
             "its URDF and MJCF are in the output folder")
    if not r.validations:
        check = "validate(log) on other motions" if library else "add [[validation]] logs (other motions)"
        return Line(f"model ready to check: {exportable[0]} is physically consistent ({files}){_held_out_clause(r, exportable[0])}; "
                    f"{check} before you use it", "title")
    if library:
        return Line(f"model ready: {exportable[0]} ({files})", "title")
    return Line(f"model ready: {exportable[0]}, as the URDF and MJCF in the output folder (other names: dynid export "
                "CONFIG --urdf FILE --mjcf FILE)", "title")


def taken_away_lines(taken: dict) -> list:
    """What ``dynid identify`` says of the files it wrote, read back by their tools (results.json's
    ``files_taken_away``, :func:`dynid.report.identification_run.taken_away`).

    Parameters
    ----------
    taken : dict

    Returns
    -------
    list of Line
    """
    where = f"on {taken['log']}" if taken["log"] else "on random states within the joint limits"
    out = []
    for f in taken["files"]:
        if "not_read_back" in f:
            out.append(Line(f"{f['file']} not read back: {f['not_read_back']}"))
            continue
        said = (f"{f['file']} read back by {f['read_by']} {where} ({f['samples']} samples): equals dynid's model to "
                f"{f['equals_model_to']:.1e} of its RMS where {f['format']} can hold it")
        gap = f.get("simulator_gap")
        if gap is not None:
            said += (f"; what {SIMULATES[f['format']]} computes from it is off dynid's whole model by "
                     + ", ".join(f"J{j + 1} {g:.2g}" for j, g in enumerate(gap) if j not in f.get("following_joints", ()))
                     + " % of each joint's RMS torque")
        if f.get("file_vs_measured") is not None:
            said += (f"; against the log's unfiltered measured torques {f['file_vs_measured']:.3g} %, dynid's whole "
                     f"model {f['model_vs_measured']:.3g} %")
        if f["cannot_hold"]:
            j = max(range(len(f["cannot_hold_share"])), key=lambda k: f["cannot_hold_share"][k])
            how = ("the file's comments, and results.json for the joints whose friction is folded, say how to add them"
                   if f.get("friction_folded") else "the file's comments say how to add them")
            said += (f"; it cannot hold {', '.join(stem_words(k) for k in f['cannot_hold'])} (up to "
                     f"{f['cannot_hold_share'][j]:.3g} % of J{j + 1}'s RMS torque: {how})")
        chosen = [text.format(", ".join(f"J{j}" for j in f[key])) for key, text in FILE_CHOICES if f.get(key)]
        if chosen:
            said += f"; {' and '.join(chosen)}, where the validation logs say that predicts the joint better (results.json: diagnostics.file_terms)"
        off = f["equals_model_to"] > 1e-6 or max(f.get("simulator_gap") or [0.0]) > SIMULATOR_GAP
        out.append(Line(said, "warning" if off else "text"))
    return out


FILE_CHOICES = (("friction_folded", "the friction of {} holds its Stribeck and load-dependent Coulomb terms folded into "
                                    "its Coulomb and viscous pair"),
                ("offsets_held", "the torque offsets of {} are held by actuators of constant bias (the others left out)"))
"""What a read-back line says of a file's ``files_taken_away`` keys (:func:`dynid.report.identification_run.file_choice`)."""

SIMULATES = {"URDF": "Pinocchio (RNEA and the joints' <dynamics>)",
             "MJCF": "MuJoCo (mj_inverse, its frictionloss a constraint as MuJoCo solves it)"}
"""What computes a written file's torques, with its own semantics (:attr:`dynid.io.exported.replay.ReplayCheck.simulator_gap`)."""

SIMULATOR_GAP = 2.0
"""[%] A joint whose simulated torque is further than this off dynid's model (of its RMS torque) makes the read-back
line a warning: a user simulating the file meets a model that much off the one identified."""


def identification_brief(result) -> list:
    """What ``dynid identify`` prints without ``--verbose``: the title, how it went and what to do next
    (:func:`in_short`), the verdict's findings and the warnings; every table is in ``--verbose`` and the report.

    Parameters
    ----------
    result : dynid.identification.result.IdentificationResult

    Returns
    -------
    list of Line
    """
    r = result
    short = in_short(r, brief=True)
    short[0] = Line("In short (every table and finding: --verbose, and report.html)", "title")
    drive = [] if r.drive_gains is None else [b for b in drive_gains_blocks(r.drive_gains, r.fit.prismatic) if isinstance(b, Line)]
    return [readiness(r), _identification_title(r), *_followers_line(r), *short, *drive, *_verdict(r, brief=True),
            *(Line(w, "warning") for w in r.warnings)]


BRIEF_FINDINGS = 2
"""Findings ``dynid identify`` prints without ``--verbose`` besides the verdict's choice and those the first line
points to (:data:`NOT_READY_KINDS`; :func:`_verdict`): those that ask something of the user first, in the verdict's
order; the others are counted by kind (issue "Fast where users wait", item 4: the verdict in a screenful).
``--verbose`` and report.html list every one."""

NOT_READY_KINDS = ("sign", "columns", "spikes", "order", "angles", "rate", "gravity", "scale", "unexplained")
"""Finding kinds that make :func:`readiness`'s first line "not ready: … the verdict at the end names it": always
printed."""


def worst_joint(relative_error, meaningful) -> tuple[int, float] | None:
    """The joint with the largest relative error among those whose relative error means something.

    Parameters
    ----------
    relative_error : (n_dof,) sequence [%]
        None or NaN where unknown.
    meaningful : (n_dof,) sequence of bool
        :meth:`dynid.validation.torques.TorqueComparison.meaningful`.

    Returns
    -------
    (int, float) or None
        0-based joint and its error [%]; None when no joint's error means something.
    """
    rel = np.asarray(relative_error, dtype=float)
    ranked = np.where(np.asarray(meaningful, dtype=bool) & np.isfinite(rel), rel, -np.inf)
    if not np.isfinite(ranked).any():
        return None
    j = int(np.argmax(ranked))
    return j, float(rel[j])


_AT_REST = ("the distance to the static-friction band, a check of the gravity model to within friction, not of "
            "motion")


def _log_lines(r, label: str) -> tuple[list, dict]:
    """:func:`in_short`'s line per scored log (:func:`log_summaries`) and the global errors [%] by log."""
    logs, errors = [], {}
    for c in (r.fit, *r.validations):
        m = c.metrics().get(label)
        if m is None:
            continue
        errors[c.name] = float(m["global_relative_error"])
        still = c is not r.fit and rests_throughout(c.rest_share)
        floor = (c.floor_metrics() or {}).get("global_relative_error", np.nan)
        logs.append(ScoredLog(c.name, errors[c.name], worst_joint(m["relative_error"], c.meaningful()), still,
                              float(floor), c is r.fit, tuple(c.dead_said)))
    return [Line(text) for text in log_summaries(logs)], errors


@dataclass(frozen=True)
class ScoredLog:
    """What the summaries say of one scored log (:func:`log_summaries`).

    Attributes
    ----------
    name : str
        The dataset.
    error : float
        Global relative torque error [%] of the estimate judged.
    worst : (int, float) or None
        Worst meaningful joint (0-based) and its error [%] (:func:`worst_joint`).
    still : bool
        Whether every joint rests in 95 % of the log or more (scored against the static-friction band).
    floor : float
        Noise floor [%] of these samples (NaN: unknown).
    fit : bool
        Whether it is the identification log.
    dead : tuple of int
        Joints (0-based) whose torque channel is constant over the log: left out of its errors.
    """

    name: str
    error: float
    worst: tuple[int, float] | None
    still: bool
    floor: float = float("nan")
    fit: bool = False
    dead: tuple[int, ...] = ()


def log_summaries(logs) -> list[str]:
    """One line per scored log, as the terminal's and the report's "In short" give them: global error, worst joint,
    noise floor. Logs at rest throughout share one line when there are several (the UR10e's p1-p10 took twenty lines
    to say "0 %" ten times), and a worst joint at 0 % is not named.

    Parameters
    ----------
    logs : sequence of ScoredLog

    Returns
    -------
    list of str
    """
    def worst_text(worst, name=""):
        return "" if worst is None or worst[1] == 0 else f", worst {name}J{worst[0] + 1} {worst[1]:.3g} %"

    out = [f"{g.name}: torque error {g.error:.3g} % {_over_joints(g.dead)}" + worst_text(g.worst)
           + (f" (noise floor {g.floor:.2g} %)" if np.isfinite(g.floor) else "") + (" (the fit)" if g.fit else "")
           for g in logs if not g.still]
    still = [g for g in logs if g.still and not g.dead]  # one line for several; a log with a dead channel says so alone
    for g in [g for g in logs if g.still and g.dead] + (still if len(still) == 1 else []):
        out.append(f"{g.name}: torque error {g.error:.3g} % {_over_joints(g.dead)}{worst_text(g.worst)} "
                   f"(at rest throughout: {_AT_REST})")
    if len(still) > 1:
        low, high = min(g.error for g in still), max(g.error for g in still)
        spread = f"{low:.3g} %" if f"{high:.3g}" == f"{low:.3g}" else f"{low:.3g}-{high:.3g} %"
        top = max(still, key=lambda g: -np.inf if g.worst is None else g.worst[1])
        out.append(f"{_resting([g.name for g in still])}: torque error {spread} "
                   f"over all joints{worst_text(top.worst, top.name + ' ')} ({_AT_REST})")
    return out


def _over_joints(dead) -> str:
    """"over all joints", or which joints a log's errors leave out: a dead torque channel's joint is in none of them
    (:attr:`dynid.validation.torques.TorqueComparison.dead`)."""
    if not len(dead):
        return "over all joints"
    joints = ", ".join(f"J{j + 1}" for j in dead)
    return (f"over the joints but {joints} ({'its torque reads' if len(dead) == 1 else 'their torques read'} a constant "
            "or the drive's limit throughout: left out)")


def _kept_line(kept: list, dead, anchored=()) -> Line:
    """:func:`in_short`'s line on the parameters the log does not determine (:attr:`LeastSquaresSolution.from_prior`).
    A joint that moved one way only has its Coulomb friction and offset undetermined apart, not each: their sum is
    estimated and only the split is the description's (it read "kept at the description's nominal values" beside
    fc = offset = 4.7 N·m, nominal 0)."""
    pairs = sorted(int(n[2:]) for n in kept
                   if n.startswith("fc") and n[2:].isdigit() and f"offset{n[2:]}" in kept and int(n[2:]) - 1 not in dead)
    none = [j for j in pairs if f"fv{j}" in kept]  # no friction term determined: a joint that did not move
    text = (f"taken from the description's nominal values along what this log does not determine (no σ): "
            f"{', '.join(kept)}")
    if [j for j in pairs if j not in none]:
        joints = ", ".join(f"J{j}" for j in pairs if j not in none)
        text += (f"; {joints} moved one way only: Coulomb friction + offset is estimated as one term, the split between "
                 "them is the description's")
    if none:
        text += f"; {', '.join(f'J{j}' for j in none)}: no friction term determined (a joint held still?)"
    taken = [n[2:] for n in anchored if n.startswith("fc")]
    if taken:
        text += (f"; {', '.join(f'J{j}' for j in taken)} moved one way only: Coulomb friction + offset is estimated as "
                 "one term and taken as Coulomb friction (the same in the direction not moved), the offset is the "
                 "description's")
    return Line(text)


def _best(errors: dict, sep: str = "; ") -> str:
    """"; best: X", or "; equal best: X, Y" where sets tie at the three digits shown ("" for one set)."""
    if len(errors) < 2:
        return ""
    low = min(errors.values())
    tied = [k for k, v in errors.items() if f"{v:.3g}" == f"{low:.3g}"]
    return f"{sep}best: {tied[0]}" if len(tied) == 1 else f"{sep}equal best: {', '.join(tied)}"


def _resting(names: list) -> str:
    """The head of the one line several logs at rest throughout share: "p1, p2 (2 logs at rest throughout)"."""
    return f"{', '.join(names)} ({len(names)} logs at rest throughout)"


def validation_in_short(comparisons, tables_follow: bool = True) -> list:
    """How a validation went, first: for each log, each parameter set's torque error over all joints and its worst
    meaningful joint, the best set named (sets that tie at the digits shown named together); logs at rest throughout
    in one line (their figure is a check of the gravity model within friction).

    Parameters
    ----------
    comparisons : sequence of dynid.validation.torques.TorqueComparison
    tables_follow : bool
        The title says the tables follow (``--verbose``), or where they are.

    Returns
    -------
    list of Line
    """
    out = [Line("In short (the tables follow)" if tables_follow else "In short (every table: --verbose, and report.html)", "title")]
    still = [c for c in comparisons if rests_throughout(c.rest_share) and not c.dead_said]
    for c in comparisons:
        if c in still and len(still) > 1:
            continue
        metrics, ok = c.metrics(), c.meaningful()
        parts = []
        for name, m in metrics.items():
            worst = worst_joint(m["relative_error"], ok)
            parts.append(f"{name} {m['global_relative_error']:.3g} %" + ("" if worst is None or worst[1] == 0 else
                                                                       f" (worst J{worst[0] + 1} {worst[1]:.3g} %)"))
        out.append(Line(f"{c.name}: torque error {_over_joints(c.dead_said)}: " + "; ".join(parts)
                        + _best({k: m["global_relative_error"] for k, m in metrics.items()})
                        + (f" (at rest throughout: {_AT_REST})" if rests_throughout(c.rest_share) else "")))
    if len(still) > 1:
        spans: dict[str, list[float]] = {}
        for c in still:
            for name, m in c.metrics().items():
                spans.setdefault(name, []).append(float(m["global_relative_error"]))
        parts = [f"{name} {min(v):.3g} %" if f"{min(v):.3g}" == f"{max(v):.3g}" else f"{name} {min(v):.3g}-{max(v):.3g} %"
                 for name, v in spans.items()]
        out.append(Line(f"{_resting([c.name for c in still])}: torque error over "
                        f"all joints: {'; '.join(parts)} ({_AT_REST})"))
    return out + _misread_lines([c.name for c in comparisons if c.misread])


def _misread_lines(names: list) -> list:
    """The line that says which logs are read otherwise than the identification log (none: no line)."""
    if not names:
        return []
    return [Line(f"{', '.join(names)}: read otherwise than the identification log (angles, mounting, torque channels, "
                 "units or rate: the warning says how): its figures say little of any estimate")]


def validation_blocks(comparisons, *, tables: bool = True) -> list:
    """What ``dynid validate`` prints of its comparisons (``IdentifiedModel.validate``'s too, through
    :func:`summary`): how it went in short, each log's table, the set to use.

    Parameters
    ----------
    comparisons : sequence of dynid.validation.torques.TorqueComparison
    tables : bool
        Each log's table of per-joint metrics (``dynid validate --verbose``).

    Returns
    -------
    list of Line and TextTable
    """
    return [*validation_in_short(comparisons, tables_follow=tables), *(comparison_table(c) for c in comparisons if tables),
            *validation_verdict(comparisons)]


def validation_verdict(comparisons) -> list:
    """The last lines of ``dynid validate``: each parameter set's mean torque error over the logs that move (logs at
    rest throughout check the gravity model within friction and would dilute the mean), the set to use and the next
    step.

    Parameters
    ----------
    comparisons : sequence of dynid.validation.torques.TorqueComparison

    Returns
    -------
    list of Line
    """
    moving = [c for c in comparisons if not rests_throughout(c.rest_share)] or list(comparisons)
    errors: dict[str, list[float]] = {}
    for c in moving:
        for name, m in c.metrics().items():
            errors.setdefault(name, []).append(m["global_relative_error"])
    if not errors:
        return []
    means = {name: float(np.mean(v)) for name, v in errors.items()}
    best = min(means, key=lambda k: means[k])
    n, left = len(moving), len(comparisons) - len(moving)
    logs = f"the {n} logs" + (" that move" if left else "") if n > 1 else "the one log" + (" that moves" if left else "")
    what = logs + (f" ({left} at rest throughout left out: they check the gravity model)" if left else "")
    out = [Line(f"mean torque error over {what}: " + "; ".join(f"{name} {v:.3g} %" for name, v in means.items())
                + _best(means, " — "), "title")]
    misread = [c.name for c in comparisons if c.misread]
    if misread:
        out.append(Line(f"next: read {', '.join(misread)} as the warning says, then validate again"))
    elif all(c.repeats_fit for c in comparisons):
        one = len(comparisons) == 1
        out.append(Line("next: validate on a log of another motion (dynid validate CONFIG --file LOG): "
                        + ("this log repeats" if one else "these logs repeat") + " the identification log's samples, so "
                        + ("its" if one else "their") + " figures are the fit's"))
    elif not best.startswith("dynid"):
        out.append(Line(f"next: {best} predicts these logs better than dynid's estimates; identify on a log that moves "
                        "as these do, or add them to [[validation]] to choose among the estimates"))
    else:
        out.append(Line("next: dynid export writes the estimate as URDF/MJCF for your controller or simulator"))
    return out


def undetermined(names, params, relative_std, kept, share: dict, boot: dict) -> tuple[list[str], list[str]]:
    """The base parameters the summary calls not determined (:func:`not_determined` on the larger σ), split into
    those whose ±σ torque on the identification log (``share``, from the covariance's σ, scaled to the larger) is
    :data:`NEGLIGIBLE_TORQUE` of their joint's torque or more, and those under it (about 0 on this motion).

    Parameters
    ----------
    names : sequence of str
    params, relative_std : sequences of float
        Least squares' values and covariance σ over |value| [%] (NaN or None where kept at the prior).
    kept : set of str
        Names kept at the prior (left out).
    share : dict
        results.json ``diagnostics.sigma_torque_percent``.
    boot : dict
        results.json ``diagnostics.bootstrap_std``.

    Returns
    -------
    (not determined, about 0) : two lists of str
    """
    loose: list[str] = []
    small: list[str] = []
    for n, v, rel in zip(names, params, relative_std):
        if n in kept or rel is None:
            continue
        larger = larger_relative_std(n, v, float(rel), boot)
        if not not_determined(n, larger, share):
            continue
        torque = share.get(n)
        if torque is not None and larger is not None and float(rel) > 0:
            torque *= larger / float(rel)
        (small if torque is not None and torque < NEGLIGIBLE_TORQUE else loose).append(n)
    return loose, small


def in_short(result, *, brief: bool = False) -> list:
    """How an identification went, in a few lines: the estimate to use and whether it is physically consistent, each
    log's global error and worst joint, and what to do next.

    Parameters
    ----------
    result : dynid.identification.result.IdentificationResult
    brief : bool
        What the log does not determine counted in one line (``dynid identify`` without ``--verbose``), not listed.

    Returns
    -------
    list of Line
    """
    r = result
    label = getattr(r, "main", None) or r.main_estimate.label  # the description's values: its set's name
    verdict = r.consistency_verdicts.get(label, "")
    consistent = verdict.startswith("yes")
    exportable = _exportable(r)
    export = "" if not exportable or exportable[0] == label else (
        f"; dynid export writes {exportable[0]}, which is physically consistent" if not consistent else
        f"; dynid export writes {exportable[0]}, the consistent estimate with a whole set of standard parameters (the "
        "main estimate's are base parameters alone)")
    out = [Line("In short (the details follow)", "title"),
           Line(f"main estimate: {label}" + ("" if not verdict else
                                             f", physically consistent{export}" if consistent else
                                             f", not physically consistent{export}"))]
    lines, errors = _log_lines(r, label)
    out += lines + _yardstick_lines(r, label)
    out += _determined_lines(r, label, brief=brief)
    fit = errors.get(r.fit.name)
    at_floor = {c.name for c in r.validations if (c.floor_metrics() or {}).get("global_relative_error", np.nan) * AT_FLOOR
                >= errors.get(c.name, np.inf)}
    misread = [c.name for c in r.validations if c.misread]
    far = [k for k, v in errors.items() if k != r.fit.name and fit is not None and v > 3 * max(fit, 1e-9)
           and k not in at_floor and k not in misread]
    out += _misread_lines(misread)
    if far:
        out.append(Line(f"{', '.join(far)}: over 3x the fit's error: motions unlike the identification log's (speeds, "
                        "rests; the report shows where)"))
    if _to_do(r):
        step = "read the verdict's findings at the end: they say where the model misses the data"
    elif not r.validations:
        step = "add [[validation]] logs (other motions) to check the model where it was not fitted"
    elif exportable:  # written already, the first line says where: nothing to do
        return out
    elif "sdp" not in r.estimators:
        step = 'for a model to simulate, add "sdp" to [estimation] estimators (a physically consistent estimate)'
    else:
        step = "use the model to predict torques; no estimate is physically consistent, so none is exported"
    out.append(Line("next: " + step))
    return out


GOOD_NEWS = ("main", "floor")
"""Finding kinds that ask nothing of the user: the verdict's choice, a fit at the noise floor (and a nominal gate
that every joint passes: :func:`_to_do`)."""


def _to_do(r) -> bool:
    """Whether some finding asks something of the user (:func:`_asks`)."""
    return any(_asks(r, f) for f in r.findings)


def _asks(r, finding) -> bool:
    """Whether a finding asks something of the user: not :data:`GOOD_NEWS`, nor the nominal gate where the main
    estimate predicts every joint better than the description."""
    worse = any(s.get("worse_joints") for s in (r.diagnostics.get("versus_nominal") or {}).values())
    return finding.kind not in GOOD_NEWS and (finding.kind != "nominal" or worse)


def _yardstick_lines(r, label: str) -> list:
    """:func:`in_short`'s line on the one yardstick (:func:`dynid.identification.evidence.with_yardstick`): the main
    estimate's and the description's mean validation errors with every log prepared by dynid's default rules alone;
    over the logs that move where others rest throughout (those say how many sets stay within the static-friction
    band, which is what they score)."""
    yard = r.diagnostics.get("yardstick") or {}
    moving = yard.get("mean_over_logs_that_move")
    mean = moving or yard.get("mean_global_relative_error") or {}
    if label not in mean:
        return []
    nominal = r.diagnostics.get("nominal_set")
    beside = f", the description's nominal model {mean[nominal]:.3g} %" if nominal in mean and nominal != label else ""
    n = len(r.validations)
    over = f"(mean over {n} logs)" if n > 1 else "(one log)"
    if moving:
        rests = [errors for name, errors in yard["global_relative_error"].items() if name not in moving["logs"]]
        sets = [(label, label)] + ([("the description", nominal)] if nominal in rests[0] and nominal != label else [])
        within = "; ".join(f"{who} on {sum(e[key] == 0 for e in rests)}" for who, key in sets)
        k = len(moving["logs"])
        over = (("(over the one log that moves" if k == 1 else f"(mean over the {k} logs that move")
                + f"; of the {len(rests)} at rest throughout, within the static-friction band: {within})")
    floor = yard.get("noise_floor")
    floor = "" if floor is None else f" (noise floor {floor:.3g} %: the measured torques' own noise)"
    return [Line(f"on one yardstick (every validation log's torques as measured, its states filtered by dynid's default "
                 f"rules whatever the settings): {label} {mean[label]:.3g} %{floor}{beside} {over}")]


CHOSEN_TERMS = ("fst", "fca", "fcl")
"""Friction terms beyond Coulomb and viscous friction: in the model because the friction models' cross-validation
(or the description) chose them, so a loose σ does not make them "not determined"."""


COUPLING_WORDS = {"Iam": "a coupled motor's inertia", "fvm": "its viscous friction", "fcm": "its Coulomb friction"}
"""A coupled motor's terms (:data:`dynid.conventions.COUPLING_TERMS`) in words."""


def stem_words(stem: str) -> str:
    """A drive term's or a coupled motor's stem written out, for a console line that lists them (issue "Never worse
    than the description", item 4: every name explained once).

    Parameters
    ----------
    stem : str
        ``"Ia"``, ``"offset"``, ``"cbsd"``, ``"Iam"`` … (:data:`dynid.friction.TERMS`,
        :data:`dynid.conventions.COUPLING_TERMS`).

    Returns
    -------
    str
        ``"Ia = rotor (reflected motor) inertia"``; the stem alone where it has no words.
    """
    words = _term_words(stem) if stem in TERMS else COUPLING_WORDS.get(stem)
    return f"{stem} = {words}" if words else stem


def _term_words(stem: str) -> str:
    """A drive term's name in words (its description before the formula); the counterbalance's four terms, which share
    one name, with their formula (cbsd: "counterbalance torque (cbsd·sin(2q))")."""
    text = TERMS[stem].description
    return f"{text.split(',')[0]} ({text.split(': ')[1]})" if stem in COUNTERBALANCE_TERMS else text.split(",")[0]


def _drive_legend(names: list[str]) -> str:
    """One line saying what the drive terms ``names`` are, each kind once, its names before it by joint ("offset2,
    offset4, constant torque offset (…) of their joint; Ia3, rotor (reflected motor) inertia of J3"); the kinds by
    their first joint."""
    stems: dict[str, list[str]] = {}
    for n in sorted(names, key=lambda n: split_name(n)[1]):
        stems.setdefault(split_name(n)[0], []).append(n)
    return "the drive terms named: " + "; ".join(
        f"{', '.join(group)}, {_term_words(stem)} of "
        + (f"J{split_name(group[0])[1] + 1}" if len(group) == 1 else "their joint") for stem, group in stems.items())


def _link_legend(names: list[str]) -> str:
    """One line saying what the link parameters among ``names`` are (issue "Never worse than the description", item 4:
    every name in the console explained once); empty where there are none."""
    stems = {split_name(n)[0] for n in names} & set(INERTIAL_TERMS)  # eq. 5's order: tensor, first moments, mass
    kinds = {"inertia" if s in INERTIAL_TERMS[:6] else "moment" if s in INERTIAL_TERMS[6:9] else "mass" for s in stems}
    if not kinds:
        return ""
    parts = [text for kind, text in (("inertia", "XXj, XYj, XZj, YYj, YZj, ZZj the inertia tensor of link j about its frame's origin"),
                                     ("moment", "MXj, MYj, MZj its first moments (mass × centre of mass)"),
                                     ("mass", "Mj its mass")) if kind in kinds]
    regrouped = " (a trailing R: regrouped, holding parameters of the links after it; results.json: regrouping)" \
        if any(n.endswith("R") and split_name(n)[0] in INERTIAL_TERMS for n in names) else ""
    return "the link parameters named: " + "; ".join(parts) + regrouped


def _determined_count(whose: str, loose: list, chosen: list, small: list) -> list:
    """The brief's one line on the base parameters the log leaves loose: how many are not determined, kept loose by the
    friction models' choice, and about 0 on its motion (those taken from the description keep their own line)."""
    parts = [f"{len(names)} {what}" for names, what in ((loose, f"not determined (σ ≥ {BAD_RELATIVE_STD:g} % of the value)"),
                                                        (chosen, "friction terms kept loose"),
                                                        (small, "about 0 on its motion")) if names]
    if not parts:
        return []
    advice = ": a richer excitation (dynid excite) determines them" if loose or chosen else ""
    return [Line(f"{whose}base parameters this log leaves open: {', '.join(parts)} (--verbose names them){advice}")]


def _determined_lines(r, label: str, brief: bool = False) -> list:
    """:func:`in_short`'s lines on what the log determines. They read least squares' σ; where the main estimate is the
    drive-only one, whose links are the description's, they say so first and name least squares as theirs, and the
    drive terms the drive-only fit kept at the description's values (:attr:`dynid.identification.drive_only.DriveOnly.held`).
    ``brief``: one line that counts them (:func:`_determined_count`)."""
    out = []
    whose, listed = "", []
    if label == DRIVE_ONLY_LABEL:
        terms, loose = ([k for k in (r.diagnostics or {}).get(key) or {} if k != "cutoff_factors"]
                        for key in ("drive_only_held", "drive_only_undetermined"))
        out.append(Line(f"{label}: the links' inertial parameters are the description's, the drive terms fitted to this log"
                        + (f"; {', '.join(terms)} kept at the description's values, as the log does not determine them "
                           "(their estimates move with the cutoffs by their own size or more)" if terms else "")
                        + (f"; not determined by this log either, kept at its values as the description gives none: "
                           f"{', '.join(loose)}" if loose else "")
                        + (" (a rotor inertia from the drive's data sheet: Ia = ... in [[robot.joints]])"
                           if any(k.startswith("Ia") for k in loose) else "")))
        whose, listed = f"{r.label}, beside it: ", [*terms, *loose]
    elif getattr(getattr(r, "estimates", {}).get(label), "key", "") == NOMINAL_KEY:  # the robot file's values
        out.append(Line(f"{label}: the robot file's own values, which this log does not improve"))
        whose = f"{r.label}, beside it: "
    kept = {r.base.names[i] for i in r.solution.from_prior}
    if kept:
        line = _kept_line([n for n in r.base.names if n in kept], r.fit.dead_said, [r.base.names[i] for i in r.solution.anchored])
        out.append(Line(whose + line.text, line.kind) if whose else line)
    share = (r.diagnostics or {}).get("sigma_torque_percent") or {}
    boot = (r.diagnostics or {}).get("bootstrap_std") or {}
    loose, small = undetermined(r.base.names, r.solution.params, r.solution.relative_std, kept, share, boot)
    which = "; σ the larger of the covariance's and the bootstrap's" if boot else ""
    chosen = [n for n in loose if split_name(n)[0] in CHOSEN_TERMS]  # the friction models' cross-validation kept them
    loose = [n for n in loose if n not in chosen]
    if brief:
        return out + _determined_count(whose, loose, chosen, small)
    if loose:
        out.append(Line(f"{whose}not determined by this log (σ ≥ {BAD_RELATIVE_STD:g} % of the value{which}): "
                        f"{', '.join(loose)}: their values are set by the noise and the misfit; a richer excitation "
                        "(dynid excite) determines them"))
    if chosen:
        by = ("the friction models' cross-validation (they lower the held-out error)"
              if getattr(getattr(r, "choices", None), "friction", None) is not None else "the description")
        out.append(Line(f"{whose}kept by {by}, their values loose (σ ≥ {BAD_RELATIVE_STD:g} % of the value{which}): {', '.join(chosen)}: the log "
                        "shows the effect, not its size; a richer excitation (dynid excite) sizes them"))
    named = list(dict.fromkeys(n for n in [*listed, *loose, *chosen, *small] if split_name(n)[0] in TERMS))
    if named:
        out.append(Line(_drive_legend(named)))
    legend = _link_legend([*loose, *chosen, *small])
    if legend:
        out.append(Line(legend))
    if small:
        out.append(Line(f"{whose}about 0 on this log's motion (σ ≥ {BAD_RELATIVE_STD:g} % of the value{which}, but ±σ "
                        f"under {NEGLIGIBLE_TORQUE:g} % of the joint's torque): {', '.join(small)}: a faster or wider "
                        "motion may need them; the validation logs say whether it does"))
    return out



"""Identification of a real robot from its logs, and validation on other logs.

Recording (CSV, :mod:`dynid.io.datasets`) → the preprocessing pipeline (:mod:`dynid.preprocessing.pipeline`:
filtered positions and derivatives, base regressor and torques filtered in parallel and decimated,
chunk by chunk, cutoffs derived from the excitation band) → OLS/WLS accumulated by incremental QR
(memory independent of the log's length) → validation: relative error, RMSE and correlation
coefficient (eq. 18) per joint and the global relative error, for dynid's parameters and each
reference set.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ..column_store import root_mean_square
from ..conventions import unit_of
from ..dynamics.base_parameters import BaseParameters
from ..dynamics.layout import consistency_layout
from ..estimators import paper_objective
from ..estimators.accumulate import LeastSquaresAccumulator, LeastSquaresSolution
from ..estimators.physically_consistent import PhysicallyConsistentLeastSquares, consistency_margin, consistency_verdict
from ..exceptions import ConfigError, DynIdError, IdentifiabilityError
from ..io.references import ReferenceSet
from ..model.robot import Robot
from ..estimators.names import LEAST_SQUARES as METHODS
from ..preprocessing.pipeline import PreparedData, base_chunks
from ..tables import Line, TextTable, render_text
from ..validation.diagnostics import (BlockGrams, Finding, ResidualSums, bootstrap_finding, excitation_findings,
                                     sign_findings)
from ..validation.torques import TorqueComparison, TorqueSums, comparison_table, resting_rows

__all__ = ["IdentificationResult", "identify"]


def estimate_label(method: str) -> str:
    """How dynid's estimate is labelled in tables, figures and JSON: ``"dynid WLS"``, ``"dynid ABC×10"``."""
    from ..estimators.names import LABELS

    return f"dynid {LABELS.get(method, method.upper())}"


SDP_LABEL = "dynid SDP"
"""Label of the physically consistent estimate."""


def parameter_sets(method: str, params: np.ndarray, references=(), consistent: np.ndarray | None = None,
                   others: dict | None = None) -> dict:
    """label -> base parameter vector: dynid's estimate, its physically consistent estimate if any, the
    other estimators' (``others``: label -> vector), then each reference set."""
    sdp = {} if consistent is None else {SDP_LABEL: consistent}
    return {estimate_label(method): params, **sdp, **(others or {}), **{r.name: r.beta for r in references}}


BOX_SIGMAS = 5.0
BOX_FRACTION = 0.5
"""Search box of the box searches (ABC, DE, PSO) and LAD on real logs: ``β̂ ± (5·σ + 0.5·|β̂|)`` around the
OLS/WLS estimate ``β̂`` with its standard deviation ``σ``: wide enough to hold the true parameters when σ
is underestimated severalfold, narrow enough to be searched."""


def search_box(params: np.ndarray, std: np.ndarray) -> np.ndarray:
    """(n_base, 2) box ``params ± (BOX_SIGMAS·std + BOX_FRACTION·|params|)`` (a zero width gets 1e-6)."""
    half = np.maximum(BOX_SIGMAS * np.asarray(std) + BOX_FRACTION * np.abs(params), 1e-6)
    return np.column_stack([params - half, params + half])


@dataclass(frozen=True)
class OtherEstimate:
    """An estimator of :mod:`dynid.estimators.registry` run on the stacked, parallel-filtered rows.

    Attributes
    ----------
    key : str
    params : (n_base,) array
    seconds : float
    n_evaluations : int or None
        Evaluations of eq. 9 (box searches only).
    """

    key: str
    params: np.ndarray
    seconds: float
    n_evaluations: int | None

    @property
    def label(self) -> str:
        return estimate_label(self.key)


@dataclass(frozen=True)
class ConsistentEstimate:
    """Physically consistent least squares on a real log (same row weights as the OLS/WLS estimate).

    Attributes
    ----------
    standard : (n_params,) array
        Standard parameters (each link's pseudo-inertia ⪰ 0, friction and rotor inertias ≥ 0).
    base : (n_base,) array
    pseudo_inertia_min_eig : (n_dof,) array
    prior : str
        What the unidentifiable directions were pulled towards.
    """

    standard: np.ndarray
    base: np.ndarray
    pseudo_inertia_min_eig: np.ndarray
    prior: str = "the robot model's nominal parameters"
    note: str = ""


@dataclass(frozen=True)
class IdentificationResult:
    """Identified base parameters with their uncertainty, fit, validations and reference sets.

    Attributes
    ----------
    robot : str
    base : BaseParameters
    method : str
        "ols" or "wls".
    solution : LeastSquaresSolution
        Parameters, covariance, std, relative std [%], condition number of the (weighted) base
        observation matrix.
    joint_std : (n_dof,) array [N·m]
        Residual standard deviation of each joint (OLS residuals; the WLS weights are their inverses).
    references : tuple of ReferenceSet
    fit : TorqueComparison
        On the identification data.
    validations : tuple of TorqueComparison
    n_rows : int
        Equations used (after decimation and the speed threshold).
    settings : dict
    warnings : tuple of str
    consistent : ConsistentEstimate or None
        The physically consistent estimate, when asked for.
    consistency : dict
        label -> consistency margin of each parameter set (``>= 0``: some mass distribution with non-negative
        friction and rotor inertias has these base parameters; :func:`dynid.estimators.consistency_margin`).
    consistency_verdicts : dict
        label -> "yes" or "no: reason" (:func:`dynid.estimators.physically_consistent.consistency_verdict`).
    others : tuple of OtherEstimate
        The other estimators asked for (``[estimation] methods``).
    objective : dict
        label -> F of eq. 9 on the identification rows [N·m] (when other estimators ran).
    box : (n_base, 2) array or None
        The box searches' box (:func:`search_box`).
    drive_gains : dynid.experiment.drive_gains.GainsAndPayload or None
        Drive gains and payload from ``[drive_gains]``.
    model : Robot or None
        The robot as identified: its drive terms are the friction models chosen for its joints.
    findings : tuple of Finding
        The verdict on the model: one line each (:mod:`dynid.validation.diagnostics`).
    diagnostics : dict
        The statistics behind the findings (residual autocorrelation, bootstrap σ, nominal correlation, …).
    main : str
        Label of the estimate to trust (the first unless the physically consistent one validates better).
    """

    robot: str
    base: BaseParameters
    method: str
    solution: LeastSquaresSolution
    joint_std: np.ndarray
    references: tuple[ReferenceSet, ...]
    fit: TorqueComparison
    validations: tuple[TorqueComparison, ...] = ()
    n_rows: int = 0
    settings: dict = field(default_factory=dict)
    warnings: tuple[str, ...] = ()
    consistent: ConsistentEstimate | None = None
    consistency: dict = field(default_factory=dict)
    consistency_verdicts: dict = field(default_factory=dict)
    others: tuple = ()
    objective: dict = field(default_factory=dict)
    box: np.ndarray | None = None
    drive_gains: object = None
    model: Robot | None = None
    findings: tuple = ()
    diagnostics: dict = field(default_factory=dict)
    main: str = ""

    @property
    def label(self) -> str:
        return estimate_label(self.method)

    def parameter_sets(self) -> dict:
        """label -> base parameter vector: dynid's estimate(s), then each reference set."""
        return parameter_sets(self.method, self.solution.params, self.references,
                              None if self.consistent is None else self.consistent.base,
                              {o.label: o.params for o in self.others})

    def reference_agreement(self, ref: ReferenceSet) -> dict:
        """Differences to a reference that states relative standard deviations: ``z = |Δ| / σ_ref``."""
        sigma = np.abs(ref.beta) * ref.relative_std / 100.0
        diff = self.solution.params - ref.beta
        with np.errstate(divide="ignore", invalid="ignore"):
            z = np.abs(diff) / sigma
        ok = np.isfinite(z)
        return {"z": z, "within_1_sigma": int(np.sum(z[ok] <= 1)), "within_2_sigma": int(np.sum(z[ok] <= 2)),
                "within_3_sigma": int(np.sum(z[ok] <= 3)), "compared": int(ok.sum())}

    def to_dict(self) -> dict:
        sol = self.solution
        params = [{"name": n, "value": float(v), "std": float(s), "relative_std_percent": float(r), "unit": unit_of(n),
                   "expression": e.split(" = ", 1)[1]}
                  for n, v, s, r, e in zip(self.base.names, sol.params, sol.params_std, sol.relative_std, self.base.expressions)]
        refs = []
        for r in self.references:
            entry = {"name": r.name, "source": r.source, "values": dict(zip(self.base.names, r.beta.tolist()))}
            if r.relative_std is not None:
                agree = self.reference_agreement(r)
                entry["agreement"] = {k: v for k, v in agree.items() if k != "z"}
                entry["z"] = dict(zip(self.base.names, agree["z"].tolist()))
            refs.append(entry)
        return {
            "robot": self.robot, "method": self.method, "base_parameters": params,
            "condition_number": sol.condition_number, "residual_std": sol.residual_std,
            "joint_residual_std": self.joint_std, "n_rows": self.n_rows, "settings": self.settings,
            "identification": self.fit.to_dict(), "validation": [v.to_dict() for v in self.validations],
            "references": refs, "warnings": list(self.warnings),
            "consistency_margin": self.consistency, "physically_consistent_verdict": self.consistency_verdicts,
            "methods": {o.label: {"key": o.key, "values": dict(zip(self.base.names, o.params.tolist())),
                                  "seconds": o.seconds, "n_evaluations": o.n_evaluations} for o in self.others},
            "objective_eq9": self.objective, "main_estimate": self.main or self.label,
            "findings": [f.to_dict() for f in self.findings], "diagnostics": self.diagnostics,
            **({} if self.drive_gains is None else {"drive_gains": self.drive_gains.to_dict()}),
            **({} if self.box is None else {"search_box": {"rule": f"estimate ± ({BOX_SIGMAS:g}·σ + {BOX_FRACTION:g}·|estimate|)",
                                                            "bounds": dict(zip(self.base.names, self.box.tolist()))}}),
            **({} if self.consistent is None else {"physically_consistent": {
                "label": SDP_LABEL, "prior": self.consistent.prior,
                "values": dict(zip(self.base.names, self.consistent.base.tolist())),
                "standard_values": dict(zip(self.base.standard_names, self.consistent.standard.tolist())),
                "pseudo_inertia_min_eig": self.consistent.pseudo_inertia_min_eig.tolist()}}),
        }

    def summary_blocks(self) -> list:
        """What ``dynid identify`` prints, as blocks of :mod:`dynid.tables` (lines and tables)."""
        sol, base = self.solution, self.base
        out = [Line(f"dynid identify — robot {self.robot}, {self.method.upper()} on {self.fit.name}: {base.n_base} base "
                    f"parameters from {self.n_rows} equations, cond = {sol.condition_number:.4g}", "title")]
        pre = self.settings.get("preprocessing", {})
        if pre.get("derivation"):
            out.append(Line("preprocessing: " + pre["derivation"]))
        if self.settings.get("preprocessing_cross_validation") is not None:
            out.append(filter_choice_table(self.settings["preprocessing_cross_validation"]))
        if self.settings.get("coulomb_cross_validation") is not None:
            out.append(coulomb_choice_table(self.settings["coulomb_cross_validation"]))
        if self.settings.get("friction_models") is not None:
            out.append(friction_choice_table(self.settings["friction_models"]))
        rows = tuple((n, unit_of(n), f"{sol.params[i]:.4g}", f"{sol.params_std[i]:.2g}", f"{sol.relative_std[i]:.1f}",
                      *(f"{r.beta[i]:.4g}" for r in self.references)) for i, n in enumerate(base.names))
        out.append(TextTable("Base parameters (σ: standard deviation; reference values beside)",
                             ("name", "unit", "value", "σ", "σ %", *(r.name for r in self.references)), rows, labels=2))
        for r in self.references:
            if r.relative_std is not None:
                a = self.reference_agreement(r)
                out.append(Line(f"{r.name}: dynid's values lie within 1σ / 2σ / 3σ of its stated standard deviations for "
                                f"{a['within_1_sigma']} / {a['within_2_sigma']} / {a['within_3_sigma']} of {a['compared']} base parameters"))
        out.append(Line("residual σ per joint (N·m): " + ", ".join(f"{x:.3g}" for x in self.joint_std)))
        if self.consistent is not None:
            out.append(Line(f"dynid SDP: physically consistent least squares, prior: {self.consistent.prior}; smallest "
                            "pseudo-inertia eigenvalue per link " + ", ".join(f"{x:.3g}" for x in self.consistent.pseudo_inertia_min_eig)))
        if self.consistency_verdicts:
            out.append(Line("physically consistent (some mass distribution with friction and rotor inertias ≥ 0 has these base "
                            "parameters)? " + "; ".join(f"{label}: {v}" for label, v in self.consistency_verdicts.items())))
        if self.others:
            others = {o.label: o for o in self.others}
            rows = tuple((label, f"{f:.4f}", "" if label not in others else (str(others[label].n_evaluations) if others[label].n_evaluations else "solve"),
                          "" if label not in others else f"{others[label].seconds:.2f}") for label, f in self.objective.items())
            out.append(TextTable(f"Estimators on {self.fit.name} (the validation tables follow)",
                                 ("parameters", "F eq. 9 (N·m)", "evaluations", "time (s)"), rows))
            out.append(Line(f"LAD, ABC, DE and PSO search the box {self.label} ± ({BOX_SIGMAS:g}·σ + {BOX_FRACTION:g}·|value|); "
                            "ABC at the paper's budget (Ns = 30, limit = 15, Tmax = 50), ABC×10, DE and PSO at 10× its evaluations"))
        if self.drive_gains is not None:
            out.extend(self.drive_gains.summary_blocks())
        for c in (self.fit, *self.validations):
            out.append(comparison_table(c))
            out.extend(Line(f) for f in c.flags())
        out.append(Line("Verdict on the model: " + ("no finding: the residuals show no structure the checks look for"
                                                   if not self.findings else f"{len(self.findings)} finding(s)"), "title"))
        out.extend(Line(f.text) for f in self.findings)
        out.extend(Line(w, "warning") for w in self.warnings)
        return out

    def summary(self, width: int = 100) -> str:
        """Plain-text summary: parameters with σ beside the references, fit and validation metrics."""
        return render_text(self.summary_blocks(), width)


def filter_choice_table(cv: dict) -> TextTable:
    """``preprocessing = "auto"``: each candidate's cutoffs and out-of-fold errors on the common held-out samples."""
    n = len(cv["out_of_fold_rms_error"][0])
    rows = tuple((f"{c['position_cutoff']:.3g}{'*' if i == cv['chosen'] else ''}", f"{c['parallel_cutoff']:.3g}", str(c["decimation"]),
                  *(f"{x:.4g}" for x in e), f"{s:.4g}")
                 for i, (c, e, s) in enumerate(zip(cv["candidates"], cv["out_of_fold_rms_error"], cv["score"])))
    return TextTable("Cutoffs by cross-validation: out-of-fold RMS torque error (N·m) on the same held-out samples; chosen: *",
                     ("positions Hz", "parallel Hz", "decimation", *(f"J{j + 1}" for j in range(n)), "score"), rows, labels=3)


def friction_choice_table(choice: dict) -> TextTable:
    """Each joint's friction model chosen by cross-validation, its out-of-fold error against the plain model's."""
    plain, chosen = np.asarray(choice["plain_out_of_fold_rms_error"]), np.asarray(choice["chosen_out_of_fold_rms_error"])
    share = choice.get("rest_share")
    rows = tuple((f"J{j + 1}", m["label"], f"{plain[j]:.3g}", f"{chosen[j]:.3g}",
                  "" if share is None else f"{100 * share[j]:.0f}") for j, m in enumerate(choice["models"]))
    return TextTable(f"Friction model of each joint, chosen by {choice['folds']}-fold blocked cross-validation "
                     "(out-of-fold RMS torque error, N·m; the state at rest is judged where 5 % of the samples rest)",
                     ("joint", "model", "plain", "chosen", "at rest %"), rows, labels=2)


def coulomb_choice_table(cv: dict) -> TextTable:
    """The candidates of the Coulomb smoothing velocity and their out-of-fold errors, per joint."""
    rows = tuple(("sign" if frac == 0 else f"{frac:g}", *(f"{e:.4g}{'*' if v == c else ''}" for e, v, c in zip(e_row, vs_row, cv["velocity"])))
                 for frac, vs_row, e_row in zip(cv["grid_fraction_of_rms_speed"], cv["candidates"], cv["out_of_fold_rms_error"]))
    return TextTable(f"Coulomb term tanh(q̇/v_s): out-of-fold RMS torque error (N·m), {cv['folds']} contiguous folds; chosen: *",
                     ("v_s / RMS speed", *(f"J{j + 1}" for j in range(len(cv["velocity"])))), rows)

def identify(robot: Robot, base: BaseParameters, data: PreparedData, method: str = "wls",
             references: tuple[ReferenceSet, ...] = (), progress=None, physically_consistent: bool = False,
             methods: tuple[str, ...] = (), rng=0, held_out: bool = False) -> IdentificationResult:
    """Estimate the base parameters from one prepared recording by OLS or WLS (chunked), and with
    ``physically_consistent`` also by physically consistent least squares over the standard parameters
    (same row weights; prior: the robot model's nominal parameters). Every parameter set gets its
    consistency margin.

    ``progress(step, done, total)`` reports each step (the regressor pass chunk by chunk, the SDP, each other
    estimator, the consistency checks).

    ``held_out``: with ``physically_consistent``, when no validation log will say which estimate to trust, compare the
    unconstrained and the physically consistent estimates by blocked cross-validation (:data:`HELD_OUT_FOLDS`
    contiguous blocks), and make the consistent one the main estimate when the unconstrained one is not consistent
    and predicts the held-out blocks worse.

    ``methods`` adds estimators of :mod:`dynid.estimators.registry` other than OLS/WLS/SDP (IRLS, LAD, ABC,
    ABC×10, DE, PSO) on the same parallel-filtered rows, stacked in memory (rows below ``min_speed`` set
    to 0, so that they count for no method); LAD and the box searches search :func:`search_box`, seeded
    by ``rng``.

    Raises
    ------
    ConfigError
        Unknown method.
    IdentifiabilityError
        Too few rows or a rank-deficient base observation matrix (the log does not excite every
        base parameter).
    """
    if method not in METHODS:
        raise ConfigError(f"estimation.method: expected one of {', '.join(METHODS)}, got {method!r}")
    n = robot.n_dof
    acc = LeastSquaresAccumulator(base.n_base, n)
    acc_std = LeastSquaresAccumulator(robot.n_params, n) if physically_consistent else None
    extra = tuple(k for k in methods if k not in (method, "sdp"))
    stacked_w, stacked_tau = [], []
    # the fit's metrics and the verdict's sums accumulate on the same pass: no second pass over the log
    sums = TorqueSums.for_data(data, base.n_base)
    residuals = ResidualSums(n, base.n_base)
    blocks = BlockGrams(n, base.n_base, data.t.shape[0])
    near_reversal = 5 * np.broadcast_to(np.asarray(data.settings.min_speed, dtype=float), (n,))
    folds = [LeastSquaresAccumulator(robot.n_params, n) for _ in range(HELD_OUT_FOLDS)] if held_out and acc_std is not None else []
    n_s = data.t.shape[0]
    for index, y, tau, keep in base_chunks(robot, base, data, _step(progress, f"regressor, {data.name}"), standard=physically_consistent):
        if acc_std is not None:
            acc_std.add(y.reshape(-1, robot.n_params), tau.reshape(-1), keep.reshape(-1))
            fold = index * HELD_OUT_FOLDS // n_s
            for k in np.unique(fold) if folds else ():
                sel = fold == k
                folds[k].add(y[sel].reshape(-1, robot.n_params), tau[sel].reshape(-1), keep[sel].reshape(-1))
            y = base.base_observation(y)
        acc.add(y.reshape(-1, base.n_base), tau.reshape(-1), keep.reshape(-1))
        sums.add(data.t[index], y, tau, resting_rows(data, index))
        direction = np.asarray(data.direction[index]) if data.direction is not None else np.sign(np.asarray(data.dq[index]))
        residuals.add(y, tau, np.asarray(data.q[index]), np.asarray(data.dq[index]), direction, near_reversal, keep)
        blocks.add(index, y, tau, keep)
        if extra:
            k = keep.reshape(-1)
            stacked_w.append(y.reshape(-1, base.n_base) * k[:, None])
            stacked_tau.append(tau.reshape(-1) * k)
    try:
        ols = acc.solve(names=base.names)
    except IdentifiabilityError as exc:
        speed = root_mean_square(data.dq)
        still = [f"J{j + 1}" for j in np.flatnonzero(speed < 1e-3 * max(speed.max(), 1e-12))]
        hint = f"; joint(s) {', '.join(still)} barely move" if still else ""
        raise IdentifiabilityError(f"{data.name}: {exc}{hint}") from None
    joint_std = acc.joint_residual_std(ols.params)
    row_weights = None if method == "ols" else 1.0 / np.where(joint_std > 0, joint_std, 1.0)
    sol = ols if method == "ols" else acc.solve(row_weights)
    if acc_std is not None and progress is not None:
        progress("physically consistent SDP", 0, 1)
    consistent = None if acc_std is None else _consistent_estimate(robot, base, acc_std, row_weights)
    warnings = list(robot.nominal_problems) + list(data.warnings) + ([consistent.note] if consistent is not None and consistent.note else [])
    dropped = 1.0 - acc.rows.sum() / (n * len(range(0, data.t.shape[0], data.settings.decimation)))
    if dropped > 0.5:
        warnings.append(f"{data.name}: {100 * dropped:.0f}% of the rows are below preprocessing.min_speed and were left out")
    for r in references:
        warnings.extend(r.warnings)
    others, objective, box = (), {}, None
    if extra:
        w_all, tau_all = np.concatenate(stacked_w), np.concatenate(stacked_tau)
        others, box = _other_estimates(extra, base, w_all, tau_all, n, sol, rng, progress)
    sets = parameter_sets(method, sol.params, references, None if consistent is None else consistent.base,
                          {o.label: o.params for o in others})
    if extra:
        objective = {label: float(paper_objective(tau_all - w_all @ beta, n)) for label, beta in sets.items()}
    if progress is not None:
        progress("consistency checks", 0, 1)
    links, nonneg = consistency_layout(robot)
    margins, verdicts = {}, {}
    for label, beta in sets.items():
        try:
            margins[label] = consistency_margin(base.regrouping, beta, links, nonneg)
            verdicts[label] = consistency_verdict(margins[label], base.regrouping, beta, base.names, nonneg)
        except DynIdError as exc:  # a failed check never stops the identification
            margins[label], verdicts[label] = float("nan"), f"not checked: {exc}"
    fit = replace(sums.comparison(data.name, sets), noise=joint_std, speed=root_mean_square(data.dq))
    findings, stats = _verdict(robot, base, sol, ols, joint_std, row_weights, sums, residuals, blocks, fit, data, rng)
    main = ""
    if folds and consistent is not None and not str(verdicts.get(estimate_label(method), "yes")).startswith("yes"):
        if progress is not None:
            progress("physically consistent SDP, held-out blocks", 0, 1)
        own, sdp = _held_out_errors(robot, folds, row_weights)
        stats["held_out_rms_error"] = {estimate_label(method): own, SDP_LABEL: sdp}
        if sdp < own:
            main = SDP_LABEL
            findings.insert(0, Finding("main", f"main estimate: {SDP_LABEL}, physically consistent, where "
                                               f"{estimate_label(method)} is not and predicts held-out blocks of the log "
                                               f"worse ({sdp:.3g} against {own:.3g} N·m RMS, {HELD_OUT_FOLDS}-fold blocked "
                                               "cross-validation)"))
    return IdentificationResult(robot.name, base, method, sol, joint_std, tuple(references), fit, n_rows=int(acc.rows.sum()),
                                settings={"preprocessing": data.settings.to_dict(), "rate": data.rate}, warnings=tuple(warnings),
                                consistent=consistent, consistency=margins, consistency_verdicts=verdicts,
                                others=others, objective=objective, box=box, model=robot, findings=tuple(findings),
                                diagnostics=stats, main=main)


def _verdict(robot, base, sol, ols, joint_std, row_weights, sums, residuals, blocks, fit, data, rng):
    """The verdict's findings on the identification log (:mod:`dynid.validation.diagnostics`) and their statistics."""
    n = robot.n_dof
    rms = fit.rms_torque
    findings, stats = [], {}
    if np.any(robot.inertial != 0):  # the description's nominal model: does the data run against it?
        nominal = base.base_from_standard(robot.standard_parameters())
        corr = sums.comparison(data.name, {"nominal": nominal}).metrics()["nominal"]["correlation"]
        stats["nominal_correlation"] = corr
        findings += sign_findings(corr, fit.varies(), data.name)
    fc = np.array([sol.params[base.names.index(f"fc{j + 1}")] if f"fc{j + 1}" in base.names else 0.0 for j in range(n)])
    more, res_stats = residuals.residual_checks(ols.params, rms, fc)
    findings += more
    stats.update(res_stats)
    boot = blocks.bootstrap_std(row_weights, rng=rng)
    more, ratio = bootstrap_finding(sol.params_std, boot)
    findings += more
    stats.update({"bootstrap_std": dict(zip(base.names, boot.tolist())), "bootstrap_over_covariance_std": ratio})
    raw = sums.m2 + sums.count * np.einsum("jc,jd->jcd", sums.mean, sums.mean)  # Σ z zᵀ per joint
    col_rms = np.sqrt(np.max(np.diagonal(raw, axis1=1, axis2=2)[:, :-1], axis=0) / max(sums.count, 1))
    findings += excitation_findings(base.names, sol.params, sol.params_std, col_rms, float(np.sqrt(np.mean(rms**2))))
    # the prediction's spread from the parameters' covariance: Σ diag(y C yᵀ) = trace(C Σ y yᵀ)
    spread = np.sqrt(np.maximum(np.einsum("cd,jdc->j", sol.covariance, raw[:, :-1, :-1]) / max(sums.count, 1), 0.0))
    stats["prediction_spread"] = spread
    return findings, stats


HELD_OUT_FOLDS = 5
"""Contiguous blocks of the identification log that compare the estimates when no validation log does."""


def _held_out_errors(robot: Robot, folds, row_weights) -> tuple[float, float]:
    """RMS torque error on the held-out blocks of the unconstrained (OLS/WLS, minimum-norm over the standard
    parameters: the base estimate's predictions) and the physically consistent estimates, each fitted on the others."""
    p = robot.n_params
    links, nonneg = consistency_layout(robot)
    sse = np.zeros(2)
    rows = 0
    for k, held in enumerate(folds):
        rest = LeastSquaresAccumulator.merged([a for i, a in enumerate(folds) if i != k])
        reduced = rest.reduced(row_weights)
        phi = np.linalg.lstsq(reduced[:p, :p], reduced[:p, p], rcond=1e-10)[0]
        est = PhysicallyConsistentLeastSquares(links=links, nonnegative=nonneg, prior=robot.standard_parameters())
        est.fit(reduced[:, :p], reduced[:, p])
        sse += [held.joint_residual_sumsq(phi).sum(), held.joint_residual_sumsq(est.params_).sum()]
        rows += int(held.rows.sum())
    own, sdp = np.sqrt(sse / max(rows, 1))
    return float(own), float(sdp)


def _step(progress, label: str):
    """``progress(label, done, total)`` as a ``(done, total)`` callback (None stays None)."""
    return None if progress is None else (lambda done, total: progress(label, done, total))


def _other_estimates(keys, base, w, tau, n_dof, sol, rng, progress=None) -> tuple[tuple[OtherEstimate, ...], np.ndarray]:
    """Fit each of ``keys`` on the stacked rows; the box from the OLS/WLS solution ``sol``."""
    from ..estimators.names import LABELS, METHODS as ALL
    from ..estimators.registry import FitData, SearchBudget, fit_methods

    box = search_box(sol.params, sol.params_std)
    data = FitData(w, tau, n_dof, box, base)
    rngs = {k: np.random.default_rng([int(rng), ALL.index(k)]) for k in keys}  # (seed, method): whatever else is asked for
    report = None if progress is None else (lambda key, i, f: progress(f"estimators: {LABELS[key]}", 0 if i is None else i, 0))
    fitted = fit_methods(keys, data, SearchBudget(), rngs, report)
    return tuple(OtherEstimate(k, f.params, f.seconds, f.n_evaluations) for k, f in fitted.items()), box


def _consistent_estimate(robot: Robot, base: BaseParameters, acc: LeastSquaresAccumulator, row_weights) -> ConsistentEstimate:
    """The SDP on the accumulated triangular factor of the standard problem (weighted like the estimate)."""
    robot.require_physical_nominal("estimation.physically_consistent (its prior is the description's nominal values)")
    p = robot.n_params
    reduced = acc.reduced(row_weights)
    links, nonneg = consistency_layout(robot)
    est = PhysicallyConsistentLeastSquares(links=links, nonnegative=nonneg, prior=robot.standard_parameters())
    est.fit(reduced[:, :p], reduced[:, p])
    note = ("" if est.status_ == "optimal" else
            f"physically consistent least squares: the SDP solver (Clarabel) ended with status {est.status_}: its estimate "
            "may be slightly off the optimum (a poorly excited log or badly scaled parameters)")
    return ConsistentEstimate(est.params_, base.base_from_standard(est.params_), est.pseudo_inertia_min_eig_, note=note)

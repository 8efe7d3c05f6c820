"""The identification's result: the base parameters every estimator found with their uncertainty, the fit, the
validations and reference sets, the verdict's findings and diagnostics (:class:`IdentificationResult`, what
results.json holds), and the search box the box searches (ABC, DE, PSO) and LAD are given around least squares."""

from __future__ import annotations

import textwrap
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..dynamics.base_parameters import BaseParameters
from ..estimators.accumulate import LeastSquaresSolution
from ..estimators.registry import estimate_label
from ..io.config.references import ReferenceSet
from ..model.robot import Robot
from ..validation.torques import TorqueComparison
from .drive_only import DriveOnly
from .estimates import Estimate
from .fitted_model import Parameters

__all__ = ["IdentificationResult", "search_box"]


BOX_SIGMAS = 5.0
BOX_FRACTION = 0.5
"""Search box of the box searches (ABC, DE, PSO) and LAD on real logs: ``β̂ ± (5·σ + 0.5·|β̂|)`` around the
least-squares estimate ``β̂`` with its standard deviation ``σ``: wide enough to hold the true parameters when σ
is underestimated severalfold, narrow enough to be searched."""


def search_box(params: np.ndarray, std: np.ndarray) -> np.ndarray:
    """The box ``params ± (BOX_SIGMAS·std + BOX_FRACTION·|params|)`` (a zero width gets 1e-6).

    Parameters
    ----------
    params, std : (n_base,) arrays
        An estimate and its standard deviations.

    Returns
    -------
    (n_base, 2) array
        Lower and upper bounds.
    """
    half = np.maximum(BOX_SIGMAS * np.asarray(std) + BOX_FRACTION * np.abs(params), 1e-6)
    return np.column_stack([params - half, params + half])


@dataclass(frozen=True)
class IdentificationResult:
    """Identified base parameters with their uncertainty, fit, validations and reference sets.

    Attributes
    ----------
    robot : str
    base : BaseParameters
    estimators : tuple of str
        The estimators asked for; the first is the main estimate unless the verdict chose another (:attr:`main`).
    least_squares : str
        "ols" or "wls": the least-squares estimate with σ that every identification has (the first of them listed,
        else WLS); its residuals give each joint's noise, its σ the box searches' box.
    solution : LeastSquaresSolution
        That estimate: parameters, covariance, std, relative std [%], condition number of the (weighted) base
        observation matrix.
    joint_std : (n_dof,) array [N·m]
        Residual standard deviation of each joint (OLS residuals; the WLS weights are their inverses).
    estimates : dict
        label -> :class:`Estimate`, every estimate (the least-squares one included), in the order asked.
    references : tuple of ReferenceSet
    fit : TorqueComparison
        On the identification data.
    validations : tuple of TorqueComparison
    n_rows : int
        Equations used (after decimation and the speed threshold).
    settings : dict
    warnings : tuple of str
    consistency : dict
        label -> consistency margin of each parameter set (``>= 0``: some mass distribution with non-negative
        friction and rotor inertias has these base parameters; :func:`dynid.estimators.consistency_margin`).
    consistency_verdicts : dict
        label -> "yes" or "no: reason" (:func:`dynid.estimators.physically_consistent.consistency_verdict`).
    objective : dict
        label -> F of eq. 9 on the identification rows [N·m] (when estimators other than least squares ran).
    box : (n_base, 2) array or None
        The box searches' box (:func:`search_box`).
    drive_gains : dynid.identification.drive_gains.GainsAndPayload or None
        Drive gains and payload from ``[drive_gains]``.
    model : Robot or None
        The robot as identified: its drive terms are the friction models chosen for its joints.
    findings : tuple of Finding
        The verdict on the model: one line each (:mod:`dynid.validation.diagnostics`).
    diagnostics : dict
        The statistics behind the findings (residual autocorrelation, bootstrap σ, nominal correlation, …).
    main : str
        Label of the estimate to trust.
    drive_only : DriveOnly or None
        The description's rigid body with the drive terms fitted (:mod:`dynid.identification.drive_only`): made the
        main estimate by :func:`dynid.identification.verdict.choose_main_estimate` where the validation logs prefer it; not
        in :attr:`estimates` otherwise (None: a description without inertial parameters).
    choices : ModelChoices or None
        What the data chose for :attr:`model` (:class:`dynid.identification.choices.ModelChoices`): set by
        :class:`dynid.identification.pipeline.IdentificationPipeline`, None where :func:`identify` is called alone.
    sdp_refits : tuple of (n_base,) arrays
        The physically consistent estimate refitted on all blocks of the log but one (``identify(jackknife=True)``);
        empty otherwise.
    """

    robot: str
    base: BaseParameters
    estimators: tuple[str, ...]
    least_squares: str
    solution: LeastSquaresSolution
    joint_std: np.ndarray
    estimates: dict
    references: tuple[ReferenceSet, ...]
    fit: TorqueComparison
    validations: tuple[TorqueComparison, ...] = ()
    n_rows: int = 0
    settings: dict = field(default_factory=dict)
    warnings: tuple[str, ...] = ()
    consistency: dict = field(default_factory=dict)
    consistency_verdicts: dict = field(default_factory=dict)
    objective: dict = field(default_factory=dict)
    box: np.ndarray | None = None
    drive_gains: Any = None
    model: Robot | None = None
    findings: tuple = ()
    diagnostics: dict = field(default_factory=dict)
    main: str = ""
    drive_only: DriveOnly | None = None
    choices: Any = None
    sdp_refits: tuple = ()

    @property
    def label(self) -> str:
        """Label of the least-squares estimate (``"dynid WLS"``)."""
        return estimate_label(self.least_squares)

    @property
    def main_estimate(self) -> Estimate:
        """The estimate to trust (:attr:`main`)."""
        return self.estimates[self.main or estimate_label(self.estimators[0])]

    def __repr__(self) -> str:
        main = self.main or estimate_label(self.estimators[0])
        fit = self.fit.metrics().get(main, {}).get("global_relative_error") if self.fit is not None else None
        valid = [v.metrics()[main]["global_relative_error"] for v in self.validations if main in v.metrics()]
        parts = [f"robot={self.robot!r}", f"main={main!r}", f"estimates={list(self.estimates)}", f"rows={self.n_rows}"]
        parts += [f"fit {fit:.3g} %"] if fit is not None else []
        parts += [f"validation {np.mean(valid):.3g} % ({len(valid)} log{'s' * (len(valid) != 1)})"] if valid else []
        return f"IdentificationResult({', '.join(parts)}, {len(self.findings)} findings)"

    def summary(self) -> str:
        """A few lines: what :func:`repr` says, the verdict's first findings and the main estimate's base parameters
        (the terminal's whole text: :func:`dynid.report.summaries.summary`).

        Returns
        -------
        str
        """
        main = self.main_estimate
        findings = [textwrap.fill(f.text, 100, initial_indent="  ", subsequent_indent="    ") for f in self.findings[:3]]
        return "\n".join([repr(self), *findings, repr(Parameters(self.base.names, main.params, main.std, units=tuple(map(self.base.unit, self.base.names))))])

    def parameter_sets(self) -> dict:
        """Every parameter set compared: dynid's estimates, then each reference set.

        Returns
        -------
        dict
            label -> (n_base,) base parameter vector.
        """
        return {**{label: e.params for label, e in self.estimates.items()}, **{r.name: r.beta for r in self.references}}

    def reference_agreement(self, ref: ReferenceSet) -> dict:
        """Differences of the least-squares estimate to a reference that states relative standard deviations.

        Parameters
        ----------
        ref : ReferenceSet

        Returns
        -------
        dict
            ``z = |Δ| / σ_ref`` per base parameter and how many lie within 1, 2 and 3 σ.
        """
        sigma = np.abs(ref.beta) * ref.relative_std / 100.0
        diff = self.solution.params - ref.beta
        with np.errstate(divide="ignore", invalid="ignore"):
            z = np.abs(diff) / sigma
        ok = np.isfinite(z)
        return {"z": z, "within_1_sigma": int(np.sum(z[ok] <= 1)), "within_2_sigma": int(np.sum(z[ok] <= 2)),
                "within_3_sigma": int(np.sum(z[ok] <= 3)), "compared": int(ok.sum())}

    def to_dict(self) -> dict:
        """The result as results.json stores it (read back by :func:`dynid.load_results`).

        Returns
        -------
        dict
        """
        sol = self.solution
        params = [{"name": n, "value": float(v), "std": float(s), "relative_std_percent": float(r), "unit": self.base.unit(n),
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
            "robot": self.robot, "estimators": list(self.estimators), "least_squares": self.least_squares,
            "base_parameters": params,
            "condition_number": sol.condition_number, "residual_std": sol.residual_std,
            "joint_residual_std": self.joint_std, "n_rows": self.n_rows, "settings": self.settings,
            "identification": self.fit.to_dict(), "validation": [v.to_dict() for v in self.validations],
            "references": refs, "warnings": list(self.warnings),
            "consistency_margin": self.consistency, "physically_consistent_verdict": self.consistency_verdicts,
            "estimates": {label: e.to_dict(self.base) for label, e in self.estimates.items()},
            "objective_eq9": self.objective, "main_estimate": self.main or estimate_label(self.estimators[0]),
            "findings": [f.to_dict() for f in self.findings], "diagnostics": self.diagnostics,
            **({} if self.drive_gains is None else {"drive_gains": self.drive_gains.to_dict()}),
            **({} if self.box is None else {"search_box": {"rule": f"estimate ± ({BOX_SIGMAS:g}·σ + {BOX_FRACTION:g}·|estimate|)",
                                                            "bounds": dict(zip(self.base.names, self.box.tolist()))}}),
        }

"""Measured against predicted torques on the same preprocessed samples: per-joint relative error, RMSE,
correlation coefficient (eq. 18) and the global relative error, for any number of parameter sets."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..dynamics.base_parameters import BaseParameters
from ..model.robot import Robot
from ..preprocessing.pipeline import PreparedData, base_chunks
from ..tables import TextTable
from .metrics import correlation_coefficient, global_relative_error, relative_error, rmse

__all__ = ["TorqueComparison", "TorqueSums", "compare_torques", "comparison_table"]


@dataclass(frozen=True)
class TorqueComparison:
    """Measured and predicted torques of one dataset (decimated), with per-joint metrics.

    Attributes
    ----------
    name : str
    t : (M,) array [s]
    measured : (M, n_dof) array [N·m]
    predicted : dict label -> (M, n_dof) array
    """

    name: str
    t: np.ndarray
    measured: np.ndarray
    predicted: dict
    summary: dict | None = None
    """From :class:`TorqueSums`: the metrics, sample count and RMS torque of all samples, while ``t``,
    ``measured`` and ``predicted`` hold only the samples a figure draws."""

    def metrics(self) -> dict:
        """label -> {relative_error [%], rmse [N·m], correlation (eq. 18)}, each (n_dof,), and
        global_relative_error [%] over all joints and samples (a float)."""
        if self.summary is not None:
            return self.summary["metrics"]
        return {label: {"relative_error": relative_error(self.measured, p), "rmse": rmse(self.measured, p),
                        "correlation": correlation_coefficient(self.measured, p),
                        "global_relative_error": global_relative_error(self.measured, p)}
                for label, p in self.predicted.items()}

    @property
    def n_samples(self) -> int:
        return int(self.summary["n_samples"]) if self.summary is not None else int(self.t.shape[0])

    @property
    def rms_torque(self) -> np.ndarray:
        return self.summary["rms_torque"] if self.summary is not None else np.sqrt((self.measured**2).mean(axis=0))

    def to_dict(self) -> dict:
        return {"name": self.name, "n_samples": self.n_samples, "rms_torque": self.rms_torque, "metrics": self.metrics()}


class TorqueSums:
    """Per-joint sums of a dataset's decimated regressor rows and torques, from which the metrics of any
    parameter vector follow exactly (to round-off) without a second pass over the log: with the joint's
    rows ``Y``, torques ``τ`` and prediction ``Yβ``, ``‖τ - Yβ‖² = τ·τ - 2β·Yᵀτ + β·YᵀYβ``, and the sums of
    eq. 18 are ``β·Yᵀτ``, ``β·YᵀYβ``, ``Σ Y β`` and ``Σ τ``. Memory: n_dof Gram matrices, whatever the
    log's length, plus the rows a figure draws (every ``thin``-th).

    Parameters
    ----------
    n_dof, n_columns : int
    n_rows : int
        Decimated samples the dataset will give (for the figure's thinning, as :func:`dynid.report.figures`).
    max_points : int
        Samples a figure draws at most.
    """

    def __init__(self, n_dof: int, n_columns: int, n_rows: int, max_points: int = 2500):
        self.gram = np.zeros((n_dof, n_columns, n_columns))
        self.cross = np.zeros((n_dof, n_columns))
        self.col_sum = np.zeros((n_dof, n_columns))
        self.tau_sq = np.zeros(n_dof)
        self.tau_sum = np.zeros(n_dof)
        self.count = 0
        self.thin = max(1, -(-n_rows // max_points))
        self.kept_t, self.kept_y, self.kept_tau = [], [], []

    def add(self, t: np.ndarray, y: np.ndarray, tau: np.ndarray) -> None:
        """Rows ``y`` (M, n_dof, n_columns), torques ``tau`` (M, n_dof) at times ``t`` (M,)."""
        self.gram += np.einsum("mjc,mjd->jcd", y, y)
        self.cross += np.einsum("mjc,mj->jc", y, tau)
        self.col_sum += y.sum(axis=0)
        self.tau_sq += (tau**2).sum(axis=0)
        self.tau_sum += tau.sum(axis=0)
        first = (-self.count) % self.thin  # rows count, count+1, …: keep those at multiples of thin
        self.kept_t.append(t[first::self.thin])
        self.kept_y.append(y[first::self.thin])
        self.kept_tau.append(tau[first::self.thin])
        self.count += y.shape[0]

    def comparison(self, name: str, parameter_sets: dict) -> TorqueComparison:
        """The dataset's :class:`TorqueComparison`: metrics from the sums, curves on the kept rows."""
        n = self.count
        metrics = {}
        for label, beta in parameter_sets.items():
            b = np.asarray(beta, dtype=float)
            pp = np.einsum("c,jcd,d->j", b, self.gram, b)  # Σ τ̂²
            mp = self.cross @ b  # Σ τ τ̂
            sse = np.maximum(self.tau_sq - 2 * mp + pp, 0.0)
            p_sum = self.col_sum @ b
            cov = mp - self.tau_sum * p_sum / n
            var_m = self.tau_sq - self.tau_sum**2 / n
            var_p = pp - p_sum**2 / n
            metrics[label] = {"relative_error": 100.0 * np.sqrt(sse / self.tau_sq), "rmse": np.sqrt(sse / n),
                              "correlation": cov / np.sqrt(var_m * var_p),
                              "global_relative_error": float(100.0 * np.sqrt(sse.sum() / self.tau_sq.sum()))}
        y = np.concatenate(self.kept_y)
        summary = {"metrics": metrics, "n_samples": n, "rms_torque": np.sqrt(self.tau_sq / n)}
        return TorqueComparison(name, np.concatenate(self.kept_t), np.concatenate(self.kept_tau),
                                {label: y @ np.asarray(beta, dtype=float) for label, beta in parameter_sets.items()}, summary)


def compare_torques(robot: Robot, base: BaseParameters, data: PreparedData, parameter_sets: dict,
                    progress=None) -> TorqueComparison:
    """Predict the torques of ``data`` with each base parameter vector of ``parameter_sets`` (label ->
    (n_base,)), on the same parallel-decimated samples as the estimation."""
    ts, meas, preds = [], [], {k: [] for k in parameter_sets}
    for index, y, tau, _ in base_chunks(robot, base, data, progress):
        ts.append(data.t[index])
        meas.append(tau)
        for label, beta in parameter_sets.items():
            preds[label].append(y @ beta)
    return TorqueComparison(data.name, np.concatenate(ts), np.concatenate(meas),
                            {k: np.concatenate(v) for k, v in preds.items()})


def comparison_table(cmp: TorqueComparison) -> TextTable:
    """Relative error, RMSE and correlation coefficient per joint for every parameter set of ``cmp``: one
    label row per set, then one row per metric (narrow enough for 80 columns with six joints)."""
    rms = cmp.rms_torque
    n = cmp.measured.shape[1]
    rows, ends = [], set()
    for label, m in cmp.metrics().items():
        rows.append((label,) + ("",) * (n + 1))
        rows.append(("  error %", *(f"{x:.1f}" for x in m["relative_error"]), f"{m['global_relative_error']:.2f}"))
        rows.append(("  RMSE N·m", *(f"{x:.3g}" for x in m["rmse"]), ""))
        rows.append(("  ρ (eq. 18)", *(f"{x:.4f}" for x in m["correlation"]), ""))
        ends.add(len(rows) - 1)
    return TextTable(f"{cmp.name}: {cmp.n_samples} samples; RMS torque " + ", ".join(f"{x:.3g}" for x in rms) + " N·m",
                     ("parameters", *(f"J{j + 1}" for j in range(n)), "all"), tuple(rows), section_ends=frozenset(ends))

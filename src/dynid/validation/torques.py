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
    """Per-joint statistics of a dataset's decimated regressor rows and torques, from which the metrics of any
    parameter vector follow without a second pass over the log.

    Per joint it keeps the mean of ``z = (Y, τ)`` and its centred Gram matrix ``Σ (z - z̄)(z - z̄)ᵀ``, merged
    chunk by chunk with Chan, Golub & LeVeque's update (Am. Stat. 37(3), 1983), which stays accurate where
    raw sums would cancel (a log at rest: an almost constant prediction). With ``p = Yβ``: the centred sums of
    eq. 18 are ``βᵀS_YYβ``, ``βᵀS_Yτ`` and ``S_ττ``; ``‖τ - p‖² = S_ττ - 2βᵀS_Yτ + βᵀS_YYβ + N (τ̄ - Ȳβ)²``.
    Memory: n_dof matrices of (n_columns + 1)², whatever the log's length, plus the rows a figure draws
    (every ``thin``-th).

    Parameters
    ----------
    n_dof, n_columns : int
    n_rows : int
        Decimated samples the dataset will give (for the figure's thinning, as :func:`dynid.report.figures`).
    max_points : int
        Samples a figure draws at most.
    """

    def __init__(self, n_dof: int, n_columns: int, n_rows: int, max_points: int = 2500):
        self.mean = np.zeros((n_dof, n_columns + 1))
        self.m2 = np.zeros((n_dof, n_columns + 1, n_columns + 1))
        self.count = 0
        self.thin = max(1, -(-n_rows // max_points))
        self.kept_t, self.kept_y, self.kept_tau = [], [], []

    @classmethod
    def for_data(cls, data: PreparedData, n_columns: int) -> "TorqueSums":
        """Statistics for the decimated samples :func:`dynid.preprocessing.pipeline.base_chunks` gives of ``data``."""
        return cls(data.tau.shape[1], n_columns, len(range(0, data.t.shape[0], data.settings.decimation)))

    def add(self, t: np.ndarray, y: np.ndarray, tau: np.ndarray) -> None:
        """Rows ``y`` (M, n_dof, n_columns), torques ``tau`` (M, n_dof) at times ``t`` (M,)."""
        m = y.shape[0]
        z = np.concatenate([y, tau[:, :, None]], axis=2)
        mean = z.mean(axis=0)
        zc = z - mean
        m2 = np.einsum("mjc,mjd->jcd", zc, zc)
        n = self.count
        delta = mean - self.mean
        self.mean += delta * (m / (n + m))
        self.m2 += m2 + np.einsum("jc,jd->jcd", delta, delta) * (n * m / (n + m))
        first = (-n) % self.thin  # rows n, n+1, …: keep those at multiples of thin
        # copies of the kept rows: a slice would be a view that keeps the whole chunk alive, and the whole log with it
        self.kept_t.append(t[first::self.thin].copy())
        self.kept_y.append(y[first::self.thin].copy())
        self.kept_tau.append(tau[first::self.thin].copy())
        self.count = n + m

    def comparison(self, name: str, parameter_sets: dict) -> TorqueComparison:
        """The dataset's :class:`TorqueComparison`: metrics from the statistics, curves on the kept rows."""
        n = self.count
        s_yy, s_yt, s_tt = self.m2[:, :-1, :-1], self.m2[:, :-1, -1], self.m2[:, -1, -1]
        y_mean, t_mean = self.mean[:, :-1], self.mean[:, -1]
        tau_sq = s_tt + n * t_mean**2  # Σ τ²
        metrics = {}
        for label, beta in parameter_sets.items():
            b = np.asarray(beta, dtype=float)
            s_pp = np.einsum("c,jcd,d->j", b, s_yy, b)
            s_pt = s_yt @ b
            sse = np.maximum(s_tt - 2 * s_pt + s_pp, 0.0) + n * (t_mean - y_mean @ b) ** 2
            metrics[label] = {"relative_error": 100.0 * np.sqrt(sse / tau_sq), "rmse": np.sqrt(sse / n),
                              "correlation": s_pt / np.sqrt(s_tt * s_pp),
                              "global_relative_error": float(100.0 * np.sqrt(sse.sum() / tau_sq.sum()))}
        y = np.concatenate(self.kept_y)
        summary = {"metrics": metrics, "n_samples": n, "rms_torque": np.sqrt(tau_sq / n)}
        return TorqueComparison(name, np.concatenate(self.kept_t), np.concatenate(self.kept_tau),
                                {label: y @ np.asarray(beta, dtype=float) for label, beta in parameter_sets.items()}, summary)


def compare_torques(robot: Robot, base: BaseParameters, data: PreparedData, parameter_sets: dict,
                    progress=None) -> TorqueComparison:
    """Predict the torques of ``data`` with each base parameter vector of ``parameter_sets`` (label ->
    (n_base,)), on the same parallel-decimated samples as the estimation. The parameter sets are known
    before the pass, so the predictions are stored and the metrics computed from them directly (exact also
    for a log at rest, where a prediction is almost constant); :class:`TorqueSums` serves the fit, whose
    parameters come out of the same pass."""
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

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

__all__ = ["TorqueComparison", "compare_torques", "comparison_table"]


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

    def metrics(self) -> dict:
        """label -> {relative_error [%], rmse [N·m], correlation (eq. 18)}, each (n_dof,), and
        global_relative_error [%] over all joints and samples (a float)."""
        return {label: {"relative_error": relative_error(self.measured, p), "rmse": rmse(self.measured, p),
                        "correlation": correlation_coefficient(self.measured, p),
                        "global_relative_error": global_relative_error(self.measured, p)}
                for label, p in self.predicted.items()}

    def to_dict(self) -> dict:
        return {"name": self.name, "n_samples": int(self.t.shape[0]),
                "rms_torque": np.sqrt((self.measured**2).mean(axis=0)), "metrics": self.metrics()}


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
    rms = np.sqrt((cmp.measured**2).mean(axis=0))
    n = cmp.measured.shape[1]
    rows, ends = [], set()
    for label, m in cmp.metrics().items():
        rows.append((label,) + ("",) * (n + 1))
        rows.append(("  error %", *(f"{x:.1f}" for x in m["relative_error"]), f"{m['global_relative_error']:.2f}"))
        rows.append(("  RMSE N·m", *(f"{x:.3g}" for x in m["rmse"]), ""))
        rows.append(("  ρ (eq. 18)", *(f"{x:.4f}" for x in m["correlation"]), ""))
        ends.add(len(rows) - 1)
    return TextTable(f"{cmp.name}: {cmp.t.shape[0]} samples; RMS torque " + ", ".join(f"{x:.3g}" for x in rms) + " N·m",
                     ("parameters", *(f"J{j + 1}" for j in range(n)), "all"), tuple(rows), section_ends=frozenset(ends))

"""Per-joint agreement between measured and predicted torques."""

from __future__ import annotations

import numpy as np

from .._util.checks import check_same_length
from ..exceptions import ShapeError


def _pair(measured, predicted) -> tuple[np.ndarray, np.ndarray]:
    m = np.asarray(measured, dtype=float)
    p = np.asarray(predicted, dtype=float)
    if m.ndim == 1:
        m, p = m[:, None], p.reshape(-1, 1)
    if m.shape != p.shape:
        raise ShapeError(f"measured {m.shape} and predicted {p.shape} torques differ in shape")
    check_same_length(measured=m, predicted=p)
    return m, p


ROUND_OFF = 1e-7
"""A prediction whose standard deviation over the samples is below this fraction of its size does not vary: what is
left is rounding (e.g. a joint whose nominal torque is 0 in exact arithmetic, 4e-17 N·m in floating point), and its
correlation with anything is undefined. The size is the larger of the measured torque's spread and that of the
terms the prediction sums where they are known (:func:`correlation_from_sums`: their rounding floor is ``√ε ≈ 1.5e-8``
of it), else the prediction's RMS: a prediction that varies 1e-7 as much as what it predicts explains nothing of it."""


def correlation_from_sums(s_mp: np.ndarray, s_mm: np.ndarray, s_pp: np.ndarray, size: np.ndarray) -> np.ndarray:
    """Correlation coefficient (paper eq. 18) from centred sums; NaN where the prediction does not vary.

    Parameters
    ----------
    s_mp, s_mm, s_pp : (n_dof,) arrays
        ``Σ (m - m̄)(p - p̄)``, ``Σ (m - m̄)²``, ``Σ (p - p̄)²`` over the samples of each joint.
    size : (n_dof,) array
        The prediction's size in the units of ``s_pp``: where ``s_pp <= ROUND_OFF² · size`` its spread is rounding
        (:data:`ROUND_OFF`; ``s_mm`` when it is larger). For ``p = Y·β`` from centred column sums ``S``:
        ``(Σ_c |β_c| √S_cc)²``.

    Returns
    -------
    (n_dof,) ndarray
        ρ per joint, NaN where it is undefined (a prediction or a measurement that does not vary).
    """
    s_pp, s_mm = np.asarray(s_pp, dtype=float), np.asarray(s_mm, dtype=float)
    varies = s_pp > ROUND_OFF**2 * np.maximum(np.asarray(size, dtype=float), s_mm)
    with np.errstate(invalid="ignore", divide="ignore"):
        rho = np.asarray(s_mp, dtype=float) / np.sqrt(s_mm * s_pp)
    return np.where(varies, rho, np.nan)


def correlation_coefficient(measured, predicted) -> np.ndarray:
    """Correlation coefficient per joint (paper eq. 18); 1 is a perfect model.

    Parameters
    ----------
    measured, predicted : (N, n_dof) arrays [N·m]

    Returns
    -------
    (n_dof,) ndarray
        NaN for a joint whose prediction (or measurement) does not vary: a standard deviation below :data:`ROUND_OFF`
        times the prediction's RMS, or the measured torque's spread, is rounding, and no correlation is defined.
    """
    m, p = _pair(measured, predicted)
    mc, pc = m - m.mean(axis=0), p - p.mean(axis=0)
    return correlation_from_sums((mc * pc).sum(axis=0), (mc**2).sum(axis=0), (pc**2).sum(axis=0), (p**2).sum(axis=0))


def rmse(measured, predicted) -> np.ndarray:
    """Root-mean-square error per joint.

    Parameters
    ----------
    measured, predicted : (N, n_dof) arrays [N·m]

    Returns
    -------
    (n_dof,) ndarray [N·m]
    """
    m, p = _pair(measured, predicted)
    return np.sqrt(((m - p) ** 2).mean(axis=0))


def relative_error(measured, predicted) -> np.ndarray:
    """Relative error per joint, ``100·||tau - tau_p|| / ||tau||``.

    Parameters
    ----------
    measured, predicted : (N, n_dof) arrays [N·m]

    Returns
    -------
    (n_dof,) ndarray [%]
    """
    m, p = _pair(measured, predicted)
    return 100.0 * np.linalg.norm(m - p, axis=0) / np.linalg.norm(m, axis=0)


def global_relative_error(measured, predicted) -> float:
    """Relative error over all joints and samples, ``100·||tau - tau_p||_F / ||tau||_F``.

    Joints with large torques weigh more than in the per-joint :func:`relative_error`.

    Parameters
    ----------
    measured, predicted : (N, n_dof) arrays [N·m]

    Returns
    -------
    float [%]
    """
    m, p = _pair(measured, predicted)
    return float(100.0 * np.linalg.norm(m - p) / np.linalg.norm(m))

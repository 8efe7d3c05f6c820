"""Per-joint agreement between measured and predicted torques."""

from __future__ import annotations

import numpy as np

from ..checks import check_same_length
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


def correlation_coefficient(measured, predicted) -> np.ndarray:
    """Correlation coefficient per joint (paper eq. 18); 1 is a perfect model.

    Parameters
    ----------
    measured, predicted : (N, n_dof) arrays [N·m]

    Returns
    -------
    (n_dof,) ndarray
    """
    m, p = _pair(measured, predicted)
    mc, pc = m - m.mean(axis=0), p - p.mean(axis=0)
    return (mc * pc).sum(axis=0) / np.sqrt((mc**2).sum(axis=0) * (pc**2).sum(axis=0))


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

"""Instrumental variables: least squares whose regressor carries the noise of the measurements it is built from.

In closed loop the positions the observation matrix is computed from carry the loop's noise, which the controller
also turns into torque: the regressor and the residual are correlated and least squares is biased. Instruments ``Z``
correlated with the noise-free regressor and not with the noise (the observation matrix of a simulation driven by
the current estimate, Janot, Vandanjon & Gautier, IEEE TCST 22(1), 2014) give a consistent estimate

    β = (Zᵀ W)⁻¹ Zᵀ τ,   cov β = σ² (Zᵀ W)⁻¹ Zᵀ Z (Wᵀ Z)⁻¹,

(Söderström & Stoica, "Instrumental variable methods for system identification", Springer 1983, eq. 3.4 with
weighting 1).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..exceptions import IdentifiabilityError, ShapeError
from .base import check_observations

CLOSED_LOOP_METHODS = ("idim-iv", "didim")
"""Keys of the closed-loop estimators (:mod:`dynid.experiment.closed_loop`; case-insensitive): they need the
controller that drove the run (``[controller]`` of a config)."""


@dataclass(frozen=True)
class InstrumentalSolution:
    """An instrumental-variable estimate.

    Attributes
    ----------
    params : (p,) array
    params_std : (p,) array
    covariance : (p, p) array
    residual_std : float [N·m]
        ``‖τ − Wβ‖ / sqrt(M − p)`` on the rows given (weighted, when weighted).
    condition_number : float
        Of ``Zᵀ W``.
    """

    params: np.ndarray
    params_std: np.ndarray
    covariance: np.ndarray
    residual_std: float
    condition_number: float


def instrumental_variables(w, tau, z) -> InstrumentalSolution:
    """The simple instrumental-variable estimate with its covariance (module docstring).

    Parameters
    ----------
    w : (M, p) array
        Observation matrix built from the measurements.
    tau : (M,) array [N·m]
        Measured torques, same rows.
    z : (M, p) array
        Instruments, same rows: the observation matrix of a noise-free simulation.

    Returns
    -------
    InstrumentalSolution

    Raises
    ------
    ShapeError
        Shapes that do not match, or values that are not finite.
    IdentifiabilityError
        Fewer rows than parameters, or ``Zᵀ W`` singular (instruments that do not excite every parameter).
    """
    w, tau = check_observations(w, tau)
    z = np.asarray(z, dtype=float)
    if z.shape != w.shape:
        raise ShapeError(f"expected instruments Z with the shape of W {w.shape}, got {z.shape}")
    if not np.all(np.isfinite(z)):
        raise ShapeError("the instruments Z hold NaN or infinite values")
    m, p = w.shape
    if m <= p:
        raise IdentifiabilityError(f"instrumental variables: {m} rows for {p} parameters")
    zw = z.T @ w
    cond = float(np.linalg.cond(zw))
    if not np.isfinite(cond) or cond > 1e14:
        raise IdentifiabilityError(f"instrumental variables: ZᵀW is singular (condition number {cond:.3g})")
    params = np.linalg.solve(zw, z.T @ tau)
    residual = tau - w @ params
    sigma2 = float(residual @ residual) / (m - p)
    inverse = np.linalg.inv(zw)
    covariance = sigma2 * inverse @ (z.T @ z) @ inverse.T
    return InstrumentalSolution(params, np.sqrt(np.maximum(np.diag(covariance), 0.0)), covariance, float(np.sqrt(sigma2)), cond)

"""Design criteria of an excitation trajectory and their derivatives with respect to the base regressor.

Both take the stacked base observation matrix ``W_b`` (N·n_dof, n_base) and return the value and
``M = ∂f/∂W_b`` (same shape), from which the chain rule gives the gradient in any parametrisation:
``df = Σ M ∘ dW_b``.

- ``cond``: ``log cond(W_b) = log σ_max - log σ_min`` (paper eq. 15 minimises cond(Φ)); with the singular
  triplets, ``dσ = u^T dW v``, here from the eigenpairs of ``W_b^T W_b`` (Gautier & Khalil 1992; Swevers et al. 1997).
- ``d-optimal``: ``-log det(W_b^T W_b / N)``, the D-optimality criterion of the information matrix
  (Swevers et al., IEEE TRA 13(5), 1997); ``M = -2 W_b (W_b^T W_b)^{-1}``.
"""

from __future__ import annotations

import numpy as np

from ..exceptions import ConfigError

CRITERIA = ("cond", "d-optimal")


RESOLVED = 1e-10
"""The smallest eigenvalue of ``W^T W`` that it resolves, as a share of its largest: ``eigh`` holds each eigenvalue to
about 1e-16 of the largest, so one at 1e-10 of it to about 1e-6 of itself; below (cond W above 1e5), ``W``'s own
singular values."""


def log_condition_number(w: np.ndarray) -> tuple[float, np.ndarray]:
    """``log cond(W)`` and its derivative with respect to ``W``.

    From the extreme eigenpairs ``(λ, v)`` of ``W^T W`` (``σ² = λ``): ``d log σ = (W v)^T dW v / λ``.

    Parameters
    ----------
    w : (M, p) array

    Returns
    -------
    value : float
    gradient : (M, p) ndarray
    """
    lam, v = np.linalg.eigh(w.T @ w)
    if lam[0] <= lam[-1] * RESOLVED:  # beyond what W^T W resolves: the singular triplets of W itself
        u, s, vt = np.linalg.svd(w, full_matrices=False)
        if s[-1] <= s[0] * 1e-15:
            return float(np.log(1e15)), np.zeros_like(w)  # rank-deficient: flat, the constraints move on
        return float(np.log(s[0] / s[-1])), np.outer(u[:, 0], vt[0]) / s[0] - np.outer(u[:, -1], vt[-1]) / s[-1]
    grad = np.outer(w @ v[:, -1], v[:, -1]) / lam[-1] - np.outer(w @ v[:, 0], v[:, 0]) / lam[0]
    return float(0.5 * np.log(lam[-1] / lam[0])), grad


def neg_log_det_information(w: np.ndarray) -> tuple[float, np.ndarray]:
    """``-log det(W^T W / N)`` (N rows) and its derivative with respect to ``W``.

    Parameters
    ----------
    w : (M, p) array

    Returns
    -------
    value : float
    gradient : (M, p) ndarray
    """
    info = w.T @ w
    sign, logdet = np.linalg.slogdet(info / w.shape[0])
    if sign <= 0:
        return float(np.log(1e14) * w.shape[1]), np.zeros_like(w)
    return float(-logdet), -2.0 * np.linalg.solve(info, w.T).T


def criterion_function(name: str):
    """The criterion function of a design criterion.

    Parameters
    ----------
    name : str
        "cond" or "d-optimal".

    Returns
    -------
    callable
        ``f(W) -> (value, dvalue/dW)``.

    Raises
    ------
    ConfigError
        For another name.
    """
    if name == "cond":
        return log_condition_number
    if name == "d-optimal":
        return neg_log_det_information
    raise ConfigError(f"design.criterion must be one of {', '.join(CRITERIA)}, got {name!r}")

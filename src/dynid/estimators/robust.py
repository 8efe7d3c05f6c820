"""Iteratively reweighted least squares: a Huber M-estimator, robust to torque outliers.

Each iteration solves a weighted least-squares problem whose row weights come from the previous
residuals: with ``u = r / s_j`` (``s_j`` the robust scale ``1.4826 · MAD`` of joint ``j``'s residuals),
Huber's weight is ``min(1, c / |u|)`` with ``c = 1.345`` (95 % efficiency under Gaussian noise).
Rows with large residuals count less, which makes the estimate insensitive to spikes in the currents.
Ref.: P. J. Huber, "Robust Statistics", Wiley 1981, §7.8 (IRLS) and §7.6 (covariance);
P. W. Holland & R. E. Welsch, "Robust regression using iteratively reweighted least-squares", 1977.
"""

from __future__ import annotations

import numpy as np

from ..exceptions import ConfigError, IdentifiabilityError
from .base import Estimator, check_observations, infer_n_dof, weighted_rows

HUBER_C = 1.345
MAD_TO_STD = 1.4826


class IterativelyReweightedLeastSquares(Estimator):
    """IRLS with Huber weights and one robust scale per joint, started from OLS.

    The joints per sample in ``W``'s rows (row ``k·n_dof + j`` is joint ``j``) come to ``fit`` as
    ``problem=FitData(n_dof=...)``, else are inferred from tau given as (N, n_dof).

    Parameters
    ----------
    tuning : float
        Huber's ``c`` (default 1.345); ``inf`` gives per-joint weighted least squares.
    max_iter : int
    tol : float
        Stop when ``||Δp|| <= tol · ||p||``.

    Attributes
    ----------
    params_ : (p,) array
    covariance_ : (p, p) array
        Huber's sandwich ``(M/(M-p)) A⁻¹ B A⁻¹`` with ``A = Σ ψ'(u) w wᵀ / s²``, ``B = Σ ψ(u)² w wᵀ / s²``.
    params_std_, relative_std_ [%] : (p,) arrays
    joint_scale_ : (n_dof,) array
        Robust residual scale per joint [N·m].
    row_weights_ : (M,) array
        Huber weights of the last iteration (1 = full weight).
    n_iter_ : int
    converged_ : bool

    Raises
    ------
    IdentifiabilityError
        If ``W`` is rank-deficient.
    """

    PROBLEM_FIELDS = ("n_dof",)

    CONSTRAINTS = {"tuning": ("real", 1e-12, None), "max_iter": ("int", 1, 1_000_000), "tol": ("real", 0.0, None)}

    def __init__(self, *, tuning: float = HUBER_C, max_iter: int = 50, tol: float = 1e-8):
        self.tuning = tuning
        self.max_iter = max_iter
        self.tol = tol

    def fit(self, w, tau, sample_weight=None, *, problem=None) -> IterativelyReweightedLeastSquares:
        """Huber M-estimate by iteratively reweighted least squares, with its sandwich covariance.

        Parameters
        ----------
        w : (M, p) array
            Observation matrix, row ``k·n_dof + j`` = sample ``k``, joint ``j``.
        tau : (M,) or (N, n_dof) array [N·m]
        sample_weight : (M,) or (N, n_dof) array, optional
            One weight ≥ 0 per row of the squared loss (:func:`dynid.estimators.base.weighted_rows`).
        problem : FitData, optional
            Its ``n_dof``.

        Returns
        -------
        self

        Raises
        ------
        ConfigError
            A tuning constant that is not positive.
        IdentifiabilityError
            No more rows than parameters.
        """
        w, tau = weighted_rows(w, tau, sample_weight, self.loss_power)
        if not self.tuning > 0:
            raise ConfigError(f"IRLS tuning constant must be positive, got {self.tuning}")
        self.n_dof_ = infer_n_dof(self.take_problem(problem).n_dof, tau)
        w, tau = check_observations(w, tau, self.n_dof_)
        m, p = w.shape
        if m <= p:
            raise IdentifiabilityError(f"IRLS needs more equations than parameters, got {m} rows for {p} parameters")
        params = _weighted_solve(w, tau, np.ones(m))
        self.converged_ = False
        for it in range(1, self.max_iter + 1):  # noqa: B007 - the count is n_iter_
            u, scale = self._standardised(tau - w @ params)
            new = _weighted_solve(w, tau, self._huber_weights(u) / np.tile(scale, m // self.n_dof_) ** 2)
            step = np.linalg.norm(new - params)
            params = new
            if step <= self.tol * max(float(np.linalg.norm(params)), 1e-300):
                self.converged_ = True
                break
        self.n_iter_ = it
        u, scale = self._standardised(tau - w @ params)
        s_rows = np.tile(scale, m // self.n_dof_)
        psi = np.clip(u, -self.tuning, self.tuning)
        dpsi = (np.abs(u) <= self.tuning).astype(float)
        a = (w * (dpsi / s_rows**2)[:, None]).T @ w
        b = (w * (psi**2 / s_rows**2)[:, None]).T @ w
        a_inv = np.linalg.pinv(a)
        cov = m / (m - p) * a_inv @ b @ a_inv
        self.params_ = params
        self.covariance_ = cov
        self.params_std_ = np.sqrt(np.diag(cov))
        with np.errstate(divide="ignore", invalid="ignore"):
            self.relative_std_ = 100.0 * self.params_std_ / np.abs(params)
        self.joint_scale_ = scale
        self.row_weights_ = self._huber_weights(u)
        return self

    def _huber_weights(self, u: np.ndarray) -> np.ndarray:
        return np.minimum(1.0, self.tuning / np.maximum(np.abs(u), 1e-300))

    def _standardised(self, residual: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Residuals divided by their joint's robust scale, and the scales (n_dof,)."""
        r = residual.reshape(-1, self.n_dof_)
        scale = MAD_TO_STD * np.median(np.abs(r - np.median(r, axis=0)), axis=0)
        scale = np.where(scale > 0, scale, np.maximum(np.abs(r).max(axis=0), 1e-12))
        return (r / scale).ravel(), scale


def _weighted_solve(w: np.ndarray, tau: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """``argmin Σ weights_k (tau_k - W_k p)²`` by QR of the row-scaled problem."""
    sw = np.sqrt(weights)
    ws = w * sw[:, None]
    q, r = np.linalg.qr(ws, mode="reduced")
    sv = np.linalg.svd(r, compute_uv=False)
    if sv[-1] <= max(w.shape) * np.finfo(float).eps * sv[0]:
        raise IdentifiabilityError(f"observation matrix is rank-deficient (cond = {sv[0] / max(sv[-1], 1e-300):.3g}): "
                                   "use base parameters or a richer excitation")
    return np.linalg.solve(r, q.T @ (tau * sw))

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
from .least_squares import OrdinaryLeastSquares

CLOSED_LOOP_METHODS = ("idim-iv", "didim", "didim-sdp")
"""Keys of the closed-loop estimators (:mod:`dynid.identification.closed_loop_estimators`; case-insensitive): they need the
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


def newey_west_lags(n_instants: int) -> int:
    """Lags of :func:`long_run_covariance` for a log of ``n_instants`` rows in time: ``⌊4 (T/100)^(2/9)⌋``
    (Newey & West, "Automatic lag selection in covariance matrix estimation", Rev. Econ. Stud. 61(4), 1994, the
    Bartlett kernel's rule of thumb).

    Parameters
    ----------
    n_instants : int

    Returns
    -------
    int
        At least 1.
    """
    return max(1, int(4 * (max(n_instants, 1) / 100) ** (2 / 9)))


def parzen_lags(n_instants: int) -> int:
    """Lags of :func:`long_run_covariance` with the Parzen kernel for a log of ``n_instants`` rows in time: a fiftieth
    of the log (a fixed fraction of the sample, Kiefer & Vogelsang, "A new asymptotic theory for
    heteroskedasticity-autocorrelation robust tests", Econometric Theory 21(6), 2005), and at least twice
    :func:`newey_west_lags` (the Parzen window weighs a lag ``l`` less than Bartlett's of the same ``L``).

    A log filtered above its excitation band leaves a residual whose noise is blue (differentiated encoder noise up to
    the cutoff): its autocorrelations are negative over several samples and cancel in the sum of the scores, whose
    instruments live below the band. Newey–West's few lags cannot see the cancellation: on the ER-16 closed-loop study
    with 30 Hz cutoffs (1,908 instants, 40 realisations) their σ was 2.7-3.3 times the estimates' spread; with these
    lags and the Parzen kernel 0.96-1.13 times it (medians over the base parameters), and 0.89-0.91 with the
    default filter (161 instants; Newey–West's 0.91-0.94).

    Parameters
    ----------
    n_instants : int

    Returns
    -------
    int
        At least 2.
    """
    return max(2 * newey_west_lags(n_instants), int(n_instants) // 50)


KERNELS = ("bartlett", "parzen")
"""Lag windows of :func:`long_run_covariance`."""

_FFT_ABOVE = 64
"""Lags above which :func:`long_run_covariance` sums the lags in the frequency domain (the same sum)."""


def _lag_weights(lags: int, kernel: str) -> np.ndarray:
    """``k(l / (L + 1))`` for ``l = 0..L``: Bartlett ``1 − x``; Parzen ``1 − 6x² + 6x³`` (x ≤ ½), ``2 (1 − x)³``."""
    x = np.arange(lags + 1) / (lags + 1.0)
    if kernel == "bartlett":
        return 1.0 - x
    return np.where(x <= 0.5, 1.0 - 6.0 * x**2 + 6.0 * x**3, 2.0 * (1.0 - x) ** 3)


def long_run_covariance(scores, instants, lags: int | None = None, kernel: str = "bartlett") -> np.ndarray:
    """The covariance of a sum of scores correlated in time: a kernel estimate (Newey–West's with the Bartlett kernel).

    The rows of one instant (one per joint) are summed first (the loop's noise couples the joints), then
    ``S = Γ₀ + Σ_{l=1}^{L} k(l/(L+1)) (Γ_l + Γ_lᵀ)``, ``Γ_l = Σ_k g_k g_{k−l}ᵀ`` over the instants, a missing instant
    counting zero (Newey & West, Econometrica 55(3), 1987; the Parzen kernel: Andrews, Econometrica 59(3), 1991). Both
    windows keep ``S`` positive semi-definite. Filtered and decimated residuals are neither white nor independent
    between joints, which the textbook ``σ² (WᵀW)⁻¹`` assumes. Above 64 lags the sum is taken by FFT (the same sum, to
    rounding).

    Parameters
    ----------
    scores : (M, p) array
        One row's contribution to the estimating equation, e.g. ``z_i e_i`` (instrument row times residual).
    instants : (M,) int array
        The instant (row in time, 0-based) of each row.
    lags : int, optional
        ``L``; default :func:`newey_west_lags` (Bartlett) or :func:`parzen_lags` (Parzen) of the number of instants.
    kernel : {"bartlett", "parzen"}

    Returns
    -------
    (p, p) array
        Symmetric, positive semi-definite.

    Raises
    ------
    ShapeError
        ``instants`` not one non-negative integer per row.
    ValueError
        An unknown kernel.
    """
    if kernel not in KERNELS:
        raise ValueError(f"kernel: expected one of {', '.join(KERNELS)}, got {kernel!r}")
    scores = np.asarray(scores, dtype=float)
    instants = np.asarray(instants)
    if scores.ndim != 2 or instants.shape != (scores.shape[0],) or (instants.size and instants.min() < 0):
        raise ShapeError(f"expected one non-negative instant per score row ({scores.shape[0]}), got shape {instants.shape}")
    n_instants = int(instants.max()) + 1 if instants.size else 0
    g = np.zeros((n_instants, scores.shape[1]))
    np.add.at(g, instants.astype(int), scores)
    if lags is None:
        lags = newey_west_lags(n_instants) if kernel == "bartlett" else parzen_lags(n_instants)
    weights = _lag_weights(int(lags), kernel)
    used = min(int(lags), max(n_instants - 1, 0))
    if used > _FFT_ABOVE:
        return _long_run_covariance_fft(g, weights[: used + 1])
    total = g.T @ g
    for lag in range(1, used + 1):
        gamma = g[lag:].T @ g[:-lag]
        total += weights[lag] * (gamma + gamma.T)
    return total


def _long_run_covariance_fft(g: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """``Σ_{|l|≤L} k_l Γ_l`` by the circular correlation of ``g`` padded to at least ``T + L`` (no lag wraps onto
    another), weighted by the window's transform: ``(1/n) Σ_f K(f) G(f) G(f)ᴴ``."""
    from scipy.fft import next_fast_len, rfft

    lags = weights.size - 1
    n = next_fast_len(g.shape[0] + lags + 1, real=True)
    window = np.zeros(n)
    window[: lags + 1] = weights
    window[n - lags:] = weights[1:][::-1]
    k = rfft(window).real
    spectrum = rfft(g, n, axis=0)
    factor = np.full(k.size, 2.0)
    factor[0] = 1.0
    if n % 2 == 0:
        factor[-1] = 1.0
    weighted = spectrum * (factor * k)[:, None]
    total = (weighted.T @ spectrum.conj()).real / n
    return 0.5 * (total + total.T)


def instrumental_variables(w, tau, z, instants=None, kernel: str = "bartlett") -> InstrumentalSolution:
    """The simple instrumental-variable estimate with its covariance (module docstring).

    With ``instants`` the covariance is the sandwich ``(ZᵀW)⁻¹ S (WᵀZ)⁻¹`` with ``S`` the long-run covariance of the
    scores ``z_i e_i`` (:func:`long_run_covariance` with ``kernel`` and its default lags), for residuals correlated in
    time and between joints.

    Parameters
    ----------
    w : (M, p) array
        Observation matrix built from the measurements.
    tau : (M,) array [N·m]
        Measured torques, same rows.
    z : (M, p) array
        Instruments, same rows: the observation matrix of a noise-free simulation.
    instants : (M,) int array, optional
        The instant of each row (rows of one instant: one per joint); default: rows independent, ``σ²`` formula.
    kernel : {"bartlett", "parzen"}
        The lag window of the sandwich (with ``instants``).

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
    middle = sigma2 * (z.T @ z) if instants is None else long_run_covariance(z * residual[:, None], instants, kernel=kernel)
    covariance = inverse @ middle @ inverse.T
    return InstrumentalSolution(params, np.sqrt(np.maximum(np.diag(covariance), 0.0)), covariance, float(np.sqrt(sigma2)), cond)


def weighted_least_squares(w, tau, row_sigma, instants=None, kernel: str = "parzen") -> tuple[np.ndarray, np.ndarray]:
    """Weighted least squares with its standard deviations, the estimate the closed-loop estimators start from and
    DIDIM's step (:mod:`dynid.identification.closed_loop_estimators`).

    The estimate is the package's :class:`~dynid.estimators.least_squares.OrdinaryLeastSquares` with the weights
    ``1/σ²``; its σ is the textbook ``σ² (AᵀA)⁻¹`` of the scaled rows ``A = W/σ``, or with ``instants`` the sandwich
    ``(AᵀA)⁻¹ S (AᵀA)⁻¹`` whose middle ``S`` is the long-run covariance of the scores ``a_i r_i``
    (:func:`long_run_covariance` with ``kernel``), for residuals correlated in time and between joints.

    Parameters
    ----------
    w : (M, p) array
        Observation matrix.
    tau : (M,) array [N·m]
        Torques, same rows.
    row_sigma : (M,) array [N·m]
        Each row's noise standard deviation; ``inf`` leaves a row out.
    instants : (M,) int array, optional
        The instant of each row; default: rows independent.
    kernel : {"bartlett", "parzen"}
        The lag window of the sandwich (with ``instants``).

    Returns
    -------
    params : (p,) array
    params_std : (p,) array

    Raises
    ------
    ShapeError
        Shapes that do not match, or values that are not finite.
    """
    fit = OrdinaryLeastSquares().fit(w, tau, sample_weight=row_sigma**-2.0)
    if instants is None:
        return fit.params_, fit.params_std_
    a = w / row_sigma[:, None]
    r = tau / row_sigma - a @ fit.params_
    inverse = np.linalg.pinv(a.T @ a)
    cov = inverse @ long_run_covariance(a * r[:, None], instants, kernel=kernel) @ inverse
    return fit.params_, np.sqrt(np.maximum(np.diag(cov), 0.0))

"""Least squares accumulated chunk by chunk (incremental QR), so memory does not grow with the data.

For each joint ``j`` the rows of ``[W | tau]`` that belong to it are folded into an upper-triangular
factor ``R_j`` of size (p+1, p+1): ``R_j ← qr([R_j; W_j | tau_j])``. Since ``Q`` is orthogonal, every
least-squares quantity follows from the factors alone: stacking ``R_j / sigma_j`` and one more QR
gives the OLS (all ``sigma_j = 1``) or WLS solution, its residual sum of squares (the last diagonal
entry squared), its covariance, and each joint's residual ``||R_j [theta; -1]||``.
Ref.: Golub & Van Loan, "Matrix Computations", §6.5 (updating QR); Gautier & Poignet 2001 (WLS).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._util.reprs import short_repr
from ..exceptions import IdentifiabilityError, ShapeError


@short_repr
@dataclass(frozen=True)
class LeastSquaresSolution:
    """Solution of an accumulated (weighted) least-squares problem.

    Attributes
    ----------
    params : (p,) array
    covariance : (p, p) array
        ``sigma² (WᵀW)⁻¹`` of the (weighted) problem, ``sigma² = ||r||² / (M - p)``.
    params_std : (p,) array
    relative_std : (p,) array [%]
    condition_number : float
        cond of the (weighted) observation matrix.
    residual_std : float
        ``sigma`` of the (weighted) residual.
    n_rows : int
    from_prior : tuple of int
        Parameters the rows do not determine, whose values are the prior's (σ NaN).
    anchored : tuple of int
        The free member of each anchored pair that took the pair's determined combination
        (:meth:`LeastSquaresAccumulator.solve`'s ``pairs``).
    """

    params: np.ndarray
    covariance: np.ndarray
    params_std: np.ndarray
    relative_std: np.ndarray
    condition_number: float
    residual_std: float
    n_rows: int
    from_prior: tuple[int, ...] = ()
    """Parameters the rows do not determine, whose values are the prior's (their σ is NaN: not known)."""
    anchored: tuple[int, ...] = ()
    """The free member of each anchored pair (:meth:`LeastSquaresAccumulator.solve`'s ``pairs``) that took the pair's
    determined combination, its partner keeping the prior."""


UNDETERMINED_RCOND = 1e-10
"""With a prior, directions of the column-scaled observation matrix whose singular value is below this fraction of
the largest are left at the prior (:meth:`LeastSquaresAccumulator.solve`)."""

ZERO_COLUMN = 1e-10
"""With a prior, a column of the observation matrix whose norm is below this fraction of the largest column's is
numerically zero: the parameter acts on no row the log keeps (e.g. a link's inertia that only a dead torque channel's
joint feels), and rounding alone gives its column; it is left at the prior, not scaled up to unit norm with the
others and "determined" with a σ of 1e15 (:meth:`LeastSquaresAccumulator.solve`)."""

ANCHOR_RELATIVE_STD = 0.1
"""An anchored pair (:meth:`LeastSquaresAccumulator.solve`'s ``pairs``) whose one determined combination has a σ at most
this fraction of its value gives that combination to its free member."""


class LeastSquaresAccumulator:
    """Incremental QR of ``[W | tau]``, one triangular factor per joint.

    Parameters
    ----------
    n_params : int
    n_dof : int
        Rows of ``W`` come in groups of ``n_dof`` (row ``k·n_dof + j`` is sample ``k``, joint ``j``).
    """

    def __init__(self, n_params: int, n_dof: int = 1):
        self.n_params = int(n_params)
        self.n_dof = int(n_dof)
        self.factors = np.zeros((self.n_dof, self.n_params + 1, self.n_params + 1))
        self.rows = np.zeros(self.n_dof, dtype=np.int64)

    def add(self, w, tau, mask=None) -> None:
        """Fold in a chunk of rows.

        Parameters
        ----------
        w : (M, p) array
            Observation matrix rows, M a whole number of samples (n_dof rows each).
        tau : (M,) array [N·m]
        mask : (M,) bool array, optional
            Rows to keep.

        Raises
        ------
        ShapeError
            Wrong shapes, rows not a whole number of samples, or non-finite values.
        """
        w = np.asarray(w, dtype=float)
        tau = np.asarray(tau, dtype=float).reshape(-1)
        if w.ndim != 2 or w.shape[1] != self.n_params or w.shape[0] != tau.shape[0] or w.shape[0] % self.n_dof:
            raise ShapeError(f"expected W (M, {self.n_params}) and tau (M,) with M a multiple of {self.n_dof}, got {w.shape} and {tau.shape}")
        if not (np.all(np.isfinite(w)) and np.all(np.isfinite(tau))):
            raise ShapeError("W or tau holds NaN or infinite values")
        keep = np.ones(tau.shape[0], dtype=bool) if mask is None else np.asarray(mask, dtype=bool).reshape(-1)
        for j in range(self.n_dof):
            sel = keep[j::self.n_dof]
            if not sel.any():
                continue
            block = np.column_stack([w[j::self.n_dof][sel], tau[j::self.n_dof][sel]])
            self.factors[j] = _triangular(np.vstack([self.factors[j], block]), self.n_params + 1)
            self.rows[j] += int(sel.sum())

    @classmethod
    def merged(cls, accumulators) -> LeastSquaresAccumulator:
        """One accumulator holding the rows of several (the same sizes).

        Parameters
        ----------
        accumulators : iterable of LeastSquaresAccumulator

        Returns
        -------
        LeastSquaresAccumulator
        """
        first = accumulators[0]
        out = cls(first.n_params, first.n_dof)
        for j in range(out.n_dof):
            out.factors[j] = _triangular(np.vstack([a.factors[j] for a in accumulators]), out.n_params + 1)
        out.rows = sum(a.rows for a in accumulators)
        return out

    def joint_residual_sumsq(self, params: np.ndarray) -> np.ndarray:
        """Residual sum of squares of each joint, ``||tau_j - W_j params||²``.

        Parameters
        ----------
        params : (p,) array

        Returns
        -------
        (n_dof,) ndarray [N²·m²]
        """
        x = np.append(np.asarray(params, dtype=float), -1.0)
        return np.array([float(np.sum((f @ x) ** 2)) for f in self.factors])

    def joint_residual_std(self, params: np.ndarray) -> np.ndarray:
        """Residual standard deviation of each joint, ``sqrt(||r_j||² / (M_j - p/n_dof))``.

        Parameters
        ----------
        params : (p,) array

        Returns
        -------
        (n_dof,) ndarray [N·m]
        """
        dof = np.maximum(self.rows - self.n_params / self.n_dof, 1.0)
        return np.sqrt(self.joint_residual_sumsq(params) / dof)

    def reduced(self, joint_weights=None) -> np.ndarray:
        """Triangular factor of the (weighted) problem, valid for a rank-deficient ``W`` too.

        ``||D(τ - Wθ)||² = ||z - Rθ||² + ρ²`` with ``R = [:p, :p]``, ``z = [:p, p]`` and ``ρ = [p, p]``.

        Parameters
        ----------
        joint_weights : (n_dof,) array, optional
            ``D``: rows of joint ``j`` multiplied by ``joint_weights[j]`` (ones by default).

        Returns
        -------
        (p+1, p+1) ndarray
            ``[R | z]`` upper triangular.
        """
        wts = np.ones(self.n_dof) if joint_weights is None else np.asarray(joint_weights, dtype=float)
        return _triangular(np.vstack([f * wj for f, wj in zip(self.factors, wts)]), self.n_params + 1)

    def solve(self, joint_weights=None, rcond: float | None = None, names=None, prior=None,
              pairs=(), gaussian=None) -> LeastSquaresSolution:
        """OLS (default) or WLS with one weight per joint.

        Where the rows do not determine every parameter (a rank-deficient observation matrix) and a ``prior`` is given,
        the directions they determine are estimated and the others keep the prior's values: the least-squares
        correction of the prior within the determined subspace of the column-scaled problem (truncated SVD about
        the prior; Gautier's base parameters with a prior, e.g. Hansen, *Rank-Deficient and Discrete Ill-Posed
        Problems*, SIAM 1998, §3.2). A full-rank problem is solved as without a prior.

        Parameters
        ----------
        joint_weights : (n_dof,) array, optional
            Rows of joint ``j`` multiplied by ``joint_weights[j]``.
        rcond : float, optional
            Relative singular-value threshold of the rank test.
        names : sequence of str, optional
            (p,) names of the parameters, to name the unexcited ones in the error.
        prior : (p,) array, optional
            Values kept where the rows say nothing (the description's nominal parameters).
        pairs : sequence of (int, int)
            ``(free, anchored)`` parameter indices (with a prior only), as above.
        gaussian : ((p,) array, (p,) array), optional
            ``(values, sigmas)``: a Gaussian prior on the parameters whose σ is finite (a drive's data sheet), as
            :meth:`solve_affine`'s (the maximum a posteriori estimate).

        Returns
        -------
        LeastSquaresSolution
            Parameters, their covariance and the residuals; :attr:`LeastSquaresSolution.from_prior` lists the
            parameters left at the prior (σ NaN).

        Raises
        ------
        IdentifiabilityError
            Fewer rows than parameters, or a rank-deficient observation matrix without a prior.
        """
        p = self.n_params
        m = int(self.rows.sum())
        if m <= p:
            raise IdentifiabilityError(f"least squares needs more equations than parameters, got {m} rows for {p} parameters")
        r_all = self.reduced(joint_weights)
        r, rhs, rho = r_all[:p, :p], r_all[:p, p], abs(r_all[p, p])
        _, sv, vt = np.linalg.svd(r)
        tol = rcond if rcond is not None else max(m, p) * np.finfo(float).eps
        if sv[-1] <= tol * sv[0]:
            if prior is not None:
                sol = _about_prior(r, rhs, rho, m, np.asarray(prior, dtype=float), pairs)
                return _with_gaussian(r, rhs, rho, m, prior=np.asarray(prior, dtype=float), pairs=pairs, sol=sol,
                                      gaussian=gaussian)
            weak = _weak(vt[sv <= tol * sv[0]])
            what = (", ".join(str(names[i]) for i in np.flatnonzero(weak)) if names is not None
                    else f"{int(weak.sum())} parameter(s)")
            raise IdentifiabilityError(f"the data do not excite {what} (cond = {sv[0] / max(sv[-1], 1e-300):.3g}): "
                                       "a richer excitation, or a longer log, is needed")
        sol = _full_rank(r, rhs, rho, m, sv)
        return _with_gaussian(r, rhs, rho, m, prior=sol.params if prior is None else np.asarray(prior, dtype=float),
                              pairs=pairs, sol=sol, gaussian=gaussian)

    def solve_affine(self, basis, offset, joint_weights=None, prior=None, pairs=(),
                     gaussian=None) -> tuple[np.ndarray, np.ndarray, LeastSquaresSolution]:
        """Least squares over an affine subset of the parameters, ``params = offset + basis @ x``.

        The parameters of a model whose other terms are fixed (e.g. the description's rigid body with only the drive
        terms fitted): ``x`` solves ``min ||D(τ - W (offset + basis x))||²`` as :meth:`solve` does, with the
        undetermined directions of ``x`` at ``prior`` and the same ``pairs`` rule.

        Parameters
        ----------
        basis : (p, d) array
        offset : (p,) array
        joint_weights : (n_dof,) array, optional
            As :meth:`solve`.
        prior : (d,) array, optional
            Values of ``x`` kept where the rows say nothing (zeros by default).
        pairs : sequence of (int, int)
            ``(free, anchored)`` indices of ``x``, as :meth:`solve`.
        gaussian : ((d,) array, (d,) array), optional
            ``(values, sigmas)``: a Gaussian prior on the entries of ``x`` whose σ is finite (a drive's data sheet), as
            rows ``(s/σ_i)·(x_i - value_i)`` beside the data's, ``s`` the residual σ of the fit without them (so the
            rows weigh as ``1/σ_i²`` against the data's ``1/s²``: the maximum a posteriori estimate).

        Returns
        -------
        params : (p,) ndarray
        covariance : (p, p) ndarray
            ``basis · cov(x) · basisᵀ``.
        solution : LeastSquaresSolution
            Of ``x``.

        Raises
        ------
        IdentifiabilityError
            No more rows than columns of ``basis``.
        """
        basis = np.asarray(basis, dtype=float)
        offset = np.asarray(offset, dtype=float)
        p, d = basis.shape
        m = int(self.rows.sum())
        if m <= d:
            raise IdentifiabilityError(f"least squares needs more equations than parameters, got {m} rows for {d} parameters")
        r_all = self.reduced(joint_weights)
        r, z, rho = r_all[:p, :p], r_all[:p, p], abs(r_all[p, p])
        prior = np.zeros(d) if prior is None else np.asarray(prior, dtype=float)
        a, b = r @ basis, z - r @ offset
        sol = _with_gaussian(a, b, rho, m, prior=prior, pairs=pairs, sol=_about_prior(a, b, rho, m, prior, pairs),
                             gaussian=gaussian)
        return offset + basis @ sol.params, basis @ sol.covariance @ basis.T, sol


def _with_gaussian(a: np.ndarray, b: np.ndarray, rho: float, m: int, *, prior: np.ndarray, pairs, sol: LeastSquaresSolution,
                   gaussian) -> LeastSquaresSolution:
    """``sol`` of ``min ||a x - b||²`` again with a Gaussian prior ``(values, sigmas)`` on the entries whose σ is finite,
    as rows ``(s/σ_i)·(x_i - value_i)`` beside the data's, ``s`` the residual σ of ``sol`` (so the rows weigh as ``1/σ_i²``
    against the data's ``1/s²``: the maximum a posteriori estimate); ``sol`` itself without such a σ."""
    if gaussian is None or not np.any(np.isfinite(gaussian[1])):
        return sol
    values, sigmas = (np.asarray(g, dtype=float) for g in gaussian)
    held = np.flatnonzero(np.isfinite(sigmas))
    rows = np.zeros((held.size, a.shape[1]))
    rows[np.arange(held.size), held] = sol.residual_std / sigmas[held]
    return _about_prior(np.vstack([a, rows]), np.concatenate([b, rows[np.arange(held.size), held] * values[held]]),
                        rho, m, prior, pairs)


def _full_rank(r: np.ndarray, rhs: np.ndarray, rho: float, m: int, sv: np.ndarray) -> LeastSquaresSolution:
    """The least-squares solution and its covariance of a full-rank triangular problem (:meth:`LeastSquaresAccumulator.solve`)."""
    p = r.shape[1]
    params = np.linalg.solve(r, rhs)
    sigma2 = rho**2 / (m - p)
    rinv = np.linalg.inv(r)
    cov = sigma2 * (rinv @ rinv.T)
    std = np.sqrt(np.diag(cov))
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = 100.0 * std / np.abs(params)
    return LeastSquaresSolution(params, cov, std, rel, float(sv[0] / sv[-1]), float(np.sqrt(sigma2)), m)


def _weak(null_rows: np.ndarray) -> np.ndarray:
    """The parameters that take part in the given null-space directions (rows of Vᵀ): (p,) bool."""
    null = np.abs(null_rows)
    return np.any(null > 0.3 * null.max(axis=1, keepdims=True), axis=0)


def _about_prior(r: np.ndarray, rhs: np.ndarray, rho: float, m: int, prior: np.ndarray, pairs=()) -> LeastSquaresSolution:
    """Least squares in the determined subspace of the column-scaled ``r``, the prior elsewhere (:meth:`solve`)."""
    p = r.shape[1]
    if prior.shape != (p,) or not np.all(np.isfinite(prior)):
        raise IdentifiabilityError(f"the prior must be {p} finite values, got shape {prior.shape}")
    norms = np.linalg.norm(r, axis=0)
    zero = norms <= ZERO_COLUMN * norms.max()
    scale = np.where(zero, 1.0, norms)
    rs = np.where(zero, 0.0, r / scale)
    u, sv, vt = np.linalg.svd(rs)
    k = int(np.sum(sv > UNDETERMINED_RCOND * sv[0])) if sv[0] > 0 else 0
    x0 = prior * scale
    x = x0 + vt[:k].T @ ((u[:, :k].T @ (rhs - rs @ x0)) / sv[:k])
    params = x / scale
    rss = rho**2 + float(np.sum((rhs - r @ params) ** 2))
    sigma2 = rss / max(m - k, 1)
    vk = vt[:k].T / scale[:, None]
    cov = sigma2 * (vk / sv[:k] ** 2) @ vk.T
    undetermined = _weak(vt[k:]) if k < p else np.zeros(p, dtype=bool)
    anchored = []
    for free, fixed in pairs:
        moved = _anchor(rs, scale, vt[k:], sv[0], params, cov, prior=prior, free=free, fixed=fixed)
        if moved is not None:
            params, cov = moved
            undetermined[free] = False
            anchored.append(int(free))
    std = np.where(undetermined, np.nan, np.sqrt(np.maximum(np.diag(cov), 0.0)))
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = 100.0 * std / np.abs(params)
    cond = float(sv[0] / sv[k - 1]) if k else float("inf")
    return LeastSquaresSolution(params, cov, std, rel, cond, float(np.sqrt(sigma2)), m,
                                tuple(int(i) for i in np.flatnonzero(undetermined)), tuple(anchored))


def _anchor(rs, scale, null_rows, sv_max, params, cov, *, prior, free: int, fixed: int):
    """``params`` and ``cov`` with ``fixed`` at the prior and ``free`` taking the pair's determined combination, or None
    where the two columns are not collinear by themselves, the combination is not determined to
    :data:`ANCHOR_RELATIVE_STD`, or ``free`` would be negative (:meth:`LeastSquaresAccumulator.solve`)."""
    _, sv2, vt2 = np.linalg.svd(rs[:, [free, fixed]])
    if sv2[-1] > UNDETERMINED_RCOND * sv_max:
        return None
    n_free, n_fixed = vt2[-1] / scale[[free, fixed]]  # the pair's null direction, unscaled
    if abs(n_free) < 1e-12 * abs(n_fixed) or abs(n_fixed) < 1e-12 * abs(n_free):
        return None
    g = np.zeros(params.size)  # the combination the rows determine: value of `fixed` with `free` moved to 0
    g[free], g[fixed] = -n_fixed / n_free, 1.0
    h = g / scale  # in the scaled coordinates, orthogonal to every undetermined direction if determined
    if np.linalg.norm(null_rows @ h) > 1e-6 * np.linalg.norm(h):
        return None
    c = float(g @ params)
    sd = float(np.sqrt(max(g @ cov @ g, 0.0)))
    d = -n_fixed / n_free  # c = d·free + fixed along the null direction
    value = (c - prior[fixed]) / d
    if not sd <= ANCHOR_RELATIVE_STD * abs(c) or value < 0:
        return None
    t = np.eye(params.size)  # the new parameters as a linear map of the old (plus the prior's offset)
    t[free] = g / d
    t[fixed] = 0.0
    out = t @ params
    out[fixed] = prior[fixed]
    out[free] = value
    return out, t @ cov @ t.T


def _triangular(a: np.ndarray, size: int) -> np.ndarray:
    r = np.asarray(np.linalg.qr(a, mode="r"))
    out = np.zeros((size, size))
    out[: r.shape[0]] = r[:size]
    return out

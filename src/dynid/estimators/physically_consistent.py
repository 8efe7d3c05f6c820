"""Physically consistent least squares: a semidefinite program over the standard parameters.

``min ||W φ - τ||² + λ ||φ - φ_prior||²`` subject to, for every link, the pseudo-inertia matrix
``J(φ_link) = [[½ tr(I)·1 - I, h], [hᵀ, m]] ⪰ ε·1`` (``I`` the inertia about the link origin, ``h`` the first
moments ``MX, MY, MZ``, ``m`` the mass), which holds exactly when the parameters are those of a real
mass distribution (Wensing, Kim & Slotine, "Linear matrix inequalities for physically consistent inertial
parameter identification", IEEE RA-L 3(1), 2018), and non-negative friction coefficients and rotor
inertias. The least-squares term is reduced to ``||R φ - Qᵀτ||²`` by a QR factorisation of ``W`` first,
so the SDP's size does not grow with the number of samples. Solved by cvxpy with Clarabel.

The estimator sees only ``(W, τ)`` and the parameter layout (which columns form each link's ten inertial
parameters, which must be non-negative); :func:`dynid.dynamics.layout.consistency_layout` builds it for a robot.
"""

from __future__ import annotations

import warnings

import numpy as np

from ..exceptions import DynIdError, ShapeError
from ..model.spatial import CONSISTENCY_TOL as CONSISTENCY_TOL  # the solver's accuracy, defined with the rule using it
from ..model.spatial import pseudo_inertia, within_round_off
from .base import AccumulatingEstimator, check_observations, weighted_rows

PRIOR_KIND = "euclidean"
"""The SDP's prior by default (:class:`PhysicallyConsistentLeastSquares`)."""

PRIOR_KINDS = ("euclidean", "geometric")
"""The SDP's priors: squared distance to the nominal parameters, or the pseudo-inertias' log-det divergence."""


class PhysicallyConsistentLeastSquares(AccumulatingEstimator):
    """Least squares over the standard parameters with each link's pseudo-inertia positive semidefinite.

    What it reads of the problem (``fit(..., problem=FitData(...))``, or ``partial_fit``'s and ``solve``'s):

    - ``layout``, ``(links, nonnegative)``, required: ``links`` (n_links, 10) the columns of ``W`` holding each link's
      ``XX, XY, XZ, YY, YZ, ZZ, MX, MY, MZ, M``, ``nonnegative`` the columns constrained ``>= 0`` (viscous and Coulomb
      friction, rotor inertias); :func:`dynid.dynamics.layout.consistency_layout` builds it for a robot;
    - ``prior``, (p,): the parameters the unidentifiable directions are pulled towards (nominal/CAD values);
    - ``prior_std``, (p,): each parameter's prior standard deviation, NaN where none (a drive's data sheet:
      :meth:`Robot.prior_sigmas`): such a parameter is pulled toward ``prior`` as a Gaussian prior,
      ``(s/σ_i)²·(φ_i - prior_i)²`` beside the data's squared residuals, ``s`` the unconstrained least squares' residual
      σ (the maximum a posteriori estimate under the constraints);
    - ``n_dof``: joints per sample (rows given chunk by chunk by ``partial_fit`` are folded per joint);
    - ``joint_weights``, (n_dof,): the weight of each joint's rows when solving rows given by ``partial_fit`` (e.g. the
      WLS weights); default 1.

    Parameters
    ----------
    prior_weight : float
        ``λ`` relative to the mean squared column norm of ``W``: 1e-6 barely moves the identifiable
        directions and fixes the unidentifiable ones at the prior's values.
    epsilon : float
        Smallest eigenvalue allowed for each pseudo-inertia [kg·m², kg].
    prior_kind : {"euclidean", "geometric"}
        How the prior pulls: the squared distance ``||φ - φ_prior||²``, or, for each link whose prior pseudo-inertia
        ``J₀`` is positive definite, the log-det divergence ``tr(J₀⁻¹ J) - log det J`` (up to constants; Lee, Wensing
        & Park, "Geometric robot dynamic identification", IEEE T-RO 2020), which keeps the unidentifiable directions
        at a plausible mass distribution (no vanishing principal inertia); the drive terms keep the squared distance.

    Attributes
    ----------
    params_ : (p,) array
        Standard parameters.
    pseudo_inertia_min_eig_ : (n_links,) array
        Smallest eigenvalue of each link's pseudo-inertia at the solution.
    status_ : str
        Solver status.

    Raises
    ------
    DynIdError
        If the solver fails.
    ShapeError
        If the layout does not fit ``W``.
    """

    PROBLEM_FIELDS = ("n_dof", "layout", "prior", "prior_std", "joint_weights")

    PARAMETER_CHOICES = {"prior_kind": PRIOR_KINDS}
    """The values each hyper-parameter may take, checked where a config gives them
    (:func:`dynid.estimators.registry.configured_estimator`)."""

    CONSTRAINTS = {"prior_weight": ("real", 0.0, None), "epsilon": ("real", 0.0, None)}

    def __init__(self, *, prior_weight: float = 1e-6, epsilon: float = 0.0, prior_kind: str = PRIOR_KIND):
        self.prior_kind = prior_kind
        self.prior_weight = prior_weight
        self.epsilon = epsilon

    def fit(self, w, tau, sample_weight=None, *, problem=None) -> PhysicallyConsistentLeastSquares:
        """Solve the SDP on all rows at once (their QR factor).

        Parameters
        ----------
        w : (M, p) array
            Standard observation matrix.
        tau : (M,) or (N, n_dof) array [N·m]
        sample_weight : (M,) or (N, n_dof) array, optional
            One weight ≥ 0 per row of the squared loss (:func:`dynid.estimators.base.weighted_rows`).
        problem : FitData
            Its ``layout`` (required), ``prior`` and ``prior_std`` (the class's docstring).

        Returns
        -------
        self
        """
        w, tau = weighted_rows(w, tau, sample_weight, self.loss_power)
        self.take_problem(problem)
        self.__dict__.pop("accumulator_", None)
        self._fit_rows(w, tau)
        self.__dict__["_solved"] = True
        return self

    def _solve(self, acc) -> None:
        """The SDP on the accumulated triangular factor ``[R | z]`` of the (joint-weighted) rows."""
        p = acc.n_params
        reduced = acc.reduced(self.problem_.joint_weights)
        self._fit_rows(reduced[:, :p], reduced[:, p], int(acc.rows.sum()))

    def _fit_rows(self, w, tau, n_rows: int | None = None) -> None:
        import cvxpy as cp

        w, tau = check_observations(w, tau)
        m, p = w.shape
        problem = self.problem_
        if problem.layout is None:
            raise ShapeError("PhysicallyConsistentLeastSquares: the parameter layout (problem=FitData(layout=(links, "
                             "nonnegative)): the columns of each link's 10 parameters) is needed to fit "
                             "(dynid.dynamics.layout.consistency_layout of the robot)")
        links = np.asarray(problem.layout[0], dtype=int).reshape(-1, 10)
        nonneg = np.asarray(problem.layout[1], dtype=int)
        if links.size and (links.min() < 0 or links.max() >= p) or (nonneg.size and (nonneg.min() < 0 or nonneg.max() >= p)):
            raise ShapeError(f"parameter layout refers to columns outside W's {p}")
        scale = np.sqrt(m)
        r, z = _reduced_least_squares(w / scale, tau / scale)
        phi = cp.Variable(p)
        cost = cp.sum_squares(r @ phi - z)
        if problem.prior is not None:
            prior = np.asarray(problem.prior, dtype=float)
            if prior.shape != (p,):
                raise ShapeError(f"expected a prior of shape ({p},), got {prior.shape}")
            weight = self.prior_weight * float(np.mean(r**2) * r.shape[0])
            if self.prior_kind == "geometric":
                cost = cost + weight * _geometric_prior(cp, phi, prior, links)
            elif self.prior_kind == "euclidean":
                cost = cost + weight * cp.sum_squares(phi - prior)
            else:
                raise ShapeError(f"prior_kind: expected one of {', '.join(PRIOR_KINDS)}, got {self.prior_kind!r}")
            cost = cost + _gaussian_prior(cp, phi, prior, problem.prior_std, r=r, z=z, tau=tau / scale, n_rows=n_rows or m)
        sdp = cp.Problem(cp.Minimize(cost), _consistency_constraints(phi, links, nonneg, self.epsilon))
        try:
            status = _solve(sdp, "physically consistent least squares").status
        except DynIdError:  # the same cause as a status without a solution, said the same way (not cvxpy's advice)
            status = cp.SOLVER_ERROR
        if status not in ("optimal", "optimal_inaccurate") or phi.value is None:
            raise DynIdError(f"physically consistent least squares (sdp): the solver found no physically consistent "
                             f"parameters for these torques (status {status}); torque columns that are not the "
                             "robot's torques (another signal, or far off in size) do this: check the torques (or "
                             "currents) columns and their units, or list the estimators without sdp")
        self.params_ = np.asarray(phi.value, dtype=float)
        self.status_ = status
        self.pseudo_inertia_min_eig_ = np.array([np.linalg.eigvalsh(pseudo_inertia(self.params_[idx])).min() for idx in links])


def _gaussian_prior(cp, phi, prior: np.ndarray, prior_std, *, r: np.ndarray, z: np.ndarray, tau: np.ndarray, n_rows: int):
    """The cost of the parameters with a prior σ (:class:`PhysicallyConsistentLeastSquares`'s ``prior_std``) in the
    scaled problem ``||rφ - z||²`` of ``(w, τ)`` divided by ``√m``: ``Σ (s²/m)/σ_i² (φ_i - prior_i)²`` with ``s²`` the
    unconstrained least squares' residual variance on the ``n_rows`` rows the problem stands for."""
    sigma = None if prior_std is None else np.asarray(prior_std, dtype=float)
    if sigma is None or not np.any(np.isfinite(sigma)):
        return 0
    if sigma.shape != prior.shape:
        raise ShapeError(f"expected a prior_std of shape {prior.shape}, got {sigma.shape}")
    fitted, _, rank, _ = np.linalg.lstsq(r, z, rcond=None)
    rss = max(float(tau @ tau - z @ z + np.sum((r @ fitted - z) ** 2)), 0.0)  # the rows' part beyond R's range too
    held = np.flatnonzero(np.isfinite(sigma))
    weight = rss / max(n_rows - int(rank), 1) / sigma[held] ** 2
    return cp.sum(cp.multiply(weight, cp.square(phi[held] - prior[held])))


def _reduced_least_squares(w: np.ndarray, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(R, Qᵀτ)`` with ``W = QR``: ``||Wφ - τ||² = ||Rφ - Qᵀτ||² + const``."""
    q, r = np.linalg.qr(w, mode="reduced")
    return r, q.T @ tau


def consistency_margin(regrouping, beta, links, nonnegative=(), bound: float = 1.0) -> float:
    """Largest ``t <= bound`` such that some standard parameters ``φ`` with ``regrouping @ φ = beta`` have every
    link's pseudo-inertia ``⪰ t·1`` and the ``nonnegative`` columns ``>= 0``: a feasibility SDP.

    ``t >= 0`` means the base parameters ``beta`` are those of a physically consistent robot (Sousa & Cortesão,
    "Physical feasibility of robot base inertial parameter identification: a linear matrix inequality approach",
    IJRR 33(6), 2014); ``t < 0`` means no mass distribution gives them.

    Parameters
    ----------
    regrouping : (n_base, p) array
        ``beta = regrouping @ φ`` (:attr:`dynid.dynamics.base_parameters.BaseParameters.regrouping`).
    beta : (n_base,) array
    links : (n_links, 10) int array
    nonnegative : sequence of int
    bound : float
        Cap on ``t`` that keeps the problem bounded [kg·m², kg].

    Returns
    -------
    float
        ``t*``, or ``-inf`` when even ``t`` very negative is infeasible (non-finite input).

    Raises
    ------
    DynIdError
        If the solver fails.
    """
    k = np.asarray(regrouping, dtype=float)
    b = np.asarray(beta, dtype=float)
    if not np.all(np.isfinite(b)):
        return float("-inf")
    problem, b_param, t = _margin_problem(k, np.asarray(links, dtype=int), np.asarray(nonnegative, dtype=int), float(bound))
    b_param.value = b
    problem = _solve(problem, "consistency check")
    if problem.status in ("infeasible", "infeasible_inaccurate"):
        return float("-inf")
    if t.value is None:
        raise DynIdError(f"consistency check: solver status {problem.status}")
    return float(t.value)


def margin_is_consistent(margin: float, beta=None) -> bool:
    """Whether a :func:`consistency_margin` says "physically consistent": at least 0 to the solver's round-off
    relative to the base parameters checked (:func:`dynid.model.spatial.within_round_off`).

    Parameters
    ----------
    margin : float [kg·m²]
    beta : (n_base,) array, optional
        The base parameters checked.

    Returns
    -------
    bool
    """
    return within_round_off(margin, beta)


def consistency_verdict(margin: float, regrouping=None, beta=None, names=(), nonnegative=()) -> str:
    """A margin of :func:`consistency_margin` in words: "yes", or "no" with the reason.

    Margins within the solver's round-off of 0 are "yes" (:func:`margin_is_consistent`). An infeasible problem (margin -inf)
    names the base parameters that are a non-negative term alone (friction, rotor inertia) and are negative, e.g.
    ``no: fv4 = -0.02 < 0``; other negative margins give the margin: how far the closest mass distribution's smallest
    pseudo-inertia eigenvalue is below 0 [kg·m²].

    Parameters
    ----------
    margin : float [kg·m²]
    regrouping : (n_base, n_params) array, optional
    beta : (n_base,) array, optional
        The estimate, to name its negative terms.
    names : sequence of str
        Base parameter names.
    nonnegative : sequence of int
        Standard columns of the non-negative terms.

    Returns
    -------
    str
    """
    if margin_is_consistent(margin, beta):
        return "yes"
    if np.isfinite(margin):
        return f"no: some link's pseudo-inertia has an eigenvalue {margin:.3g} < 0 at best"
    if regrouping is not None and beta is not None:
        k = np.asarray(regrouping, dtype=float)
        nonneg = set(int(i) for i in np.asarray(nonnegative, dtype=int).ravel())
        bad = [f"{names[i]} = {float(b):.3g} < 0" for i, (row, b) in enumerate(zip(k, np.asarray(beta, dtype=float)))
               if b < 0 and np.all(row >= 0) and set(np.flatnonzero(row).tolist()) <= nonneg and np.any(row)]
        if not np.all(np.isfinite(beta)):
            return "no: some value is not finite"
        if bad:
            return "no: " + ", ".join(bad)
    return "no: no mass distribution with non-negative friction and rotor inertias has these base parameters"


_MARGIN_PROBLEMS: dict = {}


def _margin_problem(k, links, nonnegative, bound):
    """The feasibility SDP of :func:`consistency_margin` with ``beta`` as a parameter, built once per robot
    layout: cvxpy compiles it on the first solve and only substitutes ``beta`` on the next (DPP)."""
    import cvxpy as cp

    key = (k.shape, k.tobytes(), links.tobytes(), nonnegative.tobytes(), bound)
    if key not in _MARGIN_PROBLEMS:
        if len(_MARGIN_PROBLEMS) >= 8:
            _MARGIN_PROBLEMS.pop(next(iter(_MARGIN_PROBLEMS)))
        phi, t, b = cp.Variable(k.shape[1]), cp.Variable(), cp.Parameter(k.shape[0])
        cons = [k @ phi == b, t <= bound, *_consistency_constraints(phi, links, nonnegative, t)]
        _MARGIN_PROBLEMS[key] = (cp.Problem(cp.Maximize(t), cons), b, t)
    return _MARGIN_PROBLEMS[key]


def _consistency_constraints(phi, links, nonnegative, margin) -> list:
    """Every link's pseudo-inertia ``⪰ margin·1`` and the ``nonnegative`` columns ``>= 0``."""
    cons = [_pseudo_inertia_expression(phi, idx) >> margin * np.eye(4) for idx in np.asarray(links, dtype=int).reshape(-1, 10)]
    nonneg = np.asarray(nonnegative, dtype=int)
    if nonneg.size:
        cons.append(phi[nonneg] >= 0)
    return cons


def _solve(problem, what: str):
    """Solve with Clarabel; a solver failure becomes a one-line :class:`DynIdError` naming ``what``."""
    import cvxpy as cp

    try:
        with warnings.catch_warnings():  # an inaccurate solution is said by its status, which the callers report
            warnings.simplefilter("ignore", UserWarning)
            problem.solve(solver=cp.CLARABEL)
    except cp.error.SolverError as exc:
        raise DynIdError(f"{what}: the SDP solver failed ({exc})") from None
    except BaseException as exc:  # Clarabel's Rust core panics on extreme values (a PanicException, not an Exception)
        if type(exc).__name__ != "PanicException":
            raise
        raise DynIdError(f"{what}: the SDP solver failed on these values ({exc})") from None
    return problem


def _geometric_prior(cp, phi, prior, links):
    """The log-det divergence of each link's pseudo-inertia from the prior's where that is positive definite, the
    squared distance for everything else (drive terms, links whose prior is degenerate)."""
    terms, euclidean = [], np.ones(phi.shape[0], dtype=bool)
    for idx in links:
        j0 = pseudo_inertia(prior[idx])
        eig = np.linalg.eigvalsh(j0)
        if eig.min() <= 1e-9 * max(eig.max(), 1e-300):
            continue
        j = _pseudo_inertia_expression(phi, idx)
        terms.append(cp.trace(np.linalg.inv(j0) @ j) - cp.log_det((j + j.T) / 2))
        euclidean[np.asarray(idx, dtype=int)] = False
    out = cp.sum_squares(phi[np.flatnonzero(euclidean)] - prior[euclidean]) if euclidean.any() else 0
    return out + (cp.sum(cp.hstack(terms)) if terms else 0)


def _pseudo_inertia_expression(phi, idx):
    """cvxpy expression of a link's pseudo-inertia from its ten parameters ``phi[idx]``: one linear map,
    ``J = reshape(A φ)`` with column ``idx[k]`` of ``A`` the pseudo-inertia of the k-th unit vector (J is
    linear in φ). One affine atom instead of thirty: cvxpy compiles the problem in a third of the time, and
    Clarabel receives the same problem."""
    import cvxpy as cp

    a = np.zeros((16, phi.shape[0]))
    for k, column in enumerate(np.asarray(idx, dtype=int)):
        a[:, column] = pseudo_inertia(np.eye(10)[k]).reshape(16)
    return cp.reshape(a @ phi, (4, 4), order="C")

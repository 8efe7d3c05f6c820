import numpy as np
import pytest

from dynid.dynamics.base_parameters import base_parameters
from dynid.dynamics.regressor import observation_matrix
from dynid.estimators import BeeColonyEstimator, OrdinaryLeastSquares, paper_objective
from dynid.exceptions import IdentifiabilityError, ShapeError
from dynid.model.description import load_robot

from ..conftest import random_states


@pytest.fixture(scope="module")
def problem():
    rng = np.random.default_rng(5)
    robot = load_robot("er16").submodel(3)
    bp = base_parameters(robot, rng=0)
    q, dq, ddq = random_states(rng, 600, 3)
    w = bp.base_observation(observation_matrix(robot, q, dq, ddq))
    beta = bp.base_from_standard(robot.standard_parameters())
    return w, beta


def make(kind, beta):
    from dynid.estimators import LeastAbsoluteDeviations, WeightedLeastSquares

    if kind == "ols":
        return OrdinaryLeastSquares()
    if kind == "wls":
        return WeightedLeastSquares(n_dof=3)
    if kind == "lad":
        return LeastAbsoluteDeviations(n_dof=3)
    bounds = np.stack([beta - 1.0, beta + 1.0], axis=1)
    return BeeColonyEstimator(bounds=bounds, n_dof=3, maxiter=5, rng=0)


@pytest.mark.parametrize("kind", ["ols", "wls", "lad", "abc"])
def test_shared_contract(problem, kind):
    w, beta = problem
    est = make(kind, beta)
    with pytest.raises(AttributeError, match="not fitted"):
        est.predict(w)
    assert est.fit(w, w @ beta) is est
    assert est.params_.shape == beta.shape
    assert est.predict(w).shape == (w.shape[0],)
    assert est.score(w, w @ beta) <= 1.0
    assert est.score(w, est.predict(w)) == pytest.approx(1.0)  # R² of a perfect prediction
    with pytest.raises(ShapeError):
        est.fit(w, (w @ beta)[:-1])


def test_ols_recovers_truth_exactly_from_noise_free_data(problem):
    w, beta = problem
    ols = OrdinaryLeastSquares().fit(w, w @ beta)
    np.testing.assert_allclose(ols.params_, beta, rtol=1e-9, atol=1e-9)


def test_ols_within_3_sigma_on_noisy_data(problem):
    w, beta = problem
    rng = np.random.default_rng(11)
    ols = OrdinaryLeastSquares().fit(w, w @ beta + rng.normal(0, 2.0, w.shape[0]))
    z = np.abs(ols.params_ - beta) / ols.params_std_
    assert np.all(z < 4.0) and np.mean(z < 3.0) > 0.9
    assert ols.residual_std_ == pytest.approx(2.0, rel=0.05)
    assert ols.condition_number_ > 1


def test_ols_rank_deficient_raises(problem):
    w, beta = problem
    with pytest.raises(IdentifiabilityError, match="rank-deficient"):
        OrdinaryLeastSquares().fit(np.hstack([w, w[:, :1]]), w @ beta)


def test_paper_objective_is_eq9():
    r = np.array([1.0, -2.0, 3.0, -4.0])  # 2 samples x 2 joints
    assert paper_objective(r, 2) == pytest.approx((1 + 2 + 3 + 4) / 2)
    assert paper_objective(r, 2, np.array([1.0, 0.5])) == pytest.approx((1 + 1 + 3 + 2) / 2)


def test_abc_never_worse_than_its_start_and_is_seeded(problem):
    w, beta = problem
    tau = w @ beta
    a = BeeColonyEstimator(bounds=np.stack([beta - 2, beta + 2], 1), n_dof=3, maxiter=30, rng=3).fit(w, tau)
    b = BeeColonyEstimator(bounds=np.stack([beta - 2, beta + 2], 1), n_dof=3, maxiter=30, rng=3).fit(w, tau)
    np.testing.assert_array_equal(a.params_, b.params_)
    assert a.objective_ == pytest.approx(paper_objective(tau - w @ a.params_, 3))
    assert a.history_[-1] < a.history_[0]
    with pytest.raises(ShapeError, match="bounds"):
        BeeColonyEstimator(bounds=[(0, 1)], n_dof=3).fit(w, tau)


def _primal_lad(w, tau, n_dof, bounds=None):
    """Independent check: the primal LP min Σ(u+v)/N s.t. W p + u - v = tau."""
    from scipy.optimize import linprog

    m, p = w.shape
    c = np.concatenate([np.zeros(p), np.full(2 * m, n_dof / m)])
    a = np.hstack([w, np.eye(m), -np.eye(m)])
    pb = [(None, None)] * p if bounds is None else [tuple(b) for b in bounds]
    res = linprog(c, A_eq=a, b_eq=tau, bounds=pb + [(0, None)] * (2 * m), method="highs")
    return res.fun


@pytest.mark.parametrize("bounded", [False, True])
def test_lad_matches_primal_linear_program(rng, bounded):
    from dynid.estimators import LeastAbsoluteDeviations

    w = rng.normal(size=(120, 4))
    tau = w @ np.array([1.0, -2.0, 0.5, 3.0]) + rng.standard_t(2, 120)
    bounds = np.array([[-5, 5], [-1.5, 0], [0, 1], [-5, 2.5]]) if bounded else None
    lad = LeastAbsoluteDeviations(n_dof=3, bounds=bounds).fit(w, tau)
    assert lad.objective_ == pytest.approx(_primal_lad(w, tau, 3, bounds), rel=1e-6)
    if bounded:
        assert np.all(lad.params_ >= bounds[:, 0]) and np.all(lad.params_ <= bounds[:, 1])


def test_lad_objective_never_above_abc(problem):
    """LAD minimises eq. 9 exactly over the same box, so ABC can never beat it."""
    from dynid.estimators import LeastAbsoluteDeviations

    w, beta = problem
    rng = np.random.default_rng(8)
    tau = w @ beta + rng.normal(0, 1.0, w.shape[0])
    bounds = np.stack([beta - 3, beta + 3], 1)
    lad = LeastAbsoluteDeviations(n_dof=3, bounds=bounds).fit(w, tau)
    for seed in range(3):
        abc = BeeColonyEstimator(bounds=bounds, n_dof=3, maxiter=20, rng=seed).fit(w, tau)
        assert lad.objective_ <= abc.objective_ + 1e-9


def test_wls_recovers_truth_and_weights_joints(problem):
    from dynid.estimators import WeightedLeastSquares

    w, beta = problem
    rng = np.random.default_rng(9)
    noise = rng.normal(0, 1.0, (w.shape[0] // 3, 3)) * np.array([0.5, 5.0, 1.0])
    wls = WeightedLeastSquares(n_dof=3).fit(w, w @ beta + noise.ravel())
    np.testing.assert_allclose(wls.joint_std_, [0.5, 5.0, 1.0], rtol=0.25)  # first-step OLS residuals leak noise across joints
    assert np.argsort(wls.joint_std_).tolist() == [0, 2, 1]
    z = np.abs(wls.params_ - beta) / wls.params_std_
    assert np.all(z < 4.5)
    np.testing.assert_allclose(WeightedLeastSquares(n_dof=3).fit(w, w @ beta).params_, beta, rtol=1e-8, atol=1e-8)


@pytest.mark.parametrize("kind", ["wls", "lad"])
def test_rows_must_be_whole_samples(problem, kind):
    w, beta = problem
    with pytest.raises(ShapeError, match="multiple of n_dof"):
        make(kind, beta).fit(w[:-1], (w @ beta)[:-1])

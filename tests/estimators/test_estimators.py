import numpy as np
import pytest

from dynid.dynamics.base_parameters import base_parameters
from dynid.dynamics.regressor import observation_matrix
from dynid.estimators import (
    BeeColonyEstimator,
    DifferentialEvolutionEstimator,
    FitData,
    IterativelyReweightedLeastSquares,
    OrdinaryLeastSquares,
    ParticleSwarmEstimator,
    paper_objective,
)
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
    """An unfitted estimator of ``kind`` with its hyper-parameters only (what it sees of the problem: :func:`given`)."""
    from dynid.estimators import LeastAbsoluteDeviations, WeightedLeastSquares

    if kind == "ols":
        return OrdinaryLeastSquares()
    if kind == "wls":
        return WeightedLeastSquares()
    if kind == "lad":
        return LeastAbsoluteDeviations()
    if kind == "irls":
        return IterativelyReweightedLeastSquares()
    if kind == "de":
        return DifferentialEvolutionEstimator(popsize=2, maxiter=5, rng=0)
    if kind == "pso":
        return ParticleSwarmEstimator(maxiter=5, rng=0)
    return BeeColonyEstimator(maxiter=5, rng=0)


def given(kind, beta, n_dof=3):
    """The problem ``make(kind, beta)`` is fitted on: the joints per sample, and a box around ``beta`` for a search."""
    return FitData(n_dof=n_dof, bounds=np.stack([beta - 1.0, beta + 1.0], axis=1) if kind in BOX_SEARCHES else None)


PROBLEM_NAMES = {"n_dof", "bounds", "weights", "prior", "links", "nonnegative", "joint_weights", "base_prior",
                 "base_prior_std", "prior_std", "layout"}
"""What an estimator sees of the problem: never its hyper-parameters (issue "Parts carry their settings", item 1)."""


BOX_SEARCHES = ["abc", "de", "pso"]


@pytest.fixture(scope="module")
def standard_problem():
    """The physically consistent estimator works on the standard parameters: W (M, 3·13) and the robot's φ."""
    from dynid.dynamics.layout import consistency_layout
    from dynid.estimators import PhysicallyConsistentLeastSquares

    robot = load_robot("er16").submodel(3)
    q, dq, ddq = random_states(np.random.default_rng(6), 400, 3)
    return (observation_matrix(robot, q, dq, ddq), robot.standard_parameters(), PhysicallyConsistentLeastSquares,
            FitData(layout=consistency_layout(robot), prior=robot.standard_parameters()))


@pytest.mark.parametrize("kind", ["ols", "wls", "lad", "irls", *BOX_SEARCHES, "sdp"])
def test_shared_contract(problem, standard_problem, kind):
    if kind == "sdp":
        w, beta, factory, seen = standard_problem
        est = factory()
    else:
        w, beta = problem
        est, seen = make(kind, beta), given(kind, beta)
    with pytest.raises(AttributeError, match="not fitted"):
        est.predict(w)
    assert not PROBLEM_NAMES & set(est.get_params())  # the problem comes to fit
    assert est.fit(w, w @ beta, problem=seen) is est
    assert est.params_.shape == beta.shape
    assert est.predict(w).shape == (w.shape[0],)
    assert est.score(w, w @ beta) <= 1.0
    assert est.score(w, est.predict(w)) == pytest.approx(1.0)  # R² of a perfect prediction
    with pytest.raises(ShapeError):
        est.fit(w, (w @ beta)[:-1], problem=seen)
    # scikit-learn contract: hyper-parameters only, a clone is unfitted and refits to the same result
    twin = est.clone()
    assert type(twin) is type(est) and not hasattr(twin, "params_")
    assert twin.get_params().keys() == est.get_params().keys()
    with pytest.raises(ValueError, match="has no parameter 'nonsense'"):
        twin.set_params(nonsense=1)


def test_an_estimators_repr_names_what_differs_from_its_defaults():
    """scikit-learn's repr: the parameters set away from the constructor's defaults (an array by its shape), so that a
    list of estimators given to the identification fits a line; an estimator of the problem's inputs alone (its search
    box, its layout) needs none of them to be built, and refuses to fit without them, naming them."""
    from dynid.estimators import BeeColonyEstimator, PhysicallyConsistentLeastSquares

    assert repr(PhysicallyConsistentLeastSquares(prior_kind="geometric")) == "PhysicallyConsistentLeastSquares(prior_kind='geometric')"
    assert repr(BeeColonyEstimator(colony_size=60, rng=np.arange(3))) == "BeeColonyEstimator(colony_size=60, rng=<array (3,)>)"
    assert repr(OrdinaryLeastSquares()) == "OrdinaryLeastSquares()"
    w, tau = np.eye(6), np.ones(6)
    with pytest.raises(ShapeError, match=r"BeeColonyEstimator: the search box \(problem=FitData\(bounds=...\), of shape \(6, 2\)\)"):
        BeeColonyEstimator().fit(w, tau, problem=FitData(n_dof=1))
    with pytest.raises(ShapeError, match=r"PhysicallyConsistentLeastSquares: the parameter layout \(problem=FitData\(layout="):
        PhysicallyConsistentLeastSquares().fit(w, tau)
    with pytest.raises(TypeError, match="problem is a dynid.estimators.FitData"):
        OrdinaryLeastSquares().fit(w, tau, problem={"n_dof": 1})
    with pytest.raises(TypeError, match=r"^BeeColonyEstimator\(bounds=...\): what depends on the data comes to fit now, "
                                        r"fit\(W, tau, problem=dynid.estimators.FitData\(bounds=...\)\)$"):
        BeeColonyEstimator(bounds=np.zeros((6, 2)), maxiter=3)
    with pytest.raises(TypeError, match=r"FitData\(layout=...\)"):
        PhysicallyConsistentLeastSquares(links=np.arange(10)[None, :])

    class TakesAny(OrdinaryLeastSquares):  # a plugin's constructor that takes any keyword is left to take them
        def __init__(self, **given):
            self.given = given

    assert TakesAny(n_dof=3).given == {"n_dof": 3}


@pytest.mark.parametrize("kind", ["wls", "lad", "irls", *BOX_SEARCHES])
def test_n_dof_is_inferred_from_tau_given_per_joint(problem, kind):
    w, beta = problem
    stated = make(kind, beta).fit(w, w @ beta, problem=given(kind, beta))
    inferred = make(kind, beta).fit(w, (w @ beta).reshape(-1, 3), problem=given(kind, beta, n_dof=None))
    assert inferred.n_dof_ == 3
    np.testing.assert_allclose(inferred.params_, stated.params_, rtol=1e-9, atol=1e-12)
    with pytest.raises(ShapeError, match=r"pass tau as \(N, n_dof\) or set n_dof"):
        make(kind, beta).fit(w, w @ beta, problem=given(kind, beta, n_dof=None))


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
    with pytest.raises(IdentifiabilityError, match="do not excite 2 parameter"):
        OrdinaryLeastSquares().fit(np.hstack([w, w[:, :1]]), w @ beta)


def test_paper_objective_is_eq9():
    r = np.array([1.0, -2.0, 3.0, -4.0])  # 2 samples x 2 joints
    assert paper_objective(r, 2) == pytest.approx((1 + 2 + 3 + 4) / 2)
    assert paper_objective(r, 2, np.array([1.0, 0.5])) == pytest.approx((1 + 1 + 3 + 2) / 2)


def test_abc_never_worse_than_its_start_and_is_seeded(problem):
    w, beta = problem
    tau = w @ beta
    box = FitData(n_dof=3, bounds=np.stack([beta - 2, beta + 2], 1))
    a = BeeColonyEstimator(maxiter=30, rng=3).fit(w, tau, problem=box)
    b = BeeColonyEstimator(maxiter=30, rng=3).fit(w, tau, problem=box)
    np.testing.assert_array_equal(a.params_, b.params_)
    assert a.objective_ == pytest.approx(paper_objective(tau - w @ a.params_, 3))
    assert a.history_[-1] < a.history_[0]
    with pytest.raises(ShapeError, match="bounds"):
        BeeColonyEstimator().fit(w, tau, problem=FitData(n_dof=3, bounds=[(0, 1)]))


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
    lad = LeastAbsoluteDeviations().fit(w, tau, problem=FitData(n_dof=3, bounds=bounds))
    assert lad.objective_ == pytest.approx(_primal_lad(w, tau, 3, bounds), rel=1e-6)
    if bounded:
        assert np.all(lad.params_ >= bounds[:, 0]) and np.all(lad.params_ <= bounds[:, 1])


@pytest.mark.parametrize("kind", BOX_SEARCHES)
def test_lad_objective_never_above_box_searches(problem, kind):
    """LAD minimises eq. 9 exactly over the same box, so neither ABC, DE nor PSO can beat it."""
    from dynid.estimators import LeastAbsoluteDeviations

    w, beta = problem
    rng = np.random.default_rng(8)
    tau = w @ beta + rng.normal(0, 1.0, w.shape[0])
    bounds = np.stack([beta - 3, beta + 3], 1)
    lad = LeastAbsoluteDeviations().fit(w, tau, problem=FitData(n_dof=3, bounds=bounds))
    cls = {"abc": BeeColonyEstimator, "de": DifferentialEvolutionEstimator, "pso": ParticleSwarmEstimator}[kind]
    for seed in range(3):
        est = cls(maxiter=20, rng=seed).fit(w, tau, problem=FitData(n_dof=3, bounds=bounds))
        assert lad.objective_ <= est.objective_ + 1e-9
        assert est.objective_ == pytest.approx(paper_objective(tau - w @ est.params_, 3))


@pytest.mark.parametrize("kind", BOX_SEARCHES)
def test_box_searches_are_seeded_and_improve(problem, kind):
    w, beta = problem
    tau = w @ beta
    a, b = (make(kind, beta).fit(w, tau, problem=given(kind, beta)) for _ in range(2))
    np.testing.assert_array_equal(a.params_, b.params_)
    assert a.n_evaluations_ > 0 and a.history_[-1] <= a.history_[0]
    population = {"abc": None, "de": 2 * beta.size, "pso": 30}[kind]
    if population:  # evaluations count points, not calls of the vectorised objective
        assert a.n_evaluations_ == population * (len(a.history_) + 1)
    assert np.all(a.params_ >= beta - 1.0) and np.all(a.params_ <= beta + 1.0)


def test_box_searches_approach_the_minimum_with_budget(problem):
    """With a realistic budget DE and PSO get close to the exact minimiser (LAD) of eq. 9."""
    from dynid.estimators import LeastAbsoluteDeviations

    w, beta = problem
    tau = w @ beta + np.random.default_rng(4).normal(0, 0.5, w.shape[0])
    bounds = np.stack([beta - 0.5, beta + 0.5], 1)
    f_lad = LeastAbsoluteDeviations().fit(w, tau, problem=FitData(n_dof=3, bounds=bounds)).objective_
    f_start = paper_objective(tau - w @ bounds.mean(axis=1), 3)
    de = DifferentialEvolutionEstimator(popsize=5, maxiter=400, rng=1).fit(w, tau, problem=FitData(n_dof=3, bounds=bounds))
    pso = ParticleSwarmEstimator(swarm_size=40, maxiter=500, rng=1).fit(w, tau, problem=FitData(n_dof=3, bounds=bounds))
    for est in (de, pso):
        assert est.objective_ - f_lad < 0.1 * (f_start - f_lad)


def test_irls_ignores_outliers_that_pull_ols(problem):
    w, beta = problem
    rng = np.random.default_rng(12)
    tau = w @ beta + rng.normal(0, 0.5, w.shape[0])
    spikes = rng.choice(w.shape[0], w.shape[0] // 20, replace=False)
    tau[spikes] += rng.choice([-1, 1], spikes.size) * 40.0
    ols = OrdinaryLeastSquares().fit(w, tau)
    irls = IterativelyReweightedLeastSquares().fit(w, tau, problem=FitData(n_dof=3))
    assert irls.converged_
    assert np.linalg.norm(irls.params_ - beta) < 0.2 * np.linalg.norm(ols.params_ - beta)
    assert np.median(irls.row_weights_[spikes]) < 0.1
    clean = IterativelyReweightedLeastSquares().fit(w, w @ beta + rng.normal(0, 0.5, w.shape[0]), problem=FitData(n_dof=3))
    np.testing.assert_allclose(clean.joint_scale_, 0.5, rtol=0.15)


def test_irls_covariance_matches_spread_over_realisations(problem):
    """Huber's sandwich covariance predicts the scatter of IRLS estimates over noise realisations."""
    w, beta = problem
    rng = np.random.default_rng(13)
    fits = [IterativelyReweightedLeastSquares().fit(w, w @ beta + rng.standard_t(3, w.shape[0]), problem=FitData(n_dof=3))
            for _ in range(60)]
    spread = np.std([f.params_ for f in fits], axis=0, ddof=1)
    predicted = np.mean([f.params_std_ for f in fits], axis=0)
    ratio = spread / predicted
    assert 0.7 < np.median(ratio) < 1.3


def test_bootstrap_std_matches_covariance_and_is_seeded(problem):
    from dynid.estimators import bootstrap_intervals

    w, beta = problem
    tau = w @ beta + np.random.default_rng(14).normal(0, 1.0, w.shape[0])
    ols = OrdinaryLeastSquares().fit(w, tau)
    bs = bootstrap_intervals(OrdinaryLeastSquares, w, tau, 3, n_resamples=300, block_length=1, rng=2)
    ratio = bs.std / ols.params_std_
    assert 0.75 < np.median(ratio) < 1.25
    assert np.all(bs.lower < bs.upper)
    inside = (bs.lower <= beta) & (beta <= bs.upper)
    assert inside.mean() >= 0.8
    again = bootstrap_intervals(OrdinaryLeastSquares, w, tau, 3, n_resamples=300, block_length=1, rng=2)
    np.testing.assert_array_equal(bs.samples, again.samples)


def test_block_bootstrap_follows_the_true_spread_under_correlated_noise():
    """Smooth regressors and noise correlated over 10 samples: the OLS covariance formula (i.i.d. noise)
    understates the spread over realisations; the block bootstrap (blocks of 50) follows it."""
    from dynid.estimators import bootstrap_intervals

    n = 3000
    t = np.linspace(0, 1, n)
    w = np.column_stack([np.ones(n)] + [f(2 * np.pi * k * t) for k in (1, 2) for f in (np.sin, np.cos)])
    beta = np.array([1.0, -2.0, 0.5, 3.0, 1.5])
    rng = np.random.default_rng(15)

    def noise():
        e = rng.normal(0, 1.0, n + 9)
        return np.convolve(e, np.ones(10), mode="valid") / np.sqrt(10)

    truth_spread = np.std([OrdinaryLeastSquares().fit(w, w @ beta + noise()).params_ for _ in range(200)], axis=0, ddof=1)
    tau = w @ beta + noise()
    ols = OrdinaryLeastSquares().fit(w, tau)
    blocks = bootstrap_intervals(OrdinaryLeastSquares, w, tau, 1, n_resamples=300, block_length=50, rng=3)
    assert np.median(ols.params_std_ / truth_spread) < 0.5
    assert 0.6 < np.median(blocks.std / truth_spread) < 1.4


def test_bootstrap_rejects_bad_settings(problem):
    from dynid.estimators import bootstrap_intervals
    from dynid.exceptions import ConfigError

    w, beta = problem
    for kwargs in ({"n_resamples": 1}, {"level": 1.0}, {"block_length": 0}):
        with pytest.raises(ConfigError):
            bootstrap_intervals(OrdinaryLeastSquares, w, w @ beta, 3, **kwargs)


def test_wls_recovers_truth_and_weights_joints(problem):
    from dynid.estimators import WeightedLeastSquares

    w, beta = problem
    rng = np.random.default_rng(9)
    noise = rng.normal(0, 1.0, (w.shape[0] // 3, 3)) * np.array([0.5, 5.0, 1.0])
    wls = WeightedLeastSquares().fit(w, w @ beta + noise.ravel(), problem=FitData(n_dof=3))
    np.testing.assert_allclose(wls.joint_std_, [0.5, 5.0, 1.0], rtol=0.25)  # first-step OLS residuals leak noise across joints
    assert np.argsort(wls.joint_std_).tolist() == [0, 2, 1]
    z = np.abs(wls.params_ - beta) / wls.params_std_
    assert np.all(z < 4.5)
    np.testing.assert_allclose(WeightedLeastSquares().fit(w, w @ beta, problem=FitData(n_dof=3)).params_, beta, rtol=1e-8, atol=1e-8)


@pytest.mark.parametrize("kind", ["wls", "lad", "irls", *BOX_SEARCHES])
def test_rows_must_be_whole_samples(problem, kind):
    w, beta = problem
    with pytest.raises(ShapeError, match="multiple of n_dof"):
        make(kind, beta).fit(w[:-1], (w @ beta)[:-1], problem=given(kind, beta))


@pytest.mark.parametrize("kind", ["ols", "wls"])
def test_bootstrap_by_weighted_grams_equals_refitting_each_resample(problem, kind):
    """The fast path (per-sample Gram matrices weighted by the resample counts) gives the parameters that
    refitting every resample gives (a subclass takes the generic path), to round-off."""
    from dynid.estimators import WeightedLeastSquares
    from dynid.estimators.bootstrap import bootstrap_intervals

    base_cls = OrdinaryLeastSquares if kind == "ols" else WeightedLeastSquares

    class Refit(base_cls):
        pass

    w, beta = problem
    tau = w @ beta + np.random.default_rng(4).normal(0, 1.0, w.shape[0])
    fast = bootstrap_intervals(base_cls, w, tau, 3, n_resamples=20, block_length=7, rng=5)  # the problem: n_dof = 3
    slow = bootstrap_intervals(Refit, w, tau, 3, n_resamples=20, block_length=7, rng=5)
    np.testing.assert_allclose(fast.samples, slow.samples, rtol=1e-9, atol=1e-9 * np.abs(beta).max())


def test_abc_coordinate_moves_give_the_same_search_as_full_evaluations(problem):
    """The ABC's one-column residual updates (eq. 9) visit the same candidates for the same seed as full
    evaluations of W·x, and end at the same point (to round-off)."""
    from dynid.estimators.base import LinearAbsoluteObjective
    from dynid.optim.bee_colony import minimize_bee_colony

    w, beta = problem
    tau = w @ beta + np.random.default_rng(8).normal(0, 0.5, w.shape[0])
    objective = LinearAbsoluteObjective(w, tau, 3)
    bounds = np.stack([beta - 2.0, beta + 2.0], axis=1)
    fast = minimize_bee_colony(objective, bounds, maxiter=40, rng=9)
    full = minimize_bee_colony(lambda x: objective(x), bounds, maxiter=40, rng=9)
    assert fast.nfev == full.nfev
    np.testing.assert_allclose(fast.x, full.x, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(fast.history, full.history, rtol=1e-10)
    assert fast.fun == pytest.approx(objective(fast.x), rel=1e-10)


def test_a_fitted_estimator_summarises_what_it_learned(problem):
    """summary() works on every estimator, fitted or not (issue "Parts carry their settings, one route", item 6):
    before fit it says so; after, it gives each learned attribute (an array by its shape and range)."""
    w, beta = problem
    est = BeeColonyEstimator(maxiter=12, rng=3)
    before = est.summary()
    assert before.splitlines()[0] == repr(est) and before.endswith("not fitted yet: call fit(W, tau)")
    after = est.fit(w, w @ beta, problem=FitData(n_dof=3, bounds=np.stack([beta - 2, beta + 2], 1))).summary().splitlines()
    learned = dict(line.strip().split(": ", 1) for line in after[1:])
    assert learned["history_"].startswith(f"array ({len(est.history_)},) from ") and learned["objective_"] == f"{est.objective_:.6g}"
    assert learned["params_"] == f"array ({beta.size},) from {est.params_.min():.4g} to {est.params_.max():.4g}"
    assert learned["problem_"] == f"FitData(n_dof=3, bounds=<array ({beta.size}, 2)>)"  # what it read of the problem

import numpy as np
import pytest

from dynid.estimators.accumulate import LeastSquaresAccumulator
from dynid.exceptions import IdentifiabilityError, ShapeError


def _problem(rng, n_s=300, n=3, p=7):
    w = rng.normal(size=(n_s * n, p))
    theta = rng.normal(size=p)
    noise = rng.normal(size=(n_s, n)) * np.array([0.1, 1.0, 3.0])
    return w, w @ theta + noise.ravel(), theta


def test_chunked_equals_one_shot_least_squares(rng):
    w, tau, _ = _problem(rng)
    acc = LeastSquaresAccumulator(w.shape[1], 3)
    for a in range(0, w.shape[0], 3 * 37):  # chunks of 37 samples
        acc.add(w[a:a + 111], tau[a:a + 111])
    sol = acc.solve()
    ref, res, *_ = np.linalg.lstsq(w, tau, rcond=None)
    np.testing.assert_allclose(sol.params, ref, rtol=1e-10, atol=1e-12)
    sigma2 = res[0] / (w.shape[0] - w.shape[1])
    np.testing.assert_allclose(sol.covariance, sigma2 * np.linalg.inv(w.T @ w), rtol=1e-8)
    np.testing.assert_allclose(sol.condition_number, np.linalg.cond(w), rtol=1e-8)
    r = (tau - w @ ref).reshape(-1, 3)
    np.testing.assert_allclose(acc.joint_residual_sumsq(ref), (r**2).sum(0), rtol=1e-8)


def test_weighted_and_masked_rows_match_explicit_lstsq(rng):
    w, tau, _ = _problem(rng)
    mask = rng.uniform(size=tau.shape) > 0.2
    acc = LeastSquaresAccumulator(w.shape[1], 3)
    acc.add(w[:450], tau[:450], mask[:450])
    acc.add(w[450:], tau[450:], mask[450:])
    wts = np.array([10.0, 1.0, 0.3])
    scale = np.tile(wts, w.shape[0] // 3)[mask]
    ref = np.linalg.lstsq(w[mask] * scale[:, None], tau[mask] * scale, rcond=None)[0]
    np.testing.assert_allclose(acc.solve(wts).params, ref, rtol=1e-10, atol=1e-12)
    assert acc.rows.sum() == mask.sum()


def test_accumulator_errors(rng):
    acc = LeastSquaresAccumulator(4, 2)
    with pytest.raises(ShapeError, match="multiple of 2"):
        acc.add(np.zeros((3, 4)), np.zeros(3))
    with pytest.raises(IdentifiabilityError, match="more equations"):
        acc.solve()
    acc.add(np.column_stack([np.ones(20), np.ones(20), rng.normal(size=(20, 2))]), rng.normal(size=20))
    with pytest.raises(IdentifiabilityError, match=r"the data do not excite a, b \(cond = "):
        acc.solve(names=["a", "b", "c", "d"])  # columns a and b are equal: only their sum is identifiable


def test_a_rank_deficient_problem_keeps_the_prior_where_the_rows_say_nothing():
    """Columns 2 and 3 equal (a joint that moves one way: Coulomb friction and offset are one column): without a prior
    the problem is refused; with one, the other columns and the sum θ2 + θ3 are the truth's (noise-free rows), the
    difference θ2 - θ3 is the prior's, and exactly those two parameters are said to be the prior's (σ NaN)."""
    from dynid.estimators.accumulate import LeastSquaresAccumulator
    from dynid.exceptions import IdentifiabilityError

    rng = np.random.default_rng(7)
    w = rng.standard_normal((400, 4)) * np.array([1.0, 100.0, 0.01, 0.01])
    w[:, 3] = w[:, 2]
    truth = np.array([1.0, -0.02, 30.0, 10.0])
    acc = LeastSquaresAccumulator(4, 1)
    acc.add(w, w @ truth)
    with pytest.raises(IdentifiabilityError, match="do not excite"):
        acc.solve()
    prior = np.array([5.0, 5.0, 1.0, 3.0])
    sol = acc.solve(prior=prior)
    assert sol.params[:2] == pytest.approx(truth[:2], rel=1e-9)
    assert sol.params[2] + sol.params[3] == pytest.approx(truth[2] + truth[3], rel=1e-9)
    assert sol.params[2] - sol.params[3] == pytest.approx(prior[2] - prior[3], rel=1e-9)
    assert sol.from_prior == (2, 3)
    assert np.isnan(sol.params_std[2:]).all() and np.isfinite(sol.params_std[:2]).all()
    full = LeastSquaresAccumulator(3, 1)  # a full-rank problem is solved as without a prior
    full.add(w[:, :3], w[:, :3] @ truth[:3] + 0.01 * rng.standard_normal(400))
    assert full.solve(prior=np.zeros(3)).params == pytest.approx(full.solve().params, rel=1e-12)


def test_a_column_that_only_rounding_fills_keeps_the_prior():
    """A parameter that acts on no row the log keeps (a link inertia only a dead torque channel's joint feels) has a
    column of rounding, ~1e-16 of the others: scaled to unit norm with them it was "determined", at -3.7e14 ± 2.9e15
    on a simulated UR5 with J2's channel dead, and that estimate missed the validation log by 1e15 %. Now it keeps
    the prior, is said to (σ NaN), and the other parameters are the truth's (noise-free rows)."""
    rng = np.random.default_rng(3)
    w = rng.standard_normal((500, 4))
    w[:, 2] = 1e-17 * rng.standard_normal(500)  # what rounding leaves of an absent term
    truth = np.array([1.5, -2.0, 0.7, 4.0])
    acc = LeastSquaresAccumulator(4, 1)
    acc.add(w, w[:, [0, 1, 3]] @ truth[[0, 1, 3]])
    prior = np.array([0.0, 0.0, 0.25, 0.0])
    sol = acc.solve(prior=prior)
    assert sol.params[2] == prior[2] and sol.from_prior == (2,) and np.isnan(sol.params_std[2])
    assert sol.params[[0, 1, 3]] == pytest.approx(truth[[0, 1, 3]], rel=1e-9)


def _one_way_rows(rng, direction: float, noise: float):
    """A joint moving one way only: its Coulomb column sign(q̇) = ``direction`` everywhere, its offset column 1."""
    x = rng.standard_normal((600, 2))
    w = np.column_stack([x, np.full(600, direction), np.ones(600)])
    truth = np.array([2.0, -1.0, 3.0, 0.5])  # the rows see only direction·fc + offset
    acc = LeastSquaresAccumulator(4, 1)
    acc.add(w, w @ truth + noise * rng.standard_normal(600))
    return acc, truth


@pytest.mark.parametrize("direction", [1.0, -1.0])
def test_a_determined_pair_term_goes_to_its_free_member(direction):
    """(fc, offset) as an anchored pair: where the log determines their one term to 10 %, the offset keeps the prior
    and Coulomb friction takes the term (its σ that of the term); the residual is the one of the prior's split."""
    rng = np.random.default_rng(3)
    acc, truth = _one_way_rows(rng, direction, noise=0.05)
    prior = np.array([0.0, 0.0, 0.4, 0.2])
    term = direction * truth[2] + truth[3]
    split = acc.solve(prior=prior)
    sol = acc.solve(prior=prior, pairs=[(2, 3)])
    assert split.anchored == () and sol.anchored == (2,)
    assert sol.params[3] == prior[3]
    assert direction * sol.params[2] + sol.params[3] == pytest.approx(term, abs=0.01)
    assert sol.params[:2] == pytest.approx(split.params[:2], rel=1e-9)
    assert sol.from_prior == (3,) and np.isfinite(sol.params_std[2]) and np.isnan(sol.params_std[3])
    # the free member's σ is the determined term's: the spread of 'direction·fc + offset' over repeated noise draws
    draws = []
    for k in range(200):
        a, _ = _one_way_rows(np.random.default_rng(100 + k), direction, noise=0.05)
        draws.append(a.solve(prior=prior, pairs=[(2, 3)]).params[2])
    assert sol.params_std[2] == pytest.approx(np.std(draws), rel=0.25)
    assert np.sum(acc.joint_residual_sumsq(sol.params)) == pytest.approx(np.sum(acc.joint_residual_sumsq(split.params)),
                                                                         rel=1e-9)


def test_a_loose_or_negative_pair_term_keeps_the_prior_split():
    """Not anchored where the term's σ is over 10 % of it, nor where the free member would turn negative."""
    rng = np.random.default_rng(4)
    acc, _ = _one_way_rows(rng, 1.0, noise=200.0)
    prior = np.zeros(4)
    assert acc.solve(prior=prior, pairs=[(2, 3)]).anchored == ()
    acc, _ = _one_way_rows(rng, 1.0, noise=0.05)
    assert acc.solve(prior=np.array([0.0, 0.0, 0.0, 10.0]), pairs=[(2, 3)]).anchored == ()  # fc would be 3.5 - 10 < 0


def test_an_affine_subset_is_the_weighted_least_squares_of_its_coordinates(rng):
    """``params = offset + basis x``: x against np.linalg.lstsq of the weighted ``(W basis) x = τ - W offset``, the
    covariance ``basis (σ² (AᵀA)⁻¹) basisᵀ`` with σ² from that fit's residual, the fixed directions exactly at
    ``offset``."""
    w, tau, theta = _problem(rng)
    basis = np.zeros((7, 3))
    basis[[1, 4, 6], [0, 1, 2]] = 1.0
    basis[2, 0] = 0.5  # a column that moves two parameters together
    offset = theta + 0.3 * rng.normal(size=7)
    acc = LeastSquaresAccumulator(7, 3)
    acc.add(w, tau)
    wts = np.array([10.0, 1.0, 0.3])
    params, cov, sol = acc.solve_affine(basis, offset, wts)
    scale = np.tile(wts, w.shape[0] // 3)
    a = (w @ basis) * scale[:, None]
    b = (tau - w @ offset) * scale
    x, res, *_ = np.linalg.lstsq(a, b, rcond=None)
    np.testing.assert_allclose(sol.params, x, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(params, offset + basis @ x, rtol=1e-9, atol=1e-12)
    fixed = [0, 3, 5]
    np.testing.assert_array_equal(params[fixed], offset[fixed])
    sigma2 = res[0] / (a.shape[0] - 3)
    np.testing.assert_allclose(cov, basis @ (sigma2 * np.linalg.inv(a.T @ a)) @ basis.T, rtol=1e-7, atol=1e-14)


def test_a_gaussian_prior_is_the_maximum_a_posteriori_estimate(rng):
    """solve(gaussian=(values, sigmas)): the normal equations of the data plus ``(s/σ_i)²(x_i - v_i)²``, ``s`` the
    unconstrained fit's residual σ, solved independently; parameters without a σ (NaN) are not pulled, and an
    infinite-looking σ gives the fit without the prior."""
    w = rng.normal(size=(400, 4)) * [1.0, 5.0, 0.2, 2.0]
    tau = w @ np.array([1.0, -2.0, 3.0, 0.5]) + rng.normal(0.0, 0.3, 400)
    acc = LeastSquaresAccumulator(4)
    acc.add(w, tau)
    plain = acc.solve()
    values, sigmas = np.array([0.0, 0.0, 2.0, 0.0]), np.array([np.nan, np.nan, 0.05, np.nan])
    s2 = plain.residual_std ** 2
    lam = np.zeros(4)
    lam[2] = s2 / sigmas[2] ** 2
    expected = np.linalg.solve(w.T @ w + np.diag(lam), w.T @ tau + lam * values)
    got = acc.solve(gaussian=(values, sigmas))
    np.testing.assert_allclose(got.params, expected, rtol=1e-9)
    assert abs(got.params[2] - 2.0) < abs(plain.params[2] - 2.0)
    np.testing.assert_allclose(acc.solve(gaussian=(values, np.where(np.isnan(sigmas), np.nan, 1e9))).params,
                               plain.params, rtol=1e-9)

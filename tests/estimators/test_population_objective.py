"""Eq. 9 for a whole population, in row blocks: the same values as the plain formula, so DE and PSO visit the
same candidates and return the same parameters however the rows are blocked."""

import numpy as np

from dynid.estimators import DifferentialEvolutionEstimator, FitData, ParticleSwarmEstimator
from dynid.estimators.base import LinearAbsoluteObjective, paper_objective


def _problem(m=9_000, p=6, n_dof=3, seed=1):
    rng = np.random.default_rng(seed)
    w = rng.standard_normal((m, p))
    beta = rng.uniform(-1, 1, p)
    tau = w @ beta + 0.1 * rng.standard_normal(m)
    return w, tau, np.column_stack([beta - 1, beta + 1]), n_dof


def test_blocked_population_objective_equals_eq_9():
    w, tau, _, n = _problem()
    x = np.random.default_rng(2).standard_normal((w.shape[1], 17))
    weights = np.array([1.0, 0.5, 0.25])
    f = LinearAbsoluteObjective(w, tau, n, weights)
    np.testing.assert_allclose(f(x), paper_objective(tau[:, None] - w @ x, n, weights), rtol=1e-13)
    np.testing.assert_allclose(f(x[:, 3]), paper_objective(tau - w @ x[:, 3], n, weights), rtol=1e-13)


def test_de_and_pso_do_not_depend_on_the_blocking(monkeypatch):
    w, tau, bounds, n = _problem()
    results = []
    for block in (10**9, 1000):  # one block (the plain formula's order of operations), then nine
        monkeypatch.setattr(LinearAbsoluteObjective, "BLOCK", block)
        box = FitData(n_dof=n, bounds=bounds)
        de = DifferentialEvolutionEstimator(popsize=3, maxiter=30, rng=np.random.default_rng(4)).fit(w, tau, problem=box)
        pso = ParticleSwarmEstimator(swarm_size=12, maxiter=30, rng=np.random.default_rng(4)).fit(w, tau, problem=box)
        results.append((de.params_, pso.params_))
    for a, b in zip(*results):
        np.testing.assert_allclose(a, b, rtol=1e-12)


def test_a_coordinate_move_is_eq_9_of_the_moved_candidate_and_its_residual_is_written_when_used():
    """The ABC's move: F of x + δ·e_j equals eq. 9 of that candidate; the residual, written only when a later move
    starts from it, is the candidate's (chains of moves stay exact)."""
    from dynid.estimators.base import ShiftedResidual

    w, tau, _, n = _problem(m=3_000)
    f = LinearAbsoluteObjective(w, tau, n)
    x = np.random.default_rng(5).standard_normal(w.shape[1])
    _, r = f.start(x)
    state = r
    for j, delta in ((2, 0.3), (0, -1.1), (2, 0.05)):
        fv, state = f.move(state, j, delta)
        x = x.copy()
        x[j] += delta
        assert isinstance(state, ShiftedResidual)
        np.testing.assert_allclose(fv, paper_objective(tau - w @ x, n), rtol=1e-12)
    np.testing.assert_allclose(state.array(), tau - w @ x, rtol=1e-10, atol=1e-10)

"""Physically consistent least squares (SDP): consistency of the result and recovery of known parameters."""

import numpy as np

from dynid.dynamics.base_parameters import base_parameters
from dynid.dynamics.layout import consistency_layout
from dynid.dynamics.regressor import observation_matrix
from dynid.dynamics.rnea import rnea_torques
from dynid.estimators.physically_consistent import PhysicallyConsistentLeastSquares
from dynid.estimators.problem import FitData
from dynid.model.description import load_robot
from dynid.model.spatial import is_physically_consistent, pseudo_inertia

from ..conftest import random_states


def _data(robot, rng, noise, n=300):
    q, dq, ddq = random_states(rng, n, robot.n_dof)
    w = observation_matrix(robot, q, dq, ddq)
    tau = rnea_torques(robot, q, dq, ddq) + rng.normal(0, noise, q.shape)
    return w, tau.ravel()


def test_pseudo_inertia_is_psd_exactly_for_physical_links(rng):
    robot = load_robot("er16")
    for phi in robot.inertial:
        assert np.linalg.eigvalsh(pseudo_inertia(phi)).min() > 0 and is_physically_consistent(phi)
    bad = robot.inertial[1].copy()
    bad[0] = -bad[3] - bad[5]  # XX < 0 beyond the triangle inequality
    assert np.linalg.eigvalsh(pseudo_inertia(bad)).min() < 0 and not is_physically_consistent(bad)


def test_sdp_is_physically_consistent_and_recovers_the_base_parameters(rng):
    robot = load_robot("er16")
    w, tau = _data(robot, rng, noise=0.5)
    links, nonneg = consistency_layout(robot)
    assert [robot.parameter_names[k] for k in nonneg][:2] == ["fc1", "fv1"]
    prior = robot.standard_parameters() * rng.uniform(0.7, 1.3, robot.n_params)  # a rough CAD guess
    est = PhysicallyConsistentLeastSquares().fit(w, tau, problem=FitData(layout=(links, nonneg), prior=prior))
    for idx in links:
        assert is_physically_consistent(est.params_[idx], tol=1e-7)
    assert np.all(est.params_[nonneg] >= -1e-9)
    base = base_parameters(robot, rng=0)
    truth, got = base.base_from_standard(robot.standard_parameters()), base.base_from_standard(est.params_)
    assert np.linalg.norm(got - truth) / np.linalg.norm(truth) < 0.01


def test_constraints_bind_when_the_data_ask_for_negative_friction(rng):
    """Viscous friction of joint 2 set to -3 in the data: the SDP keeps it at 0, OLS would not."""
    robot = load_robot("er16")
    drive = robot.drive.copy()
    drive[1, robot.drive_terms.index("fv")] = -3.0
    w, tau = _data(robot.with_parameters(np.concatenate([np.concatenate([robot.inertial, drive], 1).ravel()])), rng, noise=0.0)
    links, nonneg = consistency_layout(robot)
    est = PhysicallyConsistentLeastSquares().fit(w, tau, problem=FitData(layout=(links, nonneg), prior=robot.standard_parameters()))
    assert abs(est.params_[robot.parameter_names.index("fv2")]) < 1e-6
    assert est.pseudo_inertia_min_eig_.min() >= -1e-7


def test_a_solver_failure_names_the_likely_cause_not_the_solvers_advice(rng, monkeypatch):
    """Clarabel failing outright (cvxpy's SolverError, "Try another solver, or solve with verbose=True") is said as a
    status without a solution is: one line naming the likely cause and the settings that fix it, never an advice to
    call cvxpy with arguments a user of dynid cannot give."""
    import cvxpy as cp
    import pytest

    from dynid.exceptions import DynIdError

    robot = load_robot("er16")
    w, tau = _data(robot, rng, noise=0.5, n=40)
    links, nonneg = consistency_layout(robot)

    def failing(self, *args, **kwargs):
        raise cp.error.SolverError("Solver 'CLARABEL' failed. Try another solver, or solve with verbose=True for more "
                                   "information.")

    monkeypatch.setattr(cp.Problem, "solve", failing)
    with pytest.raises(DynIdError) as err:
        PhysicallyConsistentLeastSquares().fit(w, tau, problem=FitData(layout=(links, nonneg)))
    said = str(err.value)
    assert "(status solver_error)" in said and "check the torques (or currents) columns and their units" in said
    assert "verbose" not in said and "another solver" not in said and "\n" not in said


def test_consistency_margin_tells_realisable_base_parameters_from_impossible_ones():
    """The true parameters' base projection is realisable (margin > 0); a negative viscous friction or a
    base inertia far below what any mass distribution allows is not."""
    from dynid.estimators import consistency_margin

    robot = load_robot("er16").submodel(3)
    base = base_parameters(robot, rng=0)
    links, nonneg = consistency_layout(robot)
    beta = base.base_from_standard(robot.standard_parameters())
    assert consistency_margin(base.regrouping, beta, links, nonneg) > 0
    bad = beta.copy()
    bad[base.names.index("fv2")] = -0.5
    assert consistency_margin(base.regrouping, bad, links, nonneg) < 0
    bad = beta.copy()
    bad[base.names.index("ZZ1R")] = -10.0  # ZZ1R collects the inertias about axis 1: never negative
    assert consistency_margin(base.regrouping, bad, links, nonneg) < 0


def test_consistency_verdict_names_the_violated_condition():
    from dynid.estimators.physically_consistent import CONSISTENCY_TOL, consistency_verdict

    regrouping = np.array([[1.0, 0.0, 1.0], [0.0, 1.0, 0.0]])  # beta0 = a + c (a inertial), beta1 = fv4 alone
    names = ("ZZ1R", "fv4")
    assert consistency_verdict(-0.5 * CONSISTENCY_TOL) == "yes"
    assert consistency_verdict(float("-inf"), regrouping, np.array([1.0, -0.02]), names, [1]) == "no: fv4 = -0.02 < 0"
    assert consistency_verdict(-0.24).startswith("no: some link's pseudo-inertia has an eigenvalue -0.24")

import numpy as np
import pytest

from dynid.dynamics.base_parameters import base_parameters
from dynid.dynamics.regressor import observation_matrix
from dynid.model.description import load_robot
from dynid.studies.paper_reference import TABLE2, paper_symbol

from ..conftest import random_states


def test_er16_joints_1_to_3_has_the_papers_21_parameters():
    robot = load_robot("er16").submodel(3)
    bp = base_parameters(robot, rng=0)
    assert bp.n_base == 21
    inertial = [n for n in bp.names if not n.startswith("f")]
    assert len(inertial) == 15
    assert sorted(paper_symbol(n) for n in bp.names) == sorted(TABLE2)
    expr = dict(e.split(" = ", 1) for e in bp.expressions)
    assert expr["ZZ1R"].startswith("ZZ1 + YY2") and "YY3" in expr["ZZ1R"]
    assert expr["XX2R"].startswith("XX2 - YY2")


def test_base_invariant_on_independent_data(rng):
    """W·φ == W_base·β for random φ and fresh random states (not those used to find the base)."""
    for robot in (load_robot("er16"), load_robot("er16").submodel(3)):
        bp = base_parameters(robot, rng=1)
        q, dq, ddq = random_states(rng, 50, robot.n_dof)
        w = observation_matrix(robot, q, dq, ddq)
        phi = rng.normal(size=robot.n_params)
        np.testing.assert_allclose(w @ phi, bp.base_observation(w) @ bp.base_from_standard(phi), atol=1e-9)
        assert np.linalg.matrix_rank(bp.base_observation(w)) == bp.n_base


def test_standard_from_base_round_trip(rng):
    robot = load_robot("er16").submodel(3)
    bp = base_parameters(robot, rng=2)
    beta = rng.normal(size=bp.n_base)
    for ref in (None, robot.standard_parameters()):
        phi = bp.standard_from_base(beta, reference=ref)
        np.testing.assert_allclose(bp.base_from_standard(phi), beta, atol=1e-12)
    kept_masses = bp.standard_from_base(beta, reference=robot.standard_parameters())[9::12]
    np.testing.assert_allclose(kept_masses, robot.inertial[:, 9])


def test_six_joint_er16_count():
    bp = base_parameters(load_robot("er16"), rng=0)
    assert bp.n_base == 36 + 12  # anthropomorphic 6R: 36 inertial base parameters + 2 friction per joint


@pytest.mark.parametrize("setting, message", [({"n_samples": 0}, "n_samples: expected a positive integer"),
                                              ({"n_samples": 2.5}, "n_samples: expected a positive integer"),
                                              ({"tol": -1.0}, r"tol: expected a relative tolerance in \(0, 1\)"),
                                              ({"tol": float("nan")}, r"tol: expected a relative tolerance in \(0, 1\)")])
def test_a_sample_count_or_tolerance_out_of_range_is_refused(setting, message):
    """``n_samples=0`` raised NumPy's "zero-size array" error, ``tol=-1`` kept every column in silence."""
    from dynid.exceptions import ConfigError

    with pytest.raises(ConfigError, match=rf"^base_parameters: {message}"):
        base_parameters("er16", **setting)

"""Every function of dynid that takes a robot takes it as Identifier does: a Robot, a built-in robot's name or a
description's path (a name gave an AttributeError traceback: 'str' object has no attribute 'n_dof')."""

import numpy as np
import pytest

import dynid
from dynid.identification.pipeline import IdentificationPipeline


@pytest.fixture(scope="module")
def er16():
    return dynid.load_robot("er16")


def test_a_robot_by_name_gives_what_the_robot_gives(er16):
    rng = np.random.default_rng(0)
    q, dq, ddq = (rng.normal(size=(5, er16.n_dof)) for _ in range(3))
    np.testing.assert_array_equal(dynid.regressor("er16", q, dq, ddq), dynid.regressor(er16, q, dq, ddq))
    np.testing.assert_allclose(dynid.rnea_torques("er16", q, dq, ddq), dynid.rnea_torques(er16, q, dq, ddq))
    assert dynid.base_parameters("er16").names == dynid.base_parameters(er16).names
    np.testing.assert_array_equal(dynid.simulated_log("er16", seconds=1.0).tau, dynid.simulated_log(er16, seconds=1.0).tau)
    assert dynid.urdf_from_robot("er16") == dynid.urdf_from_robot(er16)
    assert dynid.mjcf_from_robot("er16") == dynid.mjcf_from_robot(er16)
    for made in (dynid.ExcitationProblem("er16", 0.6, 2).robot, IdentificationPipeline("er16").robot):
        assert isinstance(made, dynid.Robot) and made.name == "er16"
        np.testing.assert_array_equal(made.standard_parameters(), er16.standard_parameters())


def test_a_log_is_read_for_a_robot_by_name(er16, tmp_path):
    log = dynid.simulated_log(er16, seconds=2.0)
    names = ["time", *(f"q{j + 1}" for j in range(6)), *(f"tau{j + 1}" for j in range(6))]
    path = tmp_path / "log.csv"
    np.savetxt(path, np.column_stack([log.t, log.q, log.tau]), delimiter=",", header=",".join(names), comments="")
    by_name, by_robot = dynid.load_recording(path, "er16"), dynid.load_recording(path, er16)
    np.testing.assert_array_equal(by_name.tau, by_robot.tau)
    np.testing.assert_array_equal(by_name.q, by_robot.q)


def test_anything_else_is_refused_in_one_line_saying_what_is_expected():
    with pytest.raises(TypeError, match=r"^robot: expected a Robot \(dynid.load_robot\(...\)\), a built-in robot's name "
                                        r"or a description's path, got int$"):
        dynid.regressor(3, np.zeros((1, 6)), np.zeros((1, 6)), np.zeros((1, 6)))
    with pytest.raises(dynid.exceptions.ConfigError, match="nosuch"):
        dynid.simulated_log("nosuch")

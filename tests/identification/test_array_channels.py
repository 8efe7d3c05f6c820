"""Arrays given to the library are checked as a log's columns are: a velocity channel not logged, a position step."""

import numpy as np
import pytest

from dynid.exceptions import DataError
from dynid.io.logs.datasets import recording_from_arrays
from dynid.model.description import load_robot


def _arrays():
    t = np.arange(600) * 0.008
    q = 0.3 * np.sin(np.outer(t, np.arange(1, 7)))
    dq = 0.3 * np.cos(np.outer(t, np.arange(1, 7))) * np.arange(1, 7)
    tau = np.cos(np.outer(t, np.ones(6)))
    return t, q, dq, tau


def test_velocities_of_zeros_are_left_out_and_said():
    """dq with joint 4 at 0 throughout while it moves: the recording is the one without dq, with one warning."""
    robot = load_robot("ur10e")
    t, q, dq, tau = _arrays()
    dq[:, 3] = 0.0
    given = recording_from_arrays(robot, t, q, tau, dq, name="run")
    without = recording_from_arrays(robot, t, q, tau, name="run")
    assert given.dq is None
    np.testing.assert_array_equal(given.q, without.q)
    assert given.warnings == ("run: joint 4's measured velocities read 0 rad/s throughout while the positions span "
                              "up to 0.6 rad (a velocity channel not logged?): every joint's velocities are left out "
                              "and derived from the positions",)
    assert recording_from_arrays(robot, *_arrays()[:2], _arrays()[3], _arrays()[2]).dq is not None


def test_a_position_step_is_refused():
    robot = load_robot("ur10e")
    t, q, dq, tau = _arrays()
    q[400:, 0] -= 1.0
    with pytest.raises(DataError, match=r"run: joint 1's position steps by -1.0\d* rad at t = 3.200 s and stays there"):
        recording_from_arrays(robot, t, q, tau, dq, name="run")

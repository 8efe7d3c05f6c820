"""Arrays given to the library are checked as the log readers check a file's positions: degrees read as radians are
refused, positions outside the joint limits said."""

import numpy as np
import pytest

import dynid
from dynid.exceptions import DataError
from dynid.io.logs.datasets import recording_from_arrays


def test_positions_in_degrees_given_as_arrays_are_refused_as_a_files_are():
    """``Identifier(robot).fit(t, numpy.degrees(q), tau)`` fitted without a word (torque error 97 %) and said "model
    ready to check", where the same positions read from a file are refused: "implausible for radians"."""
    robot = dynid.load_robot("ur10e")
    log = dynid.simulated_log(robot, seconds=4, rng=1)
    with pytest.raises(DataError, match=r"arrays: joint \d reaches [\d.]+ rad, implausible for radians: are the "
                                        r"positions in degrees \(numpy.radians\(q\)\)\?"):
        dynid.Identifier(robot).fit(log.t, np.degrees(log.q), log.tau)
    assert recording_from_arrays(robot, log.t, log.q, log.tau).warnings == ()  # radians within the limits: nothing said


def test_one_joint_in_degrees_within_4_pi_is_said_by_its_speed():
    """A wrist that oscillates by ±0.1 rad at 1 Hz, logged in degrees: ±5.7 "rad" stays within 4π and within the
    UR10e's ±2π limits, so nothing was said and its inertia and friction came out scaled. Read as radians it moves at
    33 rad/s (75th percentile), 11× its velocity limit and within it read as degrees: that joint alone is named."""
    robot = dynid.load_robot("ur10e")
    log = dynid.simulated_log(robot, seconds=4, rng=1)
    q = log.q.copy()
    q[:, 5] = 0.1 * np.sin(2 * np.pi * log.t)
    assert recording_from_arrays(robot, log.t, q, log.tau).warnings == ()
    q[:, 5] = np.degrees(q[:, 5])
    (said,) = recording_from_arrays(robot, log.t, q, log.tau, name="run").warnings
    assert said.startswith("run: joint 6 moves at ") and "× its velocity limit (3.14 rad/s) and within it read as " \
        "degrees: are its positions in degrees (numpy.radians(q))?" in said
    speed = float(said.split("moves at ")[1].split(" rad/s")[0])  # its speed's 75th percentile, read as radians
    assert speed == pytest.approx(np.degrees(0.1 * 2 * np.pi) * np.percentile(np.abs(np.cos(2 * np.pi * log.t)), 75),
                                  rel=0.05)


def test_positions_outside_the_joint_limits_given_as_arrays_are_said():
    robot = dynid.load_robot("ur10e")
    log = dynid.simulated_log(robot, seconds=4, rng=1)
    q = log.q.copy()
    q[:, 1] += robot.limits.q_max[1] + 0.3 - q[:, 1].max()  # joint 2 shifted: its peak 0.3 rad beyond its upper limit
    beyond = np.flatnonzero(q[:, 1] > robot.limits.q_max[1] + 0.05)
    (said,) = recording_from_arrays(robot, log.t, q, log.tau, name="run").warnings
    assert said.startswith(f"run: joint 2 leaves its limits [{robot.limits.q_min[1]:.3g}, {robot.limits.q_max[1]:.3g}] "
                           f"rad during {beyond.size} samples from t = {log.t[beyond[0]] - log.t[0]:.3f} s")


def test_time_stamps_in_milliseconds_given_as_arrays_are_refused_as_a_files_are():
    """``fit(t * 1000, q, tau)`` fitted a 20 000 s log without a word ("model ready to check"), where a file's time
    column in milliseconds is refused with its unit."""
    robot = dynid.load_robot("ur10e")
    log = dynid.simulated_log(robot, seconds=4, rng=1)  # 250 Hz
    with pytest.raises(DataError, match=r"^t: the time stamps step by 4 s \(0.25 Hz\), slower than any robot controller "
                                        r"logs \(at least 5 Hz\): they look like ms \(give t × 0.001, in seconds\)$"):
        dynid.Identifier(robot).fit(log.t * 1000.0, log.q, log.tau)


def test_arrays_of_a_robot_at_rest_throughout_are_refused_for_what_they_are():
    """Positions that never change were answered "every joint's torque reads one value throughout (dead channels, or
    not the torque or current columns?)": the torques were fine, the robot did not move. A file's frozen log was
    already said so."""
    robot = dynid.load_robot("ur10e")
    log = dynid.simulated_log(robot, seconds=4, rng=1)
    rest = np.tile(log.q[:1], (log.t.size, 1))
    with pytest.raises(DataError, match=r"^arrays: no joint's position ever changes: a robot at rest throughout, or the "
                                        r"wrong array\?$"):
        dynid.Identifier(robot).fit(log.t, rest, np.tile(log.tau[:1], (log.t.size, 1)))
    model = dynid.Identifier(robot).fit(log).model_  # a pose's torques are still predicted
    predicted = model.predict(log.t, rest)
    assert predicted.shape == rest.shape and np.any(np.isfinite(predicted))

"""Benchmark: the regressor of a 7-axis tracked arm against its 6-axis arm, per joint (issue "Every arm a user has").

The er16 (6 revolute joints, built as the tracked one is: its joints, links and drive terms, no coupled wrist) and the
er16 on a linear track (a prismatic joint along x under its base, 7 joints),
25,000 random samples each, the full (N, n_dof, n_params) array by the compiled form (each robot's SIMD code; the
NumPy budget is spent first), best of 10 rounds in which the two are timed in turn (each first in half of them: the one timed first in a
round ran slower, NOTEBOOK.md), each after a warm-up. Prints the time per sample and per sample and joint of each,
and their ratio (target: the tracked arm's per joint within 1.3x the arm's; the pairs of joints alone make it
(7·8/2/7)/(6·7/2/6) = 1.14x). Checks first that the tracked arm's torques equal Pinocchio's RNEA.
"""

from __future__ import annotations

import numpy as np
from timing import best_of  # benchmarks/timing.py (run as scripts from benchmarks/)

from dynid.dynamics import regressor as regressor_module
from dynid.dynamics.regressor import regressor
from dynid.dynamics.rnea import rnea_torques
from dynid.model.description import load_robot
from dynid.model.robot import Joint, Robot, default_limits

N = 25_000
REPEATS = 5
CARRIAGE = np.array([0.4, 0.01, 0.02, 0.5, 0.0, 0.6, 1.0, 0.5, -0.5, 30.0])
"""The carriage's ten inertial parameters (30 kg), eq. 5 order."""


def tracked(arm: Robot, track: bool = True) -> Robot:
    """``arm`` on a track: a prismatic joint along x first, its carriage, drive terms as the arm's first joint's; with
    ``track`` False, the arm alone built the same way (its joints, links and drive terms; no coupled wrist)."""
    if not track:
        return Robot(arm.name, arm.joints, arm.gravity, arm.inertial, arm.drive_terms, arm.drive, arm.drive_gains,
                     default_limits(arm.n_dof))
    slide = Joint("track", np.eye(3), np.zeros(3), np.array([1.0, 0.0, 0.0]), prismatic=True)
    return Robot(f"{arm.name} on a track", (slide, *arm.joints), arm.gravity, np.vstack([CARRIAGE, arm.inertial]),
                 arm.drive_terms, np.vstack([arm.drive[:1], arm.drive]), np.r_[1.0, arm.drive_gains],
                 default_limits(arm.n_dof + 1))


def main() -> None:
    regressor_module._numpy_used = regressor_module.NUMPY_SAMPLES  # the compiled form from the first sample
    arm = load_robot("er16")
    robots = (tracked(arm, track=False), tracked(arm))
    rng = np.random.default_rng(0)
    q7, dq7, ddq7 = (rng.uniform(-1.5, 1.5, (N, 7)) for _ in range(3))
    y = regressor(robots[1], q7[:200], dq7[:200], ddq7[:200])
    tau = rnea_torques(robots[1], q7[:200], dq7[:200], ddq7[:200])
    assert np.allclose(y @ robots[1].standard_parameters(), tau, atol=1e-8), "the tracked arm's regressor is not RNEA"
    per_joint = []
    print(f"samples: {N}, best of {2 * REPEATS} rounds, the two robots timed in turn, each first in half of them, "
          "compiled (SIMD) form")
    calls = [lambda robot=robot: regressor(robot, q7[:, -robot.n_dof:], dq7[:, -robot.n_dof:], ddq7[:, -robot.n_dof:])
             for robot in robots]
    best = [np.inf, np.inf]
    for r in range(2 * REPEATS):  # in turn, each first in half the rounds: the one timed first in a round ran slower
        for i in ((0, 1) if r % 2 else (1, 0)):
            best[i] = min(best[i], best_of(calls[i], 1))
    for robot, t in zip(robots, best):
        per_joint.append(t / N / robot.n_dof)
        print(f"{robot.name:<18} {robot.n_dof} joints: {1e6 * t / N:7.3f} µs/sample, "
              f"{1e6 * t / N / robot.n_dof:6.3f} µs/sample/joint")
    ratio = per_joint[1] / per_joint[0]
    print(f"ratio per joint (tracked / arm): {ratio:.2f}x   target <= 1.3x: {'met' if ratio <= 1.3 else 'NOT met'}")


if __name__ == "__main__":
    main()

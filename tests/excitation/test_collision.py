"""The links' distances along an excitation (issue "An excitation safe to run on the real robot", item 2): coal's
capsule distances against a brute-force distance between the skeleton's segments, and what dynid excite says."""

from __future__ import annotations

import numpy as np


def _brute(a, b, radius: float) -> float:
    """Surface distance of two capsules by sampling both segments densely (independent of coal)."""
    s = np.linspace(0.0, 1.0, 401)[:, None]
    pa, pb = a[0] + s * (a[1] - a[0]), b[0] + s * (b[1] - b[0])
    return float(np.min(np.linalg.norm(pa[:, None] - pb[None], axis=2))) - 2 * radius


def test_coals_capsule_distances_equal_the_segments_own(rng):
    from dynid.excitation.collision import _distance

    for _ in range(20):
        a, b = rng.normal(size=(2, 3)), rng.normal(size=(2, 3)) + rng.normal(size=3)
        assert abs(_distance(a, b, 0.05) - _brute(a, b, 0.05)) < 2e-3
    sphere = np.array([[0.3, 0.0, 0.0], [0.3, 0.0, 0.0]])  # a zero-length segment: a sphere
    assert abs(_distance(sphere, np.array([[0.0, -1, 0.5], [0.0, 1, 0.5]]), 0.1) - (np.hypot(0.3, 0.5) - 0.2)) < 1e-6


def test_the_closest_pair_along_a_trajectory_is_found():
    from dynid.excitation.collision import _segments, self_clearance, touching_pairs
    from dynid.model.description import load_robot

    robot = load_robot("ur10e")
    rng = np.random.default_rng(4)
    q = rng.uniform(-2.5, 2.5, (20, robot.n_dof))
    t = np.arange(20) * 0.01
    found = self_clearance(robot, t, q, 0.05)
    pairs = touching_pairs(robot, 0.05)
    assert found.pairs == len(pairs) and all(j - i >= 2 for i, j in pairs)
    seg = _segments(robot, q)
    brute = min((_brute(seg[k, i], seg[k, j], 0.05), (i + 1, j + 1), t[k]) for k in range(20) for i, j in pairs)
    assert abs(found.distance - brute[0]) < 2e-3 and found.pair == brute[1] and found.time == brute[2]

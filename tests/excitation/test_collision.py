"""The links' distances along an excitation (issue "An excitation safe to run on the real robot", item 2): coal's
capsule distances against a brute-force distance between the skeleton's segments, and what dynid excite says."""

from __future__ import annotations

import numpy as np
import pytest


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
    from dynid.excitation.collision import self_clearance, touching_pairs
    from dynid.excitation.obstacles import link_segments
    from dynid.model.description import load_robot

    robot = load_robot("ur10e")
    rng = np.random.default_rng(4)
    q = rng.uniform(-2.5, 2.5, (20, robot.n_dof))
    t = np.arange(20) * 0.01
    found = self_clearance(robot, t, q, 0.05)
    pairs = touching_pairs(robot, 0.05)
    assert found.pairs == len(pairs) and all(j - i >= 2 for i, j in pairs)
    seg = link_segments(robot, q)
    brute = min((_brute(seg[k, i], seg[k, j], 0.05), (i + 1, j + 1), t[k]) for k in range(20) for i, j in pairs)
    assert abs(found.distance - brute[0]) < 2e-3 and found.pair == brute[1] and found.time == brute[2]


@pytest.mark.parametrize("name,radius,spread", [("ur10e", 0.05, 2.5), ("ur10e", 0.12, 3.0), ("er16", 0.3, 2.0)])
def test_coal_is_asked_where_the_closest_pair_can_be_and_finds_what_asking_it_everywhere_finds(name, radius, spread):
    """The clearance coal measures at the samples and pairs the closed form screens equals, to the bit, coal asked at
    every sample and pair (capsules apart, and overlapping: the ER-16's forearm and base, as in its digest)."""
    from dynid.excitation.collision import _distance, self_clearance, touching_pairs
    from dynid.excitation.obstacles import link_segments
    from dynid.model.description import load_robot

    robot = load_robot(name)
    rng = np.random.default_rng(11)
    q = rng.uniform(-spread, spread, (300, robot.n_dof))
    t = np.arange(300) * 0.002
    found = self_clearance(robot, t, q, radius)
    pairs, seg = touching_pairs(robot, radius), link_segments(robot, q)
    best = (np.inf, None, None)
    for k in range(300):  # coal at every sample and pair, the first smallest kept
        for i, j in pairs:
            d = _distance(seg[k, i], seg[k, j], radius)
            if d < best[0]:
                best = (d, (i + 1, j + 1), t[k])
    assert (found.distance, found.pair, found.time) == best


def test_the_segments_closest_points_equal_a_dense_search_in_every_case(rng):
    """``closest_points`` (Ericson's, for arrays of segments) against sampling both segments densely: random pairs,
    parallel ones, crossing ones, a point against a segment and two points."""
    from dynid.excitation.collision import closest_points

    cases = [(rng.normal(size=(2, 3)), rng.normal(size=(2, 3)) + rng.normal(size=3)) for _ in range(30)]
    cases += [(np.array([[0.0, 0, 0], [1, 0, 0]]), np.array([[0.2, 0.3, 0], [1.5, 0.3, 0]])),  # parallel, overlapping
              (np.array([[0.0, 0, 0], [1, 0, 0]]), np.array([[2.0, 0.3, 0], [3, 0.3, 0]])),  # parallel, apart
              (np.array([[-1.0, 0, 0], [1, 0, 0]]), np.array([[0.0, -1, 0], [0, 1, 0]])),  # crossing
              (np.array([[0.3, 0.2, 0.1], [0.3, 0.2, 0.1]]), np.array([[0.0, -1, 0.5], [0, 1, 0.5]])),  # a point
              (np.array([[0.0, -1, 0.5], [0, 1, 0.5]]), np.array([[0.3, 0.2, 0.1], [0.3, 0.2, 0.1]])),
              (np.array([[0.1, 0, 0], [0.1, 0, 0]]), np.array([[0.0, 0.4, 0], [0.0, 0.4, 0]]))]  # two points
    a = np.array([c[0] for c in cases])
    b = np.array([c[1] for c in cases])
    s, t = closest_points(a[:, 0], a[:, 1], b[:, 0], b[:, 1])
    assert np.all((0 <= s) & (s <= 1) & (0 <= t) & (t <= 1))
    found = np.linalg.norm(a[:, 0] + s[:, None] * (a[:, 1] - a[:, 0]) - b[:, 0] - t[:, None] * (b[:, 1] - b[:, 0]), axis=1)
    dense = np.array([_brute(x, y, 0.0) for x, y in cases])
    assert np.all(found <= dense + 1e-12) and np.all(found >= dense - 2e-3), np.c_[found, dense]


def test_capsule_self_distances_are_coals_and_their_gradient_the_finite_differences():
    """What the design keeps apart with ``avoid_self_collision``: the capsules' surface distances equal coal's (the
    set-points' check), and their gradient the distances' central differences."""
    from dynid.excitation.collision import CapsuleSelfDistances, _distance, touching_pairs
    from dynid.excitation.obstacles import link_segments
    from dynid.model.description import load_robot

    robot = load_robot("ur10e")
    q = np.random.default_rng(7).uniform(-2.5, 2.5, (30, robot.n_dof))
    pairs = touching_pairs(robot, 0.05)
    measured = CapsuleSelfDistances(robot, q, 0.05, pairs)
    seg = link_segments(robot, q)
    coal_d = np.array([[_distance(seg[k, i], seg[k, j], 0.05) for i, j in pairs] for k in range(q.shape[0])])
    np.testing.assert_allclose(measured.dist, coal_d, atol=1e-9)
    grad = measured.distances(gradient=True).gradient
    h = 1e-6
    for d in range(robot.n_dof):
        step = np.zeros(robot.n_dof)
        step[d] = h
        central = (CapsuleSelfDistances(robot, q + step, 0.05, pairs).dist
                   - CapsuleSelfDistances(robot, q - step, 0.05, pairs).dist) / (2 * h)
        np.testing.assert_allclose(grad[:, :, d], central, atol=1e-6)


def test_a_row_per_window_holds_every_sample_of_it():
    """The capsules' constraint rows of ``CAPSULE_WINDOW`` samples: each row's soft minimum lies at or below the
    smallest value of its samples (so a row at or above zero holds each of them), the last row padded; the gradient
    rows are the weighted sums of their samples' gradients."""
    from dynid.excitation.design import _windows, soft_min

    rng = np.random.default_rng(3)
    values, jac = rng.normal(size=(23, 4)) * 0.05, rng.normal(size=(23, 4, 7))
    v, j = _windows(values, jac, 10)
    assert v.shape == (3, 40) and j.shape == (3, 40, 7)
    soft, grad = soft_min(v, j)
    for r, rows in enumerate((slice(0, 10), slice(10, 20), slice(20, 23))):
        assert soft[r] <= values[rows].min() + 1e-15
        assert soft[r] >= values[rows].min() - np.log(values[rows].size) / 1000.0
    step = 1e-7 * rng.normal(size=7)
    moved = soft_min(*_windows(values + np.einsum("npx,x->np", jac, step), None, 10))[0]
    np.testing.assert_allclose(moved - soft, grad @ step, atol=1e-10)

"""Units that stand out from a fleet: the z-scores against hand-computed values, and the false-flag rate measured on
simulated fleets whose units differ only at random."""

import numpy as np
import pytest
from scipy.stats import norm, t

from dynid.exceptions import ShapeError
from dynid.fleet.outliers import FALSE_FLAG_RATE, fleet_outliers, fleet_z


def test_a_unit_off_a_fleet_that_agrees_within_its_sigma_gets_the_z_computed_by_hand():
    x = np.array([[10.0], [10.01], [9.99], [10.5], [10.0], [10.02]])
    s = np.full_like(x, 0.02)
    z, limit = fleet_z(x, s)
    others = np.array([10.0, 10.01, 9.99, 10.0, 10.02])
    med = np.median(others)
    spread = max(1.4826 * np.median(np.abs(others - med)), 0.02)
    assert z[3, 0] == pytest.approx((10.5 - med) / np.hypot(spread, 0.02))
    assert limit[3, 0] == pytest.approx(norm.isf(FALSE_FLAG_RATE / (2 * x.size)))
    found, _ = fleet_outliers([f"u{i}" for i in range(6)], ["K2"], x, s)
    assert [(o.unit, o.parameter) for o in found] == [("u3", "K2")]


def test_a_parameter_that_varies_between_units_is_judged_against_a_prediction_interval():
    x = np.array([[1.0], [1.3], [0.8], [1.1], [0.9], [1.2]])
    s = np.full_like(x, 0.01)  # far below the units' spread: they differ
    z, limit = fleet_z(x, s, may_differ=[True])
    others = np.delete(x[:, 0], 1)
    expected = (1.3 - others.mean()) / np.sqrt(others.var(ddof=1) * (1 + 1 / 5) + 0.01 ** 2)
    assert z[1, 0] == pytest.approx(expected)
    assert limit[1, 0] == pytest.approx(t.isf(FALSE_FLAG_RATE / (2 * x.size), 4))  # Student's t, 5 others
    assert fleet_outliers([f"u{i}" for i in range(6)], ["fv1"], x, s, may_differ=[True])[0] == ()


@pytest.mark.parametrize("units", [6, 20])
def test_fleets_whose_units_differ_only_at_random_are_rarely_flagged(units):
    rng = np.random.default_rng(3)
    fleets, flagged = 150, 0
    for _ in range(fleets):
        same = 10 + rng.normal(0, 0.02, size=(units, 20))                 # agree within σ (gains, inertia)
        varied = rng.uniform(0.8, 1.2, size=(units, 20)) + rng.normal(0, 0.01, size=(units, 20))  # friction ±20 %
        std = np.column_stack([np.full((units, 20), 0.02), np.full((units, 20), 0.01)])
        found, _ = fleet_outliers([str(u) for u in range(units)], [str(k) for k in range(40)], np.column_stack([same, varied]), std,
                                  may_differ=[False] * 20 + [True] * 20)
        flagged += bool(found)
    assert flagged / fleets <= 3 * FALSE_FLAG_RATE  # 1 % designed (a uniform spread has lighter tails than normal)


def test_malformed_values_are_refused():
    with pytest.raises(ShapeError, match="values"):
        fleet_z(np.zeros(5))
    with pytest.raises(ShapeError, match="std"):
        fleet_z(np.zeros((5, 2)), np.zeros((5, 3)))
    with pytest.raises(ShapeError, match="values"):
        fleet_outliers(["a", "b"], ["x"], np.zeros((3, 1)))

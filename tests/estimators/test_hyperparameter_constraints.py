"""An estimator's hyper-parameters are checked where the estimator is built (issue "Every assurance checked on what
the user meets", item 6): from a config's estimators entry they were tracebacks (``colony_size = 6.0`` a TypeError,
``colony_size = 10**9`` a 432 GiB allocation, a negative or NaN ``prior_weight`` a cvxpy DCPError), an SDP margin of
-1 gave a "physically consistent" estimate with pseudo-inertia eigenvalues down to -1, a zero DE ``popsize`` ran."""

import re

import pytest

from dynid.estimators.bee_colony import BeeColonyEstimator
from dynid.estimators.global_search import DifferentialEvolutionEstimator, ParticleSwarmEstimator
from dynid.estimators.physically_consistent import PhysicallyConsistentLeastSquares
from dynid.exceptions import ConfigError
from dynid.model.description import parse_angle

from ..cli.refusals import assert_refused, dynid

CASES = [
    ("abc", "colony_size = 6.0", "BeeColonyEstimator: colony_size: expected an integer from 2 to 100000, got 6.0"),
    ("abc", "colony_size = 1000000000", "colony_size: expected an integer from 2 to 100000, got 1000000000"),
    ("abc", "limit = 0", "limit: expected an integer of at least 1, got 0"),
    ("sdp", "prior_weight = -1.0", "PhysicallyConsistentLeastSquares: prior_weight: expected a finite number of at "
                                   "least 0, got -1.0"),
    ("sdp", "prior_weight = nan", "prior_weight: expected a finite number of at least 0, got nan"),
    ("sdp", "epsilon = -1.0", "epsilon: expected a finite number of at least 0, got -1.0"),
    ("de", "popsize = 0", "DifferentialEvolutionEstimator: popsize: expected an integer from 1 to 10000, got 0"),
    ("pso", "swarm_size = true", "swarm_size: expected an integer from 2 to 100000, got True"),
]


@pytest.mark.parametrize("key, setting, message", CASES)
def test_a_configs_bad_hyperparameter_is_one_line_naming_the_entry(tmp_path, key, setting, message):
    from tests.simulated_logs import simulated_case

    cfg, _ = simulated_case(tmp_path, "er16", 100.0, "fourier", duration=5.0)
    cfg.write_text(cfg.read_text().replace('estimators = ["ols"]', f'estimators = ["ols", {{ key = "{key}", {setting} }}]'))
    p = dynid("identify", cfg, "--out", tmp_path / "out", "-q")
    assert_refused(p, message, tmp_path / "out")
    assert f"config.toml: estimation.estimators[1]: {key}: " in p.stderr


@pytest.mark.parametrize("cls, params", [
    (BeeColonyEstimator, {"colony_size": 6.0}), (BeeColonyEstimator, {"maxiter": -1}),
    (PhysicallyConsistentLeastSquares, {"epsilon": float("inf")}),
    (DifferentialEvolutionEstimator, {"tol": -1e-3}), (ParticleSwarmEstimator, {"maxiter": 0}),
])
def test_the_api_refuses_them_where_the_object_is_built_and_in_set_params(cls, params):
    with pytest.raises(ConfigError, match=re.escape(f"{cls.__name__}: {next(iter(params))}: expected")) as err:
        cls(**params)
    assert err.value.field == next(iter(params))
    good = cls()
    with pytest.raises(ConfigError):
        good.set_params(**params)
    assert cls().get_params() == cls(**cls().get_params()).get_params()  # the defaults pass their own check


def test_an_angle_divided_by_zero_is_one_line():
    with pytest.raises(ConfigError, match=r"joints\[2\]\.position_offset: expected a finite angle like 'pi/2', got 'pi/0'"):
        parse_angle("pi/0", "joints[2].position_offset")
    assert parse_angle("-3*pi/4", "x") == pytest.approx(-2.356194490192345)


def test_a_nan_drive_gain_is_refused_naming_the_joint(tmp_path):
    """A NaN drive gain passed the description's check (NaN is not <= 0) and the log's currents became NaN torques
    that were filled in and identified to "model ready"."""
    from pathlib import Path

    from tests.simulated_logs import simulated_case

    cfg, _ = simulated_case(tmp_path, "er16", 100.0, "fourier", duration=5.0)
    robot = Path(re.search(r'^robot = "(.*)"$', cfg.read_text(), flags=re.M).group(1))
    robot.write_text(re.sub(r"drive_gain = [^\n]*", "drive_gain = nan", robot.read_text(), count=1))
    p = dynid("identify", cfg, "--out", tmp_path / "out", "-q")
    assert_refused(p, "joints[0].drive_gain: expected a finite, positive gain (N·m/A), got nan", tmp_path / "out")
    assert robot.name in p.stderr

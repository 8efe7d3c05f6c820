"""A prepared log with another rest model or presliding distance: its direction of motion computed anew, and kept
where neither changes (``PreparedData.with_rest_model``)."""

import numpy as np
import pytest

import dynid
from dynid.exceptions import ConfigError
from dynid.preprocessing.preparation import prepare
from dynid.preprocessing.prepared import direction_of_motion
from dynid.preprocessing.settings import Preprocessing


@pytest.fixture(scope="module")
def data():
    """A simulated log whose joints hold still for 2 s of its 10 (a rest model acts only at rest)."""
    from dataclasses import replace

    log = dynid.simulated_log(dynid.load_robot("ur10e"), seconds=10.0, rate=250.0, rng=2)
    q = np.array(log.q)
    q[1000:1500] = q[1000]
    return prepare(replace(log, q=q), Preprocessing())


def _anew(data, settings):
    return np.asarray(direction_of_motion(data.dq, data.motion, settings, data.rate))


def test_the_same_rest_model_keeps_the_direction_it_would_compute_again(data):
    n = data.dq.shape[1]
    same = data.with_rest_model((data.settings.rest_friction,) * n, data.settings.presliding)
    assert same.direction is data.direction and same.settings.rest_friction == (data.settings.rest_friction,) * n
    np.testing.assert_array_equal(np.asarray(same.direction), _anew(data, same.settings))


@pytest.mark.parametrize("rest,presliding", [("zero", 0.0), (0.5, 0.0), ("held", 0.002)])
def test_another_rest_model_or_presliding_distance_computes_it_anew(data, rest, presliding):
    other = data.with_rest_model(rest, presliding)
    assert other.direction is not data.direction
    np.testing.assert_array_equal(np.asarray(other.direction), _anew(data, other.settings))
    assert not np.array_equal(np.asarray(other.direction), np.asarray(data.direction))


def test_an_unknown_rest_model_is_refused(data):
    with pytest.raises(ConfigError, match="rest_friction"):
        data.with_rest_model("sticky", 0.0)


@pytest.mark.parametrize("presliding", [-0.001, float("nan"), float("inf"), 5.0, "x", (0.001, -1.0)])
def test_a_presliding_distance_no_drive_has_is_refused_where_the_settings_are_made(presliding):
    """Through the API as through a config (tests/cli/test_bad_input_corpus.py): a negative distance made the Dahl
    columns grow without bound and an infinite one kept them at 0, and either was fitted in silence."""
    with pytest.raises(ConfigError, match=r"preprocessing\.presliding: expected a distance from 0 to 1"):
        Preprocessing(presliding=presliding)
    assert Preprocessing(presliding=(0.0, 0.001, 1.0)).presliding == (0.0, 0.001, 1.0)

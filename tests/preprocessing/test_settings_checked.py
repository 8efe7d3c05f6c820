"""``Preprocessing`` refuses a setting no log can mean where it is made, naming the field, as a config's
``[preprocessing]`` table is checked (issue "Every assurance checked on what the user meets", bad input): through the
API these were used in silence (a negative cutoff as none, a NaN cutoff, a filter of order 0, a negative relaxation
time, a NaN rest velocity ending in "0 rows") or raised a NumPy error (a negative trim)."""

import pytest

import dynid
from dynid.exceptions import ConfigError

BAD = {
    "order": (0, "an integer >= 1"), "decimation": (0, "an integer >= 1"), "chunk": (2.5, "an integer >= 1"),
    "smoothing_passes": (-1, "an integer >= 0"), "band": (0.0, "a number > 0"), "position_cutoff": (-5.0, "a number >= 0"),
    "velocity_cutoff": (float("nan"), "a number >= 0"), "parallel_cutoff": ("10", "a number >= 0"),
    "trim": (-1.0, "a number >= 0"), "rest_friction": (-1.0, "relaxation time >= 0 s"),
    "rest_velocity": (float("nan"), '"auto", a speed >= 0'), "min_speed": ((0.1, -0.2), '"auto", a speed >= 0'),
    "coulomb_velocity": ("fast", '"auto", a speed >= 0'), "rest_floor": ("auto", "a speed >= 0"),
}


@pytest.mark.parametrize("field", sorted(BAD))
def test_a_setting_out_of_its_range_is_refused_naming_the_field(field):
    value, expected = BAD[field]
    with pytest.raises(ConfigError, match=rf"^preprocessing\.{field}: expected .*{expected}"):
        dynid.Preprocessing(**{field: value})


def test_the_settings_dynid_itself_derives_and_the_edges_pass():
    s = dynid.Preprocessing(order=1, band=1e-3, position_cutoff=0.0, velocity_cutoff=0.0, parallel_cutoff=0.0,
                            decimation=1, trim=0.0, chunk=1, smoothing_passes=0, rest_friction=("held", "zero", 0.0, 2.5),
                            rest_velocity=(0.0, 0.1), min_speed=0.0, coulomb_velocity="auto", rest_floor=(0.0, 0.01))
    assert s.order == 1 and s.rest_friction == ("held", "zero", 0.0, 2.5)
    robot = dynid.load_robot("er16")
    log = dynid.simulated_log(robot, seconds=10.0, rng=1)
    resolved = dynid.identify_from_arrays(robot, log.t, log.q, log.tau, estimators=("ols",)).settings["preprocessing"]
    assert dynid.Preprocessing(**{k: tuple(v) if isinstance(v, list) else v for k, v in resolved.items()}).order == resolved["order"]

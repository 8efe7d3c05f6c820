"""A robot description's nominal drive values are finite (issue "Every assurance checked on what the user meets",
item 6): a NaN value, plain or as a prior's ``{ value, sigma }``, loaded and became a NaN prior that named no field."""

from importlib import resources

import pytest

from dynid.exceptions import ConfigError
from dynid.model.description import load_robot

URDF = resources.files("dynid.model") / "robots" / "ur10e.urdf"


@pytest.mark.parametrize("given, message", [
    ("fc = nan", r"joints\[0\]\.fc: expected a finite nominal value, got nan"),
    ("fc = { value = nan, sigma = 1.0 }", r"joints\[0\]\.fc: expected a finite nominal value, got nan"),
    ("fv = -inf", r"joints\[0\]\.fv: expected a finite nominal value, got -inf"),
])
def test_a_nominal_value_that_is_not_finite_is_named(tmp_path, given, message):
    path = tmp_path / "arm.toml"
    path.write_text(f'name = "arm"\nconvention = "urdf"\nurdf = "{URDF}"\ndrive_terms = ["fc", "fv"]\n[[joints]]\n{given}\n'
                    + "[[joints]]\n" * 5)
    with pytest.raises(ConfigError, match=rf"arm.toml: {message}"):
        load_robot(path)
    path.write_text(path.read_text().replace(given, "fc = { value = 2.0, sigma = 1.0 }"))
    robot = load_robot(path)
    assert robot.drive[0, 0] == 2.0 and dict(robot.prior_sigma)["fc1"] == 1.0

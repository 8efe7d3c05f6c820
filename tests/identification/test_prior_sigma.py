"""A drive term stated with its uncertainty (issue "Never worse than the description", item 2): ``Ia = { value,
sigma }`` in ``[[joints]]`` pulls the drive-only and the physically consistent estimates toward the value as a
Gaussian prior: a σ of almost 0 holds the term at the value, a σ far above what the log determines leaves the
estimate as without it."""

from __future__ import annotations

import re

import numpy as np
import pytest


def _identify(tmp_path, sigma: float | None, value: float = 0.7):
    from dynid.identification.run import run_identification
    from dynid.io.identification_config import load_identification_config
    from tests.simulated_logs import simulated_case

    folder = tmp_path / f"s{sigma}"
    folder.mkdir()
    cfg, _ = simulated_case(folder, "er16", 125.0, "fourier", duration=10.0)
    cfg.write_text(cfg.read_text().replace('estimators = ["ols"]', 'estimators = ["wls", "sdp"]'))
    robot = re.search(r'^robot = "(.*)"', cfg.read_text(), flags=re.M).group(1)
    text = open(robot).read()
    given = f"{value}" if sigma is None else f"{{ value = {value}, sigma = {sigma} }}"  # the same nominal value
    text = text.replace('name = "joint2"', f'name = "joint2"\nIa = {given}', 1)
    assert f"Ia = {given}" in text
    open(robot, "w").write(text)
    result = run_identification(load_identification_config(cfg))
    k = list(result.model.parameter_names).index("Ia2")
    return result.drive_only.standard[k], result.estimates["dynid SDP"].standard[k], dict(result.model.prior_sigma)


@pytest.fixture(scope="module")
def plain(tmp_path_factory):
    return _identify(tmp_path_factory.mktemp("plain"), None)


def test_a_sigma_near_zero_holds_the_term_at_its_value(tmp_path, plain):
    drive_only, sdp, stated = _identify(tmp_path, 1e-9)
    assert stated == {"Ia2": 1e-9}
    assert abs(plain[0] - 0.7) > 0.05 and abs(plain[1] - 0.7) > 0.05  # without σ the log sets the term elsewhere
    assert plain[2] == {}
    assert abs(drive_only - 0.7) < 1e-4 and abs(sdp - 0.7) < 1e-3


def test_a_sigma_far_above_what_the_log_determines_changes_nothing(tmp_path, plain):
    drive_only, sdp, _ = _identify(tmp_path, 1e6)
    np.testing.assert_allclose([drive_only, sdp], plain[:2], rtol=1e-5, atol=1e-6)

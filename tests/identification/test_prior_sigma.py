"""A drive term stated with its uncertainty (issue "Never worse than the description", item 2): ``Ia = { value,
sigma }`` in ``[[joints]]`` pulls the drive-only, the physically consistent and the least-squares estimates toward
the value as a Gaussian prior: a σ of almost 0 holds the term at the value, a σ far above what the log determines
leaves the estimate as without it; a term least squares holds regrouped with others is said."""

from __future__ import annotations

import re

import numpy as np
import pytest


def _stated(folder, sigma: float | None, term: str, joint: int, value: float, estimators: str):
    """The ER-16's simulated case in ``folder`` identified with ``term`` of ``joint`` stated as ``{ value, sigma }``
    (``value`` alone without a σ) in place of the simulated arm's own, where it states one."""
    from dynid.identification.run import run_identification
    from dynid.io.config.identification_config import load_identification_config
    from tests.simulated_logs import simulated_case

    folder.mkdir()
    cfg, _ = simulated_case(folder, "er16", 125.0, "fourier", duration=10.0)
    cfg.write_text(cfg.read_text().replace('estimators = ["ols"]', f"estimators = {estimators}"))
    robot = re.search(r'^robot = "(.*)"', cfg.read_text(), flags=re.M).group(1)
    given = f"{value}" if sigma is None else f"{{ value = {value}, sigma = {sigma} }}"
    blocks = open(robot).read().split("[[joints]]")
    line = re.compile(rf"^{term} = .*$", flags=re.M)
    block = blocks[joint]
    blocks[joint] = line.sub(f"{term} = {given}", block) if line.search(block) else block.replace(
        f'name = "joint{joint}"', f'name = "joint{joint}"\n{term} = {given}', 1)
    assert f"{term} = {given}" in blocks[joint]
    open(robot, "w").write("[[joints]]".join(blocks))
    return run_identification(load_identification_config(cfg))


def _identify(tmp_path, sigma: float | None, value: float = 0.7):
    result = _stated(tmp_path / f"s{sigma}", sigma, "Ia", 2, value, '["wls", "sdp"]')  # the same nominal value
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


def _least_squares(tmp_path, sigma: float | None, term: str = "fv", joint: int = 2, value: float = 40.0):
    """The WLS estimate's base parameter ``term+joint`` with ``term = { value, sigma }`` stated, its σ, and the run's
    warnings."""
    result = _stated(tmp_path / f"ls{term}{joint}{sigma}", sigma, term, joint, value, '["wls"]')
    wls = result.estimates["dynid WLS"]
    names = list(result.base.names)
    k = names.index(f"{term}{joint}") if f"{term}{joint}" in names else None
    return (None if k is None else wls.params[k]), (None if k is None else wls.std[k]), result.warnings


def test_least_squares_pulls_a_stated_term_as_its_gaussian_prior(tmp_path):
    """WLS with fv2 = { value = 40, sigma } where the simulated arm's is 6: a σ of almost 0 holds fv2 at 40 (its σ
    the prior's, times the residual's growth), a σ far above what the log determines gives WLS's estimate without it, to 1e-6 (its σ too)."""
    free, free_std, _ = _least_squares(tmp_path, None)
    assert abs(free - 40.0) > 10.0  # the log sets fv2 near the simulated arm's own (7.8 on this 10 s log)
    held, held_std, warnings = _least_squares(tmp_path, 1e-9)
    assert abs(held - 40.0) < 1e-6 and held_std < 1e-4 * free_std  # σ: the prior's, scaled by the worse residual
    assert not any("the σ stated" in w for w in warnings)
    loose, loose_std, _ = _least_squares(tmp_path, 1e6)
    np.testing.assert_allclose([loose, loose_std], [free, free_std], rtol=1e-6)


def test_a_stated_term_least_squares_holds_regrouped_is_said(tmp_path):
    """Ia1 is regrouped into ZZ1R (both multiply q̈1 alone): least squares cannot pull it, and says so."""
    _, _, warnings = _least_squares(tmp_path, 0.01, "Ia", 1, 0.5)
    said = [w for w in warnings if "the σ stated" in w]
    assert said == ["Ia1: the σ stated for it is used by the SDP and the drive-only estimate, not by least squares, "
                    "whose base parameters hold it regrouped with other terms"]

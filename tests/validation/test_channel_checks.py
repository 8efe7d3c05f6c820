"""A validation log whose torque channels are read otherwise than the identification log's (a sign flipped, two
columns swapped) is named, and the verdict does not weigh it; a log read right is not called wrong."""

import json

import numpy as np
import pytest

from dynid.validation.channel_checks import channel_findings
from dynid.validation.torques import TorqueComparison

from ..cli.refusals import dynid


def _comparison(measured, predicted):
    return TorqueComparison("log", np.arange(len(measured)) * 0.01, measured, {"fit": predicted})


def test_a_flipped_and_a_swapped_channel_against_a_fitted_prediction(rng):
    t = np.arange(2000) * 0.005
    predicted = np.column_stack([np.sin((k + 1) * t + k) * (k + 2) for k in range(4)])
    predicted[:, 2] = 0.9 * predicted[:, 1] + 0.3 * np.cos(5 * t)  # two joints of alike shape, as the UR10e's J2, J3
    measured = predicted + rng.normal(0, 0.02, predicted.shape)
    fitted = np.full(4, 0.999)
    assert channel_findings(_comparison(measured, predicted), "fit", fitted) == []
    flipped = measured * [1, 1, -1, 1]
    (found,) = channel_findings(_comparison(flipped, predicted), "fit", fitted)
    assert found.kind == "misread" and found.joint == 2
    assert found.text.startswith("log: J3's measured torque runs against fit's prediction (ρ = -1.000)")
    assert "sign = [1, 1, -1, 1]" in found.text
    assert channel_findings(_comparison(flipped, predicted), "fit", [0.999, 0.999, 0.5, 0.999]) == []  # not fitted there
    swapped = measured[:, [0, 2, 1, 3]]
    (found,) = channel_findings(_comparison(swapped, predicted), "fit", fitted)
    assert found.joint == 1 and found.text.startswith("log: J2's and J3's measured torques fit each other's prediction")


@pytest.mark.parametrize("change", ["sign", "swap"])
def test_a_validation_log_with_a_flipped_or_swapped_torque_channel_is_named_and_not_weighed(tmp_path, change):
    """``dynid example ur10e``'s validation log with J3's effort negated, or J2's and J3's effort columns swapped: the
    verdict weighed it (the main estimate went from the SDP to the description's links with the drive terms fitted on
    the swap) and the geometry check took the swap for swapped angles. The warning names the channel, the verdict
    leaves the log out, the main estimate is the one chosen on the log read right."""
    assert dynid("example", "ur10e", tmp_path / "try", "-q").returncode == 0
    p = dynid("identify", tmp_path / "try" / "ur10e.toml", "--out", tmp_path / "right", "--no-figures", "-q")
    assert p.returncode == 0, p.stderr
    right = json.loads((tmp_path / "right" / "results.json").read_text())
    path = tmp_path / "try" / "validation.csv"
    header = path.read_text().splitlines()[0].split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    a, b = header.index("shoulder_lift_joint_effort"), header.index("elbow_joint_effort")
    if change == "sign":
        data[:, b] *= -1
    else:
        data[:, [a, b]] = data[:, [b, a]]
    np.savetxt(path, data, delimiter=",", header=",".join(header), comments="", fmt="%.10g")
    p = dynid("identify", tmp_path / "try" / "ur10e.toml", "--out", tmp_path / "out", "--no-figures")
    assert p.returncode == 0, p.stderr
    said = " ".join(p.stderr.split())
    expected = ("validation: J3's measured torque runs against dynid WLS's prediction" if change == "sign" else
                "validation: J2's and J3's measured torques fit each other's prediction by dynid WLS far better")
    assert f"warning: {expected}" in said and "logged angles" not in said
    results = json.loads((tmp_path / "out" / "results.json").read_text())
    assert results["validation"][0]["misread"].startswith(expected)
    assert results["main_estimate"] == right["main_estimate"]
    assert [f["kind"] for f in results["findings"]].count("misread") == 1

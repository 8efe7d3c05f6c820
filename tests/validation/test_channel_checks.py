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


def test_a_scaled_log_is_named_only_where_the_description_sees_the_scale_too(rng):
    """Every channel at 0.1× the fitted prediction and the nominal one (another unit, another drive gain) is named with
    the scale that brings it back; one channel at 1000× (N·mm) with its own; a channel the fit is 0.1× off on while the
    description predicts the log at its size (the identification log's unit, not this log's) is not named, nor is a
    scale without a nominal model to tell."""
    t = np.arange(2000) * 0.005
    predicted = np.column_stack([np.sin((k + 1) * t + k) * (k + 2) for k in range(4)])
    nominal = predicted * [1.2, 0.8, 1.3, 0.7] + 0.3 * np.cos(3 * t)[:, None]  # a CAD description, off
    measured = predicted + rng.normal(0, 0.02, predicted.shape)
    fitted = np.full(4, 0.999)

    def found(log, sets):
        return channel_findings(TorqueComparison("log", t, log, sets), "fit", fitted, nominal="nominal")

    assert found(measured, {"fit": predicted, "nominal": nominal}) == []
    (tenth,) = found(0.1 * measured, {"fit": predicted, "nominal": nominal})
    assert tenth.kind == "misread" and "scale = 10 }" in tenth.text and "J4 (0.1×)" in tenth.text
    (one,) = found(measured * [1, 1000, 1, 1], {"fit": predicted, "nominal": nominal})
    assert one.joint == 1 and "scale = [1, 0.001, 1, 1]" in one.text
    assert found(measured * [1, 0.1, 1, 1], {"fit": predicted, "nominal": nominal * [1, 0.1, 1, 1]}) == []
    assert channel_findings(TorqueComparison("log", t, 0.1 * measured, {"fit": predicted}), "fit", fitted) == []


def test_a_validation_log_in_another_unit_is_named_and_not_weighed(tmp_path):
    """``dynid example ur10e``'s validation torques at 0.1× (another unit or drive gain than the identification log's):
    dynid kept the description ("this log cannot improve them", 888 % against the SDP's 900 %). The warning names the
    scale, the verdict leaves the log out and chooses as on the log read right; with that scale in the validation table
    the log is scored at the noise floor again. A log whose identification log has J2 in another unit instead is not
    called misread: the description predicts it at its size."""
    assert dynid("example", "ur10e", tmp_path / "try", "-q").returncode == 0
    folder = tmp_path / "try"
    p = dynid("identify", folder / "ur10e.toml", "--out", tmp_path / "right", "--no-figures", "-q")
    assert p.returncode == 0, p.stderr
    right = json.loads((tmp_path / "right" / "results.json").read_text())
    original = (folder / "validation.csv").read_text()
    header = original.splitlines()[0].split(",")
    data = np.loadtxt(folder / "validation.csv", delimiter=",", skiprows=1)
    efforts = [k for k, name in enumerate(header) if name.endswith("_effort")]
    data[:, efforts] *= 0.1
    np.savetxt(folder / "validation.csv", data, delimiter=",", header=",".join(header), comments="", fmt="%.10g")
    p = dynid("identify", folder / "ur10e.toml", "--out", tmp_path / "out", "--no-figures")
    assert p.returncode == 0, p.stderr
    results = json.loads((tmp_path / "out" / "results.json").read_text())
    assert "are that many times dynid WLS's prediction" in results["validation"][0]["misread"]
    assert "scale = 10 }" in results["validation"][0]["misread"]
    assert results["main_estimate"] == right["main_estimate"]
    assert results["readiness"].startswith("not ready: validation is read otherwise")
    text = (folder / "ur10e.toml").read_text()
    (folder / "scaled.toml").write_text(text.replace('file = "validation.csv"', 'file = "validation.csv"\n'
                                                     'torques = { columns = [' + ", ".join(f'"{header[k]}"' for k in efforts)
                                                     + "], scale = 10 }"))
    p = dynid("identify", folder / "scaled.toml", "--out", tmp_path / "scaled", "--no-figures", "-q")
    assert p.returncode == 0, p.stderr
    scaled = json.loads((tmp_path / "scaled" / "results.json").read_text())
    assert "misread" not in scaled["validation"][0] or not scaled["validation"][0]["misread"]
    floor = scaled["validation"][0]["noise_floor"]["global_relative_error"]
    assert scaled["validation"][0]["metrics"][scaled["main_estimate"]]["global_relative_error"] < 1.5 * floor
    p = dynid("validate", folder / "ur10e.toml", "--results", tmp_path / "right" / "results.json", "--file",
              folder / "validation.csv", "--out", tmp_path / "validated")  # dynid validate judges it too
    assert p.returncode == 0, p.stderr
    assert "are that many times dynid SDP's prediction" in " ".join(p.stderr.split()) and "scale = 10 }" in p.stderr
    said = " ".join(p.stdout.split())
    assert "validation.csv: read otherwise than the identification log" in said  # in short, not only at the end
    assert "next: read validation.csv as the warning says, then validate again" in said and "dynid export" not in said
    (folder / "validation.csv").write_text(original)
    ident = np.loadtxt(folder / "identification.csv", delimiter=",", skiprows=1)
    ident[:, header.index("shoulder_lift_joint_effort")] *= 10
    np.savetxt(folder / "identification.csv", ident, delimiter=",", header=",".join(header), comments="", fmt="%.10g")
    p = dynid("identify", folder / "ur10e.toml", "--out", tmp_path / "ident", "--no-figures", "-q")
    assert p.returncode == 0, p.stderr
    assert not json.loads((tmp_path / "ident" / "results.json").read_text())["validation"][0].get("misread")

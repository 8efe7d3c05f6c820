"""Drive terms no drive has (issue "Never worse than the description", item 3): a negative friction is a finding."""

from __future__ import annotations

from dataclasses import replace


def test_a_negative_friction_is_said_and_nothing_else():
    from dynid.identification.plausibility import drive_term_findings

    found = drive_term_findings("dynid OLS", ["fv1", "fc2", "Ia3", "XX1", "fc3", "offset4"], [-0.1, 0.2, 5.0, -1.0, -0.3, -2.0])
    assert [(f.kind, f.joint) for f in found] == [("drive", 0), ("drive", 2)]
    assert "fv1 = -0.1" in found[0].text and "viscous" in found[0].text and "Coulomb" in found[1].text


def test_the_main_estimates_negative_friction_is_a_finding_of_the_verdict(tmp_path):
    """An identification whose main estimate (least squares) has a negative viscous friction gets the finding, naming
    the joint; the same result with that friction positive gets none."""
    from dynid.identification.run import run_identification
    from dynid.identification.verdict import choose_main_estimate
    from dynid.io.config.identification_config import load_identification_config
    from tests.simulated_logs import simulated_case

    cfg, _ = simulated_case(tmp_path, "er16", 125.0, "fourier", duration=10.0)
    result = run_identification(load_identification_config(cfg), validate=False)
    label = result.main
    k = result.base.names.index("fv2")
    for sign, expected in ((-1.0, [1]), (1.0, [])):
        params = result.estimates[label].params.copy()
        params[k] = sign * abs(params[k])
        changed = replace(result, estimates={**result.estimates, label: replace(result.estimates[label], params=params)})
        found = [f.joint for f in choose_main_estimate(changed).findings if f.kind == "drive"]
        assert found == expected


def test_a_solvers_zero_is_no_negative_friction_and_is_exported_as_zero():
    """An SDP bounds friction at 0 to its round-off (fv = -1.3e-11 on a two-arm robot's simulated log): no finding, and
    the files hold 0; a friction negative beyond the round-off is still said and refused."""
    import numpy as np
    import pytest

    import dynid
    from dynid.exceptions import ConfigError
    from dynid.identification.plausibility import drive_term_findings
    from dynid.model.description_files import urdf_from_robot

    assert drive_term_findings("dynid SDP", ["XX1", "fv1", "fc1"], [2.0, -1.3e-11, -8.7e-12]) == []
    assert len(drive_term_findings("dynid SDP", ["XX1", "fv1", "fc1"], [2.0, -1e-3, 0.5])) == 1
    robot = dynid.load_robot("er16")
    phi = robot.standard_parameters().copy()
    k = robot.parameter_names.index("fv2")
    phi[k] = -1.3e-11
    written = urdf_from_robot(robot, phi)
    assert 'damping="0"' in written and "e-11" not in written
    phi[k] = -1e-3
    with pytest.raises(ConfigError, match="joint 2: negative friction"):
        urdf_from_robot(robot, phi)
    np.testing.assert_array_equal(phi[:k], robot.standard_parameters()[:k])

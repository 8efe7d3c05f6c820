"""URDF export: the exported model, loaded by Pinocchio, reproduces dynid's torques (round trip)."""

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from dynid.dynamics.base_parameters import base_parameters
from dynid.dynamics.regressor import regressor
from dynid.exceptions import ConfigError
from dynid.io.exported.export import urdf_from_results
from dynid.model.description import load_robot
from dynid.model.description_files import urdf_from_robot


def _with_friction(robot, rng):
    drive = np.abs(rng.uniform(0.1, 2.0, robot.drive.shape)) * robot.drive_mask
    if "offset" in robot.drive_terms:
        drive[:, robot.drive_terms.index("offset")] *= rng.choice([-1.0, 1.0], robot.n_dof)
    robot = replace(robot, drive=drive)
    coupled = np.abs(rng.uniform(0.1, 1.0, robot.transmission.coupled_values.shape))
    return robot.with_parameters(np.concatenate([robot.standard_parameters()[:robot.n_dof * robot.n_params_per_joint], coupled.ravel()]))


@pytest.mark.parametrize("name", ["ur10e", "tx40", "er16"])
def test_exported_urdf_reproduces_the_identified_base_parameters_torques(tmp_path, rng, name):
    """Physically consistent standard parameters φ with friction, exported; Pinocchio's RNEA of the URDF
    plus the joint friction written in it (<dynamics>) and the terms in its comments (rotor inertia,
    offset, the TX40's coupled wrist motor) equal dynid's prediction with the base parameters β = Kφ."""
    import pinocchio as pin

    robot = _with_friction(load_robot(name), rng)
    phi = robot.standard_parameters()
    base = base_parameters(robot, rng=0)
    beta = base.base_from_standard(phi)
    path = tmp_path / "robot.urdf"
    path.write_text(urdf_from_robot(robot, phi))
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    assert model.nq == robot.n_dof
    np.testing.assert_allclose(model.damping, robot.drive[:, robot.drive_terms.index("fv")] if "fv" in robot.drive_terms else 0)
    q, dq, ddq = (rng.uniform(-1.5, 1.5, (30, robot.n_dof)) for _ in range(3))
    tau = np.array([pin.rnea(model, data, a, b, c) for a, b, c in zip(q, dq, ddq)])
    terms = dict(zip(robot.drive_terms, robot.drive.T))
    tau += model.damping * dq + model.friction * np.sign(dq) + terms.get("Ia", 0) * ddq + terms.get("offset", 0)
    if robot.transmission.n_coupled_params:  # stated in a comment: the coupled motor's columns
        tau += robot.transmission.coupling_columns(dq, ddq) @ robot.transmission.coupled_values.ravel()
    predicted = base.base_observation(regressor(robot, q, dq, ddq)) @ beta
    np.testing.assert_allclose(tau, predicted, atol=1e-8 * max(1.0, np.abs(predicted).max()))


def test_inconsistent_parameters_are_refused_naming_link_and_rule(rng):
    robot = load_robot("er16")
    phi = robot.standard_parameters().copy()
    phi[robot.parameter_names.index("XX2")] = -5.0
    with pytest.raises(ConfigError, match=r"export: link 2 \(joint2\): .*only physically consistent parameters"):
        urdf_from_robot(robot, phi)
    with pytest.raises(ConfigError, match=r"r.json: no physically consistent estimate to export"):
        urdf_from_results(robot, {"base_parameters": []}, source="r.json")
    results = {"physically_consistent": {"label": "dynid SDP", "standard_values": dict(zip(robot.parameter_names, phi))},
               "physically_consistent_verdict": {"dynid SDP": "no: fv4 = -0.02 < 0"}}
    with pytest.raises(ConfigError, match=r"did not pass the consistency check \(no: fv4 = -0.02 < 0\)"):
        urdf_from_results(robot, results, source="r.json")


def _without_identified(root):
    """The URDF's elements as (path, tag, attributes, text), leaving out what the write-back replaces: the moving links'
    and their fixed children's <inertial>, the joints' <dynamics>, and comments."""
    out = []

    def walk(e, where):
        for child in e:
            if not isinstance(child.tag, str) or child.tag in ("inertial", "dynamics"):
                continue
            here = f"{where}/{child.tag}[{child.get('name', '')}]"
            out.append((here, tuple(sorted(child.attrib.items())), (child.text or "").strip()))
            walk(child, here)

    walk(root, "")
    return out


def test_the_users_urdf_gets_the_identified_values_and_keeps_everything_else(tmp_path):
    """Write-back export: names, frames, visuals, collisions, meshes, transmissions, gazebo tags stay; read back by
    Pinocchio (dynid's URDF reader), the links hold exactly the standard parameters written (the fixed tool frames'
    inertials merged into the last link, as dynid identified them)."""
    import xml.etree.ElementTree as ET
    from importlib import resources

    import dynid
    from dynid.io.exported.urdf_write_back import urdf_written_back

    urdf = Path(str(resources.files("dynid.model") / "robots" / "ur10e.urdf"))
    robot = dynid.load_robot(urdf)
    rng = np.random.default_rng(0)
    phi = robot.standard_parameters().copy()
    names = list(robot.parameter_names)
    for j in range(robot.n_dof):  # another physically consistent set: each link's mass and friction scaled
        scale = rng.uniform(0.7, 1.3)
        for term in ("XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M"):
            phi[names.index(f"{term}{j + 1}")] *= scale
        phi[names.index(f"fv{j + 1}")] = 0.5 + j
        phi[names.index(f"fc{j + 1}")] = 2.0 + j
    text, moved = urdf_written_back(urdf, robot, phi)
    (tmp_path / "back.urdf").write_text(text)
    original = ET.parse(urdf).getroot()
    written = ET.fromstring(text.encode("utf-8"))
    assert _without_identified(written) == _without_identified(original)
    back = dynid.load_robot(tmp_path / "back.urdf")
    assert [j.name for j in back.joints] == [j.name for j in robot.joints]
    np.testing.assert_allclose(back.inertial, robot.with_parameters(phi).inertial, rtol=1e-12, atol=1e-15)
    dynamics = {j.get("name"): j.find("dynamics") for j in written.findall("joint") if j.get("type") == "revolute"}
    assert [float(dynamics[j.name].get("damping")) for j in robot.joints] == [0.5 + j for j in range(6)]
    assert [float(dynamics[j.name].get("friction")) for j in robot.joints] == [2.0 + j for j in range(6)]
    assert "one physically consistent choice among the many" in text and moved == []


def test_a_link_far_from_the_urdfs_values_is_said(tmp_path):
    from importlib import resources

    import dynid
    from dynid.io.exported.urdf_write_back import urdf_written_back

    urdf = Path(str(resources.files("dynid.model") / "robots" / "ur10e.urdf"))
    robot = dynid.load_robot(urdf)
    phi = robot.standard_parameters().copy()
    names = list(robot.parameter_names)
    for term in ("XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M"):
        phi[names.index(f"{term}4")] *= 3.0
    text, moved = urdf_written_back(urdf, robot, phi)
    assert len(moved) == 1 and moved[0].startswith("wrist_1_link: mass ") and "(the URDF's " in moved[0]
    assert "Far from the URDF's own values" in text

"""``torques = { ..., sensor = "joint" }``: a joint torque sensor on the link side measures no rotor inertia, so the
default drive terms leave ``Ia`` out (issue "Never worse than the description", item 3)."""

from importlib import resources
from pathlib import Path

import numpy as np
import pytest

from dynid.exceptions import ConfigError
from dynid.io.config.identification_config import load_identification_config
from dynid.model.description import load_robot

URDF = Path(str(resources.files("dynid.model") / "robots" / "ur10e.urdf"))


def _config(tmp_path: Path, robot: str, torques: str) -> Path:
    data = np.column_stack([np.arange(300) * 0.01, np.zeros((300, 12))])
    header = ",".join(["t", *(f"q{j}" for j in range(1, 7)), *(f"tau{j}" for j in range(1, 7))])
    np.savetxt(tmp_path / "log.csv", data, delimiter=",", header=header, comments="")
    (tmp_path / "arm.urdf").write_text(URDF.read_text(encoding="utf-8"), encoding="utf-8")
    path = tmp_path / "arm.toml"
    path.write_text(f"{robot}\n[identification]\nfile = \"log.csv\"\nheader = true\ntime = {{ column = \"t\" }}\n"
                    f"positions = {{ columns = {[f'q{j}' for j in range(1, 7)]} }}\n".replace("'", '"')
                    + f"torques = {{ columns = {[f'tau{j}' for j in range(1, 7)]}{torques} }}\n".replace("'", '"'))
    return path


def test_a_joint_torque_sensor_leaves_the_rotor_inertia_out_of_the_default_terms(tmp_path):
    described = load_robot(URDF).drive_terms
    assert "Ia" in described  # a URDF's default drive terms hold the rotor inertia
    drive = load_identification_config(_config(tmp_path, 'robot = "arm.urdf"', ', sensor = "drive"')).robot
    plain = load_identification_config(_config(tmp_path, 'robot = "arm.urdf"', "")).robot
    joint = load_identification_config(_config(tmp_path, 'robot = "arm.urdf"', ', sensor = "joint"')).robot
    assert drive.drive_terms == plain.drive_terms == described
    assert joint.drive_terms == tuple(t for t in described if t != "Ia")
    np.testing.assert_array_equal(joint.inertial, plain.inertial)
    assert joint.n_params == plain.n_params - joint.n_dof


def test_a_rotor_inertia_the_user_lists_beside_a_joint_sensor_is_kept_and_said(tmp_path):
    table = '[robot]\nurdf = "arm.urdf"\ndrive_terms = ["Ia", "fc", "fv"]'
    robot = load_identification_config(_config(tmp_path, table, ', sensor = "joint"')).robot
    assert robot.drive_terms == ("Ia", "fc", "fv")
    assert any("sensor = \"joint\"" in n and "Ia" in n for n in robot.nominal_notes)


def test_a_sensor_on_another_signal_is_refused_in_one_line(tmp_path):
    path = _config(tmp_path, 'robot = "arm.urdf"', "")
    text = path.read_text().replace('"q6"] }', '"q6"], sensor = "joint" }')
    path.write_text(text)
    with pytest.raises(ConfigError, match=r"identification.positions.sensor: only the torques have a sensor") as info:
        load_identification_config(path)
    assert "\n" not in str(info.value)


def test_results_of_a_joint_sensor_log_read_back_with_the_robot_as_identified(tmp_path):
    """``dynid.load_results`` on the results of a config that names a URDF with ``sensor = "joint"`` (what ``dynid
    init`` writes for a KUKA LBR) refused them: "its base parameters (66) are not those of robot 'med7dock' (71)". It
    rebuilt the robot from the URDF alone, with its rotor inertias, which the identification had left out. The
    results now say the drive terms identified, and the model read back predicts what the one identified predicts."""
    import dynid
    from dynid.identification.fitted_model import IdentifiedModel, load_results
    from dynid.identification.run import run_identification

    path = _config(tmp_path, 'robot = "arm.urdf"', ', sensor = "joint"')
    log = dynid.simulated_log(load_robot(URDF).without_drive_terms(("Ia",)), seconds=20.0, rate=100.0, rng=3)
    header = ",".join(["t", *(f"q{j}" for j in range(1, 7)), *(f"tau{j}" for j in range(1, 7))])
    np.savetxt(tmp_path / "log.csv", np.column_stack([log.t, log.q, log.tau]), delimiter=",", header=header, comments="")
    result = run_identification(load_identification_config(path), validate=False)
    model = IdentifiedModel.from_result(result)
    model.save(tmp_path / "out")
    back = load_results(tmp_path / "out")
    assert "Ia" not in result.settings["drive_terms"] and "fc" in result.settings["drive_terms"]
    assert back.base.names == model.base.names
    other = dynid.simulated_log(load_robot(URDF).without_drive_terms(("Ia",)), seconds=5.0, rate=100.0, rng=4)
    np.testing.assert_allclose(back.predict(other), model.predict(other), rtol=1e-12, atol=1e-12)

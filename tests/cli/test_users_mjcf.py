"""``mjcf_model`` in an identify config (issue "A user's first hour", item 5: one output folder, one model): identify
writes the identified values into a copy of the user's own MuJoCo model, under its name, and export writes the same
by default; a model that is not the robot's is refused in one line before any work."""

import numpy as np
import pytest

from dynid.io.config.identification_config import load_identification_config

from ..io.test_mjcf_write_back import TETRAHEDRON, _users_mjcf
from ..simulated_logs import simulated_case
from .refusals import assert_refused, dynid

mujoco = pytest.importorskip("mujoco")


def _case(tmp_path):
    cfg, _ = simulated_case(tmp_path, "er16", 125.0, "fourier", duration=20.0)
    robot = load_identification_config(cfg).robot
    (tmp_path / "mine" / "meshes").mkdir(parents=True)
    (tmp_path / "mine" / "meshes" / "piece.obj").write_text(TETRAHEDRON)
    (tmp_path / "mine" / "arm.xml").write_text(_users_mjcf(robot, np.random.default_rng(3)))
    text = cfg.read_text().replace('estimators = ["ols"]', 'estimators = ["wls", "sdp"]')
    cfg.write_text('mjcf_model = "mine/arm.xml"\n' + text)
    return cfg


def test_identify_writes_the_values_into_the_users_mjcf_and_export_does_the_same(tmp_path):
    cfg = _case(tmp_path)
    p = dynid("identify", cfg, "--out", tmp_path / "out", "--no-figures")
    assert p.returncode == 0, p.stderr
    out = tmp_path / "out"
    assert (out / "arm.xml").is_file() and not (out / "dynid-model.xml").exists()
    written = mujoco.MjModel.from_xml_path(str(out / "arm.xml"))  # the meshes found from the output folder
    users = mujoco.MjModel.from_xml_path(str(tmp_path / "mine" / "arm.xml"))
    import json

    from dynid.io.results import stored_standard

    res = json.loads((out / "results.json").read_text())
    held = sum(res["diagnostics"]["file_terms"][stored_standard(res)[0]]["offset"])
    # the user's actuator kept first, one of constant bias after it per torque offset the validation log chose to hold
    assert written.nmesh == users.nmesh == 1 and written.nu == users.nu + held and written.nbody == users.nbody
    assert mujoco.mj_id2name(written, mujoco.mjtObj.mjOBJ_ACTUATOR, 0) == mujoco.mj_id2name(users, mujoco.mjtObj.mjOBJ_ACTUATOR, 0)
    assert not np.allclose(written.body_mass, users.body_mass)  # the values are the identified ones
    p = dynid("export", cfg, "--results", out / "results.json", "--mjcf", tmp_path / "exported" / "arm.xml")
    assert p.returncode != 0  # its folder does not exist: refused, as any --mjcf
    (tmp_path / "exported").mkdir()
    p = dynid("export", cfg, "--results", out / "results.json", "--mjcf", tmp_path / "exported" / "arm.xml")
    assert p.returncode == 0, p.stderr
    assert "the MJCF is arm.xml with only its inertials and joint dynamics replaced" in " ".join(p.stdout.split())
    exported = mujoco.MjModel.from_xml_path(str(tmp_path / "exported" / "arm.xml"))
    for field in ("body_mass", "body_inertia", "body_ipos", "dof_damping", "dof_armature", "dof_frictionloss", "actuator_biasprm"):
        np.testing.assert_allclose(getattr(exported, field), getattr(written, field), err_msg=field)


def test_identify_into_the_mjcfs_own_folder_keeps_the_users_file(tmp_path):
    cfg = _case(tmp_path)
    before = (tmp_path / "mine" / "arm.xml").read_text()
    p = dynid("identify", cfg, "--out", tmp_path / "mine", "--no-figures")
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "mine" / "arm.xml").read_text() == before
    assert mujoco.MjModel.from_xml_path(str(tmp_path / "mine" / "arm-identified.xml")).nmesh == 1


@pytest.mark.parametrize("model, message", [
    ("missing.xml", "mjcf_model: no such file"),
    ("other.xml", "mjcf_model: "),
])
def test_a_missing_or_foreign_mjcf_model_is_refused_in_one_line(tmp_path, model, message):
    cfg = _case(tmp_path)
    (tmp_path / "other.xml").write_text("<mujoco><worldbody><body><joint name='elsewhere'/><geom size='.1'/></body>"
                                        "</worldbody></mujoco>")
    cfg.write_text(cfg.read_text().replace('mjcf_model = "mine/arm.xml"', f'mjcf_model = "{model}"'))
    p = dynid("identify", cfg, "--out", tmp_path / "out", "--no-figures")
    assert_refused(p, message)
    assert str(cfg.name) in p.stderr and not (tmp_path / "out" / "results.json").exists()

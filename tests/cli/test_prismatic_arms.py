"""A tracked arm and a SCARA through `dynid init` and `dynid identify` as a user runs them (issue "Every arm a user
has", item 1): their logs simulated by Pinocchio's RNEA of the URDF, the identified model as good as the truth on
another motion, and written back with its prismatic joints."""

import json
import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from dynid.model.description import load_robot
from dynid.model.urdf import joints_to_hold
from dynid.studies.example import _csv, _with_drives
from dynid.studies.simulated_logs import simulated_log

from ..dynamics.test_prismatic_joints import SCARA, TRACKED
from .refusals import dynid as run


def _folder(tmp_path, name, text):
    (tmp_path / f"{name}.urdf").write_text(text)
    robot = _with_drives(load_robot(tmp_path / f"{name}.urdf", held=joints_to_hold(tmp_path / f"{name}.urdf")),
                         np.random.default_rng(0))
    for file, seconds, seed in (("identification.csv", 60.0, 1), ("validation.csv", 20.0, 2)):
        (tmp_path / file).write_text(_csv(simulated_log(robot, seconds=seconds, rate=250.0, rng=seed), robot))
    return robot


@pytest.mark.parametrize("name", ["tracked", "scara"])
def test_a_prismatic_arm_is_identified_from_init_to_its_written_files(tmp_path, name):
    robot = _folder(tmp_path, name, TRACKED if name == "tracked" else SCARA)
    p = run("init", f"{name}.urdf", "identification.csv", "validation.csv", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    sliding = ", ".join(j.name for j in robot.joints if j.prismatic)
    assert f"prismatic: {sliding}: positions in m" in " ".join(p.stdout.split())
    p = run("identify", "arm.toml", "--no-figures", cwd=tmp_path)
    said = " ".join((p.stdout + p.stderr).split())
    assert p.returncode == 0, p.stderr
    assert said.startswith("model ready") or "\nmodel ready" in p.stdout, said[:300]
    results = json.loads((tmp_path / "dynid-identify" / "results.json").read_text())
    validation = results["validation"][0]
    main = validation["metrics"][results["main_estimate"]]["global_relative_error"]
    assert main <= 1.5 * validation["noise_floor"]["global_relative_error"]  # near the truth on another motion (1.34x:
    # the tracked arm's Coulomb friction at reversals, 2x its joint's floor there; at the floor without it)
    units = {b["name"]: b["unit"] for b in results["base_parameters"]}
    j = int(np.flatnonzero(robot.prismatic)[0]) + 1
    assert units[f"fv{j}"] == "N·s/m" and units[f"fc{j}"] == "N"
    # written back with the joints' kinds: Pinocchio and MuJoCo read them as dynid's model, said so
    assert "equals dynid's model to" in said and "read back by MuJoCo" in said
    urdf = ET.parse(tmp_path / "dynid-identify" / f"{name}.urdf").getroot()
    kinds = {e.get("name"): e.get("type") for e in urdf.iter("joint")}
    assert [kinds[j.name] for j in robot.joints] == ["prismatic" if j.prismatic else "revolute" for j in robot.joints]
    mjcf = ET.parse(tmp_path / "dynid-identify" / "dynid-model.xml").getroot()
    kinds = {e.get("name"): e.get("type") for e in mjcf.iter("joint")}
    assert [kinds[j.name] for j in robot.joints] == ["slide" if j.prismatic else "hinge" for j in robot.joints]
    figures = re.findall(r"equals dynid's model to ([0-9.e+-]+) of its RMS", said)
    assert len(figures) == 2 and all(float(f) < 1e-9 for f in figures), figures
    # the sliding joint's figures are forces: results.json names it, the tables and lines say N for it
    slide = np.flatnonzero(robot.prismatic).tolist()
    joints = ", ".join(f"J{k + 1}" for k in slide)
    assert results["identification"]["prismatic_joints"] == validation["prismatic_joints"] == slide
    assert f" rad/s; {joints} in m/s), " in results["settings"]["preprocessing"]["derivation"]
    assert f"RMSE N·m ({joints} in N)" in (tmp_path / "dynid-identify" / "report.html").read_text()
    p = run("validate", "arm.toml", "-v", cwd=tmp_path)
    said = " ".join(p.stdout.split())
    assert p.returncode == 0 and re.search(rf"RMS torque [0-9.e+-]+(, [0-9.e+-]+)* N·m \({joints} in N\)", said), said[:500]


def test_a_track_logged_in_millimetres_is_refused_with_its_scale(tmp_path):
    _folder(tmp_path, "tracked", TRACKED)
    rows = (tmp_path / "identification.csv").read_text().splitlines()
    cells = [r.split(",") for r in rows[1:]]
    (tmp_path / "identification.csv").write_text("\n".join([rows[0]] + [",".join([c[0], f"{float(c[1]) * 1000:.9g}", *c[2:]])
                                                                       for c in cells]) + "\n")
    assert run("init", "tracked.urdf", "identification.csv", cwd=tmp_path).returncode == 0
    p = run("identify", "arm.toml", "--no-figures", cwd=tmp_path)
    said = " ".join((p.stdout + p.stderr).split())
    assert p.returncode != 0 and "joint 1 (prismatic) reaches" in said and "scale = [0.001, 1, 1, 1, 1, 1]" in said, said


def test_degrees_leave_a_prismatic_joints_metres_alone(tmp_path):
    """unit = "deg" converts the revolute joints' columns, not the track's metres."""
    from dynid.io.logs.dataset_specs import dataset_spec

    table = {"file": "x.csv", "time": {"column": 1}, "positions": {"columns": [2, 3, 4], "unit": "deg"},
             "torques": {"columns": [5, 6, 7]}}
    spec = dataset_spec(table, tmp_path, "t", "t", 3, (True, False, False))
    np.testing.assert_allclose(spec.signals["positions"].scale, [1.0, np.pi / 180, np.pi / 180])

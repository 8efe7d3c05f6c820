"""A palletiser whose passive joint follows another (`<mimic>`) through `dynid init`, `identify`, `export` and `excite`
as a user runs them (issue "Every arm a user has", item 2): its logs hold the four driven joints only, simulated by
Pinocchio's RNEA of the URDF with the passive joint coupled; the identified model as good as the truth on another
motion, written back with the coupling kept, and an excitation that keeps it at every set-point."""

import json
import re
import xml.etree.ElementTree as ET

import numpy as np

from dynid.model.description import load_robot
from dynid.model.urdf import joints_to_hold
from dynid.studies.example import _csv, _with_drives
from dynid.studies.simulated_logs import simulated_log

from ..dynamics.test_mimic_joints import PALLETISER
from .refusals import dynid as run


def _folder(tmp_path):
    (tmp_path / "palletiser.urdf").write_text(PALLETISER)
    robot = _with_drives(load_robot(tmp_path / "palletiser.urdf", held=joints_to_hold(tmp_path / "palletiser.urdf")),
                         np.random.default_rng(0))
    for file, seconds, seed in (("identification.csv", 60.0, 1), ("validation.csv", 20.0, 2)):
        (tmp_path / file).write_text(_csv(simulated_log(robot, seconds=seconds, rate=250.0, rng=seed), robot))
    return robot


def test_a_palletiser_with_a_mimic_joint_is_identified_from_init_to_its_written_files(tmp_path):
    robot = _folder(tmp_path)
    assert robot.followers == (3,) and (tmp_path / "identification.csv").read_text().splitlines()[0].count("_position") == 4
    p = run("init", "palletiser.urdf", "identification.csv", "validation.csv", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    said = " ".join(p.stdout.split())
    assert "J4 (j4) follows J3 (j3): q4 = -1·q3 + 0.1 rad (<mimic>)" in said, said
    p = run("identify", "arm.toml", "--no-figures", cwd=tmp_path)
    said = " ".join((p.stdout + p.stderr).split())
    assert p.returncode == 0 and "\nmodel ready" in "\n" + p.stdout, said[:400]
    assert "dead" not in said and "J4's torque" not in said  # a follower is no dead channel
    results = json.loads((tmp_path / "dynid-identify" / "results.json").read_text())
    validation = results["validation"][0]
    main = validation["metrics"][results["main_estimate"]]["global_relative_error"]
    assert main <= 1.5 * validation["noise_floor"]["global_relative_error"], main  # the truth's own error on that motion
    assert results["identification"]["following_joints"] == validation["following_joints"] == [3]
    # written back with the coupling kept, read back by Pinocchio and MuJoCo as dynid's model
    urdf = ET.parse(tmp_path / "dynid-identify" / "palletiser.urdf").getroot()
    mimic = {e.get("name"): e.find("mimic") for e in urdf.iter("joint")}
    assert mimic["j4"] is not None and mimic["j4"].get("joint") == "j3" and float(mimic["j4"].get("multiplier")) == -1.0
    mjcf = ET.parse(tmp_path / "dynid-identify" / "dynid-model.xml").getroot()
    equality = mjcf.find("equality/joint")
    assert equality is not None and (equality.get("joint1"), equality.get("joint2")) == ("j4", "j3")
    assert [float(x) for x in equality.get("polycoef").split()[:2]] == [0.1, -1.0]
    figures = re.findall(r"equals dynid's model to ([0-9.e+-]+) of its RMS", said)
    assert len(figures) == 2 and all(float(f) < 1e-9 for f in figures), figures
    # MuJoCo simulates the file along the validation log with the coupling as its equality, J3 driving both
    p = run("export", "arm.toml", "--mjcf", "m.xml", "--forward", cwd=tmp_path)
    said = " ".join(p.stdout.split())
    forward = re.search(r"the torques it needs are ([0-9.]+) % off the measured ones, against ([0-9.]+) %", said)
    assert p.returncode == 0 and forward is not None and float(forward.group(1)) < 1.0, said[-600:]


def test_a_log_that_holds_the_followers_columns_too_is_read_by_its_driven_joints(tmp_path):
    """A log written with every joint's columns (a ROS joint_states log holds a mimic joint's position): init takes the
    driven joints' and says why the follower's are left, not that the robot file may miss joints."""
    _folder(tmp_path)
    lines = (tmp_path / "identification.csv").read_text().splitlines()
    head = lines[0].split(",")
    i, k = head.index("j3_position") + 1, head.index("j3_effort") + 1
    rows = [",".join(head[:i] + ["j4_position"] + head[i:k] + ["j4_effort"] + head[k:])]
    for line in lines[1:]:
        cells = line.split(",")
        rows.append(",".join(cells[:i] + [repr(-float(cells[i - 1]) + 0.1)] + cells[i:k] + ["0"] + cells[k:]))
    (tmp_path / "identification.csv").write_text("\n".join(rows) + "\n")
    p = run("init", "palletiser.urdf", "identification.csv", cwd=tmp_path)
    said = " ".join(p.stdout.split())
    assert p.returncode == 0 and "positions: j1_position, j2_position, j3_position, j5_position" in said, said
    assert ("not read: j4_position, j4_effort — the columns of joints that follow others in palletiser.urdf (<mimic>: "
            "j4)") in said and "more joint columns" not in said
    # a config that lists every joint's columns (as one written before such joints were read) is honoured: the
    # follower's columns read and not used, said so, and the same model as from the driven joints' columns alone
    assert run("identify", "arm.toml", "--no-figures", "-q", "--out", "four", cwd=tmp_path).returncode == 0
    config = (tmp_path / "arm.toml").read_text()
    every = config.replace('"j3_position", "j5_position"', '"j3_position", "j4_position", "j5_position"').replace(
        '"j3_effort", "j5_effort"', '"j3_effort", "j4_effort", "j5_effort"')
    assert every != config
    (tmp_path / "every.toml").write_text(every)
    p = run("identify", "every.toml", "--no-figures", "-q", "--out", "five", cwd=tmp_path)
    said = " ".join((p.stdout + p.stderr).split())
    assert p.returncode == 0 and "the columns of j4 (<mimic>: a joint that follows another) are read and not used" in said, said
    four, five = (json.loads((tmp_path / d / "results.json").read_text()) for d in ("four", "five"))
    values = lambda r: [b["value"] for b in r["base_parameters"]]  # noqa: E731
    np.testing.assert_allclose(values(five), values(four), rtol=1e-12, atol=0)


def test_an_excitation_keeps_a_mimic_joint_on_its_coupling_at_every_set_point(tmp_path):
    (tmp_path / "palletiser.urdf").write_text(PALLETISER)
    p = run("excite", "palletiser.urdf", "--starts", "2", cwd=tmp_path)
    said = " ".join((p.stdout + p.stderr).split())
    assert p.returncode == 0 and "every constraint holds" in said, said[:600]
    assert "their columns in excitation.csv are what they do, not set-points" in said
    rows = np.loadtxt(tmp_path / "dynid-excite" / "excitation.csv", delimiter=",", skiprows=1)
    q3, q4, dq3, dq4 = rows[:, 3], rows[:, 4], rows[:, 8], rows[:, 9]
    np.testing.assert_allclose(q4, -q3 + 0.1, atol=1e-8)
    np.testing.assert_allclose(dq4, -dq3, atol=1e-8)
    assert np.ptp(q3) > 0.1  # the coupled joints move
    robot = load_robot(tmp_path / "palletiser.urdf", held=joints_to_hold(tmp_path / "palletiser.urdf"))
    assert np.all(q4 >= robot.limits.q_min[3] - 1e-9) and np.all(q4 <= robot.limits.q_max[3] + 1e-9)


def test_the_api_takes_a_coupled_robots_log_as_its_coordinates_arrays(tmp_path):
    """dynid.load_recording of the CSV (its columns found as init finds them) and identify_from_arrays on the driven
    joints' arrays alone give the same identification: the coordinates widened, the follower coupled, its torque 0."""
    import dynid

    robot = _folder(tmp_path)
    rec = dynid.load_recording(tmp_path / "identification.csv", robot)
    assert rec.followers == (3,) and np.all(rec.tau[:, 3] == 0.0)
    np.testing.assert_allclose(rec.q[:, 3], -rec.q[:, 2] + 0.1, atol=1e-12)
    kept = robot.independent
    from_log = dynid.identify_from_arrays(robot, rec)
    from_arrays = dynid.identify_from_arrays(robot, rec.t, rec.q[:, kept], rec.tau[:, kept])
    a, b = from_arrays.solution.params, from_log.solution.params  # as any two routes agree (a robot without followers:
    assert np.linalg.norm(a - b) <= 1e-8 * np.linalg.norm(b)      # 3e-9 of the largest parameter, the same two calls)
    label = from_log.main
    assert abs(from_arrays.fit.metrics()[label]["global_relative_error"]
               - from_log.fit.metrics()[label]["global_relative_error"]) <= 1e-6 * from_log.fit.metrics()[label]["global_relative_error"]
    assert from_arrays.fit.followers == (3,) and "dead" not in " ".join(from_arrays.warnings)

"""A two-arm robot on a turning torso through `dynid init` and `dynid identify` as a user runs them (issue "Every arm a
user has", item 3): one log of both arms simulated by Pinocchio's RNEA, identified as one model whose rows are every
joint, as good as the truth on another motion, and written back as the tree it is."""

import json
import re
import xml.etree.ElementTree as ET

import numpy as np

from dynid.model.description import load_robot
from dynid.studies.example import _csv, _with_drives
from dynid.studies.simulated_logs import simulated_log

from ..dynamics.test_tree_robots import TWO_ARMS
from .refusals import dynid as run


def test_two_arms_on_a_torso_are_identified_as_one_model_from_init_to_its_written_files(tmp_path):
    (tmp_path / "two_arms.urdf").write_text(TWO_ARMS)
    robot = _with_drives(load_robot(tmp_path / "two_arms.urdf"), np.random.default_rng(0))
    for file, seconds, seed in (("identification.csv", 60.0, 1), ("validation.csv", 20.0, 2)):
        (tmp_path / file).write_text(_csv(simulated_log(robot, seconds=seconds, rate=250.0, rng=seed), robot))
    p = run("init", "two_arms.urdf", "identification.csv", "validation.csv", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert "the log's joints are on several branches: one model of its 7 joints (a tree" in " ".join(p.stdout.split())
    p = run("identify", "arm.toml", "--no-figures", cwd=tmp_path)
    said = " ".join((p.stdout + p.stderr).split())
    assert p.returncode == 0, p.stderr
    assert p.stdout.startswith("model ready") or "\nmodel ready" in p.stdout, said[:400]
    results = json.loads((tmp_path / "dynid-identify" / "results.json").read_text())
    validation = results["validation"][0]
    main = validation["metrics"][results["main_estimate"]]["global_relative_error"]
    assert main <= 1.5 * validation["noise_floor"]["global_relative_error"]  # near the truth on another motion
    # written back as the tree: each joint on the link it rode on; Pinocchio and MuJoCo read it as dynid's model
    source = {e.get("name"): e.find("parent").get("link") for e in ET.parse(tmp_path / "two_arms.urdf").getroot().iter("joint")}
    written = ET.parse(tmp_path / "dynid-identify" / "two_arms.urdf").getroot()
    assert {e.get("name"): e.find("parent").get("link") for e in written.iter("joint")} == source
    assert "equals dynid's model to" in said and "read back by MuJoCo" in said
    figures = re.findall(r"equals dynid's model to ([0-9.e+-]+) of its RMS", said)
    assert len(figures) == 2 and all(float(f) < 1e-9 for f in figures), figures


def test_a_config_whose_log_covers_one_branch_is_refused_naming_the_joints_to_hold(tmp_path):
    """A config written by hand for a robot with branches, its log one arm's: refused in one line that names the robot's
    joints and the ``held`` list that keeps its longest chain (before trees were read, the URDF itself was refused with
    that list)."""
    from .refusals import assert_refused

    (tmp_path / "two_arms.urdf").write_text(TWO_ARMS)
    robot = load_robot(tmp_path / "two_arms.urdf", held={"right_j1": 0.0, "right_j2": 0.0, "right_j3": 0.0})
    (tmp_path / "log.csv").write_text(_csv(simulated_log(robot, seconds=5.0, rate=100.0, rng=1), robot))
    names = [j.name for j in robot.joints]
    (tmp_path / "arm.toml").write_text(
        'robot = "two_arms.urdf"\ndata_root = "."\n[identification]\nfile = "log.csv"\nheader = true\n'
        'time = { column = "time" }\n'
        f'positions = {{ columns = {[n + "_position" for n in names]!r} }}\n'.replace("'", '"')
        + f'torques = {{ columns = {[n + "_effort" for n in names]!r} }}\n'.replace("'", '"'))
    p = run("identify", "arm.toml", "--no-figures", cwd=tmp_path)
    assert_refused(p, "identification.positions.columns: expected 7 columns (one per joint)")
    assert ('hold those the log has no columns for in the config\'s [robot] table, held = ["right_j1", "right_j2", '
            '"right_j3"] for its longest chain') in p.stderr


def _two_arms_mjcf() -> str:
    """A torso turning about z with two three-hinge arms, as an MJCF (MuJoCo compiles its bodies' tree)."""
    def arm(side, y):
        return (f'<body name="{side}_link1" pos="0 {y} 0.5"><joint name="{side}1" axis="0 0 1" range="-3 3"/>'
                f'<inertial pos="0.02 0.01 0.15" mass="2.5" diaginertia="0.01 0.02 0.015"/>'
                f'<body name="{side}_link2" pos="0 0 0.3"><joint name="{side}2" axis="0 1 0" range="-3 3"/>'
                f'<inertial pos="0.15 0 0.01" mass="1.5" diaginertia="0.01 0.02 0.015"/>'
                f'<body name="{side}_link3" pos="0.3 0 0"><joint name="{side}3" axis="1 0 0" range="-3 3"/>'
                f'<inertial pos="0.05 0.02 0" mass="0.8" diaginertia="0.003 0.004 0.002"/></body></body></body>')

    return (f'<mujoco model="two"><worldbody><body name="torso" pos="0 0 0.3"><joint name="yaw" axis="0 0 1" '
            f'range="-3 3"/><inertial pos="0 0 0.2" mass="10" diaginertia="0.3 0.3 0.1"/>{arm("l", 0.3)}'
            f'{arm("r", -0.3)}</body></worldbody></mujoco>')


def test_an_mjcf_of_two_arms_is_identified_as_one_model_and_written_back_into_it(tmp_path):
    """The same from an MJCF: its bodies' tree read as MuJoCo compiles it, the user's file written back with both
    arms' identified bodies, and the URDF dynid writes from the model; MuJoCo and Pinocchio read both as dynid's
    model."""
    (tmp_path / "two.xml").write_text(_two_arms_mjcf())
    robot = _with_drives(load_robot(tmp_path / "two.xml"), np.random.default_rng(0))
    assert robot.parents.tolist() == [-1, 0, 1, 2, 0, 4, 5]
    for file, seconds, seed in (("identification.csv", 60.0, 1), ("validation.csv", 20.0, 2)):
        (tmp_path / file).write_text(_csv(simulated_log(robot, seconds=seconds, rate=250.0, rng=seed), robot))
    assert run("init", "two.xml", "identification.csv", "validation.csv", cwd=tmp_path).returncode == 0
    p = run("identify", "arm.toml", "--no-figures", cwd=tmp_path)
    said = " ".join((p.stdout + p.stderr).split())
    assert p.returncode == 0 and "\nmodel ready" in "\n" + p.stdout, said[:400]
    assert "two.xml read back by MuJoCo" in said and "dynid-model.urdf read back by Pinocchio" in said
    figures = re.findall(r"equals dynid's model to ([0-9.e+-]+) of its RMS", said)
    assert len(figures) == 2 and all(float(f) < 1e-9 for f in figures), figures

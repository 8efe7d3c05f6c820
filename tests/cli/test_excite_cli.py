"""`dynid excite` as a user runs it, and `dynid run --excitation` on its output."""

import json
from importlib import resources
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from dynid.dynamics.kinematics import tool_positions
from dynid.dynamics.rnea import rnea_torques
from dynid.io.config.excitation_config import load_excitation_config
from dynid.io.logs.trajectories import load_trajectory
from dynid.model.description import load_robot

from .refusals import assert_refused, dynid
from .test_cli import FAST

REPO = Path(__file__).resolve().parents[2]


def _small(tmp_path, source: str, replace: dict) -> Path:
    text = (REPO / "configs" / source).read_text()
    for old, new in replace.items():
        assert old in text
        text = text.replace(old, new)
    path = tmp_path / source
    path.write_text(text)
    return path


def test_excite_ur10e_satisfies_every_constraint_on_a_10x_finer_grid(tmp_path):
    """The README's UR10e config, fewer starts and harmonics: JSON, CSV, figures; limits checked independently."""
    cfg = _small(tmp_path, "excite-ur10e.toml", {"harmonics = 5": "harmonics = 3", "starts = 4": "starts = 2"})
    out = tmp_path / "ur"
    p = dynid("excite", str(cfg), "--out", str(out), env={"COLUMNS": "1000"})  # one line each: counted below
    assert p.returncode == 0, p.stderr
    # the verdict first, the tables behind --verbose and in the report (issue "Fast where users wait", item 4)
    assert "Before / after" not in p.stdout and "Constraint margins" not in p.stdout
    said_lines = [line for line in (p.stdout + p.stderr).splitlines() if line.strip() and not line.startswith("dynid excite:")]
    assert len(said_lines) <= 20, said_lines  # the progress lines (one per start, the writing) aside
    report = (out / "report.html").read_text()
    assert "Before / after" in report and "Constraint margins" in report and "q_min [rad]" in report
    # the report reads like identify's: the verdict first, margins as numbers (item 5: "nan" for the floor's row)
    assert report.index("every constraint holds on the 10× verification grid") < report.index("Before / after")
    assert ">nan<" not in report and "checked again by MuJoCo" in report
    doc = json.loads((out / "excitation.json").read_text())
    assert doc["trajectory"]["form"] == "swevers" and doc["design"]["feasible"]
    # MuJoCo's check holds a shape that starts under the floor (the estimated capsules' link 2) only to its start
    # height and never measures the links against each other: its line says both, in the terminal and the report
    held = doc["mujoco_contacts"]["held"]
    assert held and all(name in report for name in held)
    assert "or another" not in report and "checked apart" in report
    said = next(line for line in (p.stdout + p.stderr).splitlines() if line.startswith("checked again by MuJoCo"))
    assert f"{held[0]} starts within the floor's clearance and was held only to no lower than it starts" in said
    assert "{" not in said and "{" not in report[report.index("checked again by MuJoCo"):][:400]
    assert doc["design"]["cond"] < doc["design"]["initial_cond"]
    # the verdict opens the output: the conditioning before and after, the constraints; the next step closes it
    text = " ".join(p.stdout.split())
    verdict = " ".join((p.stderr + p.stdout).split())  # with warnings standing, the verdict is one: standard error
    assert f"cond(W_base) {doc['design']['initial_cond']:.2f} → {doc['design']['cond']:.2f}" in verdict
    assert "every constraint holds" in verdict and "play excitation.csv on the robot" in text
    # the built-in UR10e's meshes are not shipped: the table is kept off estimated capsules, said as a warning first
    said = " ".join((p.stdout + p.stderr).split())  # a warning line goes to standard error
    assert "no collision shapes dynid could read" in said and "next: settle the warnings above, then play" in text
    warned = [line for line in p.stderr.splitlines() if line.startswith("warning:")]  # in the order printed
    assert warned[0].startswith("warning: cond(W_base)") and "warnings below to settle before it runs" in warned[0]
    assert "log positions and torques (or motor currents)" in " ".join(text.split())  # a torque sensor's arm logs torques
    traj = load_trajectory(out / "excitation.json")
    config = load_excitation_config(cfg)
    lim = config.problem.limits
    robot = load_robot("ur10e")
    t = np.linspace(0, traj.period, 10 * config.problem.grid_points, endpoint=False)
    q, dq, ddq = traj.evaluate(t)
    assert np.all((q >= lim.q_min) & (q <= lim.q_max))
    assert np.all(np.abs(dq) <= lim.dq_max) and np.all(np.abs(ddq) <= lim.ddq_max)
    assert np.all(np.abs(rnea_torques(robot, q, dq, ddq)) <= lim.tau_max)
    xyz = tool_positions(robot, q)
    assert np.all(xyz[:, 2] >= 0.10) and np.all(np.abs(xyz[:, :2]) <= 1.2)
    # the CSV for the controller: 500 Hz over one period, starting and ending at rest at the home pose
    csv = np.loadtxt(out / "excitation.csv", delimiter=",", skiprows=1)
    assert csv.shape == (int(round(traj.period * 500)) + 1, 19)
    np.testing.assert_allclose(csv[[0, -1], 1:7], np.tile([0, -np.pi / 2, np.pi / 2, -np.pi / 2, -np.pi / 2, 0], (2, 1)), atol=1e-7)
    np.testing.assert_allclose(csv[[0, -1], 7:], 0.0, atol=1e-7)
    assert (out / "excitation_joints.png").is_file() and (out / "excitation_tool_path.png").is_file()


def test_excite_er16_then_run_on_the_designed_trajectory(tmp_path):
    cfg = _small(tmp_path, "excite-er16.toml", {"starts = 6": "starts = 1"})
    out = tmp_path / "ex"
    p = dynid("excite", str(cfg), "--out", str(out))
    assert p.returncode == 0, p.stderr
    doc = json.loads((out / "excitation.json").read_text())
    assert doc["design"]["cond"] <= 0.5 * doc["design"]["initial_cond"]
    assert doc["settings"]["initial"] == "paper β1 (eq. A.1)" and not doc["design"]["initial_violations"]
    p = dynid("run", "--out", str(tmp_path / "run"), *FAST, "--excitation", str(out / "excitation.json"))
    assert p.returncode == 0, p.stderr
    res = json.loads((tmp_path / "run" / "results.json").read_text())
    ex = res["trajectories"]["excitation"]
    assert ex["cond_base_regressor"] == pytest.approx(doc["design"]["cond"], rel=1e-6)
    assert ex["cond_base_regressor_beta1"] == pytest.approx(doc["design"]["initial_cond"], rel=1e-6)


@pytest.mark.parametrize("replace, message", [
    ({'offsets = [-0.3857, 0.0011, 0.0]': 'offsets = [-0.3857, 0.0011, 0.0]\n[limits]\nq_min = [-1, 2, -1]\nq_max = [1, 1, 1]'},
     "limits: joint 2 has q_max = 1 rad not above q_min = 2 rad"),
    ({"floor = -0.75": "floor = 1.5"}, "workspace excludes the start pose"),
    ({"harmonics = 5": "harmonics = 0"}, "trajectory.harmonics: expected an integer >= 1, got 0"),
    ({"frequency = 0.05": "omega_f = 0.3\nfrequency = 0.05"}, "give one of frequency (Hz) or omega_f (rad/s), not both"),
    ({"[design]": "[design]\ncolour = 1"}, "design: unknown field 'colour', expected some of criterion"),
    ({'initial = "paper"': 'initial = "nosuch.json"'}, "nosuch.json: trajectory file not found"),
])
def test_bad_configs_get_one_line_errors_and_no_output(tmp_path, replace, message):
    cfg = _small(tmp_path, "excite-er16.toml", replace)
    p = dynid("excite", str(cfg), "--out", str(tmp_path / "o"))
    assert_refused(p, message, tmp_path / "o")
    assert str(cfg) in p.stderr


def test_run_excitation_file_with_wrong_joint_count(tmp_path):
    f = tmp_path / "t.json"
    f.write_text(json.dumps({"form": "paper", "omega_f": 0.5, "q0": [0, 0], "a": [[0.1], [0.1]], "b": [[0.0], [0.0]]}))
    p = dynid("run", "--out", str(tmp_path / "o"), *FAST, "--excitation", str(f))
    assert p.returncode == 1 and "the trajectory has 2 joints, the run identifies 3" in p.stderr


def test_a_continuous_joint_is_said_in_one_line_not_a_numpy_warning(tmp_path):
    """issue "An excitation safe to run", item 4: a URDF joint without position limits leaked NumPy's RuntimeWarning
    (``mid = 0.5*(q_min+q_max)`` of ±inf); it is said in one line with the range the trajectory takes."""
    urdf = Path(str(resources.files("dynid.model") / "robots" / "ur10e.urdf")).read_text(encoding="utf-8")
    old = '<joint name="wrist_3_joint" type="revolute">'
    assert urdf.count(old) == 1
    (tmp_path / "arm.urdf").write_text(urdf.replace(old, '<joint name="wrist_3_joint" type="continuous">'))
    (tmp_path / "excite.toml").write_text('robot = "arm.urdf"\n[trajectory]\nharmonics = 2\nfrequency = 0.2\n'
                                          "[limits]\nddq_max = 4.0\n[design]\nstarts = 1\nmaxiter = 5\n"
                                          "[output]\nrate = 100\n")
    p = dynid("excite", str(tmp_path / "excite.toml"), "--out", str(tmp_path / "out"))
    assert p.returncode == 0, p.stderr
    assert "RuntimeWarning" not in p.stderr + p.stdout
    said = " ".join((p.stdout + p.stderr).split())  # a warning line goes to standard error
    assert "no position limits on J6 (continuous joints)" in said
    q = np.loadtxt(tmp_path / "out" / "excitation.csv", delimiter=",", skiprows=1)[:, 6]
    assert f"J6 {q.min():.3g} to {q.max():.3g} rad" in said


def _robot_only(tmp_path, extra: str = "") -> Path:
    """A config naming the robot and nothing of the trajectory: a user's first excitation."""
    path = tmp_path / "excite.toml"
    path.write_text('robot = "ur10e"\n[design]\nstarts = 1\nmaxiter = 5\n[output]\nrate = 100\n' + extra)
    return path


def test_a_config_naming_only_the_robot_designs_the_default_trajectory(tmp_path):
    """A ``dynid excite`` config without ``[trajectory]`` was refused ("expected a [trajectory] table") where an
    identification config without ``[excitation]`` designs 5 harmonics of 0.1 Hz from and to rest: now both do."""
    p = dynid("excite", str(_robot_only(tmp_path)), "--out", str(tmp_path / "out"))
    assert p.returncode == 0, p.stderr
    doc = json.loads((tmp_path / "out" / "excitation.json").read_text())
    assert doc["harmonics"] == 5 and doc["rest"] is True
    assert doc["omega_f"] == pytest.approx(2 * np.pi * 0.1, rel=1e-12)
    csv = np.loadtxt(tmp_path / "out" / "excitation.csv", delimiter=",", skiprows=1)
    assert csv[-1, 0] == pytest.approx(10.0) and np.allclose(csv[[0, -1], 7:], 0.0, atol=1e-7)  # at rest at both ends


def test_without_a_floor_the_arm_going_below_its_base_is_said(tmp_path):
    """issue "Nothing runs, nothing silent": a design without ``[workspace] floor`` keeps nothing off the table the
    robot stands on. Where its set-points take a joint below the base frame's origin, that is said with where and
    when, checked against Pinocchio's kinematics of the robot's URDF; with a floor given it is not."""
    p = dynid("excite", str(_robot_only(tmp_path)), "--out", str(tmp_path / "out"))
    assert p.returncode == 0, p.stderr
    lowest = json.loads((tmp_path / "out" / "excitation.json").read_text())["lowest"]
    csv = np.loadtxt(tmp_path / "out" / "excitation.csv", delimiter=",", skiprows=1)
    model = pin.buildModelFromUrdf(str(resources.files("dynid.model") / "robots" / "ur10e.urdf"))
    data = model.createData()
    z = np.empty((csv.shape[0], 6))
    for n, q in enumerate(csv[:, 1:7]):
        pin.forwardKinematics(model, data, q)
        z[n] = [data.oMi[j].translation[2] for j in range(1, 7)]
    # the lowest point of the links' capsules about the joint origins (no meshes shipped): an end's height less the radius
    radius = load_excitation_config(_robot_only(tmp_path)).problem.workspace.capsule_radius(load_robot("ur10e"))
    assert lowest["point"].endswith("capsule") and lowest["height"] == pytest.approx(z.min() - radius, abs=0.02)
    assert lowest["height"] <= z[:, 1:].min() - radius + 1e-9  # the flange's end is not among Pinocchio's joints
    said = " ".join((p.stdout + p.stderr).split())
    assert (f"no floor given ([workspace] floor), so nothing kept the arm off what it stands on: {lowest['point']} "
            f"goes {-lowest['height']:.3g} m below the base frame's origin at t = {lowest['time']:.3g} s") in said
    assert "give its height in the base frame as [workspace] floor" in said
    assert "next: settle the warnings above, then play" in said  # not "play excitation.csv" at once
    assert "no floor given" in (tmp_path / "out" / "report.html").read_text().replace("&#39;", "'")

    p = dynid("excite", str(_robot_only(tmp_path, "[workspace]\nfloor = -2.0\n")), "--out", str(tmp_path / "floor"))
    assert p.returncode == 0, p.stderr
    assert "no floor given" not in p.stdout + p.stderr
    assert "lowest" not in json.loads((tmp_path / "floor" / "excitation.json").read_text())


def test_capsules_kept_apart_when_asked_and_said_otherwise(tmp_path):
    """The ER-16's design folds link 3 onto link 1 (their capsules overlap at the set-points) and says so. With
    ``[workspace] avoid_self_collision = true`` the design keeps the capsules apart, as coal's check of the set-points
    finds; the warning then names the option no longer, and excitation.json says it was asked."""
    thin = "floor = -0.75\nlink_radius = 0.05"  # capsules about as thick as the arm's skeleton allows
    plain = _small(tmp_path, "excite-er16.toml", {"starts = 6": "starts = 1", "floor = -0.75": thin})
    p = dynid("excite", str(plain), "--out", str(tmp_path / "plain"))
    assert p.returncode == 0, p.stderr
    before = json.loads((tmp_path / "plain" / "excitation.json").read_text())
    assert before["self_clearance"]["distance"] < 0
    assert "[workspace] avoid_self_collision = true" in " ".join((p.stdout + p.stderr).split())
    kept = _small(tmp_path, "excite-er16.toml", {"starts = 6": "starts = 1",
                                                 "floor = -0.75": thin + "\navoid_self_collision = true"})
    p = dynid("excite", str(kept), "--out", str(tmp_path / "kept"))
    assert p.returncode == 0, p.stderr
    after = json.loads((tmp_path / "kept" / "excitation.json").read_text())
    assert after["self_clearance"]["distance"] >= 0 and after["workspace"]["avoid_self_collision"] is True
    assert any(m["constraint"] == "self clearance [m]" and m["worst"] >= 0 for m in after["design"]["margins"])
    assert "avoid_self_collision" not in before["workspace"]


def test_a_robots_urdf_alone_is_a_config_of_it(tmp_path):
    """``dynid excite arm.urdf``, the first step with nothing but the robot's file: refused as "invalid TOML"; it now
    designs the default trajectory for that robot, as a config naming the URDF alone does."""
    urdf = tmp_path / "arm.urdf"
    urdf.write_text(Path(str(resources.files("dynid.model") / "robots" / "ur10e.urdf")).read_text(encoding="utf-8"))
    p = dynid("excite", str(urdf), "--out", str(tmp_path / "out"), "--starts", "1")
    assert p.returncode == 0, p.stderr
    doc = json.loads((tmp_path / "out" / "excitation.json").read_text())
    assert doc["joints"] == 6 and doc["harmonics"] == 5 and doc["rest"] is True
    assert doc["omega_f"] == pytest.approx(2 * np.pi * 0.1)


@pytest.mark.parametrize("height, warned, said", [
    (-0.1234, True, "joint 6's origin goes 0.123 m below the base frame's origin at t = 2.5 s"),
    (0.0123, True, "joint 6's origin comes 0.0123 m above the base frame's origin, its link within its 0.05 m clearance"),
    (0.25, False, "the lowest point, joint 6's origin, stays 0.25 m above the base frame's origin (t = 2.5 s)"),
])
def test_the_lowest_point_is_a_warning_below_the_links_clearance(height, warned, said):
    from dynid.report.excitation_summary import no_floor_line

    text, warning = no_floor_line({"height": height, "point": "joint 6's origin", "time": 2.5}, 0.05)
    assert warning is warned and said in text


def test_a_robots_urdf_alone_holds_a_grippers_finger_as_init_does(tmp_path):
    """``dynid excite arm.urdf`` of an arm with a gripper's finger (a prismatic joint past the wrist): refused with
    "hold it fixed with held = [...] in the config's [robot] table"; the finger is now held as dynid init holds it,
    and said."""
    text = Path(str(resources.files("dynid.model") / "robots" / "ur10e.urdf")).read_text(encoding="utf-8")
    finger = ('<link name="finger"><inertial><origin xyz="0 0 0"/><mass value="0.1"/><inertia ixx="1e-4" ixy="0" '
              'ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial></link><joint name="finger_joint" type="prismatic">'
              '<parent link="wrist_3_link"/><child link="finger"/><axis xyz="0 1 0"/><limit lower="0" upper="0.04" '
              'effort="20" velocity="0.2"/></joint></robot>')
    assert text.count("</robot>") == 1 and 'link name="wrist_3_link"' in text
    (tmp_path / "arm.urdf").write_text(text.replace("</robot>", finger))
    p = dynid("excite", str(tmp_path / "arm.urdf"), "--out", str(tmp_path / "out"), "--starts", "1")
    assert p.returncode == 0, p.stderr
    assert "held fixed at 0, not the arm's joints: finger_joint" in " ".join(p.stdout.split())
    assert json.loads((tmp_path / "out" / "excitation.json").read_text())["joints"] == 6


def test_excitation_csv_holds_the_encoders_angles_where_the_description_offsets_them(tmp_path):
    """The TX40's description puts J2's and J3's encoder zeros a quarter turn from its DH table's
    (``position_offset = "-pi/2"``, ``"pi/2"``: a log's angles plus the offset are the model's). excitation.csv is what
    the controller plays: the design's angles minus the offset, and said; excitation.json keeps the model's (it wrote
    the model's angles, a quarter turn off on J2 and J3 for the robot's controller)."""
    robot = REPO / "configs" / "robots" / "tx40_simulation.toml"
    config = _small(tmp_path, "excite-tx40.toml", {"starts = 4": "starts = 1\nmaxiter = 5",
                                                   '"robots/tx40_simulation.toml"': f'"{robot.as_posix()}"'})
    p = dynid("excite", str(config), "--out", str(tmp_path / "out"))
    assert p.returncode == 0, p.stderr
    assert "at the angles the joints' encoders read" in " ".join(p.stdout.split())
    csv = np.loadtxt(tmp_path / "out" / "excitation.csv", delimiter=",", skiprows=1)
    q, _, _ = load_trajectory(tmp_path / "out" / "excitation.json").evaluate(csv[:, 0])
    assert np.allclose(csv[:, 1:7] - q, [0.0, np.pi / 2, -np.pi / 2, 0.0, 0.0, 0.0], atol=1e-8)
    assert np.allclose(csv[:, 7:13], load_trajectory(tmp_path / "out" / "excitation.json").evaluate(csv[:, 0])[1],
                       atol=1e-7)


def test_the_start_pose_is_said_and_a_start_in_motion_is_a_warning(tmp_path):
    """A controller handed excitation.csv's first row from another pose jumps there: dynid excite says where it starts
    (the first row, in degrees), and warns where the design starts moving (the paper's ER-16 trajectory, not from
    rest: a step in speed for a controller at rest there)."""
    config = _small(tmp_path, "excite-tx40.toml", {"starts = 4": "starts = 1\nmaxiter = 5",
                                                   '"robots/tx40_simulation.toml"':
                                                   f'"{(REPO / "configs" / "robots" / "tx40_simulation.toml").as_posix()}"'})
    p = dynid("excite", str(config), "--out", str(tmp_path / "rest"))
    said = " ".join(p.stdout.split())
    assert p.returncode == 0 and "it starts at rest at J1 0.0°, J2 90.0°, J3 -90.0°" in said, said
    first = np.loadtxt(tmp_path / "rest" / "excitation.csv", delimiter=",", skiprows=1)[0]
    assert np.allclose(np.degrees(first[1:4]), [0.0, 90.0, -90.0], atol=0.05) and np.allclose(first[7:13], 0.0)
    kept = json.loads((tmp_path / "rest" / "excitation.json").read_text())["set_points"]  # report.html says it too
    assert np.allclose(kept["first"], first[1:7], atol=1e-8) and kept["position_offset"][1:3] == [-np.pi / 2, np.pi / 2]
    assert "it starts at rest at J1 0.0°, J2 90.0°" in (tmp_path / "rest" / "report.html").read_text()
    p = dynid("excite", str(REPO / "configs" / "excite-er16.toml"), "--out", str(tmp_path / "moving"), "--starts", "1")
    said = " ".join((p.stdout + p.stderr).split())
    first = np.loadtxt(tmp_path / "moving" / "excitation.csv", delimiter=",", skiprows=1)[0]
    j = int(np.argmax(np.abs(first[4:7])))
    assert p.returncode == 0 and f"warning: it starts moving ({abs(first[4 + j]):.3g} rad/s on J{j + 1})" in said, said
    assert "next: settle the warnings above, then play excitation.csv" in said


def _two_arm_torso(path: Path) -> None:
    """A torso with two 2-joint arms, each link a box; the left arm's second link a plate 0.8 m long held just above the
    right arm's shoulder, where the right forearm rises into it when it pitches up under it."""
    def link(name, mass, com, box, at):
        return (f'<link name="{name}"><inertial><origin xyz="{com}"/><mass value="{mass}"/><inertia ixx="0.02" ixy="0" '
                f'ixz="0" iyy="0.02" iyz="0" izz="0.02"/></inertial><collision><origin xyz="{at}"/><geometry><box '
                f'size="{box}"/></geometry></collision></link>')

    def revolute(name, parent, child, xyz, axis):
        return (f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/><origin '
                f'xyz="{xyz}"/><axis xyz="{axis}"/><limit lower="-3" upper="3" effort="80" velocity="2"/></joint>')

    body = (link("base", 10.0, "0 0 0.2", "0.2 0.2 0.5", "0 0 0.25")
            + link("l_link1", 2.0, "0 0 0.1", "0.08 0.08 0.2", "0 0 0.1") + link("l_link2", 1.5, "0 -0.4 0", "0.6 0.8 0.05", "0 -0.4 0")
            + revolute("l1", "base", "l_link1", "0 0.3 0.5", "0 0 1") + revolute("l2", "l_link1", "l_link2", "0 0 0.3", "1 0 0")
            + link("r_link1", 2.0, "0 0 0.1", "0.08 0.08 0.2", "0 0 0.1") + link("r_link2", 1.5, "0.25 0 0", "0.5 0.08 0.08", "0.25 0 0")
            + revolute("r1", "base", "r_link1", "0 -0.3 0.5", "0 0 1") + revolute("r2", "r_link1", "r_link2", "0 0 0.2", "0 1 0"))
    path.write_text(f'<?xml version="1.0"?>\n<robot name="torso">{body}</robot>\n')


def _arm_to_held_distance(urdf: Path, csv: Path) -> float:
    """The smallest distance between the right arm's forearm and the torso or the held left arm along excitation.csv,
    by Pinocchio and coal on the whole URDF (the left arm at 0): an independent pass."""
    model = pin.buildModelFromUrdf(str(urdf))
    geometry = pin.buildGeomFromUrdf(model, str(urdf), pin.GeometryType.COLLISION)
    names = [g.name for g in geometry.geometryObjects]
    for a in (i for i, n in enumerate(names) if n.startswith("r_link2")):
        for b in (i for i, n in enumerate(names) if n.startswith(("l_", "base"))):
            geometry.addCollisionPair(pin.CollisionPair(a, b))
    data, geometry_data = model.createData(), pin.GeometryData(geometry)
    at = [model.joints[model.getJointId(n)].idx_q for n in ("r1", "r2")]
    smallest = np.inf
    for row in np.loadtxt(csv, delimiter=",", skiprows=1):
        q = pin.neutral(model)
        q[at] = row[1:3]
        pin.computeDistances(model, data, geometry, geometry_data, q)
        smallest = min(smallest, min(r.min_distance for r in geometry_data.distanceResults))
    return smallest


def test_a_design_keeps_the_arm_off_a_held_arms_shapes_and_says_how_close_it_comes(tmp_path):
    """One arm of a two-arm robot designed with the other held (no floor, no obstacles): the held arm's collision
    shapes are bodies the moving arm can meet. They were left out (capsules about the moving arm's joints alone), and
    the designs drove the forearm 0.16 m into the held arm without a word; now the design keeps clear of them and the
    printed smallest distance is an independent Pinocchio + coal pass's to 1 mm."""
    _two_arm_torso(tmp_path / "torso.urdf")
    (tmp_path / "excite.toml").write_text('[robot]\nurdf = "torso.urdf"\nheld = ["l1", "l2"]\n\n'
                                          '[trajectory]\nharmonics = 3\nfrequency = 0.2\n')
    p = dynid("excite", tmp_path / "excite.toml", "--out", tmp_path / "ex", "--starts", "1", "--seed", "1",
              cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    independent = _arm_to_held_distance(tmp_path / "torso.urdf", tmp_path / "ex" / "excitation.csv")
    assert independent > 0
    said = json.loads((tmp_path / "ex" / "excitation.json").read_text())["self_clearance"]
    assert abs(said["distance"] - independent) < 1e-3
    assert "the links' collision shapes stay" in " ".join(p.stdout.split())


def test_an_excitation_table_at_the_top_of_an_identification_config_is_refused_naming_its_place(tmp_path):
    """`[workspace]` at the top of an identification config: dynid identify refuses it, and dynid excite read past it
    (its floor, SRDF and obstacles unused, in silence)."""
    cfg = tmp_path / "arm.toml"
    cfg.write_text('robot = "ur10e"\n\n[identification]\nfile = "log.csv"\n\n[workspace]\nfloor = 0.0\n')
    assert_refused(dynid("excite", cfg, "--out", tmp_path / "ex"),
                   "arm.toml: workspace: an identification config holds the excitation's settings in its [excitation] "
                   "table: [excitation.workspace]")


def test_held_links_left_unchecked_when_the_shapes_do_not_load_are_said(tmp_path):
    """The two-arm torso whose held arm's collision mesh is not beside the URDF: the shapes cannot be read, the design
    falls back to capsules about the moving arm's joint origins, and the held arm is in no check. That was said
    nowhere (the capsule warning came only with a floor or obstacles); a warning names the held joints now, and with
    the shapes readable it is not printed."""
    _two_arm_torso(tmp_path / "torso.urdf")
    text = (tmp_path / "torso.urdf").read_text()
    (tmp_path / "torso.urdf").write_text(text.replace('<box size="0.6 0.8 0.05"/>', '<mesh filename="plate.stl"/>'))
    (tmp_path / "excite.toml").write_text('[robot]\nurdf = "torso.urdf"\nheld = ["l1", "l2"]\n\n'
                                          '[trajectory]\nharmonics = 2\nfrequency = 0.2\n[design]\nmaxiter = 20\n')
    p = dynid("excite", tmp_path / "excite.toml", "--out", tmp_path / "ex", "--starts", "1", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    said = " ".join((p.stdout + p.stderr).split())
    assert "warning: the robot file has no collision shapes dynid could read" in said and "Mesh plate.stl could not be found" in said
    assert "the held joints' links (l1, l2: another arm, a head, a gripper) are in no clearance check" in said, said
    assert "the links' collision shapes stay" not in said
    written = json.loads((tmp_path / "ex" / "excitation.json").read_text())["warnings"]  # and so say the files
    assert any("the held joints' links (l1, l2" in w for w in written)
    assert "the held joints&#39; links (l1, l2" in (tmp_path / "ex" / "report.html").read_text()
    (tmp_path / "torso.urdf").write_text(text)
    p = dynid("excite", tmp_path / "excite.toml", "--out", tmp_path / "ok", "--starts", "1", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert "held joints' links" not in " ".join((p.stdout + p.stderr).split())

"""dynid init: a starter config from a URDF and a log, which dynid identify then runs on as it stands."""

import json
import re
import tomllib
from importlib import resources
from pathlib import Path

import numpy as np
import pytest

import dynid

from .refusals import assert_refused
from .refusals import dynid as run

URDF = Path(str(resources.files("dynid.model") / "robots" / "ur10e.urdf"))


def _identification(text: str) -> dict:
    """The ``[identification]`` table of a config's text."""
    return tomllib.loads(text)["identification"]


def _log(folder: Path, header: bool, robot=URDF) -> Path:
    log = dynid.simulated_log(dynid.load_robot(robot), seconds=30, rng=4)
    names = ["time"] + [f"joint_pos_{j}" for j in range(1, 7)] + [f"effort[{j}]" for j in range(6)]
    path = folder / "logs" / "run.csv"
    path.parent.mkdir()
    np.savetxt(path, np.column_stack([log.t, log.q, log.tau]), delimiter=",", comments="",
               header=",".join(names) if header else "")
    return path


def test_init_detects_the_columns_by_header_and_identify_runs_on_the_config(tmp_path, monkeypatch):
    log = _log(tmp_path, header=True)
    (tmp_path / "cfg").mkdir()
    monkeypatch.chdir(tmp_path / "cfg")  # the config beside neither the URDF nor the log: paths relative to it
    p = run("init", str(URDF), str(log), "--out", "arm.toml")
    assert p.returncode == 0, p.stderr
    text = (tmp_path / "cfg" / "arm.toml").read_text()
    ident = _identification(text)
    assert ident["positions"]["columns"][:2] == ["joint_pos_1", "joint_pos_2"]
    assert ident["torques"]["columns"][0] == "effort[0]"
    assert ident["time"] == {"column": "time"} and tomllib.loads(text)["data_root"] == "../logs"
    # the physically consistent estimate listed beside WLS (the URDF's nominal values are consistent), so that the
    # verdict can choose it and export has it
    assert tomllib.loads(text)["estimation"]["estimators"] == ["wls", "sdp"]
    p = run("identify", "arm.toml", "--out", "id", "--no-figures", "-q")
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "cfg" / "id" / "results.json").is_file()
    # one output folder, one model: the user's URDF with the identified values written in, under its own name, the
    # same file `dynid export --urdf` writes; every line but <inertial>/<dynamics> values and dynid's comments the user's
    written = tmp_path / "cfg" / "id" / URDF.name
    assert written.is_file() and not (tmp_path / "cfg" / "id" / "dynid-model.urdf").exists()
    assert (tmp_path / "cfg" / "id" / "dynid-model.xml").is_file()
    p = run("export", "arm.toml", "--results", "id/results.json", "--urdf", "exported.urdf")
    assert p.returncode == 0, p.stderr
    assert written.read_text() == (tmp_path / "cfg" / "exported.urdf").read_text()
    import difflib
    import re

    changed = [ln for ln in difflib.unified_diff(URDF.read_text().splitlines(), written.read_text().splitlines(),
                                                 lineterm="", n=0) if ln[:1] in "+-" and ln[:3] not in ("+++", "---")]
    assert changed and all(re.match(r"[-+]\s*(<origin|<mass|<inertia|<dynamics|<!-- |dynid|that predict|experiment|link's)",
                                    ln) for ln in changed), changed


def test_init_without_a_header_takes_blocks_of_columns(tmp_path):
    log = _log(tmp_path, header=False)
    p = run("init", str(URDF), str(log), "--out", str(tmp_path / "arm.toml"))
    assert p.returncode == 0, p.stderr
    text = (tmp_path / "arm.toml").read_text()
    ident = _identification(text)
    assert ident["time"] == {"column": 1} and ident["positions"]["columns"] == [2, 3, 4, 5, 6, 7]
    assert ident["torques"]["columns"] == [8, 9, 10, 11, 12, 13] and "no header: column 1 taken as time" in p.stdout
    p = run("identify", str(tmp_path / "arm.toml"), "--out", str(tmp_path / "id"), "--no-figures", "-q")
    assert p.returncode == 0, p.stderr


def test_init_refusals(tmp_path):
    log = _log(tmp_path, header=True)
    (tmp_path / "arm.toml").write_text("mine")
    assert_refused(run("init", str(URDF), str(log), "--out", str(tmp_path / "arm.toml")), "exists; give another name, or --force")
    assert (tmp_path / "arm.toml").read_text() == "mine"
    # --force replaces an earlier config, never a file the run reads: the log or the robot file
    urdf = tmp_path / "arm.urdf"
    urdf.write_text(URDF.read_text())
    before = log.read_bytes(), urdf.read_bytes()
    for target in (log, urdf):
        assert_refused(run("init", str(urdf), str(log), "--out", str(target), "--force"),
                       f"--out {target}: a file this init reads")
    assert (log.read_bytes(), urdf.read_bytes()) == before
    odd = tmp_path / "odd.csv"
    odd.write_text("a,b,c\n1,2,3\n4,5,6\n")
    assert_refused(run("init", str(URDF), str(odd), "--out", str(tmp_path / "x.toml")), "odd.csv: no time column among ['a', 'b', 'c']")
    assert_refused(run("init", str(tmp_path / "none.urdf"), str(log), "--out", str(tmp_path / "y.toml")), "none.urdf")
    assert not (tmp_path / "x.toml").exists() and not (tmp_path / "y.toml").exists()


def test_init_says_a_file_of_one_signal_per_joint_needs_one_file_per_signal(tmp_path):
    """FIGAROH's TX40 log: one file of positions and one of currents, each headed Joint_1 … Joint_6. Init said "found 0
    positions column(s)" of the file of positions (with --rate; without it, "no time column"); it now says the columns
    name joints, not a signal, and how a config gives each signal its file. Six columns that name signals still pass."""
    joints = tmp_path / "pos.csv"
    joints.write_text("Joint_1,Joint_2,Joint_3,Joint_4,Joint_5,Joint_6\n" + "0.1,0.2,0.3,0.4,0.5,0.6\n" * 5)
    for extra in ((), ("--rate", "5000")):
        p = run("init", str(URDF), str(joints), "--out", str(tmp_path / "x.toml"), *extra)
        assert_refused(p, "pos.csv: its 6 columns")
        said = " ".join(p.stderr.split())
        assert "name the joints, not a signal" in said and 'positions = { file = "pos.csv", columns = [...] }' in said
    assert not (tmp_path / "x.toml").exists()


def test_init_says_which_columns_it_took_and_which_it_left(tmp_path):
    """A log of six joints for a robot of three (a URDF that is not the whole arm): init took q1-q3 and tau1-tau3 and
    left q4-q6 and tau4-tau6 without a word; now it names what it left and asks whether the URDF is the whole arm."""
    import re

    text = URDF.read_text()
    for name in ("wrist_1_joint", "wrist_2_joint", "wrist_3_joint"):  # the wrist made fixed: a 3-joint robot
        text = re.sub(rf'(<joint name="{name}" type=")revolute(")', r"\1fixed\2", text)
    (tmp_path / "arm3.urdf").write_text(text)
    t = np.arange(200) * 0.01
    names = ["t"] + [f"q{j}" for j in range(1, 7)] + [f"tau{j}" for j in range(1, 7)] + ["temperature"]
    np.savetxt(tmp_path / "log.csv", np.column_stack([t] + [np.sin(t + j) for j in range(13)]), delimiter=",",
               header=",".join(names), comments="")
    p = run("init", str(tmp_path / "arm3.urdf"), str(tmp_path / "log.csv"), "--out", str(tmp_path / "arm.toml"))
    assert p.returncode == 0, p.stderr
    said = " ".join(p.stdout.split())
    assert "positions: q1, q2, q3" in said
    assert ("not read: q4, q5, q6, tau4, tau5, tau6, temperature — the log has more joint columns than the robot's 3 "
            "joints (q4, q5, q6, tau4, tau5, tau6): is arm3.urdf the whole arm") in said


def test_init_with_a_validation_log_writes_a_config_that_validates(tmp_path):
    """dynid init URDF LOG VALIDATION_LOG: the [[validation]] entry is a name and a file, which take the identification's
    columns (init's own template failed when uncommented: "expected 'positions'"); identify validates on it."""
    log = _log(tmp_path, header=True)
    other = dynid.simulated_log(dynid.load_robot(URDF), seconds=20, rng=5)
    names = ["time"] + [f"joint_pos_{j}" for j in range(1, 7)] + [f"effort[{j}]" for j in range(6)]
    np.savetxt(log.parent / "other.csv", np.column_stack([other.t, other.q, other.tau]), delimiter=",", comments="",
               header=",".join(names))
    p = run("init", str(URDF), str(log), str(log.parent / "other.csv"), "--out", str(tmp_path / "arm.toml"))
    assert p.returncode == 0, p.stderr
    text = (tmp_path / "arm.toml").read_text()
    assert '[[validation]]' in text and 'name = "other"' in text and 'file = "other.csv"' in text
    p = run("identify", str(tmp_path / "arm.toml"), "--out", str(tmp_path / "id"), "--no-figures", "-q")
    assert p.returncode == 0, p.stderr
    import json

    results = json.loads((tmp_path / "id" / "results.json").read_text())
    assert [v["name"] for v in results["validation"]] == ["other"]


def test_init_reads_a_plotjuggler_export_of_joint_states_in_the_urdfs_joint_order(tmp_path):
    """PlotJuggler's CSV of ``/joint_states``: ``__time`` (epoch seconds) and ``/joint_states/<joint>/position|velocity|
    effort``, the joints in the driver's (alphabetical) order. init refused it ("no time column among ['__time', …]",
    then "found 0 positions column(s)"); now it takes the columns in the URDF's joint order and says so, and identify
    on the config recovers the simulated arm (a wrong order would swap joints' torques)."""
    import json

    robot = dynid.load_robot(URDF)
    log = dynid.simulated_log(robot, seconds=30, rng=4)
    joints = [j.name for j in robot.joints]
    order = sorted(range(6), key=lambda j: joints[j])  # elbow_joint, shoulder_lift_joint, shoulder_pan_joint, wrist_…
    assert order != list(range(6))
    names = ["__time", "/joint_states/header/stamp"] + [f"/joint_states/{joints[j]}/{signal}"
                                                          for signal in ("position", "velocity", "effort") for j in order]
    dq = np.gradient(log.q, log.t, axis=0)
    columns = [log.t + 1.7e9, log.t + 1.7e9] + [x[:, j] for x in (log.q, dq, log.tau) for j in order]
    (tmp_path / "logs").mkdir()
    np.savetxt(tmp_path / "logs" / "joint_states.csv", np.column_stack(columns), delimiter=",", comments="",
               header=",".join(names), fmt="%.10f")
    p = run("init", str(URDF), str(tmp_path / "logs" / "joint_states.csv"), "--out", str(tmp_path / "arm.toml"))
    assert p.returncode == 0, p.stderr
    text = (tmp_path / "arm.toml").read_text()
    assert _identification(text)["time"] == {"column": "__time"}
    assert _identification(text)["positions"]["columns"][:3] == [
        "/joint_states/shoulder_pan_joint/position", "/joint_states/shoulder_lift_joint/position",
        "/joint_states/elbow_joint/position"]
    assert "taken in the URDF's joint order" in " ".join(p.stdout.split())
    p = run("identify", str(tmp_path / "arm.toml"), "--out", str(tmp_path / "id"), "--no-figures", "-q")
    assert p.returncode == 0, p.stderr
    results = json.loads((tmp_path / "id" / "results.json").read_text())
    # the log is the URDF's own model simulated: its prediction matches every joint carrying torque (J6 carries 0.01 N·m)
    assert min(results["diagnostics"]["nominal_correlation"][:5]) > 0.99
    assert max(results["identification"]["metrics"]["dynid WLS"]["relative_error"][:3]) < 0.1


def test_init_names_the_patterns_it_accepts(tmp_path):
    """A header init cannot read: the refusal lists what it accepts, the ROS-style names among them."""
    odd = tmp_path / "odd.csv"
    odd.write_text("__time,a,b\n1,2,3\n4,5,6\n")
    assert_refused(run("init", str(URDF), str(odd), "--out", str(tmp_path / "x.toml")),
                   "odd.csv: found 0 positions column(s) of the 6 the robot needs among ['__time', 'a', 'b']; accepted: t, "
                   "time, timestamp, __time or %time")
    assert not (tmp_path / "x.toml").exists()


def test_init_on_a_ros2_mcap_bag_writes_a_config_identify_runs(tmp_path):
    """A rosbag2 in MCAP (ROS 2's default storage since Iron) of a simulated UR10e's /joint_states, joints in the
    driver's order: init writes a bag table (it read the bag as text before: "not a UTF-8 text table") and identify
    on it matches the URDF's own model."""
    import json
    import sys

    sys.path.insert(0, str(Path(__file__).parents[1] / "io"))
    from test_bags import _write_bag

    robot = dynid.load_robot(URDF)
    log = dynid.simulated_log(robot, seconds=30, rng=4)
    names = [j.name for j in robot.joints]
    order = sorted(range(6), key=lambda j: names[j])
    (tmp_path / "logs").mkdir()
    dq = np.gradient(log.q, log.t, axis=0)
    _write_bag(tmp_path / "logs" / "run_01", log.t + 100.0, [names[j] for j in order], log.q[:, order], dq[:, order],
               log.tau[:, order], storage="mcap")
    p = run("init", str(URDF), str(tmp_path / "logs" / "run_01"), "--out", str(tmp_path / "arm.toml"))
    assert p.returncode == 0, p.stderr
    assert 'bag = "run_01"' in (tmp_path / "arm.toml").read_text()
    assert_refused(run("init", str(URDF), str(tmp_path / "logs"), "--out", str(tmp_path / "x.toml")),
                   "logs: a folder without metadata.yaml, not a ROS 2 bag")
    assert not (tmp_path / "x.toml").exists()
    p = run("identify", str(tmp_path / "arm.toml"), "--out", str(tmp_path / "id"), "--no-figures", "-q")
    assert p.returncode == 0, p.stderr
    results = json.loads((tmp_path / "id" / "results.json").read_text())
    assert min(results["diagnostics"]["nominal_correlation"][:5]) > 0.99


def test_the_config_init_wrote_runs_excite_and_identifys_advice_runs_as_printed(tmp_path, monkeypatch):
    """``dynid excite`` on the config init wrote refused it ("unknown field 'data_root'": another format, which init
    writes none of); an identification config is now an excitation config (its robot, an optional [excitation]
    table). And identify's advice is a command that runs as printed: the export line names this config, the results
    just written and files to write, where it said CONFIG and FILE."""
    import shlex

    truth = tmp_path / "truth.urdf"  # the arm the logs come from: its links 20 % heavier than the URDF init is given says
    truth.write_text(re.sub(r'<mass value="([0-9.e+-]+)"', lambda m: f'<mass value="{1.2 * float(m.group(1)):.6g}"',
                            URDF.read_text()))
    log = _log(tmp_path, header=True, robot=truth)
    other = log.with_name("other.csv")  # another motion of the same layout (a copy of the log is no validation)
    again = dynid.simulated_log(dynid.load_robot(truth), seconds=10, rng=5)
    np.savetxt(other, np.column_stack([again.t, again.q, again.tau]), delimiter=",", comments="",
               header=log.read_text().splitlines()[0])
    monkeypatch.chdir(tmp_path)
    assert run("init", str(URDF), str(log), str(other), "--out", "arm.toml").returncode == 0
    text = (tmp_path / "arm.toml").read_text()
    (tmp_path / "arm.toml").write_text(text + "\n[excitation.design]\nstarts = 1\nmaxiter = 3\n")
    p = run("excite", "arm.toml", "--out", "excitation", "-q")
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "excitation" / "excitation.csv").is_file()
    p = run("identify", "arm.toml", "--out", "id", "--no-figures")
    assert p.returncode == 0, p.stderr
    said = " ".join(p.stdout.split())  # the console wraps long lines
    assert "CONFIG" not in said and "FILE" not in said
    assert said.startswith("model ready: dynid SDP, as the URDF and MJCF in the output folder"), said[:200]
    start = said.index("dynid export")
    command = shlex.split(said[start: said.index("-identified.urdf", start) + len("-identified.urdf")])
    assert command[:2] == ["dynid", "export"]
    p = run(*command[1:])
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "arm-identified.urdf").is_file()


def test_init_reads_a_rostopic_export_with_nanosecond_time_stamps(tmp_path):
    """`rostopic echo -p /joint_states` writes %time in nanoseconds since the epoch, the joint names as text and
    field.position0…: init takes %time with unit = "ns" (it took field.header.stamp as seconds, and identify refused
    the config it wrote: "are they in milliseconds?"), and identify runs on the config as written."""
    import json

    sim = dynid.simulated_log(dynid.load_robot(URDF), seconds=20, rng=5)
    stamps = np.round((1.6e9 + sim.t) * 1e9).astype(np.int64)
    header = (["%time", "field.header.seq", "field.header.stamp"] + [f"field.name{j}" for j in range(6)]
              + [f"field.position{j}" for j in range(6)] + [f"field.effort{j}" for j in range(6)])
    rows = [",".join([str(s), str(k), str(s)] + [f"joint_{j}" for j in range(6)] + [f"{x:.9g}" for x in (*q, *tau)])
            for k, (s, q, tau) in enumerate(zip(stamps, sim.q, sim.tau))]
    (tmp_path / "js.csv").write_text("\n".join([",".join(header), *rows]) + "\n")
    p = run("init", str(URDF), str(tmp_path / "js.csv"), "--out", str(tmp_path / "ros.toml"))
    assert p.returncode == 0, p.stderr
    assert _identification((tmp_path / "ros.toml").read_text())["time"] == {"column": "%time", "unit": "ns"}
    p = run("identify", str(tmp_path / "ros.toml"), "--out", str(tmp_path / "id"), "--no-figures", "-q")
    assert p.returncode == 0, p.stderr
    results = json.loads((tmp_path / "id" / "results.json").read_text())
    rate = results["settings"]["rate"]
    assert abs(rate - 1.0 / float(np.median(np.diff(sim.t)))) < 1e-2 * rate


def test_init_reads_a_log_saved_by_numpy_with_its_header_as_a_comment(tmp_path):
    """np.savetxt(..., header="time,q1,…") writes "# time,q1,…": init found "no time column among ['# time', …]" and
    identify "no column named 'time'"; both now take the comment as the header, and identify runs on the config."""
    sim = dynid.simulated_log(dynid.load_robot(URDF), seconds=20, rng=6)
    names = ["time"] + [f"q{j}" for j in range(1, 7)] + [f"tau{j}" for j in range(1, 7)]
    np.savetxt(tmp_path / "run.csv", np.column_stack([sim.t, sim.q, sim.tau]), delimiter=",", header=",".join(names))
    assert (tmp_path / "run.csv").read_text().startswith("# time,q1")
    p = run("init", str(URDF), str(tmp_path / "run.csv"), "--out", str(tmp_path / "np.toml"))
    assert p.returncode == 0, p.stderr
    assert _identification((tmp_path / "np.toml").read_text())["time"] == {"column": "time"}
    p = run("identify", str(tmp_path / "np.toml"), "--out", str(tmp_path / "id"), "--no-figures", "-q")
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "id" / "results.json").is_file()


def test_init_takes_a_rostopic_export_in_the_urdfs_joint_order_by_its_name_columns(tmp_path):
    """ROS drivers publish /joint_states with the joints in their own order (the UR driver's is alphabetical: elbow
    first), which `rostopic echo -p` writes as field.name0… text columns beside field.position0…: init took
    field.position0 for the URDF's first joint (the UR10e log so fitted at 29.7 % instead of 1.77 %). Now each signal's
    columns are taken in the URDF's order by the names, said, and the log reads as the one written in that order."""
    from dynid.io.config.identification_config import load_identification_config
    from dynid.io.logs.datasets import load_recording

    robot = dynid.load_robot(URDF)
    joints = [j.name for j in robot.joints]
    sim = dynid.simulated_log(robot, seconds=5, rng=6)
    for name, order in (("urdf", list(range(6))), ("alphabetical", sorted(range(6), key=lambda j: joints[j]))):
        header = (["%time"] + [f"field.name{k}" for k in range(6)] + [f"field.position{k}" for k in range(6)]
                  + [f"field.effort{k}" for k in range(6)])
        rows = [",".join([f"{t:.6f}"] + [joints[j] for j in order] + [f"{q[j]:.9g}" for j in order]
                         + [f"{tau[j]:.9g}" for j in order]) for t, q, tau in zip(sim.t, sim.q, sim.tau)]
        (tmp_path / f"{name}.csv").write_text("\n".join([",".join(header), *rows]) + "\n")
        p = run("init", str(URDF), str(tmp_path / f"{name}.csv"), "--out", str(tmp_path / f"{name}.toml"))
        assert p.returncode == 0, p.stderr
    text = (tmp_path / "alphabetical.toml").read_text()
    assert "the log names its joints in field.name0" in p.stdout.replace("\n", " ")
    shuffled = sorted(range(6), key=lambda j: joints[j])
    assert _identification(text)["positions"]["columns"] == [f"field.position{shuffled.index(j)}" for j in range(6)]
    plain, alpha = (load_identification_config(tmp_path / f"{n}.toml") for n in ("urdf", "alphabetical"))
    a, b = (load_recording(c.identification, c.robot) for c in (plain, alpha))
    np.testing.assert_array_equal(np.asarray(a.q), np.asarray(b.q))
    np.testing.assert_array_equal(np.asarray(a.tau), np.asarray(b.tau))


def test_init_sums_a_time_stamp_split_into_seconds_and_nanoseconds(tmp_path):
    """issue "Nothing runs, nothing silent": bag-to-CSV converters write header.stamp.sec and header.stamp.nanosec;
    init took the whole seconds as the time (the nanoseconds 'unused'), and with 5 % of the messages dropped the fit
    missed by 4.2 % instead of 0.06 %. Both columns now make the time, and identify fits the log as simulated."""
    import json

    sim = dynid.simulated_log(dynid.load_robot(URDF), seconds=20, rng=7)
    keep = np.random.default_rng(3).random(sim.t.size) > 0.05  # 5 % of the messages lost
    ns = np.round((1.7e9 + sim.t[keep]) * 1e9).astype(np.int64)
    header = ["header.stamp.sec", "header.stamp.nanosec"] + [f"position.{j}" for j in range(6)] + \
        [f"effort.{j}" for j in range(6)]
    rows = [",".join([str(s // 10**9), str(s % 10**9)] + [f"{x:.12g}" for x in (*q, *tau)])
            for s, q, tau in zip(ns, sim.q[keep], sim.tau[keep])]
    (tmp_path / "js.csv").write_text("\n".join([",".join(header), *rows]) + "\n")
    p = run("init", str(URDF), str(tmp_path / "js.csv"), "--out", str(tmp_path / "ros.toml"))
    assert p.returncode == 0, p.stderr
    text = (tmp_path / "ros.toml").read_text()
    assert _identification(text)["time"] == {"column": "header.stamp.sec", "nanoseconds": "header.stamp.nanosec"}
    p = run("identify", str(tmp_path / "ros.toml"), "--out", str(tmp_path / "id"), "--no-figures", "-q")
    assert p.returncode == 0, p.stderr
    results = json.loads((tmp_path / "id" / "results.json").read_text())
    fit = results["identification"]["metrics"][results["main_estimate"]]["global_relative_error"]
    assert fit < 1.0, fit  # the whole seconds alone: 4.2 %
    # the whole seconds alone (what init wrote before), on the same log: the dropped messages put samples at wrong times
    (tmp_path / "sec.toml").write_text(text.replace(', nanoseconds = "header.stamp.nanosec"', ""))
    p = run("identify", str(tmp_path / "sec.toml"), "--out", str(tmp_path / "sec"), "--no-figures", "-q")
    if p.returncode == 0:
        seconds = json.loads((tmp_path / "sec" / "results.json").read_text())
        assert seconds["identification"]["metrics"][seconds["main_estimate"]]["global_relative_error"] > 2 * fit


def test_ros_style_indexed_headers_name_their_signal():
    """``/joint_states/position/0`` and ``position.0`` were refused ("found 0 positions columns")."""
    from dynid.io.logs.columns import _kind

    assert [_kind(h) for h in ("/joint_states/position/0", "position.0", "/joint_states/effort/5", "velocity.2",
                               "header.stamp.sec")] == ["positions", "positions", "torques", "velocities", "time"]


def test_init_opens_a_bag_and_writes_bag_for_a_validation_bag(tmp_path):
    """``dynid init URDF BAG OTHER_BAG`` wrote ``file =`` for the validation bag (which identify refused) and never
    opened the bags; it now reads them as identify does (joint names, rate, length, effort range), writes ``bag =``,
    and identify runs on the config as written. A bag without one of the robot's joints is refused in one line."""
    from tests.io.test_bags import _write_bag

    sim = dynid.simulated_log(dynid.load_robot(URDF), seconds=12, rng=8)
    names = [j.name for j in dynid.load_robot(URDF).joints]
    half = sim.t.size // 2
    dq = np.gradient(sim.q, sim.t, axis=0)  # the simulated log has none: the bag's velocity field
    for bag, part in (("ident", slice(0, half)), ("other", slice(half, None))):
        _write_bag(tmp_path / bag, sim.t[part], names, sim.q[part], dq[part], sim.tau[part])
    p = run("init", str(URDF), str(tmp_path / "ident"), str(tmp_path / "other"), "--out", str(tmp_path / "arm.toml"))
    assert p.returncode == 0, p.stderr
    text = (tmp_path / "arm.toml").read_text()
    assert 'bag = "other"' in text and 'file = "other"' not in text
    assert f"# ident: read as identify reads it: {half} samples over" in text
    p = run("identify", str(tmp_path / "arm.toml"), "--out", str(tmp_path / "id"), "--no-figures", "-q")
    assert p.returncode == 0, p.stderr
    _write_bag(tmp_path / "short", sim.t[:50], names[:5], sim.q[:50, :5], dq[:50, :5], sim.tau[:50, :5])
    p = run("init", str(URDF), str(tmp_path / "short"), "--out", str(tmp_path / "short.toml"))
    assert p.returncode == 1 and "lacks joint(s) wrist_3_joint" in p.stderr and "Traceback" not in p.stderr
    assert not (tmp_path / "short.toml").exists()


@pytest.mark.parametrize("style", ["plain", "ros"])
def test_init_never_takes_a_commanded_column_for_a_measured_signal(tmp_path, style):
    """A log holding commanded positions beside the measured ones (before them): init took the commanded column,
    and the fit missed by 1.4-1.7 % instead of 0.14 %, dynid suggesting a torque delay. It takes the measured one,
    and says which it left."""
    sim = dynid.simulated_log(dynid.load_robot(URDF), seconds=12, rng=9)
    names = [j.name for j in dynid.load_robot(URDF).joints]
    lagged = np.roll(sim.q, 5, axis=0)  # a set-point runs ahead of the measured position
    if style == "plain":
        cmd, measured, effort = ([f"{k}{j}" for j in range(1, 7)] for k in ("desired.q", "actual.q", "actual.tau"))
    else:
        cmd = [f"/arm_controller/state/desired/{n}/position" for n in names]
        measured = [f"/joint_states/{n}/position" for n in names]
        effort = [f"/joint_states/{n}/effort" for n in names]
    np.savetxt(tmp_path / "log.csv", np.column_stack([sim.t, lagged, sim.q, sim.tau]), delimiter=",", comments="",
               header=",".join(["t", *cmd, *measured, *effort]))
    p = run("init", str(URDF), str(tmp_path / "log.csv"), "--out", str(tmp_path / "arm.toml"))
    assert p.returncode == 0, p.stderr
    text = (tmp_path / "arm.toml").read_text()
    assert _identification(text)["positions"]["columns"] == measured
    assert f"# commanded, never taken for a measured signal: {cmd[0]}" in text


def test_init_asks_which_side_of_the_gear_measured_the_torques(tmp_path):
    """issue "Never worse than the description", item 3: a log cannot say whether its torques hold the rotor inertia;
    the config init writes asks, beside the torques, with the setting that says it (read by identify)."""
    import tomllib

    from dynid.io.logs.columns import SENSOR_HINT

    log = _log(tmp_path, header=True)
    p = run("init", str(URDF), str(log), "--out", str(tmp_path / "arm.toml"))
    assert p.returncode == 0, p.stderr
    text = (tmp_path / "arm.toml").read_text()
    assert SENSOR_HINT in text and text.index(SENSOR_HINT) > text.index("torques = {")
    joint = text.replace("]}\n" + SENSOR_HINT, '], sensor = "joint"}\n' + SENSOR_HINT)
    assert tomllib.loads(joint)["identification"]["torques"]["sensor"] == "joint"


def test_init_infers_joint_torque_sensors_from_an_arm_that_has_them(tmp_path):
    """issue "Never worse than the description", item 3: a URDF naming an arm with joint torque sensors on the link
    side (a KUKA LBR Med here, by its robot name) gets sensor = "joint" in the torques table, said with how to undo it,
    and identify reads it (no rotor inertia); another arm's URDF only gets the question."""
    import tomllib

    from dynid.io.config.identification_config import load_identification_config
    from dynid.io.logs.columns import SENSOR_HINT

    log = _log(tmp_path, header=True)
    med = tmp_path / "arm.urdf"
    med.write_text(URDF.read_text().replace('<robot name="', '<robot name="lbr_med7_', 1))
    assert '<robot name="lbr_med7_' in med.read_text()
    p = run("init", str(med), str(log), "--out", str(tmp_path / "med.toml"))
    assert p.returncode == 0, p.stderr
    text = (tmp_path / "med.toml").read_text()
    assert tomllib.loads(text)["identification"]["torques"]["sensor"] == "joint" and SENSOR_HINT not in text
    assert 'sensor = "joint" inferred from the name "lbr_med7_' in text and 'write sensor = "drive" if' in text
    assert "Ia" not in load_identification_config(tmp_path / "med.toml").robot.drive_terms
    p = run("init", str(URDF), str(log), "--out", str(tmp_path / "other.toml"))
    other = (tmp_path / "other.toml").read_text()
    assert SENSOR_HINT in other and "sensor" not in tomllib.loads(other)["identification"]["torques"]


def test_init_takes_the_rate_of_a_log_without_time_stamps(tmp_path):
    """A log with a header and no time column (the LBR Med7's lbr-stack recordings): init refuses it naming --rate,
    and with --rate writes rate = ..., which identify reads as one sample every 1/rate s (the log's own times)."""
    from dynid.io.config.identification_config import load_identification_config
    from dynid.io.logs.datasets import load_recording

    log = _log(tmp_path, header=True)
    rows = np.loadtxt(log, delimiter=",", skiprows=1)
    rate = 1.0 / float(np.median(np.diff(rows[:, 0])))
    header = log.read_text().splitlines()[0].split(",")[1:]
    np.savetxt(log, rows[:, 1:], delimiter=",", comments="", header=",".join(header))
    p = run("init", str(URDF), str(log), "--out", str(tmp_path / "arm.toml"))
    assert p.returncode == 1 and "no time column" in p.stderr and "--rate HZ" in p.stderr
    for bad in ("nan", "inf"):  # "nan" wrote rate = nan (a negative or zero rate is the option's usage error)
        p = run("init", str(URDF), str(log), "--out", str(tmp_path / "arm.toml"), "--rate", bad)
        assert p.returncode == 1 and "--rate: expected the logs' sample rate, a positive number of Hz" in p.stderr
        assert "Traceback" not in p.stderr and not (tmp_path / "arm.toml").exists()
    p = run("init", str(URDF), str(log), "--out", str(tmp_path / "arm.toml"), "--rate", f"{rate!r}")
    assert p.returncode == 0, p.stderr
    assert f"rate = {rate!r}" in (tmp_path / "arm.toml").read_text()
    config = load_identification_config(tmp_path / "arm.toml")
    robot = config.robot
    recording = load_recording(config.identification, robot)
    np.testing.assert_allclose(recording.t - recording.t[0], rows[:, 0] - rows[0, 0], atol=1e-9)
    np.testing.assert_allclose(recording.q, rows[:, 1:7], rtol=1e-12)


def test_only_arms_with_joint_torque_sensors_are_inferred_so():
    """The names init takes as joint torque sensors: the LBRs, Franka's arms and Kinova's Gen3, not its Gen3 lite or
    its other arms (whose logs are motor currents)."""
    from dynid.io.logs.columns import JOINT_SENSED

    sensed = ["lbr_iiwa_14_r820", "med7dock", "panda", "fr3", "kinova_gen3", "GEN3_7dof"]
    other = ["ur10e", "kinova", "j2s6s200", "gen3_lite", "gen3-lite", "xarm7", "staubli_tx40"]
    assert [n for n in sensed if not JOINT_SENSED.search(n)] == []
    assert [n for n in other if JOINT_SENSED.search(n)] == []


def test_init_writes_any_path_as_a_toml_string_and_identify_reads_it(tmp_path):
    """A log's folder and name holding a quote and a backslash: init wrote them unescaped (invalid TOML that identify
    refused); tomlkit now writes every string escaped, so the config reads back the paths as they are."""
    log = _log(tmp_path, header=True)
    odd = tmp_path / 'we"ird\\logs'
    odd.mkdir()
    moved = log.rename(odd / 'run "1"\\a.csv')
    other = odd / "other.csv"
    other.write_bytes(moved.read_bytes())
    p = run("init", str(URDF), str(moved), str(other), "--out", str(tmp_path / "arm.toml"))
    assert p.returncode == 0, p.stderr
    doc = tomllib.loads((tmp_path / "arm.toml").read_text())
    assert doc["data_root"] == 'we"ird\\logs' and doc["identification"]["file"] == 'run "1"\\a.csv'
    assert doc["validation"] == [{"name": "other", "file": "other.csv"}]
    p = run("identify", str(tmp_path / "arm.toml"), "--out", str(tmp_path / "id"), "--no-figures", "-q")
    assert p.returncode == 0, p.stderr
    rec = dynid.load_recording(moved, dynid.load_robot(URDF))  # a log's path alone: its columns found as init finds them
    assert np.asarray(rec.q).shape[1] == 6


def test_init_lists_the_sdp_also_where_the_descriptions_values_are_not_consistent(tmp_path):
    """A URDF whose nominal inertia breaks the triangle inequality: the SDP is listed (it was left out, so no
    consistent estimate was tried: issue "The better model wins", item 2), init says its prior and the nominal
    candidate are the nearest consistent ones, and identify names the link and runs both; with consistent values both
    are listed, without that note."""
    import json
    import re

    log = _log(tmp_path, header=True)
    bad = tmp_path / "bad.urdf"
    bad.write_text(re.sub(r'<inertia ixx="[^"]*" ixy="[^"]*" ixz="[^"]*" iyy="[^"]*" iyz="[^"]*" izz="[^"]*"',
                          '<inertia ixx="1.0" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"', URDF.read_text(), count=2))
    p = run("init", str(bad), str(log), "--out", str(tmp_path / "bad.toml"))
    assert p.returncode == 0, p.stderr
    said = " ".join(p.stdout.split())
    assert "not physically consistent: the SDP's prior and the nominal candidate are the nearest consistent ones" in said
    assert tomllib.loads((tmp_path / "bad.toml").read_text())["estimation"]["estimators"] == ["wls", "sdp"]
    p = run("identify", str(tmp_path / "bad.toml"), "--out", str(tmp_path / "id"), "--no-figures")
    assert p.returncode == 0, p.stderr
    results = json.loads((tmp_path / "id" / "results.json").read_text())
    assert "dynid SDP" in results["estimates"]
    assert "nominal candidate take the nearest consistent link" in " ".join(p.stderr.split() + p.stdout.split())
    p = run("init", str(URDF), str(log), "--out", str(tmp_path / "good.toml"))
    assert tomllib.loads((tmp_path / "good.toml").read_text())["estimation"]["estimators"] == ["wls", "sdp"]
    assert "not physically consistent" not in " ".join(p.stdout.split())


def test_without_validation_logs_the_sdp_stays_main_where_held_out_blocks_score_it_as_well(tmp_path, monkeypatch):
    """The example's log identified without validation logs: least squares predicts the held-out blocks better than
    the SDP by 3.5e-5 of their RMS. The main estimate was least squares while the first line and export named the
    SDP; held-out figures within 2 % are now the same figure, as the validation logs' are."""
    import json

    monkeypatch.chdir(tmp_path)
    assert run("example", "ur10e", "try", "-q").returncode == 0
    monkeypatch.chdir(tmp_path / "try")
    assert run("init", "ur10e.urdf", "identification.csv", "--out", "solo.toml", "-q").returncode == 0
    p = run("identify", "solo.toml", "--out", "id", "--no-figures")
    assert p.returncode == 0, p.stderr
    results = json.loads((tmp_path / "try" / "id" / "results.json").read_text())
    held = results["diagnostics"]["held_out_rms_error"]
    assert held["dynid WLS"] < held["dynid SDP"] <= 1.02 * held["dynid WLS"]  # the tie this test is about
    assert results["main_estimate"] == "dynid SDP"
    said = " ".join(p.stdout.split())
    assert said.startswith("model ready to check: dynid SDP") and "main estimate: dynid SDP, physically consistent" in said
    assert "dynid SDP predicted them as well as any, to 2 %" in said


def test_init_says_a_log_of_motor_currents_needs_drive_gains_the_urdf_cannot_state(tmp_path):
    """A UR10e's RTDE log (motor currents) with its URDF: init wrote the config without a word on the drive gains, and
    identify then read each ampere as 1 N·m. Init said so and named the built-in robot of the URDF's name that has
    them; it now writes that robot's gains in [[robot.joints]] (the real UR10e log read at 1 N·m/A predicted its
    validation log 8.86 %, with them 2.22 %). Another arm's URDF gets the note alone; a log of torques nothing."""
    from dynid.io.config.identification_config import load_identification_config
    from dynid.io.config.starter import starter_config

    builtin = dynid.load_robot("ur10e").drive_gains
    log = dynid.simulated_log(dynid.load_robot("ur10e"), seconds=5, rng=1)
    rows = np.column_stack([log.t, log.q, np.zeros_like(log.q), log.tau / builtin, np.zeros((log.t.size, 12))])
    np.savetxt(tmp_path / "rtde.csv", rows, delimiter=",")  # 31 columns: Universal Robots' RTDE layout
    robot = dynid.load_robot(URDF)
    text, notes = starter_config(URDF, tmp_path / "rtde.csv", 6, tmp_path / "a.toml", robot=robot)
    (gains,) = [n for n in notes if n.startswith("motor currents")]
    assert "ur10e.urdf states no drive gains" in gains and 'the built-in robot "ur10e"\'s are written' in gains
    (tmp_path / "a.toml").write_text(text)
    read = load_identification_config(tmp_path / "a.toml").robot
    np.testing.assert_array_equal(read.drive_gains, builtin)
    np.testing.assert_array_equal(read.inertial, robot.inertial)  # the user's URDF, the built-in's gains
    other = tmp_path / "arm.urdf"
    other.write_text(URDF.read_text().replace('<robot name="ur10e"', '<robot name="my_arm"', 1))
    text, notes = starter_config(other, tmp_path / "rtde.csv", 6, tmp_path / "b.toml", robot=dynid.load_robot(other))
    (gains,) = [n for n in notes if n.startswith("motor currents")]
    assert "built-in" not in gains and "drive_gain" not in tomllib.loads(text).get("robot", {}).__repr__()
    _, notes = starter_config(URDF, _log(tmp_path, header=True), 6, tmp_path / "c.toml", robot=robot)
    assert not [n for n in notes if n.startswith("motor currents")]  # torques: no gains needed


def test_init_writes_the_torques_sign_the_logs_own_check_finds_flipped(tmp_path):
    """dynid init identifies the log as the config it writes would have it (least squares alone) and, where every joint
    the description's nominal model judges runs against the measured torques, writes ``sign = -1`` with why beside it:
    the first dynid identify then reads the log right. A log with the torques' sign right gets none."""
    log = _log(tmp_path, header=True)
    data = np.loadtxt(log, delimiter=",", skiprows=1)
    flipped = tmp_path / "logs" / "flipped.csv"
    data[:, 7:] *= -1.0
    np.savetxt(flipped, data, delimiter=",", comments="", header=log.read_text().splitlines()[0])
    for name, logged, expected in (("right.toml", log, None), ("flipped.toml", flipped, -1)):
        p = run("init", str(URDF), str(logged), "--out", str(tmp_path / name))
        assert p.returncode == 0, p.stderr
        text = (tmp_path / name).read_text()
        assert _identification(text)["torques"].get("sign") == expected, text
        said = " ".join((p.stdout + p.stderr).split())
        assert ("torques: sign = -1 written" in said) is (expected == -1)
        assert "(dynid init's check): remove it if the log's sign is right" in text if expected else "sign" not in text
        p = run("identify", str(tmp_path / name), "--out", str(tmp_path / f"id_{name}"), "--no-figures", "-q")
        assert p.returncode == 0, p.stderr
        results = json.loads((tmp_path / f"id_{name}" / "results.json").read_text())
        assert [f for f in results["findings"] if f["kind"] == "sign"] == []


def test_init_writes_the_lbr_med7s_torque_sign_and_identify_reaches_the_expert_figure(tmp_path):
    """The real LBR Med7 (joint torque sensors; its log's torques run against its URDF on every joint the URDF's
    model judges): the config dynid init wrote read them as logged, the first dynid identify scored 20.0 % with the
    sign its finding suggested per joint, and a second step was needed. init now writes sign = -1, and the first
    identify predicts the validation log as the expert config does (configs/kuka_med7.toml: 8.84 % on the yardstick)."""
    from ..conftest import shared_data

    root = shared_data("kuka_med7_lbrstack")
    out = tmp_path / "med7.toml"
    p = run("init", str(root / "urdf" / "med7dock.urdf"), str(root / "measurements_with_ext_tau_1_dgr.csv"),
            str(root / "measurements.csv"), "--rate", "100", "--out", str(out))
    assert p.returncode == 0, p.stderr
    assert _identification(out.read_text())["torques"]["sign"] == -1
    p = run("identify", str(out), "--out", str(tmp_path / "id"), "--no-figures", "-q")
    assert p.returncode == 0, p.stderr
    results = json.loads((tmp_path / "id" / "results.json").read_text())
    assert [f for f in results["findings"] if f["kind"] == "sign"] == []
    mean = results["diagnostics"]["yardstick"]["mean_global_relative_error"]
    assert mean[results["main_estimate"]] < 0.5 * mean["description (nominal)"], mean


def test_init_reads_the_units_a_logs_column_names_carry(tmp_path):
    """Columns named with their unit (``t_s``, ``q1_deg``, ``tau1_Nm``): refused ("no time column"); the unit words are
    now read beside the signal and the joint, the positions' degrees written as ``unit = "deg"``, and dynid identify
    reads the log right (no finding on the angles or the torques' size). The name helper is checked on each form."""
    from dynid.io.logs.columns import _kind_and_unit

    assert _kind_and_unit("time [s]") == ("time", "s") and _kind_and_unit("q_deg1") == ("positions", "deg")
    assert _kind_and_unit("pos3 [rad]") == ("positions", "rad") and _kind_and_unit("i2_mA") == ("currents", "mA")
    assert _kind_and_unit("dq1_degps") == ("velocities", "deg/s") and _kind_and_unit("tau1") == ("torques", None)
    log = dynid.simulated_log(dynid.load_robot(URDF), seconds=20, rng=4)
    names = ["t_s"] + [f"q{j}_deg" for j in range(1, 7)] + [f"tau{j}_Nm" for j in range(1, 7)]
    (tmp_path / "run.csv").write_text(",".join(names) + "\n" + "\n".join(
        ",".join(f"{v:.10g}" for v in row) for row in np.column_stack([log.t, np.degrees(log.q), log.tau])) + "\n")
    p = run("init", str(URDF), str(tmp_path / "run.csv"), "--out", str(tmp_path / "arm.toml"))
    assert p.returncode == 0, p.stderr
    ident = _identification((tmp_path / "arm.toml").read_text())
    assert ident["time"] == {"column": "t_s"} and ident["positions"]["unit"] == "deg" and "unit" not in ident["torques"]
    p = run("identify", str(tmp_path / "arm.toml"), "--out", str(tmp_path / "id"), "--no-figures", "-q")
    assert p.returncode == 0, p.stderr
    findings = json.loads((tmp_path / "id" / "results.json").read_text())["findings"]
    assert not [f for f in findings if f["kind"] in ("angles", "scale", "sign", "rate")], findings


def test_init_writes_a_ceiling_mounts_gravity_and_then_judges_the_sign(tmp_path):
    """A UR10e hanging from a ceiling (gravity along +z of its base; the URDF says -z): dynid init's check finds the
    mounting, writes gravity = [0, 0, 9.81] in [robot], and judges the torques' sign again with it: against the
    upright model J3-J5 ran against the torques, which are not flipped. The first dynid identify then reads the log
    right: no gravity, angles or sign finding."""
    from dataclasses import replace

    p = _simulated_init(tmp_path, replace(dynid.load_robot(URDF), gravity=np.array([0.0, 0.0, 9.81])))
    config = tomllib.loads((tmp_path / "arm.toml").read_text())
    assert config["robot"]["gravity"] == [0.0, 0.0, 9.81] and "sign" not in config["identification"]["torques"]
    from dynid.io.config.identification_config import load_identification_config

    written = load_identification_config(tmp_path / "arm.toml").robot
    assert written.drive_terms == dynid.load_robot(URDF).drive_terms  # the [robot] table keeps the file's drive terms
    assert "robot: gravity = [0.0, 0.0, 9.81] written" in " ".join((p.stdout + p.stderr).split())
    _identify_reads_it_right(tmp_path)


def _simulated_init(tmp_path, robot, logged=lambda q: q):
    """``dynid init`` on two logs simulated from ``robot`` (30 s to identify, 20 s to validate), their angles as
    ``logged`` writes them, with the URDF: its run, checked."""
    names = ["time"] + [f"q{j}" for j in range(1, 7)] + [f"tau{j}" for j in range(1, 7)]
    for name, seed, seconds in (("run.csv", 4, 30), ("val.csv", 5, 20)):
        log = dynid.simulated_log(robot, seconds=seconds, rng=seed)
        np.savetxt(tmp_path / name, np.column_stack([log.t, logged(log.q), log.tau]), delimiter=",", comments="",
                   header=",".join(names))
    p = run("init", str(URDF), str(tmp_path / "run.csv"), str(tmp_path / "val.csv"), "--out", str(tmp_path / "arm.toml"))
    assert p.returncode == 0, p.stderr
    return p


def _identify_reads_it_right(tmp_path):
    """``dynid identify`` on the config init wrote: no gravity, angles or sign finding."""
    p = run("identify", str(tmp_path / "arm.toml"), "--out", str(tmp_path / "id"), "--no-figures", "-q")
    assert p.returncode == 0, p.stderr
    findings = json.loads((tmp_path / "id" / "results.json").read_text())["findings"]
    assert not [f for f in findings if f["kind"] in ("gravity", "angles", "sign")], findings


def test_init_writes_a_joints_zero_a_quarter_turn_off_and_identify_reads_the_log_right(tmp_path):
    """A UR10e log whose J2 encoder counts from a zero a quarter turn from the URDF's (logged angle = the URDF's − π/2):
    dynid init's check finds it, writes position_offset = "pi/2" in J2's [[robot.joints]] table (one table per joint,
    the others empty, the file's drive terms kept), and the first dynid identify has no angles finding."""
    from dynid.io.config.identification_config import load_identification_config

    p = _simulated_init(tmp_path, dynid.load_robot(URDF), lambda q: q - np.array([0.0, np.pi / 2, 0, 0, 0, 0]))
    joints = tomllib.loads((tmp_path / "arm.toml").read_text())["robot"]["joints"]
    assert joints == [{}, {"position_offset": "pi/2"}, {}, {}, {}, {}]
    robot = load_identification_config(tmp_path / "arm.toml").robot
    assert np.allclose(robot.transmission.position_offset, [0, np.pi / 2, 0, 0, 0, 0])
    assert robot.drive_terms == dynid.load_robot(URDF).drive_terms
    assert 'robot: J2 position_offset = "pi/2" written' in " ".join((p.stdout + p.stderr).split())
    _identify_reads_it_right(tmp_path)


def test_init_reads_the_kr300s_qualified_headers_as_its_expert_config_does(tmp_path):
    """The KUKA KR 300's log (Weigand et al.) names two encoders (q_se_deg1… on the link side, J4-J6 all zero;
    q_mot_deg1…, the motor encoders divided by the gear ratios), two motor-side torques (tau_mot_abs_Nm1…,
    tau_mot_rel_Nm1…) and commanded signals (q_ref…, tau_ff_mot…). dynid init passes over the encoder group with dead
    channels, reads the torques through the gear ratios (side = "motor"), never takes a feed-forward column, and
    writes the columns the hand-written config (configs/kuka_kr300.toml, from the data's SOURCE.md) reads."""
    from dynid.io.config.identification_config import load_identification_config

    from ..conftest import shared_data

    root = Path(__file__).resolve().parents[2]
    data = shared_data("kuka_kr300_weigand2021") / "recorded"
    expert = load_identification_config(root / "configs" / "kuka_kr300.toml", data_root=data.parent)
    p = run("init", str(root / "configs" / "robots" / "kuka_kr300.toml"), str(data / "traj_A.csv"),
            str(data / "traj_B.csv"), "--out", str(tmp_path / "kr.toml"))
    assert p.returncode == 0, p.stderr
    written = load_identification_config(tmp_path / "kr.toml")
    for signal in ("positions", "torques"):
        mine, theirs = (c.identification.signals[signal] for c in (written, expert))
        assert (mine.columns, mine.scale, mine.side) == (theirs.columns, theirs.scale, theirs.side)  # scale: the unit's
    said = " ".join((p.stdout + p.stderr).split())
    assert "q_se_deg4, q_se_deg5, q_se_deg6 read one value throughout" in said
    assert not {"tau_ff_mot_Nm1", "q_ref_deg1"} & {c for s in written.identification.signals.values() for c in s.columns}
    assert "the log has more joint columns" not in said  # the groups left are said as such, not as extra joints
    assert "units assumed" not in said  # every signal's columns name their unit (deg, Nm)


def test_init_takes_the_link_side_where_a_log_names_both_sides_of_the_gear(tmp_path):
    """A log with each joint's angle and torque named for both sides of its gear (``q_mot_1…`` beside ``q_link_1…``,
    ``tau_mot_1…`` beside ``tau_link_1…``), every channel alive: the link side is taken, the motor side's columns
    are said as left, and the torques get no side = "motor"."""
    log = dynid.simulated_log(dynid.load_robot(URDF), seconds=10, rng=3)
    names = (["t"] + [f"q_mot_{j}" for j in range(1, 7)] + [f"q_link_{j}" for j in range(1, 7)]
             + [f"tau_mot_{j}" for j in range(1, 7)] + [f"tau_link_{j}" for j in range(1, 7)])
    np.savetxt(tmp_path / "run.csv", np.column_stack([log.t, log.q, log.q, log.tau / 100, log.tau]), delimiter=",",
               comments="", header=",".join(names))
    p = run("init", str(URDF), str(tmp_path / "run.csv"), "--out", str(tmp_path / "arm.toml"))
    assert p.returncode == 0, p.stderr
    table = _identification((tmp_path / "arm.toml").read_text())
    assert table["positions"] == {"columns": [f"q_link_{j}" for j in range(1, 7)]}
    assert table["torques"]["columns"] == [f"tau_link_{j}" for j in range(1, 7)] and "side" not in table["torques"]
    said = " ".join((p.stdout + p.stderr).split())
    assert "positions also in the log, not read: q_mot_1…q_mot_6" in said and "tau_mot_1…tau_mot_6" in said
    assert "units assumed: positions in rad, torques in N·m" in said  # no unit in the names


def test_init_reads_a_headerless_19_column_log_of_a_ur_arm_as_rtde_currents(tmp_path):
    """A UR arm's RTDE log of 19 columns without a header (time, q, qd, motor currents: the UR10e's 2019 logs of
    Mamedov & Mikhel) was taken as time, positions, velocities and torques in N·m: each ampere read as 1 N·m, and the
    first identify found the torques a tenth of the model's. init now reads it by the 19-column RTDE preset and writes
    the built-in UR10e's drive gains, a 31-column validation log gets its own reader (it took the identification's),
    and identify finds no scale; another 6-joint arm's 19 columns stay blocks."""
    ur = dynid.load_robot(URDF)
    gains = dynid.load_robot("ur10e").drive_gains
    log = dynid.simulated_log(ur, seconds=30, rng=4)
    rtde = np.column_stack([log.t, log.q, np.gradient(log.q, log.t, axis=0), log.tau / gains])
    np.savetxt(tmp_path / "run.csv", rtde, delimiter=",")
    np.savetxt(tmp_path / "val.csv", np.column_stack([rtde, np.zeros((log.t.size, 12))]), delimiter=",")  # + targets
    p = run("init", str(URDF), str(tmp_path / "run.csv"), str(tmp_path / "val.csv"), "--out", str(tmp_path / "arm.toml"))
    assert p.returncode == 0, p.stderr
    steps = [line for line in (p.stdout + p.stderr).splitlines() if line.startswith("dynid init: ")]  # in a pipe: a line
    assert steps[0].startswith("dynid init: reading the log's columns (at ")  # each, the check's identification's too
    assert any(s.startswith("dynid init: checking the log against the robot file: regressor, ") for s in steps), steps
    config = tomllib.loads((tmp_path / "arm.toml").read_text())
    assert config["identification"]["preset"] == "ur-rtde-19"
    assert config["validation"][0]["preset"] == "ur-rtde"  # 31 columns: its own reader, not the 19 columns'
    assert np.allclose([j["drive_gain"] for j in config["robot"]["joints"]], gains)
    p = run("identify", str(tmp_path / "arm.toml"), "--out", str(tmp_path / "id"), "--no-figures", "-q")
    assert p.returncode == 0, p.stderr
    findings = json.loads((tmp_path / "id" / "results.json").read_text())["findings"]
    assert not [f for f in findings if f["kind"] in ("scale", "sign", "angles", "gravity")], findings
    other = Path(__file__).resolve().parents[2] / "configs" / "robots" / "tx40_simulation.toml"
    p = run("init", str(other), str(tmp_path / "run.csv"), "--out", str(tmp_path / "other.toml"))
    assert p.returncode == 0, p.stderr
    assert _identification((tmp_path / "other.toml").read_text())["torques"] == {"columns": list(range(14, 20))}


def test_the_torque_sign_init_writes_reaches_a_validation_log_read_by_its_own_columns():
    """A validation log of another layout has a torques table of its own (init writes it): the sign the
    identification log's check found is written there too; a validation log that takes the identification's reader
    gets none of its own."""
    from dynid.io.config.starter import with_torque_setting

    text = ('[identification]\nfile = "a.csv"\ntorques = {columns = [1, 2]}\n\n[[validation]]\nname = "b"\nfile = '
            '"b.csv"\n\n[[validation]]\nname = "c"\nfile = "c.csv"\ntorques = {columns = ["x", "y"]}\n')
    config = tomllib.loads(with_torque_setting(text, "sign", -1, "why"))
    assert config["identification"]["torques"]["sign"] == -1 and "torques" not in config["validation"][0]
    assert config["validation"][1]["torques"] == {"columns": ["x", "y"], "sign": -1}


def test_init_takes_figaroh_s_pair_of_one_signal_files_and_finds_the_motor_side(tmp_path):
    """FIGAROH's TX40 recording: positions and currents in two files headed Joint_1 … Joint_6, 5 kHz, no time column,
    the motors' angles (50.3 rad = 32 · π/2). Given both (``pos_read_data.csv curr_data.csv --rate 5000``), init
    writes each signal with its file and side = "motor" (the angles reach tens of times the joints' limits): the columns
    and side the hand-written config (configs/tx40.toml, its preset) reads."""
    from dynid.io.config.identification_config import load_identification_config

    from ..conftest import shared_data

    root = Path(__file__).resolve().parents[2]
    data = shared_data("staubli_tx40_figaroh")
    p = run("init", "tx40", str(data / "pos_read_data.csv"), str(data / "curr_data.csv"), "--rate", "5000",
            "--out", str(tmp_path / "tx.toml"))
    assert p.returncode == 0, p.stderr
    written = load_identification_config(tmp_path / "tx.toml").identification
    expert = load_identification_config(root / "configs" / "tx40.toml", data_root=data).identification
    effort = "currents" if "currents" in written.signals else "torques"
    assert written.side == expert.side == "motor" and written.rate == expert.rate == 5000.0
    for mine, theirs in ((written.signals["positions"], expert.signals["positions"]),
                         (written.signals[effort], expert.signals["torques"])):
        assert (mine.file.name, mine.columns) == (theirs.file.name, theirs.columns)
    assert "validation" not in tomllib.loads((tmp_path / "tx.toml").read_text())  # the second file is a signal


def test_init_says_a_pair_of_one_signal_files_of_different_lengths(tmp_path):
    """Two one-signal files (``pos_…``, ``curr_…``, headers Joint_1 … Joint_6) whose rows differ: a one-line error naming
    both files and both lengths (it said the second file was missing), and no config written."""
    header = ",".join(f"Joint_{j}" for j in range(1, 7))
    rng = np.random.default_rng(0)
    for name, rows in (("pos_run.csv", 120), ("curr_run.csv", 100)):
        np.savetxt(tmp_path / name, rng.normal(size=(rows, 6)), delimiter=",", header=header, comments="")
    p = run("init", "tx40", str(tmp_path / "pos_run.csv"), str(tmp_path / "curr_run.csv"), "--rate", "5000",
            "--out", str(tmp_path / "tx.toml"))
    assert p.returncode == 1 and "Traceback" not in p.stderr
    message = " ".join(p.stderr.split())
    assert "pos_run.csv" in message and "curr_run.csv" in message and "120 rows against 100" in message
    assert not (tmp_path / "tx.toml").exists()


def test_init_names_a_built_in_robot_as_given_and_leaves_its_mounting_to_a_description(tmp_path):
    """``dynid init ur10e LOG`` (a built-in robot by name) writes robot = "ur10e" wherever the config goes (it wrote a
    path relative to the working folder, which identify could not read), and a mounting the check finds otherwise is
    said, not written into a table that would take the name for a file."""
    from dataclasses import replace

    hanging = replace(dynid.load_robot("ur10e"), gravity=np.array([0.0, 0.0, 9.81]))
    names = ["time"] + [f"q{j}" for j in range(1, 7)] + [f"tau{j}" for j in range(1, 7)]
    log = dynid.simulated_log(hanging, seconds=30, rng=4)
    np.savetxt(tmp_path / "run.csv", np.column_stack([log.t, log.q, log.tau]), delimiter=",", comments="",
               header=",".join(names))
    (tmp_path / "cfg").mkdir()
    p = run("init", "ur10e", str(tmp_path / "run.csv"), "--out", str(tmp_path / "cfg" / "arm.toml"))
    assert p.returncode == 0, p.stderr
    assert tomllib.loads((tmp_path / "cfg" / "arm.toml").read_text())["robot"] == "ur10e"
    assert "(a built-in robot: give it in a description file)" in " ".join((p.stdout + p.stderr).split())


@pytest.mark.parametrize("header", [True, False])
def test_init_reads_a_european_spreadsheets_export_as_the_same_log(tmp_path, header):
    """A log saved by a spreadsheet in a European locale (semicolons between the fields, decimal commas): init took the
    commas for the delimiter (one field named 'time;joint_pos_1;…'); it now writes delimiter = ";" and decimal = ",",
    and the log reads as the same numbers as the one written with points and commas."""
    from dynid.io.config.identification_config import load_identification_config
    from dynid.io.logs.datasets import load_recording

    log = _log(tmp_path, header=header)
    european = tmp_path / "european.csv"
    european.write_text(log.read_text().replace(",", ";").replace(".", ","))
    p = run("init", str(URDF), str(european), "--out", str(tmp_path / "arm.toml"))
    assert p.returncode == 0, p.stderr
    ident = _identification((tmp_path / "arm.toml").read_text())
    assert ident["delimiter"] == ";" and ident["decimal"] == "," and "separated by semicolons" in p.stdout
    assert "decimal commas" in p.stdout
    p = run("init", str(URDF), str(log), "--out", str(tmp_path / "plain.toml"))
    assert p.returncode == 0, p.stderr
    config, plain = (load_identification_config(tmp_path / name) for name in ("arm.toml", "plain.toml"))
    ours, theirs = (load_recording(c.identification, c.robot) for c in (config, plain))
    for signal in ("t", "q", "tau"):
        np.testing.assert_array_equal(getattr(ours, signal), getattr(theirs, signal))


def test_a_decimal_separator_that_is_the_delimiter_is_refused(tmp_path):
    """``decimal = ","`` beside the default comma delimiter cannot be read: refused in one line naming the field."""
    from dynid.exceptions import ConfigError
    from dynid.io.config.identification_config import load_identification_config

    log = _log(tmp_path, header=True)
    p = run("init", str(URDF), str(log), "--out", str(tmp_path / "arm.toml"))
    assert p.returncode == 0, p.stderr
    text = (tmp_path / "arm.toml").read_text().replace("[identification]\n", '[identification]\ndecimal = ","\n', 1)
    (tmp_path / "arm.toml").write_text(text)
    with pytest.raises(ConfigError, match=r"arm.toml: identification.decimal: the numbers' decimal separator cannot be "
                                          r"the delimiter ','"):
        load_identification_config(tmp_path / "arm.toml")
    (tmp_path / "arm.toml").write_text(text.replace('decimal = ","', 'decimal = "x"'))
    with pytest.raises(ConfigError, match=r"decimal"):
        load_identification_config(tmp_path / "arm.toml")


def test_init_and_identify_read_a_log_and_a_config_that_start_with_a_byte_order_mark(tmp_path):
    """A spreadsheet's "CSV UTF-8" starts with a byte-order mark (and an editor may save a TOML so): init read the
    first column as '\\ufefftime' and found no time column; the log now reads as the same numbers, the config too."""
    from dynid.io.config.identification_config import load_identification_config
    from dynid.io.logs.datasets import load_recording

    log = _log(tmp_path, header=True)
    marked = tmp_path / "marked.csv"
    marked.write_bytes(b"\xef\xbb\xbf" + log.read_bytes())
    p = run("init", str(URDF), str(marked), "--out", str(tmp_path / "arm.toml"))
    assert p.returncode == 0, p.stderr
    assert _identification((tmp_path / "arm.toml").read_text())["time"] == {"column": "time"}
    (tmp_path / "plain.toml").write_text((tmp_path / "arm.toml").read_text().replace("marked.csv", "logs/run.csv"))
    (tmp_path / "bom.toml").write_bytes(b"\xef\xbb\xbf" + (tmp_path / "arm.toml").read_bytes())
    ours, marked_config, theirs = (load_identification_config(tmp_path / n) for n in ("arm.toml", "bom.toml", "plain.toml"))
    assert marked_config.identification == ours.identification
    p = run("migrate", str(tmp_path / "bom.toml"))  # migrate reads the config as identify does
    assert p.returncode == 0 and "nothing to rewrite" in p.stdout, p.stderr
    import tomlkit

    doc = tomlkit.parse((tmp_path / "arm.toml").read_text())  # the robot in a [robot] table: results name the config
    doc["robot"] = {"urdf": str(doc.pop("robot"))}
    (tmp_path / "table.toml").write_bytes(b"\xef\xbb\xbf" + tomlkit.dumps(doc).encode())
    p = run("identify", str(tmp_path / "table.toml"), "--out", str(tmp_path / "id"), "--no-figures", "-q")
    assert p.returncode == 0, p.stderr
    assert dynid.load_results(tmp_path / "id" / "results.json").robot.n_dof == 6  # its robot read from that config
    a, b = (load_recording(c.identification, c.robot) for c in (ours, theirs))
    for signal in ("t", "q", "tau"):
        np.testing.assert_array_equal(getattr(a, signal), getattr(b, signal))


def test_init_takes_a_header_whose_names_are_quoted(tmp_path):
    """A spreadsheet or pandas with quoting writes "time","joint_pos_1",…: init looked for '"time"' and found no time
    column, where the reader itself takes the names without their quotes."""
    log = _log(tmp_path, header=True)
    lines = log.read_text().splitlines(keepends=True)
    quoted = tmp_path / "quoted.csv"
    quoted.write_text(",".join(f'"{name}"' for name in lines[0].strip().split(",")) + "\n" + "".join(lines[1:]))
    p = run("init", str(URDF), str(quoted), "--out", str(tmp_path / "arm.toml"))
    assert p.returncode == 0, p.stderr
    ident = _identification((tmp_path / "arm.toml").read_text())
    assert ident["time"] == {"column": "time"} and ident["positions"]["columns"][0] == "joint_pos_1"
    p = run("identify", str(tmp_path / "arm.toml"), "--out", str(tmp_path / "id"), "--no-figures", "-q")
    assert p.returncode == 0, p.stderr


@pytest.mark.parametrize(("position", "torque"), [("A{}_pos", "A{}_tau"), ("axis{}_position", "axis{}_torque"),
                                                  ("JointPosition{}", "JointTorque{}"), ("J{} position", "J{} torque")])
def test_init_takes_columns_named_joint_first_or_in_camel_case(tmp_path, position, torque):
    """KUKA's axes (A1_pos … A6_tau), axis1_position, JointPosition1: the joint before the signal, or the words run
    together, were refused ("found 0 positions columns"); init now takes them, in the header's order."""
    log = dynid.simulated_log(dynid.load_robot(URDF), seconds=5, rng=4)
    names = ["time"] + [position.format(j) for j in range(1, 7)] + [torque.format(j) for j in range(1, 7)]
    path = tmp_path / "log.csv"
    np.savetxt(path, np.column_stack([log.t, log.q, log.tau]), delimiter=",", comments="", header=",".join(names))
    p = run("init", str(URDF), str(path), "--out", str(tmp_path / "arm.toml"))
    assert p.returncode == 0, p.stderr
    ident = _identification((tmp_path / "arm.toml").read_text())
    assert ident["positions"]["columns"] == names[1:7] and ident["torques"]["columns"] == names[7:]


def test_init_takes_a_headerless_log_without_time_stamps_at_its_rate_and_says_an_unused_rate(tmp_path):
    """A log of bare numbers, positions then torques, without time stamps (the Med7's recordings without their header
    line): refused even with --rate ("expected a time column"); it is now read at that rate, the arm's joint torque
    sensors inferred as for a log with a header. A --rate beside a time column was dropped without a word: said."""
    from dynid.io.config.identification_config import load_identification_config
    from dynid.io.logs.datasets import load_recording

    log = dynid.simulated_log(dynid.load_robot(URDF), seconds=5, rng=4)
    bare = tmp_path / "bare.csv"
    np.savetxt(bare, np.column_stack([log.q, log.tau]), delimiter=",")
    med = tmp_path / "arm.urdf"
    med.write_text(URDF.read_text().replace('<robot name="', '<robot name="lbr_med7_', 1))
    p = run("init", str(med), str(bare), "--out", str(tmp_path / "arm.toml"), "--rate", f"{log.rate!r}")
    assert p.returncode == 0, p.stderr
    assert "no header: positions, torques in blocks of 6" in p.stdout and 'sensor = "joint" inferred' in p.stdout
    ident = _identification((tmp_path / "arm.toml").read_text())
    assert ident["rate"] == log.rate and ident["torques"]["sensor"] == "joint"
    config = load_identification_config(tmp_path / "arm.toml")
    read = load_recording(config.identification, config.robot)
    np.testing.assert_allclose(read.q, log.q, rtol=1e-15)
    np.testing.assert_allclose(read.t - read.t[0], log.t - log.t[0], atol=1e-12)
    timed = _log(tmp_path, header=True)
    p = run("init", str(URDF), str(timed), "--out", str(tmp_path / "timed.toml"), "--rate", "500")
    assert p.returncode == 0 and "--rate 500 not used: the log's time column (time) gives its times" in p.stdout
    assert "rate" not in _identification((tmp_path / "timed.toml").read_text())


def test_inits_check_identifies_a_long_logs_first_minutes_and_a_chosen_stretch_as_chosen(tmp_path, monkeypatch):
    """init's check of the log against the description fitted the whole of an hour-long log (init took 48 s): it fits
    the first CHECKED_SECONDS of a log (here made 4 s of a 30 s log, whose torques run against the description), reading
    only the rows that hold them, finds the flipped sign there as on the whole log, and reads a stretch the config
    chose (rows) as chosen."""
    import dynid.identification.starter_check as check
    from dynid.io.logs import datasets

    log = _log(tmp_path, header=True)
    text = log.read_text().splitlines()
    flipped = tmp_path / "flipped.csv"
    flipped.write_text("\n".join([text[0]] + [",".join(f[:7] + [str(-float(x)) for x in f[7:]])
                                             for f in (line.split(",") for line in text[1:])]) + "\n")
    assert run("init", str(URDF), str(flipped), "--out", str(tmp_path / "whole.toml")).returncode == 0
    seen = []
    real = datasets.load_recording

    def spy(spec, robot, **kw):
        recording = real(spec, robot, **kw)
        seen.append((spec.time_range, spec.rows, recording.t[-1] - recording.t[0]))
        return recording

    monkeypatch.setattr(check, "load_recording", spy)
    monkeypatch.setattr(check, "CHECKED_SECONDS", 4.0)
    monkeypatch.setattr(check, "SEARCHED_SECONDS", 8.0)
    config_text = (tmp_path / "whole.toml").read_text().replace(", sign = -1", "")
    checked, notes = check.checked_against_description(config_text, tmp_path / "whole.toml")
    stretch = next(s for s in seen if s[0] is not None)  # after the first rows, which tell the sample step
    assert stretch[0] == (0.0, 8.0) and stretch[2] <= 8.0
    assert stretch[1] is not None and stretch[1][1] < len(text) / 2  # its rows alone are read, not the rest of the log
    assert "sign = -1" in checked and "sign = -1" in (tmp_path / "whole.toml").read_text()
    seen.clear()
    chosen = config_text.replace("[identification]\n", "[identification]\nrows = [1, 2000]\n", 1)
    check.checked_against_description(chosen, tmp_path / "whole.toml")
    assert seen[0][:2] == (None, (1, 2000))
    # a log that starts at rest for longer than the stretch: the stretch starts where it moves, and finds the sign
    resting = tmp_path / "resting.csv"
    rows = text[1:]
    first = rows[0].split(",")
    still = [",".join([f"{0.004 * k:.6g}"] + first[1:7] + [str(-float(x)) for x in first[7:]]) for k in range(2500)]
    moving = [",".join([f"{10.0 + float(f[0]):.6g}"] + f[1:7] + [str(-float(x)) for x in f[7:]])
              for f in (line.split(",") for line in rows)]
    resting.write_text("\n".join([text[0]] + still + moving) + "\n")
    monkeypatch.setattr(check, "SEARCHED_SECONDS", 20.0)  # 10 s at rest, then the motion
    checked, _ = check.checked_against_description(config_text.replace("flipped.csv", "resting.csv"), tmp_path / "whole.toml")
    assert "sign = -1" in checked
    tiny = tmp_path / "tiny.csv"  # too short for a stretch of it: read whole, not refused for a time_range never given
    tiny.write_text("\n".join(text[:31]) + "\n")
    _, notes = check.checked_against_description(config_text.replace("flipped.csv", "tiny.csv"), tmp_path / "whole.toml")
    assert not any("time_range" in n for n in notes), notes


def test_init_tells_the_velocities_from_the_torques_in_a_headerless_log(tmp_path, monkeypatch):
    """A headerless log written t, q, τ, q̇ (issue "Every assurance checked on what the user meets", item 2): init took
    its blocks by place (t, q, q̇, τ, or a UR's RTDE preset), and identify fitted the velocities as torques. The block
    that follows the positions' derivative is the velocities: init says so with the correlation, and the config
    reads the torques from the right columns (checked against the log the example wrote); a log written t, q, q̇, τ
    keeps its reading, its confidence said."""
    import numpy as np

    monkeypatch.chdir(tmp_path)
    assert run("example", "ur10e", "try", "-q").returncode == 0
    data = np.genfromtxt(tmp_path / "try" / "identification.csv", delimiter=",", names=True)
    t, q, tau = data["time"], np.column_stack([data[n] for n in data.dtype.names[1:7]]), \
        np.column_stack([data[n] for n in data.dtype.names[7:13]])
    dq = np.gradient(q, t, axis=0)
    np.savetxt(tmp_path / "try" / "swapped.csv", np.column_stack([t, q, tau, dq]), delimiter=",")
    np.savetxt(tmp_path / "try" / "placed.csv", np.column_stack([t, q, dq, tau]), delimiter=",")
    monkeypatch.chdir(tmp_path / "try")
    p = run("init", "ur10e.urdf", "swapped.csv", "--out", "swapped.toml")
    assert p.returncode == 0, p.stderr
    said = " ".join(p.stdout.split())
    assert "the third block follows the positions' derivative" in said and "the velocities are the third" in said
    ident = tomllib.loads((tmp_path / "try" / "swapped.toml").read_text())["identification"]
    assert ident["torques"]["columns"] == list(range(8, 14)) and ident["velocities"]["columns"] == list(range(14, 20))
    assert "preset" not in ident
    p = run("init", "ur10e.urdf", "placed.csv", "--out", "placed.toml")
    assert p.returncode == 0, p.stderr
    assert tomllib.loads((tmp_path / "try" / "placed.toml").read_text())["identification"].get("preset") == "ur-rtde-19"


def test_inits_check_starts_its_stretch_where_a_long_log_first_moves(monkeypatch):
    """A long log that starts at rest is checked on its motion: the stretch begins a second before a joint first moves
    (it began at the log's first sample, 120 s of rest checked nothing); a log no longer than the stretch is kept whole,
    and a stretch never runs past the log's end."""
    import dynid.identification.starter_check as check
    from dynid.io.logs.datasets import Recording

    monkeypatch.setattr(check, "CHECKED_SECONDS", 4.0)
    t = np.arange(0.0, 20.0, 0.01)
    q = np.zeros((t.size, 2))
    q[t >= 10.0, 1] = np.sin(t[t >= 10.0] - 10.0)  # at rest for 10 s, then joint 2 moves
    rec = Recording("log", t, q, None, np.ones((t.size, 2)), 100.0)
    cut = check._moving(rec)
    assert cut.t[0] == pytest.approx(10.01 - 1.0, abs=0.011) and cut.t[-1] - cut.t[0] == pytest.approx(4.0, abs=0.011)
    assert cut.q.shape == (cut.t.size, 2) and cut.tau.shape == (cut.t.size, 2)
    late = Recording("log", t, np.where(t[:, None] >= 18.0, 1.0, 0.0) * np.ones((1, 2)), None, np.ones((t.size, 2)), 100.0)
    assert check._moving(late).t[-1] == t[-1] and check._moving(late).t[0] == pytest.approx(16.0, abs=0.011)
    short = Recording("log", t[:300], q[:300], None, np.ones((300, 2)), 100.0)
    assert check._moving(short) is short

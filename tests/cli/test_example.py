"""`dynid example`: a folder to try dynid on, from which identify and export run as printed (issue "A user's first hour",
item 9)."""

import shlex

import numpy as np

from dynid.studies.example import example_files

from .refusals import assert_refused
from .refusals import dynid as run


def test_the_example_folder_runs_identify_and_export_as_printed(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    p = run("example", "ur10e", "try")
    assert p.returncode == 0, p.stderr
    said = " ".join(p.stdout.split())
    assert "cd try and run dynid identify ur10e.toml" in said
    assert sorted(f.name for f in (tmp_path / "try").iterdir() if not f.name.startswith(".")) == [
        "identification.csv", "ur10e.toml", "ur10e.urdf", "validation.csv"]
    monkeypatch.chdir(tmp_path / "try")
    p = run("identify", "ur10e.toml", "--no-figures", "-q")
    assert p.returncode == 0, p.stderr
    out = tmp_path / "try" / "dynid-identify"
    assert (out / "results.json").is_file() and (out / "report.html").is_file()
    assert (out / "ur10e.urdf").is_file() and (out / "dynid-model.xml").is_file()  # the user's URDF, values written in
    assert "position_offset" not in (out / "ur10e.urdf").read_text()  # no offsets: nothing said of them
    p = run("identify", "ur10e.toml", "--no-figures")
    said = " ".join(p.stdout.split())
    start = said.index("dynid export")
    command = shlex.split(said[start:said.index("-identified.xml", start) + len("-identified.xml")])
    p = run(*command[1:])
    assert p.returncode == 0, p.stderr
    import pinocchio as pin

    assert pin.buildModelFromUrdf(str(tmp_path / "try" / "ur10e-identified.urdf")).nq == 6


def test_the_tx40_example_is_logged_at_its_encoders_zeros_and_identifies_ready(tmp_path, monkeypatch):
    """The TX40's description puts J2's and J3's encoder zeros a quarter turn from its DH table's (position_offset
    -pi/2, pi/2), which a reader adds to the logged angles: the example's log holds the encoders' angles, so identify
    reads the simulated motion and says "model ready" (it read the DH angles turned again, and said "not ready: the
    logged angles do not match the robot file", J2 and J3 turned by +90° and -90°)."""
    monkeypatch.chdir(tmp_path)
    assert run("example", "tx40", "try").returncode == 0
    monkeypatch.chdir(tmp_path / "try")
    p = run("identify", "tx40.toml", "--no-figures")
    said = " ".join((p.stdout + p.stderr).split())
    assert p.returncode == 0, p.stderr
    assert "model ready" in said and "not ready" not in said, said[:300]
    assert "turned by" not in said and "leaves its limits" not in said
    # the written URDF and MJCF say their angles are the description's, the encoders' plus the offsets
    for name in ("dynid-model.urdf", "dynid-model.xml"):
        assert "encoder angle (what a log and the controller hold) plus its position_offset (J2 -90°, J3 +90°)" in (
            tmp_path / "try" / "dynid-identify" / name).read_text(), name


def test_the_example_files_are_the_same_for_the_same_seed_and_simulate_the_description():
    a, b, c = example_files("er16", rng=2), example_files("er16", rng=2), example_files("er16", rng=3)
    assert a == b and a["identification.csv"] != c["identification.csv"]
    assert set(a) == {"er16.toml", "identification.csv", "validation.csv"}  # a DH robot: no URDF, the built-in name
    rows = np.loadtxt(a["identification.csv"].splitlines()[1:], delimiter=",")
    assert rows.shape == (15000, 13) and np.all(np.diff(rows[:, 0]) > 0)  # 60 s at 250 Hz: time, 6 angles, 6 torques


def test_example_refusals(tmp_path):
    (tmp_path / "full").mkdir()
    (tmp_path / "full" / "mine.txt").write_text("a user's file")
    assert_refused(run("example", "ur10e", str(tmp_path / "full")), "exists and is not an empty folder")
    assert (tmp_path / "full" / "mine.txt").read_text() == "a user's file" and len(list((tmp_path / "full").iterdir())) == 1
    assert_refused(run("example", "ur5", str(tmp_path / "new")), "no example for robot 'ur5': choose one of ur10e, tx40, er16")
    assert not (tmp_path / "new").exists()


def test_results_refuse_a_description_whose_kinematics_changed(tmp_path, monkeypatch):
    """results.json holds the description's kinematic fingerprint: load_results and export refuse a description whose
    joint frames changed since (the base parameters then mean something else); the same description loads."""
    import dataclasses

    import pytest

    import dynid
    from dynid.exceptions import DataError

    monkeypatch.chdir(tmp_path)
    assert run("example", "ur10e", "try", "-q").returncode == 0
    monkeypatch.chdir(tmp_path / "try")
    assert run("identify", "ur10e.toml", "--no-figures", "-q").returncode == 0
    assert dynid.load_results("dynid-identify").robot.name == "ur10e"
    urdf = tmp_path / "try" / "ur10e.urdf"
    text = urdf.read_text()
    assert text.count('xyz="0.0 0.0 0.181"') == 1
    urdf.write_text(text.replace('xyz="0.0 0.0 0.181"', 'xyz="0.0 0.0 0.19"'))
    with pytest.raises(DataError, match=r"results\.json: identified with a description of 'ur10e' whose joint frames"):
        dynid.load_results("dynid-identify")
    assert_refused(run("export", "ur10e.toml", "--urdf", "x.urdf"), "fingerprint")
    assert not (tmp_path / "try" / "x.urdf").exists()
    # the fingerprint: the frames, not the nominal inertia; the built-in UR10e and its URDF read directly agree
    from importlib import resources

    robot = dynid.load_robot("ur10e")
    same = dataclasses.replace(robot, inertial=2 * robot.inertial)
    from_urdf = dynid.load_robot(str(resources.files("dynid.model") / "robots" / "ur10e.urdf"))
    assert same.kinematic_fingerprint() == robot.kinematic_fingerprint() == from_urdf.kinematic_fingerprint()
    assert dynid.load_robot(urdf).kinematic_fingerprint() != robot.kinematic_fingerprint()
    assert dynid.load_robot("tx40").kinematic_fingerprint() != robot.kinematic_fingerprint()


def test_identify_into_the_folder_of_the_users_urdf_leaves_the_urdf_as_it_was(tmp_path, monkeypatch):
    """--out . where the config's URDF lives: the written-back model is ur10e-identified.urdf, the user's file is not
    replaced."""
    monkeypatch.chdir(tmp_path)
    assert run("example", "ur10e", "try", "-q").returncode == 0
    users = (tmp_path / "try" / "ur10e.urdf").read_text()
    assert not (tmp_path / "try" / ".dynid-manifest.json").exists()  # the user's files, not a run's outputs
    monkeypatch.chdir(tmp_path / "try")
    for _ in range(2):  # the second run replaces the first's outputs, never the user's files
        p = run("identify", "ur10e.toml", "--out", ".", "--no-figures", "-q")
        assert p.returncode == 0, p.stderr
    assert (tmp_path / "try" / "ur10e.urdf").read_text() == users
    assert (tmp_path / "try" / "identification.csv").is_file() and (tmp_path / "try" / "ur10e.toml").is_file()
    written = (tmp_path / "try" / "ur10e-identified.urdf").read_text()
    assert written != users and "written by dynid into ur10e.urdf" in written
    # dynid export over a file the run reads (the robot's URDF, a log, the config, the results) is refused before it
    # writes: over the URDF the identified values would have become the nominal ones on the next run
    read = {"ur10e.urdf": "the robot's description this run reads", "identification.csv": "a file this run reads",
            "ur10e.toml": "a file this run reads", "results.json": "a file this run reads"}
    before = {name: (tmp_path / "try" / name).read_bytes() for name in read}
    for name, said in read.items():
        flag = "--mjcf" if name == "identification.csv" else "--urdf"
        assert_refused(run("export", "ur10e.toml", "--results", "results.json", flag, name), f"{flag} {name}: {said}")
    assert {name: (tmp_path / "try" / name).read_bytes() for name in read} == before
    p = run("export", "ur10e.toml", "--results", "results.json", "--urdf", "ur10e-identified.urdf", "-q")
    assert p.returncode == 0, p.stderr
    # a folder holding a file of the user's named as one validate writes is refused before any computation
    (tmp_path / "try" / "mine").mkdir()
    (tmp_path / "try" / "mine" / "report.html").write_text("my notes")
    assert_refused(run("validate", "ur10e.toml", "--results", "results.json", "--out", "mine"),
                   "report.html: a file where this run writes one, which no earlier run into mine wrote")
    assert [p.name for p in (tmp_path / "try" / "mine").iterdir()] == ["report.html"]
    assert (tmp_path / "try" / "mine" / "report.html").read_text() == "my notes"
    # dynid validate on the log the model was fitted on scores it as asked, and says its figures are the fit's
    for log, fitted in (("identification.csv", True), ("validation.csv", False)):
        p = run("validate", "ur10e.toml", "--results", "results.json", "--file", log, "--out", f"v-{log}")
        assert p.returncode == 0, p.stderr
        said = " ".join(p.stderr.split())
        assert (f"{log}: 100 % of its sampled positions are samples of the identification log the model was fitted on: "
                "its figures are the fit's" in said) is fitted, said
        out = " ".join(p.stdout.split())  # the next step: another motion, not the export, after the fit's own samples
        assert ("next: validate on a log of another motion" in out) is fitted and ("next: dynid export" in out) is not fitted

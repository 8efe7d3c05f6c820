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
    p = run("identify", "ur10e.toml", "--no-figures")
    said = " ".join(p.stdout.split())
    start = said.index("dynid export")
    command = shlex.split(said[start:said.index("-identified.xml", start) + len("-identified.xml")])
    p = run(*command[1:])
    assert p.returncode == 0, p.stderr
    import pinocchio as pin

    assert pin.buildModelFromUrdf(str(tmp_path / "try" / "ur10e-identified.urdf")).nq == 6


def test_the_example_files_are_the_same_for_the_same_seed_and_simulate_the_description():
    a, b, c = example_files("er16", seed=2), example_files("er16", seed=2), example_files("er16", seed=3)
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

"""dynid init: a starter config from a URDF and a log, which dynid identify then runs on as it stands."""

from importlib import resources
from pathlib import Path

import numpy as np

import dynid

from .refusals import assert_refused, dynid as run

URDF = Path(str(resources.files("dynid.model") / "robots" / "ur10e.urdf"))


def _log(folder: Path, header: bool) -> Path:
    log = dynid.simulated_log(dynid.load_robot(URDF), seconds=30, seed=4)
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
    assert 'positions = { columns = ["joint_pos_1", "joint_pos_2"' in text and 'torques = { columns = ["effort[0]"' in text
    assert 'time = { column = "time" }' in text and 'data_root = "../logs"' in text
    p = run("identify", "arm.toml", "--out", "id", "--no-figures", "-q")
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "cfg" / "id" / "results.json").is_file()


def test_init_without_a_header_takes_blocks_of_columns(tmp_path):
    log = _log(tmp_path, header=False)
    p = run("init", str(URDF), str(log), "--out", str(tmp_path / "arm.toml"))
    assert p.returncode == 0, p.stderr
    text = (tmp_path / "arm.toml").read_text()
    assert "time = { column = 1 }" in text and "positions = { columns = [2, 3, 4, 5, 6, 7] }" in text
    assert "torques = { columns = [8, 9, 10, 11, 12, 13] }" in text and "no header: column 1 taken as time" in p.stdout
    p = run("identify", str(tmp_path / "arm.toml"), "--out", str(tmp_path / "id"), "--no-figures", "-q")
    assert p.returncode == 0, p.stderr


def test_init_refusals(tmp_path):
    log = _log(tmp_path, header=True)
    (tmp_path / "arm.toml").write_text("mine")
    assert_refused(run("init", str(URDF), str(log), "--out", str(tmp_path / "arm.toml")), "exists; give another name, or --force")
    assert (tmp_path / "arm.toml").read_text() == "mine"
    odd = tmp_path / "odd.csv"
    odd.write_text("a,b,c\n1,2,3\n4,5,6\n")
    assert_refused(run("init", str(URDF), str(odd), "--out", str(tmp_path / "x.toml")), "odd.csv: no time column among ['a', 'b', 'c']")
    assert_refused(run("init", str(tmp_path / "none.urdf"), str(log), "--out", str(tmp_path / "y.toml")), "none.urdf")
    assert not (tmp_path / "x.toml").exists() and not (tmp_path / "y.toml").exists()

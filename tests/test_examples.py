"""The scripts of examples/ run as a user runs them, and say what they promise."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _run(name: str, cwd=None) -> str:
    p = subprocess.run([sys.executable, str(EXAMPLES / name)], capture_output=True, text=True, timeout=600,
                       env={**os.environ, "MPLBACKEND": "Agg"}, cwd=cwd)
    assert p.returncode == 0, p.stderr
    return p.stdout


def test_quickstart_example_fits_predicts_saves_loads_and_exports(tmp_path):
    assert len([line for line in (EXAMPLES / "quickstart.py").read_text().splitlines()
                if line.strip() and not line.startswith(('"""', "import"))]) <= 10
    out = _run("quickstart.py", cwd=tmp_path)
    assert "σ" in out and "ZZ1R" in out
    r2 = float(out.split("another log:")[1].split()[0])
    assert 0.99 < r2 <= 1.0
    import json

    assert json.loads((tmp_path / "er16_results.json").read_text())["kind"] == "identify"
    assert (tmp_path / "er16_identified.urdf").read_text().startswith("<?xml")


def test_paper_experiment_example():
    out = _run("paper_experiment.py")
    assert "ols" in out and "abc" in out and "F (eq. 9)" in out


def test_identify_from_arrays_example():
    out = _run("identify_from_arrays.py")
    assert "excitation band" in out and "Base parameters" in out and "ρ (eq. 18)" in out  # result.summary()


def test_export_and_simulate_example():
    out = _run("export_and_simulate.py")
    diff = float(out.split("dynid (N·m):")[1].split()[0])
    assert diff < 1e-8, out
    assert "after 0.5 s from rest" in out


def test_package_exports_the_entry_points():
    import dynid

    for name in dynid.__all__:
        assert getattr(dynid, name) is not None, name
    with pytest.raises(AttributeError):
        _ = dynid.nonexistent


def test_own_robot_example_identifies_from_a_urdf_and_a_csv(tmp_path):
    """The docs' quickstart: a config of a few lines naming a URDF and a CSV's columns by header."""
    import json

    out = _run("own_robot.py", cwd=tmp_path)
    assert "wrote arm-identified/results.json" in out
    assert "robot = " in (tmp_path / "arm.toml").read_text() and len((tmp_path / "arm.toml").read_text().splitlines()) <= 9
    results = json.loads((tmp_path / "arm-identified" / "results.json").read_text())
    fit = results["identification"]["metrics"][results["main_estimate"]]
    assert fit["global_relative_error"] < 1.0  # a simulated log: the model is right, the noise is small

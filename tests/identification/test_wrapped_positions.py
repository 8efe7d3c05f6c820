"""A continuous joint logged within one turn (issue "Honest on any log": a model from any log): its positions jump
by 2π where it passes ±π. Taken back where a log is read (and where arrays are given), the log is identified as the
one that runs on; read as they were, the jumps were filtered and differentiated into torque spikes."""

import json

import numpy as np

from ..cli.refusals import dynid
from ..simulated_logs import simulated_case


def _within_one_turn(angle):
    return (angle + np.pi) % (2 * np.pi) - np.pi


def test_a_joint_logged_within_one_turn_is_identified_as_the_one_that_runs_on(tmp_path):
    """The ER-16's J1 (about the vertical: its angle moves no torque) turned by π - its mid-range and logged in
    [-π, π), 8 jumps of 2π: the same fit and validation errors as the log as simulated, to 1e-6 relative (263 % and
    63 % before), and a warning naming the joint."""
    cfg, robot = simulated_case(tmp_path, "er16", 250.0, "fourier", seed=2, duration=20.0)
    data = np.loadtxt(tmp_path / "ident.csv", delimiter=",")
    data[:, 1] = _within_one_turn(data[:, 1] + np.pi - 0.5 * (data[:, 1].min() + data[:, 1].max()))
    assert np.count_nonzero(np.abs(np.diff(data[:, 1])) > np.pi) >= 2
    np.savetxt(tmp_path / "wrapped.csv", data, delimiter=",", fmt="%.10g")
    (tmp_path / "wrapped.toml").write_text(cfg.read_text().replace("ident.csv", "wrapped.csv"))
    errors = {}
    for name in ("config", "wrapped"):
        p = dynid("identify", tmp_path / f"{name}.toml", "--out", tmp_path / name, "--no-figures")
        assert p.returncode == 0, p.stderr
        text = " ".join((p.stdout + p.stderr).split())
        assert ("taken back so that they run on (joint 1:" in text) == (name == "wrapped"), text
        results = json.loads((tmp_path / name / "results.json").read_text())
        errors[name] = [r["metrics"]["dynid OLS"]["global_relative_error"]
                        for r in (results["identification"], results["validation"][0])]
    np.testing.assert_allclose(errors["wrapped"], errors["config"], rtol=1e-6)


def test_arrays_within_one_turn_are_taken_back_too():
    """The same rule where the arrays are given (Identifier, identify_arrays): positions equal the turning angle."""
    from dynid.io.logs.datasets import recording_from_arrays
    from dynid.model.description import load_robot

    robot = load_robot("ur10e")
    t = np.arange(500) * 0.004
    q = 0.2 * np.sin(np.outer(t, np.arange(1, 7)))
    q[:, 0] = -3.0 - 2.0 * t  # turning on through -π
    rec = recording_from_arrays(robot, t, _within_one_turn(q), np.ones_like(q), name="arrays")
    np.testing.assert_allclose(rec.q, q, atol=1e-12)
    assert any("(joint 1: 1 jump)" in w for w in rec.warnings)

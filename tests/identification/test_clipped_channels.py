"""A drive at its current limit for part of the identification log (issue "Honest on any log", item 3): the clipped
samples say only that the torque was at least that much, so that joint's rows there fit nothing and the metrics
leave those samples out; a warning names the dataset and the joint."""

import json

import numpy as np
import pytest

from ..cli.refusals import dynid
from ..simulated_logs import simulated_case


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    folder = tmp_path_factory.mktemp("clipped")
    cfg, robot = simulated_case(folder, "er16", 250.0, "fourier", seed=2, duration=20.0)
    return folder, cfg, robot


def _clip(path, joint: int, level: float, n: int = 6) -> int:
    """Clip one joint's current at ``level`` of its range from its minimum (a limit on the upper side only);
    returns the number of samples clipped."""
    data = np.loadtxt(path, delimiter=",")
    column = data[:, 1 + n + joint].copy()
    limit = column.min() + level * (column.max() - column.min())
    data[:, 1 + n + joint] = np.minimum(column, limit)
    np.savetxt(path, data, delimiter=",", fmt="%.10g")
    return int(np.sum(column > limit))


def test_a_clipped_identification_channel_fits_nothing_and_is_said(case, tmp_path):
    """J2's current held at three quarters of its range over part of the identification log: the estimate predicts the
    (unclipped) validation log's J2 within a point of the truth's error (fitted to the clipped samples as well, it
    missed by 14 %, the wrist by 280-360 %), the truth's fit is scored without the clipped samples (77 N·m RMSE on J2
    with them), and the warning names the log and the joint."""
    import shutil

    folder, cfg, robot = case
    shutil.copytree(folder, tmp_path / "c", dirs_exist_ok=True)
    c = tmp_path / "c"
    (c / "config.toml").write_text((folder / "config.toml").read_text().replace(str(folder), str(c)))
    clipped = _clip(c / "ident.csv", 1, 0.75)
    assert clipped > 100
    p = dynid("identify", c / "config.toml", "--out", c / "out", "--no-figures")
    assert p.returncode == 0, p.stderr
    text = " ".join((p.stdout + p.stderr).split())
    assert "identification (" in text and "J2's torque stays at its extreme" in text and "saturated?" in text
    results = json.loads((c / "out" / "results.json").read_text())
    ours = results["validation"][0]["metrics"]["dynid OLS"]["relative_error"]
    truth = results["validation"][0]["metrics"]["truth"]["relative_error"]
    assert ours[1] < truth[1] + 1.0, (ours, truth)
    # the fit is scored on the unclipped samples only: the truth's J2 misses them by the noise, as on the validation log
    fit_truth, valid_truth = (r["metrics"]["truth"]["rmse"][1]
                              for r in (results["identification"], results["validation"][0]))
    assert fit_truth < 1.5 * valid_truth, (fit_truth, valid_truth)


def _in_steps(path, parts: int = 20, clip_joint: int | None = None, n: int = 6) -> None:
    """Log every current in steps of 1/``parts`` of its range (as a drive that reports whole counts), after clipping
    one joint at three quarters of its range where ``clip_joint`` is given."""
    data = np.loadtxt(path, delimiter=",")
    currents = data[:, 1 + n:1 + 2 * n].copy()
    step = np.ptp(currents, axis=0) / parts
    if clip_joint is not None:
        column = currents[:, clip_joint]
        currents[:, clip_joint] = np.minimum(column, column.min() + 0.75 * np.ptp(column))
    data[:, 1 + n:1 + 2 * n] = np.round(currents / step) * step
    np.savetxt(path, data, delimiter=",", fmt="%.10g")


def test_currents_logged_in_steps_are_not_taken_for_saturation(case, tmp_path):
    """Currents logged in steps of 1/20 of their range: every smooth peak reads its top step for tens of samples. No
    joint is said saturated (three were, and their samples around the peaks left out) while J2 clipped at three quarters
    of its range and then logged in steps is still found, and the estimate from that log predicts the validation log
    about as well as the one from the unclipped log in steps (within 1.5×: with a margin of 1.5 steps, two of the four
    clipped runs were missed and the error was 4.8×)."""
    import shutil

    folder, cfg, robot = case
    errors = {}
    for name, clip_joint in (("steps", None), ("steps-clipped", 1)):
        c = tmp_path / name
        shutil.copytree(folder, c)
        (c / "config.toml").write_text((folder / "config.toml").read_text().replace(str(folder), str(c)))
        _in_steps(c / "ident.csv", clip_joint=clip_joint)
        p = dynid("identify", c / "config.toml", "--out", c / "out", "--no-figures")
        assert p.returncode == 0, p.stderr
        said = [line for line in " ".join((p.stdout + p.stderr).split()).split("warning: ") if "saturated?" in line]
        assert len(said) == (0 if clip_joint is None else 1), said
        assert clip_joint is None or said[0].startswith("identification (") and "J2's torque" in said[0]
        results = json.loads((c / "out" / "results.json").read_text())
        errors[name] = results["validation"][0]["metrics"]["dynid OLS"]["global_relative_error"]
    assert errors["steps-clipped"] < 1.5 * errors["steps"], errors

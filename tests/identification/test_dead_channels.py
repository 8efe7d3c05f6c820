"""A torque channel that reads one value for a whole log (issue "Honest on any log", item 3): said in one line naming
the dataset and the joint, its rows left out of the estimation and of the metrics, no NumPy warning."""

import json
import warnings

import numpy as np
import pytest

from ..cli.refusals import dynid
from ..simulated_logs import simulated_case


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    folder = tmp_path_factory.mktemp("dead")
    cfg, robot = simulated_case(folder, "er16", 250.0, "fourier", seed=2, duration=20.0)
    return folder, cfg, robot


def _kill(path, joint: int, n: int = 6) -> None:
    data = np.loadtxt(path, delimiter=",")
    data[:, 1 + n + joint] = 0.0
    np.savetxt(path, data, delimiter=",", fmt="%.10g")


def _run(folder, cfg, out):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        p = dynid("identify", cfg, "--out", folder / out, "--no-figures")
    assert p.returncode == 0, p.stderr
    numpy_warnings = [w for w in caught if issubclass(w.category, RuntimeWarning)]
    assert numpy_warnings == [] and "RuntimeWarning" not in p.stdout + p.stderr
    return p, json.loads((folder / out / "results.json").read_text())


def test_a_dead_validation_channel_is_left_out_of_the_metrics(case):
    """J4 reads 0 N·m in the validation log: a warning names the log and the joint, J4's figures are null and the
    global error is the other joints' (the truth scores as it does on the live joints: 13x its fit before, and a
    verdict that blamed the model); no NumPy warning."""
    folder, cfg, robot = case
    _kill(folder / "valid.csv", 3)
    p, results = _run(folder, cfg, "out-valid")
    text = " ".join((p.stdout + p.stderr).split())
    assert "validation (" in text and "J4's torque reads 0 N·m throughout" in text
    metrics = results["validation"][0]["metrics"]
    assert metrics["truth"]["relative_error"][3] is None
    assert metrics["truth"]["global_relative_error"] < 3 * results["identification"]["metrics"]["truth"]["global_relative_error"]
    assert not any("worse than it fits" in f["text"] for f in results["findings"])


def test_a_dead_identification_channel_is_left_out_of_the_estimation(tmp_path):
    """J6 reads 0 N·m in the identification log: its rows fit nothing (they would pull its drive terms and the
    wrist's inertia towards zero torque); its own drive terms keep the nominal values and the finding says why; the
    other joints' figures on the live validation log stay near the truth's."""
    c = tmp_path / "c"  # the case again, its validation log live (the module's other test killed its J4)
    c.mkdir()
    cfg, robot = simulated_case(c, "er16", 250.0, "fourier", seed=2, duration=20.0)
    _kill(c / "ident.csv", 5)
    p, results = _run(c, cfg, "out")
    (finding,) = [f for f in results["findings"] if f["kind"] == "prior"]
    assert "Ia6, fc6, fv6, offset6" in finding["text"] and "J6: a dead or saturated torque channel" in finding["text"]
    ours = results["validation"][0]["metrics"]["dynid OLS"]["relative_error"]
    truth = results["validation"][0]["metrics"]["truth"]["relative_error"]
    assert all(ours[j] < truth[j] + 1.0 for j in range(5))


def test_a_channel_at_its_limit_most_of_the_log_is_left_out_not_refused(case, tmp_path):
    """J2's torque clipped at its 30th and 70th percentiles in the identification log (60 % of the samples at a limit):
    it was refused ("no sample is left to score") though five joints are live. Now J2 is left out as a dead channel
    is, said in a warning naming the log, the joint and the share; every other joint's identification figure is
    finite and J2's is null; no NumPy warning."""
    import shutil

    folder, cfg, robot = case
    shutil.copytree(folder, tmp_path / "c", dirs_exist_ok=True)
    c = tmp_path / "c"
    (c / "config.toml").write_text((folder / "config.toml").read_text().replace(str(folder), str(c)))
    shutil.copy(c / "ident.csv", c / "valid.csv")
    data = np.loadtxt(c / "ident.csv", delimiter=",")
    column = 1 + 6 + 1
    low, high = np.percentile(data[:, column], [30, 70])
    data[:, column] = np.clip(data[:, column], low, high)
    np.savetxt(c / "ident.csv", data, delimiter=",", fmt="%.10g")
    p, results = _run(c, c / "config.toml", "out")
    text = " ".join((p.stdout + p.stderr).split())
    assert "J2's torque is at its extreme" in text and "saturated throughout?" in text
    errors = results["identification"]["metrics"]["dynid OLS"]["relative_error"]
    assert errors[1] is None and all(np.isfinite(errors[j]) for j in (0, 2, 3, 4, 5))

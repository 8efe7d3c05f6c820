"""The flipped-sign check judges the torque beyond the friction the description's nominal model may lack (issue "Honest
on any log"): a sign flipped in the log is still named; a short log whose friction runs against the nominal model is
not called flipped."""

import json

import numpy as np
import pytest

from dynid.validation.torques import TorqueSums

from ..cli.refusals import dynid
from ..conftest import shared_data
from ..simulated_logs import simulated_case


def test_the_partial_correlation_is_that_of_the_residuals_of_a_direct_regression(rng):
    """Against NumPy: both the prediction and the torque regressed on the nuisance columns (with an intercept),
    then np.corrcoef of the two residuals; on joint 0 with two nuisance columns, on joint 1 with none."""
    m, n, p = 3000, 2, 5
    y = rng.standard_normal((m, n, p))
    beta = rng.standard_normal(p)
    tau = y @ (beta * rng.uniform(-1, 1, p)) + 0.3 * rng.standard_normal((m, n)) + 2.0
    sums = TorqueSums(n, p, m)
    for a in range(0, m, 700):
        sums.add(np.arange(a, min(a + 700, m)) * 0.01, y[a:a + 700], tau[a:a + 700])
    got = sums.partial_correlation(beta, {0: [1, 3]})
    for j, cols in ((0, [1, 3]), (1, [])):
        x = np.column_stack([np.ones(m), *(y[:, j, c] for c in cols)])
        pred, meas = y[:, j] @ beta, tau[:, j]
        rp = pred - x @ np.linalg.lstsq(x, pred, rcond=None)[0]
        rt = meas - x @ np.linalg.lstsq(x, meas, rcond=None)[0]
        assert got[j] == pytest.approx(np.corrcoef(rp, rt)[0, 1], abs=1e-10)


def test_a_flipped_torque_sign_is_still_named(tmp_path):
    """J2's current written with the wrong sign in the identification log: the verdict names J2 and the fix."""
    cfg, _ = simulated_case(tmp_path, "er16", 125.0, "fourier", duration=20.0)
    data = np.loadtxt(tmp_path / "ident.csv", delimiter=",")
    data[:, 1 + 6 + 1] *= -1  # time, 6 positions, then J1's current: J2's flipped
    np.savetxt(tmp_path / "ident.csv", data, delimiter=",", fmt="%.10g")
    p = dynid("identify", cfg, "--out", tmp_path / "out", "--no-figures")
    assert p.returncode == 0, p.stderr
    findings = json.loads((tmp_path / "out" / "results.json").read_text())["findings"]
    (sign,) = [f for f in findings if f["kind"] == "sign"]
    assert "J2" in sign["text"] and "sign = [1, -1, 1, 1, 1, 1]" in sign["text"]


def test_two_seconds_of_the_ur10e_log_are_not_called_flipped(tmp_path):
    """Rows 635-800 of the UR10e's identification log (2 s): J4's torque runs against the nominal model
    (ρ = -0.865: friction the nominal model lacks) but not beyond its friction terms (-0.086); the log's sign is right
    (its full length gives no such finding). It read "J4: ... is their sign flipped?" and "not ready"."""
    root = shared_data("ur10e_mamedov2020")
    from pathlib import Path

    text = (Path(__file__).resolve().parents[2] / "configs" / "ur10e.toml").read_text()
    text = text.replace('data_root = "../../shared/data/ur10e_mamedov2020"', f'data_root = "{root}"')
    text = text.replace("rows = [635, 3510]", "rows = [635, 800]")
    (tmp_path / "c.toml").write_text(text)
    p = dynid("identify", tmp_path / "c.toml", "--out", tmp_path / "out", "--no-figures", "--no-validate")
    assert p.returncode == 0, p.stderr
    results = json.loads((tmp_path / "out" / "results.json").read_text())
    assert results["diagnostics"]["nominal_correlation"][3] < -0.5  # what the plain check saw
    assert [f for f in results["findings"] if f["kind"] == "sign"] == []
    assert "flipped" not in p.stdout + p.stderr

"""The closed-loop Monte Carlo study (``dynid montecarlo --closed-loop``): the Dask path, determinism, the bound,
the statistics, the outputs and the refusals."""

import json
from dataclasses import replace

import numpy as np
import pytest

from dynid.cli.app import main
from dynid.dynamics.regressor import observation_matrix
from dynid.exceptions import ConfigError
from dynid.simulation.closed_loop import simulate_closed_loop
from dynid.studies.closed_loop_montecarlo import (
    ClosedLoopStudyConfig,
    ClosedLoopStudyResult,
    _prepare,
    run_closed_loop_study,
    simulate_realisation,
)

SMALL = ClosedLoopStudyConfig(encoder_noise=(0.0, 1e-2), torque_noise=(0.1,), realisations=3,
                              estimators=("ols", "wls", "irls", "idim-iv"), duration=10.0)


@pytest.fixture(scope="module")
def study():
    return run_closed_loop_study(SMALL, workers=2)


def test_every_task_ran_and_matches_a_direct_call(study):
    n_base = study.truth.size
    assert "2 Dask workers" in study.cluster
    assert study.estimates.shape == (2, 3, 4, n_base) and np.all(np.isfinite(study.estimates))
    assert np.all(np.isfinite(study.std)) and np.all(study.std > 0)  # each of these estimators gives σ
    setup = _prepare(SMALL)
    direct = simulate_realisation(setup, 1, 2)
    np.testing.assert_array_equal(direct["params"], study.estimates[1, 2])  # independent of scheduling
    np.testing.assert_array_equal(direct["std"], study.std[1, 2])


def test_noise_free_motion_is_recovered_and_encoder_noise_biases_least_squares(study):
    """Without encoder noise every estimator finds the truth within 1 % (median over the parameters); at 1e-2° the
    ordinary least squares' bias grows well beyond it (the loop's noise in the observation matrix)."""
    stats = study.statistics()
    for key in SMALL.estimators:
        assert stats[key]["median_relative_bias"][0] < 0.01, key
    assert stats["ols"]["median_relative_bias"][1] > 3 * stats["ols"]["median_relative_bias"][0]


def test_the_bound_is_taken_at_the_true_states_of_the_closed_loop():
    """Independent truth: the noise-free run's applied torques are the inverse dynamics of its true states, so the
    observation rows the bound is built from predict them with the true parameters (ABA integration against the
    regressor); and the bound is the inverse of their Gram matrix."""
    setup = _prepare(SMALL)
    exp = setup.experiment
    clean = simulate_closed_loop(setup.robot, setup.t, exp.q_ref, exp.dq_ref, exp.controller, feedforward=exp.feedforward)
    w = setup.base.base_observation(observation_matrix(setup.robot, clean.q_true, clean.dq_true, clean.ddq_true))
    predicted = (w.reshape(-1, setup.base.n_base) @ setup.truth).reshape(clean.tau_applied.shape)
    np.testing.assert_allclose(predicted, clean.tau_applied, atol=1e-6 * np.abs(clean.tau_applied).max())
    gram = w.reshape(-1, setup.base.n_base).T @ w.reshape(-1, setup.base.n_base)
    np.testing.assert_allclose(setup.unit_crb @ gram, np.eye(setup.base.n_base), atol=1e-6)


def test_closed_loop_intervals_hold_the_truth_at_the_highest_encoder_noise():
    """The issue's check, at BIRDy's highest encoder noise (1e-2°, 0.1 N·m), 24 realisations of the 25 s experiment:
    IDIM-IV's and DIDIM's 95 % intervals hold the truth in 93-99 % of the (realisation, parameter) pairs (0.946 and
    0.958 with Newey–West's Bartlett lags; the Parzen window, which mends the 30 Hz cutoffs' 100 %, stays in the band:
    tests/estimators/test_instrumental.py checks the window against an exact variance). Before the log's zero-order hold was given as a torque delay and σ took the residuals'
    correlation in time into account, they held it in 78-80 % (a 0.13 % bias from the half period, σ from the
    white-noise formula)."""
    cfg = ClosedLoopStudyConfig(encoder_noise=(1e-2,), torque_noise=(0.1,), realisations=24, estimators=("idim-iv", "didim"))
    stats = run_closed_loop_study(cfg, workers=2).statistics()
    for key in cfg.estimators:
        assert stats[key]["converged"][0] == 24, key
        assert 0.93 <= stats[key]["coverage"][0] <= 0.99, (key, stats[key]["coverage"][0])


def test_didim_holds_the_truth_with_30_hz_cutoffs_at_the_highest_encoder_noise():
    """Cutoffs at 30 Hz (band 3 Hz) let the loop's noise in, where least squares is biased: DIDIM's 95 % intervals
    hold the truth in 92-99 % of the (realisation, parameter) pairs over 12 realisations, and its median |bias| is below
    0.1 %. The rows where the simulated joint is slower than min_speed fit nothing, as the measured ones do not;
    before, the loop's velocity jitter near reversals, which the noise-free simulation lacks, pulled fc 1 % low and
    fv 1 % high: 88.9 % and 0.126 % here (87 % over 40 realisations, benchmarks/NOTEBOOK.md)."""
    cfg = ClosedLoopStudyConfig(encoder_noise=(1e-2,), torque_noise=(0.1,), realisations=12, estimators=("didim",),
                                band=3.0)
    stats = run_closed_loop_study(cfg, workers=2).statistics()["didim"]
    assert stats["converged"][0] == 12
    assert 0.92 <= stats["coverage"][0] <= 0.99, stats["coverage"][0]
    assert stats["median_relative_bias"][0] < 1e-3, stats["median_relative_bias"][0]


def test_statistics_on_constructed_estimates():
    """Bias, spread and coverage against numbers built to have them: estimates truth + b + σ·z with z chosen so that
    exactly 4 of 40 (realisation, parameter) pairs fall outside 1.96 σ."""
    truth = np.array([1.0, -2.0, 4.0, 0.0])
    z = np.array([[0.5, -0.5, 1.0, 0.0], [-0.5, 0.5, -1.0, 2.5], [1.5, -1.5, 0.2, -0.2], [-1.5, 1.5, -0.2, 0.2],
                  [2.0, 0.0, 0.0, 0.0], [-0.3, 0.3, 0.0, 0.0], [0.0, 0.0, 3.0, 0.0], [0.0, 0.0, -3.0, 0.0],
                  [0.1, 0.1, 0.1, 0.1], [-0.1, -0.1, -0.1, -0.1]])
    sigma = np.array([0.1, 0.2, 0.4, 0.05])
    est = truth + 0.01 + z * sigma
    cfg = ClosedLoopStudyConfig(encoder_noise=(0.0,), torque_noise=(0.1,), realisations=10, estimators=("ols",))
    result = ClosedLoopStudyResult(cfg, ("a", "b", "c", "d"), truth, est[None, :, None, :], np.ones((1, 10, 1)),
                                   0.5 * sigma[None, :], std=np.broadcast_to(sigma, est.shape)[None, :, None, :].copy(),
                                   converged=np.ones((1, 10, 1), dtype=bool))
    s = result.statistics()["ols"]
    np.testing.assert_allclose(s["bias"][0], 0.01 + z.mean(axis=0) * sigma)
    np.testing.assert_allclose(s["spread"][0], z.std(axis=0, ddof=1) * sigma)
    assert s["coverage"][0] == pytest.approx(1 - 4 / 40)  # |z| > 1.96: 2.5, 2.0, 3.0, -3.0
    assert s["median_relative_bias"][0] == pytest.approx(np.median(np.abs(s["bias"][0][:3]) / np.abs(truth[:3])))
    np.testing.assert_allclose(s["spread_over_crb"][0], 2 * z.std(axis=0, ddof=1))
    assert result.best(0) == "ols" and result.to_dict()["cells"][0]["estimators"]["ols"]["coverage_95"] == pytest.approx(0.9)


def test_command_writes_the_study_and_prints_a_verdict(tmp_path, capsys):
    out = tmp_path / "study"
    code = main(["montecarlo", "--closed-loop", "--encoder-noise", "1e-2", "--torque-noise", "0.1", "--realisations", "2",
                 "--estimators", "ols,idim-iv", "--duration", "6", "--workers", "1", "--out", str(out)])
    assert code == 0
    printed = capsys.readouterr().out
    assert "closed loop" in printed and "IDIM-IV" in printed and "median |bias| OLS" in printed
    data = json.loads((out / "montecarlo.json").read_text())
    assert data["study"] == "closed loop" and data["kind"] == "montecarlo"
    cell = data["cells"][0]
    assert (cell["encoder_noise_deg"], cell["torque_noise_Nm"]) == (0.01, 0.1)
    assert set(cell["estimators"]) == {"ols", "idim-iv"} and cell["estimators"]["ols"]["fitted"] == 2
    rows = (out / "montecarlo_estimates.csv").read_text().splitlines()
    assert len(rows) == 1 + 2 * 2 and rows[1].startswith("0.01,0.1,0,ols,1,")
    html = (out / "report.html").read_text()
    assert "Estimators on the noise grid" in html and "IDIM-IV" in html


@pytest.mark.parametrize("change, message", [
    ({"torque_noise": (0.0,)}, "torque_noise: expected positive"),
    ({"encoder_noise": (-1e-3,)}, "encoder_noise: expected non-negative"),
    ({"estimators": ("ols", "magic")}, "estimators"),
    ({"estimators": ("ols", "ols")}, "each estimator once"),
    ({"realisations": 1}, "realisations"),
    ({"band": 600.0}, "band"),
    ({"bandwidth": 80.0}, "bandwidth"),
    ({"joints": 9}, "joints"),
])
def test_bad_settings(change, message):
    with pytest.raises(ConfigError, match=message):
        replace(SMALL, **change).validate()


def test_bad_options_are_one_line_errors(capsys):
    assert main(["montecarlo", "--closed-loop", "--encoder-noise", "1e-2,x", "--out", "/nonexistent/never"]) != 0
    err = capsys.readouterr().err
    assert "--encoder-noise: expected comma-separated noise levels in °" in err and "Traceback" not in err

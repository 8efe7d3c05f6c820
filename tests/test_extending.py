"""Extending dynid: a new estimator and a new preprocessing strategy, each one file (tests/plugins/), run through
``identify``, ``run`` and ``montecarlo`` (the Monte Carlo realisations in a Dask worker process, which registers them
from the study's setup)."""

import json

import numpy as np
import pytest

import tests.plugins.central_differences  # noqa: F401  registers "central_differences_test"
import tests.plugins.ridge  # noqa: F401  registers "ridge_test"
from dynid.identification.run import run_identification, run_validation
from dynid.io.config.identification_config import load_identification_config
from dynid.report.identification_run import save_identification
from dynid.studies.montecarlo import MonteCarloConfig, run_montecarlo
from dynid.studies.paper import PaperExperimentConfig, run_paper_experiment

from .simulated_logs import simulated_case, truth_beta

NOISE_FREE = dict(current_noise=0.0, encoder_resolution=0.0, smoothing_passes=0, duration=10.0, rate=200.0, bootstrap=0)


def test_a_new_estimator_runs_in_dynid_run():
    r = run_paper_experiment(PaperExperimentConfig(estimators=("ols", "RIDGE_test"), **NOISE_FREE))
    assert list(r.estimates) == ["ols", "ridge_test"]
    # tiny ridge on noise-free rows: the truth, as OLS finds it
    np.testing.assert_allclose(r.estimates["ridge_test"].params, r.truth, rtol=1e-5, atol=1e-6 * np.abs(r.truth).max())
    assert r.to_dict()["estimates"]["ridge_test"]["label"] == "Ridge"


def test_a_new_estimator_runs_in_dynid_identify_and_validate(tmp_path):
    cfg, truth_robot = simulated_case(tmp_path, "ur10e", 125.0, "fourier", seed=4, duration=30.0)
    cfg.write_text(cfg.read_text().replace('estimators = ["ols"]', 'estimators = ["ridge_test", "ols"]'))
    config = load_identification_config(cfg)
    result = run_identification(config)
    ridge, ols = result.estimates["dynid Ridge"], result.estimates["dynid OLS"]
    assert result.main == "dynid Ridge" and ridge.std is None  # the first is the main estimate; ridge gives no σ
    np.testing.assert_allclose(ridge.params, ols.params, rtol=1e-4, atol=1e-6 * np.abs(ols.params).max())
    truth = truth_beta(result, truth_robot)
    assert np.linalg.norm(ridge.params - truth) / np.linalg.norm(truth) < 0.02
    assert "dynid Ridge" in result.validations[0].metrics()
    save_identification(result, tmp_path / "out", figures_too=False)
    stored = json.loads((tmp_path / "out" / "results.json").read_text())
    assert stored["main_estimate"] == "dynid Ridge" and stored["estimators"] == ["ridge_test", "ols"]
    comparisons, _ = run_validation(config, stored)
    np.testing.assert_allclose(comparisons[0].metrics()["dynid Ridge"]["relative_error"],
                               result.validations[0].metrics()["dynid Ridge"]["relative_error"], rtol=1e-9)


def test_a_new_estimator_runs_in_a_monte_carlo_worker():
    cfg = MonteCarloConfig(noise_levels=(0.05,), realisations=2, estimators=("ols", "ridge_test"), duration=8.0, rate=100.0)
    study = run_montecarlo(cfg, workers=1)
    assert np.all(np.isfinite(study.estimates)) and not study.errors
    ols, ridge = study.estimates[0, :, 0], study.estimates[0, :, 1]
    np.testing.assert_allclose(ridge, ols, rtol=1e-4, atol=1e-6 * np.abs(ols).max())


def test_a_new_preprocessing_strategy_runs_in_dynid_run():
    central = run_paper_experiment(PaperExperimentConfig(estimators=("ols",), strategy="central_differences_test", **NOISE_FREE))
    # central differences at 200 Hz (one-sided at the ends): near the truth, not to round-off as the Fourier fit is
    error = np.linalg.norm(central.estimates["ols"].params - central.truth) / np.linalg.norm(central.truth)
    assert 1e-6 < error < 1e-2
    assert central.to_dict()["settings"]["strategy"] == "central_differences_test"


def test_a_new_preprocessing_strategy_runs_in_dynid_identify(tmp_path):
    cfg, truth_robot = simulated_case(tmp_path, "ur10e", 250.0, "fourier", seed=4, duration=30.0, current_std=0.002)
    cfg.write_text(cfg.read_text().replace("[estimation]", '[preprocessing]\nstrategy = "central_differences_test"\n[estimation]'))
    result = run_identification(load_identification_config(cfg))
    assert result.settings["preprocessing"]["strategy"] == "central_differences_test"
    assert result.settings["preprocessing"]["derivation"] == "central differences, no filter"
    assert result.n_rows == 250 * 30 * 6  # every row kept: no decimation, no speed threshold
    truth = truth_beta(result, truth_robot)
    assert np.linalg.norm(result.solution.params - truth) / np.linalg.norm(truth) < 0.05


def test_a_new_preprocessing_strategy_runs_in_a_monte_carlo_worker():
    base = dict(noise_levels=(0.05,), realisations=2, estimators=("ols",), duration=8.0, rate=100.0)
    central = run_montecarlo(MonteCarloConfig(strategy="central_differences_test", **base), workers=1)
    paper = run_montecarlo(MonteCarloConfig(**base), workers=1)
    assert np.all(np.isfinite(central.estimates)) and not central.errors
    assert not np.allclose(central.estimates, paper.estimates, rtol=1e-6)  # another route to the rows


def test_an_unknown_strategy_names_the_field(tmp_path):
    from dynid.exceptions import ConfigError

    with pytest.raises(ConfigError, match="preprocessing.strategy: expected one of parallel, paper"):
        run_paper_experiment(PaperExperimentConfig(strategy="nope", **NOISE_FREE))


def test_a_missing_optional_dependency_names_the_extra(monkeypatch, tmp_path):
    """Dask and rosbags are extras: without them, the command that needs one says which extra installs it, in one
    line, before any work."""
    import sys

    from typer.testing import CliRunner

    from dynid.cli.app import app

    monkeypatch.setitem(sys.modules, "distributed", None)  # as if not installed: importing it raises ImportError
    result = CliRunner().invoke(app, ["montecarlo", "--realisations", "2", "--out", str(tmp_path / "o")])
    assert result.exit_code == 1 and not (tmp_path / "o").exists()
    assert result.stderr.strip() == 'error: dynid montecarlo needs distributed, which is not installed: pip install "dynid[montecarlo]"'


@pytest.mark.parametrize("key, cls", [("prior_probe_test", "PriorProbe"), ("prior_probe_legacy_test", "LegacyPriorProbe")])
def test_a_plugin_gets_the_prior_it_documents_whatever_else_is_listed(tmp_path, key, cls):
    """A plugin estimator asking for ``prior`` got None unless ``sdp`` was also listed (a "ridge toward the nominal
    values" then shrank toward zero): it gets the robot file's standard parameters (physically consistent) either
    way, in the problem given to its ``fit`` or, written before ``fit`` took the problem, in its constructor."""
    import tests.plugins.prior_probe as probe

    cfg, _ = simulated_case(tmp_path, "er16", 100.0, "fourier", duration=8.0)
    cfg.write_text(cfg.read_text().replace('estimators = ["ols"]', f'estimators = ["wls", "{key}"]'))
    config = load_identification_config(cfg)
    seen = getattr(probe, cls).seen
    seen.clear()
    run_identification(config, validate=False)
    assert seen and seen[-1] is not None
    np.testing.assert_allclose(seen[-1], config.robot.physical_prior()[0], rtol=1e-12)


def test_a_strategy_that_extends_the_default_ones_prepare_is_run_as_written(tmp_path):
    """A plugin's subclass of the default strategy whose ``prepare`` has the base class's documented signature (no
    ``progress``): the preparation runs it, and its share is said once, at its end; the default strategy's own says
    its share as it goes (issue "Fast where users wait", item 3)."""
    from dataclasses import replace

    from dynid.io.logs.datasets import load_recording
    from dynid.preprocessing.preparation import ParallelFiltering, prepare
    from dynid.preprocessing.settings import Preprocessing
    from dynid.preprocessing.strategies import register_strategy, unregister_strategy

    class Marked(ParallelFiltering):
        def prepare(self, recording, settings, strict=True):
            data = super().prepare(recording, settings, strict)
            return replace(data, warnings=data.warnings + ("prepared by the plugin",))

    cfg, _ = simulated_case(tmp_path, "er16", 250.0, "fourier", seed=2, duration=10.0)
    config = load_identification_config(cfg)
    recording = load_recording(config.identification, config.robot)
    register_strategy("marked_test", Marked, replace=True)
    try:
        shares = []
        data = prepare(recording, Preprocessing(strategy="marked_test"), progress=shares.append)
        assert "prepared by the plugin" in data.warnings and shares == [1.0]
        own = []
        default = prepare(recording, Preprocessing(), progress=own.append)
        assert len(own) >= 5 and own[-1] == 1.0 and all(b > a for a, b in zip(own, own[1:]))
        assert np.array_equal(default.ddq, data.ddq) and "prepared by the plugin" not in default.warnings
    finally:
        unregister_strategy("marked_test")

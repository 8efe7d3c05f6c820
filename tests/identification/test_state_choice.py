"""The main estimate chosen on the validation logs' states alone (``[estimation] choice = "states"``; issue "Never worse
than the description", item 1): the choice reads no validation torque, so their figures are an independent test."""

import re
from types import SimpleNamespace

import numpy as np
import pytest

from dynid.exceptions import ConfigError
from dynid.identification.evidence import state_evidence
from dynid.identification.run import run_identification
from dynid.identification.verdict import STATE_SIGMAS
from dynid.io.config.identification_config import load_identification_config
from tests.simulated_logs import simulated_case


def _states_config(tmp_path, choice: str = "states", estimators: str = '"wls", "sdp"'):
    cfg, _ = simulated_case(tmp_path, "er16", 125.0, "fourier", duration=10.0)
    cfg.write_text(cfg.read_text().replace('estimators = ["ols"]', f'estimators = [{estimators}]\nchoice = "{choice}"'))
    return cfg


def test_the_choice_on_the_states_does_not_read_the_validation_torques(tmp_path):
    """The same identification with the validation log's currents scaled by 1.5 and offset: its figures change, the
    main estimate and the evidence it was chosen on do not (to the last digit)."""
    cfg = _states_config(tmp_path)
    first = run_identification(load_identification_config(cfg))
    log = tmp_path / "valid.csv"
    data = np.loadtxt(log, delimiter=",")
    n = (data.shape[1] - 1) // 2
    data[:, 1 + n:] = 1.5 * data[:, 1 + n:] + 0.3
    np.savetxt(log, data, delimiter=",", fmt="%.10g")
    second = run_identification(load_identification_config(cfg))
    figure = lambda r: r.diagnostics["yardstick"]["mean_global_relative_error"][r.main]  # noqa: E731
    assert second.main == first.main
    assert second.diagnostics["state_evidence"] == first.diagnostics["state_evidence"]
    assert abs(figure(second) - figure(first)) > 10.0  # the torques it was scored on did change
    main = [f for f in first.findings if f.kind == "main"]
    assert len(main) == 1 and "chosen on the validation logs' states alone" in main[0].text
    evidence = first.diagnostics["state_evidence"]
    chosen_sdp = evidence["apart_percent"] > STATE_SIGMAS * evidence["spread_percent"]
    assert (first.main == "dynid SDP") == chosen_sdp
    assert evidence["fallback"] == "dynid drive-only"  # motor currents: the description's links, the drives fitted


def test_the_evidence_is_the_block_jackknife_and_the_difference_on_the_states():
    """Two logs of known predictions: the SDP's spread is the delete-one-block jackknife's standard error of its
    predictions, the difference the RMS of SDP minus fallback, each in % of the description's RMS prediction and
    averaged over the logs by samples; at rest the prediction without its Coulomb-like terms counts."""
    rng = np.random.default_rng(4)
    logs, apart, spread, weight = [], [], [], []
    for samples in (40, 90):
        sets = {name: rng.normal(size=(samples, 3)) for name in ("sdp", "fb", "nom", *(f"r{k}" for k in range(5)))}
        centre = {name: rng.normal(size=(samples, 3)) for name in sets}
        resting = rng.random((samples, 3)) < 0.3
        logs.append(SimpleNamespace(predicted=sets, centre=centre, resting=resting))
        seen = {name: np.where(resting, centre[name], sets[name]) for name in sets}
        unit = 100 / np.sqrt(np.mean(seen["nom"] ** 2))
        refits = [seen[f"r{k}"] for k in range(5)]
        mean = sum(refits) / 5
        jack = np.sqrt(4 / 5 * sum(np.mean((r - mean) ** 2) for r in refits))
        spread.append(unit * jack)
        apart.append(unit * np.sqrt(np.mean((seen["sdp"] - seen["fb"]) ** 2)))
        weight.append(samples)
    found = state_evidence(logs, "sdp", "fb", tuple(f"r{k}" for k in range(5)), "nom")
    assert found["fallback"] == "fb"
    np.testing.assert_allclose(found["apart"], np.average(apart, weights=weight), rtol=1e-12)
    np.testing.assert_allclose(found["spread"], np.average(spread, weights=weight), rtol=1e-12)


def test_the_choice_on_the_states_needs_the_sdp_and_a_known_value(tmp_path):
    with pytest.raises(ConfigError, match=r'estimation.choice = "states" weighs the SDP\'s spread .* add sdp'):
        load_identification_config(_states_config(tmp_path, estimators='"wls"'))
    with pytest.raises(ConfigError, match=r"choice"):
        load_identification_config(_states_config(tmp_path, choice="validation"))


def test_the_default_choice_is_unchanged(tmp_path):
    """Without ``choice`` the verdict weighs the validation logs' torques as before: no SDP refits, no evidence."""
    cfg = _states_config(tmp_path)
    cfg.write_text(re.sub(r'^choice = "states"\n', "", cfg.read_text(), flags=re.M))
    config = load_identification_config(cfg)
    assert config.estimation.choice == "torques"
    result = run_identification(config)
    assert result.sdp_refits == () and "state_evidence" not in result.diagnostics

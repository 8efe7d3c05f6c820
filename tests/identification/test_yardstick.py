"""The one yardstick (issue "Never worse than the description", item 5): a validation figure that does not depend on
the identification's settings."""

from __future__ import annotations

import re

import numpy as np


def _identify(cfg, preprocessing: str = ""):
    from dynid.identification.run import run_identification
    from dynid.io.config.identification_config import load_identification_config

    text = cfg.read_text()
    if preprocessing:
        text = re.sub(r"^\[estimation\]", f"[preprocessing]\n{preprocessing}\n[estimation]", text, count=1, flags=re.M)
    path = cfg.with_name(f"config-{len(preprocessing)}.toml")
    path.write_text(text)
    return run_identification(load_identification_config(path))


def test_a_fixed_set_scores_the_same_on_the_yardstick_whatever_the_settings(tmp_path):
    """The truth's parameters (a fixed set, scored beside) get one figure on the yardstick under the defaults and
    under hand-set cutoffs, where each setting's own figure (its validation log filtered by its settings) differs; the
    main estimate's yardstick figure is on the same samples as the truth's."""
    from tests.simulated_logs import simulated_case

    cfg, _ = simulated_case(tmp_path, "er16", 125.0, "fourier", duration=10.0)
    runs = [_identify(cfg), _identify(cfg, "position_cutoff = 1.0\nparallel_cutoff = 1.0")]
    own = [float(np.mean([v.metrics()["truth"]["global_relative_error"] for v in r.validations])) for r in runs]
    yard = [r.diagnostics["yardstick"] for r in runs]
    assert abs(own[0] - own[1]) > 0.05 * max(own)  # the settings' own figures move with the settings
    truth = [y["mean_global_relative_error"]["truth"] for y in yard]
    assert np.isfinite(truth[0]) and abs(truth[0] - truth[1]) <= 1e-9 * truth[0]  # to rounding
    assert list(yard[0]["global_relative_error"]) == [v.name for v in runs[0].validations]
    for r, y in zip(runs, yard):  # every set scored is on it, the main estimate and the description's included
        assert {r.main, r.diagnostics["nominal_set"], "truth"} <= set(y["mean_global_relative_error"])
        assert r.main in y["global_relative_error"]["validation"]


def test_the_verdict_weighs_the_yardstick_and_validate_scores_on_it(tmp_path, monkeypatch):
    """The one verdict weighs every candidate's figures on the yardstick (not the settings' own), and
    ``dynid validate --yardstick`` on the results scores each set as results.json's ``diagnostics.yardstick`` does:
    two routes to one figure."""
    import json

    from typer.testing import CliRunner

    import dynid.identification.evidence as evidence
    import dynid.identification.verdict as verdict
    from dynid.cli.app import app
    from tests.simulated_logs import simulated_case

    cfg, _ = simulated_case(tmp_path, "er16", 125.0, "fourier", duration=10.0)
    cfg.write_text(cfg.read_text().replace('estimators = ["ols"]', 'estimators = ["ols", "sdp"]'))
    made, weighed = [], []
    real_scores, real_mean = evidence.yardstick_scores, verdict._mean_error

    def scores(*args, **kwargs):
        made.append(real_scores(*args, **kwargs))
        return made[-1]

    def mean(validations, label):
        weighed.append(validations)
        return real_mean(validations, label)

    monkeypatch.setattr(evidence, "yardstick_scores", scores)
    monkeypatch.setattr(verdict, "_mean_error", mean)
    out = tmp_path / "out"
    assert CliRunner().invoke(app, ["identify", str(cfg), "--out", str(out), "--no-figures", "-q"]).exit_code == 0
    every = {id(c) for one in made[0] for c in one}  # each log under each state filter, nothing else
    assert len(made) == 1 and len(made[0]) == 3 and weighed and all({id(c) for c in v} == every for v in weighed)
    identified = json.loads((out / "results.json").read_text())
    yard = identified["diagnostics"]["yardstick"]["global_relative_error"]["validation"]
    checked = tmp_path / "checked"
    result = CliRunner().invoke(app, ["validate", str(cfg), "--results", str(out / "results.json"), "--out", str(checked),
                                      "--yardstick"])
    assert result.exit_code == 0, result.output
    assert "on one yardstick" in " ".join(result.output.split())
    scored = json.loads((checked / "validation.json").read_text())["validation"][0]["metrics"]
    for label in ("dynid OLS", "dynid SDP", "truth"):
        np.testing.assert_allclose(scored[label]["global_relative_error"], yard[label], rtol=1e-9)


def test_logs_at_rest_throughout_do_not_dilute_the_yardstick_headline(shipped_identification):
    """The UR10e's validation logs are one motion (ptp_10_points) and ten static holds, each scored as the distance to
    the static-friction band (0 for a set inside it). The mean over all eleven is about a tenth of the motion's
    error; the yardstick also gives the mean over the logs that move, and the terminal's line quotes that one, with
    how many rests each set keeps within the band."""
    from dynid.report.summaries import in_short
    from dynid.validation.torques import rests_throughout

    r = shipped_identification("ur10e")
    yard = r.diagnostics["yardstick"]
    moving = [v.name for v in r.validations if not rests_throughout(v.rest_share)]
    assert moving == ["ptp_10_points"] and len(r.validations) == 11
    per_log = yard["global_relative_error"]
    over = yard["mean_over_logs_that_move"]
    assert over["logs"] == moving
    for label in (r.main, r.diagnostics["nominal_set"]):
        assert over[label] == per_log["ptp_10_points"][label]
        assert over[label] > 5 * yard["mean_global_relative_error"][label]  # the rests' zeros dilute the all-logs mean
    rests = [per_log[name] for name in per_log if name not in moving]
    kept = sum(e[r.main] == 0 for e in rests)
    line = next(b.text for b in in_short(r) if b.text.startswith("on one yardstick"))
    assert f"{r.main} {over[r.main]:.3g} %" in line and "over the one log that moves" in line
    assert f"of the 10 at rest throughout, within the static-friction band: {r.main} on {kept}" in line


def test_the_yardstick_scores_the_torques_as_measured(tmp_path):
    """On a log whose measured torques carry white noise, the truth's error on the one yardstick is the noise's share
    of the torque, under every state filter: the noise, which no model predicts, is not filtered away (a yardstick
    that low-passed the torques scored the truth at 28 % of it). The noise is measured independently from the
    log's second differences (white noise: var(Δ²τ) = 6σ²)."""
    from dynid.io.config.identification_config import load_identification_config
    from dynid.io.logs.datasets import load_recording
    from tests.simulated_logs import simulated_case

    cfg, _ = simulated_case(tmp_path, "er16", 125.0, "fourier", duration=10.0, current_std=0.5)
    config = load_identification_config(cfg)
    tau = np.asarray(load_recording(config.validation[0], config.robot).tau, dtype=float)
    sigma = np.std(np.diff(tau, 2, axis=0), axis=0) / np.sqrt(6.0)
    floor = 100.0 * np.sqrt(np.sum(sigma**2) / np.mean(np.sum(tau**2, axis=1)))
    assert floor > 2.0  # the noise dominates what the state filters and the drive model leave
    r = _identify(cfg)
    shown = r.diagnostics["yardstick"]["mean_global_relative_error"]["truth"]
    assert 0.9 * floor <= shown <= 1.25 * floor, (shown, floor)
    filters = r.diagnostics["yardstick"]["filters"]
    assert [f["cutoff_factor"] for f in filters] == [1.0, 0.5, 2.0]
    for f in filters:
        truth = f["mean_global_relative_error"]["truth"]
        assert 0.9 * floor <= truth <= 1.25 * floor, (truth, floor)


def test_the_verdict_chooses_what_predicts_the_raw_torques_on_a_real_window(tmp_path):
    """The UR10e's identification log cut to rows 1060-1560: scored on ptp_10_points' raw measured torques (states
    low-passed at 5 Hz, torques untouched), least squares predicts 8.3 %, the SDP 8.8 %, the description's rigid body
    with the drive terms fitted 11.9 %. The verdict weighed a mean with ten static holds (the distance to the
    static-friction band, another unit) and a filtered torque, and handed on the drive-only estimate (1.43× the best);
    it now hands on one within 5 % of the best candidate."""
    import re
    from pathlib import Path

    from dynid.identification.estimates import DRIVE_ONLY_LABEL
    from dynid.identification.evidence import NOMINAL_LABEL
    from dynid.identification.run import run_identification
    from dynid.io.config.identification_config import load_identification_config
    from dynid.io.logs.datasets import load_recording
    from dynid.preprocessing.preparation import prepare
    from dynid.preprocessing.settings import Preprocessing
    from dynid.validation.torques import compare_torques
    from tests.conftest import shared_data

    root = shared_data("ur10e_mamedov2020")
    repo = Path(__file__).resolve().parents[2]
    text = (repo / "configs" / "ur10e.toml").read_text()
    text = re.sub(r'^robot = "(.*)"$', lambda m: f'robot = "{(repo / "configs" / m.group(1)).resolve()}"'
                  if (repo / "configs" / m.group(1)).is_file() else m.group(0), text, flags=re.M)
    text = text.replace("rows = [635, 3510]", "rows = [1060, 1560]", 1)
    cfg = tmp_path / "window.toml"
    cfg.write_text(text)
    config = load_identification_config(cfg, data_root=root)
    r = run_identification(config)
    sets = {label: e.params for label, e in r.estimates.items()}
    sets[NOMINAL_LABEL] = r.base.base_from_standard(r.model.standard_parameters())
    sets[DRIVE_ONLY_LABEL] = r.drive_only.params
    spec = next(s for s in config.validation if s.name == "ptp_10_points")
    raw = Preprocessing(position_cutoff=5.0, velocity_cutoff=5.0, parallel_cutoff=0.0, decimation=1, trim=0.6, min_speed=0.0)
    data = prepare(load_recording(spec, config.robot), raw, strict=False)
    errors = {k: m["global_relative_error"] for k, m in compare_torques(r.model, r.base, data, sets).metrics().items()}
    main = errors[r.main] if r.main in errors else errors[DRIVE_ONLY_LABEL]
    assert main <= 1.05 * min(errors.values()), (r.main, errors)


def test_a_ranking_that_hangs_on_the_state_filter_is_said():
    """The finding appears where another candidate beats the main estimate by more than 2 % under one state filter,
    and is withdrawn where the candidates stay within 2 % (the TX40's three within 0.1 % of each other) or the main
    estimate is best under every filter."""
    from dynid.identification.verdict import _ranking_finding

    def filters(*means):
        return [{"cutoff_factor": k, "mean_global_relative_error": m, "best": min(m, key=m.get)}
                for k, m in zip((1.0, 0.5, 2.0), means)]

    split = filters({"A": 10.0, "B": 11.0}, {"A": 10.0, "B": 11.0}, {"A": 12.0, "B": 10.0})
    found = _ranking_finding(split, "A")
    assert len(found) == 1 and found[0].kind == "yardstick" and "at 2× the cutoffs B 10 % against 12 % for A" in found[0].text
    assert _ranking_finding(filters({"A": 15.63, "B": 15.64}, {"A": 15.86, "B": 15.87}, {"A": 15.77, "B": 15.75}), "A") == ()
    assert _ranking_finding(filters({"A": 10.0, "B": 11.0}, {"A": 10.0, "B": 11.0}, {"A": 10.0, "B": 10.5}), "A") == ()
    # one candidate better under every filter (the zoo's Kinova Jaco 2 Fourier log: the drive-only set 1.73-1.93 %
    # against the SDP's 1.82-2.02 %): the logs agree, and the finding says why the main estimate stays, not that the
    # logs do not settle it
    from dynid.identification.estimates import DRIVE_ONLY_LABEL

    agreed = filters({"SDP": 1.82, DRIVE_ONLY_LABEL: 1.73}, {"SDP": 2.02, DRIVE_ONLY_LABEL: 1.93},
                     {"SDP": 1.86, DRIVE_ONLY_LABEL: 1.76})
    (found,) = _ranking_finding(agreed, "SDP")
    assert "differently" not in found.text and "do not settle" not in found.text
    assert found.text.startswith(f"{DRIVE_ONLY_LABEL} predicts the validation logs better than SDP with their states "
                                 "filtered at every cutoff") and "rigid body is doubtful" in found.text
    for k in ("1", "0.5", "2"):
        assert f"at {k}× the cutoffs {DRIVE_ONLY_LABEL}" in found.text
    # least squares physically consistent, the SDP better under every filter (the zoo's SCARA with a dead channel):
    # the SDP is weighed against it only where it is not
    from dynid.identification.estimates import SDP_LABEL

    (sdp,) = _ranking_finding(filters({SDP_LABEL: 40.2, "WLS": 41.1}, {SDP_LABEL: 40.4, "WLS": 41.3},
                                      {SDP_LABEL: 40.1, "WLS": 41.1}), "WLS")
    assert "differently" not in sdp.text and sdp.text.startswith(f"{SDP_LABEL} predicts the validation logs better") \
        and f"weighs {SDP_LABEL} against it only where it is not" in sdp.text
    (other,) = _ranking_finding(filters({"SDP": 1.9, "WLS": 1.8}, {"SDP": 2.1, "WLS": 2.0}, {"SDP": 1.9, "WLS": 1.8}), "SDP")
    assert "differently" not in other.text and "WLS predicts the validation logs better than SDP" in other.text \
        and "the verdict's rules kept it" in other.text

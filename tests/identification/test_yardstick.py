"""The one yardstick (issue "Never worse than the description", item 5): a validation figure that does not depend on
the identification's settings."""

from __future__ import annotations

import re

import numpy as np


def _identify(cfg, preprocessing: str = ""):
    from dynid.identification.run import run_identification
    from dynid.io.identification_config import load_identification_config

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
    assert len(made) == 1 and weighed and all(v is made[0] for v in weighed)
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


def test_logs_at_rest_throughout_do_not_dilute_the_yardstick_headline():
    """The UR10e's validation logs are one motion (ptp_10_points) and ten static holds, each scored as the distance to
    the static-friction band (0 for a set inside it). The mean over all eleven is about a tenth of the motion's
    error; the yardstick also gives the mean over the logs that move, and the terminal's line quotes that one, with
    how many rests each set keeps within the band."""
    from pathlib import Path

    from dynid.identification.run import run_identification
    from dynid.io.identification_config import load_identification_config
    from dynid.report.summaries import in_short
    from dynid.validation.torques import rests_throughout
    from tests.conftest import shared_data

    repo = Path(__file__).resolve().parents[2]
    cfg = load_identification_config(repo / "configs" / "ur10e.toml", data_root=shared_data("ur10e_mamedov2020"))
    r = run_identification(cfg)
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

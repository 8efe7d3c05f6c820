"""A setting keeps its meaning between releases (issue "Safe and stable", item 2; "Honest on any log", item 5): a
decimation the config gives is every log's, as it was before the validation logs had settings of their own."""

import json

from ..cli.refusals import dynid
from ..simulated_logs import simulated_case


def test_a_given_decimation_is_the_validation_logs_too(tmp_path):
    """parallel_cutoff = 0 and decimation = 10 on a noisy 1 kHz log: its anti-aliasing filter is the only filter of
    the torques. Scored as a validation log, the identification log itself must give the fit's figure (the same
    samples, filtered and decimated alike); since the per-dataset settings dropped the given decimation, validation
    logs were scored on raw samples and the same log scored several times worse than its own fit."""
    cfg, robot = simulated_case(tmp_path, "er16", 1000.0, "fourier", seed=4, duration=20.0, current_std=0.2)
    text = cfg.read_text()
    cfg.write_text(text.replace("[estimation]", "[preprocessing]\nparallel_cutoff = 0\ndecimation = 10\n\n[estimation]", 1))
    p = dynid("identify", cfg, "--out", tmp_path / "out", "--no-figures", "-q")
    assert p.returncode == 0, p.stderr
    results = json.loads((tmp_path / "out" / "results.json").read_text())
    fit = results["identification"]["metrics"]["dynid OLS"]["global_relative_error"]
    # a config's validation log that repeats the identification log is left out: dynid validate scores it on request
    p = dynid("validate", cfg, "--results", tmp_path / "out" / "results.json", "--file", tmp_path / "ident.csv",
              "--out", tmp_path / "again", "-q")
    assert p.returncode == 0, p.stderr
    validated = json.loads((tmp_path / "again" / "validation.json").read_text())
    again = validated["validation"][0]["metrics"]["dynid OLS"]["global_relative_error"]
    assert abs(again - fit) < 0.02 * fit, (fit, again)

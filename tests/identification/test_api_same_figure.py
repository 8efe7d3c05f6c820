"""The API gives the CLI's figure for the same log (issue "Nothing runs, nothing silent", item 5): a fitted model keeps
the samples ``dynid validate`` keeps, with the settings as the config gave them (a given decimation included), and
``relative_error`` returns the figure the CLI prints."""

from __future__ import annotations

import json
import re

import numpy as np


def test_a_given_decimation_keeps_the_clis_samples_and_relative_error_is_its_figure(tmp_path):
    from dynid.identification.identified import load_results
    from dynid.io.datasets import load_recording
    from dynid.io.identification_config import load_identification_config
    from tests.cli.refusals import dynid
    from tests.simulated_logs import simulated_case

    cfg, _ = simulated_case(tmp_path, "ur10e", 100.0, "fourier", duration=10.0)
    cfg.write_text(re.sub(r"^\[estimation\]", "[preprocessing]\ndecimation = 4\n[estimation]", cfg.read_text(), count=1,
                          flags=re.M))
    assert dynid("identify", cfg, "--out", tmp_path / "out", "--no-figures", "-q").returncode == 0
    assert dynid("validate", cfg, "--results", tmp_path / "out" / "results.json", "--out", tmp_path / "val",
                 "-q").returncode == 0
    cli = json.loads((tmp_path / "val" / "validation.json").read_text())["validation"][0]
    model = load_results(tmp_path / "out" / "results.json")
    config = load_identification_config(cfg)
    recording = load_recording(config.validation[0], config.robot)
    api = model.validate(recording)
    assert api.t.shape[0] == cli["n_samples"]  # 180 against 225 before: the given decimation was dropped
    label = model.label()
    np.testing.assert_allclose(model.relative_error(recording), cli["metrics"][label]["global_relative_error"], rtol=1e-12)
    np.testing.assert_allclose(api.metrics()[label]["global_relative_error"],
                               cli["metrics"][label]["global_relative_error"], rtol=1e-12)

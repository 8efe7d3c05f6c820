"""validate_sets scores read logs: a generator's are read one at a time, as each is scored; a log not read is refused
in one line."""

from __future__ import annotations

import numpy as np
import pytest


def test_validate_sets_reads_a_generator_one_log_at_a_time_and_refuses_a_log_not_read(tmp_path):
    from dynid.dynamics.base_parameters import base_parameters
    from dynid.identification.evidence import validate_sets
    from dynid.io.config.identification_config import load_identification_config
    from dynid.io.logs.datasets import load_recording
    from tests.simulated_logs import simulated_case

    cfg, _ = simulated_case(tmp_path, "er16", 125.0, "fourier", duration=6.0)
    config = load_identification_config(cfg)
    base = base_parameters(config.robot, rng=0)
    sets = {"nominal": base.base_from_standard(config.robot.standard_parameters())}
    spec = config.validation[0]
    events: list[str] = []

    def logs():
        for k in range(2):  # the same log twice: two logs to score
            events.append(f"read {k}")
            yield load_recording(spec, config.robot)

    def progress(step, done, total):
        events.append("scoring")

    scored, _ = validate_sets(config, base, sets, logs(), progress=progress)
    assert [c.name for c in scored] == [spec.name, spec.name]
    # the second log is read after the first one was scored, not before (not all read first)
    assert events[0] == "read 0" and "scoring" in events[:events.index("read 1")]
    first, second = (c.metrics()["nominal"]["global_relative_error"] for c in scored)
    assert np.isfinite(first) and first == second  # the same log, the same figure
    with pytest.raises(TypeError, match=r"validate_sets: expected read logs \(dynid.load_recording"):
        validate_sets(config, base, sets, config.validation)


def test_run_validation_takes_a_log_read_already_as_its_config_dataset(tmp_path):
    """run_validation(datasets=...) scores a Recording read already as it scores the DatasetSpec it was read from
    (benchmarks/read_otherwise.py gives it logs changed after the read)."""
    import json

    from dynid.identification.run import run_identification, run_validation
    from dynid.io.config.identification_config import load_identification_config
    from dynid.io.logs.datasets import load_recording
    from dynid.report.identification_run import save_identification
    from tests.simulated_logs import simulated_case

    cfg, _ = simulated_case(tmp_path, "er16", 125.0, "fourier", duration=6.0)
    config = load_identification_config(cfg)
    save_identification(run_identification(config, validate=False), tmp_path / "out", figures_too=False)
    stored = json.loads((tmp_path / "out" / "results.json").read_text())
    spec = config.validation[0]
    (by_spec,), _ = run_validation(config, stored, datasets=(spec,))
    (by_log,), _ = run_validation(config, stored, datasets=(load_recording(spec, config.robot),))
    assert by_log.name == by_spec.name
    for label, m in by_spec.metrics().items():
        assert np.isfinite(m["global_relative_error"])
        np.testing.assert_array_equal(by_log.metrics()[label]["relative_error"], m["relative_error"])

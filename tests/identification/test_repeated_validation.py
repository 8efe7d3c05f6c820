"""A validation log that repeats the identification log's samples is left out of the validation, with a warning: its
figures would be the fit's, and the verdict would weigh them as a test of other motions."""

import json

import numpy as np

from dynid.io.logs.datasets import Recording
from dynid.io.logs.log_repairs import repeated_share

from ..cli.refusals import dynid


def _log(q):
    return Recording("log", np.arange(len(q)) * 0.01, q, None, np.zeros_like(q), 100.0)


def test_the_share_of_a_logs_positions_that_are_the_references_rows(rng):
    q = np.cumsum(rng.normal(0, 0.01, (3000, 6)), axis=0)
    reference = _log(q)
    assert repeated_share(reference, _log(q.copy())) == 1.0
    assert repeated_share(reference, _log(q[1000:2000])) == 1.0  # a window inside it
    assert repeated_share(reference, _log(q + 1e-12)) == 0.0  # another recording of the same motion
    half = np.concatenate([q[:500], q[:500] + 0.3])
    assert abs(repeated_share(reference, _log(half)) - 0.5) < 0.05
    rest = np.repeat(q[:5], 600, axis=0)  # a log at rest on rows of the reference: too few distinct rows to judge
    assert repeated_share(reference, _log(rest)) == 0.0


def test_a_validation_log_that_is_the_identification_log_is_left_out_and_said(tmp_path):
    """``[[validation]] file = "identification.csv"``: dynid scored the fit again as a validation (0.189 %, "at the
    noise floor") and said "model ready". The log is left out with a warning, and the first line asks for validation
    logs of other motions, as without any."""
    assert dynid("example", "ur10e", tmp_path / "try", "-q").returncode == 0
    config = tmp_path / "try" / "ur10e.toml"
    config.write_text(config.read_text().replace('file = "validation.csv"', 'file = "identification.csv"'))
    p = dynid("identify", config, "--out", tmp_path / "out", "--no-figures")
    assert p.returncode == 0, p.stderr
    said = " ".join((p.stdout + p.stderr).split())
    assert ("warning: validation: 100 % of its sampled positions are samples of the identification log: left out of "
            "the validation") in said
    assert "model ready to check" in said and "add [[validation]] logs (other motions)" in said
    results = json.loads((tmp_path / "out" / "results.json").read_text())
    assert results.get("validation", []) == []
    # beside a log of other motions: that one is kept, and scored as without the repeat
    config.write_text(config.read_text() + '\n[[validation]]\nname = "other"\nfile = "validation.csv"\n')
    p = dynid("identify", config, "--out", tmp_path / "both", "--no-figures")
    assert p.returncode == 0, p.stderr
    both = json.loads((tmp_path / "both" / "results.json").read_text())
    assert [v["name"] for v in both["validation"]] == ["other"]
    assert "model ready:" in " ".join(p.stdout.split())

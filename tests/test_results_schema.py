"""Every command's JSON output validates against the schema shipped in the package."""

import json
from importlib import resources

import pytest

from .cli.test_cli import dynid

jsonschema = pytest.importorskip("jsonschema")


def _validator():
    schema = json.loads((resources.files("dynid") / "schema" / "results.schema.json").read_text(encoding="utf-8"))
    jsonschema.Draft202012Validator.check_schema(schema)
    return jsonschema.Draft202012Validator(schema)


def _check(path, kind):
    data = json.loads(path.read_text())
    errors = [f"{'/'.join(map(str, e.path))}: {e.message}" for e in _validator().iter_errors(data)]
    assert not errors, errors[:5]
    assert data["kind"] == kind and data["schema_version"] == 2


def test_run_identify_validate_excite_and_montecarlo_outputs_follow_the_schema(tmp_path):
    from .simulated_logs import simulated_case

    p = dynid("run", "--estimators", "ols,abc", "--bootstrap", "0", "--duration", "4", "--no-figures", "--out", str(tmp_path / "run"))
    assert p.returncode == 0, p.stderr
    _check(tmp_path / "run" / "results.json", "run")
    cfg, _ = simulated_case(tmp_path, "er16", 125.0, "fourier", duration=20.0)
    p = dynid("identify", str(cfg), "--no-figures", "--out", str(tmp_path / "id"))
    assert p.returncode == 0, p.stderr
    _check(tmp_path / "id" / "results.json", "identify")
    p = dynid("validate", str(cfg), "--results", str(tmp_path / "id" / "results.json"), "--out", str(tmp_path / "val"))
    assert p.returncode == 0, p.stderr
    _check(tmp_path / "val" / "validation.json", "validate")
    p = dynid("montecarlo", "--realisations", "2", "--noise-levels", "0.05", "--estimators", "ols", "--duration", "4",
              "--rate", "100", "--workers", "1", "--out", str(tmp_path / "mc"))
    assert p.returncode == 0, p.stderr
    _check(tmp_path / "mc" / "montecarlo.json", "montecarlo")


def test_excite_output_follows_the_schema(tmp_path):
    from pathlib import Path

    repo = Path(__file__).resolve().parents[1]
    p = dynid("excite", str(repo / "configs" / "excite-er16.toml"), "--starts", "1", "--out", str(tmp_path / "ex"))
    assert p.returncode == 0, p.stderr
    _check(tmp_path / "ex" / "excitation.json", "excite")
    html = (tmp_path / "ex" / "report.html").read_text()
    # the joints, the tool path, and (the config has a floor) how close the links come to it
    assert "Before / after" in html and "Constraint margins" in html and html.count("data:image/png;base64,") == 3
    assert "How close the links come to the floor and the cell" in html

"""The one verdict (issue "Never worse than the description", item 1): one function chooses the main estimate, on
evidence that uses no validation torque."""

import ast
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from dynid.identification.verdict import expected_errors

SRC = Path(__file__).resolve().parents[2] / "src" / "dynid"


def test_one_function_sets_the_main_estimate():
    """A result's ``main`` is given in two places only: identify's default (the first estimator listed) and
    :func:`dynid.identification.verdict.choose_main_estimate`; a second chooser anywhere fails this test."""
    setters = []
    for path in SRC.rglob("*.py"):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, ast.Call) and any(k.arg == "main" for k in node.keywords):
                setters.append((path.relative_to(SRC).as_posix(), ast.unparse(next(k.value for k in node.keywords
                                                                                  if k.arg == "main"))))
    assert sorted(setters) == [("identification/identify.py", "estimate_label(keys[0])"),
                               ("identification/verdict.py", "main")]


def test_the_expected_error_adds_the_prediction_variance_on_the_validation_states():
    """sqrt(Σ fit_rmse² + Σ spread²) per log, averaged; a fixed model (no spread label) has its fit residual only."""
    logs = [SimpleNamespace(spread={"ls": np.array([6.0, 8.0])}), SimpleNamespace(spread={"ls": np.array([0.0, 0.0])})]
    fit = {"ls": np.array([0.0, 0.0]), "nominal": np.array([2.0, 2.0])}
    out = expected_errors(fit, {"ls": "ls", "nominal": None}, logs)
    assert np.isclose(out["ls"], (10.0 + 0.0) / 2)
    assert np.isclose(out["nominal"], np.sqrt(8.0))
    # the least-squares fit is perfect on its log, but the variance on the first log's motion makes the nominal win
    assert min(out, key=out.get) == "nominal"


def test_the_description_itself_is_the_main_estimate_where_nothing_beats_it(tmp_path, monkeypatch):
    """Where the description's nominal model has the smallest expected error, it is the main estimate: its base
    parameters are the description's, the first finding says to keep the robot file's values, and the first line,
    results.json and the validation figures name the same set."""
    import json

    import dynid.identification.verdict as verdict
    from dynid.identification.run import run_identification
    from dynid.io.identification_config import load_identification_config
    from dynid.report.output import write_results
    from dynid.report.summaries import identification_brief
    from dynid.tables import render_text
    from tests.simulated_logs import simulated_case

    real = verdict.expected_errors

    def nominal_best(fit_rmse, spreads, validations):  # the evidence as if the log could improve nothing
        out = real(fit_rmse, spreads, validations)
        out[next(k for k, v in spreads.items() if v is None)] = 0.0
        return out

    monkeypatch.setattr(verdict, "expected_errors", nominal_best)
    cfg, _ = simulated_case(tmp_path, "er16", 125.0, "fourier", duration=10.0, mass_scale=1.3)
    result = run_identification(load_identification_config(cfg))
    nominal = result.diagnostics["nominal_set"]
    assert result.main == nominal
    described = result.base.base_from_standard(result.model.standard_parameters())
    np.testing.assert_allclose(result.main_estimate.params, described, rtol=1e-12, atol=1e-12)
    np.testing.assert_array_equal(result.main_estimate.standard, result.model.standard_parameters())  # what export writes
    main = next(f for f in result.findings if f.kind == "main")
    assert main.text.startswith(f"main estimate: {nominal}: keep your robot file's values")
    write_results(tmp_path / "results.json", result.to_dict(), "identify")  # as dynid identify writes it
    assert json.loads((tmp_path / "results.json").read_text())["main_estimate"] == nominal
    first = render_text(identification_brief(result), 400).splitlines()[0]
    assert nominal in first
    assert all(nominal in v.metrics() for v in result.validations)  # its figures are the description's own

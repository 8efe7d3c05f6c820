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

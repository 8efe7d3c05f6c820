"""The benchmark scripts import what exists: every name a script under benchmarks/ imports from dynid or from the tests
is there (a script that stopped importing when a module moved — benchmarks/independent_check.py still imported
``tests.experiment`` after that package became ``tests.identification`` — fails here, not when someone runs it)."""

import ast
import importlib
from pathlib import Path

import pytest

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"


def _imports(path: Path):
    """``(line, module, names)`` of every import from dynid or the tests in a script, wherever it stands."""
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        ours = (getattr(node, "module", None) or "").split(".")[0] in ("dynid", "tests")
        if isinstance(node, ast.ImportFrom) and node.level == 0 and ours:
            yield node.lineno, node.module, [a.name for a in node.names]
        elif isinstance(node, ast.Import):
            for a in node.names:
                if a.name.split(".")[0] in ("dynid", "tests"):
                    yield node.lineno, a.name, []


def _missing(path: Path) -> list[str]:
    out = []
    for line, module, names in _imports(path):
        try:
            imported = importlib.import_module(module)
        except ImportError as exc:
            out.append(f"{path.name}:{line}: {module}: {exc}")
            continue
        out += [f"{path.name}:{line}: {module} has no {name}" for name in names
                if not hasattr(imported, name) and importlib.util.find_spec(f"{module}.{name}") is None]
    return out


SCRIPTS = sorted(BENCHMARKS.rglob("*.py"))


def test_there_are_scripts_to_check():
    assert len(SCRIPTS) >= 10, SCRIPTS


@pytest.mark.parametrize("path", SCRIPTS, ids=lambda p: str(p.relative_to(BENCHMARKS)))
def test_every_import_of_a_benchmark_script_exists(path):
    assert _missing(path) == []


def test_the_check_sees_a_moved_module_and_a_missing_name(tmp_path):
    script = tmp_path / "old.py"
    script.write_text("def main():\n    from tests.experiment.test_independent_check import _case\n"
                      "from dynid.estimators import no_such_estimator\nfrom dynid.estimators import registry\n")
    missing = sorted(_missing(script))
    assert len(missing) == 2 and "tests.experiment" in missing[0] and "no_such_estimator" in missing[1], missing

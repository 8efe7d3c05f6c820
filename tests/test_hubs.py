"""No function of the package calls more than 12 distinct dynid functions and classes (issue "One route, four named
parts", target: none on the identification route; `benchmarks/structure.py` measures it from the source, and this test
keeps it so: four functions had grown back to 13 without anything saying so)."""

import importlib.util
from pathlib import Path

import dynid

ROOT = Path(__file__).resolve().parents[1]


def _structure():
    spec = importlib.util.spec_from_file_location("structure", ROOT / "benchmarks" / "structure.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_hub_count_sees_a_function_that_calls_thirteen(tmp_path):
    """The measure itself against a package built to have one hub of 13 and one function of 12."""
    names = [f"f{k}" for k in range(13)]
    defs = "".join(f"def {n}():\n    return {k}\n\n\n" for k, n in enumerate(names))
    calls = lambda fn, called: f"def {fn}():\n    return " + " + ".join(f"{n}()" for n in called) + "\n\n\n"  # noqa: E731
    (tmp_path / "m.py").write_text(defs + calls("hub", names) + calls("not_a_hub", names[:12]), encoding="utf-8")
    found = _structure().hubs(tmp_path)
    assert found == [(13, "m.py:hub")]


def test_no_function_calls_more_than_twelve_distinct_dynid_functions():
    structure = _structure()
    assert structure.HUB == 13
    found = structure.hubs(Path(dynid.__file__).parent)
    assert not found, "functions calling 13 or more distinct dynid functions (split them into named steps): " + ", ".join(
        f"{name} ({n})" for n, name in found)

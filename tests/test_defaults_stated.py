"""Every default the prose states (docstrings, comments, messages, the docs and the README) is the number the code uses:
a default restated as a number is checked against its constant here, so changing a constant without its restatements
fails (issue 23 found docstrings saying 5× the band where the code filtered at 10×)."""

import re
from pathlib import Path

import pytest

from dynid.preprocessing import bands

ROOT = Path(__file__).resolve().parents[1]
NUMBER = r"(\d+(?:\.\d+)?)"
STATEMENTS = [
    # (pattern whose group 1 is the number, what it must equal, the constant's name)
    (NUMBER + r"\s*(?:×|x|·)\s*(?:the\s+)?(?:excitation\s+)?band\b", {bands.POSITION_FACTOR, bands.PARALLEL_FACTOR},
     "POSITION_FACTOR / PARALLEL_FACTOR"),
    (NUMBER + r"\s*·\s*f_exc\b", {bands.POSITION_FACTOR, bands.PARALLEL_FACTOR}, "POSITION_FACTOR / PARALLEL_FACTOR"),
    (NUMBER + r"\s*%\s+of\s+(?:each|the|its)\s+joint'?s?\s+RMS\s+speed", {100 * bands.MIN_SPEED_FRACTION}, "MIN_SPEED_FRACTION"),
    (NUMBER + r"\s*(?:×|x)\s+(?:the\s+|its\s+|each\s+joint's\s+)?RMS\s+speed", {bands.MIN_SPEED_FRACTION}, "MIN_SPEED_FRACTION"),
    (NUMBER + r"\s*(?:×|x)\s+its\s+velocity's\s+noise", {bands.REST_FACTOR}, "REST_FACTOR"),
    (NUMBER + r"\s*σ\s+of\s+the\s+noise", {bands.REST_FACTOR}, "REST_FACTOR"),
]


def _texts():
    files = [*sorted((ROOT / "src" / "dynid").rglob("*.py")), *sorted((ROOT / "docs").rglob("*.md")), ROOT / "README.md",
             *sorted((ROOT / "src" / "dynid" / "schema").glob("*.json"))]
    return [(f, f.read_text(encoding="utf-8")) for f in files]


def statements_against_constants(texts) -> list[str]:
    """Every restated default that differs from its constant, as ``file:line: text (constant)``."""
    bad = []
    for path, text in texts:
        flat = re.sub(r"\s+", " ", text.replace("``", "").replace("`", ""))
        for pattern, allowed, name in STATEMENTS:
            for m in re.finditer(pattern, flat):
                if float(m.group(1)) not in allowed:
                    bad.append(f"{Path(path).name}: '{m.group(0)}' ({name} = {sorted(allowed)})")
    return bad


def test_every_restated_default_is_the_codes_own():
    assert statements_against_constants(_texts()) == []


@pytest.mark.parametrize("text", ["cutoff at f_p = 5·f_exc", "(default 5× band)", "5x band", "3 % of each joint's RMS speed",
                                  "2x its velocity's noise", "below 4σ of the noise"])
def test_the_check_sees_a_default_restated_wrongly(text):
    assert statements_against_constants([("x.py", text)]) != []

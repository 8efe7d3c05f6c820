"""The compatibility corpus figure by figure (issue "Safe and stable", item 2): each earlier release's own figures
(``tests/data/compat/figures.json``, measured by ``benchmarks/compat_figures.py --record`` with that release's code
in a git worktree, on the real logs) against today's on the same config. A figure may move by 1 %; a larger move must be
one the changelog names (its entry is looked up in docs/changelog.md; each was found by bisecting the move), and then
stay within 1 % of the figure recorded with it. A new move fails: no release changes a figure without a word (an
intended one is a changelog entry here and figures.json recorded again)."""

import json
import re
import shutil
from pathlib import Path

import pytest

from dynid.identification.run import run_identification
from dynid.io.config.identification_config import load_identification_config
from dynid.io.config.migrate import migrate_text

from ..conftest import shared_data
from ..results_figures import global_errors

REPO = Path(__file__).resolve().parents[2]
RECORDED = json.loads((REPO / "tests" / "data" / "compat" / "figures.json").read_text(encoding="utf-8"))
CHANGELOG = (REPO / "docs" / "changelog.md").read_text(encoding="utf-8")
TOLERANCE = 0.01
"""Relative move of a figure that needs no word."""

CHECKED = ["kuka_kr300@d8c8501", "kuka_med7@d8c8501", "tx40@d8c8501", "tx40-full@d8c8501", "ur10e@d8c8501"]
"""The suite's share of the corpus: each config's last version of an earlier release (the benchmark runs them all)."""

BAND = "**Rests are scored against the static-friction band.**"
PADDING = "**The parallel filter pads a log's ends by mirror extension**"
EXPLAINED = [
    # (version, log, set: regular expressions; the changelog entry that names the change, found by bisecting)
    (r"ur10e@.*", r"p\d+|ptp_10_points", r".*", BAND),
    (r"tx40@.*", r"time split 5\.6-7\.6 s", r".*", "**`[preprocessing] decimation` is every log's again.**"),
    (r"kuka_kr300@.*", r"trajectory [BC]", r"dynid SDP", BAND),
    (r"kuka_med7@.*", r"faster run", r"URDF nominal|dynid SDP", BAND),
    (r"kuka_kr300@.*", r"trajectory B", r"dynid WLS", PADDING),
    (r"kuka_med7@.*", r"faster run", r"dynid WLS", PADDING),
    (r"kuka_med7@.*", r"identification", r"dynid SDP", PADDING),
]


def _today(version: str, tmp_path: Path) -> dict:
    """Today's figures on the corpus file of ``version``, beside today's robot descriptions, migrated if it must be."""
    text = (REPO / "tests" / "data" / "compat" / f"{version}.toml").read_text(encoding="utf-8")
    root = shared_data(re.search(r'data_root = "[^"]*/([^/"]+)"', text).group(1))
    shutil.copytree(REPO / "configs" / "robots", tmp_path / "robots")
    config = tmp_path / f"{version.split('@')[0]}.toml"
    config.write_text(migrate_text(text, str(config))[0] if RECORDED["versions"][version]["migrated"] else text,
                      encoding="utf-8")
    result = run_identification(load_identification_config(config, data_root=root), validate=True)
    return {f"{log}\t{label}": v for (log, label), v in global_errors(result.to_dict()).items()}


def test_every_explanation_is_in_the_changelog():
    for *_, entry in EXPLAINED:
        assert entry in CHANGELOG, entry


@pytest.mark.parametrize("version", CHECKED)
def test_a_config_of_an_earlier_release_gives_its_figures_or_a_named_change(version, tmp_path):
    recorded = RECORDED["versions"][version]
    now = _today(version, tmp_path)
    assert set(recorded["then"]) <= set(now), sorted(set(recorded["then"]) - set(now))
    silent = []
    for key, then in recorded["then"].items():
        log, label = key.split("\t")
        if abs(now[key] - then) <= TOLERANCE * abs(then):
            continue
        explained = any(re.fullmatch(v, version) and re.fullmatch(lg, log) and re.fullmatch(s, label)
                        for v, lg, s, _ in EXPLAINED)
        if explained and abs(now[key] - recorded["now"][key]) <= TOLERANCE * abs(recorded["now"][key]):
            continue  # the named change, and nothing since the figures were recorded
        silent.append(f"{log}, {label}: {then:.4g} % in that release, {now[key]:.4g} % today")
    assert not silent, f"{version}: figures moved without a word: {silent}"

"""Compatibility as a contract (issue "Safe and stable", item 2): every version of the real robots' configs that dynid
ever shipped (tests/data/compat: configs/*.toml at each commit that changed them, taken from git) loads today, as it
is or after ``dynid migrate``, which keeps the user's comments and layout and names what changed."""

import re
import shutil
from pathlib import Path

import pytest

from dynid.exceptions import ConfigError
from dynid.io.config.identification_config import load_identification_config
from dynid.io.config.migrate import migrate_text

from ..cli.refusals import dynid
from ..conftest import shared_data

REPO = Path(__file__).resolve().parents[2]
CORPUS = sorted((REPO / "tests" / "data" / "compat").glob("*.toml"))


def test_the_corpus_holds_every_shipped_version():
    """tests/data/compat is the git history's: one file per (config, commit), none missing."""
    import subprocess

    for config in ("ur10e", "tx40", "tx40-full", "kuka_kr300", "kuka_med7"):
        try:
            commits = subprocess.run(["git", "log", "--format=%h", "--", f"configs/{config}.toml"], cwd=REPO,
                                     capture_output=True, text=True, check=True).stdout.split()
        except (OSError, subprocess.CalledProcessError):
            pytest.fail("git history is needed to check the corpus (a clone, not an export)")
        held = {p.stem.split("@")[1] for p in CORPUS if p.stem.split("@")[0] == config}
        assert {c[:7] for c in commits} <= held | {commits[0][:7]}, config


@pytest.mark.parametrize("path", CORPUS, ids=[p.stem for p in CORPUS])
def test_every_shipped_config_loads_as_it_is_or_after_migrate(path, tmp_path):
    text = path.read_text(encoding="utf-8")
    root = shared_data(re.search(r'data_root = "[^"]*/([^/"]+)"', text).group(1))
    (tmp_path / "robots").mkdir()
    for robot in (REPO / "configs" / "robots").glob("*.toml"):
        shutil.copy(robot, tmp_path / "robots" / robot.name)
    config = tmp_path / path.name
    config.write_text(text, encoding="utf-8")
    migrated, changes = migrate_text(text, str(config))
    old = re.findall(r"^\s*(method|methods|physically_consistent|torque_cutoff)\s*=", text, flags=re.M)
    if old:
        with pytest.raises(ConfigError, match=r"(estimation\.\w+|preprocessing\.torque_cutoff): no longer exists"):
            load_identification_config(config, data_root=root)
        if "torque_cutoff" in old:
            assert any("torque_cutoff" in c and "its meaning changed" in c for c in changes)
        if set(old) - {"torque_cutoff"}:
            assert any(c.startswith("[estimation] ") and "-> estimators = [" in c for c in changes)
        p = dynid("migrate", config, "-q")
        assert p.returncode == 0, p.stderr
        assert config.read_text(encoding="utf-8") == migrated
        # only the old keys' lines changed: every comment and other line kept
        kept = [ln for ln in text.splitlines()
                if not re.match(r"^\s*(method|methods|physically_consistent|torque_cutoff)\s*=", ln)]
        assert [ln for ln in migrated.splitlines() if not re.match(r"(estimators|parallel_cutoff) = ", ln)] == kept
    else:
        assert migrated == text
    cfg = load_identification_config(config, data_root=root)
    assert cfg.estimation.estimators and cfg.robot.n_dof in (6, 7)

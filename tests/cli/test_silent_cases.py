"""Issue "Nothing runs, nothing silent", items 2-3: inputs that were read wrong without a word (or with a traceback)
are refused in one line naming what is wrong."""

from importlib import resources
from pathlib import Path

import pytest

from dynid.exceptions import ConfigError
from dynid.model.description import load_robot

from .refusals import assert_refused, dynid

URDF = Path(str(resources.files("dynid.model") / "robots" / "ur10e.urdf"))


def test_an_empty_estimator_list_is_refused(tmp_path):
    """``dynid run --estimators ''`` ran the default estimators."""
    assert_refused(dynid("run", "--estimators", "", "--out", tmp_path / "out", "-q"),
                   "estimators: expected a comma-separated subset of", tmp_path / "out", None)


@pytest.mark.parametrize("value", ["nan", "inf", "1e999"])
def test_a_non_finite_inertial_value_is_refused_naming_the_link(tmp_path, value):
    """A URDF mass or inertia of NaN was read as a massless link (Pinocchio's reading)."""
    text = URDF.read_text(encoding="utf-8")
    assert text.count('<mass value="0.202"/>') == 1
    path = tmp_path / "arm.urdf"
    path.write_text(text.replace('<mass value="0.202"/>', f'<mass value="{value}"/>'), encoding="utf-8")
    with pytest.raises(ConfigError, match=rf"arm.urdf: line \d+: link 'wrist_3_link': <mass value=\"{value}\">, "
                                          "expected finite numbers") as info:
        load_robot(path)
    assert "\n" not in str(info.value)
    path.write_text(text.replace('ixx="', 'ixx="nan" ixx_was="', 1), encoding="utf-8")
    with pytest.raises(ConfigError, match=r"<inertia ixx=\"nan\">"):
        load_robot(path)


def test_migrate_refuses_a_file_that_is_not_text(tmp_path):
    """``dynid migrate`` on a binary file raised UnicodeDecodeError with a traceback."""
    path = tmp_path / "config.toml"
    path.write_bytes(b"\x89PNG\r\n\x1a\n\x00\xff\xfe")
    before = path.read_bytes()
    assert_refused(dynid("migrate", path), "config.toml: not a text file")
    assert path.read_bytes() == before


def test_migrate_rewrites_an_inline_table(tmp_path):
    """``dynid migrate`` on ``estimation = { method = ... }`` reported a rewrite it did not make, and identify then sent
    the user back to migrate; the inline table is now rewritten (tomlkit), its comments kept."""
    import tomllib

    from dynid.io.config.migrate import migrate_text

    text = ('# my arm\nrobot = "ur10e"\nestimation = { method = "wls", physically_consistent = true }  # as in 0.1\n'
            'preprocessing = { torque_cutoff = 5.0 }\n[identification]\nfile = "log.csv"  # the run of May\n')
    migrated, changes = migrate_text(text, "arm.toml")
    doc = tomllib.loads(migrated)
    assert doc["estimation"] == {"estimators": ["wls", "sdp"]} and doc["preprocessing"] == {"parallel_cutoff": 5.0}
    assert "# my arm" in migrated and "# the run of May" in migrated
    assert any("-> estimators = [" in c for c in changes) and any("torque_cutoff" in c for c in changes)
    path = tmp_path / "arm.toml"
    path.write_text(text)
    p = dynid("migrate", path)
    assert p.returncode == 0, p.stderr
    assert tomllib.loads(path.read_text()) == doc and "wrote" in p.stdout
    # --out names a new file: an existing one (a log, the robot file) is refused and left as it was
    log = tmp_path / "log.csv"
    log.write_text("t,q1\n0,0\n")
    assert_refused(dynid("migrate", path, "--out", log), "--out")
    assert log.read_text() == "t,q1\n0,0\n"
    p = dynid("migrate", path, "--out", tmp_path / "new.toml")
    assert p.returncode == 0, p.stderr
    assert tomllib.loads((tmp_path / "new.toml").read_text()) == doc

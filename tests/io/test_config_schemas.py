"""The JSON Schemas of the input configs shipped in the package: generated from the typed structures dynid parses
with (so they cannot drift), and every config of configs/, the built-in robots and the tests' configs valid against
them by an independent validator (jsonschema); the same mistakes dynid refuses, the schema refuses."""

import json
import tomllib
from importlib import resources
from pathlib import Path

import pytest

from dynid._util.typed import json_schema
from dynid.io.config.config_types import SCHEMAS

jsonschema = pytest.importorskip("jsonschema")
REPO = Path(__file__).resolve().parents[2]


def _schema(name):
    return json.loads((resources.files("dynid") / "schema" / f"{name}.schema.json").read_text(encoding="utf-8"))


def _validator(name):
    schema = _schema(name)
    jsonschema.Draft202012Validator.check_schema(schema)
    return jsonschema.Draft202012Validator(schema)


@pytest.mark.parametrize("name", sorted(SCHEMAS))
def test_the_shipped_schema_is_the_structure_dynid_parses_with(name):
    kind, title, description = SCHEMAS[name]
    assert _schema(name) == json.loads(json.dumps(json_schema(kind, title, description))), \
        "regenerate with: python -m dynid.io.config.config_types"


def _kind(path: Path) -> str:
    doc = tomllib.loads(path.read_text(encoding="utf-8"))
    if "trajectory" in doc:
        return "excitation"
    return "identification" if "identification" in doc else "robot"


CONFIGS = sorted([*(REPO / "configs").glob("*.toml"), *(REPO / "configs" / "robots").glob("*.toml"),
                  *(Path(str(resources.files("dynid.model") / "robots")).glob("*.toml"))])


@pytest.mark.parametrize("path", CONFIGS, ids=lambda p: p.name)
def test_every_shipped_config_is_valid_against_its_schema(path):
    errors = [f"{'/'.join(map(str, e.path))}: {e.message}" for e in _validator(_kind(path)).iter_errors(tomllib.loads(path.read_text()))]
    assert not errors, errors[:5]


def test_the_tests_configs_are_valid_against_the_schema(tmp_path):
    from tests.cli.test_bad_input_corpus import CONFIG
    from tests.simulated_logs import config_text, robot_toml

    docs = [tomllib.loads(config_text(robot_toml("ur10e", tmp_path), tmp_path, "a.csv", "b.csv", 6, "[preprocessing]\nband = 1.0\n")),
            tomllib.loads(CONFIG), tomllib.loads(Path(robot_toml("er16", tmp_path)).read_text())]
    for doc, kind in zip(docs, ("identification", "identification", "robot")):
        assert not list(_validator(kind).iter_errors(doc))


BASE = 'robot = "ur10e"\ndata_root = "."\n'
IDENT = '[identification]\npreset = "ur-rtde"\nfile = "x.csv"\n'


@pytest.mark.parametrize("text, where", [
    (IDENT + "[estimation]\nseed = -1\n", "estimation.seed"),
    (IDENT + "[preprocessing]\ncutof = 3\n", "preprocessing"),
    (IDENT + '[preprocessing]\nmin_speed = "fast"\n', "preprocessing.min_speed"),
    ('[identification]\npreset = "ur-rtde"\nfile = "x.csv"\ngaps = "fill"\n', "identification.gaps"),
    ("colour = 1\n" + IDENT, "colour"),
])
def test_the_schema_refuses_what_dynid_refuses(tmp_path, text, where):
    from dynid.exceptions import ConfigError
    from dynid.io.config.identification_config import load_identification_config

    (tmp_path / "x.csv").write_text("0\n")
    (tmp_path / "c.toml").write_text(BASE + text)
    errors = list(_validator("identification").iter_errors(tomllib.loads(BASE + text)))
    assert errors  # the editor's check
    with pytest.raises(ConfigError, match=f"c.toml: .*{where.split('.')[-1]}"):  # dynid's own, one line naming the field
        load_identification_config(tmp_path / "c.toml")


def test_a_fleet_manifest_and_its_template_are_valid_against_their_schemas(tmp_path):
    from dynid.studies.simulated_fleet import simulate_fleet

    simulate_fleet(tmp_path, units=2, seconds=2.0, rate=50.0, validation_seconds=2.0, odd_unit=None)
    assert not list(_validator("fleet").iter_errors(tomllib.loads((tmp_path / "fleet.toml").read_text())))
    assert not list(_validator("identification").iter_errors(tomllib.loads((tmp_path / "unit.toml").read_text())))
    wrong = tomllib.loads((tmp_path / "fleet.toml").read_text())
    wrong["units"][0]["payload"] = -1.0  # dynid refuses it: so does the schema
    assert list(_validator("fleet").iter_errors(wrong))

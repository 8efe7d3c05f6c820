"""Nothing dynid reads from a user's folder runs code (issue "Safe and stable", item 1; docs/security.md).

Each loader that reads a user's file gets a hostile file that would leave a marker file if it ran code: the
marker must not appear and the file is refused in one line. A search of the package keeps formats that can run code
out of it."""

import pickle
import re
from pathlib import Path

import pytest

from dynid.exceptions import ConfigError

from .cli.refusals import assert_refused, dynid

SRC = Path(__file__).resolve().parents[1] / "src" / "dynid"

PIPES = {"processes.py", "report/output.py"}
"""The only modules allowed to unpickle: each reads the pipe of a child it forked itself, never a file."""


class _Marker:
    """Unpickling this creates the marker file (what a hostile pickle would do, harmlessly)."""

    def __init__(self, path):
        self.path = str(path)

    def __reduce__(self):
        return (Path.touch, (Path(self.path),))


def _hostile_pickle(marker) -> bytes:
    return pickle.dumps({"version": 1, "fingerprint": "", "monitor": _Marker(marker)})


def test_no_loader_that_runs_code_in_the_package():
    """pickle, marshal, shelve, joblib, numpy's allow_pickle, yaml.load and eval/exec appear nowhere in src/dynid but
    in the two modules that read their own children's pipes."""
    pattern = re.compile(r"\bpickle\.loads?\(|\bmarshal\.loads?\(|\bshelve\.open\(|\bjoblib\.load\(|allow_pickle\s*=\s*True"
                         r"|\byaml\.(load|unsafe_load)\(|(?<![\w.])eval\(|(?<![\w.])exec\(|dill\.|cloudpickle\.loads?\(")
    found = []
    for path in sorted(SRC.rglob("*.py")):
        rel = path.relative_to(SRC).as_posix()
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            code = line.split("#", 1)[0]
            if pattern.search(code) and not (rel in PIPES and "pickle.loads(" in code):
                found.append(f"{rel}:{n}: {line.strip()}")
    assert found == []
    for rel in PIPES:  # and those two read a pipe: os.read of a file descriptor made by os.pipe in the same module
        text = (SRC / rel).read_text(encoding="utf-8")
        assert "os.pipe()" in text and "pickle.loads(data)" in text


@pytest.fixture(scope="module")
def monitored(tmp_path_factory):
    """A robot's logs, its identification, and one monitor run that left its state."""
    from dynid.studies.simulated_fleet import simulate_service_life

    root = tmp_path_factory.mktemp("life")
    simulate_service_life(root, days=6, seconds=60.0, rate=100.0, wear_start_day=1e9, seed=5)
    p = dynid("identify", root / "unit.toml", "--out", root / "id", "--no-figures", "-q")
    assert p.returncode == 0, p.stderr
    return root


def _monitor(root, out, *extra):
    return dynid("monitor", root / "unit.toml", "--logs", root / "logs", "--results", root / "id" / "results.json",
                 "--out", out, "--reference-windows", "10", *extra)


def test_a_pickle_as_the_monitor_state_is_refused_and_never_run(monitored, tmp_path):
    marker = tmp_path / "ran"
    out = tmp_path / "m"
    out.mkdir()
    (out / "monitor-state.json").write_bytes(_hostile_pickle(marker))
    assert_refused(_monitor(monitored, out), "monitor-state.json: not a monitor state dynid can read")
    assert not marker.exists()


def test_an_earlier_pickled_state_is_never_read(monitored, tmp_path):
    """The development versions' monitor-state.pkl: refused in one line that says what to do, never unpickled;
    --restart starts over and writes the JSON state."""
    marker = tmp_path / "ran"
    out = tmp_path / "m"
    out.mkdir()
    (out / "monitor-state.pkl").write_bytes(_hostile_pickle(marker))
    assert_refused(_monitor(monitored, out), "monitor-state.pkl: a monitor state of an earlier dynid, a pickle")
    assert not marker.exists()
    p = _monitor(monitored, out, "--restart")
    assert p.returncode == 0, p.stderr
    assert not marker.exists() and (out / "monitor-state.json").is_file()


def test_a_tampered_monitor_state_is_refused_field_by_field(monitored, tmp_path):
    """The state is checked before use: an array of the wrong size, an unknown field, a term of another
    identification each refused in one line naming what is wrong."""
    import json

    out = tmp_path / "m"
    p = _monitor(monitored, out)
    assert p.returncode == 0, p.stderr
    good = json.loads((out / "monitor-state.json").read_text())
    assert good["format"] == "dynid-monitor-state" and good["version"] == 2

    def refused_with(state, message):
        (out / "monitor-state.json").write_text(json.dumps(state))
        assert_refused(_monitor(monitored, out), message)

    bad = json.loads(json.dumps(good))
    bad["mean"]["shape"] = [len(good["terms"]) + 1]
    refused_with(bad, "monitor-state.json: not a monitor state dynid can read (mean: expected")
    bad = {**good, "code": "print(1)"}
    refused_with(bad, "monitor-state.json: not a monitor state dynid can read (Object contains unknown field `code`)")
    bad = {**good, "terms": ["fv9"] + good["terms"][1:]}
    refused_with(bad, "monitor-state.json: not a monitor state dynid can read (terms")
    bad = {**good, "threshold": "os.system"}
    refused_with(bad, "not a monitor state dynid can read ('os.system' is no number)")


XACRO = """<?xml version="1.0"?>
<robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="prefix" default="a_"/>
  <xacro:property name="m" value="{value}"/>
  <link name="$(arg prefix)base"><inertial><mass value="${{m}}"/>
    <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
</robot>
"""

ESCAPES = [
    # through xacro's own guard on the code before this test: object's subclasses by a string key, a builtin module
    "${{[c for c in python.vars(python.type)['__subclasses__'](python.type(1.0).mro()[1]) if python.str(c) == "
    "&quot;&lt;class '_frozen_importlib.BuiltinImporter'&gt;&quot;][0].load_module('posix').system('touch {marker}') + 1}}",
    "${{[g for g in [(x for x in [1])]][0].gi_frame.f_globals}}",
    "${{python.type(1.0)}}",
]


@pytest.mark.parametrize("escape", ESCAPES)
def test_a_xacro_description_never_runs_code(tmp_path, monkeypatch, escape):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    from dynid.model.urdf import expand_xacro

    marker = tmp_path / "ran"
    path = tmp_path / "arm.urdf.xacro"
    path.write_text(XACRO.format(value=escape.format(marker=marker)))
    with pytest.raises(ConfigError, match=r"arm.urdf.xacro: the xacro expression .* uses '\w+', which a robot "
                                          "description may not run in dynid") as caught:
        expand_xacro(path)
    assert "\n" not in str(caught.value) and not marker.exists()


def test_plain_xacro_arithmetic_still_expands(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    from dynid.model.urdf import expand_xacro

    path = tmp_path / "arm.urdf.xacro"
    path.write_text(XACRO.format(value="${pi/2 + radians(90) + math.sqrt(4) + len([i for i in python.range(3)])}"))
    text = expand_xacro(path).read_text()
    assert '<mass value="8.141592653589793"/>' in text and 'name="a_base"' in text


def test_a_pickle_given_as_results_is_refused_and_never_run(tmp_path):
    """results.json is read as JSON: a pickle in its place is one line, not code."""
    import dynid as api
    from dynid.exceptions import DynIdError

    marker = tmp_path / "ran"
    results = tmp_path / "results.json"
    results.write_bytes(_hostile_pickle(marker))
    with pytest.raises(DynIdError, match="results.json") as caught:
        api.load_results(results, robot=api.load_robot("er16"))
    assert "\n" not in str(caught.value) and not marker.exists()


def test_a_non_finite_number_in_a_results_file_is_refused_where_it_is_read(tmp_path):
    """dynid export on a results.json whose physically consistent value is null or NaN: one line naming the field
    (a TypeError and a LinAlgError traceback before), nothing written; load_results likewise for an estimate's values."""
    import json

    import dynid as api
    from dynid.exceptions import DynIdError

    from .simulated_logs import simulated_case

    cfg, _ = simulated_case(tmp_path, "er16", 100.0, "fourier", duration=10.0)
    cfg.write_text(cfg.read_text().replace('estimators = ["ols"]', 'estimators = ["wls", "sdp"]'))
    p = dynid("identify", cfg, "--out", tmp_path / "out", "--no-figures", "-q")
    assert p.returncode == 0, p.stderr
    good = json.loads((tmp_path / "out" / "results.json").read_text())
    name = next(iter(good["estimates"]["dynid SDP"]["standard_values"]))
    for bad, said in ((None, "null"), (float("nan"), "nan")):
        r = json.loads(json.dumps(good))
        r["estimates"]["dynid SDP"]["standard_values"][name] = bad
        path = tmp_path / f"bad-{said}.json"
        path.write_text(json.dumps(r))
        assert_refused(dynid("export", cfg, "--results", path, "--urdf", tmp_path / "x.urdf"),
                       f"estimates.dynid SDP.standard_values.{name}: expected a finite number, got {said}")
        assert not (tmp_path / "x.urdf").exists()
    r = json.loads(json.dumps(good))
    first = next(iter(r["estimates"]["dynid WLS"]["values"]))
    r["estimates"]["dynid WLS"]["values"][first] = float("nan")
    (tmp_path / "nan-values.json").write_text(json.dumps(r))
    with pytest.raises(DynIdError, match=rf"values.{first}: expected a finite number"):
        api.load_results(tmp_path / "nan-values.json", robot=api.load_robot(str(cfg.parent / "er16_truth.toml")))

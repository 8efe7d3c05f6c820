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


class _Marker:
    """Unpickling this creates the marker file (what a hostile pickle would do, harmlessly)."""

    def __init__(self, path):
        self.path = str(path)

    def __reduce__(self):
        return (Path.touch, (Path(self.path),))


def _hostile_pickle(marker) -> bytes:
    return pickle.dumps({"version": 1, "fingerprint": "", "monitor": _Marker(marker)})


def test_no_loader_that_runs_code_in_the_package():
    """pickle, marshal, shelve, joblib, numpy's allow_pickle, yaml.load and eval/exec appear nowhere in src/dynid (the
    forked children's answers come back through multiprocessing's pipes: dynid.runtime.processes)."""
    pattern = re.compile(r"\bpickle\.loads?\(|\bmarshal\.loads?\(|\bshelve\.open\(|\bjoblib\.load\(|allow_pickle\s*=\s*True"
                         r"|\byaml\.(load|unsafe_load)\(|(?<![\w.])eval\(|(?<![\w.])exec\(|dill\.|cloudpickle\.loads?\(")
    found = []
    for path in sorted(SRC.rglob("*.py")):
        rel = path.relative_to(SRC).as_posix()
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            code = line.split("#", 1)[0]
            if pattern.search(code):
                found.append(f"{rel}:{n}: {line.strip()}")
    assert found == []


@pytest.fixture(scope="module")
def monitored(tmp_path_factory):
    """A robot's logs, its identification, and one monitor run that left its state."""
    from dynid.studies.simulated_fleet import simulate_service_life

    root = tmp_path_factory.mktemp("life")
    simulate_service_life(root, days=6, seconds=60.0, rate=100.0, wear_start_day=1e9, rng=5)
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

_SUBCLASSES = ("python{v}(python{t})['__subclasses__'](python{t}(1.0).mro()[1])")
_IMPORTER = "&quot;&lt;class '_frozen_importlib.BuiltinImporter'&gt;&quot;"
ESCAPES = {
    # what xacro's own evaluator (or the guard in front of it before) let through; the first two ran `touch`
    "attribute": "${{[c for c in " + _SUBCLASSES.format(v=".vars", t=".type") + " if python.str(c) == " + _IMPORTER
                 + "][0].load_module('posix').system('touch {marker}') + 1}}",
    # the escape: every name a string key, so the guard on names and attributes before this passed it
    "subscript": "${{[python['vars'](python['vars'](python['type'])['__getattribute__'](c, 'load_module')('posix'))"
                 "['system']('touch {marker}') for c in python['vars'](python['type'])['__subclasses__']"
                 "(python['vars'](python['type'])['mro'](python['type'](1.0))[1]) if python['str'](c) == "
                 + _IMPORTER + "][0] + 1}}",
    "string-built": "${{[c for c in python['va' + 'rs'](python['ty' + 'pe'])['__sub' + 'classes__']"
                    "(python['ty' + 'pe'](1.0).mro()[1])][0]}}",
    "passed-to-map": "${{list(map(python['vars'], [1]))}}",
    "generator frame": "${{[g for g in [(x for x in [1])]][0].gi_frame.f_globals}}",
    "type": "${{python.type(1.0)}}",
    "format string": "${{'{{0.__class__}}'.format(1)}}",
    "lambda": "${{(lambda: 1)()}}",
    # $(eval ...) ends at its first ')': the call is built in a ${...} first (this one writes the marker with xacro)
    "eval open": "$(eval ${{'open\\x28\\x27{marker}\\x27, \\x27w\\x27\\x29.write\\x28\\x27x\\x27\\x29'}})",
    "eval dunder": "$(eval ${{'\\x28\\x29.\\x5f\\x5fclass\\x5f\\x5f'}})",
    "huge power": "${{9**9**9}}",
    # round five: each ran past 120 s (a power whose exponent is small but whose base is huge, a comprehension
    # whose loops are each bounded but whose product is not)
    "power of a power": "${{(10**2499999)**64}}",
    "nested comprehension": "${{len([x for x in range(9999999) for y in range(9999999)])}}",
    "format width": "${{'%100000000d' % 1}}",  # wrote a 100 MB URDF
}


@pytest.mark.parametrize("escape", ESCAPES.values(), ids=ESCAPES.keys())
def test_a_xacro_description_never_runs_code(tmp_path, monkeypatch, escape):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    from dynid.model.urdf import expand_xacro

    marker = tmp_path / "ran"
    path = tmp_path / "arm.urdf.xacro"
    path.write_text(XACRO.format(value=escape.format(marker=marker)))
    with pytest.raises(ConfigError, match=r"arm.urdf.xacro: (the xacro expression .* uses .*, which a robot "
                                          "description may not run in dynid|xacro cannot expand it)") as caught:
        expand_xacro(path)
    assert "\n" not in str(caught.value) and not marker.exists()
    assert not list(tmp_path.glob("cache/dynid/xacro/**/*.urdf"))  # nothing cached either


def test_hostile_includes_and_yaml_are_refused(tmp_path, monkeypatch):
    """An escape in an included file, a YAML file with a Python tag, and a YAML unit value that is an expression."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    from dynid.model.urdf import expand_xacro

    marker = tmp_path / "ran"
    (tmp_path / "inc.xacro").write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:property name="evil" '
        'value="${python[\'vars\'](1)}" lazy_eval="false"/></robot>')
    (tmp_path / "tag.yaml").write_text(f"m: !!python/object/apply:os.system ['touch {marker}']\n")
    (tmp_path / "unit.yaml").write_text("m: !degrees python['vars'](1)\n")
    cases = {
        "include": '<xacro:include filename="inc.xacro"/>',
        "yaml tag": '<xacro:property name="y" value="${xacro.load_yaml(\'tag.yaml\')}" lazy_eval="false"/>',
        "yaml unit": '<xacro:property name="y" value="${xacro.load_yaml(\'unit.yaml\')}" lazy_eval="false"/>',
    }
    for name, element in cases.items():
        path = tmp_path / f"{name.replace(' ', '_')}.urdf.xacro"
        path.write_text(XACRO.format(value="1.0").replace("<link", element + "\n  <link", 1))
        with pytest.raises(ConfigError, match=r"(may not run in dynid|xacro cannot expand it)") as caught:
            expand_xacro(path)
        assert "\n" not in str(caught.value) and not marker.exists(), name


def test_files_a_description_may_not_read_are_refused_quickly_and_never_quoted(tmp_path, monkeypatch):
    """Round five: an include of a FIFO hung dynid (its reader blocks forever); ``load_yaml('/etc/passwd')`` as a
    joint's type put that whole file into the error message. A FIFO is refused as not a regular file, a data file
    outside the description's folders is refused, and a value read from a file is cut in a message."""
    import os
    import time

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    from dynid.model.description import load_robot
    from dynid.model.urdf import expand_xacro

    os.mkfifo(tmp_path / "fifo.xacro")
    outside = tmp_path.parent / f"{tmp_path.name}-secret.yaml"
    outside.write_text("a secret line " * 40 + "\n")
    cases = {
        "fifo": ('<xacro:include filename="fifo.xacro"/>', r"fifo.xacro is not a regular file"),
        "outside": (f'<xacro:property name="y" value="${{xacro.load_yaml(\'{outside}\')}}" lazy_eval="false"/>',
                    r"secret.yaml is outside the robot description's folders"),
    }
    for name, (element, message) in cases.items():
        path = tmp_path / f"{name}.urdf.xacro"
        path.write_text(XACRO.format(value="1.0").replace("<link", element + "\n  <link", 1))
        start = time.monotonic()
        with pytest.raises(ConfigError, match=message) as caught:
            expand_xacro(path)
        assert time.monotonic() - start < 10 and "a secret line" not in str(caught.value), name
    path = tmp_path / "long.urdf"  # a value read from a file is cut when a message quotes it
    path.write_text('<robot name="r"><link name="a"/><link name="b"/><joint name="j" type="' + "x" * 500 + '">'
                    '<parent link="a"/><child link="b"/></joint></robot>')
    with pytest.raises(ConfigError, match=r"has type 'x{37}\.\.\.'") as caught:
        load_robot(path)
    assert "x" * 41 not in str(caught.value)


def test_properties_that_double_themselves_are_refused_before_the_file_grows(tmp_path, monkeypatch):
    """Round five: 24 properties each the sum of the one before with itself wrote a 168 MB URDF; the sum is refused
    where it passes 10,000,000 characters."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    from dynid.model.urdf import expand_xacro

    doubling = "\n".join(['<xacro:property name="p0" value="abcdefgh"/>'] +
                          [f'<xacro:property name="p{i}" value="${{p{i - 1} + p{i - 1}}}"/>' for i in range(1, 25)])
    path = tmp_path / "arm.urdf.xacro"
    path.write_text(XACRO.format(value="1.0").replace("<link", doubling + '\n  <link name="${p24}"/>\n  <link', 1))
    with pytest.raises(ConfigError, match=r"uses a value of \d+ elements, which a robot description may not run"):
        expand_xacro(path)
    assert not list(tmp_path.glob("cache/dynid/xacro/**/*.urdf"))


def test_no_xacro_expression_reaches_eval(tmp_path, monkeypatch):
    """Properties, math, comprehensions, a YAML file with a unit, $(eval ...) and $(arg ...) all expand while Python's
    eval and the xacro package are out of reach: dynid expands the file and its interpreter computes the expressions."""
    import builtins

    def no_eval(*args, **kwargs):
        raise AssertionError("Python's eval was reached")

    real_import = builtins.__import__

    def no_xacro(name, *args, **kwargs):
        if name == "xacro" or name.startswith("xacro."):
            raise AssertionError("the xacro package was imported")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "eval", no_eval)
    monkeypatch.setattr(builtins, "__import__", no_xacro)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    from dynid.model.urdf import expand_xacro

    (tmp_path / "p.yaml").write_text("link1: {mass: 2.5, angle: !degrees 90}\n")
    path = tmp_path / "arm.urdf.xacro"
    value = ("${pi/2 + radians(90) + math.sqrt(4) + len([i for i in python.range(3)]) + props['link1']['mass']"
             " + props.link1.angle - 2.5 - pi/2 + (1 if 'a_b'.upper().startswith('A') else 0) - 1}")
    path.write_text(XACRO.format(value=value).replace(
        "<link", '<xacro:property name="props" value="${xacro.load_yaml(\'p.yaml\')}"/>\n  '
        '<link name="$(eval prefix + \'tool\' + \'8\' * 1)"/>\n  <link', 1))
    text = expand_xacro(path).read_text()
    assert '<mass value="8.141592653589793"/>' in text and 'name="a_base"' in text and 'name="a_tool8"' in text


def test_an_edited_include_expands_again(tmp_path, monkeypatch):
    """The expansion cache is keyed on every file the expansion read, not the top file only."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    from dynid.model.urdf import expand_xacro

    inc = tmp_path / "inc.xacro"
    inc.write_text('<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:property name="m" value="2.0"/></robot>')
    path = tmp_path / "arm.urdf.xacro"
    path.write_text(XACRO.format(value="1.0").replace('<xacro:property name="m" value="1.0"/>',
                                                      '<xacro:include filename="inc.xacro"/>'))
    assert '<mass value="2.0"/>' in expand_xacro(path).read_text()
    assert '<mass value="2.0"/>' in expand_xacro(path).read_text()
    inc.write_text(inc.read_text().replace("2.0", "3.0"))
    assert '<mass value="3.0"/>' in expand_xacro(path).read_text()


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


def test_an_absurd_number_in_a_results_file_is_refused_where_it_is_read(tmp_path):
    """A results.json holding 1e308 overflowed dynid validate (then a matplotlib crash, an empty output folder left)
    and dynid export wrote a URDF with a 1e308 kg link; a negative mass was written as it was."""
    import json

    from .simulated_logs import simulated_case

    cfg, _ = simulated_case(tmp_path, "er16", 100.0, "fourier", duration=10.0)
    cfg.write_text(cfg.read_text().replace('estimators = ["ols"]', 'estimators = ["wls", "sdp"]'))
    p = dynid("identify", cfg, "--out", tmp_path / "out", "--no-figures", "-q")
    assert p.returncode == 0, p.stderr
    good = json.loads((tmp_path / "out" / "results.json").read_text())
    label = "dynid SDP"  # what export writes (least squares has no standard values)
    for value, said in ((1e308, "expected a link mass in [0, 100000] kg, got 1e+308"),
                        (-2.0, "expected a link mass in [0, 100000] kg, got -2.0")):
        r = json.loads(json.dumps(good))
        r["estimates"][label]["standard_values"]["M1"] = value
        (tmp_path / "bad.json").write_text(json.dumps(r))
        assert_refused(dynid("export", cfg, "--results", tmp_path / "bad.json", "--urdf", tmp_path / "x.urdf"),
                       f"estimates.{label}.standard_values.M1: {said}")
        assert not (tmp_path / "x.urdf").exists()
    r = json.loads(json.dumps(good))
    first = next(iter(r["estimates"]["dynid WLS"]["values"]))
    r["estimates"]["dynid WLS"]["values"][first] = 1e308
    (tmp_path / "huge.json").write_text(json.dumps(r))
    assert_refused(dynid("validate", cfg, "--results", tmp_path / "huge.json", "--out", tmp_path / "v", "-q"),
                   f"values.{first}: expected a value within ±1e+12 (SI units), got 1e+308", tmp_path / "v", None)


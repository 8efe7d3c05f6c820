"""A corpus of bad inputs, each tried as a user would: every one gets exit code 1, no traceback, one error
line naming the file, line, field or option and what was expected, and no output folder (issue "Every bad
input refused cleanly"). The commands run in-process (typer's runner), which keeps the corpus fast."""

from __future__ import annotations

import json
import os
import stat
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from dynid.cli.app import app
from dynid.exceptions import DataError
from dynid.io.files import atomic_write_text

from .refusals import check_refusal


def invoke(*args):
    return CliRunner().invoke(app, [str(a) for a in args])


def assert_refused(result, message, out: Path | None = None):
    """A clean exit (not an escaped exception) and :func:`check_refusal`: one error line, nothing written."""
    assert isinstance(result.exception, SystemExit), repr(result.exception)
    check_refusal(result.exit_code, result.stdout, result.stderr, message, out)


# --- a valid UR10e RTDE log (31 columns: t, q, qd, i, i_target, tau_target) and configs around it -----------

RATE = 125.0


def _log_rows(seconds=20.0, rate=RATE):
    t = np.arange(int(seconds * rate)) / rate
    phase = np.arange(6)[None, :]
    q = 0.6 * np.sin(2 * np.pi * 0.2 * t[:, None] * (1 + 0.3 * phase) + phase)
    dq = 0.6 * 2 * np.pi * 0.2 * (1 + 0.3 * phase) * np.cos(2 * np.pi * 0.2 * t[:, None] * (1 + 0.3 * phase) + phase)
    i = 0.5 * np.sin(t[:, None] + phase) + 0.1 * np.sign(dq)
    return np.column_stack([t, q, dq, i, i, 10 * i])


def _write_log(path: Path, rows: np.ndarray):
    path.write_text("".join(",".join(f"{x:.9g}" for x in r) + "\n" for r in rows))


CONFIG = '''robot = "ur10e"
data_root = "."
[identification]
preset = "ur-rtde"
file = "log.csv"
'''


@pytest.fixture()
def ur(tmp_path):
    """A folder with log.csv (valid) and c.toml reading it; returns a function that rewrites either."""
    _write_log(tmp_path / "log.csv", _log_rows())

    def make(config_extra="", replace=None, log_text=None):
        text = CONFIG + config_extra
        for a, b in (replace or {}).items():
            assert a in text, a
            text = text.replace(a, b)
        (tmp_path / "c.toml").write_text(text)
        if log_text is not None:
            (tmp_path / "log.csv").write_text(log_text)
        return tmp_path / "c.toml"

    make.folder = tmp_path
    return make


def test_the_valid_log_is_identified(ur):
    """The corpus's base case passes, so each refusal below comes from its one change."""
    out = ur.folder / "out"
    result = invoke("identify", ur(), "--out", out, "--no-figures")
    assert result.exit_code == 0, result.stderr
    assert (out / "results.json").is_file()


GOOD = _log_rows()


def _text(rows):
    return "".join(",".join(f"{x:.9g}" for x in r) + "\n" for r in rows)


def _with(rows, fn):
    rows = rows.copy()
    fn(rows)
    return rows


LOGS = {
    "empty file": ("", "log.csv: no data lines (an empty file, or not a text table?)"),
    "only blank lines": ("\n\n\n", "log.csv: "),
    "semicolons": (_text(GOOD[:50]).replace(",", ";"), "log.csv: line 1: expected 31 columns, got 1 (fields separated by ';'?"),
    "a text cell": (_text(GOOD[:40]) + "0.5,abc" + ",1" * 29 + "\n" + _text(GOOD[41:60]), "log.csv: line 41"),
    "NaN for 36 rows": (_text(_with(GOOD[:300], lambda r: r.__setitem__((slice(5, 41), 3), np.nan))),
                        "log.csv: line 6: joint 3's positions are missing for 36 rows in a row"),
    "a missing time stamp": (_text(_with(GOOD[:300], lambda r: r.__setitem__((5, 0), np.nan))),
                             "log.csv: line 6: the time stamp is missing"),
    "infinity": (_text(_with(GOOD[:300], lambda r: r.__setitem__((7, 15), np.inf))),
                 "log.csv: line 8, column 16: infinite value"),
    # a repeated stamp whose next one is a quarter step later: no stalled clock spreads it at the log's rate
    "duplicate time stamps": (_text(_with(GOOD[:300], lambda r: r.__setitem__((slice(10, 12), 0), [r[9, 0], (r[9, 0] + r[10, 0]) / 2]))),
                              "log.csv: line 11: time stamps must increase, got a repeated time stamp"),
    "time going back": (_text(_with(GOOD[:300], lambda r: r.__setitem__((10, 0), r[5, 0]))), "log.csv: line 11: time stamps must increase"),
    "a time gap": (_text(_with(GOOD, lambda r: r.__setitem__((slice(1000, None), 0), r[1000:, 0] + 3.0))), "gap"),
    "degrees written as radians": (_text(_with(GOOD, lambda r: r.__setitem__((slice(None), slice(1, 7)), np.degrees(r[:, 1:7])))), 'unit = "deg"'),
    "huge values": (_text(_with(GOOD, lambda r: r.__setitem__((slice(None), slice(1, 7)), 1e300))), "positions"),
    "three rows": (_text(GOOD[:3]), "identification (" ),
    "time stamps in milliseconds": (_text(_with(GOOD, lambda r: r.__setitem__((slice(None), 0), r[:, 0] * 1000.0))),
                                    "log.csv: the time stamps step by"),
    # with a gap of a few samples, which dynid fills in seconds but which, read as seconds, exceeded max_gap first
    "time stamps in milliseconds, with a gap": (
        _text(_with(GOOD, lambda r: r.__setitem__((slice(None), 0), 1000.0 * (r[:, 0] + (np.arange(len(r)) >= 1000)
                                                                              * 8 * (r[1, 0] - r[0, 0]))))),
        "log.csv: the time stamps step by"),
    "velocities in deg/s": (_text(_with(GOOD, lambda r: r.__setitem__((slice(None), slice(7, 13)),
                                                                      np.degrees(r[:, 7:13])))),
                            "(deg/s read as rad/s?)"),
    "every current zero": (_text(_with(GOOD, lambda r: r.__setitem__((slice(None), slice(13, 19)), 0.0))),
                           "log.csv): every joint's torque reads one value throughout"),
    "UTF-16": (None, "log.csv: not a UTF-8 text table (it looks like UTF-16: save it as UTF-8)"),
    "a binary file": (None, "log.csv: not a UTF-8 text table (a binary file?)"),
    "a spreadsheet's workbook": (None, "log.csv: not a UTF-8 text table (a spreadsheet's workbook? save the sheet as CSV)"),
}


@pytest.mark.parametrize("case", sorted(LOGS))
def test_damaged_logs(ur, case):
    text, message = LOGS[case]
    cfg = ur()
    if case == "UTF-16":
        (ur.folder / "log.csv").write_text(_text(GOOD[:200]), encoding="utf-16")
    elif case == "a binary file":
        (ur.folder / "log.csv").write_bytes(bytes(range(256)) * 40)
    elif case == "a spreadsheet's workbook":  # an .xlsx saved under the log's name: a zip archive
        (ur.folder / "log.csv").write_bytes(b"PK\x03\x04" + bytes(range(256)) * 40)
    else:
        (ur.folder / "log.csv").write_text(text)
    out = ur.folder / "out"
    assert_refused(invoke("identify", cfg, "--out", out), message, out)


def test_a_joint_that_never_moves_is_identified_with_a_warning(ur):
    """It was refused; the other joints' parameters can be estimated (issue "Honest on any log", item 1)."""
    (ur.folder / "log.csv").write_text(_text(_with(GOOD, lambda r: r.__setitem__((slice(None), slice(3, 4)), 0.2)
                                                   or r.__setitem__((slice(None), slice(9, 10)), 0.0))))
    out = ur.folder / "out"
    result = invoke("identify", ur(), "--out", out, "--no-figures")
    assert result.exit_code == 0, result.stderr
    assert "log.csv: joint 3's position never changes in [identification]" in " ".join(result.stderr.split())
    assert (out / "results.json").is_file()


def test_a_few_missing_values_are_filled_with_a_warning(ur):
    """An empty field and a NaN (a log merging signals of other rates): filled by interpolation in time, said; they
    were refused ("NaN or infinite value")."""
    text = _text(_with(GOOD, lambda r: r.__setitem__((5, 3), np.nan))).splitlines(keepends=True)
    text[9] = ",".join(f if i != 14 else "" for i, f in enumerate(text[9].split(",")))
    (ur.folder / "log.csv").write_text("".join(text))
    out = ur.folder / "out"
    result = invoke("identify", ur(), "--out", out, "--no-figures")
    assert result.exit_code == 0, result.stderr
    assert ("2 missing value(s) (empty or NaN fields) in positions of joint 3; currents of joint 2: filled by "
            "interpolation in time") in " ".join(result.stderr.split())
    assert (out / "results.json").is_file()


CONFIGS = {
    "not TOML": ({"robot = \"ur10e\"": "robot = ur10e ="}, "c.toml"),
    "unknown top-level field": ({"data_root = \".\"": "data_root = \".\"\ncolour = 1"}, "colour"),
    "unknown robot": ({"\"ur10e\"": "\"ur99\""}, "c.toml: robot: unknown robot 'ur99'"),
    "missing URDF": ({"\"ur10e\"": "\"arm.urdf\""}, "c.toml: robot: file 'arm.urdf' not found in "),
    "missing URDF in a [robot] table": ({"robot = \"ur10e\"\ndata_root = \".\"": "data_root = \".\"\n[robot]\nurdf = \"arm.urdf\""},
                                        "c.toml: robot.urdf: file 'arm.urdf' not found in "),
    "no identification table": ({"[identification]\npreset = \"ur-rtde\"\nfile = \"log.csv\"\n": ""}, "[identification]"),
    "missing log file": ({"file = \"log.csv\"": "file = \"nosuch.csv\""}, "nosuch.csv"),
    "unknown preset": ({"preset = \"ur-rtde\"": "preset = \"kuka\""}, "kuka"),
    "unknown unit": ({"preset = \"ur-rtde\"": "preset = \"ur-rtde\"\npositions = { columns = [2, 3, 4, 5, 6, 7], unit = \"furlong\" }"}, "furlong"),
    "a column past the end": ({"preset = \"ur-rtde\"": "preset = \"ur-rtde\"\npositions = { columns = [2, 3, 4, 5, 6, 40] }"}, "40"),
    "five position columns": ({"preset = \"ur-rtde\"": "preset = \"ur-rtde\"\npositions = { columns = [2, 3, 4, 5, 6] }"}, "positions"),
    "rows beyond the file": ({"file = \"log.csv\"": "file = \"log.csv\"\nrows = [100, 999999]"}, "999999"),
    "rows inverted": ({"file = \"log.csv\"": "file = \"log.csv\"\nrows = [500, 100]"}, "rows"),
    "time range outside the log": ({"file = \"log.csv\"": "file = \"log.csv\"\ntime_range = [100.0, 200.0]"}, "time_range"),
    "data_root not a folder": ({"data_root = \".\"": "data_root = \"nowhere\""}, "--data-root"),
    "negative filter order": ("[preprocessing]\norder = -1\n", "preprocessing.order"),
    "zero band": ("[preprocessing]\nband = 0\n", "preprocessing.band"),
    "torque_cutoff": ("[preprocessing]\ntorque_cutoff = 5.0\n", "preprocessing.torque_cutoff"),
    "min_speed of the wrong length": ("[preprocessing]\nmin_speed = [0.1, 0.1]\n", "preprocessing.min_speed"),
    "unknown preprocessing field": ("[preprocessing]\ncutof = 3\n", "cutof"),
    "excitation file missing": ("[preprocessing]\nexcitation = \"nosuch.json\"\n", "nosuch.json"),
    "estimation method (renamed)": ("[estimation]\nmethod = \"abc\"\n", "estimation.method"),
    "unknown estimator": ("[estimation]\nestimators = [\"ols\", \"magic\"]\n", "estimation.estimators"),
    "negative seed": ("[estimation]\nseed = -1\n", "estimation.seed"),
    "estimators not a list": ("[estimation]\nestimators = \"wls\"\n", "estimation.estimators"),
    "drive gains without the loaded run": ("[drive_gains]\npayload_mass = 2.0\n[drive_gains.unloaded]\npreset = \"ur-rtde\"\nfile = \"log.csv\"\n", "loaded"),
    "zero payload mass": ("[drive_gains]\npayload_mass = 0\n[drive_gains.unloaded]\npreset = \"ur-rtde\"\nfile = \"log.csv\"\n"
                          "[drive_gains.loaded]\npreset = \"ur-rtde\"\nfile = \"log.csv\"\n", "payload_mass"),
    "two validations with one name": ("[[validation]]\nname = \"a\"\npreset = \"ur-rtde\"\nfile = \"log.csv\"\n"
                                      "[[validation]]\nname = \"a\"\npreset = \"ur-rtde\"\nfile = \"log.csv\"\n", "unique"),
    "reference file missing": ("[[references]]\nname = \"x\"\nfile = \"nosuch_ref.csv\"\nnames = \"name\"\nvalues = \"value\"\n", "nosuch_ref.csv"),
}


@pytest.mark.parametrize("case", sorted(CONFIGS))
def test_bad_identification_configs(ur, case):
    change, message = CONFIGS[case]
    cfg = ur(replace=change) if isinstance(change, dict) else ur(config_extra=change)
    out = ur.folder / "out"
    assert_refused(invoke("identify", cfg, "--out", out), message, out)


def test_a_config_that_does_not_exist(tmp_path):
    assert_refused(invoke("identify", tmp_path / "nosuch.toml", "--out", tmp_path / "o"), "nosuch.toml", tmp_path / "o")


def test_a_fifo_or_a_folder_given_as_a_log_is_said_as_such(ur):
    """Round five: a FIFO given as a log was "not found" to identify and hung dynid init (its reader blocks); an empty
    folder was called a ROS bag. Each is one line saying what the path is, before any read."""
    from importlib import resources

    cfg = ur(replace={'file = "log.csv"': 'file = "pipe.csv"'})
    os.mkfifo(cfg.parent / "pipe.csv")
    (cfg.parent / "empty").mkdir()
    out = cfg.parent / "o"
    assert_refused(invoke("identify", cfg, "--out", out), "pipe.csv: not a regular file (a device, a FIFO or a socket)", out)
    cfg.write_text(cfg.read_text().replace('file = "pipe.csv"', 'file = "empty"'))
    assert_refused(invoke("identify", cfg, "--out", out), "empty: not a regular file (a folder)", out)
    urdf = resources.files("dynid.model") / "robots" / "ur10e.urdf"
    target = cfg.parent / "arm.toml"
    assert_refused(invoke("init", urdf, cfg.parent / "pipe.csv", "--out", target),
                   "pipe.csv: not a regular file (a device, a FIFO or a socket)", target)
    assert_refused(invoke("init", urdf, cfg.parent / "empty", "--out", target),
                   "empty: a folder without metadata.yaml, not a ROS 2 bag", target)


def test_a_column_name_the_header_holds_twice_is_refused(ur, tmp_path):
    """Round five (an earlier corpus's silent case): two ROS-style CSV columns of one name, the first taken in
    silence. Now one line naming the columns; by number the intended one is read."""
    rows = _log_rows()
    names = ["t"] + [f"q{j}" for j in range(1, 7)] + [f"tau{j}" for j in range(1, 7)]
    names[7] = "q1"  # tau1's column carries q1's name again
    (tmp_path / "dup.csv").write_text(",".join(names) + "\n" + "".join(",".join(f"{x:.9g}" for x in r[:13]) + "\n"
                                                                    for r in rows))
    cfg = ur()
    cfg.write_text('robot = "ur10e"\ndata_root = "."\n[identification]\nfile = "dup.csv"\nheader = true\n'
                   'time = { column = "t" }\npositions = { columns = ["q1", "q2", "q3", "q4", "q5", "q6"] }\n'
                   'torques = { columns = [8, 9, 10, 11, 12, 13] }\n')
    out = tmp_path / "o"
    assert_refused(invoke("identify", cfg, "--out", out), "dup.csv: the header names 2 columns 'q1' (columns 2, 8)", out)


def test_a_config_in_utf16(ur):
    cfg = ur()
    cfg.write_text(cfg.read_text(), encoding="utf-16")
    assert_refused(invoke("identify", cfg, "--out", ur.folder / "o"), "c.toml: not UTF-8 text (it looks like UTF-16", ur.folder / "o")


RUN = ["--duration", "4", "--rate", "100", "--abc-iterations", "2", "--estimators", "ols,abc", "--bootstrap", "0"]
RUN_OPTIONS = {
    "no joints": (["--joints", "0"], "--joints"),
    "zero duration": (["--duration", "0"], "--duration must be positive"),
    "NaN rate": (["--rate", "nan"], "--rate must be positive"),
    "negative noise": (["--current-noise", "-1"], "--current-noise must be >= 0 (A), got -1.0"),
    "weights of the wrong count": (["--weights", "1,1"], "--weights"),
    "weights above one": (["--weights", "1,1,2"], "--weights"),
    "weights not numbers": (["--weights", "a,b,c"], "--weights"),
    "unknown plant": (["--plant", "real"], "--plant"),
    "paper plant on two joints": (["--plant", "paper", "--joints", "2"], "--plant"),
    "unknown box": (["--abc-bounds", "wide"], "--abc-bounds"),
    "empty estimators": (["--estimators", ","], "--estimators"),
    "excitation file missing": (["--excitation", "nosuch.json"], "nosuch.json"),
    "negative smoothing passes": (["--smoothing-passes", "-1"], "--smoothing-passes"),
    "one bootstrap resample": (["--bootstrap", "1"], "--bootstrap"),
    "a robot file that is not TOML": (["--robot", "{tmp}/robot.toml"], "robot.toml"),
    "an out that is a file": (["--out", "{tmp}/file"], "--out"),
}


@pytest.mark.parametrize("case", sorted(RUN_OPTIONS))
def test_bad_run_options(tmp_path, case):
    args, message = RUN_OPTIONS[case]
    (tmp_path / "robot.toml").write_text("name = [unclosed\n")
    (tmp_path / "file").write_text("x")
    args = [a.replace("{tmp}", str(tmp_path)) for a in args]
    out = tmp_path / "o"
    result = invoke("run", "--out", out, *RUN, *args)
    assert_refused(result, message, out if "--out" not in args else None)


MONTECARLO = {
    "noise levels not numbers": (["--noise-levels", "a,b"], "--noise-levels"),
    "zero noise": (["--noise-levels", "0"], "--noise-levels"),
    "one realisation": (["--realisations", "1"], "--realisations"),
    "no workers": (["--workers", "0"], "--workers"),
    "unknown estimator": (["--estimators", "ols,magic"], "--estimators"),
}


@pytest.mark.parametrize("case", sorted(MONTECARLO))
def test_bad_montecarlo_options(tmp_path, case):
    args, message = MONTECARLO[case]
    out = tmp_path / "o"
    assert_refused(invoke("montecarlo", "--out", out, "--duration", "2", "--realisations", "2", *args), message, out)


@pytest.fixture(scope="module")
def identified_once(tmp_path_factory):
    """The folder of one successful identification (log.csv, c.toml, id/results.json), run once for the module's
    tests, which each take a copy (:func:`identified`)."""
    folder = tmp_path_factory.mktemp("identified")
    _write_log(folder / "log.csv", GOOD)
    cfg = folder / "c.toml"
    cfg.write_text(CONFIG + "[[validation]]\nname = \"same\"\npreset = \"ur-rtde\"\nfile = \"log.csv\"\n")
    result = invoke("identify", cfg, "--out", folder / "id", "--no-figures", "--no-validate")
    assert result.exit_code == 0, result.stderr
    return folder


@pytest.fixture()
def identified(identified_once, tmp_path):
    """A config and the results.json of a successful identification, in this test's own folder."""
    import shutil

    folder = tmp_path / "ur"
    shutil.copytree(identified_once, folder)
    return folder / "c.toml", folder / "id" / "results.json"


def test_validate_and_export_refusals(identified, tmp_path):
    cfg, results = identified
    folder = cfg.parent
    (folder / "bad.json").write_text("{not json")
    (folder / "other.json").write_text(json.dumps({"base_parameters": [{"name": "X", "value": 1.0}]}))
    cases = [
        (["validate", cfg, "--results", folder / "nosuch.json", "--out", folder / "v"], "run dynid identify first"),
        (["validate", cfg, "--results", folder / "bad.json", "--out", folder / "v"], "bad.json: cannot read it as JSON"),
        (["validate", cfg, "--results", folder / "other.json", "--out", folder / "v"], "other.json: robot: missing"),
        (["validate", cfg, "--results", results, "--rows", "1,10", "--out", folder / "v"], "--rows needs --file"),
        (["validate", cfg, "--results", results, "--file", folder / "log.csv", "--rows", "a,b", "--out", folder / "v"], "--rows"),
        (["validate", cfg, "--results", results, "--file", folder / "nosuch.csv", "--out", folder / "v"], "nosuch.csv"),
        (["export", cfg, "--results", results], "--urdf"),
        (["export", cfg, "--results", results, "--urdf", folder / "no" / "where.urdf"], "its folder does not exist"),
        (["export", cfg, "--results", folder / "bad.json", "--urdf", folder / "r.urdf"], "bad.json"),
    ]
    for args, message in cases:
        assert_refused(invoke(*args), message, folder / "v")
    assert not (folder / "r.urdf").exists()


URDF = """<?xml version="1.0"?>
<robot name="r">
  <link name="base"/>
  <link name="l1"><inertial><origin xyz="0 0 0.1"/><mass value="2"/><inertia ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.01"/></inertial></link>
  <link name="l2"><inertial><origin xyz="0.1 0 0"/><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="100" velocity="3"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0 0 0.3"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="100" velocity="3"/></joint>
</robot>
"""
URDFS = {
    "malformed XML": ({"</joint>\n</robot>": "</joint>\n</robt>"}, "r.urdf: line 8, column 3: malformed XML (mismatched tag)"),
    "unknown joint type": ({'name="j2" type="revolute"': 'name="j2" type="hinge"'}, "r.urdf: line 7: joint 'j2' has type 'hinge'"),
    "planar joint": ({'name="j2" type="revolute"': 'name="j2" type="planar"'},
                     "r.urdf: joint 'j2' is JointModelPlanar, expected a revolute or prismatic joint"),
    "a parent link that does not exist": ({'<parent link="l1"/>': '<parent link="nolink"/>'}, "parent link [nolink] of joint [j2] not found"),
    "negative mass": ({'<mass value="1"/>': '<mass value="-1"/>'}, "mass"),
}


@pytest.mark.parametrize("case", sorted(URDFS))
def test_bad_urdfs_in_a_real_process(tmp_path, case):
    """A separate process: urdfdom prints on the process's own standard error, which must stay clean."""
    from .refusals import assert_refused as assert_refused_process
    from .refusals import dynid_process

    change, message = URDFS[case]
    text = URDF
    for a, b in change.items():
        assert a in text
        text = text.replace(a, b)
    (tmp_path / "r.urdf").write_text(text)
    (tmp_path / "r.toml").write_text('name = "r"\nconvention = "urdf"\nurdf = "r.urdf"\n[[joints]]\nname = "j1"\n[[joints]]\nname = "j2"\n')
    out = tmp_path / "o"
    p = dynid_process("run", "--robot", str(tmp_path / "r.toml"), "--joints", "2", "--out", str(out), *RUN)
    assert_refused_process(p, message, out)


# --- round three (issue "Bad input, round three"): results files, export targets, references, ranges, options ----


def _edited(results: Path, folder: Path, edit) -> Path:
    data = json.loads(results.read_text())
    edit(data)
    path = folder / "edited.json"
    path.write_text(json.dumps(data))
    return path


def _first_estimate(d):
    """The estimate ``dynid export`` writes (``stored_standard``'s: the main one where it has standard values, else
    the first that has; the first listed where none has); the edit nulls its base and its standard values."""
    estimates = d["estimates"]
    ordered = sorted(estimates, key=lambda k: k != d.get("main_estimate"))
    return next((estimates[k] for k in ordered if isinstance(estimates[k].get("standard_values"), dict)),
                estimates[ordered[0]])


RESULTS_EDITS = {
    "a value null": (lambda d: d["base_parameters"][0].__setitem__("value", None), "edited.json: base_parameters[0].value"),
    "a value as text": (lambda d: d["base_parameters"][1].__setitem__("value", "0.5"), "edited.json: base_parameters[1].value"),
    "an estimate's value null": (lambda d: [table.__setitem__(next(iter(table)), None) for key in ("values", "standard_values")
                                            if isinstance(table := _first_estimate(d).get(key), dict)],
                                 "edited.json: "),
    "a setting of the wrong type": (lambda d: d["settings"]["preprocessing"].__setitem__("order", "four"),
                                    "edited.json: settings.preprocessing.order"),
    "settings not a table": (lambda d: d.__setitem__("settings", [1, 2]), "edited.json: settings"),
    "no schema version": (lambda d: d.pop("schema_version"), "edited.json: schema_version"),
    "another kind of results": (lambda d: d.__setitem__("kind", "excite"), "edited.json: expected the results.json of dynid identify"),
    "another robot's results": (lambda d: d.__setitem__("robot", "tx40"), "edited.json: results of robot 'tx40'"),
    "estimators empty": (lambda d: d.__setitem__("estimators", []), "edited.json: estimators"),
}


@pytest.mark.parametrize("command", ["validate", "export"])
@pytest.mark.parametrize("case", sorted(RESULTS_EDITS))
def test_results_edited_by_hand(identified, case, command):
    cfg, results = identified
    folder = cfg.parent
    edit, message = RESULTS_EDITS[case]
    path = _edited(results, folder, edit)
    args = ["--urdf", folder / "r.urdf"] if command == "export" else ["--out", folder / "v"]
    assert_refused(invoke(command, cfg, "--results", path, *args), message, folder / "v")
    assert not (folder / "r.urdf").exists()


def test_export_targets_are_checked_before_any_work(identified):
    cfg, results = identified
    folder = cfg.parent
    (folder / "adir").mkdir()
    cases = [
        (["--urdf", folder / "adir"], "--urdf"),
        (["--urdf", folder / "same.xml", "--mjcf", folder / "same.xml"], "--urdf and --mjcf name the same file"),
        (["--mjcf", folder / "adir"], "--mjcf"),
        (["--mjcf-model", folder / "m.xml"], "give --mjcf FILE too"),
        (["--mjcf", folder / "o.xml", "--mjcf-model", folder / "nosuch.xml"], "--mjcf-model"),
        (["--mjcf", folder / "o.xml", "--mjcf-model", folder / "other.xml"], "other.xml: has no joint"),
        (["--mjcf", folder / "o.xml", "--mjcf-model", folder / "bad.xml"], "bad.xml: cannot read it as MJCF"),
    ]
    (folder / "other.xml").write_text("<mujoco><worldbody><body name='b'><joint name='x'/><geom size='.1'/></body></worldbody></mujoco>")
    (folder / "bad.xml").write_text("<mujoco><worldbody>")
    os.mkfifo(folder / "pipe.urdf")  # a device node or a FIFO is never replaced by a regular file (/dev/null as root)
    cases.append((["--urdf", folder / "pipe.urdf"], "pipe.urdf: not a regular file (a device, a FIFO or a socket)"))
    for args, message in cases:
        assert_refused(invoke("export", cfg, "--results", results, *args), message)
    assert sorted(p.name for p in folder.iterdir() if p.suffix in (".urdf", ".xml")) == ["bad.xml", "other.xml", "pipe.urdf"]
    assert stat.S_ISFIFO((folder / "pipe.urdf").stat().st_mode)
    with pytest.raises(DataError, match="pipe.urdf: not a regular file"):  # every file dynid writes goes through it
        atomic_write_text(folder / "pipe.urdf", "<robot/>")


def test_an_earlier_runs_folder_holding_a_folder_where_a_file_goes(ur):
    from .refusals import snapshot

    cfg = ur()
    out = ur.folder / "out"
    assert invoke("identify", cfg, "--out", out, "--no-figures").exit_code == 0
    (out / "results.json").unlink()
    (out / "results.json").mkdir()
    (out / "results.json" / "keep").write_text("x")
    before = snapshot(out)
    result = invoke("identify", cfg, "--out", out, "--no-figures")
    assert isinstance(result.exception, SystemExit)
    check_refusal(result.exit_code, result.stdout, result.stderr, "results.json: a folder where this run writes a file", out, before)


RANGES = {
    "payload of 1000 tonnes": ("[drive_gains]\npayload_mass = 1e6\n[drive_gains.unloaded]\npreset = \"ur-rtde\"\nfile = \"log.csv\"\n"
                               "[drive_gains.loaded]\npreset = \"ur-rtde\"\nfile = \"log.csv\"\n", "drive_gains.payload_mass"),
    "payload of infinite mass": ("[drive_gains]\npayload_mass = inf\n[drive_gains.unloaded]\npreset = \"ur-rtde\"\nfile = \"log.csv\"\n"
                                 "[drive_gains.loaded]\npreset = \"ur-rtde\"\nfile = \"log.csv\"\n", "drive_gains.payload_mass"),
    "Coulomb smoothing of 1e9 rad/s": ("[preprocessing]\ncoulomb_velocity = 1e9\n", "preprocessing.coulomb_velocity"),
    "a minimum speed above every speed": ("[preprocessing]\nmin_speed = 50.0\n", "preprocessing.min_speed"),
    "a decimation of 1000": ("[preprocessing]\ndecimation = 1000\n", "preprocessing.decimation"),
    "a torque delay of an hour": ("[preprocessing]\ntorque_delay = 3600.0\n", "preprocessing.torque_delay"),
    "a torque delay of nan": ("[preprocessing]\ntorque_delay = nan\n", "preprocessing.torque_delay"),
    "a presliding distance of 1e9 rad": ("[preprocessing]\npresliding = 1e9\n", "preprocessing.presliding"),
    "an infinite presliding distance": ("[preprocessing]\npresliding = inf\n", "preprocessing.presliding"),
    "a 50 ms time range": ({"file = \"log.csv\"": "file = \"log.csv\"\ntime_range = [1.0, 1.05]"}, "time_range"),
}


def test_interpolation_invents_no_more_than_max_gap(ur):
    rows = _with(GOOD, lambda r: r.__setitem__((slice(1000, None), 0), r[1000:, 0] + 60.0))
    cfg = ur(replace={"file = \"log.csv\"": "file = \"log.csv\"\ngaps = \"interpolate\""}, log_text=_text(rows))
    out = ur.folder / "out"
    assert_refused(invoke("identify", cfg, "--out", out), "is longer than max_gap = 0.1 s", out)


@pytest.mark.parametrize("case", sorted(RANGES))
def test_settings_out_of_range_are_named(ur, case):
    change, message = RANGES[case]
    cfg = ur(replace=change) if isinstance(change, dict) else ur(config_extra=change)
    out = ur.folder / "out"
    assert_refused(invoke("identify", cfg, "--out", out), message, out)


def test_a_current_of_1e300_is_refused(ur):
    rows = _with(GOOD, lambda r: r.__setitem__((slice(100, 200), 13), 1e300))
    cfg = ur(log_text=_text(rows))
    out = ur.folder / "out"
    assert_refused(invoke("identify", cfg, "--out", out), "log.csv", out)


def test_a_frozen_log_names_the_file(ur):
    rows = _with(GOOD, lambda r: r.__setitem__((slice(None), slice(1, 13)), 0.3))
    cfg = ur(log_text=_text(rows))
    out = ur.folder / "out"
    assert_refused(invoke("identify", cfg, "--out", out), "log.csv", out)


REFERENCE = '[[references]]\nname = "{name}"\nfile = "ref.csv"\nformat = "standard"\nheader = true\nnames = "name"\nvalues = "value"\n'
NOMINAL = '[[references]]\nname = "{name}"\nformat = "nominal"\n'
REFERENCES = {
    "a parameter given twice": ("name,value\nZZ1,1.0\nM2,3.0\nZZ1,2.0\n", REFERENCE.format(name="pub"), "ref.csv: line 4: ZZ1 given twice (line 2)"),
    "two sets with one name": ("", NOMINAL.format(name="pub") * 2, "references[1].name: 'pub' names two reference sets"),
    "a set named like dynid's estimate": ("", NOMINAL.format(name="dynid WLS"), "references[0].name: 'dynid WLS' is the name of dynid's"),
}


@pytest.mark.parametrize("case", sorted(REFERENCES))
def test_reference_sets(ur, case):
    ref, extra, message = REFERENCES[case]
    (ur.folder / "ref.csv").write_text(ref)
    cfg = ur(config_extra=extra)
    out = ur.folder / "out"
    assert_refused(invoke("identify", cfg, "--out", out), message, out)


def test_an_unknown_field_in_a_robot_description(tmp_path):
    from dynid.model.description import builtin_robots  # noqa: F401  the built-in descriptions parse

    (tmp_path / "r.toml").write_text('name = "r"\nconvention = "urdf"\nurdf = "r.urdf"\ndrives = ["fv", "fc"]\n'
                                     '[[joints]]\nname = "j1"\n[[joints]]\nname = "j2"\n')
    (tmp_path / "r.urdf").write_text(URDF)
    out = tmp_path / "o"
    assert_refused(invoke("run", "--robot", tmp_path / "r.toml", "--joints", "2", "--out", out, *RUN), "drives", out)


RUN_OPTIONS_ROUND3 = {
    "a rate of 2 Hz": (["--rate", "2"], "--rate"),
    "no ABC iterations": (["--abc-iterations", "0"], "--abc-iterations"),
    "a colony of one bee": (["--abc-colony", "1"], "--abc-colony"),
    "a scout limit of 0": (["--abc-limit", "0"], "--abc-limit"),
}


@pytest.mark.parametrize("case", sorted(RUN_OPTIONS_ROUND3))
def test_run_options_are_checked_before_the_run_starts(tmp_path, case):
    args, message = RUN_OPTIONS_ROUND3[case]
    out = tmp_path / "o"
    result = invoke("run", "--out", out, *RUN, *args)
    assert_refused(result, message, out)
    assert "dynid run: " not in result.stderr  # refused before the first step


URDFS_ROUND3 = {
    "a link without inertial": ({'<link name="l2"><inertial><origin xyz="0.1 0 0"/><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>':
                                 '<link name="l2"/>'}, "r.urdf: link 2 (j2) has a nominal mass of 0 kg (a URDF link without <inertial>?)"),
    "a mimic joint of multiplier 0": ({'<axis xyz="0 1 0"/>': '<axis xyz="0 1 0"/><mimic joint="j1" multiplier="0"/>'},
                                      "r.urdf: line 7: joint 'j2' has <mimic joint=\"j1\" multiplier=\"0\">: expected the joint "
                                      "it follows (joint=), a finite non-zero multiplier and a finite offset"),
}


@pytest.mark.parametrize("case", sorted(URDFS_ROUND3))
def test_urdfs_dynid_cannot_model(tmp_path, case):
    change, message = URDFS_ROUND3[case]
    text = URDF
    for a, b in change.items():
        assert a in text, a
        text = text.replace(a, b)
    (tmp_path / "r.urdf").write_text(text)
    out = tmp_path / "o"
    assert_refused(invoke("run", "--robot", tmp_path / "r.urdf", "--joints", "2", "--out", out, *RUN), message, out)


def test_a_damaged_bag_metadata_file_is_one_line(tmp_path):
    from ..io.test_bags import _write_bag

    t = np.arange(200) * 0.01
    q = 0.01 * np.outer(np.arange(200), np.ones(6))
    names = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"]
    _write_bag(tmp_path / "bag", t, names, q, q, q)
    (tmp_path / "bag" / "metadata.yaml").write_text("rosbag2_bagfile_information:\n  version: [5\n  bad: : :\n")
    (tmp_path / "c.toml").write_text('robot = "ur10e"\ndata_root = "."\n[identification]\nbag = "bag"\n')
    out = tmp_path / "o"
    assert_refused(invoke("identify", tmp_path / "c.toml", "--out", out),
                   "metadata.yaml: while parsing a flow sequence at line 2, column 12; expected ',' or ']', but got ':' at line 3", out)


def test_results_files_of_the_wrong_shape(identified):
    cfg, results = identified
    folder = cfg.parent
    (folder / "empty.json").write_text("")
    (folder / "list.json").write_text("[1, 2]")
    (folder / "run.json").write_text(json.dumps({"schema_version": 2, "dynid_version": "0", "kind": "run"}))
    (folder / "future.json").write_text(json.dumps({**json.loads(results.read_text()), "schema_version": 9}))
    cases = [
        (folder, "a folder; give the results.json in it"),
        (folder / "empty.json", "empty.json: cannot read it as JSON"),
        (folder / "list.json", "list.json: expected the results.json of dynid identify (a JSON object), got a list"),
        (folder / "run.json", "run.json: expected the results.json of dynid identify, got the results of dynid run"),
        (folder / "future.json", "future.json: schema_version: expected 2, got 9 (written by another version of dynid?)"),
    ]
    for path, message in cases:
        for command, args in (("validate", ["--out", folder / "v"]), ("export", ["--urdf", folder / "r.urdf"])):
            assert_refused(invoke(command, cfg, "--results", path, *args), message, folder / "v")
    assert not (folder / "r.urdf").exists()


MONTECARLO_ROUND3 = {
    "zero duration": (["--duration", "0"], "--duration"),
    "too few samples": (["--duration", "1", "--rate", "2"], "--rate"),
    "unknown robot": (["--robot", "ur99"], "ur99"),
    "joints beyond the robot": (["--joints", "9"], "--joints"),
    "unknown strategy": (["--strategy", "magic"], "--strategy"),
    "unknown box": (["--abc-bounds", "wide"], "--abc-bounds"),
}


@pytest.mark.parametrize("case", sorted(MONTECARLO_ROUND3))
def test_montecarlo_options_are_checked_before_the_workers_start(tmp_path, case):
    args, message = MONTECARLO_ROUND3[case]
    out = tmp_path / "o"
    result = invoke("montecarlo", "--out", out, "--realisations", "2", *args)
    assert_refused(result, message, out)
    assert "starting the workers" not in result.stderr

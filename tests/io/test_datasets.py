import re
from dataclasses import replace

import numpy as np
import pytest

from dynid.exceptions import ConfigError, DataError
from dynid.io.logs.datasets import dataset_spec, load_recording
from dynid.model.description import load_robot
from dynid.preprocessing.preparation import prepare
from dynid.preprocessing.settings import Preprocessing


def _ur_row(t, q, dq, i):
    return ",".join(f"{x:.6f}" for x in [t, *q, *dq, *i, *np.zeros(12)]) + "\n"


def test_ur_rtde_preset_resamples_jittered_time_onto_a_uniform_grid(tmp_path, rng):
    robot = load_robot("ur10e")
    t = 1000.0 + np.cumsum(rng.uniform(0.006, 0.014, 300))
    q = np.outer(t - t[0], np.arange(1, 7) * 0.1)  # linear in time: interpolation is exact
    cur = np.outer(np.ones_like(t), np.arange(1, 7))
    (tmp_path / "ur.csv").write_text("".join(_ur_row(tk, qk, qk * 0 + 0.5, ik) for tk, qk, ik in zip(t, q, cur)))
    spec = dataset_spec({"preset": "ur-rtde", "file": "ur.csv", "resample": 100.0}, tmp_path, "cfg", "ident", 6)
    rec = load_recording(spec, robot)
    assert rec.rate == 100.0
    np.testing.assert_allclose(np.diff(rec.t), 0.01, atol=1e-9)
    np.testing.assert_allclose(rec.q, np.outer(rec.t, np.arange(1, 7) * 0.1), atol=1e-5)
    np.testing.assert_allclose(rec.tau, np.tile(np.arange(1, 7) * robot.drive_gains, (rec.n_samples, 1)), rtol=1e-9)


def test_non_increasing_time_names_file_and_line(tmp_path):
    rows = [_ur_row(t, np.full(6, k), np.zeros(6), np.zeros(6)) for k, t in enumerate((0.0, 0.01, 0.02, 0.02, 0.03))]
    (tmp_path / "ur.csv").write_text("".join(rows))
    spec = dataset_spec({"preset": "ur-rtde", "file": "ur.csv"}, tmp_path, "cfg", "ident", 6)
    with pytest.raises(DataError, match=r"ur.csv: line 4: time stamps must increase, got a repeated time stamp"):
        load_recording(spec, load_robot("ur10e"))


@pytest.mark.parametrize("spool", [False, True])
def test_a_stalled_clock_is_spread_to_the_next_stamp(tmp_path, spool):
    """Ten rows whose time stamp stalled while their values go on (a clock that stuck for 10 ms of a 100 Hz log):
    their stamps are spread evenly to the next one, the recording equal to the one with the true stamps, one warning.
    Ten rows at one stamp with the next stamp one step later cannot be spread at the log's rate: refused, naming the
    first repeat's line."""
    t = np.arange(200) * 0.01
    q = 0.1 * np.sin(np.outer(t, np.arange(1, 7)))
    stamps = t.copy()
    stamps[50:60] = t[50]
    for name, when in (("true", t), ("stalled", stamps)):
        (tmp_path / f"{name}.csv").write_text("".join(_ur_row(tk, qk, np.zeros(6), np.full(6, 0.5))
                                                      for tk, qk in zip(when, q)))
    robot = load_robot("ur10e")
    true, stalled = (load_recording(dataset_spec({"preset": "ur-rtde", "file": f"{name}.csv"}, tmp_path, "cfg",
                                                 "ident", 6), robot, spool=spool) for name in ("true", "stalled"))
    np.testing.assert_allclose(stalled.t, true.t, atol=1e-12)
    np.testing.assert_array_equal(np.asarray(stalled.q), np.asarray(true.q))
    assert [w for w in stalled.warnings if w not in true.warnings] == [
        "ident: 9 time stamp(s) in 1 run(s) repeat the one before while the values change (a stalled or coarse clock): "
        "spread evenly to the next time stamp"]
    burst = np.r_[t[:60], np.full(10, t[60]), t[61:]]  # ten rows more at one stamp: 0.001 s apart at most
    q = 0.1 * np.sin(np.outer(np.arange(burst.size) * 0.01, np.arange(1, 7)))
    (tmp_path / "burst.csv").write_text("".join(_ur_row(tk, qk, np.zeros(6), np.full(6, 0.5))
                                                for tk, qk in zip(burst, q)))
    with pytest.raises(DataError, match=r"burst.csv: line 62: time stamps must increase, got a repeated time stamp"):
        load_recording(dataset_spec({"preset": "ur-rtde", "file": "burst.csv"}, tmp_path, "cfg", "ident", 6), robot,
                       spool=spool)


@pytest.mark.parametrize("spool", [False, True])
def test_a_row_written_twice_is_dropped_and_said(tmp_path, spool):
    """A row that repeats the previous one, time stamp and every value (a logger that wrote a sample twice): dropped,
    the recording the same as without it, one warning; time going back after it is refused naming its line in the
    file (line 6: the dropped row counted)."""
    t = np.arange(200) * 0.01
    q = 0.1 * np.sin(np.outer(t, np.arange(1, 7)))
    rows = [_ur_row(tk, qk, np.zeros(6), np.full(6, 0.5)) for tk, qk in zip(t, q)]
    (tmp_path / "once.csv").write_text("".join(rows))
    (tmp_path / "twice.csv").write_text("".join(rows[:50] + rows[49:]))
    robot = load_robot("ur10e")
    once, twice = (load_recording(dataset_spec({"preset": "ur-rtde", "file": f"{name}.csv"}, tmp_path, "cfg", "ident",
                                               6), robot, spool=spool) for name in ("once", "twice"))
    np.testing.assert_array_equal(np.asarray(twice.q), np.asarray(once.q))
    np.testing.assert_array_equal(twice.t, once.t)
    assert [w for w in twice.warnings if w not in once.warnings] == [
        "ident: 1 row(s) repeat the previous one, time stamp and every value (a sample written twice): dropped"]
    (tmp_path / "back.csv").write_text("".join(rows[:3] + rows[2:4] + rows[2:3] + rows[5:]))
    with pytest.raises(DataError, match=r"back.csv: line 6: time stamps must increase, got time going back: "
                                        r"0.02 s after 0.03 s$"):  # a glitch of the clock: no hint of two recordings
        load_recording(dataset_spec({"preset": "ur-rtde", "file": "back.csv"}, tmp_path, "cfg", "ident", 6), robot,
                       spool=spool)
    (tmp_path / "again.csv").write_text("".join(rows + rows))  # a second recording appended, its clock started again
    with pytest.raises(DataError, match=r"again.csv: line 201: time stamps must increase, got time going back: 0 s "
                                        r"after 1.99 s; two recordings one after the other\? give each its own file, "
                                        r"or select one with rows$"):
        load_recording(dataset_spec({"preset": "ur-rtde", "file": "again.csv"}, tmp_path, "cfg", "ident", 6), robot,
                       spool=spool)


def test_wrong_column_count_for_the_preset(tmp_path):
    (tmp_path / "ur.csv").write_text("1,2,3\n")
    spec = dataset_spec({"preset": "ur-rtde", "file": "ur.csv"}, tmp_path, "cfg", "ident", 6)
    with pytest.raises(DataError, match=r"ur.csv: line 1: expected 31 columns, got 3"):
        load_recording(spec, load_robot("ur10e"))


def test_motor_side_dataset_goes_through_the_transmission(tmp_path, rng):
    robot = load_robot("tx40")
    tr = robot.transmission
    q = rng.uniform(-1, 1, (50, 6))
    tau = rng.uniform(-5, 5, (50, 6))
    header = ",".join(f"Joint_{j + 1}" for j in range(6))
    np.savetxt(tmp_path / "p.csv", (q - tr.position_offset) @ tr.motor_from_joint.T, delimiter=",", header=header, comments="")
    np.savetxt(tmp_path / "c.csv", np.linalg.solve(tr.motor_from_joint.T, tau.T).T, delimiter=",", header=header, comments="")
    spec = dataset_spec({"preset": "motor-side", "rate": 200.0, "positions": {"file": "p.csv"}, "torques": {"file": "c.csv"}},
                        tmp_path, "cfg", "ident", 6)
    rec = load_recording(spec, robot)
    np.testing.assert_allclose(rec.q, q, atol=1e-12)
    np.testing.assert_allclose(rec.tau, tau, atol=1e-10)
    np.testing.assert_allclose(rec.t[1], 1 / 200.0)


@pytest.mark.parametrize("table, message", [
    ({"file": "x.csv", "rate": 10, "positions": {"columns": [1, 2, 3, 4, 5, 6]}}, "exactly one of 'currents'"),
    ({"preset": "ur-rtde", "file": "x.csv", "rate": 10}, "either a 'time' column or a sampling 'rate'"),
    ({"preset": "ur-rtde", "file": "x.csv", "positions": {"unit": "grad"}}, r"positions.unit: expected one of rad, deg"),
    ({"preset": "ur-rtde", "file": "x.csv", "side": "both"}, r"side: expected 'joint' or 'motor'"),
    ({"preset": "ur-rtde", "file": "x.csv", "rows": [10, 5]}, r"rows: expected \[first, last\]"),
    ({"preset": "ur-rtde", "file": "x.csv", "colums": 3}, r"unknown field 'colums', expected some of bag, currents"),
])
def test_dataset_config_errors(tmp_path, table, message):
    with pytest.raises(ConfigError, match=message):
        dataset_spec(table, tmp_path, "cfg: identification", "ident", 6)


def test_real_ur_log_with_a_truncated_last_line_is_read_with_a_warning():
    from ..conftest import shared_data

    root = shared_data("ur10e_mamedov2020")
    spec = dataset_spec({"preset": "ur-rtde", "file": "identification_data/ur-20_02_19_15harm50secLoad.csv", "rows": [11, 10**7]},
                        root, "cfg", "ident", 6)
    rec = load_recording(spec, load_robot("ur10e"))
    assert any("ur-20_02_19_15harm50secLoad.csv: line 6107 is truncated" in w for w in rec.warnings)
    assert rec.n_samples > 6000


def test_time_range_selects_seconds_and_is_checked(tmp_path):
    rows = [_ur_row(0.01 * k, np.full(6, 0.01 * k), np.zeros(6), np.zeros(6)) for k in range(300)]
    (tmp_path / "ur.csv").write_text("".join(rows))
    spec = dataset_spec({"preset": "ur-rtde", "file": "ur.csv", "time_range": [0.5, 1.5]}, tmp_path, "cfg", "ident", 6)
    rec = load_recording(spec, load_robot("ur10e"))
    assert rec.n_samples == 101 and rec.q[0, 0] == pytest.approx(0.5) and rec.q[-1, 0] == pytest.approx(1.5)
    with pytest.raises(ConfigError, match=r"cfg.time_range: expected \[start, stop\] in seconds"):
        dataset_spec({"preset": "ur-rtde", "file": "ur.csv", "time_range": [2.0, 1.0]}, tmp_path, "cfg", "ident", 6)
    spec = dataset_spec({"preset": "ur-rtde", "file": "ur.csv", "time_range": [10.0, 11.0]}, tmp_path, "cfg", "ident", 6)
    with pytest.raises(DataError, match=r"time_range \[10, 11\] s holds fewer than 2 samples of the 2.990 s recording"):
        load_recording(spec, load_robot("ur10e"))


def _log(tmp_path, t, q, cur, name="ur.csv"):
    (tmp_path / name).write_text("".join(_ur_row(tk, qk, qk * 0, ik) for tk, qk, ik in zip(t, q, cur)))
    return dataset_spec({"preset": "ur-rtde", "file": name}, tmp_path, "cfg: identification", "ident", 6)


def test_a_gap_in_the_time_stamps_is_refused_unless_interpolation_is_asked(tmp_path):
    """The message names the line, the time stamp in the file and into the selected rows, and the table and setting
    to change; gaps = "interpolate" fills gaps up to max_gap (0.1 s by default), with a warning saying how many and
    how long, and refuses a longer one (it would invent that much data)."""
    t = np.concatenate([np.arange(100) * 0.01, 3.0 + np.arange(100) * 0.01])
    spec = _log(tmp_path, t, 0.1 + 1e-3 * np.outer(np.arange(200), np.ones(6)), np.full((200, 6), 0.5))
    with pytest.raises(DataError, match=r"ur.csv: line 101: a gap of 2.01 s in the time stamps \(median step 0.01 s, 201 "
                                        r"samples\) after the time stamp 0.99 s \(0.990 s into the selected rows\), longer "
                                        r"than the 20 samples dynid fills by itself; set gaps = \"interpolate\" in \[identification\]"):
        load_recording(spec, load_robot("ur10e"))
    spec = dataset_spec({"preset": "ur-rtde", "file": "ur.csv", "gaps": "interpolate"}, tmp_path, "c.toml: identification", "ident", 6)
    with pytest.raises(DataError, match=r"longer than max_gap = 0.1 s.*raise max_gap in \[identification\]"):
        load_recording(spec, load_robot("ur10e"))
    spec = dataset_spec({"preset": "ur-rtde", "file": "ur.csv", "gaps": "interpolate", "max_gap": 3.0}, tmp_path,
                        "c.toml: validation[1]", "p3", 6)
    rec = load_recording(spec, load_robot("ur10e"))
    assert rec.n_samples > 200
    assert any(w.startswith("p3: 1 gap(s) in the time stamps filled by interpolation, the longest 2.01 s") and
               "[[validation]] 2" in w for w in rec.warnings)


def test_a_few_dropped_samples_are_filled_by_default_and_said(tmp_path):
    """gaps = "auto" (the default): a logger that dropped 7 samples is filled by interpolation, with a warning that names
    the setting; gaps = "refuse" refuses it as the default used to."""
    t = np.concatenate([np.arange(100) * 0.01, 1.07 + np.arange(100) * 0.01])
    spec = _log(tmp_path, t, 0.1 + 1e-3 * np.outer(np.arange(200), np.ones(6)), np.full((200, 6), 0.5))
    rec = load_recording(spec, load_robot("ur10e"))
    assert rec.n_samples == 207
    assert any("1 gap(s) in the time stamps filled by interpolation, the longest 0.08 s" in w and 'gaps = "auto"' in w
               for w in rec.warnings)
    spec = dataset_spec({"preset": "ur-rtde", "file": "ur.csv", "gaps": "refuse"}, tmp_path, "c.toml: identification",
                        "ident", 6)
    with pytest.raises(DataError, match=r"a gap of 0.08 s in the time stamps"):
        load_recording(spec, load_robot("ur10e"))


def test_positions_in_degrees_are_refused_with_the_hint(tmp_path):
    t = np.arange(100) * 0.01
    q = np.outer(np.linspace(0, 90, 100), np.ones(6))
    with pytest.raises(DataError, match=r"ur.csv: joint 1 reaches 90 rad, implausible for radians: .*unit = \"deg\""):
        load_recording(_log(tmp_path, t, q, np.ones((100, 6))), load_robot("ur10e"))
    q[:, :5] = 0.1  # the sixth joint alone in degrees: the unit would turn the others too
    with pytest.raises(DataError, match=r"joint 6 reaches 90 rad, .*unit = \"deg\" }; for this joint alone positions "
                                        r"= \{ ..., scale = \[1, 1, 1, 1, 1, 0.0174533\] \}\)\? Or a motor's angle, before "
                                        r"its gear \(side = \"motor\" in the dataset's table, .*\[transmission\] gear_ratios\)\?$"):
        load_recording(_log(tmp_path, t, q, np.ones((100, 6))), load_robot("ur10e"))


def test_saturated_currents_and_positions_outside_the_limits_are_named(tmp_path, rng):
    t = np.arange(300) * 0.01
    cur = rng.normal(0, 1, (300, 6))
    cur[100:160, 2] = 7.5  # clipped
    q = 0.1 + 1e-3 * np.outer(np.arange(300), np.ones(6))
    q[:, 1] = 7.0 + 1e-3 * np.arange(300)  # beyond the UR10e's ±2π
    robot = load_robot("ur10e")
    rec = load_recording(_log(tmp_path, t, q, cur), robot)
    assert any("joint 2 leaves its limits" in w for w in rec.warnings)
    prepared = prepare(rec, Preprocessing())  # where a clipped torque is found (preprocessing/test_channel_checks.py)
    k3 = robot.drive_gains[2]
    assert any(f"J3's torque stays at its extreme {7.5 * k3:.4g} N·m for 60 samples (t = 1.000-1.590 s)" in w
               for w in prepared.warnings)


@pytest.mark.parametrize("content, rows, message", [
    ("", None, r"no data lines \(an empty file"),
    ("\x00\x01\x02garbage\n", None, r"not a UTF-8 text table \(a binary file\?\)"),
    ("1,2,3\n" * 0, [5, 9], r"no data lines"),
])
def test_empty_and_garbage_files_say_what_they_are(tmp_path, content, rows, message):
    (tmp_path / "ur.csv").write_text(content)
    table = {"preset": "ur-rtde", "file": "ur.csv", **({"rows": rows} if rows else {})}
    with pytest.raises(DataError, match=message):
        load_recording(dataset_spec(table, tmp_path, "cfg", "ident", 6), load_robot("ur10e"))


def test_rows_beyond_the_end_of_the_file_are_refused(tmp_path):
    t = np.arange(50) * 0.01
    _log(tmp_path, t, np.zeros((50, 6)), np.ones((50, 6)))
    spec = dataset_spec({"preset": "ur-rtde", "file": "ur.csv", "rows": [10, 99999]}, tmp_path, "cfg", "ident", 6)
    with pytest.raises(DataError, match=r"ur.csv: rows = \[10, 99999\] goes beyond the file's end: it has 50 data rows"):
        load_recording(spec, load_robot("ur10e"))
    spec = dataset_spec({"preset": "ur-rtde", "file": "ur.csv", "rows": [60, 70]}, tmp_path, "cfg", "ident", 6)
    with pytest.raises(DataError, match=r"rows = \[60, 70\] selects nothing: the file has 50 data rows"):
        load_recording(spec, load_robot("ur10e"))


def _ur_jittered(tmp_path, rng):
    t = 1000.0 + np.cumsum(rng.uniform(0.006, 0.014, 400))
    q = 0.3 * np.sin(np.outer(t - t[0], np.arange(1, 7)))
    (tmp_path / "ur.csv").write_text("".join(_ur_row(tk, qk, 0.1 * qk, 2 * qk) for tk, qk in zip(t, q)))
    return load_robot("ur10e"), {"preset": "ur-rtde", "file": "ur.csv", "resample": 100.0, "time_range": [0.5, 3.0]}


def _motor_side(tmp_path, rng):
    robot = load_robot("tx40")  # coupled motors: the transmission mixes the columns
    tr = robot.transmission
    header = ",".join(f"Joint_{j + 1}" for j in range(6))
    q = rng.uniform(-1, 1, (300, 6))
    np.savetxt(tmp_path / "p.csv", (q - tr.position_offset) @ tr.motor_from_joint.T, delimiter=",", header=header, comments="")
    np.savetxt(tmp_path / "c.csv", rng.uniform(-5, 5, (300, 6)), delimiter=",", header=header, comments="")
    return robot, {"preset": "motor-side", "rate": 200.0, "positions": {"file": "p.csv", "unit": "deg"}, "torques": {"file": "c.csv"}}


@pytest.mark.parametrize("log", [_ur_jittered, _motor_side])
def test_a_spooled_recording_equals_the_one_in_memory(tmp_path, rng, log, monkeypatch):
    """Read through temporary files (as a long log is), every step gives the numbers of the in-memory path."""
    from dynid._util.column_store import StoredColumns

    monkeypatch.setattr("dynid._util.column_store.ROW_CHUNK", 64)  # the transmission in several chunks
    robot, table = log(tmp_path, rng)
    spec = dataset_spec(table, tmp_path, "cfg", "ident", 6)
    memory, spooled = load_recording(spec, robot, spool=False), load_recording(spec, robot, spool=True)
    assert isinstance(spooled.q, StoredColumns) and isinstance(spooled.tau, StoredColumns)
    np.testing.assert_array_equal(spooled.t, memory.t)
    for name in ("q", "dq", "tau"):
        a, b = getattr(memory, name), getattr(spooled, name)
        assert (a is None) == (b is None)
        if a is not None:
            np.testing.assert_allclose(np.asarray(b), a, rtol=0, atol=1e-13, err_msg=name)  # LAPACK's solve by chunks
    assert (spooled.rate, spooled.warnings) == (memory.rate, memory.warnings)


def test_signals_as_the_robot_gives_them_sign_scale_and_side(tmp_path):
    """A sign and a scale per signal (one value or one per joint) multiply it; a signal's own side overrides the
    dataset's, so motor-side torques of a log whose positions are joint side go through the gear ratios."""
    from dynid.model.description import robot_from_toml_text

    text = ('drive_terms = ["fv"]\n[transmission]\ngear_ratios = [10, -20]\n'
            + "[[joints]]\nalpha = 0.0\nmass = 1.0\ncom = [0.1, 0, 0]\ninertia = [0.01, 0.01, 0.01, 0, 0, 0]\n" * 2)
    robot = robot_from_toml_text(text, "r.toml", tmp_path)
    t = np.arange(50) * 0.01
    q = np.column_stack([np.sin(t), np.cos(t)])
    tau_m = np.column_stack([np.sin(3 * t), 0.5 + t])
    np.savetxt(tmp_path / "log.csv", np.column_stack([t, q, tau_m]), delimiter=",")
    spec = dataset_spec({"file": "log.csv", "time": {"column": 1}, "positions": {"columns": [2, 3]},
                         "torques": {"columns": [4, 5], "side": "motor", "sign": -1, "scale": [1.0, 2.0]}},
                        tmp_path, "c.toml: identification", "ident", 2)
    rec = load_recording(spec, robot)
    np.testing.assert_allclose(rec.q, q, atol=1e-12)  # joint side, no transmission
    np.testing.assert_allclose(rec.tau, -tau_m * [1.0, 2.0] * [10.0, -20.0], rtol=1e-12)  # τ = Rᵀ τ_m
    with pytest.raises(ConfigError, match=r"identification.torques.sign: expected 1 or -1 or a list of 2"):
        dataset_spec({"file": "log.csv", "time": {"column": 1}, "positions": {"columns": [2, 3]},
                      "torques": {"columns": [4, 5], "sign": [1, 2]}}, tmp_path, "c.toml: identification", "ident", 2)


def test_rows_repeating_the_previous_one_are_stale_and_interpolated(tmp_path):
    """A logger faster than its source repeats rows: with held = "interpolate" (default) each repeated row is
    replaced by linear interpolation in time between fresh rows, and the warning says how many there were."""
    t = np.arange(400) * 0.01
    q = np.outer(0.3 * t, np.ones(6))
    cur = np.outer(np.ones(400), np.arange(6)) + np.outer(t, np.ones(6))
    stale = np.zeros(400, bool)
    stale[5::4] = True  # 25 % of the rows: the previous row again
    idx = np.where(stale, np.arange(400) - 1, np.arange(400))
    spec = _log(tmp_path, t, q[idx], cur[idx])
    rec = load_recording(spec, load_robot("ur10e"))
    np.testing.assert_allclose(rec.q, q + np.asarray(load_robot("ur10e").transmission.position_offset), atol=1e-12)
    assert any("99 rows (25 %) repeat the previous one exactly" in w for w in rec.warnings)


@pytest.mark.parametrize("spool", [False, True])
def test_positions_logged_within_one_turn_are_taken_back(tmp_path, spool):
    """J6 turning on through ±π, logged in [-π, π) as a continuous joint is: every jump of a whole turn is taken back
    (the positions equal the turning angle again, as read and as stored for a long log), the warning names the joint
    and how often; J5's glitch of 4 rad, not a whole turn, is left for the other checks; the other joints untouched."""
    from dynid._util.column_store import StoredColumns

    t = np.arange(600) * 0.01
    q = 0.3 * np.sin(np.outer(t, np.arange(1, 7)))
    q[:, 5] = 2.5 + 1.5 * t  # 2.5 → 11.5 rad: through π and 3π
    q[300, 4] += 4.0
    logged = q.copy()
    logged[:, 5] = (q[:, 5] + np.pi) % (2 * np.pi) - np.pi
    rec = load_recording(_log(tmp_path, t, logged, np.full((600, 6), 0.5)), load_robot("ur10e"), spool=spool)
    assert isinstance(rec.q, StoredColumns) == spool
    np.testing.assert_allclose(np.asarray(rec.q)[:, 5], q[:, 5], atol=2e-6)  # the log holds 6 decimals
    np.testing.assert_array_equal(np.asarray(rec.q)[:, :5], np.round(q[:, :5], 6))
    said = [w for w in rec.warnings if "whole turn" in w]
    assert said == ["ident: positions jump by a whole turn (2π) between two samples, an angle logged within one turn: "
                    "taken back so that they run on (joint 6: 2 jumps)"]


@pytest.mark.parametrize("spool", [False, True])
def test_signals_of_other_rates_are_filled_in_time_and_long_holes_refused(tmp_path, spool):
    """A log that merges signals of other rates (PlotJuggler, a topics' merge): currents only every third row, empty
    before the drive's first message. The rows before are dropped, the empty fields filled by interpolation in time
    between each column's own values (linear currents: exactly), one warning; a hole longer than dynid fills is
    refused naming the line, gaps = "interpolate" fills it up to max_gap, gaps = "refuse" refuses any."""
    t = np.arange(300) * 0.01
    q = 0.1 * np.sin(np.outer(t, np.arange(1, 7)))
    cur = np.outer(1.0 + t, np.arange(1, 7))
    lines = [_ur_row(tk, qk, np.zeros(6), ik).split(",") for tk, qk, ik in zip(t, q, cur)]
    for k, fields in enumerate(lines):
        if k % 3 or k < 4:
            fields[13:19] = [""] * 6
    (tmp_path / "merged.csv").write_text("".join(",".join(f) for f in lines))
    robot = load_robot("ur10e")
    rec = load_recording(dataset_spec({"preset": "ur-rtde", "file": "merged.csv"}, tmp_path, "cfg", "ident", 6), robot,
                         spool=spool)
    np.testing.assert_allclose(rec.t, t[6:298] - t[6], atol=1e-12)  # rows 0-5 and 298-299 lack a current
    np.testing.assert_allclose(np.asarray(rec.tau), cur[6:298] * robot.drive_gains, rtol=1e-9)
    filled = 6 * sum(1 for k in range(6, 298) if k % 3)
    assert [w for w in rec.warnings if "missing" in w] == [
        f"ident: {filled} missing value(s) (empty or NaN fields) in currents of joints 1, 2, 3, 4, 5, 6: filled by "
        "interpolation in time between each column's own values (gaps = \"auto\" in [cfg]; \"refuse\" refuses them); "
        "6 row(s) before every signal started and 2 after one stopped dropped"]
    for k in range(100, 130):
        lines[k][15] = "nan"
    (tmp_path / "hole.csv").write_text("".join(",".join(f) for f in lines))
    with pytest.raises(DataError, match=r"hole.csv: line 101: joint 3's currents are missing for 32 rows in a row"):
        load_recording(dataset_spec({"preset": "ur-rtde", "file": "hole.csv"}, tmp_path, "cfg", "ident", 6), robot)
    spec = dataset_spec({"preset": "ur-rtde", "file": "hole.csv", "gaps": "interpolate", "max_gap": 0.5}, tmp_path,
                        "cfg", "ident", 6)
    assert load_recording(spec, robot, spool=spool).n_samples == 292
    with pytest.raises(DataError, match=r"merged.csv: line 8: joint 1's currents are missing .*gaps = \"refuse\""):
        load_recording(dataset_spec({"preset": "ur-rtde", "file": "merged.csv", "gaps": "refuse"}, tmp_path, "cfg",
                                    "ident", 6), robot)


@pytest.mark.parametrize("unit, factor", [("ms", 1e3), ("us", 1e6), ("ns", 1e9)])
def test_time_stamps_in_another_unit_are_named_and_read_with_it(tmp_path, unit, factor):
    """Time stamps in ms, µs or ns (ROS's are ns since the epoch): refused as seconds with the unit they look like and
    the setting; read with time = { ..., unit = ... } they give the recording in seconds."""
    t = np.arange(300) * 0.008
    q = 0.1 * np.sin(np.outer(t, np.arange(1, 7)))
    stamps = (1.7e9 + t) * factor if unit == "ns" else t * factor
    header = "t," + ",".join(f"q{j}" for j in range(1, 7)) + "," + ",".join(f"i{j}" for j in range(1, 7))
    np.savetxt(tmp_path / "log.csv", np.column_stack([stamps, q, np.ones_like(q)]), delimiter=",", header=header,
               comments="", fmt="%.17g")
    table = {"file": "log.csv", "header": True, "time": {"column": "t"},
             "positions": {"columns": [f"q{j}" for j in range(1, 7)]},
             "currents": {"columns": [f"i{j}" for j in range(1, 7)]}}
    robot = load_robot("ur10e")
    with pytest.raises(DataError, match=rf"log.csv: the time stamps step by .* they look like {unit} "
                                        rf"\(time = \{{ \.\.\., unit = \"{unit}\" \}}\)"):
        load_recording(dataset_spec(table, tmp_path, "cfg", "ident", 6), robot)
    table["time"] = {"column": "t", "unit": unit}
    rec = load_recording(dataset_spec(table, tmp_path, "cfg", "ident", 6), robot)
    assert rec.n_samples == 300 and abs(rec.rate - 125.0) < 0.01  # ns since the epoch: float64 keeps 0.25 µs
    if unit == "ns":  # resampled onto a grid of its 0.25 µs steps: the motion at the grid's times
        np.testing.assert_allclose(np.asarray(rec.q), 0.1 * np.sin(np.outer(rec.t, np.arange(1, 7))), atol=5e-5)
    else:
        np.testing.assert_allclose(np.asarray(rec.q), q, atol=1e-12)


def test_signals_of_two_topics_in_alternate_rows_are_filled_in_time(tmp_path):
    """PlotJuggler's CSV of two topics published in turn: each row holds one topic's fields, the other's empty. No
    row holds every signal (that was refused as "no two rows hold every signal"); from the row where both have
    started to the one where the first stops, each column is filled between its own values (linear: exactly)."""
    t = np.arange(201) * 0.004
    q = np.outer(0.1 + t, np.arange(1, 7) * 0.1)
    cur = np.outer(1.0 + t, np.arange(1, 7))
    header = ["__time"] + [f"/joint_states/position[{j}]" for j in range(6)] + [f"/currents/data[{j}]" for j in range(6)]
    rows = [",".join([f"{tk:.6f}"] + ([f"{x:.9g}" for x in q[k]] + [""] * 6 if k % 2 == 0 else
                                      [""] * 6 + [f"{x:.9g}" for x in cur[k]])) for k, tk in enumerate(t)]
    (tmp_path / "pj.csv").write_text("\n".join([",".join(header), *rows]) + "\n")
    table = {"file": "pj.csv", "header": True, "time": {"column": "__time"},
             "positions": {"columns": header[1:7]}, "currents": {"columns": header[7:]}}
    robot = load_robot("ur10e")
    rec = load_recording(dataset_spec(table, tmp_path, "cfg", "ident", 6), robot)
    assert rec.n_samples == 199  # rows 1-199: the currents start at row 1, the positions stop at row 200
    np.testing.assert_allclose(np.asarray(rec.q), q[1:200] + robot.transmission.position_offset, atol=1e-8)
    np.testing.assert_allclose(np.asarray(rec.tau), cur[1:200] * robot.drive_gains, rtol=1e-8)
    assert any("1 row(s) before every signal started and 1 after one stopped dropped" in w for w in rec.warnings)


@pytest.mark.parametrize("spool", [False, True])
def test_a_velocity_channel_not_logged_is_left_out_and_said(tmp_path, spool):
    """A logger that writes 0 for the velocities it does not fill: joint 3's velocities read 0 throughout while its
    positions span 0.6 rad. The measured velocities are left out (one warning naming the joint), so the recording is
    the one of the same log without velocity columns; a joint held still with velocity 0 is not taken for that."""
    t = np.arange(400) * 0.008
    q = 0.3 * np.sin(np.outer(t, np.arange(1, 7)))
    q[:, 5] = 0.2  # J6 held still: its velocity 0 is right
    dq = 0.3 * np.cos(np.outer(t, np.arange(1, 7))) * np.arange(1, 7)
    dq[:, 5] = 0.0
    cur = np.sin(np.outer(t, np.ones(6)))
    (tmp_path / "live.csv").write_text("".join(_ur_row(*r) for r in zip(t, q, dq, cur)))
    dq[:, 2] = 0.0
    (tmp_path / "dead.csv").write_text("".join(_ur_row(*r) for r in zip(t, q, dq, cur)))
    robot = load_robot("ur10e")
    live, dead = (load_recording(dataset_spec({"preset": "ur-rtde", "file": f"{name}.csv"}, tmp_path, "cfg", "ident",
                                              6), robot, spool=spool) for name in ("live", "dead"))
    assert live.dq is not None and not [w for w in live.warnings if "velocit" in w]
    without = load_recording(dataset_spec({"file": "dead.csv", "header": False, "time": {"column": 1},
                                           "positions": {"columns": [2, 3, 4, 5, 6, 7]},
                                           "currents": {"columns": [14, 15, 16, 17, 18, 19]}}, tmp_path, "cfg",
                                          "ident", 6),
                             robot, spool=spool)
    assert dead.dq is None and without.dq is None
    np.testing.assert_array_equal(np.asarray(dead.q), np.asarray(without.q))
    np.testing.assert_array_equal(np.asarray(dead.tau), np.asarray(without.tau))
    assert [w for w in dead.warnings if w not in without.warnings] == [
        "ident: joint 3's measured velocities read 0 rad/s throughout while the positions span up to 0.6 rad (a "
        "velocity channel not logged?): every joint's velocities are left out and derived from the positions"]


def test_a_position_step_the_joint_stays_at_is_refused_a_spike_is_read(tmp_path):
    """An encoder homed again mid-log: joint 2's positions step by 0.5 rad between two samples and stay there (the
    filtered derivative would be a torque-sized spike, one side of the log off by 0.5 rad): refused naming the joint,
    the step and its time. A one-sample spike of the same size, which the filters pass over, and a log whose
    description understates the joint's velocity limit are read."""
    t = np.arange(600) * 0.008
    q = 0.3 * np.sin(np.outer(t, np.arange(1, 7)))
    cur = np.cos(np.outer(t, np.ones(6)))
    step, spike = q.copy(), q.copy()
    step[300:, 1] += 0.5
    spike[300, 1] += 0.5
    for name, x in (("step", step), ("spike", spike)):
        rows = (_ur_row(tk, qk, np.zeros(6), ik) for tk, qk, ik in zip(t, x, cur))
        (tmp_path / f"{name}.csv").write_text("".join(rows))
    robot = load_robot("ur10e")
    spec = dataset_spec({"preset": "ur-rtde", "file": "step.csv"}, tmp_path, "cfg", "ident", 6)
    jump = step[300, 1] - step[299, 1]
    with pytest.raises(DataError, match=rf"step.csv: joint 2's position steps by {jump:.4g} rad at t = 2.400 s and "
                                        r"stays there, faster than the joint moves \(limit 2.09 rad/s\): an encoder "
                                        r"homed again"):
        load_recording(spec, robot)
    read = load_recording(dataset_spec({"preset": "ur-rtde", "file": "spike.csv"}, tmp_path, "cfg", "ident", 6), robot)
    np.testing.assert_allclose(np.asarray(read.q)[300, 1], spike[300, 1], atol=1e-6)
    slow = replace(robot, limits=replace(robot.limits, dq_max=np.full(6, 0.01)))  # 1/100 of what the log moves at
    (tmp_path / "plain.csv").write_text("".join(_ur_row(tk, qk, np.zeros(6), ik) for tk, qk, ik in zip(t, q, cur)))
    plain = load_recording(dataset_spec({"preset": "ur-rtde", "file": "plain.csv"}, tmp_path, "cfg", "ident", 6), slow)
    np.testing.assert_allclose(np.asarray(plain.q), q, atol=1e-6)


def test_velocities_false_leaves_a_presets_velocities_out(tmp_path):
    """velocities = false: a preset's velocity columns are not read (derived from the positions), as the refusals of
    measured velocities unlike the positions advise; velocities = true says what it takes."""
    t = np.arange(100) * 0.008
    q = 0.3 * np.sin(np.outer(t, np.arange(1, 7)))
    dq = 0.3 * np.cos(np.outer(t, np.arange(1, 7))) * np.arange(1, 7)
    (tmp_path / "ur.csv").write_text("".join(_ur_row(tk, qk, vk, np.ones(6)) for tk, qk, vk in zip(t, q, dq)))
    robot = load_robot("ur10e")
    given = load_recording(dataset_spec({"preset": "ur-rtde", "file": "ur.csv"}, tmp_path, "cfg", "ident", 6), robot)
    left = load_recording(dataset_spec({"preset": "ur-rtde", "file": "ur.csv", "velocities": False}, tmp_path, "cfg",
                                       "ident", 6), robot)
    assert given.dq is not None and left.dq is None
    np.testing.assert_array_equal(np.asarray(left.q), np.asarray(given.q))
    with pytest.raises(ConfigError, match=r"cfg.velocities: expected a table with 'columns', or false for none"):
        dataset_spec({"preset": "ur-rtde", "file": "ur.csv", "velocities": True}, tmp_path, "cfg", "ident", 6)


@pytest.mark.parametrize("spool", [False, True])
def test_isolated_spikes_in_the_currents_are_replaced_and_said(tmp_path, rng, spool):
    """Five one-sample spikes of +40 A in J2's current (a bus glitch; its standard deviation is about 1 A) were fitted
    as torque: on a simulated UR5 log 50 such spikes tripled the validation error and made a 11-sample torque delay
    finding up. Each is now replaced by the median of the five samples around it, one warning naming the log, the
    joint, the count and the largest; the other samples, and a log without spikes, are read bit for bit as before."""
    from dynid.io.logs.log_repairs import SPIKE_SPREADS

    t = np.arange(600) * 0.01
    q = 0.3 * np.sin(np.outer(t, np.arange(1, 7)))
    cur = np.sin(np.outer(t, 0.5 * np.arange(1, 7))) + 0.01 * rng.standard_normal((600, 6))
    clean = load_recording(_log(tmp_path, t, q, cur, "clean.csv"), load_robot("ur10e"), spool=spool)
    assert not any("spike" in w for w in clean.warnings)
    where = np.array([50, 120, 300, 301 + 100, 555])
    spiked = cur.copy()
    spiked[where, 1] += 40.0
    rec = load_recording(_log(tmp_path, t, q, spiked, "spiked.csv"), load_robot("ur10e"), spool=spool)
    (said,) = [w for w in rec.warnings if "spike" in w]
    assert re.match(r"ident: J2's current has 5 isolated spike\(s\), up to 4\d(\.\d+)? A from the samples around them",
                    said) and f"over {SPIKE_SPREADS:g}× the channel's standard deviation" in said
    gain = load_robot("ur10e").drive_gains[1]
    written = np.round(spiked[:, 1], 6)  # as the CSV holds them
    expected = written.copy()
    for k in where:
        expected[k] = np.median(written[k - 2:k + 3])
    np.testing.assert_allclose(np.asarray(rec.tau)[:, 1], gain * expected, rtol=1e-12)
    np.testing.assert_array_equal(np.delete(np.asarray(rec.tau), 1, axis=1), np.delete(np.asarray(clean.tau), 1, axis=1))


def test_a_channel_mostly_at_one_value_has_no_spikes(tmp_path):
    """J2's current at its limit 1.5 A in 597 of 600 samples, leaving it for one sample at a time: each such sample is
    over 10 of that channel's standard deviations from its neighbours, but they are its motion, not glitches (the
    clipped-channel check judges that channel); nothing is replaced or said."""
    t = np.arange(600) * 0.01
    q = 0.3 * np.sin(np.outer(t, np.arange(1, 7)))
    cur = np.sin(np.outer(t, 0.5 * np.arange(1, 7)))
    cur[:, 1] = 1.5
    cur[[100, 300, 500], 1] = 1.2
    rec = load_recording(_log(tmp_path, t, q, cur), load_robot("ur10e"))
    assert not any("spike" in w for w in rec.warnings)
    np.testing.assert_allclose(np.asarray(rec.tau)[:, 1], load_robot("ur10e").drive_gains[1] * cur[:, 1], rtol=1e-12)


def test_positions_and_velocities_in_degrees_are_read_in_radians(tmp_path):
    """unit = "deg" (and "deg/s") converts at input: a log in degrees read as radians went through every estimate
    without a failing test (the conversion was only checked through stored figures)."""
    t = np.arange(200) * 0.01
    deg = np.outer(np.sin(2 * np.pi * 0.5 * t), [10.0, -20.0, 30.0, 5.0, 45.0, 60.0])
    header = ["t", *(f"q{j}" for j in range(1, 7)), *(f"v{j}" for j in range(1, 7)), *(f"tau{j}" for j in range(1, 7))]
    np.savetxt(tmp_path / "d.csv", np.column_stack([t, deg, 2 * deg, np.ones((200, 6))]), delimiter=",",
               header=",".join(header), comments="")
    spec = dataset_spec({"file": "d.csv", "header": True, "time": {"column": "t"},
                         "positions": {"columns": header[1:7], "unit": "deg"},
                         "velocities": {"columns": header[7:13], "unit": "deg/s"},
                         "torques": {"columns": header[13:]}}, tmp_path, "c.toml: identification", "ident", 6)
    rec = load_recording(spec, load_robot("ur10e"))
    np.testing.assert_allclose(rec.q, np.deg2rad(deg), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(rec.dq, np.deg2rad(2 * deg), rtol=1e-12, atol=1e-12)


def test_a_log_without_time_stamps_is_read_by_its_path_with_the_rate_given(tmp_path, rng):
    """load_recording(path, robot) of a CSV without a time column said "give its sample rate: dynid init ... --rate HZ"
    and had no way to take it: load_recording(path, robot, rate=HZ) reads it as dynid init --rate does (one sample
    every 1/rate s, the values as written); a rate beside a config's dataset, or not above 0, is refused in one line."""
    robot = load_robot("er16")
    q, tau = rng.uniform(-1, 1, (40, 6)), rng.uniform(-50, 50, (40, 6))
    log = tmp_path / "no_time.csv"
    header = ",".join([f"q{j + 1}" for j in range(6)] + [f"tau{j + 1}" for j in range(6)])
    log.write_text(header + "\n" + "\n".join(",".join(f"{x:.9f}" for x in row) for row in np.hstack([q, tau])) + "\n")
    with pytest.raises(DataError, match=r"no time column .*give its sample rate: load_recording\(\.\.\., rate=HZ\)$"):
        load_recording(log, robot)
    recording = load_recording(log, robot, rate=50.0)
    np.testing.assert_allclose(recording.t, np.arange(40) / 50.0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(recording.q, q, rtol=0, atol=1e-9)
    np.testing.assert_allclose(recording.tau, tau, rtol=0, atol=1e-9)
    assert recording.rate == 50.0
    for rate in (0.0, -5.0, float("nan"), "50"):
        with pytest.raises(ConfigError, match="^load_recording: rate: expected a sample rate in Hz above 0"):
            load_recording(log, robot, rate=rate)
    spec = dataset_spec({"file": "no_time.csv", "rate": 50.0, "positions": {"columns": list(range(1, 7))},
                         "torques": {"columns": list(range(7, 13))}}, tmp_path, "cfg", "ident", 6)
    with pytest.raises(ConfigError, match="^load_recording: rate is for a log given by its path"):
        load_recording(spec, robot, rate=50.0)


@pytest.mark.parametrize("reader", ["lines", "pyarrow"])
def test_reading_a_log_says_its_share_done_as_it_goes(tmp_path, rng, monkeypatch, reader):
    """Issue "Fast where users wait", item 3: a log's reading reports its share done as its blocks are read (either
    reader), rising to the whole once the recording is ready, the files' bytes within their share of the step; the
    recording is the one read without it."""
    import dynid.io.logs.datasets as datasets
    import dynid.io.logs.table_files as tables

    robot = load_robot("ur10e")
    t = np.arange(4000) * 0.002
    q = np.sin(np.outer(t, np.arange(1, 7) * 0.3))
    (tmp_path / "ur.csv").write_text("".join(_ur_row(tk, qk, qk * 0 + 0.5, qk * 2) for tk, qk in zip(t, q)))
    spec = dataset_spec({"preset": "ur-rtde", "file": "ur.csv"}, tmp_path, "cfg", "ident", 6)
    monkeypatch.setattr(tables, "BLOCK", 500)  # the line reader's blocks
    if reader == "pyarrow":
        monkeypatch.setattr(tables, "ARROW_BYTES", -1)
        monkeypatch.setattr(tables, "ARROW_BLOCK", 40_000)
    calls = []
    rec = load_recording(spec, robot, progress=lambda done, total: calls.append(done / total))
    assert len(calls) >= 8 and calls[-1] == 1.0 and all(b >= a for a, b in zip(calls, calls[1:])), calls
    reading = [c for c in calls if c <= datasets.READ_SHARE]
    assert len(reading) >= 6 and reading[-1] == pytest.approx(datasets.READ_SHARE), calls  # every byte read
    assert 0 < calls[0] < 0.5 * datasets.READ_SHARE  # the first block: a share, not the whole
    again = load_recording(spec, robot)
    assert np.array_equal(rec.q, again.q) and np.array_equal(rec.tau, again.tau)

"""``dynid monitor``: recursive least squares against its closed form, the CUSUM against its design, and a simulated
worn joint found in its logs (and nothing found where nothing changed)."""

import json

import numpy as np
import pytest

from dynid.estimators.recursive import RecursiveLeastSquares
from dynid.exceptions import ShapeError
from dynid.fleet.change_detection import Cusum, cusum_threshold
from dynid.studies.simulated_fleet import simulate_service_life

from ..cli.refusals import assert_refused, dynid


def test_recursive_least_squares_is_the_regularised_batch_solution():
    rng = np.random.default_rng(0)
    m, n, q = 400, 3, 3
    phi, theta_true = rng.normal(size=(m, n, q)), rng.normal(size=(n, q))
    y = np.einsum("mnq,nq->mn", phi, theta_true) + 0.1 * rng.normal(size=(m, n))
    theta0, p0 = rng.normal(size=(n, q)), 5.0
    rls = RecursiveLeastSquares(theta0, p0, forgetting=1.0)
    rls.update(phi[:150], y[:150])
    got = rls.update(phi[150:], y[150:])
    for j in range(n):  # argmin |y - Aθ|² + |θ - θ0|²/p0
        a = phi[:, j, :]
        expected = np.linalg.solve(a.T @ a + np.eye(q) / p0, a.T @ y[:, j] + theta0[j] / p0)
        np.testing.assert_allclose(got[j], expected, rtol=1e-8)
    # with forgetting, the estimate follows a change: the old samples fade
    rls = RecursiveLeastSquares(np.zeros((n, q)), 1e3, forgetting=0.98)
    rls.update(phi[:200], y[:200])
    shifted = rls.update(phi[200:], y[200:] + 2.0 * phi[200:, :, 0])
    np.testing.assert_allclose(shifted[:, 0], theta_true[:, 0] + 2.0, atol=0.1)
    with pytest.raises(ShapeError):
        rls.update(phi[:, :, :2], y)


def test_the_cusum_keeps_its_false_alarm_rate_and_dates_a_change():
    rng = np.random.default_rng(1)
    h = cusum_threshold(200.0, charts=2)  # one two-sided chart: a false alarm every 200 values on average
    runs = []
    for _ in range(300):
        chart, i = Cusum(1, h), 0
        while not chart.update(rng.normal(size=1)):
            i += 1
        runs.append(i + 1)
    assert 120 < np.mean(runs) < 330  # Siegmund's approximation (design 200)
    chart = Cusum(1, cusum_threshold(1e6, 2))
    z = np.r_[rng.normal(size=100), rng.normal(size=40) + 3.0]
    alarms = [a for v in z for a in chart.update(np.array([v]))]
    assert alarms and alarms[0].direction == 1 and abs(alarms[0].start - 100) <= 2 and 100 < alarms[0].index < 110
    assert 2.0 < alarms[0].shift < 4.0


def _identified(root):
    out = root / "id"
    p = dynid("identify", root / "unit.toml", "--out", out, "--no-figures", "-q")
    assert p.returncode == 0, p.stderr
    return out / "results.json"


@pytest.fixture(scope="module")
def worn_joint(tmp_path_factory):
    """A 10 % rise of joint 3's viscous friction on day 14 (of 1-minute logs, one a day; the first 12 are the
    reference), the unit identified, and ``dynid monitor`` run once over every log: the folder, the results.json, and
    the monitor's process and output folder (two tests read them; neither writes into the folder)."""
    root = tmp_path_factory.mktemp("worn")
    simulate_service_life(root, days=18, seconds=60.0, rate=250.0, wear_joint=3, wear_start_day=14.0, wear_per_day=0.0,
                          step=0.10, coulomb=False, rng=3)
    results = _identified(root)
    p = dynid("monitor", root / "unit.toml", "--logs", root / "logs", "--results", results, "--out", root / "once")
    return root, results, p


def test_dynid_monitor_names_the_joint_whose_viscous_friction_rose(worn_joint):
    """The alarm names joint 3 and its viscous friction, within 60 s of logs of the change, with its size; no other
    term alarms."""
    root, _, p = worn_joint
    assert p.returncode == 0, p.stderr
    report = json.loads((root / "once" / "monitor.json").read_text())
    alarms = report["alarms"]
    assert [(a["joint"], a["term"]) for a in alarms] == [(3, "fv3")]
    a = alarms[0]
    assert a["detected_log"] == "2026-01-15T00-00.csv" and a["since_log"] == "2026-01-15T00-00.csv"
    assert a["detected_s"] <= 60.0 and a["delay_s"] <= 60.0
    assert a["change_percent"] == pytest.approx(10.0, abs=2.0)
    assert "joint 3: viscous friction (fv3) rose" in " ".join((p.stdout + p.stderr).split())
    assert (root / "once" / "monitor.png").is_file() and (root / "once" / "monitor.parquet").is_file()


def test_dynid_monitor_goes_on_from_its_state_as_one_run_would(worn_joint, tmp_path):
    """A folder that grows (14 daily logs, then 4 more, the change on the 15th): run once a day, the monitor goes on
    from its state in --out, reads only the new logs, and writes the very monitor.json one run over every log writes;
    its state refuses other settings and a new log dated before the last one it saw; --restart starts over."""
    import shutil

    root, results, p = worn_joint
    assert p.returncode == 0, p.stderr
    files = sorted((root / "logs").glob("*.csv"))
    growing = tmp_path / "growing"
    growing.mkdir()

    def run(folder, out, *extra):
        return dynid("monitor", root / "unit.toml", "--logs", folder, "--results", results, "--out", out, *extra)

    for f in files[:14]:
        shutil.copy(f, growing / f.name)
    p = run(growing, tmp_path / "daily")
    assert p.returncode == 0, p.stderr
    assert json.loads((tmp_path / "daily" / "monitor.json").read_text())["alarms"] == []  # the change is in log 15
    assert (tmp_path / "daily" / "monitor-state.json").is_file()
    for f in files[14:]:
        shutil.copy(f, growing / f.name)
    p = run(growing, tmp_path / "daily")
    assert p.returncode == 0, p.stderr
    assert "went on from an earlier run's state (14 logs seen then, 4 new)" in " ".join(p.stdout.split())
    once = json.loads((root / "once" / "monitor.json").read_text())
    daily = json.loads((tmp_path / "daily" / "monitor.json").read_text())
    assert daily == once and [a["term"] for a in daily["alarms"]] == ["fv3"]

    assert_refused(run(growing, tmp_path / "daily", "--window", "5"), "monitor-state.json: made from another "
                   "identification or with other monitor settings")
    shutil.copy(files[0], growing / "2025-12-31T00-00.csv")
    assert_refused(run(growing, tmp_path / "daily"), "2025-12-31T00-00.csv: a new log that sorts before")
    (growing / "2025-12-31T00-00.csv").unlink()
    (tmp_path / "daily" / "monitor-state.json").write_bytes(b"not a state")
    assert_refused(run(growing, tmp_path / "daily"), "monitor-state.json: not a monitor state dynid can read")
    p = run(growing, tmp_path / "daily", "--restart")
    assert p.returncode == 0, p.stderr
    assert json.loads((tmp_path / "daily" / "monitor.json").read_text()) == once and "went on" not in p.stdout


def test_dynid_monitor_raises_no_alarm_where_nothing_changed(tmp_path):
    """Two hours of logs (120 one-minute logs at 100 Hz) of an unchanged robot: no alarm. The 24-hour figure is
    measured by benchmarks/bench_monitor.py."""
    simulate_service_life(tmp_path, days=120, seconds=60.0, rate=100.0, wear_start_day=1e9, rng=4)
    results = _identified(tmp_path)
    p = dynid("monitor", tmp_path / "unit.toml", "--logs", tmp_path / "logs", "--results", results, "--out", tmp_path / "m")
    assert p.returncode == 0, p.stderr
    report = json.loads((tmp_path / "m" / "monitor.json").read_text())
    assert report["alarms"] == [] and len(report["windows"]) >= 600
    assert "no change" in p.stdout


def test_monitor_refusals(tmp_path):
    simulate_service_life(tmp_path, days=2, seconds=20.0, rate=100.0, rng=5)
    (tmp_path / "empty").mkdir()
    p = dynid("monitor", tmp_path / "unit.toml", "--logs", tmp_path / "empty", "--results", tmp_path / "none.json",
              "--out", tmp_path / "m")
    assert_refused(p, "no log matching")
    p = dynid("monitor", tmp_path / "unit.toml", "--logs", tmp_path / "logs", "--window", "0", "--out", tmp_path / "m")
    assert_refused(p, "--window must be a positive number of seconds")
    p = dynid("monitor", tmp_path / "unit.toml", "--logs", tmp_path / "logs", "--results", tmp_path / "none.json",
              "--out", tmp_path / "m")
    assert_refused(p, "none.json")


def test_a_log_still_being_written_is_left_for_the_next_run(tmp_path):
    """The newest log of a growing folder is half written (its last line unfinished): the run says so and leaves it;
    once complete, the next run reads it, and monitor.json is the one run over every log's (it was read half and
    never again). A log that changed after the monitor read it is refused in one line."""
    import shutil

    simulate_service_life(tmp_path, days=8, seconds=60.0, rate=100.0, wear_start_day=1e9, rng=4)
    results = _identified(tmp_path)
    files = sorted((tmp_path / "logs").glob("*.csv"))
    growing = tmp_path / "growing"
    growing.mkdir()

    def run(folder, out):
        return dynid("monitor", tmp_path / "unit.toml", "--logs", folder, "--results", results, "--out", out,
                     "--reference-windows", "10")

    p = run(tmp_path / "logs", tmp_path / "once")
    assert p.returncode == 0, p.stderr
    for f in files[:-1]:
        shutil.copy(f, growing / f.name)
    whole = files[-1].read_bytes()
    (growing / files[-1].name).write_bytes(whole[: len(whole) // 2 - 7])  # a logger half-way through a line
    p = run(growing, tmp_path / "daily")
    assert p.returncode == 0, p.stderr
    assert f"{files[-1].name}: still being written (its last line is unfinished): left for the next run" in \
        " ".join((p.stdout + p.stderr).split())
    assert files[-1].name not in json.loads((tmp_path / "daily" / "monitor.json").read_text())["logs"]
    (growing / files[-1].name).write_bytes(whole)
    p = run(growing, tmp_path / "daily")
    assert p.returncode == 0, p.stderr
    assert json.loads((tmp_path / "daily" / "monitor.json").read_text()) == \
        json.loads((tmp_path / "once" / "monitor.json").read_text())
    with open(growing / files[0].name, "ab") as fh:  # an old log written to again
        fh.write(whole.splitlines(keepends=True)[-1])
    assert_refused(run(growing, tmp_path / "daily"), f"{files[0].name}: changed since the monitor read it")


def test_only_the_newest_log_is_left_as_still_being_written_and_only_while_it_changes(tmp_path):
    """A log whose last line has no newline was taken as still being written wherever it stood: the UR10e's RTDE logs
    of Mamedov & Mikhel end without one, and the first of them left every log for the next run ("0 windows"). Only the
    newest log may be in progress, and only while it changes (:data:`WRITING_AGE`): an older one, or one unchanged for
    longer, is read."""
    import os

    from dynid.fleet.monitor import WRITING_AGE, _complete

    logs = []
    for i, ending in enumerate((b"1,2\n3,4", b"1,2\n3,4\n", b"1,2\n3,")):  # no newline, one, a row cut short
        path = tmp_path / f"log{i}.csv"
        path.write_bytes(ending)
        logs.append(path)
    now = logs[-1].stat().st_mtime + 1.0
    kept, deferred = _complete(logs, now=now)
    assert kept == logs[:2] and deferred == ("log2.csv: still being written (its last line is unfinished): left for "
                                             "the next run",)
    old = now - 2 * WRITING_AGE
    os.utime(logs[-1], (old, old))
    assert _complete(logs, now=now) == (logs, ())
    assert _complete(logs[:1], now=logs[0].stat().st_mtime + 2 * WRITING_AGE) == (logs[:1], ())


def test_a_term_that_keeps_drifting_is_read_against_its_first_reference_and_its_level_now(tmp_path):
    """Joint 3's friction rising 3 % a day from day 10 for 30 days: every rise is said (the chart follows the term's
    new level after each alarm), and the table, the title and monitor.json read the term against the reference it
    first learned (the first 60 windows) and at its level now (the windows of the last minute), both against the
    simulated truth; the relearned level is no reference."""
    truth = simulate_service_life(tmp_path, days=40, seconds=60.0, rate=100.0, wear_joint=3, wear_start_day=10.0,
                                  wear_per_day=0.03, coulomb=True, rng=3)
    results = _identified(tmp_path)
    p = dynid("monitor", tmp_path / "unit.toml", "--logs", tmp_path / "logs", "--results", results, "--out", tmp_path / "m")
    assert p.returncode == 0, p.stderr
    report = json.loads((tmp_path / "m" / "monitor.json").read_text())
    factor = json.loads((tmp_path / "truth.json").read_text())["logs"][-1]["friction_factor"]
    assert factor > 1.8
    first = [w["terms"]["fc3"] for w in report["windows"][:60]]
    for term, value in (("fc3", truth.coulomb[2]), ("fv3", truth.viscous[2])):
        assert sum(a["term"] == term for a in report["alarms"]) >= 2
        assert report["reference"][term]["mean"] == pytest.approx(value, rel=0.03)
        assert report["latest"][term] == pytest.approx(value * factor, rel=0.03)
        assert report["changed_percent"][term] == pytest.approx(100 * (factor - 1), abs=6.0)
    assert report["reference"]["fc3"]["mean"] == pytest.approx(np.mean(first), rel=1e-9)
    text = " ".join(p.stdout.split())
    change = report["changed_percent"]["fc3"]
    assert f"joint 3 fc3 {change:+.3g} % since the reference" in text

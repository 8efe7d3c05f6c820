"""The flipped-sign check judges the torque beyond the friction the description's nominal model may lack (issue "Honest
on any log"): a sign flipped in the log is still named; a short log whose friction runs against the nominal model is
not called flipped."""

import json
import re

import numpy as np
import pytest

from dynid.validation.torques import TorqueSums

from ..cli.refusals import dynid
from ..conftest import shared_data
from ..simulated_logs import simulated_case


def test_the_partial_correlation_is_that_of_the_residuals_of_a_direct_regression(rng):
    """Against NumPy: both the prediction and the torque regressed on the nuisance columns (with an intercept),
    then np.corrcoef of the two residuals and the slope of one on the other; on joint 0 with two nuisance columns, on
    joint 1 with none."""
    m, n, p = 3000, 2, 5
    y = rng.standard_normal((m, n, p))
    beta = rng.standard_normal(p)
    tau = y @ (beta * rng.uniform(-1, 1, p)) + 0.3 * rng.standard_normal((m, n)) + 2.0
    sums = TorqueSums(n, p, m)
    for a in range(0, m, 700):
        sums.add(np.arange(a, min(a + 700, m)) * 0.01, y[a:a + 700], tau[a:a + 700])
    got, slope = sums.beyond(beta, {0: [1, 3]})
    for j, cols in ((0, [1, 3]), (1, [])):
        x = np.column_stack([np.ones(m), *(y[:, j, c] for c in cols)])
        pred, meas = y[:, j] @ beta, tau[:, j]
        rp = pred - x @ np.linalg.lstsq(x, pred, rcond=None)[0]
        rt = meas - x @ np.linalg.lstsq(x, meas, rcond=None)[0]
        assert got[j] == pytest.approx(np.corrcoef(rp, rt)[0, 1], abs=1e-10)
        assert slope[j] == pytest.approx((rp @ rt) / (rp @ rp), rel=1e-10)


def test_a_flipped_torque_sign_is_still_named(tmp_path):
    """J2's current written with the wrong sign in the identification log: the verdict names J2 and the fix."""
    cfg, _ = simulated_case(tmp_path, "er16", 125.0, "fourier", duration=20.0)
    data = np.loadtxt(tmp_path / "ident.csv", delimiter=",")
    data[:, 1 + 6 + 1] *= -1  # time, 6 positions, then J1's current: J2's flipped
    np.savetxt(tmp_path / "ident.csv", data, delimiter=",", fmt="%.10g")
    p = dynid("identify", cfg, "--out", tmp_path / "out", "--no-figures")
    assert p.returncode == 0, p.stderr
    findings = json.loads((tmp_path / "out" / "results.json").read_text())["findings"]
    (sign,) = [f for f in findings if f["kind"] == "sign"]
    assert "J2" in sign["text"] and "sign = [1, -1, 1, 1, 1, 1]" in sign["text"]
    # a model fitted to a log read otherwise is not the robot's: no URDF or MJCF beside the results (they were
    # written, and their header said nothing of it); dynid export writes it when asked, with the finding as a warning
    assert not list((tmp_path / "out").glob("*.urdf")) and not list((tmp_path / "out").glob("*.xml"))
    said = " ".join(p.stderr.split())
    assert "no URDF or MJCF written: the log identification is read otherwise than the robot file (a torque's sign" in said
    assert "files_withheld" in json.loads((tmp_path / "out" / "results.json").read_text())
    assert "No URDF or MJCF written: the log identification is read otherwise" in (tmp_path / "out" / "report.html").read_text()
    e = dynid("export", cfg, "--results", tmp_path / "out" / "results.json", "--urdf", tmp_path / "asked.urdf")
    assert e.returncode == 0 and (tmp_path / "asked.urdf").is_file() and "dynid identify doubts" in e.stderr


def test_one_joints_flipped_sign_that_the_fit_cannot_follow_is_named(tmp_path):
    """J3's torque negated in both logs of ``dynid example ur10e``: the fit cannot follow one joint's sign (the links
    are shared), so J3's residual is as large as its torque, and the check that asked J3's torque to vary beyond that
    residual judged nothing (ρ beyond friction -0.9999, no word, "ready"). Its torque is judged against the noise floor
    of the samples: J3 is named, with the fix, and the model is not called ready."""
    assert dynid("example", "ur10e", tmp_path / "try", "-q").returncode == 0
    for name in ("identification.csv", "validation.csv"):
        path = tmp_path / "try" / name
        header = path.read_text().splitlines()[0]
        data = np.loadtxt(path, delimiter=",", skiprows=1)
        data[:, header.split(",").index("elbow_joint_effort")] *= -1
        np.savetxt(path, data, delimiter=",", header=header, comments="", fmt="%.10g")
    p = dynid("identify", tmp_path / "try" / "ur10e.toml", "--out", tmp_path / "out", "--no-figures")
    assert p.returncode == 0, p.stderr
    results = json.loads((tmp_path / "out" / "results.json").read_text())
    assert results["diagnostics"]["nominal_correlation_beyond_friction"][2] < -0.9  # what the check sees
    (sign,) = [f for f in results["findings"] if f["kind"] == "sign"]
    assert "J3" in sign["text"] and "sign = [1, 1, -1, 1, 1, 1]" in sign["text"]
    assert "not ready: the measured torques run against the model" in " ".join((p.stdout + p.stderr).split())


def test_a_flipped_sign_that_friction_hides_from_the_plain_correlation_is_named(tmp_path):
    """J1's current negated in the UR10e's identification log: J1's torque is mostly friction, which the nominal model
    lacks, so its plain correlation with that model is only -0.36, while beyond its friction it is -0.98. The check
    took the larger of the two and said nothing (the fit then bent the other joints' parameters to the flipped
    torque). The correlation beyond friction now judges wherever it is known: J1 is named, with the fix."""
    from pathlib import Path

    root = shared_data("ur10e_mamedov2020")
    data = tmp_path / "data"
    (data / "identification_data").mkdir(parents=True)
    for item in root.iterdir():
        if item.name != "identification_data":
            (data / item.name).symlink_to(item)
    name = "ur-20_02_10-30sec_12harm.csv"
    for item in (root / "identification_data").iterdir():  # the drive gains' runs as they are
        if item.name != name:
            (data / "identification_data" / item.name).symlink_to(item)
    rows = [line.split(",") for line in (root / "identification_data" / name).read_text().splitlines()]
    for row in rows:
        row[13] = f"{-float(row[13]):.6f}"  # J1's current (column 14 of the ur-rtde preset)
    (data / "identification_data" / name).write_text("\n".join(",".join(row) for row in rows) + "\n")
    text = (Path(__file__).resolve().parents[2] / "configs" / "ur10e.toml").read_text()
    (tmp_path / "c.toml").write_text(text.replace('data_root = "../../shared/data/ur10e_mamedov2020"',
                                                  f'data_root = "{data}"'))
    p = dynid("identify", tmp_path / "c.toml", "--out", tmp_path / "out", "--no-figures", "--no-validate")
    assert p.returncode == 0, p.stderr
    results = json.loads((tmp_path / "out" / "results.json").read_text())
    assert results["diagnostics"]["nominal_correlation"][0] > -0.5  # what the larger of the two gave
    assert results["diagnostics"]["nominal_correlation_beyond_friction"][0] < -0.9
    (sign,) = [f for f in results["findings"] if f["kind"] == "sign"]
    assert sign["text"].startswith("identification: J1: the measured torques run against")
    assert "sign = [-1, 1, 1, 1, 1, 1]" in sign["text"]


def test_two_seconds_of_the_ur10e_log_are_not_called_flipped(tmp_path):
    """Rows 635-800 of the UR10e's identification log (2 s): J4's torque runs against the nominal model
    (ρ = -0.865: friction the nominal model lacks) but not beyond its friction terms (-0.086); the log's sign is right
    (its full length gives no such finding). It read "J4: ... is their sign flipped?" and "not ready"."""
    p, results = _ur10e_rows(tmp_path, 635, 800)
    assert results["diagnostics"]["nominal_correlation"][3] < -0.5  # what the plain check saw
    assert [f for f in results["findings"] if f["kind"] == "sign"] == []
    assert "flipped" not in p.stdout + p.stderr


def test_three_seconds_of_the_ur10e_log_are_not_called_scaled(tmp_path):
    """Rows 635-935 of the UR10e's identification log (3 s, slow): beyond friction, J5's and J6's torques are mostly
    their rotor inertia's, which the description lacks (slopes 6.7 and about 2000 on the nominal model's, ρ ≥ 0.9), and
    the verdict read "the measured torques are about 6.7× the description's nominal model's ...: set scale = 0.149".
    The scale is judged beyond the rotor inertia too: no such finding (the full log gives none either)."""
    _, results = _ur10e_rows(tmp_path, 635, 935)
    assert results["diagnostics"]["nominal_slope_beyond_friction"][4] > 3  # what the check beyond friction saw
    assert [f for f in results["findings"] if f["kind"] == "scale"] == []
    slope = np.array(results["diagnostics"]["nominal_slope_beyond_drive"][:3], dtype=float)
    assert np.all(np.abs(slope - 1) < 0.5), slope  # the arm's torques have the description's size (J1-J3)


def test_a_large_rotor_inertia_the_description_lacks_is_not_a_scale(tmp_path):
    """A simulated UR10e whose rotor inertias (in the torques, not in the description) dominate a short, slow log
    in which the currents are in amperes, as the description's gains take them: no scale finding; the same torques
    in mA still get one."""
    from ..simulated_logs import config_text, fourier_motion, robot_toml, truth_robot, write_log, write_truth

    rng = np.random.default_rng(5)
    robot, (f_plus, f_minus, fv, ia) = truth_robot("ur10e", rng)
    friction = (f_plus, f_minus, fv, 300.0 * ia)  # 2-23 kg·m² at the joints, the description's Ia is 0
    rate = 500.0
    t = np.arange(int(3 * rate)) / rate
    write_log(tmp_path / "ident.csv", robot, t, *fourier_motion(robot, t, rng, f0=0.5, n_harmonics=3, fill=0.15),
              friction, rng, current_std=0.01)
    write_log(tmp_path / "valid.csv", robot, t, *fourier_motion(robot, t, rng), friction, rng, current_std=0.01)
    write_truth(tmp_path / "truth.csv", robot, robot.parameter_names)  # a reference the config names (not judged here)
    cfg = tmp_path / "config.toml"
    cfg.write_text(config_text(robot_toml("ur10e", tmp_path), tmp_path, "ident.csv", "valid.csv", robot.n_dof))
    p = dynid("identify", cfg, "--out", tmp_path / "a", "--no-figures", "--no-validate")
    assert p.returncode == 0, p.stderr
    results = json.loads((tmp_path / "a" / "results.json").read_text())
    judged = np.array(results["diagnostics"]["nominal_correlation_beyond_friction"], dtype=float) >= 0.9
    assert np.median(np.array(results["diagnostics"]["nominal_slope_beyond_friction"])[judged]) > 3  # what it saw
    assert [f for f in results["findings"] if f["kind"] == "scale"] == []
    data = np.loadtxt(tmp_path / "ident.csv", delimiter=",")
    data[:, 7:13] *= 1000.0
    np.savetxt(tmp_path / "ident.csv", data, delimiter=",", fmt="%.10g")
    p = dynid("identify", cfg, "--out", tmp_path / "ma", "--no-figures", "--no-validate")
    assert p.returncode == 0, p.stderr
    (scale,) = [f for f in _findings(tmp_path / "ma") if f["kind"] == "scale"]
    assert "scale = 0.001" in scale["text"]


def _ur10e_rows(tmp_path, first: int, last: int):
    """``dynid identify --no-validate`` on rows ``first``-``last`` of the UR10e's identification log (configs/ur10e.toml):
    the process and its results.json."""
    root = shared_data("ur10e_mamedov2020")
    from pathlib import Path

    text = (Path(__file__).resolve().parents[2] / "configs" / "ur10e.toml").read_text()
    text = text.replace('data_root = "../../shared/data/ur10e_mamedov2020"', f'data_root = "{root}"')
    text = text.replace("rows = [635, 3510]", f"rows = [{first}, {last}]")
    (tmp_path / "c.toml").write_text(text)
    p = dynid("identify", tmp_path / "c.toml", "--out", tmp_path / "out", "--no-figures", "--no-validate")
    assert p.returncode == 0, p.stderr
    return p, json.loads((tmp_path / "out" / "results.json").read_text())


def _findings(out):
    return json.loads((out / "results.json").read_text())["findings"]


def test_a_scale_far_from_the_descriptions_is_named_with_its_fix():
    """The median slope over the joints whose torque has the nominal model's shape (ρ ≥ 0.9), not over the others;
    a power of ten is given as one; within 3× nothing is said."""
    from dynid.validation.diagnostics import scale_findings

    rho = np.array([0.99, 0.95, 0.97, 0.5, 0.93])
    varies = np.ones(5, bool)
    (f,) = scale_findings(rho, np.array([980.0, 1010.0, 1100.0, 2.0, 990.0]), varies, "identification")
    assert f.kind == "scale" and "about 1e+03× " in f.text and "on J1, J2, J3, J5," in f.text
    assert "scale = 0.001" in f.text
    (g,) = scale_findings(rho, np.array([0.2, 0.21, 0.19, 1.0, 0.2]), varies, "log")
    assert "scale = 5" in g.text
    assert scale_findings(rho, np.array([1.5, 0.9, 2.8, 40.0, 1.1]), varies, "log") == []
    assert scale_findings(np.full(5, 0.5), np.full(5, 1000.0), varies, "log") == []


def test_currents_read_through_no_drive_gains_are_told_to_take_each_joints_gain():
    """The real UR10e's RTDE log with its URDF (no drive gains: each ampere read as 1 N·m): J1-J4 at 0.096, 0.085,
    0.121 and 0.121× the nominal model's. "set scale = 10" changes no fit's relative error (8.86 % on its validation
    log, as at 1); each joint's gain does (the nominal model's estimates: 6.62 %, the built-in robot's: 2.22 %). A
    log whose joints agree on one scale, or one read through gains, still gets the scale."""
    from dynid.validation.diagnostics import scale_findings

    rho, varies = np.array([0.99, 0.99, 0.98, 0.97, 0.3, 0.2]), np.ones(6, bool)
    slope = np.array([0.096, 0.085, 0.121, 0.121, 0.1, 0.1])
    (f,) = scale_findings(rho, slope, varies, "identification", gains=np.ones(6))
    assert "Give each joint's drive_gain in [[robot.joints]]" in f.text and "set scale" not in f.text
    assert "about 10.4, 11.8, 8.26, 8.26 N·m/A on J1, J2, J3, J4" in f.text
    (g,) = scale_findings(rho, np.full(6, 0.1), varies, "identification", gains=np.ones(6))
    assert "set scale = 10 " in g.text and "Give each joint's" not in g.text
    (h,) = scale_findings(rho, slope, varies, "identification", gains=np.full(6, 9.0))
    assert "set scale = 10 " in h.text


def test_a_light_joint_whose_nominal_torque_the_description_misstates_is_not_a_flipped_sign():
    """The zoo's Kinova Jaco 2 with a CAD-like description and joint torque sensors (class cad-sensor, simulated with
    the right sign): J6's measured torque runs against its small nominal torque beyond friction (ρ -0.505) at 13.7
    times its size, where the other joints' slopes are 0.66-0.80. It was called flipped and the model "not ready". A
    flip keeps the channel's size: named only within 3× of the other joints' |slope|; the same ρ at the others' size
    is named."""
    from dynid.validation.diagnostics import sign_findings

    rho = np.array([0.999, 0.999, 1.0, 0.997, 0.989, -0.505])
    slope = np.array([0.799, 0.764, 0.698, 0.735, 0.658, -13.698])
    varies = np.ones(6, bool)
    assert len(sign_findings(rho, varies, "identification")) == 1  # without the slopes, as before
    assert sign_findings(rho, varies, "identification", slope=slope) == []
    slope[5] = -0.7
    (f,) = sign_findings(rho, varies, "identification", slope=slope)
    assert "J6:" in f.text and "sign = [1, 1, 1, 1, 1, -1]" in f.text


def test_a_joint_is_judged_against_the_other_joints_size_not_its_own():
    """The zoo's SCARA with a CAD-like description and a geared drive (class cad-gear, simulated with the right
    sign): its vertical quill's force beyond friction runs against its small nominal inertial force (ρ -0.691) at 10.1
    times its size; the one other joint the nominal model judges has a slope of 0.978. The quill was called flipped
    and the model "not ready": its own slope made half of the median it was judged against (5.5). Against the other
    joint's size it is no flip; a quill at that size is."""
    from dynid.validation.diagnostics import sign_findings

    rho = np.array([0.831, 0.405, -0.691, 0.047])
    slope = np.array([0.978, 0.682, -10.06, 56.377])
    varies = np.ones(4, bool)
    assert sign_findings(rho, varies, "identification", slope=slope) == []
    slope[2] = -1.1
    (f,) = sign_findings(rho, varies, "identification", slope=slope)
    assert "J3:" in f.text and "sign = [1, 1, -1, 1]" in f.text


def test_one_joints_scale_is_named_with_a_scale_per_joint():
    """J2's torque 1000× the nominal model's where J1, J3 and J4 agree with theirs: "set scale = [1, 0.001, 1, ...]";
    the median slope of the four (about 1) said nothing. One joint 4× off where only one other is judged: nothing (no
    evidence which is right)."""
    from dynid.validation.diagnostics import scale_findings

    rho, varies = np.array([0.999, 0.99, 0.99, 0.98, 0.5, 0.1]), np.ones(6, bool)
    (f,) = scale_findings(rho, np.array([1.0, 1000.0, 1.01, 0.99, 1.0, 1.3]), varies, "identification")
    assert "on J2 (1e+03×), where the other joints' agree" in f.text and "scale = [1, 0.001, 1, 1, 1, 1]" in f.text
    assert f.joint == 1
    assert scale_findings(rho, np.array([1.0, 4.0, 1.01, 0.99, 1.0, 1.3]), np.array([1, 1, 0, 0, 0, 0], bool),
                          "identification") == []


def test_one_joints_torque_in_another_unit_in_a_simulated_log_is_named(tmp_path):
    """J2's effort written in N·mm in both logs of ``dynid example ur10e``: the fit cannot follow one joint's scale,
    so the other joints' residuals rose above their torque and only J2 was judged: "set scale = 0.001" for every
    joint. Judged against the noise floor, J1-J4 agree but J2, and the per-joint scale is given."""
    assert dynid("example", "ur10e", tmp_path / "try", "-q").returncode == 0
    for name in ("identification.csv", "validation.csv"):
        path = tmp_path / "try" / name
        header = path.read_text().splitlines()[0]
        data = np.loadtxt(path, delimiter=",", skiprows=1)
        data[:, header.split(",").index("shoulder_lift_joint_effort")] *= 1000
        np.savetxt(path, data, delimiter=",", header=header, comments="", fmt="%.10g")
    p = dynid("identify", tmp_path / "try" / "ur10e.toml", "--out", tmp_path / "out", "--no-figures")
    assert p.returncode == 0, p.stderr
    (scale,) = [f for f in _findings(tmp_path / "out") if f["kind"] == "scale"]
    assert "scale = [1, 0.001, 1, 1, 1, 1]" in scale["text"], scale["text"]


def test_a_description_that_misstates_one_joints_torque_is_not_a_channels_scale(tmp_path):
    """``dynid example ur10e`` with a description whose wrist links weigh 0.08 of the simulation's: J4's measured torque
    is about 13× its nominal one where the other joints' agree, and dynid said "not ready ... set scale = [1, 1, 1,
    0.0772, 1, 1]", advice that would spoil a log the fit follows to its noise floor (every joint at 0.96-1.04× it).
    A channel's own scale is named only where the fit cannot follow it; the same log with J2 in N·mm still is (above)."""
    from dynid.validation.diagnostics import scale_findings

    rho, slope = np.array([0.999, 0.99, 0.99, 0.98, 0.5, 0.1]), np.array([1.0, 1000.0, 1.01, 0.99, 1.0, 1.3])
    fitted = np.zeros(6, bool)
    assert scale_findings(rho, slope, np.ones(6, bool), "identification", misfit=fitted) == []
    assert len(scale_findings(rho, slope, np.ones(6, bool), "identification", misfit=fitted | [0, 1, 0, 0, 0, 0])) == 1
    assert dynid("example", "ur10e", tmp_path / "try", "-q").returncode == 0
    folder = tmp_path / "try"
    text = (folder / "ur10e.urdf").read_text()
    start = text.index('<link name="wrist_1_link">')
    head, wrist = text[:start], text[start:]
    for mass in sorted(set(re.findall(r'<mass value="([0-9.e+-]+)"/>', wrist[:wrist.index('<link name="ee_link">')]))):
        wrist = wrist.replace(f'<mass value="{mass}"/>', f'<mass value="{0.08 * float(mass):.6g}"/>')
    (folder / "ur10e.urdf").write_text(head + wrist)
    p = dynid("identify", folder / "ur10e.toml", "--out", tmp_path / "out", "--no-figures")
    assert p.returncode == 0, p.stderr
    results = json.loads((tmp_path / "out" / "results.json").read_text())
    slope = results["diagnostics"]["nominal_slope_beyond_drive"][3]
    assert slope > 3, slope  # J4's torque far beyond its nominal one, as a channel in another unit would be
    assert [f for f in results["findings"] if f["kind"] == "scale"] == []
    assert "model ready" in " ".join(p.stdout.split())


def test_a_scale_finding_names_each_joints_drive_gain_for_motor_currents():
    """A UR10e's log of motor currents read with its URDF (no drive gains: 1 N·m/A) was told "set scale = 10" alone,
    where its joints' gains differ (8.5-10.7 N·m/A). Each judged joint's gain is said: the one that brings its slope
    on the nominal model to 1, from the gains the log was read through."""
    from dynid.validation.diagnostics import scale_findings

    rho, varies = np.array([0.95, 0.99, 0.99, 0.98, 0.5, 0.1]), np.ones(6, bool)
    true = np.array([10.0, 10.6956, 8.4566, 9.0029, 9.48, 10.1232])  # the UR10e's (src/dynid/model/robots/ur10e.toml)
    for given in (np.ones(6), np.full(6, 2.0)):  # read through 1 N·m/A (a URDF), or through gains 5x too small
        (f,) = scale_findings(rho, given / true, varies, "identification", gains=given)
        assert "about 10, 10.7, 8.46, 9 N·m/A on J1, J2, J3, J4 by the description's nominal model" in f.text, f.text
    assert "N·m/A" not in scale_findings(rho, 1 / true, varies, "identification")[0].text  # no gains given: not said


def test_currents_in_milliamperes_are_named_and_the_model_not_called_ready(tmp_path):
    """Every current of the logs written in mA (1000× the amperes the description's drive gains take): a fit absorbs
    the scale (it fits as well, with masses 1000× the arm's, and dynid called it ready); the verdict names the scale
    and the fix, and dynid export repeats it. The same logs in amperes get no such finding."""
    cfg, _ = simulated_case(tmp_path, "er16", 125.0, "fourier", duration=20.0)
    cfg.write_text(cfg.read_text().replace('estimators = ["ols"]', 'estimators = ["ols", "sdp"]'))
    p = dynid("identify", cfg, "--out", tmp_path / "a", "--no-figures")
    assert p.returncode == 0, p.stderr
    assert [f for f in _findings(tmp_path / "a") if f["kind"] == "scale"] == []
    for name in ("ident.csv", "valid.csv"):
        data = np.loadtxt(tmp_path / name, delimiter=",")
        data[:, 7:13] *= 1000.0
        np.savetxt(tmp_path / name, data, delimiter=",", fmt="%.10g")
    p = dynid("identify", cfg, "--out", tmp_path / "ma", "--no-figures")
    assert p.returncode == 0, p.stderr
    (scale,) = [f for f in _findings(tmp_path / "ma") if f["kind"] == "scale"]
    assert "scale = 0.001" in scale["text"]
    said = " ".join((p.stdout + p.stderr).split())
    assert "not ready: the measured torques are far from the description's size" in said
    e = dynid("export", cfg, "--results", tmp_path / "ma" / "results.json", "--urdf", tmp_path / "ma.urdf")
    assert e.returncode == 0, e.stderr
    assert "the model was fitted to torques dynid identify doubts" in " ".join(e.stderr.split())
    assert "scale = 0.001" in e.stderr


def test_swapped_torque_channels_are_told_by_their_fit_with_friction(rng):
    """Three joints whose nominal torques have overlapping shapes (J2's is J1's plus a little, as parallel axes give):
    measured torques built as nominal + friction + noise, J1's and J2's columns swapped: the pair is named; in order,
    nothing. The correlation of the shapes alone (above 0.9 both ways) could not tell them."""
    from dynid.validation.diagnostics import OrderSums

    m = 4000
    t = np.arange(m) * 0.01
    base = np.sin(0.7 * t)
    nominal = np.column_stack([40 * base, 15 * base + 3 * np.sin(1.9 * t), 5 * np.cos(1.3 * t)])
    dq = np.column_stack([np.cos(0.5 * t), np.cos(0.8 * t + 1), np.cos(1.1 * t + 2)])
    tau = nominal + 2.0 * np.sign(dq) + 0.5 * dq + 0.2 * rng.standard_normal((m, 3))
    assert np.corrcoef(nominal[:, 0], nominal[:, 1])[0, 1] > 0.9
    for order, expected in (((0, 1, 2), []), ((1, 0, 2), ["order"])):
        sums = OrderSums(3)
        for a in range(0, m, 1000):
            sums.add(nominal[a:a + 1000], np.sign(dq[a:a + 1000]), dq[a:a + 1000], tau[a:a + 1000][:, list(order)])
        found = sums.findings(np.ones(3, bool), "log")
        assert [f.kind for f in found] == expected
        if found:
            assert "the torques of J1 and J2 (" in found[0].text and "look swapped" in found[0].text


def test_swapped_current_columns_are_named_and_the_model_not_called_ready(tmp_path):
    """J2's and J3's currents written in each other's column in both logs of a simulated ER-16: named, not ready.
    Before, the log was fitted and called ready with no word."""
    cfg, _ = simulated_case(tmp_path, "er16", 125.0, "fourier", duration=20.0)
    p = dynid("identify", cfg, "--out", tmp_path / "in-order", "--no-figures")
    assert p.returncode == 0 and [f for f in _findings(tmp_path / "in-order") if f["kind"] == "order"] == []
    for name in ("ident.csv", "valid.csv"):
        data = np.loadtxt(tmp_path / name, delimiter=",")
        data[:, [8, 9]] = data[:, [9, 8]]  # time, 6 positions, J1's current, then J2's and J3's
        np.savetxt(tmp_path / name, data, delimiter=",", fmt="%.10g")
    p = dynid("identify", cfg, "--out", tmp_path / "out", "--no-figures")
    assert p.returncode == 0, p.stderr
    (order,) = [f for f in _findings(tmp_path / "out") if f["kind"] == "order"]
    assert "J2 and J3" in order["text"]
    assert "not ready: the torques of some joints look swapped" in " ".join((p.stdout + p.stderr).split())


def test_a_description_in_grams_is_named_as_a_possible_cause_with_its_mass(tmp_path):
    """``dynid example ur10e`` read with its URDF's masses and inertias in grams (a CAD export's unit): dynid said "a
    unit (currents in mA? torques in N·mm?) or the drive gains; set scale = 1000", of torques 0.001× the description's,
    where mA and N·mm would make them larger. Measured torques smaller than the description's name its masses first,
    with their sum; larger ones name the log's unit first and the description's placeholders too."""
    from dynid import load_robot
    from dynid.validation.diagnostics import scale_findings

    assert dynid("example", "ur10e", tmp_path / "try", "-q").returncode == 0
    urdf = tmp_path / "try" / "ur10e.urdf"
    text = urdf.read_text()
    urdf.write_text(re.sub(r'((?:mass value|i[xyz]{2})=")([0-9.eE+-]+)(")',
                              lambda m: f"{m.group(1)}{float(m.group(2)) * 1000!r}{m.group(3)}", text))
    mass = float(np.sum(load_robot(urdf).inertial[:, 9]))
    p = dynid("identify", tmp_path / "try" / "ur10e.toml", "--out", tmp_path / "out", "--no-figures", "-q")
    assert p.returncode == 0, p.stderr
    (scale,) = [f["text"] for f in json.loads((tmp_path / "out" / "results.json").read_text())["findings"]
                if f["kind"] == "scale"]
    assert f"the description's masses in another unit (grams?; its moving links weigh {mass:.3g} kg in all)" in scale
    assert "currents in mA" not in scale and "scale = 1000" in scale
    rho, varies = np.full(4, 0.99), np.ones(4, bool)
    (larger,) = scale_findings(rho, np.full(4, 1000.0), varies, "log", mass=28.7)
    assert "a unit (currents in mA? torques in N·mm?)" in larger.text
    assert "the description's masses far too small (placeholders?; its moving links weigh 28.7 kg in all)" in larger.text


@pytest.mark.parametrize("flipped", [None, 5])
def test_a_flipped_sign_the_nominal_model_cannot_judge_is_named_by_the_consistent_refit(flipped):
    """A UR10e whose wrist torque is friction and rotor inertia its description lacks: the nominal model cannot judge
    J6's sign (its torque barely varies in the model), so a J6 read with the wrong sign was silent; least squares fits
    it either way (its friction negative), the SDP cannot, and with J6 negated it follows it again. Read right: no
    finding (the SDP fits every joint within 2× least squares)."""
    import dynid
    from dynid.identification.flipped_joints import MISFIT
    from dynid.identification.identifier import Identifier
    from dynid.model.description import load_robot

    from ..simulated_logs import truth_robot

    truth, _ = truth_robot("ur10e", np.random.default_rng(0))
    log = dynid.simulated_log(truth, seconds=10, rng=3)
    tau = log.tau.copy()
    if flipped is not None:
        tau[:, flipped] *= -1
    result = Identifier(load_robot("ur10e"), estimators=["wls", "sdp"]).fit(log.t, log.q, tau).result_
    signs = [f.text for f in result.findings if f.kind == "sign"]
    errors = {k: np.asarray(v["relative_error"]) for k, v in result.fit.metrics().items()}
    if flipped is None:
        assert signs == [] and np.all(errors["dynid SDP"] < MISFIT * errors["dynid WLS"])
        return
    (text,) = signs
    assert text.startswith("arrays: J6: the physically consistent estimate cannot follow") and "Negate its entry" in text
    rms = [float(x) for x in re.findall(r"J6 ([0-9.e+-]+) N·m RMS as read, ([0-9.e+-]+) flipped", text)[0]]
    assert rms[1] < 0.5 * rms[0]  # the refit with J6 negated follows it


def test_a_refit_with_a_joint_negated_that_has_no_solution_leaves_the_sign_unjudged(monkeypatch):
    """The flipped-sign check refits the SDP with a misfitting joint's torque negated; where that SDP has no solution
    (the solver's failure, provoked here), the joint's sign is not judged and the identification goes on, as every
    other check that fails: before, the refit's error refused the whole identification."""
    import dynid
    from dynid.exceptions import DynIdError
    from dynid.identification import flipped_joints
    from dynid.identification.identifier import Identifier
    from dynid.model.description import load_robot

    from ..simulated_logs import truth_robot

    truth, _ = truth_robot("ur10e", np.random.default_rng(0))
    log = dynid.simulated_log(truth, seconds=10, rng=3)
    tau = log.tau.copy()
    tau[:, 5] *= -1
    tried = []

    def failing(sdp, acc, j):
        tried.append(j)
        raise DynIdError("physically consistent least squares (sdp): the solver found no physically consistent "
                         "parameters for these torques (status solver_error)")

    monkeypatch.setattr(flipped_joints, "_refit_negated", failing)
    result = Identifier(load_robot("ur10e"), estimators=["wls", "sdp"]).fit(log.t, log.q, tau).result_
    assert 5 in tried and not [f for f in result.findings if f.kind == "sign"]
    assert "dynid SDP" in result.estimates


def test_motor_currents_given_as_torques_are_told_the_descriptions_gains_were_not_applied(tmp_path):
    """A UR10e's motor currents given as torques (a researcher's arrays: the Identifier takes N·m) were told "drive_gain
    about 126, 69.6, 74.5 N·m/A": the description's gains times the ratio, as if they had been applied. The
    recording now carries the gains it was read through (none here), and the finding names the description's gains
    and how to apply them; the config that reads the same columns as currents, through those gains, has no finding."""
    import dynid
    from dynid.io.config.identification_config import load_identification_config
    from dynid.io.logs.datasets import load_recording

    cfg, truth = simulated_case(tmp_path, "ur10e", 125.0, "fourier", duration=20.0)
    config = load_identification_config(cfg)
    recording = load_recording(config.identification, config.robot)
    np.testing.assert_array_equal(recording.drive_gains, config.robot.drive_gains)  # read as currents, eq. 16
    currents = recording.tau / config.robot.drive_gains
    ident = dynid.Identifier("ur10e", estimators=["ols"]).fit(recording.t, recording.q, currents)
    (f,) = [f for f in ident.result_.findings if f.kind == "scale"]
    gains = ", ".join(f"{g:.4g}" for g in config.robot.drive_gains)
    assert f"were read as torques: are these motor currents? The description's drive gains ({gains} N·m/A) were " \
           "not applied" in f.text, f.text
    assert "states no drive gains" not in f.text and "set scale" not in f.text
    read = dynid.Identifier("ur10e", estimators=["ols"]).fit(recording.t, recording.q, recording.tau)
    assert [f for f in read.result_.findings if f.kind == "scale"] == []

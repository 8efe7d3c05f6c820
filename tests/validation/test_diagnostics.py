"""The verdict on the model: each check finds what a log simulated with that defect holds, and nothing on a log the
model fits."""

import numpy as np
import pytest

from dynid.validation.diagnostics import BlockGrams, ResidualSums, excitation_findings, sign_findings

from ..simulated_logs import config_text, fourier_motion, robot_toml, truth_robot, write_truth


def test_a_flipped_sign_is_named_with_the_fix():
    corr = np.array([0.2, -0.999, -0.98, -0.99, -0.9, -0.95, 0.1])
    varies = np.array([False, True, True, True, True, True, False])
    (f,) = sign_findings(corr, varies, "identification")
    assert f.kind == "sign" and "J2, J3, J4, J5, J6" in f.text and "sign = -1" in f.text and "[identification]" in f.text
    (g,) = sign_findings(np.array([0.99, -0.9, 0.98]), np.ones(3, bool), "log")
    assert "sign = [1, -1, 1]" in g.text
    assert sign_findings(np.array([0.99, 0.3, 0.98]), np.ones(3, bool), "log") == []


def test_every_judged_joint_flipped_is_one_sign_for_the_log():
    """The LBR Med7's torques as logged (beyond friction, its run as measured): every joint whose nominal torque the
    description predicts runs against it, J1's and J7's it barely predicts (ρ -0.06, 0.13). The per-joint list left
    J1 and J7 flipped: with it, the SDP fitted J7 to 96 % against 32 % with sign = -1, and predicted the validation
    log 20.0 % against 8.8 %."""
    corr = np.array([-0.056, -0.999, -0.993, -0.999, -0.984, -0.982, 0.132])
    slope = np.array([-0.193, -1.145, -1.233, -1.21, -1.615, -1.281, 98.3])
    (f,) = sign_findings(corr, np.ones(7, bool), "identification", slope=slope)
    assert "sign = -1 }" in f.text and "every joint's" in f.text and "cannot judge J1, J7" in f.text and "sign = [" not in f.text
    (g,) = sign_findings(np.array([0.9, -0.99, -0.98, 0.1]), np.ones(4, bool), "log")  # a joint judged the right way
    assert "sign = [1, -1, -1, 1]" in g.text and "cannot judge" not in g.text


def test_residual_checks_find_a_position_dependence_and_friction_near_reversals(rng):
    """Rows whose torque holds a term the model lacks: an angle dependence on joint 1, a friction step near reversals
    on joint 2 (a velocity-shaped term the model's columns cannot make); a well-specified joint 3 gives nothing."""
    m, n, p = 6000, 3, 4
    t = np.arange(m) * 0.01
    q = np.column_stack([np.sin(0.3 * t), np.sin(0.5 * t + 1), np.sin(0.4 * t + 2)])
    dq = np.gradient(q, 0.01, axis=0)
    y = rng.standard_normal((m, n, p))
    beta = rng.standard_normal(p)
    tau = y @ beta + 0.05 * rng.standard_normal((m, n))
    tau[:, 0] += 0.8 * np.cos(2 * q[:, 0])
    direction = np.sign(dq)
    low = 0.1
    tau[:, 1] += 0.5 * direction[:, 1] * (np.abs(dq[:, 1]) < low)
    sums = ResidualSums(n, p)
    keep = np.ones((m, n), bool)
    for a in range(0, m, 1000):
        sl = slice(a, a + 1000)
        sums.add(y[sl], tau[sl], q[sl], dq[sl], direction=direction[sl], low_speed=np.full(n, low), keep=keep[sl])
    beta_hat = np.linalg.lstsq(y.reshape(-1, p), tau.reshape(-1), rcond=None)[0]
    findings, stats = sums.residual_checks(beta_hat, np.sqrt((tau**2).mean(0)))
    kinds = {(f.kind, f.joint) for f in findings}
    assert ("position", 0) in kinds and ("friction", 1) in kinds, findings
    assert not any(f.joint == 2 for f in findings)
    assert stats["friction_amplitude"][1] == pytest.approx(0.5, rel=0.2)


def test_the_block_bootstrap_sees_correlated_residuals():
    """Independent residuals: the bootstrap's σ is the covariance's (ratio about 1); residuals correlated over ~50 rows
    (an AR(1) with ρ = 0.98): the bootstrap's σ is several times the covariance's, which assumes them independent."""
    rng = np.random.default_rng(5)
    m, p = 20000, 3
    y = rng.standard_normal((m, 1, p)) + np.sin(np.arange(m)[:, None, None] / 200.0)
    beta = np.array([1.0, 2.0, -1.0])
    for rho, expect in ((0.0, (0.7, 1.4)), (0.98, (3.0, 20.0))):
        e = np.zeros(m)
        noise = rng.standard_normal(m)
        for k in range(1, m):
            e[k] = rho * e[k - 1] + noise[k]
        tau = y @ beta + 0.1 * e[:, None]
        blocks = BlockGrams(1, p, m)
        blocks.add(np.arange(m), y, tau, np.ones((m, 1), bool))
        boot = blocks.bootstrap_std(rng=1)
        w = y.reshape(-1, p)
        theta = np.linalg.lstsq(w, tau.ravel(), rcond=None)[0]
        r = tau.ravel() - w @ theta
        cov_std = np.sqrt(np.diag(np.linalg.inv(w.T @ w)) * (r @ r) / (m - p))
        ratio = np.median(boot / cov_std)
        assert expect[0] <= ratio <= expect[1], (rho, ratio)


def test_a_well_fitted_simulated_log_has_no_finding_and_a_counterbalance_is_found(tmp_path):
    """er16 simulated with the description's own friction model: no finding; the same log with a spring torque on
    joint 2 (a second harmonic of its angle, ±100 N·m, about a third of the joint's RMS torque) the description does
    not declare: the position finding names J2, with a size below the spring's (least squares takes most of it into
    the gravity parameters)."""
    from dynid.identification.run import run_identification
    from dynid.io.config.identification_config import load_identification_config

    from ..simulated_logs import write_log

    rng = np.random.default_rng(3)
    robot, friction = truth_robot("er16", rng)
    rate = 250.0
    t = np.arange(int(60 * rate)) / rate
    cases = {}
    for spring in (0.0, 100.0):
        folder = tmp_path / f"spring{spring:g}"
        folder.mkdir()
        r = np.random.default_rng(4)
        q, dq, ddq = fourier_motion(robot, t, r)
        write_log(folder / "ident.csv", robot, t, q, dq, ddq, friction, r, current_std=0.01)
        if spring:  # the log's currents carry the spring's torque too
            data = np.loadtxt(folder / "ident.csv", delimiter=",")
            data[:, 1 + robot.n_dof + 1] += spring * np.cos(2 * q[:, 1]) / robot.drive_gains[1]
            np.savetxt(folder / "ident.csv", data, delimiter=",", fmt="%.10g")
        write_log(folder / "valid.csv", robot, t, q, dq, ddq, friction, r, current_std=0.01)
        write_truth(folder / "truth.csv", robot, robot.parameter_names)
        cfg = folder / "config.toml"
        cfg.write_text(config_text(robot_toml("er16", folder), folder, "ident.csv", "valid.csv", robot.n_dof)
                       .replace('estimators = ["ols"]', 'estimators = ["ols"]\nfriction = "description"'))
        cases[spring] = run_identification(load_identification_config(cfg), validate=False)
    assert [f.kind for f in cases[0.0].findings if f.kind in ("position", "friction", "sign")] == []
    (found,) = [f for f in cases[100.0].findings if f.kind == "position" and f.joint == 1]
    spread = np.sqrt(2) * np.std(100.0 * np.cos(2 * q[:, 1]))
    assert 0 < float(found.text.split("±")[1].split(" N·m")[0]) < spread


def test_a_position_finding_is_sized_by_what_it_explains(rng):
    """A light joint (torque under 1 N·m RMS) swinging over 0.1 rad with a real angle dependence of 0.05 N·m: its
    harmonic features are nearly collinear there, and the coefficients' amplitude ran to hundreds of N·m; the finding
    states the spread of the fitted dependence over the joint's angles, near the truth and below the joint's torque."""
    m, n, p = 8000, 1, 2
    t = np.arange(m) * 0.01
    q = (0.6 + 0.05 * np.sin(0.7 * t))[:, None]
    dq = np.gradient(q, 0.01, axis=0)
    y = rng.standard_normal((m, n, p)) * 0.3
    beta = np.array([1.0, -0.5])
    tau = y @ beta + 0.002 * rng.standard_normal((m, n))
    effect = 0.05 * np.sin(40 * (q[:, 0] - 0.6))  # ±0.05 N·m over the swing
    tau[:, 0] += effect
    sums = ResidualSums(n, p)
    sums.add(y, tau, q, dq, direction=np.sign(dq), low_speed=np.full(n, 1e-3), keep=np.ones((m, n), bool))
    beta_hat = np.linalg.lstsq(y.reshape(-1, p), tau.reshape(-1), rcond=None)[0]
    rms = np.sqrt((tau**2).mean(0))
    assert rms[0] < 1.0
    findings, stats = sums.residual_checks(beta_hat, rms)
    spread = np.sqrt(2) * np.std(effect)
    assert stats["position_amplitude"][0] == pytest.approx(spread, rel=0.35)
    assert stats["position_amplitude"][0] < rms[0]
    (f,) = [f for f in findings if f.kind == "position"]
    size = float(f.text.split("±")[1].split(" N·m")[0])
    assert size < rms[0]


def test_the_nominal_gate_calls_an_equal_log_equal_not_better(rng):
    """A log where the estimate and the nominal model predict alike (the UR10e's resting logs: both 0 % within the
    static-friction band) was counted as one the estimate predicts "better"; it is now named as the same, and the
    logs that show a difference come first."""
    from dynid.validation.diagnostics import nominal_gate
    from dynid.validation.torques import TorqueComparison

    t = np.arange(400) * 0.01
    measured = np.column_stack([np.sin(t), 2 * np.cos(0.7 * t)])
    close = measured + 0.01 * rng.standard_normal(measured.shape)
    far = 1.3 * measured
    moving = TorqueComparison("moving", t, measured, {"est": close, "nominal": far})
    alike = TorqueComparison("alike", t, measured, {"est": far, "nominal": far})
    (gate,), stats = nominal_gate([alike, moving], "est", "nominal")
    assert stats["alike"]["worse_joints"] == [] and stats["moving"]["worse_joints"] == []
    assert "better on 1 of the 2 logs (moving:" in gate.text and gate.text.endswith("the same on alike")
    assert "every joint of the validation logs better" not in gate.text
    (only,), _ = nominal_gate([moving], "est", "nominal")
    assert only.text.startswith("est predicts every joint of the validation logs better") and "alike" not in only.text


def test_a_validation_error_far_above_the_fits_is_said_in_a_readable_figure():
    """An estimate gone astray (a WLS estimate at 1.1e15 % on a validation log it fits at 0.54 %) was said to predict
    it "2056681467058500.0× worse"; such a ratio is now given to three digits, and an ordinary one as before."""
    from dynid.validation.diagnostics import validation_findings

    (astray,) = validation_findings("validation", 1.11e15, 0.54, prediction_spread=None, fit_spread=None, label="dynid WLS")
    assert "predicts it 2.06e+15× worse than it fits the identification log (1.11e+15 % against 0.54 %)" in astray.text
    (ordinary,) = validation_findings("validation", 12.3, 2.74, prediction_spread=None, fit_spread=None, label="dynid WLS")
    assert "predicts it 4.5× worse than it fits" in ordinary.text
    (large,) = validation_findings("validation", 2980.0, 1.0055, prediction_spread=None, fit_spread=None, label="dynid WLS")
    assert "predicts it 2964× worse than it fits" in large.text  # the Med7's 60-63 s window said "2963.8×"


def test_a_weakly_excited_parameter_suggests_the_sdp_only_where_it_is_not_run():
    """Findings agree with choices (issue "Never worse than the description", item 4): where the physically consistent
    estimate is among the estimates, the finding on weakly excited parameters does not suggest adding it."""
    names = ["ZZ1R", "MX2", "fv1"]
    params, std = np.array([1.0, 0.2, 3.0]), np.array([0.01, 0.3, 0.01])  # MX2: σ above its value
    column_rms = np.array([1.0, 2.0, 1.0])  # its ±σ is 0.6 N·m, above 5 % of a 1 N·m RMS torque
    without = excitation_findings(names, params, std, column_rms, 1.0)[0].text
    with_sdp = excitation_findings(names, params, std, column_rms, 1.0, consistent=True)[0].text
    assert "hardly excites MX2 (" in without and 'add "sdp" to the estimators' in without
    assert "hardly excites MX2 (" in with_sdp and "sdp" not in with_sdp and "keeps them plausible" in with_sdp

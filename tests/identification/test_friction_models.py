"""Each joint's friction model chosen by blocked cross-validation, on logs simulated with a known model per joint
(the friction written out here, not with dynid's friction table); the out-of-fold errors against a direct refit."""

import numpy as np
import pytest

from dynid.model.friction_model import JointFriction, robot_with

from ..simulated_logs import config_text, fourier_motion, point_to_point_motion, robot_toml, truth_robot, write_truth


def _log(path, robot, t, q, dq, ddq, extra, rng, current_std=0.005):
    """A controller log whose torques are Pinocchio's RNEA + Ia, fv, fc·sign + ``extra`` (N, n) written out here."""
    import pinocchio as pin

    from dynid.dynamics.rnea import pinocchio_model

    model = pinocchio_model(robot)
    data = model.createData()
    rb = np.array([pin.rnea(model, data, a, b, c) for a, b, c in zip(q, dq, ddq)])
    ia, fc, fv = robot.drive[:, 0], robot.drive[:, 1], robot.drive[:, 2]
    tau = rb + ia * ddq + fv * dq + fc * np.sign(dq) + extra(rb, dq)
    step = 2 * np.pi / 2**20
    current = tau / robot.drive_gains + rng.normal(0.0, current_std, tau.shape)
    np.savetxt(path, np.column_stack([t, np.round(q / step) * step, current]), delimiter=",", fmt="%.10g")


def test_stribeck_and_load_dependent_friction_are_found_where_they_are(tmp_path):
    """er16, 6 joints: J2 with load-dependent Coulomb friction (0.02·|τ_rigid|), J3 with Stribeck friction
    (+40 % of f_c decaying over 0.1 × its RMS speed), the others plain: the cross-validation chooses those kinds
    there, the plain model elsewhere, and the chosen model predicts the validation log better than the plain one."""
    from dataclasses import replace

    from dynid.identification.run import run_identification
    from dynid.io.config.identification_config import load_identification_config

    rng = np.random.default_rng(7)
    robot, _ = truth_robot("er16", rng)
    robot = replace(robot, drive=robot.drive * np.array([1, 1, 1, 0]))  # no offset
    rate = 250.0
    t = np.arange(int(60 * rate)) / rate
    motions = [fourier_motion(robot, t, rng, f0=0.1) for _ in range(2)]
    speed3 = np.sqrt((motions[0][1][:, 2] ** 2).mean())
    fc = robot.drive[:, 1]

    def extra(rb, dq):
        out = np.zeros_like(dq)
        out[:, 1] = 0.02 * np.abs(rb[:, 1]) * np.sign(dq[:, 1])
        out[:, 2] = 0.4 * fc[2] * np.sign(dq[:, 2]) * np.exp(-(dq[:, 2] / (0.1 * speed3)) ** 2)
        return out

    for name, (q, dq, ddq) in zip(("ident", "valid"), motions):
        _log(tmp_path / f"{name}.csv", robot, t, q, dq, ddq, extra, rng)
    write_truth(tmp_path / "truth.csv", robot, robot.parameter_names)
    toml = robot_toml("er16", tmp_path)
    cfg = tmp_path / "config.toml"
    cfg.write_text(config_text(toml, tmp_path, "ident.csv", "valid.csv", robot.n_dof))
    result = run_identification(load_identification_config(cfg))
    models = result.settings["friction_models"]["models"]
    kinds = [m["kind"] for m in models]
    assert kinds[1] == "load" and kinds[2] == "stribeck", kinds
    assert all(k == "coulomb" for j, k in enumerate(kinds) if j not in (1, 2)), kinds
    assert models[2]["velocity"] == pytest.approx(0.1 * speed3, rel=0.5)
    fcl = result.solution.params[result.base.names.index("fcl2")]
    assert fcl == pytest.approx(0.02, rel=0.1)
    chosen = np.asarray(result.settings["friction_models"]["chosen_out_of_fold_rms_error"])
    plain = np.asarray(result.settings["friction_models"]["plain_out_of_fold_rms_error"])
    assert chosen[1] < 0.8 * plain[1] and chosen[2] < 0.9 * plain[2]
    # the plain model, identified on the same log, predicts the validation log worse on those joints
    cfg.write_text(cfg.read_text().replace('estimators = ["ols"]', 'estimators = ["ols"]\nfriction = "description"'))
    plain_result = run_identification(load_identification_config(cfg))
    auto_err = result.validations[0].metrics()["dynid OLS"]["relative_error"]
    plain_err = plain_result.validations[0].metrics()["dynid OLS"]["relative_error"]
    assert np.all(auto_err[1:3] < 0.8 * plain_err[1:3]), (auto_err, plain_err)


def test_the_state_at_rest_is_judged_only_on_a_log_with_rests(tmp_path):
    """Point-to-point moves with rests, simulated with no friction at rest (the joint's friction is that of its
    motion only while it moves): the cross-validation chooses "zero" (or a quick relaxation) at rest on the joints
    with a large Coulomb torque; on a Fourier log without rests, every joint stays "held"."""
    from dynid.identification.run import run_identification
    from dynid.io.config.identification_config import load_identification_config

    rng = np.random.default_rng(11)
    robot, _ = truth_robot("er16", rng)
    rate = 250.0
    t = np.arange(int(60 * rate)) / rate
    for motion, expect_held in ((point_to_point_motion, False), (fourier_motion, True)):
        folder = tmp_path / motion.__name__
        folder.mkdir()
        for name in ("ident", "valid"):
            q, dq, ddq = motion(robot, t, rng)
            _log(folder / f"{name}.csv", robot, t, q, dq, ddq, lambda rb, dq: np.zeros_like(dq), rng)
        write_truth(folder / "truth.csv", robot, robot.parameter_names)
        cfg = folder / "config.toml"
        cfg.write_text(config_text(robot_toml("er16", folder), folder, "ident.csv", "valid.csv", robot.n_dof))
        result = run_identification(load_identification_config(cfg), validate=False)
        rests = [m["rest"] for m in result.settings["friction_models"]["models"]]
        if expect_held:
            assert rests == ["held"] * 6, rests
        else:
            big = np.argsort(robot.drive[:, 1] / np.sqrt((result.fit.measured**2).mean(0)))[-2:]
            assert all(rests[j] != "held" for j in big), rests


def test_robot_with_models_has_each_joints_terms_only():
    from dynid.model.description import load_robot

    robot = load_robot("ur10e")
    models = [JointFriction("coulomb"), JointFriction("stribeck", 0.05), JointFriction("asymmetric", 0.0, "zero"),
              JointFriction("smooth", 0.01), JointFriction("load"), JointFriction("coulomb", 0.0, 0.5)]
    r = robot_with(robot, models)
    assert r.drive_terms == ("Ia", "fc", "fv", "offset", "fst", "fca", "fcl")
    assert r.drive_mask[0].tolist() == [True, True, True, True, False, False, False]
    assert r.drive_mask[1, 4] and r.drive_mask[2, 5] and r.drive_mask[4, 6] and not r.drive_mask[3, 4:].any()
    assert r.stribeck_velocity[1] == 0.05 and r.coulomb_velocity.tolist() == [0, 0, 0, 0.01, 0, 0]
    assert "fst2" in r.parameter_names and "fca3" in r.parameter_names and "fcl5" in r.parameter_names
    for m in models:
        assert JointFriction.from_dict(m.to_dict()) == m
    with pytest.raises(ValueError, match="friction model"):
        JointFriction.from_dict({"kind": "magic", "velocity": 0, "rest": "held"})

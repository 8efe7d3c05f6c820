"""What the written URDF and MJCF hold: Stribeck and load-dependent Coulomb friction folded into the pair the formats
hold, torque offsets as an MJCF actuator's constant bias, joint by joint where the validation logs say so (issue "Every
assurance checked on what the user meets", item 3)."""

import json
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.optimize import lsq_linear

from dynid.identification.file_terms import file_terms, folded_parameters, variant_label
from dynid.model.friction_model import JointFriction, robot_with

from ..cli.refusals import assert_refused, dynid
from ..conftest import shared_data

REPO = Path(__file__).resolve().parents[2]


def _robot(kind):
    from dynid import load_robot

    base = load_robot("er16")
    return robot_with(base, [JointFriction(kind, 0.5 if kind == "stribeck" else 0.0)] * base.n_dof)


def _states(rng, n=3000, n_dof=6):
    t = np.linspace(0, 10, n)[:, None]
    q = np.sin(0.7 * t + np.arange(n_dof)) * 1.2
    dq = 0.84 * np.cos(0.7 * t + np.arange(n_dof)) + 0.05 * rng.standard_normal((n, n_dof))
    return q, dq, -0.49 * q


def test_nothing_is_folded_where_the_model_holds_only_what_the_formats_hold(rng):
    plain = _robot("coulomb")
    assert {"fc", "fv"} <= set(plain.drive_terms) and not {"fst", "fcl"} & set(plain.drive_terms)
    assert folded_parameters(plain, plain.standard_parameters(), *_states(rng)) is None
    # fst and fcl held but 0: the pair the fold finds is the pair identified
    load = _robot("load")
    phi = load.standard_parameters().copy()
    names = list(load.parameter_names)
    for j in range(load.n_dof):
        phi[names.index(f"fc{j + 1}")], phi[names.index(f"fv{j + 1}")] = 2.0 + j, 1.0 + 0.5 * j
        phi[names.index(f"fcl{j + 1}")] = 0.0
    folded = folded_parameters(load, phi, *_states(rng))
    assert folded is not None
    np.testing.assert_allclose(folded, phi, rtol=1e-9, atol=1e-9)


def test_the_fold_is_the_nearest_non_negative_pair_to_the_joints_whole_friction(rng):
    from dynid.dynamics.regressor import regressor

    robot = _robot("stribeck")
    names = list(robot.parameter_names)
    phi = robot.standard_parameters().copy()
    for j in range(robot.n_dof):
        phi[names.index(f"fc{j + 1}")], phi[names.index(f"fv{j + 1}")] = 0.3, 0.4 * j
        phi[names.index(f"fst{j + 1}")] = 1.0 - 1.0 * j  # a negative Stribeck term pulls the pair's fc toward 0 on the last joints
    q, dq, ddq = _states(rng)
    folded = folded_parameters(robot, phi, q, dq, ddq)
    friction = np.array([n.rstrip("0123456789") in ("fc", "fv", "fst") for n in names])
    whole = regressor(robot, q, dq, ddq) @ np.where(friction, phi, 0.0)
    for j in range(robot.n_dof):
        columns = np.stack([np.sign(dq[:, j]), dq[:, j]], axis=1)
        independent = lsq_linear(columns, whole[:, j], bounds=(0.0, np.inf), tol=1e-12).x
        pair = folded[[names.index(f"fc{j + 1}"), names.index(f"fv{j + 1}")]]
        np.testing.assert_allclose(pair, independent, rtol=1e-6, atol=1e-8)
        assert folded[names.index(f"fst{j + 1}")] == 0.0
    assert np.any(folded[[names.index(f"fc{j + 1}") for j in range(robot.n_dof)]] == 0.0)  # a bound was met


def test_each_joint_is_written_as_the_variant_the_validation_logs_say_predicts_it_best():
    robot = _robot("load")
    labels = [variant_label(f, o) for f in (False, True) for o in (False, True)]

    def log(name, *errors):
        metrics = {k: {"relative_error": e} for k, e in zip(labels, errors)}
        return SimpleNamespace(name=name, metrics=lambda: metrics)

    phi = robot.standard_parameters()
    # per joint (columns): J1 folded with its offset, J2 folded alone, J3 its offset alone, J4 a tie (as identified),
    # J5 folded better on one log and worse on average
    one = log("a", [9, 9, 9, 1, 5, 1], [8, 9, 7, 1, 5, 1], [7, 4, 9, 1, 3, 1], [6, 5, 8, 1, 3, 1])
    two = log("b", [9, 9, 9, 1, 5, 1], [8, 9, 7, 1, 5, 1], [7, 4, 9, 1, 9, 1], [6, 5, 8, 1, 9, 1])
    chosen = file_terms(robot, phi, labels, (one, two))
    assert chosen["folded"] == [True, True, False, False, False, False]
    assert chosen["offset"] == [True, False, True, False, False, False]
    assert chosen["errors"][labels[3]][4] == pytest.approx(6.0) and chosen["logs"] == ["a", "b"]


@pytest.fixture(scope="module")
def ur10e(tmp_path_factory):
    root = shared_data("ur10e_mamedov2020")
    out = tmp_path_factory.mktemp("ur10e") / "out"
    p = dynid("identify", str(REPO / "configs" / "ur10e.toml"), "--out", str(out), "--data-root", str(root), "--no-figures")
    assert p.returncode == 0, p.stderr
    return root, out, p


def _frictionloss(path):
    import mujoco

    model = mujoco.MjModel.from_xml_path(str(path))
    return model.dof_frictionloss.copy(), model.dof_damping.copy()


def test_the_real_ur10es_files_hold_what_was_chosen_and_predict_its_validation_log_better(ur10e, tmp_path):
    from dynid import load_identification_config
    from dynid.identification.run import moving_validation
    from dynid.io.exported.export import consistent_estimate
    from dynid.io.exported.replay import mjcf_replay
    from dynid.model.description_files import mjcf_from_robot

    root, out, p = ur10e
    res = json.loads((out / "results.json").read_text())
    from dynid.io.results import stored_standard

    written = stored_standard(res)[0]  # the estimate the files are written from: its own choice
    chosen = res["diagnostics"]["file_terms"][written]
    folded = [j for j, f in enumerate(chosen["folded"]) if f]
    held = [j for j, f in enumerate(chosen["offset"]) if f]
    plain = chosen["errors"][variant_label(False, False, written)]
    best = [chosen["errors"][variant_label(j in folded, j in held, written)][j] for j in range(6)]
    assert folded and held and all(b < p for b, p, j in zip(best, plain, range(6)) if j in folded or j in held)
    # the MJCF holds the folded pair on those joints, the estimate's own elsewhere
    cfg = load_identification_config(REPO / "configs" / "ur10e.toml", data_root=root)
    robot, phi = consistent_estimate(cfg.robot, res)
    names = list(robot.parameter_names)
    loss, damping = _frictionloss(out / "dynid-model.xml")
    for j in range(robot.n_dof):
        fc, fv = (chosen["fc"][j], chosen["fv"][j]) if j in folded else (phi[names.index(f"fc{j + 1}")], phi[names.index(f"fv{j + 1}")])
        assert loss[j] == pytest.approx(fc, rel=1e-12) and damping[j] == pytest.approx(fv, rel=1e-12)
    # the offsets held: one actuator each, of constant force -offset whatever its ctrl (MuJoCo's own forward dynamics)
    import mujoco

    model = mujoco.MjModel.from_xml_path(str(out / "dynid-model.xml"))
    assert model.nu == len(held)
    data = mujoco.MjData(model)
    data.ctrl[:] = 5.0
    mujoco.mj_forward(model, data)
    expected = np.zeros(6)
    expected[held] = [-phi[names.index(f"offset{j + 1}")] for j in held]
    np.testing.assert_allclose(data.qfrc_actuator, expected, rtol=1e-12, atol=1e-12)
    # MuJoCo's own torques of the written file against the log's measured ones: better than the file as identified
    name, (t, q, dq, ddq, tau) = moving_validation(cfg, res, robot)
    written = mjcf_replay((out / "dynid-model.xml").read_text(), robot, phi, states=(q, dq, ddq), measured=tau)
    as_identified = mjcf_replay(mjcf_from_robot(robot, phi), robot, phi, states=(q, dq, ddq), measured=tau)
    assert written.file_vs_measured < 0.8 * as_identified.file_vs_measured
    assert f"the friction of {', '.join(f'J{j + 1}' for j in folded)} holds" in p.stderr + p.stdout
    assert f"the torque offsets of {', '.join(f'J{j + 1}' for j in held)} are held" in p.stderr + p.stdout
    said = " ".join((p.stderr + p.stdout).split())
    for line in ("dynid-model.urdf read back by Pinocchio on ptp_10_points", "dynid-model.xml read back by MuJoCo on ptp_10_points"):
        assert line in said, said  # each file's line names the log it was read back on
    assert "results.json for the joints whose friction is folded, say how to add them" in said
    report = (out / "report.html").read_text()  # the report's table says it too
    assert f"friction folded on {', '.join(f'J{j + 1}' for j in folded)}" in report
    assert f"offsets held on {', '.join(f'J{j + 1}' for j in held)}" in report
    # export writes the same files; with the choice withdrawn it writes the pair as identified and says nothing of it
    for j in range(robot.n_dof):
        chosen["folded"][j] = chosen["offset"][j] = False
    (tmp_path / "results.json").write_text(json.dumps(res))
    e = dynid("export", str(REPO / "configs" / "ur10e.toml"), "--results", str(tmp_path / "results.json"), "--mjcf",
              str(tmp_path / "m.xml"), "--data-root", str(root))
    assert e.returncode == 0, e.stderr
    assert "holds its Stribeck" not in e.stdout + e.stderr and "folded" not in (tmp_path / "m.xml").read_text()
    loss, _ = _frictionloss(tmp_path / "m.xml")
    np.testing.assert_allclose(loss, [phi[names.index(f"fc{j + 1}")] for j in range(robot.n_dof)], rtol=1e-12)
    assert mujoco.MjModel.from_xml_path(str(tmp_path / "m.xml")).nu == 0
    assert "the torque offsets of J1, J2, J3, J4, J5, J6 are left out" in (tmp_path / "m.xml").read_text()


def test_a_results_files_friction_that_is_no_pair_per_joint_is_refused_in_one_line(ur10e, tmp_path):
    root, out, _ = ur10e
    res = json.loads((out / "results.json").read_text())
    for entry in res["diagnostics"]["file_terms"].values():
        entry["fc"][0] = -1.0
    (tmp_path / "results.json").write_text(json.dumps(res))
    p = dynid("export", str(REPO / "configs" / "ur10e.toml"), "--results", str(tmp_path / "results.json"), "--mjcf",
              str(tmp_path / "m.xml"), "--data-root", str(root))
    assert_refused(p, "diagnostics.file_terms")
    assert not (tmp_path / "m.xml").exists()


def test_the_files_take_the_choice_made_for_the_estimate_they_are_written_from(ur10e):
    """Each estimate the files may be written from has its own choice (the physically consistent one, the drive-only
    candidate): a choice made for another estimate is not applied to this one."""
    from dynid import load_identification_config
    from dynid.io.exported.export import consistent_estimate, file_parameters
    from dynid.io.results import stored_standard

    root, out, _ = ur10e
    res = json.loads((out / "results.json").read_text())
    cfg = load_identification_config(REPO / "configs" / "ur10e.toml", data_root=root)
    robot, phi = consistent_estimate(cfg.robot, res)
    written = stored_standard(res)[0]
    held, note = file_parameters(robot, phi, res, form="MJCF")
    assert not np.array_equal(held, phi) and note  # its own choice applies
    res["diagnostics"]["file_terms"] = {"another estimate": res["diagnostics"]["file_terms"][written]}
    other, note = file_parameters(robot, phi, res, form="MJCF")
    np.testing.assert_array_equal(other, phi)
    assert note == ""

"""Joints that follow another (a URDF's `<mimic>`: a palletiser's parallelogram, a coupled finger) against Pinocchio's
own model of the same file, where a mimic joint is a joint of its own: dynid's regressor at any state equals Pinocchio's
at the coupled state, each following joint's row added to its master's times the multiplier (virtual work)."""

import numpy as np
import pinocchio as pin
import pytest

from dynid.dynamics.base_parameters import base_parameters
from dynid.dynamics.regressor import regressor
from dynid.dynamics.rnea import rnea_torques
from dynid.exceptions import ConfigError
from dynid.model.description import load_robot
from dynid.model.urdf import inertial_from_pinocchio

from .test_prismatic_joints import _joint, _link, _urdf

PALLETISER = _urdf(
    [_link("turret", 40.0, "0.05 0 0.2", (2.0, 2.2, 1.5, 0.02, 0.01, 0.0)),
     _link("arm", 25.0, "0 0 0.5", (2.5, 2.4, 0.3, 0.0, 0.02, 0.01)),
     _link("forearm", 15.0, "0.6 0 0", (0.2, 1.8, 1.9, 0.01, 0.0, 0.02)),
     _link("wrist", 6.0, "0.05 0 -0.1", (0.05, 0.06, 0.04, 0.0, 0.001, 0.0)),
     _link("flange", 2.0, "0 0 -0.05", (0.01, 0.01, 0.015, 0.0, 0.0, 0.0)),
     _link("finger_a", 0.3, "0 0.01 -0.03", (1e-4, 1e-4, 1e-4, 0.0, 0.0, 0.0)),
     _link("finger_b", 0.3, "0 -0.01 -0.03", (1e-4, 1e-4, 1e-4, 0.0, 0.0, 0.0))],
    [_joint("j1", "revolute", "base", "turret", "0 0 0.5", "0 0 0", "0 0 1"),
     _joint("j2", "revolute", "turret", "arm", "0.2 0 0.4", "0 0 0", "0 1 0"),
     _joint("j3", "revolute", "arm", "forearm", "0 0 1.1", "0 0 0", "0 1 0"),
     _joint("j4", "revolute", "forearm", "wrist", "1.2 0 0", "0 0 0", "0 1 0", mimic='<mimic joint="j3" multiplier="-1" offset="0.1"/>'),
     _joint("j5", "revolute", "wrist", "flange", "0.1 0 -0.2", "0 0 0", "0 0 1"),
     _joint("finger_a_joint", "prismatic", "flange", "finger_a", "0 0.03 -0.1", "0 0 0", "0 1 0", 0.0, 0.04),
     _joint("finger_b_joint", "prismatic", "flange", "finger_b", "0 -0.03 -0.1", "0 0 0", "0 -1 0", 0.0, 0.04,
            '<mimic joint="finger_a_joint" multiplier="1.0"/>')])
"""A palletiser: a turret, two arms, a passive joint that keeps the wrist level by following j3 (`<mimic>` multiplier
-1), a turning flange, and a gripper whose second finger follows the first."""


@pytest.fixture
def palletiser(tmp_path):
    path = tmp_path / "palletiser.urdf"
    path.write_text(PALLETISER)
    return path


def _fold(robot, rows):
    """Pinocchio's rows (N, n_dof, ...) folded by virtual work, written out here: each follower's row times its
    multiplier added to its master's, its own zero."""
    rows = rows.copy()
    for j, jt in enumerate(robot.joints):
        if jt.mimic is not None:
            k, multiplier, _ = jt.mimic
            rows[:, k] += multiplier * rows[:, j]
            rows[:, j] = 0.0
    return rows


def test_the_followers_are_read_from_the_file(palletiser):
    robot = load_robot(palletiser)
    follows = {jt.name: jt.mimic for jt in robot.joints if jt.mimic is not None}
    assert follows == {"j4": (2, -1.0, 0.1), "finger_b_joint": (5, 1.0, 0.0)}
    assert robot.independent.tolist() == [True, True, True, False, True, True, False]
    assert not robot.drive_mask[[3, 6]].any() and robot.drive_mask[[0, 1, 2, 4, 5]].all()  # a follower has no drive


def test_the_regressor_equals_pinocchios_at_the_coupled_state_folded(palletiser, rng):
    """1000 random states whose followers' columns hold anything: dynid's regressor equals Pinocchio's joint-torque
    regressor of the file (its mimic joints free joints of their own) at the state where they follow their masters,
    folded, link by link to 1e-10 of its RMS; Y·φ equals Pinocchio's RNEA folded, and dynid's RNEA."""
    robot = load_robot(palletiser)
    model = pin.buildModelFromUrdf(str(palletiser))
    data = model.createData()
    n = 1000
    lo, hi = robot.limits.position_span()
    q, dq, ddq = rng.uniform(lo, hi, (n, robot.n_dof)), rng.normal(size=(n, robot.n_dof)), 3 * rng.normal(size=(n, robot.n_dof))
    coupled = [x.copy() for x in (q, dq, ddq)]
    for x, offset in zip(coupled, (0.1, 0.0, 0.0)):  # j4 = -q3 + 0.1, finger_b = finger_a: written out here
        x[:, 3] = -x[:, 2] + offset
        x[:, 6] = x[:, 5]
    y = regressor(robot, q, dq, ddq)
    pin_y = np.array([pin.computeJointTorqueRegressor(model, data, *(x[k] for x in coupled)) for k in range(n)])
    tau = np.array([pin.rnea(model, data, *(x[k] for x in coupled)) for k in range(n)])
    perm = [4, 5, 7, 6, 8, 9, 1, 2, 3, 0]  # Pinocchio's parameter order -> eq. 5's
    npj = robot.n_params_per_joint
    ours = y.reshape(n, robot.n_dof, robot.n_dof, npj)[..., :10].reshape(n, robot.n_dof, -1)
    expected = _fold(robot, pin_y.reshape(n, robot.n_dof, robot.n_dof, 10)[..., perm].reshape(n, robot.n_dof, -1))
    assert np.abs(ours - expected).max() < 1e-10 * np.sqrt(np.mean(expected**2))
    rms = np.sqrt(np.mean(tau**2))
    rigid = robot.without_drive_terms(robot.drive_terms)
    np.testing.assert_allclose(regressor(rigid, q, dq, ddq) @ rigid.standard_parameters(), _fold(robot, tau), atol=1e-10 * rms, rtol=0)
    np.testing.assert_allclose(rnea_torques(rigid, q, dq, ddq), _fold(robot, tau), atol=1e-10 * rms, rtol=0)
    assert np.all(y[:, [3, 6]] == 0.0)  # the followers' own rows: their torque is their masters'
    np.testing.assert_allclose(inertial_from_pinocchio(model.inertias[4]), robot.inertial[3], rtol=1e-12)


def test_the_base_parameters_are_the_rank_of_pinocchios_folded_regressor(palletiser, rng):
    robot = load_robot(palletiser).without_drive_terms(load_robot(palletiser).drive_terms)
    model = pin.buildModelFromUrdf(str(palletiser))
    data = model.createData()
    q = robot.limits.random_positions(300, rng)
    q, dq, ddq = robot.coupled(q, rng.normal(size=q.shape), rng.normal(size=q.shape))
    w = _fold(robot, np.array([pin.computeJointTorqueRegressor(model, data, q[k], dq[k], ddq[k]) for k in range(300)]))
    assert base_parameters(robot).n_base == np.linalg.matrix_rank(w.reshape(-1, w.shape[-1]))


@pytest.mark.parametrize("change, said", [
    (('multiplier="-1"', 'multiplier="0"'), 'joint \'j4\' has <mimic joint="j3" multiplier="0" offset="0.1">: expected'),
    (('offset="0.1"', 'offset="nan"'), 'joint \'j4\' has <mimic joint="j3" multiplier="-1" offset="nan">: expected'),
    (('<mimic joint="j3"', '<mimic joint="j9"'), "mimics joint 'j9', which is not another moving joint of the file"),
    (('<mimic joint="finger_a_joint"', '<mimic joint="j4"'), "joint 'finger_b_joint' mimics joint 'j4' (multiplier 1, offset 0): expected another joint of the robot that mimics none"),
])
def test_a_coupling_that_cannot_be_is_refused_in_one_line(tmp_path, change, said):
    path = tmp_path / "bad.urdf"
    path.write_text(PALLETISER.replace(*change))
    with pytest.raises(ConfigError, match="^[^\n]*" + said.replace("(", r"\(").replace(")", r"\)")):
        load_robot(path)


def test_a_follower_whose_master_is_held_is_refused_with_its_fix(palletiser):
    with pytest.raises(ConfigError, match="joint 'finger_b_joint' mimics joint 'finger_a_joint', which the config holds "
                                          "fixed: hold 'finger_b_joint' too"):
        load_robot(palletiser, held=("finger_a_joint",))
    robot = load_robot(palletiser, held=("finger_a_joint", "finger_b_joint"))  # a gripper held, as before
    assert [jt.name for jt in robot.joints] == ["j1", "j2", "j3", "j4", "j5"] and robot.joints[3].mimic == (2, -1.0, 0.1)


def _closed_loop_palletiser(palletiser, seconds=8.0, rate=500.0):
    """The palletiser (gripper held) under its PID loop along a Fourier reference of its driven joints, noise-free."""
    from dynid.simulation.closed_loop import Controller, simulate_closed_loop
    from dynid.studies.example import _with_drives

    robot = _with_drives(load_robot(palletiser, held=("finger_a_joint", "finger_b_joint")), np.random.default_rng(0))
    t = np.arange(int(seconds * rate)) / rate
    w = 2 * np.pi * 0.25 * np.arange(1, 5)
    coefficients = np.random.default_rng(3).normal(0.0, 0.25, (4, robot.n_dof))
    q_ref = np.sin(np.outer(t, w)) @ coefficients
    dq_ref = (np.cos(np.outer(t, w)) * w) @ coefficients
    q_ref[:, 3] = dq_ref[:, 3] = 7.0  # a follower's reference columns hold anything: its master's say
    controller = Controller.for_robot(robot, rate=rate)
    return robot, t, q_ref, dq_ref, controller, simulate_closed_loop(robot, t, q_ref, dq_ref, controller)


def test_the_closed_loop_simulation_moves_a_follower_with_its_master(palletiser):
    """The closed-loop simulation (IDIM-IV's and DIDIM's) holds the coupling: the motion projected onto it (Gᵀ M G ν̇ =
    Gᵀ (τ − h), M and h from Pinocchio's CRBA and RNEA), j4 = 0.1 − q3 at every step, its commanded torque 0, and
    dynid's folded inverse dynamics at the simulated states equals the torques that moved it. It was refused before."""
    robot, t, q_ref, _, _, run = _closed_loop_palletiser(palletiser)
    assert np.abs(run.q_true[:, 3] - (0.1 - run.q_true[:, 2])).max() < 1e-12
    assert np.abs(run.dq_true[:, 3] + run.dq_true[:, 2]).max() < 1e-12 and np.all(run.tau_applied[:, 3] == 0.0)
    assert np.abs(run.q_true[:, 2] - q_ref[:, 2]).max() < 0.05  # the loop tracks
    driven = [0, 1, 2, 4]
    ours = rnea_torques(robot, run.q_true, run.dq_true, run.ddq_true)
    rms = np.sqrt(np.mean(run.tau_applied[:, driven] ** 2, axis=0))
    np.testing.assert_allclose(ours[:, driven] / rms, run.tau_applied[:, driven] / rms, atol=1e-9, rtol=0)


def test_idim_iv_and_didim_identify_a_coupled_robot_in_closed_loop(palletiser):
    """IDIM-IV and DIDIM (issue "Every arm a user has": they refused a robot with a `<mimic>` joint) on a noise-free
    closed-loop log of the palletiser: each converges, and each estimate predicts the truth's torques at the true states
    within 1 % (0.37 % measured: what the log's derivatives allow, least squares' too; a simulation that let j4 move
    freely would give DIDIM other torques to fit)."""
    from dynid.identification.closed_loop_estimators import ClosedLoopExperiment, closed_loop_identify
    from dynid.io.logs.datasets import Recording

    robot, t, q_ref, dq_ref, controller, run = _closed_loop_palletiser(palletiser)
    base = base_parameters(robot, rng=0)
    recording = Recording("closed loop", t, run.q, None, run.tau, 500.0, followers=robot.followers)
    out = closed_loop_identify(robot, base, recording, ClosedLoopExperiment(controller, q_ref, dq_ref, None))
    truth = base.base_from_standard(robot.standard_parameters())
    w = base.base_observation(regressor(robot, run.q_true, run.dq_true, run.ddq_true)).reshape(-1, base.n_base)
    for key in ("wls", "idim-iv", "didim"):
        assert out[key].converged, (key, out[key].message)
        error = np.linalg.norm(w @ (out[key].params - truth)) / np.linalg.norm(w @ truth)
        assert error < 0.01, (key, error)


def test_an_mjcf_written_with_the_coupling_is_read_back_with_it(palletiser, tmp_path, rng):
    """dynid's MJCF holds the coupling as a joint equality; read as a robot description it is the same coupled robot:
    the same followers and, on random states, the same torques to 1e-10 of their RMS. A coupling MuJoCo holds but dynid
    cannot (a quadratic polynomial) is refused in one line."""
    from dynid.model.description_files import mjcf_from_robot

    robot = load_robot(palletiser, held=("finger_a_joint", "finger_b_joint"))
    rigid = robot.without_drive_terms(robot.drive_terms)
    (tmp_path / "m.xml").write_text(mjcf_from_robot(rigid))
    again = load_robot(tmp_path / "m.xml").without_drive_terms(robot.drive_terms)
    assert [j.mimic for j in again.joints] == [j.mimic for j in robot.joints]
    q = robot.limits.random_positions(200, rng)
    dq, ddq = rng.normal(size=q.shape), rng.normal(size=q.shape)
    tau = regressor(rigid, q, dq, ddq) @ rigid.standard_parameters()
    np.testing.assert_allclose(regressor(again, q, dq, ddq) @ again.standard_parameters(), tau,
                               atol=1e-10 * np.sqrt(np.mean(tau**2)), rtol=0)
    (tmp_path / "bad.xml").write_text(mjcf_from_robot(rigid).replace('polycoef="0.10000000000000001 -1 0 0 0"',
                                                                     'polycoef="0.1 -1 0.5 0 0"'))
    with pytest.raises(ConfigError, match=r"joint 'j4' has an <equality joint> \(polycoef 0.1 -1 0.5 0 0\): expected a linear"):
        load_robot(tmp_path / "bad.xml")


def test_the_replay_on_random_states_keeps_each_follower_within_its_range(palletiser):
    """`dynid export --mjcf` without a log reads the file back on random states within the joint limits: j4 = 0.1 - q3
    left its range [-2, 2] on 3 of 200 such states, where MuJoCo's joint limit (a constraint) pushed back and the file
    was said to be 31 % off dynid's model. The states are now drawn where every follower is within its range too."""
    from dynid.io.exported.replay import mjcf_replay
    from dynid.model.description_files import mjcf_from_robot

    robot = load_robot(palletiser, held=("finger_a_joint", "finger_b_joint"))
    phi = robot.standard_parameters()
    check = mjcf_replay(mjcf_from_robot(robot, phi), robot, phi, n_states=400, rng=1)
    assert check.relative_error < 1e-9, check.relative_error


def test_a_dh_table_states_a_coupling_as_a_urdf_does(tmp_path, rng):
    """A DH table's ``mimic = { joint = "j3", multiplier = -1.0, offset = 0.1 }``: the joint follows j3, and the
    regressor is the table's robot without the coupling at the coupled state, folded (written out here); a joint name
    the table lacks and a URDF-convention table's mimic (the URDF states its own) are refused in one line."""
    rows = ('[[joints]]\nname = "j1"\nd = 0.5\n{m}[[joints]]\nname = "j2"\nalpha = "-pi/2"\na = 0.2\n{m}'
            '[[joints]]\nname = "j3"\na = 1.1\n{m}[[joints]]\nname = "j4"\na = 1.2\n{mimic}{m}'
            '[[joints]]\nname = "j5"\nalpha = "pi/2"\nd = 0.2\n{m}')
    inertial = 'mass = 3.0\ncom = [0.05, 0.01, -0.02]\ninertia = [0.02, 0.03, 0.025, 0.001, 0.0, 0.002]\n'
    coupled = tmp_path / "coupled.toml"
    coupled.write_text('name = "dh"\nconvention = "modified"\n' + rows.format(
        m=inertial, mimic='mimic = { joint = "j3", multiplier = -1.0, offset = 0.1 }\n'))
    free = tmp_path / "free.toml"
    free.write_text('name = "dh"\nconvention = "modified"\n' + rows.format(m=inertial, mimic=""))
    robot, plain = load_robot(coupled), load_robot(free)
    assert robot.followers == (3,) and robot.joints[3].mimic == (2, -1.0, 0.1)
    q = plain.limits.random_positions(100, rng)
    dq, ddq = rng.normal(size=q.shape), rng.normal(size=q.shape)
    moved = [x.copy() for x in (q, dq, ddq)]
    for x, offset in zip(moved, (0.1, 0.0, 0.0)):
        x[:, 3] = -x[:, 2] + offset
    rigid, loose = (r.without_drive_terms(r.drive_terms) for r in (robot, plain))
    np.testing.assert_array_equal(regressor(rigid, q, dq, ddq), _fold(robot, regressor(loose, *moved)))
    (tmp_path / "bad.toml").write_text(coupled.read_text().replace('joint = "j3"', 'joint = "j9"'))
    with pytest.raises(ConfigError, match=r"mimic.joint: expected the name of another joint of the table \(j1, j2, j3, "
                                          r"j4, j5\), got 'j9'"):
        load_robot(tmp_path / "bad.toml")
    (tmp_path / "p.urdf").write_text(PALLETISER)
    (tmp_path / "u.toml").write_text('convention = "urdf"\nurdf = "p.urdf"\nheld = ["finger_a_joint", "finger_b_joint"]\n'
                                     + "".join(f'[[joints]]\nname = "j{k}"\n' for k in range(1, 5))
                                     + '[[joints]]\nname = "j5"\nmimic = { joint = "j3" }\n')
    with pytest.raises(ConfigError, match=r"mimic describe a DH chain, but the chain is p.urdf's"):
        load_robot(tmp_path / "u.toml")


def test_the_folded_model_is_what_mujocos_constrained_simulation_needs(palletiser):
    """Outside dynid and Pinocchio: MuJoCo simulates the file (its parser reads each `<mimic>` as a joint equality, made
    rigid) under a loop that drives the masters only, the followers passive. dynid's folded RNEA at MuJoCo's states
    equals the torques that moved it on every driven joint, to 1e-5 of each arm joint's RMS and 1e-2 of the light
    finger's (MuJoCo's equality gives way by 1e-4 of the constraint force: it is a soft constraint); leaving a follower's row
    unfolded (its drive given nothing, as a free joint would be) is off by a large share, so the identity can fail."""
    from tests.mujoco_logs import Drives, simulate

    robot = load_robot(palletiser)
    zero = Drives(*(np.zeros(robot.n_dof) for _ in range(3)))
    log = simulate(PALLETISER, zero, "fourier", 2.0, np.random.default_rng(5), f0=0.5, harmonics=3, dry="sign",
                   centre=[0.0, 0.0, 0.0, 0.1, 0.0, 0.02, 0.02], amplitude=[0.6, 0.6, 0.6, 0.6, 0.6, 0.015, 0.015],
                   jitter=0.0, gaps=0, noise_share=0.0, torque_std=0.0)
    assert np.abs(log.q[:, 3] - (0.1 - log.q[:, 2])).max() < 1e-5 and np.abs(log.q[:, 6] - log.q[:, 5]).max() < 1e-5
    ours = rnea_torques(robot, log.q, log.dq, log.ddq)
    driven = [0, 1, 2, 4, 5]
    rms = np.sqrt(np.mean(log.tau[:, driven] ** 2, axis=0))
    assert np.all(log.tau[:, [3, 6]] == 0.0) and np.all(ours[:, [3, 6]] == 0.0)
    off = np.abs(ours[:, driven] - log.tau[:, driven]).max(axis=0) / rms
    assert off[:4].max() < 1e-5 and off[4] < 1e-2, off  # the finger's 0.3 kg: MuJoCo's equality is soft by 1e-4
    model = pin.buildModelFromUrdf(str(palletiser))  # its mimic joints free joints: their own rows
    data = model.createData()
    own = np.array([pin.rnea(model, data, *(x[k] for x in (log.q, log.dq, log.ddq))) for k in range(0, len(log.t), 10)])
    unfolded = np.abs(own[:, [2, 5]] - log.tau[::10, [2, 5]]).max(axis=0) / rms[[2, 4]]  # j3 and finger_a alone
    assert unfolded.min() > 0.1, unfolded

"""A written URDF read back by Pinocchio, and a written MJCF by MuJoCo, reproduce dynid's model where the format can
hold it (issue "The model proven where it goes", item 1); a file that lost a value does not, and the check says so."""

import json
import re
import shlex
from importlib import resources
from pathlib import Path

import numpy as np
import pytest

from dynid.dynamics.regressor import regressor
from dynid.io.exported.replay import urdf_replay
from dynid.io.exported.urdf_write_back import urdf_written_back
from dynid.model.description import load_robot

URDF = Path(str(resources.files("dynid.model") / "robots" / "ur10e.urdf"))


def _estimate():
    robot = load_robot(URDF)  # drive terms Ia, fc, fv, offset
    phi = robot.standard_parameters().copy()
    names = robot.parameter_names
    for j in range(1, 7):
        phi[names.index(f"fc{j}")], phi[names.index(f"fv{j}")] = 2.0 + j, 1.0 + 0.1 * j
        phi[names.index(f"Ia{j}")], phi[names.index(f"offset{j}")] = 0.2, 0.5
    phi[names.index("XY3")] += 0.002  # an off-diagonal inertia [kg·m²] the file must keep
    return robot, phi


def _without_dry_friction():
    """:func:`_estimate` with no Coulomb friction or offset (all the MJCF holds as dynid's model)."""
    robot, phi = _estimate()
    names = robot.parameter_names
    for j in range(1, 7):
        phi[names.index(f"fc{j}")] = phi[names.index(f"offset{j}")] = 0.0
    return robot, phi


def _sines(t: np.ndarray):
    """Each joint's sine of 0.5 Hz (amplitudes 0.3-0.8 rad) at ``t``: q, dq, ddq."""
    w, amp = 2 * np.pi * 0.5, np.linspace(0.3, 0.8, 6)
    return amp * np.sin(w * t)[:, None], amp * w * np.cos(w * t)[:, None], -amp * w**2 * np.sin(w * t)[:, None]


def test_the_written_urdf_reproduces_the_model_and_says_what_it_cannot_hold():
    robot, phi = _estimate()
    text, _ = urdf_written_back(URDF, robot, phi)
    check = urdf_replay(text, robot, phi)
    assert check.relative_error < 1e-9
    assert check.missing == ("Ia", "offset")
    assert np.all(check.missing_share > 0) and check.missing_share.shape == (6,)


def test_on_a_logs_states_the_replay_says_what_the_missing_terms_cost_against_the_measured_torque():
    """States of a smooth motion, "measured" torque = dynid's whole model: the model is 0 % off and the URDF is off by
    exactly the terms it cannot hold (Ia·q̈ + offset), computed here by hand."""
    robot, phi = _estimate()
    assert np.all(robot.coulomb_velocity == 0)  # the file's fc·sign(q̇) is the model's
    t = np.linspace(0.0, 4.0, 400)[:, None]
    w = np.arange(1, 7)[None, :]
    q, dq, ddq = 0.5 * np.sin(w * t / 2), 0.25 * w * np.cos(w * t / 2), -0.125 * w**2 * np.sin(w * t / 2)
    measured = regressor(robot, q, dq, ddq) @ phi
    text, _ = urdf_written_back(URDF, robot, phi)
    check = urdf_replay(text, robot, phi, states=(q, dq, ddq), measured=measured)
    assert check.n_states == 400 and check.relative_error < 1e-9
    assert check.model_vs_measured < 1e-9
    by_hand = 100 * np.linalg.norm(0.2 * ddq + 0.5) / np.linalg.norm(measured)
    assert check.file_vs_measured == pytest.approx(by_hand, rel=1e-6)


def test_a_file_that_dropped_the_off_diagonal_inertia_is_caught():
    """What a converter that keeps only the diagonal does: the check's error is then far above round-off."""
    robot, phi = _estimate()
    text, _ = urdf_written_back(URDF, robot, phi)
    dropped = re.sub(r'(ix[yz]|iyz)="[^"]*"', r'\1="0.0"', text)
    assert dropped != text
    assert urdf_replay(dropped, robot, phi).relative_error > 1e-5


def test_dynid_export_says_the_urdf_it_wrote_reproduces_the_model(tmp_path):
    from tests.cli.refusals import dynid
    from tests.simulated_logs import simulated_case

    cfg, _ = simulated_case(tmp_path, "ur10e", 100.0, "fourier", duration=10.0)
    cfg.write_text(cfg.read_text().replace('estimators = ["ols"]', 'estimators = ["wls", "sdp"]'))
    p = dynid("identify", cfg, "--out", tmp_path / "out", "--no-figures", env={"COLUMNS": "10000"})  # a pipe: unwrapped
    assert p.returncode == 0, p.stderr
    # identify reads back the files it wrote, on the validation log: results.json, the terminal and the report say it
    taken = json.loads((tmp_path / "out" / "results.json").read_text())["files_taken_away"]
    assert taken["log"] == "validation" and [f["format"] for f in taken["files"]] == ["URDF", "MJCF"]
    assert taken["files"][0]["equals_model_to"] < 1e-9 and taken["files"][0]["samples"] > 100
    assert taken["files"][0]["file_vs_measured"] >= taken["files"][0]["model_vs_measured"] > 0
    said = " ".join((p.stdout + p.stderr).split())  # a warning line goes to standard error
    assert f"{taken['files'][0]['file']} read back by Pinocchio on validation" in said
    assert "The files you take away" in (tmp_path / "out" / "report.html").read_text()
    # the MJCF was read back, not simulated: said, with the command that simulates it, which runs as printed
    forward = re.search(r"dynid-model\.xml not simulated forward by dynid identify \(.*?\): dynid (export .*? --forward) "
                        r"runs it", said)
    assert forward is not None, said
    f = dynid(*shlex.split(forward.group(1)), cwd=tmp_path)
    assert f.returncode == 0, f.stderr
    assert "simulated in MuJoCo along validation" in " ".join(f.stdout.split()) and (tmp_path / "config-identified.xml").is_file()
    # what each simulator computes from its file, per joint, against dynid's whole model: said, and a warning where
    # a joint is more than 2 % off (the URDF cannot hold the rotor inertia and the offset; MuJoCo's frictionloss)
    gaps = [f["simulator_gap"] for f in taken["files"]]
    assert all(len(g) == 6 for g in gaps) and max(gaps[1]) > 0
    for f, tool in zip(taken["files"], ("Pinocchio", "MuJoCo")):
        listed = ", ".join(f"J{j + 1} {g:.2g}" for j, g in enumerate(f["simulator_gap"]))
        assert f"what {tool} (" in said and f"computes from it is off dynid's whole model by {listed} %" in said
    p = dynid("export", cfg, "--results", tmp_path / "out" / "results.json", "--urdf", tmp_path / "m.urdf",
              "--mjcf", tmp_path / "m.xml")
    assert p.returncode == 0, p.stderr
    said = " ".join((p.stdout + p.stderr).split())
    on_log = re.search(r"m\.urdf read back by Pinocchio on validation \((\d+) samples\): equals dynid's model to (\S+) of "
                       r"its RMS where URDF can hold it.*?against the log's unfiltered measured torques (\S+) %, dynid's "
                       r"whole model (\S+) %; it cannot hold Ia = rotor \(reflected motor\) inertia, (.+, )*offset = "
                       r"constant torque offset", said)
    assert on_log is not None and int(on_log.group(1)) > 100 and float(on_log.group(2)) < 1e-9
    assert float(on_log.group(3)) >= float(on_log.group(4)) > 0  # the file lacks the offset the model holds
    error = float(re.search(r"m\.xml read back by MuJoCo on validation \(\d+ samples\): equals dynid's model to (\S+) of "
                            r"its RMS", said).group(1))
    assert error < 1e-6 and "frictionloss a constraint as MuJoCo solves it" in said
    p = dynid("export", cfg, "--results", tmp_path / "out" / "results.json", "--mjcf", tmp_path / "f.xml", "--forward")
    assert p.returncode == 0, p.stderr
    steps = [line.split(" (at ")[0] for line in (p.stdout + p.stderr).splitlines() if line.startswith("dynid export: ")]
    assert steps == ["dynid export: writing the model's files", "dynid export: reading the files back (MuJoCo)",
                     "dynid export: simulating the MJCF in MuJoCo along a validation log",
                     "dynid export: writing results"], steps  # in a pipe a line a step: none of them silent
    simulated = re.search(r"f\.xml simulated in MuJoCo along validation \((\d+) samples.*? the torques it needs are (\S+) % "
                          r"off the measured ones, against (\S+) % for dynid's model", " ".join(p.stdout.split()))
    assert simulated is not None and int(simulated.group(1)) > 100
    assert 0 < float(simulated.group(3)) and 0 < float(simulated.group(2)) < 3 * float(simulated.group(3)) + 1
    p = dynid("export", cfg, "--results", tmp_path / "out" / "results.json", "--urdf", tmp_path / "g.urdf", "--forward")
    assert p.returncode == 1 and "--forward simulates the MJCF: give --mjcf FILE too" in p.stderr


def test_a_model_whose_gravity_is_not_minus_z_is_written_with_its_base_turned():
    """The KR 300's model has gravity along +z of its base frame (the authors' base is turned half a turn about x); a
    URDF has no gravity field and its users take -z, so the URDF dynid wrote gave torques 71 % off its model. The
    base is now turned under a world link, and the file reproduces the model."""
    from dynid.model.description_files import urdf_from_robot

    robot = load_robot(Path(__file__).resolve().parents[2] / "configs" / "robots" / "kuka_kr300.toml")
    assert np.allclose(robot.gravity, [0.0, 0.0, 9.81])
    phi = robot.standard_parameters()
    text = urdf_from_robot(robot, phi)
    assert '<link name="world"/>' in text
    assert urdf_replay(text, robot, phi).relative_error < 1e-9
    plain = urdf_from_robot(load_robot("er16"))  # gravity along -z already: no world link
    assert '<link name="world"/>' not in plain


def test_the_written_mjcf_read_back_by_mujoco_reproduces_the_model_and_a_lost_value_is_caught():
    """MuJoCo's mj_inverse of the MJCF dynid writes (armature = Ia, damping = fv, frictionloss = fc) equals dynid's
    model of those terms; a file that dropped the off-diagonal inertia, or the armature, is caught; what MJCF cannot
    hold is the offset alone; MuJoCo's frictionloss constraint is measured apart, and is not fc·sign(q̇)."""
    from dynid.io.exported.replay import mjcf_replay
    from dynid.model.description_files import mjcf_from_robot

    robot, phi = _estimate()
    text = mjcf_from_robot(robot, phi)
    check = mjcf_replay(text, robot, phi)
    assert check.relative_error < 1e-8
    assert check.missing == ("offset",)
    assert check.frictionloss_gap > 1e-3  # a soft constraint solved for, not a function of the velocity
    full = re.compile(r'fullinertia="(\S+) (\S+) (\S+) \S+ \S+ \S+"')
    diagonal = full.sub(r'fullinertia="\1 \2 \3 0 0 0"', text)
    assert diagonal != text and mjcf_replay(diagonal, robot, phi).relative_error > 1e-5
    no_rotor = re.sub(r'armature="[^"]*"', 'armature="0"', text)
    assert mjcf_replay(no_rotor, robot, phi).relative_error > 1e-5
    # the dry-friction constraint written as stiff as MuJoCo's default step keeps stable: what MuJoCo computes from the
    # file is as near dynid's model as with MuJoCo's own default time constant or nearer, by 2-4 % of the RMS torque on
    # the wrist (the offset, which MJCF cannot hold, is the rest)
    assert 'solreffriction="0.004 1"' in text
    soft = mjcf_replay(text.replace(' solreffriction="0.004 1"', ""), robot, phi)
    assert np.all(check.simulator_gap <= soft.simulator_gap + 1e-9) and np.all((soft.simulator_gap - check.simulator_gap)[3:] > 2)


def test_a_link_at_the_limit_of_a_real_one_is_written_so_that_mujoco_loads_it():
    """A physically consistent estimate may hold a link at the limit (the TX40's link 6 from the SDP: a point mass, a
    singular inertia); MuJoCo refuses a fullinertia that is not positive definite, so the MJCF dynid wrote did not
    load; a simulated UR10e's SDP wrist broke MuJoCo's triangle inequality by round-off. The inertia is now written
    as MuJoCo loads it (dynid.model.description_files.mujoco_inertia), the torques unchanged to 1e-6."""
    import mujoco

    from dynid.io.exported.replay import mjcf_replay
    from dynid.model.description_files import mjcf_from_robot
    from dynid.model.spatial import inertial_from_physical

    robot, phi = _estimate()
    names = robot.parameter_names
    last = [names.index(f"{p}6") for p in ("XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M")]
    phi[last] = inertial_from_physical(0.5, np.array([0.0, 0.0, 0.03]), np.zeros((3, 3)))  # a point mass
    text = mjcf_from_robot(robot, phi)
    mujoco.MjModel.from_xml_string(text)  # raised "inertia must have positive eigenvalues" before
    assert mjcf_replay(text, robot, phi).relative_error < 1e-6
    rod = inertial_from_physical(0.5, np.array([0.0, 0.0, 0.03]), np.diag([0.0, 0.01, 0.01]) * (1 + np.array([0, 0, 1e-13])))
    phi[last] = rod  # a thin rod whose largest moment exceeds the sum of the others by round-off
    mujoco.MjModel.from_xml_string(mjcf_from_robot(robot, phi))


def test_the_written_mjcf_simulated_along_a_motion_needs_the_models_torques():
    """Forward check: MuJoCo's simulation of the MJCF dynid wrote, driven along a smooth motion by its own computed
    torque plus a PD loop, needs the torques of dynid's model of the same estimate (here everything the file holds:
    links, armature, damping; no dry friction) to a fraction of a percent; the measured torque taken as the model's,
    the simulated-against-measured figure is the same. With a torque offset the file cannot hold, the gap is that
    offset's share."""
    from dynid.dynamics.regressor import regressor
    from dynid.io.exported.replay import mjcf_forward
    from dynid.model.description_files import mjcf_from_robot

    robot, phi = _without_dry_friction()
    names = robot.parameter_names
    t = np.arange(0.0, 4.0, 0.01)
    q, dq, ddq = _sines(t)
    tau = regressor(robot, q, dq, ddq) @ phi
    said = []
    check = mjcf_forward(mjcf_from_robot(robot, phi), robot, phi, t, q, dq, ddq, tau,
                         progress=lambda done, total: said.append((done, total)))
    unsaid = mjcf_forward(mjcf_from_robot(robot, phi), robot, phi, t, q, dq, ddq, tau)
    assert unsaid.simulated_vs_measured == check.simulated_vs_measured
    assert np.array_equal(unsaid.tracking_error, check.tracking_error)
    assert said[0] == (0, t.size) and said[-1] == (t.size, t.size) and len(said) >= 2  # its share simulated, as it goes
    assert all(b[0] > a[0] for a, b in zip(said, said[1:]))
    assert check.simulated_vs_model < 0.5 and check.model_vs_measured < 1e-9
    assert abs(check.simulated_vs_measured - check.simulated_vs_model) < 1e-9 and np.all(check.tracking_error < 1e-3)
    phi[names.index("offset2")] = 5.0  # N·m the MJCF cannot hold: the simulator needs that much less on J2
    off = mjcf_forward(mjcf_from_robot(robot, phi), robot, phi, t, q, dq, ddq, regressor(robot, q, dq, ddq) @ phi)
    assert off.simulated_vs_model > 10 * check.simulated_vs_model


def test_the_forward_checks_reference_is_the_logs_own_state_and_acceleration_at_every_sample():
    """The reference between two samples is the quintic Hermite of their positions, velocities and accelerations
    (independent truth: a quintic polynomial motion is reproduced exactly, with its derivatives); so on a log whose
    positions carry sensor noise that its filtered accelerations do not, the PD loop does not make the arm follow an
    acceleration of the interpolant's own and the simulated torques stay the model's (the cubic of positions and
    velocities alone put 6·noise/Δt² into the acceleration asked for)."""
    from dynid.dynamics.regressor import regressor
    from dynid.io.exported.replay import _between, _hermite_weights, mjcf_forward
    from dynid.model.description_files import mjcf_from_robot

    coefficients = np.array([0.1, -0.4, 0.7, 0.3, -0.9, 0.5])  # q(t) = Σ c_i t^i on every joint, scaled per joint
    scale = np.linspace(0.5, 1.5, 3)
    t = np.array([0.2, 0.27])
    poly = np.polynomial.Polynomial(coefficients)
    states = [np.outer(poly.deriv(d)(t), scale) if d else np.outer(poly(t), scale) for d in range(3)]
    weights = _hermite_weights(8)
    position, velocity, acceleration = _between(t, *states, 0, weights)
    inside = t[0] + np.arange(8) / 8 * (t[1] - t[0])
    for got, d in ((position, 0), (velocity, 1), (acceleration, 2)):
        assert np.allclose(got, np.outer(poly.deriv(d)(inside) if d else poly(inside), scale), rtol=0, atol=1e-12)

    robot, phi = _without_dry_friction()
    t = np.arange(0.0, 4.0, 0.004)
    q, dq, ddq = _sines(t)
    noisy = q + np.random.default_rng(3).normal(0.0, 2e-5, q.shape)  # an encoder's noise; the states are filtered
    tau = regressor(robot, noisy, dq, ddq) @ phi
    check = mjcf_forward(mjcf_from_robot(robot, phi), robot, phi, t, noisy, dq, ddq, tau)
    assert check.simulated_vs_model < 0.5


def test_the_forward_checks_steps_follow_the_logs_rate():
    """By default the simulation takes 40 steps a sample, none shorter than MIN_STEP (25 µs): a 5 kHz log takes 8
    where it took 40, a 100 Hz one 40 as before; the torques the simulated arm needs are those of a simulation at 40
    steps a sample (the independent reference, 5 times finer) to 1e-3 of the model's RMS torque."""
    from dynid.dynamics.regressor import regressor
    from dynid.io.exported.replay import MIN_STEP, mjcf_forward
    from dynid.model.description_files import mjcf_from_robot

    robot, phi = _without_dry_friction()
    text = mjcf_from_robot(robot, phi)
    for rate, expected in ((5000.0, 8), (100.0, 40)):
        t = np.arange(0.0, 1.0, 1.0 / rate)
        q, dq, ddq = _sines(t)
        tau = regressor(robot, q, dq, ddq) @ phi
        default = mjcf_forward(text, robot, phi, t, q, dq, ddq, tau)
        assert default.substeps == expected and 1.0 / rate / expected >= MIN_STEP * (1 - 1e-9)
        if expected < 40:
            fine = mjcf_forward(text, robot, phi, t, q, dq, ddq, tau, substeps=40)
            assert abs(default.simulated_vs_model - fine.simulated_vs_model) < 0.1  # [%] of the model's torque

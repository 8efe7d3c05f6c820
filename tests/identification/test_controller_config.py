"""``[controller]`` in a config: IDIM-IV and DIDIM run by ``dynid identify`` on a closed-loop log beside least
squares, and refused in one line when the controller is not given."""

import json

import numpy as np
import pytest

import dynid
from dynid.dynamics.base_parameters import base_parameters
from dynid.dynamics.rnea import rnea_torques
from dynid.excitation.paper_trajectories import paper_identification_trajectory
from dynid.simulation.closed_loop import ClosedLoopNoise, Controller, simulate_closed_loop

from ..cli.refusals import assert_refused
from ..cli.refusals import dynid as dynid_cli

N = 6
COLUMNS = ", ".join(f'"q{j}"' for j in range(1, N + 1))


def _write(tmp_path, controller_table: str, estimators='["wls", "idim-iv", "didim"]') -> None:
    (tmp_path / "cl.toml").write_text(f'''robot = "er16"
[identification]
file = "log.csv"
header = true
time = {{ column = "t" }}
positions = {{ columns = [{COLUMNS}] }}
torques = {{ columns = [{", ".join(f'"tau{j}"' for j in range(1, N + 1))}] }}
[estimation]
estimators = {estimators}
friction = "description"
{controller_table}''')


@pytest.fixture(scope="module")
def closed_loop_log(tmp_path_factory):
    """10 s of the ER-16's paper excitation at 1 kHz under a PID with model feed-forward, encoder noise 1e-3 deg."""
    root = tmp_path_factory.mktemp("closed-loop")
    robot = dynid.load_robot("er16")
    t = np.arange(10000) / 1000.0
    q, dq, ddq = paper_identification_trajectory(n_dof=N).evaluate(t)
    c = Controller.for_robot(robot)
    run = simulate_closed_loop(robot, t, q, dq, c, ClosedLoopNoise(position_std=np.deg2rad(1e-3), torque_std=0.1),
                               rng=np.random.default_rng(0), feedforward=rnea_torques(robot, q, dq, ddq))
    header = "t," + ",".join(f"q{j}" for j in range(1, N + 1)) + "," + ",".join(f"tau{j}" for j in range(1, N + 1))
    np.savetxt(root / "log.csv", np.column_stack([t, run.q, run.tau]), delimiter=",", header=header, comments="", fmt="%.10g")
    np.savetxt(root / "ref.csv", q, delimiter=",", header=",".join(f"r{j}" for j in range(1, N + 1)), comments="",
               fmt="%.12g")
    table = (f"[controller]\nkp = {c.kp.tolist()}\nkd = {c.kd.tolist()}\nki = {c.ki.tolist()}\nrate = 1000.0\n"
             f"velocity_cutoff = {c.velocity_cutoff}\nfeedforward = \"model\"\n"
             f"reference = {{ file = \"ref.csv\", header = true, positions = [{COLUMNS.replace('q', 'r')}] }}\n")
    base = base_parameters(robot, rng=0)
    return root, table, dict(zip(base.names, base.base_from_standard(robot.standard_parameters())))


def test_dynid_identify_runs_idim_iv_and_didim_beside_least_squares(closed_loop_log):
    root, table, truth = closed_loop_log
    _write(root, table)
    p = dynid_cli("identify", root / "cl.toml", "--out", root / "out", "--no-figures", "--verbose")
    assert p.returncode == 0, p.stderr
    assert "IDIM-IV" in p.stdout and "DIDIM" in p.stdout  # beside least squares in the parameters table
    estimates = json.loads((root / "out" / "results.json").read_text())["estimates"]
    assert list(estimates) == ["dynid WLS", "dynid IDIM-IV", "dynid DIDIM"]
    # IDIM-IV converges. DIDIM's Gauss–Newton steps on this short six-joint log lead to a model whose closed loop
    # cannot be simulated even when halved six times: it stops and says so, with the last estimate that could be
    # (until the review of this stop it "converged" only because a bug restarted it from the description — here the
    # simulation's truth — after every halved step)
    assert "note" not in estimates["dynid IDIM-IV"], estimates["dynid IDIM-IV"].get("note")
    didim = estimates["dynid DIDIM"].get("note", "")
    assert didim == "" or "stopped: closed-loop simulation diverged" in didim, didim
    for label, e in estimates.items():
        # the well-determined parameters (σ below 5 % of the value) against the simulation's truth: within 5 σ
        good = [n for n in e["values"] if e["std"][n] < 0.05 * abs(truth[n])]
        assert len(good) >= 10
        z = [abs(e["values"][n] - truth[n]) / e["std"][n] for n in good]
        assert np.median(z) < 5, (label, np.median(z))


def test_dynid_identify_runs_didim_sdp_from_a_config(closed_loop_log, tmp_path):
    """``didim-sdp`` in ``[estimation] estimators``: a physically consistent estimate (its margin >= 0 in results.json,
    against the feasibility SDP) with no σ, beside least squares."""
    root, table, truth = closed_loop_log
    for name in ("log.csv", "ref.csv"):
        (tmp_path / name).write_bytes((root / name).read_bytes())
    _write(tmp_path, table, '["wls", "didim-sdp"]')
    p = dynid_cli("identify", tmp_path / "cl.toml", "--out", tmp_path / "out", "--no-figures", "--verbose")
    assert p.returncode == 0, p.stderr
    result = json.loads((tmp_path / "out" / "results.json").read_text())
    e = result["estimates"]["dynid DIDIM-SDP"]
    assert "note" not in e, e.get("note")
    assert e.get("std") is None
    assert result["consistency_margin"]["dynid DIDIM-SDP"] >= -1e-6
    assert result["physically_consistent_verdict"]["dynid DIDIM-SDP"].startswith("yes")
    good = [n for n in e["values"] if abs(truth[n]) > 1.0]
    assert np.median([abs(e["values"][n] - truth[n]) / abs(truth[n]) for n in good]) < 0.01


def test_closed_loop_estimators_without_the_controller_are_refused_in_one_line(closed_loop_log, tmp_path):
    root, table, _ = closed_loop_log
    (tmp_path / "log.csv").write_bytes((root / "log.csv").read_bytes())
    _write(tmp_path, "")
    assert_refused(dynid_cli("identify", tmp_path / "cl.toml", "--out", tmp_path / "o"),
                   "estimation.estimators: idim-iv simulates the run in closed loop and needs its controller: add a "
                   "[controller] table")
    _write(tmp_path, table, '["didim", "wls"]')
    assert_refused(dynid_cli("identify", tmp_path / "cl.toml", "--out", tmp_path / "o"), "list ols or wls before 'didim'")
    _write(tmp_path, table.replace("kp = [", "kp = [-1.0, "))
    assert_refused(dynid_cli("identify", tmp_path / "cl.toml", "--out", tmp_path / "o"), "controller.kp")
    # a reference with fewer set-points than the log has samples
    lines = (root / "ref.csv").read_text().splitlines()
    (tmp_path / "ref.csv").write_text("\n".join(lines[:-10]) + "\n")
    _write(tmp_path, table, '["wls", "idim-iv"]')
    assert_refused(dynid_cli("identify", tmp_path / "cl.toml", "--out", tmp_path / "o"),
                   "ref.csv: 9990 rows of set-points, the identification log has 10000 samples")


def test_the_identifier_takes_every_estimator_a_config_takes(closed_loop_log):
    """Identifier(estimators=["wls", "idim-iv"]) was refused ("expected a comma-separated subset of ols, wls, …") where
    the config took the same list: on a config with a [controller] it runs IDIM-IV beside WLS, the same estimates as
    the config's own list; on arrays, and on a config without a controller, it says what is missing in one line."""
    from dynid.exceptions import ConfigError

    root, table, _ = closed_loop_log
    _write(root, table, estimators='["wls", "idim-iv"]')
    ident = dynid.Identifier.from_config(root / "cl.toml", estimators=["wls", "idim-iv"], validate=False)
    assert list(ident.estimates_) == ["dynid WLS", "dynid IDIM-IV"]
    by_config = dynid.Identifier.from_config(root / "cl.toml", validate=False)
    np.testing.assert_allclose(ident.estimates_["dynid IDIM-IV"], by_config.estimates_["dynid IDIM-IV"], rtol=1e-12)
    _write(root, "", estimators='["wls"]')
    with pytest.raises(ConfigError, match=r"idim-iv simulates the run in closed loop and needs its controller: .*cl.toml has no \[controller\]"):
        dynid.Identifier.from_config(root / "cl.toml", estimators=["wls", "idim-iv"], validate=False)
    log = dynid.simulated_log(dynid.load_robot("er16"), seconds=5, rng=1)
    with pytest.raises(ConfigError, match=r"idim-iv simulates the run in closed loop and needs its controller: fit a config"):
        dynid.Identifier("er16", estimators=["wls", "idim-iv"]).fit(log.t, log.q, log.tau)
    with pytest.raises(ConfigError, match="list ols or wls before 'idim-iv'"):
        dynid.Identifier.from_config(root / "cl.toml", estimators=["idim-iv", "wls"])


def test_the_closed_loop_estimators_run_from_arrays_as_from_a_config(closed_loop_log):
    """IDIM-IV and DIDIM are pipeline estimators: identify_from_arrays and Identifier(controller=...) run them on
    arrays with the same numbers as ``dynid identify`` on the config that describes the same log and controller; the
    pipeline refuses them without a controller, in one line."""
    from dynid.exceptions import ConfigError
    from dynid.identification.closed_loop_estimators import ClosedLoopEstimator, ClosedLoopSetup
    from dynid.identification.pipeline import IdentificationPipeline
    from dynid.simulation.closed_loop import Controller

    root, table, _ = closed_loop_log
    _write(root, table, estimators='["wls", "idim-iv"]')
    by_config = dynid.Identifier.from_config(root / "cl.toml", validate=False)
    log = np.loadtxt(root / "log.csv", delimiter=",", skiprows=1)
    robot = dynid.load_robot("er16")
    setup = ClosedLoopSetup(Controller.for_robot(robot), np.loadtxt(root / "ref.csv", delimiter=",", skiprows=1),
                            feedforward=True)
    t, q, tau = log[:, 0], log[:, 1:N + 1], log[:, N + 1:]
    ident = dynid.Identifier(robot, estimators=["wls", "idim-iv"], controller=setup, friction="description").fit(t, q, tau)
    assert list(ident.estimates_) == ["dynid WLS", "dynid IDIM-IV"]
    for label in ident.estimates_:  # the same to rounding (the arrays' route resamples as the config's reader does)
        expected = by_config.estimates_[label]
        np.testing.assert_allclose(ident.estimates_[label], expected, rtol=1e-7, atol=1e-10 * np.abs(expected).max())
    result = dynid.identify_from_arrays(robot, t, q, tau, estimators=["wls", "idim-iv"], controller=setup,
                                        friction="description")
    np.testing.assert_allclose(result.estimates["dynid IDIM-IV"].params, ident.estimates_["dynid IDIM-IV"], rtol=0)
    _write(root, "", estimators='["wls"]')  # a config without [controller]: the one given is used
    given = dynid.Identifier.from_config(root / "cl.toml", estimators=["wls", "idim-iv"], controller=setup, validate=False)
    np.testing.assert_allclose(given.estimates_["dynid IDIM-IV"], by_config.estimates_["dynid IDIM-IV"], rtol=1e-12)
    _write(root, table, estimators='["wls", "idim-iv"]')
    with pytest.raises(ConfigError, match=r"idim-iv simulates the run in closed loop and needs its controller \(a ClosedLoopSetup"):
        IdentificationPipeline(robot, estimators=("wls", "idim-iv"))
    with pytest.raises(ConfigError, match="the first is the main estimate and starts the closed-loop ones"):
        IdentificationPipeline(robot, estimators=(ClosedLoopEstimator("didim", setup),))
    short = ClosedLoopSetup(setup.controller, setup.reference[:-10], feedforward=True)
    from dynid.exceptions import DataError

    with pytest.raises(DataError, match="the reference: 9990 rows of set-points, the identification log has 10000"):
        dynid.identify_from_arrays(robot, t, q, tau, estimators=["wls", "idim-iv"], controller=short)


def _setup_and_recording(root):
    """The ER-16, the fixture's controller with its set-points, and its log as a Recording."""
    from dynid.identification.closed_loop_estimators import ClosedLoopSetup
    from dynid.io.logs.datasets import Recording
    from dynid.simulation.closed_loop import Controller

    log = np.loadtxt(root / "log.csv", delimiter=",", skiprows=1)
    robot = dynid.load_robot("er16")
    setup = ClosedLoopSetup(Controller.for_robot(robot), np.loadtxt(root / "ref.csv", delimiter=",", skiprows=1),
                            feedforward=True)
    return robot, setup, Recording("cl", log[:, 0], log[:, 1:N + 1], None, log[:, N + 1:], 1000.0)


def test_a_closed_loop_estimator_is_a_part_that_carries_its_controller(closed_loop_log):
    """IdentificationPipeline(estimators=("wls", "idim-iv"), controller=...) is made of ClosedLoopEstimator parts, each
    carrying the controller, and takes such a part itself in its estimators: one such part added to the pipeline's open-loop result gives the pipeline's own IDIM-IV estimate, and
    an unknown method is refused in one line."""
    from dynid.exceptions import ConfigError
    from dynid.identification.closed_loop_estimators import ClosedLoopEstimator
    from dynid.identification.pipeline import IdentificationPipeline

    robot, setup, recording = _setup_and_recording(closed_loop_log[0])
    pipeline = IdentificationPipeline(robot, estimators=("wls", "idim-iv"), controller=setup)
    assert [(p.method, p.setup) for p in pipeline.closed_loop_estimators] == [("idim-iv", setup)]
    assert pipeline.open_loop == ("wls",) and pipeline.closed_loop == ("idim-iv",)
    as_part = IdentificationPipeline(robot, estimators=("wls", ClosedLoopEstimator("idim-iv", setup)))
    assert as_part.closed_loop_estimators == pipeline.closed_loop_estimators
    prepared = pipeline.prepare(recording)
    whole = pipeline.estimate(prepared, recording=recording)
    open_loop = IdentificationPipeline(robot, estimators=("wls",)).estimate(prepared)
    alone = ClosedLoopEstimator("idim-iv", setup).added_to(open_loop, prepared.robot, prepared.base, recording,
                                                           pipeline.preprocessing)
    assert list(alone.estimates) == ["dynid WLS", "dynid IDIM-IV"]
    np.testing.assert_array_equal(alone.estimates["dynid IDIM-IV"].params, whole.estimates["dynid IDIM-IV"].params)
    assert alone.consistency_verdicts["dynid IDIM-IV"] == whole.consistency_verdicts["dynid IDIM-IV"]
    with pytest.raises(ConfigError, match="closed_loop: 'idim' is not a closed-loop estimator"):
        ClosedLoopEstimator("idim", setup)


def test_the_closed_loop_estimators_fit_the_rows_the_pipeline_prepared(closed_loop_log, monkeypatch):
    """The pipeline's closed-loop parts take its prepared data (its chosen cutoffs, rest model and speeds): the
    measured log is not prepared a second time, only the simulated ones are; the estimate is the one on that data."""
    from dynid.identification import closed_loop_estimators as closed_loop
    from dynid.identification.pipeline import IdentificationPipeline

    robot, setup, recording = _setup_and_recording(closed_loop_log[0])
    pipeline = IdentificationPipeline(robot, estimators=("wls", "idim-iv"), controller=setup)
    prepared = pipeline.prepare(recording)
    real_prepare, measured = closed_loop.prepare, []

    def counted(log, *args, **kwargs):
        measured.append(log.name == "cl")
        return real_prepare(log, *args, **kwargs)

    monkeypatch.setattr(closed_loop, "prepare", counted)
    whole = pipeline.estimate(prepared, recording=recording)
    assert measured and not any(measured)  # simulated logs prepared; the measured one never again
    direct = closed_loop.closed_loop_identify(prepared.robot, prepared.base, recording,
                                              pipeline.closed_loop_estimators[0].experiment(prepared.robot, recording),
                                              methods=("idim-iv",), data=prepared.data)["idim-iv"]
    np.testing.assert_array_equal(whole.estimates["dynid IDIM-IV"].params, direct.params)


def test_the_reference_is_read_at_the_angles_the_log_is(tmp_path):
    """A description whose J2 encoder zero is a quarter turn from its model's (``position_offset = "pi/2"``): a log's
    angles get the offset, and the controller's set-points (the same encoders' angles) get it too. They were read as
    given, a quarter turn from the log's motion, which IDIM-IV and DIDIM would simulate as the reference."""
    from importlib import resources

    from dynid.io.config.identification_config import load_identification_config
    from dynid.io.logs.datasets import load_recording

    text = (resources.files("dynid.model") / "robots" / "er16.toml").read_text()
    head, first, rest = text.partition('[[joints]]\nname = "joint2"\n')
    (tmp_path / "arm.toml").write_text(head + first + 'position_offset = "pi/2"\n' + rest)
    t = np.arange(200) / 1000.0
    q = 0.3 * np.sin(np.outer(t, np.arange(1, N + 1)))
    header = "t," + ",".join(f"q{j}" for j in range(1, N + 1)) + "," + ",".join(f"tau{j}" for j in range(1, N + 1))
    np.savetxt(tmp_path / "log.csv", np.column_stack([t, q, np.cos(q)]), delimiter=",", header=header, comments="")
    np.savetxt(tmp_path / "ref.csv", q, delimiter=",", header=",".join(f"r{j}" for j in range(1, N + 1)), comments="")
    _write(tmp_path, "[controller]\nkp = 100.0\nkd = 10.0\nrate = 1000.0\n"
                     f"reference = {{ file = \"ref.csv\", header = true, positions = [{COLUMNS.replace('q', 'r')}] }}\n")
    (tmp_path / "cl.toml").write_text((tmp_path / "cl.toml").read_text().replace('robot = "er16"', 'robot = "arm.toml"'))
    config = load_identification_config(tmp_path / "cl.toml")
    logged = load_recording(config.identification, config.robot).q
    reference = config.controller.reference.read()
    assert np.allclose(reference, logged, atol=1e-9)
    assert np.allclose(reference[:, 1] - q[:, 1], np.pi / 2)


def test_a_coupled_robots_closed_loop_log_is_identified_from_its_driven_joints(tmp_path):
    """issue "Every arm a user has": a palletiser whose j4 follows j3 (`<mimic>`), its closed-loop log, gains and
    set-points given for the four driven joints as its controller has them: `dynid identify` runs IDIM-IV and DIDIM
    beside least squares (the closed-loop simulation refused such a robot before), each converged."""
    from ..dynamics.test_mimic_joints import PALLETISER, _closed_loop_palletiser

    (tmp_path / "palletiser.urdf").write_text(PALLETISER)
    robot, t, q_ref, _, controller, run = _closed_loop_palletiser(tmp_path / "palletiser.urdf")
    driven = [0, 1, 2, 4]
    names = [robot.joints[j].name for j in driven]
    np.savetxt(tmp_path / "log.csv", np.column_stack([t, run.q[:, driven], run.tau[:, driven]]), delimiter=",",
               header="t," + ",".join(f"{n}_q" for n in names) + "," + ",".join(f"{n}_tau" for n in names), comments="",
               fmt="%.12g")
    np.savetxt(tmp_path / "ref.csv", q_ref[:, driven], delimiter=",", fmt="%.12g")
    gains = {k: getattr(controller, k)[driven].tolist() for k in ("kp", "kd", "ki")}
    (tmp_path / "cl.toml").write_text(f'''[robot]
urdf = "palletiser.urdf"
held = ["finger_a_joint", "finger_b_joint"]
drive_terms = ["Ia", "fc", "fv", "offset"]
[identification]
file = "log.csv"
header = true
time = {{ column = "t" }}
positions = {{ columns = [{", ".join(f'"{n}_q"' for n in names)}] }}
torques = {{ columns = [{", ".join(f'"{n}_tau"' for n in names)}] }}
[estimation]
estimators = ["wls", "idim-iv", "didim"]
[controller]
kp = {gains["kp"]}
kd = {gains["kd"]}
ki = {gains["ki"]}
rate = 500.0
velocity_cutoff = {controller.velocity_cutoff}
reference = {{ file = "ref.csv", positions = [1, 2, 3, 4] }}
''')
    p = dynid_cli("identify", tmp_path / "cl.toml", "--out", tmp_path / "out", "--no-figures")
    assert p.returncode == 0, p.stderr
    estimates = json.loads((tmp_path / "out" / "results.json").read_text())["estimates"]
    assert list(estimates) == ["dynid WLS", "dynid IDIM-IV", "dynid DIDIM"]
    for label in ("dynid IDIM-IV", "dynid DIDIM"):
        assert "note" not in estimates[label], (label, estimates[label].get("note"))

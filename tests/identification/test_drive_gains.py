"""Drive gains (eq. 16) and a payload from runs without and with a payload of known mass."""

import re
from dataclasses import replace

import numpy as np
import pytest

from dynid.dynamics.base_parameters import base_parameters
from dynid.identification.drive_gains import identify_drive_gains, identify_payload
from dynid.io.logs.datasets import Recording
from dynid.model.spatial import inertial_from_physical
from dynid.preprocessing.preparation import Preprocessing, prepare

from ..simulated_logs import fourier_motion, torques, truth_robot

K_TRUE = np.array([10.2, 10.9, 8.3, 9.1, 9.6, 10.0])


def test_gains_and_payload_recovered_from_simulated_currents():
    """UR10e simulated with Pinocchio's RNEA and friction written out (not dynid's model), gains K_TRUE,
    a 2.805 kg payload with an unknown centre of mass and inertia, 0.005 A current noise: the gains come
    back within 1 %, and the payload's ten parameters from the loaded run."""
    rng = np.random.default_rng(0)
    robot, friction = truth_robot("ur10e", rng)
    robot = replace(robot, drive_gains=K_TRUE)
    payload = inertial_from_physical(2.805, np.array([0.01, -0.02, 0.06]), np.diag([0.004, 0.005, 0.003]))
    loaded_robot = replace(robot, inertial=np.vstack([robot.inertial[:-1], robot.inertial[-1] + payload]))
    rate = 100.0
    t = np.arange(int(50 * rate)) / rate

    def run(r, name):
        q, dq, ddq = fourier_motion(robot, t, rng)
        tau = torques(r, q, dq, ddq, friction)
        current = tau / K_TRUE + rng.normal(0, 0.005, tau.shape)
        return Recording(name, t, q, None, current, rate)

    unloaded, loaded = run(robot, "unloaded"), run(loaded_robot, "loaded")
    base = base_parameters(robot, rng=0)
    pu, pl = prepare(unloaded, Preprocessing()), prepare(loaded, Preprocessing())
    est = identify_drive_gains(robot, base, pu, pl, 2.805)
    np.testing.assert_allclose(est.gains, K_TRUE, rtol=0.01)
    assert np.all(np.abs(est.gains - K_TRUE) <= 5 * est.gains_std)
    pay = identify_payload(robot, base, est.base, replace(pl, tau=pl.tau * est.gains))
    assert pay.names == ("XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M")
    assert pay.mass == pytest.approx(2.805, rel=0.01)
    np.testing.assert_allclose(pay.values[6:9], payload[6:9], atol=0.01 * np.abs(payload[6:9]).max())


def test_ur10e_gains_from_the_loaded_and_unloaded_runs(shipped_identification):
    """The UR10e's runs 14harm50sec / 14harm50secLoad (2.805 kg): gains of joints 2-6 within 20 % of the
    authors' (which fix K1 = 10 and are uncertain by 10-20 %, SOURCE.md), the payload's mass within 10 %."""
    result = shipped_identification("ur10e", validate=False)
    gp = result.drive_gains
    authors = np.array([10.0, 10.6956, 8.4566, 9.0029, 9.4800, 10.1232])
    np.testing.assert_allclose(gp.description_gains, authors)
    assert np.all(np.abs(gp.gains.gains[1:] - authors[1:]) <= 0.2 * authors[1:])
    assert gp.payload.mass == pytest.approx(2.805, rel=0.1)
    # K1 (a vertical axis: the payload adds only its inertia's torque) is not determined, as the authors found: said
    # with why, not printed as a number ± σ; the wrist's gains, set by the joints below them, are
    assert np.isnan(gp.gains.gains[0]) and np.all(np.isfinite(gp.gains.gains[1:]))
    why = gp.gains.why_not_observable(0)
    assert "residual σ (at least 3× needed)" in why and "moves to" in why
    assert gp.gains.to_dict()["not_observable"] == {"K1": why}


def test_ur10e_drive_gains_computed_beside_the_identification_are_those_computed_after_it(monkeypatch, tmp_path):
    """run_identification computes the drive gains in a forked child while it identifies (two cores): the
    same numbers as in this process, and the same identification (both with one BLAS thread)."""
    import json
    import sys
    from pathlib import Path

    from threadpoolctl import threadpool_limits

    from dynid.identification.run import run_identification
    from dynid.io import write_json
    from dynid.io.config.identification_config import load_identification_config
    from dynid.runtime import processes
    from dynid.runtime.processes import allow_forks
    from dynid.runtime.threads import cores

    from ..conftest import shared_data, without_wall_times

    cfg = load_identification_config(Path(__file__).resolve().parents[2] / "configs" / "ur10e.toml",
                                      data_root=shared_data("ur10e_mamedov2020"))
    forks = []
    real_init = processes.ForkedCall.__init__

    def counted(call, *args):
        real_init(call, *args)
        if call._child is not None:  # a child was forked for it
            forks.append(1)

    monkeypatch.setattr(processes.ForkedCall, "__init__", counted)
    with allow_forks(), threadpool_limits(1):  # as in the CLI
        beside = run_identification(cfg, validate=False)
    assert len(forks) == (1 if cores() >= 2 and sys.platform.startswith("linux") else 0)  # the gains went to a child
    n_beside = len(forks)
    with threadpool_limits(1):  # run here, not the shared run: the check is that this run forks nothing
        after = run_identification(cfg, validate=False)  # the library alone computes them in its process
    assert len(forks) == n_beside
    for path, result in (("beside.json", beside), ("after.json", after)):
        write_json(tmp_path / path, without_wall_times(result.to_dict()))
    from .. import digests  # the same numbers, but SDP optima (consistency margins) to the solver's tolerance: cvxpy
    #                         re-solving a problem it cached earlier in the process moves them in the 11th digit
    read = lambda name: digests.flatten(json.loads((tmp_path / name).read_text()))  # noqa: E731
    assert digests.differences(read("beside.json"), read("after.json")) == []
    assert "drive_gains" in json.loads((tmp_path / "after.json").read_text())
    np.testing.assert_array_equal(beside.drive_gains.gains.gains, after.drive_gains.gains.gains)  # NaN where not determined


def test_payload_parameters_the_loaded_run_does_not_determine_are_said_so():
    from dynid.identification.drive_gains import DriveGainEstimate, GainsAndPayload, PayloadEstimate
    from dynid.report.choice_tables import drive_gains_blocks

    payload = PayloadEstimate(("XX", "MX", "MY", "MZ", "M"), np.array([0.004, 0.03, -0.001, 0.17, 2.8]),
                              np.array([0.01, 0.002, 0.004, 0.003, 0.02]))
    assert payload.not_determined == ("XX", "MY")
    stored = payload.to_dict()
    assert stored["XX"]["determined"] is False and stored["MX"]["determined"] is True
    gains = DriveGainEstimate(np.full(6, 10.0), np.full(6, 0.1), np.zeros(3), 2.805, 1000, 10.0)
    text = " ".join(line.text for line in drive_gains_blocks(GainsAndPayload(gains, payload, (10.0,) * 6))
                    if hasattr(line, "text"))
    assert "payload parameters not determined by the loaded run (σ ≥ 100 % of the value): XX, MY" in text
    assert "(0.0107, not determined, 0.0607) m" in text
    # a sliding joint's gain is a force per ampere; a joint not determined says the description's in its unit
    gains = DriveGainEstimate(np.array([10.0, np.nan, 10, 10, 10, 10]), np.full(6, 0.1), np.zeros(3), 2.805, 1000, 10.0)
    blocks = drive_gains_blocks(GainsAndPayload(gains, payload, (10.0,) * 6), (False, True, False, False, False, False))
    assert "K (N·m/A; J2 in N/A)" in blocks[0].render()
    assert any("the description's 10 N/A is used" in b.text for b in blocks if hasattr(b, "text"))


def test_the_currents_noise_is_taken_out_of_the_gains():
    """Noise on the currents, a regressor column of the stacked problem, pulls every gain towards zero in proportion to
    its variance (errors in variables). UR10e simulated as above at 0.02 A, three seeds, the same filter for every run:
    least squares gives the wrist's K5 about 4 % low; bias-compensated least squares takes the noise's variance out of
    the normal equations and leaves a third of that at most, the other gains within 0.2 %."""
    import dynid.identification.drive_gains as dg

    plain, compensated = [], []
    for seed in range(3):
        for comp in (False, True):
            rng, noise_rng = np.random.default_rng(seed), np.random.default_rng(100 + seed)
            robot, friction = truth_robot("ur10e", rng)
            robot = replace(robot, drive_gains=K_TRUE)
            payload = inertial_from_physical(2.805, np.array([0.01, -0.02, 0.06]), np.diag([0.004, 0.005, 0.003]))
            loaded_robot = replace(robot, inertial=np.vstack([robot.inertial[:-1], robot.inertial[-1] + payload]))
            t = np.arange(5000) / 100.0

            def run(r, name):
                q, dq, ddq = fourier_motion(robot, t, rng)
                current = torques(r, q, dq, ddq, friction) / K_TRUE + noise_rng.normal(0, 0.02, (t.size, 6))
                return Recording(name, t, q, None, current, 100.0)

            unloaded, loaded = run(robot, "unloaded"), run(loaded_robot, "loaded")
            pre = Preprocessing(band=0.5)
            solve = dg._compensated
            try:
                if not comp:
                    dg._compensated = lambda sol, acc, noise: sol
                est = identify_drive_gains(robot, base_parameters(robot, rng=0), prepare(unloaded, pre), prepare(loaded, pre), 2.805)
            finally:
                dg._compensated = solve
            (compensated if comp else plain).append(100 * (est.gains - K_TRUE) / K_TRUE)
    plain, compensated = np.mean(plain, axis=0), np.mean(compensated, axis=0)
    assert plain[4] < -2.0  # the bias, measured: -4.2 % (compensated: -0.18 %)
    assert abs(compensated[4]) < abs(plain[4]) / 3
    assert np.all(np.abs(compensated[:4]) < 0.2)


def test_a_drive_gains_error_names_the_runs_it_comes_from(tmp_path):
    """[drive_gains] whose loaded run selects too few rows: the one-line error named the table but no file; now it
    names both runs' files."""
    from pathlib import Path

    from dynid.exceptions import DynIdError
    from dynid.identification.run import run_identification
    from dynid.io.config.identification_config import load_identification_config

    from ..conftest import shared_data

    root = shared_data("ur10e_mamedov2020")
    text = (Path(__file__).resolve().parents[2] / "configs" / "ur10e.toml").read_text()
    text = re.sub(r"rows = \[308, 5071\]", "rows = [308, 340]", text)
    cfg_path = tmp_path / "light.toml"
    cfg_path.write_text(text.replace('data_root = "../../shared/data/ur10e_mamedov2020"', f'data_root = "{root}"'))
    with pytest.raises(DynIdError, match=r"^\[drive_gains\] \(.*14harm50sec.csv and .*14harm50secLoad.csv\): "
                                         r"\[drive_gains.loaded\]: rows = \[308, 340\] selects 33 samples") as caught:
        run_identification(load_identification_config(cfg_path), validate=False)
    assert "\n" not in str(caught.value)


def test_gains_the_description_does_not_give_are_offered_to_it():
    """A URDF alone gives drive gains 1 (currents taken as N·m): where the runs determine gains far from 1, the report
    says so with the values to give; where the description gives gains, or the runs find 1, it says nothing more."""
    from dynid.identification.drive_gains import DriveGainEstimate, GainsAndPayload, PayloadEstimate
    from dynid.report.choice_tables import drive_gains_blocks

    payload = PayloadEstimate(("MX", "MY", "MZ", "M"), np.array([0.03, -0.001, 0.17, 2.8]), np.full(4, 0.001))
    k = np.array([np.nan, 11.83, 9.77, 10.27, 1.02, 10.30])
    gains = DriveGainEstimate(k, np.full(6, 0.05), np.zeros(3), 2.805, 1000, 10.0)

    def said(description):
        return " ".join(line.text for line in drive_gains_blocks(GainsAndPayload(gains, payload, description))
                        if hasattr(line, "text"))

    assert ("the description gives no drive gains (1 N·m/A: the identification above took the currents as N·m); "
            "these runs give J2 11.83, J3 9.77, J4 10.27, J6 10.3 N·m/A: give them as drive_gain in the description's "
            "[[joints]] tables (J1: not determined by these runs, a datasheet's value) and identify again") in \
        said((1.0,) * 6)
    assert "gives no drive gains" not in said((10.0, 10.7, 8.46, 9.0, 9.48, 10.1))

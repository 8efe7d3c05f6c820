"""A geared drive's hysteresis is not a log read wrongly (issue "Every assurance checked on what the user meets": no
false alarm on logs read right; the zoo's SO-100 with a 2 mrad presliding distance was called misread)."""

import dataclasses
from importlib import resources
from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.identification.run import run_identification
from dynid.io.config.identification_config import load_identification_config

URDF = Path(str(resources.files("dynid.model") / "robots" / "ur10e.urdf"))


def _dahl(q: np.ndarray, fc: float, presliding: float) -> np.ndarray:
    """Dahl's friction along one joint's positions, integrated sample by sample (written here, not dynid's):
    ``dF/dq = σ (1 - F/fc · sign(dq))`` with ``σ = fc / presliding``."""
    f = np.zeros_like(q)
    for k in range(1, q.size):
        step = q[k] - q[k - 1]
        f[k] = np.clip(f[k - 1] + fc / presliding * step * (1 - f[k - 1] / fc * np.sign(step)), -fc, fc)
    return f


def _identified(folder: Path, tau: np.ndarray, log) -> dict:
    names = ["time"] + [f"q{j}" for j in range(1, 7)] + [f"tau{j}" for j in range(1, 7)]
    np.savetxt(folder / "log.csv", np.column_stack([log.t, log.q, tau]), delimiter=",", comments="", header=",".join(names))
    (folder / "arm.toml").write_text(
        f'robot = "{URDF}"\n[identification]\nfile = "log.csv"\nheader = true\ntime = {{ column = "time" }}\n'
        'positions = { columns = ["q1", "q2", "q3", "q4", "q5", "q6"] }\n'
        'torques = { columns = ["tau1", "tau2", "tau3", "tau4", "tau5", "tau6"] }\n[estimation]\nestimators = ["wls", "sdp"]\n')
    result = run_identification(load_identification_config(folder / "arm.toml"))
    return {"kinds": [f.kind for f in result.findings], "findings": result.findings, "stats": result.diagnostics}


def test_torques_with_a_geared_drives_hysteresis_are_not_called_misread_and_velocities_still_are(tmp_path):
    """The UR10e's log with each joint's dry friction turning over 2 mrad (Dahl), ten times its rigid-body torque's
    RMS: beyond friction that turns at once its torques follow the description on no joint (below 0.5, the misread
    check's bound), so the log was called misread; beyond Dahl's friction they do, and the verdict says the hysteresis
    instead, with the distance. The same log's velocities read as torques are still called misread."""
    log = dynid.simulated_log(dynid.load_robot(URDF), seconds=30, rng=4)
    tau = log.tau + np.column_stack([_dahl(log.q[:, j], 10 * float(np.sqrt(np.mean(log.tau[:, j] ** 2))), 0.002)
                                     for j in range(6)])
    (tmp_path / "geared").mkdir()
    geared = _identified(tmp_path / "geared", tau, log)
    plain = np.asarray(geared["stats"]["nominal_correlation_beyond_friction"])
    turned = np.asarray(geared["stats"]["nominal_correlation_beyond_hysteresis"])
    assert np.nanmax(np.abs(plain)) < 0.5 <= np.nanmax(np.abs(turned))
    assert "columns" not in geared["kinds"]
    [said] = [f.text for f in geared["findings"] if f.kind == "friction" and "presliding" in f.text]
    assert "a geared drive's hysteresis" in said and "[preprocessing] presliding = " in said
    (tmp_path / "misread").mkdir()
    misread = _identified(tmp_path / "misread", np.gradient(log.q, log.t, axis=0), log)
    assert "columns" in misread["kinds"] and "nominal_correlation_beyond_hysteresis" not in misread["stats"]


def test_a_geared_drives_hysteresis_is_not_proposed_as_a_torque_delay_alone():
    """Issue "Every assurance checked on what the user meets", item 5 (findings only when they hold out). The UR10e's
    log with each joint's dry friction turning over 2 mrad (Dahl, as much as its rigid-body torque's RMS) and no delay:
    friction that turns at once makes the torques look 11 samples late, and held-out blocks favour that lag; Dahl's
    columns at the distance found predict them better with no delay at all, so the finding says the log cannot tell the
    two apart and names the distance (the truth's, to 10 %). The same log with its torques 2.5 samples late and no
    hysteresis: the lag alone, as before."""
    robot = dynid.load_robot("ur10e")
    log = dynid.simulated_log(robot, seconds=30.0, rate=250.0, rng=3)
    tau = np.asarray(log.tau)
    geared = tau + np.column_stack([_dahl(log.q[:, j], float(np.sqrt(np.mean(tau[:, j] ** 2))), 0.002)
                                    for j in range(6)])
    r = dynid.identify_from_arrays(robot, log.t, log.q, geared, estimators=("ols",))
    [said] = [f.text for f in r.findings if f.kind == "delay"]
    found = r.diagnostics["torque_delay"]
    assert found["samples"] > 5 and found["hysteresis"]["held_out_ratio"] < found["held_out_ratio"]
    assert found["hysteresis"]["presliding"] == pytest.approx(0.002, rel=0.1)
    assert "cannot tell a late torque channel from that hysteresis" in said
    assert f"presliding = {found['hysteresis']['presliding']:.2g}" in said and "torque_delay = " in said

    f = np.fft.rfftfreq(log.t.size, 1.0 / log.rate)
    late = np.fft.irfft(np.fft.rfft(tau, axis=0) * np.exp(-2j * np.pi * f * 2.5 / log.rate)[:, None], n=log.t.size,
                        axis=0)
    r = dynid.identify_from_arrays(robot, log.t, log.q, late, estimators=("ols",))
    [said] = [f.text for f in r.findings if f.kind == "delay"]
    assert "hysteresis" not in said and "hysteresis" not in r.diagnostics["torque_delay"]
    assert r.diagnostics["torque_delay"]["samples"] == pytest.approx(2.5, abs=0.25)


def test_with_a_validation_log_the_hysteresis_and_the_delay_are_weighed_apart():
    """The same kind of log with a validation log of another motion (the same drive): the log is identified again
    with the presliding distance found and, apart, with the delay; the validation log agrees with the hysteresis, not
    with the delay (the truth has no delay), and the finding keeps the presliding distance with both figures."""
    from dynid.identification.pipeline import IdentificationPipeline

    robot = dynid.load_robot("ur10e")

    def geared(seconds: float, rng: int):
        log = dynid.simulated_log(robot, seconds=seconds, rate=250.0, rng=rng)
        tau = np.asarray(log.tau)
        return dataclasses.replace(log, tau=tau + np.column_stack(
            [_dahl(log.q[:, j], float(np.sqrt(np.mean(tau[:, j] ** 2))), 0.002) for j in range(6)]))

    result = IdentificationPipeline(robot, estimators=("ols",)).fit(geared(30.0, 3), validation=(geared(20.0, 4),))
    weighed = result.diagnostics["torque_delay"]["validation"]
    assert weighed["presliding"]["with"] * 1.02 < min(weighed["without"], weighed["with"])
    [said] = [f.text for f in result.findings if f.kind == "delay"]
    distance = result.diagnostics["torque_delay"]["hysteresis"]["presliding"]
    assert f"identified again with [preprocessing] presliding = {distance:.2g} (radians), the validation logs agree" in said
    assert f"{weighed['presliding']['with']:.3g} % against {weighed['without']:.3g} %" in said
    assert f"instead, {weighed['with']:.3g} %): keep the presliding distance" in said

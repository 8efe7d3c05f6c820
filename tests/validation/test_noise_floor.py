"""The noise floor of a scored log (issue "Honest on any log", item 5): what a perfect model scores on the same
samples, estimated from the log alone, checked against the true parameters' own error on simulated logs; and a
verdict that says "at the noise floor" instead of blaming the model."""

import json

import numpy as np
import pytest

from dynid.validation.noise_floor import looks_filtered, torque_noise

from ..cli.refusals import dynid
from ..simulated_logs import simulated_case


def test_the_noise_of_a_smooth_signal_is_found_under_its_motion(rng):
    t = np.arange(20000) / 1000.0
    motion = 50 * np.sin(2 * np.pi * 0.3 * t)[:, None] + 20 * np.sign(np.sin(2 * np.pi * 0.2 * t))[:, None]
    sigma = np.array([0.05, 0.5])
    tau = motion + rng.normal(size=(t.size, 2)) * sigma
    assert torque_noise(tau) == pytest.approx(sigma, rel=0.05)


@pytest.mark.parametrize("preprocessing", ["", "parallel_cutoff = 0\n", "parallel_cutoff = 0\ndecimation = 10\n"])
def test_the_floor_is_what_the_true_parameters_score(tmp_path, preprocessing):
    """Simulated ER-16 logs at 1 kHz with noisy currents, scored with the default parallel filter, with none (raw
    samples) and with only a decimation's anti-aliasing filter: the floor dynid reports for the validation log is the
    truth's own error there: within 25 % over all joints, 15 % on each joint (measured: within 1-4 % globally)."""
    cfg, robot = simulated_case(tmp_path, "er16", 1000.0, "fourier", seed=5, duration=20.0, current_std=0.1)
    if preprocessing:
        cfg.write_text(cfg.read_text().replace("[estimation]", f"[preprocessing]\n{preprocessing}\n[estimation]", 1))
    p = dynid("identify", cfg, "--out", tmp_path / "out", "--no-figures", "-q")
    assert p.returncode == 0, p.stderr
    v = json.loads((tmp_path / "out" / "results.json").read_text())["validation"][0]
    truth, floor = v["metrics"]["truth"], v["noise_floor"]
    assert floor["global_relative_error"] == pytest.approx(truth["global_relative_error"], rel=0.25)
    assert np.array(floor["rmse"]) == pytest.approx(np.array(truth["rmse"]), rel=0.15)


def test_a_verdict_at_the_noise_floor_does_not_blame_the_model(tmp_path):
    """Validation on raw 1 kHz samples (parallel_cutoff = 0) of a noisy log, identification filtered by a given
    decimation: the validation figure is several times the fit's, and at its floor; the verdict says "at the noise
    floor" and no longer "worse than it fits ... a model that misses something"."""
    cfg, robot = simulated_case(tmp_path, "er16", 1000.0, "fourier", seed=6, duration=20.0, current_std=0.3)
    cfg.write_text(cfg.read_text().replace("[estimation]", "[preprocessing]\nparallel_cutoff = 0\n\n[estimation]", 1))
    p = dynid("identify", cfg, "--out", tmp_path / "out", "--no-figures")
    assert p.returncode == 0, p.stderr
    results = json.loads((tmp_path / "out" / "results.json").read_text())
    kinds = [f["kind"] for f in results["findings"]]
    v = results["validation"][0]
    err = v["metrics"]["dynid OLS"]["global_relative_error"]
    assert err <= 1.5 * v["noise_floor"]["global_relative_error"]
    assert "floor" in kinds and "validation" not in kinds
    assert "at the noise floor" in " ".join(p.stdout.split())


def test_torques_filtered_before_dynid_are_recognised(rng):
    """White noise of 1 % of the RMS on a motion: raw, it is measured; low-pass filtered at 3 Hz of 100 Hz (as a
    controller or a bag recorder may) or absent, the log is recognised and its floor is unknown."""
    from scipy.signal import butter, filtfilt

    t = np.arange(3000) / 100.0
    motion = 40 * np.sin(2 * np.pi * 0.2 * t)[:, None] * np.array([1.0, 0.3]) + 5.0
    raw = motion + rng.normal(size=motion.shape) * 0.01 * np.sqrt(np.mean(motion**2, axis=0))
    b, a = butter(4, 3.0 / 50.0)
    assert not looks_filtered(raw)
    assert looks_filtered(filtfilt(b, a, raw, axis=0)) and looks_filtered(motion)
    dead = raw.copy()
    dead[:, 1] = 0.0  # a joint without torque neither hides nor shows the noise of the other
    assert not looks_filtered(dead)
    quiet = raw.copy()
    quiet[:, 1] = motion[:, 1]  # the median joint decides, not the quietest
    assert not looks_filtered(np.column_stack([raw, quiet[:, 1:]]))


def test_a_log_filtered_before_dynid_gets_no_floor_and_a_finding(tmp_path):
    """Simulated ER-16 logs at 100 Hz whose currents were low-pass filtered at 3 Hz before dynid read them: the verdict
    names both logs, and no floor is claimed; the same logs unfiltered get their floor and no such finding."""
    from scipy.signal import butter, filtfilt

    cfg, _ = simulated_case(tmp_path, "er16", 100.0, "fourier", seed=2, duration=20.0)
    p = dynid("identify", cfg, "--out", tmp_path / "raw", "--no-figures")
    raw = json.loads((tmp_path / "raw" / "results.json").read_text())
    assert p.returncode == 0 and "noise_floor" in raw["validation"][0]
    assert not [f for f in raw["findings"] if f["kind"] == "filtered"]
    b, a = butter(4, 3.0 / 50.0)
    for name in ("ident.csv", "valid.csv"):  # time, 6 positions, 6 currents
        log = np.loadtxt(tmp_path / name, delimiter=",")
        log[:, 7:] = filtfilt(b, a, log[:, 7:], axis=0)
        np.savetxt(tmp_path / name, log, delimiter=",", fmt="%.10g")
    p = dynid("identify", cfg, "--out", tmp_path / "out", "--no-figures")
    assert p.returncode == 0, p.stderr
    results = json.loads((tmp_path / "out" / "results.json").read_text())
    [found] = [f for f in results["findings"] if f["kind"] == "filtered"]
    assert found["text"].startswith("identification, validation: the torques carry no measurable sample-to-sample noise")
    assert "noise_floor" not in results["validation"][0]
    assert "at the noise floor" not in " ".join(p.stdout.split())
